"""Tests of the Python bindings of continuous collision (time_of_impact).

The C++ tests check the guarantee against closed forms and dense sampling
(tests/motion/time_of_impact_test.cpp); these check what the binding adds: motions
from Motion objects or (start, end) pose pairs, the result's fields, the
cache, and errors by name.
"""

import numpy as np
import pytest

import proxima


T = proxima.Pose.from_translation


def cube(h=1.0):
    return proxima.ConvexPolytope(
        np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)]))


def test_translating_cubes_meet_at_the_closed_form_time():
    a = cube()
    # B from x = 5 to x = -5: the faces meet when B's centre is at x = 2.
    r = proxima.time_of_impact(a, proxima.Motion.fixed(None), a,
                               (T((5, 0.3, 0)), T((-5, 0.3, 0))),
                               tolerance=1e-9)
    assert isinstance(r, proxima.ImpactResult)
    assert r.status == "contact"
    assert 0.3 - 1e-9 <= r.t <= 0.3
    assert r.at_t.distance <= 1e-9
    np.testing.assert_allclose(r.pose_b.translation, [2, 0.3, 0], atol=1e-8)
    np.testing.assert_allclose(r.at_t.normal, [1, 0, 0], atol=1e-12)
    assert r.iterations >= 1
    assert "contact" in repr(r)


def test_contact_offset_and_velocity_motion():
    a = cube()
    m = proxima.Motion.from_velocity(proxima.Pose.from_translation((5, 0, 0)), (-10, 0, 0),
                                     (0, 0, 0))
    np.testing.assert_allclose(m.end.translation, [-5, 0, 0])
    np.testing.assert_allclose(m.linear_velocity(), [-10, 0, 0])
    r = proxima.time_of_impact(a, proxima.Motion.fixed(None), a, m, target_separation=0.5,
                               tolerance=1e-10)
    assert r.status == "contact"
    assert 0.25 - 1e-10 <= r.t <= 0.25


def test_separated_overlapping_and_cache():
    a = cube()
    still = proxima.Motion.fixed(None)
    away = proxima.Motion(T((3, 0, 0)), T((9, 0, 0)))
    r = proxima.time_of_impact(a, still, a, away)
    assert r.status == "separated" and r.t == 1.0
    start_inside = proxima.Motion(T((1.5, 0, 0)), T((9, 0, 0)))
    assert proxima.time_of_impact(a, still, a, start_inside).status == "overlapping"
    cache = proxima.DistanceCache()
    toward = proxima.Motion(T((6, 0.2, 0)), T((-6, 0.2, 0)))
    tracked = proxima.time_of_impact(a, still, a, toward, cache=cache)
    assert not cache.is_cold()
    assert tracked.t == pytest.approx(proxima.time_of_impact(a, still, a, toward).t, abs=1e-12)


def test_bad_input_is_refused_by_name():
    a = cube()
    still = proxima.Motion.fixed(None)
    with pytest.raises(TypeError, match="motion_b"):
        proxima.time_of_impact(a, still, a, 42)
    with pytest.raises(ValueError, match="target_separation"):
        proxima.time_of_impact(a, still, a, still, target_separation=-1.0)
    with pytest.raises(ValueError, match="duration"):
        proxima.Motion.from_velocity(None, (1, 0, 0), (0, 0, 0), 0.0)


def test_bodies_of_any_kind():
    # Two spheres head-on: the centres 0.75 apart at t* = (4 - 0.75) / 8.
    r = proxima.time_of_impact(proxima.sphere(0.5), proxima.Motion.fixed(None),
                               proxima.sphere(0.25), (T((4, 0, 0)), T((-4, 0, 0))),
                               tolerance=1e-10)
    assert r.status == "contact"
    assert (4 - 0.75) / 8 - 1e-10 <= r.t <= (4 - 0.75) / 8
    # A plain polytope against a compound, with a BodyCache.
    pair = proxima.CompoundBody([cube(0.5).vertices, cube(0.5).vertices + [0, 2, 0]])
    cache = proxima.BodyCache()
    r = proxima.time_of_impact(pair, proxima.Motion.fixed(None), cube(0.3),
                               (T((5, 2.2, 0)), T((-5, 2.2, 0))), cache=cache)
    assert r.status == "contact"
    assert r.t == pytest.approx((5 - 0.8) / 10, abs=1e-5)
    # The cube meets piece 1 (at y = 2); piece 0 is pruned or advanced.
    assert r.piece_a == 1 and r.piece_b == -1
    assert 1 <= r.pairs_advanced <= 2
    with pytest.raises(TypeError, match="BodyCache"):
        proxima.time_of_impact(pair, proxima.Motion.fixed(None), cube(), proxima.Motion.fixed(
            T((5, 0, 0))), cache=proxima.DistanceCache())
