"""Trade-study files (:doc:`/reference/schema`): reading a study and expanding it into resolved
cases, each validated by the scenario loader.

A study varies a base scenario over a ``grid`` (cartesian product), a ``zip`` (equal-length lists
varied together) and, per grid point, ``monte_carlo`` samples of ``dispersions``. Every case gets a
seed from ``numpy.random.SeedSequence(seed).spawn``, so its values (and its result) do not depend
on the number of workers or the order in which cases finish. The study file's keys, its value
generators and its distributions are declared in :mod:`scenarios.schema.study`; the study's data
classes are in :mod:`scenarios.study.types`.
"""
from __future__ import annotations

import copy
import itertools
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from scenarios.errors import ScenarioError
from scenarios.requirements.scoring import score_fields
from scenarios.schema.columns import REQUIREMENT_MARK, SCOPES, is_requirement_column
from scenarios.schema.loader import Scenario, parse_scenario
from scenarios.schema.node import Node
from scenarios.schema.read import read_yaml
from scenarios.schema.study import MAX_CASES, STUDY, grid_values
from scenarios.study.dispersions import Dispersion, draw_unit, parse_dispersion
from scenarios.study.paths import Step, get_path, parse_path, set_path
from scenarios.study.types import Case, Execution, Study, case_key, package_version


def _tree_copy(value: Any) -> Any:
    """A copy of YAML data (nested dicts and lists; leaves are immutable)."""
    if isinstance(value, dict):
        return {k: _tree_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_tree_copy(v) for v in value]
    return value


def _plain(value: Any) -> Any:
    """YAML/JSON-safe Python value (numpy scalars and arrays to floats and lists)."""
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def _varied(entry: Node, path: str, base: dict[str, Any], paths: list[str],
            steps: list[list[Step]]) -> tuple[list, list]:
    """Check that ``path`` reaches ``base``, record it in ``paths``/``steps``, and return its
    values (set into the scenario, recorded in the tables)."""
    paths.append(path)
    steps.append(parse_path(path, entry.path))
    get_parent_ok(base, steps[-1], entry.path)
    return grid_values(entry, base)


def _grid_points(root: Node, base: dict[str, Any]) -> tuple[list[str], list[list[Step]], list[tuple[list, list]]]:
    """Varied paths, their parsed steps and the points (values set, values recorded)."""
    paths: list[str] = []
    steps: list[list[Step]] = []
    axes: list[list[list[tuple[Any, Any]]]] = []
    grid = STUDY["grid"].value(root)
    for path in grid.value:
        entry = grid.get(path)
        values, recorded = _varied(entry, path, base, paths, steps)
        axes.append([[pair] for pair in zip(values, recorded)])
    zipped = STUDY["zip"].value(root)
    columns, length = [], None
    for path in zipped.value:
        entry = zipped.get(path)
        values, recorded = _varied(entry, path, base, paths, steps)
        if length is not None and len(values) != length:
            raise entry.error(f"zip lists must have equal lengths: {len(values)} values here, {length} before")
        length = len(values)
        columns.append(list(zip(values, recorded)))
    if columns:
        axes.append([list(row) for row in zip(*columns)])
    points = []
    for combination in itertools.product(*axes):
        flat = [pair for part in combination for pair in part]
        points.append(([v for v, _ in flat], [r for _, r in flat]))
    return paths, steps, points


def get_parent_ok(base: dict[str, Any], steps: list[Step], where: str) -> None:
    """Check on the base scenario that ``steps`` can be set (reaches existing lists and labels).

    Parameters
    ----------
    base : dict
        The base scenario mapping (not changed: a copy is written).
    steps : list of Step
        The parsed scenario path (:func:`scenarios.study.paths.parse_path`).
    where : str
        The study entry, for error messages.

    Raises
    ------
    ScenarioError
        The path does not reach the base scenario.
    """
    set_path(copy.deepcopy(base), steps, None, where)


