#!/usr/bin/env python3
# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
#
# The viewer in a real browser (issue 15, "Look"): `proxima view` writes its
# pages (a convex pair from a query line, an intersecting pair from a query
# and its answer line, two compound bodies from OBJ files, two triangle
# meshes, one scene step),
# headless Chromium opens each from a file with the network off, and the test
# checks that the page rendered:
#   - the page says so (<body data-rendered="yes">, set after the first
#     frame; "error" and #errors filled on any failure);
#   - the browser's console is empty (Chromium logs every console message
#     as INFO:CONSOLE; the page writes none when all is well, three.js warns
#     through it);
#   - the label shows the answer's distance (or depth), the same double;
#   - the canvas is not blank: the screenshot below the text panel is far
#     from one flat colour (pixel variance);
#   - the wireframe toggle hides the faces (the compound page opened as
#     page.html#wireframe covers less of the canvas).
# Two pages built to fail (a script error; the canvas hidden) must fail the
# same checks, so the checks can fail.
#
#   viewer_browser_test.py --proxima build/release/cli/proxima --work DIR
#                          [--chromium PATH] [--no-browser] [--screenshots docs]
# --no-browser (the ASan build) only writes the pages and checks their data;
# --screenshots DIR keeps one screenshot per view kind there (docs/).
import argparse
import concurrent.futures
import json
import math
import os
import re
import shutil
import subprocess
import sys

WIDTH, HEIGHT = 1000, 700
PANEL_BOTTOM = 190  # the text panel's height, left out of the blank-canvas check
# Browsers open at once: each mostly waits, and four kept two cores busy.
BROWSERS = 4


def run(args, **kw):
    r = subprocess.run(args, capture_output=True, text=True, timeout=120, **kw)
    if r.returncode != 0:
        sys.exit(f"FAILED: {' '.join(args)} exited {r.returncode}\n{r.stdout}\n{r.stderr}")
    return r.stdout


def page_data(path):
    """The JSON the page draws (its <script id="proxima-data">)."""
    text = open(path, encoding="utf-8").read()
    m = re.search(r'<script id="proxima-data" type="application/json">(.*?)</script>', text, re.S)
    assert m, f"{path}: no data element"
    return json.loads(m.group(1))


def browse(chromium, page, work, name, fragment=""):
    """Opens `page` headless; returns (body state, label value, errors, console lines, png)."""
    png = os.path.join(work, name + ".png")
    if os.path.exists(png):
        os.remove(png)
    # One profile per page: the pages are opened at the same time (browse_all).
    profile = os.path.join(work, "chromium-profile-" + name)
    args = [chromium, "--headless", "--no-sandbox", "--no-first-run", "--user-data-dir=" + profile,
            # WebGL on the CPU (SwiftShader): the test machines have no GPU.
            "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
            # No network at all: the page must need none.
            "--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
            "--window-size=%d,%d" % (WIDTH, HEIGHT), "--hide-scrollbars",
            # Virtual time runs only while the page is idle: the budget is
            # reached after three.js is parsed and the frame drawn, however
            # slow the machine.
            "--virtual-time-budget=10000", "--enable-logging=stderr", "--v=0",
            "--dump-dom", "--screenshot=" + png, "file://" + os.path.abspath(page) + fragment]
    r = subprocess.run(args, capture_output=True, text=True, timeout=90)
    if r.returncode != 0 or not os.path.exists(png):
        sys.exit(f"FAILED: chromium on {page} exited {r.returncode}\n{r.stderr[-3000:]}")
    dom = r.stdout
    state = re.search(r'<body[^>]*?data-rendered="(\w+)"', dom)
    label = re.search(r'<div id="label"[^>]*?data-value="([^"]*)"', dom)
    errors = re.search(r'<div id="errors">(.*?)</div>', dom, re.S)
    console = [line for line in r.stderr.splitlines() if ":CONSOLE" in line]
    return (state.group(1) if state else None, label.group(1) if label else None,
            errors.group(1).strip() if errors else None, console, png)


