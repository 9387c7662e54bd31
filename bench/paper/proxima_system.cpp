// proxima benchmarks: proxima's own algorithms as a DistanceSystem.
// SPDX-License-Identifier: BSD-3-Clause
#include "paper/proxima_system.h"

#include <stdexcept>

#include "proxima/query/distance.h"

namespace proxima::bench {

ProximaSystem::ProximaSystem(const ConvexPolytope& a, const ConvexPolytope& b, Algorithm algorithm,
                             bool signed_distance)
    : a_(a), b_(b), signed_(signed_distance) {
  options_.algorithm = algorithm;
}

std::string ProximaSystem::name() const {
  switch (options_.algorithm) {
    case Algorithm::hybrid:
      return "proxima hybrid";
    case Algorithm::gjk:
      return "proxima GJK";
    case Algorithm::enhanced_gjk:
      return "proxima Enhanced GJK";
  }
  return "proxima";
}

bool ProximaSystem::has_tracking() const { return options_.algorithm != Algorithm::gjk; }

std::string ProximaSystem::tracking_note() const {
  switch (options_.algorithm) {
    case Algorithm::hybrid:
      return "DistanceCache: last feature pair and support hints";
    case Algorithm::enhanced_gjk:
      return "DistanceCache: last simplex and hill-climbing hints";
    case Algorithm::gjk:
      return "none (classic GJK is always cold)";
  }
  return "";
}

void ProximaSystem::load_poses(std::span<const Pose> poses_a, std::span<const Pose> poses_b) {
  if (poses_a.size() != poses_b.size())
    throw std::invalid_argument("ProximaSystem: pose sequences differ in length");
  poses_a_.assign(poses_a.begin(), poses_a.end());
  poses_b_.assign(poses_b.begin(), poses_b.end());
}

SystemAnswer ProximaSystem::query(std::size_t i, bool tracking) {
  last_ = distance(a_, poses_a_[i], b_, poses_b_[i], options_,
                   tracking && has_tracking() ? &cache_ : nullptr);
  SystemAnswer answer;
  answer.answered = true;
  answer.distance = signed_ ? last_.signed_distance() : last_.distance;
  answer.point_a = last_.point_a;
  answer.point_b = last_.point_b;
  answer.separated = last_.status == Status::separated;
  return answer;
}

double ProximaSystem::run_all(bool tracking) {
  cache_.reset();
  double sum = 0.0;
  const std::size_t n = poses_a_.size();
  DistanceCache* cache = tracking && has_tracking() ? &cache_ : nullptr;
  if (signed_) {
    for (std::size_t i = 0; i < n; ++i)
      sum += distance(a_, poses_a_[i], b_, poses_b_[i], options_, cache).signed_distance();
  } else {
    for (std::size_t i = 0; i < n; ++i)
      sum += distance(a_, poses_a_[i], b_, poses_b_[i], options_, cache).distance;
  }
  return sum;
}

}  // namespace proxima::bench
