// The accuracy suite: all three algorithms through the public
// proxima::distance() against the exact oracle (tests/support/exact_oracle.h),
// under the accuracy standard of DESIGN.md:
//
//   R = largest coordinate magnitude of both bodies in the world frame,
//   u = 2^-53, d* = exact distance of the hulls of the given doubles,
//   band = 64 u R;
//   |distance - d*| <= 1e-12 d* + band;
//   point_a within band of hull A, point_b within band of hull B,
//   |point_a - point_b| = distance within the same bound;
//   status separated exactly when d* > band;
//   never NaN/inf, iterations <= max_iterations, lower_bound <= distance,
//   and the same answer with a warm cache as without one.
//
// Most cases pass identity poses and move the vertex arrays themselves in
// double, so that the oracle sees exactly the doubles the algorithm sees
// and every comparison is exact. The cases with real poses allow the extra
// slack of pose_slack() below.
//
// Every violation prints the full input (%.17g, pasteable as a regression
// test). Each category prints how many of its cases were intersecting,
// touching, near-touching and separated, and asserts that the hard ones are
// really there.
#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "proxima/query/distance.h"
#include "support/exact_oracle.h"
#include "support/generators.h"
#include "support/regression_clouds.h"
#include "support/sanitizers.h"

namespace proxima::test {
namespace {

constexpr int count(int n) { return sanitized_count(n, 4); }

constexpr std::array<Algorithm, 3> kAlgorithms = {Algorithm::hybrid, Algorithm::gjk, Algorithm::enhanced_gjk};

// The standard's band in units of u R.
constexpr double kBandUlps = 64.0;
// The standard's relative distance tolerance.
constexpr double kRelativeTolerance = 1e-12;
// "Near touching": 0 < d* <= this times the bodies' size.
constexpr double kNearTouching = 1e-9;
// Full input dumps printed per test (all violations are counted).
constexpr int kMaxDumps = 12;

// Extra slack when a body is given as local vertices and a Pose instead of
// world doubles. The oracle sees fl(r v + t); the algorithm maps B into A's
// frame through r_a^T r_b (a rotation's transpose as its inverse). Each
// world coordinate is a 3-term dot product plus a translation, rounded with
// error <= gamma_4 (|v|_2 + |t|_inf) (gamma_4 = 4u/(1-4u)), so a vertex
// moves by at most sqrt(3) gamma_4 (|v|_2 + |t|_inf); the rotation doubles
// are orthonormal only to a few u, which moves a point by a few u |v|_2 more
// through the transpose. d* is 1-Lipschitz in each vertex position, so a
// bound of 16 u (max |v|_2 + |t|_inf) per body covers both with room.
double pose_slack(const Points& local, const Pose& pose) {
  if (pose.rotation == Mat3::Identity() && pose.translation == Vec3::Zero()) return 0.0;
  double v = 0.0;
  for (const Vec3& p : local) v = std::max(v, p.norm());
  return 16.0 * kUnitRoundoff * (v + pose.translation.cwiseAbs().maxCoeff());
}

struct Case {
  std::string category;
  Points a, b;  // local vertices (world when the poses are identities)
  Pose pose_a, pose_b;
};

std::string describe(const Case& c) {
  std::ostringstream s;
  s << "category " << c.category << "\nconst Points a = " << format_points(c.a) << ";\nconst Points b = "
    << format_points(c.b) << ";\n";
  if (pose_slack(c.a, c.pose_a) > 0 || pose_slack(c.b, c.pose_b) > 0)
    s << "pose_a = " << format_pose(c.pose_a) << "\npose_b = " << format_pose(c.pose_b) << "\n";
  return s.str();
}

std::string describe(const DistanceResult& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "status %s distance %.17g lower_bound %.17g iterations %d\n point_a (%.17g, %.17g, %.17g)\n point_b "
                "(%.17g, %.17g, %.17g)\n feature_a %s [%d %d %d] feature_b %s [%d %d %d]",
                to_string(r.status), r.distance, r.lower_bound, r.iterations, r.point_a.x(), r.point_a.y(),
                r.point_a.z(), r.point_b.x(), r.point_b.y(), r.point_b.z(), to_string(r.feature_a.type),
                r.feature_a.vertices[0], r.feature_a.vertices[1], r.feature_a.vertices[2],
                to_string(r.feature_b.type), r.feature_b.vertices[0], r.feature_b.vertices[1],
                r.feature_b.vertices[2]);
  return buf;
}

// Why `f` is not a real feature of `poly` (empty when it is): vertex ids
// in range, an edge's two vertices adjacent, a face's id a face of this
// hull holding every listed vertex (a stale or foreign face id must never
// come back: ForeignCache.WitnessFacesAreThoseOfTheQueriedHulls).
std::vector<std::string> hull_feature_violations(const Feature& f, const ConvexPolytope& poly) {
  std::vector<std::string> v;
  const int n = f.vertex_count();
  const int expected_min = f.type == FeatureType::vertex ? 1 : f.type == FeatureType::edge ? 2 : 1;
  const int expected_max = f.type == FeatureType::vertex ? 1 : f.type == FeatureType::edge ? 2 : 3;
  if (n < expected_min || n > expected_max)
    v.push_back(std::string(to_string(f.type)) + " with " + std::to_string(n) + " vertices");
  for (int k = 0; k < n; ++k) {
    const std::int32_t id = f.vertices[static_cast<std::size_t>(k)];
    if (id < 0 || id >= poly.vertex_count()) {
      v.push_back("vertex id " + std::to_string(id) + " out of range");
      return v;
    }
  }
  if (f.type == FeatureType::edge && n == 2) {
    const auto nbrs = poly.neighbors(f.vertices[0]);
    if (std::find(nbrs.begin(), nbrs.end(), f.vertices[1]) == nbrs.end())
      v.push_back("edge between non-adjacent vertices");
  }
  if (f.type != FeatureType::face) {
    if (f.face != -1)
      v.push_back("face id " + std::to_string(f.face) + " on a " + to_string(f.type));
    return v;
  }
  if (f.face < 0 || f.face >= poly.face_count()) {
    v.push_back("face id " + std::to_string(f.face) + " out of range (" +
                std::to_string(poly.face_count()) + " faces)");
    return v;
  }
  const auto verts = poly.face(f.face);
  for (int k = 0; k < n; ++k) {
    if (std::find(verts.begin(), verts.end(), f.vertices[static_cast<std::size_t>(k)]) ==
        verts.end())
      v.push_back("face " + std::to_string(f.face) + " does not hold vertex " +
                  std::to_string(f.vertices[static_cast<std::size_t>(k)]));
  }
  return v;
}

// Exactly: x <= sqrt(q) (x a double, q >= 0).
bool at_most_sqrt(double x, const mpq_class& q) {
  if (x <= 0) return true;
  const mpq_class xq(x);
  return xq * xq <= q;
}

mpq_class squared(double x) { return mpq_class(x) * mpq_class(x); }

// Squared distance between two double points, exact.
mpq_class exact_squared_distance(const Vec3& p, const Vec3& q) {
  return squared_norm(difference(to_rational(p), to_rational(q)));
}

// Largest side of the bounding box.
double extent(const Points& p) {
  Vec3 lo = p[0], hi = p[0];
  for (const Vec3& x : p) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return (hi - lo).maxCoeff();
}

// The optimality certificate of a separated answer: w = point_b - point_a
// must separate the hulls, checked exactly against every input point.
// The answer is only accurate to the standard, so the plane may tilt:
// with tol the band for the points and eps = 1e-12 |w| + tol the bound on
// |w| - d*, the answer's w lies within 2 tol of conv(B - A) and its norm
// is at most d* + eps; the exact w* (the minimum-norm point of that set)
// then satisfies |w - w*| <= 2 tol + sqrt(2 d* e + e^2) with
// e = eps + 2 tol (for z in the set, w*.(z - w*) >= 0, so
// |z - w*|^2 <= |z|^2 - d*^2). For x in A, w*.x <= w*.pa* and
// w*.(pa* - point_a) <= d* (tol + eps), hence
//   w.(x - point_a) <= d* (tol + eps) + |w - w*| (diam + tol),
// and the mirror image for B. A wrong feature or a stale plane breaks it
// by far more; near contact (d* ~ tol) the bound is loose by nature.
std::string separation_certificate(const DistanceResult& r, const Points& wa, const Points& wb, double tol) {
  const double wn = (r.point_b - r.point_a).norm();
  const double eps = kRelativeTolerance * wn + tol;
  const double e = eps + 2 * tol;
  const double d_max = wn + eps;
  const double diam = std::sqrt(3.0) * std::max(extent(wa), extent(wb));
  const double allowed =
      1.01 * (d_max * (tol + eps) + (2 * tol + std::sqrt(2 * d_max * e + e * e)) * (diam + tol));
  const QPoint qa = to_rational(r.point_a), qb = to_rational(r.point_b);
  const QPoint w = difference(qb, qa);
  const mpq_class limit(allowed);
  for (const Vec3& x : wa)
    if (dot(w, difference(to_rational(x), qa)) > limit) return "point_b - point_a does not separate: A beyond";
  for (const Vec3& y : wb)
    if (-dot(w, difference(to_rational(y), qb)) > limit) return "point_b - point_a does not separate: B beyond";
  return {};
}

// Counts per category: the kinds of cases really generated, and failures.
struct Tally {
  int cases = 0;
  int intersecting_or_touching = 0;  // d* = 0
  int in_band = 0;                   // 0 < d* <= band
  int near_touching = 0;             // band < d* <= 1e-9 size
  int few_bands = 0;                 // 0 < d* <= 16 bands (overlaps the two above)
  int separated = 0;
  int queries = 0;
  int violations = 0;
  int status_undecidable = 0;  // d* within the pose slack of the band (see check_result)
  std::map<std::string, int> by_algorithm;  // violations per algorithm
};

class AccuracySuite {
 public:
  explicit AccuracySuite(std::string name) : name_(std::move(name)) {}

