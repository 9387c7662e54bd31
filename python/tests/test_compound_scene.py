"""Tests of the Python bindings of compound bodies and scenes.

The C++ tests check the algorithms (tests/query/compound_test.cpp,
tests/scene/scene_test.cpp); these check what the binding adds: argument
conversion, ownership across the language boundary, errors, and that each
fast call agrees with its slow twin as seen from Python.
"""

import gc

import numpy as np
import pytest

import proxima


def random_compound(rng, pieces, spread=3.0):
    """A compound of `pieces` random convex pieces around the origin."""
    return proxima.CompoundBody(
        [rng.normal(size=(int(rng.integers(8, 40)), 3)) * 0.5 + rng.uniform(-spread, spread, 3)
         for _ in range(pieces)])


def quaternion(rng):
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


def tolerance(*bodies):
    """The accuracy standard: 64 u R, R of the placed vertices (generous R here)."""
    return 64 * 2.0**-53 * max(10.0, *(b.scale + 20.0 for b in bodies))


# --- CompoundBody -------------------------------------------------------------


def test_pieces_from_polytopes_points_and_posed_pairs():
    rng = np.random.default_rng(1)
    hull = proxima.ConvexPolytope(rng.normal(size=(20, 3)))
    body = proxima.CompoundBody([hull, rng.normal(size=(10, 3)), (hull, proxima.Pose.from_translation((5, 0, 0)))])
    assert body.piece_count == 3 and len(body) == 3
    polytope, pose = body.piece(2)
    assert polytope.vertex_count == hull.vertex_count
    np.testing.assert_allclose(pose.translation, [5, 0, 0])
    # The sphere holds every placed vertex of every piece.
    for i in range(body.piece_count):
        p, pose = body.piece(i)
        for v in p.vertices:
            assert np.linalg.norm(pose.apply(v) - body.center) <= body.bounding_radius * (1 + 1e-12)
    with pytest.raises(IndexError):
        body.piece(3)


def test_bad_pieces_name_the_piece():
    rng = np.random.default_rng(2)
    good = rng.normal(size=(10, 3))
    bad = good.copy()
    bad[4, 1] = np.nan
    with pytest.raises(proxima.InvalidInput, match=r"pieces\[1\]"):
        proxima.CompoundBody([good, bad])
    with pytest.raises(ValueError, match=r"pieces\[0\]"):
        proxima.CompoundBody([np.zeros((4, 2))])
    with pytest.raises(proxima.InvalidInput):
        proxima.CompoundBody([])


def test_pieces_outlive_the_python_objects():
    rng = np.random.default_rng(3)
    hull = proxima.ConvexPolytope(rng.normal(size=(20, 3)))
    body = proxima.CompoundBody([hull, (hull, proxima.Pose.from_translation((4, 0, 0)))])
    del hull
    gc.collect()
    r = proxima.distance(body, None, body, proxima.Pose.from_translation((20, 0, 0)))
    assert r.status == "separated" and r.distance > 0


def test_compound_distance_equals_its_twin_and_tracking_equals_cold():
    rng = np.random.default_rng(4)
    a = random_compound(rng, 12)
    b = random_compound(rng, 7)
    cache = proxima.CompoundCache()
    assert cache.is_cold()
    position = np.array([9.0, 0.0, 0.0])
    q_b = quaternion(rng)
    tested_tracked, tested_cold = 0, 0
    for _ in range(40):
        position += rng.normal(size=3) * 0.05
        pose_b = proxima.Pose.from_wxyz(q_b, position)
        tracked = proxima.distance(a, None, b, pose_b, cache=cache)
        cold = proxima.distance(a, None, b, pose_b)
        twin = proxima.distance_all_pairs(a, None, b, pose_b)
        assert isinstance(tracked, proxima.CompoundResult)
        assert tracked.status == twin.status
        assert abs(tracked.distance - twin.distance) <= tolerance(a, b) + 1e-12 * twin.distance
        assert abs(cold.distance - twin.distance) <= tolerance(a, b) + 1e-12 * twin.distance
        # The reported points lie on the reported pieces: the convex query of
        # those two pieces gives the same distance.
        pa, pose_pa = a.piece(tracked.piece_a)
        pb, pose_pb = b.piece(tracked.piece_b)
        world_b = proxima.Pose.from_wxyz(q_b, position) * pose_pb
        pair = proxima.distance(pa, pose_pa, pb, world_b)
        assert abs(pair.distance - tracked.distance) <= tolerance(a, b) + 1e-12 * pair.distance
        tested_tracked += tracked.pairs_tested
        tested_cold += cold.pairs_tested
    assert not cache.is_cold() and cache.near_pairs >= 1
    assert tested_tracked <= tested_cold
    assert tested_cold < 40 * a.piece_count * b.piece_count


