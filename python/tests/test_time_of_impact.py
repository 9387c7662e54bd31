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
    assert proxima.time_of_impact(a, still, a, start_inside).status == "intersecting"
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


def test_a_velocity_motion_turns_through_any_angle():
    # Issue 25 (toi_spin_wrap.sh): Motion.from_velocity kept only the end
    # pose and turned the shorter way, so a bar spinning at w = 2 pi (one
    # whole turn) or 1000 about a pivot above a cube was "separated". The
    # oracle: dense sampling of the true motion (angle s w about z), made
    # here with numpy, not with Motion.at.
    c = cube()
    bar = proxima.ConvexPolytope(np.array([[0, 0, 0], [100, 0, 0], [0, 0.01, 0]], dtype=float))
    for w, span in ((3.0, 1.0), (3.2, 1.0), (4.0, 1.0), (2 * np.pi, 1.0), (1000.0, 0.01)):
        m = proxima.Motion.from_velocity(T((0, 1.05, 0)), (0, 0, 0), (0, 0, w))
        np.testing.assert_allclose(m.angular, [0, 0, w])
        np.testing.assert_allclose(m.angular_velocity(), [0, 0, w])

        def true_pose(s):
            a = s * w
            rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
            return (rot, (0, 1.05, 0))

        first = 2.0
        for s in np.linspace(0.0, span, 4001):
            if proxima.distance(c, None, bar, true_pose(s)).distance <= 0.0:
                first = s
                break
        # The sliver bar takes about 270 steps (tests/time_of_impact_test.cpp says why).
        r = proxima.time_of_impact(c, proxima.Motion.fixed(None), bar, m, tolerance=1e-9,
                                   max_iterations=4096)
        if first > 1.0:
            assert r.status == "separated", w
            continue
        assert r.status == "contact", w
        # Never after the first sampled contact, and within a sampling step of it.
        assert first - span / 4000 <= r.t <= first, (w, r.t, first)
    # End poses alone keep their meaning: the shorter way (here no turn at all).
    m = proxima.Motion.from_velocity(T((0, 1.05, 0)), (0, 0, 0), (0, 0, 2 * np.pi))
    assert proxima.Motion(m.start, m.end).angular is None
    r = proxima.time_of_impact(c, proxima.Motion.fixed(None), bar, (m.start, m.end))
    assert r.status == "separated"


def test_a_tiny_tolerance_and_huge_velocities():
    # Issue 25: a tolerance below the contact band ended at iteration_cap;
    # velocities near the largest double ended at t = 0 or failed unnamed.
    a = cube()
    r = proxima.time_of_impact(a, proxima.Motion.fixed(None), a,
                               (T((5, 0, 0)), T((-5, 0, 0))), tolerance=1e-300)
    assert r.status == "contact" and r.t <= 0.3
    with pytest.raises(ValueError, match="motion_b.end reaches coordinates of magnitude"):
        proxima.time_of_impact(a, proxima.Motion.fixed(None), a,
                               proxima.Motion.from_velocity(T((5, 0, 0)), (1e308, 0, 0),
                                                            (0, 0, 0)))
    spin = proxima.Motion.from_velocity(T((5, 0, 0)), (0, 0, 0), (0, 0, 1e300))
    with pytest.raises(ValueError, match="motion_b.angular turns at 1e\\+300 rad per unit t"):
        proxima.time_of_impact(a, proxima.Motion.fixed(None), a, spin)
    spin = proxima.Motion.from_velocity(T((5, 0, 0)), (0, 0, 0), (0, 0, 2.0 ** 52))
    assert proxima.time_of_impact(a, proxima.Motion.fixed(None), a, spin).status == "separated"


def test_scene_set_velocity_turns_through_any_angle():
    # Issue 25: Scene.sweep kept end poses only; a bar making one whole turn
    # in place (its end pose its start) swept through nothing.
    scene = proxima.Scene()
    bar = scene.add(proxima.ConvexPolytope(
        np.array([[x, y, z] for x in (-1, 1) for y in (-0.02, 0.02) for z in (-0.02, 0.02)])),
        None)
    scene.add(cube(0.05), T((0, 0.7, 0)))
    scene.set_velocity(bar, (0, 0, 0), (0, 0, 2 * np.pi))
    hits = scene.sweep()
    assert len(hits) == 1 and hits[0].result.status == "contact"
    scene.set_end_pose(bar, scene.end_pose(bar))   # the same end pose: no turn
    assert len(scene.sweep()) == 0
