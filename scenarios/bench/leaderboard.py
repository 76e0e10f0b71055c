"""The leaderboard: every problem of the suite run through the planners that apply (the scenario's
rows, through :func:`scenarios.runner.run`, so each row's requirement status is the run's) and the
installed peers, then tabulated against the best known optimum.

Per row: the objective value (the reference metric of the problem's objective, :data:`~scenarios.bench.suite.OBJECTIVE_METRICS`,
the same measure for every planner), its gap to the optimum (absolute, in the objective's unit,
and relative), whether the plan reaches the optimum within the problem's tolerance (judged on the
plan: its reference planned and meeting every requirement the reference is scored against,
``plan_status``), the row's status (the run's, its closed loop included), the plan time (CPU and wall), the
solver iterations (``reference.stats["iterations"]``) and the certificate
(``reference.stats["certificate"]``'s ``summary`` or ``verdict``; ``-`` without one). A reference
that leaves a boundary condition of the problem free (``Reference.free_boundary``) solves another
problem: its value is shown, its gap is not; so does a minimum-time row that keeps the scenario's
duration bound (a fixed-time plan) and a minimum-energy row planned over another duration; a
row whose rate jumps (an impulse, a start the reference declares free included), whose energy is
not finite, has no value (``-``, null, empty), its note says why.
"""
from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from scenarios.bench.suite import OBJECTIVE_METRICS, BenchProblem, Suite
from scenarios.output.directory import (
    claim_output_directory,
    commit_outputs,
    new_staging,
)
from scenarios.output.provenance import environment, utc_stamp

__all__ = ["BENCH_FILES", "ROWS_SCHEMA", "BenchRow", "Leaderboard", "certificate_text", "gap", "run_bench"]

BENCH_FILES = ("leaderboard.md", "leaderboard.csv", "leaderboard.json", "gap_vs_time.png")
"""What ``slewbench bench`` writes (the plot only with plots on)."""

ROWS_SCHEMA = 2
"""The version of ``leaderboard.json``'s row keys: 2 names the objective ``objective`` and its value
``value`` (as the CSV does) and adds ``plan_cpu_s``; a file without ``rows_schema`` (version 1) has
the value in ``objective``."""

GAP_FLOOR = 1e-9
"""Relative gaps below this are drawn at it on the log axis of the plot."""


@dataclass
class BenchRow:
    """One (problem, planner or peer) entry of the leaderboard.

    Parameters
    ----------
    problem : str
        The problem's name.
    label : str
        The row's label (the scenario row's, or ``"<peer> (peer)"``).
    planner : str
        The planner's registry name, or the peer's name.
    kind : str
        ``"planner"`` or ``"peer"``.
    status : str
        The row's status as the run gives it, its closed loop included (``ok``, ``violated``,
        ``failed``; a peer's ``ok`` or ``failed``).
    value : float or None
        The objective's value in the problem's unit; ``None`` without a reference, and for a
        reference whose metric is not finite (its rate jumps: an impulse, whose energy is +inf).
    gap_abs : float or None
        ``value − optimum`` in the problem's unit; ``None`` when not comparable.
    gap_rel : float or None
        ``gap_abs / optimum``.
    reached : bool or None
        ``|gap_abs| <= tolerance`` and ``plan_status`` ``ok``.
    plan_time_s : float or None
        Plan wall time [s] (``time.perf_counter``): the second of two plans (a peer's solves), the
        first paying the build and first-call costs.
    iterations : int or None
        Solver iterations, when the planner or peer reports them.
    certificate : str
        The certificate's summary or verdict, ``-`` without one.
    message : str
        The row's message, or why its gap is not shown.
    plan_status : str
        The plan's own status: the planner's when it gave no reference (``failed``, ``infeasible``),
        ``failed`` when its reference metrics are not physical, ``violated`` when the reference
        breaks a requirement (scored as the run scores it), else ``ok``; a peer's is its status. The closed loop does not enter it: the bench
        ranks plans, and a tracking controller that dips into a keep-out cone the plan keeps
        shows in ``status``.
    plan_cpu_s : float or None
        CPU time of the same plan [s] (``time.process_time`` of this process, every thread of it:
        a loaded machine does not inflate it as it does the wall time); ``None`` where not measured.
    objective : str
        The problem's objective, by name (``min_time``, ``min_energy``), as in ``problems`` and the
        CSV.
    """

    problem: str
    label: str
    planner: str
    kind: str
    status: str
    value: float | None
    gap_abs: float | None
    gap_rel: float | None
    reached: bool | None
    plan_time_s: float | None
    iterations: int | None
    certificate: str
    message: str = ""
    plan_status: str = ""
    plan_cpu_s: float | None = None
    objective: str = ""

    def __post_init__(self) -> None:
        if not self.plan_status:
            self.plan_status = self.status


