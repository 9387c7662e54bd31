// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the `proxima` command-line tool.
//   proxima demo                                   two seeded bodies, every algorithm
//   proxima query [FILE] [--algorithm NAME] ...    JSON Lines in, JSON Lines out
//   proxima distance A B [--pose-a ...] [--json]   distance between two mesh files
//   proxima hull FILE [--out FILE.obj|.off]        hull statistics and export
//   proxima view A B | --query FILE | --scene FILE --out page.html   one HTML page
//
// The paper's experiments and the scene demo, which measure the peers (FCL,
// libccd, Bullet), are the benchmark executables bench/paper_experiments and
// bench/scene_demo (bench/paper): the shipped tool links none of the peers.
//
// Exit codes: 0 when the run completed (a query line with an error answer is
// still a completed run), 1 when the input cannot be read (bad file, bad
// numbers) or the demo fails, 2 for usage errors.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "demo.h"
#include "exit_codes.h"
#include "proxima/core/types.h"
#include "query.h"
#include "robot.h"
#include "robot_srdf.h"
#include "tools.h"
#include "view.h"

namespace {

using proxima::cli::kExitFailure;
using proxima::cli::kExitOk;
using proxima::cli::kExitUsage;

// Upper end of --max-iterations: far above any real need (the default is
// 64); it only keeps a typo from turning the cap off.
constexpr int kMaxIterationsLimit = 1000000;
// Upper end of --threads: far beyond any machine this runs on; it only keeps
// a typo from starting a million threads per block.
constexpr int kMaxThreads = 1024;

proxima::Algorithm parse_algorithm(const std::string& name) {
  if (name == "gjk") return proxima::Algorithm::gjk;
  if (name == "enhanced_gjk") return proxima::Algorithm::enhanced_gjk;
  return proxima::Algorithm::hybrid;
}
// Four numbers in the wrong order are another rotation: the order is a
// named choice, the same flag on every command that reads quaternions, and
// no default (unset: every quaternion must name its order itself, and a bare
// one is refused with both of its readings).
const std::vector<std::string> kQuaternionOrders = {"wxyz", "xyzw"};
// How a mesh file becomes a body (--as): never silently its hull.
const std::vector<std::string> kBodyKinds = {"mesh", "hull", "pieces"};

std::optional<proxima::QuaternionOrder> parse_order(const std::string& name) {
  if (name.empty()) return std::nullopt;
  return name == "xyzw" ? proxima::QuaternionOrder::xyzw : proxima::QuaternionOrder::wxyz;
}

int run_query_command(const std::string& file, const proxima::DistanceOptions& options, int threads,
                      std::optional<proxima::QuaternionOrder> order, std::uint64_t max_line_bytes) {
  // Answers go through std::cout only; untying it from C stdio lets it
  // buffer a whole answer line before the explicit flush.
  std::ios::sync_with_stdio(false);
  proxima::cli::QueryRunSummary summary;
  if (file == "-") {
    summary = proxima::cli::run_queries(std::cin, std::cout, options, threads, order,
                                           max_line_bytes);
  } else {
    // An ifstream opens a directory without complaint and then reads
    // nothing; that would look like an empty, successful run.
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) {
      std::cerr << "proxima query: cannot open '" << file << "': it is a directory\n";
      return kExitFailure;
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      std::cerr << "proxima query: cannot open '" << file << "': " << std::strerror(errno) << "\n";
      return kExitFailure;
    }
    summary = proxima::cli::run_queries(in, std::cout, options, threads, order, max_line_bytes);
  }
  if (summary.too_long_line != 0) {
    std::cerr << "proxima query: "
              << proxima::cli::too_long_message(summary.too_long_line, max_line_bytes) << "\n";
    return kExitFailure;
  }
  if (summary.read_failed) {
    std::cerr << "proxima query: reading the input failed after " << summary.answered
              << " answers\n";
    return kExitFailure;
  }
  if (!std::cout) {
    std::cerr << "proxima query: writing the answers failed\n";
    return kExitFailure;
  }
  return kExitOk;
}

