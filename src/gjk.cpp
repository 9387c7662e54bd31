// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The GJK baselines: classic GJK (Gilbert, Johnson & Keerthi 1988) and
// Cameron's Enhanced GJK (1997), both in A's frame.
//
// GJK in one paragraph. The distance between hulls A and B is the distance
// from the origin to their Minkowski difference C = A - B, whose vertices are
// differences a_i - b_j of hull vertices. GJK keeps a simplex Y of at most
// four points of C and the closest point v of conv(Y) to the origin. The
// support point w = argmin over C of v.x = s_A(-v) - s_B(v) then gives:
//   - a certified lower bound: every x in C has v.x >= v.w, hence
//     |x| >= v.w / |v| (the support plane through w separates the origin
//     from C by that much);
//   - an upper bound |v| (v is a point of C).
// If w does not close the gap, Y + w is solved for its closest point, which
// keeps the smallest sub-simplex realizing it; |v| strictly decreases, and as
// C has finitely many vertices the loop ends. Stopping rules (van den
// Bergen 1999): the gap |v| - v.w/|v| is within the relative tolerance (the
// same Re d test as the hybrid's eq. 19, so both stop at the same certified
// gap) plus rounding, w's vertex pair is already in Y, |v| did not decrease
// (rounding has taken over), |v| is in the contact band, or the cap.
//
// Each simplex point carries its vertex pair (i in A, j in B), so the closest
// points are sum(lambda_k a_ik) and sum(lambda_k b_jk) with the barycentric
// weights lambda of v, and the ids with non-zero weight are the witness
// features.
//
// Enhanced GJK differs in two places only: the support points come from hill
// climbing over the vertex adjacency, starting from the previous answers
// (near constant time under coherence), and the first simplex is the last
// query's final simplex, re-evaluated at the current pose. Any four points of
// C are a valid start for GJK (only the first closest point changes), so a
// stale or foreign cache can only cost iterations.
//
// Units. All simplex arithmetic runs on coordinates divided by a power of two
// near the bodies' magnitude: exact, and it keeps the cubic terms (face
// normals dotted with points) away from overflow and underflow whatever the
// scale.
#include "proxima/gjk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "power_of_two.h"
#include "proxima/support.h"

namespace proxima {
namespace {

// Rounding slack of the termination test, in units of u * max|w| (the
// largest simplex point seen, in scaled units): v.w and |v| are sums of
// products of coordinates of that size and v itself is rebuilt from the
// simplex points, so the computed gap |v| - v.w/|v| carries an error of a few
// u max|w|. Below this slack more iterations cannot improve v. Well inside
// the 64 u R contact band of the accuracy standard (|w| <= 2 sqrt(3) R).
constexpr double kGapUlps = 16.0;

// Budget of the contact classification (below): Minkowski-difference points
// of its inner polytope. A contact not decided within it is reported as
// touching: its distance is certified within the band, and no depth beyond
// the band was found. At 32 points the faces around the origin have been
// refined 28 times; every contact in the tests decides within a handful
// (IterationCapHoldsInContacts shows six supports for concentric cubes).
constexpr int kMaxContactVertices = 32;
// A closed triangulated surface on V vertices has at most 2V - 4 faces.
constexpr int kMaxContactFaces = 2 * kMaxContactVertices - 4;
// Each face removed when a point is added contributes three edges.
constexpr int kMaxContactEdges = 3 * kMaxContactFaces;

constexpr std::size_t idx(int i) { return static_cast<std::size_t>(i); }

// A point of the Minkowski difference with the hull vertices it comes from.
struct SupportPoint {
  Vec3 w;  // (a_ia - b_ib) / unit, A's frame
  std::int32_t ia = -1;
  std::int32_t ib = -1;
};

struct Simplex {
  std::array<SupportPoint, 4> p;
  std::array<double, 4> lambda{};
  int size = 0;
  Vec3 v = Vec3::Zero();         // closest point of conv(p) to the origin
  double vv = 0.0;               // |v|^2
  bool encloses_origin = false;  // a tetrahedron with the origin strictly inside

