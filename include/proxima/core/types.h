// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// core layer: the vocabulary every other layer speaks. Eigen aliases and poses
// (pose.h), feature ids, statuses and results.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include "proxima/core/pose.h"

namespace proxima {

// The shared rules of the accuracy standard (DESIGN.md), defined once.
//
// The contact band: a distance at or below 64 u R (plus the caller's
// absolute tolerance Ae) is indistinguishable from contact for doubles of
// magnitude R, R being the largest coordinate magnitude of the two bodies in
// the frame of the query.
inline constexpr double kContactBandUlps = 64.0;
inline double contact_band(double magnitude, double absolute_tolerance = 0.0) {
  return kContactBandUlps * kUnitRoundoff * magnitude + absolute_tolerance;
}

// The magnitude bound: an upper bound on the largest coordinate magnitude of
// a body whose coordinates in its own frame are at most `scale` (|y|_inf),
// placed at `pose`: |R y + t|_inf <= |t|_inf + |y|_2 <= |t|_inf + sqrt(3)
// scale. O(1).
inline double magnitude_bound(const Pose& pose, double scale) {
  return pose.translation.cwiseAbs().maxCoeff() + std::sqrt(3.0) * scale;
}

// Largest coordinate magnitude (bounded as above) accepted. The algorithms
// take differences of coordinates and map B into A's frame (|R y + t| up
// to sqrt(3) |y| + |t|), and the hybrid and GJK then work in units of a
// power of two near that magnitude; beyond 2^1018 (2.8e306) those
// intermediate values can overflow to inf, and differences of infinities
// are NaN. Such input is refused by name instead of answered with NaN.
inline constexpr double kMaxMagnitude = 0x1p1018;

// Which kind of boundary piece of a hull realizes a closest point.
enum class FeatureType : std::uint8_t { vertex, edge, face };

// A witness feature on one hull: its type, the hull vertex ids that span the
// closest point (one for a vertex, two for an edge, up to three of a face's
// vertices for a face) and, for a face, the hull's face id.
struct Feature {
  FeatureType type = FeatureType::vertex;
  std::array<std::int32_t, 3> vertices = {-1, -1, -1};
  std::int32_t face = -1;

