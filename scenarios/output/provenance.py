"""Where results come from: slewbench's version, the date, Python, the platform and the numerical
libraries, recorded with a run's results (``results.json``) and a study's (``study.yaml``).

The versions are read from the installed distributions' metadata (nothing is imported), slewbench's
own from ``pyproject.toml`` when it runs from a checkout that is not installed.
"""
from __future__ import annotations

import datetime
import platform
import re
import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from scenarios.schema.loader import Scenario

__all__ = ["LIBRARIES", "environment", "package_version", "run_provenance", "utc_stamp"]

LIBRARIES = ("casadi", "numpy", "scipy")
"""The numerical libraries whose versions are recorded."""


def package_version() -> str:
    """slewbench's version: the installed distribution's, else pyproject.toml's.

    Returns
    -------
    str
        The version, for example ``0.1.0``.
    """
    try:
        return version("slewbench")
    except PackageNotFoundError:  # not installed: running from a checkout
        text = (Path(__file__).resolve().parents[2] / "pyproject.toml").read_text()
        if sys.version_info >= (3, 11):
            import tomllib
            return str(tomllib.loads(text)["project"]["version"])
        found = re.search(r'^version\s*=\s*"([^"]+)"', text, re.MULTILINE)  # Python 3.10: no tomllib
        if found is None:
            raise RuntimeError("no project version in pyproject.toml") from None
        return found.group(1)


def utc_stamp(moment: datetime.datetime | None = None) -> str:
    """An instant as ISO 8601 UTC text to the second, ``2025-03-01T12:00:00Z``.

    Parameters
    ----------
    moment : datetime.datetime or None, optional
        The instant (a naive one is taken as UTC); ``None`` (default): now.

    Returns
    -------
    str
        The instant in UTC, with ``Z``.
    """
    moment = datetime.datetime.now(datetime.timezone.utc) if moment is None else moment
    if moment.tzinfo is not None:
        moment = moment.astimezone(datetime.timezone.utc).replace(tzinfo=None)
    return moment.replace(microsecond=0).isoformat() + "Z"


def environment() -> dict[str, Any]:
    """What ran: slewbench's version, Python's, the platform and the numerical libraries' versions.

    Returns
    -------
    dict
        ``slewbench`` (:func:`package_version`), ``python`` (version and implementation),
        ``platform`` (:func:`platform.platform`) and ``libraries`` (name -> version of each of
        :data:`LIBRARIES`, ``None`` when not installed).
    """
    libraries: dict[str, str | None] = {}
    for name in LIBRARIES:
        try:
            libraries[name] = version(name)
        except PackageNotFoundError:
            libraries[name] = None
    return {"slewbench": package_version(),
            "python": f"{platform.python_version()} ({platform.python_implementation()})",
            "platform": platform.platform(), "libraries": libraries}


def run_provenance(scenario: Scenario, finished: datetime.datetime) -> dict[str, Any]:
    """The provenance of a run's results: what ran, when, and on what input.

    Parameters
    ----------
    scenario : scenarios.schema.loader.Scenario
        The scenario that was run.
    finished : datetime.datetime
        When the run finished (UTC).

    Returns
    -------
    dict
        :func:`environment`'s entries, then ``date_utc`` (``finished``, :func:`utc_stamp`),
        ``scenario_file`` (the file it was read from, or ``None``), ``seeds`` (YAML path -> the
        seed used: ``simulation.sensor_noise.seed``) and ``scenario`` (the scenario's data as read
        from its YAML, before defaults; ``None`` for a scenario built without
        :func:`~scenarios.schema.loader.parse_scenario`).
    """
    return {**environment(), "date_utc": utc_stamp(finished),
            "scenario_file": None if scenario.source is None else str(scenario.source),
            "seeds": {"simulation.sensor_noise.seed": scenario.simulation.noise.seed},
            "scenario": getattr(scenario, "data", None)}
