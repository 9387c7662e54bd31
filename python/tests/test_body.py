"""Tests of the Python bindings of bodies with a radius and of the primitives.

The C++ tests check the answers (tests/query/body_test.cpp); these check what the
binding adds: distance for any two body kinds in any combination (a
ConvexPolytope against a CompoundBody raised TypeError before), the
primitives' arguments and errors, the result's fields, and the cache.
"""

import itertools

import numpy as np
import pytest

import proxima


def test_sphere_sphere_closed_form():
    r = proxima.distance(proxima.sphere(0.5), None, proxima.sphere(0.25),
                         proxima.Pose.from_translation((3, 4, 0)))
    assert isinstance(r, proxima.BodyResult)
    assert isinstance(r, proxima.DistanceResult)
    assert r.status == "separated"
    assert r.signed_distance == pytest.approx(5 - 0.75, abs=1e-14)
    assert r.distance == r.signed_distance
    np.testing.assert_allclose(r.normal, [0.6, 0.8, 0], atol=1e-15)
    np.testing.assert_allclose(r.point_a, [0.3, 0.4, 0], atol=1e-15)
    np.testing.assert_allclose(r.point_b, [3 - 0.15, 4 - 0.2, 0], atol=1e-15)
    assert r.piece_a == -1 and r.piece_b == -1
    assert not r.intersecting


def test_overlapping_rounded_bodies_have_a_negative_signed_distance():
    r = proxima.distance(proxima.capsule(1.0, 0.5), None, proxima.box((1, 1, 1), 0.25),
                         proxima.Pose.from_translation((2.5, 0, 0)))
    # Segment at x = 0, box face at x = 1.5: cores 1.5 apart, radii 0.75.
    assert r.status == "separated"
    assert r.signed_distance == pytest.approx(0.75, abs=1e-14)
    r = proxima.distance(proxima.capsule(1.0, 0.5), None, proxima.box((1, 1, 1), 0.25),
                         proxima.Pose.from_translation((1.5, 0, 0)))
    assert r.status == "intersecting"
    assert r.distance == 0.0
    assert r.signed_distance == pytest.approx(0.5 - 0.75, abs=1e-14)
    assert r.signed_lower_bound <= r.signed_distance <= r.signed_upper_bound + 1e-15


def test_overlapping_cores_give_minus_depth_minus_radii():
    # A point 0.3 inside a box's face, both rounded.
    r = proxima.distance(proxima.box((1, 1, 1), 0.1), None, proxima.sphere(0.2),
                         proxima.Pose.from_translation((0.7, 0, 0)))
    assert r.intersecting
    assert r.status == "intersecting"
    assert r.signed_distance == pytest.approx(-0.3 - 0.1 - 0.2, abs=1e-14)
    np.testing.assert_allclose(np.abs(r.normal), [1, 0, 0], atol=1e-14)


def test_any_two_body_kinds():
    rng = np.random.default_rng(3)
    points = rng.normal(size=(30, 3))
    convex = proxima.ConvexPolytope(points)
    compound = proxima.CompoundBody([convex])
    rounded = proxima.Body(convex)
    pose = proxima.Pose.from_translation((4, 0.5, 0))
    reference = proxima.distance(convex, None, convex, pose).distance
    for a, b in itertools.product([convex, compound, rounded], repeat=2):
        r = proxima.distance(a, None, b, pose)
        assert r.distance == pytest.approx(reference, rel=1e-12), (a, b)
    # Two polytopes and two compounds keep their own overloads and types.
    assert type(proxima.distance(convex, None, convex, pose)) is proxima.DistanceResult
    assert type(proxima.distance(compound, None, compound, pose)) is proxima.CompoundResult
    assert type(proxima.distance(convex, None, compound, pose)) is proxima.BodyResult
    assert proxima.distance(convex, None, compound, pose).piece_b == 0


def test_rounded_compound_and_cache():
    rng = np.random.default_rng(4)
    compound = proxima.CompoundBody([rng.normal(size=(12, 3)) * 0.3 + (x, 0, 0) for x in (-2, 2)])
    body = proxima.Body(compound, 0.1)
    assert body.kind == "compound" and body.convex is None and body.radius == 0.1
    ball = proxima.sphere(0.2)
    cache = proxima.BodyCache()
    assert cache.is_cold()
    for t in np.linspace(-4, 4, 41):
        pose = proxima.Pose.from_translation((t, 1.0, 0))
        tracked = proxima.distance(body, None, ball, pose, cache=cache)
        cold = proxima.distance(body, None, ball, pose)
        assert tracked.status == cold.status
        assert tracked.signed_distance == pytest.approx(cold.signed_distance, abs=1e-12)
        assert tracked.piece_a in (0, 1)
    assert not cache.is_cold()
    cache.reset()
    assert cache.is_cold()


