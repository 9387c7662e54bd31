// proxima benchmarks: proxima's own algorithms behind the experiments'
// DistanceSystem interface.
// SPDX-License-Identifier: BSD-3-Clause
//
//   hybrid        the paper's algorithm; tracking = the DistanceCache of the
//                 previous query (feature pair and support hints).
//   enhanced_gjk  Cameron's Enhanced GJK; tracking = the DistanceCache (last
//                 simplex and hill-climbing hints).
//   gjk           classic GJK, brute-force support, always cold.
// Options are the library defaults (relative tolerance 1e-12, absolute 0).
// Without tracking every query gets a null cache: cold. With
// `signed_distance`, answers (and run_all's sum) carry the signed distance
// (minus the penetration depth when overlapping) instead of the distance.
#pragma once

#include <vector>

#include "peers/system.h"
#include "proxima/shape/polytope.h"
#include "proxima/core/types.h"

namespace proxima::bench {

class ProximaSystem final : public DistanceSystem {
 public:
  // The polytopes must outlive the system (it keeps references).
  ProximaSystem(const ConvexPolytope& a, const ConvexPolytope& b, Algorithm algorithm,
                bool signed_distance = false);

  std::string name() const override;
  bool has_tracking() const override;
  std::string tracking_note() const override;
  void load_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) override;
  std::size_t pose_count() const override { return poses_a_.size(); }
  void reset() override { cache_.reset(); }
  SystemAnswer query(std::size_t i, bool tracking) override;
  double run_all(bool tracking) override;

  // The full result of the last query() (status, features, iterations).
  const DistanceResult& last_result() const { return last_; }

 private:
  const ConvexPolytope& a_;
  const ConvexPolytope& b_;
  DistanceOptions options_;
  bool signed_ = false;
  DistanceCache cache_;
  DistanceResult last_;
  std::vector<Pose> poses_a_;
  std::vector<Pose> poses_b_;
};

}  // namespace proxima::bench
