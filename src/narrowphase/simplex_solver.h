// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): the GJK simplex and its distance subalgorithm, the
// closest point to the origin of a simplex of one to four points of the
// Minkowski difference C = A - B (simplex_solver.cpp explains the method).
// Points are in the scaled units of the query (gjk_frame.h); the solver
// knows nothing of hulls or poses.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "proxima/core/types.h"

namespace proxima::detail {

inline constexpr std::size_t idx(int i) { return static_cast<std::size_t>(i); }

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

// Whether x and y are both positive or both negative (zero has no sign).
inline bool same_sign(double x, double y) { return (x > 0.0 && y > 0.0) || (x < 0.0 && y < 0.0); }

struct FaceNormal {
  Vec3 n;     // e1 x e2, accurate in direction to a few u
  bool thin;  // computed by the accurate path
};

// sin^2 of the angle between a face's edges below which its normal is
// recomputed accurately: at sin >= 1/8 the plain cross product's direction
// error is at most ~16 u, which moves a height over the face by ~16 u R,
// inside the 64 u R band; thinner faces would exceed it.
inline constexpr double kThinFaceSine2 = 1.0 / 64.0;

// e1 x e2 by differences of products accurate to a few u (the thin faces'
// path of face_normal, simplex_solver.cpp).
FaceNormal accurate_face_normal(const Vec3& e1, const Vec3& e2);

// e1 x e2, accurate in direction to a few u even for nearly parallel edges
// (simplex_solver.cpp: accurate cross products for thin faces). The plain
// product inline, the thin faces' path out of line: the contact
// certificate of a tracked overlapping pair (origin_depth) takes four
// normals per query, and the call cost it about 15 instructions each
// (callgrind, scene_bench at 10,000 bodies).
inline FaceNormal face_normal(const Vec3& e1, const Vec3& e2) {
  const Vec3 n = e1.cross(e2);
  if (!(n.squaredNorm() < kThinFaceSine2 * e1.squaredNorm() * e2.squaredNorm())) return {n, false};
  return accurate_face_normal(e1, e2);
}

// The faces of a tetrahedron (p0, p1, p2, p3), face m opposite vertex m.
inline constexpr std::array<std::array<int, 3>, 4> kOppositeFace = {
    {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}}};

// Replaces the simplex by the sub-simplex realizing its closest point.
void solve(Simplex& s);

// The closest point of a tetrahedron's boundary: for a tetrahedron around
// the origin, the nearest face (the projection onto the nearest face plane of
// an interior point lies in that face).
Reduction nearest_face(const Points& p);

// Replaces the simplex by its reduction r.
void apply(Simplex& s, const Reduction& r);

}  // namespace proxima::detail
