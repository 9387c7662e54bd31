// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// shape layer: ConvexPolytope, built once from a point list.
//
// The build runs in four steps:
//   1. validate (finite coordinates) and drop exact duplicates;
//   2. find the affine dimension with exact orientation predicates, so that
//      points that are coplanar (or collinear, or equal) as doubles give a
//      polygon (a segment, a point) at any scale, without joggling;
//   3. build the boundary: the two extreme points of a segment, a strict 2D
//      hull for a polygon, an exact randomized incremental hull (triangles)
//      for a solid;
//   4. clean a solid's triangles with exact predicates (merge exactly
//      coplanar neighbours, drop vertices that lie inside an edge), which
//      also proves the result exactly convex, and derive the vertex
//      adjacency, in rotational order, from the face cycles.
// A solid is always exact, for every input: planar faces, every edge
// strictly convex, only extreme points as vertices, every input point inside.
#include "proxima/shape/polytope.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/power_of_two.h"
#include "hull/affine_frame.h"
#include "hull/face_cleaning.h"
#include "hull/half_edges.h"
#include "hull/incremental_hull.h"
#include "hull/polygon_hull.h"
#include "hull/sorted_distinct.h"
#include "proxima/shape/support.h"
#include "proxima/detail/geometry/exact_predicates.h"

namespace proxima {
namespace {

using detail::Adjacency;
using detail::build_adjacency;
using detail::clean_faces;
using detail::Cycles;
using detail::exact_incremental_hull;
using detail::exact_triangle_normal;
using detail::find_frame;
using detail::Frame;
using detail::Index;
using detail::magnitude_exponent;
using detail::max_abs_coordinate;
using detail::polygon_hull;
using detail::projection_axis;
using detail::segment_ends;
using detail::times_pow2;

// A built boundary before renumbering: hull vertices as unique-point ids and
// face cycles over them.
struct Boundary {
  int dimension = 0;
  std::vector<Index> vertices;  // unique-point ids, in hull order
  Cycles faces;                 // over unique-point ids
};

Boundary polygon_boundary(std::vector<Index> ccw) {
  Boundary b;
  b.dimension = 2;
  b.faces.add(ccw);
  std::vector<Index> back(ccw.rbegin(), ccw.rend());
  std::rotate(back.begin(), back.end() - 1, back.end());  // start at the same vertex
  b.faces.add(back);
  b.vertices = std::move(ccw);
  return b;
}

// The exact hull's triangles, cleaned into faces. The construction is exact,
// so a result the cleaning cannot prove convex is a defect of this file,
// never an inexact answer handed on.
Boundary solid_boundary(std::span<const Vec3> pts, std::span<const Vec3> scaled,
                        const Frame& frame) {
  const auto point_count = static_cast<Index>(pts.size());
  Cycles triangles;
  bool proven_convex = false;
  Boundary b;
  b.dimension = 3;
  if (exact_incremental_hull(pts, scaled, frame, triangles)) {
    b.faces = clean_faces(triangles, point_count, pts, scaled, proven_convex);
  }
  if (!proven_convex) {
    throw InternalError("ConvexPolytope: internal error: the exact hull of " +
                           std::to_string(pts.size()) +
                           " distinct points is not a proven convex surface");
  }
  std::vector<bool> used(pts.size(), false);
  for (const Index v : b.faces.vertices) used[static_cast<std::size_t>(v)] = true;
  for (Index v = 0; v < point_count; ++v) {
    if (used[static_cast<std::size_t>(v)]) b.vertices.push_back(v);
  }
  return b;
}

const char* axis_name(int k) { return k == 0 ? "x" : k == 1 ? "y" : "z"; }

void validate(std::span<const Vec3> points) {
  if (points.empty()) throw InvalidInput("ConvexPolytope: no points given (need at least one)");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<Index>::max())) {
    throw InvalidInput("ConvexPolytope: too many points (" + std::to_string(points.size()) + ")");
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double c = points[i][k];
      if (std::isnan(c)) {
        throw InvalidInput("ConvexPolytope: input point " + std::to_string(i) + " has a NaN " +
                           axis_name(k) + " coordinate");
      }
      if (std::isinf(c)) {
        throw InvalidInput("ConvexPolytope: input point " + std::to_string(i) +
                           " has an infinite " + axis_name(k) + " coordinate");
      }
    }
  }
}