  ~AccuracySuite() {
    const OracleStats& s = oracle_.stats();
    std::printf("[%s] oracle: %d queries, %d by CGAL, %d CGAL answers rejected, %d by brute force, %d failed\n",
                name_.c_str(), s.queries, s.cgal_certified, s.cgal_rejected, s.brute_force_certified, s.failed);
    for (const auto& [cat, t] : tallies_) {
      std::printf("[%s] %-28s cases %4d: d*=0 %4d, in band %3d, near-touching %4d, separated %4d (<= 16 bands %3d) "
                  "| queries %5d violations %d (",
                  name_.c_str(), cat.c_str(), t.cases, t.intersecting_or_touching, t.in_band, t.near_touching,
                  t.separated, t.few_bands, t.queries, t.violations);
      for (const auto& [alg, n] : t.by_algorithm) std::printf(" %s %d", alg.c_str(), n);
      std::printf(" ) status undecidable %d\n", t.status_undecidable);
    }
  }

  const Tally& tally(const std::string& category) { return tallies_[category]; }
  ExactOracle& oracle() { return oracle_; }

  // Runs all three algorithms on one case, cold and warm, and checks every
  // answer against the oracle. Returns false when anything was violated.
  bool run(const Case& c) {
    Tally& t = tallies_[c.category];
    ++t.cases;
    const Points wa = transformed(c.a, c.pose_a), wb = transformed(c.b, c.pose_b);
    const std::optional<ExactDistance> exact = oracle_.distance(wa, wb);
    if (!exact) {
      ADD_FAILURE() << "oracle failed: " << oracle_.last_error() << "\n" << describe(c);
      return false;
    }
    const double r = std::max(max_abs_coordinate(wa), max_abs_coordinate(wb));
    const double band = kBandUlps * kUnitRoundoff * r;
    const double size = std::max(extent(wa), extent(wb));
    if (!exact->is_zero() && sqrt_at_most(exact->distance_squared, 16 * band)) ++t.few_bands;
    if (exact->is_zero())
      ++t.intersecting_or_touching;
    else if (sqrt_at_most(exact->distance_squared, band))
      ++t.in_band;
    else if (sqrt_at_most(exact->distance_squared, kNearTouching * size))
      ++t.near_touching;
    else
      ++t.separated;

    std::optional<ConvexPolytope> pa, pb;
    try {
      pa.emplace(c.a);
      pb.emplace(c.b);
    } catch (const std::exception& e) {
      report(t, c, "polytope construction", std::string("threw: ") + e.what(), *exact);
      return false;
    }
    const double slack = pose_slack(c.a, c.pose_a) + pose_slack(c.b, c.pose_b);
    bool ok = true;
    for (const Algorithm alg : kAlgorithms) {
      DistanceOptions options;
      options.algorithm = alg;
      try {
        const DistanceResult cold = distance(*pa, c.pose_a, *pb, c.pose_b, options, nullptr);
        DistanceCache cache;
        const DistanceResult first = distance(*pa, c.pose_a, *pb, c.pose_b, options, &cache);
        const DistanceResult warm = distance(*pa, c.pose_a, *pb, c.pose_b, options, &cache);
        t.queries += 3;
        std::vector<std::string> v = check_result(t, cold, *exact, *pa, *pb, wa, wb, band, slack, options);
        for (const std::string& s : check_result(t, warm, *exact, *pa, *pb, wa, wb, band, slack, options))
          v.push_back("warm: " + s);
        if (!within_bound(warm.distance, squared(cold.distance),
                          kRelativeTolerance, band + slack))
          v.push_back("warm and cold distances differ beyond the standard");
        if (first.distance != cold.distance)
          v.push_back("a cold cache and no cache give different distances");
        if (!v.empty()) {
          std::string all;
          for (const std::string& s : v) all += "  - " + s + "\n";
          report(t, c, to_string(alg), all + "cold: " + describe(cold) + "\nwarm: " + describe(warm), *exact);
          ok = false;
        }
      } catch (const std::exception& e) {
        report(t, c, to_string(alg), std::string("threw: ") + e.what(), *exact);
        ok = false;
      }
    }
    return ok;
  }

 private:
  // Is p within tol of conv(hull)? First against the reported feature (a
  // tiny, cheap oracle query that is a certificate by itself when it
  // passes), then against the whole hull. A separated or touching answer's
  // point must be within tol of its own witness feature (the hull of the
  // feature's listed vertices): `feature_mismatch` is set when it is near
  // its hull but not near its feature (the witness is wrong). For
  // intersecting answers the features carry no such promise.
  bool point_near_hull(bool& feature_mismatch, const Vec3& p, const Feature& f, bool on_boundary,
                       const ConvexPolytope& poly, const Points& world, double tol) {
    Points feature_points;
    for (int k = 0; k < f.vertex_count(); ++k) {
      const int v = f.vertices[static_cast<std::size_t>(k)];
      if (v < 0 || v >= poly.vertex_count()) {
        feature_points.clear();
        break;
      }
      feature_points.push_back(world[static_cast<std::size_t>(poly.input_index()[static_cast<std::size_t>(v)])]);
    }
    if (!feature_points.empty()) {
      const std::optional<mpq_class> d2 = oracle_.point_distance_squared(p, feature_points);
      if (d2 && sqrt_at_most(*d2, tol)) return true;
    }
    const std::optional<mpq_class> d2 = oracle_.point_distance_squared(p, world);
    if (!d2 || !sqrt_at_most(*d2, tol)) return false;
    if (on_boundary) feature_mismatch = true;
    return true;
  }

