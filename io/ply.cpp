// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: the PLY reader, ascii and binary_little_endian (see formats.h,
// include/proxima/io.h).
#include <algorithm>
#include <array>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "binary.h"
#include "formats.h"
#include "limits.h"
#include "text.h"

namespace proxima::io_detail {

enum class PlyType : std::uint8_t { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

bool ply_type(std::string_view name, PlyType* type) {
  static constexpr std::array<std::pair<std::string_view, PlyType>, 16> kNames = {{
      {"char", PlyType::int8},
      {"int8", PlyType::int8},
      {"uchar", PlyType::uint8},
      {"uint8", PlyType::uint8},
      {"short", PlyType::int16},
      {"int16", PlyType::int16},
      {"ushort", PlyType::uint16},
      {"uint16", PlyType::uint16},
      {"int", PlyType::int32},
      {"int32", PlyType::int32},
      {"uint", PlyType::uint32},
      {"uint32", PlyType::uint32},
      {"float", PlyType::float32},
      {"float32", PlyType::float32},
      {"double", PlyType::float64},
      {"float64", PlyType::float64},
  }};
  for (const auto& [n, t] : kNames) {
    if (n == name) {
      *type = t;
      return true;
    }
  }
  return false;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::int8:
    case PlyType::uint8:
      return 1;
    case PlyType::int16:
    case PlyType::uint16:
      return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32:
      return 4;
    case PlyType::float64:
      return 8;
  }
  return 1;
}

bool ply_is_float(PlyType t) { return t == PlyType::float32 || t == PlyType::float64; }
bool ply_is_signed(PlyType t) {
  return t == PlyType::int8 || t == PlyType::int16 || t == PlyType::int32;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::float32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::uint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::int64_t line = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  bool binary = false;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;  // first byte after end_header's line
  std::int64_t lines = 0;       // header lines
};

PlyHeader read_ply_header(const Source& src, std::string_view bytes) {
  PlyHeader header;
  std::size_t pos = 0;
  bool have_format = false;
  bool ended = false;
  std::set<std::string> element_names;
  std::set<std::string> property_names;  // of the current element
  while (pos < bytes.size()) {
    // Header lines end with "\n" or "\r\n"; the binary data starts right after.
    const std::size_t nl = bytes.find('\n', pos);
    const std::size_t end = nl == std::string_view::npos ? bytes.size() : nl;
    std::string_view line = bytes.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
    const std::int64_t at = ++header.lines;
    if (line.find('\0') != std::string_view::npos) src.fail_line(at, "NUL byte in the PLY header");
    if (at == 1) {
      if (line != "ply")
        src.fail_line(1, "not a PLY file: the first line is " + quote(line) + ", expected 'ply'");
      continue;
    }
    Tokens tokens(line);
    std::string_view word;
    if (!tokens.next(&word)) continue;
    if (word == "comment" || word == "obj_info") continue;
    if (word == "end_header") {
      ended = true;
      break;
    }
    if (word == "format") {
      std::string_view encoding;
      std::string_view version;
      if (!tokens.next(&encoding) || !tokens.next(&version))
        src.fail_line(at, "PLY format line incomplete");
      if (encoding == "ascii") {
        header.binary = false;
      } else if (encoding == "binary_little_endian") {
        header.binary = true;
      } else if (encoding == "binary_big_endian") {
        src.fail_line(
            at, "PLY binary_big_endian is not supported (ascii and binary_little_endian are)");
      } else {
        src.fail_line(at, "unknown PLY format " + quote(encoding));
      }
      if (version != "1.0")
        src.fail_line(at, "unsupported PLY version " + quote(version) + " (expected 1.0)");
      have_format = true;
    } else if (word == "element") {
      PlyElement element;
      std::string_view name;
      std::string_view count;
      if (!tokens.next(&name) || !tokens.next(&count))
        src.fail_line(at, "PLY element line needs a name and a count");
      if (!parse_count(count, &element.count)) {
        src.fail_line(at, "PLY element count " + quote(count) + " is not a non-negative integer");
      }
      element.name = std::string(name);
      if (!element_names.insert(element.name).second)
        src.fail_line(at, "duplicate PLY element " + quote(name));
      element.line = at;
      header.elements.push_back(std::move(element));
      property_names.clear();
    } else if (word == "property") {
      if (header.elements.empty()) src.fail_line(at, "PLY property before any element");
      PlyProperty property;
      std::string_view type;
      if (!tokens.next(&type)) src.fail_line(at, "PLY property line needs a type and a name");
      if (type == "list") {
        property.is_list = true;
        std::string_view count_type;
        if (!tokens.next(&count_type) || !tokens.next(&type))
          src.fail_line(at, "PLY list property needs two types");
        if (!ply_type(count_type, &property.count_type))
          src.fail_line(at, "unknown PLY type " + quote(count_type));
        if (ply_is_float(property.count_type)) {
          src.fail_line(at,
                        "PLY list length type " + quote(count_type) + " is not an integer type");
        }
      }
      if (!ply_type(type, &property.type)) src.fail_line(at, "unknown PLY type " + quote(type));
      std::string_view name;
      if (!tokens.next(&name)) src.fail_line(at, "PLY property has no name");
      property.name = std::string(name);
      // Names are unique per element (a set, not a scan: a header of a
      // million properties must not take quadratic time).
      if (!property_names.insert(property.name).second)
        src.fail_line(at, "duplicate PLY property " + quote(name));
      header.elements.back().properties.push_back(std::move(property));
    } else {
      src.fail_line(at, "unknown PLY header keyword " + quote(word) + " (is end_header missing?)");
    }
  }
  if (!ended) src.fail_line(header.lines, "PLY header has no end_header line");
  if (!have_format) src.fail_line(header.lines, "PLY header has no format line");
  header.data_offset = pos;
  return header;
}

struct VertexLayout {
  std::size_t element = 0;
  std::array<std::size_t, 3> xyz{};  // property indices of x, y, z
};

VertexLayout ply_vertex_layout(const Source& src, const PlyHeader& header) {
  VertexLayout layout;
  bool found = false;
  for (std::size_t e = 0; e < header.elements.size() && !found; ++e) {
    if (header.elements[e].name == "vertex") {
      layout.element = e;
      found = true;
    }
  }
  if (!found) src.fail_line(header.lines, "PLY header declares no 'vertex' element");
  const PlyElement& vertex = header.elements[layout.element];
  for (int axis = 0; axis < 3; ++axis) {
    const auto it = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                 [&](const PlyProperty& p) { return p.name == axis_name(axis); });
    if (it == vertex.properties.end()) {
      src.fail_line(vertex.line,
                    "PLY vertex element has no property '" + std::string(axis_name(axis)) + "'");
    }
    if (it->is_list) src.fail_line(vertex.line, "PLY vertex property '" + it->name + "' is a list");
    layout.xyz[static_cast<std::size_t>(axis)] =
        static_cast<std::size_t>(it - vertex.properties.begin());
  }
  if (vertex.count > kMaxPoints) {
    src.fail_line(vertex.line, "PLY header announces " + std::to_string(vertex.count) +
                                   " vertices, more than " + std::to_string(kMaxPoints));
  }
  return layout;
}