// Each subcommand: its arguments as CLI11 binds them (the addresses stay
// put: one object per subcommand, in main), the function that declares its
// options, and the one that runs it once parsed.
struct QueryArgs {
  CLI::App* app = nullptr;
  std::string file = "-";
  std::string algorithm = "hybrid";
  proxima::DistanceOptions options;
  int threads = 1;
  std::string order;
  std::uint64_t max_line_bytes = proxima::cli::kDefaultMaxLineBytes;
};

void add_query(CLI::App& app, QueryArgs& a) {
  a.app = app.add_subcommand(
      "query",
      "Answer distance queries in JSON Lines, one answer line per query line, in order "
      "(format: docs/query-format.md)");
  a.app->footer(
      "Example:\n"
      "  echo '{\"id\":1,\"a\":{\"vertices\":[[0,0,0],[1,0,0],[0,1,0],[0,0,1]]},"
      "\"b\":{\"vertices\":[[3,0,0],[4,0,0],[3,1,0],[3,0,1]]}}' | proxima query");
  a.app->add_option("FILE", a.file, "Input file of queries; '-' or none reads standard input");
  a.app->add_option("--algorithm", a.algorithm, "Algorithm answering the queries")
      ->check(CLI::IsMember(std::vector<std::string>{"hybrid", "gjk", "enhanced_gjk"}))
      ->capture_default_str();
  a.app
      ->add_option("--max-iterations", a.options.max_iterations,
                   "Iteration cap per query; a capped answer says \"iteration_cap\": true")
      ->check(CLI::Range(1, kMaxIterationsLimit))
      ->capture_default_str();
  a.app
      ->add_option("--quaternion-order", a.order,
                   "Order of a body's bare \"rotation\" numbers: wxyz (scalar first) or xyzw "
                   "(scalar last, as ROS and scipy write them). Without it a rotation must name "
                   "its order: {\"wxyz\": [w, x, y, z]} or {\"xyzw\": [x, y, z, w]}")
      ->check(CLI::IsMember(kQuaternionOrders));
  a.app
      ->add_option("--max-line-size", a.max_line_bytes,
                   "Refuse a query line longer than this many bytes (its error answer is the "
                   "last: reading stops there)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  a.app->add_flag("--extended-precision", a.options.extended_precision,
                  "Full relative accuracy: each separated or touching answer's witness pair "
                  "recomputed in double-double (docs/accuracy.md)");
  a.app
      ->add_option("--threads", a.threads,
                   "Threads answering blocks of queries; answers stay in input order")
      ->check(CLI::Range(1, kMaxThreads))
      ->capture_default_str();
}

int run(QueryArgs& a) {
  a.options.algorithm = parse_algorithm(a.algorithm);
  return run_query_command(a.file, a.options, a.threads, parse_order(a.order), a.max_line_bytes);
}

struct DistanceArgs {
  CLI::App* app = nullptr;
  proxima::cli::DistanceCommand command;
  std::string algorithm = "hybrid";
  std::string order;
  std::string as;
};

