// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The contact unit (include/proxima/detail/narrowphase/contact.h): the cross-check of an
// uncertified separated answer and the touching/intersecting decision, both
// by Enhanced GJK.
#include "proxima/detail/narrowphase/contact.h"

#include <algorithm>

#include "narrowphase/gjk_contact.h"
#include "proxima/detail/narrowphase/gjk.h"

namespace proxima {

void cross_check_separation(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, double contact_tolerance,
                            DistanceResult& result) {
  // Near contact on needles and slivers the hybrid's direction between two
  // nearly touching features can be too rough for "no support point
  // improves the pair" to mean the pair is optimal: its answer is then an
  // honest upper bound without a matching lower bound.
  DistanceCache second_cache;
  DistanceResult second =
      enhanced_gjk_distance(a, b, b_in_a, options, contact_tolerance, second_cache);
  const double lower = std::max(result.lower_bound, second.lower_bound);
  if (second.status != Status::iteration_cap && second.distance < result.distance) {
    second.iterations += result.iterations;
    result = second;
  }
  result.lower_bound = std::min(lower, result.distance);
  result.second_algorithm = true;
}

void classify_contact(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                      const DistanceOptions& options, double contact_tolerance,
                      DistanceCache& cache, DistanceResult& result) {
  DistanceResult contact;
  if (encloses_origin_deeply(a, b, b_in_a, contact_tolerance, cache.contact_a, cache.contact_b)) {
    contact.status = Status::intersecting;
    contact.iterations = 0;
  } else {
    DistanceCache contact_cache;
    contact_cache.hint_a = cache.hint_a;
    contact_cache.hint_b = cache.hint_b;
    contact_cache.vertices_a = cache.contact_a;
    contact_cache.vertices_b = cache.contact_b;
    // Its witness features would be dropped with it: not computed.
    contact = detail::enhanced_gjk_contact(a, b, b_in_a, options, contact_tolerance, contact_cache);
    cache.contact_a = contact_cache.vertices_a;
    cache.contact_b = contact_cache.vertices_b;
    result.second_algorithm = true;
  }
  if (contact.status == Status::intersecting) {
    const Vec3 middle = 0.5 * (result.point_a + result.point_b);
    result.status = Status::intersecting;
    result.distance = 0.0;
    result.point_a = result.point_b = middle;
    result.iterations += contact.iterations;
  }
}

}  // namespace proxima
