# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""`python -m proxima ARGS` runs the proxima command-line tool with ARGS.

The tool is the C++ executable `proxima` (cli/): the one named by
$PROXIMA_CLI if set, else the one in the package (proxima/bin/proxima: the
wheel carries a copy, the CMake build tree a link to its own), else the one
on PATH. Its exit status and output are the command's.
"""

import os
import shutil
import sys

BUNDLED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bin", "proxima")


def _executable(path):
    return os.path.isfile(path) and os.access(path, os.X_OK)


def find_cli(bundled=BUNDLED):
    """The tool's path, or (None, why it was not found)."""
    named = os.environ.get("PROXIMA_CLI")
    if named:
        if _executable(named):
            return named, ""
        return None, f"PROXIMA_CLI={named} is not an executable file"
    if _executable(bundled):
        return bundled, ""
    on_path = shutil.which("proxima")
    # The console script `proxima` (pyproject.toml) is this module: running
    # it again would loop.
    running = os.path.realpath(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    if on_path and os.path.realpath(on_path) != running:
        return on_path, ""
    return None, (
        f"the proxima tool was not found ({bundled} is missing, and there is no proxima on PATH): "
        "install the package with pip (docs/install.md) or build the CLI with CMake"
    )


def main(argv=None, bundled=BUNDLED):
    cli, why = find_cli(bundled)
    if cli is None:
        sys.stderr.write(f"python -m proxima: {why}\n")
        return 2
    sys.stdout.flush()
    sys.stderr.flush()
    args = sys.argv[1:] if argv is None else argv
    os.execv(cli, ["proxima"] + args)  # argv[0] "proxima": the usage line reads "Usage: proxima"
    return 0  # not reached: execv replaces the process


if __name__ == "__main__":
    sys.exit(main())
