"""``slewbench`` command line: run, validate, list, schema, codegen, export, sweep, bench, table, and ``--version``.

Exit status (:mod:`scenarios.cli.status`): 0 when the run completed (a failed planner or a
violated requirement is a row, not an error), 1 under ``run --strict`` when some row is not ``ok``
(the results are written all the same), under ``validate --strict`` when a scenario (a study's case) cannot have an ok row or has a plausibility warning, or a table is too large, or under ``table --strict`` when some entry is not, 2 for a bad scenario file, a
plugin that fails to load or takes a registered name (:mod:`scenarios.schema.plugins`), or an output location
slewbench must not or cannot write to, 1 for an internal error.
"""
from __future__ import annotations

import argparse
import contextlib
import errno
import functools
import json
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from controllers import CONTROLLERS
from planners import PLANNERS
from scenarios.cli.bench import add_bench_parser
from scenarios.cli.status import (
    EXIT_BAD_OUTPUT,
    EXIT_BAD_SCENARIO,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_NOT_OK,
    EXIT_OK,
    attached_values,
    directory_argument,
    interrupted_status,
)
from scenarios.cli.sweep import add_sweep_parser
from scenarios.cli.table import add_table_parser
from scenarios.errors import OutputError, ScenarioError, in_file
from scenarios.output.directory import (
    check_output_directory,
    claimed_output_directory,
    written_files,
)
from scenarios.output.export import EXPORT_FORMATS, default_export_directory, export_run
from scenarios.output.names import default_output_directory, suffix_note
from scenarios.output.provenance import package_version
from scenarios.output.writer import check_run_directory, plot_streamer, run_files
from scenarios.runner import final_accuracy_note, run
from scenarios.schema.labels import row_labels
from scenarios.schema.loader import (
    OTHER_FILES,
    Scenario,
    load,
    parse_scenario,
    refuse_unmarked_base,
)
from scenarios.schema.plausibility import plausibility_warnings
from scenarios.schema.plugins import PluginError, load_plugins, loaded_plugins, provider
from scenarios.schema.read import read_yaml


def command_list(args: argparse.Namespace) -> int:
    """``slewbench list [--options NAME]``: print the registered planners and controllers, one line
    each (a plugin's marked with the plugin), and the plugins loaded with what each registered, or
    the options of one of them.

    Parameters
    ----------
    args : argparse.Namespace
        ``options`` (optional): a planner's or controller's registry name, whose options are printed
        with their type, unit, default and range (:func:`scenarios.schema.reference.options_text`).

    Returns
    -------
    int
        Exit status: 0, or 2 for a name that is neither a planner nor a controller (its close
        matches are listed).
    """
    # imported here: only this command needs them
    from scenarios.schema.reference import options_text, summary_line

    name = getattr(args, "options", None)
    if name is not None:
        try:
            text = options_text(name)
        except ScenarioError as error:
            print(f"slewbench: {error}", file=sys.stderr)
            return EXIT_BAD_SCENARIO
        sys.stdout.write(text)
        return EXIT_OK
    print("planners:")
    for name, planner in PLANNERS.items():
        print(f"  {name:32s} {summary_line(planner)}{_from_plugin('planner', name)}")
    print("controllers:")
    for name, controller in CONTROLLERS.items():
        print(f"  {name:32s} {summary_line(controller)}{_from_plugin('controller', name)}")
    plugins = loaded_plugins()
    if plugins:
        print("plugins:")
        for plugin in plugins:
            provided = "; ".join(f"{kind} {', '.join(names)}" for kind, names in plugin.provided.items())
            print(f"  {plugin.label}: {provided or 'registered nothing'}")
    print("(slewbench list --options NAME: the options of one, with type, unit, default and range)")
    return EXIT_OK


def _from_plugin(kind: str, name: str) -> str:
    """`` [plugin: <label>]`` after a name a plugin provided, else nothing."""
    label = provider(kind, name)
    return f" [plugin: {label}]" if label else ""


def command_schema(args: argparse.Namespace) -> int:
    """``slewbench schema [KEY]``: print the scenario and study schema reference, or its part under KEY.

    Parameters
    ----------
    args : argparse.Namespace
        ``key``: a key such as ``maneuver``, ``planners.collocation`` or ``study.execution``
        (see :mod:`scenarios.schema.reference`), or ``None`` for everything.

    Returns
    -------
    int
        Exit status: 0, or 2 for a key the schema does not have (its close matches are listed).
    """
    from scenarios.schema.reference import schema_text

    try:
        text = schema_text(args.key)
    except ScenarioError as error:
        print(f"slewbench: {error}", file=sys.stderr)
        return EXIT_BAD_SCENARIO
    sys.stdout.write(text)
    sys.stdout.flush()
    return EXIT_OK


STRICT_LINES_SHOWN = 10
"""Lines of a study's per-case findings ``validate`` prints (the others are counted)."""
FINDINGS_PROGRESS_EVERY = 256
"""Cases between two calls of the ``progress`` callback of :func:`study_findings`."""


def study_findings(study: Any, found: StudyFindings | None = None,
                   progress: Callable[[int, int], None] | None = None) -> list[str]:
    """What ``validate`` finds in a study's cases (``sweep --dry-run`` says the same): each case's
    :func:`_strict_findings` (rows that cannot be ok, a slew longer than ``maneuver.duration`` by a
    planner's ``least_duration`` among them, and plausibility warnings), naming the case and its
    varied values.

    Parameters
    ----------
    study : scenarios.study.Study
        The expanded, checked study.
    found : StudyFindings or None, optional
        The findings gathered while the study was checked (given to
        :func:`~scenarios.study.spec.load_study` as ``parsed``): its cases are not parsed again.
        None: every case is parsed here.
    progress : callable or None, optional
        ``progress(judged, total)``, called every :data:`FINDINGS_PROGRESS_EVERY` cases and at the end.

    Returns
    -------
    list of str
        ``case N [path=value, ...]: <finding>``, in case order; empty when there is none.
    """
    return (found or StudyFindings()).lines(study, progress)


