// proxima benchmarks: FCL 0.7 as a peer.
// SPDX-License-Identifier: BSD-3-Clause
//
// Why these settings (the list itself is at the top of fcl_peer.h):
// - fcl::Convexd, not a BVH mesh: it is FCL's convex-polytope type, the one
//   a user picks for this problem, and both GJK solvers run on it directly.
//   Built from proxima's hull (same vertices, same face polygons, FCL's face
//   list [n, i0, ..., i(n-1), n, ...]), so both libraries see the same body.
//   With more than 32 vertices FCL's support search walks the vertex
//   adjacency it derives from the faces (Convex::findExtremeVertex).
// - The geometry-level fcl::distance (no CollisionObject): no broad-phase
//   bookkeeping and no AABB update inside the timed work.
// - FCL's default request except enable_nearest_points: the closest points
//   are part of the answer the experiments check. distance_tolerance stays at
//   FCL's default 1e-6 (absolute): users get that unless they tune it, and at
//   the unit scale of the timing experiments it lets FCL stop earlier than
//   proxima's relative 1e-12, which favours FCL in the timings. At other
//   scales it means nothing (bodies of 1e-23 are all within 1e-6), so the
//   libccd solver also runs with the same tolerance relative to the query's
//   scale (FclSolver::libccd_scaled): its row measures the algorithm.
// - Debian's libccd 2.1 has no separation-distance function of its own;
//   FCL's GST_LIBCCD solver (GJK on libccd's simplex code) is the libccd GJK
//   that users get, so it stands for libccd here.
// - Tracking: FCL 0.7's DistanceRequest has no cached-guess fields (only
//   CollisionRequest has enable_cached_gjk_guess); for distance the cache
//   lives in the solver (GJKSolver_indep::enableCachedGuess; every
//   shapeDistance call starts GJK from cached_guess and stores the guess of
//   its final simplex there). So the tracking mode keeps one
//   GJKSolver_indep for the sequence (gjk_tolerance set from the request,
//   as fcl::distance does) and calls its shapeDistance for the Convex pair:
//   the very call fcl::distance makes after dispatching on the shape types.
//   fcl::distance can take such a solver only through its templated
//   overload, which instantiates FCL's whole distance-function table for
//   that solver type in this file (50 s of compile time instead of 4 s, and
//   far more under ASan). Skipping the dispatch favours FCL's tracking mode
//   by its cost (type switch, traversal node, result update): measured at
//   30 to 80 ns of about 1.1 us per cube-cube query, same answers.
#include "peers/fcl_peer.h"

#include <fcl/narrowphase/detail/gjk_solver_indep.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "peers/fcl_convex.h"

namespace proxima::bench {

struct FclPeer::Impl {
  FclSolver solver;
  std::shared_ptr<fcl::Convexd> a;
  std::shared_ptr<fcl::Convexd> b;
  fcl::DistanceRequestd request;
  // The tracking state of GST_INDEP: FCL keeps the cached guess in the
  // solver (mutable members), so the solver object is the cache.
  fcl::detail::GJKSolver_indep<double> tracking_solver;
  std::vector<fcl::Transform3d> tf_a;
  std::vector<fcl::Transform3d> tf_b;
  // libccd_scaled: the largest vertex norm of each body (local frame) and
  // the distance tolerance of each pose pair.
  double radius_a = 0.0;
  double radius_b = 0.0;
  std::vector<double> tolerance;

  Impl(const ConvexPolytope& pa, const ConvexPolytope& pb, FclSolver s)
      : solver(s), a(fcl_convex(pa, "FclPeer: body a")), b(fcl_convex(pb, "FclPeer: body b")) {
    request.enable_nearest_points = true;
    request.gjk_solver_type = s == FclSolver::indep ? fcl::GST_INDEP : fcl::GST_LIBCCD;
    request.enable_signed_distance = s == FclSolver::libccd_signed;
    for (const Vec3& v : pa.vertices()) radius_a = std::max(radius_a, v.norm());
    for (const Vec3& v : pb.vertices()) radius_b = std::max(radius_b, v.norm());
    tracking_solver.gjk_tolerance = request.distance_tolerance;
    reset();
  }

