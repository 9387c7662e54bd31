// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// The branch and bound over piece pairs of compounds and meshes: balls,
// boxes and triangles advanced by their closing speed bounds, then the
// pairs' hulls by advance_hulls.
#include "piece_advancement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <type_traits>
#include <utility>
#include <vector>

#include "advancement.h"
#include "proxima/geometry/closest_point.h"
#include "proxima/query/compound_distance.h"
#include "proxima/query/mesh_distance.h"
#include "proxima/shape/support.h"

namespace proxima::detail::toi {

namespace {

// A ball carried by a moving body: its center in the body's frame.
struct Ball {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};

// Ball steps at most per node or piece pair before the hulls are looked at.
constexpr int kMaxBallSteps = 8;
// The balls' gap, as a fraction of their radii, below which their pair is
// taken as it is (the children's balls, or the hulls' advancement, go on
// from there): closer balls bound the hulls too loosely to be worth more
// steps.
constexpr double kBallCloseEnough = 0.25;

// Two motions' poses at the last time asked for: the candidates split from
// one node pair all start at its time.
class PosesAt {
 public:
  PosesAt(const Sweep& ma, const Sweep& mb) : ma_(&ma), mb_(&mb) {}
  const std::pair<Pose, Pose>& at(double t) {
    if (!(t == t_)) {
      t_ = t;
      poses_ = {ma_->at(t), mb_->at(t)};
    }
    return poses_;
  }

 private:
  const Sweep* ma_;
  const Sweep* mb_;
  double t_ = std::numeric_limits<double>::quiet_NaN();
  std::pair<Pose, Pose> poses_;
};

// One step of the bounds' advancement below, from t by gap / speed: t
// itself when the gap is within `close_enough` (the bounds are close: where
// they are is still a lower bound), infinity when nothing closes or the
// step passes t_end, the next time (> t) otherwise.
[[gnu::always_inline]] inline double advance_by_gap(double t, double gap, double close_enough,
                                                    double speed, double t_end) {
  if (!(gap > close_enough)) return t;
  const double never = std::numeric_limits<double>::infinity();
  if (!(speed > 0.0)) return never;
  const double next = t + gap / speed;
  if (!(next < t_end)) return never;
  return next > t ? next : t;
}

// The earliest time in [t, t_end] at which balls ba (moving with body A)
// and bb (with B) can come within `target` of each other, or infinity when
// they cannot before t_end: conservative advancement on the balls' gap
// |x_b - x_a| - radii, which closes no faster than the centers' relative
// speed, at most |v_b - v_a| + |w_a| |c_a| + |w_b| |c_b| (c the centers'
// offsets from the reference points; `speeds` holds |v_b - v_a|, |w_a|,
// |w_b|). The hulls inside the balls are no closer before that time.
// Stops early once the balls are close (kBallCloseEnough): the time
// returned is then where they are, still a lower bound.
[[gnu::always_inline]] inline double earliest_ball_contact(PosesAt& poses, const Vec3& speeds,
                                                           const Ball& ba, const Ball& bb,
                                                           double target, double t, double t_end) {
  const double speed =
      speeds[0] + speeds[1] * fast_norm(ba.center) + speeds[2] * fast_norm(bb.center);
  const double radii = ba.radius + bb.radius;
  const double never = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxBallSteps; ++step) {
    const auto& [pa, pb] = poses.at(t);
    const Vec3 xa = pa.apply(ba.center);
    const Vec3 xb = pb.apply(bb.center);
    // Off the rounding of the centers' coordinates.
    const double band =
        contact_band(std::max(xa.cwiseAbs().maxCoeff(), xb.cwiseAbs().maxCoeff()) + radii);
    const double gap = fast_norm(xb - xa) - radii - target - band;
    const double next = advance_by_gap(t, gap, kBallCloseEnough * radii, speed, t_end);
    if (!(next > t && next < never)) return next;
    t = next;
  }
  return t;
}

// A node's or a piece's bound in its body's frame: its ball, and for a
// mesh the node's box or the piece's triangle itself, far closer to what
// it holds than the ball where that is flat (a floor's triangles, and the
// boxes around them).
struct Bound {
  enum class Shape : std::uint8_t { ball, box, triangle };
  explicit Bound(const Ball& b) : ball(b) {}
  Bound(const Ball& b, Shape s, const std::array<Vec3, 3>& c) : ball(b), shape(s), corners(c) {}