class StudyFindings:
    """:func:`_strict_findings` of a study's cases, each case parsed by the loader once.

    Given to :func:`~scenarios.study.spec.load_study` as ``parsed``, it is called with each case
    the loader parsed while the study was checked, and keeps its findings; :meth:`lines` parses the
    others (cases checked by the verdict of an earlier case of their class). The lines that read
    only the problem, the planners and the requirements (:func:`_planning_lines`: a planner's
    ``least_duration`` plans the slew) are computed once for all cases whose scenarios differ only
    in :data:`~scenarios.schema.study.INDEPENDENT_KEYS`, which the loader reads into
    ``scenario.simulation`` alone (the same rule that lets the study check them by their own
    readers); the rest (:func:`_rate_lines`, the plausibility warnings) per case.
    """

    def __init__(self) -> None:
        self._found: dict[int, list[str]] = {}  # case index -> its findings (a case without any is absent)
        self._done: set[int] = set()
        self._planning: dict[str, list[str]] = {}  # a scenario without its independent keys -> _planning_lines

    def __call__(self, case: Any, scenario: Scenario) -> None:
        """Keep the findings of ``case``, parsed by the loader into ``scenario``.

        Parameters
        ----------
        case : scenarios.study.Case
            The case.
        scenario : Scenario
            ``parse_scenario(case.scenario, inapplicable_rows=True)``.
        """
        self._keep(case, scenario)

    def _keep(self, case: Any, scenario: Scenario) -> list[str]:
        shared = _shared_text(case.scenario)
        planning = self._planning.get(shared) if shared is not None else None
        if planning is None:
            planning = [line for line, every in _planning_lines(scenario) if every]
            if shared is not None:
                self._planning[shared] = planning
        found = (planning + [line for line, every in _rate_lines(scenario) if every]
                 + [f"warning: {warning}" for warning in plausibility_warnings(scenario)])
        self._done.add(case.index)
        if found:
            self._found[case.index] = found
        return found

    def lines(self, study: Any, progress: Callable[[int, int], None] | None = None) -> list[str]:
        """Every case's findings, naming the case and its varied values (:func:`study_findings`).

        Parameters
        ----------
        study : scenarios.study.Study
            The expanded, checked study.
        progress : callable or None, optional
            As :func:`study_findings`.

        Returns
        -------
        list of str
            ``case N [path=value, ...]: <finding>``, in case order.
        """
        findings = []
        total = len(study.cases)
        for number, case in enumerate(study.cases, 1):
            found = (self._found.get(case.index, []) if case.index in self._done
                     else self._keep(case, parse_scenario(case.scenario, inapplicable_rows=True)))
            if found:
                values = ", ".join(f"{path}={value}" for path, value in case.varied.items())
                where = f"case {case.index}" + (f" [{values}]" if values else "")
                findings += [f"{where}: {line}" for line in found]
            if progress is not None and (number % FINDINGS_PROGRESS_EVERY == 0 or number == total):
                progress(number, total)
        return findings


@functools.cache
def _independent_tree() -> dict[str, Any]:
    """:data:`~scenarios.schema.study.INDEPENDENT_KEYS` as nested mappings (a leaf: None)."""
    from scenarios.schema.study import INDEPENDENT_KEYS

    tree: dict[str, Any] = {}
    for path in INDEPENDENT_KEYS:
        *parents, last = path.split(".")
        node = tree
        for part in parents:
            node = node.setdefault(part, {})
        node[last] = None
    return tree


def _shared_text(scenario: dict[str, Any]) -> str | None:
    """A scenario mapping without its :data:`~scenarios.schema.study.INDEPENDENT_KEYS`, as JSON text
    (equal texts: equal scenarios but for those keys); None for data JSON does not hold exactly
    (then nothing is shared)."""
    def strip(data: Any, tree: dict[str, Any]) -> Any:
        if isinstance(data, list):
            return [strip(item, {}) for item in data]
        if not isinstance(data, dict):
            return data
        if not all(isinstance(key, str) for key in data):  # JSON would write 1 and "1" alike
            raise TypeError("a key that is not text")
        return {key: strip(value, tree[key]) if isinstance(tree.get(key), dict) else value
                for key, value in data.items() if not (key in tree and tree[key] is None)}

    def refuse(value: Any) -> Any:
        raise TypeError(type(value).__name__)

    try:
        return json.dumps(strip(scenario, _independent_tree()), default=refuse, allow_nan=True)
    except (TypeError, ValueError):
        return None


def print_findings(findings: list[str]) -> None:
    """Print findings as ``validate`` does: two spaces in, the first :data:`STRICT_LINES_SHOWN`, the
    others counted (``  ... and 3 more``).

    Parameters
    ----------
    findings : list of str
        The lines (:func:`study_findings`, a table's).
    """
    for line in findings[:STRICT_LINES_SHOWN]:
        print("  " + line)
    if len(findings) > STRICT_LINES_SHOWN:
        print(f"  ... and {len(findings) - STRICT_LINES_SHOWN} more")


def _validate_study(file: str) -> tuple[str, list[str]]:
    """A study file, every case expanded and checked as ``sweep`` checks it before running (its
    parser imported here: ``run`` needs none); the findings are each case's :func:`_strict_findings`,
    naming the case and its varied values."""
    from scenarios.study.spec import load_study, noise_note

    found = StudyFindings()  # each case's findings, from the loader's parse where the check parsed it
    study = load_study(file, parsed=found)
    points = len({case.point for case in study.cases})
    varied = ", ".join(study.varied_paths) or "nothing"
    findings = study_findings(study, found)
    note = noise_note(study)
    return (f"{file}: valid study {study.name!r}: {len(study.cases)} cases ({points} grid point(s) x "
            f"{study.samples} sample(s)), varying {varied}; run it with `slewbench {OTHER_FILES['study']} {file}`"
            + (f"\n{note}" if note else ""), findings)


