#!/usr/bin/env bash
# proxima installs the way Python users expect (issue 15), through the
# commands of docs/install.md: from a checkout, without network, with
# Debian's pip, setuptools and wheel,
#   - `pip install --no-build-isolation .` into a fresh virtual environment
#     created with --system-site-packages (Debian's numpy stays visible);
#   - `pip wheel .`, and the wheel installed into another fresh one;
#   - the same with PROXIMA_CMAKE_BUILD_DIR, and from the build tree.
# Every `sh` block of docs/install.md is run, in order, in a copy of the
# checkout (its files as git lists them, committed or not) whose
# build/release is the build under test. Then, in both environments, the
# installed package (not the copy) answers a distance query, `python -m
# proxima --help` runs the bundled CLI, and the type stubs are there and name
# every public name. Before issue 15 there was no package: `pip install .`
# failed (no setup.py, no pyproject.toml) and the module ran only from a
# build folder through PYTHONPATH.
#
# PROXIMA_CMAKE_BUILD_DIR (see setup.py) makes pip reuse the build under
# test: nothing is compiled again. Run as a CTest test:
#   tests/pip_install_check.sh SOURCE_DIR BUILD_DIR
# The build must be for Debian's /usr/bin/python3, the interpreter the page
# uses (the presets' default).
set -euo pipefail
if [ $# -ne 2 ]; then
  echo "usage: $0 SOURCE_DIR BUILD_DIR" >&2
  exit 2
fi
src=$1
build=$2

work=$(mktemp -d "${TMPDIR:-/tmp}/proxima-pip.XXXXXX")
trap 'rm -rf "$work"' EXIT
export PROXIMA_CMAKE_BUILD_DIR=$build PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 PYTHONDONTWRITEBYTECODE=1
unset PYTHONPATH PIP_REQUIRE_VIRTUALENV || true
cd "$work"  # not the source tree: its python/proxima must not be what is imported

check() {
  local venv=$1
  echo "== checking the package installed in $venv"
  "$venv/bin/python" - "$venv" <<'PY'
import ast
import os
import sys

import proxima

venv = os.path.realpath(sys.argv[1])
package = os.path.dirname(os.path.realpath(proxima.__file__))
assert package.startswith(venv + os.sep), f"proxima imported from {package}, not from the venv {venv}"

cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
a = proxima.ConvexPolytope(cube)
b = proxima.ConvexPolytope(cube)
r = proxima.distance(a, None, b, proxima.Pose.from_translation((3, 0, 0)))
assert r.status == "separated" and abs(r.distance - 2.0) < 1e-12, r

for name in ("py.typed", "__init__.pyi", "_proxima.pyi"):
    assert os.path.isfile(os.path.join(package, name)), f"{name} is not installed in {package}"
with open(os.path.join(package, "_proxima.pyi"), encoding="utf-8") as f:
    tree = ast.parse(f.read())
stubbed = set()
for node in tree.body:
    if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
        stubbed.add(node.name)
    elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
        stubbed.add(node.target.id)
missing = sorted(set(proxima.__all__) - stubbed)
assert not missing, f"public names without a stub: {missing}"
for name in ("ConvexPolytope", "distance", "Scene", "Body", "time_of_impact"):
    assert name in proxima.__all__, f"{name} is not public"
print(f"proxima {package}: distance {r.distance}, stubs for {len(proxima.__all__)} names")
PY
  local help
  help=$("$venv/bin/python" -m proxima --help)
  grep -q "query" <<<"$help" || { echo "python -m proxima --help printed: $help" >&2; exit 1; }
  echo "python -m proxima --help: $(head -n 1 <<<"$help")"
  # Issue 25: the README says `proxima` is on the venv's PATH after pip
  # install; there was no console script, only `python -m proxima`.
  [ -x "$venv/bin/proxima" ] || { echo "pip installed no $venv/bin/proxima" >&2; exit 1; }
  help=$(PATH="$venv/bin:/usr/bin:/bin" proxima --help)
  grep -q "query" <<<"$help" || { echo "proxima --help (the console script) printed: $help" >&2; exit 1; }
  echo "proxima --help (console script): $(head -n 1 <<<"$help")"
}

# A copy of the checkout, as a clone would have it (plus uncommitted work);
# a source tree that is no git checkout is copied whole but for build/.
copy=$work/proxima
mkdir -p "$copy/build"
if [ "$(git -C "$src" rev-parse --show-toplevel 2>/dev/null)" = "$(cd "$src" && pwd -P)" ]; then
  (cd "$src" && git ls-files -z --cached --others --exclude-standard |
    xargs -0 sh -c 'for f; do [ -e "$f" ] && printf "%s\0" "$f"; done' files |  # not the deleted ones
    xargs -0 -r cp --parents -t "$copy")
else
  tar -C "$src" --exclude=./build -cf - . | tar -C "$copy" -xf -
fi
ln -s "$build" "$copy/build/release"

# The page's sh blocks, in order.
awk '/^```sh$/ { inside = 1; next } /^```$/ { inside = 0; next } inside' "$copy/docs/install.md" >"$work/install.sh"
blocks=$(grep -c '^```sh$' "$copy/docs/install.md")
if [ "$blocks" -lt 4 ]; then
  echo "docs/install.md has $blocks sh blocks, expected at least 4 (venv, wheel, PROXIMA_CMAKE_BUILD_DIR, build tree)" >&2
  exit 1
fi
echo "== docs/install.md: $blocks sh blocks, $(wc -l <"$work/install.sh") commands, run in $copy"
(cd "$copy" && PIP_QUIET=1 bash -euxo pipefail "$work/install.sh")

check "$copy/venv"
check "$copy/other-venv"

echo "== a PROXIMA_CMAKE_BUILD_DIR that is no build is named"
if out=$(cd "$copy" && PROXIMA_CMAKE_BUILD_DIR=$work/no-build venv/bin/pip install --no-build-isolation . 2>&1); then
  echo "pip install with PROXIMA_CMAKE_BUILD_DIR=$work/no-build succeeded" >&2
  exit 1
fi
grep -q "PROXIMA_CMAKE_BUILD_DIR=$work/no-build is not a configured CMake build" <<<"$out" || {
  echo "unexpected failure: $out" >&2
  exit 1
}
echo "docs/install.md: pip install, pip wheel, PROXIMA_CMAKE_BUILD_DIR and the build tree: OK"
