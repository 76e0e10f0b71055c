"""The wheel holds every module of the source tree, and the installed package works from anywhere.

The wheel is built from a copy of the project (pip builds in the tree it is given, and a stale
``build/`` would hide a package the configuration leaves out), installed with ``--no-deps`` into a
fresh virtual environment whose dependencies come from the test's own environment through a
``.pth`` file (as ``tests/test_readme.py`` does); ``--ignore-installed``, because that environment
may hold slewbench itself (CI installs it), which pip would otherwise take as already there. From a directory outside the source tree, the
installed Python imports every module found under ``ocp/``, ``planners/``, ``controllers/`` and
``scenarios/`` of the checkout, each from the environment, not from the checkout; then
``slewbench --help``, ``python -m scenarios.cli --help`` and the version lookup run there.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("ocp", "planners", "controllers", "scenarios")
SCRIPTS = ("__main__",)
"""Modules that run a program when imported (``python -m``): run, not imported."""


def source_modules(root: Path = ROOT) -> list[str]:
    """Every module of the four packages in the source tree, by dotted name (packages included)."""
    names = []
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            parts = path.relative_to(root).with_suffix("").parts
            if parts[-1] in SCRIPTS:
                continue
            names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


def package_data(root: Path = ROOT) -> list[str]:
    """The data files the package ships: the scenarios' YAML and Markdown files."""
    return sorted(str(p.relative_to(root)) for pattern in ("*.yaml", "*.md") for p in (root / "scenarios").glob(pattern))


def _copy_project(destination: Path) -> Path:
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "build", "*.egg-info")
    for package in PACKAGES:
        shutil.copytree(ROOT / package, destination / package, ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, destination / name)
    return destination


IMPORT_ALL = """
import importlib, json, sys
names = json.loads(sys.argv[1])
found = {}
for name in names:
    module = importlib.import_module(name)
    found[name] = module.__file__
from scenarios.output.provenance import package_version
print(json.dumps({"files": found, "version": package_version(), "prefix": sys.prefix}))
"""


def _environment() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV", "PYTHONHOME")}


def test_the_installed_wheel_holds_and_imports_every_module(tmp_path):
    project = _copy_project(tmp_path / "project")
    wheels = tmp_path / "wheels"
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", str(project), "-w", str(wheels), "--no-deps",
                            "--quiet"], cwd=tmp_path, env=_environment(), capture_output=True, text=True,
                           timeout=600, check=False)
    assert built.returncode == 0, built.stdout[-2000:] + built.stderr[-2000:]
    wheel = next(wheels.glob("slewbench-*.whl"))
    contents = set(zipfile.ZipFile(wheel).namelist())
    modules = source_modules()
    files = {name: name.replace(".", "/") + ("/__init__.py" if (ROOT / name.replace(".", "/")).is_dir() else ".py")
             for name in modules}
    missing = sorted(path for path in [*files.values(), *package_data()] if path not in contents)
    assert not missing, f"the wheel lacks {missing}"

    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    site = subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    Path(site, "test_environment.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    installed = subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps",
                                "--ignore-installed", "--quiet", str(wheel)], cwd=tmp_path, env=_environment(), capture_output=True,
                               text=True, timeout=600, check=False)
    assert installed.returncode == 0, installed.stdout[-2000:] + installed.stderr[-2000:]

    outside = tmp_path / "elsewhere"
    outside.mkdir()
    environment = dict(_environment(), MPLBACKEND="Agg")
    done = subprocess.run([python, "-c", IMPORT_ALL, json.dumps(modules)], cwd=outside, env=environment,
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    prefix = Path(report["prefix"]).resolve()
    assert prefix == env_dir.resolve()
    stray = {name: path for name, path in report["files"].items()
             if not Path(path).resolve().is_relative_to(prefix) or Path(path).resolve().is_relative_to(ROOT)}
    assert not stray, f"imported from outside the installed environment: {stray}"
    assert sorted(report["files"]) == sorted(modules)
    from scenarios.output.provenance import (
        package_version,  # the checkout's answer, from pyproject.toml
    )

    assert report["version"] == package_version() != ""

    for command in ([str(env_dir / "bin" / "slewbench"), "--help"], [str(python), "-m", "scenarios.cli", "--help"]):
        helped = subprocess.run(command, cwd=outside, env=environment, capture_output=True, text=True, timeout=300,
                                check=False)
        assert helped.returncode == 0, helped.stderr[-2000:]
        assert "usage:" in helped.stdout and "sweep" in helped.stdout


def test_the_walk_finds_every_subpackage():
    modules = source_modules()
    packages = {name for name in modules if (ROOT / name.replace(".", "/")).is_dir()}
    on_disk = {".".join(p.relative_to(ROOT).parts) for package in PACKAGES for p in [ROOT / package, *(ROOT / package).rglob("*")]
               if p.is_dir() and (p / "__init__.py").exists()}
    assert packages == on_disk and len(packages) > 4
    assert "scenarios.cli.__main__" not in modules and "scenarios.study.types" in modules