  Ball ball;
  Shape shape = Shape::ball;
  std::array<Vec3, 3> corners;  // box: lo, hi; triangle: its corners (unset for a ball)

  // The distance from q (body frame) to the box or the triangle, and the
  // largest coordinate magnitude of q and of the shape (for the rounding).
  double distance_to(const Vec3& q, double& magnitude) const {
    magnitude = q.cwiseAbs().maxCoeff();
    if (shape == Shape::box) {
      magnitude =
          std::max({magnitude, corners[0].cwiseAbs().maxCoeff(), corners[1].cwiseAbs().maxCoeff()});
      return fast_norm((corners[0] - q).cwiseMax(q - corners[1]).cwiseMax(0.0));
    }
    for (const Vec3& x : corners) magnitude = std::max(magnitude, x.cwiseAbs().maxCoeff());
    const ClosestPoints<double> c =
        closest_point_triangle(q, corners[0], corners[1], corners[2], kernel_tolerance(magnitude));
    return fast_norm(c.point_b - q);
  }
};

// earliest_ball_contact where one side's bound is a box or a triangle
// (A's if both are): the gap from the other side's ball to that shape,
// dist(x_o, S) - r_o, is 1-Lipschitz in the ball's center and in the
// shape's points, which (relative to the reference point of the shape's
// body, whose translation the center's speed already counts) move at most
// at |w| (|c| + r) (the shape inside its ball, c its center): it closes no
// faster than |v_b - v_a| + |w_s| (|c_s| + r_s) + |w_o| |c_o|. The same
// rules otherwise: a lower bound on the first time the hulls inside can
// come within the target, infinity when not before t_end.
double earliest_contact(PosesAt& poses, const Vec3& speeds, const Bound& ba, const Bound& bb,
                        double target, double t, double t_end) {
  if (ba.shape == Bound::Shape::ball && bb.shape == Bound::Shape::ball)
    return earliest_ball_contact(poses, speeds, ba.ball, bb.ball, target, t, t_end);
  const bool on_a = ba.shape != Bound::Shape::ball;
  const Bound& shape = on_a ? ba : bb;
  const Ball& other = on_a ? bb.ball : ba.ball;
  const double speed = speeds[0] +
                       speeds[on_a ? 1 : 2] * (fast_norm(shape.ball.center) + shape.ball.radius) +
                       speeds[on_a ? 2 : 1] * fast_norm(other.center);
  const double never = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxBallSteps; ++step) {
    const auto& [pa, pb] = poses.at(t);
    const Pose& ps = on_a ? pa : pb;
    const Pose& po = on_a ? pb : pa;
    const Vec3 x = po.apply(other.center);
    const Vec3 q = ps.rotation.transpose() * (x - ps.translation);
    double magnitude = 0.0;
    const double d = shape.distance_to(q, magnitude);
    // Off the rounding of the center's coordinates in both frames and of
    // the distance kernel.
    const double band = contact_band(
        std::max({magnitude, x.cwiseAbs().maxCoeff(), ps.translation.cwiseAbs().maxCoeff()}) +
        shape.ball.radius + other.radius);
    const double gap = d - other.radius - target - band;
    const double next = advance_by_gap(t, gap, kBallCloseEnough * other.radius, speed, t_end);
    if (!(next > t && next < never)) return next;
    t = next;
  }
  return t;
}