def _validate_table(file: str) -> tuple[str, list[str]]:
    """A slew-table file, checked as ``slewbench table`` checks it before computing: its spec, and its
    number of entries against the default ``--max-entries`` (a finding: the limit is an option)."""
    from scenarios.cli.table import check_table_work
    from scenarios.slewtable.spec import parse_table_spec

    spec = parse_table_spec(file)
    axes = "1 axis" if len(spec.axes) == 1 else f"{len(spec.axes)} axes"
    mids = len(spec.held_out_angles_deg)
    held_out = (f" + a held-out grid of {spec.held_out} ax{'i' if spec.held_out == 1 else 'e'}s x {mids} "
                f"angle{'' if mids == 1 else 's'}" if spec.held_out else ", no held-out grid")
    refine = (f"; refined to a tolerance of {spec.refine.tolerance:g} (at most {spec.refine.max_axes} axes, "
              f"{spec.refine.max_rounds} rounds)" if spec.refine is not None else "; no refinement")
    findings = []
    entries = len(spec.axes) * len(spec.angles_deg) + spec.held_out * mids
    command = f"slewbench {OTHER_FILES['table']} {file}"
    try:  # the table command's own check, with its default limit
        check_table_work(spec, entries)
    except ScenarioError as error:
        findings.append(f"`slewbench {OTHER_FILES['table']}` refuses it without an option: {error}")
    # what the table command does with the file as it is: runs it, or refuses it (then neither valid nor run-it)
    verdict, how = (("slew table", f"`{command}` refuses it as it is (below): change the file, or confirm the "
                                   f"work with `{command} --max-entries {entries}`") if findings
                    else ("valid slew table", f"run it with `{command}`"))
    return (f"{file}: {verdict} {spec.name!r}: {axes} x {len(spec.angles_deg)} angles{held_out}, "
            f"{spec.objective}{refine}; {how}", findings)


_OTHER_VALIDATORS = {"study": _validate_study, "table": _validate_table}
"""How ``validate`` checks each kind of ``scenarios.schema.loader.OTHER_FILES`` (keyed the same):
a summary line and the findings that fail ``validate --strict``."""
_COMMAND_FILES = {"sweep": "study file", "table": "table file"}
"""What a command's file is called in its errors (``error in <kind>:``) where it is not a scenario;
``validate`` sets ``file_kind`` on its arguments once it knows. Such an error names the file
(``error in study file: FILE: execution.scheduler: ...``), where its own text does not."""


def _named_once(error: ScenarioError, file: str) -> ScenarioError:
    """``validate``'s error for a file it cannot read (:func:`~scenarios.schema.read.read_yaml`'s
    ``scenario file not found: FILE``, ``cannot read FILE: REASON``) as ``FILE: file not found``,
    ``FILE: cannot read: REASON``: the file named once, where ``error in`` names the file of a kind
    not known yet (a scenario, a study or a table); any other error as it is."""
    named = Path(file)
    if error.message == f"scenario file not found: {named}":
        return ScenarioError("", "file not found", named)
    unreadable = f"cannot read {named}: "
    if error.message.startswith(unreadable):
        return ScenarioError("", f"cannot read: {error.message[len(unreadable):]}", named)
    return error


def command_validate(args: argparse.Namespace) -> int:
    """``slewbench validate FILE``: load and check a scenario, a study or a slew-table file, print what would run.

    A file whose top level has the key ``study`` is a study (:func:`scenarios.study.spec.load_study`:
    every case is expanded and checked, as ``sweep`` checks it), one with ``table`` a slew table
    (:func:`scenarios.slewtable.spec.parse_table_spec` and the entry limit, as ``table`` checks it);
    any other is a scenario.

    Parameters
    ----------
    args : argparse.Namespace
        ``file``: the scenario, study or slew-table YAML path; ``strict`` (optional): exit 1 when
        there is a finding: a scenario (a study's case) that cannot have an ok row or has a
        plausibility warning (:mod:`scenarios.schema.plausibility`), or a table that ``table``
        refuses without ``--max-entries``.

    Returns
    -------
    int
        Exit status: 0; 1 with ``strict`` when there is a finding (:func:`_strict_findings`; a
        study's per case, a table's entry limit), printed in any case; a bad file raises
        ``ScenarioError``, which :func:`main` reports with exit 2.
    """
    args.file_kind = args.file  # until its kind is known, an error (a duplicate key, no mapping) names the file
    try:
        data = read_yaml(args.file)
    except ScenarioError as error:  # not found or not readable: main() names the file, once, as where
        raise _named_once(error, args.file) from None
    if isinstance(data, dict):
        args.file_kind = None  # a scenario's, unless a key below says otherwise
    for key in OTHER_FILES:  # a study or a slew table: its own check and summary
        if isinstance(data, dict) and key in data:
            args.file_kind = f"{key} file"  # how main() names its errors
            summary, findings = _OTHER_VALIDATORS[key](args.file)
            print(summary)
            print_findings(findings)
            return _strict_status(args, findings, f"{len(findings)} finding(s) above")
    try:
        refuse_unmarked_base(data, args.file)
        scenario = parse_scenario(data, Path(args.file))
    except ScenarioError as error:
        raise in_file(error, args.file) from None
    labels = row_labels([planner.label for planner in scenario.planners], [c.label for c in scenario.controllers])
    controllers = ", ".join(repr(c.name) for c in scenario.controllers)
    print(f"{args.file}: valid scenario {scenario.name!r} with {len(scenario.planners)} planner(s) and "
          f"controller{'s' if len(scenario.controllers) > 1 else ''} {controllers}: {len(labels)} row(s) "
          f"({', '.join(label.label for label in labels)})")
    for line in _scenario_details(scenario):
        print("  " + line)
    doomed, warned = _doomed_notes(scenario), plausibility_warnings(scenario)
    for warning in warned:
        print(f"  warning: {warning}")
    said = ([f"no row can be ok ({len(doomed)} note(s) above say every row is infeasible, fails or breaks a "
             "requirement)"] if doomed else []) + \
        ([f"{len(warned)} plausibility warning(s) above"] if warned else [])
    return _strict_status(args, [*doomed, *map(str, warned)], "; ".join(said))


