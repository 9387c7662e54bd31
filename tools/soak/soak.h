// proxima's soak: seeded random queries of every kind, checked against the
// invariants of the accuracy standard (DESIGN.md, docs/accuracy.md).
// SPDX-License-Identifier: BSD-3-Clause
//
// A tool beside the product (like the benchmarks): it links the library and
// is no part of its layers. Each episode draws its own generator from (seed,
// episode), so one violation is replayed alone by `--seed S --episode E`.
#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "proxima/proxima.h"

namespace proxima::soak {

// 2^-53, the unit roundoff of the accuracy standard's band 64 u R.
inline constexpr double kUnit = 0x1p-53;

// The episode kinds, each a function of soak_episodes.cpp.
enum class Kind { convex, tracked, rounded, compound, mesh, toi };
inline constexpr Kind kAllKinds[] = {Kind::convex,   Kind::tracked, Kind::rounded,
                                     Kind::compound, Kind::mesh,    Kind::toi};
const char* to_string(Kind kind);

// Counts and reports: what every episode writes to.
class Ledger {
 public:
  Ledger(std::uint64_t seed, int reports_per_invariant)
      : seed_(seed), reports_per_invariant_(reports_per_invariant) {}

  // One check of `invariant` ran (passed or not).
  void checked(std::string_view invariant) { ++checks_[std::string(invariant)]; }
  // A check failed: counted, and printed as one JSON line (the first few of
  // each invariant) with the seed, the episode and `detail` (a JSON object's
  // members, without braces; a `query` member holds a `proxima query` line).
  void violation(std::string_view invariant, const std::string& detail);
  void queries(std::uint64_t n) { queries_ += n; }

  std::uint64_t query_count() const { return queries_; }
  std::uint64_t violation_count() const;
  void set_episode(std::uint64_t episode, Kind kind) {
    episode_ = episode;
    kind_ = kind;
    ++episodes_[to_string(kind)];
  }
  // The closing summary line (JSON).
  std::string summary(double seconds) const;

 private:
  std::uint64_t seed_;
  int reports_per_invariant_;
  std::uint64_t episode_ = 0;
  Kind kind_ = Kind::convex;
  std::uint64_t queries_ = 0;
  std::map<std::string, std::uint64_t> checks_;
  std::map<std::string, std::uint64_t> violations_;
  std::map<std::string, std::uint64_t> episodes_;
};

// The random draws of soak.py's tour: bodies of every kind and scale, poses.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : rng_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  double normal() { return normal_(rng_); }
  int integer(int lo, int hi_exclusive) {
    return std::uniform_int_distribution<int>(lo, hi_exclusive - 1)(rng_);
  }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  Vec3 normal3() { return {normal(), normal(), normal()}; }
  Vec3 unit3();
  Mat3 rotation();  // uniform over SO(3), from a normalized Gaussian quaternion

  // One point set of the tour: Gaussian cloud, sphere, box, flat, needle,
  // segment, point, polygon, uniform box; off-centre; scaled by 10^[-3, 3],
  // and one time in ten by a further 10^[-150, 150].
  std::vector<Vec3> points();
  // Poses of B about A at the origin (soak.py's rand_pose_rows): mixed,
  // near contact (1 + 10^[-14, -2] of the reach), overlapping, or about the
  // reach.
  std::vector<Pose> poses_about(int count, double reach);
  // Poses of B that put its extreme vertex along -d on A's extreme vertex
  // along d: touching at a vertex.
  std::vector<Pose> touching_poses(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                                   int count);

 private:
  std::vector<Vec3> shape();
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
};

// Everything an episode needs.
struct Context {
  Ledger& ledger;
  Draw draw;
  std::uint64_t seed;
  std::uint64_t episode;
};

void run_episode(Kind kind, Context& context);

// Helpers shared by the episodes (soak_checks.cpp).
// The largest coordinate magnitude of the points placed at `pose`.
double placed_magnitude(const std::vector<Vec3>& points, const Pose& pose);
double local_magnitude(const std::vector<Vec3>& points);
// A `proxima query` line (docs/query-format.md) for the pair, with radii.
std::string query_line(const std::vector<Vec3>& a, const Pose& pose_a, double radius_a,
                       const std::vector<Vec3>& b, const Pose& pose_b, double radius_b);
std::string number(double x);  // %.17g, or a JSON string for a non-finite value
std::string vec(const Vec3& v);

// The invariants every distance answer keeps whatever the body kinds, with
// R the query's magnitude: finite; signed_lower_bound <= signed_distance <=
// signed_upper_bound and lower_bound <= distance; |point_a - point_b| =
// |signed_distance|; normal . (point_b - point_a) = signed_distance; a unit
// normal; status against the distance and the band 64 u R. `reproducer`
// holds the JSON members that replay the query.
void check_answer(Context& context, std::string_view tag, const DistanceResult& r, double magnitude,
                  double world_magnitude, const std::string& reproducer);

}  // namespace proxima::soak
