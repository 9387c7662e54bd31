// proxima benchmarks: one interface for every system that the paper's
// experiments measure (proxima's three algorithms and the peers).
// SPDX-License-Identifier: BSD-3-Clause
//
// Each experiment is written once against this interface, so every system
// gets exactly the same polytopes and the same pose sequence. The pose
// sequence is handed over before timing (load_poses converts it into the
// system's own types: Eigen isometries for FCL, btTransform for Bullet), and
// the timed loop (run_all) lives inside each adapter, so no conversion and no
// virtual call is inside the measured work of any system.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <string>

#include "proxima/core/types.h"

namespace proxima::bench {

// One answer in the world frame, exactly as the system reports it.
struct SystemAnswer {
  double distance = std::numeric_limits<double>::quiet_NaN();
  Vec3 point_a = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  Vec3 point_b = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  // The system returned an answer at all (FCL: the solver reported success;
  // Bullet: the point collector received a point).
  bool answered = false;
  // The system's own claim that the bodies are apart (not touching, not
  // intersecting).
  bool separated = false;
};

class DistanceSystem {
 public:
  DistanceSystem() = default;
  DistanceSystem(const DistanceSystem&) = delete;
  DistanceSystem& operator=(const DistanceSystem&) = delete;
  virtual ~DistanceSystem() = default;

  // Name in tables and CSV files, e.g. "proxima hybrid", "FCL libccd".
  virtual std::string name() const = 0;
  // Whether the system can carry coherence from one query to the next.
  virtual bool has_tracking() const = 0;
  // What tracking means for this system (or why it has none), for the tables.
  virtual std::string tracking_note() const = 0;

  // Setup, not timed: the pose sequence in the system's own types.
  virtual void load_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) = 0;
  virtual std::size_t pose_count() const = 0;
  // Forget the coherence of earlier queries: the next query is cold.
  virtual void reset() = 0;
  // One query of loaded pose pair i. With `tracking` (and has_tracking()),
  // it starts from what the previous query left; without, it is cold.
  virtual SystemAnswer query(std::size_t i, bool tracking) = 0;
  // The timed kernel: reset(), then every loaded pose pair in order, as
  // query() would do it but without building answers. Returns the sum of the
  // distances so that the work cannot be optimized away.
  virtual double run_all(bool tracking) = 0;
};

}  // namespace proxima::bench