def _strict_status(args: argparse.Namespace, findings: list[str], said: str) -> int:
    """``validate``'s exit status: 1 under ``--strict`` when there are findings (``said`` on stderr), else 0."""
    if getattr(args, "strict", False) and findings:
        print(f"slewbench: --strict: {said}", file=sys.stderr)
        return EXIT_NOT_OK
    return EXIT_OK


def _strict_findings(scenario: Scenario) -> list[str]:
    """What fails ``validate --strict`` on a scenario: :func:`_doomed_notes` and the plausibility
    warnings (:func:`scenarios.schema.plausibility.plausibility_warnings`, each ``warning: ...``)."""
    return _doomed_notes(scenario) + [f"warning: {warning}" for warning in plausibility_warnings(scenario)]


def _leaf_paths(value: Any, prefix: str) -> list[str]:
    """The dotted paths of a mapping's leaves (``truth.wheels.friction.coulomb``)."""
    if not isinstance(value, dict) or not value:
        return [prefix]
    return [path for key, item in value.items() for path in _leaf_paths(item, f"{prefix}.{key}")]


def _doomed_notes(scenario: Scenario) -> list[str]:
    """``validate``'s notes that no row can be ok (``validate --strict`` exits 1 on any): the
    lines of :func:`_before_planning` that doom every row (``infeasible``, ``failed`` or ``violated``).

    Parameters
    ----------
    scenario : Scenario
        The loaded scenario.

    Returns
    -------
    list of str
        One line per such finding (empty when a row may succeed).
    """
    return [line for line, every in _before_planning(scenario) if every]


def _before_planning(scenario: Scenario) -> list[tuple[str, bool]]:
    """What ``validate`` proves of the rows before anything runs, as the runner proves it, each line
    with whether it dooms every row.

    Per planner (a minimum-time planner's slew may end before T, its bound): an end point that
    already breaks a pointing requirement, or an angle the rate requirement cannot turn within
    ``maneuver.duration`` (:func:`~scenarios.requirements.scoring.endpoint_violations`; the row
    ``infeasible``, nothing planned), said once for the planners it dooms; a study's case a planner
    cannot take (its row ``failed``, unplanned, whatever else; said when no planner can). When every planner's row
    is doomed, but for reasons that differ by planner, one more line says so, naming each
    planner's (the requirements, or that it cannot take the case): no row can be ok. A line that
    dooms only some rows is said, but is no finding of ``validate --strict`` (another row may be ok).
    Then a boundary rate above the rate requirement (every row breaks it).

    Parameters
    ----------
    scenario : Scenario
        The loaded scenario.

    Returns
    -------
    list of (str, bool)
        Each line and whether it dooms every row.
    """
    return _planning_lines(scenario) + _rate_lines(scenario)


def _rate_lines(scenario: Scenario) -> list[tuple[str, bool]]:
    """The lines of :func:`_before_planning` that read ``scenario.simulation`` (a boundary rate, or
    the closed loop's true initial rate, above the rate requirement: each dooms every row)."""
    from scenarios.schema.checks import rate_bound_notes

    rate = scenario.requirements.rate
    if rate is None:
        return []
    return [(line, True) for line in rate_bound_notes(scenario.problem, scenario.simulation, rate.max_rate)]


def _planning_lines(scenario: Scenario) -> list[tuple[str, bool]]:
    """The lines of :func:`_before_planning` that read only the problem, the planners and the
    requirements (not ``scenario.simulation``, not ``scenario.data``): the same for every case of
    a study that differs only in :data:`~scenarios.schema.study.INDEPENDENT_KEYS`
    (:class:`StudyFindings` computes them once for such cases)."""
    from planners.capabilities import minimises_time
    from scenarios.requirements.scoring import endpoint_violations, late_slew

    requirements = scenario.requirements
    count = len(scenario.planners)
    lines: list[tuple[str, bool]] = []
    if scenario.planners and len(scenario.inapplicable) == count:  # a study's case none can take
        lines.append(("every planner's row fails, none can take it: "
                      + "; ".join(scenario.inapplicable[i] for i in sorted(scenario.inapplicable)), True))
    broken: dict[int, list[str]] = {}
    for i, spec in enumerate(scenario.planners):
        if i in scenario.inapplicable:  # a planner that cannot take a study's case fails unplanned, as the runner makes its row
            continue
        # per planner, as the runner proves it: a minimum-time planner's slew may end before T (its bound)
        found = (endpoint_violations(scenario.problem, minimises_time(type(spec.planner), spec.planner.options))
                 if requirements else [])
        least = spec.planner.least_duration(scenario.problem)  # a planner that can say its duration cheaply
        late = late_slew(scenario.problem, least) if least is not None else ""
        broken[i] = found + ([late] if late else [])
    if scenario.planners:
        for sentence in dict.fromkeys(sentence for found in broken.values() for sentence in found):
            rows = [scenario.planners[i].label for i, found in broken.items() if sentence in found]
            who = ("every planner's row is" if len(rows) == count
                   else f"the rows of {', '.join(rows)} are" if len(rows) > 1 else f"the row of {rows[0]} is")
            lines.append((f"{who} infeasible before planning: {sentence}", len(rows) == count))
    doomed = set(scenario.inapplicable) | {i for i, found in broken.items() if found}
    if scenario.planners and len(doomed) == count and not any(every for _, every in lines):
        # each row doomed, for reasons that differ by planner: none of the lines above says every row
        words = "fails or is infeasible" if scenario.inapplicable else "is infeasible"
        reasons = [f"{spec.label}: " + ("cannot take this case" if i in scenario.inapplicable
                                        else ", ".join(dict.fromkeys(line.split(":")[0] for line in broken[i])))
                   for i, spec in enumerate(scenario.planners)]
        lines.append((f"every planner's row {words} before planning ({'; '.join(reasons)}): no row can be ok", True))
    return lines


