"""Trade-study files (:doc:`/reference/schema`): reading a study and expanding it into resolved,
validated cases.

A study varies a base scenario over a ``grid`` (cartesian product), a ``zip`` (equal-length lists
varied together) and, per grid point, ``monte_carlo`` samples of ``dispersions``. Every case gets a
seed from ``numpy.random.SeedSequence(seed).spawn``, so its values (and its result) do not depend
on the number of workers or the order in which cases finish. The study file's keys, its value
generators and its distributions are declared in :mod:`scenarios.schema.study`; the study's data
classes are in :mod:`scenarios.study.types`.

The number of cases is known from the lengths of the varied lists before any case is built, and a
study over :data:`~scenarios.schema.study.MAX_CASES` is refused then. Every case is checked before
anything runs, with the scenario loader's verdict, but without running the whole loader on every
case where that gives the same verdict: a value given to one of the scenario keys that no check
of the scenario as a whole reads (:data:`~scenarios.schema.study.INDEPENDENT_KEYS`) is checked by
that key's own reader, and the loader runs once per combination of the other varied values. A
case shares the parts of the base scenario it does not vary (:func:`scenarios.study.paths.with_values`).
"""
from __future__ import annotations

import copy
import hashlib
import json
import math
import os
import shlex
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ocp.errors import excerpt
from ocp.quat import UNIT_NORM_TOLERANCE
from scenarios.errors import ScenarioError, in_file
from scenarios.output.provenance import package_version
from scenarios.requirements.fields import is_requirement_column
from scenarios.requirements.scoring import score_fields
from scenarios.schema.checks import reads_the_simulated_start
from scenarios.schema.columns import REQUIREMENT_MARK, SCOPES
from scenarios.schema.keys import Key
from scenarios.schema.loader import OTHER_FILES, Scenario, parse_scenario
from scenarios.schema.node import Node
from scenarios.schema.read import read_yaml
from scenarios.schema.study import (
    CASE_SEED,
    MAX_CASES,
    MAX_VARIED,
    STUDY,
    grid_values,
    independent_key,
    symmetric_key,
    takes_integers,
)
from scenarios.study.dispersions import Dispersion, draw_unit, parse_dispersion
from scenarios.study.paths import Step, get_path, parse_path, with_values
from scenarios.study.types import (
    Case,
    Execution,
    Study,
    case_key,
    case_text,
)

PROGRESS_EVERY = 2048
"""Most cases checked between two calls of the ``progress`` callback of :func:`parse_study`."""
PROGRESS_S = 0.25
"""Longest time between two calls of the ``progress`` callback of :func:`parse_study` while cases are
checked (a case checked by the whole loader can take tens of milliseconds) [s]."""


@dataclass
class _Varied:
    """One varied scenario path: where the study sets it and how its values are checked."""

    path: str
    entry: str  # the study entry, for messages (grid.<path>, zip.<path>, monte_carlo.dispersions.<path>)
    steps: list[Step]
    independent: Key | None = None  # the key's reader checks each value (INDEPENDENT_KEYS)
    mirror: list[Step] | None = None  # a product of inertia's twin [j][i], set to the same value

    def targets(self) -> list[list[Step]]:
        """The paths a value of this entry is set at: its own, and its mirror's."""
        return [self.steps] if self.mirror is None else [self.steps, self.mirror]


@dataclass
class _Axis:
    """One grid axis: a grid entry, or every zip entry together."""

    varied: list[_Varied]
    values: list[list[Any]]  # per path, the values set
    recorded: list[list[Any]]  # per path, the values shown in the tables
    length: int = 0
    verdicts: list[dict[int, ScenarioError]] = field(default_factory=list)  # independent paths: bad values