  bool contains(std::int32_t ia, std::int32_t ib) const {
    for (int k = 0; k < size; ++k) {
      if (p[idx(k)].ia == ia && p[idx(k)].ib == ib) return true;
    }
    return false;
  }
};

// The sub-simplex that realizes the closest point: which points of the
// simplex, with which weights.
struct Reduction {
  std::array<int, 4> index{};
  std::array<double, 4> lambda{};
  int count = 0;
  Vec3 v = Vec3::Zero();
  double vv = std::numeric_limits<double>::infinity();
  bool encloses_origin = false;
};

using Points = std::array<SupportPoint, 4>;

bool same_sign(double x, double y) { return (x > 0.0 && y > 0.0) || (x < 0.0 && y < 0.0); }

Reduction single(const Points& p, int i) {
  Reduction r;
  r.count = 1;
  r.index[0] = i;
  r.lambda[0] = 1.0;
  r.v = p[idx(i)].w;
  r.vv = r.v.squaredNorm();
  return r;
}

// ---------------------------------------------------------------------------
// Accurate cross products for thin faces. Each component of e1 x e2 is a
// difference of products, a*b - c*d; for nearly parallel edges the products
// agree in their leading digits, which cancel, and the plain result's
// relative error grows like u / sin(angle). For a needle- or sliver-shaped
// face that tilts its normal far enough to put the origin on the wrong side
// of a plane it is 1e-13 from. Splitting each product into its rounded value
// and its exact error (Dekker's two-product) gives a*b - c*d to a few u of
// itself. It costs several plain products, so it is used only for faces
// thinner than kThinFaceSine2.
// ---------------------------------------------------------------------------

// sin^2 of the angle between a face's edges below which its normal is
// recomputed accurately: at sin >= 1/8 the plain cross product's direction
// error is at most ~16 u, which moves a height over the face by ~16 u R,
// inside the 64 u R band; thinner faces would exceed it.
constexpr double kThinFaceSine2 = 1.0 / 64.0;

// a * b == p + e exactly (no overflow at the unit's scale). With a hardware
// fused multiply-add the error is one instruction; otherwise Veltkamp's
// split into 26-bit halves makes every partial product exact.
void two_product(double a, double b, double& p, double& e) {
  p = a * b;
#ifdef FP_FAST_FMA
  e = std::fma(a, b, -p);
#else
  constexpr double kSplitter = 134217729.0;  // 2^27 + 1
  const double ca = kSplitter * a;
  const double a_hi = ca - (ca - a);
  const double a_lo = a - a_hi;
  const double cb = kSplitter * b;
  const double b_hi = cb - (cb - b);
  const double b_lo = b - b_hi;
  e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo;
#endif
}

// a*b - c*d to a few u of the result: p - q is exact when the products are
// close (Sterbenz) and otherwise rounds once; the products' errors are added
// back.
double difference_of_products(double a, double b, double c, double d) {
  double p = 0.0;
  double e = 0.0;
  double q = 0.0;
  double f = 0.0;
  two_product(a, b, p, e);
  two_product(c, d, q, f);
  return (p - q) + (e - f);
}

struct FaceNormal {
  Vec3 n;     // e1 x e2, accurate in direction to a few u
  bool thin;  // computed by the accurate path
};

FaceNormal face_normal(const Vec3& e1, const Vec3& e2) {
  const Vec3 n = e1.cross(e2);
  if (!(n.squaredNorm() < kThinFaceSine2 * e1.squaredNorm() * e2.squaredNorm())) return {n, false};
  return {Vec3(difference_of_products(e1.y(), e2.z(), e1.z(), e2.y()),
               difference_of_products(e1.z(), e2.x(), e1.x(), e2.z()),
               difference_of_products(e1.x(), e2.y(), e1.y(), e2.x())),
          true};
}

// ---------------------------------------------------------------------------
// The distance subalgorithm, after the signed-volumes method of Montanari,
// Petrinic & Barbieri (2017), written from the idea. The closest point of a
// simplex to the origin is found by asking, in each dimension, where the
// origin's projection onto the simplex's affine hull falls; its barycentric
// coordinates are ratios of signed measures (lengths, areas, heights) and
// only their signs decide the region. Where the projection falls outside,
// the closest point lies on a facet whose opposite vertex has a non-positive
// coordinate, and only those facets are searched (all of them if the
// simplex is degenerate). Nothing assumes that the newest point belongs to
// the answer, so the same code solves a warm-started simplex of arbitrary
// points. Where the paper's formulas lose the direction of v for bodies
// much larger than their distance (needles, slivers), the triangle and
// tetrahedron cases below use face normals instead; each says why.
// ---------------------------------------------------------------------------

// Segment [wi, wj]. The line wi + s t, t = wj - wi, is closest to the origin
// at s* = -wi.t / t.t, so lambda_j = -wi.t / t.t and lambda_i = wj.t / t.t
// (they sum to one because wj.t - wi.t = t.t). The numerators' signs give the
// region without a division: -wi.t <= 0 means the origin is behind wi, wj.t
// <= 0 that it is beyond wj; otherwise both are positive and their sum, t.t,
// is a safe denominator.
Reduction solve_segment(const Points& p, int i, int j) {
  const Vec3& wi = p[idx(i)].w;
  const Vec3& wj = p[idx(j)].w;
  const Vec3 t = wj - wi;
  const double num_j = -wi.dot(t);
  if (num_j <= 0.0) return single(p, i);
  const double num_i = wj.dot(t);
  if (num_i <= 0.0) return single(p, j);
  const double den = num_i + num_j;
  Reduction r;
  r.count = 2;
  r.index[0] = i;
  r.index[1] = j;
  r.lambda[0] = num_i / den;
  r.lambda[1] = num_j / den;
  r.v = r.lambda[0] * wi + r.lambda[1] * wj;
  // v is orthogonal to t in exact arithmetic; the sum's rounding (u |w|) is
  // not, and along a needle's axis it tilts the next search direction by
  // u |w| / |v|: the support values of the needle's ends then differ by
  // that times its length, more than its thickness, and the support point is
  // an end of the segment itself (DistanceRegression.PointOnTheSurfaceOfANeedle
  // stopped 1.7e-9 inside a needle 1e-9 thick that way). The component along
  // t is removed; what is left is across the needle, where it is harmless.
  const double tt = t.squaredNorm();
  if (tt > 0.0) r.v -= (r.v.dot(t) / tt) * t;
  r.vv = r.v.squaredNorm();
  return r;
}

// Triangle (wi, wj, wk), normal n = (wj - wi) x (wk - wi). The origin
// projects onto the plane at p0 = n (wi.n / n.n). Its barycentric
// coordinates are ratios of signed areas; they are computed in the
// coordinate plane where the triangle's shadow is largest (dropping the axis
// of n's largest component, whose value is that shadow's doubled area), so
// that the areas are as well conditioned as the triangle allows:
//   C_i = area(p0, wj, wk), C_j = area(p0, wk, wi), C_k = area(p0, wi, wj),
// all of the sign of n[axis] exactly when p0 is inside. Otherwise the closest
// point is on an edge opposite a vertex whose C has the wrong sign (or is
// zero).
Reduction solve_triangle(const Points& p, int i, int j, int k) {
  const Vec3& wi = p[idx(i)].w;
  const Vec3& wj = p[idx(j)].w;
  const Vec3& wk = p[idx(k)].w;
  const FaceNormal face = face_normal(wj - wi, wk - wi);
  const Vec3& n = face.n;
  const double nn = n.squaredNorm();
  std::array<bool, 3> test_edge = {true, true, true};  // edge opposite i, j, k
  if (nn > 0.0) {
    const Vec3 p0 = n * (wi.dot(n) / nn);
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const int x = (axis + 1) % 3;
    const int y = (axis + 2) % 3;
    // Doubled signed area in the (x, y) plane; (x, y, axis) is a cyclic
    // order, so for the whole triangle it equals n[axis].
    // A thin triangle's areas cancel like its normal: computed accurately,
    // the weights are exact functions of the (rounded) points, and the
    // point they rebuild is off by rounding only, not by u / sin(angle)
    // times the triangle's length.
    const bool thin = face.thin;
    const auto area = [x, y, thin](const Vec3& a, const Vec3& b) {
      return thin ? difference_of_products(a[x], b[y], a[y], b[x]) : a[x] * b[y] - a[y] * b[x];
    };
    const Vec3 di = wi - p0;
    const Vec3 dj = wj - p0;
    const Vec3 dk = wk - p0;
    const std::array<double, 3> c = {area(dj, dk), area(dk, di), area(di, dj)};
    const double mu = n[axis];
    if (same_sign(mu, c[0]) && same_sign(mu, c[1]) && same_sign(mu, c[2])) {
      // All of one sign, so their sum is at least as large as each: a safe
      // denominator that makes the weights sum to one.
      const double den = c[0] + c[1] + c[2];
      Reduction r;
      r.count = 3;
      r.index = {i, j, k, 0};
      r.lambda = {c[0] / den, c[1] / den, c[2] / den, 0.0};
      // v is p0, not sum(lambda w): when the origin is much closer to the
      // plane than the vertices are to the origin, the sum's rounding
      // (u |w|) is a large error in v's direction, and the next support
      // point would be searched in a wrong direction (a sliver next to the
      // plane is then missed). p0 has n's direction, accurate to a few u
      // whatever the distance and the triangle's shape.
      r.v = p0;
      r.vv = p0.squaredNorm();
      return r;
    }
    for (int m = 0; m < 3; ++m) test_edge[idx(m)] = !same_sign(mu, c[idx(m)]);
  }
  const std::array<int, 3> id = {i, j, k};
  Reduction best;
  for (int m = 0; m < 3; ++m) {
    if (!test_edge[idx(m)]) continue;
    const Reduction r = solve_segment(p, id[idx((m + 1) % 3)], id[idx((m + 2) % 3)]);
    if (r.vv < best.vv) best = r;
  }
  return best;
}

// Tetrahedron (w0, w1, w2, w3). The origin's barycentric coordinate for
// vertex m is the ratio of heights over the opposite face's plane: with
// (a, b, c) that face and n_m = (wb - wa) x (wc - wa),
//   lambda_m = n_m.(0 - wa) / n_m.(w_m - wa).
// (The signed-volumes cofactors det[w_i, w_j, w_k] are the same ratio's
// terms with the origin as apex, but their rounding is u |w|^3 however thin
// the tetrahedron: for a needle- or sliver-shaped one, whose volume is near
// that, their signs are noise. A face normal from edge differences,
// accurate in direction to a few u (face_normal), gives these heights the
// sign the geometry gives them.) The origin is strictly
// inside exactly when every lambda_m is positive; otherwise the closest
// point is on a face opposite a vertex whose lambda is not positive (every
// face of a flat tetrahedron).
constexpr std::array<std::array<int, 3>, 4> kOppositeFace = {
    {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}}};

Reduction solve_tetrahedron(const Points& p) {
  std::array<double, 4> origin_height{};
  std::array<double, 4> vertex_height{};
  bool inside = true;
  for (int m = 0; m < 4; ++m) {
    const auto& f = kOppositeFace[idx(m)];
    const Vec3& wa = p[idx(f[0])].w;
    const Vec3 n = face_normal(p[idx(f[1])].w - wa, p[idx(f[2])].w - wa).n;
    origin_height[idx(m)] = -n.dot(wa);
    vertex_height[idx(m)] = n.dot(p[idx(m)].w - wa);
    inside = inside && same_sign(origin_height[idx(m)], vertex_height[idx(m)]);
  }
  if (inside) {
    Reduction r;
    r.count = 4;
    r.index = {0, 1, 2, 3};
    double sum = 0.0;
    for (int m = 0; m < 4; ++m) {
      // Same signs, and the origin inside is nearer each face than the
      // opposite vertex: the ratio is in (0, 1]; capping it at 1 keeps a
      // rounding-size vertex height from overflowing it.
      const double h_o = std::abs(origin_height[idx(m)]);
      const double h_v = std::abs(vertex_height[idx(m)]);
      r.lambda[idx(m)] = h_o < h_v ? h_o / h_v : 1.0;
      sum += r.lambda[idx(m)];
    }
    for (double& l : r.lambda) l /= sum;  // sum >= each positive term
    r.v = Vec3::Zero();
    r.vv = 0.0;
    r.encloses_origin = true;
    return r;
  }
  Reduction best;
  for (int m = 0; m < 4; ++m) {
    if (same_sign(origin_height[idx(m)], vertex_height[idx(m)])) continue;
    const auto& f = kOppositeFace[idx(m)];
    const Reduction r = solve_triangle(p, f[0], f[1], f[2]);
    if (r.vv < best.vv) best = r;
  }
  return best;
}

// The closest point of a tetrahedron's boundary: for a tetrahedron around
// the origin, the nearest face (the projection onto the nearest face plane of
// an interior point lies in that face).
Reduction nearest_face(const Points& p) {
  Reduction best;
  for (const auto& f : kOppositeFace) {
    const Reduction r = solve_triangle(p, f[0], f[1], f[2]);
    if (r.vv < best.vv) best = r;
  }
  return best;
}

void apply(Simplex& s, const Reduction& r) {
  const Points old = s.p;
  for (int k = 0; k < r.count; ++k) {
    s.p[idx(k)] = old[idx(r.index[idx(k)])];
    s.lambda[idx(k)] = r.lambda[idx(k)];
  }
  s.size = r.count;
  s.v = r.v;
  s.vv = r.vv;
  s.encloses_origin = r.encloses_origin;
}

// Replaces the simplex by the sub-simplex realizing its closest point.
void solve(Simplex& s) {
  switch (s.size) {
    case 1:
      apply(s, single(s.p, 0));
      break;
    case 2:
      apply(s, solve_segment(s.p, 0, 1));
      break;
    case 3:
      apply(s, solve_triangle(s.p, 0, 1, 2));
      break;
    default:
      apply(s, solve_tetrahedron(s.p));
      break;
  }
}

// ---------------------------------------------------------------------------
// The query's geometry: the two bodies, B's pose in A's frame, and the unit.
// ---------------------------------------------------------------------------
struct Frame {
  const ConvexPolytope& a;
  const ConvexPolytope& b;
  const Pose& b_in_a;
  double unit = 1.0;      // a power of two near the bodies' magnitude
  double inv_unit = 1.0;  // exact reciprocal