def test_overlapping_compounds_are_intersecting():
    rng = np.random.default_rng(5)
    a = random_compound(rng, 5, spread=1.0)
    r = proxima.distance(a, None, a, proxima.Pose.from_translation((0.1, 0, 0)))
    assert r.status == "intersecting" and r.distance == 0.0


def test_load_compound_reports_each_group(tmp_path):
    path = tmp_path / "two.obj"
    cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    lines = ["o left"] + [f"v {x} {y} {z}" for x, y, z in cube] + ["v 0.5 0.5 0.5"]
    lines += ["o right"] + [f"v {x + 3} {y} {z}" for x, y, z in cube]
    path.write_text("\n".join(lines) + "\n")
    loaded = proxima.load_compound(str(path))
    assert [p.name for p in loaded.pieces] == ["left", "right"]
    assert [p.input_points for p in loaded.pieces] == [9, 8]
    assert [p.input_was_convex for p in loaded.pieces] == [False, True]
    assert loaded.body.piece_count == 2
    with pytest.warns(proxima.NonConvexInputWarning, match="group\\(s\\) 'left'"):
        body = proxima.CompoundBody.from_file(str(path))
    r = proxima.distance(body, None, body, proxima.Pose.from_translation((0, 0, 5)))
    assert abs(r.distance - 4.0) < 1e-12
    with pytest.raises(FileNotFoundError):
        proxima.load_compound(str(tmp_path / "missing.obj"))


# --- Scene --------------------------------------------------------------------


def random_scene(rng, bodies, margin, threads=1, broad_phase="dynamic_aabb_tree"):
    shapes = [proxima.ConvexPolytope(rng.normal(size=(int(rng.integers(20, 60)), 3)) * 0.4)
              for _ in range(6)]
    compound = random_compound(rng, 4, spread=0.8)
    scene = proxima.Scene(margin=margin, threads=threads, broad_phase=broad_phase)
    side = 2.0 * bodies ** (1 / 3)
    positions = rng.uniform(0, side, size=(bodies, 3))
    ids = []
    for i in range(bodies):
        body = compound if i % 10 == 0 else shapes[i % len(shapes)]
        ids.append(scene.add(body, proxima.Pose.from_wxyz(quaternion(rng), positions[i])))
    return scene, np.array(ids), positions


def same_pairs(fast, slow, tol):
    assert [(p.a, p.b) for p in fast] == [(p.a, p.b) for p in slow]
    for f, s in zip(fast, slow):
        assert f.result.status == s.result.status
        assert abs(f.result.distance - s.result.distance) <= tol


@pytest.mark.parametrize("broad_phase", ["dynamic_aabb_tree", "sweep_and_prune"])
def test_scene_step_equals_all_pairs_while_bodies_move(broad_phase):
    rng = np.random.default_rng(6)
    scene, ids, positions = random_scene(rng, 60, margin=0.3, broad_phase=broad_phase)
    assert len(scene) == 60 and list(scene.body_ids) == list(ids)
    seen_close = 0
    for _ in range(8):
        positions += rng.normal(size=positions.shape) * 0.05
        poses = np.tile(np.eye(4), (len(ids), 1, 1))
        poses[:, :3, 3] = positions
        scene.set_poses(ids, poses)
        fast = scene.step()
        same_pairs(fast, scene.close_pairs_all_pairs(), 1e-9)
        assert scene.stats.close_pairs == len(fast)
        assert scene.stats.candidate_pairs >= len(fast)
        seen_close += len(fast)
    assert seen_close > 0  # the scene really has close pairs
    assert scene.stats.warm_pairs > 0  # and tracking really carries caches across steps


