// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): penetration depth of two overlapping convex polytopes (the
// negative side of the signed distance, DESIGN.md "Signed distance").
//
// Definitions. Work in A's frame; B's vertices are b_in_a applied to B's.
// M = A - B = {x - y : x in A, y in B} is a convex polytope, and the hulls
// overlap exactly when the origin is in M. Translating B by t turns M into
// M - t, so the shortest translation after which a plane separates A and B
// (they then touch) has the length
//   depth = distance from the origin to the boundary of M
//         = min over the facets of M of the facet plane's offset,
// the offset of a facet with outward unit normal n being
//   h_M(n) = h_A(n) + h_B(-n),  h_X(n) = max over x in X of n.x.
// Every facet of M is one of three Minkowski faces:
//   face_vertex: a face of A (n its normal) plus a vertex of B,
//   vertex_face: a vertex of A plus a face of B (n minus its normal),
//   edge_edge:   an edge of A and an edge of B whose Gauss-map arcs cross
//                (n along the cross product of the edges).
// For any unit n, h_M(n) >= depth, so every candidate's value, evaluated
// with true supports, is an upper bound, and the minimum over a candidate
// set that contains every facet of M is the depth.
//
// The result:
//   normal  unit, from A towards B: translating B by depth * normal makes
//           the hulls touch (a plane with this normal then separates them);
//   point_a a deepest point of A, on A's supporting plane along normal;
//   point_b a deepest point of B, on B's supporting plane along -normal;
//           point_b + depth * normal == point_a (up to rounding): B moved by
//           depth * normal carries point_b onto point_a;
//   feature_a, feature_b the two faces of the Minkowski face (a face and a
//           vertex, or two edges); for a face, the vertex ids of the fan
//           triangle of the face that holds the witness point;
//   lower_bound <= depth* <= upper_bound, each with its rounding slack
//           64 u R (a certified lower bound less the band; the overlap
//           h_A(n) + h_B(-n) along the reported normal plus the band;
//           a depth refined exactly near the band has bounds within 8 u).
//
// Degenerate bodies. Lower-dimensional hulls are valid. When M is flat (two
// coplanar polygons, a segment crossing a polygon in its plane, crossing
// segments, points on a body's boundary plane ...) it has no interior and
// the depth is 0: the bodies touch, and any translation out of the plane
// separates them (status touching, normal the plane's normal). A polygon
// cutting through a solid has a positive depth. Coplanar face-face contact:
// the witnesses are not unique; any pair of the overlap is returned.
//
// Input contract: meant for overlapping pairs (Status::intersecting from
// distance()). A separated pair gets PenetrationStatus::separated with depth
// 0 and a touching pair (depth within the contact band 64 u R) touching with
// its depth (>= 0); ask distance() for their distance. Never NaN, never a
// hang: every loop is bounded by the hull sizes.
//
// Robustness. Which candidates enter the minimum is decided by the Gauss-map
// arc test evaluated in double with a tolerance that errs towards inclusion:
// a pair included by mistake only adds an honest upper bound (its value is
// evaluated with hill-climbing supports, never assumed from its edges), so
// the minimum is never below the depth by more than rounding, and a facet of
// M is left out only if a face normal of a hull is wrong by more than the
// tolerance (kArcTolerance in penetration.cpp). All work is done in units of
// a power of two near R (src/core/power_of_two.h): the same answer from 1e-300
// to 1e300.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "proxima/core/types.h"
#include "proxima/detail/penetration/expansion_surface.h"
#include "proxima/shape/polytope.h"