def _plain(value: Any) -> Any:
    """YAML/JSON-safe Python value (numpy scalars and arrays to floats and lists)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def get_parent_ok(base: dict[str, Any], steps: list[Step], where: str) -> None:
    """Check on the base scenario that ``steps`` can be set (reaches existing lists and labels).

    Parameters
    ----------
    base : dict
        The base scenario mapping (not changed).
    steps : list of Step
        The parsed scenario path (:func:`scenarios.study.paths.parse_path`).
    where : str
        The study entry, for error messages.

    Raises
    ------
    ScenarioError
        The path does not reach the base scenario.
    """
    with_values(base, [(steps, None, where)])


def _recorded(value: Any) -> Any:
    """A varied value as the tables record it: lists as JSON text (a list of finite floats, the
    draws of a vector dispersion, written as ``json.dumps`` writes it, without its overhead)."""
    if not isinstance(value, list):
        return value
    if all(type(v) is float and math.isfinite(v) for v in value):
        return f"[{', '.join(map(float.__repr__, value))}]"
    return json.dumps(value)


class _KeyTemplate:
    """Case keys (:func:`scenarios.study.types.case_key`) without encoding each case's whole
    scenario: the canonical JSON of a case is the text of the first case with the varied values
    spliced in. Used when no varied path lies inside another (then every case has the same keys
    in the same places); None from :meth:`make` otherwise."""

    def __init__(self, pieces: list[str], order: list[int]):
        self.pieces, self.order = pieces, order

    @classmethod
    def make(cls, base: dict[str, Any], varied: list[_Varied], version: str) -> _KeyTemplate | None:
        targets = [(steps, item.entry) for item in varied for steps in item.targets()]  # as the cases' updates
        if any(a is not b and a[:len(b)] == b for a, _ in targets for b, _ in targets):
            return None
        marks = [f"\x00slewbench-varied-{index}\x00" for index in range(len(targets))]
        data = with_values(base, [(steps, mark, entry) for (steps, entry), mark in zip(targets, marks)])
        text = case_text(data, version)
        found = []
        for index, mark in enumerate(marks):
            written = json.dumps(mark)
            if text.count(written) != 1:
                return None
            found.append((text.index(written), index, len(written)))
        pieces, order, position = [], [], 0
        for start, index, length in sorted(found):
            pieces.append(text[position:start])
            order.append(index)
            position = start + length
        pieces.append(text[position:])
        return cls(pieces, order)

    def key(self, values: list[Any]) -> str:
        parts = [self.pieces[0]]
        for index, piece in zip(self.order, self.pieces[1:]):
            parts.append(json.dumps(values[index], sort_keys=True, separators=(",", ":")))
            parts.append(piece)
        return hashlib.sha256("".join(parts).encode()).hexdigest()[:32]


def _cut(text: str, limit: int = 60) -> str:
    """A path cut to ``limit`` characters for a message."""
    return text if len(text) <= limit else f"{text[:limit - 3]}..."


def _describe(varied: _Varied) -> str:
    return {"grid": "grid", "zip": "zip"}.get(varied.entry.split(".", 1)[0], "monte_carlo.dispersions")


def _register(varied: _Varied, seen: list[_Varied]) -> None:
    """Refuse a path varied twice, or one that replaces what an earlier entry varies inside it (the
    later entry would silently win); a longer path refining an earlier one is fine (a grid of noise
    mappings, each with the case's own seed)."""
    if len(seen) >= MAX_VARIED:
        raise ScenarioError(varied.entry, f"a study varies at most {MAX_VARIED} scenario paths")
    for earlier in seen:
        if earlier.steps == varied.steps:
            raise ScenarioError(varied.entry, f"this path is also in {_describe(earlier)}; vary it in one place")
        if varied.steps in earlier.targets()[1:] or earlier.steps in varied.targets()[1:]:
            raise ScenarioError(varied.entry, f"{_cut(earlier.path)} (varied by {_describe(earlier)}) is the same "
                                              "product of inertia: varying [i][j] sets [j][i] too; vary it in one place")
        inner, outer = sorted((earlier.steps, varied.steps), key=len, reverse=True)
        if symmetric_key(outer) and inner[:len(outer)] == outer:
            raise ScenarioError(varied.entry, f"{_cut(earlier.path)} (varied by {_describe(earlier)}) is the same "
                                              "inertia tensor; vary it in one place (the whole tensor, or its elements)")
        if any(target[:len(varied.steps)] == varied.steps for target in earlier.targets()):
            raise ScenarioError(varied.entry, f"it replaces {_cut(earlier.path)} (varied by {_describe(earlier)}) "
                                              "as a whole; vary it in one place")
    seen.append(varied)


def _mirror(steps: list[Step], base: dict[str, Any], where: str) -> list[Step] | None:
    """The twin ``<tensor>[j][i]`` of a path to a product of inertia ``<tensor>[i][j]`` (a key of
    :data:`~scenarios.schema.study.SYMMETRIC_KEYS`), which the study sets to the same value so that
    the tensor stays symmetric; None for any other path (a moment ``[i][i]`` included).

    Raises
    ------
    ScenarioError
        At ``where``: an element of a tensor the base scenario gives as 3 principal moments, or a
        whole row of a 3x3 tensor (it would break its symmetry).
    """
    for length in (len(steps) - 2, len(steps) - 1):
        if length < 1 or not symmetric_key(steps[:length]) or not all(isinstance(s, int) for s in steps[length:]):
            continue
        key = ".".join(map(str, steps[:length]))
        tensor = get_path(base, steps[:length], where)
        if not (isinstance(tensor, list) and len(tensor) == 3 and all(isinstance(row, list) for row in tensor)):
            if length == len(steps) - 2:
                raise ScenarioError(where, f"{key} holds 3 principal moments in the base scenario; give it as the 3x3 "
                                           "tensor (zero products of inertia) to vary its products of inertia")
            return None  # a principal moment of the 3 numbers
        if length == len(steps) - 1:
            raise ScenarioError(where, f"{_cut(key)}[{steps[-1]}] is a row of a symmetric tensor; vary the whole "
                                       f"tensor or its elements {key}[i][j] (each also sets [j][i])")
        i, j = (int(step) % 3 for step in steps[length:] if isinstance(step, int))
        return None if i == j else [*steps[:length], j, i]
    return None


def _axes(root: Node, base: dict[str, Any], seen: list[_Varied]) -> list[_Axis]:
    """The grid axes (one per grid entry, then one for the zip entries together), every value read
    and checked against its entry, before any case is built."""
    axes: list[_Axis] = []
    for section in ("grid", "zip"):
        node = STUDY[section].value(root)
        zipped: _Axis | None = None
        for path in node.value:
            entry = node.get(path)
            varied = _Varied(path, entry.path, parse_path(path, entry.path))
            varied.mirror = _mirror(varied.steps, base, entry.path)
            get_parent_ok(base, varied.steps, entry.path)
            _register(varied, seen)
            values, recorded = grid_values(entry, base)
            if section == "grid":
                _refuse_repeats(entry, list(recorded))
                axes.append(_Axis([varied], [values], [recorded], len(values)))
                continue
            if zipped is None:
                zipped = _Axis([], [], [], len(values))
                axes.append(zipped)
            elif len(values) != zipped.length:
                raise entry.error(f"zip lists must have equal lengths: {len(values)} values here, {zipped.length} before")
            zipped.varied.append(varied)
            zipped.values.append(values)
            zipped.recorded.append(recorded)
            if len(zipped.recorded) == len(node.value):  # the last zip entry: repeated tuples of them all
                _refuse_repeats(entry, list(zip(*zipped.recorded)), "zip")
    return axes


def _refuse_repeats(entry: Node, recorded: list[Any], section: str = "grid") -> None:
    """Refuse a value (a zip's tuple of values) given twice in one axis: the same cases ran twice,
    and the summaries and robustness tables counted them twice, without a word."""
    first: dict[Any, int] = {}
    for index, value in enumerate(recorded):
        key = tuple((type(item) is bool, item) for item in value) if isinstance(value, tuple) else \
            (type(value) is bool, value)  # true is not 1 (nor 1.0, which is 1)
        if key in first:
            what = "values" if section == "grid" else "tuple of the zip's values"
            raise entry.error(f"{value!r} is given twice ({what} [{first[key]}] and [{index}]): its cases would run "
                              "twice and count twice in the summaries; give each once")
        first[key] = index


def _base(root: Node, source: Path | None) -> dict[str, Any]:
    """The base scenario (a file next to the study, or a mapping), checked by the scenario loader."""
    node = STUDY["scenario"].value(root)
    if isinstance(node.value, str):
        folder = source.parent if source else Path.cwd()
        where = f"scenario: {folder / node.value}"  # the base scenario's errors name its file too
        try:
            base = read_yaml(folder / node.value)
        except ScenarioError as error:
            raise ScenarioError("scenario", error.message) from None
    else:
        where = "scenario"
        base = copy.deepcopy(node.mapping().value)
    if not isinstance(base, dict):
        raise ScenarioError(where, "the base scenario is not a mapping")
    try:
        parse_scenario(base, inapplicable_rows=True)  # the loader only reads its data; a planner the base
        # does not suit may suit other cases (:meth:`_Expansion.refuse_unused_planners`)
    except ScenarioError as error:
        raise ScenarioError(f"{where}: {error.path}" if error.path else where, error.message) from None
    return base


def parse_study(data: Any, source: str | os.PathLike[str] | None = None, version: str | None = None,
                progress: Callable[[int, int], None] | None = None,
                parsed: Callable[[Case, Scenario], None] | None = None,
                execution_read: Callable[[Execution], None] | None = None) -> Study:
    """Parse a study (YAML data), expand its cases and check every one (see the module docstring).

    Parameters
    ----------
    data : Any
        The study mapping (``study``, ``scenario``, ``grid``, ``zip``, ``monte_carlo``,
        ``summary``, ``execution``).
    source : str, os.PathLike or None, optional
        The study file; a ``scenario`` path is relative to its folder (None: the working
        directory).
    version : str or None, optional
        The package version in the case keys (None: this one's; a stored study's when its
        report is redrawn).
    progress : callable or None, optional
        ``progress(checked, total)``, called while the cases are checked (every
        :data:`PROGRESS_EVERY` cases, after the case that ends :data:`PROGRESS_S` since the
        last call, and at the end).
    parsed : callable or None, optional
        ``parsed(case, scenario)``, called with each case the whole scenario loader checked
        (``scenario``: what :func:`~scenarios.schema.loader.parse_scenario` built from it, with
        ``inapplicable_rows``), once it passed; a case checked by the verdict of an earlier case of
        its class is not given (see the module docstring). ``slewbench validate`` and ``sweep
        --dry-run`` take the cases' findings from it rather than parse those cases again.
    execution_read : callable or None, optional
        ``execution_read(execution)``, called with the study's ``execution`` section once the
        study's own keys are read and before any case is built or checked (``slewbench sweep``
        checks ``execution.scheduler`` there: a closed port is refused before a long check of
        the cases); what it raises is raised.

    Returns
    -------
    Study
        With ``cases`` in order: grid points (the last grid key varies fastest, then the zip),
        then the Monte Carlo samples of each point.

    Raises
    ------
    ScenarioError
        Naming the study entry (or the case and the scenario path), for a bad study or a case the
        scenario loader rejects.
    TypeError
        ``source``, ``version``, ``progress`` or ``parsed`` of the wrong type.
    """
    if source is not None and not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"source must be a path or None, got {type(source).__name__}")
    if version is not None and not isinstance(version, str):
        raise TypeError(f"version must be a str or None, got {type(version).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable or None, got {type(progress).__name__}")
    if parsed is not None and not callable(parsed):
        raise TypeError(f"parsed must be callable or None, got {type(parsed).__name__}")
    if execution_read is not None and not callable(execution_read):
        raise TypeError(f"execution_read must be callable or None, got {type(execution_read).__name__}")
    source = None if source is None else Path(source)
    root = Node(data).mapping()
    name = STUDY["study"].value(root)
    base = _base(root, source)
    seen: list[_Varied] = []
    axes = _axes(root, base, seen)
    mc = STUDY["monte_carlo"].value(root)
    samples, method, seed = (1, None, 0) if mc is None else (mc["samples"], mc["method"], mc["seed"])
    points = math.prod(axis.length for axis in axes)  # the count before any case is built
    if points * samples > MAX_CASES:
        sizes = " x ".join(str(n) for n in [*(axis.length for axis in axes), *([samples] if mc else [])])
        raise ScenarioError("grid" if points > MAX_CASES or mc is None else "monte_carlo.samples",
                            f"the study has {sizes} = {points * samples} cases; at most {MAX_CASES} are accepted")
    dispersions: list[tuple[_Varied, Dispersion]] = []
    if mc is not None:
        node = mc["dispersions"]
        if not node.value:  # every sample would be the same case: one simulation counted as many
            raise node.error("give at least one dispersion (scenario path -> distribution); without one every "
                             "Monte Carlo sample is the same case, one simulation counted as independent samples. "
                             "To run the scenario once, drop monte_carlo")
        for path in node.value:
            entry = node.get(path)
            varied = _Varied(path, entry.path, parse_path(path, entry.path))
            varied.mirror = _mirror(varied.steps, base, entry.path)
            get_parent_ok(base, varied.steps, entry.path)
            _register(varied, seen)
            dispersion = parse_dispersion(entry, base, varied.steps)
            if dispersion.kind == CASE_SEED.name and takes_integers(varied.steps, base) is False:
                raise entry.error(f"case_seed sets an integer (the case's seed); {_cut(path)} does not take one "
                                  "(simulation.sensor_noise.seed does)")
            dispersions.append((varied, dispersion))
    summary = STUDY["summary"].value(root)
    execution = Execution(**STUDY["execution"].value(root))
    robustness = STUDY["robustness"].value(root)
    STUDY["resolved"].value(root)  # written into study.yaml for the record (version, case seeds)
    root.finish()
    if execution_read is not None:
        execution_read(execution)
    _mark_independent(seen)
    study = Study(name, source, base, [v.path for axis in axes for v in axis.varied], [v.path for v, _ in dispersions],
                  samples, method, seed, summary, execution, raw=copy.deepcopy(root.value),
                  thresholds=robustness["thresholds"], worst=robustness["worst"])
    expansion = _Expansion(study, axes, dispersions, version or package_version(), progress, parsed)
    study.cases = expansion.cases()
    expansion.refuse_unused_planners()
    _check_summary([(f"summary[{index}]", column) for index, column in enumerate(summary)]
                   + [(f"robustness.thresholds.{column}", column) for column in study.thresholds], expansion.columns)
    return study