def test_scene_threads_give_the_same_answers():
    answers = []
    for threads in (1, 2):
        rng = np.random.default_rng(7)
        scene, _, _ = random_scene(rng, 80, margin=0.2, threads=threads)
        answers.append([(p.a, p.b, p.result.distance, p.result.status) for p in scene.step()])
    assert answers[0] == answers[1] and answers[0]


def test_scene_add_remove_and_errors():
    rng = np.random.default_rng(8)
    hull = proxima.ConvexPolytope(rng.normal(size=(20, 3)))
    scene = proxima.Scene(margin=0.1)
    a = scene.add(hull)
    b = scene.add(hull, proxima.Pose.from_translation((100, 0, 0)))
    del hull
    gc.collect()
    assert scene.step() == []
    scene.set_pose(b, proxima.Pose.from_translation((0.5, 0, 0)))
    pairs = scene.step()
    assert [(p.a, p.b) for p in pairs] == [(a, b)] and pairs[0].result.status == "intersecting"
    scene.remove(b)
    assert b not in scene and a in scene and len(scene) == 1
    with pytest.raises(proxima.InvalidInput, match=str(b)):
        scene.set_pose(b, None)
    with pytest.raises(proxima.InvalidInput):
        scene.set_pose(a, proxima.Pose.from_translation((np.nan, 0, 0)))
    with pytest.raises(proxima.InvalidInput):
        proxima.Scene(margin=-1.0)
    with pytest.raises(ValueError, match="broad_phase"):
        proxima.Scene(broad_phase="octree")
    with pytest.raises(ValueError, match="ids"):
        scene.set_poses(np.zeros((2, 2)), np.tile(np.eye(4), (2, 1, 1)))


def test_set_poses_is_all_or_nothing():
    # Story: set_poses moved the bodies one by one, so an unknown id (or a
    # bad pose) late in the list raised after the first bodies had moved,
    # leaving the scene half updated. Now every id and pose is checked first.
    rng = np.random.default_rng(9)
    hull = proxima.ConvexPolytope(rng.normal(size=(20, 3)))
    scene = proxima.Scene(margin=0.1)
    a = scene.add(hull, proxima.Pose.from_translation((0, 0, 0)))
    b = scene.add(hull, proxima.Pose.from_translation((10, 0, 0)))
    scene.remove(b)
    c = scene.add(hull, proxima.Pose.from_translation((20, 0, 0)))
    before = {i: scene.pose(i).matrix() for i in scene.body_ids}
    moved = np.tile(np.eye(4), (3, 1, 1))
    moved[:, :3, 3] = [[1, 1, 1], [2, 2, 2], [3, 3, 3]]

    def unchanged():
        for i, m in before.items():
            np.testing.assert_array_equal(scene.pose(i).matrix(), m)

    unknown = max(a, c) + 7
    with pytest.raises(proxima.InvalidInput, match=rf"ids\[2\] = {unknown} is not in the scene.*no body was moved"):
        scene.set_poses([a, c, unknown], moved)
    unchanged()
    with pytest.raises(proxima.InvalidInput, match="not in the scene"):
        scene.set_poses(np.array([a, -1]), moved[:2])
    unchanged()
    with pytest.raises(proxima.InvalidInput, match="not in the scene"):
        scene.set_poses(np.array([a, 2**40]), moved[:2])
    unchanged()
    bad = moved.copy()
    bad[1, 3, 0] = np.nan
    with pytest.raises(proxima.InvalidInput, match=r"poses\[1\] is not finite"):
        scene.set_poses([a, c], bad[:2])
    unchanged()
    # A Pose object is checked too (from_translation does not check).
    with pytest.raises(proxima.InvalidInput, match="no body was moved"):
        scene.set_poses([a, c], proxima.Pose.from_translation([np.nan, 0, 0]))
    unchanged()
    # Ids are integers: 0.5 is not body 0 (forcecast truncated it).
    with pytest.raises(ValueError, match="ids: expected integer body ids"):
        scene.set_poses(np.array([a + 0.5]), moved[:1])
    unchanged()
    scene.set_poses([a, c], moved[:2])
    np.testing.assert_array_equal(scene.pose(a).translation, [1, 1, 1])
    np.testing.assert_array_equal(scene.pose(c).translation, [2, 2, 2])


