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
#include "query/extended_distance.h"

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

// The contact classification's tetrahedron (around the origin when it
// certified the overlap), where a cold depth's expansion starts.
DepthSeed contact_seed(const DistanceCache& cache) { return {cache.contact_a, cache.contact_b}; }

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

// The overlap h_A(n) + h_B(-n) of the supports of a and b (placed by
// b_in_a) along the unit direction n (A's frame), an upper bound on the
// depth, and the supports (hill climbing from the algorithm's hints, which
// are read, not updated).
struct Overlap {
  double value;
  int support_a, support_b;
};
Overlap overlap_along(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                      const DistanceCache& cache, const Vec3& n) {
  const Vec3 n_in_b = b_in_a.rotation.transpose() * n;
  // Through plateaus: a climb stopped below the support by rounding would
  // understate the overlap and certify touching a pair that overlaps.
  const int ia = support_hill_climb_through_plateaus(a, n, cache.hint_a);
  const int ib = support_hill_climb_through_plateaus(b, -n_in_b, cache.hint_b);
  return {n.dot(a.vertex(ia)) - (n_in_b.dot(b.vertex(ib)) + n.dot(b_in_a.translation)), ia, ib};
}

// The rounding of an overlap (Overlap::value), in u of the magnitude
// bound: the two dot products of |.| <= sqrt(3) R (3 u each), the
// rotation of n (3 u of R) and the sums; pinned with the band's edge by
// SignedDistanceRegression.DepthJustAboveTheBandIsIntersecting.
constexpr double kOverlapErrorUlps = 16.0;

// Whether a touching answer is certified touching in O(1): the overlap of
// the supports along one of a few directions (the answer's normal, which at
// a distance of a few roundings may be noise, and the outward normals of
// its witness faces, which for a resting contact face on face are the
// contact's), plus its rounding, is within the contact band of R_w. R_w is
// bounded below by the supports' own placed coordinates (computed as
// placed_magnitude computes them), and computed (O(N), once) only when that
// lower band does not decide.
bool touching_certified(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                        const Pose& pose_b, const Pose& b_in_a, const DistanceOptions& options,
                        const DistanceCache& cache, const DistanceResult& result,
                        double& exact_band) {
  const double magnitude =
      std::max(magnitude_bound(Pose::identity(), a.scale()), magnitude_bound(b_in_a, b.scale()));
  const double error = kOverlapErrorUlps * kUnitRoundoff * magnitude;
  const auto within = [&](const Vec3& n) {
    const Overlap o = overlap_along(a, b, b_in_a, cache, n);
    const double floor = contact_band(std::max(placed_magnitude(a.vertex(o.support_a), pose_a),
                                               placed_magnitude(b.vertex(o.support_b), pose_b)),
                                      options.absolute_tolerance);
    if (o.value + error <= floor) return true;
    if (!(o.value + error <= contact_band(magnitude, options.absolute_tolerance))) return false;
    if (exact_band < 0.0)
      exact_band = contact_band(std::max(placed_magnitude(a.vertices(), pose_a), placed_magnitude(b.vertices(), pose_b)),
                                options.absolute_tolerance);
    return o.value + error <= exact_band;
  };
  if (within(result.normal)) return true;
  const Feature& fa = result.feature_a;
  if (fa.type == FeatureType::face && fa.face >= 0 && fa.face < a.face_count() &&
      within(a.face_plane(fa.face).normal)) {
    return true;
  }
  const Feature& fb = result.feature_b;
  return fb.type == FeatureType::face && fb.face >= 0 && fb.face < b.face_count() &&
         within(Vec3(-(b_in_a.rotation * b.face_plane(fb.face).normal)));
}

// With DistanceOptions::extended_precision, an intersecting answer's
// depth recomputed in double-double along its face of A - B
// (query/extended_distance.h).
void refine_depth(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                  const Pose& pose_b, const DistanceOptions& options, DistanceResult& result) {
  if (!options.extended_precision || result.status != Status::intersecting) return;
  refine_depth_extended(a, pose_a, b, pose_b, options, result);
}

}  // namespace

