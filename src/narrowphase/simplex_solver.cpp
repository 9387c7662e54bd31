// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The GJK simplex solver: the closest point to the origin of a simplex of
// one to four points, and the smallest sub-simplex realizing it.
#include "narrowphase/simplex_solver.h"

#include <array>
#include <cmath>
#include <limits>

namespace proxima::detail {
namespace {

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
// thinner than kThinFaceSine2 (simplex_solver.h).
// ---------------------------------------------------------------------------

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
}  // namespace

FaceNormal accurate_face_normal(const Vec3& e1, const Vec3& e2) {
  return {Vec3(difference_of_products(e1.y(), e2.z(), e1.z(), e2.y()),
               difference_of_products(e1.z(), e2.x(), e1.x(), e2.z()),
               difference_of_products(e1.x(), e2.y(), e1.y(), e2.x())),
          true};
}

namespace {

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

}  // namespace

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

}  // namespace proxima::detail
