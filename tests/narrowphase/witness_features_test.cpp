// Tests of the witness rule's face lookup (src/narrowphase/witness_features.h): the
// search for the hull face holding a closest point's vertices has a fast
// path on solids whose faces are all triangles (the two faces on an edge out
// of the first vertex), and its slow, obvious twin is the cached-face route,
// which tests a given face's vertex list directly. On hulls of points on a
// sphere (triangles only) and on boxes with extra points (quadrilaterals:
// the general search), for the vertices of every face and for random pairs
// and triples of vertices, the answer without a cached face is the answer
// with the true face cached, and it names the face a brute force over all
// faces finds.
#include "narrowphase/witness_features.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "proxima/shape/polytope.h"
#include "support/generators.h"

namespace proxima {
namespace {

using test::drawn;

using Rng = std::mt19937_64;

double uniform(Rng& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng() >> 11) * 0x1p-53);
}

Vec3 random_unit(Rng& rng) {
  for (;;) {
    const Vec3 p = drawn([&] { return uniform(rng, -1, 1); });
    const double n2 = p.squaredNorm();
    if (n2 > 1e-4 && n2 <= 1.0) return p / std::sqrt(n2);
  }
}

// The face holding every id, by a scan of all faces; -1 if none.
int brute_face(const ConvexPolytope& poly, const std::vector<std::int32_t>& ids) {
  for (int f = 0; f < poly.face_count(); ++f) {
    const auto verts = poly.face(f);
    if (std::all_of(ids.begin(), ids.end(), [&](std::int32_t v) {
          return std::find(verts.begin(), verts.end(), v) != verts.end();
        }))
      return f;
  }
  return -1;
}

bool same(const Feature& x, const Feature& y) {
  return x.type == y.type && x.vertices == y.vertices && x.face == y.face;
}

// The feature of `ids` at the mean of their vertices (inside their hull,
// far from its sides for the vertices of a face), as an overlapping
// answer's (no walk), with and without a cached face.
Feature feature_of(const ConvexPolytope& poly, const std::vector<std::int32_t>& ids,
                   std::int32_t cached_face) {
  Vec3 point = Vec3::Zero();
  for (const std::int32_t v : ids) point += poly.vertex(v);
  point /= static_cast<double>(ids.size());
  return detail::witness_feature_of_vertices(poly, ids, point, detail::witness_band(poly.scale()),
                                             Vec3::UnitX(), cached_face, /*locate=*/false);
}

std::vector<ConvexPolytope> hulls(Rng& rng) {
  std::vector<ConvexPolytope> out;
  for (int k = 0; k < 6; ++k) {
    std::vector<Vec3> pts;
    const int n = 8 + 20 * k;
    for (int i = 0; i < n; ++i) pts.push_back(random_unit(rng));
    out.emplace_back(pts);
  }
  // Boxes: quadrilateral faces; with a point beyond a face, triangles too.
  for (int k = 0; k < 3; ++k) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 8; ++i)
      pts.emplace_back(i & 1 ? 1.0 : -1.0, i & 2 ? 2.0 : -2.0, i & 4 ? 0.5 : -0.5);
    if (k > 0) pts.emplace_back(0.0, 0.0, 0.5 + k);
    if (k > 1) pts.emplace_back(1.0 + k, 0.3, 0.1);
    out.emplace_back(pts);
  }
  return out;
}