def _scenario_details(scenario: Scenario) -> list[str]:
    """What ``validate`` says beyond the rows: every requirement the rows are scored against, end
    points that already break one, the truth model's keys (where the plant differs from the
    design), the sensors and estimator in the loop and the sensor noise."""
    requirements = scenario.requirements
    lines = [f"requirement {line}" for line in requirements.describe()]
    if requirements.actuators is None:
        lines.append("requirements: none (requirements: null)" if not requirements else
                     "requirement actuators: off (requirements.actuators: null)")
    elif not requirements.actuators.stated and scenario.planners:
        lines.append("requirement actuators: the reference's demand at most 100 % of each actuator limit "
                     "(every scenario's, unstated)")
    lines += [line for line, _ in _before_planning(scenario)]
    window, budget = scenario.simulation.duration, scenario.problem.duration
    from planners.capabilities import minimises_time
    # the rows whose slew takes its time budget (a minimum-time one ends sooner): run says so per row, validate did not
    cut = [spec.label for spec in scenario.planners if not minimises_time(type(spec.planner), spec.planner.options)]
    if window is not None and window < budget and cut:
        lines.append(f"note: simulation.duration ({window:g} s) ends before maneuver.duration ({budget:g} s), the "
                     f"slew of {', '.join(cut)}: the closed loop stops while it is under way, and its closed-loop "
                     f"metrics (final error, settling) are those at {window:g} s")
    truth = (scenario.data or {}).get("truth")
    if scenario.truth is not None and isinstance(truth, dict):
        lines.append("truth (the closed loop's plant differs from the design in): "
                     + ", ".join(_leaf_paths(truth, "truth")))
    sensors = scenario.simulation.sensors
    if sensors is not None:
        parts = [name for name, present in (("gyro", sensors.gyro), ("star tracker", sensors.star_tracker),
                                            ("magnetometer", sensors.magnetometer)) if present is not None]
        tracker = sensors.star_tracker
        if tracker is not None and (tracker.outages or tracker.exclusions):
            parts[parts.index("star tracker")] += " (" + "; ".join(
                ([("outages " + ", ".join(f"{a:g}-{b:g} s" for a, b in tracker.outages))] if tracker.outages else [])
                + ([("blinded within " + ", ".join(f"{np.rad2deg(item.half_angle):g} deg of the {item.name}"
                                                   for item in tracker.exclusions))] if tracker.exclusions else [])) + ")"
        estimator = "MEKF" if sensors.estimator is not None else "none"
        lines.append(f"sensors: {', '.join(parts) or 'none'}; estimator: {estimator}")
    noise = scenario.simulation.noise
    stds = [f"{name} {value:.6g} {unit}" for name, value, unit in (
        ("attitude", float(np.rad2deg(noise.attitude_std)), "deg"), ("rate", noise.rate_std, "rad/s"),
        ("magnetic field", noise.field_std, "T")) if value]
    if stds:
        lines.append(f"sensor noise (simulation.sensor_noise, 1 sigma per axis): {', '.join(stds)}, seed {noise.seed}")
    return lines


def command_run(args: argparse.Namespace) -> int:
    """``slewbench run FILE``: plan, simulate and score, print the table, write the outputs.

    Parameters
    ----------
    args : argparse.Namespace
        ``file`` (scenario YAML), ``out`` (output directory or ``None``: ``results/<name>``),
        ``no_plots`` (skip the PNG figures), ``strict`` (optional: exit 1 when a row is not ok), and,
        set by :func:`main` (optional): ``interruption`` (an :class:`Interruption`) and ``renderer``
        (a :class:`scenarios.output.renderer.Renderer` to draw the plots, or ``None``).

    Returns
    -------
    int
        Exit status: 0, the run completed (failed and violated rows are results, not errors); 1
        with ``strict`` when some row is not ``ok`` (the results are written first). Plausibility
        warnings (:func:`scenarios.schema.plausibility.plausibility_warnings`) go to standard error
        before planning; they change no status.
    """
    scenario = load(args.file)
    for warning in plausibility_warnings(scenario):  # not errors: the run goes on
        print(f"slewbench: warning: {warning}", file=sys.stderr)
    out = Path(args.out) if args.out else default_output_directory(scenario.name)
    exports = getattr(args, "export", None) or []
    for name in exports:  # before planning: an export the run cannot give is refused first
        _check_run_export(name, scenario.epoch, bool(scenario.planners))
    # before planning: a long run is never lost at the end (a user's file among the run's, or another
    # scenario's run, is refused now); every directory is checked before any is claimed
    check_run_directory(out, scenario.name, run_files(scenario, plots=not args.no_plots))
    for name in exports:
        try:
            check_output_directory(default_export_directory(out, name), kind="export")
        except OutputError as error:
            raise OutputError(error.path, f"{error.message} (`--export {name}` writes beside the run, into "
                                          f"<out>-{name}: move that directory or choose another --out)") from None
    with contextlib.ExitStack() as claims:  # an interrupted or failed run withdraws the claims it committed nothing to
        claims.enter_context(claimed_output_directory(out))
        for name in exports:
            claims.enter_context(claimed_output_directory(default_export_directory(out, name), kind="export"))
        return _run_claimed(args, scenario, out, exports)


