// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 8: `proxima view` (cli/view.h). Each input becomes bodies, poses and
// an answer; viewer::pair_page or viewer::scene_page writes the page. The
// witness features are always those of the query run here: an answer line
// carries no features (docs/query-format.md), so its numbers are shown and
// the features come from proxima's own answer to the same query.
#include "view.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "exit_codes.h"
#include "json_errors.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/io.h"
#include "proxima/scene/scene.h"
#include "query.h"
#include "tools.h"
#include "viewer.h"

namespace proxima::cli {
namespace {

// Bad input to `proxima view`: the message names the file and line or the
// option.
class ViewError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Everything `in` holds, but no more than max_bytes: counted as read, so
// that /dev/zero, a pipe or a device stops at the cap (the size of a
// regular file is not trusted either), as the mesh readers do.
std::string read_capped(std::istream& in, const std::string& name, std::uint64_t max_bytes) {
  std::string text;
  std::array<char, 1 << 16> buffer{};
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<std::uint64_t>(in.gcount());
    if (got > max_bytes - text.size()) {
      throw ViewError("'" + name + "' is larger than --max-file-size (" +
                      std::to_string(max_bytes) + " bytes)");
    }
    text.append(buffer.data(), static_cast<std::size_t>(got));
  }
  if (in.bad()) throw ViewError("reading '" + name + "' failed");
  return text;
}

// The non-blank lines of a text file ("-": standard input), each with its
// line number, a trailing \r dropped.
std::vector<std::pair<long, std::string>> read_lines(const std::string& path,
                                                     std::uint64_t max_bytes) {
  std::string text;
  if (path == "-") {
    text = read_capped(std::cin, "standard input", max_bytes);
  } else {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      throw ViewError("cannot open '" + path + "': it is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ViewError("cannot open '" + path + "': " + std::strerror(errno));
    text = read_capped(in, path, max_bytes);
  }
  std::vector<std::pair<long, std::string>> lines;
  std::istringstream stream(text);
  std::string line;
  long number = 0;
  while (std::getline(stream, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t\f\v") == std::string::npos) continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

Json parse_object(const std::string& line, const std::string& where) {
  if (nesting_overflow_column(line) != 0)
    throw ViewError(where + ": the JSON is nested deeper than " + std::to_string(kMaxJsonDepth) +
                    " levels");
  Json j;
  try {
    j = Json::parse(line);
  } catch (const Json::exception& e) {
    throw ViewError(where + ": " + describe_parse_error(line, e));
  }
  if (!j.is_object()) throw ViewError(where + ": not a JSON object (it is " + kind(j) + ")");
  return j;
}

// A mesh file as a body: as `proxima distance` reads it (load_body_named):
// as --as names it, by default the hull of a convex file or point cloud,
// and a non-convex file with faces refused until --as names how to read it
// (the view once took its hull silently where distance refused it).
Body load_body(const std::string& path, const std::string& as, std::uint64_t max_bytes) {
  return load_body_named(path, as, max_bytes);
}

std::string file_name(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

void write_page(const std::string& page, const ViewCommand& command, std::ostream& out) {
  if (command.out_file == "-") {
    out << page;
    if (!out) throw ViewError("writing the page to standard output failed");
    return;
  }
  std::ofstream file(command.out_file, std::ios::binary);
  if (!file) throw ViewError("cannot write '" + command.out_file + "': " + std::strerror(errno));
  file << page;
  file.close();
  if (!file) throw ViewError("writing '" + command.out_file + "' failed");
}

std::string view_files(const ViewCommand& command) {
  const Pose pose_a = parse_pose(command.pose_a, "--pose-a", command.quaternion_order);
  const Pose pose_b = parse_pose(command.pose_b, "--pose-b", command.quaternion_order);
  const viewer::ShownBody a{file_name(command.file_a),
                            load_body(command.file_a, command.as, command.max_file_bytes), pose_a};
  const viewer::ShownBody b{file_name(command.file_b),
                            load_body(command.file_b, command.as, command.max_file_bytes), pose_b};
  const BodyResult r = distance(a.body, a.pose, b.body, b.pose, command.options);
  return viewer::pair_page(a, b, r, viewer::answer_of(r), a.name + " and " + b.name);
}

double answer_number(const Json& answer, const char* field, const std::string& where,
                     bool required) {
  const auto f = answer.find(field);
  if (f == answer.end() || f->is_null()) {
    if (required) throw ViewError(where + ": the answer has no \"" + field + "\"");
    return std::numeric_limits<double>::quiet_NaN();  // shown as n/a
  }
  if (!f->is_number() || !std::isfinite(f->get<double>()))
    throw ViewError(where + ": the answer's \"" + field + "\" is not a finite number");
  return f->get<double>();
}

Vec3 answer_point(const Json& answer, const char* field, const std::string& where) {
  const auto f = answer.find(field);
  if (f == answer.end() || !f->is_array() || f->size() != 3)
    throw ViewError(where + ": the answer's \"" + field + "\" is not [x, y, z]");
  Vec3 p;
  for (int k = 0; k < 3; ++k) {
    const Json& c = (*f)[static_cast<std::size_t>(k)];
    if (!c.is_number() || !std::isfinite(c.get<double>()))
      throw ViewError(where + ": the answer's \"" + field + "\" is not [x, y, z]");
    p[k] = c.get<double>();
  }
  return p;
}

std::string view_query(const ViewCommand& command) {
  const auto lines = read_lines(command.query_file, command.max_file_bytes);
  const std::string& name = command.query_file;
  if (lines.empty()) throw ViewError(name + ": no query line");
  if (lines.size() > 2) {
    throw ViewError(name + ", line " + std::to_string(lines[2].first) +
                    ": expected one query line and at most its answer line");
  }
  const std::string query_where = name + ", line " + std::to_string(lines[0].first);
  const Json query = parse_object(lines[0].second, query_where);
  if (query.contains("status") && !query.contains("a"))
    throw ViewError(query_where + ": this is an answer line; the query line comes first");

  // The answer: the given line, or this run's.
  std::string answer_line;
  std::string answer_where;
  if (lines.size() == 2) {
    answer_line = lines[1].second;
    answer_where = name + ", line " + std::to_string(lines[1].first);
  } else {
    answer_line = answer_query_line(lines[0].second, command.options, command.quaternion_order);
    answer_where = query_where + " (its answer)";
  }
  const Json answer = parse_object(answer_line, answer_where);
  const Json id = query.contains("id") ? query["id"] : Json(nullptr);
  if (!answer.contains("id") || answer["id"] != id) {
    throw ViewError(answer_where + ": the answer's id " +
                    (answer.contains("id") ? answer["id"].dump() : std::string("(none)")) +
                    " is not the query's id " + id.dump());
  }
  const auto status = answer.find("status");
  if (status == answer.end() || !status->is_string())
    throw ViewError(answer_where + ": the answer has no \"status\"");
  if (*status == "error") {
    const auto error = answer.find("error");
    throw ViewError(answer_where + ": the query has no answer: " +
                    (error != answer.end() && error->is_string() ? error->get<std::string>()
                                                                 : std::string("error")));
  }

  // The bodies, read as `proxima query` reads them.
  std::vector<Vec3> vertices_a, vertices_b;
  std::vector<std::array<std::int32_t, 3>> triangles_a, triangles_b;
  Pose pose_a, pose_b;
  double radius_a = 0.0, radius_b = 0.0;
  std::optional<Motion> motion_a, motion_b;
  try {
    read_body(query, "a", command.quaternion_order, vertices_a, triangles_a, pose_a, radius_a,
              motion_a);
    read_body(query, "b", command.quaternion_order, vertices_b, triangles_b, pose_b, radius_b,
              motion_b);
  } catch (const QueryError& e) {
    throw ViewError(query_where + ": " + e.what());
  }
  const bool impact = motion_a.has_value() || motion_b.has_value();
  if (impact) {
    // A time-of-impact answer: the bodies are drawn at the time it found.
    const auto read_answer_pose = [&](const char* field) {
      const auto p = answer.find(field);
      if (p == answer.end() || !p->is_object())
        throw ViewError(answer_where + ": a time-of-impact answer needs \"" + field + "\"");
      Json wrapped = Json::object();
      wrapped["a"] = Json{{"vertices", Json::array({Json::array({0, 0, 0})})}};
      for (const char* key : {"rotation", "translation"}) {
        if (p->contains(key)) wrapped["a"][key] = (*p)[key];
      }
      std::vector<Vec3> unused;
      std::vector<std::array<std::int32_t, 3>> no_triangles;
      Pose pose;
      double radius = 0.0;
      std::optional<Motion> motion;
      try {
        read_body(wrapped, "a", command.quaternion_order, unused, no_triangles, pose, radius,
                  motion);
      } catch (const QueryError& e) {
        throw ViewError(answer_where + ": " + field + ": " + e.what());
      }
      return pose;
    };
    pose_a = read_answer_pose("pose_a");
    pose_b = read_answer_pose("pose_b");
  }

  viewer::PairAnswer shown;
  shown.status = status->get<std::string>();
  shown.distance = answer_number(answer, "distance", answer_where, true);
  shown.signed_distance = answer_number(answer, "signed_distance", answer_where, true);
  shown.signed_lower_bound = answer_number(answer, "signed_lower_bound", answer_where, !impact);
  shown.signed_upper_bound = answer_number(answer, "signed_upper_bound", answer_where, !impact);
  shown.point_a = answer_point(answer, "point_a", answer_where);
  shown.point_b = answer_point(answer, "point_b", answer_where);
  shown.normal = answer_point(answer, "normal", answer_where);
  if (impact) shown.status += ", t = " + answer["t"].dump();

  const auto build = [&](const std::vector<Vec3>& vertices,
                         const std::vector<std::array<std::int32_t, 3>>& triangles, double radius,
                         const char* side) {
    try {
      return query_body(vertices, triangles, radius, side);
    } catch (const QueryError& e) {
      throw ViewError(query_where + ": " + e.what());
    }
  };
  const viewer::ShownBody a{"a", build(vertices_a, triangles_a, radius_a, "a"), pose_a};
  const viewer::ShownBody b{"b", build(vertices_b, triangles_b, radius_b, "b"), pose_b};
  const BodyResult witness = distance(a.body, a.pose, b.body, b.pose, command.options);
  return viewer::pair_page(a, b, witness, shown, "query " + id.dump());
}

std::string view_scene(const ViewCommand& command) {
  if (!std::isfinite(command.margin) || command.margin < 0.0)
    throw ViewError("--margin must be a finite number >= 0");
  const auto lines = read_lines(command.scene_file, command.max_file_bytes);
  if (lines.empty()) throw ViewError(command.scene_file + ": no body line");
  SceneOptions options;
  options.margin = command.margin;
  options.distance.max_iterations = command.options.max_iterations;
  options.distance.algorithm = command.options.algorithm;
  Scene scene(options);
  std::vector<viewer::ShownBody> bodies;
  std::vector<BodyId> ids;
  for (const auto& [number, line] : lines) {
    const std::string where = command.scene_file + ", line " + std::to_string(number);
    Json wrapped = Json::object();
    wrapped["body"] = parse_object(line, where);
    std::vector<Vec3> vertices;
    std::vector<std::array<std::int32_t, 3>> triangles;
    Pose pose;
    double radius = 0.0;
    std::optional<Motion> motion;
    try {
      read_body(wrapped, "body", command.quaternion_order, vertices, triangles, pose, radius,
                motion);
    } catch (const QueryError& e) {
      throw ViewError(where + ": " + e.what());
    }
    if (radius != 0.0) throw ViewError(where + ": a scene's body has no radius");
    if (!triangles.empty())
      throw ViewError(where + ": a scene's body is convex (no \"triangles\")");
    if (motion) throw ViewError(where + ": a scene's body has no motion (one step is drawn)");
    std::shared_ptr<const ConvexPolytope> hull;
    try {
      hull = std::make_shared<const ConvexPolytope>(vertices);
    } catch (const InvalidInput& e) {
      throw ViewError(where + ": " + e.what());
    }
    ids.push_back(scene.add(hull, pose));
    bodies.push_back({"body " + std::to_string(bodies.size()), Body(hull), pose});
  }
  std::vector<viewer::ScenePair> pairs;
  const auto index_of = [&ids](BodyId id) {
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] == id) return static_cast<int>(i);
    }
    return -1;
  };
  for (const ClosePair& p : scene.step()) pairs.push_back({index_of(p.a), index_of(p.b), p.result});
  return viewer::scene_page(bodies, pairs, command.margin,
                            file_name(command.scene_file) + ": one step");
}

}  // namespace

int run_view(const ViewCommand& command, std::ostream& out, std::ostream& err) {
  try {
    if (!viewer::available()) throw viewer::ViewerUnavailable();
    std::string page;
    if (!command.scene_file.empty()) {
      page = view_scene(command);
    } else if (!command.query_file.empty()) {
      page = view_query(command);
    } else {
      page = view_files(command);
    }
    write_page(page, command, out);
    if (command.out_file != "-") out << "wrote " << command.out_file << "\n";
    return kExitOk;
  } catch (const std::exception& e) {
    // Bad files (FileError names the file and line), bad poses, bad lines,
    // a build without three.js: one message, exit 1.
    err << "proxima view: " << e.what() << "\n";
    return kExitFailure;
  }
}

}  // namespace proxima::cli