// A node pair or a piece pair of two compounds, and the earliest time its
// balls allow a contact.
struct Candidate {
  double t = 0.0;
  bool pieces = false;  // a piece pair (a, b piece ids), else a node pair
  std::int32_t a = 0;
  std::int32_t b = 0;
  bool operator>(const Candidate& o) const { return t > o.t; }
};

bool is_identity(const Pose& p) {
  return p.rotation == Mat3::Identity() && p.translation == Vec3::Zero();
}

// One side of the branch and bound over piece pairs: a Body's convex
// pieces under its hierarchy, each node and piece bounded in the body's
// frame. Two kinds, each its own class so that the branch and bound is
// compiled for each pair of kinds (a compound pair pays for no mesh test):
// a compound's pieces (a convex body as its one piece) under its sphere
// tree, bounded by balls (CompoundTree); a mesh's triangles under its box
// tree (MeshTree), each triangle the flat hull of its three corners (a
// segment or a point where it is degenerate), built when its pair is first
// advanced: a mesh's surface first comes within the target where one of
// its triangles does.
class CompoundTree {
 public:
  static constexpr bool kMesh = false;
  explicit CompoundTree(const Body& body) : owner_(body.compound()), c_(owner_.get()) {}

  Ball node_bound(std::int32_t n) const {
    const CompoundBody::Node& node = c_->nodes()[static_cast<std::size_t>(n)];
    return {node.center, node.radius};
  }
  bool is_leaf(std::int32_t n) const { return c_->nodes()[static_cast<std::size_t>(n)].left < 0; }
  std::pair<std::int32_t, std::int32_t> children(std::int32_t n) const {
    const CompoundBody::Node& node = c_->nodes()[static_cast<std::size_t>(n)];
    return {node.left, node.right};
  }
  // A leaf's pieces: the ids order[first .. first + count).
  std::span<const std::int32_t> pieces(std::int32_t n) const {
    const CompoundBody::Node& node = c_->nodes()[static_cast<std::size_t>(n)];
    return c_->piece_order().subspan(static_cast<std::size_t>(node.first),
                                     static_cast<std::size_t>(node.count));
  }
  Ball piece_bound(std::int32_t p) const {
    const auto& sphere = c_->piece_sphere(p);
    return {sphere.center, sphere.radius};
  }
  // The piece's hull and its pose in the body (null: the body's frame).
  const ConvexPolytope& hull(std::int32_t p) { return *c_->piece(p).polytope; }
  const Pose* local(std::int32_t p) const {
    const Pose& pose = c_->piece(p).pose;
    return is_identity(pose) ? nullptr : &pose;
  }
  // The lowest value of n.y over the piece's points y at the body's pose
  // (n unit, world frame): the hull's support vertex along -n by hill
  // climbing (from the last one found: the same piece meets many
  // triangles).
  double lowest(std::int32_t p, const Pose& pose, const Vec3& n) {
    const CompoundPiece& piece = c_->piece(p);
    const Pose placed = pose * piece.pose;
    hint_ = support_hill_climb(*piece.polytope, -(placed.rotation.transpose() * n), hint_);
    return n.dot(placed.apply(piece.polytope->vertex(hint_)));
  }
  // A bound on the distance of the piece's points from the body's
  // reference point (its frame's origin).
  double reach(std::int32_t p) const {
    const auto& sphere = c_->piece_sphere(p);
    return sphere.center.stableNorm() + sphere.radius;
  }

 private:
  std::shared_ptr<const CompoundBody> owner_;
  const CompoundBody* c_;
  int hint_ = 0;  // lowest()'s last support vertex
};

// A triangle's radius and reach computed in doubles are off by a few u
// relative; the speed bounds need every corner inside them, so both are
// taken this hair larger (1e-12 is thousands of u, and costs nothing).
constexpr double kTriangleRadiusGrowth = 1.0 + 1e-12;

class MeshTree {
 public:
  static constexpr bool kMesh = true;
  explicit MeshTree(const Body& body) : mesh_(body.mesh().get()) {}

