"""The suite index: which problems the benchmark holds, where each number comes from.

``suite.yaml`` (``version``, ``problems``) lists per problem its scenario file (``problems/*.yaml``,
an ordinary scenario: ``slewbench run`` runs it too), a title, the source of its data, the
objective, the optimum (the published value or the best known one, its tolerance and where it
comes from), the eigenaxis comparison value and the planners that apply (the scenario's planner
rows), and ``peers``: ``true`` (the default: every peer is asked, and one that cannot express the
problem skips it with its reason as a note) or ``{skip: <why>}`` (no peer is asked; the reason is
the note of each peer, so that no absence in the leaderboard goes unexplained; a bare ``false`` is
refused for want of one). The scenario schema is not extended: the metadata lives here.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scenarios.errors import ScenarioError, in_file
from scenarios.schema.read import read_yaml

__all__ = ["OBJECTIVE_METRICS", "OPTIMUM_KINDS", "SUITE_FILE", "BenchProblem", "Suite", "load_suite"]

SUITE_FILE = Path(__file__).resolve().parent / "suite.yaml"
"""The shipped suite index."""

OBJECTIVE_METRICS: dict[str, tuple[str, str]] = {
    "min_time": ("duration_s", "s"),
    "min_energy": ("int_u2", "N² m² s"),
}
"""Objective -> (the reference metric that measures it, its unit)."""

OPTIMUM_KINDS = ("published", "best_known", "closed_form")
"""How an optimum is established: a published value, our best known one (by two methods or
transcriptions agreeing), or a closed form."""


@dataclass(frozen=True)
class BenchProblem:
    """One problem of the suite.

    Parameters
    ----------
    name : str
        The problem's key (``--problems`` takes it).
    file : Path
        Its scenario file.
    title : str
        One line saying what it is.
    source : str
        Where its data come from (paper, page, table, equation), or ``"ours"`` with why.
    objective : str
        A key of :data:`OBJECTIVE_METRICS`.
    optimum : float
        The published or best known optimum, in the objective's unit.
    tolerance : float
        Absolute tolerance on the optimum (objective's unit): a row within it reaches the optimum.
    optimum_kind : str
        One of :data:`OPTIMUM_KINDS`.
    optimum_source : str
        Where the optimum comes from (the paper's page, or the two methods that agree).
    eigenaxis : float or None
        The eigenaxis slew's objective value on the problem (``None``: no eigenaxis slew is feasible).
    eigenaxis_source : str
        How that value was obtained.
    planners : tuple of str
        The planner registry names that apply (those of the scenario's rows).
    peers : bool
        Whether the peers are asked to solve it (they skip what they cannot express, each with its
        reason).
    notes : str
        Anything else a reader must know.
    peers_skip : str
        Why the peers are not asked (``peers: {skip: <why>}`` in the index); empty when they are.
    """

    name: str
    file: Path
    title: str
    source: str
    objective: str
    optimum: float
    tolerance: float
    optimum_kind: str
    optimum_source: str
    eigenaxis: float | None
    eigenaxis_source: str
    planners: tuple[str, ...]
    peers: bool = True
    notes: str = ""
    peers_skip: str = ""

    @property
    def unit(self) -> str:
        """The objective's unit (:data:`OBJECTIVE_METRICS`)."""
        return OBJECTIVE_METRICS[self.objective][1]

    def metadata(self) -> dict[str, Any]:
        """The problem's metadata as JSON-ready data.

        Returns
        -------
        dict
            Every field, the file relative to the suite's folder.
        """
        return {"name": self.name, "file": self.file.name, "title": self.title, "source": self.source,
                "objective": self.objective, "unit": self.unit, "optimum": self.optimum,
                "tolerance": self.tolerance, "optimum_kind": self.optimum_kind,
                "optimum_source": self.optimum_source, "eigenaxis": self.eigenaxis,
                "eigenaxis_source": self.eigenaxis_source, "planners": list(self.planners),
                "peers": self.peers, "peers_skip": self.peers_skip, "notes": self.notes}


@dataclass(frozen=True)
class Suite:
    """The suite: its version and problems in order.

    Parameters
    ----------
    version : int
        The index's version (changes when a problem, optimum or tolerance changes).
    problems : dict of str to BenchProblem
        Name -> problem, in the index's order.
    path : Path
        The index file.
    """

    version: int
    problems: dict[str, BenchProblem] = field(default_factory=dict)
    path: Path = SUITE_FILE


_REQUIRED = ("file", "title", "source", "objective", "optimum", "planners")


def _number(value: Any, where: str, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(where, f"expected a number, got {value!r}")
    if positive and not value > 0:
        raise ScenarioError(where, f"expected a positive number, got {value!r}")
    return float(value)


def _text(entry: dict[str, Any], key: str, where: str) -> str:
    value = entry.get(key)
    if not isinstance(value, str) or not value.strip():
        raise ScenarioError(f"{where}.{key}", f"expected a non-empty text, got {value!r}")
    return value.strip()


def _peers(entry: dict[str, Any], where: str) -> str:
    """Why the peers are not asked (``peers: {skip: <why>}``); empty when they are (``peers`` absent
    or ``true``)."""
    value = entry.get("peers", True)
    if value is True:
        return ""
    if isinstance(value, dict) and set(value) == {"skip"}:
        return _text(value, "skip", f"{where}.peers")
    raise ScenarioError(f"{where}.peers", f"expected true (ask the peers; each skips with a note what it cannot "
                                         f"express) or {{skip: <why the peers are not asked>}}, got {value!r}: every "
                                         "absence in the leaderboard needs its reason")


def _problem(name: str, entry: Any, folder: Path) -> BenchProblem:
    where = f"problems.{name}"
    if not isinstance(entry, dict):
        raise ScenarioError(where, f"expected a mapping, got {entry!r}")
    missing = [key for key in _REQUIRED if key not in entry]
    if missing:
        raise ScenarioError(where, f"missing {', '.join(missing)}")
    objective = entry["objective"]
    if objective not in OBJECTIVE_METRICS:
        raise ScenarioError(f"{where}.objective", f"expected one of {sorted(OBJECTIVE_METRICS)}, got {objective!r}")
    optimum = entry["optimum"]
    if not isinstance(optimum, dict):
        raise ScenarioError(f"{where}.optimum", f"expected a mapping (value, tolerance, kind, source), got {optimum!r}")
    kind = optimum.get("kind")
    if kind not in OPTIMUM_KINDS:
        raise ScenarioError(f"{where}.optimum.kind", f"expected one of {list(OPTIMUM_KINDS)}, got {kind!r}")
    eigenaxis = entry.get("eigenaxis")
    if not isinstance(eigenaxis, dict):
        raise ScenarioError(f"{where}.eigenaxis", f"expected a mapping (value, source), got {eigenaxis!r}")
    planners = entry["planners"]
    if not isinstance(planners, list) or not planners or not all(isinstance(p, str) for p in planners):
        raise ScenarioError(f"{where}.planners", f"expected a list of planner names, got {planners!r}")
    # the registry, with its plugins, when a suite is read
    from planners import PLANNERS
    from planners.errors import UnknownNameError
    for index, planner in enumerate(planners):
        if planner not in PLANNERS:  # metadata of the leaderboard: a typo would be published as a planner
            raise ScenarioError(f"{where}.planners[{index}]", str(UnknownNameError("planner", planner, PLANNERS)))
    skip = _peers(entry, where)
    file = folder / _text(entry, "file", where)
    if not file.is_file():
        raise ScenarioError(f"{where}.file", f"no scenario file {file.name} beside the index")
    return BenchProblem(
        name=name, file=file, title=_text(entry, "title", where), source=_text(entry, "source", where),
        objective=objective, optimum=_number(optimum.get("value"), f"{where}.optimum.value", positive=True),
        tolerance=_number(optimum.get("tolerance"), f"{where}.optimum.tolerance", positive=True),
        optimum_kind=kind, optimum_source=_text(optimum, "source", f"{where}.optimum"),
        eigenaxis=None if eigenaxis.get("value") is None else _number(eigenaxis["value"], f"{where}.eigenaxis.value"),
        eigenaxis_source=_text(eigenaxis, "source", f"{where}.eigenaxis"),
        planners=tuple(planners), peers=not skip, notes=str(entry.get("notes", "")).strip(), peers_skip=skip)


def load_suite(path: str | Path | None = None) -> Suite:
    """Read and check a suite index.

    Parameters
    ----------
    path : str, Path or None, optional
        The index file; ``None`` (default): the shipped one, :data:`SUITE_FILE`.

    Returns
    -------
    Suite
        The suite, its problems in the index's order.

    Raises
    ------
    ScenarioError
        A missing or malformed field, named by its YAML path, or a scenario file that is not there;
        its :attr:`~scenarios.errors.ScenarioError.file` is the index, named in its text.
    """
    path = SUITE_FILE if path is None else Path(path)
    try:
        data = read_yaml(path)
        if not isinstance(data, dict) or not isinstance(data.get("problems"), dict):
            raise ScenarioError("problems", "expected a mapping with version and problems")
        version = data.get("version")
        if isinstance(version, bool) or not isinstance(version, int) or version < 1:
            raise ScenarioError("version", f"expected a positive integer, got {version!r}")
        folder = path.parent / "problems"
        problems = {str(name): _problem(str(name), entry, folder) for name, entry in data["problems"].items()}
    except ScenarioError as error:
        raise in_file(error, path, "suite") from None
    return Suite(version, problems, path)
