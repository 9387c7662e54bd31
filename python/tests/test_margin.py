"""Tests of the boolean and margin queries from Python (issue 26):
within_margin and intersects for one pair, PairBatch.within_margin and
PairBatch.intersects, Scene.step_within and Scene.first_within.

The C++ tests check the algorithms (tests/query/margin_test.cpp,
tests/query/batch_test.cpp, tests/scene/scene_margin_test.cpp); these check
what the binding adds (conversion, the caches shared with distance(),
errors) and each fast call against its slow twin as seen from Python: the
full distance query compared with the margin.
"""

import numpy as np
import pytest

import proxima

# Verdicts within this of the margin may differ from the twin's: the
# contact band 64 u R (R about 10 here, band about 1e-13), with room.
BAND = 1e-10


def box_mesh(h):
    v = np.array([[x, y, z] for z in (-h, h) for y in (-h, h) for x in (-h, h)], dtype=float)
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return proxima.TriangleMesh(v, f)


def random_bodies(rng):
    hull = proxima.ConvexPolytope(rng.normal(size=(30, 3)) * 0.4)
    return [
        hull,
        proxima.Body(hull, 0.1),
        proxima.CompoundBody([rng.normal(size=(12, 3)) * 0.3,
                              rng.normal(size=(12, 3)) * 0.3 + (0.8, 0, 0)]),
        box_mesh(0.4),
        proxima.capsule(0.5, 0.2),
    ]


def random_pose(rng, spread):
    q = rng.normal(size=4)
    return proxima.Pose.from_wxyz(q / np.linalg.norm(q), rng.uniform(-spread, spread, 3))


def twin_verdict(a, pa, b, pb, margin):
    """The slow twin: the full distance query compared with the margin;
    None inside the band, where either verdict is right."""
    r = proxima.distance(a, pa, b, pb)
    if r.status in ("touching", "intersecting") or r.distance < margin - BAND:
        return True, r
    if r.distance > margin + BAND:
        return False, r
    return None, r


def test_single_queries_agree_with_the_full_distance_on_every_kind():
    rng = np.random.default_rng(26)
    bodies = random_bodies(rng)
    counts = {True: 0, False: 0}
    for _ in range(300):
        a = bodies[int(rng.integers(len(bodies)))]
        b = bodies[int(rng.integers(len(bodies)))]
        pa, pb = random_pose(rng, 1.0), random_pose(rng, 1.0)
        margin = float(rng.choice([0.0, 0.05, 0.3]))
        expected, full = twin_verdict(a, pa, b, pb, margin)
        r = proxima.within_margin(a, pa, b, pb, margin)
        assert r.margin == margin
        if expected is not None:
            assert r.within == expected, (r, full)
            assert bool(r) == expected
            counts[expected] += 1
        if r.within:
            assert r.status == "within"
            assert r.upper_bound <= margin + BAND
            assert np.linalg.norm(r.point_b - r.point_a) == pytest.approx(r.upper_bound, abs=BAND)
        else:
            assert r.status == "beyond"
            assert margin < r.lower_bound <= full.distance + BAND
        if margin == 0.0:
            i = proxima.intersects(a, pa, b, pb)
            assert i.status == r.status
    assert counts[True] >= 50 and counts[False] >= 50


def test_caches_are_the_distance_querys():
    rng = np.random.default_rng(27)
    hull = proxima.ConvexPolytope(rng.normal(size=(40, 3)))
    cache = proxima.DistanceCache()
    mesh = box_mesh(0.5)
    body_cache = proxima.BodyCache()
    for step in range(20):
        pose = proxima.Pose.from_translation((2.5 - 0.1 * step, 0.0, 0.0))
        if step % 2:
            proxima.distance(hull, None, hull, pose, cache=cache)
            proxima.distance(mesh, None, mesh, pose, cache=body_cache)
        tracked = proxima.within_margin(hull, None, hull, pose, 0.1, cache=cache)
        cold = proxima.within_margin(hull, None, hull, pose, 0.1)
        assert tracked.status == cold.status
        tracked_mesh = proxima.within_margin(mesh, None, mesh, pose, 0.1, cache=body_cache)
        assert tracked_mesh.status == proxima.within_margin(mesh, None, mesh, pose, 0.1).status
    assert not cache.is_cold() and not body_cache.is_cold()


