// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima query`, the JSON Lines exchange (docs/query-format.md):
// the query loop. What is wrong with a line is said by json_errors.h, the
// answer lines are written by answer_writer.h.
//
// Each line is answered on its own: parse, validate every field with a
// message that names where the problem is (`b.vertices[3][1]`), build both
// hulls, run one cold distance query, print one answer line. Nothing but
// buffers survives from one line to the next, so a bad line can never change
// the answer to a good one. A body with a "radius" is a rounded body
// (proxima/query/body_distance.h); a body with a motion ("pose_end" or velocities) makes
// the line a time-of-impact query (proxima/motion/time_of_impact.h).
#include "query.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "answer_writer.h"
#include "line_reader.h"
#include "json_errors.h"
#include "proxima/motion/time_of_impact.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/query/margin.h"
#include "proxima/shape/polytope.h"

namespace proxima::cli {
namespace {

double read_finite(const Json& v, const std::string& path_if_bad) {
  if (!v.is_number()) fail(path_if_bad + " is not a number (it is " + kind(v) + ")");
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(path_if_bad + " is not a finite number");
  return x;
}

// An array of exactly `n` finite numbers, written to out[0..n).
void read_numbers(const Json& v, const std::string& path, std::size_t n, const char* what,
                  double* out) {
  if (!v.is_array()) fail(path + " is not an array of " + what + " (it is " + kind(v) + ")");
  if (v.size() != n) {
    fail(path + " is not an array of " + what + " (it has " + std::to_string(v.size()) +
         " elements)");
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Json& c = v[k];
    // The common case first; the path string is built only for a bad value.
    if (c.is_number()) {
      out[k] = c.get<double>();
      if (std::isfinite(out[k])) continue;
    }
    out[k] = read_finite(c, indexed(path, k));
  }
}

// A "rotation" value, named `path` in errors: {"wxyz": [w, x, y, z]} or
// {"xyzw": [x, y, z, w]}, which name their order, or four bare numbers,
// read in the order the run names (--quaternion-order). Four bare numbers
// in a run that names no order are refused with both of their readings:
// the same numbers in the other order are another rotation (ROS's identity
// [0, 0, 0, 1] read scalar first is a half turn), so no default is safe.
Quat read_rotation(const Json& value, const std::string& path,
                   std::optional<QuaternionOrder> run_order) {
  double numbers[4];
  std::optional<QuaternionOrder> order = run_order;
  std::string where = path;
  if (value.is_object()) {
    const auto wxyz = value.find("wxyz");
    const auto xyzw = value.find("xyzw");
    if (value.size() != 1 || (wxyz == value.end() && xyzw == value.end())) {
      fail(path + " is an object but not {\"wxyz\": [w, x, y, z]} or {\"xyzw\": [x, y, z, w]}");
    }
    order = wxyz != value.end() ? QuaternionOrder::wxyz : QuaternionOrder::xyzw;
    where = path + "." + to_string(*order);
    read_numbers(wxyz != value.end() ? *wxyz : *xyzw, where, 4,
                 *order == QuaternionOrder::wxyz ? "4 numbers [w, x, y, z]"
                                                 : "4 numbers [x, y, z, w]",
                 numbers);
  } else {
    read_numbers(value, path, 4,
                 !order                            ? "4 numbers"
                 : *order == QuaternionOrder::wxyz ? "4 numbers [w, x, y, z]"
                                                   : "4 numbers [x, y, z, w] (--quaternion-order xyzw)",
                 numbers);
  }
  // Normalized at any magnitude, a zero quaternion refused: the pose
  // contract's own functions (proxima/core/pose.h), as in Python.
  try {
    if (!order) {
      fail(path + " " + value.dump() + " does not name its quaternion order: " +
           quaternion_readings(numbers, path) +
           ". Write {\"wxyz\": [...]} or {\"xyzw\": [...]}, or run with --quaternion-order "
           "wxyz or xyzw");
    }
    return unit_quaternion(quaternion_in_order(numbers, *order), where);
  } catch (const InvalidInput& e) {
    fail(e.what());
  }
}

// A pose object's "rotation" and "translation" fields (absent or null:
// identity), named `path` in errors.
Pose read_pose(const Json& object, const std::string& path,
               std::optional<QuaternionOrder> order) {
  Quat rotation = Quat::Identity();
  const auto q = object.find("rotation");
  if (q != object.end() && !q->is_null()) rotation = read_rotation(*q, path + "rotation", order);
  Vec3 translation = Vec3::Zero();
  const auto t = object.find("translation");
  if (t != object.end() && !t->is_null()) {
    read_numbers(*t, path + "translation", 3, "3 numbers [x, y, z]", translation.data());
  }
  return Pose(rotation, translation);
}

}  // namespace

// Reads body `name` ("a" or "b") of `query` into vertices, pose, radius and
// motion (time of impact, proxima/motion/time_of_impact.h: "pose_end", or
// "linear_velocity" and "angular_velocity" per unit t; none: no motion),
// its rotations' four numbers in `order`.
void read_body(const Json& query, const std::string& name, std::optional<QuaternionOrder> order,
               std::vector<Vec3>& vertices, std::vector<std::array<std::int32_t, 3>>& triangles,
               Pose& pose, double& radius, std::optional<Motion>& motion) {
  const auto body = query.find(name);
  if (body == query.end()) fail("missing \"" + name + "\"");
  if (!body->is_object()) fail(name + " is not an object (it is " + kind(*body) + ")");

  const std::string vertices_path = name + ".vertices";
  const auto list = body->find("vertices");
  if (list == body->end()) fail("missing \"" + vertices_path + "\"");
  if (!list->is_array()) {
    fail(vertices_path + " is not an array of points (it is " + kind(*list) + ")");
  }
  if (list->empty()) fail(vertices_path + " is empty: a body needs at least one point");
  vertices.clear();
  vertices.reserve(list->size());
  for (std::size_t i = 0; i < list->size(); ++i) {
    double xyz[3];
    const Json& p = (*list)[i];
    if (p.is_array() && p.size() == 3 && p[0].is_number() && p[1].is_number() && p[2].is_number()) {
      xyz[0] = p[0].get<double>();
      xyz[1] = p[1].get<double>();
      xyz[2] = p[2].get<double>();
      if (std::isfinite(xyz[0]) && std::isfinite(xyz[1]) && std::isfinite(xyz[2])) {
        vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
        continue;
      }
    }
    read_numbers(p, indexed(vertices_path, i), 3, "3 numbers [x, y, z]", xyz);
    vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
  }

  // "triangles": a mesh body (proxima/query/mesh_distance.h) of the vertices as given;
  // absent or null, the hull of the vertices. Indices are checked here so
  // that the message names the JSON path.
  triangles.clear();
  const auto faces = body->find("triangles");
  if (faces != body->end() && !faces->is_null()) {
    const std::string path = name + ".triangles";
    if (!faces->is_array())
      fail(path + " is not an array of triangles (it is " + kind(*faces) + ")");
    if (faces->empty()) fail(path + " is empty: a mesh needs at least one triangle");
    triangles.reserve(faces->size());
    for (std::size_t i = 0; i < faces->size(); ++i) {
      const Json& t = (*faces)[i];
      const std::string at = indexed(path, i);
      if (!t.is_array()) {
        fail(at + " is not an array of 3 vertex indices [i, j, k] (it is " + kind(t) + ")");
      }
      if (t.size() != 3) {
        fail(at + " is not an array of 3 vertex indices [i, j, k] (it has " +
             std::to_string(t.size()) + " elements)");
      }
      std::array<std::int32_t, 3> tri{};
      for (std::size_t k = 0; k < 3; ++k) {
        const Json& v = t[k];
        if (!v.is_number_integer() || v.get<std::int64_t>() < 0 ||
            v.get<std::int64_t>() >= static_cast<std::int64_t>(vertices.size())) {
          fail(indexed(at, k) + " is not a vertex index: expected an integer in [0, " +
               std::to_string(vertices.size()) + ")");
        }
        tri[k] = static_cast<std::int32_t>(v.get<std::int64_t>());
      }
      triangles.push_back(tri);
    }
  }

  // Absent and null both mean identity, so that writers with optional
  // fields need not special-case them.
  pose = read_pose(*body, name + ".", order);

  // The body's radius (proxima/query/body_distance.h): absent or null, 0.
  radius = 0.0;
  const auto r = body->find("radius");
  if (r != body->end() && !r->is_null()) {
    radius = read_finite(*r, name + ".radius");
    if (radius < 0.0) fail(name + ".radius is negative: a radius must be >= 0");
  }

  // The motion: an end pose, or velocities, or none.
  motion.reset();
  const auto end = body->find("pose_end");
  const auto linear = body->find("linear_velocity");
  const auto angular = body->find("angular_velocity");
  const bool has_end = end != body->end() && !end->is_null();
  const bool has_linear = linear != body->end() && !linear->is_null();
  const bool has_angular = angular != body->end() && !angular->is_null();
  if (has_end && (has_linear || has_angular)) {
    fail(name + " has both \"pose_end\" and a velocity: give one motion");
  }
  if (has_end) {
    if (!end->is_object()) {
      fail(name + ".pose_end is not an object {\"rotation\": ..., \"translation\": ...} (it is " +
           kind(*end) + ")");
    }
    motion = Motion{pose, read_pose(*end, name + ".pose_end.", order)};
  } else if (has_linear || has_angular) {
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
    if (has_linear)
      read_numbers(*linear, name + ".linear_velocity", 3, "3 numbers [x, y, z]", v.data());
    if (has_angular) {
      read_numbers(*angular, name + ".angular_velocity", 3, "3 numbers [x, y, z]", w.data());
    }
    motion = Motion::from_velocity(pose, v, w, 1.0);
  }
}

namespace {

// A query-level number that must be finite and >= 0: absent or null gives
// `otherwise`.
double read_nonnegative(const Json& query, const char* field, double otherwise) {
  const auto f = query.find(field);
  if (f == query.end() || f->is_null()) return otherwise;
  const double x = read_finite(*f, field);
  if (x < 0.0) fail(std::string(field) + " is negative: it must be >= 0");
  return x;
}

// {"rotation":{"wxyz":[w,x,y,z]},"translation":[x,y,z]} (or "xyzw" when the
// run reads that order): an answer's rotation names its order, so that it
// reads back the same anywhere.
void append_pose(std::string& out, const Pose& pose, std::optional<QuaternionOrder> run_order) {
  const QuaternionOrder order = run_order.value_or(QuaternionOrder::wxyz);
  const Quat q(pose.rotation);
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
  const double* numbers = order == QuaternionOrder::wxyz ? wxyz : xyzw;
  out += "{\"rotation\":{\"";
  out += to_string(order);
  out += "\":[";
  for (int i = 0; i < 4; ++i) {
    if (i > 0) out += ',';
    append_number(out, numbers[i]);
  }
  out += "]},\"translation\":";
  append_point(out, pose.translation);
  out += '}';
}

// Buffers reused from line to line, so that a long run does not allocate the
// vertex arrays again for every query.
struct Workspace {
  std::vector<Vec3> vertices_a;
  std::vector<Vec3> vertices_b;
  std::vector<std::array<std::int32_t, 3>> triangles_a;
  std::vector<std::array<std::int32_t, 3>> triangles_b;
};

}  // namespace

Body query_body(const std::vector<Vec3>& vertices,
                const std::vector<std::array<std::int32_t, 3>>& triangles, double radius,
                const std::string& name) {
  try {
    if (!triangles.empty()) {
      return Body(std::make_shared<const TriangleMesh>(
                      std::span<const Vec3>(vertices),
                      std::span<const std::array<std::int32_t, 3>>(triangles)),
                  radius);
    }
    return Body(std::make_shared<const ConvexPolytope>(vertices), radius);
  } catch (const InvalidInput& e) {
    fail(name + ": " + e.what());
  }
}

namespace {

ConvexPolytope build_hull(const std::vector<Vec3>& vertices, const std::string& name) {
  try {
    return ConvexPolytope(vertices);
  } catch (const InvalidInput& e) {
    fail(name + ": " + e.what());
  }
}

// The margin answer of one line (the "margin" field).
void append_margin_answer(std::string& out, const Json* id, const MarginResult& m,
                          bool with_triangles) {
  if (!std::isfinite(m.lower_bound) || !m.point_a.allFinite() || !m.point_b.allFinite())
    fail("the result is not finite: the coordinates are too large for double arithmetic");
  out += "{\"id\":";
  append_id(out, id);
  out += ",\"within\":";
  out += m.is_within() ? "true" : "false";
  out += ",\"status\":\"";
  out += to_string(m.status);
  out += "\",\"margin\":";
  append_number(out, m.margin);
  out += ",\"lower_bound\":";
  append_number(out, m.lower_bound);
  out += ",\"upper_bound\":";
  if (std::isfinite(m.upper_bound)) {
    append_number(out, m.upper_bound);
    out += ",\"point_a\":";
    append_point(out, m.point_a);
    out += ",\"point_b\":";
    append_point(out, m.point_b);
  } else {
    out += "null";
  }
  if (with_triangles) {
    out += ",\"triangle_a\":" + std::to_string(m.triangle_a);
    out += ",\"triangle_b\":" + std::to_string(m.triangle_b);
  }
  out += '}';
}

// The time-of-impact answer of one line (a body with a motion).
void append_impact_answer(std::string& out, const Json* id, const ImpactResult& hit,
                          std::optional<QuaternionOrder> order) {
  const DistanceResult& at = hit.at_t;
  if (!std::isfinite(at.distance) || !std::isfinite(at.signed_distance()) ||
      !at.point_a.allFinite() || !at.point_b.allFinite()) {
    fail("the result is not finite: the coordinates are too large for double arithmetic");
  }
  out += "{\"id\":";
  append_id(out, id);
  out += ",\"status\":\"";
  out += to_string(hit.status);
  out += "\",\"t\":";
  append_number(out, hit.t);
  out += ",\"distance\":";
  append_number(out, at.distance);
  out += ",\"signed_distance\":";
  append_number(out, at.signed_distance());
  out += ",\"point_a\":";
  append_point(out, at.point_a);
  out += ",\"point_b\":";
  append_point(out, at.point_b);
  out += ",\"normal\":";
  append_point(out, at.normal);
  out += ",\"pose_a\":";
  append_pose(out, hit.pose_a, order);
  out += ",\"pose_b\":";
  append_pose(out, hit.pose_b, order);
  out += ",\"iterations\":";
  out += std::to_string(hit.iterations);
  out += '}';
}

// The distance answer of one line. `mesh_answer`: the answer of a query
// with a mesh body (its closest triangles are reported), else null.
// Returns false (and appends an error answer) when a number is not finite.
bool append_distance_answer(std::string& out, const Json* id, long line_number,
                            const DistanceResult& r, const BodyResult* mesh_answer) {
  // A JSON line can carry no NaN or infinity. Finite inputs whose products
  // overflow (coordinates near 1e308) are the only way to get one; say so
  // rather than print an invalid line.
  // An overlap with a mesh has no depth: its signed lower bound is
  // -infinity, written as null.
  const bool no_depth = mesh_answer != nullptr && mesh_answer->intersecting;
  if (!std::isfinite(r.distance) || !std::isfinite(r.signed_distance()) ||
      (!std::isfinite(r.signed_lower_bound()) && !no_depth) ||
      !std::isfinite(r.signed_upper_bound()) || !r.point_a.allFinite() || !r.point_b.allFinite() ||
      !r.normal.allFinite()) {
    append_error_answer(out, id, line_number,
                        "the result is not finite: the coordinates are too large for double "
                        "arithmetic");
    return false;
  }

  // A capped answer says so in its status: its distance is an upper bound
  // only, and calling it separated or touching from that bound would claim
  // what the algorithm did not certify.
  out += "{\"id\":";
  append_id(out, id);
  out += ",\"status\":\"";
  out += to_string(r.status);
  out += "\",\"distance\":";
  append_number(out, r.distance);
  out += ",\"signed_distance\":";
  append_number(out, r.signed_distance());
  out += ",\"signed_lower_bound\":";
  if (std::isfinite(r.signed_lower_bound())) {
    append_number(out, r.signed_lower_bound());
  } else {
    out += "null";
  }
  out += ",\"signed_upper_bound\":";
  append_number(out, r.signed_upper_bound());
  out += ",\"point_a\":";
  append_point(out, r.point_a);
  out += ",\"point_b\":";
  append_point(out, r.point_b);
  out += ",\"normal\":";
  append_point(out, r.normal);
  out += ",\"iterations\":";
  out += std::to_string(r.iterations);
  if (mesh_answer != nullptr) {
    // The closest triangles of mesh bodies (-1 for a hull).
    out += ",\"triangle_a\":" + std::to_string(mesh_answer->triangle_a);
    out += ",\"triangle_b\":" + std::to_string(mesh_answer->triangle_b);
  }
  if (r.status == Status::iteration_cap) out += ",\"iteration_cap\":true";
  out += '}';
  return true;
}

// The line as a JSON object, or an error answer (id null: it cannot be
// read) and nullopt.
std::optional<Json> parse_query_line(const std::string& line, long line_number,
                                     std::string& out) {
  if (const std::size_t column = nesting_overflow_column(line); column != 0) {
    append_error_answer(out, nullptr, line_number,
                        "the JSON is nested deeper than " + std::to_string(kMaxJsonDepth) +
                            " levels (at column " + std::to_string(column) + ")");
    return std::nullopt;
  }
  Json query;
  try {
    query = Json::parse(line);
  } catch (const Json::exception& e) {
    append_error_answer(out, nullptr, line_number, describe_parse_error(line, e));
    return std::nullopt;
  }
  if (!query.is_object()) {
    append_error_answer(out, nullptr, line_number,
                        "the line is not a JSON object (it is " + kind(query) + ")");
    return std::nullopt;
  }
  return query;
}

// Appends the answer to one query line to `out`; returns false for an error
// answer. The line asks for a margin answer ("margin"), a time of impact (a
// body with a motion) or the distance.
bool answer_line(const std::string& line, long line_number, const DistanceOptions& options,
                 std::optional<QuaternionOrder> order, Workspace& work, std::string& out) {
  const std::optional<Json> parsed = parse_query_line(line, line_number, out);
  if (!parsed) return false;
  const Json& query = *parsed;
  const auto id_it = query.find("id");
  const Json* id = id_it != query.end() ? &*id_it : nullptr;

  // Everything the answer may need to write goes to `answer` first, so
  // that an error part way leaves only the error answer.
  std::string answer;
  DistanceResult r;
  std::optional<BodyResult> mesh_answer;  // a query with a mesh body
  try {
    Pose pose_a;
    Pose pose_b;
    double radius_a = 0.0;
    double radius_b = 0.0;
    std::optional<Motion> motion_a;
    std::optional<Motion> motion_b;
    read_body(query, "a", order, work.vertices_a, work.triangles_a, pose_a, radius_a, motion_a);
    read_body(query, "b", order, work.vertices_b, work.triangles_b, pose_b, radius_b, motion_b);
    const bool meshes = !work.triangles_a.empty() || !work.triangles_b.empty();
    const auto body = [&](const char* name) {
      const bool a = name[0] == 'a';
      return query_body(a ? work.vertices_a : work.vertices_b,
                        a ? work.triangles_a : work.triangles_b, a ? radius_a : radius_b, name);
    };
    const auto margin_it = query.find("margin");
    if (margin_it != query.end() && !margin_it->is_null()) {
      // The margin (or, at 0, boolean) query: its own answer line.
      const double margin = read_nonnegative(query, "margin", 0.0);
      if (motion_a || motion_b) {
        fail("margin asks for the margin answer at one pose; a body with a motion asks for a "
             "time of impact (use target_separation there)");
      }
      append_margin_answer(answer, id,
                           within_margin(body("a"), pose_a, body("b"), pose_b, margin, options,
                                         nullptr),
                           meshes);
      out += answer;
      return true;
    }
    if (motion_a || motion_b) {
      // A time-of-impact query: its own answer line.
      ImpactOptions impact;
      impact.distance = options;
      impact.target_separation = read_nonnegative(query, "target_separation", 0.0);
      impact.tolerance = read_nonnegative(query, "tolerance", 0.0);
      append_impact_answer(answer, id,
                           time_of_impact(body("a"), motion_a.value_or(Motion::fixed(pose_a)),
                                          body("b"), motion_b.value_or(Motion::fixed(pose_b)),
                                          impact),
                           order);
      out += answer;
      return true;
    }
    if (meshes) {
      // A mesh on either side: the one call for any two bodies.
      mesh_answer = distance(body("a"), pose_a, body("b"), pose_b, options, nullptr);
      r = *mesh_answer;
    } else {
      const auto a = std::make_shared<const ConvexPolytope>(build_hull(work.vertices_a, "a"));
      const auto b = std::make_shared<const ConvexPolytope>(build_hull(work.vertices_b, "b"));
      if (radius_a > 0.0 || radius_b > 0.0) {
        // Rounded bodies: the cores' answer offset by the radii, points on
        // the rounded surfaces.
        r = distance(Body(a, radius_a), pose_a, Body(b, radius_b), pose_b, options, nullptr);
      } else {
        r = distance(*a, pose_a, *b, pose_b, options, nullptr);
      }
    }
  } catch (const QueryError& e) {
    append_error_answer(out, id, line_number, e.what());
    return false;
  } catch (const InvalidInput& e) {
    append_error_answer(out, id, line_number, e.what());
    return false;
  } catch (const std::exception& e) {
    append_error_answer(out, id, line_number, std::string("internal error: ") + e.what());
    return false;
  }
  return append_distance_answer(out, id, line_number, r,
                                mesh_answer ? &*mesh_answer : nullptr);
}

}  // namespace

std::string answer_query_line(const std::string& line, const DistanceOptions& options,
                              std::optional<QuaternionOrder> order) {
  Workspace work;
  std::string out;
  answer_line(line, 1, options, order, work, out);
  return out;
}

namespace {

bool is_blank(std::string_view line) {
  return line.find_first_not_of(" \t\r\n\f\v") == std::string_view::npos;
}

}  // namespace

QueryRunSummary run_queries(std::istream& in, std::ostream& out, const DistanceOptions& options,
                            int threads, std::optional<QuaternionOrder> order,
                            std::uint64_t max_line_bytes) {
  QueryRunSummary summary;
  std::string line;
  long line_number = 0;
  // A line past the limit gets its error answer, and the run stops there
  // (read_line: its rest cannot be skipped safely).
  const auto refuse_long_line = [&] {
    summary.too_long_line = line_number;
    std::string answer;
    append_error_answer(answer, nullptr, line_number,
                        "longer than the limit of " + std::to_string(max_line_bytes) +
                            " bytes (--max-line-size)");
    answer += '\n';
    out.write(answer.data(), static_cast<std::streamsize>(answer.size()));
    out.flush();
    ++summary.answered;
    ++summary.errors;
  };
  if (threads <= 1) {
    Workspace work;
    std::string answer;
    for (;;) {
      const LineRead read = read_line(in, line, max_line_bytes);
      if (read == LineRead::end) break;
      ++line_number;
      if (read == LineRead::too_long) {
        refuse_long_line();
        break;
      }
      if (is_blank(line)) continue;
      answer.clear();
      if (!answer_line(line, line_number, options, order, work, answer)) ++summary.errors;
      ++summary.answered;
      answer += '\n';
      out.write(answer.data(), static_cast<std::streamsize>(answer.size()));
      out.flush();
    }
    summary.read_failed = in.bad();
    return summary;
  }

  // Blocks of lines answered in parallel. Every answer depends on its line
  // alone (answer_line keeps nothing between lines but buffers, one
  // Workspace per thread), so the answers are those of the serial loop, and
  // writing them in block order keeps the input order.
  struct Pending {
    std::string line;
    long line_number = 0;
    std::string answer;
    bool ok = true;
  };
  const auto block_size = static_cast<std::size_t>(kQueryBlockLines);
  std::vector<Pending> block(block_size);
  std::vector<Workspace> work(static_cast<std::size_t>(threads));
  bool more = true;
  bool too_long = false;
  while (more) {
    std::size_t count = 0;
    while (count < block_size) {
      const LineRead read = read_line(in, line, max_line_bytes);
      if (read == LineRead::end) {
        more = false;
        break;
      }
      ++line_number;
      if (read == LineRead::too_long) {
        more = false;
        too_long = true;
        break;
      }
      if (!is_blank(line)) {
        Pending& p = block[count++];
        p.line.swap(line);
        p.line_number = line_number;
      }
      // Stop the block at the end of what has arrived: reading on would wait
      // for the next query before answering this one.
      if (in.rdbuf()->in_avail() <= 0) break;
    }
    if (count == 0) continue;

    std::atomic<std::size_t> next{0};
    // answer_line turns every failure of a query into an error answer; what
    // escapes it (out of memory) is carried to this thread, as the serial
    // loop would let it escape.
    std::mutex failure_mutex;
    std::exception_ptr failure;
    auto worker = [&](Workspace& ws) {
      try {
        for (std::size_t i = next++; i < count; i = next++) {
          Pending& p = block[i];
          p.answer.clear();
          p.ok = answer_line(p.line, p.line_number, options, order, ws, p.answer);
          p.answer += '\n';
        }
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = count;  // the other threads stop at their next line
      }
    };
    const std::size_t helpers = std::min(work.size(), count) - 1;
    {
      std::vector<std::jthread> pool;
      pool.reserve(helpers);
      for (std::size_t t = 0; t < helpers; ++t) pool.emplace_back(worker, std::ref(work[t + 1]));
      worker(work[0]);
    }  // joins the helpers
    if (failure) std::rethrow_exception(failure);

    for (std::size_t i = 0; i < count; ++i) {
      if (!block[i].ok) ++summary.errors;
      ++summary.answered;
      out.write(block[i].answer.data(), static_cast<std::streamsize>(block[i].answer.size()));
    }
    out.flush();
  }
  if (too_long) refuse_long_line();
  summary.read_failed = in.bad();
  return summary;
}

}  // namespace proxima::cli
