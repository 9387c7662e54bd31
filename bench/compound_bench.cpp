// Compound body benchmarks: the branch-and-bound distance tracked (one
// CompoundCache across the steps), cold, and its twin distance_all_pairs, on
// two compounds of N = 10, 50, 200 pieces moving by small steps. Time per
// query is the benchmark's time per iteration; the counters give the piece
// pairs tested per query and the share of steps where the bodies intersect.
//
// BM_ColdBoxes runs the same cold branch and bound with axis-aligned boxes
// (in each body's frame, re-fitted to the query frame by |R| h every visit)
// in place of the library's spheres: the measured comparison behind the
// choice of spheres (see src/shape/compound.cpp).
//
//   ./build/release/bench/compound_bench --benchmark_repetitions=3
//       --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "proxima/query/compound_distance.h"
#include "proxima/query/distance.h"

namespace proxima {
namespace {

constexpr int kSteps = 2000;

Vec3 unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const Vec3 p(g(rng), g(rng), g(rng));
    if (p.norm() > 1e-3) return p.normalized();
  }
}

// N pieces with centers uniform in a ball of radius 1.2 cbrt(N): about as
// dense as a chair or a robot link cut into convex parts, neighbouring
// pieces touching or overlapping. Round pieces (shape 0) are 16 points on
// spheres of radius 0.3 .. 0.6; long ones (shape 1) are boxes of
// 1.2 x 0.15 x 0.15, randomly turned: the case where a sphere is loosest.
CompoundBody make_body(int n, int shape, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> r(0.3, 0.6);
  std::uniform_real_distribution<double> c(-1.0, 1.0);
  const double spread = 1.2 * std::cbrt(n);
  std::vector<CompoundPiece> pieces;
  while (static_cast<int>(pieces.size()) < n) {
    const Vec3 center(c(rng), c(rng), c(rng));
    if (center.norm() > 1.0) continue;
    std::vector<Vec3> pts;
    if (shape == 0) {
      const double radius = r(rng);
      for (int i = 0; i < 16; ++i) pts.push_back(radius * unit(rng));
      pieces.push_back(
          {std::make_shared<const ConvexPolytope>(pts), Pose::from_translation(spread * center)});
    } else {
      for (int i = 0; i < 8; ++i)
        pts.emplace_back((i & 1) ? 0.6 : -0.6, (i & 2) ? 0.075 : -0.075, (i & 4) ? 0.075 : -0.075);
      const Quat turn(Eigen::AngleAxisd(std::numbers::pi * c(rng), unit(rng)));
      pieces.push_back({std::make_shared<const ConvexPolytope>(pts), Pose(turn, spread * center)});
    }
  }
  return CompoundBody(std::move(pieces));
}

struct Setup {
  CompoundBody a;
  CompoundBody b;
  std::vector<Pose> poses_b;  // A stays at the identity
  int shape = 0;
};

// B beside A, about 0.3 apart at the start, spinning slowly about its own
// center (0.2 degree per step) while its center circles by 0.2: the closest
// pieces change along the way, and the bodies sometimes touch.
const Setup& setup(int n, int shape) {
  static std::vector<std::unique_ptr<Setup>> cache;
  for (const auto& s : cache) {
    if (s->a.piece_count() == n && s->shape == shape) return *s;
  }
  auto s =
      std::make_unique<Setup>(Setup{make_body(n, shape, 1), make_body(n, shape, 2), {}, shape});
  const Vec3 axis = Vec3(0.3, 1.0, 0.5).normalized();
  const double start = s->a.bounding_radius() + s->b.bounding_radius();
  const CompoundResult far =
      distance(s->a, Pose(), s->b, Pose::from_translation(Vec3(start, 0, 0)));
  const double x = start - far.distance + 0.3;
  for (int i = 0; i < kSteps; ++i) {
    const double t = 2.0 * std::numbers::pi * i / kSteps;
    const Quat spin(Eigen::AngleAxisd(0.2 * std::numbers::pi / 180.0 * i, axis));
    // Spin about B's bounding center: translation = p - R c.
    const Vec3 place(x, 0.2 * std::cos(t), 0.2 * std::sin(t));
    const Vec3 c = s->b.center();
    s->poses_b.emplace_back(spin, place + c - (spin * c));
  }
  cache.push_back(std::move(s));
  return *cache.back();
}