  std::vector<std::string> check_result(Tally& t, const DistanceResult& r, const ExactDistance& e,
                                        const ConvexPolytope& pa, const ConvexPolytope& pb, const Points& wa,
                                        const Points& wb, double band, double slack,
                                        const DistanceOptions& options) {
    std::vector<std::string> v;
    const double tol = band + slack;
    if (!std::isfinite(r.distance) || !std::isfinite(r.lower_bound) || !r.point_a.allFinite() ||
        !r.point_b.allFinite() || !r.normal.allFinite()) {
      v.push_back("non-finite result");
      return v;
    }
    if (r.iterations < 0 || r.iterations > options.max_iterations) v.push_back("iterations beyond the cap");
    if (r.status == Status::iteration_cap) v.push_back("iteration cap reached");
    if (!within_bound(r.distance, e.distance_squared, kRelativeTolerance, tol)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "distance off: d* = %.17g, error = %.3g u R", e.distance(),
                    (r.distance - e.distance()) / (band / kBandUlps));
      v.push_back(buf);
    }
    if (!(r.lower_bound <= r.distance)) v.push_back("lower_bound > distance");
    if (!at_most_sqrt(r.lower_bound - tol, e.distance_squared)) v.push_back("lower_bound > d* + band");
    // Status: separated exactly when d* > band (DESIGN.md), judged by the
    // exact d* of the oracle, never by the reported distance. The one zone
    // where it is not judged: d* within `slack` of the band. With poses the
    // oracle's bodies are the world points rounded from the poses, so d* is
    // known only to within that slack (pose_slack; 0 without poses, where
    // the zone is empty and the status must follow d* exactly). An answer
    // whose status follows its own distance but not d* outside that zone
    // is a violation.
    const bool separated_reported = r.status == Status::separated;
    const bool d_star_above = !sqrt_at_most(e.distance_squared, band - slack);
    const bool d_star_at_most = sqrt_at_most(e.distance_squared, band + slack);
    if (d_star_above && d_star_at_most) ++t.status_undecidable;
    const bool ok_by_d_star = separated_reported ? d_star_above : d_star_at_most;
    if (!ok_by_d_star) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "status %s with d* = %.3g band and distance = %.3g band", to_string(r.status),
                    e.distance() / band, r.distance / band);
      v.push_back(buf);
    }
    // Intersecting answers carry the deepest points (the penetration depth,
    // types.h): they are the depth apart.
    const double apart = r.status == Status::intersecting ? r.depth : r.distance;
    if (!within_bound(apart, exact_squared_distance(r.point_a, r.point_b), kRelativeTolerance, tol))
      v.push_back("|point_a - point_b| differs from distance (intersecting: from depth)");
    // Witness features: always real features of the queried hulls, and for
    // answers on the boundary (separated or touching) holding their point
    // within the band. No budget: every mismatch is a violation.
    const bool on_boundary = r.status != Status::intersecting;
    bool mismatch_a = false;
    bool mismatch_b = false;
    if (!point_near_hull(mismatch_a, r.point_a, r.feature_a, on_boundary, pa, wa, tol))
      v.push_back("point_a not within band of hull A");
    if (!point_near_hull(mismatch_b, r.point_b, r.feature_b, on_boundary, pb, wb, tol))
      v.push_back("point_b not within band of hull B");
    if (mismatch_a) v.push_back("point_a not within band of its witness feature_a");
    if (mismatch_b) v.push_back("point_b not within band of its witness feature_b");
    for (const std::string& s : hull_feature_violations(r.feature_a, pa))
      v.push_back("feature_a: " + s);
    for (const std::string& s : hull_feature_violations(r.feature_b, pb))
      v.push_back("feature_b: " + s);
    if (separated_reported && !sqrt_at_most(e.distance_squared, 2 * band)) {
      const std::string s = separation_certificate(r, wa, wb, tol);
      if (!s.empty()) v.push_back(s);
    }
    return v;
  }

  void report(Tally& t, const Case& c, const std::string& who, const std::string& what, const ExactDistance& e) {
    ++t.violations;
    ++t.by_algorithm[who];
    if (dumps_++ < kMaxDumps) {
      ADD_FAILURE() << "[" << name_ << "] " << who << " violates the standard:\n"
                    << what << "\nexact d* = " << e.distance() << " (d*^2 = " << e.distance_squared.get_d()
                    << ")\n"
                    << describe(c);
    } else {
      ADD_FAILURE() << "[" << name_ << "] " << who << " violation in " << c.category << " (dump limit reached)";
    }
  }

  std::string name_;
  ExactOracle oracle_;
  std::map<std::string, Tally> tallies_;
  int dumps_ = 0;
};

// Applies the same random rotation and translation to a shape (in double).
Points posed(Rng& rng, const Points& p, double spread = 0.0) {
  return transformed(p, random_rotation(rng), spread * random_unit_vector(rng));
}

// B placed against A: a random direction, then by mode an overlap, exact
// contact along the slab, a gap relative to `size`, or (tighten) a gap
// made exact with the oracle so that d* itself is near-touching.
Points place(AccuracySuite& suite, Rng& rng, const Points& a, const Points& b, double size, double rel_gap,
             bool tighten) {
  const Points placed = place_along(a, b, random_unit_vector(rng), rel_gap * size);
  if (!tighten || rel_gap <= 0) return placed;
  const std::optional<Points> t = tighten_to_gap(suite.oracle(), a, placed, rel_gap * size);
  return t ? *t : placed;
}

// ---------------------------------------------------------------------------
// Seeded random polytopes: 4 to 2000 vertices, separations 1e-12 to 1e3 of
// their size, a share tightened to near-touching.

TEST(DistanceAccuracy, RandomPolytopes) {
  AccuracySuite suite("random");
  Rng rng(1);
  const int n_small = count(500), n_large = count(16);
  for (int i = 0; i < n_small + n_large; ++i) {
    const bool large = i >= n_small;
    const int na = large ? static_cast<int>(log_uniform(rng, 300, 2000)) : static_cast<int>(log_uniform(rng, 4, 200));
    const int nb = large ? static_cast<int>(log_uniform(rng, 4, 2000)) : static_cast<int>(log_uniform(rng, 4, 200));
    const ShapeKind kinds[] = {ShapeKind::sphere, ShapeKind::cube_cloud, ShapeKind::grid};
    const Points a = posed(rng, random_shape(rng, kinds[uniform_int(rng, 0, 2)], na));
    const Points b0 = posed(rng, random_shape(rng, kinds[uniform_int(rng, 0, 2)], nb));
    const int mode = uniform_int(rng, 0, 9);
    double rel_gap = log_uniform(rng, 1e-12, 1e3);
    bool tighten = false;
    if (mode == 0) rel_gap = -uniform(rng, 0.0, 0.5);  // overlap
    if (mode >= 7) {                                   // near-touching d*
      rel_gap = log_uniform(rng, 1e-14, 1e-9);
      tighten = true;
    }
    suite.run({large ? "random_large" : "random_small", a, place(suite, rng, a, b0, 2.0, rel_gap, tighten), {}, {}});
  }
  EXPECT_GT(suite.tally("random_small").near_touching, 0);
  EXPECT_GT(suite.tally("random_small").separated, 0);
  EXPECT_GT(suite.tally("random_small").intersecting_or_touching, 0);
  EXPECT_GT(suite.tally("random_large").cases, 0);
}

// ---------------------------------------------------------------------------
// The paper's two stress experiments, 100 orientations each, d* made the
// stated gap with the oracle.

TEST(DistanceAccuracy, PaperStressExperiments) {
  AccuracySuite suite("paper");
  Rng rng(1998);
  for (int i = 0; i < count(100); ++i) {
    for (const bool tetrahedra : {true, false}) {
      const BodyPair p = tetrahedra ? paper_tetrahedra(rng) : paper_cubes(rng);
      const double gap = tetrahedra ? kPaperTetrahedronGap : kPaperCubeGap;
      const std::optional<Points> b = tighten_to_gap(suite.oracle(), p.a, p.b, gap);
      ASSERT_TRUE(b);
      suite.run({tetrahedra ? "paper_tetrahedra" : "paper_cubes", p.a, *b, {}, {}});
    }
  }
  // Both experiments are separated by far more than the band: the gap is
  // 2e-22 against 64 u R ~ 1e-36, and 1e29 against ~1e28.
  EXPECT_EQ(suite.tally("paper_tetrahedra").separated + suite.tally("paper_tetrahedra").near_touching,
            suite.tally("paper_tetrahedra").cases);
  EXPECT_EQ(suite.tally("paper_cubes").intersecting_or_touching, 0);
}

// ---------------------------------------------------------------------------
// Degenerate shapes: flat polygons, segments, points, duplicated vertices,
// needles, slivers, against each other and against solids.

TEST(DistanceAccuracy, DegenerateShapes) {
  AccuracySuite suite("degenerate");
  Rng rng(2);
  const ShapeKind degenerate[] = {ShapeKind::needle,         ShapeKind::sliver,  ShapeKind::flat_polygon,
                                  ShapeKind::tilted_polygon, ShapeKind::segment, ShapeKind::point,
                                  ShapeKind::duplicates};
  for (int i = 0; i < count(360); ++i) {
    const ShapeKind ka = degenerate[uniform_int(rng, 0, 6)];
    const ShapeKind kb = (i % 2) ? degenerate[uniform_int(rng, 0, 6)] : random_shape_kind(rng);
    // Flat and collinear shapes stay exactly so only unrotated: rotate half.
    const bool rotate = rng() & 1;
    Points a = random_shape(rng, ka, uniform_int(rng, 4, 16));
    Points b0 = random_shape(rng, kb, uniform_int(rng, 4, 16));
    if (rotate) {
      a = posed(rng, a);
      b0 = posed(rng, b0);
    }
    const int mode = uniform_int(rng, 0, 5);
    const double rel_gap = mode == 0 ? -uniform(rng, 0.0, 0.3) : mode == 1 ? log_uniform(rng, 1e-13, 1e-9) : log_uniform(rng, 1e-6, 10);
    suite.run({std::string("degenerate_") + to_string(ka), a, place(suite, rng, a, b0, 2.0, rel_gap, mode == 1), {}, {}});
  }
  int near = 0, zero = 0;
  for (const ShapeKind k : degenerate) {
    const Tally& t = suite.tally(std::string("degenerate_") + to_string(k));
    EXPECT_GT(t.cases, 0) << to_string(k);
    near += t.near_touching;
    zero += t.intersecting_or_touching;
  }
  EXPECT_GT(near, 0);
  EXPECT_GT(zero, 0);
}

