// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Witness features from the hull vertices that span a closest point
// (witness_features.h states the rule).
#include "narrowphase/witness_features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>

#include "core/power_of_two.h"
#include "proxima/geometry/closest_point.h"

namespace proxima::detail {
namespace {

// Faces rule 3's walk may visit. A walk crosses a face per step towards the
// point; it is needed where faces coplanar within rounding were not merged
// (random_small's near-coplanar clusters have a handful), and the cap keeps
// the rule O(1) when the point is not on the boundary at all (an overlap).
constexpr int kMaxWalkFaces = 32;

constexpr std::size_t at(int i) { return static_cast<std::size_t>(i); }

// Whether face f holds ids[first..m) (its vertex list looked up once).
bool face_holds_all(const ConvexPolytope& poly, int f, const std::array<std::int32_t, 4>& ids,
                    int m, int first = 0) {
  const auto verts = poly.face(f);
  for (int i = first; i < m; ++i) {
    if (std::find(verts.begin(), verts.end(), ids[at(i)]) == verts.end()) return false;
  }
  return true;
}

// A face holding all of ids[0..m), among the faces around ids[0] (each face
// through a vertex is left of exactly one of its outgoing edges); -1 if
// none. In a solid two faces share at most an edge, so the face holding a
// diagonal or three vertices is unique; a polygon has two, one per side:
// the one facing `outward`.
//
// On a solid whose faces are all triangles (points in general position:
// the common case) the search needs no face but at most two: two vertices
// share a face only when adjacent, and a face holding ids[0], u and w is the
// triangle left of ids[0] -> u (its third vertex w) or left of ids[0] -> w.
// The answer is the general search's: the first of those two faces in
// ids[0]'s adjacency order that holds them all, or none.
int face_containing(const ConvexPolytope& poly, const std::array<std::int32_t, 4>& ids, int m,
                    const Vec3& outward) {
  const auto offsets = poly.adjacency_offsets();
  const auto left = poly.adjacency_faces();
  const auto v0 = at(ids[0]);
  if (poly.dimension() == 3 && (m == 2 || m == 3) &&
      poly.face_vertices().size() == 3 * at(poly.face_count())) {
    const auto nbrs = poly.adjacency();
    const auto position = [&](std::int32_t v) {  // of the edge ids[0] -> v; -1: not adjacent
      for (auto k = at(offsets[v0]); k < at(offsets[v0 + 1]); ++k) {
        if (nbrs[k] == v) return static_cast<std::ptrdiff_t>(k);
      }
      return std::ptrdiff_t{-1};
    };
    const std::ptrdiff_t k1 = position(ids[1]);
    if (k1 < 0) return -1;
    if (m == 2) {
      // Adjacent: the two faces on the edge (the callers take the edge
      // before they look for a face). The general search below.
    } else {
      const std::ptrdiff_t k2 = position(ids[2]);
      if (k2 < 0) return -1;
      for (const std::ptrdiff_t k : {std::min(k1, k2), std::max(k1, k2)}) {
        const int f = left[static_cast<std::size_t>(k)];
        if (f >= 0 && face_holds_all(poly, f, ids, m, 1)) return f;
      }
      return -1;
    }
  }
  int best = -1;
  bool best_aligned = false;  // best_alignment computed (only when another face competes)
  double best_alignment = 0.0;
  for (auto k = at(offsets[v0]); k < at(offsets[v0 + 1]); ++k) {
    const int f = left[k];
    // f is left of an edge out of ids[0]: it holds ids[0].
    if (f < 0 || !face_holds_all(poly, f, ids, m, 1)) continue;
    if (best < 0) {
      best = f;
      if (poly.dimension() == 3) break;
      continue;
    }
    if (!best_aligned) {
      best_alignment = poly.face_plane(best).normal.dot(outward);
      best_aligned = true;
    }
    const double alignment = poly.face_plane(f).normal.dot(outward);
    if (alignment > best_alignment) {
      best = f;
      best_alignment = alignment;
    }
  }
  return best;
}

// The face to the left of the directed hull edge v -> w, -1 if none.
int face_left_of(const ConvexPolytope& poly, std::int32_t v, std::int32_t w) {
  const auto offsets = poly.adjacency_offsets();
  const auto nbrs = poly.adjacency();
  for (auto k = at(offsets[at(v)]); k < at(offsets[at(v) + 1]); ++k) {
    if (nbrs[k] == w) return poly.adjacency_faces()[k];
  }
  return -1;
}

// The hull seen from the point, in units of a power of two near the
// hull's magnitude where it is far from 1: coordinates of any finite scale
// (1e-300 .. 1e300) then give squared distances and cross products without
// overflow or underflow (DistanceRegression.ScalesFrom1eMinus300To1e300
// trapped on inf / inf). Between 2^-300 and 2^300 the unit is 1: squares of
// the band (about 2^-47 R) and cross products of coordinate differences
// stay far inside the doubles' range, and the hot path skips the scaling.
// Exact but for the one subtraction.
struct View {
  const ConvexPolytope& poly;
  const Vec3& point;
  double inverse_unit = 1.0;
  bool scaled = false;

