"""The data of a trade study (:doc:`/reference/schema`): how its cases run
(:class:`Execution`), one resolved case (:class:`Case`), the expanded study (:class:`Study`), and
the store key of a case (:func:`case_key`), and the short forms a notebook shows of a study and its
results (:func:`sweep_repr`, :func:`sweep_repr_html`). :mod:`scenarios.study.spec` builds them from a
study file.
"""
from __future__ import annotations

import collections
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scenarios.output.tables import ROW_STATUSES, html_table


@dataclass
class Execution:
    """How cases run (the study's ``execution`` mapping).

    Parameters
    ----------
    workers : int or None
        Cases run at once on the local process pool (1 to 1024); None (``auto``): one per core.
    scheduler : str or None
        Address of a Dask scheduler (``tcp://host:port``); None: the local process pool.
    case_timeout_s : float
        Wall time after which a case is stopped and becomes a ``crashed`` row [s].
    retries : int
        How many times a case whose worker died is run again (0 to 10).
    """

    workers: int | None = None
    scheduler: str | None = None
    case_timeout_s: float = 600.0
    retries: int = 1


@dataclass
class Case:
    """One resolved case.

    Parameters
    ----------
    index : int
        The case's number, from 0, in the study's order.
    seed : int
        The case's seed, from ``numpy.random.SeedSequence(seed).spawn`` (``case_seed``).
    point : int
        The grid point (from 0) the case belongs to; Monte Carlo samples share it.
    varied : dict
        Scenario path -> the value recorded in the tables (a number, a string, or JSON text for
        lists; the rotation angle [deg] for ``axis_angle`` quaternions).
    scenario : dict
        The resolved scenario mapping (plain YAML data), as a worker receives it.
    key : str
        The store key (:func:`case_key`); empty until the study is expanded.
    drawn : dict
        Parameter -> the number the case drew for it (:attr:`Study.parameters`): the drawn
        quantities of its Monte Carlo dispersions, one per independent component (a whole-tensor
        ``scale`` is one factor, however many elements it multiplies).
    """

    index: int
    seed: int
    point: int
    varied: dict[str, Any]
    scenario: dict[str, Any]
    key: str = ""
    drawn: dict[str, float] = field(default_factory=dict)


@dataclass
class Study:
    """A parsed study with its cases expanded and validated (:func:`scenarios.study.spec.parse_study`).

    Parameters
    ----------
    name : str
        The study's name (``study:``).
    source : Path or None
        The study file; None for a mapping given in code.
    base : dict
        The base scenario mapping (plain YAML data).
    grid_paths : list of str
        The scenario paths varied by ``grid`` then ``zip``, in order.
    mc_paths : list of str
        The scenario paths dispersed by ``monte_carlo``.
    samples : int
        Monte Carlo samples per grid point (1 without ``monte_carlo``).
    method : str or None
        ``random`` or ``latin_hypercube``; None without ``monte_carlo``.
    seed : int
        The study's seed (``monte_carlo.seed``; 0 without it).
    summary : list of str
        The metrics summarised (``ref.<metric>``, ``cl.<metric>``).
    execution : Execution
        How the cases run.
    cases : list of Case
        The expanded cases, in order.
    raw : dict
        The study mapping as given (for ``study.yaml``), in the plain values YAML gives: dicts, lists,
        ``str``, ``int``, ``float``, ``bool`` and None; a mapping built in Python has its numpy numbers
        and arrays and its tuples converted (:func:`scenarios.schema.node.plain_value`), so that it
        serialises with ``json`` and ``yaml.safe_dump``.
    thresholds : dict
        Metric column -> ``(sense, bound)`` with sense ``at_most`` or ``at_least``
        (``robustness.thresholds``): the robustness table's criteria beside every requirement.
    worst : int
        Worst cases listed per planner row and summary metric (``robustness.worst``).
    parameters : dict
        The drawn quantities of the Monte Carlo dispersions (each case's are in
        :attr:`Case.drawn`), in order: parameter -> what the number is, ``value`` (the drawn value),
        ``scale`` (a factor on the base value), ``offset`` (added to it) or ``principal`` (a
        principal moment's factor, a component of the principal axes' rotation [deg]). The
        parameter is the dispersed path, with the component for a vector (``[k]``) or matrix
        (``[i][j]``) and ``.principal.moments_scale[k]`` or ``.principal.axes_deg[k]`` for a
        ``principal`` dispersion; ``case_seed`` draws none.
    units : tuple of str
        What one case and several are called in the progress of a sweep: ``("case", "cases")``;
        a slew table's study, one case per table entry, says ``("entry", "entries")``.
    """

    name: str
    source: Path | None
    base: dict[str, Any]
    grid_paths: list[str]
    mc_paths: list[str]
    samples: int
    method: str | None
    seed: int
    summary: list[str]
    execution: Execution
    cases: list[Case] = field(default_factory=list)
    raw: dict[str, Any] = field(default_factory=dict)
    thresholds: dict[str, tuple[str, float]] = field(default_factory=dict)
    worst: int = 5
    parameters: dict[str, str] = field(default_factory=dict)
    units: tuple[str, str] = ("case", "cases")

    @property
    def varied_paths(self) -> list[str]:
        """Every varied scenario path: the grid's and zip's, then the Monte Carlo dispersions'."""
        return self.grid_paths + self.mc_paths

    def __repr__(self) -> str:
        varied = ", ".join(self.varied_paths) or "nothing"
        return (f"<Study {self.name!r}: {len(self.cases)} cases, {self.samples} sample(s) per grid point; "
                f"varies {varied}>")


