// proxima benchmarks: the exact reference that every system's answer in the
// robustness experiments is judged against.
// SPDX-License-Identifier: BSD-3-Clause
//
// The bodies are placed exactly: each world vertex is R x + t evaluated in
// rational arithmetic from the very doubles the systems get (hull vertices
// and pose), so the reference is the exact distance of the hulls of the
// given doubles, as DESIGN.md's accuracy standard asks. The distance comes
// from proxima's closed-form kernels instantiated on Boost.Multiprecision's
// header-only cpp_rational, brute force over every vertex-triangle,
// triangle-vertex and edge-edge pair: the pairs are ranked by their distance
// in double and evaluated exactly in that order until one pair's answer
// passes the certificate, which does not depend on the kernels or on the
// ranking:
//
//   pa = sum l_i a_i with l >= 0, sum l = 1 (a point of hull A), pb likewise
//   in hull B, w = pb - pa. If w.a_i <= w.pa for every vertex a_i of A and
//   w.b_j >= w.pb for every vertex b_j of B, then for any x in A, y in B,
//   w.(y - x) >= w.pb - w.pa = |w|^2, so |y - x| >= |w| (Cauchy-Schwarz):
//   d* = |w| exactly.
//
// Judging an answer (all comparisons exact, u = 2^-53, R the largest
// coordinate magnitude of the two placed bodies, tol = 64 u R):
//   distance   |d - d*| <= 1e-12 d* + tol, i.e.
//              (d - tol) / (1 + 1e-12) <= d* <= (d + tol) / (1 - 1e-12)
//   points     point_a within tol of hull A, point_b within tol of hull B,
//              | |point_a - point_b| - d | <= tol
//   status     the system says "separated" exactly when d* > tol
//   finite     no NaN or infinity anywhere in the answer
// A point's distance to a hull: zero when no face plane has it outside;
// otherwise the closest hull point lies on a face whose plane has it
// outside (the outward normals that span p - q at the closest point q
// cannot all be orthogonal to it), so the minimum over those faces'
// triangles of the point-triangle kernel is exact.
#pragma once

#include <memory>

#include "peers/system.h"
#include "proxima/shape/polytope.h"
#include "proxima/core/types.h"

namespace proxima::bench {

struct ExactCase {
  double distance = 0.0;   // d*, the exact distance rounded (sqrt of the exact d*^2)
  double magnitude = 0.0;  // R
  double tolerance = 0.0;  // 64 u R
  bool separated = true;   // d* > 64 u R
  bool certified = false;  // the certificate above held
};

struct Verdict {
  bool finite = false;
  bool status_ok = false;
  bool distance_ok = false;
  bool points_ok = false;
  double relative_error = 0.0;  // |d - d*| / d* (in double; infinite when not finite)

  bool within_standard() const { return finite && status_ok && distance_ok && points_ok; }
};

class ExactReference {
 public:
  // The hulls' topology (vertices, edges, face triangles) comes from the
  // polytopes; they must outlive the reference.
  ExactReference(const ConvexPolytope& a, const ConvexPolytope& b);
  ~ExactReference();
  ExactReference(const ExactReference&) = delete;
  ExactReference& operator=(const ExactReference&) = delete;

  // Places the bodies exactly and solves the case; judge() then refers to it.
  ExactCase solve(const Pose& pose_a, const Pose& pose_b);
  Verdict judge(const SystemAnswer& answer) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace proxima::bench