  int vertex_count() const {
    return vertices[2] >= 0 ? 3 : vertices[1] >= 0 ? 2 : vertices[0] >= 0 ? 1 : 0;
  }
};

enum class Status : std::uint8_t {
  separated,      // distance > 64 u R: the hulls do not touch
  touching,       // distance <= 64 u R: in contact at machine precision
  intersecting,   // the hulls overlap; distance reported as 0
  iteration_cap,  // undecided, bounds still valid: the loop stopped at
                  // options.max_iterations, or (GJK, Enhanced GJK) rounding hid an
                  // answer more than 16 bands from contact that it could not certify
};

inline const char* to_string(Status s) {
  switch (s) {
    case Status::separated:
      return "separated";
    case Status::touching:
      return "touching";
    case Status::intersecting:
      return "intersecting";
    case Status::iteration_cap:
      return "iteration_cap";
  }
  return "unknown";
}

inline const char* to_string(FeatureType t) {
  switch (t) {
    case FeatureType::vertex:
      return "vertex";
    case FeatureType::edge:
      return "edge";
    case FeatureType::face:
      return "face";
  }
  return "unknown";
}

// Which algorithm answers a distance query. All three run behind the same
// call so that every comparison is side by side.
enum class Algorithm : std::uint8_t {
  hybrid,        // the paper: feature pairs, closed-form local distances, support updates
  gjk,           // classic GJK, brute-force support, cold simplex
  enhanced_gjk,  // Cameron's: hill-climbing support, last simplex as warm start
};

inline const char* to_string(Algorithm a) {
  switch (a) {
    case Algorithm::hybrid:
      return "hybrid";
    case Algorithm::gjk:
      return "gjk";
    case Algorithm::enhanced_gjk:
      return "enhanced_gjk";
  }
  return "unknown";
}

// The options of a distance query. Convex, rounded and compound bodies
// honour every field. A query with a triangle mesh (distance of two
// TriangleMeshes, a Body pair with a mesh, their margin queries, a time of
// impact or a scene pair with a mesh, a robot's mesh geometry) solves its
// triangle pairs in closed form and stops its search at its hull's bound to
// the relative tolerance 1e-12: it honours absolute_tolerance, and refuses
// with InvalidInput (naming the field and the triangle mesh) any other
// algorithm, relative_tolerance or max_iterations than the defaults;
// distance(TriangleMesh, ConvexPolytope), whose leaves are the convex query,
// honours algorithm and max_iterations there and refuses only another
// relative_tolerance. No mesh query computes a depth (penetration: below).
struct DistanceOptions {
  Algorithm algorithm = Algorithm::hybrid;
  // Re of the paper's eq. 19: stop when distance - lower_bound <= Re * distance.
  double relative_tolerance = 1e-12;
  // Ae of eq. 19, added to the machine-precision contact band 64 u R: a
  // distance at or below it is reported as touching.
  double absolute_tolerance = 0.0;
  // Hard cap on iterations; a query that reaches it says so in its status.
  // It bounds each stage of a query, not their sum: the hybrid's loop, and
  // then Enhanced GJK's contact classification or its cross-check of an
  // uncertified answer (DistanceResult::second_algorithm), each get the full
  // cap; a touching answer re-solved with the band of the exact R runs its
  // stages once more. DistanceResult::iterations counts the hybrid's
  // iterations plus Enhanced GJK's where its answer is the one reported (an
  // intersection it certified, or the closer pair of the cross-check).
  int max_iterations = 64;
  // Whether an intersecting answer gets its penetration depth (the signed
  // distance's negative side, proxima/detail/penetration/penetration.h): the deepest points,
  // the separating normal and the Minkowski face's features. Costs nothing
  // for separated or touching pairs (the depth is computed only after the
  // algorithm answered intersecting or touching; a tracked pair that was
  // penetrating tries its cached depth first, once, and when that certifies
  // the overlap the algorithm does not run). False: an intersecting answer is
  // reported as without it, distance 0, signed_distance() 0 in the
  // certificate [-infinity, 0] (depth_upper_bound +infinity: not computed);
  // for a caller that only needs the status (a scene of resting contacts).
  // The default differs in SceneOptions::distance, which turns it off
  // (proxima/scene/scene.h says why); the margin queries never compute a
  // depth (their answer has none), and the mesh queries answer an overlap
  // as with false (MeshResult).
  bool penetration = true;
  // Full relative accuracy (docs/accuracy.md): a separated or touching
  // answer at any distance has its witness feature pair's distance
  // recomputed in double-double (the placed coordinates to 2^-104 of R)
  // with a certified lower bound, the support gap along the pair's normal,
  // and takes them when the two agree, so that the distance is within a
  // few ulps of the exact distance of the given doubles whenever the
  // feature pair is right, and the certificate [lower_bound, distance] is
  // that tight. An intersecting answer's depth between two convex
  // polytopes likewise: its face of A - B recomputed in double-double, the depth within a few ulps of the
  // exact depth whenever the face is the deepest, and depth_upper_bound
  // that tight (depth_lower_bound stays the algorithm's). Off (the
  // default): answers within 16 bands of touching are recomputed so, the
  // others keep the standard's absolute term 64 u R. It costs about
  // 10,000 instructions per answer, off the tracked path (an overlapping
  // pair under the option does not take the tracked depth's shortcut).
  bool extended_precision = false;
};

struct PenetrationCache;  // proxima/detail/penetration/penetration.h

namespace detail {
// Out of line (src/query/signed_distance.cpp), where PenetrationCache is complete.
PenetrationCache* new_penetration_cache();
PenetrationCache* copy_penetration_cache(const PenetrationCache& c);
void delete_penetration_cache(PenetrationCache* c) noexcept;
}  // namespace detail

// The penetration-depth state of one pair (a PenetrationCache), owned by
// its DistanceCache and allocated on the pair's first overlap, so that a
// cache of a pair that never overlapped stays one null pointer (cheap to
// copy; scenes keep one cache per pair). Value semantics: a copy is a deep
// copy (an independent cache, so that the rule "distinct caches may be used
// concurrently" holds for copies too; O(size of the state) when present,
// one null test when not); a move takes the state and leaves the source
// empty (cold for the depth).
class PenetrationState {
 public:
  PenetrationState() = default;
  PenetrationState(const PenetrationState& other)
      : cache_(other.cache_ != nullptr ? detail::copy_penetration_cache(*other.cache_) : nullptr) {}
  PenetrationState(PenetrationState&& other) noexcept
      : cache_(std::exchange(other.cache_, nullptr)) {}
  PenetrationState& operator=(const PenetrationState& other) {
    if (this != &other) {
      PenetrationState copy(other);
      std::swap(cache_, copy.cache_);
    }
    return *this;
  }
  PenetrationState& operator=(PenetrationState&& other) noexcept {
    if (this != &other) {
      PenetrationState old(std::move(*this));
      cache_ = std::exchange(other.cache_, nullptr);
    }
    return *this;
  }
  ~PenetrationState() {
    if (cache_ != nullptr) detail::delete_penetration_cache(cache_);
  }