void finish_signed_distance(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                            const Pose& pose_b, const Pose& b_in_a, const DistanceOptions& options,
                            DistanceCache& cache, DistanceResult& result) {
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
    // overlap and its rounding are within the contact band of R_w the pair
    // is touching and the depth is not computed (resting contacts: face on
    // face, n the face normal; hill climbing from the algorithm's support
    // hints, which are read, not updated). A band of the magnitude bound
    // instead (up to sqrt(3) times R_w) called an overlap 1.09 bands deep
    // touching (SignedDistanceRegression.DepthJustAboveTheBandIsIntersecting).
    double exact_band = -1.0;  // not computed yet
    if (touching_certified(a, pose_a, b, pose_b, b_in_a, options, cache, result, exact_band))
      return;
    const PenetrationResult p = penetration_depth(a, b, b_in_a, cache.penetration.get_or_create(), contact_seed(cache));
    if (p.status == PenetrationStatus::separated) return;
    // Intersecting exactly when the depth is above the band of R_w (near
    // the band the depth is exact up to 8 u of itself: penetration.cpp,
    // kRefineBands), whatever the band of A's frame that p.status used.
    if (exact_band < 0.0)
      exact_band = contact_band(std::max(placed_magnitude(a.vertices(), pose_a), placed_magnitude(b.vertices(), pose_b)),
                                options.absolute_tolerance);
    if (!(p.depth > exact_band)) return;
    result.status = Status::intersecting;
    result.distance = 0.0;
    result.lower_bound = 0.0;
    take_depth(p, result);
    refine_depth(a, pose_a, b, pose_b, options, result);
    return;
  }
  take_depth(penetration_depth(a, b, b_in_a, cache.penetration.get_or_create(), contact_seed(cache)), result);
  refine_depth(a, pose_a, b, pose_b, options, result);
}

bool tracked_overlap(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& b_in_a,
                     double band, DistanceCache& cache, DistanceResult& result) {
  // overlap_trackable(options, cache) holds: distance() chose this path by it.
  PenetrationCache* depth_cache = cache.penetration.get();
  PenetrationResult p;
  if (!penetration_depth_tracked(a, b, b_in_a, *depth_cache, p) ||
      p.status != PenetrationStatus::intersecting || !(p.lower_bound > band)) {
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

namespace {

// The refusal of a mesh overlap's gradient, with its reason.
[[noreturn]] void refuse_mesh_overlap() {
  throw InvalidInput(
      "signed_distance_gradient: the bodies overlap and one of them is a triangle mesh; no "
      "penetration depth is defined for an overlap with a mesh (its answer brackets the signed "
      "distance in [-infinity, 0]), so there is no gradient to give. Use the mesh's convex hull "
      "or convex pieces (a compound), whose overlaps have a depth, or treat the overlap as a "
      "collision (intersects())");
}

}  // namespace

SignedDistanceGradient signed_distance_gradient(const MeshResult& result, const Pose& pose_a,
                                                const Pose& pose_b) {
  if (result.status == Status::intersecting) refuse_mesh_overlap();
  return signed_distance_gradient(static_cast<const DistanceResult&>(result), pose_a, pose_b);
}

SignedDistanceGradient signed_distance_gradient(const BodyResult& result, const Pose& pose_a,
                                                const Pose& pose_b) {
  // A pair with a mesh side reports that side's closest triangle.
  const bool mesh_pair = result.triangle_a >= 0 || result.triangle_b >= 0;
  if (mesh_pair && result.intersecting &&
      result.depth_upper_bound == std::numeric_limits<double>::infinity()) {
    refuse_mesh_overlap();
  }
  return signed_distance_gradient(static_cast<const DistanceResult&>(result), pose_a, pose_b);
}

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