// ---------------------------------------------------------------------------
// Parallel closest features: boxes face to face (exactly parallel faces,
// laterally offset), boxes turned 45 degrees about z (parallel vertical
// edges), and both under one common rotation (parallel up to rounding).

TEST(DistanceAccuracy, ParallelFeatures) {
  AccuracySuite suite("parallel");
  Rng rng(3);
  for (int i = 0; i < count(150); ++i) {
    const int kind = i % 3;
    const Vec3 ha = drawn([&] { return uniform(rng, 0.1, 2); });
    const Vec3 hb = drawn([&] { return uniform(rng, 0.1, 2); });
    const double gap = (rng() & 1) ? log_uniform(rng, 1e-12, 1e-6) : log_uniform(rng, 1e-3, 3);
    Points a = box(ha), b = box(hb);
    if (kind == 1) {  // edge-edge: both turned 45 degrees about z
      const Mat3 turn = Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()).toRotationMatrix();
      a = transformed(a, turn, Vec3::Zero());
      b = transformed(b, turn, Vec3::Zero());
    }
    // Side by side along x, offset laterally so the faces overlap partly.
    const double dx = support_value(a, Vec3::UnitX()) + support_value(b, -Vec3::UnitX()) + gap;
    b = translated(b, drawn([&] { return dx; }, [&] { return uniform(rng, -0.5, 0.5) * hb.y(); },
                            [&] { return uniform(rng, -0.5, 0.5) * hb.z(); }));
    if (kind == 2) {
      const Mat3 r = random_rotation(rng);
      a = transformed(a, r, Vec3::Zero());
      b = transformed(b, r, Vec3::Zero());
    }
    const char* names[] = {"parallel_face_face", "parallel_edge_edge", "parallel_rotated"};
    suite.run({names[kind], a, b, {}, {}});
  }
  EXPECT_GT(suite.tally("parallel_face_face").near_touching + suite.tally("parallel_face_face").in_band, 0);
  EXPECT_GT(suite.tally("parallel_edge_edge").separated, 0);
}

// ---------------------------------------------------------------------------
// Scales from 1e-20 to 1e20, and bodies 1e6 (of their size) from the origin.

TEST(DistanceAccuracy, ScalesAndFarFromOrigin) {
  AccuracySuite suite("scale");
  Rng rng(4);
  for (int i = 0; i < count(300); ++i) {
    const bool far = i % 2;
    const double s = far ? log_uniform(rng, 1e-3, 1e3) : log_uniform(rng, 1e-20, 1e20);
    const Points a0 = posed(rng, random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 40)));
    const Points b0 = posed(rng, random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 40)));
    const int mode = uniform_int(rng, 0, 4);
    const double rel_gap = mode == 0 ? -0.2 : mode == 1 ? log_uniform(rng, 1e-12, 1e-9) : log_uniform(rng, 1e-6, 1e2);
    Points a = scaled(a0, s);
    Points b = place(suite, rng, a, scaled(b0, s), 2 * s, rel_gap, mode == 1);
    if (far) {
      const Vec3 offset = 1e6 * s * random_unit_vector(rng);
      a = translated(a, offset);
      b = translated(b, offset);
      // At 1e6 sizes from the origin the band is ~1e-8 of the size, so
      // "near touching" here means a few bands: re-tighten on the final
      // doubles to d* = 4 bands.
      if (mode == 1) {
        const double r = std::max(max_abs_coordinate(a), max_abs_coordinate(b));
        const std::optional<Points> t = tighten_to_gap(suite.oracle(), a, b, 4 * kBandUlps * kUnitRoundoff * r);
        if (t) b = *t;
      }
    }
    suite.run({far ? "far_from_origin" : "scale_1e-20_to_1e20", a, b, {}, {}});
  }
  EXPECT_GT(suite.tally("far_from_origin").separated, 0);
  EXPECT_GT(suite.tally("scale_1e-20_to_1e20").separated, 0);
  EXPECT_GT(suite.tally("far_from_origin").few_bands, 0);
  EXPECT_GT(suite.tally("scale_1e-20_to_1e20").near_touching, 0);
}

// ---------------------------------------------------------------------------
// Touching (exact contact, d* = 0, built from shared vertices) and
// intersecting pairs.

TEST(DistanceAccuracy, TouchingAndIntersecting) {
  AccuracySuite suite("contact");
  Rng rng(5);
  for (int i = 0; i < count(160); ++i) {
    const Points a = posed(rng, random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 30)));
    Points b = posed(rng, random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 30)));
    if (i % 2 == 0) {
      // Shared vertex: B's support vertex in -n moved onto A's support
      // vertex in n, then set to the very same doubles.
      const Vec3 n = random_unit_vector(rng);
      int ia = 0, ib = 0;
      for (int k = 0; k < static_cast<int>(a.size()); ++k)
        if (n.dot(a[static_cast<std::size_t>(k)]) > n.dot(a[static_cast<std::size_t>(ia)])) ia = k;
      for (int k = 0; k < static_cast<int>(b.size()); ++k)
        if (n.dot(b[static_cast<std::size_t>(k)]) < n.dot(b[static_cast<std::size_t>(ib)])) ib = k;
      b = translated(b, a[static_cast<std::size_t>(ia)] - b[static_cast<std::size_t>(ib)]);
      b[static_cast<std::size_t>(ib)] = a[static_cast<std::size_t>(ia)];
      suite.run({"touching_shared_vertex", a, b, {}, {}});
    } else {
      suite.run({"intersecting", a, place(suite, rng, a, b, 2.0, -uniform(rng, 1e-6, 0.5), false), {}, {}});
    }
  }
  EXPECT_EQ(suite.tally("touching_shared_vertex").intersecting_or_touching, suite.tally("touching_shared_vertex").cases);
  EXPECT_GT(suite.tally("intersecting").intersecting_or_touching, 0);
}

// ---------------------------------------------------------------------------
// Real poses: local vertices and non-identity poses on both sides, checked
// with pose_slack() added to the band.

TEST(DistanceAccuracy, NonIdentityPoses) {
  AccuracySuite suite("poses");
  Rng rng(6);
  for (int i = 0; i < count(120); ++i) {
    const Points a = random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 60));
    const Points b = random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 60));
    const Pose pose_a(random_quaternion(rng), uniform(rng, 0, 100) * random_unit_vector(rng));
    const Mat3 rb = random_rotation(rng);
    // Put B next to A in the world: its world vertices placed along a
    // random direction, then the translation read back.
    const Points wa = transformed(a, pose_a), wb = transformed(b, rb, Vec3::Zero());
    const double rel_gap = (i % 3 == 0) ? -0.1 : log_uniform(rng, 1e-6, 10);
    const Vec3 n = random_unit_vector(rng);
    const Vec3 t = (support_value(wa, n) + support_value(wb, -n) + rel_gap) * n;
    suite.run({"non_identity_poses", a, b, pose_a, Pose(rb, t)});
  }
  EXPECT_GT(suite.tally("non_identity_poses").separated, 0);
}

// ---------------------------------------------------------------------------
// Tracking: along long motion sequences, a query with a cache gives the same
// answer (within the standard) as a cold one, for all three algorithms,
// and both stay within the standard of the oracle.

