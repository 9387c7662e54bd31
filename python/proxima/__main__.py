# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""`python -m proxima ARGS` runs the proxima command-line tool with ARGS.

The tool is the C++ executable `proxima` (cli/), carried in the wheel as
proxima/bin/proxima. Outside an installed wheel (PYTHONPATH pointing at a
CMake build), the tool on PATH is used, or the one named by $PROXIMA_CLI.
"""

import os
import shutil
import sys


def _find_cli():
    bundled = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bin", "proxima")
    for candidate in (os.environ.get("PROXIMA_CLI"), bundled, shutil.which("proxima")):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return None


def main():
    cli = _find_cli()
    if cli is None:
        sys.stderr.write(
            "python -m proxima: the proxima tool was not found (not in the package as "
            "proxima/bin/proxima, not on PATH, $PROXIMA_CLI unset); install the package with pip "
            "(docs/install.md) or build the CLI with CMake\n"
        )
        return 2
    sys.stdout.flush()
    sys.stderr.flush()
    os.execv(cli, ["proxima"] + sys.argv[1:])  # the usage line reads "proxima"
    return 0  # not reached: execv replaces the process


if __name__ == "__main__":
    sys.exit(main())