namespace proxima {

enum class PenetrationStatus : std::uint8_t {
  intersecting,  // depth > 64 u R: the interiors overlap
  touching,     // depth <= 64 u R (flat M included): in contact at machine precision
  separated,    // the hulls do not meet (depth reported as 0): use distance()
};

inline const char* to_string(PenetrationStatus s) {
  switch (s) {
    case PenetrationStatus::intersecting:
      return "intersecting";
    case PenetrationStatus::touching:
      return "touching";
    case PenetrationStatus::separated:
      return "separated";
  }
  return "unknown";
}

// The kind of Minkowski face of A - B that realizes the depth.
enum class MinkowskiFace : std::uint8_t { face_vertex, vertex_face, edge_edge };

inline const char* to_string(MinkowskiFace k) {
  switch (k) {
    case MinkowskiFace::face_vertex:
      return "face_vertex";
    case MinkowskiFace::vertex_face:
      return "vertex_face";
    case MinkowskiFace::edge_edge:
      return "edge_edge";
  }
  return "unknown";
}

// One Minkowski face: the kind and its hull ids. face_vertex: a = face of A,
// b0 = vertex of B; vertex_face: a0 = vertex of A, b = face of B;
// edge_edge: (a0, a1) an edge of A, (b0, b1) an edge of B. Unused ids -1;
// all -1 when the reported direction is not a face of A - B (the fast
// query's first trial direction, which can be the answer only for
// separated bodies or in a tie).
struct MinkowskiFaceId {
  MinkowskiFace kind = MinkowskiFace::face_vertex;
  std::int32_t a0 = -1, a1 = -1;
  std::int32_t b0 = -1, b1 = -1;
};

struct PenetrationResult {
  PenetrationStatus status = PenetrationStatus::separated;
  double depth = 0.0;           // >= 0; the exact depth within the accuracy standard
  double lower_bound = 0.0;     // lower_bound <= exact depth (up to 64 u R)
  double upper_bound = 0.0;     // exact depth <= upper_bound: the overlap along normal + band
  Vec3 normal = Vec3::UnitX();  // unit, from A towards B, A's frame
  Vec3 point_a = Vec3::Zero();  // deepest point of A, A's frame
  Vec3 point_b = Vec3::Zero();  // deepest point of B, A's frame
  MinkowskiFaceId face;         // the Minkowski face realizing the depth
  Feature feature_a;
  Feature feature_b;
  // Work of this query in Minkowski faces: evaluated (F_A + F_B + the
  // crossing edge pairs) for an enumeration, the candidates of the facet
  // along the expanding polytope's normal for a cold query it answered;
  // faces and tree nodes visited, and faces an expansion evaluated, for a
  // tracked one.
  int candidates = 0;
  // True when the cache certified the answer (no enumeration of M).
  bool tracked = false;
};

// Coherence between queries of one pair, owned by the caller;
// default-constructed means cold. It holds every Minkowski face of A - B
// found by the last enumeration (O(F_A + F_B + crossing edge pairs)
// entries: not small for large hulls), with their offsets at the
// enumeration's translation of B. A query reuses it when it comes from the
// same two polytope objects (addresses, sizes and a few coordinates are
// checked: a cache of another pair is ignored, at worst making a query
// cold) and B's rotation is unchanged bit for bit: then the faces of A - B
// are the cached ones translated, each offset moved by -n.(t -
// t_enumeration) (one rounding), and the depth is the least of them. The
// faces are kept in a tree over their normals: each node holds a ball
// around its faces' normals (centre c, radius rho) and a lower bound o on
// their values at B's translation t_node (its anchor), so that every face
// under it has a value now of at least o - min(|delta|, c.delta + rho
// |delta|), delta = t - t_node. A query evaluates the last answer's face
// first, then descends (nearer child first) into the nodes whose bound is
// below the best value found: the faces whose normals point away from
// delta, or whose values are far above the depth, are never touched. Each
// node it enters is anchored again at t (a leaf with its faces' least
// value, an inner node with its children's least bound), so the bounds
// near the answer stay tight wherever B goes, at no cost beyond the
// search. The faces the enumeration pruned are not lost: each pruned group
// (a face of A or of B, an edge of A, or all the edges at a vertex of A)
// is kept as a Bound, a lower bound on its faces' values at the
// enumeration with a ball around their normals, so that it moves with B
// like a face (its value now is at least lower - (c.delta + spread
// |delta|)) and sits in a second tree searched the same way: the answer is
// certified when no Bound is below it. A B that moved towards pruned
// groups expands them: each is enumerated alone at the new pose (pruned
// against the best value, its own pruned parts kept as new groups), its
// faces join the cache, and the search certifies again. A rotated B
// first tries the expanding polytope's surface kept from the last turned
// query (`surface`, src/penetration/tracked_expansion.h: its keys bounded
// by how far B moved, a few triangles evaluated again), then a fresh
// expansion (whose surface it keeps), and enumerates only when neither
// certifies; the first translation after a cold enumeration enumerates
// again (it records no groups: a caller querying cold every time would
// pay for them).
struct PenetrationCache {
  struct Facet {
    MinkowskiFaceId id;
    Vec3 normal = Vec3::UnitX();     // outward unit normal of the face of A - B
    double enumerated_offset = 0.0;  // h_A(n) + h_B(-n) at the enumeration, A's units
    std::int32_t support_a = -1;     // supports along n and -n (they do not
    std::int32_t support_b = -1;     // change under a translation)
  };
  // A node of the tree over facets[begin, end): the ball |n - center| <=
  // radius holds their normals (radius rounded up), least_offset a lower
  // bound on their values at B's translation `anchor` (see above);
  // children (two, at `left` and `left` + 1) or none yet
  // (left = -1: a leaf of at most kLeaf faces, or a node not split yet:
  // a search splits the nodes it descends into, so the tree is only as
  // deep as the searches went). nodes[0] is the root.
  struct Node {
    Vec3 center = Vec3::Zero();
    double radius = 0.0;
    double least_offset = 0.0;
    Vec3 anchor = Vec3::Zero();
    std::int32_t begin = 0, end = 0;
    std::int32_t left = -1;
  };
  // A group of faces of A - B the enumeration pruned: their outward unit
  // normals lie within `spread` of `center` (spread 2: anywhere), and
  // `lower` bounds their values h_A(n) + h_B(-n) from below at B's
  // translation `anchor` (A's units): the enumeration's, or an
  // expansion's. `kind` and `i`, `j` name the element of the enumeration
  // it stands for, so that it can be expanded alone: a face i of A, a face
  // i of B, the edges (i, w) at a vertex i of A with i < w, or the edge
  // (i, j) of A (i < j).
  enum class Group : std::uint8_t { face_a, face_b, vertex_a, edge_a };
  struct Bound {
    Vec3 center = Vec3::Zero();
    double spread = 2.0;
    double lower = 0.0;
    Vec3 anchor = Vec3::Zero();
    Group kind = Group::face_a;
    std::int32_t i = -1, j = -1;
  };
  // Faces at most this many to a leaf.
  static constexpr int kLeaf = 8;

