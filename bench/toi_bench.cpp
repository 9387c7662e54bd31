// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Time of impact, proxima against FCL 0.7's continuousCollide (conservative
// advancement, interpolated motion: the same motion as proxima's, constant
// linear and angular velocity about the body frame's origin) and Bullet
// 3.24's btContinuousConvexCollision (conservative advancement on GJK, the
// motion from the same start and end transforms, btTransformUtil's constant
// velocities: the same motion again; double precision, margin 0), on the
// same motions, side by side in one run:
//
//   ./build/release/bench/toi_bench [motions per N, default 200]
//
// Hulls of N points on unit spheres, N = 8 .. 4096. B starts 3 to 5 away
// from A in a random direction and ends on the other side of A (so most
// motions meet), turning up to a full turn about a random axis; A turns up
// to a half turn in place. Per N: the median time per query, the mean
// number of distance queries (advancement steps) for motions that meet,
// and each peer's misses (no contact where proxima found one) and largest
// time error |t_peer - t_proxima| (proxima's t is tested never to be after
// the true first contact and within 1e-9 of the size in distance,
// tests/motion/time_of_impact_test.cpp).
//
// Then compounds (proxima only): a grid of K convex pieces (hulls of 12
// points) turning in place against a hull of 64 points thrown through it
// while turning, the same kind of motions. Per K: the median time of
// proxima's pruned time of impact (the Body call: piece pairs in order of
// their moving bounding balls, src/motion/time_of_impact.cpp), the mean number of
// piece pairs advanced and of distance queries, and the median time of
// every piece pair advanced on its own (each piece re-hulled in its body's
// frame, the convex call per pair, the earliest kept: no pruning), with
// the largest difference of the two times.
//
// Then meshes (given a mesh directory, default bench/data/fcl):
// FCL's env.obj (2180 triangles, a box of about 6000 units, fixed) against
// the hull of rob.obj's vertices thrown through it from random poses in
// FCL's test box [-3000, 3000]^2 x [0, 3000] to others, turning up to a
// full turn. Per row: the median time of proxima's time of impact (the
// Body call: the branch and bound over the mesh's triangles,
// src/motion/time_of_impact.cpp), the mean triangles advanced and distance
// queries, and FCL 0.7's continuousCollide on the same motions
// (conservative advancement, BVHModel<OBBRSS> against fcl::Convexd of the
// same hull) with its misses, extra contacts and largest time error
// against proxima's t. Start poses are drawn until clear of env. The mesh
// rows are the only part that reads files.
//
//   ./build/release/bench/toi_bench [motions per N, default 200] [mesh directory]
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/NarrowPhaseCollision/btContinuousConvexCollision.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/continuous_collision.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "peers/fcl_convex.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/compound_distance.h"
#include "proxima/io.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/motion/time_of_impact.h"

