// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 3: ConvexPolytope, built once from a point list.
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
#include "proxima/polytope.h"

#include <algorithm>
#include <bit>
#include <boost/multiprecision/cpp_int.hpp>
#include <cfenv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace proxima {
namespace {

using Index = std::int32_t;

// ---------------------------------------------------------------------------
// Exact orientation predicates
// ---------------------------------------------------------------------------
//
// orient2d(a, b, c) = (a - c).x * (b - c).y - (a - c).y * (b - c).x, positive
// when a, b, c turn counter-clockwise. side3d(a, b, c, d) = ((b - a) x (c - a))
// . (d - a), positive when d lies on the side the right-hand normal of the
// triangle a, b, c points to. Both are evaluated first in double with
// Shewchuk's forward error bound ("Adaptive precision floating-point
// arithmetic and fast robust geometric predicates", 1997, the A-level bounds
// ccwerrboundA and o3derrboundA): if |det| exceeds the bound times the
// permanent (the same expression with every term replaced by its absolute
// value), the sign of the rounded determinant is the exact sign. Otherwise the
// determinant is recomputed exactly in integers: every double is m * 2^e with
// a 53-bit integer m, so shifting all inputs of one predicate to their
// smallest exponent turns the determinant into an integer polynomial. When
// those integers are small (integer or dyadic data: the usual source of exact
// degeneracies) 128-bit arithmetic holds the determinant, else fixed 1024-bit
// integers, else Boost.Multiprecision's cpp_int.
//
// Shewchuk's bound assumes no overflow and no underflow. Inputs larger than
// kFilterMaxMagnitude skip the filter (a cubic term could overflow), and an
// absolute slack kUnderflowSlack covers products that underflowed (each loses
// at most 2^-1075, later multiplied by factors below 2^302).

constexpr double kEpsilon = 0x1p-53;
// Shewchuk's ccwerrboundA: relative error bound of the rounded orient2d.
constexpr double kOrient2dErrorBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
// Shewchuk's o3derrboundA: relative error bound of the rounded orient3d.
constexpr double kOrient3dErrorBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
// Largest coordinate magnitude for which the double filter cannot overflow:
// differences stay below 2^301 and a product of three below 2^903.
constexpr double kFilterMaxMagnitude = 0x1p300;
// Absolute error that underflowed products can add to a filtered determinant
// (far above the worst case 2^-1075 * 2^302 * 6). Determinants below it go to
// the exact path: inputs smaller than about 2^-233 (1e-70) always do, which
// is slower but still right.
constexpr double kUnderflowSlack = 0x1p-700;

using BigInt = boost::multiprecision::cpp_int;
// Fixed 1024-bit integers, no allocation: enough for inputs below 2^300.
using MediumInt = boost::multiprecision::number<boost::multiprecision::cpp_int_backend<
    1024, 1024, boost::multiprecision::signed_magnitude, boost::multiprecision::unchecked, void>>;
__extension__ using Int128 = __int128;

// Doubles as integers q_i = x_i / 2^s sharing the smallest exponent s, exactly:
// each x = m * 2^e with a 53-bit integer m (frexp, then scaling by 2^53).
template <std::size_t N>
struct CommonIntegers {
  std::array<std::int64_t, N> mantissa{};
  std::array<int, N> shift{};
  int bits = 0;  // bit length of the largest |q_i|

  explicit CommonIntegers(const std::array<double, N>& x) {
    std::array<int, N> exponent{};
    int smallest = INT_MAX;
    for (std::size_t i = 0; i < N; ++i) {
      if (x[i] == 0.0) continue;
      int e = 0;
      const double f = std::frexp(x[i], &e);                       // x = f * 2^e, 0.5 <= |f| < 1
      mantissa[i] = static_cast<std::int64_t>(std::ldexp(f, 53));  // exact: f has 53 bits
      exponent[i] = e - 53;
      smallest = std::min(smallest, exponent[i]);
    }
    for (std::size_t i = 0; i < N; ++i) {
      if (mantissa[i] == 0) continue;
      shift[i] = exponent[i] - smallest;
      const auto magnitude =
          static_cast<std::uint64_t>(mantissa[i] < 0 ? -mantissa[i] : mantissa[i]);
      bits = std::max(bits, static_cast<int>(std::bit_width(magnitude)) + shift[i]);
    }
  }
  // Only when bits leaves room: the caller checks.
  std::array<Int128, N> small() const {
    std::array<Int128, N> out{};
    for (std::size_t i = 0; i < N; ++i)
      out[i] = static_cast<Int128>(mantissa[i]) * (static_cast<Int128>(1) << shift[i]);
    return out;
  }
  template <class T>
  std::array<T, N> wide() const {
    std::array<T, N> out;
    for (std::size_t i = 0; i < N; ++i) {
      if (mantissa[i] == 0) continue;
      T magnitude = mantissa[i] < 0 ? -mantissa[i] : mantissa[i];
      magnitude <<= static_cast<unsigned>(shift[i]);
      out[i] = mantissa[i] < 0 ? T(-magnitude) : magnitude;
    }
    return out;
  }
};

template <class T>
int sign_of(const T& v) {
  return v > 0 ? 1 : v < 0 ? -1 : 0;
}

// 128-bit limits: orient2d has degree 2, so inputs below 2^60 keep every
// term below 2^123; orient3d has degree 3, so inputs below 2^40 keep every
// term below 2^126.
constexpr int kOrient2dSmallBits = 60;
constexpr int kOrient3dSmallBits = 40;
// 1024-bit limit: inputs below 2^300 keep every orient3d term below 2^906.
// Beyond (exponents spread over more than about 250 binades) cpp_int.
constexpr int kMediumBits = 300;

template <class T>
int orient2d_integer(const std::array<T, 6>& q) {
  return sign_of(T((q[0] - q[4]) * (q[3] - q[5]) - (q[1] - q[5]) * (q[2] - q[4])));
}

int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy) {
  const CommonIntegers<6> q({ax, ay, bx, by, cx, cy});
  if (q.bits <= kOrient2dSmallBits) return orient2d_integer(q.small());
  if (q.bits <= kMediumBits) return orient2d_integer(q.template wide<MediumInt>());
  return orient2d_integer(q.template wide<BigInt>());
}

// Sign of orient2d: +1 counter-clockwise, -1 clockwise, 0 collinear (exact).
int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double m = std::max(
      {std::abs(ax), std::abs(ay), std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)});
  if (m <= kFilterMaxMagnitude) {
    const double left = (ax - cx) * (by - cy);
    const double right = (ay - cy) * (bx - cx);
    const double det = left - right;
    const double bound = kOrient2dErrorBound * (std::abs(left) + std::abs(right)) + kUnderflowSlack;
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  return orient2d_exact(ax, ay, bx, by, cx, cy);
}

// Sign of Shewchuk's orient3d(a, b, c, d) on exact integers.
template <class T>
int orient3d_integer(const std::array<T, 12>& q) {
  const T adx = q[0] - q[9], ady = q[1] - q[10], adz = q[2] - q[11];
  const T bdx = q[3] - q[9], bdy = q[4] - q[10], bdz = q[5] - q[11];
  const T cdx = q[6] - q[9], cdy = q[7] - q[10], cdz = q[8] - q[11];
  return sign_of(T(adx * (bdy * cdz - bdz * cdy) + bdx * (cdy * adz - cdz * ady) +
                   cdx * (ady * bdz - adz * bdy)));
}