def browse_all(chromium, work, jobs):
    """Opens every (name, page, fragment) of `jobs`, several at a time; returns
    browse()'s answer by name. Most of a headless Chromium's time on a page is
    spent waiting (its start, the virtual-time budget), not computing, and
    one page after the other was most of the test's time."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=BROWSERS) as pool:
        futures = {name: pool.submit(browse, chromium, page, work, name, fragment)
                   for name, page, fragment in jobs}
        return {name: future.result() for name, future in futures.items()}


def canvas_variance(png):
    """Variance of the grey levels below the panel, and the share of pixels
    that differ from the most common one (the background)."""
    from PIL import Image
    image = Image.open(png).convert("L")
    region = image.crop((0, PANEL_BOTTOM, image.width, image.height))
    histogram = region.histogram()
    n = sum(histogram)
    mean = sum(i * c for i, c in enumerate(histogram)) / n
    variance = sum(c * (i - mean) ** 2 for i, c in enumerate(histogram)) / n
    drawn = 1.0 - max(histogram) / n
    return variance, drawn


def check_rendered(browsed, name, expected_label=None):
    """Returns what is wrong with the page `name` as browse_all rendered it
    (empty: fine), the screenshot and the share of the canvas drawn."""
    state, label, errors, console, png = browsed[name]
    problems = []
    if state != "yes":
        problems.append(f"the page did not render (data-rendered={state!r}, errors: {errors!r})")
    if errors:
        problems.append(f"the page reports errors: {errors!r}")
    if console:
        problems.append("the console is not empty:\n    " + "\n    ".join(console))
    if expected_label is not None and (label is None or float(label) != expected_label):
        problems.append(f"the label shows {label!r}, the answer is {expected_label!r}")
    variance, drawn = canvas_variance(png)
    # A blank canvas is one colour: variance 0, nothing drawn. The bodies
    # cover 5 to 30 % of the canvas in these pages.
    if variance < 20.0 or drawn < 0.01:
        problems.append(f"the canvas looks blank (grey variance {variance:.1f}, "
                        f"{100 * drawn:.2f} % of pixels drawn)")
    print(f"  {name}: rendered={state} label={label} console={len(console)} "
          f"variance={variance:.1f} drawn={100 * drawn:.1f}%")
    return problems, png, drawn


def tetrahedron(offset, s=1.0):
    x, y, z = offset
    return [[x, y, z], [x + s, y, z], [x, y + s, z], [x, y, z + s]]


def box_points(lo, hi):
    return [[a, b, c] for a in (lo[0], hi[0]) for b in (lo[1], hi[1]) for c in (lo[2], hi[2])]


def write_obj(path, groups):
    """An OBJ file whose groups are a compound's pieces (point groups, no faces)."""
    with open(path, "w") as f:
        for name, points in groups:
            f.write(f"g {name}\n")
            for p in points:
                f.write("v %r %r %r\n" % tuple(p))