  // Null until the pair first overlapped (or after reset()).
  PenetrationCache* get() const { return cache_; }
  // The state, allocated (cold) if there is none yet.
  PenetrationCache& get_or_create() {
    if (cache_ == nullptr) cache_ = detail::new_penetration_cache();
    return *cache_;
  }
  explicit operator bool() const { return cache_ != nullptr; }

 private:
  PenetrationCache* cache_ = nullptr;
};

// Coherence between queries of one pair, owned by the caller (Box2D's
// b2SimplexCache habit). Default-constructed means cold. Passing the same
// cache to the next query of the same pair is tracking. Ids are hull vertex
// ids; a cache from another pair or a stale one is range-checked and at worst
// makes a query slower, never wrong.
struct DistanceCache {
  // The feature pair of the last answer (hybrid) or the last simplex's
  // vertex pairs (GJK family), -1 where unused.
  std::array<std::int32_t, 4> vertices_a = {-1, -1, -1, -1};
  std::array<std::int32_t, 4> vertices_b = {-1, -1, -1, -1};
  // Support hints: the last support vertex on each body.
  std::int32_t hint_a = -1;
  std::int32_t hint_b = -1;
  // The hull faces of the last witness features (-1 for a vertex or an
  // edge), so that a tracked query whose features did not change skips the
  // face lookup.
  std::int32_t face_a = -1;
  std::int32_t face_b = -1;
  // The hybrid's contact classification (touching or intersecting): the
  // vertex pairs (a_k in A, b_k in B) of its last tetrahedron of points
  // a_k - b_k that held the origin deeper than the contact band, or of its
  // last simplex, -1 where unused. While the bodies overlap the next query
  // re-certifies that tetrahedron in O(1) instead of searching again.
  std::array<std::int32_t, 4> contact_a = {-1, -1, -1, -1};
  std::array<std::int32_t, 4> contact_b = {-1, -1, -1, -1};
  // The penetration depth's tracking state (Minkowski faces of A - B),
  // allocated when the pair first answers intersecting with
  // DistanceOptions::penetration; null for a pair that never overlapped.
  // Copying a cache copies it (see PenetrationState).
  PenetrationState penetration;
  // B's pose in A's frame at the hybrid's last query (zero: none), so that
  // a pose far from it starts cold instead of from a stale pair.
  Mat3 rotation = Mat3::Zero();
  Vec3 translation = Vec3::Zero();