// Input indices of the distinct points, the first occurrence of each.
std::vector<Index> distinct_points(std::span<const Vec3> points) {
  std::vector<Index> order = detail::sorted_distinct(points.size(), [&](Index i) {
    const Vec3& p = points[static_cast<std::size_t>(i)];
    return std::array<double, 3>{p.x(), p.y(), p.z()};
  });
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace

ConvexPolytope::ConvexPolytope(std::span<const Vec3> points) {
  validate(points);
  const std::vector<Index> distinct = distinct_points(points);
  std::vector<Vec3> pts;
  pts.reserve(distinct.size());
  for (const Index i : distinct) pts.push_back(points[static_cast<std::size_t>(i)]);
  const int input_exponent = magnitude_exponent(max_abs_coordinate(pts));
  std::vector<Vec3> scaled;
  scaled.reserve(pts.size());
  for (const Vec3& p : pts) scaled.push_back(times_pow2(p, -input_exponent));

  const Frame frame = find_frame(pts, scaled);
  Boundary boundary;
  boundary.dimension = frame.dimension;
  switch (frame.dimension) {
    case 0:
      boundary.vertices = {0};
      break;
    case 1:
      boundary.vertices = segment_ends(pts, frame);
      break;
    case 2:
      boundary = polygon_boundary(polygon_hull(pts, projection_axis(pts, scaled, frame)));
      break;
    default:
      boundary = solid_boundary(pts, scaled, frame);
      break;
  }

  // Renumber: unique-point ids -> hull vertex ids.
  dimension_ = static_cast<std::int8_t>(boundary.dimension);
  const auto vertex_count = static_cast<Index>(boundary.vertices.size());
  std::vector<Index> local(pts.size(), -1);
  std::vector<Vec3> vertices;
  std::vector<std::int32_t> input_index;
  vertices.reserve(boundary.vertices.size());
  input_index.reserve(boundary.vertices.size());
  for (Index v = 0; v < vertex_count; ++v) {
    const Index u = boundary.vertices[static_cast<std::size_t>(v)];
    local[static_cast<std::size_t>(u)] = v;
    vertices.push_back(pts[static_cast<std::size_t>(u)]);
    input_index.push_back(distinct[static_cast<std::size_t>(u)]);
  }
  Cycles faces;
  faces.offsets = std::move(boundary.faces.offsets);
  faces.vertices.reserve(boundary.faces.vertices.size());
  for (const Index u : boundary.faces.vertices)
    faces.vertices.push_back(local[static_cast<std::size_t>(u)]);

  Adjacency adjacency;
  std::vector<std::int32_t> face_offsets{0};
  std::vector<std::int32_t> face_vertices;
  if (dimension_ == 1) {
    adjacency.offsets = {0, 1, 2};
    adjacency.neighbors = {1, 0};
    adjacency.faces = {-1, -1};
  } else if (dimension_ == 0) {
    adjacency.offsets = {0, 0};
  } else {
    if (!build_adjacency(faces, vertex_count, adjacency)) {
      throw InternalError("ConvexPolytope: internal error: the hull of " +
                          std::to_string(points.size()) +
                          " points is not a closed surface after cleaning");
    }
    face_offsets = std::move(faces.offsets);
    face_vertices = std::move(faces.vertices);
  }

  // Into the one allocation (polytope.h), without what follows from the
  // counts: the offsets of triangle-only faces, an identity input index.
  vertex_count_ = vertex_count;
  if (3 * static_cast<std::uint64_t>(vertex_count) > std::numeric_limits<std::uint32_t>::max()) {
    throw InvalidInput("ConvexPolytope: the hull of " + std::to_string(points.size()) +
                       " points has " + std::to_string(vertex_count) + " vertices, more than " +
                       std::to_string(std::numeric_limits<std::uint32_t>::max() / 3) +
                       " (the most one polytope can hold)");
  }
  ints_at_ = 3 * static_cast<std::uint32_t>(vertex_count);
  adjacency_size_ = static_cast<std::int32_t>(adjacency.neighbors.size());
  face_count_ = static_cast<std::int32_t>(face_offsets.size()) - 1;
  triangles_only_ = true;
  for (std::size_t f = 0; f + 1 < face_offsets.size(); ++f)
    triangles_only_ = triangles_only_ && face_offsets[f + 1] - face_offsets[f] == 3;
  identity_input_ = true;
  for (Index v = 0; v < vertex_count; ++v)
    identity_input_ = identity_input_ && input_index[static_cast<std::size_t>(v)] == v;
  table_side_ = static_cast<std::int16_t>(table_side_for(vertex_count));
  allocate(doubles_for(vertex_count_, adjacency.offsets.size() + 2 * adjacency.neighbors.size() +
                                          (triangles_only_ ? 0 : face_offsets.size()) +
                                          face_vertices.size() +
                                          (identity_input_ ? 0 : input_index.size()) +
                                          6 * static_cast<std::size_t>(table_side_) * table_side_));
  std::uninitialized_copy(vertices.begin(), vertices.end(), reinterpret_cast<Vec3*>(data_.get()));
  auto* out = const_cast<std::int32_t*>(ints());
  const auto put = [&out](const std::vector<std::int32_t>& values) {
    out = std::uninitialized_copy(values.begin(), values.end(), out);
  };
  put(adjacency.offsets);
  put(adjacency.neighbors);
  put(adjacency.faces);
  if (!triangles_only_) put(face_offsets);
  put(face_vertices);
  if (!identity_input_) put(input_index);
  build_table();

  measure();
  interior_point_count_ = static_cast<int>(points.size()) - vertex_count;
}

void ConvexPolytope::measure() {
  const std::span<const Vec3> vertices = this->vertices();
  // Centroid and radius on power-of-two scaled copies: exact scaling, and no
  // sum or square can overflow near the largest doubles.
  const int exponent = magnitude_exponent(max_abs_coordinate(vertices));
  Vec3 sum = Vec3::Zero();
  for (const Vec3& v : vertices) sum += times_pow2(v, -exponent);
  const Vec3 mean = sum / static_cast<double>(vertices.size());
  double radius = 0.0;
  for (const Vec3& v : vertices)
    radius = std::max(radius, (times_pow2(v, -exponent) - mean).norm());
  // Scale back per value: 2^exponent itself overflows for coordinates
  // beyond 2^1023 (found by the reader fuzzer: a vertex at -1e308).
  centroid_ = times_pow2(mean, exponent);
  bounding_radius_ = std::ldexp(radius, exponent);
  scale_ = max_abs_coordinate(vertices);
  if (vertex_count_ <= kTableMinVertices) return;  // no box (polytope.h)
  Vec3 lo = vertices.front(), hi = vertices.front();
  for (const Vec3& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  box_at_ = static_cast<std::uint32_t>(ints_at_ + (int_count() + 1) / 2);
  const Vec3 center = 0.5 * lo + 0.5 * hi;
  const Vec3 half = 0.5 * hi - 0.5 * lo;
  double* box = data_.get() + box_at_;
  for (int k = 0; k < 3; ++k) {
    box[k] = center[k];
    box[3 + k] = half[k];
  }
}

std::size_t ConvexPolytope::int_count() const {
  return table_at() + 6 * static_cast<std::size_t>(table_side_) * static_cast<std::size_t>(table_side_);
}

int ConvexPolytope::table_side_for(std::int32_t vertex_count) {
  if (vertex_count <= kTableMinVertices) return 0;
  // 6 side^2 cells, about vertex_count / kTableVerticesPerCell of them.
  const double cells = static_cast<double>(vertex_count) / kTableVerticesPerCell;
  return std::max(1, static_cast<int>(std::ceil(std::sqrt(cells / 6.0))));
}

// Each cell's support along its centre direction, by hill climbing from
// the previous cell's (rows run back and forth, so that consecutive cells
// are neighbours and each climb is short). Exact: a climb reaches a
// maximizer from any start (support.h).
void ConvexPolytope::build_table() {
  if (table_side_ == 0) return;
  const int side = table_side_;
  auto* table = const_cast<std::int32_t*>(ints()) + table_at();
  int last = 0;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    for (int row = 0; row < side; ++row)
      for (int k = 0; k < side; ++k) {
        const int column = row % 2 == 0 ? k : side - 1 - k;
        Vec3 d;
        d[axis] = face % 2 == 0 ? 1.0 : -1.0;
        d[(axis + 1) % 3] = -1.0 + (2.0 * row + 1.0) / side;
        d[(axis + 2) % 3] = -1.0 + (2.0 * column + 1.0) / side;
        last = support_hill_climb(*this, d, last);
        table[(face * side + row) * side + column] = last;
      }
  }
}

std::size_t ConvexPolytope::doubles_for(std::int32_t vertex_count, std::size_t int_count) {
  return 3 * static_cast<std::size_t>(vertex_count) + (int_count + 1) / 2 +
         (vertex_count > kTableMinVertices ? 6 : 0);  // the box
}

void ConvexPolytope::allocate(std::size_t doubles) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double) && alignof(Vec3) <= alignof(double));
  static_assert(std::is_trivially_destructible_v<Vec3>);
  data_ = std::make_unique_for_overwrite<double[]>(doubles);
}

