// proxima benchmarks: the signed distance through contact, proxima against
// the peers' penetration queries on the same poses, in one run (issue 10,
// "Speed, side by side in one run").
// SPDX-License-Identifier: BSD-3-Clause
//
//   ./build/release/bench/penetration_peers [--passes 5] [--sample 40] [--quick]
//
// Bodies: A = hull of N points on the unit sphere, B = hull of N points on
// the sphere of radius 0.8 (seeded; N = 8, 64, 512, 4096). A sits at the
// origin; B, turned once (fixed rotation), sweeps through A along a line and
// back, its centre on a triangle wave from -2.4 to 2.4 in steps of 1.6e-3
// (the step of the paper's translation experiment, bench/paper/paper.cpp;
// 6000 poses): the hulls overlap on about three quarters of the poses (the
// spheres for |s| < 1.8; the printed fraction is the hulls').
//
// Systems, each answering the signed distance (the distance when apart,
// minus the penetration depth when overlapping) of poses of this sweep:
//   proxima tracked  distance() with one DistanceCache for the sweep
//                    (DistanceOptions::penetration, the default);
//   proxima cold     distance() without a cache;
//   FCL libccd       fcl::distance on fcl::Convexd (the same hull's
//                    vertices and faces), enable_signed_distance, GST_LIBCCD,
//                    enable_nearest_points, FCL's default distance_tolerance
//                    1e-6 (absolute), what its users get (a tolerance of
//                    64 u R, tried while writing this benchmark, gave the
//                    same accuracy on the refereed poses and was up to 30%
//                    slower);
//   Bullet pair      btGjkPairDetector with btGjkEpaPenetrationDepthSolver
//                    (what Bullet's convex-convex collision uses), margin 0;
//   Bullet SD        btGjkEpaSolver2::SignedDistance (GJK, then EPA), margin 0.
// FCL's GST_INDEP is not run: with enable_signed_distance FCL 0.7 aborts on
// an internal assert for overlapping Convex pairs (checked on two unit cubes
// as fcl::Convexd, B shifted by (0.75, 0.1, 0.2): "distance-inl.h:177 ...
// Assertion `index != static_cast<std::size_t>(-1)' failed", also with
// NDEBUG: the assert is compiled into libfcl; its fallback collide() finds
// no contact for the pair). None of the peers tracks a
// penetration query from one call to the next (FCL's libccd solver takes no
// guess; Bullet resets its cached axis on every call), so their one mode is
// compared with both of proxima's.
//
// Timing: the thread's CPU time (CLOCK_THREAD_CPUTIME_ID, as the paper's
// experiments: another process on a shared core does not inflate it) around
// a whole pass. Each pass runs every system once, one after the other (a
// change of load hits them all), after one untimed warm-up pass; the figure
// is the median over `--passes` of the pass's time per query. proxima
// tracked runs the whole sweep in order (one cache; it is what tracking
// needs), and also the sweep's overlapping poses only and its separated
// poses only (in sweep order, the cache kept), for the target "overlapping
// <= 2x separated". proxima cold and the peers, whose cost does not depend
// on the previous query, run every k-th pose of the same sweep (at most
// 200,000 / N poses, at least 100; all of them at N = 8), so that the slow
// configurations at N = 4096 stay within the run's budget.
//
// Accuracy. A screen first: on every untracked pose, each system's answer
// against proxima tracked's; a pose where one differs (beyond 1e-12
// relative and twice the band, or no answer) goes to the referee. Refereed
// too: `--sample` poses spread over the sweep (a quarter as many above
// N = 64: the referee's cost), and the first overlapping pose of each entry
// into A and exit from it (the shallowest overlaps). The referee: for
// N <= 512 the exact oracle of tests/support/penetration_oracle.h (the hull
// of A - B in exact arithmetic, CGAL) and, for separated poses,
// tests/support/exact_oracle.h's certified distance; at N = 4096 the exact
// hull of A - B (16.7 million points) is out of reach, and the referee is
// proxima's slow twin penetration_depth_brute_force (every face and every
// Gauss-map-crossing edge pair; double, not exact, and not independent of
// proxima's hull) for overlapping poses, the exact distance oracle for
// separated ones. The referee sees B's vertices placed in double (the
// "given doubles" of the standard). Counted per system over the refereed
// poses: answers outside the standard |sd - sd*| <= 1e-12 |sd*| + 64 u R,
// answers off by more than 1e-6 |sd*| + 64 u R, sign errors (overlap
// reported apart or the reverse, beyond the band), no answer (exceptions,
// failed solvers), and the largest error, relative to max(|sd*|, 64 u R),
// and absolute. A peer's wrong answer on an untracked pose escapes the
// count only if proxima gave the same wrong answer.
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "peers/fcl_convex.h"
#include "proxima/query/distance.h"
#include "proxima/detail/penetration/penetration.h"
#include "support/exact_oracle.h"
#include "support/penetration_oracle.h"
#include "support/penetration_sweep.h"
#include "support/random.h"