def _requirement_columns(scenario: Scenario) -> list[str]:
    """The requirement columns a case's rows can give (``ref.req.<name>.<field>``, ``cl.req...``), each
    requirement's verdict first (:func:`~scenarios.requirements.scoring.score_fields`)."""
    fields = score_fields(scenario.requirements, scenario.problem.spacecraft, scenario.truth)
    return [f"{prefix}.{REQUIREMENT_MARK}.{name}.{field}" for scope, prefix in SCOPES
            for name, names in fields[scope].items() for field in names]


def _check_summary(summary: list[tuple[str, str]], columns: dict[str, None]) -> None:
    """Refuse a summary entry (or threshold), given as ``(where, column)``, naming a requirement
    column that no case gives (a typo would summarise nothing, silently; a requirement's verdict, a
    bool, is refused where the study's YAML is read)."""
    for where, column in summary:
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
        raise ScenarioError(where, f"{column!r}: {why}"
                            + (f" (the study's requirement columns: {listed[:12]}{more})" if listed else ""))


def _mark_independent(seen: list[_Varied]) -> None:
    """Give each varied path whose key no whole-scenario check reads its key, unless another varied
    path lies inside it or holds it (then the two are checked together by the loader)."""
    for varied in seen:
        overlaps = any(other is not varied and (other.steps[:len(varied.steps)] == varied.steps
                                                or varied.steps[:len(other.steps)] == other.steps) for other in seen)
        varied.independent = None if overlaps else independent_key(varied.steps)