TEST(DistanceAccuracy, TrackingEqualsColdAlongMotion) {
  Rng rng(7);
  ExactOracle oracle;
  const int steps = count(200);
  int compared = 0, near = 0, violations = 0;
  const std::vector<std::pair<Points, Points>> bodies = {
      {points_on_sphere(rng, 30), points_in_cube(rng, 20, 0.5)},
      {box(Vec3(1, 0.5, 0.25)), box(Vec3(0.3, 0.3, 0.3))},
      {grid_points(rng, 60, 2), regular_tetrahedron(1.0)},
      {flat_polygon(rng, 12), needle(rng, 2.0, 1e-3)},
  };
  for (const auto& [a_pts, b_pts] : bodies) {
    const ConvexPolytope a(a_pts), b(b_pts);
    std::array<DistanceCache, 3> caches{};
    // B circles A, spinning, at a clearance that sweeps from 1 down to
    // 1e-10 and back (log scale); the motion is a Pose (the tracking use).
    const Vec3 axis = random_unit_vector(rng);
    const Mat3 spin_step = random_small_rotation(rng, 0.02);
    Mat3 spin = random_rotation(rng);
    for (int s = 0; s < steps; ++s) {
      const double phase = 2 * std::numbers::pi * s / steps;
      const Vec3 dir = (Eigen::AngleAxisd(phase, axis) * axis.unitOrthogonal()).normalized();
      spin = spin * spin_step;
      const double clearance = std::pow(10.0, -5.0 + 5.0 * std::cos(3 * phase));
      const Points wb0 = transformed(b_pts, spin, Vec3::Zero());
      Vec3 t = (support_value(a_pts, dir) + support_value(wb0, -dir)) * dir;
      // d* made the clearance itself (see tighten_to_gap).
      const std::optional<Points> tight = tighten_to_gap(oracle, a_pts, translated(wb0, t), clearance);
      ASSERT_TRUE(tight) << oracle.last_error();
      t += (*tight)[0] - (wb0[0] + t);
      const Pose pose_b(spin, t);
      const Points wb = transformed(b_pts, pose_b);
      const double r = std::max(max_abs_coordinate(a_pts), max_abs_coordinate(wb));
      const double band = kBandUlps * kUnitRoundoff * r;
      const double slack = pose_slack(b_pts, pose_b);
      const std::optional<ExactDistance> exact = oracle.distance(a_pts, wb);
      ASSERT_TRUE(exact) << oracle.last_error();
      if (sqrt_at_most(exact->distance_squared, 1e-6)) ++near;
      for (std::size_t k = 0; k < kAlgorithms.size(); ++k) {
        DistanceOptions options;
        options.algorithm = kAlgorithms[k];
        const DistanceResult warm = distance(a, Pose(), b, pose_b, options, &caches[k]);
        const DistanceResult cold = distance(a, Pose(), b, pose_b, options, nullptr);
        ++compared;
        std::string what;
        if (!within_bound(warm.distance, squared(cold.distance), kRelativeTolerance, band)) what += " warm != cold;";
        if (!(warm.iterations <= options.max_iterations && std::isfinite(warm.distance))) what += " warm cap/finite;";
        if (!within_bound(warm.distance, exact->distance_squared, kRelativeTolerance, band + slack)) what += " warm != d*;";
        if (!within_bound(cold.distance, exact->distance_squared, kRelativeTolerance, band + slack)) what += " cold != d*;";
        if (what.empty()) continue;
        if (violations++ < kMaxDumps) {
          ADD_FAILURE() << to_string(kAlgorithms[k]) << " tracking step " << s << ":" << what << "\nwarm "
                        << describe(warm) << "\ncold " << describe(cold) << "\nexact d* " << exact->distance()
                        << "\nconst Points a = " << format_points(a_pts) << ";\nconst Points b = "
                        << format_points(b_pts) << ";\npose_b = " << format_pose(pose_b);
        } else {
          ADD_FAILURE() << to_string(kAlgorithms[k]) << " tracking step " << s << ":" << what << " (dump limit reached)";
        }
      }
    }
  }
  std::printf("[tracking] %d warm/cold comparisons, %d steps with d* <= 1e-6, violations %d\n", compared, near,
              violations);
  EXPECT_GT(near, 0);
}

// ---------------------------------------------------------------------------
// Properties (rapidcheck, fixed seed): symmetry, invariance under a common
// rigid motion, the iteration cap. Each property draws a seed and builds
// its case with the seeded generators.

rc::detail::TestParams property_params() {
  rc::detail::TestParams p;
  p.seed = 0x5eed;
  p.maxSuccess = count(150);
  p.disableShrinking = true;  // the case is a function of one seed: nothing to shrink
  return p;
}

template <class Fn>
void check_property(const char* name, Fn fn) {
  rc::detail::TestMetadata meta;
  meta.id = name;
  meta.description = name;
  const auto result = rc::detail::checkTestable(fn, meta, property_params());
  if (!result.template is<rc::detail::SuccessResult>()) {
    std::ostringstream s;
    rc::detail::printResultMessage(result, s);
    ADD_FAILURE() << s.str();
  }
}

// A random pair from one seed: world vertices, any shape kinds, any gap.
BodyPair pair_from_seed(std::uint64_t seed) {
  Rng rng(seed);
  const Points a = posed(rng, random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 40)));
  const Points b0 = posed(rng, random_shape(rng, random_shape_kind(rng), uniform_int(rng, 4, 40)));
  const int mode = uniform_int(rng, 0, 3);
  const double gap = mode == 0 ? -uniform(rng, 0, 0.5) : mode == 1 ? log_uniform(rng, 1e-12, 1e-8) : log_uniform(rng, 1e-4, 1e2);
  return {a, place_along(a, b0, random_unit_vector(rng), gap)};
}

double band_of(const Points& a, const Points& b) {
  return kBandUlps * kUnitRoundoff * std::max(max_abs_coordinate(a), max_abs_coordinate(b));
}

TEST(DistanceProperties, SymmetricInTheBodies) {
  check_property("symmetric", [] {
    const BodyPair p = pair_from_seed(*rc::gen::arbitrary<std::uint64_t>());
    const ConvexPolytope a(p.a), b(p.b);
    for (const Algorithm alg : kAlgorithms) {
      DistanceOptions o;
      o.algorithm = alg;
      const DistanceResult ab = distance(a, Pose(), b, Pose(), o);
      const DistanceResult ba = distance(b, Pose(), a, Pose(), o);
      RC_LOG() << to_string(alg) << " d(A,B) " << describe(ab) << "\nd(B,A) " << describe(ba) << "\nconst Points a = "
               << format_points(p.a) << ";\nconst Points b = " << format_points(p.b) << ";\n";
      RC_ASSERT(within_bound(ab.distance, squared(ba.distance), kRelativeTolerance,
                             band_of(p.a, p.b)));
    }
  });
}

TEST(DistanceProperties, InvariantUnderCommonRigidMotion) {
  // d(A, B) against d(T A, T B) with T applied in double to both vertex
  // arrays, and against the same T given as both poses. Each answer is
  // within a band of its own exact distance, and rounding T moves every
  // vertex by at most pose_slack(): the answers agree within
  // 1e-12 d + band (before) + band (after) + slack of both bodies.
  check_property("rigid motion", [] {
    Rng rng(*rc::gen::arbitrary<std::uint64_t>());
    const BodyPair p = pair_from_seed(rng());
    const Pose t(random_quaternion(rng), uniform(rng, 0, 1e3) * random_unit_vector(rng));
    const Points ta = transformed(p.a, t), tb = transformed(p.b, t);
    const ConvexPolytope a(p.a), b(p.b), moved_a(ta), moved_b(tb);
    const double tol = band_of(p.a, p.b) + band_of(ta, tb) + pose_slack(p.a, t) + pose_slack(p.b, t);
    for (const Algorithm alg : kAlgorithms) {
      DistanceOptions o;
      o.algorithm = alg;
      const DistanceResult d0 = distance(a, Pose(), b, Pose(), o);
      const DistanceResult d1 = distance(moved_a, Pose(), moved_b, Pose(), o);
      const DistanceResult d2 = distance(a, t, b, t, o);
      RC_LOG() << to_string(alg) << " before " << describe(d0) << "\nmoved " << describe(d1) << "\nposed "
               << describe(d2) << "\nconst Points a = " << format_points(p.a) << ";\nconst Points b = "
               << format_points(p.b) << ";\nT = " << format_pose(t) << "\nmoved:\nconst Points a = "
               << format_points(ta) << ";\nconst Points b = " << format_points(tb) << ";\n";
      const mpq_class d0_sq = squared(d0.distance);
      RC_ASSERT(within_bound(d1.distance, d0_sq, kRelativeTolerance, tol));
      RC_ASSERT(within_bound(d2.distance, d0_sq, kRelativeTolerance, tol));
    }
  });
}