  Bound node_bound(std::int32_t n) const {
    // The box, and its ball: its center and half diagonal (the rounding of
    // both, a few u of the coordinates, is inside the contact band that
    // earliest_contact keeps off).
    Vec3 lo, hi;
    mesh_->box(n, lo, hi);
    return {Ball{0.5 * (lo + hi), 0.5 * (hi - lo).stableNorm()}, Bound::Shape::box, {lo, hi, hi}};
  }
  bool is_leaf(std::int32_t n) const {
    return mesh_->nodes()[static_cast<std::size_t>(n)].is_leaf();
  }
  std::pair<std::int32_t, std::int32_t> children(std::int32_t n) const {
    return {n + 1, mesh_->nodes()[static_cast<std::size_t>(n)].first_or_right};
  }
  std::span<const std::int32_t> pieces(std::int32_t n) const {
    const TriangleMesh::Node& node = mesh_->nodes()[static_cast<std::size_t>(n)];
    return mesh_->triangle_order().subspan(static_cast<std::size_t>(node.first_or_right),
                                           static_cast<std::size_t>(node.count));
  }
  Bound piece_bound(std::int32_t p) const {
    // The triangle, and its ball about its centroid (the radius a hair
    // out, for its rounding: the speed bound needs every corner inside).
    const auto corners = triangle_corners(p);
    const Vec3 center = (corners[0] + corners[1] + corners[2]) / 3.0;
    double radius = 0.0;
    for (const Vec3& x : corners) radius = std::max(radius, (x - center).stableNorm());
    return {Ball{center, radius * kTriangleRadiusGrowth}, Bound::Shape::triangle, corners};
  }
  const ConvexPolytope& hull(std::int32_t p) {
    auto it = triangles_.find(p);
    if (it == triangles_.end()) {
      const auto corners = triangle_corners(p);
      it = triangles_.emplace(p, ConvexPolytope(std::span<const Vec3>(corners))).first;
    }
    return it->second;
  }
  const Pose* local(std::int32_t) const { return nullptr; }
  double lowest(std::int32_t p, const Pose& pose, const Vec3& n) const {
    double low = std::numeric_limits<double>::infinity();
    for (const Vec3& x : triangle_corners(p)) low = std::min(low, n.dot(pose.apply(x)));
    return low;
  }
  double reach(std::int32_t p) const {
    double r = 0.0;
    for (const Vec3& x : triangle_corners(p)) r = std::max(r, x.stableNorm());
    return r * kTriangleRadiusGrowth;
  }
  std::array<Vec3, 3> triangle_corners(std::int32_t p) const {
    const TriangleMesh::Triangle& t = mesh_->triangle(p);
    return {mesh_->vertex(static_cast<int>(t[0])), mesh_->vertex(static_cast<int>(t[1])),
            mesh_->vertex(static_cast<int>(t[2]))};
  }

 private:
  const TriangleMesh* mesh_;
  // The triangles' hulls built so far (a map: references stay valid).
  std::unordered_map<std::int32_t, ConvexPolytope> triangles_;
};

const Ball& ball_of(const Ball& b) { return b; }
const Ball& ball_of(const Bound& b) { return b.ball; }

// earliest_contact for the bounds of either tree: two balls as
// earliest_ball_contact, else with the box or the triangle.
[[gnu::always_inline]] inline double earliest_of(PosesAt& poses, const Vec3& speeds, const Ball& ba,
                                                 const Ball& bb, double target, double t,
                                                 double t_end) {
  return earliest_ball_contact(poses, speeds, ba, bb, target, t, t_end);
}
template <class BA, class BB>
double earliest_of(PosesAt& poses, const Vec3& speeds, const BA& ba, const BB& bb, double target,
                   double t, double t_end) {
  const auto bound = [](const auto& x) {
    if constexpr (std::is_same_v<std::decay_t<decltype(x)>, Ball>) {
      return Bound(x);
    } else {
      return x;
    }
  };
  return earliest_contact(poses, speeds, bound(ba), bound(bb), target, t, t_end);
}