  Frame(const ConvexPolytope& pa, const ConvexPolytope& pb, const Pose& pose)
      : a(pa), b(pb), b_in_a(pose) {
    // B's coordinates in A's frame are bounded without mapping its vertices.
    const detail::PowerOfTwoUnit u =
        detail::power_of_two_unit(std::max(a.scale(), magnitude_bound(pose, b.scale())));
    unit = u.unit;
    inv_unit = u.inverse;
  }

  Vec3 b_point(std::int32_t ib) const { return b_in_a.apply(b.vertex(ib)); }
  SupportPoint point(std::int32_t ia, std::int32_t ib) const {
    return {(a.vertex(ia) - b_point(ib)) * inv_unit, ia, ib};
  }
  // A direction of A's frame seen in B's frame (a rotation only).
  Vec3 dir_in_b(const Vec3& d) const { return b_in_a.rotation.transpose() * d; }
};

// Support of C = A - B in direction d: argmax d.(a - b) = s_A(d) - s_B(-d).
struct BruteForceSupport {
  const Frame& frame;
  SupportPoint operator()(const Vec3& d) const {
    const int ia = support_brute_force(frame.a.vertices(), d);
    const int ib = support_brute_force(frame.b.vertices(), frame.dir_in_b(-d));
    return frame.point(ia, ib);
  }
};

struct HillClimbSupport {
  const Frame& frame;
  std::int32_t hint_a = 0;
  std::int32_t hint_b = 0;
  SupportPoint operator()(const Vec3& d) {
    hint_a = support_hill_climb(frame.a, d, hint_a);
    hint_b = support_hill_climb(frame.b, frame.dir_in_b(-d), hint_b);
    return frame.point(hint_a, hint_b);
  }
};

// The origin's depth inside the tetrahedron (p0, p1, p2, p3): its smallest
// distance to the four face planes, each oriented outwards by the centroid
// and computed as classify_contact computes a face (below). Negative when the
// origin is outside. Depth above the contact band tol certifies
// intersection: the tetrahedron's points are points of C.
//
// The orientation must be right for the certificate to hold, and it is
// decided by the centroid's side of each face: on a nearly flat tetrahedron
// that side is rounding noise, and a flipped face puts the origin "below"
// every face (ForeignCache.FlatContactTetrahedronDoesNotCertifyIntersection:
// a flat base a few bands above a touching apex certified intersection from
// a warm cache). A tetrahedron holding a ball of radius r has each face's
// height h_f = 3V/A_f > 6V/A = 2r (a face is smaller than half the surface
// A), so its centroid is more than h_f/4 > r/2 from every face: one whose
// centroid is within tol/2 of a face cannot hold the origin deeper than tol,
// and is refused (the lowest double), as a flat one is.
double origin_depth(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double tol) {
  const std::array<const Vec3*, 4> p = {&p0, &p1, &p2, &p3};
  const Vec3 inner = 0.25 * (p0 + p1 + p2 + p3);
  double depth = std::numeric_limits<double>::max();
  for (const auto& f : kOppositeFace) {
    const Vec3& pi = *p[idx(f[0])];
    Vec3 nrm = face_normal(*p[idx(f[1])] - pi, *p[idx(f[2])] - pi).n;
    double side = nrm.dot(pi - inner);
    if (side < 0.0) {
      nrm = -nrm;
      side = -side;
    }
    const double len = nrm.norm();
    if (!(side > 0.0) || !(len > 0.0) || !(side > 0.5 * tol * len))
      return std::numeric_limits<double>::lowest();
    depth = std::min(depth, (nrm / len).dot(pi));
  }
  return depth;
}

// ---------------------------------------------------------------------------
// Contact classification. GJK reaches the contact band in one of two ways:
// a tetrahedron of C that strictly encloses the origin, or a closest point
// within the band (origin on or near a lower-dimensional simplex; symmetric
// bodies do this often). Neither tells touching from intersecting by itself:
// a tetrahedron can enclose the origin by a rounding error, and a point of C
// near the origin may be deep inside C. The band is decided by two
// certificates on a polytope P of points of C around the origin:
//   - touching: a unit d with max over C of d.x <= tol. C lies in that half
//     space and comes within tol of the origin, so the origin is within tol of
//     C's boundary;
//   - intersecting: every face of P at distance > tol from the origin, the
//     origin inside P. P is in C, so the origin is deeper than tol in C.
// P starts as the simplex, blown up to a tetrahedron by supports orthogonal
// to its affine hull (each either certifies touching or adds a dimension:
// the hull passes within tol of the origin, so a support beyond tol is off
// it). Then, as in an expanding polytope (EPA), the face nearest the origin
// is pushed out by C's support point in its normal until one certificate
// holds. Its support evaluations count as iterations: a contact still
// undecided at options.max_iterations is reported as iteration_cap (the
// distance is within the band either way).
// ---------------------------------------------------------------------------
struct ContactFace {
  std::array<int, 3> v{};
  Vec3 normal = Vec3::Zero();  // unit, outward
  double offset = 0.0;         // normal.x == offset on the face; the origin's depth below it
};

// When it certifies intersection, `deep` receives a tetrahedron of P's points
// (with their vertex pairs) that holds the origin deeper than tol by itself,
// if one exists (P itself when it is a tetrahedron; otherwise the deepest of
// the cones from a vertex of P over its faces, which tile P): a tracked
// query re-checks it in O(1) (encloses_origin_deeply). deep[0].ia stays -1
// when there is none.
template <class Support>
Status classify_contact(const Simplex& s, double tol, Support& support, int& iterations,
                        int max_iterations, Points& deep) {
  tol = std::max(tol, 0.0);
  std::array<SupportPoint, kMaxContactVertices> sp;
  std::array<Vec3, kMaxContactVertices> p;
  int n = 0;
  for (int k = 0; k < s.size; ++k) {
    sp[idx(n)] = s.p[idx(k)];
    p[idx(n++)] = s.p[idx(k)].w;
  }

  while (n < 4) {
    Vec3 d = Vec3::UnitX();
    if (n == 3) {
      d = (p[1] - p[0]).cross(p[2] - p[0]);
      if (!(d.squaredNorm() > 0.0)) {  // collinear: an edge is all there is
        --n;
        continue;
      }
    } else if (n == 2) {
      const Vec3 e = p[1] - p[0];
      if (!(e.squaredNorm() > 0.0)) {
        --n;
        continue;
      }
      int axis = 0;
      e.cwiseAbs().minCoeff(&axis);
      d = e.cross(Vec3::Unit(axis));  // |d| >= |e| sqrt(2/3) > 0
    }
    d.normalize();
    if (iterations >= max_iterations) return Status::iteration_cap;
    const SupportPoint w = support(d);
    ++iterations;
    if (d.dot(w.w) <= tol) return Status::touching;
    sp[idx(n)] = w;
    p[idx(n++)] = w.w;
  }

  const Vec3 inner = 0.25 * (p[0] + p[1] + p[2] + p[3]);
  std::array<ContactFace, kMaxContactFaces> faces;
  int nf = 0;
  // Orientation by the inner point, which stays strictly inside P as P grows.
  const auto add_face = [&](int i, int j, int k) {
    if (nf == kMaxContactFaces) return false;
    Vec3 nrm = face_normal(p[idx(j)] - p[idx(i)], p[idx(k)] - p[idx(i)]).n;
    double side = nrm.dot(p[idx(i)] - inner);
    if (side < 0.0) {
      std::swap(j, k);
      nrm = -nrm;
      side = -side;
    }
    const double len = nrm.norm();
    if (!(side > 0.0) || !(len > 0.0)) return false;  // flat: cannot orient
    ContactFace& f = faces[idx(nf++)];
    f.v = {i, j, k};
    f.normal = nrm / len;
    f.offset = f.normal.dot(p[idx(i)]);
    return true;
  };
  if (!add_face(0, 1, 2) || !add_face(0, 1, 3) || !add_face(0, 2, 3) || !add_face(1, 2, 3)) {
    return Status::touching;
  }

  for (;;) {
    int best = 0;
    for (int f = 1; f < nf; ++f) {
      if (faces[idx(f)].offset < faces[idx(best)].offset) best = f;
    }
    if (faces[idx(best)].offset > tol) {
      if (n == 4) {
        deep = {sp[0], sp[1], sp[2], sp[3]};
        return Status::intersecting;
      }
      double deepest = tol;
      for (int r = 0; r < n; ++r) {
        for (int f = 0; f < nf; ++f) {
          const auto& v = faces[idx(f)].v;
          if (v[0] == r || v[1] == r || v[2] == r) continue;
          const double depth =
              origin_depth(p[idx(r)], p[idx(v[0])], p[idx(v[1])], p[idx(v[2])], tol);
          if (depth > deepest) {
            deepest = depth;
            deep = {sp[idx(r)], sp[idx(v[0])], sp[idx(v[1])], sp[idx(v[2])]};
          }
        }
      }
      return Status::intersecting;
    }
    if (n == kMaxContactVertices) return Status::touching;
    if (iterations >= max_iterations) return Status::iteration_cap;
    const Vec3 normal = faces[idx(best)].normal;
    const SupportPoint w = support(normal);
    ++iterations;
    if (normal.dot(w.w) <= tol) return Status::touching;

    // Add w: remove the faces it sees, close the hole with a cone over the
    // horizon (the edges of exactly one removed face).
    sp[idx(n)] = w;
    p[idx(n)] = w.w;
    std::array<std::array<int, 3>, kMaxContactEdges> edges;  // lo, hi, count
    int ne = 0;
    int kept = 0;
    for (int f = 0; f < nf; ++f) {
      const ContactFace& face = faces[idx(f)];
      if (face.normal.dot(w.w) > face.offset) {
        for (int e = 0; e < 3; ++e) {
          const int u = face.v[idx(e)];
          const int t = face.v[idx((e + 1) % 3)];
          const int lo = std::min(u, t);
          const int hi = std::max(u, t);
          int found = 0;
          while (found < ne && !(edges[idx(found)][0] == lo && edges[idx(found)][1] == hi)) ++found;
          if (found < ne) {
            ++edges[idx(found)][2];
          } else {
            edges[idx(ne++)] = {lo, hi, 1};
          }
        }
      } else {
        faces[idx(kept++)] = face;
      }
    }
    nf = kept;
    for (int e = 0; e < ne; ++e) {
      if (edges[idx(e)][2] == 1 && !add_face(edges[idx(e)][0], edges[idx(e)][1], n))
        return Status::touching;
    }
    ++n;
  }
}

// ---------------------------------------------------------------------------
// Witness features.
// ---------------------------------------------------------------------------

bool face_has(const ConvexPolytope& poly, int f, std::int32_t v) {
  for (const std::int32_t x : poly.face(f)) {
    if (x == v) return true;
  }
  return false;
}

// A face containing all of ids[0..m), found among the faces around ids[0]
// (each face through a vertex is left of exactly one of its outgoing edges).
// A polygon has two, one per side: take the one facing `outward`.
int face_containing(const ConvexPolytope& poly, const std::array<std::int32_t, 4>& ids, int m,
                    const Vec3& outward) {
  const auto offsets = poly.adjacency_offsets();
  const auto left = poly.adjacency_faces();
  const auto v0 = idx(ids[0]);
  int best = -1;
  bool best_aligned = false;  // best_alignment computed (only when another face competes)
  double best_alignment = 0.0;
  for (auto k = idx(offsets[v0]); k < idx(offsets[v0 + 1]); ++k) {
    const int f = left[k];
    if (f < 0) continue;
    bool all = true;
    for (int i = 1; i < m && all; ++i) all = face_has(poly, f, ids[idx(i)]);
    if (!all) continue;
    if (best < 0) {
      best = f;
      continue;
    }
    if (!best_aligned) {
      best_alignment = poly.face_plane(best).normal.dot(outward);
      best_aligned = true;
    }
    const double alignment = poly.face_plane(f).normal.dot(outward);
    if (alignment > best_alignment) {
      best = f;
      best_alignment = alignment;
    }
  }
  return best;
}

// The feature spanned by the vertex ids that carry weight: one id is a
// vertex, two adjacent ids an edge, two non-adjacent ids or three ids a face
// (the hull face through them). When the ids span no hull face (only when
// intersecting, or when rounding kept a sliver of weight on a vertex off the
// closest face), the feature falls back to the heaviest vertex.
Feature witness_feature(const ConvexPolytope& poly, const std::array<std::int32_t, 4>& raw_ids,
                        const std::array<double, 4>& raw_weights, int count, const Vec3& outward) {
  std::array<std::int32_t, 4> ids{};
  std::array<double, 4> weights{};
  int m = 0;
  for (int k = 0; k < count; ++k) {
    int j = 0;
    while (j < m && ids[idx(j)] != raw_ids[idx(k)]) ++j;
    if (j == m) {
      ids[idx(m)] = raw_ids[idx(k)];
      weights[idx(m++)] = 0.0;
    }
    weights[idx(j)] += raw_weights[idx(k)];
  }
  if (m == 4) {  // a tetrahedron around the origin: keep the three heaviest
    int lightest = 0;
    for (int j = 1; j < 4; ++j) {
      if (weights[idx(j)] < weights[idx(lightest)]) lightest = j;
    }
    ids[idx(lightest)] = ids[3];
    weights[idx(lightest)] = weights[3];
    m = 3;
  }
  int heaviest = 0;
  for (int j = 1; j < m; ++j) {
    if (weights[idx(j)] > weights[idx(heaviest)]) heaviest = j;
  }
  const std::int32_t heaviest_id = ids[idx(heaviest)];
  for (int j = 1; j < m; ++j) {  // ascending ids (at most three: insertion)
    for (int i = j; i > 0 && ids[idx(i - 1)] > ids[idx(i)]; --i)
      std::swap(ids[idx(i - 1)], ids[idx(i)]);
  }

  Feature f;
  f.vertices = {ids[0], -1, -1};
  if (m == 1) return f;
  if (m == 2) {
    for (const std::int32_t w : poly.neighbors(ids[0])) {
      if (w == ids[1]) {
        f.type = FeatureType::edge;
        f.vertices = {ids[0], ids[1], -1};
        return f;
      }
    }
  }
  const int face = face_containing(poly, ids, m, outward);
  if (face < 0) {
    f.vertices = {heaviest_id, -1, -1};
    return f;
  }
  f.type = FeatureType::face;
  f.face = face;
  f.vertices = {ids[0], ids[1], m == 3 ? ids[2] : -1};
  return f;
}

// ---------------------------------------------------------------------------
// The loop shared by both variants.
// ---------------------------------------------------------------------------

// `simplex` is solved on entry (at least one point); `iterations` counts the
// support evaluations made so far; `direction` is the search direction used
// so far (from A towards B), the normal reported when no better one exists.
// `deep` receives the contact classification's tetrahedron around the origin
// when it certifies intersection (classify_contact).
template <class Support>
DistanceResult run_gjk(const Frame& frame, const DistanceOptions& options, double contact_tolerance,
                       Simplex& simplex, int iterations, Vec3 direction, Support& support,
                       Points& deep) {
  const double tol = contact_tolerance * frame.inv_unit;
  double lower = 0.0;  // certified lower bound, scaled units
  double w_max2 = 0.0;
  for (int k = 0; k < simplex.size; ++k)
    w_max2 = std::max(w_max2, simplex.p[idx(k)].w.squaredNorm());
  direction = direction.squaredNorm() > 0.0 ? Vec3(direction.normalized()) : Vec3(Vec3::UnitX());

  bool contact = false;
  bool capped = false;
  for (;;) {
    if (simplex.encloses_origin || simplex.vv <= tol * tol) {
      contact = true;
      break;
    }
    if (iterations >= options.max_iterations) {
      capped = true;
      break;
    }
    const double v_norm = std::sqrt(simplex.vv);  // > 0: vv > tol^2 >= 0
    direction = -simplex.v / v_norm;
    const SupportPoint w = support(-simplex.v);
    ++iterations;
    w_max2 = std::max(w_max2, w.w.squaredNorm());
    lower = std::max(lower, simplex.v.dot(w.w) / v_norm);
    if (v_norm - lower <=
        options.relative_tolerance * v_norm + kGapUlps * kUnitRoundoff * std::sqrt(w_max2)) {
      break;
    }
    if (simplex.contains(w.ia, w.ib)) break;  // nothing new: v is exact for this simplex
    Simplex next = simplex;
    next.p[idx(next.size++)] = w;
    solve(next);
    if (!next.encloses_origin && next.vv >= simplex.vv) break;  // rounding has taken over: keep v
    simplex = next;
  }

  Status status = Status::separated;
  if (contact) {
    status = classify_contact(simplex, tol, support, iterations, options.max_iterations, deep);
    // A touching contact whose tetrahedron encloses the origin (by rounding,
    // or within the band): the origin is within tol of a face of it (else
    // the classification would have certified depth), so that face's
    // closest points are the witnesses. Its barycentric weights of the
    // origin would only give rounding noise from a sliver tetrahedron.
    if (status == Status::touching && simplex.encloses_origin)
      apply(simplex, nearest_face(simplex.p));
  }

  // Closest points from the original coordinates (the weights are
  // unit-free): sums of hull points with weights summing to one. B's is
  // formed in B's frame and mapped once (the pose is affine).
  Vec3 point_a = Vec3::Zero();
  Vec3 local_b = Vec3::Zero();
  std::array<std::int32_t, 4> ids_a{};
  std::array<std::int32_t, 4> ids_b{};
  for (int k = 0; k < simplex.size; ++k) {
    const SupportPoint& sp = simplex.p[idx(k)];
    point_a += simplex.lambda[idx(k)] * frame.a.vertex(sp.ia);
    local_b += simplex.lambda[idx(k)] * frame.b.vertex(sp.ib);
    ids_a[idx(k)] = sp.ia;
    ids_b[idx(k)] = sp.ib;
  }
  const Vec3 point_b = frame.b_in_a.apply(local_b);

  DistanceResult result;
  result.iterations = iterations;
  if (status == Status::intersecting) {
    // A tetrahedron around the origin gives one point in both hulls
    // (sum lambda a = sum lambda b); otherwise the two are within tol.
    const Vec3 contact_point = 0.5 * (point_a + point_b);
    result.point_a = contact_point;
    result.point_b = contact_point;
    result.distance = 0.0;
    result.lower_bound = 0.0;
    result.normal = direction;
  } else {
    result.point_a = point_a;
    result.point_b = point_b;
    result.distance = ((point_b - point_a) * frame.inv_unit).norm() * frame.unit;
    result.lower_bound = std::clamp(lower * frame.unit, 0.0, result.distance);
    if (!contact)
      status = result.distance > contact_tolerance ? Status::separated : Status::touching;
    if (capped) status = Status::iteration_cap;
    // Within the band the points' difference is rounding noise: keep the
    // last search direction there.
    result.normal = (!contact && status != Status::touching && result.distance > 0.0)
                        ? Vec3((point_b - point_a) / result.distance)
                        : direction;
  }
  result.status = status;
  result.feature_a = witness_feature(frame.a, ids_a, simplex.lambda, simplex.size, result.normal);
  result.feature_b =
      witness_feature(frame.b, ids_b, simplex.lambda, simplex.size, frame.dir_in_b(-result.normal));
  return result;
}

// The first simplex of a cold query: the support point in the direction from
// A's centroid towards B's, i.e. the point of C least far along the
// centroids' difference (a point of C near the closest one when the bodies
// are apart).
//
// The direction is taken in the unit's scale: the supports dot it with the
// vertices, and at coordinates from 1e155 on the raw difference of
// centroids times a vertex overflowed to inf and -inf, whose sum is NaN
// (DistanceRegression.ScalesFrom1eMinus300To1e300).
template <class Support>
Simplex cold_start(const Frame& frame, Support& support, Vec3& direction) {
  direction = (frame.b_in_a.apply(frame.b.centroid()) - frame.a.centroid()) * frame.inv_unit;
  if (!(direction.squaredNorm() > 0.0)) direction = Vec3::UnitX();
  Simplex s;
  s.p[0] = support(direction);
  s.size = 1;
  solve(s);
  return s;
}

}  // namespace

