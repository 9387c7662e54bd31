// Triangle-mesh distance benchmark (issue 12): FCL's protocol on its own
// test meshes, proxima's TriangleMesh against FCL 0.7's BVHModel with
// fcl::distance, side by side in one run.
//
//   ./build/release/bench/mesh_bench [--poses N] [--steps S] [--referee K] [mesh directory]
//   (defaults: N = 200 random poses, S = 2000 motion steps, K = 10 refereed
//   poses of each kind, directory bench/data/fcl)
//
// Workloads, env.obj at the identity, rob.obj at each pose:
//   random   translations uniform in [-3000, 3000] x [-3000, 3000] x
//            [0, 3000] and uniform random rotations (FCL's and Coal's test
//            protocol), seeded;
//   motion   rob along a smooth path through env: translation on a
//            Lissajous curve across the box, rotation turning slowly, S steps.
// Systems:
//   proxima cold      distance(mesh, pose, mesh, pose) without a cache;
//   proxima tracked   the same with one MeshCache kept over the sequence;
//   FCL OBBRSS, RSS   fcl::distance on BVHModel<OBBRSS> / <RSS> (built from
//                     the same vertices and triangles), DistanceRequest with
//                     enable_nearest_points, rel_err = abs_err = 0 (exact).
//                     FCL's mesh distance has no tracking: its row is cold.
// Per system: median time per query (each pose timed separately, medians over
// 3 repetitions of the sequence), median triangle pairs tested (proxima),
// and the largest disagreement with the referee, distance_all_pairs (every
// triangle pair with the closed-form kernel), on K poses of each kind.
// Then: mesh against convex (env against the hull of rob along the motion,
// cold and tracked; the same hull as a closed mesh, mesh against mesh; FCL
// BVHModel<OBBRSS> against fcl::Convexd of the same hull), the exact triangle-triangle kernel's
// time, and the build of a ~10^6-triangle mesh (time, bytes against the raw vertices + triangles).
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/distance.h>
#include <proxima/geometry/closest_point.h>
#include <proxima/query/distance.h>
#include <proxima/io.h>
#include <proxima/query/mesh_distance.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "geometry/triangle_distance.h"
#include "peers/fcl_convex.h"

namespace {

using proxima::Pose;
using proxima::TriangleMesh;
using proxima::Vec3;
using Clock = std::chrono::steady_clock;

struct MeshFile {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
};

MeshFile load(const std::string& path) {
  proxima::PointCloud cloud = proxima::read_points(path);
  return {std::move(cloud.points), std::move(cloud.triangles)};
}

fcl::Transform3d to_fcl(const Pose& p) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = p.rotation;
  tf.translation() = p.translation;
  return tf;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

proxima::Quat random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return proxima::Quat(n(rng), n(rng), n(rng), n(rng)).normalized();
}

struct Row {
  std::string name;
  std::vector<double> times;  // per query, microseconds
  std::vector<double> pairs;
  double worst = 0.0;  // largest |distance - referee|
};

void print_row(const Row& r, double fcl_time) {
  std::printf("  %-18s %10.2f us  %8.0f pairs  %7.2fx FCL OBBRSS  max |d - ref| %.3g\n",
              r.name.c_str(), median(r.times), median(r.pairs), fcl_time / median(r.times),
              r.worst);
}

template <class F>
double time_us(F&& f) {
  const auto t0 = Clock::now();
  f();
  return std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
}