void add_distance(CLI::App& app, DistanceArgs& a) {
  a.app = app.add_subcommand(
      "distance",
      "Distance, closest points, normal and witness features between two mesh files (OBJ, "
      "OFF, STL, PLY, XYZ), each read as its convex hull, a triangle mesh or a compound of "
      "hulls (--as)");
  a.app->add_option("A", a.command.file_a, "First body's mesh file")->required();
  a.app->add_option("B", a.command.file_b, "Second body's mesh file")->required();
  a.app
      ->add_option("--pose-a", a.command.pose_a,
                   "Pose of A: translation x y z, then optionally a rotation quaternion in the "
                   "order --quaternion-order names (required with one)")
      ->expected(3, 7)
      ->type_name("x y z [q q q q]");
  a.app
      ->add_option("--pose-b", a.command.pose_b,
                   "Pose of B: translation x y z, then optionally a rotation quaternion in the "
                   "order --quaternion-order names (required with one)")
      ->expected(3, 7)
      ->type_name("x y z [q q q q]");
  a.app
      ->add_option("--quaternion-order", a.order,
                   "Order of the quaternion in --pose-a/--pose-b: wxyz (qw qx qy qz) or xyzw "
                   "(qx qy qz qw, as ROS and scipy write them); no default")
      ->check(CLI::IsMember(kQuaternionOrders));
  a.app->add_option("--algorithm", a.algorithm, "Algorithm answering the query")
      ->check(CLI::IsMember(std::vector<std::string>{"hybrid", "gjk", "enhanced_gjk"}))
      ->capture_default_str();
  a.app->add_flag("--json", a.command.json, "One JSON object instead of the table");
  a.app->add_flag("--extended-precision", a.command.options.extended_precision,
                  "Full relative accuracy: the witness pair's distance recomputed in "
                  "double-double (docs/accuracy.md)");
  a.app
      ->add_option("--as", a.as,
                   "How both files become bodies: mesh (the surface as given), hull (the convex "
                   "hull of every point) or pieces (one hull per OBJ group). Default: the hull "
                   "of a convex file or a point cloud; a non-convex file with faces must be named")
      ->check(CLI::IsMember(kBodyKinds));
  a.app->add_option("--as-a", a.command.as_a, "--as for file A only")->check(CLI::IsMember(kBodyKinds));
  a.app->add_option("--as-b", a.command.as_b, "--as for file B only")->check(CLI::IsMember(kBodyKinds));
  a.app
      ->add_option("--max-file-size", a.command.max_file_bytes,
                   "Refuse an input file larger than this many bytes")
      ->capture_default_str();
  a.app->footer(
      "Example:\n"
      "  proxima distance a.obj b.stl --pose-b 0 0 2 0.7071067811865476 0 0 0.7071067811865476 "
      "--quaternion-order wxyz --json");
}

int run(DistanceArgs& a) {
  a.command.options.algorithm = parse_algorithm(a.algorithm);
  a.command.quaternion_order = parse_order(a.order);
  if (a.command.as_a.empty()) a.command.as_a = a.as;
  if (a.command.as_b.empty()) a.command.as_b = a.as;
  return proxima::cli::run_distance(a.command, std::cout, std::cerr);
}

struct HullArgs {
  CLI::App* app = nullptr;
  proxima::cli::HullCommand command;
};

void add_hull(CLI::App& app, HullArgs& a) {
  a.app = app.add_subcommand("hull", "Hull statistics of a mesh file, and its export as OBJ or OFF");
  a.app->add_option("FILE", a.command.file, "Mesh file (OBJ, OFF, STL, PLY, XYZ)")->required();
  a.app->add_option("--out", a.command.out_file,
                   "Write the hull here; the format from the extension")
      ->check(CLI::Validator(
          [](const std::string& path) {
            return proxima::cli::export_format(path).empty()
                       ? std::string("the hull is written as .obj or .off, not '" + path + "'")
                       : std::string();
          },
          "FILE.obj|FILE.off"));
  a.app->add_flag("--json", a.command.json, "One JSON object instead of the table");
  a.app->add_option("--max-file-size", a.command.max_file_bytes,
                   "Refuse an input file larger than this many bytes")
      ->capture_default_str();
  a.app->footer("Example:\n  proxima hull body.stl --out hull.off");
}

struct ViewArgs {
  CLI::App* app = nullptr;
  proxima::cli::ViewCommand command;
  std::string order;
  std::string algorithm = "hybrid";
};