int orient3d_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const CommonIntegers<12> q(
      {a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z(), d.x(), d.y(), d.z()});
  if (q.bits <= kOrient3dSmallBits) return orient3d_integer(q.small());
  if (q.bits <= kMediumBits) return orient3d_integer(q.template wide<MediumInt>());
  return orient3d_integer(q.template wide<BigInt>());
}

// Sign of side3d (see above): +1 when d is on the normal side of triangle abc.
int side3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double m = std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(),
                             c.cwiseAbs().maxCoeff(), d.cwiseAbs().maxCoeff()});
  if (m <= kFilterMaxMagnitude) {
    // Shewchuk's orient3d(a, b, c, d), which is -side3d(a, b, c, d).
    const double adx = a.x() - d.x(), ady = a.y() - d.y(), adz = a.z() - d.z();
    const double bdx = b.x() - d.x(), bdy = b.y() - d.y(), bdz = b.z() - d.z();
    const double cdx = c.x() - d.x(), cdy = c.y() - d.y(), cdz = c.z() - d.z();
    const double bdycdz = bdy * cdz, bdzcdy = bdz * cdy;
    const double cdyadz = cdy * adz, cdzady = cdz * ady;
    const double adybdz = ady * bdz, adzbdy = adz * bdy;
    const double det = adx * (bdycdz - bdzcdy) + bdx * (cdyadz - cdzady) + cdx * (adybdz - adzbdy);
    const double permanent = (std::abs(bdycdz) + std::abs(bdzcdy)) * std::abs(adx) +
                             (std::abs(cdyadz) + std::abs(cdzady)) * std::abs(bdx) +
                             (std::abs(adybdz) + std::abs(adzbdy)) * std::abs(cdx);
    const double bound = kOrient3dErrorBound * permanent + kUnderflowSlack;
    if (det > bound) return -1;
    if (-det > bound) return 1;
  }
  return -orient3d_exact(a, b, c, d);
}

// a, b, c on one line (exactly): (b - a) x (c - a) == 0, i.e. all three
// coordinate projections are collinear.
bool collinear3d(const Vec3& a, const Vec3& b, const Vec3& c) {
  return orient2d(a.x(), a.y(), b.x(), b.y(), c.x(), c.y()) == 0 &&
         orient2d(a.y(), a.z(), b.y(), b.z(), c.y(), c.z()) == 0 &&
         orient2d(a.z(), a.x(), b.z(), b.x(), c.z(), c.x()) == 0;
}

// ---------------------------------------------------------------------------
// Scaling helpers: heuristics (farthest points, Newell sums) run on copies
// scaled by a power of two so that no square overflows whatever the input's
// magnitude. Exact decisions always use the original doubles.
// ---------------------------------------------------------------------------

// The exponent e with max|x| < 2^e (0 for an all-zero input).
int magnitude_exponent(double max_abs) {
  if (max_abs == 0.0) return 0;
  int e = 0;
  std::frexp(max_abs, &e);
  return e;
}

// p * 2^e per component, through ldexp: exact unless a component underflows,
// and never through the factor 2^e itself, which overflows when |e| > 1023
// (inputs near the largest doubles, or subnormal ones).
Vec3 times_pow2(const Vec3& p, int e) {
  return {std::ldexp(p.x(), e), std::ldexp(p.y(), e), std::ldexp(p.z(), e)};
}

double max_abs_coordinate(std::span<const Vec3> pts) {
  double m = 0.0;
  for (const Vec3& p : pts) m = std::max(m, p.cwiseAbs().maxCoeff());
  return m;
}

// ---------------------------------------------------------------------------
// Affine frame: dimension and well-spread base points
// ---------------------------------------------------------------------------

struct Frame {
  int dimension = 0;
  // Indices into the unique point list: p0, p1 (dimension >= 1), p2 (>= 2).
  std::array<Index, 3> base = {0, 0, 0};
};

// Exact affine dimension of `pts` (distinct points). p1 is the point farthest
// from p0 and p2 the point farthest from the line p0 p1 (both measured in
// double, only to keep the later projections well conditioned); the decisions
// "collinear" and "coplanar" are exact.
Frame find_frame(std::span<const Vec3> pts, std::span<const Vec3> scaled) {
  Frame frame;
  const auto n = static_cast<Index>(pts.size());
  if (n == 1) return frame;
  const Vec3& s0 = scaled[0];
  Index i1 = 1;
  double best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const double d = (scaled[static_cast<std::size_t>(i)] - s0).squaredNorm();
    if (d > best) best = d, i1 = i;
  }
  frame.dimension = 1;
  frame.base[1] = i1;
  const Vec3& p0 = pts[0];
  const Vec3& p1 = pts[static_cast<std::size_t>(i1)];
  const Vec3 line = scaled[static_cast<std::size_t>(i1)] - s0;
  Index i2 = -1;
  best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (collinear3d(p0, p1, pts[k])) continue;
    const double d = line.cross(scaled[k] - s0).squaredNorm();
    if (d > best) best = d, i2 = i;
  }
  if (i2 < 0) return frame;
  frame.dimension = 2;
  frame.base[2] = i2;
  const Vec3& p2 = pts[static_cast<std::size_t>(i2)];
  for (Index i = 1; i < n; ++i) {
    if (side3d(p0, p1, p2, pts[static_cast<std::size_t>(i)]) != 0) {
      frame.dimension = 3;
      break;
    }
  }
  return frame;
}

// The direction of (b - a) x (c - a), computed exactly and then rounded: the
// normal of a sliver triangle (the exact hull of rounded, nearly collinear
// points keeps such faces) is lost to cancellation in double, but its exact
// plane still has every input point below it. The three components share the
// factor 2^(2s) of CommonIntegers, so their ratios are exact; each is cut to
// its top 62 bits before conversion (relative error below 2^-60).
Vec3 exact_triangle_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const CommonIntegers<9> q({a.x(), a.y(), a.z(), b.x(), b.y(), b.z(), c.x(), c.y(), c.z()});
  const auto w = q.template wide<BigInt>();
  const BigInt ux = w[3] - w[0], uy = w[4] - w[1], uz = w[5] - w[2];
  const BigInt vx = w[6] - w[0], vy = w[7] - w[1], vz = w[8] - w[2];
  const std::array<BigInt, 3> n = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
  std::size_t bits = 0;
  for (const BigInt& k : n) {
    if (k != 0)
      bits = std::max(bits, static_cast<std::size_t>(boost::multiprecision::msb(abs(k))) + 1);
  }
  const std::size_t cut = bits > 62 ? bits - 62 : 0;
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    const BigInt& v = n[static_cast<std::size_t>(k)];
    const BigInt m = abs(v) >> static_cast<unsigned>(cut);
    const double d = static_cast<double>(m.convert_to<std::uint64_t>());
    out[k] = v < 0 ? -d : d;
  }
  return out;
}

// ---------------------------------------------------------------------------
// Lower-dimensional hulls
// ---------------------------------------------------------------------------