enum class Mode { tracked, cold, all_pairs };

void run(benchmark::State& state, Mode mode) {
  const Setup& s = setup(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  CompoundCache cache;
  std::size_t i = 0;
  long long pairs = 0;
  long long intersecting = 0;
  long long queries = 0;
  for (auto _ : state) {
    const Pose& pose_b = s.poses_b[i];
    CompoundResult r;
    switch (mode) {
      case Mode::tracked:
        r = distance(s.a, Pose(), s.b, pose_b, {}, &cache);
        break;
      case Mode::cold:
        r = distance(s.a, Pose(), s.b, pose_b);
        break;
      case Mode::all_pairs:
        r = distance_all_pairs(s.a, Pose(), s.b, pose_b);
        break;
    }
    benchmark::DoNotOptimize(r.distance);
    pairs += r.pairs_tested;
    intersecting += r.status == Status::intersecting;
    ++queries;
    i = (i + 1) % s.poses_b.size();
  }
  state.counters["pairs"] = static_cast<double>(pairs) / static_cast<double>(queries);
  state.counters["intersecting"] = static_cast<double>(intersecting) / static_cast<double>(queries);
}

void BM_Tracked(benchmark::State& state) { run(state, Mode::tracked); }
void BM_Cold(benchmark::State& state) { run(state, Mode::cold); }
void BM_AllPairs(benchmark::State& state) { run(state, Mode::all_pairs); }

// ---------------------------------------------------------------------------
// The alternative bounding volume: a box hierarchy over the same pieces (same
// median split), each box fitted to the placed vertices in the body's frame.
// A box of B seen from A's frame is bounded by the box of half-widths |R| h
// around the transformed center, and the distance between two boxes is the
// norm of the per-axis gaps: a lower bound as cheap as the spheres' one.

struct BoxNode {
  Vec3 center;
  Vec3 half;
  int left = -1;
  int right = -1;
  int piece = -1;
};

struct BoxTree {
  std::vector<BoxNode> nodes;

  explicit BoxTree(const CompoundBody& body) {
    std::vector<int> order(static_cast<std::size_t>(body.piece_count()));
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    build(body, order, 0, static_cast<int>(order.size()));
  }

  int build(const CompoundBody& body, std::vector<int>& order, int first, int last) {
    const int id = static_cast<int>(nodes.size());
    nodes.emplace_back();
    Vec3 lo = Vec3::Constant(INFINITY);
    Vec3 hi = -lo;
    if (last - first == 1) {
      const int p = order[static_cast<std::size_t>(first)];
      const CompoundPiece& piece = body.piece(p);
      for (const Vec3& v : piece.polytope->vertices()) {
        lo = lo.cwiseMin(piece.pose.apply(v));
        hi = hi.cwiseMax(piece.pose.apply(v));
      }
      nodes[static_cast<std::size_t>(id)].piece = p;
    } else {
      Vec3 clo = Vec3::Constant(INFINITY);
      Vec3 chi = -clo;
      for (int i = first; i < last; ++i) {
        const Vec3& c = body.piece_sphere(order[static_cast<std::size_t>(i)]).center;
        clo = clo.cwiseMin(c);
        chi = chi.cwiseMax(c);
      }
      int axis = 0;
      (chi - clo).maxCoeff(&axis);
      const int middle = first + (last - first) / 2;
      std::nth_element(
          order.begin() + first, order.begin() + middle, order.begin() + last, [&](int p, int q) {
            return body.piece_sphere(p).center[axis] < body.piece_sphere(q).center[axis];
          });
      const int l = build(body, order, first, middle);
      const int r = build(body, order, middle, last);
      for (const int k : {l, r}) {
        const BoxNode& child = nodes[static_cast<std::size_t>(k)];
        lo = lo.cwiseMin(child.center - child.half);
        hi = hi.cwiseMax(child.center + child.half);
      }
      nodes[static_cast<std::size_t>(id)].left = l;
      nodes[static_cast<std::size_t>(id)].right = r;
    }
    // A relative inflation far above rounding: only the pruning power is
    // compared here, not the last ulp.
    nodes[static_cast<std::size_t>(id)].center = 0.5 * (lo + hi);
    nodes[static_cast<std::size_t>(id)].half =
        0.5 * (hi - lo) * (1 + 1e-12) + Vec3::Constant(1e-12);
    return id;
  }
};

// The cold branch and bound of src/shape/compound.cpp, depth first, nearer child
// pair first, descending the larger volume, with boxes. Returns the distance
// and counts the pairs tested.
double box_distance(const CompoundBody& a, const BoxTree& ta, const CompoundBody& b,
                    const BoxTree& tb, const Pose& pose_b, int& pairs) {
  const Mat3 abs_r = pose_b.rotation.cwiseAbs();
  const auto lower = [&](const BoxNode& na, const BoxNode& nb) {
    const Vec3 c = pose_b.apply(nb.center);
    const Vec3 h = abs_r * nb.half;
    return ((na.center - c).cwiseAbs() - na.half - h).cwiseMax(0.0).norm();
  };
  struct Entry {
    int a;
    int b;
    double lb;
  };
  std::vector<Entry> stack{{0, 0, 0.0}};
  double best = INFINITY;
  pairs = 0;
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (e.lb > best) continue;
    const BoxNode& na = ta.nodes[static_cast<std::size_t>(e.a)];
    const BoxNode& nb = tb.nodes[static_cast<std::size_t>(e.b)];
    if (na.piece >= 0 && nb.piece >= 0) {
      const CompoundPiece& pa = a.piece(na.piece);
      const CompoundPiece& pb = b.piece(nb.piece);
      const DistanceResult r = distance(*pa.polytope, pa.pose, *pb.polytope, pose_b * pb.pose);
      ++pairs;
      best = std::min(best, r.distance);
      if (r.status == Status::intersecting) break;
      continue;
    }
    const bool split_a =
        na.piece < 0 && (nb.piece >= 0 || na.half.squaredNorm() >= nb.half.squaredNorm());
    Entry first{};
    Entry second{};
    if (split_a) {
      first = {na.left, e.b, lower(ta.nodes[static_cast<std::size_t>(na.left)], nb)};
      second = {na.right, e.b, lower(ta.nodes[static_cast<std::size_t>(na.right)], nb)};
    } else {
      first = {e.a, nb.left, lower(na, tb.nodes[static_cast<std::size_t>(nb.left)])};
      second = {e.a, nb.right, lower(na, tb.nodes[static_cast<std::size_t>(nb.right)])};
    }
    if (first.lb < second.lb) std::swap(first, second);
    if (first.lb <= best) stack.push_back(first);
    if (second.lb <= best) stack.push_back(second);
  }
  return best;
}

