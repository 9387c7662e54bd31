// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 7: `proxima distance` and `proxima hull` (cli/tools.h).
//
// Both read their files through proxima_io, build the hull of every point
// (a non-convex input is reported, not refused) and print either a table for
// people or one JSON object for programs. Every number is printed in its
// shortest round-trip form, so the JSON output and an exported hull give back
// the very doubles computed.
#include "tools.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "exit_codes.h"
#include "proxima/query/body_distance.h"
#include "proxima/query/distance.h"
#include "proxima/io.h"
#include "proxima/shape/polytope.h"

namespace proxima::cli {
namespace {

using OrderedJson = nlohmann::ordered_json;

// A bad pose number or quaternion: bad input (exit 1), named by option.
class BadArgument : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Shortest decimal that reads back as the same double (std::to_chars without
// a precision is round-trip exact); "-0" prints as "0" so that tables do not
// show signed zeros produced by rotations.
std::string number(double x) {
  if (x == 0.0) return "0";
  std::array<char, 32> buffer{};
  const auto [end, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  if (ec != std::errc()) return "nan";
  return {buffer.data(), end};
}

std::string point_text(const Vec3& p) {
  return number(p.x()) + " " + number(p.y()) + " " + number(p.z());
}

OrderedJson point_json(const Vec3& p) { return OrderedJson::array({p.x(), p.y(), p.z()}); }

struct LoadedFile {
  ConvexPolytope polytope;
  MeshFormat format = MeshFormat::unknown;
  int input_points = 0;
  bool convex = true;  // surface_is_convex: the input surface is its hull's boundary
};

// read_points, then the hull of every point (what load_convex does), keeping
// the format read for the report. A hull failure becomes a FileError naming
// the file, like load_convex's.
LoadedFile load_file(const std::string& path, std::uint64_t max_file_bytes) {
  ReadOptions options;
  options.max_file_bytes = max_file_bytes;
  PointCloud cloud = read_points(path, options);
  try {
    ConvexPolytope polytope(cloud.points);
    const bool convex = surface_is_convex(polytope, cloud.points, cloud.triangles);
    return LoadedFile{std::move(polytope), cloud.format, static_cast<int>(cloud.points.size()),
                      convex};
  } catch (const FileError&) {
    throw;
  } catch (const InvalidInput& e) {
    throw FileError::in_file(path, e.what());
  }
}

std::vector<std::int32_t> hull_ids(const Feature& f) {
  std::vector<std::int32_t> ids;
  for (int i = 0; i < f.vertex_count(); ++i) ids.push_back(f.vertices[static_cast<std::size_t>(i)]);
  return ids;
}

std::vector<std::int32_t> input_ids(const Feature& f, const ConvexPolytope& p) {
  std::vector<std::int32_t> ids;
  for (const std::int32_t v : hull_ids(f))
    ids.push_back(p.input_index()[static_cast<std::size_t>(v)]);
  return ids;
}

std::string id_list(const std::vector<std::int32_t>& ids) {
  std::string s;
  for (const std::int32_t id : ids) {
    if (!s.empty()) s += ' ';
    s += std::to_string(id);
  }
  return s;
}

OrderedJson feature_json(const Feature& f, const ConvexPolytope& p) {
  OrderedJson j;
  j["type"] = to_string(f.type);
  j["hull_vertices"] = hull_ids(f);
  j["face"] = f.face >= 0 ? OrderedJson(f.face) : OrderedJson(nullptr);
  j["input_indices"] = input_ids(f, p);
  return j;
}

std::string feature_text(const Feature& f, const ConvexPolytope& p) {
  std::string s = to_string(f.type);
  if (f.face >= 0) s += " " + std::to_string(f.face);
  s += ": hull vertices " + id_list(hull_ids(f)) + " (input points " + id_list(input_ids(f, p)) +
       ")";
  return s;
}

// A file read as its hull: what was read and how convex it was.
OrderedJson hull_report_json(const std::string& path, MeshFormat format, int input_points,
                      const ConvexPolytope& hull, bool convex) {
  OrderedJson j;
  j["file"] = path;
  j["format"] = to_string(format);
  j["input_points"] = input_points;
  j["hull_vertices"] = hull.vertex_count();
  j["dimension"] = hull.dimension();
  j["points_inside"] = hull.interior_point_count();
  j["convex"] = convex;
  return j;
}

std::string hull_report_text(const std::string& path, MeshFormat format, int input_points,
                             const ConvexPolytope& hull, bool convex) {
  std::ostringstream s;
  s << path << " (" << to_string(format) << "): " << input_points << " points, "
    << hull.vertex_count() << " hull vertices, dimension " << hull.dimension();
  const int inside = hull.interior_point_count();
  if (!convex) {
    s << "; not convex: ";
    if (inside > 0)
      s << inside << (inside == 1 ? " point is" : " points are")
        << " inside the hull (or repeated), ";
    else
      s << "the surface folds inward, ";
    s << "the hull of all points is used";
  }
  return s.str();
}


// A file read as the kind of body the command names (DistanceCommand::as_a).
struct LoadedBody {
  std::optional<Body> body;
  std::string as;  // "mesh", "hull" or "pieces"
  MeshFormat format = MeshFormat::unknown;
  int input_points = 0;
  int triangles = 0;  // the file's (fan-triangulated) faces
  bool convex = true;
  std::optional<ConvexPolytope> hull;  // as "hull": the polytope (for the hull-only answer)
  int degenerate_triangles = 0;        // as "mesh"
  bool closed = false;                 // as "mesh"
  int pieces = 0;                      // as "pieces"
};

LoadedBody load_body_as(const std::string& path, const std::string& as,
                        std::uint64_t max_file_bytes) {
  ReadOptions options;
  options.max_file_bytes = max_file_bytes;
  const PointCloud cloud = read_points(path, options);
  LoadedBody out;
  out.format = cloud.format;
  out.input_points = static_cast<int>(cloud.points.size());
  out.triangles = static_cast<int>(cloud.triangles.size());
  try {
    std::string kind = as;
    if (kind.empty() || kind == "hull") {
      ConvexPolytope polytope(cloud.points);
      out.convex = surface_is_convex(polytope, cloud.points, cloud.triangles);
      if (kind.empty() && !out.convex && !cloud.triangles.empty()) {
        throw FileError::in_file(
            path,
            "not convex (its surface is not its hull's boundary): say how to read it: --as mesh "
            "(the surface as given), --as hull (its convex hull) or --as pieces (one hull per "
            "group); --as-a / --as-b for one file");
      }
      kind = "hull";
      out.hull.emplace(polytope);
      out.body.emplace(std::make_shared<const ConvexPolytope>(std::move(polytope)));
    } else if (kind == "mesh") {
      LoadedMesh m = mesh_from_cloud(cloud);
      out.degenerate_triangles = m.degenerate_triangles;
      out.closed = m.closed;
      out.body.emplace(std::make_shared<const TriangleMesh>(std::move(m.mesh)));
    } else {  // "pieces" (main.cpp checks the names)
      LoadedCompound c = compound_from_cloud(cloud);
      out.pieces = c.body.piece_count();
      out.body.emplace(std::make_shared<const CompoundBody>(std::move(c.body)));
    }
    out.as = kind;
  } catch (const FileError&) {
    throw;
  } catch (const InvalidInput& e) {
    throw FileError::in_file(path, e.what());
  }
  return out;
}

OrderedJson loaded_json(const std::string& path, const LoadedBody& body) {
  OrderedJson j;
  j["file"] = path;
  j["format"] = to_string(body.format);
  j["as"] = body.as;
  j["input_points"] = body.input_points;
  if (body.as == "hull") {
    j["hull_vertices"] = body.hull->vertex_count();
    j["dimension"] = body.hull->dimension();
    j["convex"] = body.convex;
  } else if (body.as == "mesh") {
    j["triangles"] = body.triangles;
    j["degenerate_triangles"] = body.degenerate_triangles;
    j["closed"] = body.closed;
  } else {
    j["pieces"] = body.pieces;
  }
  return j;
}

std::string loaded_text(const std::string& path, const LoadedBody& body) {
  std::ostringstream s;
  s << path << " (" << to_string(body.format) << ") as " << body.as << ": " << body.input_points
    << " points";
  if (body.as == "hull") {
    s << ", " << body.hull->vertex_count() << " hull vertices, dimension " << body.hull->dimension()
      << (body.convex ? "" : "; not convex, its hull is used (--as hull)");
  } else if (body.as == "mesh") {
    s << ", " << body.triangles << " triangles, " << (body.closed ? "closed" : "open");
    if (body.degenerate_triangles > 0)
      s << ", " << body.degenerate_triangles << " degenerate (measured as segments or points)";
  } else {
    s << ", " << body.pieces << " pieces";
  }
  return s.str();
}

// `proxima distance` between two hulls keeps its hull report (input
// indices of the features), with how the file was read.
OrderedJson hull_json(const std::string& path, const LoadedBody& body) {
  OrderedJson j = hull_report_json(path, body.format, body.input_points, *body.hull, body.convex);
  j["as"] = body.as;
  return j;
}

std::string hull_text(const std::string& path, const LoadedBody& body) {
  return hull_report_text(path, body.format, body.input_points, *body.hull, body.convex);
}

// A feature of a body's core: vertex ids in the core's terms (hull ids for
// a hull or a piece, the file's vertex ids for a mesh), the face (hull face,
// or the triangle for a mesh), the piece or triangle it is on.
OrderedJson body_feature_json(const Feature& f, std::int32_t piece, std::int32_t triangle) {
  OrderedJson j;
  j["type"] = to_string(f.type);
  j["vertices"] = hull_ids(f);
  j["face"] = f.face >= 0 ? OrderedJson(f.face) : OrderedJson(nullptr);
  if (piece >= 0) j["piece"] = piece;
  if (triangle >= 0) j["triangle"] = triangle;
  return j;
}

std::string body_feature_text(const Feature& f, std::int32_t piece, std::int32_t triangle) {
  std::string s = to_string(f.type);
  if (triangle >= 0) {
    s += " of triangle " + std::to_string(triangle);
  } else if (f.face >= 0) {
    s += " " + std::to_string(f.face);
  }
  if (piece >= 0) s += " of piece " + std::to_string(piece);
  s += ": vertices " + id_list(hull_ids(f));
  return s;
}

// One line of JSON. File names are bytes, not necessarily UTF-8, and
// nlohmann's dump throws on invalid UTF-8 (a name with byte 0xff lost the
// whole answer): such bytes are written as U+FFFD instead.
std::string json_line(const OrderedJson& j) {
  return j.dump(-1, ' ', false, OrderedJson::error_handler_t::replace) + "\n";
}

void row(std::ostream& out, const std::string& name, const std::string& value) {
  out << std::left << std::setw(14) << name << value << "\n";
}

std::string hull_shape(int dimension) {
  switch (dimension) {
    case 0:
      return "a point";
    case 1:
      return "a segment";
    case 2:
      return "a polygon";
    default:
      return "a solid";
  }
}

struct ExportSummary {
  int vertices = 0;
  int faces = 0;
  std::string note;  // what was written for a hull of lower dimension
};

// Writes the hull as OBJ or OFF: the hull vertices in hull order (vertex i
// of the file is hull vertex i) and the faces as polygons, counter-clockwise
// seen from outside. A polygon (dimension 2) has both sides as faces, so it
// is written as two opposite polygons; a segment has no faces (OBJ gets one
// `l` line element, OFF only the two vertices); a point is one vertex.
ExportSummary write_hull(const ConvexPolytope& p, const std::string& path,
                         const std::string& format, const std::string& source) {
  std::ostringstream text;
  const bool obj = format == "obj";
  const int faces = p.face_count();
  if (obj) {
    text << "# convex hull of " << source << " written by proxima hull: " << p.vertex_count()
         << " vertices, " << faces << " faces, dimension " << p.dimension() << "\n";
    for (const Vec3& v : p.vertices()) text << "v " << point_text(v) << "\n";
    for (int f = 0; f < faces; ++f) {
      text << "f";
      for (const std::int32_t v : p.face(f)) text << " " << v + 1;
      text << "\n";
    }
    if (p.dimension() == 1) text << "l 1 2\n";
  } else {
    text << "OFF\n" << p.vertex_count() << " " << faces << " " << p.edge_count() << "\n";
    for (const Vec3& v : p.vertices()) text << point_text(v) << "\n";
    for (int f = 0; f < faces; ++f) {
      text << p.face(f).size();
      for (const std::int32_t v : p.face(f)) text << " " << v;
      text << "\n";
    }
  }

  std::ofstream file(path, std::ios::binary);
  const std::string contents = text.str();
  file.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  file.close();
  if (!file) throw FileError::in_file(path, "cannot write the hull");

  ExportSummary summary{p.vertex_count(), faces, {}};
  if (p.dimension() == 2) {
    summary.note = "the hull is a polygon: written as two faces, one per side";
  } else if (p.dimension() == 1) {
    summary.note =
        obj ? "the hull is a segment: its two end points and one line element, no faces"
            : "the hull is a segment: its two end points only (OFF has no line elements)";
  } else if (p.dimension() == 0) {
    summary.note = "the hull is a single point: one vertex, no faces";
  }
  return summary;
}

}  // namespace

Body load_body_named(const std::string& path, const std::string& as,
                     std::uint64_t max_file_bytes) {
  return *load_body_as(path, as, max_file_bytes).body;
}

namespace {

double parse_number(const std::string& token, const std::string& option, int position,
                    std::optional<QuaternionOrder> order) {
  static constexpr std::array<const char*, 7> kScalarFirst = {"x",  "y",  "z", "qw",
                                                              "qx", "qy", "qz"};
  static constexpr std::array<const char*, 7> kScalarLast = {"x", "y", "z", "qx", "qy", "qz", "qw"};
  static constexpr std::array<const char*, 7> kUnnamed = {"x", "y", "z", "q[0]",
                                                          "q[1]", "q[2]", "q[3]"};
  const auto& kNames = !order                            ? kUnnamed
                       : *order == QuaternionOrder::wxyz ? kScalarFirst
                                                         : kScalarLast;
  double value = 0.0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (!token.empty() && token.front() == '+') ++first;  // from_chars takes no plus sign
  const auto [end, ec] = std::from_chars(first, last, value);
  const std::string where = option + " " + kNames[static_cast<std::size_t>(position)];
  if (ec == std::errc::result_out_of_range)
    throw BadArgument(where + ": '" + token + "' is out of the range of double");
  if (ec != std::errc() || end != last || first == last)
    throw BadArgument(where + ": '" + token + "' is not a number");
  if (!std::isfinite(value)) throw BadArgument(where + ": '" + token + "' is not finite");
  return value;
}

}  // namespace

// x y z, then optionally the quaternion in `order` (qw qx qy qz or qx qy qz
// qw); the quaternion is normalized, so it only has to be non-zero (a zero
// quaternion has no rotation to normalize to).
Pose parse_pose(const std::vector<std::string>& tokens, const std::string& option,
                std::optional<QuaternionOrder> order) {
  if (tokens.empty()) return Pose::identity();
  if (tokens.size() != 3 && tokens.size() != 7) {
    throw BadArgument(option + " takes 3 numbers (x y z) or 7 (x y z and a quaternion), not " +
                      std::to_string(tokens.size()));
  }
  std::array<double, 7> v{};
  for (std::size_t i = 0; i < tokens.size(); ++i)
    v[i] = parse_number(tokens[i], option, static_cast<int>(i), order);
  const Vec3 translation(v[0], v[1], v[2]);
  if (tokens.size() == 3) return Pose(Mat3::Identity(), translation);
  // The pose contract's quaternion (proxima/core/pose.h): normalized at any
  // magnitude, a zero one refused in the same words as everywhere. Four
  // numbers whose order is not named are refused with both readings: in
  // the other order they are another rotation.
  try {
    if (!order) {
      const std::string what = option + " quaternion";
      throw BadArgument(option + ": the quaternion " + tokens[3] + " " + tokens[4] + " " +
                        tokens[5] + " " + tokens[6] + " does not name its order: " +
                        quaternion_readings(&v[3], what) +
                        ". Add --quaternion-order wxyz or --quaternion-order xyzw");
    }
    const char* words = *order == QuaternionOrder::wxyz ? " (qw qx qy qz)" : " (qx qy qz qw)";
    return Pose(
        unit_quaternion(quaternion_in_order(&v[3], *order), option + words).toRotationMatrix(),
        translation);
  } catch (const InvalidInput& e) {
    throw BadArgument(e.what());
  }
}

std::string export_format(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".obj") return "obj";
  if (ext == ".off") return "off";
  return {};
}

// `proxima distance` when a file is read as a mesh or as pieces: the one
// call for any two bodies (body.h), its signed distance and the triangles
// or pieces of the answer.
int print_body_distance(const DistanceCommand& command, const LoadedBody& a, const LoadedBody& b,
                        const Pose& pose_a, const Pose& pose_b, std::ostream& out,
                        std::ostream& err) {
  const BodyResult r = distance(*a.body, pose_a, *b.body, pose_b, command.options, nullptr);
  if (!std::isfinite(r.distance) || !r.point_a.allFinite() || !r.point_b.allFinite()) {
    err << "proxima distance: the result is not finite: the coordinates are too large for double "
           "arithmetic\n";
    return kExitFailure;
  }
  const auto bound = [](double v) { return std::isfinite(v) ? OrderedJson(v) : OrderedJson(nullptr); };
  if (command.json) {
    OrderedJson j;
    j["a"] = loaded_json(command.file_a, a);
    j["b"] = loaded_json(command.file_b, b);
    j["status"] = to_string(r.status);
    j["distance"] = r.distance;
    j["lower_bound"] = r.lower_bound;
    j["signed_distance"] = r.signed_distance();
    j["signed_lower_bound"] = bound(r.signed_lower_bound());
    j["signed_upper_bound"] = bound(r.signed_upper_bound());
    j["point_a"] = point_json(r.point_a);
    j["point_b"] = point_json(r.point_b);
    j["normal"] = point_json(r.normal);
    j["feature_a"] = body_feature_json(r.feature_a, r.piece_a, r.triangle_a);
    j["feature_b"] = body_feature_json(r.feature_b, r.piece_b, r.triangle_b);
    out << json_line(j);
  } else {
    row(out, "A", loaded_text(command.file_a, a));
    row(out, "B", loaded_text(command.file_b, b));
    row(out, "status", to_string(r.status));
    row(out, "distance", number(r.distance));
    row(out, "lower bound", number(r.lower_bound));
    row(out, "signed",
        number(r.signed_distance()) + "  (certified in [" + number(r.signed_lower_bound()) + ", " +
            number(r.signed_upper_bound()) + "])");
    row(out, "point on A", point_text(r.point_a));
    row(out, "point on B", point_text(r.point_b));
    row(out, "normal", point_text(r.normal) + "  (from A towards B)");
    row(out, "feature A", body_feature_text(r.feature_a, r.piece_a, r.triangle_a));
    row(out, "feature B", body_feature_text(r.feature_b, r.piece_b, r.triangle_b));
  }
  out.flush();
  if (!out) {
    err << "proxima distance: writing the answer failed\n";
    return kExitFailure;
  }
  return kExitOk;
}

int run_distance(const DistanceCommand& command, std::ostream& out, std::ostream& err) {
  Pose pose_a;
  Pose pose_b;
  try {
    pose_a = parse_pose(command.pose_a, "--pose-a", command.quaternion_order);
    pose_b = parse_pose(command.pose_b, "--pose-b", command.quaternion_order);
  } catch (const BadArgument& e) {
    err << "proxima distance: " << e.what() << "\n";
    return kExitFailure;
  }
  std::optional<LoadedBody> a;
  std::optional<LoadedBody> b;
  try {
    a.emplace(load_body_as(command.file_a, command.as_a, command.max_file_bytes));
    b.emplace(load_body_as(command.file_b, command.as_b, command.max_file_bytes));
  } catch (const InvalidInput& e) {
    err << "proxima distance: " << e.what() << "\n";
    return kExitFailure;
  }
  if (a->as != "hull" || b->as != "hull")
    return print_body_distance(command, *a, *b, pose_a, pose_b, out, err);

  const ConvexPolytope& hull_a = *a->hull;
  const ConvexPolytope& hull_b = *b->hull;
  const DistanceResult r = distance(hull_a, pose_a, hull_b, pose_b, command.options, nullptr);
  // Finite inputs whose products overflow (coordinates near 1e308) are the
  // only way to a non-finite answer; JSON cannot carry it and a table of
  // "inf" would look like an answer.
  if (!std::isfinite(r.distance) || !r.point_a.allFinite() || !r.point_b.allFinite()) {
    err << "proxima distance: the result is not finite: the coordinates are too large for double "
           "arithmetic\n";
    return kExitFailure;
  }

  if (command.json) {
    OrderedJson j;
    j["a"] = hull_json(command.file_a, *a);
    j["b"] = hull_json(command.file_b, *b);
    j["algorithm"] = to_string(command.options.algorithm);
    j["status"] = to_string(r.status);
    j["distance"] = r.distance;
    j["lower_bound"] = r.lower_bound;
    j["iterations"] = r.iterations;
    j["point_a"] = point_json(r.point_a);
    j["point_b"] = point_json(r.point_b);
    j["normal"] = point_json(r.normal);
    j["feature_a"] = feature_json(r.feature_a, hull_a);
    j["feature_b"] = feature_json(r.feature_b, hull_b);
    out << json_line(j);
  } else {
    row(out, "A", hull_text(command.file_a, *a));
    row(out, "B", hull_text(command.file_b, *b));
    row(out, "algorithm", to_string(command.options.algorithm));
    row(out, "status", to_string(r.status));
    row(out, "distance", number(r.distance));
    row(out, "lower bound", number(r.lower_bound));
    row(out, "iterations", std::to_string(r.iterations));
    row(out, "point on A", point_text(r.point_a));
    row(out, "point on B", point_text(r.point_b));
    row(out, "normal", point_text(r.normal) + "  (from A towards B)");
    row(out, "feature A", feature_text(r.feature_a, hull_a));
    row(out, "feature B", feature_text(r.feature_b, hull_b));
  }
  out.flush();
  if (!out) {
    err << "proxima distance: writing the answer failed\n";
    return kExitFailure;
  }
  return kExitOk;
}

int run_hull(const HullCommand& command, std::ostream& out, std::ostream& err) {
  std::optional<LoadedFile> body;
  std::optional<ExportSummary> exported;
  try {
    body.emplace(load_file(command.file, command.max_file_bytes));
    if (!command.out_file.empty()) {
      exported = write_hull(body->polytope, command.out_file, export_format(command.out_file),
                            command.file);
    }
  } catch (const InvalidInput& e) {
    err << "proxima hull: " << e.what() << "\n";
    return kExitFailure;
  }
  const ConvexPolytope& p = body->polytope;

  if (command.json) {
    OrderedJson j;
    j["file"] = command.file;
    j["format"] = to_string(body->format);
    j["input_points"] = body->input_points;
    j["vertices"] = p.vertex_count();
    j["edges"] = p.edge_count();
    j["faces"] = p.face_count();
    j["dimension"] = p.dimension();
    j["scale"] = p.scale();
    j["bounding_radius"] = p.bounding_radius();
    j["centroid"] = point_json(p.centroid());
    j["points_inside"] = p.interior_point_count();
    j["convex"] = body->convex;
    j["memory_bytes"] = p.memory_bytes();
    if (exported) {
      OrderedJson e;
      e["file"] = command.out_file;
      e["format"] = export_format(command.out_file);
      e["vertices"] = exported->vertices;
      e["faces"] = exported->faces;
      e["note"] = exported->note.empty() ? OrderedJson(nullptr) : OrderedJson(exported->note);
      j["export"] = e;
    }
    out << json_line(j);
  } else {
    row(out, "file", command.file + " (" + to_string(body->format) + ")");
    row(out, "input points", std::to_string(body->input_points));
    row(out, "vertices", std::to_string(p.vertex_count()));
    row(out, "edges", std::to_string(p.edge_count()));
    row(out, "faces", std::to_string(p.face_count()));
    row(out, "dimension", std::to_string(p.dimension()) + " (" + hull_shape(p.dimension()) + ")");
    row(out, "scale", number(p.scale()) + "  (largest absolute vertex coordinate)");
    row(out, "radius", number(p.bounding_radius()) + "  (bounding radius about the centroid)");
    row(out, "centroid", point_text(p.centroid()));
    const int inside = p.interior_point_count();
    row(out, "points inside",
        std::to_string(inside) + (inside > 0 ? "  (inside the hull or repeated)" : ""));
    row(out, "convex input",
        body->convex ? "yes (the input surface is its hull's boundary)"
                     : "no (the hull of all points is used)");
    row(out, "memory", std::to_string(p.memory_bytes()) + " bytes");
    if (exported) {
      std::string line = command.out_file + ": " + std::to_string(exported->vertices) +
                         " vertices, " + std::to_string(exported->faces) + " faces";
      if (!exported->note.empty()) line += " (" + exported->note + ")";
      row(out, "written", line);
    }
  }
  out.flush();
  if (!out) {
    err << "proxima hull: writing the statistics failed\n";
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace proxima::cli