// The extreme points of exactly collinear, distinct points: along the line,
// any coordinate in which p0 and p1 differ is strictly monotone, so the
// smallest and largest values of that coordinate are the ends.
std::vector<Index> segment_ends(std::span<const Vec3> pts, const Frame& frame) {
  const Vec3 d = pts[static_cast<std::size_t>(frame.base[1])] - pts[0];
  int axis = 0;
  d.cwiseAbs().maxCoeff(&axis);  // nonzero: p1 != p0 exactly, and the largest |d_k| > 0
  Index lo = 0, hi = 0;
  for (Index i = 1; i < static_cast<Index>(pts.size()); ++i) {
    const double v = pts[static_cast<std::size_t>(i)][axis];
    if (v < pts[static_cast<std::size_t>(lo)][axis]) lo = i;
    if (v > pts[static_cast<std::size_t>(hi)][axis]) hi = i;
  }
  return {lo, hi};
}

// Which coordinate to drop when projecting the plane of p0, p1, p2: one where
// the normal has a nonzero component, checked exactly, preferring the largest
// (best conditioned). Projecting onto the other two axes, in cyclic order
// (k+1, k+2), is then a bijection of the plane that maps counter-clockwise
// (about the normal with positive k component) to counter-clockwise.
int projection_axis(std::span<const Vec3> pts, std::span<const Vec3> scaled, const Frame& frame) {
  const auto& b = frame.base;
  const Vec3 normal =
      (scaled[static_cast<std::size_t>(b[1])] - scaled[static_cast<std::size_t>(b[0])])
          .cross(scaled[static_cast<std::size_t>(b[2])] - scaled[static_cast<std::size_t>(b[0])]);
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](int l, int r) { return std::abs(normal[l]) > std::abs(normal[r]); });
  for (const int k : order) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Vec3& a = pts[static_cast<std::size_t>(b[0])];
    const Vec3& c = pts[static_cast<std::size_t>(b[1])];
    const Vec3& e = pts[static_cast<std::size_t>(b[2])];
    if (orient2d(a[i], a[j], c[i], c[j], e[i], e[j]) != 0) return k;
  }
  return order[0];  // unreachable for a non-collinear base triangle
}

// Strict convex hull (extreme points only), counter-clockwise in the
// projection that drops `axis`, by Andrew's monotone chain with the exact
// orient2d. Exact for coplanar points.
std::vector<Index> polygon_hull(std::span<const Vec3> pts, int axis) {
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  std::vector<Index> order(pts.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](Index v) {
    const Vec3& p = pts[static_cast<std::size_t>(v)];
    return std::pair<double, double>(p[i], p[j]);
  };
  std::sort(order.begin(), order.end(), [&](Index l, Index r) {
    const auto kl = key(l), kr = key(r);
    return kl != kr ? kl < kr : l < r;
  });
  // Points that project to one 2D point (only when not exactly coplanar):
  // keep the first.
  order.erase(
      std::unique(order.begin(), order.end(), [&](Index l, Index r) { return key(l) == key(r); }),
      order.end());
  const auto turns_left = [&](Index a, Index b, Index c) {
    const Vec3& pa = pts[static_cast<std::size_t>(a)];
    const Vec3& pb = pts[static_cast<std::size_t>(b)];
    const Vec3& pc = pts[static_cast<std::size_t>(c)];
    return orient2d(pa[i], pa[j], pb[i], pb[j], pc[i], pc[j]) > 0;
  };
  std::vector<Index> hull;
  hull.reserve(order.size() + 1);
  for (int pass = 0; pass < 2; ++pass) {  // lower chain, then upper chain
    const std::size_t floor = hull.size();
    for (const Index v : order) {
      while (hull.size() >= floor + 2 && !turns_left(hull[hull.size() - 2], hull.back(), v))
        hull.pop_back();
      hull.push_back(v);
    }
    hull.pop_back();  // the last point starts the other chain
    std::reverse(order.begin(), order.end());
  }
  return hull;
}

// ---------------------------------------------------------------------------
// Half-edges over face cycles
// ---------------------------------------------------------------------------

// Face cycles in CSR form over vertex ids 0 .. vertex_count-1.
struct Cycles {
  std::vector<Index> offsets{0};
  std::vector<Index> vertices;

  Index count() const { return static_cast<Index>(offsets.size()) - 1; }
  Index size(Index f) const {
    return offsets[static_cast<std::size_t>(f) + 1] - offsets[static_cast<std::size_t>(f)];
  }
  Index at(Index f, Index i) const {
    return vertices[static_cast<std::size_t>(offsets[static_cast<std::size_t>(f)] + i)];
  }
  template <class Range>
  void add(const Range& cycle) {
    vertices.insert(vertices.end(), cycle.begin(), cycle.end());
    offsets.push_back(static_cast<Index>(vertices.size()));
  }
};

// Half-edge h of face f at position i runs at(f, i) -> at(f, i + 1); face f
// is on its left. Half-edges are indexed by their slot in Cycles::vertices.
// They are also sorted by (source, target) in `by_source` for lookups.
class HalfEdges {
 public:
  HalfEdges(const Cycles& cycles, Index vertex_count) : cycles_(cycles) {
    const auto h_count = cycles.vertices.size();
    face_.resize(h_count);
    next_.resize(h_count);
    prev_.resize(h_count);
    for (Index f = 0; f < cycles.count(); ++f) {
      const Index b = cycles.offsets[static_cast<std::size_t>(f)], n = cycles.size(f);
      for (Index i = 0; i < n; ++i) {
        const auto h = static_cast<std::size_t>(b + i);
        face_[h] = f;
        next_[h] = b + (i + 1) % n;
        prev_[h] = b + (i + n - 1) % n;
      }
    }
    // Counting sort by source, then by target within a source.
    source_offsets_.assign(static_cast<std::size_t>(vertex_count) + 1, 0);
    for (const Index v : cycles.vertices) ++source_offsets_[static_cast<std::size_t>(v) + 1];
    std::partial_sum(source_offsets_.begin(), source_offsets_.end(), source_offsets_.begin());
    by_source_.resize(h_count);
    std::vector<Index> fill(source_offsets_.begin(), source_offsets_.end() - 1);
    for (std::size_t h = 0; h < h_count; ++h) {
      by_source_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cycles.vertices[h])]++)] =
          static_cast<Index>(h);
    }
    for (Index v = 0; v < vertex_count; ++v) {
      auto first = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v)];
      auto last = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v) + 1];
      std::sort(first, last, [&](Index l, Index r) { return target(l) < target(r); });
      for (auto it = first; it != last && it + 1 != last; ++it) {
        if (target(*it) == target(*(it + 1))) consistent_ = false;  // a directed edge twice
      }
    }
    twin_.resize(h_count);
    for (std::size_t h = 0; h < h_count; ++h) {
      twin_[h] = find(target(static_cast<Index>(h)), source(static_cast<Index>(h)));
      if (twin_[h] < 0) consistent_ = false;  // no reverse edge
    }
  }

  // False when some directed edge appears twice or has no reverse: the
  // cycles do not bound a closed oriented surface.
  bool consistent() const { return consistent_; }

  Index source(Index h) const { return cycles_.vertices[static_cast<std::size_t>(h)]; }
  Index target(Index h) const {
    return cycles_.vertices[static_cast<std::size_t>(next_[static_cast<std::size_t>(h)])];
  }
  Index face(Index h) const { return face_[static_cast<std::size_t>(h)]; }
  Index prev(Index h) const { return prev_[static_cast<std::size_t>(h)]; }
  Index twin(Index h) const { return twin_[static_cast<std::size_t>(h)]; }

  // The half-edge v -> w, or -1.
  Index find(Index v, Index w) const {
    const auto first = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v)];
    const auto last = by_source_.begin() + source_offsets_[static_cast<std::size_t>(v) + 1];
    const auto it =
        std::lower_bound(first, last, w, [&](Index h, Index t) { return target(h) < t; });
    return it != last && target(*it) == w ? *it : -1;
  }

  std::span<const Index> outgoing(Index v) const {
    const auto b = static_cast<std::size_t>(source_offsets_[static_cast<std::size_t>(v)]);
    const auto e = static_cast<std::size_t>(source_offsets_[static_cast<std::size_t>(v) + 1]);
    return std::span<const Index>(by_source_).subspan(b, e - b);
  }

 private:
  const Cycles& cycles_;
  std::vector<Index> face_, next_, prev_, twin_;
  std::vector<Index> source_offsets_, by_source_;
  bool consistent_ = true;
};

