// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// narrowphase layer (internal): GJK's contact search. Once GJK's closest point is in
// the contact band, classify_contact tells touching from intersecting, each
// by a certificate (gjk_contact.cpp); origin_depth is the intersection
// certificate of one tetrahedron, also behind encloses_origin_deeply
// (proxima/detail/narrowphase/gjk.h).
#pragma once

#include "narrowphase/gjk_frame.h"
#include "narrowphase/simplex_solver.h"
#include "proxima/core/types.h"

namespace proxima::detail {

// The origin's depth inside the tetrahedron (p0, p1, p2, p3), each face
// oriented by the centroid; the lowest double when the tetrahedron is too
// flat to orient (gjk_contact.cpp says why). Above tol it certifies
// intersection.
double origin_depth(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double tol);

// origin_depth(p0, p1, p2, p3, tol) > tol, the same decision on the same
// arithmetic, face by face: it stops at the first face that decides
// against. The certificate of a tracked overlapping pair
// (encloses_origin_deeply).
bool origin_deeper_than(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double tol);

// Touching, intersecting or iteration_cap for a solved simplex whose closest
// point is within tol of the origin (gjk_contact.cpp). Its support
// evaluations count in `iterations`. When it certifies intersection, `deep`
// receives a tetrahedron of C's points that holds the origin deeper than tol
// by itself, if one exists (deep[0].ia stays -1 otherwise). Instantiated for
// BruteForceSupport and HillClimbSupport (gjk_frame.h).
template <class Support>
Status classify_contact(const Simplex& s, double tol, Support& support, int& iterations,
                        int max_iterations, Points& deep);

// enhanced_gjk_distance (proxima/detail/narrowphase/gjk.h) without the witness features: the
// same status, distance, points, bounds, iterations and cache simplex and
// hints, the features left default and the cache's faces -1. For the
// contact unit (contact.cpp), which keeps the status, the iterations and the
// simplex only: the witness rule on its tetrahedron (four triangle
// distances per dropped vertex, then the face searches) was about 45% of
// its Enhanced GJK run (callgrind, scene_bench at 10,000 bodies).
DistanceResult enhanced_gjk_contact(const ConvexPolytope& a, const ConvexPolytope& b,
                                    const Pose& b_in_a, const DistanceOptions& options,
                                    double contact_tolerance, DistanceCache& cache);

}  // namespace proxima::detail
