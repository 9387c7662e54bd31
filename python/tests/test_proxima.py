"""Tests of the Python module proxima.

Run with Debian's interpreter and the built module on the path:

    PYTHONPATH=build/release/python /usr/bin/python3 -m pytest -q python/tests

(CTest does this as `python_tests`). The checks are independent of the C++
code where they can be: hand-computed distances, an optimality certificate
computed in numpy (the normal separates the two vertex sets, the points lie
on the hulls), hull structure recomputed from the arrays; and, for the
bindings' own logic, equality with the single-query path (pose formats, batch
rows, caches). Randomness is seeded.
"""

import math
import warnings

import numpy as np
import pytest

import proxima


def random_rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return q, np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix(rotation, translation):
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = translation
    return m


def cube(edge=1.0):
    h = edge / 2
    return np.array([[sx * h, sy * h, sz * h] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])


def world(polytope, pose_matrix):
    return polytope.vertices @ pose_matrix[:3, :3].T + pose_matrix[:3, 3]


def random_scene(rng, k, spread=2.0):
    """k pose matrices for A and for B, random orientations, centres within spread."""
    pa, pb = np.empty((k, 4, 4)), np.empty((k, 4, 4))
    for i in range(k):
        pa[i] = matrix(random_rotation(rng)[1], rng.uniform(-spread, spread, 3))
        pb[i] = matrix(random_rotation(rng)[1], rng.uniform(-spread, spread, 3))
    return pa, pb


@pytest.fixture(scope="module")
def bodies():
    rng = np.random.default_rng(1)
    return proxima.ConvexPolytope(rng.normal(size=(60, 3))), proxima.ConvexPolytope(rng.uniform(-1, 1, (40, 3)))


# --- hand-computed -----------------------------------------------------------


def test_unit_cubes_face_to_face():
    a = proxima.ConvexPolytope(cube())
    b = proxima.ConvexPolytope(cube())
    r = proxima.distance(a, None, b, proxima.Pose.from_translation((3, 0, 0)))
    assert r.status == "separated"
    assert r.distance == pytest.approx(2.0, rel=1e-15)
    assert r.lower_bound <= r.distance
    assert r.lower_bound == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(r.normal, [1, 0, 0], atol=1e-15)
    assert r.point_a[0] == pytest.approx(0.5)
    assert r.point_b[0] == pytest.approx(2.5)
    # The closest points lie on the facing faces (|y|, |z| <= 0.5).
    assert np.all(np.abs(r.point_a[1:]) <= 0.5) and np.all(np.abs(r.point_b[1:]) <= 0.5)


def test_vertex_to_vertex_along_the_diagonal():
    # B moved along the diagonal: the closest features are A's corner
    # (1,1,1)/2 and B's corner (1,1,1)/2 + t - (1,1,1), distance sqrt(3).
    a = proxima.ConvexPolytope(cube())
    r = proxima.distance(a, None, a, proxima.Pose.from_translation([2.0, 2.0, 2.0]))
    assert r.status == "separated"
    assert r.distance == pytest.approx(math.sqrt(3.0), rel=1e-15)
    assert r.feature_a.type == "vertex" and r.feature_b.type == "vertex"
    np.testing.assert_array_equal(r.point_a, [0.5, 0.5, 0.5])
    np.testing.assert_array_equal(r.point_b, [1.5, 1.5, 1.5])
    np.testing.assert_array_equal(a.vertices[r.feature_a.vertices[0]], [0.5, 0.5, 0.5])
    np.testing.assert_array_equal(a.vertices[r.feature_b.vertices[0]], [-0.5, -0.5, -0.5])


def test_overlap_and_contact():
    a = proxima.ConvexPolytope(cube())
    b = proxima.ConvexPolytope(cube())
    assert proxima.distance(a, None, b, proxima.Pose.from_translation((0.5, 0.1, 0))).status == "intersecting"
    touching = proxima.distance(a, None, b, proxima.Pose.from_translation((1.0, 0.2, 0.1)))
    assert touching.status == "touching"
    assert touching.distance <= 64 * 2.0**-53 * 2


# --- certificate against numpy -----------------------------------------------


@pytest.mark.parametrize("algorithm", ["hybrid", "gjk", "enhanced_gjk"])
def test_random_pairs_certified_in_numpy(algorithm):
    rng = np.random.default_rng(2)
    separated = 0
    for _ in range(200):
        a = proxima.ConvexPolytope(rng.normal(size=(rng.integers(4, 60), 3)))
        b = proxima.ConvexPolytope(rng.uniform(-1, 1, size=(rng.integers(4, 60), 3)))
        pa, pb = random_scene(rng, 1, spread=2.5)
        r = proxima.distance(a, pa[0], b, pb[0], algorithm=algorithm)
        assert np.all(np.isfinite(r.point_a)) and np.all(np.isfinite(r.point_b))
        assert r.lower_bound <= r.distance * (1 + 1e-12) + 1e-14
        if r.status != "separated":
            continue
        separated += 1
        va, vb = world(a, pa[0]), world(b, pb[0])
        scale = max(np.abs(va).max(), np.abs(vb).max())
        tol = 64 * 2.0**-53 * scale + 1e-12 * r.distance
        n = r.normal
        assert np.linalg.norm(n) == pytest.approx(1.0, abs=1e-12)
        assert np.linalg.norm(r.point_a - r.point_b) == pytest.approx(r.distance, abs=tol)
        # Optimality: the plane through point_a normal to n has all of A
        # behind it and all of B at least `distance` in front. The points are
        # right within 64 u R, so n's direction within 2 * 64 u R / distance,
        # which moves vertices up to a diameter away by that much more.
        diameter = np.ptp(np.vstack([va, vb]), axis=0).max()
        plane_tol = tol + 2 * 64 * 2.0**-53 * scale * diameter / r.distance
        assert np.max(va @ n) <= n @ r.point_a + plane_tol
        assert np.min(vb @ n) >= n @ r.point_a + r.distance - 2 * plane_tol
        # The witness features span the closest points.
        fa, fb = r.feature_a.vertices, r.feature_b.vertices
        assert 1 <= len(fa) <= 3 and 1 <= len(fb) <= 3
        for ids, verts, point in ((fa, va, r.point_a), (fb, vb, r.point_b)):
            # point is in the affine hull of the feature: least squares residual ~ 0
            base = verts[ids[0]]
            span = (verts[ids[1:]] - base).T if len(ids) > 1 else np.zeros((3, 0))
            if span.shape[1]:
                coef, *_ = np.linalg.lstsq(span, point - base, rcond=None)
                residual = np.linalg.norm(span @ coef - (point - base))
            else:
                residual = np.linalg.norm(point - base)
            assert residual <= 1e-9 * max(1.0, scale)
    assert 50 <= separated <= 190  # the random set has both kinds