  void reset() {
    tracking_solver.enableCachedGuess(true);
    tracking_solver.setCachedGuess(fcl::Vector3d(1, 0, 0));  // FCL's own cold guess
  }

  bool tracks(bool tracking) const { return tracking && solver == FclSolver::indep; }

  // One query. Without tracking: fcl::distance into a fresh result
  // (DistanceResult::update keeps the minimum over calls, so a reused result
  // would hide later answers). FCL reports a failed or colliding GJK as -1.
  double query(std::size_t i, bool tracking, fcl::Vector3d& p1, fcl::Vector3d& p2) {
    if (tracks(tracking)) {
      double d = -1;
      tracking_solver.shapeDistance(*a, tf_a[i], *b, tf_b[i], &d, &p1, &p2);
      return d;
    }
    fcl::DistanceResultd result;
    if (solver == FclSolver::libccd_scaled) request.distance_tolerance = tolerance[i];
    fcl::distance(a.get(), tf_a[i], b.get(), tf_b[i], request, result);
    p1 = result.nearest_points[0];
    p2 = result.nearest_points[1];
    return result.min_distance;
  }
};

FclPeer::FclPeer(const ConvexPolytope& a, const ConvexPolytope& b, FclSolver solver)
    : impl_(std::make_unique<Impl>(a, b, solver)) {}

FclPeer::~FclPeer() = default;

std::string FclPeer::name() const {
  switch (impl_->solver) {
    case FclSolver::libccd:
      return "FCL libccd";
    case FclSolver::libccd_scaled:
      return "FCL libccd scaled";
    case FclSolver::libccd_signed:
      return "FCL libccd signed";
    case FclSolver::indep:
      break;
  }
  return "FCL GJK";
}

bool FclPeer::has_tracking() const { return impl_->solver == FclSolver::indep; }

std::string FclPeer::tracking_note() const {
  return impl_->solver != FclSolver::indep ? "none (FCL's libccd solver ignores a cached guess)"
                                           : "cached GJK guess of GJKSolver_indep (last simplex)";
}

void FclPeer::load_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) {
  if (poses_a.size() != poses_b.size())
    throw std::invalid_argument("FclPeer: pose sequences differ in length");
  impl_->tf_a.clear();
  impl_->tf_b.clear();
  for (const Pose& p : poses_a) impl_->tf_a.push_back(fcl_transform(p));
  for (const Pose& p : poses_b) impl_->tf_b.push_back(fcl_transform(p));
  impl_->tolerance.clear();
  for (std::size_t i = 0; i < poses_a.size(); ++i) {
    const double scale = std::max(poses_a[i].translation.norm() + impl_->radius_a,
                                  poses_b[i].translation.norm() + impl_->radius_b);
    impl_->tolerance.push_back(kFclScaledTolerance * scale);
  }
}

std::size_t FclPeer::pose_count() const { return impl_->tf_a.size(); }

void FclPeer::reset() { impl_->reset(); }

SystemAnswer FclPeer::query(std::size_t i, bool tracking) {
  fcl::Vector3d p1 = fcl::Vector3d::Zero();
  fcl::Vector3d p2 = fcl::Vector3d::Zero();
  const double d = impl_->query(i, tracking, p1, p2);
  SystemAnswer answer;
  answer.distance = d;
  answer.point_a = p1;
  answer.point_b = p2;
  // fcl::distance leaves min_distance at its initial max() when it tested
  // no pair at all; -1 (a failed or colliding GJK) is an answer.
  answer.answered = d != std::numeric_limits<double>::max();
  answer.separated = d > 0.0;
  return answer;
}

double FclPeer::run_all(bool tracking) {
  impl_->reset();
  double sum = 0.0;
  const std::size_t n = impl_->tf_a.size();
  fcl::Vector3d p1, p2;
  for (std::size_t i = 0; i < n; ++i) sum += impl_->query(i, tracking, p1, p2);
  return sum;
}

}  // namespace proxima::bench