void run(const char* title, const TriangleMesh& env, const TriangleMesh& rob,
         const std::vector<Pose>& poses, const fcl::BVHModel<fcl::OBBRSSd>& env_obbrss,
         const fcl::BVHModel<fcl::OBBRSSd>& rob_obbrss, const fcl::BVHModel<fcl::RSSd>& env_rss,
         const fcl::BVHModel<fcl::RSSd>& rob_rss, int referee_count) {
  Row cold{"proxima cold", {}, {}, 0}, tracked{"proxima tracked", {}, {}, 0};
  Row obbrss{"FCL OBBRSS", {}, {}, 0}, rss{"FCL RSS", {}, {}, 0};
  std::vector<double> d_cold(poses.size()), d_tracked(poses.size()), d_obbrss(poses.size()),
      d_rss(poses.size());
  int intersecting = 0;
  std::vector<double> pairs_in, pairs_out, nodes_in, nodes_out;
  for (int rep = 0; rep < 3; ++rep) {
    proxima::MeshCache cache;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      proxima::MeshResult r;
      cold.times.push_back(time_us([&] { r = proxima::distance(env, Pose(), rob, poses[i]); }));
      if (rep == 0) {
        cold.pairs.push_back(r.pairs_tested);
        d_cold[i] = r.distance;
        intersecting += r.status == proxima::Status::intersecting ? 1 : 0;
        (r.status == proxima::Status::intersecting ? pairs_in : pairs_out)
            .push_back(r.pairs_tested);
        (r.status == proxima::Status::intersecting ? nodes_in : nodes_out)
            .push_back(r.nodes_tested);
      }
      tracked.times.push_back(
          time_us([&] { r = proxima::distance(env, Pose(), rob, poses[i], {}, &cache); }));
      if (rep == 0) {
        tracked.pairs.push_back(r.pairs_tested);
        d_tracked[i] = r.distance;
      }
      const fcl::Transform3d tf_a = fcl::Transform3d::Identity(), tf_b = to_fcl(poses[i]);
      fcl::DistanceRequestd request(true, false, 0.0, 0.0);
      fcl::DistanceResultd res1, res2;
      obbrss.times.push_back(
          time_us([&] { fcl::distance(&env_obbrss, tf_a, &rob_obbrss, tf_b, request, res1); }));
      rss.times.push_back(
          time_us([&] { fcl::distance(&env_rss, tf_a, &rob_rss, tf_b, request, res2); }));
      if (rep == 0) {
        d_obbrss[i] = std::max(res1.min_distance, 0.0);
        d_rss[i] = std::max(res2.min_distance, 0.0);
      }
    }
  }
  // The referee on evenly spaced poses.
  // --referee 0 skips it (the header line says so; the rows' errors then read 0).
  const std::size_t stride =
      referee_count > 0 ? std::max<std::size_t>(1, poses.size() / static_cast<std::size_t>(referee_count)) : 1;
  int refereed = 0;
  double referee_time = 0.0;
  for (std::size_t i = 0; i < poses.size() && refereed < referee_count; i += stride, ++refereed) {
    proxima::MeshResult ref;
    referee_time += time_us([&] { ref = proxima::distance_all_pairs(env, Pose(), rob, poses[i]); });
    const double d = ref.distance;
    cold.worst = std::max(cold.worst, std::abs(d_cold[i] - d));
    tracked.worst = std::max(tracked.worst, std::abs(d_tracked[i] - d));
    obbrss.worst = std::max(obbrss.worst, std::abs(d_obbrss[i] - d));
    rss.worst = std::max(rss.worst, std::abs(d_rss[i] - d));
  }
  const double fcl_time = median(obbrss.times);
  if (refereed > 0)
    std::printf("%s: %zu poses (%d intersecting), refereed on %d (brute force %.0f ms each)\n", title,
                poses.size(), intersecting, refereed, referee_time / 1000.0 / refereed);
  else
    std::printf("%s: %zu poses (%d intersecting), not refereed (--referee 0)\n", title, poses.size(),
                intersecting);
  for (const Row* r : {&cold, &tracked, &obbrss, &rss}) print_row(*r, fcl_time);
  std::printf(
      "  cold, median triangle pairs / node pairs tested: intersecting %.0f / %.0f, apart %.0f / "
      "%.0f\n",
      median(pairs_in), median(nodes_in), median(pairs_out), median(nodes_out));
}

}  // namespace

