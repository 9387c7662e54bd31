// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// time_of_impact: conservative advancement on the tracked distance query
// (proxima/motion/time_of_impact.h). The motions and their checks are in
// sweep.h, the advancement of two convex hulls in advancement.h (its
// closing bounds in closing_bounds.h), the branch and bound over the
// pieces of compounds and meshes in piece_advancement.h.
#include "proxima/motion/time_of_impact.h"

#include "advancement.h"
#include "core/accuracy.h"
#include "piece_advancement.h"
#include "proxima/query/body_distance.h"
#include "sweep.h"
#include "time_of_impact.h"

namespace proxima {

using detail::toi::advance_hulls;
using detail::toi::advance_pieces;
using detail::toi::body_size;
using detail::toi::check_closing_speed;
using detail::toi::checked_sweep;
using detail::toi::MovingHull;
using detail::toi::Sweep;

ImpactResult time_of_impact(const ConvexPolytope& a, const Motion& motion_a,
                            const ConvexPolytope& b, const Motion& motion_b,
                            const ImpactOptions& options, DistanceCache* cache) {
  detail::check_impact_options(options, "time_of_impact");
  const Sweep ma = checked_sweep(motion_a, a.scale(), "time_of_impact: motion_a");
  const Sweep mb = checked_sweep(motion_b, b.scale(), "time_of_impact: motion_b");
  check_closing_speed(ma, a.scale(), mb, b.scale());
  const double tolerance = options.tolerance > 0.0
                               ? options.tolerance
                               : detail::kDefaultImpactTolerance *
                                     (a.bounding_radius() + b.bounding_radius());
  DistanceCache local;
  return advance_hulls(MovingHull(a, ma), MovingHull(b, mb), options, tolerance,
                       cache != nullptr ? *cache : local);
}

ImpactResult time_of_impact(const Body& a, const Motion& motion_a, const Body& b,
                            const Motion& motion_b, const ImpactOptions& options,
                            BodyCache* cache) {
  detail::check_impact_options(options, "time_of_impact");
  // The answer at t of a pair with a mesh is the mesh query's, which cannot
  // honour every distance option: refused before any step.
  if (a.kind() == Body::Kind::mesh || b.kind() == Body::Kind::mesh) {
    detail::check_mesh_options(options.distance, "time_of_impact",
                               detail::MeshOptionUse::triangle_pairs, "options.distance");
  }
  BodyCache local;
  BodyCache& c = cache != nullptr ? *cache : local;
  const double ra = a.radius();
  const double rb = b.radius();
  const double default_tolerance = detail::kDefaultImpactTolerance * (body_size(a) + body_size(b));
  if (a.kind() == Body::Kind::convex && b.kind() == Body::Kind::convex) {
    // The cores, with the radii added to the target; then the answer at t
    // moved onto the rounded surfaces.
    ImpactOptions cores = options;
    cores.target_separation += ra + rb;
    if (cores.tolerance == 0.0) cores.tolerance = default_tolerance;
    ImpactResult r = time_of_impact(*a.convex(), motion_a, *b.convex(), motion_b, cores, &c.convex);
    r.at_t = distance(a, r.pose_a, b, r.pose_b, options.distance, &c);
    return r;
  }

  const Sweep ma = checked_sweep(motion_a, a.scale(), "time_of_impact: motion_a");
  const Sweep mb = checked_sweep(motion_b, b.scale(), "time_of_impact: motion_b");
  check_closing_speed(ma, a.scale(), mb, b.scale());
  const double tolerance = options.tolerance > 0.0 ? options.tolerance : default_tolerance;
  // A closed mesh has an inside: a body that starts there overlaps it
  // without touching a triangle. Otherwise the surfaces first come within
  // the target where two pieces do (a body outside a closed mesh enters
  // it only through a triangle), which the branch and bound finds.
  const auto closed = [](const Body& body) {
    return body.kind() == Body::Kind::mesh && body.mesh()->is_closed();
  };
  if (closed(a) || closed(b)) {
    const Pose pa = ma.at(0.0);
    const Pose pb = mb.at(0.0);
    const BodyResult at = distance(a, pa, b, pb, options.distance, &c);
    const double target = options.target_separation;
    if (at.status == Status::intersecting || at.signed_distance() < target) {
      ImpactResult out;
      out.status = ImpactStatus::intersecting;
      out.t = 0.0;
      out.pose_a = pa;
      out.pose_b = pb;
      out.at_t = at;
      out.piece_a = a.kind() == Body::Kind::mesh ? at.triangle_a : at.piece_a;
      out.piece_b = b.kind() == Body::Kind::mesh ? at.triangle_b : at.piece_b;
      out.iterations = 1;
      return out;
    }
  }
  return advance_pieces(a, ma, b, mb, options, tolerance, c);
}

}  // namespace proxima