def test_algorithms_agree(bodies):
    a, b = bodies
    rng = np.random.default_rng(3)
    pa, pb = random_scene(rng, 100, spread=3.0)
    for i in range(100):
        d = [proxima.distance(a, pa[i], b, pb[i], algorithm=alg).distance for alg in ("hybrid", "gjk", "enhanced_gjk")]
        assert d[1] == pytest.approx(d[0], rel=1e-9, abs=1e-12)
        assert d[2] == pytest.approx(d[0], rel=1e-9, abs=1e-12)


# --- pose formats ------------------------------------------------------------


def test_pose_formats_agree():
    rng = np.random.default_rng(4)
    points_a, points_b = rng.normal(size=(30, 3)), rng.normal(size=(30, 3))
    a, b = proxima.ConvexPolytope(points_a), proxima.ConvexPolytope(points_b)
    q, rot = random_rotation(rng)
    t = np.array([3.0, -1.0, 0.5])
    as_matrix = proxima.distance(a, None, b, matrix(rot, t))
    as_tuple = proxima.distance(a, None, b, (rot, t))
    as_list = proxima.distance(a, None, b, [rot.tolist(), list(t)])
    as_pose = proxima.distance(a, None, b, proxima.Pose.from_wxyz(q, t))
    as_pose_rt = proxima.distance(a, proxima.Pose(), b, proxima.Pose(rot, t))
    # The quaternion path builds the matrix in C++ (Eigen): equal up to rounding.
    for r in (as_tuple, as_list, as_pose):
        assert r.distance == pytest.approx(as_matrix.distance, rel=1e-13)
    assert as_pose_rt.distance == as_matrix.distance
    # Moving the points in numpy instead of passing a pose: the same hull up
    # to rounding of the coordinates.
    moved = proxima.ConvexPolytope(points_b @ rot.T + t)
    assert proxima.distance(a, None, moved, None).distance == pytest.approx(as_matrix.distance, rel=1e-12)
    # A non-unit quaternion is normalized, not a scale.
    assert proxima.distance(a, None, b, proxima.Pose.from_wxyz(3 * q, t)).distance == pytest.approx(
        as_pose.distance, rel=1e-13)


def test_pose_object():
    rng = np.random.default_rng(5)
    q, rot = random_rotation(rng)
    p = proxima.Pose.from_wxyz(q, [1, 2, 3])
    np.testing.assert_allclose(p.rotation, rot, atol=1e-15)
    np.testing.assert_array_equal(p.translation, [1, 2, 3])
    m = p.matrix()
    assert m.shape == (4, 4)
    np.testing.assert_array_equal(m[3], [0, 0, 0, 1])
    x = np.array([0.3, -0.2, 0.9])
    np.testing.assert_allclose(p.apply(x), rot @ x + [1, 2, 3], atol=1e-15)
    np.testing.assert_allclose((p * p.inverse()).matrix(), np.eye(4), atol=8e-16 * 4)  # |t| = 3.7: a few roundings of R^T t
    np.testing.assert_array_equal(proxima.Pose.from_matrix(m).matrix(), m)
    np.testing.assert_array_equal(proxima.Pose.from_translation([4, 5, 6]).translation, [4, 5, 6])
    assert proxima.Pose.identity().is_finite()


@pytest.mark.parametrize(
    "pose, words",
    [
        (np.diag([2.0, 1.0, 1.0, 1.0]), "not a rotation"),
        (np.diag([-1.0, 1.0, 1.0, 1.0]), "not a rotation"),  # a reflection
        (np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0.5, 1.0]]), "bottom row"),
        (np.eye(3), "4x4"),
        (((0, 0, 0, 0), (1, 2, 3)), "quaternion is zero"),
        (((1, 0, 0), (1, 2, 3)), "rotation must be a 3x3 matrix, a scipy Rotation or a quaternion"),
        ((np.eye(3), (1, 2)), "3 numbers"),
    ],
)
def test_bad_poses_are_value_errors(pose, words):
    a = proxima.ConvexPolytope(cube())
    with pytest.raises(ValueError, match=words):
        proxima.distance(a, None, a, pose)


def test_non_finite_pose_is_invalid_input_from_cpp():
    a = proxima.ConvexPolytope(cube())
    m = np.eye(4)
    m[1, 3] = np.nan
    with pytest.raises(proxima.InvalidInput, match="pose_b is not finite"):
        proxima.distance(a, None, a, m)


def test_float32_pose_is_accepted():
    rng = np.random.default_rng(6)
    a = proxima.ConvexPolytope(cube())
    m = matrix(random_rotation(rng)[1], [3, 0, 0]).astype(np.float32)
    r = proxima.distance(a, None, a, m)
    assert r.status == "separated"


@pytest.mark.parametrize("row, col", [(r, c) for r in range(4) for c in range(4)])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_entry_anywhere_in_a_4x4_pose_is_refused(row, col, bad):
    # Story: the bottom row was only compared with (0, 0, 0, 1) when finite,
    # so a NaN or an infinity there was accepted as the identity's row. Every
    # path that takes a 4x4 matrix must refuse it, naming the entry.
    a = proxima.ConvexPolytope(cube())
    m = matrix(np.eye(3), [3.0, 0.0, 0.0])
    m[row, col] = bad
    where = f"row {row}, column {col}"
    with pytest.raises(proxima.InvalidInput, match=f"pose_b is not finite.*{where}"):
        proxima.distance(a, None, a, m)
    with pytest.raises(proxima.InvalidInput, match=where):
        proxima.Pose.from_matrix(m)
    batch = np.tile(matrix(np.eye(3), [3.0, 0.0, 0.0]), (3, 1, 1))
    batch[2] = m
    with pytest.raises(proxima.InvalidInput, match=rf"poses_b\[2\] is not finite.*{where}"):
        proxima.distance_batch(a, None, a, batch)
    scene = proxima.Scene()
    i = scene.add(a)
    with pytest.raises(proxima.InvalidInput, match=where):
        scene.set_pose(i, m)
    with pytest.raises(proxima.InvalidInput, match=where):
        scene.add(a, m)
    assert len(scene) == 1