struct Adjacency {
  std::vector<Index> offsets, neighbors, faces;
};

// Vertex adjacency from face cycles, each vertex's neighbours in
// counter-clockwise order seen from outside. Rotation: if v -> w is in face F
// and u -> v precedes it in F, then v -> u is the next edge counter-clockwise
// about v (for a counter-clockwise polygon the interior angle at v sweeps
// from the outgoing to the incoming edge), and it lies in the face across
// u -> v. Returns false if the cycles are not a closed surface whose every
// vertex has one disk of faces around it.
bool build_adjacency(const Cycles& cycles, Index vertex_count, Adjacency& out) {
  const HalfEdges he(cycles, vertex_count);
  if (!he.consistent()) return false;
  out.offsets.assign(1, 0);
  out.neighbors.clear();
  out.faces.clear();
  out.neighbors.reserve(cycles.vertices.size());
  out.faces.reserve(cycles.vertices.size());
  for (Index v = 0; v < vertex_count; ++v) {
    const auto outgoing = he.outgoing(v);
    if (outgoing.empty()) return false;  // a vertex on no face
    const Index start = outgoing.front();
    Index h = start;
    for (std::size_t step = 0; step < outgoing.size(); ++step) {
      if (step > 0 && h == start) return false;  // more than one fan around v
      out.neighbors.push_back(he.target(h));
      out.faces.push_back(he.face(h));
      h = he.find(v, he.source(he.prev(h)));
      if (h < 0) return false;
    }
    if (h != start) return false;
    out.offsets.push_back(static_cast<Index>(out.neighbors.size()));
  }
  return true;
}

// ---------------------------------------------------------------------------
// Solids: exact incremental hull, then exact cleaning
// ---------------------------------------------------------------------------

// Union-find over faces.
class Groups {
 public:
  explicit Groups(Index n) : parent_(static_cast<std::size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  Index find(Index f) {
    while (parent_[static_cast<std::size_t>(f)] != f) {
      parent_[static_cast<std::size_t>(f)] =
          parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(f)])];
      f = parent_[static_cast<std::size_t>(f)];
    }
    return f;
  }
  void unite(Index a, Index b) {
    a = find(a), b = find(b);
    if (a != b) parent_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

 private:
  std::vector<Index> parent_;
};

// Three vertices of face f that are not collinear (exactly), or nothing.
// Spread out (farthest-point choice in double) to keep the filter effective.
bool face_triangle(const Cycles& faces, Index f, std::span<const Vec3> pts,
                   std::span<const Vec3> scaled, std::array<Index, 3>& tri) {
  const Index n = faces.size(f);
  const Index a = faces.at(f, 0);
  const Vec3& sa = scaled[static_cast<std::size_t>(a)];
  Index b = faces.at(f, 1);
  double best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const Index v = faces.at(f, i);
    const double d = (scaled[static_cast<std::size_t>(v)] - sa).squaredNorm();
    if (d > best) best = d, b = v;
  }
  const Vec3 line = scaled[static_cast<std::size_t>(b)] - sa;
  Index c = -1;
  best = -1.0;
  for (Index i = 1; i < n; ++i) {
    const Index v = faces.at(f, i);
    if (v == b || collinear3d(pts[static_cast<std::size_t>(a)], pts[static_cast<std::size_t>(b)],
                              pts[static_cast<std::size_t>(v)])) {
      continue;
    }
    const double d = line.cross(scaled[static_cast<std::size_t>(v)] - sa).squaredNorm();
    if (d > best) best = d, c = v;
  }
  if (c < 0) return false;
  tri = {a, b, c};
  return true;
}

