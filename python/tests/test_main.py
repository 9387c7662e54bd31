"""`python -m proxima` runs the proxima CLI (issue 15): from an installed
wheel the copy it carries (tests/pip_install_check.sh checks that one), from
the build tree the build's own (a link in build/<preset>/python/proxima/bin).
Before issue 15 there was no `python -m proxima`."""

import json
import os
import subprocess
import sys

import pytest

import proxima.__main__ as main_module

QUERY = json.dumps({"id": 7, "a": {"vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]},
                    "b": {"vertices": [[3, 0, 0], [4, 0, 0], [3, 1, 0], [3, 0, 1]]}}) + "\n"


def run(args, stdin="", env_extra=None):
    env = dict(os.environ, **(env_extra or {}))
    if "PROXIMA_CLI" not in (env_extra or {}):
        env.pop("PROXIMA_CLI", None)
    return subprocess.run([sys.executable, "-m", "proxima", *args], input=stdin, capture_output=True,
                          text=True, env=env, timeout=60)


@pytest.mark.skipif(not os.path.exists(main_module.BUNDLED), reason="the CLI is not built (PROXIMA_BUILD_CLI=OFF)")
def test_python_m_proxima_runs_the_cli_with_its_arguments_input_and_status():
    r = run(["--help"])
    assert r.returncode == 0, r.stderr
    assert "Usage: proxima [OPTIONS] SUBCOMMAND" in r.stdout
    answer = run(["query", "--algorithm", "gjk"], stdin=QUERY)
    assert answer.returncode == 0, answer.stderr
    line = json.loads(answer.stdout)
    assert line["id"] == 7 and line["status"] == "separated" and line["distance"] == 2, line
    bad = run(["query", "--algorithm", "nonsense"], stdin=QUERY)
    assert bad.returncode != 0 and "nonsense" in bad.stderr, bad.stderr


def test_a_missing_cli_is_named(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("PROXIMA_CLI", raising=False)
    missing = str(tmp_path / "bin" / "proxima")
    assert main_module.main(["--help"], bundled=missing) == 2
    assert f"the proxima tool was not found ({missing} is missing" in capsys.readouterr().err


def test_proxima_cli_naming_no_executable_is_an_error(tmp_path, monkeypatch, capsys):
    not_executable = tmp_path / "proxima"
    not_executable.write_text("")
    monkeypatch.setenv("PROXIMA_CLI", str(not_executable))
    assert main_module.main(["--help"]) == 2
    assert f"PROXIMA_CLI={not_executable} is not an executable file" in capsys.readouterr().err
