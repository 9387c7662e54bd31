#!/usr/bin/env bash
# proxima installs the way Python users expect (issue 15): from a checkout,
# without network, with Debian's pip, setuptools and wheel,
#   1. `pip install --no-build-isolation .` into a fresh virtual environment
#      created with --system-site-packages (Debian's numpy stays visible);
#   2. `pip wheel .`, and the wheel installed into another fresh one.
# In each the installed package answers a distance query, `python -m proxima
# --help` runs the bundled CLI, and the type stubs are there and name every
# public name. Before issue 15 there was no package: the module ran only from
# a build folder through PYTHONPATH.
#
# The CMake build this test runs in is reused (PROXIMA_CMAKE_BUILD_DIR, see
# setup.py): nothing is compiled again. Run as a CTest test:
#   tests/pip_install_check.sh SOURCE_DIR BUILD_DIR PYTHON
set -euo pipefail
if [ $# -ne 3 ]; then
  echo "usage: $0 SOURCE_DIR BUILD_DIR PYTHON" >&2
  exit 2
fi
src=$1
build=$2
python=$3

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
r = proxima.distance(a, None, b, ((1, 0, 0, 0), (3, 0, 0)))
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
}

echo "== pip install --no-build-isolation $src"
"$python" -m venv --system-site-packages "$work/venv-install"
"$work/venv-install/bin/python" -m pip install -q --no-build-isolation "$src"
check "$work/venv-install"

echo "== pip wheel --no-build-isolation $src, installed into a fresh venv"
"$python" -m venv --system-site-packages "$work/venv-wheel"
"$work/venv-wheel/bin/python" -m pip wheel -q --no-build-isolation --no-deps -w "$work/wheels" "$src"
wheels=("$work"/wheels/proxima-*.whl)
[ ${#wheels[@]} -eq 1 ] && [ -f "${wheels[0]}" ] || { echo "expected one wheel, got: ${wheels[*]}" >&2; exit 1; }
echo "wheel: $(basename "${wheels[0]}")"
"$work/venv-wheel/bin/python" -m pip install -q "${wheels[0]}"
check "$work/venv-wheel"
echo "pip install and pip wheel: OK"