static_assert(sizeof(btScalar) == 8,
              "penetration_peers must be built with BT_USE_DOUBLE_PRECISION");

namespace proxima::bench {
namespace {

// Largest N whose referee is the exact hull of A - B (N^2 points in CGAL's
// exact kernel: 5 ms a pose at N = 64, 0.5 s at N = 512; N = 4096 would be
// 16.7 million exact points).
constexpr int kExactOracleMaxN = 512;
// The peers' looser accuracy count: off by more than this relative error
// (plus the contact band).
constexpr double kPeerRelative = 1e-6;
constexpr double kStandardRelative = 1e-12;

struct Options {
  int passes = 5;
  int sample = 40;
  // Poses per pass of the untracked systems: at most budget / N.
  int untracked_budget = 200000;
  int untracked_min = 100;
  // Above N = 64, at most this many poses of disagreement go to the
  // referee (each costs 0.5 to 1 s); the rest are counted as not refereed.
  int max_refereed_disagreements = 16;
  std::vector<int> sizes = {8, 64, 512, 4096};
};

// ---------------------------------------------------------------------------
// The systems: each answers the signed distance of pose i.

class System {
 public:
  virtual ~System() = default;
  virtual std::string name() const = 0;
  virtual void start_pass() {}
  // The signed distance of pose i, or nullopt when the system gave no
  // answer (an exception, a failed solver).
  virtual std::optional<double> query(std::size_t i) = 0;
};

class ProximaSystem final : public System {
 public:
  ProximaSystem(const ConvexPolytope& a, const ConvexPolytope& b, const std::vector<Pose>& poses,
                bool tracking)
      : a_(a), b_(b), poses_(poses), tracking_(tracking) {}
  std::string name() const override { return tracking_ ? "proxima tracked" : "proxima cold"; }
  void start_pass() override { cache_.reset(); }
  std::optional<double> query(std::size_t i) override {
    const DistanceResult r =
        distance(a_, Pose::identity(), b_, poses_[i], {}, tracking_ ? &cache_ : nullptr);
    status_ = r.status;
    return r.signed_distance();
  }
  Status last_status() const { return status_; }

 private:
  const ConvexPolytope& a_;
  const ConvexPolytope& b_;
  const std::vector<Pose>& poses_;
  bool tracking_;
  DistanceCache cache_;
  Status status_ = Status::separated;
};

class FclSystem final : public System {
 public:
  FclSystem(const ConvexPolytope& a, const ConvexPolytope& b, const std::vector<Pose>& poses)
      : a_(fcl_convex(a, "penetration_peers: A")), b_(fcl_convex(b, "penetration_peers: B")) {
    request_.enable_signed_distance = true;
    request_.enable_nearest_points = true;
    request_.gjk_solver_type = fcl::GST_LIBCCD;
    tf_a_ = fcl_transform(Pose::identity());
    for (const Pose& p : poses) tf_b_.push_back(fcl_transform(p));
  }
  std::string name() const override { return "FCL libccd"; }
  std::optional<double> query(std::size_t i) override {
    // A fresh result per query: DistanceResult::update keeps the minimum.
    fcl::DistanceResultd result;
    try {
      fcl::distance(a_.get(), tf_a_, b_.get(), tf_b_[i], request_, result);
    } catch (const std::exception&) {
      return std::nullopt;
    }
    if (result.min_distance == std::numeric_limits<double>::max()) return std::nullopt;
    return result.min_distance;
  }