// Exact cleaning of a closed triangulated (or polygonal) surface, in the
// coordinates of the given doubles:
//  - neighbouring facets that are exactly coplanar (and lie on either side of
//    their common edge, not folded) become one face: the triangles of a
//    square;
//  - a vertex on exactly two faces and exactly collinear with its two
//    neighbours along them lies inside an edge: it is not an extreme point and
//    is dropped from both cycles (a cube's edge midpoints).
// A vertex strictly inside a face disappears with the merge, because it is on
// no boundary cycle any more.
//
// `proven_convex` tells whether the result is exactly a convex polytope's
// boundary: a closed, consistently oriented surface whose faces are planar
// and whose every edge is exactly convex (x strictly below the plane of the
// face across the edge). A closed surface that is locally convex at every
// edge bounds a convex body, so no global test is needed.
Cycles clean_faces(const Cycles& raw, Index point_count, std::span<const Vec3> pts,
                   std::span<const Vec3> scaled, bool& proven_convex) {
  const Index face_count = raw.count();
  const HalfEdges he(raw, point_count);
  proven_convex = he.consistent();
  const auto at = [&](Index v) -> const Vec3& { return pts[static_cast<std::size_t>(v)]; };
  Groups groups(face_count);
  {
    // A face is planar when all its vertices lie on the plane of a spread
    // triangle of them (exact; zero is the expected answer, so this is where
    // the exact fallback runs, once per vertex of a non-triangular face).
    std::vector<std::array<Index, 3>> tri(static_cast<std::size_t>(face_count));
    std::vector<bool> planar(static_cast<std::size_t>(face_count), false);
    for (Index f = 0; f < face_count; ++f) {
      auto& t = tri[static_cast<std::size_t>(f)];
      if (!face_triangle(raw, f, pts, scaled, t)) continue;
      bool flat = true;
      for (Index i = 0; i < raw.size(f) && flat; ++i) {
        const Index v = raw.at(f, i);
        flat =
            v == t[0] || v == t[1] || v == t[2] || side3d(at(t[0]), at(t[1]), at(t[2]), at(v)) == 0;
      }
      planar[static_cast<std::size_t>(f)] = flat;
      proven_convex = proven_convex && flat;
    }
    // Planar neighbours f and g share the edge s -> t (in f; t -> s in g).
    // With y a vertex of f and x one of g off the line s t, side3d(s, t, y, x)
    // is the edge's convexity: negative convex, zero coplanar, positive
    // reflex (a defect of the surface). Coplanar faces merge when, in a projection
    // that keeps the plane's orientation, x and y lie on opposite sides of
    // the edge.
    for (Index h = 0; h < static_cast<Index>(raw.vertices.size()); ++h) {
      const Index twin = he.twin(h);
      if (twin < 0) continue;
      const Index f = he.face(h), g = he.face(twin);
      if (f >= g) continue;
      if (!planar[static_cast<std::size_t>(f)] || !planar[static_cast<std::size_t>(g)]) continue;
      const Index s = he.source(h), t = he.target(h);
      const auto off_line = [&](Index face) {
        for (const Index v : tri[static_cast<std::size_t>(face)]) {
          if (v != s && v != t && !collinear3d(at(s), at(t), at(v))) return v;
        }
        return Index{-1};
      };
      const Index y = off_line(f), x = off_line(g);
      if (x < 0 || y < 0) {
        proven_convex = false;
        continue;
      }
      const int side = side3d(at(s), at(t), at(y), at(x));
      if (side != 0) {
        proven_convex = proven_convex && side < 0;
        continue;
      }
      int y_side = 0, x_side = 0;
      for (int k = 0; k < 3 && y_side == 0; ++k) {
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        y_side = orient2d(at(s)[i], at(s)[j], at(t)[i], at(t)[j], at(y)[i], at(y)[j]);
        x_side = orient2d(at(s)[i], at(s)[j], at(t)[i], at(t)[j], at(x)[i], at(x)[j]);
      }
      if (x_side == -y_side) {
        groups.unite(f, g);
      } else {
        proven_convex = false;  // folded onto itself
      }
    }
  }

  // Boundary cycle of each group: its half-edges whose twin lies in another
  // group, chained head to tail. A group that does not chain into one simple
  // cycle keeps its facets unmerged.
  std::vector<std::vector<Index>> members(static_cast<std::size_t>(face_count));
  for (Index f = 0; f < face_count; ++f) {
    const Index root = groups.find(f);
    if (root != f) members[static_cast<std::size_t>(root)].push_back(f);
  }
  Cycles merged;
  const auto add_own = [&](Index f) {
    const auto first = raw.vertices.begin() + raw.offsets[static_cast<std::size_t>(f)];
    merged.add(std::span<const Index>(&*first, static_cast<std::size_t>(raw.size(f))));
  };
  std::vector<std::pair<Index, Index>> boundary;  // (source, target)
  std::vector<Index> chain;
  for (Index root = 0; root < face_count; ++root) {
    if (groups.find(root) != root) continue;
    auto& group = members[static_cast<std::size_t>(root)];
    if (group.empty()) {
      add_own(root);
      continue;
    }
    group.push_back(root);
    boundary.clear();
    for (const Index f : group) {
      for (Index i = 0; i < raw.size(f); ++i) {
        const Index h = raw.offsets[static_cast<std::size_t>(f)] + i;
        const Index twin = he.twin(h);
        if (twin < 0 || groups.find(he.face(twin)) != root)
          boundary.emplace_back(he.source(h), he.target(h));
      }
    }
    std::sort(boundary.begin(), boundary.end());
    bool simple = boundary.size() >= 3;
    for (std::size_t k = 1; k < boundary.size() && simple; ++k)
      simple = boundary[k].first != boundary[k - 1].first;
    chain.clear();
    if (simple) {
      const auto next_of = [&](Index v) {
        const auto it = std::lower_bound(boundary.begin(), boundary.end(),
                                         std::pair<Index, Index>(v, INT32_MIN));
        return it != boundary.end() && it->first == v ? it->second : -1;
      };
      Index v = boundary.front().first;
      do {
        chain.push_back(v);
        v = next_of(v);
      } while (v >= 0 && v != boundary.front().first && chain.size() <= boundary.size());
      simple = v == boundary.front().first && chain.size() == boundary.size();
    }
    if (simple) {
      merged.add(chain);
    } else {
      proven_convex = false;
      for (const Index f : group) add_own(f);
    }
  }

  // Drop vertices inside edges. The cycles become doubly linked lists over
  // nodes (one node per slot of merged.vertices); a vertex on exactly two
  // faces remembers its two nodes.
  const auto node_count = merged.vertices.size();
  std::vector<Index> next(node_count), prev(node_count), node_face(node_count);
  std::vector<Index> face_size(static_cast<std::size_t>(merged.count()));
  for (Index f = 0; f < merged.count(); ++f) {
    const Index b = merged.offsets[static_cast<std::size_t>(f)], n = merged.size(f);
    face_size[static_cast<std::size_t>(f)] = n;
    for (Index i = 0; i < n; ++i) {
      next[static_cast<std::size_t>(b + i)] = b + (i + 1) % n;
      prev[static_cast<std::size_t>(b + i)] = b + (i + n - 1) % n;
      node_face[static_cast<std::size_t>(b + i)] = f;
    }
  }
  std::vector<Index> occurrence_count(static_cast<std::size_t>(point_count), 0);
  std::vector<std::array<Index, 2>> occurrence(static_cast<std::size_t>(point_count), {-1, -1});
  for (std::size_t node = 0; node < node_count; ++node) {
    const auto v = static_cast<std::size_t>(merged.vertices[node]);
    if (occurrence_count[v] < 2)
      occurrence[v][static_cast<std::size_t>(occurrence_count[v])] = static_cast<Index>(node);
    ++occurrence_count[v];
  }
  std::vector<bool> alive(node_count, true);
  std::vector<Index> work;
  for (Index v = 0; v < point_count; ++v) {
    if (occurrence_count[static_cast<std::size_t>(v)] == 2) work.push_back(v);
  }
  const auto vertex_of = [&](Index node) {
    return merged.vertices[static_cast<std::size_t>(node)];
  };
  while (!work.empty()) {
    const Index v = work.back();
    work.pop_back();
    if (occurrence_count[static_cast<std::size_t>(v)] != 2) continue;
    const auto [n0, n1] = occurrence[static_cast<std::size_t>(v)];
    const Index u = vertex_of(prev[static_cast<std::size_t>(n0)]);
    const Index w = vertex_of(next[static_cast<std::size_t>(n0)]);
    // The other face must run w -> v -> u: v sits on one edge of both.
    if (vertex_of(prev[static_cast<std::size_t>(n1)]) != w ||
        vertex_of(next[static_cast<std::size_t>(n1)]) != u)
      continue;
    if (face_size[static_cast<std::size_t>(node_face[static_cast<std::size_t>(n0)])] <= 3 ||
        face_size[static_cast<std::size_t>(node_face[static_cast<std::size_t>(n1)])] <= 3) {
      continue;
    }
    if (!collinear3d(at(u), at(v), at(w))) continue;
    for (const Index node : {n0, n1}) {
      const Index before = prev[static_cast<std::size_t>(node)],
                  after = next[static_cast<std::size_t>(node)];
      next[static_cast<std::size_t>(before)] = after;
      prev[static_cast<std::size_t>(after)] = before;
      alive[static_cast<std::size_t>(node)] = false;
      --face_size[static_cast<std::size_t>(node_face[static_cast<std::size_t>(node)])];
    }
    occurrence_count[static_cast<std::size_t>(v)] = 0;
    work.push_back(u);  // their neighbours changed: check them again
    work.push_back(w);
  }

  Cycles out;
  out.vertices.reserve(node_count);
  for (Index f = 0; f < merged.count(); ++f) {
    Index start = merged.offsets[static_cast<std::size_t>(f)];
    while (!alive[static_cast<std::size_t>(start)]) ++start;  // some node survives: faces keep >= 3
    Index node = start;
    do {
      out.vertices.push_back(vertex_of(node));
      node = next[static_cast<std::size_t>(node)];
    } while (node != start);
    out.offsets.push_back(static_cast<Index>(out.vertices.size()));
  }
  return out;
}

