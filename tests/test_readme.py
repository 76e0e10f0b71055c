"""Every command and code block of README.md and of the user guide (docs/guide/*.rst) is run or
checked here, taken from the text itself, so that a test fails when the documentation drifts from
what the code does.

* ``slewbench ...`` commands run as ``python -m scenarios.console ...`` (placeholders ``FILE.yaml``
  and ``[--out DIR]`` filled in) in a scratch directory; the files the README promises must appear.
* ``pytest ...`` commands are collected (``--collect-only``, ``slow``): they must select tests, and
  ``pytest -m slow`` none of the default ones. The whole default run is CI's job (``.ci/run``).
* ``python`` blocks are executed from the repository root and must print; ``python tests/...``
  commands run there and must exit 0; ``mypy`` too (``slow``: CI runs it as a step of its own).
* ``yaml`` blocks that are whole scenarios (a ``maneuver`` key) or studies (a ``study`` key) are
  read and parsed as slewbench reads a file, every case of a study included; a scenario block named like a shipped
  scenario must be that file. Fragments (a ``controllers:`` list alone) are not checked.
* ``pip install ".[extra]"`` must name an extra of ``pyproject.toml``; ``pip install .`` into a
  fresh virtual environment, then the quick start's ``slewbench run`` through the installed console
  script: ``slow``. ``sphinx-build`` builds the documentation as the README says: ``slow``.

Commands are taken from the README's ``bash`` blocks and its inline code, and from the guide's
``.. code-block:: bash`` blocks (not from its inline literals, which name keys and commands in
prose); ``text`` blocks are shown, not run. A command written in several places runs once.
"""
from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import textwrap
import venv
from functools import cache
from pathlib import Path

import pytest

from scenarios.schema.read import parse_yaml_text, read_yaml

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
GUIDE = {path.relative_to(ROOT).as_posix(): path.read_text() for path in sorted((ROOT / "docs" / "guide").glob("*.rst"))}


def _markdown_blocks(text: str) -> list[tuple[str, str]]:
    return re.findall(r"```(\w+)\n(.*?)```", text, flags=re.DOTALL)


def _rst_blocks(text: str) -> list[tuple[str, str]]:
    """``.. code-block:: LANG`` directives: their indented body, dedented."""
    found = re.findall(r"^\.\. code-block:: (\w+)\n(?: {3}:.*\n)*\n((?:(?: {3}.*)?\n)+)", text, flags=re.MULTILINE)
    return [(language, textwrap.dedent(body).strip("\n") + "\n") for language, body in found]


BLOCKS = [("README.md", language, body) for language, body in _markdown_blocks(README)]
BLOCKS += [(name, language, body) for name, text in GUIDE.items() for language, body in _rst_blocks(text)]
# Inline code of the README that is a command (multi-line spans joined into one line).
INLINE = [" ".join(c.split()) for c in re.findall(
    r"`((?:pytest|slewbench|python -m pytest|python tests/|mypy|pip install mypy)\b[^`]*)`", README)]


def _shell_commands() -> list[str]:
    """Every command: bash block lines (comments dropped, ``&&`` split) and the README's inline ones,
    each once, in order of appearance."""
    commands = []
    for _, language, body in BLOCKS:
        if language != "bash":
            continue
        for line in body.splitlines():
            line = line.split("#")[0].strip()
            commands += [part.strip() for part in line.split("&&") if part.strip()]
    # Inline mentions of a subcommand by name (`slewbench run` in prose) are not commands.
    mentions = {"slewbench"} | {f"slewbench {name}" for name in ("run", "validate", "sweep", "codegen")}
    commands += [c for c in INLINE if c not in mentions]
    return list(dict.fromkeys(commands))


COMMANDS = _shell_commands()
SLEWBENCH = [c for c in COMMANDS if c.startswith("slewbench ")]
PYTEST = sorted({c for c in COMMANDS if c.startswith(("pytest", "python -m pytest"))})
PYTHON = [(source, body) for source, language, body in BLOCKS if language == "python"]
SCRIPTS = [c for c in COMMANDS if c.startswith(("python tests/", "mypy"))]
SPHINX = [c for c in COMMANDS if c.startswith("sphinx-build ")]
YAML = [(source, parse_yaml_text(body, source)) for source, language, body in BLOCKS if language == "yaml"]
SCENARIOS = [(source, data) for source, data in YAML if isinstance(data, dict) and "maneuver" in data]
STUDIES = [(source, data) for source, data in YAML if isinstance(data, dict) and "study" in data]


def test_the_documentation_has_the_commands_it_is_tested_for():
    readme = _markdown_commands()
    assert any(c.startswith("pip install .") for c in readme)
    assert any(c.startswith("slewbench run scenarios/") for c in readme)
    assert "pytest -n 2" in readme and "pytest -m slow" in readme  # the default run, as CI runs it
    assert sum(language == "python" for source, language, _ in BLOCKS if source == "README.md") >= 2
    assert "python tests/public_api.py" in readme and "mypy" in readme
    assert any(c.startswith("sphinx-build ") for c in readme)
    assert GUIDE and SCENARIOS and STUDIES
    unknown = [c for c in COMMANDS if not c.startswith(("pip install", "slewbench ", "pytest", "python -m pytest",
                                                        "python tests/", "mypy", "sphinx-build "))]
    assert not unknown, f"commands this test does not know how to run: {unknown}"