ConvexPolytope::ConvexPolytope(const ConvexPolytope& other)
    : vertex_count_(other.vertex_count_),
      adjacency_size_(other.adjacency_size_),
      face_count_(other.face_count_),
      interior_point_count_(other.interior_point_count_),
      ints_at_(other.ints_at_),
      dimension_(other.dimension_),
      triangles_only_(other.triangles_only_),
      identity_input_(other.identity_input_),
      table_side_(other.table_side_),
      box_at_(other.box_at_),
      centroid_(other.centroid_),
      bounding_radius_(other.bounding_radius_),
      scale_(other.scale_) {
  if (!other.data_) return;  // moved from
  allocate(doubles_for(vertex_count_, other.int_count()));
  const std::span<const Vec3> v = other.vertices();
  std::uninitialized_copy(v.begin(), v.end(), reinterpret_cast<Vec3*>(data_.get()));
  std::uninitialized_copy(other.ints(), other.ints() + other.int_count(),
                          const_cast<std::int32_t*>(ints()));
  if (box_at_ != 0)
    std::uninitialized_copy(other.data_.get() + box_at_, other.data_.get() + box_at_ + 6,
                            data_.get() + box_at_);
}

ConvexPolytope::ConvexPolytope(ConvexPolytope&& other) noexcept { take(other); }

