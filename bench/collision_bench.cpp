// Collision checks at planner speed (issue 26): the boolean and margin
// queries (proxima/query/margin.h) against FCL 0.7 on the same pairs and poses.
// The robotics example's arm (the Franka Panda's seven links and hand,
// examples/panda_arm.h), every non-adjacent pair of links (28), with the
// links as their hulls and as their meshes as given, along the example's
// trajectory (160 configurations, link origins moving a few mm a step) and
// on 160 random configurations.
//
//   ./build/release/bench/collision_bench [--repeat R] [mesh directory]   (R = 5)
//
// Per configuration, timed separately in the same loop so that machine
// noise falls on every system:
//   proxima intersects, tracked   intersects() on each pair, one cache per
//                                 pair (DistanceCache for hulls, MeshCache
//                                 for meshes) carried along;
//   proxima intersects, cold      the same without a cache;
//   proxima within 5 cm, tracked  within_margin(..., 0.05, ...), tracked;
//   intersects_batch, tracked     the same as one batch call per configuration
//                                 (within_margin_batch, margin 0; the
//                                 poses gathered into its arrays inside the
//                                 timing), a cache per row (DistanceCache
//                                 for hulls, BodyCache for meshes);
//   within_margin_batch 5 cm      the batch with the 5 cm margin;
//   FCL collide                   fcl::collide (default CollisionRequest:
//                                 one contact), fcl::Convexd of the same
//                                 hull / BVHModel<OBBRSS> of the same mesh;
//   FCL distance <= 5 cm          fcl::distance (default request) compared
//                                 with 5 cm: FCL's way to a margin answer.
// Times: the median over all configurations of all repetitions of one
// configuration's time. Verdicts: on every configuration of the first
// repetition, each proxima answer against its slow twin, the full distance
// query (cold) compared with the margin: wrong verdicts outside the contact
// band (64 u R of the margin; none may be wrong there), and FCL's collide
// and distance verdicts against the same referee.
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>
#include <proxima/io.h>
#include <proxima/query/batch.h>
#include <proxima/query/distance.h>
#include <proxima/query/margin.h>
#include <proxima/query/mesh_distance.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "panda_arm.h"
#include "peers/fcl_convex.h"

#ifndef PROXIMA_PANDA_MESH_DIR
#define PROXIMA_PANDA_MESH_DIR "examples/data/panda"
#endif

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kBodies = 9;
constexpr double kMargin = 0.05;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Verdicts of one system against the referee's.
struct Verdicts {
  int checked = 0;
  int wrong = 0;    // outside the band of the margin
  int in_band = 0;  // referee within the band: either verdict is right
  int yes = 0;
  void add(bool said_within, double referee_distance, bool referee_contact, double margin,
           double band) {
    ++checked;
    yes += said_within ? 1 : 0;
    if (!referee_contact && std::abs(referee_distance - margin) <= band) {
      ++in_band;
      return;
    }
    const bool want = referee_contact || referee_distance <= margin;
    wrong += want != said_within ? 1 : 0;
  }
};

struct Links {
  std::vector<std::shared_ptr<const proxima::ConvexPolytope>> hulls;
  std::vector<std::shared_ptr<const proxima::TriangleMesh>> meshes;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> fcl_hulls;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> fcl_meshes;
};

enum System {
  tracked,
  cold,
  margin_tracked,
  batch_tracked,
  batch_margin,
  fcl_collide,
  fcl_distance,
  kSystems
};
const std::array<const char*, kSystems> kNames = {
    "proxima intersects, tracked", "proxima intersects, cold", "proxima within 5 cm, tracked",
    "intersects_batch, tracked",   "within_margin_batch 5 cm",  "FCL collide",
    "FCL distance <= 5 cm"};

