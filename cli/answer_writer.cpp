// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the answer lines of `proxima query` (answer_writer.h).
#include "answer_writer.h"

#include <charconv>
#include <stdexcept>
#include <string>
#include <system_error>

namespace proxima::cli {

using Json = nlohmann::json;

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

}  // namespace proxima::cli