void add_view(CLI::App& app, ViewArgs& a) {
  a.app = app.add_subcommand(
      "view",
      "Write one self-contained HTML page (three.js inline, no network) showing two bodies, "
      "their closest points, witness features, normal and certificate, or one scene step "
      "(docs/viewer.md)");
  a.app->add_option("A", a.command.file_a, "First body's mesh file");
  a.app->add_option("B", a.command.file_b, "Second body's mesh file");
  a.app->add_option("--pose-a", a.command.pose_a, "Pose of A, as for `proxima distance`")
      ->expected(3, 7)
      ->type_name("x y z [q q q q]");
  a.app->add_option("--pose-b", a.command.pose_b, "Pose of B, as for `proxima distance`")
      ->expected(3, 7)
      ->type_name("x y z [q q q q]");
  a.app->add_option("--as", a.command.as,
                   "How A and B become bodies, as for `proxima distance`: mesh (the surface as "
                   "given), hull (the convex hull of every point) or pieces (one hull per OBJ "
                   "group). Default: the hull of a convex file or a point cloud; a non-convex "
                   "file with faces must be named")
      ->check(CLI::IsMember(kBodyKinds));
  a.app->add_option("--query", a.command.query_file,
                   "A file ('-': standard input) holding one `proxima query` line, then "
                   "optionally its answer line; without one the query is answered here");
  a.app->add_option("--scene", a.command.scene_file,
                   "A file of JSON Lines, one body per line ({\"vertices\": ..., \"rotation\": "
                   "..., \"translation\": ...}): one step of a Scene, close pairs coloured by "
                   "distance");
  a.app->add_option("--margin", a.command.margin,
                   "With --scene: pairs within this distance are drawn")
      ->capture_default_str();
  a.app->add_option("--quaternion-order", a.order,
                   "Order of the bare quaternions (poses, query rotations): wxyz or xyzw; no "
                   "default")
      ->check(CLI::IsMember(kQuaternionOrders));
  a.app->add_option("--algorithm", a.algorithm, "Algorithm answering the query")
      ->check(CLI::IsMember(std::vector<std::string>{"hybrid", "gjk", "enhanced_gjk"}))
      ->capture_default_str();
  a.app->add_option("--max-file-size", a.command.max_file_bytes,
                   "Refuse an input file larger than this many bytes")
      ->capture_default_str();
  a.app->add_option("-o,--out", a.command.out_file, "The page to write ('-': standard output)")
      ->required();
  a.app->footer(
      "Examples:\n"
      "  proxima view a.obj b.stl --pose-b 0 0 2 --out pair.html\n"
      "  proxima view --query query.jsonl --out query.html\n"
      "  proxima view --scene bodies.jsonl --margin 0.1 --out scene.html");
}

int run(ViewArgs& a) {
  // Exactly one input: two files, a query file or a scene file.
  const bool files = !a.command.file_a.empty();
  const int inputs = (files ? 1 : 0) + (a.command.query_file.empty() ? 0 : 1) +
                     (a.command.scene_file.empty() ? 0 : 1);
  if (inputs != 1 || (files && a.command.file_b.empty())) {
    std::cerr << "proxima view: give two mesh files A B, or --query FILE, or --scene FILE "
                 "(exactly one of them)\n";
    return kExitUsage;
  }
  if (!files && (!a.command.pose_a.empty() || !a.command.pose_b.empty())) {
    std::cerr << "proxima view: --pose-a and --pose-b go with two mesh files\n";
    return kExitUsage;
  }
  a.command.options.algorithm = parse_algorithm(a.algorithm);
  a.command.quaternion_order = parse_order(a.order);
  return proxima::cli::run_view(a.command, std::cout, std::cerr);
}

struct RobotArgs {
  CLI::App* app = nullptr;
  proxima::cli::RobotCommand command;
};

