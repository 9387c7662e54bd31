// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A fixed amount of compound-query work, most of it overlapping, for
// callgrind's instruction counts and for checking that a change of the
// compound search leaves every answer's bits as they were:
//
//   valgrind --tool=callgrind --toggle-collect='*run_queries*'
//     build/release/bench/compound_instructions body 20
// (one command line)
//
// then instructions per query = the collected total / the printed queries.
// Two compounds of N pieces (bench/compound_bench.cpp's round pieces: 16
// points on spheres of radius 0.3 .. 0.6, centers in a ball of radius
// 1.2 cbrt(N)) meet at seeded poses, B's center within the sum of the
// bounding radii of A's (most pairs overlap, some deeply). Modes:
//   body             distance(Body, ...) on the compounds with radii 0,
//                    0.05 and 0.2 in turn, cold (no cache)
//   body_tracked     the same bodies along one path (B passes through A
//                    and out, turning), one BodyCache per radius
//   compound         distance(CompoundBody, ...) with the depth, cold
//   compound_tracked the same along the path, one CompoundCache
//   margin           within_margin(CompoundBody, ...) at margins 0.05,
//                    0.3 and 1 in turn, cold
//   margin_tracked   the same along the path, one CompoundCache per margin
// The output is the number of queries and overlapping answers, the sums of
// the answers' fields (status, signed distance and its bounds, points,
// normal, piece ids) printed to the last bit (%a), and a hash of every
// field of every answer in order: two builds answer bit for bit alike
// exactly when their lines are equal (a sum alone could hide two changes
// that cancel). A third argument `print` also prints every answer (status,
// pieces, signed distance and its bounds, to the last bit), one a line, for
// a diff of two builds' answers.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/margin.h"

namespace {

using proxima::Body;
using proxima::BodyCache;
using proxima::BodyResult;
using proxima::CompoundBody;
using proxima::CompoundCache;
using proxima::CompoundPiece;
using proxima::CompoundResult;
using proxima::ConvexPolytope;
using proxima::DistanceResult;
using proxima::MarginResult;
using proxima::Pose;
using proxima::Quat;
using proxima::Status;
using proxima::Vec3;

constexpr int kColdQueries = 300;
constexpr int kPathSteps = 600;

Vec3 unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const Vec3 p(g(rng), g(rng), g(rng));
    if (p.norm() > 1e-3) return p.normalized();
  }
}

Quat turn(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  return Quat(Eigen::AngleAxisd(angle(rng), unit(rng)));
}

// bench/compound_bench.cpp's round pieces.
std::shared_ptr<const CompoundBody> make_compound(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> r(0.3, 0.6);
  std::uniform_real_distribution<double> c(-1.0, 1.0);
  const double spread = 1.2 * std::cbrt(n);
  std::vector<CompoundPiece> pieces;
  while (static_cast<int>(pieces.size()) < n) {
    const Vec3 center(c(rng), c(rng), c(rng));
    if (center.norm() > 1.0) continue;
    const double radius = r(rng);
    std::vector<Vec3> pts;
    for (int i = 0; i < 16; ++i) pts.push_back(radius * unit(rng));
    pieces.push_back({std::make_shared<const ConvexPolytope>(pts), Pose(turn(rng), spread * center)});
  }
  return std::make_shared<const CompoundBody>(std::move(pieces));
}

// The hash and the sums of the answers' fields.
class Checksum {
 public:
  explicit Checksum(bool print) : print_(print) {}

  void add(const DistanceResult& r, std::int32_t piece_a, std::int32_t piece_b) {
    if (print_) {
      std::printf("%d: status %d pieces %d %d signed %a [%a, %a] normal %a %a %a\n", queries_,
                  static_cast<int>(r.status), piece_a, piece_b, r.signed_distance(),
                  r.signed_lower_bound(), r.signed_upper_bound(), r.normal.x(), r.normal.y(),
                  r.normal.z());
    }
    ++queries_;
    overlapping_ += r.status == Status::intersecting ? 1 : 0;
    status_ += static_cast<int>(r.status);
    pieces_ += 1000 * piece_a + piece_b;
    value_ += r.signed_distance();
    lower_ += r.signed_lower_bound();
    upper_ += r.signed_upper_bound();
    points_ += r.point_a.sum() + r.point_b.sum();
    normal_ += r.normal.sum();
    mix(static_cast<std::uint64_t>(r.status));
    mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(piece_a)));
    mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(piece_b)));
    for (const double x : {r.distance, r.lower_bound, r.depth, r.depth_lower_bound,
                           r.depth_upper_bound})
      mix(std::bit_cast<std::uint64_t>(x));
    for (const Vec3* v : {&r.point_a, &r.point_b, &r.normal})
      for (int k = 0; k < 3; ++k) mix(std::bit_cast<std::uint64_t>((*v)[k]));
    for (const proxima::Feature* f : {&r.feature_a, &r.feature_b}) {
      mix(static_cast<std::uint64_t>(f->type));
      for (const std::int32_t id : f->vertices) mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(id)));
      mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(f->face)));
    }
  }

  // A margin answer: its status in place of the distance status, its
  // bounds in place of the signed bounds.
  void add(const MarginResult& r) {
    DistanceResult d;
    d.status = r.status == proxima::MarginStatus::within ? Status::intersecting
               : r.status == proxima::MarginStatus::beyond ? Status::separated
                                                           : Status::iteration_cap;
    d.lower_bound = r.lower_bound;
    d.distance = r.upper_bound;
    d.point_a = r.point_a;
    d.point_b = r.point_b;
    add(d, r.piece_a, r.piece_b);
  }

  void print() const {
    std::printf("%d queries, %d overlapping\n", queries_, overlapping_);
    std::printf("sum status %lld, pieces %lld\n", status_, pieces_);
    std::printf("sum signed distance %a, lower %a, upper %a\n", value_, lower_, upper_);
    std::printf("sum points %a, normal %a\n", points_, normal_);
    std::printf("hash %016llx\n", static_cast<unsigned long long>(hash_));
  }

 private:
  // FNV-1a over the bytes of each word.
  void mix(std::uint64_t word) {
    for (int k = 0; k < 8; ++k) {
      hash_ ^= (word >> (8 * k)) & 0xffu;
      hash_ *= 0x100000001b3ull;
    }
  }

  bool print_ = false;
  int queries_ = 0;
  int overlapping_ = 0;
  long long status_ = 0;
  long long pieces_ = 0;
  double value_ = 0.0;
  double lower_ = 0.0;
  double upper_ = 0.0;
  double points_ = 0.0;
  double normal_ = 0.0;
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