TEST(DistanceProperties, IterationCapHolds) {
  // With the default cap nothing generated reaches it; with a cap of 2 the
  // answer says so when it stops early and its bounds stay ordered.
  check_property("iteration cap", [] {
    const BodyPair p = pair_from_seed(*rc::gen::arbitrary<std::uint64_t>());
    const ConvexPolytope a(p.a), b(p.b);
    for (const Algorithm alg : kAlgorithms) {
      DistanceOptions o;
      o.algorithm = alg;
      const DistanceResult r = distance(a, Pose(), b, Pose(), o);
      RC_LOG() << to_string(alg) << " " << describe(r) << "\nconst Points a = " << format_points(p.a)
               << ";\nconst Points b = " << format_points(p.b) << ";\n";
      RC_ASSERT(r.iterations <= o.max_iterations);
      RC_ASSERT(r.status != Status::iteration_cap);
      o.max_iterations = 2;
      const DistanceResult capped = distance(a, Pose(), b, Pose(), o);
      RC_ASSERT(capped.iterations <= 2);
      RC_ASSERT(capped.lower_bound <= capped.distance);
      RC_ASSERT(std::isfinite(capped.distance));
    }
  });
}

TEST(DistanceCertificate, SeparationCertificateRejectsAWrongPair) {
  // The check itself must be able to fail: unit cubes 1 apart along x,
  // with the right closest points it passes; with point_a moved to a far
  // corner of A (still in A, but not closest) the plane tilts and A pokes
  // through it.
  const Points a = cube(1.0), b = translated(cube(1.0), Vec3(2, 0, 0));
  const double tol = kBandUlps * kUnitRoundoff * 2.5;
  DistanceResult r;
  r.point_a = Vec3(0.5, 0, 0);
  r.point_b = Vec3(1.5, 0, 0);
  EXPECT_EQ(separation_certificate(r, a, b, tol), "");
  r.point_a = Vec3(0.5, -0.5, -0.5);
  r.point_b = Vec3(1.5, 0.5, 0.5);
  EXPECT_NE(separation_certificate(r, a, b, tol), "");
}

// ---------------------------------------------------------------------------
// Named regression tests: the peers' known failure cases (FCL, libccd,
// Bullet report wrong distances or contact states on these), each run
// through all three algorithms against the oracle.

bool run_named(const char* name, const Points& a, const Points& b) {
  AccuracySuite suite(name);
  return suite.run({name, a, b, {}, {}});
}

TEST(DistanceRegression, KissingBoxesWithTinyRotatedGap) {
  // Two unit boxes face to face, one turned by 1e-7 rad about a random
  // axis, 1e-9 apart: the closest features are a vertex or edge against a
  // nearly parallel face, where GJK-type simplices become flat.
  Rng rng(11);
  AccuracySuite suite("kissing_boxes");
  for (int i = 0; i < 10; ++i) {
    const Points a = cube(1.0);
    const Points b0 = transformed(cube(1.0), random_small_rotation(rng, 1e-7), Vec3::Zero());
    const Points b = place_along(a, b0, Vec3::UnitX(), 1e-9);
    const std::optional<Points> tight = tighten_to_gap(suite.oracle(), a, b, 1e-9);
    ASSERT_TRUE(tight);
    suite.run({"kissing_boxes", a, *tight, {}, {}});
  }
  EXPECT_EQ(suite.tally("kissing_boxes").violations, 0);
}

TEST(DistanceRegression, LongThinTriangleAsClosestFeature) {
  // A triangle 1000 long and 1e-3 wide (a flat body), and a small cube
  // above the middle of its long side: the closest feature is the thin
  // triangle itself, where a*c - b*b of the kernels nearly cancels.
  const Points tri{Vec3(-500, 0, 0), Vec3(500, 0, 0), Vec3(0, 1e-3, 0)};
  EXPECT_TRUE(run_named("long_thin_triangle_cube", tri, translated(cube(0.01), Vec3(3.7, 0.0004, 0.25))));
  EXPECT_TRUE(run_named("long_thin_triangle_point", tri, {Vec3(-123.4, 0.0002, 1e-6)}));
  Rng rng(12);
  const Mat3 r = random_rotation(rng);
  EXPECT_TRUE(run_named("long_thin_triangle_rotated", transformed(tri, r, Vec3::Zero()),
                        transformed({Vec3(17.0, 0.0005, 0.01)}, r, Vec3::Zero())));
}

TEST(DistanceRegression, BoxesOfSize5And02) {
  // A box of edge 5 and one of edge 0.2 in many orientations and gaps.
  Rng rng(13);
  AccuracySuite suite("boxes_5_02");
  for (int i = 0; i < 40; ++i) {
    const Points a = posed(rng, cube(5.0));
    const Points b0 = posed(rng, cube(0.2));
    const double gap = (i % 2) ? log_uniform(rng, 1e-12, 1e-6) : log_uniform(rng, 1e-3, 1.0);
    const Points b = place_along(a, b0, random_unit_vector(rng), gap);
    const std::optional<Points> tight = tighten_to_gap(suite.oracle(), a, b, gap);
    ASSERT_TRUE(tight);
    suite.run({"boxes_5_02", a, *tight, {}, {}});
  }
  EXPECT_EQ(suite.tally("boxes_5_02").violations, 0);
}

// Issue 9: witness features came from two definitions with different
// fallbacks, GJK's and the hybrid's. On the paper's cubes (a cube of edge
// 1e42 at 1e29, about 6 bands, from one of edge 1e24) GJK's simplex kept a
// sliver of weight on a vertex off the closest face, and GJK and Enhanced
// GJK reported their heaviest vertex, 1e42 away from their closest point
// (208 wrong features in the accuracy suite); the hybrid's triangle of
// support points crossed the big cube within rounding of its face. One rule
// now (src/narrowphase/witness_features.h): where the algorithms' closest points agree
// within the band, so do their features, and they hold the points.
TEST(DistanceRegression, WitnessFeaturesAgreeAcrossAlgorithms) {
  ExactOracle oracle;
  Rng rng(1998);
  int compared = 0;
  for (int i = 0; i < 20; ++i) {
    const BodyPair p = paper_cubes(rng);
    const std::optional<Points> b = tighten_to_gap(oracle, p.a, p.b, kPaperCubeGap);
    ASSERT_TRUE(b);
    const ConvexPolytope pa(p.a);
    const ConvexPolytope pb(*b);
    const double band =
        kBandUlps * kUnitRoundoff * std::max(max_abs_coordinate(p.a), max_abs_coordinate(*b));
    std::array<DistanceResult, kAlgorithms.size()> r;
    for (std::size_t k = 0; k < kAlgorithms.size(); ++k) {
      DistanceOptions options;
      options.algorithm = kAlgorithms[k];
      r[k] = distance(pa, Pose{}, pb, Pose{}, options, nullptr);
      ASSERT_EQ(r[k].status, Status::separated) << to_string(kAlgorithms[k]);
    }
    const auto same = [](const Feature& x, const Feature& y) {
      return x.type == y.type && x.vertices == y.vertices && x.face == y.face;
    };
    for (std::size_t k = 1; k < kAlgorithms.size(); ++k) {
      if ((r[k].point_a - r[0].point_a).norm() > band ||
          (r[k].point_b - r[0].point_b).norm() > band)
        continue;
      ++compared;
      EXPECT_TRUE(same(r[k].feature_a, r[0].feature_a) && same(r[k].feature_b, r[0].feature_b))
          << "case " << i << ": " << to_string(kAlgorithms[k]) << "\n"
          << describe(r[k]) << "\nhybrid:\n"
          << describe(r[0]);
    }
  }
  EXPECT_GT(compared, 20);
}

TEST(DistanceRegression, StackedCubesSharingAFaceTouch) {
  // [0,1]^3 and [0,1]^2 x [1,2]: the shared face is exact contact, d* = 0;
  // the status must not be separated. Also under a common rotation (the
  // shared vertices stay identical doubles, so contact stays exact).
  const Points a = translated(cube(1.0), Vec3::Constant(0.5));
  const Points b = translated(cube(1.0), Vec3(0.5, 0.5, 1.5));
  EXPECT_TRUE(run_named("stacked_cubes", a, b));
  Rng rng(14);
  const Mat3 r = random_rotation(rng);
  EXPECT_TRUE(run_named("stacked_cubes_rotated", transformed(a, r, Vec3::Zero()), transformed(b, r, Vec3::Zero())));
  // Shifted half a cube sideways: a shared half face.
  EXPECT_TRUE(run_named("stacked_cubes_shifted", a, translated(b, Vec3(0.5, 0.25, 0))));
}

