// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The boolean and margin queries (proxima/query/margin.h) for convex hulls and for
// Bodies of any kinds: the hybrid's loop stopped at the first proof, the
// full distance query where it could not prove either way, and the radii
// of rounded bodies added to the margin (the compound and mesh traversals
// are in compound.cpp and mesh_distance.cpp).
#include "proxima/query/margin.h"

#include "core/accuracy.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <utility>

#include "proxima/detail/narrowphase/hybrid.h"
#include "proxima/query/distance.h"

namespace proxima {
namespace {

// Slack of a sphere gap, in units of u times the magnitudes involved (the
// centers' coordinates, the radii, the gap's norm): the placed centers are
// a rotation and a translation away from stored doubles (a few u of their
// magnitude each), a stored radius is a rounded maximum of rounded norms (a
// few u of itself), and the norm and subtractions add a few u more. 256 u
// covers all of them with room, as the compound pruning's slack does.
constexpr double kSphereSlackUlps = 256.0;

// A certified lower bound on the distance between two hulls from their
// boxes (ConvexPolytope::box_center, box_half; both must have one), B placed in A's frame by
// `relative`, or 0 when it cannot prove them beyond `margin`. Any
// orthonormal axis separates the boxes' projections by at most their
// distance, so the gaps along A's three axes, and along B's, each bound it
// from below, and so does the root of the sum of their squares within one
// frame (the mesh roots' bound, query/mesh_pair.h). The boxes, their
// placement and the gaps round by a few u R each: prune_slack(R) covers
// them. The largest single gap is tried first: it needs no square, which
// would overflow for margins beyond 1e153 (a sum that is not finite proves
// nothing).
double box_gap_lower_bound(const ConvexPolytope& a, const ConvexPolytope& b,
                           const Pose& relative, double margin, double magnitude) {
  const double slack = detail::prune_slack(magnitude);
  const Vec3 d = relative.rotation * b.box_center() + relative.translation - a.box_center();
  const Mat3 abs_rotation = relative.rotation.cwiseAbs();
  const Vec3 gaps_a = d.cwiseAbs() - a.box_half() - abs_rotation * b.box_half();
  const Vec3 gaps_b =
      (relative.rotation.transpose() * d).cwiseAbs() - b.box_half() - abs_rotation.transpose() * a.box_half();
  const double largest = std::max(gaps_a.maxCoeff(), gaps_b.maxCoeff());
  if (largest - slack > margin) return largest - slack;
  if (!(largest - slack > 0.0)) return 0.0;
  const double sum = std::max(gaps_a.cwiseMax(0.0).squaredNorm(), gaps_b.cwiseMax(0.0).squaredNorm());
  if (!std::isfinite(sum)) return 0.0;
  return std::max(0.0, std::sqrt(sum) - slack);
}

// The verdict of a full distance answer (the fallback, and the twin's
// rule): touching and intersecting are within any margin; a separated or
// capped answer is within when its closest points are at most margin +
// band apart, beyond when its certified lower bound is above the margin.
MarginResult from_distance(const DistanceResult& r, double margin, double band) {
  MarginResult out;
  out.margin = margin;
  out.point_a = r.point_a;
  out.point_b = r.point_b;
  out.upper_bound = (r.point_b - r.point_a).norm();
  out.lower_bound = r.status == Status::separated || r.status == Status::iteration_cap
                        ? r.lower_bound
                        : 0.0;
  out.iterations = r.iterations;
  out.pairs_tested = 1;
  if (r.status == Status::touching || r.status == Status::intersecting ||
      out.upper_bound <= margin + band) {
    out.status = MarginStatus::within;
  } else if (out.lower_bound > margin) {
    out.status = MarginStatus::beyond;
  } else {
    out.status = MarginStatus::undecided;
  }
  return out;
}

// A rounded bodies' answer from their cores' answer for the margin plus
// both radii (exact: a rounded body's distance is its core's minus the
// radii): the witness points moved onto the rounded surfaces along their
// difference, or to one common point when the rounded bodies overlap.
// In place: the answer of a pair without radii is the cores' as it is.
void add_radii(MarginResult& r, double margin, double radius_a, double radius_b) {
  r.margin = margin;
  const double radii = radius_a + radius_b;
  if (radii == 0.0) return;
  r.lower_bound = std::max(0.0, r.lower_bound - radii);
  if (!std::isfinite(r.upper_bound)) return;
  const Vec3 diff = r.point_b - r.point_a;
  const double d = diff.norm();
  if (d > radii) {
    const Vec3 n = diff / d;
    r.point_a += radius_a * n;
    r.point_b -= radius_b * n;
    r.upper_bound = (r.point_b - r.point_a).norm();
  } else {
    // Within radius_a of point_a and radius_b of point_b: in both.
    const Vec3 p = r.point_a + (radius_a / radii) * diff;
    r.point_a = p;
    r.point_b = p;
    r.upper_bound = 0.0;
  }
}

// Pairs with a mesh on at least one side: every pair of meshes of
// Body::meshes(), each with its own MeshCache (the distance query's), the
// last answer's pair first; a pair whose pieces' bounding spheres are
// farther apart than the margin is beyond without a query, and the first
// pair within ends the search.
MarginResult mesh_pairs_within(const Body& a, const Pose& pose_a, const Body& b,
                               const Pose& pose_b, double margin, const DistanceOptions& options,
                               BodyCache& cache) {
  // The triangle pairs take only absolute_tolerance: a field they cannot
  // honour is refused here, where every Body margin query with a mesh
  // (single, batch, scene) passes.
  if (!detail::mesh_options_plainly_valid(options, detail::MeshOptionUse::triangle_pairs))
    [[unlikely]] detail::check_mesh_options(options, "within_margin", detail::MeshOptionUse::triangle_pairs);
  const std::vector<Body::MeshOfPiece>& ma = a.meshes();
  const std::vector<Body::MeshOfPiece>& mb = b.meshes();
  const std::size_t pairs = ma.size() * mb.size();
  if (cache.mesh.size() != pairs) cache.mesh.assign(pairs, MeshCache{});
  const std::size_t first =
      cache.mesh_closest >= 0 && static_cast<std::size_t>(cache.mesh_closest) < pairs
          ? static_cast<std::size_t>(cache.mesh_closest)
          : 0;
  MarginResult out;
  out.margin = margin;
  out.lower_bound = std::numeric_limits<double>::infinity();
  bool undecided = false;
  int tested = 0;
  for (std::size_t n = 0; n < pairs; ++n) {
    const std::size_t k = n == 0 ? first : n <= first ? n - 1 : n;
    const std::size_t i = k / mb.size();
    const std::size_t j = k % mb.size();
    // A mesh body is its one mesh at the identity: its pose as it is (the
    // product with the identity would give the same bits, at the cost of
    // two pose products on every query of a tracked mesh pair).
    // A piece's placement (a product of rigid poses, rigid up to rounding)
    // is put under the contract as the mesh query would have put it.
    // Referenced, not copied, for a mesh body (the common tracked pair).
    Pose placed_a, placed_b;
    const Pose& place_a = a.kind() == Body::Kind::mesh
                              ? pose_a
                              : (placed_a = checked_pose(pose_a * ma[i].pose, "within_margin: pose_a"));
    const Pose& place_b = b.kind() == Body::Kind::mesh
                              ? pose_b
                              : (placed_b = checked_pose(pose_b * mb[j].pose, "within_margin: pose_b"));
    if (pairs > 1) {
      const double gap = detail::sphere_gap_lower_bound(
          place_a.apply(ma[i].mesh->center()), ma[i].mesh->bounding_radius(),
          place_b.apply(mb[j].mesh->center()), mb[j].mesh->bounding_radius());
      if (gap > margin) {
        out.lower_bound = std::min(out.lower_bound, gap);
        continue;
      }
    }
    // Poses, margin and options were checked by within_margin(Body, ...).
    MarginResult r = detail::within_margin_of_rigid_poses(*ma[i].mesh, place_a, *mb[j].mesh,
                                                          place_b, margin, options, &cache.mesh[k]);
    tested += r.pairs_tested;
    if (r.status == MarginStatus::within) {
      cache.mesh_closest = static_cast<std::int32_t>(k);
      if (a.kind() == Body::Kind::compound) r.piece_a = static_cast<std::int32_t>(i);
      if (b.kind() == Body::Kind::compound) r.piece_b = static_cast<std::int32_t>(j);
      if (a.kind() != Body::Kind::mesh) r.triangle_a = -1;
      if (b.kind() != Body::Kind::mesh) r.triangle_b = -1;
      r.pairs_tested = tested;
      return r;
    }
    undecided = undecided || r.status == MarginStatus::undecided;
    out.lower_bound = std::min(out.lower_bound, r.lower_bound);
    if (r.upper_bound < out.upper_bound) {
      out.upper_bound = r.upper_bound;
      out.point_a = r.point_a;
      out.point_b = r.point_b;
    }
  }
  out.pairs_tested = tested;
  out.status = undecided || !(out.lower_bound > margin) ? MarginStatus::undecided
                                                        : MarginStatus::beyond;
  return out;
}

// A body placed at `pose` within the supported magnitude (its core's
// scale plus its radius, as Body::scale()), or refused by name; the message
// is built out of line, off the path of every query.
[[gnu::noinline, gnu::cold]] void refuse_reach(const Body& body, double reach, const char* name) {
  char message[200];
  std::snprintf(message, sizeof message,
                "within_margin: body %s with radius %g reaches coordinates of magnitude %g, "
                "beyond the supported %g",
                name, body.radius(), reach, kMaxMagnitude);
  throw InvalidInput(message);
}

inline void check_reach(const Body& body, const Pose& pose, const char* name) {
  const double scale = body.mesh() != nullptr ? body.mesh()->scale() + body.radius() : body.scale();
  const double reach = magnitude_bound(pose, scale);
  if (!(reach <= kMaxMagnitude)) [[unlikely]]
    refuse_reach(body, reach, name);
}

}  // namespace

namespace detail {

double sphere_gap_lower_bound(const Vec3& center_a, double radius_a, const Vec3& center_b,
                              double radius_b) {
  const double d = (center_a - center_b).norm();
  const double reach = center_a.cwiseAbs().maxCoeff() + center_b.cwiseAbs().maxCoeff() + d +
                       radius_a + radius_b;
  return d - radius_a - radius_b - kSphereSlackUlps * kUnitRoundoff * reach;
}

MarginResult within_margin_of_rigid_poses(const ConvexPolytope& a, const Pose& pose_a,
                                          const ConvexPolytope& b, const Pose& pose_b,
                                          double margin, const DistanceOptions& options,
                                          DistanceCache& cache) {
  const double magnitude =
      std::max(magnitude_bound(pose_a, a.scale()), magnitude_bound(pose_b, b.scale()));
  if (!(magnitude <= kMaxMagnitude)) {
    char message[200];
    std::snprintf(message, sizeof message,
                  "within_margin: the bodies reach coordinates of magnitude %.3g, beyond the "
                  "supported %.3g",
                  magnitude, kMaxMagnitude);
    throw InvalidInput(message);
  }
  const double band = contact_band(magnitude, options.absolute_tolerance);
  // Far apart: the bounding spheres prove it without the hulls, and then
  // the boxes (a long link's sphere reaches far beyond it).
  const double gap = sphere_gap_lower_bound(pose_a.apply(a.centroid()), a.bounding_radius(),
                                            pose_b.apply(b.centroid()), b.bounding_radius());
  const Pose relative = pose_a.inverse() * pose_b;
  const double box_gap = gap > margin || !a.has_box() || !b.has_box()
                             ? gap
                             : box_gap_lower_bound(a, b, relative, margin, magnitude);
  if (box_gap > margin) {
    MarginResult out;
    out.margin = margin;
    out.lower_bound = box_gap;
    return out;
  }
  if (options.algorithm == Algorithm::hybrid) {
    const DistanceResult r = hybrid_within(a, b, relative, options, band, margin, cache);
    const bool proved_within = r.distance <= margin + band;
    if (proved_within || r.lower_bound > margin) {
      MarginResult out;
      out.status = proved_within ? MarginStatus::within : MarginStatus::beyond;
      out.margin = margin;
      out.lower_bound = r.lower_bound;
      out.upper_bound = r.distance;
      out.point_a = pose_a.apply(r.point_a);
      out.point_b = pose_a.apply(r.point_b);
      out.iterations = r.iterations;
      out.pairs_tested = 1;
      return out;
    }
  }
  // No proof at machine precision or at the cap (or another algorithm):
  // the full query, whose status decides contact, and its bounds.
  DistanceOptions full = options;
  full.penetration = false;
  return from_distance(detail::distance_of_rigid_poses(a, pose_a, b, pose_b, full, &cache),
                       margin, band);
}

}  // namespace detail

namespace {

// The convex query with poses to check (or re-orthonormalize) and a cold
// cache of its own where the caller gave none: out of line, so that the
// tracked query of rigid poses (a planner's every check) pays neither the
// copies of the poses nor a cold cache's construction.
[[gnu::noinline]] MarginResult convex_within_slow(const ConvexPolytope& a, const Pose& pose_a,
                                                  const ConvexPolytope& b, const Pose& pose_b,
                                                  double margin, const DistanceOptions& options,
                                                  DistanceCache* cache) {
  DistanceCache cold;
  return detail::within_margin_of_rigid_poses(a, checked_pose(pose_a, "within_margin: pose_a"), b,
                                              checked_pose(pose_b, "within_margin: pose_b"),
                                              margin, options, cache != nullptr ? *cache : cold);
}

}  // namespace

MarginResult within_margin(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                           const Pose& pose_b, double margin, const DistanceOptions& options,
                           DistanceCache* cache) {
  detail::check_finite_non_negative(margin, "within_margin", "margin");
  detail::check_distance_options(options, "within_margin");
  if (cache == nullptr || !detail::are_rigid(pose_a, pose_b)) [[unlikely]]
    return convex_within_slow(a, pose_a, b, pose_b, margin, options, cache);
  return detail::within_margin_of_rigid_poses(a, pose_a, b, pose_b, margin, options, *cache);
}

MarginResult within_margin(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                           double margin, const DistanceOptions& options, BodyCache* cache) {
  // A cold cache of its own only where the caller gave none: a BodyCache
  // (with its penetration and mesh caches) costs about as much to build and
  // destroy as a tracked query of a mesh pair whose hulls are apart.
  if (cache == nullptr) {
    BodyCache cold;
    return within_margin(a, pose_a, b, pose_b, margin, options, &cold);
  }
  detail::check_finite_non_negative(margin, "within_margin", "margin");
  detail::check_distance_options(options, "within_margin");
  // Both poses in one paired test (as the convex query), no copies when
  // they are rigid.
  if (detail::are_rigid(pose_a, pose_b)) [[likely]]
    return detail::within_margin_of_rigid_poses(a, pose_a, b, pose_b, margin, options, *cache);
  return detail::within_margin_of_rigid_poses(a, checked_pose(pose_a, "within_margin: pose_a"), b,
                                              checked_pose(pose_b, "within_margin: pose_b"),
                                              margin, options, *cache);
}

namespace detail {

MarginResult within_margin_of_rigid_poses(const Body& a, const Pose& pa, const Body& b,
                                          const Pose& pb, double margin,
                                          const DistanceOptions& options, BodyCache& cache) {
  check_reach(a, pa, "a");
  check_reach(b, pb, "b");
  const double radii = a.radius() + b.radius();
  if (a.mesh() != nullptr && b.mesh() != nullptr) [[likely]] {
    // Two mesh bodies (a planner's mesh links): their one pair of meshes,
    // each at its body's pose, straight to the mesh query, without the
    // pieces' mesh list (Body::meshes(), a call_once on every query), the
    // placements and the spheres' test that only pieces need, and the
    // answer returned where it was made. mesh_pairs_within answers the same
    // (one pair: no sphere test, the pose as it is), field by field
    // (Margin.MeshBodiesAnswerAsTheirMeshes).
    // The options the triangle pairs cannot honour are refused, as
    // mesh_pairs_within refuses them.
    if (!detail::mesh_options_plainly_valid(options, detail::MeshOptionUse::triangle_pairs))
      [[unlikely]] detail::check_mesh_options(options, "within_margin",
                                              detail::MeshOptionUse::triangle_pairs);
    if (cache.mesh.size() != 1) [[unlikely]]
      cache.mesh.assign(1, MeshCache{});
    MarginResult r = detail::within_margin_of_rigid_poses(*a.mesh(), pa, *b.mesh(), pb,
                                                          margin + radii, options,
                                                          cache.mesh.data());
    if (r.status == MarginStatus::within) cache.mesh_closest = 0;
    if (radii != 0.0) add_radii(r, margin, a.radius(), b.radius());
    return r;
  }
  const double core_margin = margin + radii;
  MarginResult r;
  if (a.kind() == Body::Kind::convex && b.kind() == Body::Kind::convex) {
    r = detail::within_margin_of_rigid_poses(*a.convex(), pa, *b.convex(), pb, core_margin,
                                             options, cache.convex);
  } else if (a.kind() == Body::Kind::mesh || b.kind() == Body::Kind::mesh) {
    r = mesh_pairs_within(a, pa, b, pb, core_margin, options, cache);
  } else {
    r = within_margin(*a.compound(), pa, *b.compound(), pb, core_margin, options, &cache.compound);
    // A convex body met a compound as its one-piece wrapper: no pieces.
    if (a.kind() == Body::Kind::convex) r.piece_a = -1;
    if (b.kind() == Body::Kind::convex) r.piece_b = -1;
  }
  add_radii(r, margin, a.radius(), b.radius());
  return r;
}

}  // namespace detail

}  // namespace proxima