def _run_claimed(args: argparse.Namespace, scenario: Any, out: Path, exports: list[str]) -> int:
    """:func:`command_run` once its output directories are claimed: plan, simulate, write, export."""
    start = time.perf_counter()
    interruption = getattr(args, "interruption", None) or Interruption()

    def progress(line: str) -> None:
        interruption.check()  # a signal swallowed on the way (see Interruption) stops the run here
        print(line, flush=True)

    renderer = getattr(args, "renderer", None)
    results = run(scenario, progress=progress,
                  on_row=plot_streamer(scenario, renderer) if renderer is not None and not args.no_plots else None)
    interruption.check()
    print()
    print(results.to_terminal(all_metrics=getattr(args, "all_metrics", False)))
    if scenario.requirements.final is None:  # status reflects requirements: say what it does not check
        note = final_accuracy_note([((row.closed_loop_metrics or {}).get("final_error_deg"),
                                     scenario.simulation.settling_tolerance_deg) for row in results.rows],
                                   len(results.rows))
        if note:
            print(note)
    earlier = written_files(out)
    results.write(out, plots=not args.no_plots, renderer=renderer)
    print(f"\nwrote {out}/ (results.json, results.csv, results.md, timeseries/"
          f"{'' if args.no_plots else ', PNG plots, report.html'}) in {time.perf_counter() - start:.2f} s")
    renamed = suffix_note([row.label for row in results.rows], "results.json and results.csv")
    if renamed:
        print(renamed)
    removed = sorted(earlier - written_files(out))
    if removed:
        print(f"removed {len(removed)} file(s) of the earlier run in {out}/ that this run did not write: "
              + ", ".join(removed))
    for name in exports:
        _print_export(export_run(out, name))
    not_ok = [row.label for row in results.rows if row.status != "ok"]
    if getattr(args, "strict", False) and not_ok:
        print(f"slewbench: --strict: {len(not_ok)} of {len(results.rows)} rows not ok ({', '.join(not_ok)})",
              file=sys.stderr)
        return EXIT_NOT_OK
    return EXIT_OK


def _check_run_export(name: str, epoch: Any, planned: bool = True) -> None:
    """Refuse ``run --export NAME`` for an unknown format, an AEM of a scenario without an epoch, or
    waypoint files of a scenario without planners (``planned`` False: regulation rows only)."""
    if name not in EXPORT_FORMATS:
        raise ScenarioError("--export", f"{name!r} is not an export format; known: {', '.join(EXPORT_FORMATS)}")
    if name == "basilisk" and not planned:
        raise ScenarioError("--export", "`--export basilisk` writes each planner row's reference, and the scenario has "
                                        "no planner (planners: []: regulation rows, without a reference); nothing "
                                        "would be exported")
    if name == "aem" and epoch is None:
        raise ScenarioError("epoch", "the scenario has no epoch, so its times are not absolute and its inertial "
                                     "frame is not the GCRF; `--export aem` needs both: give the scenario an `epoch` "
                                     "(UTC, e.g. 2027-03-20T12:00:00Z)")


def _print_export(report: Any) -> None:
    """The lines ``export`` (and ``run --export``) print: what was written and what was left out."""
    print(f"wrote {report.directory}/: " + (", ".join(report.files) or "nothing"))
    for note in report.notes:
        print(f"  {note}")


def command_export(args: argparse.Namespace) -> int:
    """``slewbench export RUN_DIR --format NAME [--out DIR] [--option NAME=VALUE ...]``: write a
    finished run's rows in another tool's format (:data:`scenarios.output.export.EXPORT_FORMATS`).

    Parameters
    ----------
    args : argparse.Namespace
        ``run_directory`` (the output directory of ``slewbench run``), ``format``, ``out``
        (``None``: ``<RUN_DIR>-<format>``) and ``option`` (``NAME=VALUE`` texts, or ``None``).

    Returns
    -------
    int
        Exit status: 0, or 2 for a directory that is not a finished run, a run the format cannot
        take (an AEM of a run without an epoch), an unknown option, or an output location
        slewbench must not write to.
    """
    try:
        export = EXPORT_FORMATS[args.format]
        options = export.parse_options(args.option or [])
        report = export_run(args.run_directory, args.format, args.out, options)
    except ScenarioError as error:
        print(f"slewbench: export: {error}", file=sys.stderr)
        return EXIT_BAD_SCENARIO
    _print_export(report)
    return EXIT_OK


