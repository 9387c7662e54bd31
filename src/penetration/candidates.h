// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): the candidate faces of A - B: their evaluation, pruning by lower bounds, and the enumerations (faces, the overlay walk, the brute-force edge pairs).
// A part of penetration.cpp's translation unit, included by it alone: its
// definitions have internal linkage so that the hot paths (a tracked query
// is a few hundred nanoseconds) inline across the parts as they did in one
// file (see penetration.cpp for the derivation).
#pragma once

#include "penetration/gauss_map_arcs.h"
#include "proxima/shape/support.h"

namespace proxima {
namespace {

// An evaluated candidate: its value h_A(n) + h_B(-n) (scaled units), the
// normal and the supports found.
struct Candidate {
  MinkowskiFaceId id;
  Vec3 normal = Vec3::UnitX();
  double value = std::numeric_limits<double>::infinity();
  int support_a = 0;
  int support_b = 0;
};

Candidate evaluate(const Query& q, const MinkowskiFaceId& id, const Vec3& n, int hint_a,
                   int hint_b) {
  Candidate c;
  c.id = id;
  c.normal = n;
  // Through plateaus: a candidate's hints are its own vertices, which for
  // a pair the arc test kept without a crossing can sit on the far side of
  // a hull, on a facet split by rounding into nearly coplanar faces, where
  // the plain climb stops far below the support and the value is no upper
  // bound (support_hill_climb_through_plateaus). Not from a face along its
  // own normal: its vertices are supports already (up to the normal's
  // rounding), and a climb from a support only rises.
  const bool own_face_a = id.kind == MinkowskiFace::face_vertex && id.a0 >= 0;
  const bool own_face_b = id.kind == MinkowskiFace::vertex_face && id.b0 >= 0;
  const Vec3 n_b = q.rotation_t * (-n);
  c.support_a = own_face_a ? support_hill_climb(q.a, n, hint_a)
                           : support_hill_climb_through_plateaus(q.a, n, hint_a);
  c.support_b = own_face_b ? support_hill_climb(q.b, n_b, hint_b)
                           : support_hill_climb_through_plateaus(q.b, n_b, hint_b);
  c.value = n.dot(q.point_a(c.support_a) - q.point_b(c.support_b));
  return c;
}

// The candidate of a face of A (face_vertex) or of B (vertex_face), hints
// from the id.
Candidate evaluate_face(const Query& q, const MinkowskiFaceId& id) {
  if (id.kind == MinkowskiFace::face_vertex)
    return evaluate(q, id, q.normal_a(id.a0), q.a.face(id.a0)[0], id.b0);
  return evaluate(q, id, q.normal_b(id.b0), id.a0, q.b.face(id.b0)[0]);
}

// Pruning (fast cold query): a face of A - B whose lower bound exceeds the
// best value found so far (an upper bound on the depth, q.bound) by more
// than rounding cannot realize the depth and is not evaluated; q.pruned
// keeps the least such lower bound, and q.bounds_out (when set) the group
// with the ball around its normals that `cone` gives (the tracking cache
// needs them: PenetrationCache::Bound). Lower bounds from the balls inside
// the hulls (Query::inradius):
//   face f of A, normal n:   n.a_f + h_B(-n) >= n.(a_f - c_B) + r_B,
//   face g of B, normal n:   h_A(n) - n.b_g >= n.(c_A - b_g) + r_A,
//   edge e of A, n on its arc: n.a_e + h_B(-n) >= min over the arc of
//                            n.(a_e - c_B), plus r_B (arc_minimum);
// and from points a' of A and b' of B (h_A(n) >= n.a', h_B(-n) >= -n.b'):
//   face f of A:  >= n.(a_f - b'),   face g of B:  >= n.(a' - b_g),
//   edge e of A:  >= min over the arc of n.(a_e - b').
// The points are the supports of the best candidate so far (reference_a,
// reference_b): for the faces whose normals are near its direction, the
// ones that can realize the depth, they bound h_A and h_B to second order
// in the angle, where the balls leave the gap between the hulls'
// circumradius and inradius. The face that realizes the depth has a lower
// bound at most the depth, so it is never pruned.
// `kind`, `i`, `j`: the group's element (PenetrationCache::Bound).
template <class Cone>
bool pruned_by(Query& q, double lower, PenetrationCache::Group kind, int i, int j, Cone&& cone) {
  if (!q.prune || !(lower > q.bound + q.prune_margin + kValueSlackUlps * kUnitRoundoff))
    return false;
  q.pruned = std::min(q.pruned, lower);
  if (q.bounds_out != nullptr) {
    PenetrationCache::Bound b = cone();
    b.lower = lower * q.unit;
    b.anchor = q.translation * q.unit;
    b.kind = kind;
    b.i = i;
    b.j = j;
    q.bounds_out->push_back(b);
  }
  return true;
}

// Whether pruned_by would prune a group of lower bound `lower` (a cheaper
// bound first, a dearer one only when that does not prune).
bool above_bound(const Query& q, double lower) {
  return q.prune && lower > q.bound + q.prune_margin + kValueSlackUlps * kUnitRoundoff;
}

// Edge pairs whose cross product is below this share of their lengths'
// product (the sine of their angle) are skipped as parallel, like an
// exactly zero product (the next test): normalizing a product that small
// would scale its rounding (a few u of the lengths' product) by more than
// 2^150. The cutoff is far below the sines whose normals carry
// information (above a few u), so it drops only pairs parallel within
// rounding.
constexpr double kParallelEdgeSine = 0x1p-200;

// Balls around a pruned group's normals (PenetrationCache::Bound). Slack
// on a ball's radius for the roundings of its centre and of the distances
// to it (a few u each).
constexpr double kConeSlack = 0x1p-40;
// A cap of the unit sphere about a unit centre c is geodesically convex
// when its angular radius is below 90 degrees, i.e. its chord radius below
// sqrt(2): then it holds the arcs between any of its points. Balls wider
// than this are replaced by the whole sphere.
constexpr double kMaxConeChord = 1.4;

PenetrationCache::Bound whole_sphere() { return {Vec3::Zero(), 2.0, 0.0}; }

// The ball around the normals on the arc between the unit normals p and q
// (a face's normals within ep and eq of them): the cap about the
// normalized p + q through both ends.
PenetrationCache::Bound cone_of_arc(const Vec3& p, double ep, const Vec3& q, double eq) {
  const Vec3 sum = p + q;
  const double length = sum.norm();
  if (!(length > 0.25)) return whole_sphere();
  const Vec3 c = sum / length;
  const double spread = std::max((p - c).norm(), (q - c).norm()) + std::max(ep, eq) + kConeSlack;
  if (!(spread < kMaxConeChord)) return whole_sphere();
  return {c, spread, 0.0};
}

using Candidates = std::pmr::vector<Candidate>;

void keep(Query& q, const Candidate& c, Candidates& out) {
  out.push_back(c);
  if (c.value < q.bound) {
    q.bound = c.value;
    q.set_references(c.support_a, c.support_b);
  }
}

// The candidates of an edge pair whose arcs may cross (xa: A's arcs, yb:
// -B's), appended to out: none for parallel edges (they span no face of
// A - B; their faces' candidates cover it). The face's normal is on A's
// arc (outward at A's edge) and on -B's. An arc shorter than a half circle
// holds n or -n, the one on the side of its middle; a segment's arcs make
// a whole circle, then -B's arc decides; for two segments (or arcs so near
// a half circle that the side is unclear, kClearMiddle) both n and -n are
// added (each an upper bound). Pruning: a0 is in A and b0 in B, so the
// value h_A(n) + h_B(-n) is at least n.(a0 - b0), the value itself when
// the pair is a face of A - B (its supports are the edges' points); most
// edge pairs the walk evaluates have a value above the bound, and each
// evaluation costs two hill climbs. Not when the pruned groups are recorded
// (an enumeration after a translation, PenetrationCache::bounds): the
// tracked queries that follow would search one more group per pair
// (bench/penetration_bench's TrackedSweep).
void add_edge_candidate(Query& q, int a0, int a1, const std::array<Arc, 4>& xa, int na, int b0,
                        int b1, const std::array<Arc, 4>& yb, int nb, Candidates& out) {
  const MinkowskiFaceId id{MinkowskiFace::edge_edge, a0, a1, b0, b1};
  // Scaled, a small body's edges can be 2^-500 long beside the other's
  // (PenetrationRegression.TinyBodyInHugeOneHasUnitNormal): exponent_free.
  const Vec3 ea = detail::exponent_free(xa[0].k);
  const Vec3 eb = detail::exponent_free(yb[0].k);
  Vec3 n = ea.cross(eb);
  const double length = n.norm();
  if (!(length > kParallelEdgeSine * ea.norm() * eb.norm()) || !(length > 0.0)) return;
  n /= length;
  Vec3 middle = arc_middle(xa, na);
  if (middle.squaredNorm() == 0) middle = arc_middle(yb, nb);
  const auto add = [&](const Vec3& normal) {
    if (q.bounds_out == nullptr) {
      // Pruned as pruned_by does when it records no group.
      const double lower = normal.dot(q.point_a(a0) - q.point_b(b0));
      if (above_bound(q, lower)) {
        q.pruned = std::min(q.pruned, lower);
        return;
      }
    }
    keep(q, evaluate(q, id, normal, a0, b0), out);
  };
  if (middle.squaredNorm() == 0) {
    add(n);
    add(-n);
    return;
  }
  add(n.dot(middle) < 0 ? Vec3(-n) : n);
}

// A lower bound on n.w for the exact unit normal n of a face, from its
// stored normal `m` (within `error` of n; a few u more for B's, turned by
// the rotation), |w| <= reach (Query::reach: no square root).
double face_lower(const Vec3& m, double error, const Vec3& w, double reach) {
  return m.dot(w) - error * reach;
}

// Appends every face candidate (faces of A, faces of B), the ones that
// pruned_by leaves. The pruning test reads the fast normals; a face kept
// is evaluated along its exact one.
// A list of n hints in q.memory, all -1.
std::int32_t* new_hints(const Query& q, int n) {
  std::int32_t* hints =
      std::pmr::polymorphic_allocator<std::int32_t>(q.memory).allocate(static_cast<std::size_t>(n));
  std::fill_n(hints, n, -1);
  return hints;
}

void add_face_candidates(Query& q, Candidates& out) {
  const PenetrationCache::HullNormals& sa = *q.shapes_a;
  const PenetrationCache::HullNormals& sb = *q.shapes_b;
  // Hints for the other hull's support: the last one found for a face
  // through each vertex (neighbouring faces have near normals, so the
  // climb from it is short; the previous face's, in index order, can be
  // anywhere: at N = 4096 an enumeration that keeps many faces spent most
  // of its time climbing). Allocated with the first face evaluated.
  // A face that the two lower bounds of pruned_by's comment leave gets a
  // third, the same with the hint's point of the other hull (a point of
  // it, and near its support along the face's normal, so that the bound
  // is near the face's value): most faces evaluated have a value above the
  // bound, so the test saves most candidates of a cold query
  // (bench/penetration_bench's Cold, with the edge pairs' test).
  std::int32_t*& near_b = q.near_b;
  std::int32_t* near_a = nullptr;
  int hint_b = 0;
  const int count_a =
      q.only != nullptr ? static_cast<int>(q.only->faces_a.size()) : q.a.face_count();
  for (int k = 0; k < count_a; ++k) {
    const int f = q.only != nullptr ? q.only->faces_a[static_cast<std::size_t>(k)] : k;
    const auto i = static_cast<std::size_t>(f);
    if (q.prune) {
      const auto cycle = q.a.face(f);
      const Vec3 af = q.point_a(cycle[0]);
      const Vec3& n = sa.normals[i];
      const double error = sa.error[i];
      double lower = std::max(face_lower(n, error, af - q.centroid_b, q.reach) + q.inradius_b,
                              face_lower(n, error, af - q.reference_b, q.reach));
      if (!above_bound(q, lower)) {
        const std::int32_t near = near_b == nullptr ? -1 : near_b[cycle[0]];
        lower = std::max(lower,
                         face_lower(n, error, af - q.point_b(near >= 0 ? near : hint_b), q.reach));
      }
      if (pruned_by(q, lower, PenetrationCache::Group::face_a, f, -1, [&] {
            return PenetrationCache::Bound{n, error + kConeSlack, 0.0};
          }))
        continue;
    }
    const auto cycle = q.a.face(f);
    if (near_b == nullptr) near_b = new_hints(q, q.a.vertex_count());
    const std::int32_t near = near_b[static_cast<std::size_t>(cycle[0])];
    MinkowskiFaceId id{MinkowskiFace::face_vertex, f, -1, near >= 0 ? near : hint_b, -1};
    Candidate c = evaluate_face(q, id);
    c.id.b0 = c.support_b;
    hint_b = c.support_b;
    for (const std::int32_t v : cycle) near_b[static_cast<std::size_t>(v)] = c.support_b;
    keep(q, c, out);
  }
  int hint_a = 0;
  const int count_b =
      q.only != nullptr ? static_cast<int>(q.only->faces_b.size()) : q.b.face_count();
  for (int k = 0; k < count_b; ++k) {
    const int g = q.only != nullptr ? q.only->faces_b[static_cast<std::size_t>(k)] : k;
    const auto i = static_cast<std::size_t>(g);
    if (q.prune) {
      // In B's frame (scaled): with n = -(R m), b_g = R b'_g + t and x' =
      // R^T (x - t), n.(x - b_g) = m.(b'_g - x'); 8 u more of error for
      // the rotations' roundings.
      const Vec3& m = sb.normals[i];
      const double error = sb.error[i] + 8.0 * kUnitRoundoff;
      const auto cycle = q.b.face(g);
      const Vec3 bg = q.b.vertex(cycle[0]) * q.inverse;
      double lower = std::max(face_lower(m, error, bg - q.centroid_a_in_b, q.reach) + q.inradius_a,
                              face_lower(m, error, bg - q.reference_a_in_b, q.reach));
      if (!above_bound(q, lower)) {
        const std::int32_t near = near_a == nullptr ? -1 : near_a[cycle[0]];
        const Vec3 hint_in_b =
            q.rotation_t * (q.point_a(near >= 0 ? near : hint_a) - q.translation);
        lower = std::max(lower, face_lower(m, error, bg - hint_in_b, q.reach));
      }
      // The face's normal of A - B is -(R m), within error of it (8 u
      // for the rotation's rounding included).
      if (pruned_by(q, lower, PenetrationCache::Group::face_b, g, -1, [&] {
            return PenetrationCache::Bound{-(q.rotation * m), error + kConeSlack, 0.0};
          }))
        continue;
    }
    const auto cycle = q.b.face(g);
    if (near_a == nullptr) near_a = new_hints(q, q.b.vertex_count());
    const std::int32_t near = near_a[static_cast<std::size_t>(cycle[0])];
    MinkowskiFaceId id{MinkowskiFace::vertex_face, near >= 0 ? near : hint_a, -1, g, -1};
    Candidate c = evaluate_face(q, id);
    c.id.a0 = c.support_a;
    hint_a = c.support_a;
    for (const std::int32_t v : cycle) near_a[static_cast<std::size_t>(v)] = c.support_a;
    keep(q, c, out);
  }
}

// The least n.w over the arc from p to q (unit, angle alpha < pi), or a
// lower bound on it: with n = c1 p + c2 q, c1, c2 >= 0 and
// 1 <= c1 + c2 <= 1 / cos(alpha / 2), n.w >= m = min(p.w, q.w) when
// m >= 0 and n.w >= m / cos(alpha / 2) otherwise (cos(alpha / 2) =
// |p + q| / 2). -infinity for an arc too near a half circle. The arc's
// ends within `error` of the exact arc's (fast face normals,
// kArcNormalError), |w| <= reach: each end's value within error * reach,
// and the exact cos(alpha / 2) at least |p + q| / 2 - error.
//
// kMinArcHalfCos: below it the arc is taken as a half circle. Soundness
// needs only a positive threshold (the lower bound on cos(alpha / 2) must
// be positive for the division to keep the sign); at 1e-3 the bound m /
// half_cos is already a thousand times m, too loose to prune a group, so a
// smaller threshold would buy nothing and risk dividing by rounding noise.
// The fast-against-brute-force twins (PenetrationTwins.WalkMatchesBruteForce,
// ...SmallHullsWithFastArcNormalsMatchBruteForce) catch an unsound prune.
constexpr double kMinArcHalfCos = 1e-3;
double arc_minimum(const Arc& arc, const Vec3& w, double error, double reach) {
  const double m = std::min(arc.p.dot(w), arc.q.dot(w)) - error * reach;
  if (m >= 0.0) return m;
  const double half_cos = 0.5 * (arc.p + arc.q).norm() - error;
  return half_cos > kMinArcHalfCos ? m / half_cos : -std::numeric_limits<double>::infinity();
}

// Brute force over all edge pairs.
void add_edge_candidates_brute_force(Query& q, Candidates& out) {
  struct EdgeArcs {
    int v, w, count;
    std::array<Arc, 4> arcs;
  };
  auto all = [](const ConvexPolytope& poly, auto&& arcs_of) {
    std::vector<EdgeArcs> edges;
    for (const auto& e : poly.edges()) {
      EdgeArcs x{e[0], e[1], 0, {}};
      x.count = arcs_of(e[0], e[1], x.arcs);
      if (x.count > 0) edges.push_back(x);
    }
    return edges;
  };
  const std::vector<EdgeArcs> ea =
      all(q.a, [&](int v, int w, std::array<Arc, 4>& o) { return arcs_of_a(q, v, w, o); });
  const std::vector<EdgeArcs> eb =
      all(q.b, [&](int v, int w, std::array<Arc, 4>& o) { return arcs_of_b(q, v, w, o); });
  for (const EdgeArcs& x : ea)
    for (const EdgeArcs& y : eb)
      if (edges_may_cross(x.arcs, x.count, y.arcs, y.count))
        add_edge_candidate(q, x.v, x.w, x.arcs, x.count, y.v, y.w, y.arcs, y.count, out);
}

// B's arcs by adjacency slot (add_edge_candidates_walk) up to this size
// come from the query's scratch buffer (solve_cold).
constexpr std::size_t kScratchArcBytes = 4096;

// A solid B's arcs, one per edge, computed once on first use (each is met
// from several arcs of A), by adjacency slot of either direction (an arc
// read backwards is the same arc for the crossing test); a polygon's or a
// segment's arcs (up to four) each time.
class ArcsOfB {
 public:
  explicit ArcsOfB(Query& q)
      : q_(q),
        memo_(q.b.dimension() == 3),
        offsets_(q.b.adjacency_offsets()),
        adjacency_(q.b.adjacency()),
        faces_(q.b.adjacency_faces()),
        slot_ready_(memo_ ? q.b.adjacency().size() : 0, 0, q.memory) {
    // Storage only (not value-initialized): with pruning a query reads a
    // few of B's slots, and writing all of them (80 bytes each) would make
    // a large cold query pay the page faults of the fresh allocation. From
    // the scratch buffer when small; else from the heap (the buffer's next
    // blocks double in size: a large body's arcs would take a fresh block,
    // and its page faults, every query).
    const std::size_t slots = slot_ready_.size();
    if (slots * sizeof(Arc) <= kScratchArcBytes) {
      slot_arc_ = std::pmr::polymorphic_allocator<Arc>(q.memory).allocate(slots);
      std::uninitialized_default_construct_n(slot_arc_, slots);
    } else {
      heap_arcs_ = std::make_unique_for_overwrite<Arc[]>(slots);
      slot_arc_ = heap_arcs_.get();
    }
  }