 private:
  std::shared_ptr<fcl::Convexd> a_, b_;
  fcl::DistanceRequestd request_;
  fcl::Transform3d tf_a_;
  std::vector<fcl::Transform3d> tf_b_;
};

btVector3 to_bt(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

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

class BulletSystem final : public System {
 public:
  enum class Kind { pair_detector, signed_distance };
  BulletSystem(const ConvexPolytope& a, const ConvexPolytope& b, const std::vector<Pose>& poses,
               Kind kind)
      : kind_(kind) {
    fill_hull(shape_a_, a);
    fill_hull(shape_b_, b);
    // Built after the margins are set: the detector copies them.
    detector_ = std::make_unique<btGjkPairDetector>(&shape_a_, &shape_b_, &simplex_solver_,
                                                    &penetration_solver_);
    tf_a_ = to_bt(Pose::identity());
    for (const Pose& p : poses) tf_b_.push_back(to_bt(p));
  }
  std::string name() const override {
    return kind_ == Kind::pair_detector ? "Bullet pair+EPA" : "Bullet SignedDistance";
  }
  std::optional<double> query(std::size_t i) override {
    if (kind_ == Kind::pair_detector) {
      btPointCollector out;
      btGjkPairDetector::ClosestPointInput input;
      input.m_transformA = tf_a_;
      input.m_transformB = tf_b_[i];
      input.m_maximumDistanceSquared = std::numeric_limits<btScalar>::max();
      detector_->getClosestPoints(input, out, nullptr);
      if (!out.m_hasResult) return std::nullopt;
      return out.m_distance;
    }
    btGjkEpaSolver2::sResults results;
    // The guess Bullet's own btGjkEpaPenetrationDepthSolver passes: the
    // centres' difference.
    const btVector3 guess = tf_b_[i].getOrigin() - tf_a_.getOrigin();
    if (!btGjkEpaSolver2::SignedDistance(&shape_a_, tf_a_, &shape_b_, tf_b_[i], guess, results))
      return std::nullopt;
    return results.distance;
  }

 private:
  Kind kind_;
  btConvexHullShape shape_a_, shape_b_;
  btVoronoiSimplexSolver simplex_solver_;
  btGjkEpaPenetrationDepthSolver penetration_solver_;
  std::unique_ptr<btGjkPairDetector> detector_;
  btTransform tf_a_;
  std::vector<btTransform> tf_b_;
};

// ---------------------------------------------------------------------------
// Timing.

// CPU time of the calling thread, in ns.
double thread_cpu_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e9 + static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

volatile double g_sink = 0.0;

// ns per query of one pass of `system` over `indices`.
double pass_ns(System& system, const std::vector<std::size_t>& indices) {
  double sum = 0.0;
  system.start_pass();
  const double t0 = thread_cpu_ns();
  for (const std::size_t i : indices) sum += system.query(i).value_or(0.0);
  const double ns = thread_cpu_ns() - t0;
  g_sink = g_sink + sum;
  return ns / static_cast<double>(indices.size());
}

// ---------------------------------------------------------------------------
// Accuracy.

// The referee's signed distance of one pose: sign (-1 overlapping, 0
// touching, +1 separated) and the exact square of its magnitude.
struct Referee {
  int sign = 0;
  // |sd*|^2 in GMP rationals: exact from the depth and distance oracles,
  // the slow twin's double squared otherwise.
  mpq_class magnitude_squared = 0;
  double value = 0.0;  // sd*, rounded
  bool exact = true;   // false: proxima's slow twin (double)
};

std::optional<Referee> referee(const ConvexPolytope& a, const ConvexPolytope& b, const Pose& pose,
                               test::ExactOracle& oracle, std::string& error) {
  const test::Points pa(a.vertices().begin(), a.vertices().end());
  const test::Points pb_local(b.vertices().begin(), b.vertices().end());
  const test::Points pb = test::transformed(pb_local, pose);
  Referee r;
  auto separated_or_touching = [&]() -> std::optional<Referee> {
    const std::optional<test::ExactDistance> d = oracle.distance(pa, pb);
    if (!d) {
      error = "distance oracle failed: " + oracle.last_error();
      return std::nullopt;
    }
    r.magnitude_squared = d->distance_squared;
    r.sign = sgn(d->distance_squared) > 0 ? 1 : 0;
    r.value = test::sqrt_to_double(d->distance_squared);
    return r;
  };
  if (a.vertex_count() <= kExactOracleMaxN && b.vertex_count() <= kExactOracleMaxN) {
    const test::ExactDepth e = test::exact_depth(pa, pb);
    if (e.flat || e.origin != test::OriginInM::inside) return separated_or_touching();
    r.sign = -1;
    r.magnitude_squared = e.depth_squared;
    r.value = -e.depth();
    return r;
  }
  const PenetrationResult slow = penetration_depth_brute_force(a, b, pose);
  if (slow.status == PenetrationStatus::separated) return separated_or_touching();
  r.sign = slow.status == PenetrationStatus::intersecting ? -1 : 0;
  r.magnitude_squared = mpq_class(slow.depth) * mpq_class(slow.depth);
  r.value = -slow.depth;
  r.exact = false;
  return r;
}

struct Accuracy {
  // The screen: untracked poses compared with proxima tracked, and those
  // where this system's answer differed (beyond 1e-12 relative and twice
  // the band) or was missing; every such pose goes to the referee (up to
  // Options::max_refereed_disagreements per N above N = 64).
  int screened = 0;
  int disagreements = 0;
  int checked = 0;  // poses judged by the referee
  int outside_standard = 0;
  int off_peer = 0;  // off by more than kPeerRelative
  int wrong_sign = 0;
  int no_answer = 0;
  double worst_relative = 0.0;
  double worst_absolute = 0.0;
};

// |sd - sd*| <= rel |sd*| + band, decided exactly where the signs agree.
bool within(double sd, const Referee& ref, double rel, double band) {
  const int s = sd > 0 ? 1 : sd < 0 ? -1 : 0;
  if (s == 0 || ref.sign == 0 || s == ref.sign) {
    return test::within_bound(std::abs(sd), ref.magnitude_squared, rel, band);
  }
  // Opposite signs: |sd - sd*| = |sd| + |sd*|.
  return std::abs(sd) + std::abs(ref.value) <= rel * std::abs(ref.value) + band;
}

void judge(std::optional<double> sd, const Referee& ref, double band, Accuracy& acc) {
  ++acc.checked;
  if (!sd || !std::isfinite(*sd)) {
    ++acc.no_answer;
    ++acc.outside_standard;
    ++acc.off_peer;
    return;
  }
  if (!within(*sd, ref, kStandardRelative, band)) ++acc.outside_standard;
  if (!within(*sd, ref, kPeerRelative, band)) ++acc.off_peer;
  if ((ref.value<-band&& * sd> band) || (ref.value > band && *sd < -band)) ++acc.wrong_sign;
  const double err = std::abs(*sd - ref.value);
  acc.worst_absolute = std::max(acc.worst_absolute, err);
  acc.worst_relative = std::max(acc.worst_relative, err / std::max(std::abs(ref.value), band));
}

// Poses checked against the referee: fewer above N = 64, where one referee
// answer costs about 0.5 s (the exact hull of A - B at N = 512) or 1 s (the
// slow twin at N = 4096).
int sample_size(int n, const Options& opt) {
  return n <= 64 ? opt.sample : std::max(2, opt.sample / 4);
}

// ---------------------------------------------------------------------------

struct Row {
  std::string name;
  double ns = 0.0;
  Accuracy acc;
};

struct SizeResult {
  int n = 0;
  int overlapping = 0, poses = 0, untracked_poses = 0;
  double timing_seconds = 0.0, accuracy_seconds = 0.0;
  int sample_overlapping = 0;
  int unrefereed = 0;       // poses of disagreement left out of the referee
  double shallowest = 0.0;  // smallest depth* of the sampled overlaps
  std::vector<Row> rows;    // proxima tracked, proxima cold, then the peers
  double tracked_overlap_ns = 0.0, tracked_separated_ns = 0.0;
  bool exact_referee = true;
  std::vector<std::string> proxima_failures;  // reproducers
};

std::string format_pose(const Pose& p) {
  char buf[512];
  const Mat3& r = p.rotation;
  std::snprintf(buf, sizeof buf,
                "R = [%.17g %.17g %.17g; %.17g %.17g %.17g; %.17g %.17g %.17g], t = [%.17g %.17g "
                "%.17g]",
                r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2),
                p.translation.x(), p.translation.y(), p.translation.z());
  return buf;
}

SizeResult run_size(int n, const Options& opt) {
  SizeResult out;
  out.n = n;
  const SweepBodies bodies = penetration_sweep_bodies(n);
  const ConvexPolytope& a = bodies.a;
  const ConvexPolytope& b = bodies.b;
  const std::vector<Pose> poses = penetration_sweep();

  ProximaSystem tracked(a, b, poses, true), cold(a, b, poses, false);
  FclSystem fcl(a, b, poses);
  BulletSystem bullet_pair(a, b, poses, BulletSystem::Kind::pair_detector);
  BulletSystem bullet_sd(a, b, poses, BulletSystem::Kind::signed_distance);
  std::vector<System*> systems = {&tracked, &cold, &fcl, &bullet_pair, &bullet_sd};

  // Overlapping or not: the status of a tracked pass (the accuracy check
  // below holds its signed distances against the referee).
  std::vector<std::size_t> all, overlap, apart, strided;
  std::vector<double> tracked_sd(poses.size());
  tracked.start_pass();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    all.push_back(i);
    tracked_sd[i] = tracked.query(i).value_or(NAN);
    (tracked.last_status() == Status::intersecting ? overlap : apart).push_back(i);
  }
  const std::size_t want =
      static_cast<std::size_t>(std::max(opt.untracked_min, opt.untracked_budget / std::max(n, 1)));
  const std::size_t stride = std::max<std::size_t>(1, poses.size() / want);
  for (std::size_t i = stride / 2; i < poses.size(); i += stride) strided.push_back(i);
  out.poses = static_cast<int>(poses.size());
  out.untracked_poses = static_cast<int>(strided.size());
  out.overlapping = static_cast<int>(overlap.size());