def command_codegen(args: argparse.Namespace) -> int:
    """``slewbench codegen FILE --out DIR``: export the controller law, its saturation stage and every
    planner row's reference (as a table) as C behind ``slewbench_step``, with a Makefile and an example.

    Parameters
    ----------
    args : argparse.Namespace
        ``file`` (scenario YAML) and ``out`` (output directory).

    Returns
    -------
    int
        Exit status (0).
    """
    from scenarios.codegen import (
        generate,  # CasADi's code generator: only for this command
    )

    scenario = load(args.file)
    report = generate(scenario, args.out)
    for line in report.summary():
        print(line)
    print(f"build: make -C {report.directory}")
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    """The ``slewbench`` argument parser (run, validate, codegen, export, list, schema, sweep, report).

    Returns
    -------
    argparse.ArgumentParser
        Each sub-command sets ``handler``, the function that runs it.
    """
    parser = argparse.ArgumentParser(
        prog="slewbench", description="Spacecraft attitude manoeuvre planning workbench",
        epilog=f"exit status: {EXIT_OK} done (failed, infeasible and violated rows are results); {EXIT_BAD_SCENARIO} bad "
               f"scenario, study or table file, or output location (nothing written); {EXIT_INTERNAL} internal "
               f"error (a traceback on stderr) or run interrupted (Ctrl-C, SIGTERM); {EXIT_INTERRUPTED} "
               f"interrupted sweep or table (run it again to finish). Under run --strict or table --strict, "
               f"{EXIT_NOT_OK} also for a completed run with a row (or table entry) not ok: its files are "
               f"written and stderr says so ('slewbench: --strict: N of M ... not ok'); under validate --strict, "
               f"{EXIT_NOT_OK} for a scenario (a study's case) whose notes say no row can be ok or that has a "
               f"plausibility warning, or a table "
               f"too large for `table` without --max-entries. Plugins: the "
               f"'slewbench.plugins' entry points of installed distributions and the modules or .py files of "
               f"SLEWBENCH_PLUGINS (comma-separated) load at start; one that fails or takes a registered name: "
               f"exit {EXIT_BAD_SCENARIO}")
    parser.add_argument("--version", action="version", version=f"slewbench {package_version()}")
    commands = parser.add_subparsers(dest="command", required=True)
    run_parser = commands.add_parser("run", help="plan, simulate and score every planner of a scenario")
    run_parser.add_argument("file", help="scenario YAML file")
    run_parser.add_argument("--out", type=directory_argument, help="output directory (default: results/<scenario name>)")
    run_parser.add_argument("--no-plots", action="store_true", help="skip the PNG plots and report.html")
    run_parser.add_argument("--all-metrics", action="store_true",
                            help="show every metric in the table, also those with no value in any row")
    run_parser.add_argument("--strict", action="store_true",
                            help=f"exit {EXIT_NOT_OK} when any row is not ok (violated: it breaks a requirement; "
                                 "infeasible: no motion meets the requirements or maneuver.duration, the time budget; "
                                 "failed: a numerical failure), after writing the "
                                 "results (for continuous integration)")
    run_parser.add_argument("--export", action="append", choices=sorted(EXPORT_FORMATS), metavar="FORMAT",
                            help="also export the rows into <out>-FORMAT/ (formats: "
                                 f"{', '.join(sorted(EXPORT_FORMATS))}; as `slewbench export` with default options)")
    run_parser.set_defaults(handler=command_run)
    validate_parser = commands.add_parser("validate", help="check a scenario, study or slew-table file; print what would run")
    validate_parser.add_argument("file", help="scenario, study or slew-table YAML file (a study has the top-level key 'study', a table 'table')")
    validate_parser.add_argument("--strict", action="store_true",
                                 help=f"exit {EXIT_NOT_OK} when a scenario (a study's case) cannot have an ok row (a note "
                                      "says every row is infeasible, e.g. its slew longer than maneuver.duration, "
                                      "fails, or breaks a requirement) or has a plausibility warning (a likely unit "
                                      "slip), or a table has more entries than `table` computes "
                                      "without --max-entries, after printing the check (for continuous integration)")
    validate_parser.set_defaults(handler=command_validate)
    codegen_parser = commands.add_parser("codegen", help="export the controller law, saturation and reference tables as flight C")
    codegen_parser.add_argument("file", help="scenario YAML file")
    codegen_parser.add_argument("--out", required=True, type=directory_argument, help="output directory (new, empty, or written by slewbench)")
    codegen_parser.set_defaults(handler=command_codegen)
    export_parser = commands.add_parser("export", help="write a finished run's rows in another tool's format "
                                                       "(aem: CCSDS attitude ephemeris messages)")
    export_parser.add_argument("run_directory", metavar="RUN_DIR", help="output directory of `slewbench run`")
    export_parser.add_argument("--format", required=True, choices=sorted(EXPORT_FORMATS),
                               help="; ".join(f"{name}: {fmt.description}" for name, fmt in EXPORT_FORMATS.items()))
    export_parser.add_argument("--out", type=directory_argument, help="export directory (default: RUN_DIR-FORMAT beside RUN_DIR)")
    export_parser.add_argument("--option", action="append", metavar="NAME=VALUE",
                               help="a format option, repeatable (aem: time_system=UTC|TAI|TT|TDB|GPS, "
                                    "attitude_type=QUATERNION/ANGVEL|QUATERNION, originator, object_name, object_id)")
    export_parser.set_defaults(handler=command_export)
    list_parser = commands.add_parser("list", help="registered planners and controllers, and the plugins that "
                                                   "provided any (slewbench.plugins entry points, SLEWBENCH_PLUGINS)")
    list_parser.add_argument("--options", metavar="NAME",
                             help="the options of planner or controller NAME: type, unit, default and range")
    list_parser.set_defaults(handler=command_list)
    schema_parser = commands.add_parser("schema", help="every scenario and study key: type, unit, default, range, "
                                                       "meaning")
    schema_parser.add_argument("key", nargs="?", help="only the keys under KEY: a YAML path without list indices "
                                                      "(maneuver, simulation.sensor_noise.seed), "
                                                      "planners.<planner>[.<option>], controller.<controller>, "
                                                      "environment.magnetic_field.<model>, scenario, or study[.<key>]")
    schema_parser.set_defaults(handler=command_schema)
    add_sweep_parser(commands)
    add_bench_parser(commands)
    add_table_parser(commands)
    return parser


class Interruption:
    """SIGTERM and Ctrl-C (SIGINT) handler: ends a run like Ctrl-C, so that staged files are removed
    on the way out, and remembers that it fired.

    The ``KeyboardInterrupt`` can be lost: raised inside a finaliser (``__del__`` of a CasADi
    object run by the garbage collector, where Python only prints "Exception ignored"), or turned
    into an error that the runner records as a failed row. :meth:`check`, called between the run's
    phases and before writing, then still stops the run.
    """

    def __init__(self) -> None:
        self.signalled = False

    def __call__(self, signum: int, frame: Any) -> None:
        """Record the signal and raise ``KeyboardInterrupt``.

        Parameters
        ----------
        signum : int
            The signal number.
        frame : frame or None
            The interrupted frame (unused).
        """
        self.signalled = True
        raise KeyboardInterrupt

    def check(self) -> None:
        """Raise ``KeyboardInterrupt`` if a signal has fired (even one swallowed on the way)."""
        if self.signalled:
            raise KeyboardInterrupt


def _interrupted(args: argparse.Namespace) -> int:
    """Say that the command was interrupted, in one line; its exit status
    (:func:`~scenarios.cli.status.interrupted_status`)."""
    command = getattr(args, "command", None)
    print("slewbench: interrupted; nothing written" if command in _WRITES_NOTHING else  # as the console says it
          "slewbench: interrupted; results not written or marked incomplete in the output manifest", file=sys.stderr)
    return interrupted_status(command)