# Issue 11, pair filters: a robot's adjacent links overlap by construction
# and were computed and reported every step. Groups/masks and excluded pairs
# drop pairs in the broad phase.
def test_scene_pair_filters():
    rng = np.random.default_rng(21)
    scene, ids, _ = random_scene(rng, 60, margin=0.3)
    plain = {(p.a, p.b) for p in scene.step()}
    assert len(plain) > 10
    excluded = sorted(plain)[:5]
    for a, b in excluded:
        scene.exclude_pair(int(a), int(b))
        assert scene.is_excluded(int(b), int(a))
    ghost = int(ids[1])
    scene.set_filter(ghost, group=0b10, mask=0)  # tested against nothing
    assert scene.filter(ghost) == (0b10, 0)
    kept = {(p.a, p.b) for p in scene.step()}
    expected = {pair for pair in plain if pair not in set(excluded) and ghost not in pair}
    assert kept == expected
    assert {(p.a, p.b) for p in scene.close_pairs_all_pairs()} == expected
    assert scene.stats.filtered_pairs >= len(plain) - len(expected)
    scene.include_pair(*map(int, excluded[0]))
    assert not scene.is_excluded(*map(int, excluded[0]))
    with pytest.raises(ValueError, match="a pair needs two bodies"):
        scene.exclude_pair(int(ids[0]), int(ids[0]))
    with pytest.raises(ValueError, match="body 999 is not in the scene"):
        scene.set_filter(999, 1, 1)


def test_scene_nearest_pair_and_pairs_within():
    # The same seeded scene twice: one with margin 0 asked the queries, one
    # with a huge margin whose all-pairs twin gives every pair's distance.
    scene, ids, _ = random_scene(np.random.default_rng(22), 30, margin=0.0)
    twin, _, _ = random_scene(np.random.default_rng(22), 30, margin=1e6)
    all_pairs = twin.close_pairs_all_pairs()
    assert len(all_pairs) == 30 * 29 // 2
    nearest = scene.nearest_pair()
    assert abs(nearest.result.distance - min(p.result.distance for p in all_pairs)) <= 1e-9
    body = int(ids[0])
    within = scene.pairs_within(body, 1.0)
    expected = sorted(p.b if p.a == body else p.a for p in all_pairs
                      if body in (p.a, p.b) and p.result.distance <= 1.0)
    assert [p.b if p.a == body else p.a for p in within] == expected
    assert proxima.Scene().nearest_pair() is None


def test_compound_and_scene_results_carry_the_signed_distance():
    # The compound's signed distance is the smallest over its piece pairs
    # (the deepest overlapping pair); a scene's close pair carries it.
    rng = np.random.default_rng(5)
    a = random_compound(rng, 5, spread=1.0)
    r = proxima.distance(a, None, a, proxima.Pose.from_translation((0.1, 0, 0)))
    assert r.status == "intersecting" and r.signed_distance < 0
    assert r.signed_lower_bound <= r.signed_distance <= r.signed_upper_bound
    twin = proxima.distance_all_pairs(a, None, a, proxima.Pose.from_translation((0.1, 0, 0)))
    assert abs(twin.signed_distance - r.signed_distance) <= 1e-12
    hull = proxima.ConvexPolytope(np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]))
    # A scene skips the depth unless asked (its overlapping pairs would pay
    # for it every step).
    plain = proxima.Scene(margin=0.1)
    plain.add(hull)
    plain.add(hull, proxima.Pose.from_translation((0.75, 0.1, 0.2)))
    pairs = plain.step()
    assert len(pairs) == 1 and pairs[0].result.signed_distance == 0.0
    scene = proxima.Scene(margin=0.1, penetration=True)
    scene.add(hull)
    scene.add(hull, proxima.Pose.from_translation((0.75, 0.1, 0.2)))
    pairs = scene.step()
    assert len(pairs) == 1 and abs(pairs[0].result.signed_distance + 0.25) <= 1e-15