  bool is_cold() const {
    return vertices_a[0] < 0 && hint_a < 0 && contact_a[0] < 0 && !penetration;
  }
  void reset() { *this = DistanceCache{}; }
};

// The answer of a query. Separated and touching answers: the closest
// points, their features and distance = |point_a - point_b|. Intersecting
// answers (with DistanceOptions::penetration, the default) report the
// penetration depth instead: the deepest points, the separating normal and
// the features of the face of the Minkowski difference A - B that realizes
// it (proxima/detail/penetration/penetration.h); distance stays 0. The signed distance ties
// both: distance when apart, minus the depth when overlapping, continuous
// through contact: signed_distance() = distance - depth.
struct DistanceResult {
  Status status = Status::separated;
  // Separated, touching, iteration cap: an upper bound on the distance,
  // |point_a - point_b|. Intersecting: 0.
  double distance = 0.0;
  // Certified: lower_bound <= exact distance (up to rounding); 0 for an
  // intersecting answer.
  double lower_bound = 0.0;
  // Separated, touching: the closest points, world frame. Intersecting: the
  // deepest points, point_b + depth * normal == point_a (up to rounding):
  // B translated by depth * normal carries point_b onto point_a, and the
  // bodies then touch. point_a lies on A's supporting plane along normal,
  // point_b on B's along -normal. Without the depth
  // (DistanceOptions::penetration false): a point of the overlap on both.
  Vec3 point_a = Vec3::Zero();
  Vec3 point_b = Vec3::Zero();
  // Unit, from A towards B, world frame. Separated: along point_b - point_a.
  // Intersecting: the direction that separates, translating B by
  // depth * normal makes the hulls touch (a plane with this normal then
  // separates them). In both cases signed_distance is
  // normal . (point_b - point_a) up to rounding (signed_distance()).
  Vec3 normal = Vec3::UnitX();
  // The hull features that realize the answer (hull ids of each body).
  // Intersecting: the two features of the Minkowski face (a face of A and a
  // vertex of B, a vertex of A and a face of B, or two edges; for a face, the
  // ids of the fan triangle that holds the witness point).
  Feature feature_a;
  Feature feature_b;
  // The penetration depth: the length of the shortest translation of B
  // after which a plane separates the hulls (they then touch), with a
  // certificate depth_lower_bound <= exact depth <= depth_upper_bound (the
  // lower bound is certified less the contact band 64 u R, the upper bound
  // is the overlap of the supports along normal plus that band, so that
  // the exact depth is inside, rounding included). Computed for intersecting answers (with
  // DistanceOptions::penetration, the default); 0, 0, 0 for separated and
  // touching ones. (With the depth, a touching answer of the algorithm is
  // checked by it: an overlap deeper than the contact band that the contact
  // classification could not certify, faces of A and B coplanar, is
  // reported intersecting with its depth.) Intersecting without the depth: 0, 0, +infinity (not
  // computed). Iteration cap: 0, 0, and when lower_bound > 0 does not
  // certify separation, the depth of the bodies' bounding balls as the
  // upper bound (the pair may overlap).
  double depth = 0.0;
  double depth_lower_bound = 0.0;
  double depth_upper_bound = 0.0;

  // The signed distance: distance when separated or touching, minus the
  // penetration depth when intersecting; continuous through contact,
  // Lipschitz 1 in the translation. Equal to normal . (point_b - point_a)
  // up to rounding. Functions of the fields above, so that a separated
  // answer pays nothing for them.
  double signed_distance() const { return distance - depth; }
  // The certificate: signed_lower_bound() <= exact signed distance <=
  // signed_upper_bound() (up to the contact band 64 u R). Separated and
  // touching: [lower_bound, distance]. Intersecting: [-depth_upper_bound,
  // -depth_lower_bound]; without the depth, [-infinity, 0].
  double signed_lower_bound() const { return lower_bound - depth_upper_bound; }
  double signed_upper_bound() const { return distance - depth_lower_bound; }

  int iterations = 0;
  // Whether a second algorithm ran in this query: for the hybrid, Enhanced
  // GJK's contact classification (touching or intersecting; not when a
  // cached contact tetrahedron re-certified intersection in O(1)) or its
  // cross-check of an answer the hybrid could not certify. Always false for
  // GJK and Enhanced GJK. The penetration depth is not counted here.
  bool second_algorithm = false;
};

}  // namespace proxima