  std::vector<std::vector<double>> ns(systems.size());
  std::vector<double> ns_overlap, ns_apart;
  auto poses_of = [&](std::size_t k) -> const std::vector<std::size_t>& {
    return k == 0 ? all : strided;
  };
  const double t_timing = thread_cpu_ns();
  // One untimed pass first (page faults, caches, FCL's first-call setup).
  for (std::size_t k = 0; k < systems.size(); ++k) pass_ns(*systems[k], poses_of(k));
  for (int p = 0; p < opt.passes; ++p) {
    for (std::size_t k = 0; k < systems.size(); ++k)
      ns[k].push_back(pass_ns(*systems[k], poses_of(k)));
    if (!overlap.empty()) ns_overlap.push_back(pass_ns(tracked, overlap));
    if (!apart.empty()) ns_apart.push_back(pass_ns(tracked, apart));
  }
  for (std::size_t k = 0; k < systems.size(); ++k)
    out.rows.push_back({systems[k]->name(), median(ns[k]), {}});
  out.tracked_overlap_ns = ns_overlap.empty() ? 0.0 : median(ns_overlap);
  out.tracked_separated_ns = ns_apart.empty() ? 0.0 : median(ns_apart);
  out.timing_seconds = (thread_cpu_ns() - t_timing) * 1e-9;
  const double t_accuracy = thread_cpu_ns();

