// proxima: minimum distance between convex polyhedra.
// SPDX-License-Identifier: BSD-3-Clause
//
// A scene of moving bodies: its bodies, filters and step() (scene_impl.h
// says how the state is kept).
#include "scene/scene_impl.h"

namespace proxima {

Scene::Scene(const SceneOptions& options) : impl_(std::make_unique<Impl>()) {
  detail::check_finite_non_negative(options.margin, "Scene", "options.margin");
  detail::check_at_least(options.threads, 0, "Scene", "options.threads", "0: all cores");
  detail::check_distance_options(options.distance, "Scene", "options.distance");
  impl_->options = options;
  impl_->finder = detail::make_pair_finder(options.broad_phase);
}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

BodyId Scene::add(std::shared_ptr<const ConvexPolytope> body, const Pose& pose) {
  if (!body) throw InvalidInput("Scene::add: the convex body is null");
  Impl::Body b;
  b.pose = checked_pose(pose, "Scene::add: pose of the new convex body");
  b.end = b.pose;
  if (impl_->compound_count > 0) b.compound = Impl::wrap(body);
  b.shape = std::make_unique<Impl::Shape>(Impl::Shape{proxima::Body(body), proxima::Body(body)});
  b.convex = std::move(body);
  return impl_->insert(std::move(b));
}

BodyId Scene::add(const proxima::Body& body, const Pose& pose, double padding) {
  checked_padding(padding, "Scene::add");
  // Its pairs are answered by the mesh query, which cannot honour every
  // distance option: refused as the mesh comes in, not at a later step.
  if (body.kind() == proxima::Body::Kind::mesh) {
    detail::check_mesh_options(impl_->options.distance, "Scene::add",
                               detail::MeshOptionUse::triangle_pairs, "options.distance");
  }
  if (body.kind() != proxima::Body::Kind::mesh && body.radius() == 0.0 && padding == 0.0) {
    // A plain body: the adds above, keeping the Body as given (its
    // approximation error, for body()).
    const BodyId id = body.kind() == proxima::Body::Kind::convex ? add(body.convex(), pose)
                                                                 : add(body.compound(), pose);
    impl_->bodies[slot(id)].shape = std::make_unique<Impl::Shape>(Impl::Shape{body, body});
    return id;
  }
  Impl::Body b;
  b.pose = checked_pose(pose, "Scene::add: pose of the new body");
  b.end = b.pose;
  if (body.kind() == proxima::Body::Kind::convex) {
    b.convex = body.convex();
    if (impl_->compound_count > 0) b.compound = Impl::wrap(b.convex);
  } else if (body.kind() == proxima::Body::Kind::compound) {
    b.compound = body.compound();
  }
  b.shape = std::make_unique<Impl::Shape>(Impl::Shape{body, body, padding});
  Impl::pad(b);
  const bool compound = body.kind() == proxima::Body::Kind::compound;
  if (compound && impl_->compound_count == 0) impl_->wrap_convex_bodies();
  const BodyId id = impl_->insert(std::move(b));
  if (compound) ++impl_->compound_count;
  return id;
}

void Scene::set_padding(BodyId id, double padding) {
  impl_->live_body(id, "set_padding");
  checked_padding(padding, "Scene::set_padding: " + name(id));
  Impl::Body& b = impl_->bodies[slot(id)];
  b.shape->padding = padding;
  Impl::pad(b);
}

double Scene::padding(BodyId id) const { return impl_->live_body(id, "padding").shape->padding; }

const proxima::Body& Scene::body(BodyId id) const {
  return impl_->live_body(id, "body").shape->given;
}

BodyId Scene::add(std::shared_ptr<const CompoundBody> body, const Pose& pose) {
  if (!body) throw InvalidInput("Scene::add: the compound body is null");
  const Pose checked = checked_pose(pose, "Scene::add: pose of the new compound body");
  if (impl_->compound_count == 0) impl_->wrap_convex_bodies();
  Impl::Body b;
  b.shape = std::make_unique<Impl::Shape>(Impl::Shape{proxima::Body(body), proxima::Body(body)});
  b.compound = std::move(body);
  b.pose = checked;
  b.end = checked;
  const BodyId id = impl_->insert(std::move(b));
  ++impl_->compound_count;
  return id;
}

void Scene::set_pose(BodyId id, const Pose& pose) {
  impl_->live_body(id, "set_pose");
  Impl::Body& b = impl_->bodies[slot(id)];
  b.pose = checked_pose(pose, [&] { return "Scene::set_pose: pose of " + name(id); });
  b.end = b.pose;
  b.angular.reset();
}

void Scene::set_end_pose(BodyId id, const Pose& end) {
  impl_->live_body(id, "set_end_pose");
  Impl::Body& b = impl_->bodies[slot(id)];
  b.end = checked_pose(end, [&] { return "Scene::set_end_pose: end pose of " + name(id); });
  b.angular.reset();
}

void Scene::set_velocity(BodyId id, const Vec3& linear, const Vec3& angular) {
  impl_->live_body(id, "set_velocity");
  Impl::Body& b = impl_->bodies[slot(id)];
  Motion m;
  try {
    m = Motion::from_velocity(b.pose, linear, angular);
  } catch (const InvalidInput& e) {
    throw InvalidInput("Scene::set_velocity: " + name(id) + ": " + e.what());
  }
  b.end = m.end;
  b.angular = m.angular;
}

std::optional<Vec3> Scene::angular_velocity(BodyId id) const {
  return impl_->live_body(id, "angular_velocity").angular;
}

const Pose& Scene::end_pose(BodyId id) const { return impl_->live_body(id, "end_pose").end; }

void Scene::remove(BodyId id) {
  impl_->live_body(id, "remove");
  Impl::Body& b = impl_->bodies[slot(id)];
  if (b.shape->given.kind() == proxima::Body::Kind::compound) --impl_->compound_count;
  b = Impl::Body{};
  // Its exclusions go with it: the id may be reused by a new body.
  std::erase_if(impl_->excluded, [id](std::uint64_t key) {
    return detail::pair_first(key) == id || detail::pair_second(key) == id;
  });
  impl_->finder->remove(id);
  impl_->free_ids.push_back(id);
  impl_->removed_since_step.push_back(id);
  if (impl_->sweep_finder) {
    impl_->sweep_finder->remove(id);
    impl_->removed_since_sweep.push_back(id);
  }
  --impl_->live_count;
}

void Scene::set_filter(BodyId id, const CollisionFilter& filter) {
  impl_->live_body(id, "set_filter");
  impl_->bodies[slot(id)].filter = filter;
}

const CollisionFilter& Scene::filter(BodyId id) const {
  return impl_->live_body(id, "filter").filter;
}

namespace {
// The key of the pair {a, b} of two distinct live bodies, checked.
std::uint64_t checked_pair(const Scene& scene, BodyId a, BodyId b, const char* what) {
  for (const BodyId id : {a, b}) {
    if (!scene.contains(id)) {
      throw InvalidInput(std::string("Scene::") + what + ": " + name(id) +
                         " is not in the scene (never added, or removed)");
    }
  }
  if (a == b) {
    throw InvalidInput(std::string("Scene::") + what + ": a pair needs two bodies, got " + name(a) +
                       " twice");
  }
  return detail::pair_key(std::min(a, b), std::max(a, b));
}
}  // namespace

void Scene::exclude_pair(BodyId a, BodyId b) {
  const std::uint64_t key = checked_pair(*this, a, b, "exclude_pair");
  auto& excluded = impl_->excluded;
  const auto at = std::lower_bound(excluded.begin(), excluded.end(), key);
  if (at == excluded.end() || *at != key) excluded.insert(at, key);
}

void Scene::include_pair(BodyId a, BodyId b) {
  const std::uint64_t key = checked_pair(*this, a, b, "include_pair");
  auto& excluded = impl_->excluded;
  const auto at = std::lower_bound(excluded.begin(), excluded.end(), key);
  if (at != excluded.end() && *at == key) excluded.erase(at);
}

bool Scene::is_excluded(BodyId a, BodyId b) const {
  return impl_->excluded_key(checked_pair(*this, a, b, "is_excluded"));
}

bool Scene::tests_pair(BodyId a, BodyId b) const {
  const std::uint64_t key = checked_pair(*this, a, b, "tests_pair");
  return !impl_->excluded_key(key) &&
         impl_->groups_meet(impl_->bodies[slot(a)], impl_->bodies[slot(b)]);
}

bool Scene::contains(BodyId id) const {
  return id >= 0 && slot(id) < impl_->bodies.size() && impl_->bodies[slot(id)].live;
}

const Pose& Scene::pose(BodyId id) const { return impl_->live_body(id, "pose").pose; }

std::vector<BodyId> Scene::body_ids() const {
  std::vector<BodyId> ids;
  ids.reserve(static_cast<std::size_t>(impl_->live_count));
  for (std::size_t k = 0; k < impl_->bodies.size(); ++k) {
    if (impl_->bodies[k].live) ids.push_back(static_cast<BodyId>(k));
  }
  return ids;
}

int Scene::body_count() const { return impl_->live_count; }

const SceneOptions& Scene::options() const { return impl_->options; }

std::span<const ClosePair> Scene::step() {
  Impl& s = *impl_;
  s.find_candidates();
  const double margin = s.options.margin;
  s.stats.convex_queries = s.narrow_phase(
      s.results, s.close, [&s](Impl::PairState& state, ClosePair& p) { s.query_into(state, p); },
      [margin](const ClosePair& p) { return is_close(p.result, margin); });
  s.stats.close_pairs = static_cast<int>(s.close.size());
  return s.close;
}

const SceneStats& Scene::stats() const { return impl_->stats; }

}  // namespace proxima