QUATERNION_PATHS = ("maneuver.initial.q", "maneuver.final.q")
"""The scenario paths of the attitudes, whose quaternion form (four numbers, at the path itself or
in the mapping form at ``<path>.quaternion``) a dispersion would draw number by number
(:func:`_refuse_drawn_quaternions`)."""


def _refuse_drawn_quaternions(varied: _Varied, values: np.ndarray) -> None:
    """One error for the whole dispersion, at its study entry, when a dispersion of a quaternion
    (:data:`QUATERNION_PATHS`, four numbers) draws any case whose norm is not within
    ``ocp.quat.UNIT_NORM_TOLERANCE`` of 1, rather than the scenario loader's per-case advice to
    normalise a quaternion, which a study's user cannot act on: the draws are the study's. Such a
    draw is not normalised either: four numbers drawn independently and normalised are not a
    distribution of rotations anyone asked for (draws within the tolerance are, as a written
    quaternion is, by the loader)."""
    attitude = varied.path.removesuffix(".quaternion")
    if attitude not in QUATERNION_PATHS or values.shape[1] != 4:
        return
    norms = np.linalg.norm(values, axis=1)
    off = np.flatnonzero(np.abs(norms - 1.0) > UNIT_NORM_TOLERANCE)
    if not off.size:
        return
    first = int(off[0])
    start = ("; for the closed loop's start about the planned attitude, simulation.initial_attitude_error_deg "
             "(a rotation vector [deg], body axes)" if attitude == "maneuver.initial.q" else "")
    raise ScenarioError(varied.entry, f"{off.size} of {len(values)} cases draw a quaternion whose norm is not within "
                                      f"{UNIT_NORM_TOLERANCE:g} of 1 (case {first}: norm {norms[first]:.6g}): the four "
                                      "numbers of a quaternion do not disperse independently (normalised, such draws "
                                      "would be a distribution of rotations nobody asked for); "
                                      f"disperse a rotation instead: write {attitude} in the axis_angle form "
                                      f"({attitude}: {{axis_angle: {{axis: [x, y, z], angle_deg: a}}}}) and "
                                      f"disperse {attitude}.axis_angle.angle_deg and "
                                      f"{attitude}.axis_angle.axis{start}")