  // Accuracy on a sample: tracked answers from the first tracked pass
  // (sweep order), the others queried again. Poses evenly spread, plus the
  // first overlapping pose of every entry into A and exit from it (the
  // shallowest overlaps of the sweep, where EPA and GJK disagree most),
  // and for N <= 64 the last separated one beside it.
  std::vector<std::size_t> sample;
  const int k = std::min<int>(sample_size(n, opt), out.poses);
  for (int j = 0; j < k; ++j)
    sample.push_back(static_cast<std::size_t>((static_cast<long>(j) * out.poses) / k + 3) %
                     poses.size());
  const std::vector<bool> overlapping = [&] {
    std::vector<bool> v(poses.size(), false);
    for (const std::size_t i : overlap) v[i] = true;
    return v;
  }();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::size_t next = (i + 1) % poses.size();
    if (overlapping[i] == overlapping[next]) continue;
    const std::size_t inside = overlapping[i] ? i : next, outside = overlapping[i] ? next : i;
    sample.push_back(inside);
    if (n <= 64) sample.push_back(outside);
  }
  auto band_at = [&](std::size_t i) {
    double radius = 0.0;
    for (const Vec3& v : a.vertices()) radius = std::max(radius, v.cwiseAbs().maxCoeff());
    for (const Vec3& v : b.vertices()) radius = std::max(radius, poses[i].apply(v).cwiseAbs().maxCoeff());
    return kContactBandUlps * 0x1p-53 * radius;
  };
  // The screen: every untracked pose, every other system against proxima
  // tracked; the poses where one differs go to the referee too.
  std::vector<std::size_t> disagreeing;
  for (const std::size_t i : strided) {
    bool differs = false;
    const double band = band_at(i);
    for (std::size_t s = 1; s < systems.size(); ++s) {
      const std::optional<double> sd = systems[s]->query(i);
      ++out.rows[s].acc.screened;
      if (!sd || !std::isfinite(*sd) ||
          std::abs(*sd - tracked_sd[i]) > kStandardRelative * std::abs(tracked_sd[i]) + 2 * band) {
        ++out.rows[s].acc.disagreements;
        differs = true;
      }
    }
    if (differs) disagreeing.push_back(i);
  }
  const int cap = opt.max_refereed_disagreements;
  if (n > 64 && static_cast<int>(disagreeing.size()) > cap) {
    out.unrefereed = static_cast<int>(disagreeing.size()) - cap;
    std::vector<std::size_t> kept;
    for (int j = 0; j < cap; ++j)
      kept.push_back(disagreeing[(static_cast<std::size_t>(j) * disagreeing.size()) /
                                 static_cast<std::size_t>(cap)]);
    disagreeing = kept;
  }
  sample.insert(sample.end(), disagreeing.begin(), disagreeing.end());
  std::sort(sample.begin(), sample.end());
  sample.erase(std::unique(sample.begin(), sample.end()), sample.end());
  out.shallowest = std::numeric_limits<double>::infinity();
  test::ExactOracle oracle;
  for (const std::size_t i : sample) {
    std::string error;
    const std::optional<Referee> ref = referee(a, b, poses[i], oracle, error);
    if (!ref) {
      std::fprintf(stderr, "penetration_peers: N = %d, pose %zu: referee failed: %s\n", n, i,
                   error.c_str());
      std::exit(1);
    }
    out.exact_referee = out.exact_referee && ref->exact;
    if (ref->sign < 0) {
      ++out.sample_overlapping;
      out.shallowest = std::min(out.shallowest, -ref->value);
    }
    const double band = band_at(i);
    for (std::size_t s = 0; s < systems.size(); ++s) {
      const std::optional<double> sd =
          s == 0 ? std::optional<double>(tracked_sd[i]) : systems[s]->query(i);
      const int before = out.rows[s].acc.outside_standard;
      judge(sd, *ref, band, out.rows[s].acc);
      if (s <= 1 && out.rows[s].acc.outside_standard != before) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s, N = %d, pose %zu: sd %.17g, referee %.17g (%s)",
                      systems[s]->name().c_str(), n, i, sd.value_or(NAN), ref->value,
                      ref->exact ? "exact" : "slow twin");
        out.proxima_failures.push_back(std::string(buf) + ", B in A: " + format_pose(poses[i]));
      }
    }
  }
  out.accuracy_seconds = (thread_cpu_ns() - t_accuracy) * 1e-9;
  return out;
}

