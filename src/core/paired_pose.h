// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The pose arithmetic every convex query pays (distance.cpp): the magnitude
// bound of two placed bodies, B's pose in A's frame, and the answer mapped
// back to the world frame. Each has two forms that round alike, operation
// for operation:
//  - the scalar twin (`..._scalar`), written out in the rounding order that
//    defines the answer, compiled on every target; the one used where the
//    target has no SSE2 (ARM, or -DPROXIMA_SCALAR);
//  - the SSE2 form, two lanes per instruction, used on x86-64.
// paired_pose_test compares the two bit for bit (and the scalar twin with
// Eigen's Pose::apply and products, whose rounding it reproduces), so the
// twin an x86-64 build does not run is still compiled and checked there.
#pragma once

#include <algorithm>

#include "proxima/core/types.h"

#if defined(__SSE2__) && !defined(PROXIMA_SCALAR)
#include <emmintrin.h>
#define PROXIMA_PAIRED_POSE_SSE2 1
#endif

namespace proxima::detail {

// max(magnitude_bound(pose_a, scale_a), magnitude_bound(pose_b, scale_b)).
inline double magnitude_bound_pair_scalar(const Pose& pose_a, double scale_a, const Pose& pose_b,
                                          double scale_b) {
  return std::max(magnitude_bound(pose_a, scale_a), magnitude_bound(pose_b, scale_b));
}

// The same value (max is exact, and each lane rounds as the scalar does),
// with the two bounds in the two lanes of one register. The poses'
// translations are finite (the pose contract).
[[gnu::always_inline]] inline double magnitude_bound_pair(const Pose& pose_a, double scale_a,
                                                          const Pose& pose_b, double scale_b) {
#if defined(PROXIMA_PAIRED_POSE_SSE2)
  const __m128d no_sign = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
  const auto pair = [no_sign](const double& x, const double& y) {
    return _mm_and_pd(_mm_loadh_pd(_mm_load_sd(&x), &y), no_sign);
  };
  const Vec3& ta = pose_a.translation;
  const Vec3& tb = pose_b.translation;
  const __m128d largest =
      _mm_max_pd(_mm_max_pd(pair(ta[0], tb[0]), pair(ta[1], tb[1])), pair(ta[2], tb[2]));
  const __m128d bounds = _mm_add_pd(
      largest, _mm_mul_pd(_mm_set1_pd(std::sqrt(3.0)), _mm_set_pd(scale_b, scale_a)));
  return _mm_cvtsd_f64(_mm_max_sd(bounds, _mm_unpackhi_pd(bounds, bounds)));
#else
  return magnitude_bound_pair_scalar(pose_a, scale_a, pose_b, scale_b);
#endif
}

// B's pose in A's frame, pose_a^-1 pose_b = (R_a^T R_b, R_a^T (t_b - t_a)),
// formed directly (the transpose is the inverse of a rotation under the
// pose contract). Entry i of column j of R_a^T [R_b | d] is the dot product
// of column i of R_a with column j, summed left to right:
// (R_a(0,i) v_0 + R_a(1,i) v_1) + R_a(2,i) v_2, as Eigen's 3x3 product
// rounds it.
inline Pose relative_pose_scalar(const Pose& pose_a, const Pose& pose_b) {
  const double* ra = pose_a.rotation.data();  // column-major: R_a(k, i) = ra[3 i + k]
  const double* rb = pose_b.rotation.data();
  const Vec3 d = pose_b.translation - pose_a.translation;
  const auto dot = [ra](int i, const double* v) {
    return (ra[3 * i] * v[0] + ra[3 * i + 1] * v[1]) + ra[3 * i + 2] * v[2];
  };
  Pose b_in_a;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) b_in_a.rotation(i, j) = dot(i, rb + 3 * j);
    b_in_a.translation[i] = dot(i, d.data());
  }
  return b_in_a;
}

