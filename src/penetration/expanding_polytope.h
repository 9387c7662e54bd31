// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// penetration layer (internal): a polytope expanding inside M = A - B
// towards its nearest facet, in the manner of EPA, whose lower bound on
// the depth is certified (the cold query's fast path, issue 29).
//
// Certificate. P is a closed triangulated surface whose vertices are
// points a_i - b_j of M (placed in double). Every triangle is kept with
// its plane's offset from the origin, less a bound on that offset's
// rounding (its key). When every key is positive, the origin lies strictly
// on the inner side of every triangle (consistently oriented outwards), so
// each triangle subtends a positive solid angle at the origin; their sum
// is 4 pi times P's winding number about the origin, which is therefore at
// least 1. Let rho be the least key: no point of P is within rho of the
// origin (a triangle's distance is at least its plane's), so every point of
// the ball of radius rho has P's winding number about it too (it is
// constant off P), is not outside conv(P) (a point outside has winding
// number 0), and lies in M (conv(P) is in M). Hence depth(M) >= rho: the
// certificate needs P to be a closed surface (each edge shared by two
// triangles in opposite directions, which the expansion keeps by
// construction, integer bookkeeping only) and positive keys, not P's
// convexity, which rounding can break.
//
// Start. The seed's tetrahedron (the contact classification's, which the
// distance query built when it found the overlap) or the octahedron; a
// seed whose four keys are not all positive is dropped for the octahedron.
//
// Expansion. The triangle of least key is expanded: the support s of M
// along its normal n (h_M(n) = n.s, an upper bound on the depth) replaces
// the triangles whose planes s is beyond (a connected set around it) by
// the fan from s to their boundary. It stops when s is not beyond that
// triangle (n.s within rounding of its offset): the triangle lies on M's
// supporting plane along n, so the least key is within rounding of
// h_M(n) and of the depth. The caller certifies the answer from the
// facet of M along n (penetration.cpp, solve_expanding) and falls back to
// the enumeration whenever the expansion cannot certify (M flat or thin,
// the origin on or near M's boundary, a boundary that is not one loop, the
// iteration cap).
#pragma once

#include <limits>

#include "proxima/core/types.h"
#include "proxima/detail/penetration/penetration.h"
#include "proxima/shape/polytope.h"

namespace proxima::detail {

// Supports of M = A - B in A's frame, in scaled units: A's vertices times
// `inverse`, B's mapped by (rotation, translation) after the same scaling
// (translation scaled), as the penetration query places them.
struct MinkowskiSupport {
  const ConvexPolytope& a;
  const ConvexPolytope& b;
  Mat3 rotation;
  Mat3 rotation_t;
  Vec3 translation;
  double inverse = 1.0;

  Vec3 point_a(int i) const { return a.vertex(i) * inverse; }
  Vec3 point_b(int j) const { return rotation * (b.vertex(j) * inverse) + translation; }
};

struct ExpansionResult {
  // True when P was closed with every key positive (see above): then
  // depth(M) >= lower for M's points as placed.
  bool certified = false;
  // True when the last triangle expanded lies on M's supporting plane
  // along `normal` (the expansion converged).
  bool converged = false;
  double lower = 0.0;
  Vec3 normal = Vec3::UnitX();  // unit normal of the triangle of least key
  double upper = std::numeric_limits<double>::infinity();  // h_M(normal) found
  int support_a = -1;  // A's support along normal, B's along -normal
  int support_b = -1;
  int iterations = 0;
};

// Expands P, at most `max_iterations` times, from the tetrahedron of the
// seed's points of M when every one of its four triangles (oriented by the
// sign of its volume) has a positive key (the certificate's condition, so
// that P stays certified), else from the octahedron of M's supports along
// the six axes.
ExpansionResult expand_polytope(const MinkowskiSupport& m, int max_iterations,
                                const DepthSeed& seed = {});

}  // namespace proxima::detail
