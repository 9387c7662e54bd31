// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima query`, the JSON Lines exchange (docs/query-format.md).
//
// Each line is answered on its own: parse, validate every field with a
// message that names where the problem is (`b.vertices[3][1]`), build both
// hulls, run one cold distance query, print one answer line. Nothing but
// buffers survives from one line to the next, so a bad line can never change
// the answer to a good one.
#include "query.h"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "proxima/distance.h"
#include "proxima/polytope.h"

namespace proxima::cli {
namespace {

using Json = nlohmann::json;

// What is wrong with one query line. The message names the place in the
// query; the caller adds the line number.
class QueryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void fail(const std::string& message) { throw QueryError(message); }

// "(it is a string)" reads better than nlohmann's bare type name.
std::string kind(const Json& v) {
  switch (v.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array";
    case Json::value_t::string:
      return "a string";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::binary:
      return "binary data";
    case Json::value_t::discarded:
      return "discarded";
    default:
      return "a number";
  }
}

std::string indexed(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// nlohmann's messages start with "[json.exception.parse_error.101] "; the
// tag means nothing to someone fixing their input file. Each line is parsed
// on its own, so its "at line 1, column 7" would contradict our line number:
// keep only the column.
std::string readable_parse_message(std::string_view what) {
  if (!what.empty() && what.front() == '[') {
    const auto close = what.find("] ");
    if (close != std::string_view::npos) what.remove_prefix(close + 2);
  }
  std::string message(what);
  constexpr std::string_view kLineOne = "at line 1, column";
  const auto at = message.find(kLineOne);
  if (at != std::string::npos) message.replace(at, kLineOne.size(), "at column");
  return message;
}

// Where in a line the JSON parser gave up, as a path like a.vertices[3][1].
// The parser itself reports only a column. Replaying the line through this
// SAX handler, which keeps nothing but the path to the current value, stops
// at the same token; the path at that moment names the value being read.
// Used only after a parse has failed, so good lines pay nothing for it.
class ParsePathTracker final : public nlohmann::json_sax<Json> {
 public:
  bool null() override { return value(); }
  bool boolean(bool /*val*/) override { return value(); }
  bool number_integer(number_integer_t /*val*/) override { return value(); }
  bool number_unsigned(number_unsigned_t /*val*/) override { return value(); }
  bool number_float(number_float_t /*val*/, const string_t& /*s*/) override { return value(); }
  bool string(string_t& /*val*/) override { return value(); }
  bool binary(binary_t& /*val*/) override { return value(); }
  bool start_object(std::size_t /*elements*/) override {
    value();
    frames_.push_back(Frame{false, -1, {}});
    return true;
  }
  bool key(string_t& val) override {
    frames_.back().key = val;
    return true;
  }
  bool end_object() override {
    frames_.pop_back();
    return true;
  }
  bool start_array(std::size_t /*elements*/) override {
    value();
    frames_.push_back(Frame{true, -1, {}});
    return true;
  }
  bool end_array() override {
    frames_.pop_back();
    return true;
  }
  bool parse_error(std::size_t /*position*/, const std::string& /*last_token*/,
                   const Json::exception& /*ex*/) override {
    // The token that failed was never counted as a value, so in an array it
    // is the element after the last one counted.
    path_ = path(/*next_element=*/true);
    return false;
  }

  const std::string& error_path() const { return path_; }

 private:
  struct Frame {
    bool is_array;
    long index;       // arrays: index of the last value started
    std::string key;  // objects: the last key read ("" before the first)
  };

  bool value() {
    if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
    return true;
  }

  std::string path(bool next_element) const {
    std::string out;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      if (f.is_array) {
        const long index = f.index + (next_element && i + 1 == frames_.size() ? 1 : 0);
        if (index >= 0) {
          out += '[';
          out += std::to_string(index);
          out += ']';
        }
      } else if (!f.key.empty()) {
        if (!out.empty()) out += '.';
        out += f.key;
      }
    }
    return out;
  }

  std::vector<Frame> frames_;
  std::string path_;
};

// The message for a line that is not valid JSON, naming where it broke.
std::string describe_parse_error(const std::string& line, const Json::exception& ex) {
  ParsePathTracker tracker;
  Json::sax_parse(line, &tracker);
  const std::string& where = tracker.error_path();
  // 406 is nlohmann's "number overflow": a literal such as 1e999 that is
  // valid JSON but does not fit a double. Name it like the other
  // non-finite inputs, so the user sees the same message either way.
  constexpr int kNumberOverflow = 406;
  if (ex.id == kNumberOverflow) {
    return (where.empty() ? std::string("a number") : where) + " is not a finite number (" +
           readable_parse_message(ex.what()) + ")";
  }
  std::string message = "not valid JSON";
  if (!where.empty()) message += " near " + where;
  return message + ": " + readable_parse_message(ex.what());
}

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

// Reads body `name` ("a" or "b") of `query` into vertices and pose.
void read_body(const Json& query, const std::string& name, std::vector<Vec3>& vertices,
               Pose& pose) {
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

  // Absent and null both mean identity, so that writers with optional
  // fields need not special-case them.
  Quat rotation = Quat::Identity();
  const auto q = body->find("rotation");
  if (q != body->end() && !q->is_null()) {
    double wxyz[4];
    read_numbers(*q, name + ".rotation", 4, "4 numbers [w, x, y, z]", wxyz);
    // Normalized at any magnitude, a zero quaternion refused: the pose
    // contract's own function (proxima/pose.h), as in Python.
    try {
      rotation = unit_quaternion(Quat(wxyz[0], wxyz[1], wxyz[2], wxyz[3]), name + ".rotation");
    } catch (const InvalidInput& e) {
      fail(e.what());
    }
  }
  Vec3 translation = Vec3::Zero();
  const auto t = body->find("translation");
  if (t != body->end() && !t->is_null()) {
    read_numbers(*t, name + ".translation", 3, "3 numbers [x, y, z]", translation.data());
  }
  pose = Pose(rotation, translation);
}

void append_number(std::string& out, double x) {
  // "%.17g": 17 significant digits always identify a double uniquely, so the
  // reader gets back the very double we computed. std::to_chars with the
  // general format and precision 17 is defined as printf's %.17g, and unlike
  // printf it never looks at the locale (a decimal comma would break JSON).
  // 32 bytes hold the longest case, "-1.2345678901234567e-308".
  char buffer[32];
  const auto [end, ec] =
      std::to_chars(buffer, buffer + sizeof(buffer), x, std::chars_format::general, 17);
  if (ec != std::errc{}) throw std::logic_error("number formatting overflowed its buffer");
  out.append(buffer, end);
}

void append_point(std::string& out, const Vec3& p) {
  out += '[';
  append_number(out, p.x());
  out += ',';
  append_number(out, p.y());
  out += ',';
  append_number(out, p.z());
  out += ']';
}

void append_json_string(std::string& out, const std::string& s) {
  // Messages may quote the input (nlohmann's "last read: '...'"), which can
  // hold invalid UTF-8; replacing it keeps every answer line valid JSON.
  out += Json(s).dump(-1, ' ', false, Json::error_handler_t::replace);
}

void append_id(std::string& out, const Json* id) {
  // Echoed as parsed (nlohmann prints a double with its shortest exact
  // representation, so the value is the one given); null when absent.
  out += id != nullptr ? id->dump(-1, ' ', false, Json::error_handler_t::replace) : "null";
}

void append_error_answer(std::string& out, const Json* id, long line_number,
                         const std::string& message) {
  out += "{\"id\":";
  append_id(out, id);
  out += ",\"status\":\"error\",\"error\":";
  std::string located = "line ";
  located += std::to_string(line_number);
  located += ": ";
  located += message;
  append_json_string(out, located);
  out += '}';
}

// Largest absolute world coordinate of a hull: the R of DESIGN.md's
// accuracy standard, for the contact band that classifies an iteration-cap
// answer.
double world_scale(const ConvexPolytope& p, const Pose& pose) {
  double r = 0.0;
  for (const Vec3& v : p.vertices()) r = std::max(r, pose.apply(v).cwiseAbs().maxCoeff());
  return r;
}

// Buffers reused from line to line, so that a long run does not allocate the
// vertex arrays again for every query.
struct Workspace {
  std::vector<Vec3> vertices_a;
  std::vector<Vec3> vertices_b;
};

ConvexPolytope build_hull(const std::vector<Vec3>& vertices, const std::string& name) {
  try {
    return ConvexPolytope(vertices);
  } catch (const InvalidInput& e) {
    fail(name + ": " + e.what());
  }
}

// Appends the answer to one query line to `out`; returns false for an error
// answer.
bool answer_line(const std::string& line, long line_number, const DistanceOptions& options,
                 Workspace& work, std::string& out) {
  Json query;
  try {
    query = Json::parse(line);
  } catch (const Json::exception& e) {
    append_error_answer(out, nullptr, line_number, describe_parse_error(line, e));
    return false;
  }
  if (!query.is_object()) {
    append_error_answer(out, nullptr, line_number,
                        "the line is not a JSON object (it is " + kind(query) + ")");
    return false;
  }
  const auto id_it = query.find("id");
  const Json* id = id_it != query.end() ? &*id_it : nullptr;

  DistanceResult r;
  bool capped = false;
  double contact_band = 0.0;
  try {
    Pose pose_a;
    Pose pose_b;
    read_body(query, "a", work.vertices_a, pose_a);
    read_body(query, "b", work.vertices_b, pose_b);
    const ConvexPolytope a = build_hull(work.vertices_a, "a");
    const ConvexPolytope b = build_hull(work.vertices_b, "b");
    r = distance(a, pose_a, b, pose_b, options, nullptr);
    capped = r.status == Status::iteration_cap;
    if (capped) {
      // The same band the library uses for touching: 64 u R plus Ae.
      const double scale = std::max(world_scale(a, pose_a), world_scale(b, pose_b));
      contact_band = proxima::contact_band(scale, options.absolute_tolerance);
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

  // A JSON line can carry no NaN or infinity. Finite inputs whose products
  // overflow (coordinates near 1e308) are the only way to get one; say so
  // rather than print an invalid line.
  if (!std::isfinite(r.distance) || !r.point_a.allFinite() || !r.point_b.allFinite()) {
    append_error_answer(out, id, line_number,
                        "the result is not finite: the coordinates are too large for double "
                        "arithmetic");
    return false;
  }

  const char* status = to_string(r.status);
  if (capped) status = r.distance > contact_band ? "separated" : "touching";

  out += "{\"id\":";
  append_id(out, id);
  out += ",\"status\":\"";
  out += status;
  out += "\",\"distance\":";
  append_number(out, r.distance);
  out += ",\"point_a\":";
  append_point(out, r.point_a);
  out += ",\"point_b\":";
  append_point(out, r.point_b);
  out += ",\"iterations\":";
  out += std::to_string(r.iterations);
  if (capped) out += ",\"iteration_cap\":true";
  out += '}';
  return true;
}

bool is_blank(std::string_view line) {
  return line.find_first_not_of(" \t\r\n\f\v") == std::string_view::npos;
}

}  // namespace

QueryRunSummary run_queries(std::istream& in, std::ostream& out, const DistanceOptions& options,
                            int threads) {
  QueryRunSummary summary;
  std::string line;
  long line_number = 0;
  if (threads <= 1) {
    Workspace work;
    std::string answer;
    while (std::getline(in, line)) {
      ++line_number;
      if (is_blank(line)) continue;
      answer.clear();
      if (!answer_line(line, line_number, options, work, answer)) ++summary.errors;
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
  while (more) {
    std::size_t count = 0;
    while (count < block_size) {
      if (!std::getline(in, line)) {
        more = false;
        break;
      }
      ++line_number;
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
          p.ok = answer_line(p.line, p.line_number, options, ws, p.answer);
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
  summary.read_failed = in.bad();
  return summary;
}

}  // namespace proxima::cli
