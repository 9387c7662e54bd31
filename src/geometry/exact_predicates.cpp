// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// geometry layer: exact orientation predicates (see proxima/detail/geometry/exact_predicates.h).
#include "proxima/detail/geometry/exact_predicates.h"

#include <algorithm>
#include <array>
#include <bit>
#include <boost/multiprecision/cpp_int.hpp>
#include <climits>
#include <cmath>
#include <cstdint>

namespace proxima::detail {
namespace {

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

}  // namespace

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

}  // namespace proxima::detail
