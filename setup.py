# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""Builds the Python package proxima with CMake underneath (docs/install.md).

    python3 -m venv --system-site-packages venv
    venv/bin/pip install --no-build-isolation .

The extension proxima._proxima, its type stubs and the `proxima` tool
(carried as proxima/bin/proxima for `python -m proxima`) are built by the
project's CMake (targets proxima_python and proxima_cli) in build/pip, a
Release build configured for the interpreter that runs this script, and
copied into the package. Set PROXIMA_CMAKE_BUILD_DIR to an existing CMake
build (e.g. build/release) to build and take them from there instead; its
Python must have the same ABI (the extension's suffix is checked). The
compiler launcher (ccache) comes from CMake's CMAKE_CXX_COMPILER_LAUNCHER
environment variable, the parallelism from CMAKE_BUILD_PARALLEL_LEVEL.
"""

import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(proxima VERSION (\d+\.\d+\.\d+)", f.read())
    if not m:
        raise RuntimeError("setup.py: no `project(proxima VERSION x.y.z` in CMakeLists.txt")
    return m.group(1)


def cmake_build_dir():
    given = os.environ.get("PROXIMA_CMAKE_BUILD_DIR")
    if given:
        return os.path.abspath(given), True
    return os.path.join(ROOT, "build", "pip"), False


def run(command):
    print("setup.py: " + " ".join(command), flush=True)
    subprocess.run(command, check=True)


class CMakeBuild(build_ext):
    """Builds proxima_python and proxima_cli with CMake and copies them into the package."""

    def build_extension(self, ext):
        build_dir, existing = cmake_build_dir()
        if existing:
            if not os.path.isfile(os.path.join(build_dir, "CMakeCache.txt")):
                raise RuntimeError(
                    f"setup.py: PROXIMA_CMAKE_BUILD_DIR={build_dir} is not a configured CMake build "
                    "(no CMakeCache.txt)"
                )
        else:
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            run(
                ["cmake", "-S", ROOT, "-B", build_dir, *generator,
                 "-DCMAKE_BUILD_TYPE=Release", "-DPROXIMA_BUILD_TESTS=OFF", "-DPROXIMA_BUILD_BENCH=OFF",
                 "-DPROXIMA_BUILD_CLI=ON", "-DPROXIMA_BUILD_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}"]
            )
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        run(["cmake", "--build", build_dir, "--target", "proxima_python", "proxima_cli", "-j", jobs])

        package_dir = os.path.join(build_dir, "python", "proxima")
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = os.path.join(package_dir, "_proxima" + suffix)
        if not os.path.isfile(built):
            found = sorted(f for f in os.listdir(package_dir) if f.startswith("_proxima.")) if os.path.isdir(
                package_dir) else []
            raise RuntimeError(
                f"setup.py: {built} was not built: the CMake build {build_dir} has {found or 'no extension'} "
                f"(its Python3_EXECUTABLE differs from {sys.executable}?)"
            )
        target = self.get_ext_fullpath(ext.name)
        target_dir = os.path.dirname(target)
        os.makedirs(os.path.join(target_dir, "bin"), exist_ok=True)
        shutil.copyfile(built, target)
        for stub in ("_proxima.pyi", "__init__.pyi"):
            shutil.copyfile(os.path.join(package_dir, stub), os.path.join(target_dir, stub))
        cli = os.path.join(target_dir, "bin", "proxima")
        shutil.copyfile(os.path.join(build_dir, "cli", "proxima"), cli)
        os.chmod(cli, 0o755)
        warn_if_no_viewer(build_dir)


def warn_if_no_viewer(build_dir):
    """Says loudly when the build has no viewer (three.js was not installed
    by scripts/setup's npm step): proxima.view() and `proxima view` would then
    refuse to run, which the build would otherwise not show."""
    assets = os.path.join(build_dir, "viewer", "viewer_assets.cpp")
    try:
        with open(assets, encoding="utf-8", errors="replace") as f:
            empty = "kThreeJs = \"\";" in f.read()
    except OSError:
        empty = True
    if empty:
        line = "=" * 78
        sys.stderr.write(
            f"\n{line}\nsetup.py: WARNING: this build of proxima has NO VIEWER: three.js was not "
            "installed\n(run scripts/setup, whose `npm ci` in viewer/ installs it from the npm "
            "registry,\nthen build again). proxima.view() and `proxima view` will refuse to run."
            f"\n{line}\n\n"
        )


# setuptools' own build files go under the CMake build folder, not into the
# source tree (its default build/ would sit among the CMake presets' folders).
_build_base = os.path.join(cmake_build_dir()[0], "setuptools")
os.makedirs(_build_base, exist_ok=True)

setup(
    version=project_version(),
    package_dir={"": "python"},
    packages=["proxima"],
    package_data={"proxima": ["py.typed"]},
    ext_modules=[Extension("proxima._proxima", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": _build_base}, "egg_info": {"egg_base": _build_base}},
)