  // The arcs of B's edge j -> k, whose adjacency slot (of j) is `slot`,
  // into ys; returns their count.
  int arcs(int j, std::int32_t k, std::size_t slot, std::array<Arc, 4>& ys) {
    if (!memo_) return arcs_of_b(q_, j, k, ys);
    if (!slot_ready_[slot]) {
      // Both directions of the edge at once: k -> j's slot (its left face
      // is j -> k's right one) gets the same arc read backwards, (q, p,
      // -k), what arcs_of_b gives for it.
      const auto back = static_cast<std::size_t>(
          std::find(adjacency_.begin() + offsets_[static_cast<std::size_t>(k)],
                    adjacency_.begin() + offsets_[static_cast<std::size_t>(k) + 1], j) -
          adjacency_.begin());
      const int count = arcs_of_b(q_, j, k, faces_[slot], faces_[back], ys);
      slot_ready_[slot] = slot_ready_[back] = count == 1 ? 1 : 2;
      slot_arc_[slot] = ys[0];
      slot_arc_[back] = {ys[0].q, ys[0].p, -ys[0].k, ys[0].tolerance};
    }
    ys[0] = slot_arc_[slot];
    return slot_ready_[slot] == 1 ? 1 : 0;
  }

 private:
  Query& q_;
  const bool memo_;
  const std::span<const std::int32_t> offsets_;
  const std::span<const std::int32_t> adjacency_;
  const std::span<const std::int32_t> faces_;
  std::pmr::vector<char> slot_ready_;
  std::unique_ptr<Arc[]> heap_arcs_;
  Arc* slot_arc_ = nullptr;
};

// Whether every edge at A's vertex v (adjacency slots [slot_begin,
// slot_end)) is pruned at once: the faces to the left of v -> w over its
// neighbours w are all the faces around v, so both faces of every edge at
// v; the bound below (the per-edge one, with the least over all of them)
// is at most each edge's. Saves finding each edge's right face (a scan of
// its other end's neighbours) away from the answer. `near`: a vertex of B
// near B's support along -n for the normals n near v's cell (near_hint).
bool vertex_edges_pruned(Query& q, int v, std::size_t slot_begin, std::size_t slot_end,
                         int near) {
  const PenetrationCache::HullNormals& sa = *q.shapes_a;
  const auto faces_a = q.a.adjacency_faces();
  const Vec3 av = q.point_a(v);
  const Vec3 wc = av - q.centroid_b, wr = av - q.reference_b;
  double mc = kInfinity, mr = kInfinity;
  bool all = true;
  for (std::size_t at = slot_begin; at < slot_end && all; ++at) {
    const int f = faces_a[at];
    all = f >= 0;
    if (!all) break;
    const auto i = static_cast<std::size_t>(f);
    mc = std::min(mc, face_lower(sa.normals[i], sa.error[i], wc, q.reach));
    mr = std::min(mr, face_lower(sa.normals[i], sa.error[i], wr, q.reach));
  }
  // The faces of A - B of the edges at v have their normals in v's cell of
  // A's Gauss map, the spherical polygon of the normals of the faces around
  // v: inside the cap about their normalized sum that holds them all.
  const auto cone = [&] {
    Vec3 sum = Vec3::Zero();
    double error = 0.0;
    for (std::size_t at = slot_begin; at < slot_end; ++at) {
      const auto i = static_cast<std::size_t>(faces_a[at]);
      sum += sa.normals[i];
      error = std::max(error, sa.error[i]);
    }
    const double length = sum.norm();
    if (!(length > 0.25)) return whole_sphere();
    const Vec3 c = sum / length;
    double spread = 0.0;
    for (std::size_t at = slot_begin; at < slot_end; ++at)
      spread = std::max(spread, (sa.normals[static_cast<std::size_t>(faces_a[at])] - c).norm());
    spread += error + kConeSlack;
    if (!(spread < kMaxConeChord)) return whole_sphere();
    return PenetrationCache::Bound{c, spread, 0.0};
  };
  double lower = std::max(mc >= 0.0 ? mc + q.inradius_b : -kInfinity, mr >= 0.0 ? mr : -kInfinity);
  if (all && slot_begin < slot_end && !above_bound(q, lower)) {
    // The same with B's point at the hint (near_hint).
    const Vec3 wh = av - q.point_b(near);
    double mh = kInfinity;
    for (std::size_t at = slot_begin; at < slot_end; ++at) {
      const auto i = static_cast<std::size_t>(faces_a[at]);
      mh = std::min(mh, face_lower(sa.normals[i], sa.error[i], wh, q.reach));
    }
    if (mh >= 0.0) lower = std::max(lower, mh);
  }
  return all && slot_begin < slot_end &&
         pruned_by(q, lower, PenetrationCache::Group::vertex_a, v, -1, cone);
}

// Whether A's edge v -> w (faces l on its left, r on its right) is pruned
// from the faces' stored normals, without the arc: every n on the arc from
// nL to nR is c1 nL + c2 nR with c1, c2 >= 0 and c1 + c2 >= 1, so n.w >=
// min(nL.w, nR.w) when that is >= 0 (arc_minimum).
bool edge_pruned_by_faces(Query& q, int v, int w_end, int l, int r) {
  const PenetrationCache::HullNormals& sa = *q.shapes_a;
  const auto il = static_cast<std::size_t>(l), ir = static_cast<std::size_t>(r);
  const auto least = [&](const Vec3& w) {
    return std::min(face_lower(sa.normals[il], sa.error[il], w, q.reach),
                    face_lower(sa.normals[ir], sa.error[ir], w, q.reach));
  };
  const Vec3 av = q.point_a(v);
  const double m = least(av - q.centroid_b), m2 = least(av - q.reference_b);
  const double lower =
      std::max(m >= 0.0 ? m + q.inradius_b : -kInfinity, m2 >= 0.0 ? m2 : -kInfinity);
  return pruned_by(q, lower, PenetrationCache::Group::edge_a, v, w_end, [&] {
    return cone_of_arc(sa.normals[il], sa.error[il], sa.normals[ir], sa.error[ir]);
  });
}

// Whether A's edge e, with its nx arcs xs (faces l and r, -1 for none), is
// pruned by the bounds of its arcs against B's centroid, reference point
// and the point at `near` (near_hint).
bool edge_pruned_by_arcs(Query& q, const std::array<int, 2>& e, int l, int r,
                         const std::array<Arc, 4>& xs, int nx, int near) {
  const PenetrationCache::HullNormals& sa = *q.shapes_a;
  const Vec3 w = q.point_a(e[0]) - q.centroid_b;
  const Vec3 w2 = q.point_a(e[0]) - q.reference_b;
  // The arcs' ends: the faces' normals as arcs_of_a read them (error 0
  // once face_plane's), and for a polygon the in-plane normal from them,
  // normalized (twice the error at most).
  const double error = l >= 0 && r >= 0
                           ? 2.0 * std::max(sa.error[static_cast<std::size_t>(l)],
                                            sa.error[static_cast<std::size_t>(r)])
                           : 0.0;
  double lower = kInfinity, lower2 = kInfinity;
  for (int i = 0; i < nx; ++i) {
    const Arc& x = xs[static_cast<std::size_t>(i)];
    lower = std::min(lower, arc_minimum(x, w, error, q.reach));
    lower2 = std::min(lower2, arc_minimum(x, w2, error, q.reach));
  }
  double arc_lower = std::max(lower + q.inradius_b, lower2);
  if (!above_bound(q, arc_lower)) {
    const Vec3 wh = q.point_a(e[0]) - q.point_b(near);
    double lower3 = kInfinity;
    for (int i = 0; i < nx; ++i)
      lower3 = std::min(lower3, arc_minimum(xs[static_cast<std::size_t>(i)], wh, error, q.reach));
    arc_lower = std::max(arc_lower, lower3);
  }
  return pruned_by(q, arc_lower, PenetrationCache::Group::edge_a, e[0], e[1], [&] {
    // A solid's one arc; a polygon's or a segment's half or whole circle:
    // anywhere.
    return nx == 1 ? cone_of_arc(xs[0].p, 0.0, xs[0].q, 0.0) : whole_sphere();
  });
}

// The chain of B cells that arc x of A's edge e crosses, from B's support
// along -x.p (from `start`), breadth first over B's adjacency; each
// crossing edge of B becomes a candidate with e once. `chain` and
// `visited` are scratch (visited is all 0 on entry and on return).
void walk_arc(Query& q, const Arc& x, const std::array<int, 2>& e, const std::array<Arc, 4>& xs,
              int nx, int start, ArcsOfB& arcs_b, std::pmr::vector<std::int32_t>& chain,
              std::pmr::vector<char>& visited, Candidates& out) {
  const auto offsets = q.b.adjacency_offsets();
  std::array<Arc, 4> ys;
  chain.clear();
  chain.push_back(start);
  visited[static_cast<std::size_t>(start)] = 1;
  for (std::size_t head = 0; head < chain.size(); ++head) {
    const int j = chain[head];
    const auto slot0 = static_cast<std::size_t>(offsets[static_cast<std::size_t>(j)]);
    const auto nbrs = q.b.neighbors(j);
    for (std::size_t slot = slot0; slot < slot0 + nbrs.size(); ++slot) {
      const std::int32_t k = nbrs[slot - slot0];
      const int ny = arcs_b.arcs(j, k, slot, ys);
      bool crosses = false;
      for (int m = 0; m < ny && !crosses; ++m)
        crosses = arcs_may_cross(x, ys[static_cast<std::size_t>(m)]);
      if (!crosses) continue;
      // Each crossing edge once: from its first-visited end.
      if (!visited[static_cast<std::size_t>(k)]) {
        visited[static_cast<std::size_t>(k)] = 1;
        chain.push_back(k);
        add_edge_candidate(q, e[0], e[1], xs, nx, std::min(j, static_cast<int>(k)),
                           std::max(j, static_cast<int>(k)), ys, ny, out);
      } else if (std::find(chain.begin(), chain.begin() + static_cast<std::ptrdiff_t>(head), k) ==
                 chain.begin() + static_cast<std::ptrdiff_t>(head)) {
        // k was reached from another cell of this chain, not expanded yet:
        // the edge j-k is another crossing of the arc.
        add_edge_candidate(q, e[0], e[1], xs, nx, std::min(j, static_cast<int>(k)),
                           std::max(j, static_cast<int>(k)), ys, ny, out);
      }
    }
  }
  for (const std::int32_t j : chain) visited[static_cast<std::size_t>(j)] = 0;
}

// The overlay walk: for each arc of A, the chain of B cells it crosses.
void add_edge_candidates_walk(Query& q, Candidates& out) {
  // Visited B vertices of the current arc (the queue too).
  std::pmr::vector<std::int32_t> chain(q.memory);
  std::pmr::vector<char> visited(static_cast<std::size_t>(q.b.vertex_count()), 0, q.memory);
  int hint = 0;
  // A vertex of B near B's support along -n for the normals n near v's
  // cell of A's Gauss map: the support found for a face through v, else
  // the last arc's start. The lower bounds read it as a point of B when
  // the centroid's and the reference's do not prune (a third bound, as
  // for the faces in add_face_candidates).
  const auto near_hint = [&](int v) {
    const std::int32_t near = q.near_b == nullptr ? -1 : q.near_b[v];
    return near >= 0 ? static_cast<int>(near) : hint;
  };
  std::array<Arc, 4> xs;
  ArcsOfB arcs_b(q);
  const bool solid_a = q.a.dimension() == 3;
  const auto offsets_a = q.a.adjacency_offsets();
  const auto adjacency_a = q.a.adjacency();
  const auto faces_a = q.a.adjacency_faces();
  // Every edge of A once, as ConvexPolytope::edges() lists them (v < w, in
  // adjacency order), with the face to its left from the slot.
  // In an expansion (Query::only) an item is all the edges at a vertex
  // (only_w = -1) or one edge.
  const int items =
      q.only != nullptr ? static_cast<int>(q.only->edges_a.size()) : q.a.vertex_count();
  for (int item = 0; item < items; ++item) {
    const int v = q.only != nullptr ? q.only->edges_a[static_cast<std::size_t>(item)][0] : item;
    const int only_w = q.only != nullptr ? q.only->edges_a[static_cast<std::size_t>(item)][1] : -1;
    const auto slot_begin = static_cast<std::size_t>(offsets_a[static_cast<std::size_t>(v)]);
    const auto slot_end = static_cast<std::size_t>(offsets_a[static_cast<std::size_t>(v) + 1]);
    if (q.prune && solid_a && only_w < 0 &&
        vertex_edges_pruned(q, v, slot_begin, slot_end, near_hint(v)))
      continue;
    for (std::size_t at = slot_begin; at < slot_end; ++at) {
      const int w_end = adjacency_a[at];
      if (!(v < w_end) || (only_w >= 0 && w_end != only_w)) continue;
      const std::array<int, 2> e = {v, w_end};
      const int l = q.a.dimension() >= 2 ? faces_a[at] : -1;
      const int r = q.a.dimension() >= 2 ? left_face(q.a, w_end, v) : -1;
      if (q.prune && solid_a && l >= 0 && r >= 0 && edge_pruned_by_faces(q, v, w_end, l, r))
        continue;
      const int nx = arcs_of_a(q, v, w_end, l, r, xs);
      if (q.prune && nx > 0 && edge_pruned_by_arcs(q, e, l, r, xs, nx, near_hint(v))) continue;
      for (int i = 0; i < nx; ++i) {
        const Arc& x = xs[static_cast<std::size_t>(i)];
        // The B cell of direction p: B's support along -p. From the
        // support found for a face through v, when one was evaluated (for
        // a solid A, p is the normal of such a face).
        const std::int32_t near = q.near_b == nullptr ? -1 : q.near_b[v];
        const int start = support_hill_climb_through_plateaus(q.b, q.rotation_t * (-x.p),
                                                              near >= 0 ? near : hint);
        hint = start;
        walk_arc(q, x, e, xs, nx, start, arcs_b, chain, visited, out);
      }
    }
  }
}

}  // namespace
}  // namespace proxima