  // The point lies in the hull up to rounding: the hull's own magnitude is
  // the point's too.
  View(const ConvexPolytope& p, const Vec3& x) : poly(p), point(x) {
    const double r = p.scale();
    if (!(r > 0x1p-300 && r < 0x1p300)) {
      inverse_unit = power_of_two_unit(r).inverse;
      scaled = true;
    }
  }
  // Vertex v relative to the point.
  Vec3 at(std::int32_t v) const {
    const Vec3 d = poly.vertex(v) - point;
    return scaled ? Vec3(d * inverse_unit) : d;
  }
};

// The squared distance from the origin to the segment [p, q].
double segment_distance2(const Vec3& p, const Vec3& q) {
  const Vec3 e = q - p;
  const double ee = e.squaredNorm();
  const double t = ee > 0.0 ? std::clamp(-p.dot(e) / ee, 0.0, 1.0) : 0.0;
  return (p + t * e).squaredNorm();
}

// The squared distance from the origin to the triangle (p, q, r).
double triangle_distance2(const Vec3& p, const Vec3& q, const Vec3& r) {
  const std::array<Vec3, 3> t = {p, q, r};
  const Vec3 origin = Vec3::Zero();
  return closest_points<double>(t.data(), 3, &origin, 1, kernel_tolerance(4.0)).distance_squared;
}

// Whether face f has no area at the precision of its coordinates (collinear
// vertices): its plane is rounding noise, and it holds no point by itself.
bool flat_face(const View& view, int f) {
  const auto verts = view.poly.face(f);
  const Vec3 v0 = view.at(verts[0]);
  Vec3 area = Vec3::Zero();
  double reach2 = 0.0;
  for (std::size_t i = 1; i < verts.size(); ++i) {
    const Vec3 e = view.at(verts[i]) - v0;
    reach2 = std::max(reach2, e.squaredNorm());
    if (i + 1 < verts.size()) area += e.cross(view.at(verts[i + 1]) - v0);
  }
  return !(area.norm() > kContactBandUlps * kUnitRoundoff * reach2);
}

// The point's height over the plane of face f (scaled units).
double plane_gap(const View& view, int f) {
  return std::abs(view.poly.face_plane(f).normal.dot(view.at(view.poly.face(f)[0])));
}

// Of the faces around ids[0..m), the one whose plane is nearest the point:
// where rule 3's walk starts (a cube's face through a vertex and the
// opposite face through another can both hold the point's projection; only
// one holds the point).
int nearest_plane(const View& view, const std::array<std::int32_t, 4>& ids, int m) {
  const auto offsets = view.poly.adjacency_offsets();
  const auto left = view.poly.adjacency_faces();
  int best = -1;
  double best_gap = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) {
    for (auto k = at(offsets[at(ids[at(i)])]); k < at(offsets[at(ids[at(i)]) + 1]); ++k) {
      const int f = left[k];
      if (f < 0 || flat_face(view, f)) continue;
      const double gap = plane_gap(view, f);
      if (gap < best_gap) {
        best_gap = gap;
        best = f;
      }
    }
  }
  return best;
}

// Rule 3's walk on a solid: from face `f`, while the point is beyond one of
// the face's edges by more than `band` (measured in the face's plane, where
// the inside of a counter-clockwise edge e is left of it, along n x e),
// cross the edge it is furthest beyond. The face reached holds the point
// within `band` if its plane does too; -1 when it does not, when the walk
// leaves the hull's faces or when it exceeds kMaxWalkFaces. `band` in
// scaled units.
int locate_face(const View& view, double band, int f) {
  for (int step = 0; step < kMaxWalkFaces && f >= 0; ++step) {
    const Vec3 n = view.poly.face_plane(f).normal;
    const auto verts = view.poly.face(f);
    double deepest = -band;
    int across = -2;  // -2: inside every edge
    for (std::size_t i = 0; i < verts.size(); ++i) {
      const std::int32_t v = verts[i];
      const std::int32_t w = verts[(i + 1) % verts.size()];
      const Vec3 pv = view.at(v);
      const Vec3 e = view.at(w) - pv;
      const double len = e.norm();
      if (!(len > 0.0)) continue;
      const double inside = -n.cross(e).dot(pv) / len;
      if (inside < deepest) {
        deepest = inside;
        across = face_left_of(view.poly, w, v);
      }
    }
    if (across == -2) return plane_gap(view, f) <= band && !flat_face(view, f) ? f : -1;
    f = across;
  }
  return -1;
}

// The least feature of face f holding the point within band (scaled units;
// f holds it within that): a vertex of f, an edge of f, or f with the
// vertices of its fan triangle (f0, fi, fi+1) nearest the point (a face
// with collinear vertices has degenerate fan triangles, which are nearest
// only where an edge would have been); nothing when none of these holds the
// point within band.
std::optional<Feature> feature_of_face(const View& view, int f, double band) {
  const auto verts = view.poly.face(f);
  const std::size_t k = verts.size();
  const double band2 = band * band;
  Feature out;
  for (const std::int32_t v : verts) {
    if (view.at(v).squaredNorm() <= band2) {
      out.vertices = {v, -1, -1};
      return out;
    }
  }
  for (std::size_t i = 0; i < k; ++i) {
    const std::int32_t v = verts[i];
    const std::int32_t w = verts[(i + 1) % k];
    if (segment_distance2(view.at(v), view.at(w)) <= band2) {
      out.type = FeatureType::edge;
      out.vertices = {std::min(v, w), std::max(v, w), -1};
      return out;
    }
  }
  std::size_t best = 1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i + 1 < k; ++i) {
    const double d2 =
        triangle_distance2(view.at(verts[0]), view.at(verts[i]), view.at(verts[i + 1]));
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  if (!(best_d2 <= band2)) return std::nullopt;
  std::array<std::int32_t, 3> tri = {verts[0], verts[best], verts[best + 1]};
  std::sort(tri.begin(), tri.end());
  out.type = FeatureType::face;
  out.vertices = tri;
  out.face = f;
  return out;
}

}  // namespace