def parse_study(data: Any, source: Path | None = None, version: str | None = None) -> Study:
    """Parse a study (YAML data), expand its cases and validate every one with the scenario loader.

    Parameters
    ----------
    data : Any
        The study mapping (``study``, ``scenario``, ``grid``, ``zip``, ``monte_carlo``,
        ``summary``, ``execution``).
    source : Path or None, optional
        The study file; a ``scenario`` path is relative to its folder (None: the working
        directory).
    version : str or None, optional
        The package version in the case keys (None: this one's; a stored study's when its
        report is redrawn).

    Returns
    -------
    Study
        With ``cases`` in order: grid points (the last grid key varies fastest, then the zip),
        then the Monte Carlo samples of each point.
    """
    root = Node(data).mapping()
    name = STUDY["study"].value(root)
    scenario_node = STUDY["scenario"].value(root)
    if isinstance(scenario_node.value, str):
        folder = source.parent if source else Path.cwd()
        try:
            base = read_yaml(folder / scenario_node.value)
        except ScenarioError as error:
            raise ScenarioError("scenario", error.message) from None
    else:
        base = copy.deepcopy(scenario_node.mapping().value)
    if not isinstance(base, dict):
        raise ScenarioError("scenario", "the base scenario is not a mapping")
    try:
        parse_scenario(copy.deepcopy(base))
    except ScenarioError as error:
        raise ScenarioError(f"scenario: {error.path}", error.message) from None
    paths, steps, points = _grid_points(root, base)
    mc = STUDY["monte_carlo"].value(root)
    dispersions: list[tuple[str, list[Step], Dispersion]] = []
    samples, method, seed = 1, None, 0
    if mc is not None:
        samples, method, seed = mc["samples"], mc["method"], mc["seed"]
        disp_node = mc["dispersions"]
        for path in disp_node.value:
            entry = disp_node.get(path)
            path_steps = parse_path(path, entry.path)
            if path in paths:
                raise entry.error("this path is also in grid or zip; vary it in one place")
            get_parent_ok(base, path_steps, entry.path)
            dispersions.append((path, path_steps, parse_dispersion(entry, base, path_steps)))
    total = len(points) * samples
    if total > MAX_CASES:
        raise ScenarioError("grid", f"the study has {total} cases; at most {MAX_CASES} are accepted")
    summary = STUDY["summary"].value(root)
    execution = Execution(**STUDY["execution"].value(root))
    STUDY["resolved"].value(root)  # written into study.yaml for the record (version, case seeds)
    root.finish()
    study = Study(name, source, base, paths, [p for p, _, _ in dispersions], samples, method, seed,
                  summary, execution, raw=copy.deepcopy(data))
    columns: dict[str, None] = {}
    study.cases = _expand(study, steps, points, dispersions, version or package_version(), columns)
    _check_summary(summary, columns)
    return study


def _requirement_columns(scenario: Scenario) -> list[str]:
    """The requirement columns a case's rows can give (``ref.req.<name>.<field>``, ``cl.req...``)."""
    fields = score_fields(scenario.requirements, scenario.problem.spacecraft)
    return [f"{prefix}.{REQUIREMENT_MARK}.{name}.{field}" for scope, prefix in SCOPES
            for name, names in fields[scope].items() for field in names]


def _check_summary(summary: list[str], columns: dict[str, None]) -> None:
    """Refuse a summary entry naming a requirement column that no case gives (a typo would
    summarise nothing, silently)."""
    for index, column in enumerate(summary):
        if not is_requirement_column(column) or column in columns:
            continue
        prefix, _, name, field = column.split(".")
        scope = {p: s for s, p in SCOPES}[prefix]
        own = [c for c in columns if c.split(".")[2] == name]
        if not own:
            names = sorted({c.split(".")[2] for c in columns})
            why = (f"no case has a requirement {name!r}; the study's requirements are {names}" if names
                   else f"no case has a requirement {name!r}: the scenario states none")
        elif not any(c.startswith(f"{prefix}.") for c in own):
            why = (f"requirement {name!r} is not scored in the {scope.replace('_', ' ')}; its columns are "
                   f"{own}")
        else:
            why = f"requirement {name!r} has no field {field!r}; its columns are {own}"
        listed = list(columns)
        more = f" ... ({len(listed)} in all)" if len(listed) > 12 else ""
        raise ScenarioError(f"summary[{index}]", f"{column!r}: {why}"
                            + (f" (the study's requirement columns: {listed[:12]}{more})" if listed else ""))