// Exact randomized incremental hull with conflict lists: the boundary of
// every solid. Qhull (used here before) decides "inside" within its roundoff
// estimate, even without merging, so on rounded nearly flat data a true
// extreme point could be left out of its triangulation (found by
// polytope_test's NearlyFlatCloudsFarFromTheOriginAreExact), and its merged
// hull drops points within that estimate of a facet, true extreme points
// among them (measured: 0.03 of support on a body of size 2 at distance 420,
// 1e11 of support on a cloud of size 5e11 at 4.7e13). Checking its answer
// exactly cost more than building the hull exactly.
//
// The beneath-beyond construction (Clarkson and Shor; de Berg et al.,
// "Computational Geometry", ch. 11) with every decision an exact side3d:
// start from a tetrahedron of four exactly non-coplanar input points; every
// other point not yet known to be inside keeps one conflict face, a current
// face that sees it strictly (side3d > 0: a closed convex polytope contains
// exactly the points on or below all of its face planes). Points are added
// in a seeded random order. Adding x: the strictly visible faces form a
// connected cap (found from x's conflict face by walking to neighbours that
// see x) whose boundary, the horizon, is a simple cycle; the cap is replaced
// by the cone of triangles from the horizon edges to x. No cone triangle is
// degenerate: if x were on the line of a horizon edge it would lie in the
// plane of the visible face across that edge, which then would not see it
// strictly. The points in the conflict lists of the removed faces are tested
// against the cone's faces only: a point strictly above a removed face and
// below every cone plane is x + t (h - x) for some h of the old hull with
// t < 1 (the removed face's plane separates x from the old hull), so it is
// inside the new hull and is dropped for good. Points on the boundary
// without being beyond any face are never added; coplanar triangles are left
// for clean_faces to merge. The result is exactly the convex hull, as
// triangles, for every input: no budget, no fallback.
//
// Expected cost O(n log n) predicate calls (random order). Most calls are
// decided by the double filter of side3d; nearly coplanar rounded points
// (a rotated cylinder's caps) send many to the exact integer path.
bool incremental_hull_in_order(std::span<const Vec3> pts, std::span<const Vec3> scaled,
                               const Frame& frame, Cycles& out) {
  const auto n = static_cast<Index>(pts.size());
  const auto at = [&](Index v) -> const Vec3& { return pts[static_cast<std::size_t>(v)]; };
  const auto sc = [&](Index v) -> const Vec3& { return scaled[static_cast<std::size_t>(v)]; };
  const Index a = frame.base[0], b = frame.base[1], c = frame.base[2];
  // Fourth point: the farthest from the base plane (in double, for a
  // well-shaped start) among the points exactly off it.
  const Vec3 normal = (sc(b) - sc(a)).cross(sc(c) - sc(a));
  Index d = -1;
  double best = -1.0;
  for (Index i = 0; i < n; ++i) {
    const double h = std::abs(normal.dot(sc(i) - sc(a)));
    if (h > best && side3d(at(a), at(b), at(c), at(i)) != 0) best = h, d = i;
  }
  if (d < 0) return false;  // coplanar: not a solid (the frame says otherwise)

  // Triangles with their neighbours: across[3 t + k] is the triangle across
  // the edge tri[k] -> tri[k + 1]. Removed triangles' slots are reused.
  std::vector<std::array<Index, 3>> tris;
  std::vector<std::array<Index, 3>> across;
  std::vector<char> mark;            // 0 live, 1 visible from the current point, 2 free
  std::vector<Index> conflict_head;  // first point of each triangle's conflict list, or -1
  std::vector<Index> free_slots;
  std::vector<Index> next_conflict(pts.size(), -1);  // singly linked conflict lists
  const auto new_triangle = [&](Index u, Index v, Index w) {
    Index t;
    if (!free_slots.empty()) {
      t = free_slots.back();
      free_slots.pop_back();
      tris[static_cast<std::size_t>(t)] = {u, v, w};
      across[static_cast<std::size_t>(t)] = {-1, -1, -1};
      mark[static_cast<std::size_t>(t)] = 0;
      conflict_head[static_cast<std::size_t>(t)] = -1;
    } else {
      t = static_cast<Index>(tris.size());
      tris.push_back({u, v, w});
      across.push_back({-1, -1, -1});
      mark.push_back(0);
      conflict_head.push_back(-1);
    }
    return t;
  };
  const auto sees = [&](Index t, Index x) {
    const auto& tri = tris[static_cast<std::size_t>(t)];
    return side3d(at(tri[0]), at(tri[1]), at(tri[2]), at(x)) > 0;
  };
  const auto link = [&](Index t, int k, Index s, int j) {
    across[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)] = s;
    across[static_cast<std::size_t>(s)][static_cast<std::size_t>(j)] = t;
  };

  // Outward tetrahedron: with d below triangle (p, q, r), its faces are
  // (p, q, r), (p, d, q), (q, d, r), (r, d, p).
  Index p = a, q = b, r = c;
  if (side3d(at(p), at(q), at(r), at(d)) > 0) std::swap(q, r);
  const Index t0 = new_triangle(p, q, r), t1 = new_triangle(p, d, q), t2 = new_triangle(q, d, r),
              t3 = new_triangle(r, d, p);
  link(t0, 0, t1, 2);  // p -> q | q -> p
  link(t0, 1, t2, 2);  // q -> r | r -> q
  link(t0, 2, t3, 2);  // r -> p | p -> r
  link(t1, 0, t3, 1);  // p -> d | d -> p
  link(t1, 1, t2, 0);  // d -> q | q -> d
  link(t2, 1, t3, 0);  // d -> r | r -> d

  // Seeded random order (splitmix64: portable and reproducible), then every
  // point's first conflict face.
  std::vector<Index> order;
  order.reserve(pts.size());
  for (Index i = 0; i < n; ++i) {
    if (i != a && i != b && i != c && i != d) order.push_back(i);
  }
  std::uint64_t state = 0x9e3779b97f4a7c15ULL ^ static_cast<std::uint64_t>(n);
  const auto random_below = [&](std::size_t bound) {
    state += 0x9e3779b97f4a7c15ULL;
    std::uint64_t z = state;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return static_cast<std::size_t>(z % bound);
  };
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[random_below(i)]);
  // Biased randomized insertion order (Amenta, Choi and Rote, 2003): rounds
  // of doubling size, each a random sample, each sorted by index. The caller
  // numbers the points along a space-filling curve, so consecutive insertions
  // touch nearby triangles and points (cache), while the rounds keep the
  // expected work of a random order.
  for (std::size_t first = 0, size = 1; first < order.size(); first += size, size *= 2) {
    const std::size_t last = std::min(order.size(), first + size);
    std::sort(order.begin() + static_cast<std::ptrdiff_t>(first),
              order.begin() + static_cast<std::ptrdiff_t>(last));
  }
  std::vector<Index> conflict(pts.size(), -1);  // the conflict face of each point, -1 when inside
  const auto assign = [&](Index x, std::span<const Index> candidates) {
    for (const Index t : candidates) {
      if (sees(t, x)) {
        conflict[static_cast<std::size_t>(x)] = t;
        next_conflict[static_cast<std::size_t>(x)] = conflict_head[static_cast<std::size_t>(t)];
        conflict_head[static_cast<std::size_t>(t)] = x;
        return;
      }
    }
    conflict[static_cast<std::size_t>(x)] = -1;
  };
  {
    const std::array<Index, 4> first = {t0, t1, t2, t3};
    for (const Index x : order) assign(x, first);
  }

  std::vector<Index> visible;
  std::vector<Index> stack;
  struct HorizonEdge {
    Index u, v, outside;  // u -> v in a visible triangle; `outside` across it, not visible
    int outside_slot;     // which edge of `outside` runs v -> u
  };
  std::vector<HorizonEdge> horizon;
  std::vector<Index> cone;
  std::vector<Index> cone_from(pts.size(), -1);  // horizon vertex u -> the cone triangle (u, v, x)
  for (const Index x : order) {
    const Index start = conflict[static_cast<std::size_t>(x)];
    if (start < 0) continue;  // inside the current hull: inside the final one
    // The visible cap, by depth-first search from the conflict face.
    visible.clear();
    stack.assign(1, start);
    mark[static_cast<std::size_t>(start)] = 1;
    while (!stack.empty()) {
      const Index t = stack.back();
      stack.pop_back();
      visible.push_back(t);
      for (const Index s : across[static_cast<std::size_t>(t)]) {
        if (mark[static_cast<std::size_t>(s)] == 0 && sees(s, x)) {
          mark[static_cast<std::size_t>(s)] = 1;
          stack.push_back(s);
        }
      }
    }
    horizon.clear();
    for (const Index t : visible) {
      const auto& tri = tris[static_cast<std::size_t>(t)];
      for (int k = 0; k < 3; ++k) {
        const Index s = across[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)];
        if (mark[static_cast<std::size_t>(s)] == 1) continue;
        const Index u = tri[static_cast<std::size_t>(k)],
                    v = tri[static_cast<std::size_t>((k + 1) % 3)];
        int slot = 0;
        while (tris[static_cast<std::size_t>(s)][static_cast<std::size_t>(slot)] != v) ++slot;
        horizon.push_back({u, v, s, slot});
      }
    }
    // Free the cap (its conflict lists are redistributed below), then build
    // the cone: triangle (u, v, x) has its edge 0 on the horizon, edge 1
    // (v -> x) against the cone triangle starting at v, edge 2 (x -> u)
    // against the one ending at u.
    for (const Index t : visible) {
      mark[static_cast<std::size_t>(t)] = 2;
      free_slots.push_back(t);
    }
    // Take the lists before the slots are reused.
    stack.clear();
    for (const Index t : visible) {
      for (Index y = conflict_head[static_cast<std::size_t>(t)]; y >= 0;
           y = next_conflict[static_cast<std::size_t>(y)]) {
        if (y != x) stack.push_back(y);
      }
      conflict_head[static_cast<std::size_t>(t)] = -1;
    }
    cone.clear();
    for (const HorizonEdge& e : horizon) {
      const Index t = new_triangle(e.u, e.v, x);
      link(t, 0, e.outside, e.outside_slot);
      cone_from[static_cast<std::size_t>(e.u)] = t;
      cone.push_back(t);
    }
    for (const Index t : cone) {
      const Index v = tris[static_cast<std::size_t>(t)][1];
      const Index s = cone_from[static_cast<std::size_t>(v)];
      if (s < 0) return false;  // the horizon is not a cycle: cannot happen
      link(t, 1, s, 2);
    }
    for (const HorizonEdge& e : horizon) cone_from[static_cast<std::size_t>(e.u)] = -1;
    conflict[static_cast<std::size_t>(x)] = -1;
    for (const Index y : stack) assign(y, cone);
  }
  out = Cycles();
  for (Index t = 0; t < static_cast<Index>(tris.size()); ++t) {
    if (mark[static_cast<std::size_t>(t)] == 0) out.add(tris[static_cast<std::size_t>(t)]);
  }
  return true;
}

