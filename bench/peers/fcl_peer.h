// proxima benchmarks: FCL 0.7 as a peer (its libccd solver and its own GJK).
// SPDX-License-Identifier: BSD-3-Clause
//
// Settings (the reasons are at the top of fcl_peer.cpp):
//   geometry      fcl::Convexd built from the SAME hull as proxima's: the
//                 ConvexPolytope's vertices and its face polygons.
//   query         fcl::distance(geometry, transform, geometry, transform,
//                 request, result), one fresh DistanceResult per query.
//   request       enable_nearest_points = true, enable_signed_distance =
//                 false, rel_err = abs_err = 0, distance_tolerance = 1e-6
//                 (FCL's default), gjk_solver_type GST_LIBCCD or GST_INDEP.
//   tracking      GST_INDEP only: one GJKSolver_indep kept for the whole
//                 sequence with enableCachedGuess(true), its shapeDistance
//                 called for the Convex pair (what fcl::distance calls after
//                 its type dispatch); FCL then starts each query's GJK from
//                 the previous query's simplex. GST_LIBCCD has no tracking
//                 (FCL's libccd solver ignores a cached guess).
// FCL's headers stay in fcl_peer.cpp: a user of this header does not compile
// them.
#pragma once

#include <memory>

#include "peers/system.h"
#include "proxima/polytope.h"

namespace proxima::bench {

enum class FclSolver { libccd, indep };

class FclPeer final : public DistanceSystem {
 public:
  // The polytopes are copied into FCL's own geometry; they need not outlive
  // the peer.
  FclPeer(const ConvexPolytope& a, const ConvexPolytope& b, FclSolver solver);
  ~FclPeer() override;

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