class _Expansion:
    """The cases of a study, built and checked in order (see the module docstring)."""

    def __init__(self, study: Study, axes: list[_Axis], dispersions: list[tuple[_Varied, Dispersion]], version: str,
                 progress: Callable[[int, int], None] | None, parsed: Callable[[Case, Scenario], None] | None = None):
        self.study, self.axes, self.dispersions, self.version = study, axes, dispersions, version
        self.progress, self.parsed = progress, parsed
        self.points = math.prod(axis.length for axis in axes)
        self.total = self.points * study.samples
        self.checked: set[tuple[int, ...]] = set()  # classes of cases the whole loader has passed
        # classes whose controllers read the simulated start (reads_the_simulated_start): every case of
        # theirs goes through the whole loader, their initial errors not independent of the scenario
        self.start_read: set[tuple[int, ...]] = set()
        self.columns: dict[str, None] = {}  # requirement columns the cases give, in order
        self.accepted: set[int] = set()  # planner rows some case's problem suits
        self.refused: dict[int, tuple[Case, str, str]] = {}  # planner row -> its first refused case, name, reason
        for axis in axes:
            axis.verdicts = [self._verdicts(varied, values) for varied, values in zip(axis.varied, axis.values)]

    @staticmethod
    def _verdicts(varied: _Varied, values: list[Any]) -> dict[int, ScenarioError]:
        """The errors of an independent grid path's values, by position (each value checked once)."""
        if varied.independent is None:
            return {}
        found = {}
        for position, value in enumerate(values):
            try:
                _read(varied.independent, value, varied.path)
            except ScenarioError as error:
                found[position] = error
        return found

    def _draws(self, seeds: list[int], children: list[np.random.SeedSequence]) -> list[list[Any]]:
        """Per dispersion, the value of every case (in case order), drawn as case by case; the drawn
        quantities (:meth:`scenarios.study.dispersions.Dispersion.drawn`) go into ``self.drawn``."""
        self.drawn: list[tuple[str, str, np.ndarray]] = []  # (parameter, draw, values per case)
        if not self.dispersions:
            return []
        study, n = self.study, self.total
        dims = sum(d.dimension for _, d in self.dispersions)
        units = np.zeros((n, dims))
        if dims and study.method == "latin_hypercube":
            for point in range(self.points):
                rng = np.random.default_rng(children[n + point])
                units[point * study.samples:(point + 1) * study.samples] = draw_unit(study.method, dims, study.samples, rng)
        elif dims:
            for index in range(n):
                units[index] = np.random.default_rng(children[index]).random(dims)
        columns: list[list[Any]] = []
        column = 0
        for varied, dispersion in self.dispersions:
            base = get_path(study.base, varied.steps, varied.entry) if dispersion.needs_base else None
            own = units[:, column:column + dispersion.dimension]
            values = dispersion.values(own, seeds, base)
            column += dispersion.dimension
            refused = dispersion.refused(own)
            if refused is not None:
                raise ScenarioError(varied.entry, f"case {refused[0]}: {refused[1]}")
            names, drawn = dispersion.drawn(own)
            draw = {"set": "value"}.get(dispersion.combine, dispersion.combine)
            self.drawn += [(varied.path + name, draw, drawn[:, k]) for k, name in enumerate(names)]
            if isinstance(values, np.ndarray):
                finite = np.isfinite(values.reshape(n, -1)).all(axis=1)
                if not finite.all():
                    bad = int(np.argmin(finite))
                    raise ScenarioError(varied.entry, f"case {bad} draws a value that is not finite "
                                                      f"({excerpt(values[bad].tolist())}); the distribution's "
                                                      "parameters are too large")
                _refuse_drawn_quaternions(varied, values.reshape(n, -1))
                columns.append(values.tolist())
            else:
                columns.append(values)
        return columns

    def cases(self) -> list[Case]:
        """Every case, built, checked and keyed."""
        study, n, samples = self.study, self.total, self.study.samples
        children = np.random.SeedSequence(study.seed).spawn(n + self.points)
        seeds = [int(child.generate_state(1)[0]) for child in children[:n]]
        draws = self._draws(seeds, children)
        study.parameters = {name: draw for name, draw, _ in self.drawn}
        names = list(study.parameters)
        drawn_rows = [dict(zip(names, row)) for row in np.column_stack([v for _, _, v in self.drawn]).tolist()] \
            if names else [{} for _ in range(n)]
        radix = [axis.length for axis in self.axes]
        template = _KeyTemplate.make(study.base, [item for axis in self.axes for item in axis.varied]
                                     + [item for item, _ in self.dispersions], self.version)
        cases = []
        called = time.monotonic()
        for point in range(self.points):
            positions, rest = [], point
            for length in reversed(radix):  # the last axis varies fastest
                rest, position = divmod(rest, length)
                positions.append(position)
            positions.reverse()
            updates, varied, grid_class = [], {}, []
            for axis, position in zip(self.axes, positions):
                independent = True
                for item, values, recorded in zip(axis.varied, axis.values, axis.recorded):
                    updates += [(steps, values[position], item.entry) for steps in item.targets()]
                    varied[item.path] = recorded[position]
                    independent &= item.independent is not None
                grid_class.append(-1 if independent else position)
            for sample in range(samples):
                index = point * samples + sample
                case_updates, case_varied = list(updates), dict(varied)
                case_class, drawn = tuple(grid_class), []
                for (item, _), column in zip(self.dispersions, draws):
                    value = column[index]
                    case_updates += [(steps, value, item.entry) for steps in item.targets()]
                    case_varied[item.path] = _recorded(value)
                    if item.independent is None:
                        case_class += (index,)
                    else:
                        drawn.append((item, value))
                case = Case(index, seeds[index], point, case_varied, with_values(study.base, case_updates),
                            drawn=drawn_rows[index])
                self._check(case, case_class, positions, drawn)
                case.key = case_key(case.scenario, self.version) if template is None else \
                    template.key([value for _, value, _ in case_updates])
                cases.append(case)
                if self.progress is not None and index + 1 < n and (
                        (index + 1) % PROGRESS_EVERY == 0 or time.monotonic() - called >= PROGRESS_S):
                    self.progress(index + 1, n)
                    called = time.monotonic()
        if self.progress is not None:
            self.progress(n, n)
        return cases

    def _check(self, case: Case, case_class: tuple[int, ...], positions: list[int],
               drawn: list[tuple[_Varied, Any]]) -> None:
        """The loader's verdict on ``case``: its independent values by their keys' readers, the rest
        by the whole loader once per class of cases."""
        for axis, position in zip(self.axes, positions):
            for verdicts in axis.verdicts:
                if position in verdicts:
                    raise _case_error(case, verdicts[position])
        for item, value in drawn:
            try:
                _read(item.independent, value, item.path)  # type: ignore[arg-type]
            except ScenarioError as error:
                raise _case_error(case, error) from None
        if case_class not in self.checked or case_class in self.start_read:
            try:
                scenario = parse_scenario(case.scenario, inapplicable_rows=True)  # the loader only reads its data
            except ScenarioError as error:
                raise _case_error(case, error) from None
            self.checked.add(case_class)
            if reads_the_simulated_start(scenario.controllers):
                self.start_read.add(case_class)
            if self.parsed is not None:
                self.parsed(case, scenario)
            # a class shares the problem (independent keys are not in it): its planners' verdicts hold for all
            for index, spec in enumerate(scenario.planners):
                if index in scenario.inapplicable:
                    self.refused.setdefault(index, (case, spec.name, scenario.inapplicable[index]))
                else:
                    self.accepted.add(index)
            # a class of cases shares every key a requirement column depends on (independent keys
            # are initial errors, noise and tolerances), so one parse per class lists them all
            self.columns.update(dict.fromkeys(_requirement_columns(scenario)))

    def refuse_unused_planners(self) -> None:
        """Refuse a planner row that no case's problem suits (as ``run`` refuses it): a study of its
        rows would hold nothing but failures. One that suits some cases fails the others' rows."""
        for index, (case, name, reason) in self.refused.items():
            if index not in self.accepted:
                raise ScenarioError(f"scenario: planners[{index}]",
                                    f"{name} cannot take any of the study's {self.total} case(s) (case {case.index}: "
                                    f"{reason}); remove it, or vary the study so that some case suits it")