def _markdown_commands() -> list[str]:
    """The README's own commands (its bash blocks and inline code)."""
    readme = [body for source, language, body in BLOCKS if source == "README.md" and language == "bash"]
    commands = [part.strip() for body in readme for line in body.splitlines()
                for part in line.split("#")[0].split("&&") if part.strip()]
    return commands + INLINE


def test_the_guide_is_every_page_of_its_index():
    """Each guide page is in the guide's toctree (else Sphinx warns and the page is unreachable)."""
    index = GUIDE["docs/guide/index.rst"]
    entries = set(re.findall(r"^ {3}(\w+)$", index.split(".. toctree::")[1], flags=re.MULTILINE))
    pages = {Path(name).stem for name in GUIDE} - {"index"}
    assert entries == pages


def _environment() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    return env


def _filled(command: str, scratch: Path) -> list[str]:
    """Placeholders replaced: FILE.yaml by the demo scenario, [--out DIR] by a scratch directory, [KEY]
    by a schema key."""
    command = command.replace("FILE.yaml", "scenarios/eigenaxis_demo.yaml")
    command = command.replace("[--out DIR]", f"--out {scratch / 'out'}").replace("[--no-plots]", "--no-plots")
    command = command.replace("[KEY]", "maneuver.duration")
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
    if args[1] == "schema":
        assert "maneuver.duration" in done.stdout and "number" in done.stdout
    if args[1] == "list" and "--options" in args:  # one registry entry's options, one line each
        name = args[args.index("--options") + 1]
        assert done.stdout.startswith(f"{name} (") and "\n  option " in done.stdout
    elif args[1] == "list":
        assert "spin_extremal" in done.stdout and "augmented_quaternion_feedback" in done.stdout
    if args[1] == "--version":
        assert done.stdout.startswith("slewbench ")
    if args[1] == "validate" and "study_" in args[2]:
        assert " cases (" in done.stdout
    if args[1] == "codegen":
        (folder,) = [tmp_path / args[args.index("--out") + 1]]
        assert {"Makefile", "interface.json"} <= {path.name for path in folder.iterdir()}
        assert any(folder.glob("*.c")) and any(folder.glob("*.h"))


@cache
def _collected(command: str) -> list[str]:
    args = shlex.split(command.replace("my_method", "eigenaxis"))  # the documentation's placeholder planner name
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


@pytest.mark.parametrize("index", range(len(PYTHON)), ids=[f"{source}-{i}" for i, (source, _) in enumerate(PYTHON)])
def test_python_block(index, monkeypatch, capsys):
    monkeypatch.chdir(ROOT)
    source, body = PYTHON[index]
    # run as a script's main module: a block guarded by ``if __name__ == "__main__":`` runs
    exec(compile(body, f"{source} python block {index}", "exec", dont_inherit=True), {"__name__": "__main__"})
    assert capsys.readouterr().out.strip()  # every block prints its result


@pytest.mark.parametrize("index", range(len(SCENARIOS)),
                         ids=[f"{source}-{data.get('name')}" for source, data in SCENARIOS])
def test_yaml_scenario_block_loads(index):
    import scenarios

    _, data = SCENARIOS[index]
    scenario = scenarios.parse_scenario(data, ROOT / "scenarios" / "documentation.yaml")
    shipped = {read_yaml(path).get("name"): path for path in (ROOT / "scenarios").glob("*.yaml")}
    if scenario.name in shipped:
        # A block named like a shipped scenario shows that file, as it is.
        assert data == read_yaml(shipped[scenario.name]), shipped[scenario.name].name


@pytest.mark.parametrize("index", range(len(STUDIES)), ids=[f"{source}-{data.get('study')}" for source, data in STUDIES])
def test_yaml_study_block_loads(index):
    import scenarios

    _, data = STUDIES[index]
    study = scenarios.parse_study(data, ROOT / "scenarios" / "documentation.yaml")
    assert study.cases  # every case was checked by the scenario loader


@pytest.mark.parametrize("command", [c for c in COMMANDS if re.match(r"pip install \S*\[", c)])
def test_pip_extra_exists(command):
    (extra,) = re.findall(r"\[(\w+)\]", command)
    # The keys of [project.optional-dependencies] (tomllib is Python 3.11+; the project supports 3.10).
    section = (ROOT / "pyproject.toml").read_text().split("[project.optional-dependencies]\n")[1].split("\n[")[0]
    extras = re.findall(r"^(\w+)\s*=", section, flags=re.MULTILINE)
    assert extra in extras, f"{command!r}: pyproject.toml has no extra {extra!r} (it has {sorted(extras)})"


@pytest.mark.slow  # builds every page, the API reference and the gallery (minutes)
@pytest.mark.parametrize("command", SPHINX)
def test_sphinx_build_command(command, tmp_path):
    pytest.importorskip("sphinx")
    args = shlex.split(command)[1:]
    args[-1] = str(tmp_path / "html")  # the README's output folder, moved out of the checkout
    done = subprocess.run([sys.executable, "-m", "sphinx", *args], cwd=ROOT, env=_environment(),
                          capture_output=True, text=True, check=False, timeout=1800)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert (tmp_path / "html" / "index.html").is_file()
    assert (tmp_path / "html" / "guide" / "index.html").is_file()


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