void print_results(const std::vector<SizeResult>& results, const Options& opt) {
  std::printf(
      "## Signed distance through contact: proxima vs FCL 0.7 and Bullet 3.24 "
      "(bench/penetration_peers)\n\n");
  std::printf(
      "B (N points on a sphere of radius 0.8) sweeps through A (N points on the unit "
      "sphere) and back, %d poses in steps of %.1e, B's rotation fixed. Median over %d "
      "passes of the thread's CPU time per query, in ns. proxima tracked runs every pose "
      "in order with one DistanceCache; proxima cold and the peers (no tracking) every "
      "k-th pose of the same sweep ('untracked poses'). ratio = proxima tracked / peer "
      "(proxima cold / peer in brackets): below 1, proxima is faster.\n\n",
      results.front().poses, kSweepStep, opt.passes);
  std::printf("| N | overlapping | untracked poses | proxima tracked | proxima cold |");
  for (std::size_t k = 2; k < results[0].rows.size(); ++k)
    std::printf(" %s | ratio |", results[0].rows[k].name.c_str());
  std::printf("\n|---|---|---|---|---|");
  for (std::size_t k = 2; k < results[0].rows.size(); ++k) std::printf("---|---|");
  std::printf("\n");
  for (const SizeResult& r : results) {
    std::printf("| %d | %.0f%% | %d | %.0f | %.0f |", r.n, 100.0 * r.overlapping / r.poses,
                r.untracked_poses, r.rows[0].ns, r.rows[1].ns);
    for (std::size_t k = 2; k < r.rows.size(); ++k)
      std::printf(" %.0f | %.3f (%.3f) |", r.rows[k].ns, r.rows[0].ns / r.rows[k].ns,
                  r.rows[1].ns / r.rows[k].ns);
    std::printf("\n");
  }

  std::printf("\n### Accuracy against a referee\n\n");
  std::printf(
      "Screen: on every untracked pose, each system's signed distance against proxima "
      "tracked's ('differ': beyond 1e-12 relative + 2 x 64 u R, or no answer). Refereed: "
      "poses spread evenly over the sweep, the first overlapping pose of each entry and "
      "exit (and for N <= 64 the separated one beside it), and every pose where a system "
      "differed (above N = 64 at most %d of them). So a peer's wrong answer on an "
      "untracked pose is refereed unless proxima gave the same one. ",
      opt.max_refereed_disagreements);
  std::printf(
      "Referee: N <= %d the exact hull of A - B (CGAL, tests/support/penetration_oracle.h) "
      "and the exact distance oracle (tests/support/exact_oracle.h) for separated poses; "
      "larger N proxima's slow twin penetration_depth_brute_force for overlapping poses "
      "(double, not exact) and the exact distance oracle for separated ones. "
      "standard: |sd - sd*| <= 1e-12 |sd*| + 64 u R; 1e-6: |sd - sd*| <= 1e-6 |sd*| + "
      "64 u R; sign: overlap reported apart or the reverse beyond the band; "
      "worst rel: max |sd - sd*| / max(|sd*|, 64 u R).\n\n",
      kExactOracleMaxN);
  for (const SizeResult& r : results)
    std::printf(
        "- N = %d: %d poses refereed, %d of them overlapping, the shallowest %.3g deep%s\n", r.n,
        r.rows[0].acc.checked, r.sample_overlapping, r.shallowest,
        r.unrefereed > 0
            ? (", " + std::to_string(r.unrefereed) + " poses of disagreement NOT refereed").c_str()
            : "");
  std::printf(
      "\n| N | referee | system | screened | differ | refereed | outside standard | "
      "off > 1e-6 | wrong sign | no answer | worst rel | worst abs "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const SizeResult& r : results)
    for (const Row& row : r.rows)
      std::printf("| %d | %s | %s | %s | %s | %d | %d | %d | %d | %d | %.3g | %.3g |\n", r.n,
                  r.exact_referee ? "exact" : "slow twin", row.name.c_str(),
                  row.acc.screened > 0 ? std::to_string(row.acc.screened).c_str() : "-",
                  row.acc.screened > 0 ? std::to_string(row.acc.disagreements).c_str() : "-",
                  row.acc.checked, row.acc.outside_standard, row.acc.off_peer, row.acc.wrong_sign,
                  row.acc.no_answer, row.acc.worst_relative, row.acc.worst_absolute);

  std::printf("\n### The issue's targets\n\n| target | N | figure | met |\n|---|---|---|---|\n");
  auto met = [](bool ok) { return ok ? "met" : "NOT met"; };
  for (const SizeResult& r : results) {
    const double q = r.tracked_overlap_ns / r.tracked_separated_ns;
    std::printf(
        "| tracked overlapping <= 2x tracked separated | %d | %.0f / %.0f ns = %.2fx | %s "
        "|\n",
        r.n, r.tracked_overlap_ns, r.tracked_separated_ns, q, met(q <= 2.0));
  }
  const SizeResult& small = results.front();
  const SizeResult& large = results.back();
  const double flat = large.tracked_overlap_ns / small.tracked_overlap_ns;
  std::printf(
      "| tracked overlapping flat in N (%d vs %d <= 1.5x) | %d/%d | %.0f / %.0f ns = "
      "%.2fx | %s |\n",
      large.n, small.n, large.n, small.n, large.tracked_overlap_ns, small.tracked_overlap_ns, flat,
      met(flat <= 1.5));
  for (const SizeResult& r : results) {
    std::size_t fastest = 2;
    for (std::size_t k = 3; k < r.rows.size(); ++k)
      if (r.rows[k].ns < r.rows[fastest].ns) fastest = k;
    const double peer = r.rows[fastest].ns;
    std::printf(
        "| tracked >= 10x faster than the fastest peer | %d | %s %.0f / %.0f ns = %.1fx | "
        "%s |\n",
        r.n, r.rows[fastest].name.c_str(), peer, r.rows[0].ns, peer / r.rows[0].ns,
        met(peer / r.rows[0].ns >= 10.0));
    std::printf(
        "| cold >= 3x faster than the fastest peer | %d | %s %.0f / %.0f ns = %.1fx | %s "
        "|\n",
        r.n, r.rows[fastest].name.c_str(), peer, r.rows[1].ns, peer / r.rows[1].ns,
        met(peer / r.rows[1].ns >= 3.0));
  }
  bool any = false;
  for (const SizeResult& r : results)
    for (const std::string& f : r.proxima_failures) {
      if (!any) std::printf("\nproxima answers outside the standard (reproducers):\n\n");
      any = true;
      std::printf("- %s\n", f.c_str());
    }
  std::printf("\nproxima answers outside the standard on the samples: %s\n", any ? "SOME" : "none");
}