RESULTS_FORMAT = 2
"""What a stored case's results mean, in the store key beside the package version (:func:`case_text`):
raised when a result a case stores changes its meaning or its columns, so that a resumed study
recomputes its cases instead of mixing two meanings in one table. 2 (2026-12-03): the settling
band defaults to ``requirements.final.error_deg``, and the actuator score stores
``unrealised_torque_allowed``."""


def case_key(scenario: dict[str, Any], version: str) -> str:
    """Store key: a hash of the resolved case (canonical JSON), the package version and
    :data:`RESULTS_FORMAT`.

    Parameters
    ----------
    scenario : dict
        The resolved scenario mapping (plain YAML data).
    version : str
        slewbench's version (:func:`scenarios.output.provenance.package_version`).

    Returns
    -------
    str
        32 hexadecimal digits of the SHA-256 of both.
    """
    return hashlib.sha256(case_text(scenario, version).encode()).hexdigest()[:32]


def case_text(scenario: dict[str, Any], version: str) -> str:
    """The canonical JSON that :func:`case_key` hashes.

    Parameters
    ----------
    scenario : dict
        The resolved scenario mapping (plain YAML data).
    version : str
        slewbench's version.

    Returns
    -------
    str
        ``{"results": RESULTS_FORMAT, "scenario": ..., "version": ...}`` with sorted keys and no spaces.
    """
    return json.dumps({"results": RESULTS_FORMAT, "scenario": scenario, "version": version}, sort_keys=True,
                      separators=(",", ":"))


def _status_counts(study: Study, records: dict[str, dict[str, Any]]) -> dict[str, collections.Counter[str]]:
    """Row label -> how many of its rows have each status, over the stored cases of the study."""
    counts: dict[str, collections.Counter[str]] = {}
    for case in study.cases:
        for row in (records.get(case.key) or {}).get("rows", []):
            counts.setdefault(str(row.get("label")), collections.Counter())[str(row.get("status"))] += 1
    return counts


_STATUS_ORDER = ROW_STATUSES[::-1]
"""The statuses of a row in the order a study's summary lists them (from ``ok``)."""


def _headline(study: Study, records: dict[str, dict[str, Any]]) -> str:
    missing = sum(case.key not in records for case in study.cases)
    crashed = sum((records.get(case.key) or {}).get("status") == "crashed" for case in study.cases)
    return (f"{study.name!r}: {len(study.cases)} cases ({missing} missing"
            + (f", {crashed} crashed" if crashed else "") + ")")


def sweep_repr(study: Study, records: dict[str, dict[str, Any]]) -> str:
    """The repr of a study's results: the cases, then each row label's rows by status.

    Parameters
    ----------
    study : Study
        The expanded study.
    records : dict
        Case key -> stored record (``status``, ``rows`` as :meth:`scenarios.output.results.Row.to_dict`).

    Returns
    -------
    str
        ``<SweepResults 'name': 12 cases (0 missing)`` and one line per row label, such as
        ``  smooth: 10 ok, 2 violated``.
    """
    lines = [f"<SweepResults {_headline(study, records)}"]
    for label, counts in _status_counts(study, records).items():
        statuses = [status for status in _STATUS_ORDER if counts[status]] + sorted(set(counts) - set(_STATUS_ORDER))
        lines.append(f"  {label}: " + ", ".join(f"{counts[status]} {status}" for status in statuses))
    return "\n".join(lines) + ">"


def sweep_repr_html(study: Study, records: dict[str, dict[str, Any]]) -> str:
    """The notebook table of a study's results: one line per row label, its rows by status.

    Parameters
    ----------
    study : Study
        The expanded study.
    records : dict
        Case key -> stored record, as :func:`sweep_repr`.

    Returns
    -------
    str
        An HTML table (label, rows, then one column per status) captioned with the case count.
    """
    counts = _status_counts(study, records)
    statuses = [status for status in _STATUS_ORDER if any(c[status] for c in counts.values())]
    statuses += sorted({status for c in counts.values() for status in c} - set(_STATUS_ORDER))
    records_table = [[label, sum(c.values()), *(c[status] for status in statuses)] for label, c in counts.items()]
    return html_table(["label", "rows", *statuses], records_table, caption=_headline(study, records))