struct Work {
  std::shared_ptr<const CompoundBody> a;
  std::shared_ptr<const CompoundBody> b;
  std::vector<Pose> poses_a;
  std::vector<Pose> poses_b;
};

// Seeded poses, B's center within the sum of the bounding radii of A's.
Work cold_work(int n) {
  Work w{make_compound(n, 1), make_compound(n, 2), {}, {}};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> reach(0.0, 1.0);
  const double far = w.a->bounding_radius() + w.b->bounding_radius();
  for (int i = 0; i < kColdQueries; ++i) {
    const Pose pa(turn(rng), Vec3::Zero());
    const Quat rb = turn(rng);
    // B's bounding center placed at the drawn point: translation = p - R c.
    const Vec3 place = pa.apply(w.a->center()) + reach(rng) * far * unit(rng);
    w.poses_a.push_back(pa);
    w.poses_b.emplace_back(rb, place - (rb * w.b->center()));
  }
  return w;
}

// B's center on a line through A's, from one side to the other, turning
// 0.5 degree per step.
Work path_work(int n) {
  Work w{make_compound(n, 1), make_compound(n, 2), {}, {}};
  const double far = w.a->bounding_radius() + w.b->bounding_radius();
  const Vec3 direction = Vec3(1.0, 0.4, -0.2).normalized();
  const Vec3 axis = Vec3(0.3, 1.0, 0.5).normalized();
  for (int i = 0; i < kPathSteps; ++i) {
    const double t = -1.0 + 2.0 * i / (kPathSteps - 1);
    const Quat rb(Eigen::AngleAxisd(0.5 * std::numbers::pi / 180.0 * i, axis));
    const Vec3 place = w.a->center() + t * far * direction;
    w.poses_a.push_back(Pose::identity());
    w.poses_b.emplace_back(rb, place - (rb * w.b->center()));
  }
  return w;
}

[[gnu::noinline]] void run_queries(const std::string& mode, const Work& w, Checksum& sum) {
  const bool tracked = mode.ends_with("_tracked");
  const std::size_t count = w.poses_b.size();
  if (mode.starts_with("body")) {
    const double radii[] = {0.0, 0.05, 0.2};
    for (int k = 0; k < 3; ++k) {
      const Body a(w.a, radii[k]);
      const Body b(w.b, radii[(k + 1) % 3]);
      BodyCache cache;
      for (std::size_t i = 0; i < count; ++i) {
        const BodyResult r = proxima::distance(a, w.poses_a[i], b, w.poses_b[i], {},
                                               tracked ? &cache : nullptr);
        sum.add(r, r.piece_a, r.piece_b);
      }
    }
    return;
  }
  if (mode.starts_with("margin")) {
    for (const double margin : {0.05, 0.3, 1.0}) {
      CompoundCache cache;
      for (std::size_t i = 0; i < count; ++i) {
        sum.add(proxima::within_margin(*w.a, w.poses_a[i], *w.b, w.poses_b[i], margin, {},
                                       tracked ? &cache : nullptr));
      }
    }
    return;
  }
  CompoundCache cache;
  for (std::size_t i = 0; i < count; ++i) {
    const CompoundResult r = proxima::distance(*w.a, w.poses_a[i], *w.b, w.poses_b[i], {},
                                               tracked ? &cache : nullptr);
    sum.add(r, r.piece_a, r.piece_b);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc >= 2 ? argv[1] : "";
  const bool known = mode == "body" || mode == "body_tracked" || mode == "compound" ||
                     mode == "compound_tracked" || mode == "margin" || mode == "margin_tracked";
  const bool print = argc == 4 && std::strcmp(argv[3], "print") == 0;
  const int n = argc >= 3 ? std::atoi(argv[2]) : 0;
  if ((argc != 3 && !print) || !known || n < 1) {
    std::fprintf(stderr,
                 "usage: compound_instructions body|body_tracked|compound|compound_tracked|margin|"
                 "margin_tracked N "
                 "[print] (N >= 1 pieces per body)\n");
    return 2;
  }
  const Work w = mode.ends_with("_tracked") ? path_work(n) : cold_work(n);
  Checksum sum(print);
  run_queries(mode, w, sum);
  std::printf("%s N = %d: ", mode.c_str(), n);
  sum.print();
  return 0;
}