# --- Scene.sweep (continuous collision) ------------------------------------------


def box(hx, hy, hz):
    return proxima.ConvexPolytope(
        np.array([[x, y, z] for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)]))


def test_scene_sweep_catches_the_cube_that_tunnels_through_a_plate():
    scene = proxima.Scene()
    T = proxima.Pose.from_translation
    plate = scene.add(box(2, 2, 0.01), T((0, 0, 0)))
    cube = scene.add(box(0.05, 0.05, 0.05), T((0.3, -0.2, 1.0)))
    scene.set_end_pose(cube, T((0.3, -0.2, -1.0)))
    np.testing.assert_allclose(scene.end_pose(cube).translation, [0.3, -0.2, -1.0])
    assert scene.step() == []
    hits = scene.sweep()
    assert len(hits) == 1
    hit = hits[0]
    assert isinstance(hit, proxima.ImpactPair)
    assert (hit.a, hit.b) == (plate, cube)
    assert hit.result.status == "contact"
    assert 0.47 - 1e-5 <= hit.result.t <= 0.47
    assert "contact" in repr(hit)
    stats = scene.sweep_stats
    assert (stats.bodies, stats.moving_bodies, stats.candidate_pairs, stats.impact_pairs) == (2, 1, 1, 1)
    assert stats.distance_queries == hit.result.iterations
    twin = scene.impact_pairs_all_pairs()
    assert [(p.a, p.b, p.result.t) for p in twin] == [(plate, cube, hit.result.t)]
    # A contact offset: met earlier.
    early = scene.sweep(target_separation=0.2)
    assert early[0].result.t < hit.result.t
    # set_pose ends the motion.
    scene.set_pose(cube, T((0.3, -0.2, -1.0)))
    assert scene.sweep() == []


def test_scene_set_end_poses_is_all_or_nothing_and_errors_are_named():
    rng = np.random.default_rng(3)
    scene = proxima.Scene()
    ids = [scene.add(proxima.ConvexPolytope(rng.normal(size=(12, 3))), np.eye(4)) for _ in range(3)]
    poses = np.tile(np.eye(4), (3, 1, 1))
    poses[:, 0, 3] = [1.0, 2.0, 3.0]
    scene.set_end_poses(np.array(ids), poses)
    np.testing.assert_allclose([scene.end_pose(i).translation[0] for i in ids], [1.0, 2.0, 3.0])
    bad = poses.copy()
    bad[2, 0, 3] = np.nan
    with pytest.raises(proxima.InvalidInput, match=r"poses\[2\] is not finite"):
        scene.set_end_poses(np.array(ids), bad)
    np.testing.assert_allclose([scene.end_pose(i).translation[0] for i in ids], [1.0, 2.0, 3.0])
    with pytest.raises(proxima.InvalidInput, match=r"set_end_poses: ids\[1\] = 9"):
        scene.set_end_poses(np.array([0, 9]), poses[:2])
    with pytest.raises(proxima.InvalidInput, match="body 9"):
        scene.set_end_pose(9, np.eye(4))
    with pytest.raises(proxima.InvalidInput, match="Scene::sweep: options.tolerance"):
        scene.sweep(tolerance=-1.0)
    with pytest.raises(proxima.InvalidInput, match="max_iterations"):
        scene.sweep(max_iterations=0)


# --- Scenes of any body: rounded, padded, meshes -------------------------------


def box_mesh(lo, hi):
    """The closed surface of the box [lo, hi] (outward triangles)."""
    v = np.array([[hi[0] if k & 1 else lo[0], hi[1] if k & 2 else lo[1],
                   hi[2] if k & 4 else lo[2]] for k in range(8)], dtype=float)
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return proxima.TriangleMesh(v, f)