void run_case(const Links& links, bool meshes, const char* motion,
              const std::vector<std::array<proxima::Pose, kBodies>>& poses, int repeat) {
  std::vector<std::pair<int, int>> pairs;
  for (int a = 0; a < kBodies; ++a)
    for (int b = a + 2; b < kBodies; ++b) pairs.emplace_back(a, b);
  std::array<std::vector<double>, kSystems> times;
  std::array<Verdicts, kSystems> verdicts;
  std::vector<proxima::DistanceCache> hull_caches(pairs.size()), hull_margin(pairs.size());
  std::vector<proxima::MeshCache> mesh_caches(pairs.size()), mesh_margin(pairs.size());
  // The batches: one call per configuration over every pair (hulls as
  // BatchPairs with DistanceCaches, meshes as BodyPairs with BodyCaches),
  // in the calling thread (28 pairs are under two of the batch's grains).
  std::vector<proxima::Body> mesh_bodies;
  for (const auto& m : links.meshes) mesh_bodies.emplace_back(m);
  std::vector<proxima::BatchPair> batch_pairs;
  std::vector<proxima::BodyPair> body_pairs;
  for (const auto& [a, b] : pairs) {
    batch_pairs.push_back({links.hulls[a].get(), links.hulls[b].get()});
    body_pairs.push_back({&mesh_bodies[a], &mesh_bodies[b]});
  }
  std::vector<proxima::DistanceCache> batch_hull_caches(pairs.size()),
      batch_hull_margin(pairs.size());
  std::vector<proxima::BodyCache> batch_body_caches(pairs.size()), batch_body_margin(pairs.size());
  std::vector<proxima::Pose> batch_poses_a(pairs.size()), batch_poses_b(pairs.size());
  std::vector<proxima::MarginResult> batch_results(pairs.size());
  long sink = 0;
  long pairs_tested = 0, answers = 0;
  std::vector<double> referee_distance(pairs.size()), band(pairs.size());
  std::vector<char> referee_contact(pairs.size());
  const auto run_proxima = [&](int s, const std::array<proxima::Pose, kBodies>& pose, bool check) {
    const double margin = s == margin_tracked ? kMargin : 0.0;
    const auto start = Clock::now();
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto [a, b] = pairs[k];
      const proxima::MarginResult m =
          meshes ? proxima::within_margin(
                       *links.meshes[a], pose[a], *links.meshes[b], pose[b], margin, {},
                       s == cold ? nullptr : s == tracked ? &mesh_caches[k] : &mesh_margin[k])
                 : proxima::within_margin(
                       *links.hulls[a], pose[a], *links.hulls[b], pose[b], margin, {},
                       s == cold ? nullptr : s == tracked ? &hull_caches[k] : &hull_margin[k]);
      sink += m.is_within() ? 1 : 0;
      if (s == tracked) {
        pairs_tested += m.pairs_tested;
        ++answers;
      }
      if (check)
        verdicts[s].add(m.is_within(), referee_distance[k], referee_contact[k], margin, band[k]);
    }
    times[s].push_back(seconds_since(start));
  };
  const auto run_batch = [&](int s, const std::array<proxima::Pose, kBodies>& pose, bool check) {
    const double margin = s == batch_margin ? kMargin : 0.0;
    const auto start = Clock::now();
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      batch_poses_a[k] = pose[pairs[k].first];
      batch_poses_b[k] = pose[pairs[k].second];
    }
    if (meshes) {
      proxima::within_margin_batch(
          body_pairs, batch_poses_a, batch_poses_b, margin, batch_results,
          s == batch_margin ? batch_body_margin : batch_body_caches, {}, 1);
    } else {
      proxima::within_margin_batch(
          batch_pairs, batch_poses_a, batch_poses_b, margin, batch_results,
          s == batch_margin ? batch_hull_margin : batch_hull_caches, {}, 1);
    }
    times[s].push_back(seconds_since(start));
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      sink += batch_results[k].is_within() ? 1 : 0;
      if (check) {
        verdicts[s].add(batch_results[k].is_within(), referee_distance[k], referee_contact[k],
                        margin, band[k]);
      }
    }
  };
  const auto run_fcl = [&](int s, const std::array<proxima::Pose, kBodies>& pose, bool check) {
    const auto start = Clock::now();
    std::array<fcl::Transform3d, kBodies> tf;
    for (int i = 0; i < kBodies; ++i) tf[i] = proxima::bench::fcl_transform(pose[i]);
    const auto& geometry = meshes ? links.fcl_meshes : links.fcl_hulls;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto [a, b] = pairs[k];
      bool within = false;
      if (s == fcl_collide) {
        fcl::CollisionRequestd request;
        fcl::CollisionResultd result;
        within =
            fcl::collide(geometry[a].get(), tf[a], geometry[b].get(), tf[b], request, result) > 0;
      } else {
        fcl::DistanceRequestd request;
        fcl::DistanceResultd result;
        within = fcl::distance(geometry[a].get(), tf[a], geometry[b].get(), tf[b], request,
                               result) <= kMargin;
      }
      sink += within ? 1 : 0;
      if (check) {
        verdicts[s].add(within, referee_distance[k], referee_contact[k],
                        s == fcl_collide ? 0.0 : kMargin, band[k]);
      }
    }
    times[s].push_back(seconds_since(start));
  };
  // The referee's answers, once.
  std::vector<std::vector<double>> referee_distances(poses.size()), bands(poses.size());
  std::vector<std::vector<char>> referee_contacts(poses.size());
  for (std::size_t c = 0; c < poses.size(); ++c) {
    const auto& pose = poses[c];
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto [a, b] = pairs[k];
      const proxima::DistanceResult d =
          meshes ? proxima::distance(*links.meshes[a], pose[a], *links.meshes[b], pose[b])
                 : proxima::distance(*links.hulls[a], pose[a], *links.hulls[b], pose[b]);
      referee_distances[c].push_back(d.distance);
      referee_contacts[c].push_back(d.status != proxima::Status::separated);
      const double scale_a = meshes ? links.meshes[a]->scale() : links.hulls[a]->scale();
      const double scale_b = meshes ? links.meshes[b]->scale() : links.hulls[b]->scale();
      bands[c].push_back(
          proxima::contact_band(std::max(proxima::magnitude_bound(pose[a], scale_a),
                                         proxima::magnitude_bound(pose[b], scale_b))));
    }
  }
  // Each system runs the whole motion in one pass (a planner's order: the
  // tracked caches follow the motion, and no other system's data evicts
  // its own between two configurations); the passes alternate in a
  // shuffled order in every repetition, so that load changes of the
  // machine fall on all of them.
  std::array<int, kSystems> order = {tracked,      cold,        margin_tracked, batch_tracked,
                                     batch_margin, fcl_collide, fcl_distance};
  std::mt19937 rng(26);
  for (int r = 0; r < repeat; ++r) {
    std::shuffle(order.begin(), order.end(), rng);
    for (const int s : order) {
      for (std::size_t c = 0; c < poses.size(); ++c) {
        referee_distance = referee_distances[c];
        referee_contact = referee_contacts[c];
        band = bands[c];
        if (s == fcl_collide || s == fcl_distance) {
          run_fcl(s, poses[c], r == 0);
        } else if (s == batch_tracked || s == batch_margin) {
          run_batch(s, poses[c], r == 0);
        } else {
          run_proxima(s, poses[c], r == 0);
        }
      }
    }
  }
  std::printf("\n%s, %s: %zu configurations x %d repetitions, %zu pairs each\n",
              meshes ? "meshes" : "hulls", motion, poses.size(), repeat, pairs.size());
  std::printf("%-30s %10s %16s %8s %7s %8s %6s\n", "system", "us/config", "x FCL collide",
              "checked", "within", "in band", "wrong");
  const double base = median(times[fcl_collide]);
  for (int s = 0; s < kSystems; ++s) {
    const double t = median(times[s]);
    std::printf("%-30s %10.2f %16.2f %8d %7d %8d %6d\n", kNames[s], 1e6 * t, base / t,
                verdicts[s].checked, verdicts[s].yes, verdicts[s].in_band, verdicts[s].wrong);
  }
  std::printf("(leaf pairs tested per tracked intersects: %.2f; checksum %ld)\n",
              double(pairs_tested) / double(std::max(answers, 1L)), sink);
}