int main(int argc, char** argv) {
  int pose_count = 200, steps = 2000, referee = 10;
  std::string dir = PROXIMA_BENCH_DATA "/fcl";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--poses" && i + 1 < argc) {
      pose_count = std::atoi(argv[++i]);
    } else if (arg == "--steps" && i + 1 < argc) {
      steps = std::atoi(argv[++i]);
    } else if (arg == "--referee" && i + 1 < argc) {
      referee = std::atoi(argv[++i]);
      if (referee < 0) {
        std::fprintf(stderr, "mesh_bench: --referee takes a count >= 0, got %s\n", argv[i]);
        return 2;
      }
    } else {
      dir = arg;
    }
  }
  const MeshFile env_file = load(dir + "/env.obj");
  const MeshFile rob_file = load(dir + "/rob.obj");
  const TriangleMesh env(env_file.vertices, env_file.triangles);
  const TriangleMesh rob(rob_file.vertices, rob_file.triangles);
  std::printf("env: %d vertices, %d triangles, closed %d, %zu degenerate, %zu components\n",
              env.vertex_count(), env.triangle_count(), env.is_closed() ? 1 : 0,
              env.degenerate_triangles().size(), env.component_vertices().size());
  std::printf("rob: %d vertices, %d triangles, closed %d, %zu degenerate, %zu components\n",
              rob.vertex_count(), rob.triangle_count(), rob.is_closed() ? 1 : 0,
              rob.degenerate_triangles().size(), rob.component_vertices().size());
  const auto env_obbrss =
      proxima::bench::fcl_mesh<fcl::OBBRSSd>(env_file.vertices, env_file.triangles);
  const auto rob_obbrss =
      proxima::bench::fcl_mesh<fcl::OBBRSSd>(rob_file.vertices, rob_file.triangles);
  const auto env_rss = proxima::bench::fcl_mesh<fcl::RSSd>(env_file.vertices, env_file.triangles);
  const auto rob_rss = proxima::bench::fcl_mesh<fcl::RSSd>(rob_file.vertices, rob_file.triangles);

  std::mt19937_64 rng(20261125);
  std::vector<Pose> random_poses;
  for (int i = 0; i < pose_count; ++i) {
    random_poses.emplace_back(
        random_rotation(rng),
        Vec3(uniform(rng, -3000, 3000), uniform(rng, -3000, 3000), uniform(rng, 0, 3000)));
  }
  run("random poses", env, rob, random_poses, *env_obbrss, *rob_obbrss, *env_rss, *rob_rss,
      referee);

  std::vector<Pose> motion;
  const proxima::Quat q0 = random_rotation(rng);
  for (int i = 0; i < steps; ++i) {
    const double s = 2.0 * M_PI * i / steps;
    const proxima::Quat turn(Eigen::AngleAxisd(s, Vec3(0.3, 0.5, 0.8).normalized()));
    motion.emplace_back(turn * q0, Vec3(2500 * std::sin(s), 2500 * std::sin(2 * s + 0.4),
                                        1500 + 1200 * std::sin(3 * s + 1.1)));
  }
  run("smooth motion", env, rob, motion, *env_obbrss, *rob_obbrss, *env_rss, *rob_rss, referee);

  // Mesh against convex: env against the hull of rob (a solid), along the
  // motion; FCL: BVHModel<OBBRSS> against fcl::Convexd of the same hull
  // (GST_LIBCCD, its default solver).
  {
    const proxima::ConvexPolytope hull(rob_file.vertices);
    const auto fcl_hull = proxima::bench::fcl_convex(hull, "rob hull");
    // The same hull as a closed triangle mesh (its faces fanned), queried
    // mesh against mesh: the other way to put a convex body against a mesh.
    std::vector<proxima::TriangleMesh::Triangle> hull_triangles;
    for (int f = 0; f < hull.face_count(); ++f) {
      const auto face = hull.face(f);
      for (std::size_t k = 1; k + 1 < face.size(); ++k)
        hull_triangles.push_back({static_cast<std::uint32_t>(face[0]),
                                  static_cast<std::uint32_t>(face[k]),
                                  static_cast<std::uint32_t>(face[k + 1])});
    }
    const TriangleMesh hull_mesh(hull.vertices(), hull_triangles);
    std::vector<double> as_mesh_cold, as_mesh_tracked;
    int status_differs = 0;
    std::vector<double> cold, tracked, fcl_times, pairs;
    double worst = 0.0;
    int intersecting = 0;
    for (int rep = 0; rep < 3; ++rep) {
      proxima::MeshCache cache, mesh_cache;
      for (std::size_t i = 0; i < motion.size(); ++i) {
        proxima::MeshResult r, w, m, mt;
        as_mesh_cold.push_back(
            time_us([&] { m = proxima::distance(env, Pose(), hull_mesh, motion[i]); }));
        as_mesh_tracked.push_back(time_us(
            [&] { mt = proxima::distance(env, Pose(), hull_mesh, motion[i], {}, &mesh_cache); }));
        cold.push_back(time_us([&] { r = proxima::distance(env, Pose(), hull, motion[i]); }));
        tracked.push_back(
            time_us([&] { w = proxima::distance(env, Pose(), hull, motion[i], {}, &cache); }));
        fcl::DistanceRequestd request(true, false, 0.0, 0.0);
        fcl::DistanceResultd res;
        fcl_times.push_back(time_us([&] {
          fcl::distance(env_obbrss.get(), fcl::Transform3d::Identity(), fcl_hull.get(),
                        to_fcl(motion[i]), request, res);
        }));
        if (rep == 0) {
          pairs.push_back(r.pairs_tested);
          intersecting += r.status == proxima::Status::intersecting ? 1 : 0;
          worst = std::max(worst, std::abs(r.distance - w.distance));
          if (m.status != r.status) ++status_differs;
          if (r.status == proxima::Status::separated && m.status == r.status)
            worst = std::max(worst, std::abs(r.distance - m.distance));
          if (r.status == proxima::Status::separated)
            worst = std::max(worst, std::abs(r.distance - res.min_distance));
        }
      }
    }
    std::printf("mesh vs convex (env vs hull of rob), smooth motion: %zu poses (%d intersecting)\n",
                motion.size(), intersecting);
    std::printf("  proxima cold       %10.2f us  %8.0f triangles\n", median(cold), median(pairs));
    std::printf("  proxima tracked    %10.2f us\n", median(tracked));
    std::printf(
        "  hull as a closed mesh (closed %d), mesh-mesh: cold %.2f us, tracked %.2f us, "
        "status differs on %d poses\n",
        hull_mesh.is_closed() ? 1 : 0, median(as_mesh_cold), median(as_mesh_tracked),
        status_differs);
    std::printf(
        "  FCL OBBRSS-Convex  %10.2f us  (largest |proxima - FCL| where separated, and "
        "|cold - tracked|, |convex - closed mesh|: %.3g)\n",
        median(fcl_times), worst);
  }

  // The triangle-triangle kernel alone, on rob's triangles against env's.
  {
    std::vector<double> times;
    double sink = 0.0;
    const auto t0 = Clock::now();
    int n = 0;
    for (int i = 0; i < env.triangle_count(); i += 7) {
      for (int j = 0; j < rob.triangle_count(); ++j, ++n) {
        const auto& ta = env.triangle(i);
        const auto& tb = rob.triangle(j);
        const auto r = proxima::closest_triangle_triangle(
            env.vertex(static_cast<int>(ta[0])), env.vertex(static_cast<int>(ta[1])),
            env.vertex(static_cast<int>(ta[2])), rob.vertex(static_cast<int>(tb[0])),
            rob.vertex(static_cast<int>(tb[1])), rob.vertex(static_cast<int>(tb[2])));
        sink += r.distance_squared;
      }
    }
    const double ns = std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / n;
    // The traversal's fast kernel on the same pairs (triangles prepared
    // once, as the traversal's leaf cache does).
    const auto tol = proxima::kernel_tolerance(std::max(env.scale(), rob.scale()));
    std::vector<proxima::detail::FastTriangle> fa, fb;
    for (int i = 0; i < env.triangle_count(); i += 7) {
      const auto& t = env.triangle(i);
      fa.emplace_back(env.vertex(static_cast<int>(t[0])), env.vertex(static_cast<int>(t[1])),
                      env.vertex(static_cast<int>(t[2])), tol.min_sin_squared);
    }
    for (int j = 0; j < rob.triangle_count(); ++j) {
      const auto& t = rob.triangle(j);
      fb.emplace_back(rob.vertex(static_cast<int>(t[0])), rob.vertex(static_cast<int>(t[1])),
                      rob.vertex(static_cast<int>(t[2])), tol.min_sin_squared);
    }
    double fast_sink = 0.0;
    const auto t1 = Clock::now();
    for (const auto& x : fa)
      for (const auto& y : fb) fast_sink += proxima::detail::triangle_distance_squared(x, y, tol);
    const double fast_ns = std::chrono::duration<double, std::nano>(Clock::now() - t1).count() / n;
    std::printf(
        "triangle-triangle kernel: exact twin %.0f ns, fast %.0f ns per pair (%d pairs, "
        "checksums %g %g)\n",
        ns, fast_ns, n, sink, fast_sink);
  }

  // Build of a ~10^6-triangle mesh: a wavy height field of 708 x 708 cells.
  {
    const int n = 708;
    std::vector<Vec3> v;
    std::vector<TriangleMesh::Triangle> t;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j)
        v.emplace_back(i, j, 20.0 * std::sin(0.05 * i) * std::cos(0.07 * j));
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const auto a = static_cast<std::uint32_t>(i * (n + 1) + j);
        const auto b = a + 1, c = a + static_cast<std::uint32_t>(n + 1), d = c + 1;
        t.push_back({a, b, d});
        t.push_back({a, d, c});
      }
    }
    std::vector<double> times;
    std::size_t bytes = 0;
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = Clock::now();
      const TriangleMesh m(v, t);
      times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      bytes = m.memory_bytes();
    }
    const double raw = static_cast<double>(v.size() * sizeof(Vec3) + t.size() * sizeof(t[0]));
    std::printf(
        "build: %zu triangles, %zu vertices: %.3f s (median of 3), %.1f MB = %.2fx the raw "
        "vertices and triangles (%.1f MB)\n",
        t.size(), v.size(), median(times), bytes / 1e6, bytes / raw, raw / 1e6);
  }
  return 0;
}