// Interleaves the low 21 bits of x, y and z (a Morton code).
std::uint64_t morton_code(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
  const auto spread = [](std::uint64_t v) {
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  return spread(x) | spread(y) << 1 | spread(z) << 2;
}

// The incremental hull on a copy of the points laid out in Morton order:
// the points of one conflict list are near each other in space, so they are
// near in memory too. On a million points the construction is bound by
// memory traffic, not arithmetic (measured on 10^6 points on a sphere: 31 s
// in the input's layout with a plain random order, 4.8 s with this layout
// and the rounds of incremental_hull_in_order). Only the memory layout
// changes; every decision is exact on the same doubles.
bool exact_incremental_hull(std::span<const Vec3> pts, std::span<const Vec3> scaled,
                            const Frame& frame, Cycles& out) {
  const auto n = static_cast<Index>(pts.size());
  Vec3 lo = scaled[0], hi = scaled[0];
  for (const Vec3& s : scaled) lo = lo.cwiseMin(s), hi = hi.cwiseMax(s);
  const Vec3 extent = (hi - lo).cwiseMax(Vec3::Constant(std::numeric_limits<double>::min()));
  std::vector<std::pair<std::uint64_t, Index>> keyed(pts.size());
  for (Index i = 0; i < n; ++i) {
    const Vec3 t = (scaled[static_cast<std::size_t>(i)] - lo).cwiseQuotient(extent) * 2097151.0;
    const auto cell = [&](int k) {
      return static_cast<std::uint32_t>(std::clamp(t[k], 0.0, 2097151.0));
    };
    keyed[static_cast<std::size_t>(i)] = {morton_code(cell(0), cell(1), cell(2)), i};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<Vec3> local_pts(pts.size()), local_scaled(pts.size());
  std::vector<Index> local_of(pts.size());
  for (Index j = 0; j < n; ++j) {
    const Index i = keyed[static_cast<std::size_t>(j)].second;
    local_pts[static_cast<std::size_t>(j)] = pts[static_cast<std::size_t>(i)];
    local_scaled[static_cast<std::size_t>(j)] = scaled[static_cast<std::size_t>(i)];
    local_of[static_cast<std::size_t>(i)] = j;
  }
  Frame local_frame = frame;
  for (Index& v : local_frame.base) v = local_of[static_cast<std::size_t>(v)];
  if (!incremental_hull_in_order(local_pts, local_scaled, local_frame, out)) return false;
  for (Index& v : out.vertices) v = keyed[static_cast<std::size_t>(v)].second;
  return true;
}

// ---------------------------------------------------------------------------
// The build
// ---------------------------------------------------------------------------

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
    throw std::logic_error("ConvexPolytope: internal error: the exact hull of " +
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
  std::vector<Index> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  const auto key = [&](Index i) {
    const Vec3& p = points[static_cast<std::size_t>(i)];
    return std::array<double, 3>{p.x(), p.y(), p.z()};
  };
  std::sort(order.begin(), order.end(), [&](Index l, Index r) {
    const auto kl = key(l), kr = key(r);
    return kl != kr ? kl < kr : l < r;
  });
  order.erase(
      std::unique(order.begin(), order.end(), [&](Index l, Index r) { return key(l) == key(r); }),
      order.end());
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
  dimension_ = boundary.dimension;
  const auto vertex_count = static_cast<Index>(boundary.vertices.size());
  std::vector<Index> local(pts.size(), -1);
  vertices_.reserve(boundary.vertices.size());
  input_index_.reserve(boundary.vertices.size());
  for (Index v = 0; v < vertex_count; ++v) {
    const Index u = boundary.vertices[static_cast<std::size_t>(v)];
    local[static_cast<std::size_t>(u)] = v;
    vertices_.push_back(pts[static_cast<std::size_t>(u)]);
    input_index_.push_back(distinct[static_cast<std::size_t>(u)]);
  }
  Cycles faces;
  faces.offsets = std::move(boundary.faces.offsets);
  faces.vertices.reserve(boundary.faces.vertices.size());
  for (const Index u : boundary.faces.vertices)
    faces.vertices.push_back(local[static_cast<std::size_t>(u)]);

  if (dimension_ == 1) {
    adjacency_offsets_ = {0, 1, 2};
    adjacency_ = {1, 0};
    adjacency_faces_ = {-1, -1};
  } else if (dimension_ == 0) {
    adjacency_offsets_ = {0, 0};
  } else {
    Adjacency adjacency;
    if (!build_adjacency(faces, vertex_count, adjacency)) {
      throw InvalidInput("ConvexPolytope: the hull of " + std::to_string(points.size()) +
                         " points is not a closed surface after cleaning (internal error)");
    }
    adjacency_offsets_ = std::move(adjacency.offsets);
    adjacency_ = std::move(adjacency.neighbors);
    adjacency_faces_ = std::move(adjacency.faces);
    face_offsets_ = std::move(faces.offsets);
    face_vertices_ = std::move(faces.vertices);
  }
  for (auto* v : {&input_index_, &adjacency_offsets_, &adjacency_, &adjacency_faces_,
                  &face_offsets_, &face_vertices_}) {
    v->shrink_to_fit();
  }
  vertices_.shrink_to_fit();

  // Centroid and radius on power-of-two scaled copies: exact scaling, and no
  // sum or square can overflow near the largest doubles.
  const int exponent = magnitude_exponent(max_abs_coordinate(vertices_));
  Vec3 sum = Vec3::Zero();
  for (const Vec3& v : vertices_) sum += times_pow2(v, -exponent);
  const Vec3 mean = sum / static_cast<double>(vertices_.size());
  double radius = 0.0;
  for (const Vec3& v : vertices_)
    radius = std::max(radius, (times_pow2(v, -exponent) - mean).norm());
  // Scale back per value: 2^exponent itself overflows for coordinates
  // beyond 2^1023 (found by the reader fuzzer: a vertex at -1e308).
  centroid_ = times_pow2(mean, exponent);
  bounding_radius_ = std::ldexp(radius, exponent);
  scale_ = max_abs_coordinate(vertices_);
  interior_point_count_ = static_cast<int>(points.size()) - vertex_count;
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
  double max_abs = 0.0;
  for (const Index v : cycle) max_abs = std::max(max_abs, vertex(v).cwiseAbs().maxCoeff());
  const int exponent = magnitude_exponent(max_abs);
  const auto local = [&](std::size_t i) { return times_pow2(vertex(cycle[i]), -exponent); };
  const Vec3 origin = local(0);
  Vec3 normal = Vec3::Zero();
  Vec3 sum = Vec3::Zero();
  double magnitude_sum = 0.0;
  for (std::size_t i = 0; i < cycle.size(); ++i) {
    const Vec3 p = local(i) - origin;
    const Vec3 q = local((i + 1) % cycle.size()) - origin;
    normal += p.cross(q);
    sum += p;
    magnitude_sum += p.norm() * q.norm();
  }
  const Vec3 mean = origin + sum / static_cast<double>(cycle.size());
  // Conditioning: the rounded Newell sum is off by about u sum |p_i||p_i+1|
  // (each cross product's error). When that bound exceeds kSliverRatio per
  // vertex times the normal (a sliver: nearly collinear vertices, which the
  // exact hull of rounded data keeps as faces), or when a vertex of the face
  // is farther than kPlaneResidual u from the resulting plane (coordinates
  // here are below 1), the normal is taken exactly instead.
  bool exact = !(magnitude_sum <= kSliverRatio * static_cast<double>(cycle.size()) * normal.norm());
  if (!exact) {
    const Vec3 unit = normal.normalized();
    for (std::size_t i = 0; i < cycle.size() && !exact; ++i) {
      exact = !(std::abs(unit.dot(local(i) - mean)) <= kPlaneResidual * kEpsilon);
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
    for (std::size_t i = 1; i < cycle.size(); ++i) {
      const double d = (local(i) - origin).squaredNorm();
      if (d > best) best = d, ib = i;
    }
    const Vec3 line = local(ib) - origin;
    std::size_t ic = ib == 1 ? 2 : 1;
    best = -1.0;
    for (std::size_t i = 1; i < cycle.size(); ++i) {
      if (i == ib) continue;
      const double d = line.cross(local(i) - origin).squaredNorm();
      if (d > best) best = d, ic = i;
    }
    normal = exact_triangle_normal(vertex(cycle[0]), vertex(cycle[std::min(ib, ic)]),
                                   vertex(cycle[std::max(ib, ic)]));
  }
  const double length = normal.norm();
  if (!(length > 0.0))
    return {Vec3::UnitZ(), vertex(cycle[0]).z()};  // degenerate face: never built
  normal /= length;
  return {normal, std::ldexp(normal.dot(mean), exponent)};
}

std::vector<std::array<std::int32_t, 3>> ConvexPolytope::triangles() const {
  std::vector<std::array<std::int32_t, 3>> out;
  out.reserve(face_vertices_.size());
  for (int f = 0; f < face_count(); ++f) {
    const auto c = face(f);
    for (std::size_t i = 1; i + 1 < c.size(); ++i) out.push_back({c[0], c[i], c[i + 1]});
  }
  return out;
}

std::vector<std::int32_t> ConvexPolytope::triangle_face() const {
  std::vector<std::int32_t> out;
  out.reserve(face_vertices_.size());
  for (int f = 0; f < face_count(); ++f) {
    const auto n = face(f).size();
    out.insert(out.end(), n >= 2 ? n - 2 : 0, f);
  }
  return out;
}

std::vector<std::array<std::int32_t, 2>> ConvexPolytope::edges() const {
  std::vector<std::array<std::int32_t, 2>> out;
  out.reserve(adjacency_.size() / 2);
  for (int v = 0; v < vertex_count(); ++v) {
    for (const std::int32_t w : neighbors(v)) {
      if (v < w) out.push_back({v, w});
    }
  }
  return out;
}

std::size_t ConvexPolytope::memory_bytes() const {
  const auto index_bytes = [](const std::vector<std::int32_t>& v) {
    return v.capacity() * sizeof(std::int32_t);
  };
  return sizeof(*this) + vertices_.capacity() * sizeof(Vec3) + index_bytes(input_index_) +
         index_bytes(adjacency_offsets_) + index_bytes(adjacency_) + index_bytes(adjacency_faces_) +
         index_bytes(face_offsets_) + index_bytes(face_vertices_);
}

}  // namespace proxima
