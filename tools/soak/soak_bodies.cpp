// proxima's soak: rounded bodies, compounds and meshes against their slow
// twins, and time of impact against dense sampling.
// SPDX-License-Identifier: BSD-3-Clause
#include <algorithm>
#include <cmath>

#include "soak_bodies.h"

namespace proxima::soak {

namespace {

double pair_magnitude(const std::vector<Vec3>& a, const Pose& pose_a, const std::vector<Vec3>& b,
                      const Pose& pose_b, double local) {
  return std::max({placed_magnitude(a, pose_a), placed_magnitude(b, pose_b), local,
                   pose_a.translation.cwiseAbs().maxCoeff(),
                   pose_b.translation.cwiseAbs().maxCoeff()});
}

}  // namespace

// A rounded pair answers the cores' signed distance minus the radii, exactly
// up to the standard (the rounding is an offset along the normal).
void rounded_episode(Context& c) {
  const ConvexPair pair = draw_convex_pair(c.draw);
  static constexpr double kRadiiA[] = {0.0, 1e-12, 1e-3, 0.3, 2.0};
  static constexpr double kRadiiB[] = {0.0, 1e-9, 0.1, 1.0};
  const double ra = kRadiiA[c.draw.integer(0, 5)] * pair.scale;
  const double rb = kRadiiB[c.draw.integer(0, 4)] * pair.scale;
  const Body a(pair.a, ra), b(pair.b, rb);
  const int count = c.draw.integer(20, 120);
  const Pose identity;
  for (const Pose& pose_b : c.draw.poses_about(count, pair.reach + ra + rb)) {
    const BodyResult r = distance(a, identity, b, pose_b);
    const DistanceResult core = distance(*pair.a, identity, *pair.b, pose_b);
    c.ledger.queries(2);
    const double magnitude =
        pair_magnitude(pair.points_a, identity, pair.points_b, pose_b, pair.scale) + ra + rb;
    const double world = std::max(placed_magnitude(pair.points_a, identity),
                                  placed_magnitude(pair.points_b, pose_b)) +
                         ra + rb;
    const std::string line = query_line(pair.points_a, identity, ra, pair.points_b, pose_b, rb);
    check_answer(c, "rounded", r, magnitude, world, line);
    const double expected = core.signed_distance() - ra - rb;
    c.ledger.checked("rounded:equals_core_minus_radii");
    if (std::abs(r.signed_distance() - expected) >
        2 * (1e-12 * std::abs(expected) + 64 * kUnit * magnitude) + 1e-12 * (ra + rb))
      c.ledger.violation("rounded:equals_core_minus_radii",
                         "\"got\":" + number(r.signed_distance()) + ",\"expected\":" +
                             number(expected) + "," + line);
  }
}

// The compound traversal (tracked through its cache) against every piece
// pair.
void compound_episode(Context& c) {
  std::vector<std::vector<Vec3>> pieces_a, pieces_b;
  const int na = c.draw.integer(1, 5), nb = c.draw.integer(1, 4);
  double spread = 0;
  for (int i = 0; i < na; ++i) pieces_a.push_back(c.draw.points());
  for (const auto& p : pieces_a) spread = std::max(spread, local_magnitude(p));
  for (auto& p : pieces_a) {
    const Vec3 shift = c.draw.normal3() * spread;
    for (Vec3& v : p) v += shift;
  }
  for (int i = 0; i < nb; ++i) pieces_b.push_back(c.draw.points());
  const CompoundBody a = CompoundBody::from_point_sets(pieces_a);
  const CompoundBody b = CompoundBody::from_point_sets(pieces_b);
  std::vector<Vec3> all_a, all_b;
  for (const auto& p : pieces_a) all_a.insert(all_a.end(), p.begin(), p.end());
  for (const auto& p : pieces_b) all_b.insert(all_b.end(), p.begin(), p.end());
  const double scale = std::max(local_magnitude(all_a), local_magnitude(all_b));
  CompoundCache cache;
  const Pose identity;
  for (const Pose& pose_b : c.draw.poses_about(40, 2 * scale)) {
    const CompoundResult r = distance(a, identity, b, pose_b, {}, &cache);
    const CompoundResult slow = distance_all_pairs(a, identity, b, pose_b);
    c.ledger.queries(2);
    const double magnitude = pair_magnitude(all_a, identity, all_b, pose_b, scale);
    const double band = 64 * kUnit * magnitude;
    // No query line: the JSON form has no compounds; the seed and episode
    // replay it.
    const std::string where = "\"pose_b\":{\"rotation\":" + vec(pose_b.rotation.row(0)) + "," +
                              vec(pose_b.rotation.row(1)) + "," + vec(pose_b.rotation.row(2)) +
                              ",\"translation\":" + vec(pose_b.translation) + "}";
    c.ledger.checked("compound:finite");
    if (!std::isfinite(r.distance) || !std::isfinite(r.signed_distance())) {
      c.ledger.violation("compound:finite", "\"distance\":" + number(r.distance) + "," + where);
      continue;
    }
    c.ledger.checked("compound:equals_all_pairs");
    if (std::abs(r.distance - slow.distance) > 2 * (1e-12 * slow.distance + band))
      c.ledger.violation("compound:equals_all_pairs", "\"got\":" + number(r.distance) +
                                                          ",\"all_pairs\":" + number(slow.distance) +
                                                          ",\"band\":" + number(band) + "," + where);
    c.ledger.checked("compound:certificate");
    if (r.signed_lower_bound() > r.signed_distance() + band ||
        r.signed_distance() > r.signed_upper_bound() + band)
      c.ledger.violation("compound:certificate",
                         "\"bounds\":[" + number(r.signed_lower_bound()) + "," +
                             number(r.signed_upper_bound()) + "],\"signed_distance\":" +
                             number(r.signed_distance()) + "," + where);
  }
}

// A closed mesh of a hull's triangles against the hull: the same distance
// when separated, intersecting when the hull overlaps.
void mesh_episode(Context& c) {
  const ConvexPair pair = draw_convex_pair(c.draw);
  if (pair.a->dimension() < 3) return;
  const auto triangles = pair.a->triangles();
  const std::vector<Vec3> vertices(pair.a->vertices().begin(), pair.a->vertices().end());
  const TriangleMesh mesh(vertices, triangles);
  c.ledger.checked("mesh:hull_triangulation_closed");
  if (!mesh.is_closed()) {
    c.ledger.violation("mesh:hull_triangulation_closed",
                       "\"vertices\":" + std::to_string(vertices.size()));
    return;
  }
  const int count = c.draw.integer(10, 60);
  const Pose identity;
  for (const Pose& pose_b : c.draw.poses_about(count, pair.reach)) {
    const MeshResult r = distance(mesh, identity, *pair.b, pose_b);
    const DistanceResult hull = distance(*pair.a, identity, *pair.b, pose_b);
    c.ledger.queries(2);
    const double magnitude = pair_magnitude(vertices, identity, pair.points_b, pose_b, pair.scale);
    const double world = std::max(placed_magnitude(vertices, identity),
                                  placed_magnitude(pair.points_b, pose_b));
    const double band = 64 * kUnit * magnitude;
    std::string line = query_line(vertices, identity, 0, pair.points_b, pose_b, 0);
    // The mesh form of A: its triangles beside its vertices.
    std::string faces = ",\"triangles\":[";
    for (std::size_t i = 0; i < triangles.size(); ++i)
      faces += (i ? ",[" : "[") + std::to_string(triangles[i][0]) + "," +
               std::to_string(triangles[i][1]) + "," + std::to_string(triangles[i][2]) + "]";
    line.insert(line.find(",\"rotation\""), faces + "]");
    check_answer(c, "mesh", r, magnitude, world, line);
    if (hull.signed_distance() > 2 * band) {
      c.ledger.checked("mesh:equals_hull_when_separated");
      if (std::abs(r.distance - hull.distance) > 2 * (1e-12 * hull.distance + band))
        c.ledger.violation("mesh:equals_hull_when_separated", "\"mesh\":" + number(r.distance) +
                                                                  ",\"hull\":" +
                                                                  number(hull.distance) + "," + line);
    }
    if (hull.signed_distance() < -2 * band) {
      c.ledger.checked("mesh:closed_overlap_intersecting");
      if (r.status != Status::intersecting)
        c.ledger.violation("mesh:closed_overlap_intersecting",
                           "\"status\":\"" + std::string(to_string(r.status)) + "\",\"hull\":" +
                               number(hull.signed_distance()) + "," + line);
    }
  }
}

// Time of impact never after a contact that dense sampling finds, and at
// the reported t the distance within the tolerance of the target.
void toi_episode(Context& c) {
  const ConvexPair pair = draw_convex_pair(c.draw);
  const double reach = pair.reach;
  const Vec3 d0 = c.draw.unit3();
  const Pose start_b(c.draw.rotation(), Vec3(d0 * reach * c.draw.uniform(1.0, 4.0)));
  Pose end_b(c.draw.rotation(),
             Vec3(-d0 * reach * c.draw.uniform(0, 4) + c.draw.normal3() * reach * 0.3));
  if (c.draw.chance(0.3)) end_b.rotation = start_b.rotation;
  const bool by_velocity = c.draw.integer(0, 3) != 0;
  Motion motion_b(start_b, end_b);
  if (by_velocity)
    motion_b = Motion::from_velocity(start_b, Vec3(end_b.translation - start_b.translation),
                                     Vec3(c.draw.normal3() * std::pow(10.0, c.draw.uniform(-3, 2))));
  Motion motion_a = Motion::fixed(Pose());
  if (c.draw.chance(0.3))
    motion_a = Motion::from_velocity(Pose(), Vec3(c.draw.normal3() * reach), c.draw.normal3());
  static constexpr double kTargets[] = {0.0, 0.0, 1e-3, 0.1};
  static constexpr double kTolerances[] = {0.0, 1e-9, 1e-4, 1e-2};
  ImpactOptions options;
  options.target_separation = kTargets[c.draw.integer(0, 4)] * reach;
  options.tolerance = kTolerances[c.draw.integer(0, 4)] * reach;
  const double ra = c.draw.chance(1.0 / 3.0) ? 0.1 * local_magnitude(pair.points_a) : 0.0;
  const Body a(pair.a, ra), b(pair.b);
  std::string what = "\"target\":" + number(options.target_separation) +
                     ",\"tolerance\":" + number(options.tolerance) + ",\"radius_a\":" + number(ra);
  ImpactResult r;
  c.ledger.checked("toi:no_exception");
  try {
    r = time_of_impact(a, motion_a, b, motion_b, options);
  } catch (const std::exception& e) {
    c.ledger.violation("toi:no_exception", what + ",\"error\":\"" + std::string(e.what()) + "\"");
    return;
  }
  c.ledger.queries(static_cast<std::uint64_t>(r.iterations) + 1);
  what += ",\"status\":\"" + std::string(to_string(r.status)) + "\",\"t\":" + number(r.t);
  c.ledger.checked("toi:finite");
  if (!std::isfinite(r.t) || !std::isfinite(r.at_t.distance)) {
    c.ledger.violation("toi:finite", what);
    return;
  }
  constexpr int kSamples = 400;
  double magnitude = std::max(pair.scale, 0.0) + ra;
  std::vector<double> sampled(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double t = static_cast<double>(i) / (kSamples - 1);
    const Pose pa = motion_a.at(t), pb = motion_b.at(t);
    sampled[static_cast<std::size_t>(i)] = distance(*pair.a, pa, *pair.b, pb).signed_distance() - ra;
    magnitude = std::max(magnitude, pair.scale + ra + pa.translation.cwiseAbs().maxCoeff() +
                                        pb.translation.cwiseAbs().maxCoeff());
  }
  c.ledger.queries(kSamples);
  const double band = 64 * kUnit * magnitude;
  const double slack = 4 * band + 1e-9 * reach;
  for (int i = 0; i < kSamples; ++i) {
    if (sampled[static_cast<std::size_t>(i)] > options.target_separation - slack) continue;
    const double t_sample = static_cast<double>(i) / (kSamples - 1);
    c.ledger.checked("toi:not_after_sampled_contact");
    if (r.t > t_sample + 1e-12 || r.status == ImpactStatus::separated)
      c.ledger.violation("toi:not_after_sampled_contact",
                         what + ",\"t_sample\":" + number(t_sample) + ",\"sampled\":" +
                             number(sampled[static_cast<std::size_t>(i)]));
    break;
  }
  if (r.status == ImpactStatus::contact) {
    const double effective =
        options.tolerance > 0 ? options.tolerance
                              : 2e-6 * std::max(pair.a->bounding_radius(), pair.b->bounding_radius());
    const double at_t = r.at_t.signed_distance();
    c.ledger.checked("toi:contact_within_tolerance");
    if (at_t < options.target_separation - slack ||
        at_t > options.target_separation + 1.01 * effective + slack)
      c.ledger.violation("toi:contact_within_tolerance", what + ",\"at_t\":" + number(at_t));
  }
  c.ledger.checked("toi:intersecting_at_0");
  if (r.status == ImpactStatus::intersecting && r.t != 0)
    c.ledger.violation("toi:intersecting_at_0", what);
}

}  // namespace proxima::soak