int parse_int(const char* flag, const char* value) {
  char* end = nullptr;
  const long v = value != nullptr ? std::strtol(value, &end, 10) : 0;
  if (value == nullptr || *end != '\0' || v < 1 || v > 1000000) {
    std::fprintf(stderr, "penetration_peers: %s needs a positive integer, got '%s'\n", flag,
                 value != nullptr ? value : "");
    std::exit(2);
  }
  return static_cast<int>(v);
}

}  // namespace
}  // namespace proxima::bench

int main(int argc, char** argv) {
  using namespace proxima::bench;
  Options opt;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : nullptr;
    if (arg == "--passes") {
      opt.passes = parse_int("--passes", next);
      ++i;
    } else if (arg == "--sample") {
      opt.sample = parse_int("--sample", next);
      ++i;
    } else if (arg == "--quick") {
      // The same sweep; fewer passes, poses and samples: checks the chain.
      opt.passes = 3;
      opt.sample = 8;
      opt.untracked_budget = 40000;
      opt.untracked_min = 20;
      opt.max_refereed_disagreements = 2;
    } else {
      std::fprintf(stderr, "usage: penetration_peers [--passes P] [--sample K] [--quick]\n");
      return 2;
    }
  }
  std::vector<SizeResult> results;
  for (const int n : opt.sizes) {
    std::fprintf(stderr, "penetration_peers: N = %d\n", n);
    results.push_back(run_size(n, opt));
    std::fprintf(stderr, "  %.1f s timing, %.1f s accuracy (CPU)\n", results.back().timing_seconds,
                 results.back().accuracy_seconds);
  }
  print_results(results, opt);
  return 0;
}