namespace {

// FCL's conservative advancement with its libccd solver, linear motion,
// proxima's iteration cap and a time tolerance of 1e-6.
fcl::ContinuousCollisionRequestd fcl_ca_request() {
  fcl::ContinuousCollisionRequestd request;
  request.ccd_motion_type = fcl::CCDM_LINEAR;
  request.ccd_solver_type = fcl::CCDC_CONSERVATIVE_ADVANCEMENT;
  request.gjk_solver_type = fcl::GST_LIBCCD;
  request.num_max_iterations = 256;
  request.toc_err = 1e-6;
  return request;
}

using proxima::ConvexPolytope;
using proxima::Motion;
using proxima::Pose;
using proxima::Quat;
using proxima::Vec3;

std::vector<Vec3> sphere_points(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> pts;
  while (static_cast<int>(pts.size()) < n) {
    const Vec3 p(g(rng), g(rng), g(rng));
    if (p.norm() > 1e-3) pts.push_back(p.normalized());
  }
  return pts;
}

static_assert(sizeof(btScalar) == 8, "toi_bench compares with Bullet in double precision");

// Bullet's hull of the same vertices, margin 0 (as bench/peers/bullet_peer).
std::unique_ptr<btConvexHullShape> bullet_hull(const ConvexPolytope& p) {
  auto shape = std::make_unique<btConvexHullShape>();
  for (const Vec3& v : p.vertices()) shape->addPoint(btVector3(v.x(), v.y(), v.z()), false);
  shape->recalcLocalAabb();
  shape->setMargin(0);
  return shape;
}

btTransform bullet_transform(const Pose& p) {
  const auto& r = p.rotation;
  return btTransform(
      btMatrix3x3(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
      btVector3(p.translation.x(), p.translation.y(), p.translation.z()));
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Case {
  Motion a, b;
};

// The motion FCL and Bullet are given: its two end poses, between which
// they turn the shorter way (FCL's linear motion, Bullet's
// calcTimeOfImpact). A motion from velocities keeps its angular velocity
// and turns through all of it (past a half turn, the longer way), so
// proxima is given the end poses alone too: every library answers the same
// motion, and the misses, extras and t errors compare like with like.
Motion as_peers_see(const Motion& m) { return Motion{m.start, m.end}; }

std::vector<Case> motions(int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Case> out;
  for (int i = 0; i < count; ++i) {
    const Vec3 axis_a = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 axis_b = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 dir = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Pose a0(Quat(g(rng), g(rng), g(rng), g(rng)).normalized(), Vec3::Zero());
    const Pose b0(Quat(g(rng), g(rng), g(rng), g(rng)).normalized(), (3.0 + 2.0 * u(rng)) * dir);
    const Vec3 end_b = -(3.0 + 2.0 * u(rng)) * dir + 0.8 * Vec3(g(rng), g(rng), g(rng));
    out.push_back(
        {as_peers_see(Motion::from_velocity(a0, Vec3::Zero(), M_PI * u(rng) * axis_a)),
         as_peers_see(
             Motion::from_velocity(b0, end_b - b0.translation, 2.0 * M_PI * u(rng) * axis_b))});
  }
  return out;
}

// A side x side x side grid of hulls of 12 points of radius `size`,
// `spacing` apart, centred on the origin.
proxima::CompoundBody grid(int side, double spacing, double size) {
  std::vector<std::vector<Vec3>> sets;
  std::uint32_t seed = 100;
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      for (int k = 0; k < side; ++k) {
        std::vector<Vec3> pts = sphere_points(12, seed++);
        const Vec3 at = spacing * (Vec3(i, j, k) - Vec3::Constant(0.5 * (side - 1)));
        for (Vec3& p : pts) p = size * p + at;
        sets.push_back(pts);
      }
    }
  }
  return proxima::CompoundBody::from_point_sets(sets);
}

// The fastest of three runs of `run` in ns, as every row of this benchmark
// times a query (what `run` writes is the last run's).
template <class Run>
double best_of_three_ns(Run&& run) {
  double best = 1e300;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    best = std::min(
        best,
        std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

void compound_section(int count) {
  std::printf(
      "\n# compounds: K pieces against a hull of 64 points, %d motions per K (median ns per "
      "query)\n",
      count);
  std::printf(
      "| K | proxima ns | pairs advanced | distance queries | contacts | every pair ns | max t "
      "difference |\n|---|---|---|---|---|---|---|\n");
  for (const int side : {3, 5}) {
    const proxima::CompoundBody compound = grid(side, 3.0 / side, 1.0 / side);
    const proxima::Body a(compound);
    const proxima::Body b(ConvexPolytope(sphere_points(64, 3)));
    std::vector<proxima::Body> pieces;
    for (const proxima::CompoundPiece& piece : compound.pieces()) {
      std::vector<Vec3> placed;
      for (const Vec3& v : piece.polytope->vertices()) placed.push_back(piece.pose.apply(v));
      pieces.emplace_back(ConvexPolytope(placed));
    }
    const std::vector<Case> cases = motions(count, 99u + static_cast<std::uint32_t>(side));
    std::vector<double> ours_ns, every_ns;
    long pairs = 0, queries = 0;
    int contacts = 0;
    double worst = 0.0;
    for (const Case& c : cases) {
      proxima::ImpactResult r;
      ours_ns.push_back(best_of_three_ns([&] { r = proxima::time_of_impact(a, c.a, b, c.b); }));
      pairs += r.pairs_advanced;
      queries += r.iterations;
      contacts += r.status == proxima::ImpactStatus::contact ? 1 : 0;
      double earliest = 1.0;
      every_ns.push_back(best_of_three_ns([&] {
        earliest = 1.0;
        for (const proxima::Body& piece : pieces) {
          const proxima::ImpactResult p = proxima::time_of_impact(piece, c.a, b, c.b);
          if (p.status != proxima::ImpactStatus::separated) earliest = std::min(earliest, p.t);
        }
      }));
      worst = std::max(worst, std::abs(earliest - r.t));
    }
    std::printf("| %d | %.0f | %.1f | %.1f | %d/%d | %.0f | %.2g |\n", compound.piece_count(),
                median(ours_ns), static_cast<double>(pairs) / count,
                static_cast<double>(queries) / count, contacts, count, median(every_ns), worst);
  }
}

void mesh_section(int count, const std::string& dir) {
  const std::string env_path = dir + "/env.obj", rob_path = dir + "/rob.obj";
  if (!std::filesystem::exists(env_path) || !std::filesystem::exists(rob_path)) {
    std::printf("\n# meshes: %s or %s not found, skipped\n", env_path.c_str(), rob_path.c_str());
    return;
  }
  const proxima::PointCloud env = proxima::read_points(env_path);
  const proxima::PointCloud rob = proxima::read_points(rob_path);
  const proxima::Body mesh(proxima::TriangleMesh(env.points, env.triangles));
  const ConvexPolytope hull(rob.points);
  const proxima::Body convex(hull);
  const auto fmesh = proxima::bench::fcl_mesh<fcl::OBBRSSd>(env.points, env.triangles);
  const auto fhull = proxima::bench::fcl_convex(hull, "toi_bench: rob hull");
  std::printf(
      "\n# meshes: env.obj (%d triangles, fixed) against the hull of rob.obj (%d vertices), %d "
      "motions (median ns per query)\n",
      mesh.mesh()->triangle_count(), hull.vertex_count(), count);
  std::printf(
      "| proxima ns | triangles advanced | distance queries | contacts | overlapping at 0 | FCL CA "
      "ns | FCL misses | FCL extra | FCL max t error |\n|---|---|---|---|---|---|---|---|---|\n");
  std::mt19937 rng(2024);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto in_box = [&] {
    return Vec3(6000 * u(rng) - 3000, 6000 * u(rng) - 3000, 3000 * u(rng));
  };
  std::vector<double> ours_ns, fcl_ns;
  long pairs = 0, queries = 0;
  int contacts = 0, overlapping = 0, misses = 0, extra = 0, timed = 0;
  double worst = 0.0;
  const Motion still = Motion::fixed(Pose::identity());
  for (int i = 0; i < count; ++i) {
    // A start pose clear of env (its inside boxes are many: FCL's random
    // poses overlap more often than not), drawn until proxima's distance
    // says so.
    Pose b0;
    do {
      b0 = Pose(Quat(g(rng), g(rng), g(rng), g(rng)).normalized(), in_box());
    } while (proxima::distance(mesh, Pose::identity(), convex, b0).signed_distance() <= 0.0);
    const Vec3 to = in_box();
    const Motion mb = as_peers_see(Motion::from_velocity(
        b0, to - b0.translation, 2.0 * M_PI * u(rng) * Vec3(g(rng), g(rng), g(rng)).normalized()));
    proxima::ImpactResult r;
    const double ns =
        best_of_three_ns([&] { r = proxima::time_of_impact(mesh, still, convex, mb); });
    if (r.status == proxima::ImpactStatus::intersecting) {
      ++overlapping;
      continue;
    }
    ++timed;
    ours_ns.push_back(ns);
    pairs += r.pairs_advanced;
    queries += r.iterations;
    const bool ours_hit = r.status == proxima::ImpactStatus::contact;
    contacts += ours_hit ? 1 : 0;

    const fcl::ContinuousCollisionRequestd request = fcl_ca_request();
    fcl::ContinuousCollisionResultd result;
    fcl_ns.push_back(best_of_three_ns([&] {
      result = fcl::ContinuousCollisionResultd();
      fcl::continuousCollide(fmesh.get(), proxima::bench::fcl_transform(still.start),
                             proxima::bench::fcl_transform(still.end), fhull.get(),
                             proxima::bench::fcl_transform(mb.start),
                             proxima::bench::fcl_transform(mb.end), request, result);
    }));
    if (ours_hit && !result.is_collide) ++misses;
    if (!ours_hit && result.is_collide) ++extra;
    if (ours_hit && result.is_collide)
      worst = std::max(worst, std::abs(result.time_of_contact - r.t));
  }
  std::printf("| %.0f | %.1f | %.1f | %d/%d | %d | %.0f | %d | %d | %.2g |\n", median(ours_ns),
              timed > 0 ? static_cast<double>(pairs) / timed : 0.0,
              timed > 0 ? static_cast<double>(queries) / timed : 0.0, contacts, timed, overlapping,
              median(fcl_ns), misses, extra, worst);
}

}  // namespace

int main(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 200;
  if (count < 1) {
    std::fprintf(stderr, "usage: toi_bench [motions per N >= 1] [mesh directory]\n");
    return 2;
  }
  const std::string mesh_dir = argc > 2 ? argv[2] : PROXIMA_BENCH_DATA "/fcl";
  std::printf(
      "# time of impact, %d motions per N (median ns per query; steps: mean distance queries of "
      "motions that meet)\n",
      count);
  std::printf(
      "| N | proxima ns | proxima steps | contacts | FCL CA ns | FCL misses | FCL extra | "
      "FCL max t error | Bullet ns | Bullet misses | Bullet extra | Bullet max t error |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const int n : {8, 64, 512, 4096}) {
    const ConvexPolytope a(sphere_points(n, 1));
    const ConvexPolytope b(sphere_points(n, 2));
    const auto fa = proxima::bench::fcl_convex(a, "toi_bench: A");
    const auto fb = proxima::bench::fcl_convex(b, "toi_bench: B");
    const auto ba = bullet_hull(a);
    const auto bb = bullet_hull(b);
    std::vector<double> bullet_ns;
    int bullet_misses = 0, bullet_extra = 0;
    double bullet_worst = 0.0;
    const std::vector<Case> cases = motions(count, 7u + static_cast<std::uint32_t>(n));
    std::vector<double> ours_ns, fcl_ns;
    long steps = 0;
    int contacts = 0, misses = 0, extra = 0;
    double worst = 0.0;
    for (const Case& c : cases) {
      // Interleaved: each motion timed for both libraries in turn, best of 3.
      proxima::ImpactResult r;
      ours_ns.push_back(best_of_three_ns([&] { r = proxima::time_of_impact(a, c.a, b, c.b); }));
      const bool ours_hit = r.status == proxima::ImpactStatus::contact ||
                            r.status == proxima::ImpactStatus::intersecting;
      if (ours_hit) {
        ++contacts;
        steps += r.iterations;
      }

      const fcl::ContinuousCollisionRequestd request = fcl_ca_request();
      fcl::ContinuousCollisionResultd result;
      fcl_ns.push_back(best_of_three_ns([&] {
        result = fcl::ContinuousCollisionResultd();
        fcl::continuousCollide(fa.get(), proxima::bench::fcl_transform(c.a.start),
                               proxima::bench::fcl_transform(c.a.end), fb.get(),
                               proxima::bench::fcl_transform(c.b.start),
                               proxima::bench::fcl_transform(c.b.end), request, result);
      }));
      if (ours_hit && !result.is_collide) ++misses;
      if (!ours_hit && result.is_collide) ++extra;
      if (ours_hit && result.is_collide)
        worst = std::max(worst, std::abs(result.time_of_contact - r.t));

      // Bullet: a fresh solver per query, as its users call it.
      bool bullet_hit = false;
      double bullet_t = 0.0;
      bullet_ns.push_back(best_of_three_ns([&] {
        btVoronoiSimplexSolver simplex;
        btGjkEpaPenetrationDepthSolver epa;
        btContinuousConvexCollision cast(ba.get(), bb.get(), &simplex, &epa);
        btConvexCast::CastResult cast_result;
        bullet_hit = cast.calcTimeOfImpact(bullet_transform(c.a.start), bullet_transform(c.a.end),
                                           bullet_transform(c.b.start), bullet_transform(c.b.end),
                                           cast_result);
        bullet_t = cast_result.m_fraction;
      }));
      if (ours_hit && !bullet_hit) ++bullet_misses;
      if (!ours_hit && bullet_hit) ++bullet_extra;
      if (ours_hit && bullet_hit) bullet_worst = std::max(bullet_worst, std::abs(bullet_t - r.t));
    }
    std::printf("| %d | %.0f | %.2f | %d/%d | %.0f | %d | %d | %.2g | %.0f | %d | %d | %.2g |\n", n,
                median(ours_ns), contacts > 0 ? static_cast<double>(steps) / contacts : 0.0,
                contacts, count, median(fcl_ns), misses, extra, worst, median(bullet_ns),
                bullet_misses, bullet_extra, bullet_worst);
  }
  compound_section(count);
  mesh_section(count, mesh_dir);
  return 0;
}