def _expand(study: Study, steps: list[list[Step]], points: list[tuple[list, list]],
            dispersions: list[tuple[str, list[Step], Dispersion]], version: str,
            columns: dict[str, None] | None = None) -> list[Case]:
    """The cases, each validated by the scenario loader; ``columns`` collects the requirement columns
    the cases can give (in order)."""
    n_cases = len(points) * study.samples
    children = np.random.SeedSequence(study.seed).spawn(n_cases + len(points))
    dims = sum(d.dimension for _, _, d in dispersions)
    cases = []
    for point, (values, recorded) in enumerate(points):
        design = None
        if dispersions and study.method == "latin_hypercube":
            design = draw_unit(study.method, dims, study.samples, np.random.default_rng(children[n_cases + point]))
        for sample in range(study.samples):
            index = point * study.samples + sample
            seed = int(children[index].generate_state(1)[0])
            data = _tree_copy(study.base)
            varied: dict[str, Any] = {}
            for path, path_steps, value, shown in zip(study.grid_paths, steps, values, recorded):
                set_path(data, path_steps, _tree_copy(value), path)
                varied[path] = shown
            if dispersions:
                unit = design[sample] if design is not None else \
                    draw_unit("random", dims, 1, np.random.default_rng(children[index]))[0]
                column = 0
                for path, path_steps, dispersion in dispersions:
                    u = unit[column:column + dispersion.dimension]
                    column += dispersion.dimension
                    value = _plain(dispersion.value(u, seed, get_path(study.base, path_steps, path)
                                                    if dispersion.needs_base else None))
                    set_path(data, path_steps, value, path)
                    varied[path] = value if not isinstance(value, list) else json.dumps(value)
            case = Case(index, seed, point, varied, data)
            scenario = _validate(study, case)
            if columns is not None:
                columns.update(dict.fromkeys(_requirement_columns(scenario)))
            case.key = case_key(data, version)
            cases.append(case)
    return cases


def _validate(study: Study, case: Case) -> Scenario:
    """The scenario loader's verdict on a case, naming the study, the case and the study entry."""
    try:
        return parse_scenario(case.scenario)  # the loader only reads its data
    except ScenarioError as error:
        entries = [p for p in case.varied if error.path.startswith(p) or p.startswith(error.path)]
        varied = ", ".join(f"{p}={json.dumps(v)[:40]}" for p, v in case.varied.items())
        culprit = f" (set by {', '.join(entries)})" if entries else ""
        raise ScenarioError(f"case {case.index} [{varied}]: {error.path}{culprit}", error.message) from None


def load_study(path: str | os.PathLike[str]) -> Study:
    """Read, expand and validate a study file.

    Parameters
    ----------
    path : str or os.PathLike
        The study YAML file.

    Returns
    -------
    Study
        As :func:`parse_study`.

    Raises
    ------
    ScenarioError
        Naming the study file, the case and the path, for a missing file, a bad entry or a case
        the scenario loader rejects.
    """
    path = Path(path)
    try:
        return parse_study(read_yaml(path), path)
    except ScenarioError as error:
        if error.message.startswith(f"scenario file not found: {path}"):
            raise ScenarioError("", f"study file not found: {path}") from None
        raise ScenarioError(f"{path}: {error.path}" if error.path else str(path), error.message) from None