// Plane steps at most per triangle pair before its hull is built.
constexpr int kMaxPlaneSteps = 4;

// The first time from t that a mesh's triangle (piece `ps` of tree `s`,
// moving by `ms`) and a piece of the other body (`po` of `o`, moving by
// `mo`) can come within `target`, or infinity when not before t_end, by
// conservative advancement on the planes of the triangle's normal n (the
// side towards the other piece's ball): the triangle's highest corner and
// the other piece's lowest point along n bound the distance from below by
// their gap, and along a fixed n a point r from its body's reference point
// moves at most at v.n + |w x n| |r| (as the hulls' planes of
// advance_hulls). Where the triangle faces the other piece (a body landing
// on a floor) this settles most pairs before their triangle's hull is
// built, which costs more than their advancement (exact predicates on
// three coplanar points). Stops at the first step that does not, or after
// kMaxPlaneSteps: the time reached is still a lower bound.
template <class Other>
double triangle_plane_advance(const MeshTree& s, std::int32_t ps, const Sweep& ms, Other& o,
                              std::int32_t po, const Sweep& mo, const Vec3& other_center,
                              double target, double t, double t_end) {
  const auto corners = s.triangle_corners(ps);
  const Vec3 normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
  const double length = normal.stableNorm();
  if (!(length > 0.0)) return t;  // a degenerate triangle: its hull decides
  const Vec3 unit = normal / length;
  const double reach_s = s.reach(ps), reach_o = o.reach(po);
  const Vec3 vs = ms.linear_velocity(), vo = mo.linear_velocity();
  const Vec3 ws = ms.angular_velocity(), wo = mo.angular_velocity();
  const double never = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxPlaneSteps; ++step) {
    const Pose pose_s = ms.at(t), pose_o = mo.at(t);
    const std::array<Vec3, 3> placed = {pose_s.apply(corners[0]), pose_s.apply(corners[1]),
                                        pose_s.apply(corners[2])};
    const Vec3 center = pose_o.apply(other_center);
    // Off the rounding of the placed coordinates.
    const double band = contact_band(std::max(pose_s.translation.cwiseAbs().maxCoeff() + reach_s,
                                              pose_o.translation.cwiseAbs().maxCoeff() + reach_o));
    // Two normals: the triangle's, and the one from its closest point to
    // the other piece's ball center (where the triangle's plane cuts the
    // other piece beside the triangle); the longer step of the two.
    std::array<Vec3, 2> normals = {pose_s.rotation * unit, Vec3::Zero()};
    if (normals[0].dot(center - placed[0]) < 0.0) normals[0] = -normals[0];
    const Vec3 foot = closest_point_triangle(center, placed[0], placed[1], placed[2],
                                             kernel_tolerance(band / kUnitRoundoff))
                          .point_b;
    const double apart = fast_norm(center - foot);
    const int count = apart > 0.0 ? 2 : 1;
    if (count == 2) normals[1] = (center - foot) / apart;
    double longest = 0.0;
    for (int k = 0; k < count; ++k) {
      const Vec3& n = normals[static_cast<std::size_t>(k)];
      double top = -std::numeric_limits<double>::infinity();
      for (const Vec3& x : placed) top = std::max(top, n.dot(x));
      const double gap = o.lowest(po, pose_o, n) - top - target - band;
      if (!(gap > 0.0)) continue;
      const double rate =
          (vs - vo).dot(n) + fast_norm(ws.cross(n)) * reach_s + fast_norm(wo.cross(n)) * reach_o;
      if (!(rate > 0.0)) return never;
      longest = std::max(longest, gap / rate);
    }
    const double next = t + longest;
    if (!(next < t_end)) return never;
    if (!(next > t)) return t;
    t = next;
  }
  return t;
}