int run(int repeat, const std::string& mesh_dir) {
  Links links;
  int triangles = 0;
  for (int i = 0; i < kBodies; ++i) {
    const std::string path = mesh_dir + "/" + panda::kLinkNames[i] + ".stl";
    links.meshes.push_back(
        std::make_shared<const proxima::TriangleMesh>(proxima::load_mesh(path).mesh));
    const proxima::TriangleMesh& m = *links.meshes.back();
    triangles += m.triangle_count();
    links.hulls.push_back(std::make_shared<const proxima::ConvexPolytope>(
        std::vector<proxima::Vec3>(m.vertices().begin(), m.vertices().end())));
    links.fcl_meshes.push_back(proxima::bench::fcl_mesh<fcl::OBBRSSd>(m.vertices(), m.triangles()));
    links.fcl_hulls.push_back(proxima::bench::fcl_convex(*links.hulls.back(), path));
  }
  std::printf("Panda collision checks: %d links (%d triangles), margin query %.0f cm\n", kBodies,
              triangles, 100 * kMargin);
  std::vector<std::array<proxima::Pose, kBodies>> trajectory, random;
  for (const auto& q : panda::trajectory(2026, 5, 40)) trajectory.push_back(panda::link_poses(q));
  for (const auto& q : panda::trajectory(7, 161, 1)) random.push_back(panda::link_poses(q));
  for (const bool meshes : {false, true}) {
    run_case(links, meshes, "trajectory", trajectory, repeat);
    run_case(links, meshes, "random configurations", random, repeat);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int repeat = 5;
    std::string mesh_dir = PROXIMA_PANDA_MESH_DIR;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--repeat" && i + 1 < argc) {
        repeat = std::atoi(argv[++i]);
        if (repeat < 1) {
          std::fprintf(stderr, "collision_bench: --repeat needs a positive count, got '%s'\n",
                       argv[i]);
          return 2;
        }
      } else if (!arg.empty() && arg[0] == '-') {
        std::fprintf(stderr, "usage: collision_bench [--repeat R] [mesh directory]\n");
        return 2;
      } else {
        mesh_dir = arg;
      }
    }
    return run(repeat, mesh_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "collision_bench: %s\n", e.what());
    return 2;
  }
}