def _read(key: Key, value: Any, path: str) -> Any:
    """``value`` read by ``key``'s reader at the scenario ``path`` (as the loader reads it)."""
    return key.read(Node(value, path))  # type: ignore[misc]


CASE_VALUE_CHARS = 80
"""Most characters of one varied value in the message on a bad case (:func:`_shown_value`)."""
CASE_VALUES_CHARS = 300
"""Most characters of the varied values listed in the message on a bad case; the others are counted."""


def _shown_value(value: Any, limit: int = CASE_VALUE_CHARS) -> str:
    """A varied value as an error message shows it: numbers to 6 significant digits, a vector or
    matrix (recorded as JSON text, :func:`_recorded`) element by element, and at most ``limit``
    characters, a cut value ending in ``...`` inside its brackets or quotes, so that it cannot be
    read as running into the next value."""
    if isinstance(value, str) and value.startswith("["):
        try:
            value = json.loads(value)
        except ValueError:
            pass
    return _compact(value, max(limit, 8))


def _compact(value: Any, limit: int) -> str:
    """:func:`_shown_value` of a parsed value."""
    if isinstance(value, float):
        text = f"{value:.6g}"
        text += "" if any(c in text for c in ".enia") else ".0"  # 30.0 stays a float; not nan, inf
    elif isinstance(value, (list, tuple, dict)):
        items = list(value.items()) if isinstance(value, dict) else list(value)
        opening, closing = ("{", "}") if isinstance(value, dict) else ("[", "]")
        parts: list[str] = []
        used = 2
        for index, item in enumerate(items):
            room = limit - used - (5 if index < len(items) - 1 else 0)  # and the ", ..." of a cut
            # a nested list is cut to the room left, a number or a key is shown whole or not at all
            if isinstance(value, dict):
                key = f"{_compact(item[0], limit)}: "
                part = key + _compact(item[1], max(room - len(key), 8))
            else:
                part = _compact(item, max(room, 8))
            if len(part) > room:
                parts.append("...")
                break
            parts.append(part)
            used += len(part) + 2
        return opening + ", ".join(parts) + closing
    elif isinstance(value, str):
        text = json.dumps(value)
        if len(text) > limit:
            kept = limit - 5
            while kept > 0 and len(json.dumps(value[:kept])) > limit - 3:  # escapes are longer
                kept -= 1
            text = f"{json.dumps(value[:kept])[:-1]}...\""
    else:
        text = json.dumps(value) if value is None or isinstance(value, bool) else str(value)
    return text if len(text) <= limit else f"{text[:limit - 3]}..."


