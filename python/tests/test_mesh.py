# Issue 12 from Python: triangle meshes from numpy arrays and files, against
# any body through distance(), explicit loading (mesh, hull or pieces).
# The referee is the convex query on the same shape given as a polytope.
import numpy as np
import pytest

import proxima


def cube(h=0.5):
    v = np.array([[x, y, z] for z in (-h, h) for y in (-h, h) for x in (-h, h)], float)
    f = np.array([[0, 2, 1], [1, 2, 3], [0, 1, 4], [1, 5, 4], [0, 4, 2], [2, 4, 6],
                  [1, 3, 5], [3, 7, 5], [2, 6, 3], [3, 6, 7], [4, 5, 6], [5, 7, 6]])
    return v, f


def test_mesh_from_arrays_and_its_properties():
    v, f = cube()
    m = proxima.TriangleMesh(v, f)
    assert (m.vertex_count, m.triangle_count, m.is_closed) == (8, 12, True)
    np.testing.assert_array_equal(m.vertices, v)
    np.testing.assert_array_equal(m.triangles, f)
    assert m.contains((0.1, 0.2, -0.3)) and not m.contains((1, 0, 0))
    assert not proxima.TriangleMesh(v, f[:10]).is_closed
    assert len(proxima.TriangleMesh(v, np.array([[0, 1, 1]])).degenerate_triangles) == 1
    assert "closed" in repr(m)


def test_mesh_against_any_body_equals_the_convex_query():
    v, f = cube()
    mesh = proxima.TriangleMesh(v, f)
    box = proxima.box((0.5, 0.5, 0.5))
    rng = np.random.default_rng(12)
    other = proxima.ConvexPolytope(rng.normal(size=(20, 3)) * 0.3)
    for k in range(40):
        pose = proxima.Pose.from_translation(tuple(rng.uniform(-3, 3, size=3)))
        want = proxima.distance(box, None, other, pose)
        got = proxima.distance(mesh, None, other, pose)
        assert type(got) is proxima.BodyResult
        if want.intersecting:
            assert got.status == "intersecting"
            continue
        assert got.signed_distance == pytest.approx(want.signed_distance, abs=1e-12)
        assert got.triangle_a >= 0 and got.triangle_b == -1
    body = proxima.Body(mesh, 0.1)
    assert body.kind == "mesh" and body.mesh is not None and body.compound is None
    assert "mesh" in repr(body)
    ball = proxima.sphere(0.2)
    r = proxima.distance(body, None, ball, proxima.Pose.from_translation((2, 0, 0)))
    assert r.signed_distance == pytest.approx(2 - 0.5 - 0.1 - 0.2, abs=1e-12)
    # A ball inside the closed cube overlaps it; mesh against mesh too.
    assert proxima.distance(mesh, None, proxima.sphere(0.1), None).status == "intersecting"
    small = proxima.TriangleMesh(*cube(0.1))
    assert proxima.distance(mesh, None, small, None).status == "intersecting"
    r = proxima.distance(mesh, None, small, proxima.Pose.from_translation((3, 0, 0)))
    assert r.distance == pytest.approx(2.4, abs=1e-12)
    assert r.triangle_a >= 0 and r.triangle_b >= 0


def test_gradient_of_a_mesh_overlap_names_the_real_reason():
    # Issue 26: the refusal blamed the penetration option (which was on); no
    # depth is defined for an overlap with a mesh, and the message says so.
    mesh = proxima.TriangleMesh(*cube(1.0))
    at = proxima.Pose.from_translation((0.9, 0, 0))
    r = proxima.distance(mesh, None, proxima.sphere(0.5), at)
    assert r.status == "intersecting"
    with pytest.raises(proxima.InvalidInput, match="triangle mesh"):
        proxima.signed_distance_gradient(r, None, at)
    box = proxima.box((1, 1, 1))
    g = proxima.signed_distance_gradient(proxima.distance(box, None, proxima.sphere(0.5), at), None, at)
    assert g.shape == (2, 6)


def test_options_a_mesh_cannot_honour_are_refused_by_name():
    # Issue 24: distance() and within_margin() with a mesh took algorithm,
    # relative_tolerance and max_iterations and silently ignored them.
    mesh = proxima.TriangleMesh(*cube())
    ball = proxima.sphere(0.2)
    at = proxima.Pose.from_translation((2, 0, 0))
    for field, value in (("algorithm", "gjk"), ("relative_tolerance", 1e-6), ("max_iterations", 8)):
        with pytest.raises(proxima.InvalidInput, match=f"options.{field} .* does not apply to a triangle mesh"):
            proxima.distance(mesh, None, ball, at, **{field: value})
        with pytest.raises(proxima.InvalidInput, match=f"options.{field} .* does not apply to a triangle mesh"):
            proxima.within_margin(ball, None, mesh, at, 0.1, **{field: value})
    # absolute_tolerance applies: the contact band widens.
    assert proxima.distance(mesh, None, ball, at, absolute_tolerance=2.0).status == "touching"


def test_bad_arrays_are_named():
    v, f = cube()
    with pytest.raises(ValueError, match="integer vertex indices"):
        proxima.TriangleMesh(v, f.astype(float))
    with pytest.raises(ValueError, match=r"\(F, 3\) array"):
        proxima.TriangleMesh(v, f[:, :2])
    with pytest.raises(ValueError, match="triangle 1 has vertex index -1"):
        proxima.TriangleMesh(v, np.array([[0, 1, 2], [0, -1, 2]]))
    with pytest.raises(proxima.InvalidInput, match="triangle 0"):
        proxima.TriangleMesh(v, np.array([[0, 1, 8]]))


def test_load_body_says_what_it_reads(tmp_path):
    # An L-shaped closed prism: non-convex, in two OBJ groups.
    outline = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    lines = [f"v {x} {y} {z}" for z in (0, 1) for x, y in outline]
    faces = [(1, 3, 2), (1, 4, 3), (1, 6, 4), (4, 6, 5), (7, 8, 9), (7, 9, 10), (7, 10, 12),
             (10, 11, 12)]
    for i in range(6):
        j = (i + 1) % 6
        faces += [(i + 1, j + 1, j + 7), (i + 1, j + 7, i + 7)]
    lines += ["g all"] + [f"f {a} {b} {c}" for a, b, c in faces]
    path = tmp_path / "l.obj"
    path.write_text("\n".join(lines) + "\n")
    mesh = proxima.load_body(str(path), as_="mesh")
    hull = proxima.load_body(str(path), as_="hull")
    pieces = proxima.load_body(str(path), as_="pieces", radius=0.01)
    assert (mesh.kind, hull.kind, pieces.kind) == ("mesh", "convex", "compound")
    assert pieces.radius == 0.01 and mesh.mesh.is_closed
    # In the notch: 0.5 from the L's surface, inside its hull.
    at = proxima.Pose.from_translation((1.5, 1.5, 0.5))
    ball = proxima.sphere(0.1)
    assert proxima.distance(mesh, None, ball, at).signed_distance == pytest.approx(0.4, abs=1e-12)
    assert proxima.distance(hull, None, ball, at).status == "intersecting"
    with pytest.raises(proxima.InvalidInput, match="load as 'convex'"):
        proxima.load_body(str(path), as_="convex")
    cloud = tmp_path / "cloud.xyz"
    cloud.write_text("0 0 0\n1 0 0\n0 1 0\n")
    with pytest.raises(proxima.FileError, match="no faces"):
        proxima.TriangleMesh.from_file(str(cloud))
    assert proxima.TriangleMesh.from_file(str(path)).triangle_count == 20