def test_complex_arrays_are_refused_everywhere():
    # Story: numpy's forcecast turned a complex array into its real part
    # without a word, so (1 + 5j) became 1 in a point, a pose, a quaternion
    # or a translation. Every array argument now checks its dtype first.
    a = proxima.ConvexPolytope(cube())
    pose = matrix(np.eye(3), [3.0, 0.0, 0.0])
    words = "expected real numbers.*complex"
    with pytest.raises(ValueError, match="points: " + words):
        proxima.ConvexPolytope(cube().astype(complex))
    with pytest.raises(ValueError, match="points: " + words):
        proxima.ConvexPolytope([[0, 0, 0], [1, 0, 0], [0, 1j, 0]])  # a list with one complex
    with pytest.raises(ValueError, match=r"pieces\[0\]: points: " + words):
        proxima.CompoundBody([cube().astype(complex)])
    with pytest.raises(ValueError, match="pose_b: " + words):
        proxima.distance(a, None, a, pose.astype(complex))
    with pytest.raises(ValueError, match="pose_b quaternion: " + words):
        proxima.distance(a, None, a, (np.array([1, 0, 0, 0], dtype=complex), (3, 0, 0)))
    with pytest.raises(ValueError, match="pose_b translation: " + words):
        proxima.distance(a, None, a, (np.eye(3), (3 + 1j, 0, 0)))
    with pytest.raises(ValueError, match="matrix: " + words):
        proxima.Pose.from_matrix(pose.astype(complex))
    with pytest.raises(ValueError, match="rotation: " + words):
        proxima.Pose(np.eye(3, dtype=complex), [0, 0, 0])
    with pytest.raises(ValueError, match="translation: " + words):
        proxima.Pose.from_translation(np.zeros(3, dtype=np.complex64))
    with pytest.raises(ValueError, match="point: " + words):
        proxima.Pose().apply(np.ones(3, dtype=complex))
    with pytest.raises(ValueError, match="poses_b: " + words):
        proxima.distance_batch(a, None, a, np.tile(pose, (2, 1, 1)).astype(complex))
    scene = proxima.Scene()
    i = scene.add(a)
    with pytest.raises(ValueError, match="pose: " + words):
        scene.set_pose(i, pose.astype(complex))
    with pytest.raises(ValueError, match="poses: " + words):
        scene.set_poses([i], pose[None].astype(complex))
    np.testing.assert_array_equal(scene.pose(i).matrix(), np.eye(4))
    # Strings are not numbers either (forcecast parsed them).
    with pytest.raises(ValueError, match="points: expected real numbers.*<U"):
        proxima.ConvexPolytope(cube().astype(str))
    # Integers and float32 are real numbers.
    assert proxima.ConvexPolytope(cube(2).astype(int)).vertex_count == 8
    assert proxima.distance(a, None, a, pose.astype(np.float32)).distance == pytest.approx(2.0)


