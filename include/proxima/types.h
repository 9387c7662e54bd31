// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// Layer 1: the vocabulary every other layer speaks. Eigen aliases and poses
// (pose.h), feature ids, statuses and results.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "proxima/pose.h"

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
  iteration_cap,  // the loop stopped at options.max_iterations; bounds still valid
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
  // B's pose in A's frame at the hybrid's last query (zero: none), so that
  // a pose far from it starts cold instead of from a stale pair.
  Mat3 rotation = Mat3::Zero();
  Vec3 translation = Vec3::Zero();

  bool is_cold() const { return vertices_a[0] < 0 && hint_a < 0 && contact_a[0] < 0; }
  void reset() { *this = DistanceCache{}; }
};

struct DistanceResult {
  Status status = Status::separated;
  double distance = 0.0;        // upper bound: |point_a - point_b|
  double lower_bound = 0.0;     // certified: lower_bound <= exact distance (up to rounding)
  Vec3 point_a = Vec3::Zero();  // closest point on A, world frame
  Vec3 point_b = Vec3::Zero();  // closest point on B, world frame
  Vec3 normal = Vec3::UnitX();  // unit, from A towards B
  Feature feature_a;
  Feature feature_b;
  int iterations = 0;
  // Whether a second algorithm ran in this query: for the hybrid, Enhanced
  // GJK's contact classification (touching or intersecting; not when a
  // cached contact tetrahedron re-certified intersection in O(1)) or its
  // cross-check of an answer the hybrid could not certify. Always false for
  // GJK and Enhanced GJK.
  bool second_algorithm = false;
};

}  // namespace proxima
