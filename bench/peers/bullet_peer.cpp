// proxima benchmarks: Bullet 3.24 (double precision) as a peer.
// SPDX-License-Identifier: BSD-3-Clause
//
// Why these settings (the list itself is at the top of bullet_peer.h):
// - Double precision: Debian ships Bullet built both ways; the float64
//   libraries and BT_USE_DOUBLE_PRECISION make btScalar a double, so Bullet
//   sees the same doubles as everyone else (a float build could not even
//   represent the paper's 1e-23 tetrahedra next to 1e-22 gaps sensibly).
// - btConvexHullShape with margin 0: Bullet's default margin (0.04) rounds
//   the body and shifts the distance; with 0 the shape is exactly the hull
//   of the vertices. Its support search is a linear scan over the points.
// - btGjkPairDetector + btVoronoiSimplexSolver + btGjkEpaPenetrationDepthSolver
//   is the pair Bullet's own convex-convex algorithm uses for closest points.
// - m_maximumDistanceSquared defaults to BT_LARGE_FLOAT (1e30): at the
//   paper's 1e39 scale every squared distance is larger, and Bullet would
//   return no point at all. A user asking for the distance sets it out of
//   the way, so do we.
// - No tracking: Bullet 3.24's getClosestPointsNonVirtual sets
//   m_cachedSeparatingAxis to (0, 1, 0) before iterating, so the axis that a
//   previous call left (or setCachedSeparatingAxis gave) is never used.
#include "peers/bullet_peer.h"

#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <btBulletCollisionCommon.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

static_assert(sizeof(btScalar) == 8, "the Bullet peer must be built with BT_USE_DOUBLE_PRECISION");

namespace proxima::bench {
namespace {

btVector3 to_bt(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
Vec3 from_bt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

btTransform to_bt(const Pose& pose) {
  const Mat3& r = pose.rotation;
  return btTransform(
      btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
      to_bt(pose.translation));
}

void fill_hull(btConvexHullShape& shape, const ConvexPolytope& p) {
  for (const Vec3& v : p.vertices()) shape.addPoint(to_bt(v), false);
  shape.recalcLocalAabb();
  shape.setMargin(0.0);
}

}  // namespace

struct BulletPeer::Impl {
  btConvexHullShape shape_a;
  btConvexHullShape shape_b;
  btVoronoiSimplexSolver simplex_solver;
  btGjkEpaPenetrationDepthSolver penetration_solver;
  // Built after the margins are set: btGjkPairDetector copies the shapes'
  // margins in its constructor (built first, it would keep Bullet's default
  // 0.04 and report every distance 0.08 short).
  std::unique_ptr<btGjkPairDetector> detector;
  std::vector<btTransform> tf_a;
  std::vector<btTransform> tf_b;

  Impl(const ConvexPolytope& a, const ConvexPolytope& b) {
    fill_hull(shape_a, a);
    fill_hull(shape_b, b);
    detector = std::make_unique<btGjkPairDetector>(&shape_a, &shape_b, &simplex_solver,
                                                   &penetration_solver);
  }

  void query(std::size_t i, btPointCollector& out) {
    btGjkPairDetector::ClosestPointInput input;
    input.m_transformA = tf_a[i];
    input.m_transformB = tf_b[i];
    input.m_maximumDistanceSquared = std::numeric_limits<btScalar>::max();
    detector->getClosestPoints(input, out, nullptr);
  }
};

BulletPeer::BulletPeer(const ConvexPolytope& a, const ConvexPolytope& b)
    : impl_(std::make_unique<Impl>(a, b)) {}

BulletPeer::~BulletPeer() = default;

std::string BulletPeer::name() const { return "Bullet GJK"; }

bool BulletPeer::has_tracking() const { return false; }

std::string BulletPeer::tracking_note() const {
  return "none (Bullet 3.24 resets its cached separating axis on every call)";
}

void BulletPeer::load_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) {
  if (poses_a.size() != poses_b.size())
    throw std::invalid_argument("BulletPeer: pose sequences differ in length");
  impl_->tf_a.clear();
  impl_->tf_b.clear();
  for (const Pose& p : poses_a) impl_->tf_a.push_back(to_bt(p));
  for (const Pose& p : poses_b) impl_->tf_b.push_back(to_bt(p));
}

std::size_t BulletPeer::pose_count() const { return impl_->tf_a.size(); }

void BulletPeer::reset() {}

SystemAnswer BulletPeer::query(std::size_t i, bool /*tracking*/) {
  btPointCollector out;
  impl_->query(i, out);
  SystemAnswer answer;
  answer.answered = out.m_hasResult;
  if (out.m_hasResult) {
    // Bullet reports the point on B and the normal from B towards A.
    answer.distance = out.m_distance;
    answer.point_b = from_bt(out.m_pointInWorld);
    answer.point_a = answer.point_b + out.m_distance * from_bt(out.m_normalOnBInWorld);
    answer.separated = out.m_distance > 0.0;
  }
  return answer;
}

double BulletPeer::run_all(bool /*tracking*/) {
  double sum = 0.0;
  const std::size_t n = impl_->tf_a.size();
  for (std::size_t i = 0; i < n; ++i) {
    btPointCollector out;
    impl_->query(i, out);
    sum += out.m_distance;
  }
  return sum;
}

}  // namespace proxima::bench