@pytest.mark.parametrize("magnitude", [3e-162, 1e200, 1e-300, 1e300, 5e-324])
def test_quaternion_of_any_magnitude_is_its_rotation(magnitude):
    # Story: Python normalized a quaternion through its squared norm, which
    # overflows for 1e200 (1, 0, 0, 1) (the rotation became the identity)
    # and loses its digits for 3e-162 (1, 0, 0, 1) (a non-rigid matrix, det
    # 0.84). Python and the CLI now both use proxima's unit_quaternion: the
    # rotation is that of (1, 0, 0, 1), a quarter turn about z, bit for bit.
    q = magnitude * np.array([1.0, 0.0, 0.0, 1.0])
    unit = proxima.Pose.from_wxyz([1.0, 0.0, 0.0, 1.0], [0, 0, 0])
    pose = proxima.Pose.from_wxyz(q, [0, 0, 0])
    np.testing.assert_array_equal(pose.rotation, unit.rotation)
    np.testing.assert_allclose(pose.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    assert np.linalg.det(pose.rotation) == pytest.approx(1.0, abs=1e-15)
    # The same through every path that takes a pose.
    a = proxima.ConvexPolytope(np.array([[0.0, 0, 0], [1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]]))
    b = proxima.ConvexPolytope(np.array([[0.0, 0, 0]]))
    # B's point at (0, 2, 0) is A's vertex (1, 0, 0) turned a quarter about z,
    # plus (0, 1, 0): distance 1 exactly when the rotation is right.
    r = proxima.distance(a, proxima.Pose.from_wxyz(q), b, proxima.Pose.from_translation((0, 2, 0)))
    assert r.distance == pytest.approx(1.0, abs=1e-15)
    scene = proxima.Scene(margin=10.0)
    i = scene.add(a, proxima.Pose.from_wxyz(q))
    np.testing.assert_array_equal(scene.pose(i).rotation, unit.rotation)
    body = proxima.CompoundBody([(a, proxima.Pose.from_xyzw(np.roll(q, -1)))])
    np.testing.assert_array_equal(body.piece(0)[1].rotation, unit.rotation)


@pytest.mark.parametrize(
    "q, words",
    [((0, 0, 0, 0), "quaternion is zero"), ((0.0, -0.0, 0.0, -0.0), "quaternion is zero"),
     ((np.nan, 0, 0, 1), "not finite"), ((1, np.inf, 0, 0), "not finite")])
def test_zero_or_non_finite_quaternion_is_refused(q, words):
    with pytest.raises(proxima.InvalidInput, match="pose: .*" + words):
        proxima.Pose.from_wxyz(q, (0, 0, 0))
    scene = proxima.Scene()
    with pytest.raises(proxima.InvalidInput, match=words):
        scene.add(proxima.ConvexPolytope(cube()), (q, (0, 0, 0)))
    assert len(scene) == 0


# --- caches and tracking -----------------------------------------------------


def test_cache_tracking(bodies):
    a, b = bodies
    cache = proxima.DistanceCache()
    assert cache.is_cold()
    total_tracked = total_cold = 0
    for step in range(50):
        t = (3.0 + 0.01 * step, 0.5, 0.0)
        q = (math.cos(0.005 * step), 0.0, math.sin(0.005 * step), 0.0)
        tracked = proxima.distance(a, None, b, proxima.Pose.from_wxyz(q, t), cache=cache)
        cold = proxima.distance(a, None, b, proxima.Pose.from_wxyz(q, t))
        assert not cache.is_cold()
        assert tracked.distance == pytest.approx(cold.distance, rel=2.5e-12)
        if step > 0:
            total_tracked += tracked.iterations
            total_cold += cold.iterations
    assert 2 * total_tracked < total_cold
    cache.reset()
    assert cache.is_cold() and cache.hint_a == -1 and list(cache.vertices_a) == [-1, -1, -1, -1]


def test_cache_from_another_pair_is_harmless(bodies):
    a, b = bodies
    foreign = proxima.DistanceCache()
    proxima.distance(b, None, b, proxima.Pose.from_translation((5, 0, 0)), cache=foreign)
    foreign.hint_a, foreign.vertices_b = 10**6, [10**6, -5, 3, 2]
    r = proxima.distance(a, None, b, proxima.Pose.from_translation((4, 1, 0)), cache=foreign)
    assert r.distance == pytest.approx(proxima.distance(a, None, b, proxima.Pose.from_translation((4, 1, 0))).distance, rel=2.5e-12)


# --- batch --------------------------------------------------------------------


def test_batch_rows_equal_single_queries(bodies):
    a, b = bodies
    rng = np.random.default_rng(7)
    k = 300
    pa, pb = random_scene(rng, k)
    for threads in (1, 2, 0):
        out = proxima.distance_batch(a, pa, b, pb, threads=threads)
        assert set(out) >= {"status", "distance", "lower_bound", "point_a", "point_b", "normal", "iterations"}
        assert out["point_a"].shape == (k, 3) and out["distance"].shape == (k,)
        for i in range(k):
            r = proxima.distance(a, pa[i], b, pb[i])
            # The same C++ query: bit for bit.
            assert out["distance"][i] == r.distance
            assert out["lower_bound"][i] == r.lower_bound
            assert np.array_equal(out["point_a"][i], r.point_a)
            assert np.array_equal(out["point_b"][i], r.point_b)
            assert np.array_equal(out["normal"][i], r.normal)
            assert out["status"][i] == r.status
            assert out["iterations"][i] == r.iterations
            assert out["feature_a_type"][i] == r.feature_a.type
            assert list(out["feature_b_vertices"][i][: len(r.feature_b.vertices)]) == list(r.feature_b.vertices)
            assert out["feature_b_face"][i] == r.feature_b.face
    statuses = set(out["status"])
    assert {"separated", "intersecting"} <= statuses


def test_batch_caches_track_across_calls(bodies):
    a, b = bodies
    rng = np.random.default_rng(8)
    k = 200
    pa, pb = random_scene(rng, k)
    pb[:, :3, 3] = pa[:, :3, 3] + [5.0, 0.0, 0.0]  # all separated
    caches = [proxima.DistanceCache() for _ in range(k)]
    loop_caches = [proxima.DistanceCache() for _ in range(k)]
    for frame in range(3):
        out = proxima.distance_batch(a, pa, b, pb, caches=caches, threads=2)
        for i in range(k):
            r = proxima.distance(a, pa[i], b, pb[i], cache=loop_caches[i])
            assert out["distance"][i] == r.distance
            assert list(caches[i].vertices_a) == list(loop_caches[i].vertices_a)
            assert list(caches[i].vertices_b) == list(loop_caches[i].vertices_b)
            assert (caches[i].hint_a, caches[i].hint_b) == (loop_caches[i].hint_a, loop_caches[i].hint_b)
        if frame == 0:
            cold_iterations = out["iterations"].sum()
        pb[:, :3, 3] += 0.001
    assert not any(c.is_cold() for c in caches)
    assert 2 * out["iterations"].sum() < cold_iterations


def test_batch_broadcasts_one_pose(bodies):
    a, b = bodies
    k = 50
    pb = np.tile(np.eye(4), (k, 1, 1))
    pb[:, 0, 3] = np.linspace(3.0, 6.0, k)
    ident = proxima.distance_batch(a, None, b, pb)
    same = proxima.distance_batch(a, np.eye(4), b, pb)
    tupled = proxima.distance_batch(a, proxima.Pose.from_translation((0, 0, 0)), b, pb)
    np.testing.assert_array_equal(ident["distance"], same["distance"])
    np.testing.assert_array_equal(ident["distance"], tupled["distance"])
    swapped = proxima.distance_batch(b, pb, a, None)  # K from either side
    np.testing.assert_allclose(swapped["distance"], ident["distance"], rtol=1e-12)
    # Distance to a convex body along a line is convex in the parameter.
    d = ident["distance"]
    assert np.all(d[:-2] + d[2:] >= 2 * d[1:-1] - 1e-12)


def test_batch_errors(bodies):
    a, b = bodies
    pa = np.tile(np.eye(4), (10, 1, 1))
    pb = pa.copy()
    pb[:, 0, 3] = 5
    with pytest.raises(ValueError, match="9 poses, but the other side has 10"):
        proxima.distance_batch(a, pa, b, pb[:9])
    with pytest.raises(ValueError, match=r"\(K, 4, 4\) or \(K, 3, 4\)"):
        proxima.distance_batch(a, np.zeros((10, 3, 3)), b, pb)
    with pytest.raises(ValueError, match=r"poses_a\[0\]: rotation is not orthonormal"):
        proxima.distance_batch(a, np.zeros((10, 3, 4)), b, pb)
    with pytest.raises(ValueError, match="give K poses"):
        proxima.distance_batch(a, None, b, None)
    with pytest.raises(ValueError, match="caches: 3 caches for 10 poses"):
        proxima.distance_batch(a, pa, b, pb, caches=[proxima.DistanceCache() for _ in range(3)])
    with pytest.raises(ValueError, match=r"caches\[1\] is not a DistanceCache"):
        proxima.distance_batch(a, pa, b, pb, caches=[proxima.DistanceCache(), 7] + [proxima.DistanceCache()] * 8)
    bad = pb.copy()
    bad[3, 2, 3] = np.inf
    with pytest.raises(proxima.InvalidInput, match=r"poses_b\[3\] is not finite"):
        proxima.distance_batch(a, pa, b, bad)
    scaled = pb.copy()
    scaled[6, :3, :3] *= 2
    with pytest.raises(ValueError, match=r"poses_b\[6\].*not a rotation"):
        proxima.distance_batch(a, pa, b, scaled)
    with pytest.raises(proxima.InvalidInput, match=r"threads must be at least 0 \(0: all cores\), got -1"):
        proxima.distance_batch(a, pa, b, pb, threads=-1)
    with pytest.raises(proxima.InvalidInput, match="max_iterations must be at least 1"):
        proxima.distance_batch(a, np.tile(np.eye(4), (500, 1, 1)), b, None, max_iterations=0, threads=2)
    with pytest.raises(ValueError, match="algorithm must be"):
        proxima.distance_batch(a, pa, b, pb, algorithm="epa")


# --- polytope -----------------------------------------------------------------


def test_polytope_arrays_are_consistent():
    rng = np.random.default_rng(10)
    points = rng.normal(size=(80, 3))
    p = proxima.ConvexPolytope(points)
    v = p.vertices
    assert p.dimension == 3 and v.shape == (p.vertex_count, 3) and v.dtype == np.float64
    np.testing.assert_array_equal(v, points[p.input_index])
    assert p.interior_point_count == 80 - p.vertex_count
    assert p.scale == np.abs(v).max()
    np.testing.assert_allclose(p.centroid, v.mean(axis=0), atol=1e-15)
    assert p.bounding_radius == pytest.approx(np.linalg.norm(v - p.centroid, axis=1).max())
    # Adjacency: CSR, symmetric, the same edges as edges().
    off, adj = p.adjacency_offsets, p.adjacency
    assert off[0] == 0 and off[-1] == len(adj) and len(off) == p.vertex_count + 1
    pairs = {(u, int(w)) for u in range(p.vertex_count) for w in adj[off[u] : off[u + 1]]}
    assert all((w, u) in pairs for u, w in pairs)
    assert {(min(u, w), max(u, w)) for u, w in pairs} == {tuple(e) for e in p.edges()}
    assert p.edge_count == len(p.edges())
    np.testing.assert_array_equal(p.neighbors(0), adj[off[0] : off[1]])
    assert len(p.adjacency_faces) == len(adj)
    # Faces: on their planes, every vertex behind every plane (convexity),
    # Euler's formula V - E + F = 2.
    assert len(p.faces) == p.face_count
    assert p.vertex_count - p.edge_count + p.face_count == 2
    np.testing.assert_array_equal(np.concatenate(p.faces), p.face_vertices)
    for f, face in enumerate(p.faces):
        normal, offset = p.face_plane(f)
        np.testing.assert_array_equal(p.face(f), face)
        assert np.abs(v[face] @ normal - offset).max() < 1e-12
        assert (v @ normal).max() <= offset + 1e-12
    tri = p.triangles()
    assert tri.shape == (sum(len(f) - 2 for f in p.faces), 3)
    assert len(p.triangle_face()) == len(tri)
    assert p.memory_bytes() > v.nbytes
    with pytest.raises(IndexError):
        p.face(p.face_count)
    with pytest.raises(IndexError):
        p.neighbors(-1)


def test_lower_dimensional_polytopes():
    assert proxima.ConvexPolytope([[1.0, 2.0, 3.0]]).dimension == 0
    assert proxima.ConvexPolytope([[0, 0, 0], [1, 1, 1], [0.5, 0.5, 0.5]]).dimension == 1
    square = proxima.ConvexPolytope([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert square.dimension == 2 and square.face_count == 2
    r = proxima.distance(square, None, proxima.ConvexPolytope([[0.5, 0.5, 2.0]]), None)
    assert r.distance == pytest.approx(2.0, rel=1e-15)


def test_bad_points():
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        proxima.ConvexPolytope(np.zeros((5, 2)))
    with pytest.raises(proxima.InvalidInput):
        proxima.ConvexPolytope(np.zeros((0, 3)))
    pts = np.zeros((4, 3))
    pts[2, 1] = np.nan
    with pytest.raises(proxima.InvalidInput, match="2"):
        proxima.ConvexPolytope(pts)
    assert issubclass(proxima.InvalidInput, ValueError)
    assert issubclass(proxima.FileError, proxima.InvalidInput)


# --- files --------------------------------------------------------------------


def test_from_file(tmp_path):
    path = tmp_path / "cube.obj"
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in cube(2.0)] + ["v 0.1 0.2 0.3"]
    path.write_text("\n".join(lines) + "\n")
    with pytest.warns(proxima.NonConvexInputWarning, match="cube.obj: not convex"):
        p = proxima.ConvexPolytope.from_file(str(path))
    assert p.vertex_count == 8 and p.interior_point_count == 1 and p.face_count == 6
    loaded = proxima.load_convex(str(path))
    assert loaded.input_points == 9 and loaded.interior_points == 1 and not loaded.input_was_convex
    points = proxima.read_points(str(path))
    assert points.shape == (9, 3)
    np.testing.assert_array_equal(points[8], [0.1, 0.2, 0.3])


# Issue 9: ConvexPolytope.from_file returned the hull of a non-convex file
# without a word, where the CLI reports "not convex". It now warns
# NonConvexInputWarning (a UserWarning); load_convex reports in its result.
def test_non_convex_file_warns_convex_file_does_not(tmp_path):
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(1, 3, 4), (1, 4, 2), (5, 6, 8), (5, 8, 7), (1, 2, 6), (1, 6, 5),
             (3, 7, 8), (3, 8, 4), (1, 5, 7), (1, 7, 3), (2, 4, 8), (2, 8, 6)]
    text = "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
    text += "".join(f"f {a} {b} {c}\n" for a, b, c in faces)
    convex = tmp_path / "cube.obj"
    convex.write_text(text)
    folded = tmp_path / "folded.obj"
    folded.write_text(text + "f 1 4 6\n")  # through the inside: every vertex is on the hull
    assert issubclass(proxima.NonConvexInputWarning, UserWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert proxima.ConvexPolytope.from_file(str(convex)).vertex_count == 8
        assert proxima.load_convex(str(convex)).input_was_convex
        loaded = proxima.load_convex(str(folded))  # the report, no warning
    assert not loaded.input_was_convex and loaded.interior_points == 0
    with pytest.warns(proxima.NonConvexInputWarning, match="folded.obj: not convex"):
        p = proxima.ConvexPolytope.from_file(str(folded))
    assert p.vertex_count == 8
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(proxima.NonConvexInputWarning):
            proxima.ConvexPolytope.from_file(str(folded))


def test_file_errors(tmp_path):
    missing = tmp_path / "nope.obj"
    with pytest.raises(FileNotFoundError, match="nope.obj") as info:
        proxima.ConvexPolytope.from_file(str(missing))
    assert info.value.filename == str(missing)
    bad = tmp_path / "bad.obj"
    bad.write_text("v 1 2 3\nv 1 two 3\n")
    with pytest.raises(proxima.FileError, match="bad.obj, line 2") as info:
        proxima.ConvexPolytope.from_file(str(bad))
    assert isinstance(info.value, ValueError)
    with pytest.raises(FileNotFoundError):
        proxima.read_points(str(missing))


# --- documentation --------------------------------------------------------------


def test_every_binding_has_a_docstring():
    missing = []
    for name in dir(proxima):
        if name.startswith("_"):
            continue
        obj = getattr(proxima, name)
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if isinstance(obj, type) and not issubclass(obj, BaseException):
            for member in vars(obj):
                if member.startswith("_"):
                    continue
                if not (getattr(obj, member).__doc__ or "").strip():
                    missing.append(f"{name}.{member}")
    assert not missing, missing


# Issue 25: a bare quaternion still went through silently. proxima.distance
# (a, None, b, (q, t)) read q as (w, x, y, z), so a ROS user's (x, y, z, w)
# gave another rotation with no warning (0.0839 m where the right pose gives
# 0.0778 m in the case). Four numbers that do not name their order
# are now refused wherever a pose is taken, with what they mean in each order.
def test_a_bare_quaternion_is_refused_with_both_readings():
    a = proxima.ConvexPolytope(cube())
    ros_identity = (0.0, 0.0, 0.0, 1.0)
    both = (r"does not name its order: as \(w, x, y, z\) it is a turn of 180 degrees about "
            r"\(0, 0, 1\); as \(x, y, z, w\) \(ROS, scipy\) it is the identity")
    with pytest.raises(ValueError, match="pose_b: the quaternion .*" + both + r".*Pose.from_xyzw"):
        proxima.distance(a, None, a, (ros_identity, (3, 0, 0)))
    with pytest.raises(ValueError, match=both):
        proxima.Scene().add(a, (list(ros_identity), [3, 0, 0]))
    with pytest.raises(ValueError, match=both):
        proxima.CompoundBody([(a, (np.array(ros_identity), None))])
    with pytest.raises(ValueError, match=both + r".*order='wxyz' or order='xyzw'"):
        proxima.Pose.from_quaternion(ros_identity, (3, 0, 0))
    with pytest.raises(ValueError, match="order must be 'wxyz' or 'xyzw'"):
        proxima.Pose.from_quaternion(ros_identity, order="ros")
    # Named, each order is read as named: the ROS identity is the identity.
    np.testing.assert_array_equal(
        proxima.Pose.from_quaternion(ros_identity, order="xyzw").rotation, np.eye(3))
    r = proxima.distance(a, None, a, proxima.Pose.from_xyzw(ros_identity, (3, 0, 0)))
    assert r.distance == pytest.approx(2.0, rel=1e-15)
    # A quarter turn: the axis and angle of each reading.
    with pytest.raises(ValueError, match=r"as \(w, x, y, z\) it is a turn of 90 degrees about "
                                         r"\(0, 0, 1\); as \(x, y, z, w\) \(ROS, scipy\) it is a "
                                         r"turn of 90 degrees about \(1, 0, 0\)"):
        proxima.distance(a, None, a, ((1, 0, 0, 1), (3, 0, 0)))


# Issue 11, rotations that cannot be misread: a ROS/scipy quaternion
# (x, y, z, w) passed as a plain 4-tuple was read as (w, x, y, z): ROS's
# identity (0, 0, 0, 1) became a half turn about z. The orders now have
# names, and scipy Rotation objects and 3x4 matrices are taken as they are.
def test_quaternion_orders_are_named():
    ros_identity = (0.0, 0.0, 0.0, 1.0)
    np.testing.assert_array_equal(proxima.Pose.from_xyzw(ros_identity).rotation, np.eye(3))
    # The same four numbers read scalar first: the half turn about z.
    np.testing.assert_array_equal(
        proxima.Pose.from_wxyz(ros_identity).rotation, np.diag([-1.0, -1.0, 1.0]))
    rng = np.random.default_rng(11)
    q_wxyz, rot = random_rotation(rng)
    q_xyzw = np.roll(q_wxyz, -1)
    t = np.array([0.5, -2.0, 3.0])
    from_xyzw = proxima.Pose.from_xyzw(q_xyzw, t)
    from_wxyz = proxima.Pose.from_wxyz(q_wxyz, t)
    np.testing.assert_array_equal(from_xyzw.rotation, from_wxyz.rotation)
    np.testing.assert_allclose(from_xyzw.rotation, rot, atol=1e-15)
    np.testing.assert_array_equal(from_xyzw.translation, t)
    # Round trips, up to the quaternion's sign.
    sign = np.sign(from_wxyz.as_wxyz()[0]) * np.sign(q_wxyz[0])
    np.testing.assert_allclose(from_wxyz.as_wxyz() * sign, q_wxyz, atol=1e-15)
    np.testing.assert_allclose(from_xyzw.as_xyzw() * sign, q_xyzw, atol=1e-15)
    # The older name takes the order as a keyword.
    np.testing.assert_array_equal(
        proxima.Pose.from_quaternion(q_wxyz, t, order="wxyz").rotation, from_wxyz.rotation)
    np.testing.assert_array_equal(
        proxima.Pose.from_quaternion(q_xyzw, t, order="xyzw").rotation, from_wxyz.rotation)
    # The error names the order it expected.
    with pytest.raises(ValueError, match=r"4 numbers \(x, y, z, w\)"):
        proxima.Pose.from_xyzw((0.0, 0.0, 1.0))


def test_scipy_rotations_and_3x4_matrices_are_poses():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(12)
    a = proxima.ConvexPolytope(rng.normal(size=(25, 3)))
    b = proxima.ConvexPolytope(rng.normal(size=(25, 3)))
    r = Rotation.from_euler("xyz", [0.3, -1.1, 2.0])
    t = np.array([4.0, 0.5, -0.3])
    reference = proxima.distance(a, None, b, proxima.Pose(r.as_matrix(), t))
    as_pair = proxima.distance(a, None, b, (r, t))
    as_matrix_pair = proxima.distance(a, None, b, (r.as_matrix(), t))
    as_rows = proxima.distance(a, None, b, np.hstack([r.as_matrix(), t[:, None]]))
    from_rotation = proxima.distance(a, None, b, proxima.Pose.from_rotation(r, t))
    from_scipy_quat = proxima.distance(a, None, b, proxima.Pose.from_xyzw(r.as_quat(), t))
    for result in (as_pair, as_matrix_pair, as_rows, from_rotation):
        assert result.distance == reference.distance
    assert from_scipy_quat.distance == pytest.approx(reference.distance, rel=1e-13)
    # A rotation alone is a pose without translation.
    alone = proxima.distance(a, r, b, proxima.Pose.from_translation(t))
    assert alone.distance == proxima.distance(a, proxima.Pose(r.as_matrix(), [0, 0, 0]), b,
                                              proxima.Pose.from_translation(t)).distance
    # Batches take (K, 3, 4) poses too.
    rows = np.stack([np.hstack([Rotation.from_rotvec([0, 0, 0.1 * k]).as_matrix(), t[:, None]])
                     for k in range(4)])
    batch = proxima.distance_batch(a, None, b, rows)
    for k in range(4):
        single = proxima.distance(a, None, b, rows[k])
        assert batch["distance"][k] == single.distance
    # A stack of rotations where one is expected is refused by name.
    with pytest.raises(ValueError, match="a stack of 3 scipy rotations"):
        proxima.Pose.from_rotation(Rotation.from_rotvec(np.zeros((3, 3))))
    # A non-rigid 3x4 matrix is refused by the pose contract.
    with pytest.raises(ValueError, match="not orthonormal"):
        proxima.distance(a, None, b, np.hstack([1.01 * np.eye(3), t[:, None]]))


# Issue 11, Python at C++ speed: K different pairs in one call, each pair's
# cache kept inside the PairBatch. Row k equals the single tracked query of
# pair k, bit for bit, call after call.
def test_pair_batch_equals_single_tracked_queries():
    rng = np.random.default_rng(31)
    shapes = [proxima.ConvexPolytope(rng.normal(size=(int(rng.integers(8, 60)), 3))) for _ in range(7)]
    k = 50
    a = [shapes[i % 7] for i in range(k)]
    b = [shapes[(3 * i + 1) % 7] for i in range(k)]
    batch = proxima.PairBatch(a, b)
    assert len(batch) == k
    caches = [proxima.DistanceCache() for _ in range(k)]
    poses_b = np.tile(np.eye(4), (k, 1, 1))
    poses_b[:, :3, 3] = rng.uniform(-4, 4, size=(k, 3))
    statuses = set()
    for step in range(4):
        poses_b[:, :3, 3] += rng.normal(size=(k, 3)) * 0.05
        out = batch.distance(None, poses_b, threads=2)
        assert batch.last_call_seconds > 0
        for i in range(k):
            single = proxima.distance(a[i], None, b[i], poses_b[i], cache=caches[i])
            assert out["distance"][i] == single.distance
            assert out["status"][i] == single.status
            np.testing.assert_array_equal(out["point_b"][i], single.point_b)
            statuses.add(single.status)
    assert {"separated", "intersecting"} <= statuses  # premise: both kinds of pair
    batch.reset()
    with pytest.raises(ValueError, match="PairBatch: 2 bodies a but 1 bodies b"):
        proxima.PairBatch(a[:2], b[:1])
    with pytest.raises(TypeError, match=r"b\[1\]: expected a ConvexPolytope, a CompoundBody, a TriangleMesh or a Body, got str"):
        proxima.PairBatch(a[:2], [b[0], "x"])
    with pytest.raises(ValueError, match="poses_b"):
        batch.distance(None, poses_b[:3])


def pair_batch_scene(seed, k=40):
    """K pairs of random hulls at random poses, some overlapping."""
    rng = np.random.default_rng(seed)
    shapes = [proxima.ConvexPolytope(rng.normal(size=(int(rng.integers(8, 50)), 3))) for _ in range(6)]
    a = [shapes[i % 6] for i in range(k)]
    b = [shapes[(5 * i + 2) % 6] for i in range(k)]
    pa, pb = random_scene(rng, k, spread=1.5)
    return rng, a, b, pa, pb


def assert_same_answer(got, expected):
    assert list(got) == list(expected)
    for key, column in expected.items():
        assert got[key].dtype == column.dtype and got[key].shape == column.shape, key
        np.testing.assert_array_equal(got[key], column, err_msg=key)


# Issue 11, Python at C++ speed: out=<an earlier answer> fills that answer's
# arrays again in place, so that a tracking loop allocates nothing: the same
# dict and the same array objects come back, every row equal, bit for bit,
# to a twin batch's new arrays and to the single tracked query of its pair,
# call after call, on 1 and 2 threads.
def test_pair_batch_out_refills_the_same_arrays():
    rng, a, b, pa, pb = pair_batch_scene(33)
    k = len(a)
    batch, twin = proxima.PairBatch(a, b), proxima.PairBatch(a, b)
    caches = [proxima.DistanceCache() for _ in range(k)]
    out, arrays, statuses = None, None, set()
    for step in range(4):
        pb[:, :3, 3] += rng.normal(size=(k, 3)) * 0.05
        threads = 1 + step % 2
        fresh = twin.distance(pa, pb, threads=threads)
        got = batch.distance(pa, pb, threads=threads, out=out)
        if out is None:
            out, arrays = got, {key: id(column) for key, column in got.items()}
        assert got is out and {key: id(column) for key, column in got.items()} == arrays
        assert_same_answer(got, fresh)
        for i in range(k):
            single = proxima.distance(a[i], pa[i], b[i], pb[i], cache=caches[i])
            assert got["distance"][i] == single.distance and got["status"][i] == single.status
            assert got["signed_distance"][i] == single.signed_distance
            np.testing.assert_array_equal(got["point_a"][i], single.point_a)
            np.testing.assert_array_equal(got["normal"][i], single.normal)
            assert got["feature_b_type"][i] == single.feature_b.type
            statuses.add(single.status)
    assert {"separated", "intersecting"} <= statuses  # premise: both kinds of pair
    # A batch of Bodies fills its pieces too.
    bodies_a = [proxima.Body(p, 0.1) for p in a]
    body_batch, body_twin = proxima.PairBatch(bodies_a, b), proxima.PairBatch(bodies_a, b)
    body_out = body_batch.distance(pa, pb)
    body_twin.distance(pa, pb)
    pb[:, :3, 3] += 0.05
    assert body_batch.distance(pa, pb, out=body_out) is body_out
    assert_same_answer(body_out, body_twin.distance(pa, pb))


# out= is checked whole before anything runs: a dict that is not a K-row
# answer of this kind of batch (a missing, extra or renamed key, another K,
# dtype or byte order, a read-only or strided array, two keys sharing memory)
# raises ValueError naming the key, and neither the batch (its caches, its
# last_call_seconds) nor any array of out has changed.
def test_pair_batch_refuses_a_bad_out_before_anything_changes():
    rng, a, b, pa, pb = pair_batch_scene(34)
    k = len(a)
    batch, twin = proxima.PairBatch(a, b), proxima.PairBatch(a, b)
    out = batch.distance(pa, pb)
    twin.distance(pa, pb)
    before = {key: column.copy() for key, column in out.items()}
    seconds = batch.last_call_seconds
    pb[:, :3, 3] += 0.05

    def replaced(**columns):
        d = dict(out)
        d.update(columns)
        return d

    read_only = out["distance"].copy()
    read_only.flags.writeable = False
    renamed = dict(out)
    renamed["normals"] = renamed.pop("normal")
    body_answer = proxima.PairBatch([proxima.Body(p) for p in a], b).distance(pa, pb)
    cases = [
        ([out["distance"]], r"out: expected the dict of an earlier answer of this batch, got list"),
        (proxima.PairBatch(a[:3], b[:3]).distance(pa[:3], pb[:3]), r"out\['status'\]: expected <U13 of shape \(40,\), got <U13 of shape \(3,\)"),
        ({key: v for key, v in out.items() if key != "normal"}, r"expected the 16 arrays .*got 15 entries"),
        (renamed, r"out\['normal'\] is missing"),
        (body_answer, r"out: expected the 16 arrays of an answer of this batch \(without piece_a and piece_b\), got 18"),
        (replaced(distance=out["distance"].astype(np.float32)), r"out\['distance'\]: expected float64 of shape \(40,\), got float32"),
        (replaced(distance=out["distance"].astype(">f8")), r"out\['distance'\]: expected float64"),
        (replaced(iterations=out["iterations"].astype(np.int64)), r"out\['iterations'\]: expected int32"),
        (replaced(status=out["status"].astype("<U20")), r"out\['status'\]: expected <U13"),
        (replaced(point_a=out["point_a"].reshape(-1)), r"out\['point_a'\]: expected float64 of shape \(40, 3\), got float64 of shape \(120,\)"),
        (replaced(point_a=np.zeros((k, 6))[:, ::2]), r"out\['point_a'\]: the array must be C-contiguous, aligned and writeable"),
        (replaced(distance=read_only), r"out\['distance'\]: the array must be C-contiguous, aligned and writeable"),
        (replaced(lower_bound=out["distance"]), r"out\['lower_bound'\] shares memory with \['distance'\]"),
        (replaced(feature_b_vertices=out["feature_a_vertices"][::-1]), r"out\['feature_b_vertices'\]: the array must be C-contiguous"),
        (replaced(distance=list(out["distance"])), r"out\['distance'\]: expected a numpy array"),
    ]
    for bad, message in cases:
        with pytest.raises(ValueError, match=message):
            batch.distance(pa, pb, out=bad)
        assert batch.last_call_seconds == seconds  # the batch did not run
        for key, column in out.items():
            np.testing.assert_array_equal(column, before[key], err_msg=key)
    assert_same_answer(batch.distance(pa, pb, out=out), twin.distance(pa, pb))


# The pose contract on PairBatch's poses is checked once, by the C++ batch
# before its first query (the conversion only copies them): a non-finite
# entry, a rotation that is not orthonormal, a reflection, a bad bottom row
# or a complex array is refused naming the pose and its index, and neither
# the caches nor out have changed. A rotation off by float32 rounding is
# accepted and answered as the single query answers it (re-orthonormalized).
def test_pair_batch_refuses_bad_poses_naming_the_index():
    rng, a, b, pa, pb = pair_batch_scene(35)
    k = len(a)
    batch, twin = proxima.PairBatch(a, b), proxima.PairBatch(a, b)
    out = batch.distance(pa, pb)
    twin.distance(pa, pb)
    before = {key: column.copy() for key, column in out.items()}
    seconds = batch.last_call_seconds
    pb[:, :3, 3] += 0.05

    def changed(poses, index, entry, value):
        poses = poses.copy()
        poses[(index, *entry)] = value
        return poses

    reflected = pb.copy()
    reflected[5, :3, 0] *= -1
    stretched = pa.copy()
    stretched[3, :3, :3] *= 1.01
    cases = [
        (pa, changed(pb, 7, (0, 1), np.nan), r"PairBatch.distance: poses_b\[7\] is not finite"),
        (changed(pa, 39, (2, 3), np.inf), pb, r"PairBatch.distance: poses_a\[39\] is not finite"),
        (pa[:, :3, :], changed(pb[:, :3, :], 4, (1, 3), -np.inf), r"poses_b\[4\] is not finite"),
        (stretched, pb, r"PairBatch.distance: poses_a\[3\]: rotation is not orthonormal"),
        (pa, reflected, r"PairBatch.distance: poses_b\[5\]: rotation is a reflection"),
        (pa, changed(pb, 2, (3, 0), 0.5), r"poses_b\[2\]: the bottom row of a pose matrix must be \(0, 0, 0, 1\)"),
        (pa, changed(pb, 6, (3, 3), np.nan), r"poses_b\[6\] is not finite"),
        (pa, pb.astype(complex), r"poses_b: expected real numbers"),
    ]
    for poses_a, poses_b, message in cases:
        for threads in (1, 2):
            with pytest.raises(ValueError, match=message):
                batch.distance(poses_a, poses_b, threads=threads, out=out)
            assert batch.last_call_seconds == seconds  # the batch did not run
            for key, column in out.items():
                np.testing.assert_array_equal(column, before[key], err_msg=key)
    assert_same_answer(batch.distance(pa, pb, out=out), twin.distance(pa, pb))
    rounded = pb.astype(np.float32).astype(np.float64)
    assert np.abs(rounded[:, :3, :3] - pb[:, :3, :3]).max() > 0  # premise: not orthonormal to u
    cold = proxima.PairBatch(a, b).distance(pa, rounded, threads=2)
    for i in range(k):
        single = proxima.distance(a[i], pa[i], b[i], rounded[i])
        assert cold["distance"][i] == single.distance
        np.testing.assert_array_equal(cold["point_b"][i], single.point_b)


# --- signed distance ---------------------------------------------------------
# Every result carries the signed distance (distance when apart, minus the
# penetration depth when overlapping) and its certificate; the batch and the
# PairBatch give them as arrays.
def test_signed_distance_of_overlapping_and_separated_cubes():
    a = proxima.ConvexPolytope(cube())
    b = proxima.ConvexPolytope(cube())
    over = proxima.distance(a, None, b, proxima.Pose.from_translation((0.75, 0.1, 0.2)))
    assert over.status == "intersecting" and over.distance == 0.0
    assert math.isclose(over.signed_distance, -0.25, abs_tol=1e-15)
    assert math.isclose(over.depth, 0.25, abs_tol=1e-15)
    assert over.signed_lower_bound <= over.signed_distance <= over.signed_upper_bound
    np.testing.assert_allclose(over.normal, [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(over.point_b + over.depth * over.normal, over.point_a, atol=1e-15)
    apart = proxima.distance(a, None, b, proxima.Pose.from_translation((1.5, 0.1, 0.2)))
    assert apart.signed_distance == apart.distance and apart.depth == 0.0
    assert apart.signed_lower_bound == apart.lower_bound
    assert "signed_distance=" in repr(over)


def test_batch_and_pair_batch_carry_signed_distance_arrays(bodies):
    a, b = bodies
    rng = np.random.default_rng(11)
    k = 200
    pa, pb = random_scene(rng, k)
    out = proxima.distance_batch(a, pa, b, pb, threads=2)
    assert out["signed_distance"].shape == (k,)
    negative = 0
    for i in range(k):
        r = proxima.distance(a, pa[i], b, pb[i])
        assert out["signed_distance"][i] == r.signed_distance
        assert out["signed_lower_bound"][i] == r.signed_lower_bound
        assert out["signed_upper_bound"][i] == r.signed_upper_bound
        assert out["signed_lower_bound"][i] <= out["signed_distance"][i] <= out["signed_upper_bound"][i]
        assert (out["signed_distance"][i] < 0) == (r.status == "intersecting" and r.depth > 0)
        negative += r.signed_distance < 0
    assert negative >= 10
    batch = proxima.PairBatch([a] * k, [b] * k)
    out = batch.distance(pa, pb, threads=2)
    for i in range(k):
        assert out["signed_distance"][i] == proxima.distance(a, pa[i], b, pb[i]).signed_distance


def test_signed_distance_gradient_matches_central_differences():
    # B translated along x out of an overlap of 0.25: d sd / d t_b = normal.
    a = proxima.ConvexPolytope(cube())
    b = proxima.ConvexPolytope(cube())
    for t_b in ([0.75, 0.1, 0.2], [1.6, 0.3, -0.2]):
        pb = matrix(np.eye(3), t_b)
        r = proxima.distance(a, None, b, pb)
        g = proxima.signed_distance_gradient(r, None, pb)
        assert g.shape == (2, 6)
        h = 1e-6
        for k in range(3):
            plus, minus = pb.copy(), pb.copy()
            plus[k, 3] += h
            minus[k, 3] -= h
            fd = (proxima.distance(a, None, b, plus).signed_distance - proxima.distance(a, None, b, minus).signed_distance) / (2 * h)
            assert abs(fd - g[1, k]) <= 1e-6
            assert abs(g[0, k] + g[1, k]) == 0.0


def test_penetration_false_skips_the_depth_everywhere():
    # DistanceOptions.penetration as a keyword: an intersecting answer
    # without its depth, signed distance 0 in [-inf, 0]; separated answers
    # are the same either way.
    a = proxima.ConvexPolytope(cube())
    b = proxima.ConvexPolytope(cube())
    over = proxima.Pose.from_translation((0.75, 0.1, 0.2))
    r = proxima.distance(a, None, b, over, penetration=False)
    assert r.status == "intersecting" and r.signed_distance == 0.0 and r.depth == 0.0
    assert r.signed_lower_bound == -math.inf and r.signed_upper_bound == 0.0
    with pytest.raises(proxima.InvalidInput, match="penetration"):
        proxima.signed_distance_gradient(r, None, over)
    apart = proxima.Pose.from_translation((1.5, 0.1, 0.2))
    x = proxima.distance(a, None, b, apart, penetration=False)
    y = proxima.distance(a, None, b, apart)
    assert x.signed_distance == y.signed_distance and np.array_equal(x.point_a, y.point_a)
    poses_b = np.tile(np.eye(4), (2, 1, 1))
    poses_b[0, :3, 3] = over.translation
    poses_b[1, :3, 3] = apart.translation
    out = proxima.distance_batch(a, None, b, poses_b, penetration=False)
    assert list(out["signed_distance"]) == [0.0, y.signed_distance]
    batch = proxima.PairBatch([a, a], [b, b])
    out = batch.distance(None, poses_b, penetration=False)
    assert out["signed_lower_bound"][0] == -math.inf
    scene = proxima.Scene(margin=0.1, penetration=False)
    scene.add(a)
    scene.add(b, over)
    (pair,) = scene.step()
    assert pair.result.status == "intersecting" and pair.result.signed_distance == 0.0