def test_pair_batch_rows_are_the_single_queries_and_share_their_caches():
    rng = np.random.default_rng(28)
    # Each body wrapped once as a Body, as the batch holds them: a plain
    # polytope or compound given to a single query is wrapped again on every
    # call (its lazily built parts, e.g. a compound's pieces as meshes, are
    # new each time), which keeps the answers right but the caches of a
    # pair with a mesh colder than the batch's.
    bodies = [proxima.Body(x) for x in random_bodies(rng)]
    k = 120
    a = [bodies[int(i)] for i in rng.integers(len(bodies), size=k)]
    b = [bodies[int(i)] for i in rng.integers(len(bodies), size=k)]
    batch = proxima.PairBatch(a, b)
    caches = [proxima.BodyCache() for _ in range(k)]
    poses_a = np.stack([random_pose(rng, 1.0).matrix() for _ in range(k)])
    poses_b = np.stack([random_pose(rng, 1.0).matrix() for _ in range(k)])
    for frame in range(3):
        if frame == 1:
            batch.distance(poses_a, poses_b)
            for i in range(k):
                proxima.distance(a[i], poses_a[i], b[i], poses_b[i], cache=caches[i])
        out = batch.intersects(poses_a, poses_b) if frame == 2 else \
            batch.within_margin(poses_a, poses_b, 0.2, threads=2)
        margin = 0.0 if frame == 2 else 0.2
        assert set(out) == {"status", "within", "lower_bound", "upper_bound", "point_a",
                            "point_b", "piece_a", "piece_b", "triangle_a", "triangle_b",
                            "pairs_tested", "iterations"}
        assert out["point_a"].shape == (k, 3) and out["within"].dtype == bool
        for i in range(k):
            r = proxima.within_margin(a[i], poses_a[i], b[i], poses_b[i], margin,
                                      cache=caches[i])
            assert out["status"][i] == r.status
            assert out["within"][i] == r.within
            assert out["lower_bound"][i] == r.lower_bound
            assert out["upper_bound"][i] == r.upper_bound
            np.testing.assert_array_equal(out["point_a"][i], r.point_a)
            assert out["triangle_a"][i] == r.triangle_a
            assert out["piece_b"][i] == r.piece_b
        assert 10 <= int(out["within"].sum()) <= k - 10
        poses_b[:, :3, 3] += rng.normal(size=(k, 3)) * 0.01


def test_pair_batch_of_polytopes_and_bad_margins():
    rng = np.random.default_rng(29)
    hulls = [proxima.ConvexPolytope(rng.normal(size=(20, 3))) for _ in range(4)]
    batch = proxima.PairBatch(hulls, hulls[::-1])
    poses = np.stack([np.eye(4)] * 4)
    poses[:, 0, 3] = (0.0, 3.0, 6.0, 9.0)
    out = batch.within_margin(None, poses, 0.5)
    for i in range(4):
        expected, _ = twin_verdict(hulls[i], None, hulls[3 - i], poses[i], 0.5)
        assert out["within"][i] == expected
    with pytest.raises(proxima.InvalidInput, match="PairBatch.within_margin: margin must be"):
        batch.within_margin(None, poses, -1.0)
    with pytest.raises(proxima.InvalidInput, match="within_margin: margin must be finite"):
        proxima.within_margin(hulls[0], None, hulls[1], None, float("nan"))
    bad = poses.copy()
    bad[2, 0, 0] = 3.0
    with pytest.raises(proxima.InvalidInput, match=r"PairBatch.intersects: poses_b\[2\]"):
        batch.intersects(None, bad)


def test_scene_step_within_and_first_within_are_steps_pairs():
    rng = np.random.default_rng(30)
    bodies = random_bodies(rng)
    scene = proxima.Scene(margin=0.1)
    for i in range(40):
        scene.add(bodies[i % len(bodies)], random_pose(rng, 2.5))
    found = 0
    for _ in range(3):
        full = {(p.a, p.b): p for p in scene.step()}
        within = scene.step_within()
        assert scene.stats.close_pairs == len(within)
        for p in within:
            assert isinstance(p, proxima.MarginPair)
            assert p.result.status == "within"
            assert p.result.upper_bound <= 0.1 + BAND
        reported = {(p.a, p.b) for p in within}
        for key, p in full.items():
            if p.result.status in ("touching", "intersecting") or p.result.distance < 0.1 - BAND:
                assert key in reported
        assert reported <= set(full)
        hit = scene.first_within()
        assert (hit is None) == (not full)
        if hit is not None:
            assert (hit.a, hit.b) in full
        found += len(within)
        for i in range(40):
            scene.set_pose(i, random_pose(rng, 2.5))
    assert found >= 10
