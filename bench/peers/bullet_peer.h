// proxima benchmarks: Bullet 3.24 (double precision) as a peer.
// SPDX-License-Identifier: BSD-3-Clause
//
// Settings (the reasons are at the top of bullet_peer.cpp):
//   build         libBulletCollision-float64 / libLinearMath-float64, this
//                 adapter compiled with BT_USE_DOUBLE_PRECISION (checked:
//                 sizeof(btScalar) == 8).
//   geometry      btConvexHullShape of the SAME hull vertices as proxima's,
//                 collision margin 0.
//   query         btGjkPairDetector with btVoronoiSimplexSolver and
//                 btGjkEpaPenetrationDepthSolver, answers via btPointCollector;
//                 ClosestPointInput::m_maximumDistanceSquared = DBL_MAX.
//   tracking      none. The detector object is kept for the whole sequence,
//                 but Bullet 3.24 resets its cached separating axis at the
//                 start of every getClosestPoints call, so nothing carries
//                 over from one query to the next.
// Bullet's headers stay in bullet_peer.cpp: they must never be compiled
// without BT_USE_DOUBLE_PRECISION, and a user of this header does not see
// them.
#pragma once

#include <memory>

#include "peers/system.h"
#include "proxima/shape/polytope.h"

namespace proxima::bench {

class BulletPeer final : public DistanceSystem {
 public:
  BulletPeer(const ConvexPolytope& a, const ConvexPolytope& b);
  ~BulletPeer() override;

  std::string name() const override;
  bool has_tracking() const override;
  std::string tracking_note() const override;
  void load_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) override;
  std::size_t pose_count() const override;
  void reset() override;
  SystemAnswer query(std::size_t i, bool tracking) override;
  double run_all(bool tracking) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace proxima::bench