ConvexPolytope& ConvexPolytope::operator=(ConvexPolytope&& other) noexcept {
  if (this != &other) take(other);
  return *this;
}

void ConvexPolytope::take(ConvexPolytope& other) noexcept {
  data_ = std::move(other.data_);
  vertex_count_ = std::exchange(other.vertex_count_, 0);
  adjacency_size_ = std::exchange(other.adjacency_size_, 0);
  face_count_ = std::exchange(other.face_count_, 0);
  interior_point_count_ = std::exchange(other.interior_point_count_, 0);
  ints_at_ = std::exchange(other.ints_at_, 0);
  dimension_ = std::exchange(other.dimension_, 0);
  triangles_only_ = std::exchange(other.triangles_only_, true);
  identity_input_ = std::exchange(other.identity_input_, true);
  table_side_ = std::exchange(other.table_side_, 0);
  centroid_ = other.centroid_;
  box_at_ = std::exchange(other.box_at_, 0);
  bounding_radius_ = other.bounding_radius_;
  scale_ = other.scale_;
}

ConvexPolytope& ConvexPolytope::operator=(const ConvexPolytope& other) {
  if (this != &other) *this = ConvexPolytope(other);
  return *this;
}

// Newell's normal: for a planar polygon, sum over edges (p_i x p_(i+1)) is
// twice the area times the unit normal, and for a slightly non-planar one it
// is the normal of the best-fitting plane in the sense of projected areas.
// Vertices are taken relative to the first one (less cancellation) and scaled
// by a power of two of the face's magnitude (no overflow, exact scaling).
// The offset is taken at the mean of the face's vertices.
namespace {
// Ratio of Newell's error bound (u sum |p_i||p_i+1|) to u |normal|, per
// vertex, above which face_plane takes its normal exactly. Below it the
// rounded normal's angle error stays below about 16 u per vertex of the face
// (a convex polygon's fan from one vertex gives a ratio near n / pi), so only
// slivers pay for the exact path.
constexpr double kSliverRatio = 16.0;
// Largest distance, in units of u times the face's largest coordinate
// magnitude, that a face's own vertex may have from the plane built from
// Newell's normal before face_plane takes the exact normal instead: well
// inside the accuracy standard's 64 u R, and above the few u that evaluating
// the distance itself costs.
constexpr double kPlaneResidual = 8.0;
}  // namespace