TEST(WitnessFeatures, FaceLookupMatchesTheCachedFaceAndABruteForce) {
  Rng rng(1414);
  int triangle_hulls = 0;
  int general_hulls = 0;
  int faces_found = 0;
  int no_face = 0;
  for (const ConvexPolytope& poly : hulls(rng)) {
    ASSERT_EQ(poly.dimension(), 3);
    const bool triangles = poly.face_vertices().size() == 3 * std::size_t(poly.face_count());
    (triangles ? triangle_hulls : general_hulls) += 1;
    // Three vertices of every face, and for a larger face two opposite ones.
    for (int f = 0; f < poly.face_count(); ++f) {
      const auto verts = poly.face(f);
      std::vector<std::vector<std::int32_t>> sets = {{verts[0], verts[1], verts[2]}};
      if (verts.size() >= 4) sets.push_back({verts[0], verts[2]});
      for (const auto& ids : sets) {
        SCOPED_TRACE(testing::Message() << "face " << f << " of " << poly.face_count());
        const Feature fresh = feature_of(poly, ids, -1);
        EXPECT_EQ(fresh.type, FeatureType::face);
        EXPECT_EQ(fresh.face, f);
        EXPECT_TRUE(same(fresh, feature_of(poly, ids, f)));
        ++faces_found;
      }
    }
    // Random pairs and triples: with the brute force's face cached (or, when
    // there is none, any face), the same answer.
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<std::int32_t> ids;
      const int m = trial % 2 == 0 ? 2 : 3;
      while (static_cast<int>(ids.size()) < m) {
        const auto v = static_cast<std::int32_t>(rng() % std::uint64_t(poly.vertex_count()));
        if (std::find(ids.begin(), ids.end(), v) == ids.end()) ids.push_back(v);
      }
      const int face = brute_face(poly, ids);
      const auto cached =
          face >= 0 ? face : static_cast<std::int32_t>(rng() % std::uint64_t(poly.face_count()));
      const Feature fresh = feature_of(poly, ids, -1);
      SCOPED_TRACE(testing::Message() << "trial " << trial << ", brute face " << face);
      EXPECT_TRUE(same(fresh, feature_of(poly, ids, cached)));
      if (face >= 0 && fresh.vertex_count() == m && fresh.type == FeatureType::face) {
        EXPECT_EQ(fresh.face, face);
      }
      no_face += face < 0 ? 1 : 0;
    }
  }
  EXPECT_EQ(triangle_hulls, 6);
  EXPECT_EQ(general_hulls, 3);
  EXPECT_GT(faces_found, 500);
  EXPECT_GT(no_face, 1000);
}

// The shortcut for two vertices that are not adjacent on a solid of
// triangles, without rule 3's walk (an overlapping answer's features),
// against the rules it stands for (those of a longer id list, where the
// shortcut does not apply: the same two ids with one repeated, which the
// rules reduce to the two): the same feature for random pairs and points,
// in both orders, through witness_feature and witness_feature_of_vertices,
// and for ties (a centrally symmetric hull, the point at its centre: a
// vertex and its opposite are equally far).
TEST(WitnessFeatures, NonAdjacentPairShortcutIsTheGeneralRule) {
  Rng rng(2024);
  int checked = 0;
  int ties = 0;
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 10 + 12 * trial; ++i) {
      const Vec3 p = random_unit(rng);
      pts.push_back(p);
      if (trial % 2 == 1) pts.push_back(-p);  // centrally symmetric
    }
    const ConvexPolytope poly(pts);
    ASSERT_EQ(poly.face_vertices().size(), 3 * std::size_t(poly.face_count()));
    const double band = detail::witness_band(poly.scale());
    for (int k = 0; k < 400; ++k) {
      const auto u = static_cast<std::int32_t>(rng() % std::uint64_t(poly.vertex_count()));
      const auto w = static_cast<std::int32_t>(rng() % std::uint64_t(poly.vertex_count()));
      const auto nbrs = poly.neighbors(u);
      if (u == w || std::find(nbrs.begin(), nbrs.end(), w) != nbrs.end()) continue;
      const double t = uniform(rng, 0.0, 1.0);
      Vec3 point = (1.0 - t) * poly.vertex(u) + t * poly.vertex(w);
      if (trial % 2 == 1 && k % 4 == 0 && (poly.vertex(u) + poly.vertex(w)).norm() == 0.0) {
        point = Vec3::Zero();  // u and w opposite: a tie
        ++ties;
      }
      for (const std::array<std::int32_t, 2> ids :
           {std::array<std::int32_t, 2>{u, w}, std::array<std::int32_t, 2>{w, u}}) {
        const Feature inline_path = detail::witness_feature(
            poly, ids, band, -1,
            [&] {
              return detail::WitnessPoint{point, Vec3::UnitX()};
            },
            /*locate=*/false);
        const Feature shortcut =
            detail::witness_feature_of_vertices(poly, ids, point, band, Vec3::UnitX(), -1, false);
        const std::array<std::int32_t, 3> repeated = {ids[0], ids[1], ids[0]};
        const Feature general = detail::witness_feature_of_vertices(poly, repeated, point, band,
                                                                    Vec3::UnitX(), -1, false);
        SCOPED_TRACE(testing::Message()
                     << "trial " << trial << ", ids " << ids[0] << " " << ids[1]);
        EXPECT_TRUE(same(inline_path, general));
        EXPECT_TRUE(same(shortcut, general));
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 2000);
  EXPECT_GT(ties, 0);
}

}  // namespace
}  // namespace proxima
