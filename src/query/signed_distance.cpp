// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The signed distance of an answer: the penetration depth of an
// intersecting one (proxima/detail/penetration/penetration.h), the bounds of an uncertified
// one, the gradient, and the out-of-line parts of PenetrationState.
#include "query/signed_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "proxima/detail/penetration/penetration.h"
#include "proxima/query/signed_distance.h"
#include "proxima/shape/support.h"

namespace proxima {
namespace detail {

PenetrationCache* new_penetration_cache() { return new PenetrationCache(); }
PenetrationCache* copy_penetration_cache(const PenetrationCache& c) {
  return new PenetrationCache(c);
}
void delete_penetration_cache(PenetrationCache* c) noexcept { delete c; }

namespace {

// An upper bound on the penetration depth from the bodies' bounding balls
// (centroid, bounding_radius; b's centroid placed by b_in_a): A - B lies in
// the ball of radius r_a + r_b about c_a - c_b, and the largest ball about
// the origin inside it has radius r_a + r_b - |c_a - c_b|. Depth is
// monotone under inclusion, so it bounds the bodies' depth. Padded by a few
// roundings of its terms (64 u of each): an honest upper bound in doubles.
double ball_depth_bound(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a) {
  const double ra = a.bounding_radius();
  const double rb = b.bounding_radius();
  const double d = (a.centroid() - b_in_a.apply(b.centroid())).norm();
  const double slack = contact_band(ra + rb + d + a.centroid().cwiseAbs().maxCoeff() +
                                    b_in_a.translation.cwiseAbs().maxCoeff());
  return std::max(ra + rb - d, 0.0) + slack;
}

// The depth's answer in place of the algorithm's. A separated or touching
// verdict of the depth for an intersecting answer (the two disagree within
// rounding near contact) has depth 0 and bounds 0: the status stays
// intersecting and the signed distance 0, so that the sign never
// contradicts the status.
void take_depth(const PenetrationResult& p, DistanceResult& result) {
  result.depth = p.depth;
  result.depth_lower_bound = p.lower_bound;
  result.depth_upper_bound = p.upper_bound;
  result.point_a = p.point_a;
  result.point_b = p.point_b;
  result.normal = p.normal;
  result.feature_a = p.feature_a;
  result.feature_b = p.feature_b;
}

// Whether the overlap of the supports of a and b (placed by b_in_a) along
// the unit direction n (A's frame) is within `band`: then the depth is too.
bool overlap_within(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                    const DistanceCache& cache, const Vec3& n, double band) {
  const Vec3 n_in_b = b_in_a.rotation.transpose() * n;
  const int ia = support_hill_climb(a, n, cache.hint_a);
  const int ib = support_hill_climb(b, -n_in_b, cache.hint_b);
  const double overlap =
      n.dot(a.vertex(ia)) - (n_in_b.dot(b.vertex(ib)) + n.dot(b_in_a.translation));
  return overlap <= band;
}

// Whether a touching answer is certified touching in O(1): the overlap of
// the supports along one of a few directions (the answer's normal, which at
// a distance of a few roundings may be noise, and the outward normals of
// its witness faces, which for a resting contact face on face are the
// contact's) is within the contact band of the bodies' magnitude bound.
bool touching_certified(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                        const DistanceOptions& options, const DistanceCache& cache,
                        const DistanceResult& result) {
  const double magnitude =
      std::max(magnitude_bound(Pose::identity(), a.scale()), magnitude_bound(b_in_a, b.scale()));
  const double band = contact_band(magnitude, options.absolute_tolerance);
  if (overlap_within(a, b, b_in_a, cache, result.normal, band)) return true;
  const Feature& fa = result.feature_a;
  if (fa.type == FeatureType::face && fa.face >= 0 && fa.face < a.face_count() &&
      overlap_within(a, b, b_in_a, cache, a.face_plane(fa.face).normal, band)) {
    return true;
  }
  const Feature& fb = result.feature_b;
  return fb.type == FeatureType::face && fb.face >= 0 && fb.face < b.face_count() &&
         overlap_within(a, b, b_in_a, cache,
                        Vec3(-(b_in_a.rotation * b.face_plane(fb.face).normal)), band);
}

}  // namespace

void finish_signed_distance(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                            const DistanceOptions& options, DistanceCache& cache,
                            DistanceResult& result) {
  if (result.status == Status::iteration_cap) {
    // The distance is an upper bound on the signed distance (a pair that
    // overlaps has a negative one); the lower bound certifies separation
    // only when positive, else the pair may overlap as deep as its bounding
    // balls allow.
    if (!(result.lower_bound > 0.0)) result.depth_upper_bound = ball_depth_bound(a, b, b_in_a);
    return;
  }
  if (!options.penetration) {
    if (result.status == Status::intersecting)
      result.depth_upper_bound = std::numeric_limits<double>::infinity();
    return;
  }
  if (result.status == Status::touching) {
    // Touching: within the contact band of each other, or overlapping in a
    // configuration the contact classification could not certify (the
    // origin on planes of A - B's vertex differences: faces of A and B
    // coplanar, as stacked cubes shifted along one axis; found by
    // SignedDistanceHand.CoplanarOverlapCalledTouchingGetsItsDepth). The
    // depth decides, tracked like an overlap's. First a certificate in O(1)
    // from the answer's normal n: depth <= h_A(n) + h_B(-n) (the overlap of
    // the supports along any unit direction bounds it), so when that
    // overlap is within the contact band of the magnitude bound the pair
    // is touching and the depth is not computed (resting contacts: face on
    // face, n the face normal; hill climbing from the algorithm's support
    // hints, which are read, not updated).
    if (touching_certified(a, b, b_in_a, options, cache, result)) return;
    const PenetrationResult p = penetration_depth(a, b, b_in_a, cache.penetration.get_or_create());
    if (p.status != PenetrationStatus::penetrating) return;
    result.status = Status::intersecting;
    result.distance = 0.0;
    result.lower_bound = 0.0;
    take_depth(p, result);
    return;
  }
  take_depth(penetration_depth(a, b, b_in_a, cache.penetration.get_or_create()), result);
}

bool tracked_overlap(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                     double band, DistanceCache& cache, DistanceResult& result) {
  // overlap_trackable(options, cache) holds: distance() chose this path by it.
  PenetrationCache* depth_cache = cache.penetration.get();
  PenetrationResult p;
  if (!penetration_depth_tracked(a, b, b_in_a, *depth_cache, p) ||
      p.status != PenetrationStatus::penetrating || !(p.lower_bound > band)) {
    // Not certified here: distance()'s algorithm decides, and the depth is
    // asked again (penetration_depth) only if it finds an overlap.
    depth_cache->last_status = PenetrationStatus::separated;
    return false;
  }
  // depth >= lower_bound > the band: the origin is inside A - B deeper
  // than the band, which the algorithm would certify intersecting.
  result = DistanceResult{};
  result.status = Status::intersecting;
  take_depth(p, result);
  return true;
}

}  // namespace detail

SignedDistanceGradient signed_distance_gradient(const DistanceResult& result, const Pose& pose_a,
                                                const Pose& pose_b) {
  if (result.status == Status::intersecting &&
      result.depth_upper_bound == std::numeric_limits<double>::infinity()) {
    throw InvalidInput(
        "signed_distance_gradient: the result is intersecting without its penetration depth "
        "(computed with DistanceOptions::penetration false); its normal is not the depth's");
  }
  const Vec3& n = result.normal;
  SignedDistanceGradient g;
  g.a.head<3>() = -n;
  g.a.tail<3>() = (result.point_a - pose_a.translation).cross(-n);
  g.b.head<3>() = n;
  g.b.tail<3>() = (result.point_b - pose_b.translation).cross(n);
  return g;
}

}  // namespace proxima
