// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the errors of `proxima query` lines (json_errors.h): messages
// that name where a line is wrong, the parse-error path tracker and the
// nesting limit.
#include "json_errors.h"

#include <string>
#include <string_view>
#include <vector>

namespace proxima::cli {
namespace {

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

}  // namespace

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

// One counter and a flag for "inside a string"; an escape skips the next
// character, so an escaped quote does not end the string.
std::size_t nesting_overflow_column(std::string_view line) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_string) {
      if (c == '\\') {
        ++i;  // the escaped character, possibly a quote
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return i + 1;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return 0;
}

}  // namespace proxima::cli