_WRITES_NOTHING = frozenset({"validate", "list", "schema"})
"""Commands that only print: an interruption has no results to speak of (it said 'results not
written or marked incomplete in the output manifest')."""


def _names(given: str, path: Path) -> bool:
    """Whether ``path`` is the directory given on the command line, or inside it."""
    try:
        directory, path = Path(given).expanduser().absolute(), path.expanduser().absolute()
    except (RuntimeError, OSError, ValueError):  # a ~user that does not exist: named as given
        return True
    return path == directory or directory in path.parents


def _tolerant_streams() -> None:
    """Standard output and error that escape what their encoding cannot show (``\\u2717``)
    instead of raising: the tables and messages use ✓, ✗, ω, ‖ and °, which a console or a file
    in a legacy encoding (cp1252) lacks, and a ``UnicodeEncodeError`` there stopped a run before
    its files were written. Streams already UTF-8, or without ``reconfigure`` (a test's
    ``StringIO``), are left as they are."""
    for stream in (sys.stdout, sys.stderr):
        encoding = (getattr(stream, "encoding", None) or "").lower().replace("_", "-")
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is None or encoding in ("utf-8", "utf8") or getattr(stream, "errors", None) != "strict":
            continue
        try:
            reconfigure(errors="backslashreplace")
        except (ValueError, OSError):  # a stream that cannot change now: left as it is
            continue


_STORAGE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS})
"""``OSError`` numbers of a file system that refuses a write (full, over quota, file too large,
read-only): an output error, not a bug."""


def _internal_error() -> int:
    """Report the exception being handled as a bug, with its traceback; the exit status."""
    traceback.print_exc()
    print("slewbench: internal error (this is a bug; please report it with the scenario file)", file=sys.stderr)
    return EXIT_INTERNAL


def main(argv: list[str] | None = None, renderer: Any = None) -> int:
    """Run the ``slewbench`` command line.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (without the program name); ``None``: ``sys.argv[1:]``.
    renderer : scenarios.output.renderer.Renderer, optional
        A plot process started before the model was imported (:mod:`scenarios.console`), used by
        ``run``; ``None``: plots are drawn in this process.

    Returns
    -------
    int
        Exit status: 0 done, 2 bad scenario file or output location (the message names its path) or
        a plugin that fails to load or takes a registered name (the message names the plugin),
        1 internal error or interrupted, or a row not ok under ``run --strict`` (an entry under
        ``table --strict``; a scenario that cannot have an ok row under ``validate --strict``), 130 an interrupted sweep or a table interrupted while it computes
        (an error raised after Ctrl-C or SIGTERM counts as the interruption: C code such as
        CasADi's turns a ``KeyboardInterrupt`` into one).
    """
    parser = build_parser()
    args = parser.parse_args(attached_values(sys.argv[1:] if argv is None else list(argv), parser))
    _tolerant_streams()
    args.interruption = Interruption()
    args.renderer = renderer
    # Ctrl-C too: CasADi turns a KeyboardInterrupt raised inside IPOPT into a failed solve, and the
    # run would go on; Interruption remembers it, and the run's next check() stops it
    previous = ({signum: signal.signal(signum, args.interruption) for signum in (signal.SIGTERM, signal.SIGINT)}
                if threading.current_thread() is threading.main_thread() else None)
    try:
        try:
            load_plugins()  # the slewbench.plugins entry points and SLEWBENCH_PLUGINS, before any name is read
            return args.handler(args)
        except Exception:
            if args.interruption.signalled:  # a Ctrl-C that C code (CasADi) turned into an error: not a bad file, no bug
                raise KeyboardInterrupt from None
            raise
    except PluginError as error:
        print(f"slewbench: plugin error: {error}", file=sys.stderr)
        return EXIT_BAD_SCENARIO
    except ScenarioError as error:
        # a command-line option's error is named as such, not as the scenario's; a study's as the study's
        kind = "option" if (error.path or "").startswith("--") else getattr(args, "file_kind", None) or \
            _COMMAND_FILES.get(args.command, "scenario")
        text = str(error)
        given = getattr(args, "file", None)
        if kind in _COMMAND_FILES.values():  # a study's or a table's error names its file (its YAML path follows)
            if not given:
                kind = "the command line"  # no file given: nothing to name
            elif error.file is None and str(given) not in text:  # raised after the file was read
                text = f"{given}: {text}"
        # the given file (./FILE is FILE in the error) where its kind is not known yet: named once
        named = str(error.file) if given and error.file is not None and error.file == Path(given) else kind
        print(f"slewbench: error in {text}" if kind == given and text.startswith(f"{named}: ")
              else f"slewbench: error in {kind}: {text}", file=sys.stderr)
        return EXIT_BAD_SCENARIO
    except OutputError as error:
        given = "--report" if getattr(args, "report", None) else "--out" if getattr(args, "out", None) else None
        # not for the default results/<name>, nor for another directory (run --export's <out>-<format>)
        where = f"{given} " if given and _names(getattr(args, given[2:]), error.path) else ""
        print(f"slewbench: output error: {where}{error}", file=sys.stderr)
        return EXIT_BAD_OUTPUT
    except BrokenPipeError:  # `slewbench list | head`: the reader has gone; nothing is lost
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except KeyboardInterrupt:
        return _interrupted(args)
    except OSError as error:
        if error.errno not in _STORAGE_ERRORS:
            return _internal_error()
        # the file system refused a write (full, over quota, read-only): not a bug, no traceback; every
        # writer stages its files and commits them last, so what was being written is discarded
        named = f" {error.filename}" if error.filename else ""
        print(f"slewbench: output error: cannot write{named}: {error.strerror}; the files being written were "
              "discarded (an earlier complete output is kept): free space or choose another location, and run "
              "again", file=sys.stderr)
        return EXIT_BAD_OUTPUT
    except Exception:  # noqa: BLE001 (the last resort: any bug is reported as one, with its traceback)
        return _internal_error()
    finally:
        for signum, handler in (previous or {}).items():
            signal.signal(signum, handler)

