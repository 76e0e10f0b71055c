"""``slewbench table``: a slew table (minimum time over eigen-axes and angles) and its fit.

Everything that can fail before an entry is computed is checked first (the scenario or table file
and the options: exit 2 naming the YAML path or option; the output directory: exit 2 if it is not
slewbench's or holds another kind of output; a Dask scheduler). Entries run on the trade-study
engine and are stored as they finish, so a table interrupted (exit 130) or run again into the same
``--out`` computes only the entries it lacks. A table whose entries crashed (raised or killed their
worker) or timed out (the planner still solving when ``case_timeout_s`` ran out: status
``timed_out``) writes its files, then exits 1 (as ``slewbench sweep``) saying how many, why, and the
command that runs them again. This module imports only the
standard library until the command runs.
"""
from __future__ import annotations

import argparse
import math
import shlex
import signal
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from scenarios.cli.status import (
    EXIT_BAD_SCENARIO,
    EXIT_CRASHED,
    EXIT_INTERRUPTED,
    EXIT_NOT_OK,
    EXIT_OK,
    crash_report,
    directory_argument,
    workers_note,
)

if TYPE_CHECKING:
    from scenarios.errors import ScenarioError
    from scenarios.slewtable.spec import TableSpec


def _terminate(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def _integer(text: str) -> int | str:
    """``--axes``: a count (an integer of any sign: the table spec says which it takes)."""
    try:
        return int(text)
    except ValueError:
        return text


def _count(number: int, one: str, many: str | None = None) -> str:
    """``1 axis``, ``2 axes``."""
    return f"{number} {one if number == 1 else (many or one + 's')}"


MAX_ENTRIES = 2000
"""Most entries (axes x angles, and the held-out grid's) ``table`` computes without ``--max-entries``:
at 1 to 90 s of collocation each, 2000 entries are hours on a few cores."""


BARE_ANGLES = 14
"""Most angles a bare count (``--angles N``, or ``angles_deg: N`` in a table file) gives without
``--max-entries``: a larger count reads like a slew angle in degrees (``--angles 90`` is 90 angles
from 10 to 180 deg, not 90 deg: 1080 entries on 12 axes), so it is refused before anything runs
unless ``--max-entries`` confirms the work (or the angles are listed). 14 angles are a step of
13 deg; the default table has 7."""


def check_table_work(spec: TableSpec, entries: int, max_entries: int | None = None, angles: str | None = None) -> None:
    """The work a table would take, checked before anything is computed (by ``slewbench table``,
    and by ``slewbench validate`` on a table file, with the default limit).

    Says (on standard output) how many axes the grid has when it is not the number asked for, and
    refuses more than ``max_entries`` entries, naming the count and how to go on. Angles given as a
    bare count (``--angles N``, or ``angles_deg: N`` in the table file) are said to be one (on
    standard output), and a count above :data:`BARE_ANGLES`, which reads like an angle in degrees,
    is refused without ``max_entries`` (given, it confirms the work), at the flag or YAML path that
    gave it.

    Parameters
    ----------
    spec : TableSpec
        The table (its axes, angles and held-out grid; :attr:`~scenarios.slewtable.spec.TableSpec.angles_count`
        the count its angles were given as, and where).
    entries : int
        Its number of entries: axes x angles, plus the held-out grid's.
    max_entries : int or None, optional
        ``--max-entries``: the most entries to compute; ``None`` (default): :data:`MAX_ENTRIES`.
    angles : str or None, optional
        ``--angles`` as given (a bare count there is checked at ``--angles``); ``None``: the
        count the spec records, if any (a flag's or the table file's).

    Raises
    ------
    ScenarioError
        At ``--max-entries``: a limit below 1, or more entries than the limit; at ``--angles`` or
        ``table.angles_deg``: a bare count above :data:`BARE_ANGLES` without ``max_entries``.
    """
    if spec.axes_asked is not None and spec.axes_asked != len(spec.axes):
        print(f"{spec.name}: {_count(spec.axes_asked, 'axis', 'axes')} asked for, the {spec.grid} grid has "
              f"{len(spec.axes)}: every vertex and face centre of the torque polytope, its faces subdivided evenly "
              f"(so its counts come in steps); --grid fibonacci gives exactly {spec.axes_asked}", flush=True)
    from scenarios.errors import ScenarioError
    from scenarios.schema.table import bare_count
    if max_entries is not None and max_entries < 1:
        raise ScenarioError("--max-entries", f"expected a positive number of entries, got {max_entries}")
    limit = MAX_ENTRIES if max_entries is None else max_entries
    count, where = (bare_count(angles), "--angles") if angles is not None else (spec.angles_count, spec.angles_where)
    flag = where.startswith("--")
    said = f"{where} {count}" if flag else f"{where}: {count}"  # --angles 90, table.angles_deg: 90
    listed = ("a comma-separated list", "--angles 60,90,120", "--angles 30,90") if flag else \
        ("a YAML list", f"{where.rsplit('.', 1)[-1]}: [60, 90, 120]", f"{where.rsplit('.', 1)[-1]}: [30, 90]")
    if entries <= limit:
        if count is None:
            return
        degrees = f", not the angle {count} deg" if count <= 180 else ""
        if count > BARE_ANGLES and max_entries is None:
            raise ScenarioError(where, f"{count} is a count: {count} angles spread from 10 to 180 deg "
                                       f"({_work(spec, entries)}){degrees}; angles in degrees are {listed[0]} of at "
                                       f"least 2 (e.g. {listed[1]}; for one slew, slewbench run); to compute the "
                                       f"{count} angles, confirm the work with --max-entries {entries}")
        print(f"{said} is a count: {count} angles spread from 10 to 180 deg{degrees} (angles in degrees are "
              f"{listed[0]}, e.g. {listed[2]})", flush=True)
        return
    bare = f"; {said} means {count} angles spread from 10 to 180 deg, not {count} deg (angles in degrees are " \
           f"{listed[0]}, e.g. {listed[2]})" if count is not None else ""
    raise ScenarioError("--max-entries", f"{_work(spec, entries)}, more than {limit} (each a collocation solve: "
                                         f"seconds to minutes){bare}; to compute them all, give --max-entries {entries}")


def _work(spec: TableSpec, entries: int) -> str:
    """``12 axes x 90 angles = 1080 entries``, with the held-out grid's entries when it has one."""
    return (f"{_count(len(spec.axes), 'axis', 'axes')} x {_count(len(spec.angles_deg), 'angle')}"
            + (f" + the held-out grid's {spec.held_out * len(spec.held_out_angles_deg)}" if spec.held_out else "")
            + f" = {entries} entries")


def _file_kind(file: str, error: ScenarioError) -> tuple[str, ScenarioError]:
    """What ``slewbench table``'s file is, for :func:`~scenarios.cli.commands.main`'s ``error in
    <kind>:`` of ``error``: ``table file`` (top-level ``table``), ``study file`` (``study``,
    refused) or ``scenario``; the file itself where it cannot be read as a mapping (a duplicate
    key), as ``validate`` names it; a ``table file`` where there is no file (``table file not
    found``). Returns the kind and the error to raise."""
    from scenarios.cli.commands import _named_once
    from scenarios.errors import ScenarioError
    from scenarios.schema.loader import OTHER_FILES
    from scenarios.schema.read import read_yaml
    if not Path(file).is_file():  # not found, or a directory: a table file in the command's terms
        return "table file", error
    try:
        data = read_yaml(file)
    except ScenarioError as unread:  # a duplicate key, a syntax error, no permission: named by the file, as
        return file, _named_once(unread, file)  # validate names it (its kind is not known)
    if not isinstance(data, dict):
        return file, error
    return next((f"{key} file" for key in OTHER_FILES if key in data), "scenario"), error


def command_table(args: argparse.Namespace) -> int:
    """Compute the table of ``args.file`` into ``args.out`` and print its fit's quality.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``table`` arguments (``file``, ``axes``, ``angles``, ``objective``,
        ``duration``, ``held_out``, ``tolerance``, ``check_angles``, ``max_axes``, ``max_rounds``,
        ``out``, ``workers``, ``scheduler``, ``no_plots``, ``strict``).

    Returns
    -------
    int
        0 when every entry is stored (entries that are not ok included: they are results); 1 when
        entries crashed or timed out (:data:`~scenarios.cli.status.EXIT_CRASHED`: they have no
        result; the files are written first), or with ``strict`` when an entry of the table or of its held-out
        grid is not ``ok`` (the files are written first); 130 when interrupted.

    Raises
    ------
    ScenarioError
        A bad file or option (exit 2; nothing written).
    OutputError
        An output directory slewbench must not write to (exit 2; nothing written).
    """
    from scenarios.errors import ScenarioError, SweepInterrupted
    from scenarios.output.directory import new_staging
    from scenarios.output.names import default_output_directory
    from scenarios.schema.table import TABLE_FLAGS
    from scenarios.slewtable.compute import compute_table, quality_lines
    from scenarios.slewtable.files import write_table_files
    from scenarios.slewtable.spec import parse_table_spec
    from scenarios.study.engine import (
        connect_scheduler,
        default_workers,
        start_forkserver,
    )
    from scenarios.study.store import claim_sweep_directory, commit_sweep_outputs

    if not args.scheduler:
        start_forkserver()
    # every flag of the table's keys (the key's reader checks its value, naming the flag)
    overrides = {flag[2:]: getattr(args, flag[2:].replace("-", "_")) for flag in TABLE_FLAGS.values()}
    try:
        spec = parse_table_spec(args.file, overrides)
    except ScenarioError as error:
        args.file_kind, named = _file_kind(args.file, error)  # how main() names it: the file's kind, not "table file"
        raise named from None
    if not args.no_plots:
        import matplotlib  # noqa: F401  (fail now, not after the entries ran)
    out = Path(args.out) if args.out else default_output_directory(f"table-{spec.name}")
    entries = len(spec.axes) * len(spec.angles_deg) + spec.held_out * len(spec.held_out_angles_deg)
    check_table_work(spec, entries, args.max_entries, args.angles)
    # the scheduler first: one that cannot be reached exits 2 with nothing written
    cluster = connect_scheduler(spec.scheduler, "--scheduler" if args.scheduler else "table.execution.scheduler") \
        if spec.scheduler else None
    try:
        directory = claim_sweep_directory(out, kind="table")  # the store beside the files
    except BaseException:
        if cluster is not None:
            cluster.close()
        raise
    print(f"{spec.name}: {_count(len(spec.axes), 'axis', 'axes')} x {_count(len(spec.angles_deg), 'angle')}"
          + (f" + {_count(spec.held_out, 'held-out axis', 'held-out axes')} x "
             f"{_count(len(spec.held_out_angles_deg), 'angle')} (the table's and their midpoints)" if spec.held_out else "")
          + f" = {entries} entries, {spec.objective}, {cluster.address if cluster else 'local process pool'}"
          + (f"; then refined to a tolerance of {spec.refine.tolerance:g} (at most {spec.refine.max_axes} axes, "
             f"{spec.refine.max_rounds} rounds)" if spec.refine else ""), flush=True)
    note = None if cluster else workers_note(spec.workers, default_workers(),  # --workers is in spec.workers
                                             "--workers" if args.workers is not None else "table.execution.workers", "entries")
    if note:
        print(note, flush=True)
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        table = compute_table(spec, directory, workers=args.workers, cluster=cluster, progress=True)
    except (SweepInterrupted, KeyboardInterrupt):
        print(f"slewbench: table interrupted; finished entries are stored in {directory}. Run the same command "
              "again to compute the rest.", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        signal.signal(signal.SIGTERM, previous)
        if cluster is not None:
            cluster.close()
    staging = new_staging(directory)
    start = time.perf_counter()
    write_table_files(table, staging, plots=not args.no_plots)
    files = commit_sweep_outputs(directory, staging, kind="table")
    again = [_count(count, words) for count, words in ((table.rerun, "crashed one"),
                                                          (table.rerun_timed_out, "timed-out one")) if count]
    rerun = f", {' and '.join(again)} run again" if again else ""
    print(f"computed in {table.wall_time_s:.1f} s ({table.stored} entries already stored{rerun}); table: "
          f"{entry_counts(table)}; files written in {time.perf_counter() - start:.1f} s: {directory}/ "
          f"({', '.join(sorted(files))})")
    if table.refinement:
        refinement = table.refinement
        for item in refinement["rounds"]:
            boundary = item.get("boundary", 0)  # said only when some were: a table whose entries all have a time has none
            across = f"{boundary} of them across the boundary of the entries without a time; " if boundary else ""
            largest = ("unbounded (a check where the entry or the fit has no time)" if item["max_miss"] is None
                       else f"{100 * item['max_miss']:.3g} %")
            print(f"refinement round {item['round']}: {item['checked']} midpoints checked, largest miss "
                  f"{largest}, {item['missed']} over the tolerance, {item['split']} triangles split "
                  f"({across}+{item['graded']} to keep the mesh graded), {item['axes']} axes, {item['solves']} entries "
                  "solved")
        print(f"refinement: {'reached' if refinement['reached'] else 'NOT reached'} at its check points "
              f"({refinement['stopped']}); {refinement['axes']} axes in the fit, {refinement['check_points']} check "
              "points outside it")
    if table.fit is None:
        print(no_fit_line(table.fit_note))
    else:
        quality = table.fit_quality
        lines = quality_lines(quality)
        if not quality.get("points"):
            why = "--held-out 0" if not spec.held_out else "every held-out point in a gap of the table"
            lines[0] = lines[0].replace("no held-out points", f"no held-out points ({why})")
        for line in lines:
            print(line)
        between = refinement_verdict(table.refinement, quality)
        if between:
            print(between)
        if table.fit_note:
            print(f"fit note: {table.fit_note}")
        print(f"use it: from scenarios.slewtable import load_fit; slew_time = load_fit('{directory / 'fit.json'}')")
    not_ok = _not_ok(table)
    if args.strict and not_ok:
        print(f"slewbench: --strict: {not_ok} not ok", file=sys.stderr)
    crashed = crashed_message(table, rerun_command(args, directory))
    if crashed:
        print(crashed, file=sys.stderr)
    timed_out = timed_out_message(table, spec.case_timeout_s, rerun_command(args, directory, {
        "--case-timeout": f"{_more_time(spec.case_timeout_s):g}"}))
    if timed_out:
        print(timed_out, file=sys.stderr)
    if crashed or timed_out:
        return EXIT_CRASHED
    return EXIT_NOT_OK if args.strict and not_ok else EXIT_OK


def no_fit_line(note: str) -> str:
    """The line that says why a table has no fit, from its ``fit_note``: the reason once.

    The note lists the entries not ok before the reason (``N entries not ok (...): the fit gives
    NaN in the cells around them ...; no fit: no entry is ok``): with no fit, the entry counts
    line says those, and the cells the note speaks of are not there. ``slewbench table`` printed
    ``no fit: <note>``, so "no fit" two or three times and a fit's cells that do not exist.

    Parameters
    ----------
    note : str
        :attr:`~scenarios.slewtable.compute.SlewTable.fit_note` of a table without a fit.

    Returns
    -------
    str
        ``no fit: <reason>`` (``no fit over the sphere: <reason>`` where that is the reason).
    """
    start = note.find("no fit")
    if start < 0:  # a reason of its own (a min_energy table is not fitted)
        return f"no fit: {note}"
    reason = note[start:]
    head, rest = reason[:len("no fit")], reason[len("no fit"):]
    return head + rest.replace(": no fit over the sphere", ", so none over the sphere").replace("no fit: ", "")


def refinement_verdict(refinement: dict[str, Any], quality: dict[str, Any]) -> str:
    """What the command says when a refinement reached its tolerance at its check points but the
    held-out grid, which it never saw, finds the fit missing by more: the checks are samples (edge
    midpoints at the check angles), not a bound on the error between them.

    Parameters
    ----------
    refinement : dict
        ``meta.refinement`` (:attr:`scenarios.slewtable.compute.SlewTable.refinement`); empty: none.
    quality : dict
        The fit's held-out errors (:func:`scenarios.slewtable.compute.held_out_errors`).

    Returns
    -------
    str
        ``fit: the refinement reached its tolerance 1 % at its check points, but the held-out error
        is +1.24 % ...``; empty without a refinement, without held-out points, or when the held-out
        error is within the tolerance.
    """
    if not refinement or not refinement.get("reached") or not quality.get("points"):
        return ""
    tolerance, error = refinement["tolerance"], quality["max_rel_error"]
    if error <= tolerance:
        return ""
    worst = quality["worst"]
    return (f"fit: the refinement reached its tolerance {100 * tolerance:g} % at its check points, but the held-out "
            f"error is {100 * worst['error']:+.3g} % at {worst['angle_deg']:g} deg: the checks sample the fit, they do "
            "not bound it between them (give a smaller --tolerance, and judge the fit by the held-out grid)")


def entry_counts(table: Any) -> str:
    """What the summary line says of the table's entries: how many are ok, the others by status,
    and how many of the ok ones are not the best known (:attr:`scenarios.slewtable.compute.TablePart.best_known`
    false; they are fitted); the held-out grid's flagged entries too.

    Parameters
    ----------
    table : SlewTable
        The computed table.

    Returns
    -------
    str
        ``3 of 4 entries ok (1 crashed)``, ``8 of 8 entries ok, 4 of them not the best known (slower
        than a feasible slew the planner knows: best_known false in slew_table.csv; fitted, their time
        achievable)``.
    """
    part = table.parts["table"]
    ok = part.ok
    text = f"{int(ok.sum())} of {ok.size} entries ok"
    others = [status for row, flags in zip(part.status, ok.tolist()) for status, good in zip(row, flags)
              if not good]
    others = ["missing" if status == "ok" else status for status in others]  # ok without a finite time
    if others:
        text += " (" + ", ".join(f"{others.count(kind)} {kind}" for kind in dict.fromkeys(others)) + ")"
    slower = int(part.not_best_known.sum())
    held = table.parts.get("held_out")
    held_slower = 0 if held is None else int(held.not_best_known.sum())
    if slower or held_slower:
        where = (f", {slower} of them not the best known" if slower else "") + \
            (f"; {_count(held_slower, 'ok held-out entry', 'ok held-out entries')} not the best known"
             if held_slower else "")
        text += (f"{where} (slower than a feasible slew the planner knows: best_known false in slew_table.csv"
                 + ("; fitted, their time achievable)" if slower else ")"))
    return text


def crashed_message(table: Any, command: str) -> str:
    """What a table whose entries crashed says last (:func:`~scenarios.cli.status.crash_report`).

    Parameters
    ----------
    table : SlewTable
        The computed table (every grid: the table's, the held-out one, a refinement's check points).
    command : str
        The command that runs the crashed entries again (:func:`rerun_command`).

    Returns
    -------
    str
        The message; empty when no entry crashed.
    """
    reasons, total = [], 0
    for part in table.parts.values():
        for statuses, messages in zip(part.status, part.message):
            total += len(statuses)
            reasons += [message for status, message in zip(statuses, messages) if status == "crashed"]
    return crash_report(reasons, total, ("entry", "entries"), "slew_table.csv", "the fit has no time around them",
                        command, "raised or killed their worker")


def _more_time(limit_s: float) -> float:
    """The time limit the advice of a table whose entries timed out suggests [s]: twice ``limit_s``
    (rounded up to a whole second), within the key's bound."""
    from scenarios.schema.study import MAX_CASE_TIMEOUT_S
    return float(min(math.ceil(2.0 * limit_s), MAX_CASE_TIMEOUT_S))


def timed_out_message(table: Any, limit_s: float, command: str) -> str:
    """What a table whose entries ran out of their time limit says last (status ``timed_out``: the
    planner was still solving, no error; the engine runs them again, as crashed ones, when the table
    is run again into the same directory).

    Parameters
    ----------
    table : SlewTable
        The computed table (every grid).
    limit_s : float
        ``table.execution.case_timeout_s`` [s].
    command : str
        The command that runs them again with more time (:func:`rerun_command` with a larger
        ``--case-timeout``: a flag, so that it holds for a scenario given alone as for a table file).

    Returns
    -------
    str
        ``slewbench: N of M entries timed out ...`` with the limit, what it means and how to give
        them more time; empty when none timed out.
    """
    count, total = 0, 0
    for part in table.parts.values():
        for statuses in part.status:
            total += len(statuses)
            count += sum(status == "timed_out" for status in statuses)
    if not count:
        return ""
    return (f"slewbench: {count} of {_count(total, 'entry', 'entries')} timed out: the planner was still solving "
            f"when table.execution.case_timeout_s ({limit_s:g} s) ran out (no error, not a crash): they have no "
            "result (status timed_out in slew_table.csv; the fit has no time around them). Give them more time "
            "(--case-timeout, which wins over table.execution.case_timeout_s) and run again (the entries already "
            f"stored are kept), e.g. with twice the time:\n  {command}")


def rerun_command(args: argparse.Namespace, out: Path, changed: dict[str, str] | None = None) -> str:
    """The command that computes a table's missing and crashed entries again: the same file, the
    flags the user gave that set the table's keys (so that it asks for the same entries),
    ``--out`` the table's directory, ``--no-plots`` and ``--strict`` as given, each argument quoted
    for a POSIX shell.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``table`` arguments.
    out : Path
        The table's directory.
    changed : dict, optional
        Flags of :data:`~scenarios.schema.table.TABLE_FLAGS` -> the value the command gives them
        instead of the user's (``{"--case-timeout": "600"}``).

    Returns
    -------
    str
        ``slewbench table FILE [flags] --out DIR [--no-plots] [--strict]``.
    """
    from scenarios.schema.table import TABLE_FLAGS
    changed = changed or {}
    words = ["slewbench", "table", str(args.file)]
    for flag in TABLE_FLAGS.values():
        value = changed.get(flag, getattr(args, flag[2:].replace("-", "_"), None))
        if value is not None:
            words += [flag, str(value)]
    words += ["--out", str(out)]
    words += [flag for flag, given in (("--no-plots", args.no_plots), ("--strict", args.strict)) if given]
    return shlex.join(words)


def _not_ok(table: Any) -> str:
    """The entries of the table and of its held-out grid whose status is not ``ok``, counted by
    status (``3 of 14 table entries (2 failed, 1 infeasible)``); empty when every entry is ok. A
    refinement's check points that were not split are not entries of the table."""
    counts = []
    for name, words in (("table", "table"), ("held_out", "held-out")):
        part = table.parts.get(name)
        if part is None or not part.ok.size:
            continue
        statuses = [status if good else ("missing" if status == "ok" else status)
                    for row, flags in zip(part.status, part.ok.tolist()) for status, good in zip(row, flags)]
        bad = [status for status in statuses if status != "ok"]
        if bad:
            kinds = ", ".join(f"{bad.count(kind)} {kind}" for kind in dict.fromkeys(bad))
            counts.append(f"{len(bad)} of {len(statuses)} {words} entries ({kinds})")
    return "; ".join(counts)


def add_table_parser(commands: Any) -> None:
    """Add the ``table`` subcommand to the ``slewbench`` parser.

    Parameters
    ----------
    commands : Any
        The ``argparse`` sub-parsers object of ``slewbench`` (from ``add_subparsers``).
    """
    parser = commands.add_parser(
        "table", help="slew table: minimum slew time over eigen-axes and angles, CSV, NetCDF and a fast fit "
                      "slew_time(q0, qf)",
        epilog=f"exit status: {EXIT_OK} done (entries that failed or are not ok are results, stored with their "
               f"status); {EXIT_CRASHED} entries crashed or timed out (no result: the files are written, the message says the "
               f"command that runs them again), or under --strict, an entry of the table or its held-out grid not ok; "
               f"{EXIT_BAD_SCENARIO} bad scenario or table file, option, or output location (nothing written); "
               f"{EXIT_INTERRUPTED} interrupted (the finished entries are stored: run it again). The table file's "
               "keys: slewbench schema table")
    parser.add_argument("file", help="scenario YAML file, or a table file (top-level key 'table')")
    parser.add_argument("--axes", type=_integer, help="number of eigen-axes (default 40; a polytope grid takes the "
                                                      "nearest count it makes, at least its vertices and face "
                                                      "centres, and says so; fibonacci: exactly)")
    parser.add_argument("--grid", help="how the axes are spread: polytope (default: along the actuators' kinks) "
                                       "or fibonacci")
    parser.add_argument("--angles", help="slew angles [deg]: a comma-separated list (e.g. 30,90), or N, a count: "
                                         "N angles spread from 10 to 180 deg (default 10,30,60,90,120,150,180); "
                                         f"a count above {BARE_ANGLES} reads like degrees and needs --max-entries")
    parser.add_argument("--max-entries", type=int,
                        help=f"most entries (axes x angles) to compute; more are refused (default {MAX_ENTRIES})")
    parser.add_argument("--objective", help="min_time (default) or min_energy (needs --duration)")
    parser.add_argument("--duration", type=float, help="slew duration for min_energy [s]")
    parser.add_argument("--held-out", type=int, help="axes of the held-out grid the fit is measured on "
                                                     "(at every table angle and the midpoints; 0: none; default 0)")
    parser.add_argument("--tolerance", type=float,
                        help="refine the axes until the fit's misses at the triangles' edge midpoints are at most "
                             "this fraction of the slew time (e.g. 0.01; default: no refinement); samples, not a "
                             "bound: judge the fit by --held-out")
    parser.add_argument("--check-angles", help="with --tolerance: the table angles [deg] a midpoint is checked at "
                                               "first, comma-separated, or 'all' (default)")
    parser.add_argument("--max-axes", type=int, help="with --tolerance: axes at most (default 2000)")
    parser.add_argument("--max-rounds", type=int, help="with --tolerance: refinement rounds at most (default 8)")
    parser.add_argument("--out", type=directory_argument, help="output directory (default: results/table-<scenario name>)")
    parser.add_argument("--workers", type=int, help="entries at once (default: one per core)")
    parser.add_argument("--scheduler", help="Dask scheduler address (tcp://host:port) instead of local processes")
    parser.add_argument("--case-timeout", type=float, metavar="SECONDS",
                        help="wall time after which an entry's planner is stopped: the entry is then timed_out "
                             "(default 600)")
    parser.add_argument("--no-plots", action="store_true", help="skip agility_envelope.png")
    parser.add_argument("--strict", action="store_true",
                        help=f"exit {EXIT_NOT_OK} when any entry of the table or its held-out grid is not ok (failed, "
                             "violated, infeasible, timed_out, crashed), after writing the files (for continuous "
                             "integration)")
    parser.set_defaults(handler=command_table)