TEST(DistanceRegression, SeparatedJustAboveTheBand) {
  // Unit cubes [0,1]^3 and [1+g, 2+g] x [0,1]^2 with g = 1.5 bands
  // (R = 2): d* = g exactly, every algorithm computes it exactly, so the
  // status must be separated. (2026-11-21: all three said touching, their
  // contact band being taken from a bound on R up to sqrt(3) too large.)
  const double g = 1.5 * kBandUlps * kUnitRoundoff * 2.0;
  const Points a = translated(cube(1.0), Vec3::Constant(0.5));
  EXPECT_TRUE(run_named("just_above_band", a, translated(a, Vec3(1 + g, 0, 0))));
}

TEST(DistanceRegression, ParallelClosestFaces) {
  // Faces exactly parallel and overlapping in a region, at gaps 1e-3 and
  // 1e-12: every point of the overlap is a closest point, so the answer is
  // a whole set and the algorithms must pick a consistent pair.
  const Points a = box(Vec3(1, 2, 0.5));
  for (const double gap : {1e-3, 1e-12}) {
    const Points b = translated(box(Vec3(0.7, 0.4, 0.3)), Vec3(0.3, 1.0, 0.5 + 0.3 + gap));
    EXPECT_TRUE(run_named(gap > 1e-6 ? "parallel_faces_1e-3" : "parallel_faces_1e-12", a, b));
  }
}

TEST(DistanceRegression, CloudFarFromTheOriginKeepsItsHull) {
  // Found by ScalesAndFarFromOrigin (2026-11-21): 23 points of a cloud of
  // size ~5e11 some 4.7e13 from the origin. The polytope kept 5 hull
  // vertices and left 15 input points up to 1e11 outside its hull, so all
  // three algorithms answered 4.7855e13 (with a "certified" lower bound
  // equal to it) for the distance from the origin, d* = 4.7792e13.
  const Points cloud = test::cloud_far_from_origin_23();
  EXPECT_TRUE(run_named("cloud_far_from_origin", {Vec3(0, 0, 0)}, cloud));
}

TEST(DistanceRegression, MovedFlatPolygonsKeepTheirHulls) {
  // Found by InvariantUnderCommonRigidMotion (2026-11-21): two flat
  // polygons (38 and 13 points, size ~2) moved together by a rotation and
  // a translation of ~420. Unmoved, all three algorithms find d* = 0.38162;
  // moved, the polytopes (now full-dimensional by rounding) leave input
  // points up to 0.04 outside their hulls and all three answer 0.39055.
  const Points a = moved_flat_polygon_38();
  const Points b{Vec3(-19.948076569969334, 284.02284624653043, -416.3046874447283),
                Vec3(-21.458296484550715, 283.32638998549879, -416.11565083842339),
                Vec3(-21.389884705755655, 283.30043366992504, -416.08102358165678),
                Vec3(-21.164284199930893, 284.58946175939445, -416.99927270128279),
                Vec3(-20.838377215309258, 284.85818784518557, -417.12901631794972),
                Vec3(-21.011611014920906, 283.24683739834728, -415.95709732659049),
                Vec3(-21.455469811682622, 284.66629345478879, -417.1213870686924),
                Vec3(-20.350920158281159, 283.69145208338182, -416.14489358675138),
                Vec3(-21.706547896215753, 283.48899652906317, -416.29269136447903),
                Vec3(-20.077488122200776, 284.55725904950901, -416.73469393705022),
                Vec3(-21.892196520885072, 284.07170196412847, -416.77140828731393),
                Vec3(-20.950389199079449, 284.24675999960994, -416.69456745397866),
                Vec3(-20.240275219488407, 283.54555886455148, -416.01084360240884)};
  EXPECT_TRUE(run_named("moved_flat_polygons", a, b));
}

TEST(DistanceRegression, PointNearANeedle) {
  // Found by DegenerateShapes (2026-11-21): a point 2.4e-13 from a needle
  // (5 points, 2 long, 4e-9 thick). The hybrid stopped on the edge
  // [0 1] at 6.0e-10 with lower bound 0 after 2 iterations; both GJKs
  // found d* to 0.01 u R.
  const Points a{Vec3(-0.093249359488972894, -0.013550249080565874, 0)};
  const Points b{Vec3(-0.69089681648325885, -0.013550248903682394, 5.7753080096034637e-10),
                Vec3(1.3091031835167413, -0.013550248903682394, 5.7753080096034637e-10),
                Vec3(1.0082165423143632, -0.013550249406037773, -1.0639477632246042e-09),
                Vec3(-0.12503958944525853, -0.013550248625723738, 2.548473543306784e-09),
                Vec3(1.0853006518400046, -0.013550251973242389, 4.1503033787471111e-09)};
  EXPECT_TRUE(run_named("point_near_needle", a, b));
}

TEST(DistanceRegression, PointOnTheSurfaceOfANeedle) {
  // Found while testing compound bodies (2026-11-22): hull A is a needle
  // (8 points, 1.6 long, about 1e-9 thick: every face a sliver of sine
  // 2e-9 to 6e-8). The hybrid's closest point of A to a body B lies on A's
  // edge [3 4] up to rounding, but a one-point polytope at that point
  // queried against A came back separated at 1.7e-9 (64 u R is 1.7e-14)
  // with lower bound 0, from all three algorithms: each stopped on the
  // needle's inner diagonal [0 1], 1.7e-9 inside A, because the direction
  // from the point to a segment (XB - XA in the hybrid, the segment's
  // closest point to the origin in GJK) carried a rounding tilt of 3e-7
  // along the needle's axis, enough to make the diagonal's own ends the
  // support points. Fixed by removing the direction's component along the
  // edge (and a sliver normal's along its longest edge).
  const Points a{Vec3(0.64570826897257039, 1.0916144697291843, -2.3653994057992471),
                Vec3(0.26093063673681099, -0.34264654060582755, -1.4723259974216281),
                Vec3(0.40649011539237856, 0.19992732624482967, -1.8101712634469185),
                Vec3(0.30015071866601672, -0.19645344783991581, -1.5633562661371294),
                Vec3(0.41957581180478987, 0.24870432648957028, -1.8405433102119573),
                Vec3(0.42596359466299316, 0.27251483882812022, -1.8553694352701549),
                Vec3(0.6383927211929038, 1.0643457221086727, -2.3484199325477353),
                Vec3(0.32908813721908725, -0.088589033091828806, -1.6305203564892963)};
  const Points b{Vec3(2.0906222377249106, -0.9092490457813569, -3.7248656828888445),
                Vec3(1.8152240608591552, -0.31843705773102737, -3.7363319564783675),
                Vec3(1.8898489869539294, -0.5483587601509452, -3.3044976449903212),
                Vec3(2.0392667377217468, -1.0577862859468361, -4.1792750991192671),
                Vec3(0.76847997780858623, -0.89646580205225534, -4.0919684834729946),
                Vec3(1.9184228561566516, -1.3301445055116932, -3.8280657960945303),
                Vec3(0.84599015254432963, -1.3783600987658717, -3.3294697676048752),
                Vec3(1.0231322361558197, -0.88012886059826734, -3.2933276778303773),
                Vec3(1.0932849052567679, -0.75859553139976255, -3.4135985609408022)};
  EXPECT_TRUE(run_named("needle_vs_body", a, b));
  // The reported point, and the one the query returns now: both on A.
  const ConvexPolytope hull_a(a);
  const ConvexPolytope hull_b(b);
  const Vec3 found = distance(hull_a, Pose(), hull_b, Pose()).point_a;
  ExactOracle oracle;
  for (const Vec3& p : {Vec3(0.40812459482325075, 0.20601984426821252, -1.8139649010790968), found}) {
    // The expected answer itself: d* is within the band (the point is on A
    // up to rounding), so touching is right and separated is wrong.
    const std::optional<ExactDistance> exact = oracle.distance({p}, a);
    ASSERT_TRUE(exact);
    EXPECT_TRUE(sqrt_at_most(exact->distance_squared, kBandUlps * kUnitRoundoff * max_abs_coordinate(a)));
    EXPECT_TRUE(run_named("point_on_needle_edge", {p}, a));
    EXPECT_TRUE(run_named("needle_edge_point", a, {p}));
  }
}