// The same, two columns at a time: the columns (0, 1) of R_b and (2, d)
// share the nine broadcast entries of R_a, each multiplied once per pair of
// outputs, the rounding of each lane the scalar twin's term by term. Eigen's
// own vectorized product pairs the rows of R_a instead and costs more
// instructions per query (bench/tracked_instructions).
[[gnu::always_inline]] inline Pose relative_pose(const Pose& pose_a, const Pose& pose_b) {
#if defined(PROXIMA_PAIRED_POSE_SSE2)
  const double* ra = pose_a.rotation.data();
  const double* rb = pose_b.rotation.data();
  const double* ta = pose_a.translation.data();
  const double* tb = pose_b.translation.data();
  // d = t_b - t_a, entries 0 and 1 in a pair, entry 2 alone.
  const __m128d d01 = _mm_sub_pd(_mm_loadu_pd(tb), _mm_loadu_pd(ta));
  const __m128d d2 = _mm_sub_sd(_mm_load_sd(tb + 2), _mm_load_sd(ta + 2));
  // Entry k of columns 0 and 1 of R_b, and of column 2 of R_b and d.
  const __m128d v01[3] = {_mm_loadh_pd(_mm_load_sd(rb + 0), rb + 3),
                          _mm_loadh_pd(_mm_load_sd(rb + 1), rb + 4),
                          _mm_loadh_pd(_mm_load_sd(rb + 2), rb + 5)};
  const __m128d v2d[3] = {_mm_unpacklo_pd(_mm_load_sd(rb + 6), d01), _mm_loadl_pd(d01, rb + 7),
                          _mm_unpacklo_pd(_mm_load_sd(rb + 8), d2)};
  Pose b_in_a;  // written in place (the returned object itself)
  double* out = b_in_a.rotation.data();
  double* out_t = b_in_a.translation.data();
  for (int i = 0; i < 3; ++i) {
    const __m128d c0 = _mm_set1_pd(ra[3 * i]), c1 = _mm_set1_pd(ra[3 * i + 1]),
                  c2 = _mm_set1_pd(ra[3 * i + 2]);
    const __m128d e01 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, v01[0]), _mm_mul_pd(c1, v01[1])),
                                   _mm_mul_pd(c2, v01[2]));
    const __m128d e2d = _mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, v2d[0]), _mm_mul_pd(c1, v2d[1])),
                                   _mm_mul_pd(c2, v2d[2]));
    _mm_storel_pd(out + i, e01);      // (i, 0)
    _mm_storeh_pd(out + 3 + i, e01);  // (i, 1)
    _mm_storel_pd(out + 6 + i, e2d);  // (i, 2)
    _mm_storeh_pd(out_t + i, e2d);    // translation i
  }
  return b_in_a;
#else
  return relative_pose_scalar(pose_a, pose_b);
#endif
}

// An answer's two points and normal from A's frame to the world frame, in
// place: x -> R_a x + t_a and n -> R_a n, rounded as Pose::apply (Eigen's
// matrix-vector product) rounds them: rows 0 and 1 as
// ((R_0 x_0 + R_1 x_1) + R_2 x_2) + t with R_k column k, row 2 as
// (R_20 x_0 + (R_21 x_1 + R_22 x_2)) + t_2.
inline void to_frame_scalar(const Pose& pose, Vec3& point_a, Vec3& point_b, Vec3& normal) {
  const double* r = pose.rotation.data();  // column-major: column k at r + 3 k
  const double* t = pose.translation.data();
  const auto map = [r, t](Vec3& x, bool translate) {
    const double x0 = x[0], x1 = x[1], x2 = x[2];
    double y[3];
    for (int i = 0; i < 2; ++i) y[i] = (r[i] * x0 + r[3 + i] * x1) + r[6 + i] * x2;
    y[2] = r[2] * x0 + (r[5] * x1 + r[8] * x2);
    for (int i = 0; i < 3; ++i) x[i] = translate ? y[i] + t[i] : y[i];
  };
  map(point_a, true);
  map(point_b, true);
  map(normal, false);
}

// The same, rows 0 and 1 in the two lanes, with the pose loaded into
// registers once before the first store: the compiler cannot know that the
// outputs do not alias the pose, and would reload it for every entry
// written.
[[gnu::always_inline]] inline void to_frame(const Pose& pose, Vec3& point_a, Vec3& point_b,
                                            Vec3& normal) {
#if defined(PROXIMA_PAIRED_POSE_SSE2)
  const double* r = pose.rotation.data();
  const double* t = pose.translation.data();
  const __m128d c0 = _mm_loadu_pd(r), c1 = _mm_loadu_pd(r + 3), c2 = _mm_loadu_pd(r + 6);
  const __m128d t01 = _mm_loadu_pd(t);
  const double r20 = r[2], r21 = r[5], r22 = r[8], t2 = t[2];
  const auto map = [&](Vec3& x, bool translate) {
    const double x0 = x[0], x1 = x[1], x2 = x[2];
    __m128d top =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(c0, _mm_set1_pd(x0)), _mm_mul_pd(c1, _mm_set1_pd(x1))),
                   _mm_mul_pd(c2, _mm_set1_pd(x2)));
    double bottom = r20 * x0 + (r21 * x1 + r22 * x2);
    if (translate) {
      top = _mm_add_pd(top, t01);
      bottom += t2;
    }
    _mm_storeu_pd(x.data(), top);
    x[2] = bottom;
  };
  map(point_a, true);
  map(point_b, true);
  map(normal, false);
#else
  to_frame_scalar(pose, point_a, point_b, normal);
#endif
}

}  // namespace proxima::detail