// Bytes of one instance counting each list as empty: the least an instance
// can take.
std::size_t ply_min_instance_bytes(const PlyElement& element) {
  std::size_t bytes = 0;
  for (const PlyProperty& p : element.properties)
    bytes += p.is_list ? ply_size(p.count_type) : ply_size(p.type);
  return bytes;
}

bool ply_has_list(const PlyElement& element) {
  return std::any_of(element.properties.begin(), element.properties.end(),
                     [](const PlyProperty& p) { return p.is_list; });
}

class PlyBinaryReader {
 public:
  PlyBinaryReader(const Source& src, std::string_view bytes, std::size_t pos)
      : src_(src), bytes_(bytes), pos_(pos) {}

  std::size_t left() const { return bytes_.size() - pos_; }
  std::size_t pos() const { return pos_; }

  // The header's count of `element` must fit in the bytes left, at the least
  // size an instance can take; checked before anything is allocated for it.
  void check_fits(const PlyElement& element) const {
    const std::size_t least = ply_min_instance_bytes(element);
    if (least > 0 && element.count > left() / least) {
      src_.fail_byte(bytes_.size(),
                     "truncated PLY: the header announces " + std::to_string(element.count) + " '" +
                         element.name + "' elements of at least " + std::to_string(least) +
                         " bytes each, but only " + std::to_string(left()) + " bytes follow");
    }
  }