Plane ConvexPolytope::face_plane(int f) const {
  const auto cycle = face(f);
  const std::size_t n = cycle.size();
  double max_abs = 0.0;
  for (const Index v : cycle) max_abs = std::max(max_abs, vertex(v).cwiseAbs().maxCoeff());
  const int exponent = magnitude_exponent(max_abs);
  const auto local = [&](std::size_t i) { return times_pow2(vertex(cycle[i]), -exponent); };
  const Vec3 origin = local(0);
  // p_i = local(i) - origin, with p_0 = p_n = 0 exactly (x - x): each edge's
  // end is the next edge's start, so each p_i and its norm are computed once
  // (penetration depth computes every face's plane of a small hull per cold
  // query: bench/penetration_bench's Cold).
  Vec3 normal = Vec3::Zero();
  Vec3 sum = Vec3::Zero();
  double magnitude_sum = 0.0;
  Vec3 p = Vec3::Zero();
  double p_norm = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool last = i + 1 == n;
    const Vec3 q = last ? Vec3::Zero() : Vec3(local(i + 1) - origin);
    const double q_norm = last ? 0.0 : q.norm();
    normal += p.cross(q);
    sum += p;
    magnitude_sum += p_norm * q_norm;
    p = q;
    p_norm = q_norm;
  }
  const Vec3 mean = origin + sum / static_cast<double>(n);
  // Conditioning: the rounded Newell sum is off by about u sum |p_i||p_i+1|
  // (each cross product's error). When that bound exceeds kSliverRatio per
  // vertex times the normal (a sliver: nearly collinear vertices, which the
  // exact hull of rounded data keeps as faces), or when a vertex of the face
  // is farther than kPlaneResidual u from the resulting plane (coordinates
  // here are below 1), the normal is taken exactly instead.
  const double newell_length = normal.norm();
  bool exact = !(magnitude_sum <= kSliverRatio * static_cast<double>(n) * newell_length);
  Vec3 unit = Vec3::UnitZ();
  if (!exact) {
    if (!(newell_length > 0.0))
      return {Vec3::UnitZ(), vertex(cycle[0]).z()};  // degenerate face: never built
    unit = normal / newell_length;
    for (std::size_t i = 0; i < n && !exact; ++i) {
      exact = !(std::abs(unit.dot(local(i) - mean)) <= kPlaneResidual * kUnitRoundoff);
    }
  }
  if (exact) {
    // From a spread triangle of the face (b farthest from the first vertex
    // a, c farthest from the line a b, in double), taken in cycle order so
    // that (a, b, c) turns like the face. Faces are exactly planar and
    // strictly convex (the cleaning proves it), so any three of their
    // vertices are exactly non-collinear and span the face's plane: the
    // exact cross product, rounded, is the face's normal with its
    // orientation, to a relative error of a few u, however thin the face.
    std::size_t ib = 1;
    double best = -1.0;
    for (std::size_t i = 1; i < n; ++i) {
      const double d = (local(i) - origin).squaredNorm();
      if (d > best) best = d, ib = i;
    }
    const Vec3 line = local(ib) - origin;
    std::size_t ic = ib == 1 ? 2 : 1;
    best = -1.0;
    for (std::size_t i = 1; i < n; ++i) {
      if (i == ib) continue;
      const double d = line.cross(local(i) - origin).squaredNorm();
      if (d > best) best = d, ic = i;
    }
    normal = exact_triangle_normal(vertex(cycle[0]), vertex(cycle[std::min(ib, ic)]),
                                   vertex(cycle[std::max(ib, ic)]));
    const double length = normal.norm();
    if (!(length > 0.0))
      return {Vec3::UnitZ(), vertex(cycle[0]).z()};  // degenerate face: never built
    unit = normal / length;
  }
  // The offset scaled back by a power of two: a product, exact or rounded
  // once like ldexp, while the factor is a normal double.
  const double offset = unit.dot(mean);
  return {unit, exponent >= -1022 && exponent <= 1023 ? offset * detail::pow2(exponent)
                                                      : std::ldexp(offset, exponent)};
}

std::vector<std::int32_t> ConvexPolytope::face_offsets() const {
  std::vector<std::int32_t> out;
  out.reserve(static_cast<std::size_t>(face_count_) + 1);
  for (int f = 0; f <= face_count_; ++f) out.push_back(static_cast<std::int32_t>(face_begin(f)));
  return out;
}

std::vector<std::array<std::int32_t, 3>> ConvexPolytope::triangles() const {
  std::vector<std::array<std::int32_t, 3>> out;
  out.reserve(face_vertices().size());
  for (int f = 0; f < face_count(); ++f) {
    const auto c = face(f);
    for (std::size_t i = 1; i + 1 < c.size(); ++i) out.push_back({c[0], c[i], c[i + 1]});
  }
  return out;
}

std::vector<std::int32_t> ConvexPolytope::triangle_face() const {
  std::vector<std::int32_t> out;
  out.reserve(face_vertices().size());
  for (int f = 0; f < face_count(); ++f) {
    const auto n = face(f).size();
    out.insert(out.end(), n >= 2 ? n - 2 : 0, f);
  }
  return out;
}

std::vector<std::array<std::int32_t, 2>> ConvexPolytope::edges() const {
  std::vector<std::array<std::int32_t, 2>> out;
  out.reserve(static_cast<std::size_t>(adjacency_size_) / 2);
  for (int v = 0; v < vertex_count(); ++v) {
    for (const std::int32_t w : neighbors(v)) {
      if (v < w) out.push_back({v, w});
    }
  }
  return out;
}

std::size_t ConvexPolytope::memory_bytes() const {
  return sizeof(*this) + (data_ ? doubles_for(vertex_count_, int_count()) * sizeof(double) : 0);
}

}  // namespace proxima
