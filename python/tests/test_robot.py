# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""proxima.Robot: a robot from its URDF, the same answers as C++ (robot_test.cpp
checks those against the slow path), numpy joint vectors, names and batches.

The real descriptions come from ../shared/robots relative to the repository
root; the tests skip when it is absent."""

import pathlib

import numpy as np
import pytest

import proxima

ROOT = pathlib.Path(__file__).resolve().parents[2]
ROBOTS = ROOT.parent / "shared" / "robots"
PANDA = ROBOTS / "robots" / "panda_description"
needs_robots = pytest.mark.skipif(not (PANDA / "urdf" / "panda.urdf").exists(),
                                  reason=f"{ROBOTS} absent")


def load_panda(**kwargs):
    return proxima.Robot(str(PANDA / "urdf" / "panda.urdf"), srdf=str(PANDA / "srdf" / "panda.srdf"),
                         package_dirs=[f"example-robot-data={ROBOTS}"], **kwargs)


def random_q(robot, rng):
    return rng.uniform(robot.lower_limits, robot.upper_limits)


@needs_robots
def test_panda_loads_with_names_and_the_hand_checked_flange():
    robot = load_panda()
    assert robot.name == "panda"
    assert robot.dof == 8
    assert robot.joint_names[:7] == [f"panda_joint{i}" for i in range(1, 8)]
    assert robot.joint_names[7] == "panda_finger_joint1"
    poses = robot.forward_kinematics(np.zeros(8))
    assert poses.shape == (len(robot.link_names), 4, 4)
    flange = poses[robot.link_names.index("panda_link8")]
    np.testing.assert_allclose(flange[:3, 3], [0.088, 0.0, 0.926], atol=1e-12)
    # By name: the same configuration.
    named = dict(zip(robot.joint_names, np.zeros(8)))
    np.testing.assert_array_equal(robot.forward_kinematics(named), poses)


@needs_robots
def test_distances_and_gradients_against_finite_differences_and_the_batch():
    robot = load_panda()
    robot.set_environment([(proxima.box((0.6, 0.6, 0.02)), proxima.Pose.from_translation((0.3, 0, -0.021))),
                           (proxima.box((0.2, 0.4, 0.01)), proxima.Pose.from_translation((0.5, 0, 0.4)))])
    rng = np.random.default_rng(7)
    qs = np.array([random_q(robot, rng) for _ in range(50)])
    checked = 0
    for q in qs:
        r = robot.distances(q, margin=0.05, gradients=True)
        assert r.closest.signed_distance == r.min_signed_distance
        assert min(r.min_self, r.min_environment) == r.min_signed_distance
        assert all(p.signed_distance <= 0.05 for p in r.close_pairs)
        # The minimum's gradient against central differences of the minimum,
        # where the same pair stays the closest with the same features.
        h = 1e-6
        difference = np.zeros(robot.dof)
        smooth = True
        for v in range(robot.dof):
            up, down = q.copy(), q.copy()
            up[v] += h
            down[v] -= h
            ru, rd = robot.distances(up), robot.distances(down)
            for other in (ru, rd):
                smooth &= (other.closest.geometry_a, other.closest.geometry_b, other.closest.environment) == \
                          (r.closest.geometry_a, r.closest.geometry_b, r.closest.environment)
                smooth &= (list(other.closest.result.feature_a.vertices) ==
                           list(r.closest.result.feature_a.vertices)) and \
                          (list(other.closest.result.feature_b.vertices) ==
                           list(r.closest.result.feature_b.vertices))
            difference[v] = (ru.min_signed_distance - rd.min_signed_distance) / (2 * h)
        if smooth:
            checked += 1
            assert np.linalg.norm(r.gradient - difference) <= 1e-6 * max(1.0, np.linalg.norm(difference))
    assert checked > 20
    minima, gradients = robot.distances_batch(qs, threads=2)
    assert minima.shape == (50,) and gradients.shape == (50, robot.dof)
    robot.reset()
    for k, q in enumerate(qs):
        r = robot.distances(q, gradients=True)
        assert abs(minima[k] - r.min_signed_distance) <= 1e-10
        np.testing.assert_allclose(gradients[k], r.gradient, atol=1e-8)
    # minimum_only: the same minimum, no close pairs.
    for q in qs[:20]:
        full = robot.distances(q, margin=0.05)
        only = robot.distances(q, margin=0.05, minimum_only=True)
        assert abs(only.min_signed_distance - full.min_signed_distance) <= 1e-10
        assert len(only.close_pairs) == 0


@needs_robots
def test_bad_input_is_refused_naming_the_problem(tmp_path):
    robot = load_panda()
    with pytest.raises(ValueError, match=r"shape \(8,\)"):
        robot.distances(np.zeros(7))
    with pytest.raises(ValueError, match="panda_joint3"):
        robot.distances({name: 0.0 for name in robot.joint_names if name != "panda_joint3"})
    with pytest.raises(ValueError, match="panda_joint2"):
        q = np.zeros(8)
        q[1] = np.nan
        robot.distances(q)
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="bad"><link name="a"><collision><geometry>'
                   '<mesh filename="package://nowhere/x.stl"/></geometry></collision></link></robot>')
    with pytest.raises(proxima.InvalidInput, match="nowhere"):
        proxima.Robot(str(bad))
    with pytest.raises(ValueError, match="hulls"):
        load_panda(mesh_as="hulls")


@needs_robots
def test_ur5_and_talos_load_from_their_urdf_and_srdf():
    # Talos writes package:///example-robot-data/... (three slashes).
    packages = [f"example-robot-data={ROBOTS}"]
    ur5 = proxima.Robot(str(ROBOTS / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"),
                        srdf=str(ROBOTS / "robots" / "ur_description" / "srdf" / "ur5.srdf"),
                        package_dirs=packages)
    assert ur5.dof == 6
    talos = proxima.Robot(str(ROBOTS / "robots" / "talos_data" / "robots" / "talos_full_v2.urdf"),
                          srdf=str(ROBOTS / "robots" / "talos_data" / "srdf" / "talos.srdf"),
                          package_dirs=packages)
    assert talos.dof > 30
    rng = np.random.default_rng(47)
    for robot in (ur5, talos):
        r = robot.distances(random_q(robot, rng))
        assert np.isfinite(r.min_signed_distance)
