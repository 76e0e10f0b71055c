"""Every command and code block of README.md is run here, taken from the README itself, so that a
test fails when the README drifts from what the code does.

* ``slewbench ...`` lines run as ``python -m scenarios.cli ...`` (placeholders ``FILE.yaml`` and
  ``[--out DIR]`` filled in) in a scratch directory; the files the README promises must appear.
* ``pytest ...`` commands are collected (``--collect-only``, ``slow``): they must select tests, and
  ``pytest -m slow`` none of the default ones. The whole default run is CI's job (``.ci/run``).
* ``python`` blocks are executed from the repository root; ``python tests/...`` commands run there
  and must exit 0; ``mypy`` too (``slow``: CI runs it as a step of its own).
* ``pip install .`` into a fresh virtual environment, then the quick start's ``slewbench run``
  through the installed console script: ``slow``.
"""
from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import venv
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
BLOCKS = re.findall(r"```(\w+)\n(.*?)```", README, flags=re.DOTALL)
INLINE = re.findall(r"`((?:pytest|slewbench|python -m pytest|python tests/|mypy|pip install mypy)\b[^`]*)`", README)


def _shell_commands() -> list[str]:
    """Every command of the README: bash block lines (comments dropped, ``&&`` split) and inline ones."""
    commands = []
    for language, body in BLOCKS:
        if language != "bash":
            continue
        for line in body.splitlines():
            line = line.split("#")[0].strip()
            commands += [part.strip() for part in line.split("&&") if part.strip()]
    # Inline mentions of a subcommand by name (`slewbench run` in prose) are not commands.
    mentions = {"slewbench"} | {f"slewbench {name}" for name in ("run", "validate", "sweep", "codegen")}
    return commands + [c.strip() for c in INLINE if c.strip() not in commands and c.strip() not in mentions]


COMMANDS = _shell_commands()
SLEWBENCH = [c for c in COMMANDS if c.startswith("slewbench ")]
PYTEST = sorted({c for c in COMMANDS if c.startswith(("pytest", "python -m pytest"))})
PYTHON = [body for language, body in BLOCKS if language == "python"]
SCRIPTS = [c for c in COMMANDS if c.startswith(("python tests/", "mypy"))]


def test_the_readme_has_the_commands_it_is_tested_for():
    assert any(c.startswith("pip install .") for c in COMMANDS)
    assert any(c.startswith("slewbench run scenarios/") for c in SLEWBENCH)
    assert "pytest" in PYTEST and "pytest -m slow" in PYTEST
    assert len(PYTHON) >= 2
    assert "python tests/public_api.py" in SCRIPTS and "mypy" in SCRIPTS
    unknown = [c for c in COMMANDS if not c.startswith(("pip install", "slewbench ", "pytest", "python -m pytest",
                                                        "python tests/", "mypy"))]
    assert not unknown, f"commands this test does not know how to run: {unknown}"


def _environment() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    return env


def _filled(command: str, scratch: Path) -> list[str]:
    """Placeholders replaced: FILE.yaml by the demo scenario, [--out DIR] by a scratch directory."""
    command = command.replace("FILE.yaml", "scenarios/eigenaxis_demo.yaml")
    command = command.replace("[--out DIR]", f"--out {scratch / 'out'}").replace("[--no-plots]", "--no-plots")
    return shlex.split(command)


@pytest.mark.parametrize("command", SLEWBENCH)
def test_slewbench_command(command, tmp_path):
    (tmp_path / "scenarios").symlink_to(ROOT / "scenarios")
    args = _filled(command, tmp_path)
    done = subprocess.run([sys.executable, "-m", "scenarios.console", *args[1:]], cwd=tmp_path, env=_environment(),
                          capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    if args[1] == "run" and "--out" not in args:
        # The quick start's promise: results/<scenario name>/ with tables, time series and plots.
        (folder,) = (tmp_path / "results").iterdir()
        for name in ("results.json", "results.csv", "results.md", "comparison.png"):
            assert (folder / name).is_file(), name
        assert any((folder / "timeseries").glob("*.csv"))
    if args[1] == "list":
        assert "spin_extremal" in done.stdout and "augmented_quaternion_feedback" in done.stdout


@cache
def _collected(command: str) -> list[str]:
    args = shlex.split(command.replace("my_method", "eigenaxis"))  # the README's placeholder planner name
    args = args[1:] if args[0] == "pytest" else args[3:]
    done = subprocess.run([sys.executable, "-m", "pytest", *args, "--collect-only", "-q", "-p", "no:cacheprovider"],
                          cwd=ROOT, env=_environment(), capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return [line for line in done.stdout.splitlines() if "::" in line]


@pytest.mark.slow  # each collection imports and parametrises the whole suite (~10 s)
@pytest.mark.parametrize("command", PYTEST)
def test_pytest_command_selects_tests(command):
    collected = _collected(command)
    assert collected, f"{command!r} selects no test"
    if command == "pytest -m slow":
        # Only slow cases, and not the default ones (the command line's -m overrides addopts').
        default = set(_collected("pytest"))
        assert not default & set(collected)


@pytest.mark.parametrize("command", [c for c in SCRIPTS if c.startswith("python tests/")])
def test_python_script_command(command):
    done = subprocess.run([sys.executable, *shlex.split(command)[1:]], cwd=ROOT, env=_environment(),
                          capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


@pytest.mark.slow  # about 25 s; CI runs it as a step of its own (.ci/run)
def test_mypy_command():
    pytest.importorskip("mypy")
    done = subprocess.run([sys.executable, "-m", "mypy"], cwd=ROOT, env=_environment(),
                          capture_output=True, text=True, check=False, timeout=600)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]


@pytest.mark.parametrize("index", range(len(PYTHON)))
def test_python_block(index, monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    exec(compile(PYTHON[index], f"README.md python block {index}", "exec", dont_inherit=True), {"__name__": "readme"})
    assert capsys.readouterr().out.strip()  # every block prints its result


@pytest.mark.slow
def test_quick_start_in_a_fresh_virtual_environment(tmp_path):
    """``pip install .`` (the dependencies come from the test's own environment through a .pth
    file, so only slewbench itself is built and installed), then the quick start's run."""
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    python = env_dir / "bin" / "python"
    site = subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    import numpy  # the parent environment's site-packages

    Path(site, "parent_environment.pth").write_text(str(Path(numpy.__file__).parents[1]) + "\n")
    install = next(c for c in COMMANDS if c.startswith("pip install ."))
    environment = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    done = subprocess.run([python, "-m", *shlex.split(install)], cwd=ROOT, env=environment,
                          capture_output=True, text=True, check=False, timeout=900)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    (tmp_path / "scenarios").symlink_to(ROOT / "scenarios")
    run = next(c for c in SLEWBENCH if c.startswith("slewbench run scenarios/"))
    done = subprocess.run([str(env_dir / "bin" / "slewbench"), *shlex.split(run)[1:], "--no-plots"], cwd=tmp_path,
                          env=dict(environment, MPLBACKEND="Agg"), capture_output=True, text=True, check=False, timeout=900)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert any((tmp_path / "results").glob("*/results.json"))