void add_robot(CLI::App& app, RobotArgs& a) {
  a.app = app.add_subcommand(
      "robot",
      "A robot from its URDF (and SRDF): answer JSON Lines of configurations with the minimum "
      "signed distance, the close pairs and the gradient (docs/robotics.md)");
  a.app->add_option("FILE", a.command.file,
                    "Input file of configurations; '-' or none reads standard input");
  a.app->add_option("--urdf", a.command.urdf, "The robot's URDF")->required();
  a.app->add_option("--srdf", a.command.srdf,
                    "Its SRDF: the disable_collisions pairs are not tested");
  a.app->add_option("--package-dir", a.command.package_dirs,
                    "Where package:// URIs point: NAME=DIR, or a directory holding packages "
                    "(repeatable)");
  a.app->add_option("--mesh-as", a.command.mesh_as,
                    "How a collision mesh becomes a body: hull, mesh or pieces")
      ->check(CLI::IsMember(std::vector<std::string>{"hull", "mesh", "pieces"}))
      ->capture_default_str();
  a.app->add_option("--margin", a.command.margin,
                    "Pairs whose signed distance is at most this are listed")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  a.app->add_flag("--gradients", a.command.gradients,
                  "Answer each pair's gradient with respect to the joint vector");
  a.app->add_option("--environment", a.command.environment,
                    "JSON Lines of obstacles, one body per line as a query's (\"vertices\", "
                    "\"triangles\", \"radius\", \"pose\") with an optional \"name\"");
  a.app->add_option("--view", a.command.view_out,
                    "Write a viewer page of the last configuration (close pairs drawn, excluded "
                    "pairs never shown as collisions)");
  a.app->footer(
      "Example:\n"
      "  echo '{\"id\":1,\"q\":[0,-0.78,0,-2.36,0,1.57,0.78,0.01]}' |\n"
      "    proxima robot --urdf panda.urdf --srdf panda.srdf --package-dir NAME=DIR --gradients\n"
      "Each line: {\"id\": any, \"q\": [numbers] or {\"joint name\": number, ...}}.");
}

int run(RobotArgs& a) {
  std::ios::sync_with_stdio(false);
  if (a.command.file == "-") return proxima::cli::run_robot(a.command, std::cin, std::cout, std::cerr);
  std::ifstream in(a.command.file, std::ios::binary);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(a.command.file, ec)) {
    std::cerr << "proxima robot: cannot open '" << a.command.file << "'\n";
    return kExitFailure;
  }
  return proxima::cli::run_robot(a.command, in, std::cout, std::cerr);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "proxima: minimum distance, closest points and closest features between convex "
      "polyhedra, rounded bodies, compounds and triangle meshes"};
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  proxima distance a.obj b.stl --pose-b 0 0 2\n"
      "  proxima hull body.ply --out hull.obj\n"
      "  proxima query queries.jsonl --threads 2 > answers.jsonl\n"
      "Exit codes: 0 ok, 1 bad input (unreadable file, bad numbers), 2 usage.\n"
      "The paper's experiments and the scene demo are benchmark executables of the build tree\n"
      "(bench/paper_experiments, bench/scene_demo), not part of the installed tool.");

  CLI::App* demo = app.add_subcommand(
      "demo", "Build two seeded polytopes, print their hulls and the distance by each algorithm");
  demo->footer("Example:\n  proxima demo");
  QueryArgs query;
  add_query(app, query);
  DistanceArgs distance;
  add_distance(app, distance);
  HullArgs hull;
  add_hull(app, hull);
  ViewArgs view;
  add_view(app, view);
  RobotArgs robot;
  add_robot(app, robot);
  proxima::cli::RobotSrdfCommand robot_srdf_command;
  CLI::App* robot_srdf = proxima::cli::add_robot_srdf(app, robot_srdf_command);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11's own codes for bad usage are 100 and up; ours is 2 for all of
    // them. Help (--help) is a successful run.
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }

  try {
    if (*demo) return proxima::cli::run_demo();
    if (*query.app) return run(query);
    if (*distance.app) return run(distance);
    if (*hull.app) return proxima::cli::run_hull(hull.command, std::cout, std::cerr);
    if (*robot.app) return run(robot);
    if (*robot_srdf) return proxima::cli::run_robot_srdf(robot_srdf_command, std::cout, std::cerr);
    if (*view.app) return run(view);
  } catch (const std::exception& e) {
    std::cerr << "proxima: " << e.what() << "\n";
    return kExitFailure;
  }
  return kExitUsage;
}
