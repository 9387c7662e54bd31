// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// `proxima robot`: see robot.h.
#include "robot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <string>

#include "line_reader.h"

#include "json_errors.h"
#include "proxima/robot/robot_distance.h"
#include "proxima/robot/urdf.h"
#include "query.h"
#include "viewer.h"

namespace proxima::cli {
namespace {

Json vec3_json(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json vector_json(const Eigen::VectorXd& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v[i]);
  return out;
}

// A non-finite value (no pair at all: +infinity) is written as null, which
// JSON can hold.
Json number_json(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

std::vector<double> read_q(const Robot& robot, const Json& query) {
  const auto it = query.find("q");
  if (it == query.end()) fail("no \"q\" (the joint vector: an array, or an object by joint name)");
  const std::vector<std::string> names = robot.variable_names();
  std::vector<double> q(names.size());
  const auto number = [](const Json& v, const std::string& path) {
    if (!v.is_number()) fail(path + " is not a number " + kind(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(path + " is not finite");
    return x;
  };
  if (it->is_array()) {
    if (it->size() != names.size()) {
      fail("q has " + std::to_string(it->size()) + " entries, the robot " +
           std::to_string(names.size()) + " joints (" +
           [&] {
             std::string list;
             for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
             return list;
           }() +
           ")");
    }
    for (std::size_t v = 0; v < names.size(); ++v) q[v] = number((*it)[v], indexed("q", v));
    return q;
  }
  if (it->is_object()) {
    for (std::size_t v = 0; v < names.size(); ++v) {
      const auto joint = it->find(names[v]);
      if (joint == it->end()) fail("q names no value for joint \"" + names[v] + "\"");
      q[v] = number(*joint, "q." + names[v]);
    }
    for (const auto& [key, value] : it->items()) {
      if (std::find(names.begin(), names.end(), key) == names.end()) {
        fail("q names \"" + key + "\", which is not a joint variable of the robot");
      }
    }
    return q;
  }
  fail("q is neither an array nor an object " + kind(*it));
}

// The obstacles of an environment file (RobotCommand::environment).
// Throws QueryError naming the file and line.
std::vector<Obstacle> read_environment(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("cannot open the environment '" + path + "'");
  std::vector<Obstacle> obstacles;
  std::string line;
  long number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = path + ", line " + std::to_string(number);
    try {
      if (nesting_overflow_column(line) != 0) fail("the JSON is nested too deeply");
      Json body;
      try {
        body = Json::parse(line);
      } catch (const Json::exception& e) {
        fail(describe_parse_error(line, e));
      }
      if (!body.is_object()) fail("the line is not a JSON object " + kind(body));
      // A misspelt key ("pose" for "translation") would silently put the
      // obstacle at the origin: only the body's own keys are read.
      for (const auto& [key, value] : body.items()) {
        static const std::array<const char*, 6> kKeys = {"name",     "vertices",    "triangles",
                                                         "radius",   "translation", "rotation"};
        if (std::find(kKeys.begin(), kKeys.end(), key) == kKeys.end()) {
          fail("unknown key \"" + key +
               "\" (an obstacle has name, vertices, triangles, radius, translation, rotation)");
        }
      }
      std::string name = "obstacle " + std::to_string(obstacles.size());
      if (const auto it = body.find("name"); it != body.end()) {
        if (!it->is_string()) fail("\"name\" is not a string " + kind(*it));
        name = it->get<std::string>();
        body.erase("name");
      }
      Json wrapped = Json::object();
      wrapped["body"] = std::move(body);
      std::vector<Vec3> vertices;
      std::vector<std::array<std::int32_t, 3>> triangles;
      Pose pose;
      double radius = 0.0;
      std::optional<Motion> motion;
      read_body(wrapped, "body", std::nullopt, vertices, triangles, pose, radius, motion);
      if (motion) fail("an obstacle has no motion");
      obstacles.emplace_back(query_body(vertices, triangles, radius, "body"), pose, name);
    } catch (const std::exception& e) {
      fail(where + ": " + e.what());
    }
  }
  if (in.bad()) fail("reading the environment '" + path + "' failed after line " +
                     std::to_string(number));
  return obstacles;
}

// The viewer page of one configuration: every geometry at its pose, the
// obstacles after them, and the close pairs (only tested pairs: excluded
// ones are never queried, so never drawn as collisions).
std::string robot_page(const Robot& robot, std::span<const Pose> link_poses,
                       std::span<const Obstacle> obstacles, const RobotDistances& r, double margin,
                       const std::string& title) {
  std::vector<viewer::ShownBody> bodies;
  for (const RobotGeometry& g : robot.geometries()) {
    bodies.push_back({g.name, g.body, link_poses[static_cast<std::size_t>(g.link)] * g.origin});
  }
  for (const Obstacle& o : obstacles) bodies.push_back({o.name, o.body, o.pose});
  std::vector<viewer::ScenePair> pairs;
  const int n_geometries = static_cast<int>(robot.geometries().size());
  for (const RobotPairResult& p : r.close_pairs) {
    viewer::ScenePair shown;
    shown.a = p.geometry_a;
    shown.b = p.environment ? n_geometries + p.geometry_b : p.geometry_b;
    static_cast<DistanceResult&>(shown.result) = p.result;
    shown.result.piece_a = p.result.piece_a;
    shown.result.piece_b = p.result.piece_b;
    pairs.push_back(shown);
  }
  return viewer::scene_page(bodies, pairs, margin, title);
}

Json pair_json(const Robot& robot, std::span<const Obstacle> obstacles,
               const RobotPairResult& pair, bool gradients) {
  const auto& geometries = robot.geometries();
  const RobotGeometry& a = geometries[static_cast<std::size_t>(pair.geometry_a)];
  Json out;
  out["a"] = a.name;
  out["link_a"] = robot.links()[static_cast<std::size_t>(a.link)].name;
  if (pair.environment) {
    out["b"] = obstacles[static_cast<std::size_t>(pair.geometry_b)].name;
  } else {
    const RobotGeometry& b = geometries[static_cast<std::size_t>(pair.geometry_b)];
    out["b"] = b.name;
    out["link_b"] = robot.links()[static_cast<std::size_t>(b.link)].name;
  }
  out["status"] = to_string(pair.result.status);
  out["signed_distance"] = number_json(pair.signed_distance());
  out["point_a"] = vec3_json(pair.result.point_a);
  out["point_b"] = vec3_json(pair.result.point_b);
  out["normal"] = vec3_json(pair.result.normal);
  if (gradients) out["gradient"] = pair.has_gradient ? vector_json(pair.gradient) : Json(nullptr);
  return out;
}

}  // namespace

int run_robot(const RobotCommand& command, std::istream& in, std::ostream& out, std::ostream& err) {
  RobotLoadOptions load;
  load.package_dirs = command.package_dirs;
  std::optional<Robot> robot;
  std::vector<Obstacle> obstacles;
  try {
    load.mesh_as = load_as_from_string(command.mesh_as);
    robot.emplace(load_robot(command.urdf, command.srdf, load));
    if (!command.environment.empty()) obstacles = read_environment(command.environment);
  } catch (const std::exception& e) {
    err << "proxima robot: " << e.what() << "\n";
    return 1;
  }
  RobotQueryOptions options;
  options.margin = command.margin;
  options.gradients = command.gradients;
  RobotQueryState state;
  std::optional<RobotDistances> last_shown;
  long shown_line = 0;
  std::string line;
  long line_number = 0;
  for (;;) {
    const LineRead read = read_line(in, line, kDefaultMaxLineBytes);
    if (read == LineRead::end) break;
    ++line_number;
    if (read == LineRead::too_long) {
      // Its rest cannot be skipped safely (read_line): the run stops here.
      out.flush();
      err << "proxima robot: " << too_long_message(line_number, kDefaultMaxLineBytes) << "\n";
      return 1;
    }
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    Json answer;
    try {
      if (const std::size_t column = nesting_overflow_column(line); column != 0) {
        fail("the JSON is nested deeper than " + std::to_string(kMaxJsonDepth) +
             " levels (at column " + std::to_string(column) + ")");
      }
      Json query;
      try {
        query = Json::parse(line);
      } catch (const Json::exception& e) {
        fail(describe_parse_error(line, e));
      }
      if (!query.is_object()) fail("the line is not a JSON object " + kind(query));
      if (const auto id = query.find("id"); id != query.end()) answer["id"] = *id;
      const std::vector<double> q = read_q(*robot, query);
      const RobotDistances r = robot_distances(*robot, q, obstacles, options, &state);
      if (!command.view_out.empty()) {
        last_shown = r;
        shown_line = line_number;
      }
      answer["min_signed_distance"] = number_json(r.min_signed_distance);
      if (r.closest.geometry_a >= 0) {
        answer["closest"] = pair_json(*robot, obstacles, r.closest, command.gradients);
      }
      Json pairs = Json::array();
      for (const RobotPairResult& pair : r.close_pairs) {
        pairs.push_back(pair_json(*robot, obstacles, pair, command.gradients));
      }
      answer["pairs"] = std::move(pairs);
      if (command.gradients && r.closest.geometry_a >= 0) {
        answer["gradient"] = vector_json(r.closest.gradient);
      }
    } catch (const std::exception& e) {
      Json error;
      if (answer.contains("id")) error["id"] = answer["id"];
      error["error"] = "line " + std::to_string(line_number) + ": " + e.what();
      answer = std::move(error);
    }
    out << answer.dump(-1, ' ', false, Json::error_handler_t::replace) << "\n";
  }
  out.flush();
  if (in.bad()) {
    err << "proxima robot: reading the input failed after line " << line_number << "\n";
    return 1;
  }
  if (!command.view_out.empty()) {
    if (!last_shown) {
      err << "proxima robot: no configuration was answered: no page for --view\n";
      return 1;
    }
    try {
      const std::string page =
          robot_page(*robot, state.link_poses(), obstacles, *last_shown, command.margin,
                     robot->name() + ": configuration of line " + std::to_string(shown_line));
      std::ofstream file(command.view_out, std::ios::binary);
      file << page;
      file.close();
      if (!file) throw std::runtime_error("cannot write '" + command.view_out + "'");
    } catch (const std::exception& e) {
      err << "proxima robot: --view: " << e.what() << "\n";
      return 1;
    }
  }
  return out ? 0 : 1;
}

}  // namespace proxima::cli