def _case_error(case: Case, error: ScenarioError) -> ScenarioError:
    """The loader's error on a case, naming the case, its varied values (each cut short and marked
    so, at most :data:`CASE_VALUES_CHARS` of them in all) and the study entry that set the
    offending path."""
    entries = [p for p in case.varied if error.path.startswith(p) or p.startswith(error.path)]
    shown: list[str] = []
    used = 0
    for number, (path, value) in enumerate(case.varied.items()):
        part = f"{_cut(path)}={_shown_value(value)}"
        if shown and used + len(part) > CASE_VALUES_CHARS:
            shown.append(f"... {len(case.varied) - number} more of {len(case.varied)} values")
            break
        shown.append(part)
        used += len(part) + 2
    culprit = f" (set by {', '.join(_cut(p) for p in entries[:3])})" if entries else ""
    return ScenarioError(f"case {case.index} [{', '.join(shown)}]: {error.path}{culprit}", error.message)


def _refuse_other_file(data: Any, path: Path) -> None:
    """A scenario or slew-table file given where a study is expected: name the command that runs it
    (the mirror of :func:`scenarios.schema.loader.load`'s message for a study given to ``run``)."""
    if not isinstance(data, dict) or "study" in data:
        return
    for key, command in OTHER_FILES.items():
        if key in data:
            raise ScenarioError("", f"this is a {key} file, not a study: run it with `slewbench {command} {path}`")
    if "maneuver" in data:  # every scenario has one; no study has it at the top level
        raise ScenarioError("", f"this is a scenario file, not a study: run it with `slewbench run {path}` "
                                "(a study names it under `scenario:`)")