// Time of impact of two Bodies made of convex pieces (CompoundTree,
// MeshTree: compounds, a convex body as its one piece, meshes' triangles):
// the earliest over piece pairs of their convex advancement, by branch and
// bound over the two hierarchies. Candidates (node or piece pairs) are
// taken in order of the earliest time their moving bounds allow a contact
// (earliest_of); a node pair is split into its children's pairs, a piece
// pair is first advanced on its triangle's planes where one side is a mesh
// (triangle_plane_advance), then advanced as two hulls (from the time
// reached on, and only up to the best time found, since a later contact
// changes nothing); everything from the best time on is pruned. Each rule keeps the
// guarantee: a pruned pair cannot come within the target before the
// reported t, and every pair advanced is advanced safely.
template <class TreeA, class TreeB>
ImpactResult pieces_time_of_impact(const Body& a, const Sweep& ma, const Body& b, const Sweep& mb,
                                   const ImpactOptions& options, double tolerance, BodyCache& c) {
  TreeA ta(a);
  TreeB tb(b);
  ImpactOptions pair_options = options;
  pair_options.target_separation += a.radius() + b.radius();
  pair_options.tolerance = tolerance;
  const double target = pair_options.target_separation;

  ImpactResult best;               // separated at 1 until a pair says otherwise
  bool met = false;                // a pair's advancement stopped before the end
  CompoundCache::Entry best_pair;  // its pieces and its cache at best.t
  int iterations = 0, pairs = 0;
  // Whether a pair whose contact cannot come before t may still change the
  // answer: before the best time, or at 0 while the best is a contact at 0
  // (an overlapping pair there is the answer).
  const auto may_beat = [&](double t) {
    return t < best.t || (t == 0.0 && best.t == 0.0 && best.status == ImpactStatus::contact);
  };
  // The better of two answers at the same time: overlapping, then contact,
  // then the iteration cap.
  const auto rank = [](ImpactStatus s) {
    return s == ImpactStatus::intersecting ? 0 : s == ImpactStatus::contact ? 1 : 2;
  };

  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> queue;
  PosesAt poses(ma, mb);
  // |v_b - v_a|, |w_a|, |w_b|: the balls' speeds.
  const Vec3 speeds((mb.linear_velocity() - ma.linear_velocity()).stableNorm(),
                    fast_norm(ma.angular_velocity()), fast_norm(mb.angular_velocity()));
  const auto push = [&](Candidate k, const auto& ba, const auto& bb) {
    k.t = earliest_of(poses, speeds, ba, bb, target, k.t, best.t);
    if (may_beat(k.t)) queue.push(k);
  };
  push({0.0, false, 0, 0}, ta.node_bound(0), tb.node_bound(0));
  while (!queue.empty()) {
    const Candidate k = queue.top();
    queue.pop();
    if (!may_beat(k.t)) break;  // every later candidate starts later still
    if (k.pieces) {
      // A mesh's triangle: its planes first (triangle_plane_advance).
      double from = k.t;
      if constexpr (TreeA::kMesh) {
        from = triangle_plane_advance(ta, k.a, ma, tb, k.b, mb, ball_of(tb.piece_bound(k.b)).center,
                                      target, from, best.t);
      } else if constexpr (TreeB::kMesh) {
        from = triangle_plane_advance(tb, k.b, mb, ta, k.a, ma, ball_of(ta.piece_bound(k.a)).center,
                                      target, from, best.t);
      }
      if (!may_beat(from)) continue;
      const MovingHull ha(ta.hull(k.a), ma, ta.local(k.a));
      const MovingHull hb(tb.hull(k.b), mb, tb.local(k.b));
      DistanceCache pair_cache;
      ImpactResult r = advance_hulls(ha, hb, pair_options, tolerance, pair_cache, from, best.t);
      iterations += r.iterations;
      ++pairs;
      if (r.status != ImpactStatus::separated &&
          (r.t < best.t || (r.t == best.t && (best.status == ImpactStatus::separated ||
                                              rank(r.status) < rank(best.status))))) {
        best.t = r.t;
        best.status = r.status;
        met = true;
        best_pair = {k.a, k.b, std::move(pair_cache)};
      }
      continue;
    }
    const auto na = ta.node_bound(k.a);
    const auto nb = tb.node_bound(k.b);
    const bool leaf_a = ta.is_leaf(k.a), leaf_b = tb.is_leaf(k.b);
    if (leaf_a && leaf_b) {
      for (const std::int32_t pa : ta.pieces(k.a)) {
        const auto ba = ta.piece_bound(pa);
        for (const std::int32_t pb : tb.pieces(k.b))
          push({k.t, true, pa, pb}, ba, tb.piece_bound(pb));
      }
    } else if (leaf_b || (!leaf_a && ball_of(na).radius >= ball_of(nb).radius)) {
      const auto [left, right] = ta.children(k.a);
      for (const std::int32_t child : {left, right})
        push({k.t, false, child, k.b}, ta.node_bound(child), nb);
    } else {
      const auto [left, right] = tb.children(k.b);
      for (const std::int32_t child : {left, right})
        push({k.t, false, k.a, child}, na, tb.node_bound(child));
    }
  }

  // The answer at the best time (1 when no pair met): the Bodies' query
  // there, whose closest pair and features describe it. Between compounds
  // the pair that met seeds the query's cache (tried first, with its
  // features at that time): its distance is the first bound of the query's
  // branch and bound.
  if (met && !TreeA::kMesh && !TreeB::kMesh) {
    c.compound.piece_a = best_pair.piece_a;
    c.compound.piece_b = best_pair.piece_b;
    const auto less = [](const CompoundCache::Entry& x, const CompoundCache::Entry& y) {
      return std::pair(x.piece_a, x.piece_b) < std::pair(y.piece_a, y.piece_b);
    };
    auto& near = c.compound.near;
    if (std::is_sorted(near.begin(), near.end(), less)) {
      const auto it = std::lower_bound(near.begin(), near.end(), best_pair, less);
      if (it != near.end() && it->piece_a == best_pair.piece_a &&
          it->piece_b == best_pair.piece_b) {
        *it = std::move(best_pair);
      } else {
        near.insert(it, std::move(best_pair));
      }
    }
  }
  const Pose pose_a = ma.at(best.t);
  const Pose pose_b = mb.at(best.t);
  const BodyResult at = distance(a, pose_a, b, pose_b, options.distance, &c);
  ImpactResult out;
  out.t = best.t;
  out.status = best.status;
  out.pose_a = pose_a;
  out.pose_b = pose_b;
  out.at_t = at;
  out.piece_a = a.kind() == Body::Kind::mesh ? at.triangle_a : at.piece_a;
  out.piece_b = b.kind() == Body::Kind::mesh ? at.triangle_b : at.piece_b;
  out.iterations = iterations + 1;
  out.pairs_advanced = pairs;
  if (!met && (at.status == Status::intersecting || at.status == Status::touching ||
               at.signed_distance() <= options.target_separation + tolerance)) {
    // No pair met before 1, and the bodies are within the tolerance at 1.
    out.status = ImpactStatus::contact;
  }
  return out;
}

}  // namespace

ImpactResult advance_pieces(const Body& a, const Sweep& ma, const Body& b, const Sweep& mb,
                            const ImpactOptions& options, double tolerance, BodyCache& c) {
  const bool mesh_a = a.kind() == Body::Kind::mesh, mesh_b = b.kind() == Body::Kind::mesh;
  if (mesh_a && mesh_b)
    return pieces_time_of_impact<MeshTree, MeshTree>(a, ma, b, mb, options, tolerance, c);
  if (mesh_a)
    return pieces_time_of_impact<MeshTree, CompoundTree>(a, ma, b, mb, options, tolerance, c);
  if (mesh_b)
    return pieces_time_of_impact<CompoundTree, MeshTree>(a, ma, b, mb, options, tolerance, c);
  return pieces_time_of_impact<CompoundTree, CompoundTree>(a, ma, b, mb, options, tolerance, c);
}

}  // namespace proxima::detail::toi