  // Identity of the pair the cache was filled for.
  const ConvexPolytope* a = nullptr;
  const ConvexPolytope* b = nullptr;
  std::array<double, 4> fingerprint = {0, 0, 0, 0};
  // B's rotation, and its translation at the enumeration.
  Mat3 rotation = Mat3::Zero();
  Vec3 enumerated_translation = Vec3::Zero();
  // All faces of A - B found, in tree order, and a forest over them: the
  // trees' roots in nodes, each over a run of facets (the enumeration's,
  // then each expansion's, merged with the run before it when that run is
  // at most twice as long: a few trees, each entry rebuilt into a new tree
  // O(log) times); empty until the first search builds one over all.
  std::vector<Facet> facets;
  std::vector<Node> nodes;
  std::vector<std::int32_t> roots;
  // The facet of the last answer (a copy: the tree reorders facets while
  // it is built, lazily, by the searches that descend into it).
  Facet last;
  // The faces the enumeration and the expansions pruned (not in facets):
  // their groups and a forest over them like the facets' (built by the
  // first tracked query), when recorded (`bounded`: only by an
  // enumeration after a translation outgrew the cached faces, and by the
  // expansions after it; a cold one or one for a B that turned does not
  // record them: a caller querying cold, or a rotating B, enumerates every
  // query), an expanded group staying with lower +infinity until the
  // groups are compacted (`expanded` counts them); and in any case the
  // enumeration's least lower bound at its translation (+infinity when
  // none), the certificate when they are not recorded.
  std::vector<Bound> bounds;
  std::vector<Node> bound_nodes;
  std::vector<std::int32_t> bound_roots;
  std::int32_t expanded = 0;
  bool bounded = false;
  double pruned = 0.0;
  // Faces within this of the best value are kept by an enumeration or an
  // expansion even where a lower bound would prune them, and the groups
  // within it of the best value are expanded: a few steps of B (so that
  // the next queries find them cached); halves when B turns.
  double prune_margin = 0.0;
  // B's translation at the last query with this cache (its step sets the
  // margin).
  Vec3 previous_translation = Vec3::Zero();
  // Work done with this cache: full enumerations of A - B, and
  // expansions of pruned groups (a translation towards them).
  std::int64_t enumerations = 0;
  std::int64_t expansions = 0;
  // Turned-B answers whose facet was the last answer's, evaluated alone
  // without the supports' rings (solve_expanding's cached_facet).
  std::int64_t cached_facets = 0;
  // What the query needs of each hull whatever the pose, in its own frame:
  // face normals and the radius of a ball about the centroid inside it.
  // A normal is first a fast one (a triangle's rounded cross product,
  // within error[f] of the exact unit normal), good for pruning and, when
  // error[f] is within 512 u, for the Gauss-map arcs; a face the query
  // evaluates, or whose arc it tests with a larger error, gets
  // ConvexPolytope::face_plane's (exact[f] set, error 0), once.
  struct HullNormals {
    std::vector<Vec3> normals;
    std::vector<double> error;
    std::vector<char> exact;
    double inradius = 0.0;
  };
  struct Shapes {
    HullNormals a, b;
  } shapes;