def check_bad_input(proxima, w):
    """Bad input: exit 1 (2 for usage) and a message naming what and where."""
    good = json.dumps({"id": 1, "a": {"vertices": tetrahedron([0, 0, 0])},
                       "b": {"vertices": tetrahedron([3, 0, 0])}})
    cases = [
        # (file content or None, extra arguments, exit code, words the message must hold)
        (good + "\n" + good.replace('"id": 1', '"id": 2') + "\n", [], 1, "the answer's id"),
        (good + "\n" + good + "\n" + good + "\n", [], 1, "line 3: expected one query line"),
        ('{"id": 1, "status": "separated"}\n', [], 1, "this is an answer line"),
        (good.replace("[3, 0, 0]", '[3, "x", 0]') + "\n", [], 1, "the query has no answer: line 1: b.vertices[0][1]"),
        ('{"id": 1, "status": "error", "error": "line 1: boom"}\n', [], 1, "answer line"),
        ("", [], 1, "no query line"),
        ("not json\n", [], 1, "line 1:"),
    ]
    for i, (content, extra, code, words) in enumerate(cases):
        path = w(f"bad{i}.jsonl")
        open(path, "w").write(content)
        r = subprocess.run([proxima, "view", "--query", path, "--out", w("bad.html"), *extra],
                           capture_output=True, text=True, timeout=60)
        assert r.returncode == code and words in r.stderr, (i, r.returncode, r.stderr)
    # A scene body with a radius; an unreadable mesh file; no input; two inputs.
    open(w("bad_scene.jsonl"), "w").write(json.dumps({"vertices": [[0, 0, 0]], "radius": 1}) + "\n")
    for args, code, words in [
        (["--scene", w("bad_scene.jsonl")], 1, "bad_scene.jsonl, line 1: a scene's body has no radius"),
        ([w("missing.obj"), w("missing.obj")], 1, "missing.obj"),
        ([], 2, "exactly one of them"),
        (["--query", w("pair.jsonl"), "--scene", w("scene.jsonl")], 2, "exactly one of them"),
        (["--scene", w("pair.jsonl"), "--margin", "-1"], 1, "--margin"),
        # Issue 25: `view` took the hull of a non-convex file that `distance`
        # refuses; both now read files the same way (--as).
        ([w("l.obj"), w("cube.obj")], 1, "l.obj: not convex (its surface is not its hull's boundary)"),
        # Issue 25 (view_devzero.sh): --query and --scene read their file
        # whole with no cap, so /dev/zero grew to std::bad_alloc. The cap
        # counts the bytes as they are read.
        (["--query", "/dev/zero", "--max-file-size", "1000000"], 1,
         "'/dev/zero' is larger than --max-file-size (1000000 bytes)"),
        (["--scene", "/dev/zero", "--max-file-size", "2000000"], 1,
         "'/dev/zero' is larger than --max-file-size (2000000 bytes)"),
    ]:
        r = subprocess.run([proxima, "view", *args, "--out", w("bad.html")], capture_output=True,
                           text=True, timeout=60)
        assert r.returncode == code and words in r.stderr, (args, r.returncode, r.stderr)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--proxima", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--chromium", default=shutil.which("chromium") or "")
    ap.add_argument("--no-browser", action="store_true")
    ap.add_argument("--screenshots", default="")
    opt = ap.parse_args()
    os.makedirs(opt.work, exist_ok=True)
    proxima = opt.proxima
    w = lambda name: os.path.join(opt.work, name)
    pages = []  # (name, page, label the answer gives, or None)

    # 1. A convex pair: the query line alone, answered by `proxima view`.
    query = {"id": "pair", "a": {"vertices": box_points([-1, -1, -1], [1, 1, 1])},
             "b": {"vertices": tetrahedron([0, 0, 0], 1.5), "rotation": {"wxyz": [0.9, 0.2, 0.3, 0.1]},
                   "translation": [2.2, 0.6, 0.9]}}
    line = json.dumps(query)
    open(w("pair.jsonl"), "w").write(line + "\n")
    answer = json.loads(run([proxima, "query", w("pair.jsonl")]))
    assert answer["status"] == "separated", answer
    run([proxima, "view", "--query", w("pair.jsonl"), "--out", w("pair.html")])
    pages.append(("pair", w("pair.html"), answer["distance"]))

    # 2. An intersecting pair, its answer line given: the label is the depth.
    query = {"id": 3, "a": {"vertices": box_points([0, 0, 0], [2, 2, 2])},
             "b": {"vertices": box_points([0, 0, 0], [1, 1, 1]), "translation": [1.6, 0.5, 0.4],
                   "rotation": {"wxyz": [0.95, 0.1, 0.2, 0.0]}}}
    open(w("overlap.jsonl"), "w").write(json.dumps(query) + "\n")
    answer_line = run([proxima, "query", w("overlap.jsonl")])
    answer = json.loads(answer_line)
    assert answer["status"] == "intersecting", answer
    open(w("overlap.jsonl"), "a").write(answer_line)
    run([proxima, "view", "--query", w("overlap.jsonl"), "--out", w("overlap.html")])
    pages.append(("overlap", w("overlap.html"), -answer["signed_distance"]))  # the depth

    # 2b. Bodies at 1e39 (the paper scales cubes to 1e39): float32 vertices
    # overflow past 3.4e38. The first viewer sent the world coordinates to
    # the GPU as they were: this page was blank and three.js logged NaN
    # bounding spheres. It now draws every point as (p - center) / extent,
    # computed in doubles; the label keeps the answer's numbers.
    big = 1e39
    query = {"id": "huge", "a": {"vertices": [[big * c for c in p] for p in box_points([-1, -1, -1], [1, 1, 1])]},
             "b": {"vertices": [[big * c for c in p] for p in tetrahedron([0, 0, 0], 1.5)],
                   "translation": [2.5 * big, 0.4 * big, 0.2 * big], "rotation": {"wxyz": [0.9, 0.2, 0.3, 0.1]}}}
    open(w("huge.jsonl"), "w").write(json.dumps(query) + "\n")
    answer = json.loads(run([proxima, "query", w("huge.jsonl")]))
    run([proxima, "view", "--query", w("huge.jsonl"), "--out", w("huge.html")])
    pages.append(("huge", w("huge.html"), answer["distance"]))

    # 3. Two compound bodies (OBJ groups): a table and an L-shaped bracket.
    table = [("top", box_points([-1, -1, 0.9], [1, 1, 1]))] + [
        (f"leg{i}", box_points([sx * 0.9 - 0.05, sy * 0.9 - 0.05, 0], [sx * 0.9 + 0.05, sy * 0.9 + 0.05, 0.9]))
        for i, (sx, sy) in enumerate([(-1, -1), (-1, 1), (1, -1), (1, 1)])]
    bracket = [("base", box_points([0, 0, 0], [1, 0.3, 0.1])), ("upright", box_points([0, 0, 0], [0.1, 0.3, 0.8]))]
    write_obj(w("table.obj"), table)
    write_obj(w("bracket.obj"), bracket)
    pose_b = ["1.3", "-0.15", "0.95", "0.98", "0.0", "0.0", "0.2"]
    # The compounds' distance, independently: `proxima query` on every pair
    # of pieces, the smallest.
    with open(w("pieces.jsonl"), "w") as f:
        for _, pa in table:
            for _, pb in bracket:
                f.write(json.dumps({"a": {"vertices": pa}, "b": {
                    "vertices": pb, "translation": [float(t) for t in pose_b[:3]],
                    "rotation": {"wxyz": [float(q) for q in pose_b[3:]]}}}) + "\n")
    expected = min(json.loads(l)["distance"] for l in run([proxima, "query", w("pieces.jsonl")]).splitlines())
    run([proxima, "view", w("table.obj"), w("bracket.obj"), "--as", "pieces", "--pose-b", *pose_b,
         "--quaternion-order", "wxyz", "--out", w("compound.html")])
    data = page_data(w("compound.html"))
    assert [len(b["pieces"]) for b in data["bodies"]] == [5, 2], "the compounds lost pieces"
    assert data["pair"]["status"] == "separated", data["pair"]
    assert abs(data["pair"]["distance"] - expected) <= 1e-12, (data["pair"]["distance"], expected)
    pages.append(("compound", w("compound.html"), data["pair"]["distance"]))

    # 4. Two triangle meshes (--as mesh): an L-shaped prism (non-convex,
    # closed, 20 triangles) and a small cube mesh in its notch, 0.3 from both
    # inner walls (x = 1 and y = 1) while inside the L's hull.
    outline = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    l_faces = [(1, 3, 2), (1, 4, 3), (1, 6, 4), (4, 6, 5), (7, 8, 9), (7, 9, 10), (7, 10, 12),
               (10, 11, 12)]
    for i in range(6):
        j = (i + 1) % 6
        l_faces += [(i + 1, j + 1, j + 7), (i + 1, j + 7, i + 7)]
    with open(w("l.obj"), "w") as f:
        f.writelines(f"v {x} {y} {z}\n" for z in (0, 1) for x, y in outline)
        f.writelines(f"f {a} {b} {c}\n" for a, b, c in l_faces)
    cube = box_points([-0.2, -0.2, -0.2], [0.2, 0.2, 0.2])  # corner i: bits (x, y, z) = (i>>2, i>>1, i) & 1
    cube_faces = [(1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2), (3, 4, 8),
                  (3, 8, 7), (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4)]
    with open(w("cube.obj"), "w") as f:
        f.writelines("v %r %r %r\n" % tuple(p) for p in cube)
        f.writelines(f"f {a} {b} {c}\n" for a, b, c in cube_faces)
    run([proxima, "view", w("l.obj"), w("cube.obj"), "--as", "mesh", "--pose-b", "1.5", "1.5", "0.5",
         "--out", w("mesh.html")])
    data = page_data(w("mesh.html"))
    assert [len(b["pieces"][0]["triangles"]) // 3 for b in data["bodies"]] == [20, 12], "the meshes lost triangles"
    assert data["pair"]["status"] == "separated", data["pair"]
    assert abs(data["pair"]["distance"] - 0.3) <= 1e-12, data["pair"]["distance"]
    pages.append(("mesh", w("mesh.html"), data["pair"]["distance"]))

    # 5. One scene step: a 4 x 4 grid of turned cubes, some close.
    with open(w("scene.jsonl"), "w") as f:
        for i in range(16):
            x, y = i % 4, i // 4
            angle = 0.37 * i
            f.write(json.dumps({"vertices": box_points([-0.35, -0.35, -0.35], [0.35, 0.35, 0.35]),
                                "rotation": {"wxyz": [math.cos(angle / 2), 0.3 * math.sin(angle / 2), 0.0,
                                                      math.sin(angle / 2)]},
                                "translation": [x * (1.0 + 0.04 * y), y * 1.02, 0.05 * x * y]}) + "\n")
    run([proxima, "view", "--scene", w("scene.jsonl"), "--margin", "0.45", "--out", w("scene.html")])
    data = page_data(w("scene.html"))
    assert len(data["bodies"]) == 16 and len(data["pairs"]) > 0, "the scene has no close pair"
    assert all(p["distance"] <= 0.45 for p in data["pairs"])
    pages.append(("scene", w("scene.html"), None))

    # 6. Hostile text (issue 25): the page once escaped only "</" in its
    # data, so an id, a file name or a title holding "<!--<script>" put the
    # HTML parser in its "script data double escaped" state, the data element
    # swallowed three.js and the viewer code, and the page stayed at "loading
    # three.js..." with no error. Every string from input must be inert: the
    # data element holds no '<', '>' or '&' at all, and the pages render.
    hostile = "<!--<script></script><script>document.body.dataset.rendered='pwned'</script>-->&\u2028\u2029"
    query = {"id": hostile, "a": {"vertices": tetrahedron([0, 0, 0])},
             "b": {"vertices": tetrahedron([2, 0, 0])}}
    open(w("hostile.jsonl"), "w", encoding="utf-8").write(json.dumps(query, ensure_ascii=False) + "\n")
    answer = json.loads(run([proxima, "query", w("hostile.jsonl")]))
    run([proxima, "view", "--query", w("hostile.jsonl"), "--out", w("hostile-id.html")])
    assert hostile in page_data(w("hostile-id.html"))["title"], page_data(w("hostile-id.html"))["title"]
    pages.append(("hostile-id", w("hostile-id.html"), answer["distance"]))
    # File names: any bytes but '/' and NUL, so also bytes that are not
    # UTF-8 (which once failed with json type_error.316).
    names = [os.fsencode(w("<!--<script>&\u2028a.xyz")), os.fsencode(w("b")) + b"\xff<!--<script>.xyz"]
    for name, offset in zip(names, ([0, 0, 0], [2, 0, 0])):
        with open(name, "w") as f:
            f.writelines("%r %r %r\n" % tuple(p) for p in tetrahedron(offset))
    r = subprocess.run([os.fsencode(proxima), b"view", *names, b"--out", os.fsencode(w("hostile-names.html"))],
                       capture_output=True, timeout=120)
    assert r.returncode == 0, r.stderr
    data = page_data(w("hostile-names.html"))
    assert data["bodies"][0]["name"] == "<!--<script>&\u2028a.xyz", data["bodies"][0]["name"]
    assert data["bodies"][1]["name"] == "b\ufffd<!--<script>.xyz", data["bodies"][1]["name"]
    pages.append(("hostile-names", w("hostile-names.html"), data["pair"]["distance"]))
    for name in ("hostile-id", "hostile-names"):
        text = open(w(name + ".html"), encoding="utf-8").read()
        inside = re.search(r'<script id="proxima-data" type="application/json">(.*?)</script>', text, re.S)
        assert not re.search("[<>&\u2028\u2029]", inside.group(1)), f"{name}: the data holds raw markup"

    check_bad_input(proxima, w)

    # A time-of-impact line: the bodies drawn at the time found (the
    # answer's poses), no bounds (null).
    hit = {"id": "hit", "a": {"vertices": box_points([-1, -1, -1], [1, 1, 1])},
           "b": {"vertices": box_points([-1, -1, -1], [1, 1, 1]), "translation": [5, 0, 0],
                 "pose_end": {"translation": [-5, 0, 0]}}}
    open(w("hit.jsonl"), "w").write(json.dumps(hit) + "\n")
    answer = json.loads(run([proxima, "query", w("hit.jsonl")]))
    run([proxima, "view", "--query", w("hit.jsonl"), "--out", w("hit.html")])
    data = page_data(w("hit.html"))
    assert data["pair"]["status"].startswith("contact, t = ") and data["pair"]["signed_lower_bound"] is None
    b_x = data["bodies"][1]["pieces"][0]["positions"][0::3]
    assert min(b_x) == answer["pose_b"]["translation"][0] - 1, (min(b_x), answer["pose_b"])

    # The pages' data say what the answers said.
    pair = page_data(w("pair.html"))["pair"]
    assert pair["distance"] == pages[0][2] and pair["feature_a"]["points"], pair
    if opt.no_browser:
        print("pages written and checked; no browser (--no-browser)")
        return 0

    if not opt.chromium or not os.path.exists(opt.chromium):
        sys.exit("FAILED: no chromium (scripts/setup installs Debian's chromium)")
    # The checks can fail: a page whose script throws, and one whose canvas
    # is hidden, must each be caught (the controls, checked below).
    html = open(w("pair.html"), encoding="utf-8").read()
    broken = html.replace("const data = JSON.parse(", "undefinedFunction(); const data = JSON.parse(", 1)
    hidden = html.replace("#view { position: absolute;", "#view { display: none; position: absolute;", 1)
    assert broken != html and hidden != html, "the page template changed: update the controls"
    open(w("broken.html"), "w", encoding="utf-8").write(broken)
    open(w("hidden.html"), "w", encoding="utf-8").write(hidden)

    # Every page at once, the wireframe toggle opened checked through #wireframe.
    browsed = browse_all(opt.chromium, opt.work,
                         [(name, page, "") for name, page, _ in pages] +
                         [("wireframe", w("compound.html"), "#wireframe"),
                          ("broken", w("broken.html"), ""), ("hidden", w("hidden.html"), "")])
    failures = []
    shots = {}
    drawn = {}
    for name, page, label in pages:
        problems, png, drawn[name] = check_rendered(browsed, name, label)
        failures += [f"{name}: {p}" for p in problems]
        shots[name] = png

    # The wireframe toggle: the faces hidden, the edges and the witness still
    # drawn, less canvas covered.
    problems, _, wire = check_rendered(browsed, "wireframe", {n: l for n, _, l in pages}["compound"])
    failures += [f"wireframe: {p}" for p in problems]
    if not wire < 0.7 * drawn["compound"]:
        failures.append(f"wireframe: {100 * wire:.1f} % of the canvas drawn, with faces "
                        f"{100 * drawn['compound']:.1f} %: the faces were not hidden")

    problems, _, _ = check_rendered(browsed, "broken", pages[0][2])
    if not any("console" in p for p in problems) or not any("did not render" in p for p in problems):
        failures.append(f"control: a script error went unnoticed ({problems})")
    problems, _, _ = check_rendered(browsed, "hidden", pages[0][2])
    if not any("blank" in p for p in problems):
        failures.append(f"control: a hidden canvas went unnoticed ({problems})")

    if failures:
        sys.exit("FAILED:\n" + "\n".join(failures))
    if opt.screenshots:
        for name in ("pair", "compound", "mesh", "scene"):
            shutil.copy(shots[name], os.path.join(opt.screenshots, f"viewer-{name}.png"))
    print("viewer pages rendered in Chromium")
    return 0


if __name__ == "__main__":
    sys.exit(main())