  void skip_element(const PlyElement& element) {
    check_fits(element);
    if (!ply_has_list(element)) {
      pos_ += static_cast<std::size_t>(element.count) * ply_min_instance_bytes(element);
      return;
    }
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const PlyProperty& p : element.properties) skip_property(element, i, p);
    }
  }

  // Reads the vertex element; other properties skipped by their type.
  std::vector<Vec3> read_vertices(const PlyElement& element, const VertexLayout& layout) {
    check_fits(element);
    std::vector<Vec3> points;
    points.reserve(static_cast<std::size_t>(element.count));
    for (std::size_t i = 0; i < element.count; ++i) {
      Vec3 p = Vec3::Zero();
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const PlyProperty& property = element.properties[k];
        const auto axis = static_cast<int>(std::find(layout.xyz.begin(), layout.xyz.end(), k) -
                                           layout.xyz.begin());
        if (axis == 3) {
          skip_property(element, i, property);
          continue;
        }
        need(ply_size(property.type), element, i);
        p[axis] = scalar(property.type, [&] { return coordinate_label(axis, i); });
      }
      points.push_back(p);
    }
    return points;
  }

 private:
  void need(std::size_t n, const PlyElement& element, std::uint64_t index) const {
    if (n > left()) {
      src_.fail_byte(bytes_.size(), "truncated PLY: the data ends inside '" + element.name +
                                        "' element " + std::to_string(index) + " (0-based) of " +
                                        std::to_string(element.count));
    }
  }

  template <class Label>
  double scalar(PlyType type, Label&& label) {
    const std::size_t size = ply_size(type);
    double v = 0.0;
    if (ply_is_float(type)) {
      v = binary_float(src_, bytes_, pos_, type == PlyType::float64, label);
    } else {
      const std::uint64_t raw = load_le(bytes_, pos_, size);
      if (ply_is_signed(type)) {
        // Sign-extend from `size` bytes.
        const unsigned shift = 64U - 8U * static_cast<unsigned>(size);
        v = static_cast<double>(static_cast<std::int64_t>(raw << shift) >> shift);
      } else {
        v = static_cast<double>(raw);
      }
    }
    pos_ += size;
    return v;
  }

  void skip_property(const PlyElement& element, std::uint64_t index, const PlyProperty& p) {
    if (!p.is_list) {
      need(ply_size(p.type), element, index);
      pos_ += ply_size(p.type);
      return;
    }
    const std::size_t count_size = ply_size(p.count_type);
    need(count_size, element, index);
    const std::size_t at = pos_;
    const std::uint64_t raw = load_le(bytes_, pos_, count_size);
    pos_ += count_size;
    const bool negative = ply_is_signed(p.count_type) && ((raw >> (8 * count_size - 1)) & 1U) != 0;
    if (negative) src_.fail_byte(at, "negative length of PLY list '" + p.name + "'");
    const std::size_t item = ply_size(p.type);
    if (raw > left() / item) {
      src_.fail_byte(at, "truncated PLY: list '" + p.name + "' of '" + element.name + "' element " +
                             std::to_string(index) + " (0-based) announces " + std::to_string(raw) +
                             " items, more than the " + std::to_string(left()) +
                             " bytes left can hold");
    }
    pos_ += static_cast<std::size_t>(raw) * item;
  }

  const Source& src_;
  std::string_view bytes_;
  std::size_t pos_;
};