Feature witness_feature_of_vertices(const ConvexPolytope& poly, std::span<const std::int32_t> id,
                                    const Vec3& point, double band, const Vec3& outward,
                                    std::int32_t cached_face, bool locate) {
  const View view(poly, point);
  const double scaled_band = band * view.inverse_unit;
  const double band2 = scaled_band * scaled_band;
  // Two vertices farther than the band from the point and not adjacent, on
  // a solid whose faces are all triangles, for an overlapping answer (no
  // walk): no face holds both, so the rules below drop the one farther from
  // the point (rule 1's nearest drop on the ids in ascending order: a tie
  // keeps the larger id). The tracked overlapping query's common case, at
  // the same arithmetic, without the searches.
  if (!locate && id.size() == 2 && id[0] != id[1] && poly.dimension() == 3 &&
      poly.face_vertices().size() == 3 * at(poly.face_count())) {
    const std::int32_t lower = std::min(id[0], id[1]);
    const std::int32_t upper = std::max(id[0], id[1]);
    const double d_lower = view.at(lower).squaredNorm();
    const double d_upper = view.at(upper).squaredNorm();
    const auto nbrs = poly.neighbors(lower);
    if (d_lower > band2 && d_upper > band2 &&
        std::find(nbrs.begin(), nbrs.end(), upper) == nbrs.end()) {
      Feature f;
      f.vertices = {d_lower < d_upper ? lower : upper, -1, -1};
      return f;
    }
  }
  // The distinct ids (a GJK simplex repeats a vertex of one body).
  // with their positions relative to the point.
  std::array<std::int32_t, 4> ids;
  std::array<Vec3, 4> rel;
  int m = 0;
  for (std::size_t k = 0; k < id.size() && k < 4; ++k) {
    int j = 0;
    while (j < m && ids[at(j)] != id[k]) ++j;
    if (j == m) {
      ids[at(m)] = id[k];
      rel[at(m++)] = view.at(id[k]);
    }
  }
  // The squared distance from the point to the hull of the ids but ids[k].
  const auto gap = [&](int k) {
    const auto v = [&](int i) -> const Vec3& { return rel[at(i)]; };
    if (m == 2) return v(1 - k).squaredNorm();
    if (m == 3) return segment_distance2(v((k + 1) % 3), v((k + 2) % 3));
    return triangle_distance2(v((k + 1) % 4), v((k + 2) % 4), v((k + 3) % 4));
  };
  // The id whose removal leaves the hull of the rest nearest the point.
  const auto nearest_drop = [&](double& best_gap) {
    int best = 0;
    best_gap = gap(0);
    for (int k = 1; k < m; ++k) {
      const double g = gap(k);
      if (g < best_gap) {
        best_gap = g;
        best = k;
      }
    }
    return best;
  };
  // nearest_drop of the set as it is (ids and order), once evaluated: rule
  // 1's last evaluation is what the drops below would compute again (at
  // four vertices, four triangle distances) until the set or its order
  // changes. -1: not known.
  int known_drop = -1;
  const auto drop = [&](int j) {
    --m;
    ids[at(j)] = ids[at(m)];
    rel[at(j)] = rel[at(m)];
    known_drop = -1;
  };
  const auto drop_nearest = [&] {
    double g = 0.0;
    drop(known_drop >= 0 ? known_drop : nearest_drop(g));
  };

  // Rule 1.
  while (m > 1) {
    double g = 0.0;
    const int j = nearest_drop(g);
    if (!(g <= band2)) {
      known_drop = j;
      break;
    }
    drop(j);
  }
  if (m == 4) drop_nearest();

  // Rules 2 and 3.
  bool walked = false;
  for (;;) {
    for (int j = 1; j < m; ++j) {  // ascending ids (at most three: insertion)
      for (int i = j; i > 0 && ids[at(i - 1)] > ids[at(i)]; --i) {
        std::swap(ids[at(i - 1)], ids[at(i)]);
        std::swap(rel[at(i - 1)], rel[at(i)]);
        known_drop = -1;  // the gaps depend on the order (rounding)
      }
    }
    Feature f;
    f.vertices = {ids[0], m > 1 ? ids[1] : -1, m > 2 ? ids[2] : -1};
    if (m == 1) return f;
    if (m == 2) {
      const auto nbrs = poly.neighbors(ids[0]);
      if (std::find(nbrs.begin(), nbrs.end(), ids[1]) != nbrs.end()) {
        f.type = FeatureType::edge;
        return f;
      }
    }
    // The cache may come from another pair (DistanceCache's contract): its
    // face is used only when it is a face of this solid holding every
    // vertex (ForeignCache.WitnessFacesAreThoseOfTheQueriedHulls: a foreign
    // face id, up to 15 on a 4-face tetrahedron, was returned).
    int face = -1;
    if (cached_face >= 0 && cached_face < poly.face_count() && poly.dimension() == 3 &&
        face_holds_all(poly, cached_face, ids, m)) {
      face = cached_face;
    } else {
      face = face_containing(poly, ids, m, outward);
    }
    if (face >= 0) {
      f.type = FeatureType::face;
      f.face = face;
      return f;
    }
    if (!walked && locate && poly.dimension() == 3) {
      walked = true;
      const int located = locate_face(view, scaled_band, nearest_plane(view, ids, m));
      if (located >= 0) {
        if (const std::optional<Feature> held = feature_of_face(view, located, scaled_band))
          return *held;
      }
    }
    drop_nearest();
  }
}

}  // namespace proxima::detail