void BM_ColdBoxes(benchmark::State& state) {
  const Setup& s = setup(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const BoxTree ta(s.a);
  const BoxTree tb(s.b);
  std::size_t i = 0;
  long long pairs = 0;
  long long queries = 0;
  for (auto _ : state) {
    int tested = 0;
    benchmark::DoNotOptimize(box_distance(s.a, ta, s.b, tb, s.poses_b[i], tested));
    pairs += tested;
    ++queries;
    i = (i + 1) % s.poses_b.size();
  }
  state.counters["pairs"] = static_cast<double>(pairs) / static_cast<double>(queries);
}

// Arguments: pieces per body, piece shape (0 round, 1 long).
void sizes(benchmark::internal::Benchmark* b) {
  for (const int shape : {0, 1}) {
    for (const int n : {10, 50, 200}) b->Args({n, shape});
  }
  b->ArgNames({"pieces", "long"})->Unit(benchmark::kMicrosecond);
}
BENCHMARK(BM_Tracked)->Apply(sizes);
BENCHMARK(BM_Cold)->Apply(sizes);
BENCHMARK(BM_ColdBoxes)->Apply(sizes);
BENCHMARK(BM_AllPairs)->Apply(sizes);

}  // namespace
}  // namespace proxima

BENCHMARK_MAIN();