TEST(DistanceRegression, PointsOnTheSurfacesOfThinHulls) {
  // The family of PointOnTheSurfaceOfANeedle: a point on a random hull
  // triangle (inside it, on one of its edges or at a vertex, rounded to
  // doubles) against the hull, for needles and slivers down to 1e-12 thick
  // and for round bodies, turned and moved at random. d* is at most a few
  // u R, so every answer must be touching within the band.
  Rng rng(31);
  AccuracySuite suite("points_on_surfaces");
  const char* const kinds[] = {"point_on_needle", "point_on_sliver", "point_on_sphere"};
  for (int i = 0; i < count(90); ++i) {
    const int kind = i % 3;
    Points shape = kind == 0   ? needle(rng, 2.0, log_uniform(rng, 1e-12, 1e-3), uniform_int(rng, 4, 12))
                   : kind == 1 ? sliver(rng, log_uniform(rng, 1e-12, 1e-3))
                               : points_on_sphere(rng, uniform_int(rng, 4, 20));
    shape = transformed(shape, random_rotation(rng), uniform(rng, 0, 3) * random_unit_vector(rng));
    const ConvexPolytope hull(shape);
    const std::vector<std::array<std::int32_t, 3>> triangles = hull.triangles();
    if (triangles.empty()) continue;  // rounded flat: no faces to sample
    const auto& t = triangles[static_cast<std::size_t>(uniform_int(rng, 0, static_cast<int>(triangles.size()) - 1))];
    std::array<double, 3> w = {uniform(rng, 0.01, 1), uniform(rng, 0.01, 1), uniform(rng, 0.01, 1)};
    const int where = uniform_int(rng, 0, 2);  // 0: inside, 1: on an edge, 2: at a vertex
    if (where >= 1) w[static_cast<std::size_t>(uniform_int(rng, 0, 2))] = 0;
    if (where == 2) w = {1, 0, 0};
    const double sum = w[0] + w[1] + w[2];
    Vec3 p = Vec3::Zero();
    for (std::size_t k = 0; k < 3; ++k) p += (w[k] / sum) * hull.vertex(t[k]);
    suite.run({kinds[kind], {p}, shape, {}, {}});
  }
  for (const char* kind : kinds) {
    const Tally& t = suite.tally(kind);
    EXPECT_GT(t.cases, 0) << kind;
    EXPECT_EQ(t.violations, 0) << kind;
    // The generator's promise: every point is on its hull within the band.
    EXPECT_EQ(t.intersecting_or_touching + t.in_band, t.cases) << kind;
  }
}

TEST(DistanceRegression, ScalesFrom1eMinus300To1e300) {
  // Found while testing compound bodies (2026-11-22): two 12-point spheres
  // scaled by s, B moved by 3 s. From s = 1e155 on distance() raised
  // FE_INVALID (a NaN: the squares of coordinate differences overflowed,
  // inf - inf; GJK's cold-start direction, a raw difference of centroids
  // dotted with the vertices, did too); from s = 1e-200 down the hybrid
  // reported touching at distance 0 for bodies a unit of their size apart
  // (the squares underflowed), and at 1e-160 it was off by 2e-5 (squares
  // in subnormals). Fixed by running the hybrid on coordinates scaled by a
  // power of two outside 2^+-64 (GJK already works in such a unit), and by
  // refusing coordinates beyond 2^1018, where differences may overflow.
  // Far apart, nearly touching (d* a few bands) and overlapping, all three
  // algorithms, cold and warm, against the oracle's exact d*. (Checked
  // here rather than by AccuracySuite, whose separation certificate bounds
  // its slack in double: products of 1e-300 sizes underflow to 0 there.)
  Rng rng(41);
  ExactOracle oracle;
  const Points a0 = points_on_sphere(rng, 12);
  const Points b0 = points_on_sphere(rng, 12);
  int cases = 0;
  int near_cases = 0;
  // Every 25 decades; every 75 under ASan, where the oracle is slow.
  constexpr int kDecades = kUnderSanitizers ? 75 : 25;
  for (int e = -300; e <= 300; e += kDecades) {
    const double s = std::pow(10.0, e);
    const Points a = scaled(a0, s);
    const Points b = scaled(b0, s);
    const double r = 2 * s;  // about R of the placed bodies (radius 1)
    const double gap = 4 * kBandUlps * kUnitRoundoff * r;
    const Points near = place_along(a, b, Vec3(1, 2, 2) / 3, gap);
    const std::optional<Points> tight = tighten_to_gap(oracle, a, near, gap);
    const std::array<Points, 3> placed = {translated(b, Vec3(3 * s, 0, 0)), translated(b, Vec3(s, 0.5 * s, 0)),
                                          tight ? *tight : near};
    const ConvexPolytope pa(a);
    for (const Points& bk : placed) {
      const std::optional<ExactDistance> exact = oracle.distance(a, bk);
      ASSERT_TRUE(exact);
      const double band = kBandUlps * kUnitRoundoff * std::max(max_abs_coordinate(a), max_abs_coordinate(bk));
      const bool separated = !sqrt_at_most(exact->distance_squared, band);
      const ConvexPolytope pb(bk);
      ++cases;
      if (separated && sqrt_at_most(exact->distance_squared, 16 * band)) ++near_cases;
      for (const Algorithm alg : kAlgorithms) {
        DistanceOptions options;
        options.algorithm = alg;
        DistanceCache cache;
        for (int pass = 0; pass < 2; ++pass) {  // cold, then warm
          const DistanceResult res = distance(pa, Pose(), pb, Pose(), options, &cache);
          SCOPED_TRACE(std::string(to_string(alg)) + (pass ? " warm" : " cold") + " at s = 1e" + std::to_string(e) +
                       ", d* = " + std::to_string(exact->distance()) + ": " + describe(res));
          ASSERT_TRUE(std::isfinite(res.distance) && std::isfinite(res.lower_bound) && res.point_a.allFinite() &&
                      res.point_b.allFinite() && res.normal.allFinite());
          EXPECT_EQ(res.status == Status::separated, separated);
          EXPECT_NE(res.status, Status::iteration_cap);
          EXPECT_TRUE(within_bound(res.distance, exact->distance_squared, kRelativeTolerance, band));
          // Intersecting: the deepest points, the depth apart (types.h).
          const double apart = res.status == Status::intersecting ? res.depth : res.distance;
          EXPECT_TRUE(within_bound(apart, exact_squared_distance(res.point_a, res.point_b), kRelativeTolerance, band));
          EXPECT_LE(res.lower_bound, res.distance);
          EXPECT_TRUE(at_most_sqrt(res.lower_bound - band, exact->distance_squared));
          const std::optional<mpq_class> da = oracle.point_distance_squared(res.point_a, a);
          const std::optional<mpq_class> db = oracle.point_distance_squared(res.point_b, bk);
          EXPECT_TRUE(da && sqrt_at_most(*da, band));
          EXPECT_TRUE(db && sqrt_at_most(*db, band));
        }
      }
    }
  }
  // The nearly touching placements really are a few bands apart.
  EXPECT_GT(near_cases, cases / 6);
}

TEST(DistanceRegression, CoordinatesWhoseDifferencesOverflowAreRefused) {
  // Bodies near +-1.7e308: B - A overflows, which used to come back as
  // NaN; the query refuses them by name. Just inside the limit the answer
  // is finite and right.
  const Points a = translated(cube(1e300), Vec3(-1.7e308, 0, 0));
  const Points b = translated(cube(1e300), Vec3(1.7e308, 0, 0));
  const ConvexPolytope pa(a), pb(b);
  for (const Algorithm alg : kAlgorithms) {
    DistanceOptions options;
    options.algorithm = alg;
    EXPECT_THROW(distance(pa, Pose(), pb, Pose(), options), InvalidInput);
    const ConvexPolytope unit(cube(1.0));
    EXPECT_THROW(distance(unit, Pose::from_translation(Vec3(0, -1.7e308, 0)), unit,
                          Pose::from_translation(Vec3(0, 1.7e308, 0)), options),
                 InvalidInput);
    const double s = 0x1p1016;
    const DistanceResult r = distance(unit, Pose::from_translation(Vec3(-s, 0, 0)), unit,
                                      Pose::from_translation(Vec3(s, 0, 0)), options);
    EXPECT_EQ(r.status, Status::separated);
    EXPECT_NEAR(r.distance / (2 * s), 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace proxima::test
