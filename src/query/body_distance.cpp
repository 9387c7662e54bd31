// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Bodies of any kind (a convex, compound or mesh core plus a radius) and the
// one distance call between two of them: the cores' query (convex, compound
// or mesh, the convex query taking the depth of overlapping cores or
// pieces itself), the contact normal of rounded bodies whose cores touch,
// and the offset by the radii along the normal
// (proxima/query/body_distance.h says why that is exact).
#include "proxima/query/body_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/accuracy.h"
#include "core/magnitude_limit.h"
#include "proxima/query/distance.h"
#include "query/extended_distance.h"

namespace proxima {
namespace {

// The cores' answer in the world frame as a signed value with its bounds:
// the distance of the cores (>= 0), or minus their penetration depth when
// they overlap.
struct CoreAnswer {
  Status status = Status::separated;
  double value = 0.0;
  double lower = 0.0;
  double upper = 0.0;
  Vec3 point_a = Vec3::Zero();
  Vec3 point_b = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();
  Feature feature_a;
  Feature feature_b;
  int iterations = 0;
  bool second_algorithm = false;
  bool overlap = false;
  std::int32_t piece_a = -1;
  std::int32_t piece_b = -1;
};

// Whether rounded bodies need their cores' penetration query on top of
// the cores' signed answer: when the cores touch without a certified gap.
// The normal of a distance answer is trusted only when the support gap
// along it, the lower bound, is above 0 (the cores are then apart along
// it, and the offset points are the rounded bodies' closest points); below
// that it is a direction of a few roundings, and the penetration query's
// normal (the direction of least overlap, or of contact) is taken.
// Overlapping cores need nothing more: the convex query took their depth
// itself (DistanceOptions::penetration, src/query/signed_distance.cpp).
bool needs_contact_normal(const CoreAnswer& c, double radii) {
  return c.status == Status::touching && radii > 0.0 && !(c.lower > 0.0);
}

// The answer for overlapping cores when the caller skipped the depth
// (DistanceOptions::penetration false), as for a mesh overlap: signed value
// 0 with the certificate [-infinity, 0]; points and normal stay the distance
// query's.
void without_depth(CoreAnswer& c) {
  c.value = 0.0;
  c.lower = -std::numeric_limits<double>::infinity();
  c.upper = 0.0;
  c.overlap = true;
}

// Replaces a touching answer's value, bounds, points, normal and features
// by the penetration query's (in the frame `frame_a`), unless it found the
// cores apart (the two queries disagree within rounding at the band's
// edge): then the distance query's answer stands.
void take_contact_depth(CoreAnswer& c, const PenetrationResult& p, const Pose& frame_a) {
  if (p.status == PenetrationStatus::separated) return;
  c.value = -p.depth;
  c.lower = -p.upper_bound;
  c.upper = -p.lower_bound;
  c.point_a = frame_a.apply(p.point_a);
  c.point_b = frame_a.apply(p.point_b);
  c.normal = frame_a.rotation * p.normal;
  c.feature_a = p.feature_a;
  c.feature_b = p.feature_b;
}

// B's pose in A's frame under the pose contract (the product of two rigid
// poses is rigid to a few u; re-orthonormalized if not).
Pose relative(const Pose& pose_a, const Pose& pose_b) {
  return checked_pose(pose_a.inverse() * pose_b, "distance: relative pose");
}

// The penetration query of two hulls at world poses (its answer in A's
// frame), and with DistanceOptions::extended_precision its depth
// recomputed in double-double along its face of A - B, as distance() does
// for two polytopes (query/extended_distance.h).
PenetrationResult depth_of(const ConvexPolytope& a, const Pose& pose_a, const ConvexPolytope& b,
                           const Pose& pose_b, PenetrationCache& cache,
                           const DistanceOptions& options) {
  PenetrationResult p = penetration_depth(a, b, relative(pose_a, pose_b), cache);
  if (!options.extended_precision || p.status != PenetrationStatus::intersecting) return p;
  DistanceResult r;
  r.status = Status::intersecting;
  r.depth = p.depth;
  r.depth_lower_bound = p.lower_bound;
  r.depth_upper_bound = p.upper_bound;
  r.normal = p.normal;
  r.feature_a = p.feature_a;
  r.feature_b = p.feature_b;
  if (detail::refine_depth_extended(a, pose_a, b, pose_b, options, r)) {
    p.depth = r.depth;
    p.lower_bound = r.depth_lower_bound;
    p.normal = r.normal;
  }
  p.upper_bound = r.depth_upper_bound;
  return p;
}

// The pieces (convex bodies, compound pieces or meshes) that gave the
// answer, placed: the accuracy standard's R is theirs, as for the compound
// and mesh queries. `scale` is the largest coordinate magnitude of
// `vertices` (ConvexPolytope::scale, TriangleMesh::scale).
struct Placed {
  std::span<const Vec3> vertices;
  double scale;
  Pose pose;
};
template <class Shape>
Placed placed(const Shape& shape, const Pose& pose) {
  return {shape.vertices(), shape.scale(), pose};
}

// The status of the rounded bodies from their signed value s: the contact
// band of the rounded pieces (core R plus radius; the largest coordinate of
// a ball of radius r about x is |x|_inf + r). First from the O(1) bound on
// R; a value inside that band is decided with the exact R (O(N), only near
// contact).
Status rounded_status(double s, const Placed& a, double ra, const Placed& b, double rb,
                      const DistanceOptions& options) {
  const double bound =
      std::max(magnitude_bound(a.pose, a.scale) + ra, magnitude_bound(b.pose, b.scale) + rb);
  double band = contact_band(bound, options.absolute_tolerance);
  if (std::abs(s) <= band) {
    band = contact_band(std::max(detail::placed_magnitude(a.vertices, a.pose) + ra,
                                 detail::placed_magnitude(b.vertices, b.pose) + rb),
                        options.absolute_tolerance);
  }
  return s > band ? Status::separated : s >= -band ? Status::touching : Status::intersecting;
}

// The rounded bodies' answer from the cores' one. `rounded` gives the
// status of the rounded bodies from their signed value (used only when a
// radius is not 0).
template <class RoundedStatus>
BodyResult offset(const CoreAnswer& c, const Body& a, const Body& b, RoundedStatus rounded) {
  const double ra = a.radius();
  const double rb = b.radius();
  const double radii = ra + rb;
  BodyResult r;
  const double value = c.value - radii;
  const double lower = c.lower - radii;
  const double upper = c.upper - radii;
  if (c.status == Status::iteration_cap || radii == 0.0) {
    r.status = c.status;
  } else {
    r.status = rounded(value);
  }
  // The signed values in DistanceResult's fields, so that its
  // signed_distance(), signed_lower_bound() and signed_upper_bound() give
  // them: distance - depth, lower_bound - depth_upper_bound and
  // distance - depth_lower_bound.
  if (value >= 0.0) {
    r.distance = value;
    r.depth = 0.0;
    r.depth_lower_bound = value - upper;  // 0 when the upper bound is the distance
  } else {
    r.distance = 0.0;
    r.depth = -value;
    r.depth_lower_bound = -upper;  // negative when the overlap is not certified
  }
  r.lower_bound = std::max(lower, 0.0);
  r.depth_upper_bound = r.lower_bound - lower;
  r.normal = c.normal;
  r.point_a = c.point_a + ra * c.normal;
  r.point_b = c.point_b - rb * c.normal;
  r.feature_a = c.feature_a;
  r.feature_b = c.feature_b;
  r.iterations = c.iterations;
  r.second_algorithm = c.second_algorithm;
  r.piece_a = c.piece_a;
  r.piece_b = c.piece_b;
  r.intersecting = c.overlap;
  r.approximation_error = a.approximation_error() + b.approximation_error();
  return r;
}

// The cores' answer from the signed answer of a convex query, or of a
// compound search (the least over piece pairs of the convex query's): the
// signed distance and its certificate (DistanceResult::signed_lower_bound
// and signed_upper_bound). An overlap's depth was taken by the convex
// query itself (DistanceOptions::penetration, src/query/signed_distance.cpp:
// tracked through its DistanceCache, a touching answer checked for an
// overlap that the contact classification could not certify); without the
// depth the certificate is [-infinity, 0] (as without_depth's), and an
// iteration cap's lower bound leaves room for an overlap as deep as the
// bounding balls allow.
CoreAnswer from_signed(const DistanceResult& r) {
  CoreAnswer c;
  c.status = r.status;
  c.value = r.signed_distance();
  c.lower = r.signed_lower_bound();
  c.upper = r.signed_upper_bound();
  c.point_a = r.point_a;
  c.point_b = r.point_b;
  c.normal = r.normal;
  c.feature_a = r.feature_a;
  c.feature_b = r.feature_b;
  c.iterations = r.iterations;
  c.second_algorithm = r.second_algorithm;
  c.overlap = r.status == Status::intersecting;
  return c;
}

// Two convex cores: the convex query with its own depth, and for rounded
// bodies whose cores touch, the contact normal (needs_contact_normal),
// tracked through BodyCache::penetration.
BodyResult convex_pair(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                       const DistanceOptions& options, BodyCache& cache) {
  const ConvexPolytope& ca = *a.convex();
  const ConvexPolytope& cb = *b.convex();
  CoreAnswer c = from_signed(
      detail::distance_of_rigid_poses(ca, pose_a, cb, pose_b, options, &cache.convex));
  if (options.penetration && needs_contact_normal(c, a.radius() + b.radius()))
    take_contact_depth(c, depth_of(ca, pose_a, cb, pose_b, cache.penetration, options), pose_a);
  return offset(c, a, b, [&](double value) {
    return rounded_status(value, placed(ca, pose_a), a.radius(), placed(cb, pose_b), b.radius(),
                          options);
  });
}

// Two compounds (or a compound and a convex body, its one-piece wrapper):
// the compound search, which with the depth finds the deepest overlapping
// piece pair itself (the least signed distance over piece pairs, by branch
// and bound on the pieces' spheres, each pair's convex query taking its
// own depth and tracked through the near list of BodyCache::compound).
// Rounded bodies whose best pieces touch take that pair's contact normal
// (needs_contact_normal), tracked through BodyCache::penetration as a
// convex pair's.
BodyResult compound_pair(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                         const DistanceOptions& options, BodyCache& cache) {
  const std::shared_ptr<const CompoundBody> hold_a = a.compound();
  const std::shared_ptr<const CompoundBody> hold_b = b.compound();
  const CompoundBody& ca = *hold_a;
  const CompoundBody& cb = *hold_b;
  const CompoundResult cr = distance(ca, pose_a, cb, pose_b, options, &cache.compound);
  CoreAnswer c = from_signed(cr);
  c.piece_a = cr.piece_a;
  c.piece_b = cr.piece_b;
  const CompoundPiece& piece_a = ca.piece(c.piece_a);
  const CompoundPiece& piece_b = cb.piece(c.piece_b);
  if (options.penetration && needs_contact_normal(c, a.radius() + b.radius())) {
    // The penetration cache keeps the pair of polytopes it was filled for
    // and starts over for another: the best pieces may change.
    const Pose place_a = pose_a * piece_a.pose;
    take_contact_depth(c,
                       depth_of(*piece_a.polytope, place_a, *piece_b.polytope,
                                pose_b * piece_b.pose, cache.penetration, options),
                       place_a);
  }
  // The pieces are placed only for a radius (offset calls this only then).
  BodyResult r = offset(c, a, b, [&](double value) {
    return rounded_status(value, placed(*piece_a.polytope, pose_a * piece_a.pose), a.radius(),
                          placed(*piece_b.polytope, pose_b * piece_b.pose), b.radius(), options);
  });
  // A convex body met a compound as its one-piece wrapper: it has no pieces.
  if (a.kind() == Body::Kind::convex) r.piece_a = -1;
  if (b.kind() == Body::Kind::convex) r.piece_b = -1;
  return r;
}

// The magnitude a placed piece center is rounded against: the
// translations of both poses plus the local center.
double placed_size(const Pose& pose, const Body::MeshOfPiece& m) {
  return pose.translation.cwiseAbs().maxCoeff() + m.pose.translation.cwiseAbs().maxCoeff() +
         m.mesh->center().cwiseAbs().maxCoeff();
}

// A pair with a mesh on at least one side: every pair of meshes of
// Body::meshes() (one per convex piece, one for a mesh), each tracked by its
// own MeshCache, the closest (or a crossing) pair kept. A pair is skipped
// when a lower bound on its distance, from the pieces' bounding spheres, is
// above the best distance found: only slower if the bound were loose, never
// wrong.
BodyResult mesh_pair(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                       const DistanceOptions& options, BodyCache& cache) {
  const std::vector<Body::MeshOfPiece>& ma = a.meshes();
  const std::vector<Body::MeshOfPiece>& mb = b.meshes();
  const std::size_t pairs = ma.size() * mb.size();
  if (cache.mesh.size() != pairs) cache.mesh.assign(pairs, MeshCache{});
  // Each piece's placed bounding sphere: the root box's center and half
  // diagonal, placed.
  const auto sphere = [](const Body::MeshOfPiece& m, const Pose& pose) {
    return std::pair<Vec3, double>((pose * m.pose).apply(m.mesh->center()),
                                   m.mesh->bounding_radius());
  };
  MeshResult best;
  bool have = false;
  std::size_t best_i = 0, best_j = 0;
  // The last answer's pair first: its distance prunes the others.
  const std::size_t first =
      cache.mesh_closest >= 0 && static_cast<std::size_t>(cache.mesh_closest) < pairs
          ? static_cast<std::size_t>(cache.mesh_closest)
          : 0;
  for (std::size_t n = 0; n < pairs; ++n) {
    const std::size_t k = n == 0 ? first : n <= first ? n - 1 : n;
    const std::size_t i = k / mb.size();
    const std::size_t j = k % mb.size();
    const Pose place_a = pose_a * ma[i].pose;
    const Pose place_b = pose_b * mb[j].pose;
    if (have && pairs > 1) {
      const auto [ca, ra] = sphere(ma[i], pose_a);
      const auto [cb, rb] = sphere(mb[j], pose_b);
      const double center_distance = (ca - cb).norm();
      const double gap = center_distance - ra - rb;
      // The placed centers are rounded against the poses' translations and
      // the local centers (placed_size), the norm and subtractions against
      // the center distance and the radii: the shared prune slack of their
      // sum keeps a pruned pair farther than the best in exact arithmetic
      // (BodyMesh.CompoundAgainstAMeshIsTheNearestPiece).
      const double slack = detail::prune_slack(placed_size(pose_a, ma[i]) + placed_size(pose_b, mb[j]) +
                                               center_distance + ra + rb);
      if (gap - slack > best.distance) continue;
    }
    MeshResult r = distance(*ma[i].mesh, place_a, *mb[j].mesh, place_b, options, &cache.mesh[k]);
    const bool better = !have ||
                        (r.status == Status::intersecting && best.status != Status::intersecting) ||
                        (best.status != Status::intersecting && r.distance < best.distance);
    if (better) {
      if (have) r.lower_bound = std::min(r.lower_bound, best.lower_bound);
      best = r;
      best_i = i;
      best_j = j;
      have = true;
    } else {
      best.lower_bound = std::min(best.lower_bound, r.lower_bound);
    }
  }
  cache.mesh_closest = static_cast<std::int32_t>(best_i * mb.size() + best_j);
  CoreAnswer c;
  c.status = best.status;
  c.point_a = best.point_a;
  c.point_b = best.point_b;
  c.normal = best.normal;
  c.feature_a = best.feature_a;
  c.feature_b = best.feature_b;
  c.iterations = best.iterations;
  if (best.status == Status::intersecting) {
    without_depth(c);
  } else {
    c.value = best.distance;
    c.lower = best.lower_bound;
    c.upper = best.distance;
  }
  // A convex core's features in its hull's terms: mesh vertex ids are hull
  // vertex ids; a triangle's face is the hull face it came from.
  const auto hull_face = [](Feature& f, const Body::MeshOfPiece& m) {
    if (!m.faces.empty() && f.face >= 0) f.face = m.faces[static_cast<std::size_t>(f.face)];
  };
  hull_face(c.feature_a, ma[best_i]);
  hull_face(c.feature_b, mb[best_j]);
  if (a.kind() == Body::Kind::compound) c.piece_a = static_cast<std::int32_t>(best_i);
  if (b.kind() == Body::Kind::compound) c.piece_b = static_cast<std::int32_t>(best_j);
  const Pose place_a = pose_a * ma[best_i].pose;
  const Pose place_b = pose_b * mb[best_j].pose;
  BodyResult r = offset(c, a, b, [&](double value) {
    return rounded_status(value, placed(*ma[best_i].mesh, place_a), a.radius(),
                          placed(*mb[best_j].mesh, place_b), b.radius(), options);
  });
  if (a.kind() == Body::Kind::mesh) r.triangle_a = best.triangle_a;
  if (b.kind() == Body::Kind::mesh) r.triangle_b = best.triangle_b;
  return r;
}

}  // namespace

BodyResult distance(const Body& a, const Pose& pose_a, const Body& b, const Pose& pose_b,
                      const DistanceOptions& options, BodyCache* cache) {
  // One paired test in the common case; the named refusal (or the
  // re-orthonormalized poses) only for a pose that fails it.
  if (!detail::are_rigid(pose_a, pose_b)) [[unlikely]] {
    return detail::distance_of_rigid_poses(a, checked_pose(pose_a, "distance: pose_a"), b,
                                           checked_pose(pose_b, "distance: pose_b"), options,
                                           cache);
  }
  return detail::distance_of_rigid_poses(a, pose_a, b, pose_b, options, cache);
}

BodyResult distance(const Body& a, const RigidPose& pose_a, const Body& b, const RigidPose& pose_b,
                    const DistanceOptions& options, BodyCache* cache) {
  // Under the contract by construction (RigidPose).
  return detail::distance_of_rigid_poses(a, pose_a.pose(), b, pose_b.pose(), options, cache);
}

namespace detail {

BodyResult distance_of_rigid_poses(const Body& a, const Pose& pa, const Body& b, const Pose& pb,
                                   const DistanceOptions& options, BodyCache* cache) {
  BodyCache cold;
  BodyCache& c = cache != nullptr ? *cache : cold;
  // The cores' query refuses coordinates beyond kMaxMagnitude; radii that
  // take the rounded bodies there are refused too (their sum, the signed
  // distance or the offset points could overflow to infinity).
  for (const auto& [body, pose, name] : {std::tuple(&a, &pa, "a"), std::tuple(&b, &pb, "b")}) {
    const double reach = magnitude_bound(*pose, body->scale());
    if (!(reach <= kMaxMagnitude)) {
      char radius[64];
      std::snprintf(radius, sizeof radius, "%.3g", body->radius());
      throw InvalidInput(detail::beyond_magnitude(std::string("distance: body ") + name, reach,
                                                  std::string("with its radius ") + radius));
    }
  }
  // The depth (DistanceOptions::penetration) is the cores' queries' own:
  // the convex query takes it for a convex pair and for each piece pair of
  // a compound search; a mesh query has none and ignores the option.
  if (a.kind() == Body::Kind::convex && b.kind() == Body::Kind::convex) {
    return convex_pair(a, pa, b, pb, options, c);
  }
  if (a.kind() == Body::Kind::mesh || b.kind() == Body::Kind::mesh) {
    return mesh_pair(a, pa, b, pb, options, c);
  }
  return compound_pair(a, pa, b, pb, options, c);
}

}  // namespace detail
}  // namespace proxima