// ASCII PLY data: whitespace-separated tokens, instances usually one per line
// but not necessarily; lines are counted for messages.
class PlyTextReader {
 public:
  PlyTextReader(const Source& src, std::string_view bytes, std::size_t pos, std::int64_t line)
      : src_(src), bytes_(bytes), pos_(pos), line_(line + 1), last_line_(line) {}

  std::size_t left() const { return bytes_.size() - pos_; }

  void skip_element(const PlyElement& element) {
    if (element.properties.empty()) return;  // no tokens at all, whatever the count
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (const PlyProperty& p : element.properties) skip_property(element, i, p);
    }
  }

  std::vector<Vec3> read_vertices(const PlyElement& element, const VertexLayout& layout) {
    std::vector<Vec3> points;
    // Each property takes at least one character and one separator.
    points.reserve(std::min<std::size_t>(element.count, left() / (2 * element.properties.size())));
    for (std::size_t i = 0; i < element.count; ++i) {
      Vec3 p = Vec3::Zero();
      for (std::size_t k = 0; k < element.properties.size(); ++k) {
        const auto axis = static_cast<int>(std::find(layout.xyz.begin(), layout.xyz.end(), k) -
                                           layout.xyz.begin());
        if (axis == 3) {
          skip_property(element, i, element.properties[k]);
          continue;
        }
        const std::string_view token = next(element, i);
        p[axis] = text_coordinate(src_, line_, token, axis, i);
      }
      points.push_back(p);
    }
    return points;
  }

 private:
  std::string_view next(const PlyElement& element, std::uint64_t index) {
    while (pos_ < bytes_.size()) {
      const char c = bytes_[pos_];
      if (c == '\n' || (c == '\r' && (pos_ + 1 == bytes_.size() || bytes_[pos_ + 1] != '\n'))) {
        ++line_;
      } else if (c == '\0') {
        src_.fail_line(line_, "NUL byte in ASCII PLY data");
      } else if (!is_blank(c) && c != '\r') {
        break;
      }
      ++pos_;
    }
    if (pos_ == bytes_.size()) {
      src_.fail_line(last_line_, "the ASCII PLY data ends inside '" + element.name + "' element " +
                                     std::to_string(index) + " (0-based) of the " +
                                     std::to_string(element.count) + " the header announces");
    }
    const std::size_t b = pos_;
    last_line_ = line_;
    while (pos_ < bytes_.size()) {
      const char c = bytes_[pos_];
      if (is_blank(c) || c == '\r' || c == '\n' || c == '\0') break;
      ++pos_;
    }
    return bytes_.substr(b, pos_ - b);
  }

  void skip_property(const PlyElement& element, std::uint64_t index, const PlyProperty& p) {
    const std::string_view token = next(element, index);
    if (!p.is_list) return;
    std::uint64_t items = 0;
    if (!parse_count(token, &items)) {
      src_.fail_line(line_, "PLY list length " + quote(token) + " of '" + p.name +
                                "' is not a non-negative integer");
    }
    for (std::uint64_t j = 0; j < items; ++j) next(element, index);
  }

  const Source& src_;
  std::string_view bytes_;
  std::size_t pos_;
  std::int64_t line_;       // the line at pos_
  std::int64_t last_line_;  // the line of the last token: where a short file is reported to end
};

PointCloud read_ply(const Source& src, std::string_view bytes) {
  const PlyHeader header = read_ply_header(src, bytes);
  const VertexLayout layout = ply_vertex_layout(src, header);
  PointCloud cloud;
  if (header.binary) {
    PlyBinaryReader reader(src, bytes, header.data_offset);
    for (std::size_t e = 0; e < layout.element; ++e) reader.skip_element(header.elements[e]);
    cloud.points = reader.read_vertices(header.elements[layout.element], layout);
    cloud.format = MeshFormat::ply_binary_le;
  } else {
    PlyTextReader reader(src, bytes, header.data_offset, header.lines);
    for (std::size_t e = 0; e < layout.element; ++e) reader.skip_element(header.elements[e]);
    cloud.points = reader.read_vertices(header.elements[layout.element], layout);
    cloud.format = MeshFormat::ply_ascii;
  }
  return cloud;
}

}  // namespace proxima::io_detail