def test_primitives_and_their_approximation_error():
    cylinder = proxima.cylinder(1.0, 2.0, 1e-3)
    sides, circumradius, deviation = proxima.polygon_sides(1.0, 1e-3)
    assert cylinder.approximation_error == deviation <= 1e-3
    assert cylinder.convex.vertex_count == 2 * sides
    assert circumradius <= 1.0 + deviation <= circumradius + 1e-14  # deviation rounded up
    cone = proxima.cone(1.0, 2.0, 1e-3)
    assert cone.convex.vertex_count == sides + 1
    r = proxima.distance(cylinder, None, cone, proxima.Pose.from_translation((5, 0, 0)))
    assert r.approximation_error == 2 * deviation
    # The polytopes hold the true solids: their distance is at most the true 3.
    assert 3 - 2 * deviation <= r.distance <= 3
    assert proxima.box((1, 2, 3)).convex.vertex_count == 8
    assert proxima.box(np.array([1.0, 2.0, 3.0]), radius=0.5).scale == 3.5
    assert proxima.Body(np.eye(3), 0.5).convex.dimension == 2
    assert proxima.Body(proxima.sphere(1.0)).radius == 0.0  # the core, new radius
    assert proxima.sphere(1.0).with_radius(2.0).radius == 2.0


@pytest.mark.parametrize("make, words", [
    (lambda: proxima.sphere(-1.0), "make_sphere: radius must be finite and >= 0, got -1"),
    (lambda: proxima.sphere(float("nan")), "radius must be finite and >= 0, got nan"),
    (lambda: proxima.box((1, -1, 1)), "make_box: half_extents.y must be finite"),
    (lambda: proxima.capsule(1.0, float("inf")), "make_capsule: radius must be finite"),
    (lambda: proxima.cylinder(1.0, 1.0, 0.0), "make_cylinder: tolerance must be finite and > 0"),
    (lambda: proxima.cone(1.0, 1.0, 1e-13), "make_cone: tolerance 1e-13"),
    (lambda: proxima.Body(proxima.ConvexPolytope(np.eye(3)), -0.5),
     "Body: radius must be finite and >= 0, got -0.5"),
])
def test_bad_input_is_named(make, words):
    with pytest.raises(proxima.InvalidInput, match=words.replace("(", r"\(")):
        make()


def test_wrong_kinds_raise_type_error():
    with pytest.raises(TypeError, match="b: expected a ConvexPolytope, a CompoundBody, a TriangleMesh or a Body"):
        proxima.distance(proxima.sphere(1.0), None, "sphere", None)


# Issue 11: a PairBatch of bodies of any kinds (rounded, compound, primitives
# mixed with plain polytopes) answers row k as the single tracked
# distance(Body, Body) of pair k, bit for bit, with the pieces of the pair.
def test_pair_batch_of_any_body_kinds_equals_single_tracked_queries():
    rng = np.random.default_rng(8)
    convex = proxima.ConvexPolytope(rng.normal(size=(30, 3)))
    compound = proxima.CompoundBody([rng.normal(size=(12, 3)) * 0.3 + (x, 0, 0) for x in (-1, 1)])
    kinds = [convex, proxima.Body(convex, 0.2), compound, proxima.Body(compound, 0.1),
             proxima.sphere(0.3), proxima.capsule(0.5, 0.1), proxima.box((0.4, 0.2, 0.3))]
    k = 49
    a = [kinds[i % 7] for i in range(k)]
    b = [kinds[(i // 7) % 7] for i in range(k)]
    batch = proxima.PairBatch(a, b)
    assert len(batch) == k
    caches = [proxima.BodyCache() for _ in range(k)]
    poses_b = np.tile(np.eye(4), (k, 1, 1))
    poses_b[:, :3, 3] = rng.uniform(-2.5, 2.5, size=(k, 3))
    signs = set()
    for step in range(3):
        poses_b[:, :3, 3] += rng.normal(size=(k, 3)) * 0.05
        out = batch.distance(None, poses_b, threads=2)
        for i in range(k):
            single = proxima.distance(proxima.Body(a[i]) if isinstance(a[i], proxima.ConvexPolytope) else a[i],
                                      None, b[i], poses_b[i], cache=caches[i])
            assert out["signed_distance"][i] == single.signed_distance
            assert out["status"][i] == single.status
            assert out["piece_a"][i] == single.piece_a and out["piece_b"][i] == single.piece_b
            np.testing.assert_array_equal(out["point_a"][i], single.point_a)
            np.testing.assert_array_equal(out["normal"][i], single.normal)
            signs.add(single.signed_distance > 0)
    assert signs == {True, False}  # premise: overlapping and separated pairs