DistanceResult gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, double contact_tolerance) {
  const Frame frame(a, b, b_in_a);
  BruteForceSupport support{frame};
  Vec3 direction;
  Simplex simplex = cold_start(frame, support, direction);
  Points deep;
  return run_gjk(frame, options, contact_tolerance, simplex, 1, direction, support, deep);
}

DistanceResult enhanced_gjk_distance(const ConvexPolytope& a, const ConvexPolytope& b,
                                     const Pose& b_in_a, const DistanceOptions& options,
                                     double contact_tolerance, DistanceCache& cache) {
  const Frame frame(a, b, b_in_a);
  const auto valid = [](std::int32_t id, int count) { return id >= 0 && id < count; };
  HillClimbSupport support{frame, valid(cache.hint_a, a.vertex_count()) ? cache.hint_a : 0,
                           valid(cache.hint_b, b.vertex_count()) ? cache.hint_b : 0};

  // Warm start: the cached vertex pairs, re-evaluated at the current pose.
  // Ids out of range are dropped, repeated pairs kept once.
  Simplex simplex;
  for (std::size_t k = 0; k < 4; ++k) {
    const std::int32_t ia = cache.vertices_a[k];
    const std::int32_t ib = cache.vertices_b[k];
    if (valid(ia, a.vertex_count()) && valid(ib, b.vertex_count()) && !simplex.contains(ia, ib)) {
      simplex.p[idx(simplex.size++)] = frame.point(ia, ib);
    }
  }
  int iterations = 0;
  Vec3 direction;
  if (simplex.size == 0) {
    simplex = cold_start(frame, support, direction);
    iterations = 1;
  } else {
    solve(simplex);
    direction = -simplex.v;
    if (!(direction.squaredNorm() > 0.0))
      direction = (frame.b_in_a.apply(b.centroid()) - a.centroid()) * frame.inv_unit;
  }

  Points deep;
  const DistanceResult result =
      run_gjk(frame, options, contact_tolerance, simplex, iterations, direction, support, deep);
  // run_gjk reduced `simplex` in place to the final one. An intersection
  // certified by a tetrahedron around the origin caches that tetrahedron
  // instead: while the bodies overlap by more than the band, the next query
  // starts from it enclosing the origin and certifies it again without a
  // support search.
  if (result.status == Status::intersecting && deep[0].ia >= 0) {
    simplex.p = deep;
    simplex.size = 4;
  }
  for (std::size_t k = 0; k < 4; ++k) {
    const bool used = static_cast<int>(k) < simplex.size;
    cache.vertices_a[k] = used ? simplex.p[k].ia : -1;
    cache.vertices_b[k] = used ? simplex.p[k].ib : -1;
  }
  cache.hint_a = support.hint_a;
  cache.hint_b = support.hint_b;
  return result;
}

bool encloses_origin_deeply(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            double contact_tolerance, const std::array<std::int32_t, 4>& ids_a,
                            const std::array<std::int32_t, 4>& ids_b) {
  for (std::size_t k = 0; k < 4; ++k) {
    if (ids_a[k] < 0 || ids_a[k] >= a.vertex_count() || ids_b[k] < 0 ||
        ids_b[k] >= b.vertex_count())
      return false;
  }
  // In the units of the GJK simplex, like the contact classification: the
  // same points, the same faces, the same certificate.
  const Frame frame(a, b, b_in_a);
  const double tol = std::max(contact_tolerance, 0.0) * frame.inv_unit;
  const auto w = [&](std::size_t k) { return frame.point(ids_a[k], ids_b[k]).w; };
  return origin_depth(w(0), w(1), w(2), w(3), tol) > tol;
}

}  // namespace proxima