def test_scene_takes_bodies_meshes_and_padding_as_distance_of_bodies():
    rng = np.random.default_rng(40)
    hull = proxima.ConvexPolytope(rng.normal(size=(20, 3)) * 0.4)
    kinds = [hull, proxima.sphere(0.3), proxima.capsule(0.3, 0.2), box_mesh((-.4,) * 3, (.4,) * 3),
             random_compound(rng, 2, spread=0.3), proxima.Body(hull, 0.1)]
    scene = proxima.Scene(margin=0.2)
    entries = []
    for i in range(30):
        body = kinds[i % len(kinds)]
        pose = proxima.Pose.from_wxyz(quaternion(rng), rng.uniform(0, 4, 3))
        padding = 0.1 if i % 4 == 0 else 0.0
        assert scene.add(body, pose, padding=padding) == i
        entries.append((proxima.Body(body) if not isinstance(body, proxima.Body) else body,
                        pose, padding))
    assert scene.padding(0) == 0.1 and scene.padding(1) == 0.0
    assert scene.body(3).kind == "mesh" and scene.body(5).radius == 0.1
    pairs = scene.step()
    twin = scene.close_pairs_all_pairs()
    assert [(p.a, p.b) for p in pairs] == [(p.a, p.b) for p in twin]
    assert len(pairs) >= 10
    seen_mesh = False
    for p in pairs:
        (ba, pa, da), (bb, pb, db) = entries[p.a], entries[p.b]
        # The first step is cold: bit for bit the twin and, for a pair with a
        # rounded, padded or mesh body, distance(Body, Body) of the padded bodies.
        twin_pair = twin[[(q.a, q.b) for q in twin].index((p.a, p.b))]
        assert p.result.distance == twin_pair.result.distance
        if ba.kind == "mesh" or bb.kind == "mesh":
            seen_mesh = True
            assert p.triangle_a >= 0 or p.triangle_b >= 0
        else:
            assert p.triangle_a == -1 and p.triangle_b == -1
        if ba.radius + da > 0 or bb.radius + db > 0 or "mesh" in (ba.kind, bb.kind):
            d = proxima.distance(ba.with_radius(ba.radius + da), pa,
                                 bb.with_radius(bb.radius + db), pb, penetration=False)
            assert p.result.distance == d.distance
            assert p.result.signed_distance == d.signed_distance
            assert p.result.status == d.status
    assert seen_mesh


def test_scene_padding_acts_as_a_radius_and_is_checked():
    ball = proxima.sphere(0.5)
    scene = proxima.Scene()
    a = scene.add(ball, proxima.Pose.from_translation((0, 0, 0)))
    b = scene.add(ball, proxima.Pose.from_translation((1.5, 0, 0)))  # 0.5 apart
    assert scene.step() == []
    scene.set_padding(a, 0.3)
    assert scene.step() == []  # 0.2 apart
    scene.set_padding(b, 0.3)  # overlap 0.1
    (pair,) = scene.step()
    assert pair.result.status == "intersecting"
    assert abs(pair.result.signed_distance - -0.1) <= 1e-12
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(proxima.InvalidInput, match="padding"):
            scene.set_padding(a, bad)
        with pytest.raises(proxima.InvalidInput, match="padding"):
            scene.add(ball, None, padding=bad)
    with pytest.raises(proxima.InvalidInput, match="body 9"):
        scene.set_padding(9, 0.1)
    with pytest.raises(TypeError, match="body"):
        scene.add("a sphere")


def test_scene_bodies_inside_a_closed_room_mesh_intersect_it_and_sweep_takes_it():
    scene = proxima.Scene()
    room = scene.add(box_mesh((-10, -10, 0), (10, 10, 10)))
    inside = scene.add(proxima.sphere(0.5), proxima.Pose.from_translation((0, 0, 5)), padding=0.2)
    scene.add(proxima.sphere(0.5), proxima.Pose.from_translation((30, 0, 5)))
    (pair,) = scene.step()
    assert (pair.a, pair.b) == (room, inside) and pair.result.status == "intersecting"
    hits = scene.sweep()  # a mesh sweeps too: the ball inside overlaps at t = 0
    assert [(h.a, h.b, h.result.status) for h in hits] == [(room, inside, "intersecting")]
