"""proxima.view() and proxima.view_scene() (issue 15, "Look"): the page of
`proxima view` from Python, written by the same C++ writer. The browser test
(tests/viewer/viewer_browser_test.py) renders the CLI's pages; these check that the
Python pages carry the right data, go where they are asked to, and show
inline in a notebook (a stand-in IPython kernel here)."""

import json
import re
import sys
import types

import numpy as np
import pytest

import proxima


def cube(h=0.5):
    return proxima.ConvexPolytope([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])


def data_of(page):
    m = re.search(r'<script id="proxima-data" type="application/json">(.*?)</script>', page, re.S)
    assert m, "the page has no data"
    return json.loads(m.group(1))


def test_view_writes_the_pair_page(tmp_path):
    a, b = cube(), cube()
    pose_b = proxima.Pose.from_wxyz([0.9, 0.1, 0.3, 0.2], [2.0, 0.3, 0.1])
    path = tmp_path / "pair.html"
    page = proxima.view(a, b, pose_b=pose_b, path=path, name_a="left", name_b="right", inline=False)
    assert path.read_text(encoding="utf-8") == page
    assert page.startswith("<!doctype html>") and "three.js" in page
    data = data_of(page)
    r = proxima.distance(a, None, b, pose_b)
    assert data["kind"] == "pair" and data["title"] == "left and right"
    assert data["pair"]["distance"] == r.distance
    assert data["pair"]["signed_lower_bound"] == r.signed_lower_bound
    assert data["pair"]["point_b"] == list(r.point_b)
    assert data["pair"]["feature_a"]["type"] == str(r.feature_a.type).split(".")[-1]
    assert [b["name"] for b in data["bodies"]] == ["left", "right"]


def test_view_of_compounds_draws_every_piece():
    pieces = [np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float) + [2 * i, 0, 0]
              for i in range(3)]
    compound = proxima.CompoundBody(pieces)
    data = data_of(proxima.view(compound, proxima.Body(cube(), 0.1), pose_b=np.eye(4), inline=False))
    assert len(data["bodies"][0]["pieces"]) == 3
    assert data["bodies"][1]["radius"] == 0.1


def test_view_scene_draws_the_close_pairs(tmp_path):
    bodies = [cube() for _ in range(4)]
    poses = [proxima.Pose.from_translation([1.1 * i, 0, 0]) for i in range(4)]
    page = proxima.view_scene(bodies, poses, margin=0.2, path=str(tmp_path / "s.html"), inline=False)
    data = data_of(page)
    assert data["kind"] == "scene" and len(data["bodies"]) == 4
    assert sorted((p["a"], p["b"]) for p in data["pairs"]) == [(0, 1), (1, 2), (2, 3)]
    assert all(abs(p["distance"] - 0.1) < 1e-12 for p in data["pairs"])


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="b: expected a ConvexPolytope"):
        proxima.view(cube(), "not a body", inline=False)
    with pytest.raises(ValueError, match="pose_b"):
        proxima.view(cube(), cube(), pose_b=np.eye(3), inline=False)
    with pytest.raises(proxima.InvalidInput, match="2 bodies but 1 poses"):
        proxima.view_scene([cube(), cube()], [None], margin=0.1, inline=False)
    with pytest.raises(FileNotFoundError):
        proxima.view(cube(), cube(), path="/nonexistent/dir/page.html", inline=False)


def test_in_a_notebook_the_page_shows_inline(monkeypatch):
    shown = []
    ipython = types.ModuleType("IPython")
    display = types.ModuleType("IPython.display")
    kernel_shell = types.SimpleNamespace(kernel=object())
    ipython.get_ipython = lambda: kernel_shell
    display.HTML = lambda html: ("HTML", html)
    display.display = shown.append
    ipython.display = display
    monkeypatch.setitem(sys.modules, "IPython", ipython)
    monkeypatch.setitem(sys.modules, "IPython.display", display)
    page = proxima.view(cube(), cube(), pose_b=proxima.Pose.from_translation([3, 0, 0]))
    assert len(shown) == 1 and shown[0][0] == "HTML"
    assert shown[0][1].startswith("<iframe srcdoc=\"&lt;!doctype html&gt;")
    # Outside a kernel (a terminal IPython), nothing is shown.
    ipython.get_ipython = lambda: None
    proxima.view(cube(), cube())
    assert len(shown) == 1
    assert page


def test_names_cannot_end_the_data_script():
    # The data sits in a <script> element, which the first "</script" ends.
    name = "</script><script>alert(1)</script>"
    data = data_of(proxima.view(cube(), cube(), pose_b=proxima.Pose.from_translation([2, 0, 0]), name_a=name,
                                inline=False))
    assert data["bodies"][0]["name"] == name


def test_titles_and_names_are_inert_in_the_page():
    # Issue 25: only "</" was escaped, so a title or name holding
    # "<!--<script>" put the HTML parser in its "script data double escaped"
    # state and the data element swallowed three.js and the viewer code (the
    # page never rendered). No '<', '>', '&', U+2028 or U+2029 is written raw
    # in the data now; the browser test renders such pages.
    hostile = "<!--<script>&\u2028\u2029-->"
    page = proxima.view(cube(), cube(), pose_b=proxima.Pose.from_translation([2, 0, 0]), title=hostile,
                        name_a=hostile, inline=False)
    inside = re.search(r'<script id="proxima-data" type="application/json">(.*?)</script>', page, re.S).group(1)
    assert not re.search("[<>&\u2028\u2029]", inside), inside[:200]
    data = json.loads(inside)
    assert data["title"] == hostile and data["bodies"][0]["name"] == hostile
    scene = proxima.view_scene([cube(), cube()], [None, proxima.Pose.from_translation([2, 0, 0])], margin=1.0,
                               title=hostile, inline=False)
    assert data_of(scene)["title"] == hostile and "<!--<script>" not in scene.split("proxima-data")[1][:4000]