LARGE_STUDY = 1000
"""Cases above which ``sweep`` and ``sweep --dry-run`` say how to estimate the run time
(:func:`size_note`); a study of any size up to :data:`~scenarios.schema.study.MAX_CASES` runs."""


NOISE_SEED_PATH = "simulation.sensor_noise.seed"
"""The scenario path of the seed of every sensor's noise (:func:`noise_note`)."""


def _noisy(scenario: Any) -> bool:
    """Whether a case's scenario mapping measures with noise: a ``simulation.sensor_noise`` standard
    deviation above 0, or ``simulation.sensors`` (a gyro, a star tracker) given."""
    simulation = scenario.get("simulation") if isinstance(scenario, dict) else None
    if not isinstance(simulation, dict):
        return False
    noise = simulation.get("sensor_noise")
    stds = [noise.get(key) for key in ("attitude_deg", "rate", "magnetic_field")] if isinstance(noise, dict) else []
    return (any(isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0 for v in stds)
            or simulation.get("sensors") not in (None, "none"))


def noise_note(study: Study) -> str | None:
    """A Monte Carlo study whose samples measure with noise but share its seed
    (:data:`NOISE_SEED_PATH` varied by no entry): each grid point's samples then see one and the
    same noise history, so their spread holds none of the noise's. A note, never a refusal: common
    noise may be meant (to isolate a plant dispersion's effect).

    Parameters
    ----------
    study : Study
        The study.

    Returns
    -------
    str or None
        ``note: ...`` naming the fix, or ``None`` (one sample per grid point, no noise, or a varied seed).
    """
    if study.samples <= 1 or not study.cases:
        return None
    steps = NOISE_SEED_PATH.split(".")
    if any(path.split(".")[:len(steps)] == steps[:len(path.split("."))] for path in study.grid_paths + study.mc_paths):
        return None  # the seed (or a mapping that holds it) is varied
    if not any(_noisy(case.scenario) for case in study.cases):
        return None
    return (f"note: the {study.samples} Monte Carlo samples of each grid point share one sensor-noise history "
            f"({NOISE_SEED_PATH} is the same in every case), so their spread holds none of the noise's (as meant "
            f"when the noise is held fixed to isolate what the dispersions do); to draw the noise per case, add "
            f"'{NOISE_SEED_PATH}: case_seed' to monte_carlo.dispersions")

def size_note(study: Study, workers: int) -> str | None:
    """What to know of a large study before it runs: its case count, the worker time at 1 s a case
    and how to time one of its cases. Never a refusal.

    Parameters
    ----------
    study : Study
        The study.
    workers : int
        The workers it runs on (at least 1).

    Returns
    -------
    str or None
        ``note: ...`` for a study of more than :data:`LARGE_STUDY` cases, else ``None``.
    """
    cases, workers = len(study.cases), max(int(workers), 1)
    if cases <= LARGE_STUDY:
        return None
    scenario = study.raw.get("scenario") if isinstance(study.raw, dict) else None
    if isinstance(scenario, str):
        base = Path(scenario) if study.source is None else Path(study.source).parent / scenario
        timing = f"slewbench run {shlex.quote(str(base))} --no-plots"
    else:
        timing = "slewbench run on its base scenario with --no-plots"
    hours = cases / 3600.0
    return (f"note: {cases} cases is a large study (over {LARGE_STUDY}): at 1 s a case that is {hours:.1f} h of "
            f"worker time, {hours / workers:.1f} h on {workers} worker{'s' if workers != 1 else ''}. To estimate "
            f"it, time one case ({timing} prints its plan and simulation times) and multiply by {cases} / "
            f"{workers}; once cases finish, the progress bar shows the time left.")


def load_study(path: str | os.PathLike[str], progress: Callable[[int, int], None] | None = None,
               parsed: Callable[[Case, Scenario], None] | None = None,
               execution_read: Callable[[Execution], None] | None = None) -> Study:
    """Read, expand and check a study file.

    Parameters
    ----------
    path : str or os.PathLike
        The study YAML file.
    progress : callable or None, optional
        As :func:`parse_study`.
    parsed : callable or None, optional
        As :func:`parse_study`.
    execution_read : callable or None, optional
        As :func:`parse_study`.

    Returns
    -------
    Study
        As :func:`parse_study`.

    Raises
    ------
    ScenarioError
        Naming the study file (its :attr:`~scenarios.errors.ScenarioError.file`, and first in its
        text), the case and the path, for a missing file, a bad entry or a case the scenario loader
        rejects; an error in a base scenario read from its own file names that file too.
    TypeError
        ``path`` is not a path.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a str or os.PathLike, got {type(path).__name__}")
    path = Path(path)
    try:
        data = read_yaml(path)
        _refuse_other_file(data, path)
        return parse_study(data, path, progress=progress, parsed=parsed, execution_read=execution_read)
    except ScenarioError as error:
        raise in_file(error, path, "study") from None

