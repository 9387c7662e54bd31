// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer (internal): the squared distance between two triangles, fast, for
// the mesh traversal's leaves. Its slow twin is closest_triangle_triangle
// (proxima/geometry/closest_triangle_triangle.h), which also gives the features; the
// traversal ranks pairs by this one and asks the twin for the winner's
// points and features (mesh_distance.cpp), and mesh_test compares the two.
//
// Derivation (the reduction of closest_triangle_triangle): a closest pair
// of two triangles either has a point on an edge of each (nine
// segment-segment problems), or a vertex of one over the interior of the
// other (six vertex-plane projections that land inside), or the triangles
// intersect, in which case an edge of one crosses the other's plane inside
// it (distance 0). The candidates are pairs of points on the two triangles,
// so the smallest is an upper bound within rounding; the reduction says it
// is the distance. A triangle whose normal is negligible against its edges
// (sin of its angle below kParallelSinFactor u, as the twin decides) is
// treated as its edges only: that drops at most its height, inside the
// accuracy standard. Cost: no division except the segment solves'
// (~30 flops each) and one per projection that lands inside.
#pragma once

#include <algorithm>
#include <array>
#include <limits>

#include "proxima/geometry/closest_point.h"

namespace proxima::detail {

struct FastVec {
  double x, y, z;
};
inline FastVec fv(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
inline FastVec operator-(const FastVec& a, const FastVec& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline FastVec operator+(const FastVec& a, const FastVec& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline FastVec operator*(double s, const FastVec& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double fdot(const FastVec& a, const FastVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline FastVec fcross(const FastVec& a, const FastVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// The closest parameters of segments p1 + s d1 and p2 + t d2, s, t in
// [0, 1]: the unconstrained minimum of the quadratic, clamped in s, then t
// solved for that s and clamped, then s re-solved for a clamped t (each
// step is the exact minimizer of a one-variable convex parabola on [0, 1]).
// Parallel (a e - b^2 negligible) and point segments take s = 0 first.
struct SegmentParameters {
  double s = 0.0, t = 0.0;
};
inline SegmentParameters segment_segment_parameters(const FastVec& p1, const FastVec& d1,
                                                    const FastVec& p2, const FastVec& d2,
                                                    double min_length_squared,
                                                    double min_sin_squared) {
  const FastVec r = p1 - p2;
  const double a = fdot(d1, d1), e = fdot(d2, d2), f = fdot(d2, r);
  double s = 0.0, t = 0.0;
  const auto clamp01 = [](double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); };
  if (a <= min_length_squared) {
    if (e > min_length_squared) t = f >= e ? 1.0 : (f <= 0.0 ? 0.0 : f / e);
  } else {
    const double c = fdot(d1, r);
    if (e <= min_length_squared) {
      s = -c >= a ? 1.0 : (-c <= 0.0 ? 0.0 : -c / a);
    } else {
      const double b = fdot(d1, d2);
      const double denom = a * e - b * b;
      if (denom > min_sin_squared * a * e) s = clamp01((b * f - c * e) / denom);
      const double tn = b * s + f;
      if (tn <= 0.0) {
        t = 0.0;
        s = -c >= a ? 1.0 : (-c <= 0.0 ? 0.0 : -c / a);
      } else if (tn >= e) {
        t = 1.0;
        s = b - c >= a ? 1.0 : (b - c <= 0.0 ? 0.0 : (b - c) / a);
      } else {
        t = tn / e;
      }
    }
  }
  return {s, t};
}

// Squared distance between the segments, at those parameters.
inline double segment_segment_squared(const FastVec& p1, const FastVec& d1, const FastVec& p2,
                                      const FastVec& d2, double min_length_squared,
                                      double min_sin_squared) {
  const auto [s, t] =
      segment_segment_parameters(p1, d1, p2, d2, min_length_squared, min_sin_squared);
  const FastVec w = (p1 + s * d1) - (p2 + t * d2);
  return fdot(w, w);
}

// A triangle prepared once per leaf visit: vertices, edges, normal, and
// whether the normal is usable (a non-degenerate triangle).
struct FastTriangle {
  std::array<FastVec, 3> v;
  std::array<FastVec, 3> e;  // v1 - v0, v2 - v1, v0 - v2
  FastVec n;
  bool planar = false;

  FastTriangle() = default;
  FastTriangle(const Vec3& a, const Vec3& b, const Vec3& c, double min_sin_squared) {
    v = {fv(a), fv(b), fv(c)};
    e = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    n = fcross(e[0], v[2] - v[0]);
    const double nn = fdot(n, n);
    planar = nn > min_sin_squared * fdot(e[0], e[0]) * fdot(e[2], e[2]) && nn > 0.0;
  }
  // Whether p projects into the closed triangle (requires planar).
  bool holds_projection(const FastVec& p) const {
    return fdot(fcross(e[0], p - v[0]), n) >= 0.0 && fdot(fcross(e[1], p - v[1]), n) >= 0.0 &&
           fdot(fcross(e[2], p - v[2]), n) >= 0.0;
  }
};

// The smallest candidate met so far: its squared distance, and with
// kPoints the pair of points that realizes it (on A, on B).
template <bool kPoints>
struct Candidate {
  double d2;
};
template <>
struct Candidate<true> {
  double d2;
  FastVec on_a{}, on_b{};
};

// Squared distance from vertices of `from` projected into `onto`, and 0 if
// an edge of `from` crosses `onto` inside it; `best` is lowered (with its
// points: `from_is_a` says which side `from` is).
template <bool kPoints>
void plane_candidates(const FastTriangle& from, const FastTriangle& onto, Candidate<kPoints>& best,
                      [[maybe_unused]] bool from_is_a) {
  if (!onto.planar) return;
  const double nn = fdot(onto.n, onto.n);
  [[maybe_unused]] const auto keep = [&](const FastVec& on_from, const FastVec& on_onto) {
    if constexpr (kPoints) {
      best.on_a = from_is_a ? on_from : on_onto;
      best.on_b = from_is_a ? on_onto : on_from;
    }
  };
  std::array<double, 3> side;
  for (int k = 0; k < 3; ++k) {
    side[k] = fdot(onto.n, from.v[k] - onto.v[0]);
    const double d2 = side[k] * side[k] / nn;
    if (d2 < best.d2 && onto.holds_projection(from.v[k])) {
      best.d2 = d2;
      if constexpr (kPoints) keep(from.v[k], from.v[k] - (side[k] / nn) * onto.n);
    }
  }
  for (int k = 0; k < 3 && best.d2 > 0.0; ++k) {
    const int l = (k + 1) % 3;
    if ((side[k] < 0.0 && side[l] > 0.0) || (side[k] > 0.0 && side[l] < 0.0)) {
      const double w = side[k] / (side[k] - side[l]);
      const FastVec x = from.v[k] + w * (from.v[l] - from.v[k]);
      if (onto.holds_projection(x)) {
        best.d2 = 0.0;
        if constexpr (kPoints) keep(x, x);
      }
    }
  }
}

// Squared gap between the boxes of segments [p, q] and [r, s]: a lower
// bound on their squared distance (within rounding).
inline double segment_box_gap_squared(const FastVec& p, const FastVec& q, const FastVec& r,
                                      const FastVec& s) {
  const auto gap = [](double p1, double q1, double r1, double s1) {
    const double g =
        std::max(std::min(p1, q1) - std::max(r1, s1), std::min(r1, s1) - std::max(p1, q1));
    return g > 0.0 ? g * g : 0.0;
  };
  return gap(p.x, q.x, r.x, s.x) + gap(p.y, q.y, r.y, s.y) + gap(p.z, q.z, r.z, s.z);
}

// The smallest candidate of two prepared triangles, and with kPoints its
// points. With a `bound` (a squared distance the caller needs no answer
// beyond), candidates that cannot go below it are skipped: an edge pair
// whose boxes are farther apart, a vertex projection that is farther than
// the bound from the plane. The result is then the distance when below the
// bound (within rounding: a skipped edge pair's box gap rounds like its
// distance), and some value >= the bound otherwise (no points then).
// Measured on env/rob (bench/mesh_bench): most pairs that reach the kernel
// in a traversal end beyond the bound, and the box check costs a third of a
// segment solve.
template <bool kPoints>
Candidate<kPoints> triangle_closest(const FastTriangle& a, const FastTriangle& b,
                                    const KernelTolerance<double>& tol, double bound) {
  Candidate<kPoints> best{bound};
  plane_candidates(a, b, best, true);
  if (best.d2 > 0.0) plane_candidates(b, a, best, false);
  for (int i = 0; i < 3 && best.d2 > 0.0; ++i) {
    const FastVec& ai = a.v[static_cast<std::size_t>(i)];
    const FastVec& ai1 = a.v[static_cast<std::size_t>((i + 1) % 3)];
    const FastVec& ei = a.e[static_cast<std::size_t>(i)];
    for (int j = 0; j < 3; ++j) {
      const FastVec& bj = b.v[static_cast<std::size_t>(j)];
      const FastVec& bj1 = b.v[static_cast<std::size_t>((j + 1) % 3)];
      const FastVec& ej = b.e[static_cast<std::size_t>(j)];
      if (segment_box_gap_squared(ai, ai1, bj, bj1) > best.d2) continue;
      const auto [s, t] =
          segment_segment_parameters(ai, ei, bj, ej, tol.min_length_squared, tol.min_sin_squared);
      const FastVec on_a = ai + s * ei;
      const FastVec on_b = bj + t * ej;
      const FastVec w = on_a - on_b;
      const double d2 = fdot(w, w);
      if constexpr (kPoints) {
        if (d2 < best.d2) best = {d2, on_a, on_b};
      } else {
        best.d2 = std::min(best.d2, d2);  // a minimum, no branch
      }
    }
  }
  return best;
}

// The squared distance between two prepared triangles (triangle_closest
// without the points).
inline double triangle_distance_squared(const FastTriangle& a, const FastTriangle& b,
                                        const KernelTolerance<double>& tol,
                                        double bound = std::numeric_limits<double>::infinity()) {
  return triangle_closest<false>(a, b, tol, bound).d2;
}

// The closest points of two prepared triangles as the fast kernel finds
// them: a point of each (within rounding, a few u of the coordinates) whose
// squared distance is triangle_distance_squared's. Where a caller needs
// only a witness pair, not the features (the margin query's "within"
// proof), at the cost of one kernel call instead of the slow twin's.
inline Candidate<true> triangle_closest_points(const FastTriangle& a, const FastTriangle& b,
                                               const KernelTolerance<double>& tol) {
  return triangle_closest<true>(a, b, tol, std::numeric_limits<double>::infinity());
}

}  // namespace proxima::detail