  // The supporting features of the last answer's direction (its face's id
  // and normal): the simplices of each hull searched for the witness
  // points (support_region in penetration.cpp), which a translation of B
  // does not change; empty when none.
  struct Witnesses {
    MinkowskiFaceId id;
    Vec3 normal = Vec3::Zero();
    std::vector<Feature> a, b;
  } witnesses;
  // The status of the last answer given with this cache.
  PenetrationStatus last_status = PenetrationStatus::separated;
  // The expanding polytope's surface of the last query whose B had turned
  // (src/penetration/tracked_expansion.h): the next turned query starts
  // from it; empty when none (a cold cache, or an expansion that did not
  // certify).
  detail::ExpansionSurface surface;

  bool is_cold() const { return a == nullptr; }
  void reset() { *this = PenetrationCache{}; }
};

// Penetration depth of hulls a and b, B placed by b_in_a (checked by the
// caller against the pose contract; rigid). A cold cache (solids) first
// tries a polytope expanding inside A - B on support points, whose lower
// bound is certified (src/penetration/expanding_polytope.h), and takes the
// facet of A - B along its normal when its value is within half the
// accuracy standard of that bound; the cache then holds that facet and the
// bound. Otherwise (and for a warm cache) the enumeration: it walks the overlay of the two Gauss maps (for each edge of A,
// the cells of B its arc crosses, found by hill climbing and stepping
// across B's edges), O(F_A + F_B + E_A + E_B + crossings), and skips every
// face of A - B (and every edge of A with all its edge pairs) whose lower
// bound exceeds the best value found so far, so that only the faces near
// the answer are evaluated; a tracked query (same pair, same rotation, see
// PenetrationCache) searches the cached faces' tree. A rotated B answers
// from the kept expansion when it certifies, else from a fresh one, else
// enumerates again (with the cached face normals and the last answer as
// the first bound). Not thread-safe on one cache; the polytopes may be
// shared.
//
// `seed`: vertex pairs (a_k of A, b_k of B) of four points a_k - b_k of
// A - B whose tetrahedron may hold the origin, the contact classification's
// (DistanceCache::contact_a, contact_b); a cold expansion starts from it
// when it does (certified as the expansion certifies a triangle), from
// supports along the six axes otherwise. Any ids are safe: a seed out of
// range, flat or beside the origin is not used.
struct DepthSeed {
  std::array<std::int32_t, 4> a = {-1, -1, -1, -1};
  std::array<std::int32_t, 4> b = {-1, -1, -1, -1};
};
PenetrationResult penetration_depth(const ConvexPolytope& a, const ConvexPolytope& b,
                                    const Pose& b_in_a, PenetrationCache& cache,
                                    const DepthSeed& seed = {});

// The tracked query alone: when `cache` holds this pair's faces of A - B
// at B's rotation and certifies their least value without enumerating
// again (the translation-only path of penetration_depth, expansions of
// pruned groups included), or B turned and the kept expansion's surface
// certifies the depth (dropped when it does not), fills `out` with the
// answer penetration_depth would give and returns true; else returns
// false, `out` and the answer's
// cache state unchanged (the tree's bounds may have been tightened, faces
// added), and the caller decides whether the depth is wanted (distance() asks it first for a pair
// that was penetrating, and skips its own algorithm when the depth certifies the overlap).
bool penetration_depth_tracked(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                               PenetrationCache& cache, PenetrationResult& out);

// The slow, obvious twin: every face of A, every face of B, and every pair
// (edge of A, edge of B) through the Gauss-map arc test,
// O(F_A + F_B + E_A * E_B). Same result conventions; no cache.
PenetrationResult penetration_depth_brute_force(const ConvexPolytope& a, const ConvexPolytope& b,
                                                const Pose& b_in_a);

}  // namespace proxima