def gap(value: float | None, optimum: float) -> tuple[float | None, float | None]:
    """The gap of ``value`` to ``optimum``.

    Parameters
    ----------
    value : float or None
        An objective value (``None``: none).
    optimum : float
        The best known optimum (nonzero), same unit.

    Returns
    -------
    tuple
        ``(value − optimum, (value − optimum) / |optimum|)``; ``(None, None)`` for ``None`` or a
        non-finite value.
    """
    if value is None or not math.isfinite(value):
        return None, None
    difference = value - optimum
    return difference, difference / abs(optimum)


def certificate_text(stats: Any) -> str:
    """The certificate column: ``stats["certificate"]``'s ``summary``, else its ``verdict``, else ``-``.

    Parameters
    ----------
    stats : mapping or None
        A reference's ``stats``.

    Returns
    -------
    str
        One short line.
    """
    certificate = stats.get("certificate") if isinstance(stats, dict) else None
    if not isinstance(certificate, dict):
        return "-"
    text = certificate.get("summary") or certificate.get("verdict")
    return str(text) if text else "-"


def _number(value: Any) -> int | None:
    return int(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _planner_rows(problem: BenchProblem, scenario: Any, results: Any, specs: list[Any],
                  cpu: dict[int, float] | None = None) -> list[BenchRow]:
    from planners import PLANNERS
    from planners.capabilities import minimises_time
    from scenarios.schema.labels import row_labels

    metric = OBJECTIVE_METRICS[problem.objective][0]
    # each row's planner spec and controller, in the runner's row order (``specs`` is what it ran)
    labels = row_labels([spec.label for spec in specs], [c.label for c in scenario.controllers])
    planner_of = [i for _, i, _ in labels]
    # a reference tracked by several controllers is one plan, scored through each row's controller's
    # allocation (the actuator demand differs between allocations), as the runner scores it
    plans: dict[tuple[int, int], str] = {}
    rows = []
    for row, i, (_, _, j) in zip(results.rows, planner_of, labels):
        plan = (id(row.reference), j)
        if plan not in plans:
            plans[plan] = _plan_status(scenario, row, scenario.controllers[j].controller)
        spec = specs[i] if i is not None else None
        timed = spec is not None and minimises_time(PLANNERS[spec.name], spec.options)
        reference = row.reference
        stats = getattr(reference, "stats", None) if reference is not None else None
        value = None
        if row.reference_metrics is not None and row.reference_metrics.get(metric) is not None:
            value = float(row.reference_metrics[metric])
        gap_abs, gap_rel = gap(value, problem.optimum)
        message = row.message
        if row.planner is not None and row.label == f"{row.planner} (defaults)":  # other_planners
            message = f"default options (the planner's own objective, not tuned to this problem); {message}"
        free = sorted(getattr(reference, "free_boundary", ()) or ())
        other = _other_problem(problem, scenario, reference, row, timed)
        infinite = value is not None and not math.isfinite(value)
        if value is not None and other.startswith("impulse"):
            value = gap_abs = gap_rel = None
        elif infinite:  # no value, as a jump the run counts against the plan (other) has none
            message = f"{_infinite_note(metric, free)}; {message}"
            value = None
        if (value is not None or infinite) and free:
            gap_abs = gap_rel = None
            message = f"leaves {', '.join(free)} free: solves another problem, no gap; {message}"
        if other and not (free and not other.startswith("impulse")):
            gap_abs = gap_rel = None
            message = f"{other}; {message}"
        rows.append(BenchRow(
            problem.name, row.label, row.planner or "-", "planner", row.status, value, gap_abs, gap_rel,
            _reached(plans[plan], gap_abs, problem), row.plan_time_s,
            _number((stats or {}).get("iterations")), certificate_text(stats), message, plans[plan],
            (cpu or {}).get(id(reference)), problem.objective))
    return rows


def _cpu_timed(planners: Iterable[Any], cpu: dict[int, float]) -> Callable[[], None]:
    """Time each planner's :meth:`~planners.Planner.plan` in CPU (``time.process_time``) while the
    run plans: ``cpu[id(reference)]`` is the CPU time of the plan that returned ``reference``. The
    planners' ``plan`` is wrapped on the instances only; the returned function unwraps them.

    Parameters
    ----------
    planners : iterable of Planner
        The planner instances the run will call.
    cpu : dict of int to float
        Filled with the CPU time [s] of each plan, by the reference's ``id``.

    Returns
    -------
    callable
        Restores the planners' own ``plan``.
    """
    wrapped = []
    for planner in planners:
        if "plan" in vars(planner):  # the same instance twice: wrapped once
            continue
        plan = planner.plan

        def timed(problem: Any, _plan: Callable[[Any], Any] = plan) -> Any:
            began = time.process_time()
            reference = _plan(problem)
            cpu[id(reference)] = time.process_time() - began
            return reference

        planner.plan = timed
        wrapped.append(planner)

    def restore() -> None:
        for planner in wrapped:
            vars(planner).pop("plan", None)
    return restore


def _plan_status(scenario: Any, row: Any, controller: Any) -> str:
    """A planner row's plan status (:class:`BenchRow`'s ``plan_status``): its reference scored against
    the scenario's requirements as :func:`scenarios.runner.run` scores it (the same times, the row's
    controller's allocation for the actuator demand), without the closed loop."""
    from ocp import metric_violations
    from scenarios.requirements.scoring import (
        plant_limits,
        reference_times,
        score_reference,
    )
    from scenarios.runner import closed_loop_window

    reference = row.reference
    if reference is None or not reference.ok:  # the planner's own status (failed, infeasible)
        return str(getattr(reference, "status", None) or "failed")
    if row.reference_metrics is None or metric_violations(row.reference_metrics):
        return "failed"
    if not scenario.requirements:
        return "ok"
    times = reference_times(reference.duration, closed_loop_window(scenario, reference),
                            scenario.simulation.sample_time)
    scores = score_reference(scenario.requirements, scenario.problem, times, reference.sample(times), controller,
                             reference, plant_limits(scenario.truth))
    return "ok" if all(score.met for score in scores.values()) else "violated"


def _other_problem(problem: BenchProblem, scenario: Any, reference: Any, row: Any, minimises_time: bool) -> str:
    """Why a row's value is not the problem's objective ("" when it is): a minimum-time row from a
    planner that does not minimise time (``minimises_time``, :func:`planners.capabilities.minimises_time`:
    it plans over the scenario's bound or a duration of its own, so its "time" is an input), a
    minimum-energy row planned over another duration than the problem's, or a minimum-energy row
    whose rate jumps (an impulse, whose energy is not finite; the sampled torque misses it)."""
    duration = getattr(reference, "duration", None)
    bound = scenario.problem.duration
    if duration is None or not getattr(reference, "ok", False):  # a failed plan solved nothing
        return ""
    if problem.objective == "min_time" and not minimises_time:
        if math.isclose(duration, bound, rel_tol=1e-9):
            return (f"keeps the scenario's bound T = {bound:g} s (a fixed-time plan, not minimum time): solves "
                    "another problem, no gap")
        return (f"plans its own duration T = {duration:.6g} s without minimising it (not minimum time): solves "
                "another problem, no gap")
    if problem.objective == "min_energy":
        if not math.isclose(duration, bound, rel_tol=1e-9):
            return f"plans its own duration T = {duration:.6g} s, not the problem's {bound:g} s: another problem, no gap"
        actuators = ((row.requirements or {}).get("reference") or {}).get("actuators") or {}
        if (actuators.get("rate_jump") or 0.0) > 0.0:
            return ("impulse: its rate jumps (no finite torque gives it), so its energy is not finite; no value "
                    "or gap")
    return ""


def _infinite_note(metric: str, free: list[str]) -> str:
    """Why a row whose reference metric is not finite has no value: the metrics count each jump of
    the rate as an impulse (``int_u2`` +inf, :data:`ocp.metrics.IMPULSE_INFINITE`), a start the
    reference declares free included (it starts at its own rate, not the problem's)."""
    where = ("from the problem's initial rate to the rate it starts at (omega0 free)" if "omega0" in free
             else "")
    return (f"impulse: its rate jumps{' ' + where if where else ''} (no finite torque gives it), so its {metric} is "
            "not finite; no value")


def _reached(status: str, gap_abs: float | None, problem: BenchProblem) -> bool | None:
    """Whether a row reaches the optimum: within the tolerance, and its plan ``ok`` (``status`` is the
    plan's status: a plan that breaks a requirement or failed never does, however close its value);
    ``None`` without a gap."""
    if gap_abs is None:
        return None
    return status == "ok" and abs(gap_abs) <= problem.tolerance


def _peer_row(problem: BenchProblem, name: str, result: Any) -> BenchRow:
    gap_abs, gap_rel = gap(result.objective, problem.optimum)
    message = result.message
    eigenaxis = problem.eigenaxis
    if (result.objective is not None and eigenaxis is not None and abs(eigenaxis - problem.optimum) > problem.tolerance
            and abs(result.objective - eigenaxis) <= problem.tolerance):
        # where the eigenaxis slew is not the optimum it can be a stationary point (a saddle of
        # Bilimoria & Wie's slews): a peer that stops there is noted (its message names its start)
        message = f"{EIGENAXIS_NOTE}; {message}" if message else EIGENAXIS_NOTE
    return BenchRow(problem.name, f"{name} (peer)", name, "peer", result.status, result.objective, gap_abs, gap_rel,
                    _reached(result.status, gap_abs, problem), result.solve_time_s,
                    _number(result.iterations), "-", message, plan_cpu_s=getattr(result, "solve_cpu_s", None),
                    objective=problem.objective)


@dataclass
class Leaderboard:
    """The rows of a bench run, with what was skipped and where the run took place.

    Parameters
    ----------
    suite : Suite
        The suite run.
    problems : list of BenchProblem
        The problems run, in order.
    rows : list of BenchRow
        The entries, problem by problem.
    notes : list of str
        Peers skipped and why, problems without a row.
    wall_time_s : float
        Wall time of the whole run [s].
    date : str
        When it ran (UTC, ISO 8601).
    peer_versions : dict of str to str
        The version of each peer that ran (its tool's, as the peer's ``version()`` gives it).
    """

    suite: Suite
    problems: list[BenchProblem]
    rows: list[BenchRow] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    wall_time_s: float = 0.0
    date: str = ""
    peer_versions: dict[str, str] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The leaderboard as JSON-ready data: suite version, provenance, problems, rows, notes.

        Returns
        -------
        dict
            ``suite_version``, ``slewbench``, ``date``, ``environment`` (versions and platform, with
            ``peers``: the version of each peer that ran), ``wall_time_s``, ``problems`` (metadata),
            ``rows``, ``notes``, ``rows_schema`` (:data:`ROWS_SCHEMA`). A row's ``objective`` is the
            objective's name and ``value`` its value, as in ``problems`` and the CSV.
        """
        env = {**environment(), "peers": dict(self.peer_versions)}
        return {"suite_version": self.suite.version, "rows_schema": ROWS_SCHEMA, "slewbench": env["slewbench"],
                "date": self.date,
                "platform": env["platform"], "environment": env, "wall_time_s": self.wall_time_s,
                "problems": [problem.metadata() for problem in self.problems],
                "rows": [dataclasses.asdict(row) for row in self.rows], "notes": list(self.notes)}

    def reached_text(self) -> str:
        """How many rows reach their problem's optimum, by the kind of that optimum.

        Returns
        -------
        str
            ``"3 at the optimum (2 published, 1 best known)"``: the kinds (``published``,
            ``best known``, ``closed form``, the suite's ``optimum.kind``) in the order the rows meet
            them; ``"0 at the optimum"`` when no row reaches one.
        """
        kinds = {problem.name: problem.optimum_kind.replace("_", " ") for problem in self.problems}
        counts: dict[str, int] = {}
        for row in self.rows:
            if row.reached:
                counts[kinds[row.problem]] = counts.get(kinds[row.problem], 0) + 1
        total = sum(counts.values())
        return f"{total} at the optimum" + (f" ({', '.join(f'{n} {kind}' for kind, n in counts.items())})"
                                            if total else "")

    def to_csv(self) -> str:
        """One line per row, with the problem's objective, unit, optimum and tolerance.

        Returns
        -------
        str
            CSV text with a header.
        """
        problems = {problem.name: problem for problem in self.problems}
        stream = io.StringIO()
        writer = csv.writer(stream, lineterminator="\n")
        writer.writerow(["problem", "objective", "unit", "optimum", "tolerance", "label", "planner", "kind", "status",
                         "plan_status", "value", "gap_abs", "gap_rel", "reached", "plan_time_s", "plan_cpu_s",
                         "iterations", "certificate", "message"])
        for row in self.rows:
            problem = problems[row.problem]
            writer.writerow([row.problem, problem.objective, problem.unit, repr(problem.optimum), repr(problem.tolerance),
                             row.label, row.planner, row.kind, row.status, row.plan_status, _csv(row.value),
                             _csv(row.gap_abs),
                             _csv(row.gap_rel), "" if row.reached is None else row.reached, _csv(row.plan_time_s),
                             _csv(row.plan_cpu_s), "" if row.iterations is None else row.iterations, row.certificate, row.message])
        return stream.getvalue()

    def to_markdown(self) -> str:
        """A section per problem (its optimum and where it comes from, then a table of its rows).

        Returns
        -------
        str
            Markdown text.
        """
        env = environment()
        lines = [f"# slewbench bench: suite version {self.suite.version}", "",
                 (f"slewbench {env['slewbench']}, {self.date}, {env['platform']}; {len(self.problems)} problem(s), "
                  f"{len(self.rows)} row(s) in {self.wall_time_s:.1f} s."), "",
                 ("Gap: value − optimum (the objective's unit) and relative to the optimum; ✓ within the problem's "
                  "tolerance with the plan ok. Plan: the plan's own status (its reference against the requirements); "
                  "status: the run's, its closed loop included (the bench ranks plans: a tracking controller's "
                  "violation shows there, not in the ✓). Plan time: the second of two plans (a peer's solves), the "
                  "first paying the build and first-call costs; CPU: the process's CPU time (time.process_time), "
                  "wall: the elapsed time (time.perf_counter), which a loaded machine inflates."), "",
                 VALUE_LEGEND, ""]
        lines += self._summary()
        for problem in self.problems:
            lines += [f"## {problem.name}: {problem.title}", "",
                      (f"{problem.objective} [{problem.unit}]; optimum {_with_tolerance(problem.optimum, problem.tolerance)} "
                       f"± {problem.tolerance:.2g} "
                       f"({problem.optimum_kind.replace('_', ' ')}: {problem.optimum_source}); eigenaxis "
                       f"{'-' if problem.eigenaxis is None else f'{problem.eigenaxis:.6g}'} ({problem.eigenaxis_source}). "
                       f"Source: {problem.source}"), "",
                      ("| row | kind | plan | status | value | gap | gap (rel) | plan CPU [s] | plan wall [s] | "
                       "iterations | certificate | note |"),
                      "|---|---|---|---|---|---|---|---|---|---|---|---|"]
            whole: list[str] = []  # the notes shortened in the table, in full below it
            for row in (r for r in self.rows if r.problem == problem.name):
                mark = "" if row.reached is None else (" ✓" if row.reached else "")
                note = _note(row)
                if len(note) > NOTE_CHARS:
                    whole.append(note)
                    note = f"{note[:NOTE_CHARS - 1]}… [{len(whole)}]"
                lines.append(
                    f"| {_md(row.label)} | {row.kind} | {row.plan_status} | {row.status} | {_fmt(row.value)} | "
                    f"{_fmt(row.gap_abs, '+.3g')}"
                    f"{mark} | {_fmt(row.gap_rel, '+.2e')} | {_fmt(row.plan_cpu_s, '.3g')} | {_fmt(row.plan_time_s, '.3g')} | "
                    f"{'-' if row.iterations is None else row.iterations} | {_md(row.certificate)} | {_md(note)} |")
            lines.append("")
            if whole:
                lines += [f"[{k}] {_md(note)}" + ("  " if k < len(whole) else "") for k, note in enumerate(whole, 1)]
                lines.append("")
        if self.notes:
            lines += ["## Notes", ""] + [f"- {_md(note)}" for note in self.notes] + [""]
        return "\n".join(lines)

    def _summary(self) -> list[str]:
        """Markdown lines: per planner, then per peer (each in order of first appearance), its rows,
        those with a gap (the others solve another problem or failed), how many reach the optimum,
        the median absolute relative gap of the plans ok with a gap and the median plan time, CPU
        and wall."""
        lines = ["## Summary", "",
                 ("| planner | kind | rows | rows with a gap | at the optimum | median \\|gap\\| (rel) | "
                  "median plan CPU [s] | median plan wall [s] |"), "|---|---|---|---|---|---|---|---|"]
        names = dict.fromkeys(row.planner for row in sorted(self.rows, key=lambda row: row.kind != "planner"))
        for name in names:
            rows = [row for row in self.rows if row.planner == name]
            gapped = [row for row in rows if row.gap_rel is not None]
            gaps = [abs(row.gap_rel) for row in gapped if row.gap_rel is not None and row.plan_status == "ok"]
            times = [row.plan_time_s for row in rows if row.plan_time_s is not None]
            cpus = [row.plan_cpu_s for row in rows if row.plan_cpu_s is not None]
            lines.append(f"| {_md(name)} | {rows[0].kind} | {len(rows)} | {len(gapped)} | "
                         f"{sum(1 for row in rows if row.reached)} | {_fmt(_median(gaps), '.2e')} | "
                         f"{_fmt(_median(cpus), '.3g')} | {_fmt(_median(times), '.3g')} |")
        return lines + [""]

    def plot(self, path: Path) -> None:
        """Relative gap against plan CPU time, one marker per planner or peer, log axes; rows without a
        gap or a CPU time are left out, gaps below :data:`GAP_FLOOR` drawn at it. Each planner or peer keeps its
        colour and marker from run to run (``_plot_style``); the legend is beside the axes.

        Parameters
        ----------
        path : Path
            The PNG to write.
        """
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        figure = Figure(figsize=(9.0, 4.8), dpi=110)
        canvas = FigureCanvasAgg(figure)
        axis = figure.add_subplot(1, 1, 1)
        figure.subplots_adjust(left=0.09, right=0.7, top=0.92, bottom=0.11)
        kinds = {row.planner: row.kind for row in self.rows}
        drawn = 0
        for name in sorted(kinds, key=lambda planner: (kinds[planner] == "peer", planner)):  # planners, then peers
            points = [(row.plan_cpu_s, max(abs(row.gap_rel), GAP_FLOOR)) for row in self.rows
                      if row.planner == name and row.gap_rel is not None and row.plan_cpu_s and row.plan_status == "ok"]
            if not points:
                continue
            kind = kinds[name]
            x, y = zip(*points)
            style = _plot_style(name, kind)
            axis.scatter(x, y, marker=style["marker"], label=f"{name}{' (peer)' if kind == 'peer' else ''}",
                         facecolors="none" if kind == "peer" else style["color"], edgecolors=style["color"])
            drawn += 1
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel("plan CPU time [s]")
        axis.set_ylabel(f"relative gap |J − J*| / J* [-] (floor {GAP_FLOOR:g})")
        axis.set_title(f"slewbench bench, suite version {self.suite.version}")
        axis.grid(True, which="major", alpha=0.3)
        if drawn:
            axis.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
        canvas.print_png(str(path))

    def write(self, out: str | Path, plots: bool = True) -> list[str]:
        """Write the tables (and the plot) into ``out``, a directory slewbench owns (claimed as
        ``kind="bench"``; files it did not write are never replaced).

        Parameters
        ----------
        out : str or Path
            The output directory.
        plots : bool, optional
            Draw ``gap_vs_time.png`` (default ``True``).

        Returns
        -------
        list of str
            The files written (relative to ``out``).

        Raises
        ------
        scenarios.errors.OutputError
            The directory is not slewbench's, or a result would replace a file slewbench did not write.
        """
        directory = claim_output_directory(out, kind="bench")
        staging = new_staging(directory)
        (staging / "leaderboard.md").write_text(self.to_markdown(), encoding="utf-8")
        (staging / "leaderboard.csv").write_text(self.to_csv(), encoding="utf-8")
        (staging / "leaderboard.json").write_text(json.dumps(self.to_json(), indent=1, default=_json_default) + "\n",
                                                  encoding="utf-8")
        if plots:
            self.plot(staging / "gap_vs_time.png")
        return commit_outputs(directory, staging, "bench")


_PLOT_MARKERS = "osD^v<>pPX*h"
"""Markers of the planners and peers in ``gap_vs_time.png``, in ``_plot_style``'s order."""


def _plot_style(name: str, kind: str) -> dict[str, str]:
    """The colour and marker of a planner or peer in ``gap_vs_time.png``, the same in every run: by
    its place in :data:`planners.PLANNERS` (a planner) or after them in
    :data:`scenarios.bench.peers.PEERS` (a peer, drawn hollow); a name in neither takes one from
    a checksum of its name.

    Parameters
    ----------
    name : str
        The planner's registry name or the peer's name.
    kind : str
        ``"planner"`` or ``"peer"``.

    Returns
    -------
    dict
        ``color`` (a matplotlib ``"C<n>"`` colour) and ``marker``.
    """
    import zlib

    from planners import PLANNERS
    from scenarios.bench.peers import PEERS

    known = list(PLANNERS) + list(PEERS)
    if name in (PEERS if kind == "peer" else PLANNERS):
        index = len(PLANNERS) + list(PEERS).index(name) if kind == "peer" else list(PLANNERS).index(name)
    else:
        index = len(known) + zlib.crc32(name.encode()) % len(_PLOT_MARKERS)
    return {"color": f"C{index % 10}", "marker": _PLOT_MARKERS[index % len(_PLOT_MARKERS)]}


def _json_default(value: Any) -> Any:
    if hasattr(value, "item"):
        return value.item()
    if hasattr(value, "tolist"):
        return value.tolist()
    return str(value)


def _median(values: list[float]) -> float | None:
    if not values:
        return None
    ordered = sorted(values)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else 0.5 * (ordered[middle - 1] + ordered[middle])


def _csv(value: float | None) -> str:
    return "" if value is None else repr(float(value))


def _fmt(value: float | None, spec: str = ".6g") -> str:
    return "-" if value is None else format(value, spec)


def _with_tolerance(value: float, tolerance: float) -> str:
    """``value`` with the significant digits down to its tolerance's leading digit, trailing zeros
    kept, and never fewer than the value as stated has (11.21 ± 1e-4 reads ``11.2100``, 2.5897 ±
    1e-3 ``2.5897``, 5.8467e-8 ± 3e-12 ``5.8467e-08``); 6 without a positive tolerance or for a
    zero value."""
    if not (tolerance > 0.0 and value != 0.0 and math.isfinite(value)):
        return f"{value:.6g}"
    stated = len(repr(abs(value)).split("e")[0].replace(".", "").lstrip("0"))  # the value's own digits
    digits = math.floor(math.log10(abs(value))) - math.floor(math.log10(tolerance)) + 1
    return f"{value:#.{min(max(digits, stated, 1), 17)}g}"


VALUE_LEGEND = ("Value: the objective (the reference metric of the problem's objective, the same measure for every "
                "row); - where there is none: a plan that failed, or a motion whose rate jumps (an impulse, a free "
                "start included), whose energy is not finite (the note says so). Iterations: what the planner or "
                "peer reports of its solver (collocation: its NLP solver's iterations; a peer: its solver's), - where "
                "it reports none (closed forms); methods differ in what one iteration is. Certificate: the evidence "
                "that a plan is a local optimum of its discretised problem (the verdict, then the KKT residual, SOSC: "
                "the second-order sufficient conditions, switching: the bang-bang samples on the side of Pontryagin's "
                "switching function, the co-state gap, and the seeds: 1 seed when one start was made, a/b seeds "
                "agreed when a of b starts reached the optimum), - where the planner writes none (closed forms, "
                "peers).")
"""The legend of the leaderboard's value, iterations and certificate columns, under its header."""
NOTE_CHARS = 100
"""Longest note in a Markdown table cell: a longer one is cut there and given whole below the table
(as are the CSV and JSON)."""
EIGENAXIS_NOTE = "stopped at the eigenaxis slew's value (a stationary point)"
"""The note of a peer whose value is the eigenaxis slew's where that is not the optimum."""


def _note(row: BenchRow) -> str:
    """The row's message when it is a peer's (it names the peer's start), not ok or has no gap;
    else empty."""
    if row.kind != "peer" and row.status == "ok" and row.gap_abs is not None:
        return ""
    return row.message.strip()


def _md(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def other_planners(scenario: Any) -> list[Any]:
    """Every registered planner that the scenario's rows do not name and that accepts its problem
    (:meth:`planners.Planner.problem_error` is ``None``), with its default options, labelled
    ``<name> (defaults)``: the problem's suite entry names the planners its scenario was written
    for, and the leaderboard runs every planner that can take the problem.

    Parameters
    ----------
    scenario : scenarios.schema.loader.Scenario
        A problem's scenario.

    Returns
    -------
    list of scenarios.schema.loader.PlannerSpec
        In registry order.
    """
    from planners import PLANNERS
    from scenarios.schema.loader import PlannerSpec

    named = {spec.name for spec in scenario.planners}
    labels = {spec.label for spec in scenario.planners}
    specs = []
    for name, cls in PLANNERS.items():
        label = f"{name} (defaults)"
        if name in named or label in labels:
            continue
        planner = cls({})
        if planner.problem_error(scenario.problem) is None:
            specs.append(PlannerSpec(name, label, planner.options, planner))
    return specs


def run_bench(suite: Suite, problems: Iterable[str] | None = None, planners: Iterable[str] | None = None,
              peers: Iterable[str] = (), progress: Callable[[str], None] | None = None) -> Leaderboard:
    """Run problems of ``suite`` through their planners (and ``peers``) and collect the leaderboard.

    Parameters
    ----------
    suite : Suite
        The suite (:func:`~scenarios.bench.suite.load_suite`).
    problems : iterable of str or None, optional
        Names of the problems to run (``None``: all, in the suite's order).
    planners : iterable of str or None, optional
        Planner registry names to keep of each scenario's rows and of :func:`other_planners`
        (``None``: all of them).
    peers : iterable of str, optional
        Names of :data:`scenarios.bench.peers.PEERS` to run beside them (default none).
    progress : callable or None, optional
        Receives a line per problem.

    Returns
    -------
    Leaderboard
        The rows; peers missing, unable to express a problem or not asked on it (the suite's
        ``peers: {skip: <why>}``) are notes, each with its reason.

    Raises
    ------
    KeyError
        A problem name the suite does not hold (the CLI checks names first).
    """
    from scenarios.bench.peers import PEERS, PeerUnavailable, load_peer
    from scenarios.runner import run
    from scenarios.schema.loader import load

    say = progress or (lambda line: None)
    chosen = [suite.problems[name] for name in (problems if problems is not None else suite.problems)]
    keep = None if planners is None else set(planners)
    board = Leaderboard(suite, chosen, date=utc_stamp())
    loaded: dict[str, Any] = {}
    for name in peers:
        try:
            loaded[name] = load_peer(name, PEERS)
        except PeerUnavailable as error:
            board.notes.append(str(error))
    ran: set[str] = set()
    start = time.perf_counter()
    for i, problem in enumerate(chosen, 1):
        began = time.perf_counter()
        scenario = load(problem.file)
        specs = [spec for spec in [*scenario.planners, *other_planners(scenario)] if keep is None or spec.name in keep]
        rows: list[BenchRow] = []
        if specs:
            for spec in specs:  # the first plan pays the build, untimed, as a peer's first solve does
                try:
                    spec.planner.plan(scenario.problem)
                except Exception:  # noqa: BLE001, S110 (the timed plan below records a crash as a failed row)
                    pass
            cpu: dict[int, float] = {}
            restore = _cpu_timed([spec.planner for spec in specs], cpu)
            try:
                results = run(dataclasses.replace(scenario, planners=specs))
            finally:
                restore()
            rows += _planner_rows(problem, scenario, results, specs, cpu)
        if not problem.peers:  # the index's reason, a note per peer as a peer's own refusal is
            board.notes += [f"peer {name} not asked on {problem.name}: "
                            f"{problem.peers_skip or 'the suite does not ask the peers (no reason given)'}"
                            for name in loaded]
        for name, peer in loaded.items() if problem.peers else ():
            reason = peer.problem_error(scenario.problem, problem.objective)
            if reason is not None:
                board.notes.append(f"peer {name} skipped on {problem.name}: {reason}")
                continue
            try:
                result = peer.solve(scenario.problem, problem.objective)
            except Exception as error:  # noqa: BLE001 (a peer's crash is a failed row, not the end of the run)
                from scenarios.bench.peers import PeerResult

                result = PeerResult(None, 0.0, "failed", None, f"{type(error).__name__}: {error}")
            rows.append(_peer_row(problem, name, result))
            ran.add(name)
        if not rows:
            board.notes.append(f"{problem.name}: no planner or peer selected applies")
        board.rows += rows
        reached = sum(1 for row in rows if row.reached)
        say(f"[{i}/{len(chosen)}] {problem.name}: {len(rows)} row(s), {reached} at the optimum, "
            f"{time.perf_counter() - began:.1f} s")
    board.wall_time_s = time.perf_counter() - start
    board.peer_versions = {name: _peer_version(peer) for name, peer in loaded.items() if name in ran}
    return board


def _peer_version(peer: Any) -> str:
    """A peer's version (its ``version()``), or why it is not known."""
    version = getattr(peer, "version", None)
    if not callable(version):
        return "unknown (the peer has no version())"
    try:
        return str(version())
    except Exception as error:  # noqa: BLE001 (a version query must not lose the leaderboard)
        return f"unknown ({type(error).__name__}: {error})"
