"""``slewbench sweep``: run a trade study into a directory, resume it, or redraw its report.

Everything that can fail before a case runs is checked first, and nothing is written until it
passes: the study and every case (exit 2), the options, the output directory (exit 2 if it is not
slewbench's, already holds a sweep and ``--resume`` was not given, holds another study's sweep
or one of this study with another definition, :func:`scenarios.study.store.check_resume`, or holds a
sweep of an earlier slewbench, which ``--report`` still redraws), and a Dask scheduler (it must answer as one and have
workers). A directory this command created is removed again if the sweep cannot start in it (a
full disk). An interrupted sweep exits 130 and says how to resume; one whose cases crashed (raised,
ran out of time or killed their worker) writes its tables, then exits 1 saying how many crashed,
why, and how to run them again.
"""
from __future__ import annotations

import argparse
import shlex
import shutil
import signal
import sqlite3
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from scenarios.cli.status import (
    EXIT_CRASHED,
    EXIT_INTERRUPTED,
    EXIT_OK,
    crash_report,
    directory_argument,
    workers_note,
)
from scenarios.errors import OutputError, ScenarioError, SweepInterrupted
from scenarios.output.directory import (
    HOSTS,
    MARKER,
    claimed_output_directory,
    written_files,
)
from scenarios.output.names import default_output_directory, suffix_note
from scenarios.output.provenance import package_version
from scenarios.output.tables import is_missing
from scenarios.output.writer import check_run_directory

if TYPE_CHECKING:  # the trade-study machinery is imported by the handlers: `slewbench run` does not load it
    from scenarios.cli.commands import StudyFindings
    from scenarios.study.engine import DaskCluster
    from scenarios.study.store import SweepStore
    from scenarios.study.types import Study

def _terminate(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def _check_interrupted(args: argparse.Namespace) -> None:
    """Raise ``KeyboardInterrupt`` if Ctrl-C or SIGTERM came (``args.interruption``, set by
    :func:`scenarios.cli.commands.main`), also one whose ``KeyboardInterrupt`` was lost on the way:
    raised inside CasADi while the study's cases were checked, it was swallowed or turned into
    another error, and the sweep ran on."""
    interruption = getattr(args, "interruption", None)
    if interruption is not None:
        interruption.check()


def command_report(args: argparse.Namespace) -> int:
    """Redraw tables and plots of ``args.report`` from its store, without running anything.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``sweep`` arguments (``report``, ``no_plots``).

    Returns
    -------
    int
        The exit status (0).

    Raises
    ------
    ScenarioError
        Given with a study file, ``--dry-run``, ``--resume``, ``--out``, ``--workers`` or
        ``--scheduler`` (exit 2; nothing written).
    OutputError
        The directory holds no slewbench sweep (a sweep of an earlier slewbench whose store is
        still readable is redrawn), or its store is damaged.
    """
    from scenarios.study.rerun import stored_results

    # each of these asks for something --report does not do (it redraws DIR in place, running nothing):
    # ignored, a --dry-run rewrote DIR's files and an --out's were written into DIR instead
    clashing = [name for name, given in (("a study file", args.file), ("--dry-run", args.dry_run),
                                         ("--resume", args.resume), ("--out", args.out),
                                         ("--workers", args.workers is not None),
                                         ("--scheduler", args.scheduler)) if given]
    if clashing:
        raise ScenarioError("--report", f"redraws the tables and plots of the stored sweep {args.report} in place "
                                        f"from its store, running nothing; it does not take {clashing[0]}"
                                        + (f" ({args.file})" if clashing[0] == "a study file" else ""))
    out = Path(args.report)
    results, _ = stored_results(out)
    earlier = written_files(out)
    files = results.write(out, plots=not args.no_plots, progress=True)
    crashed = sum(record.get("status") == "crashed" for record in results.records.values())
    print(f"redrew {out}/ ({', '.join(files)}) from {len(results.records)} stored case(s)"
          + (f" ({crashed} crashed: no result; `--resume` runs them again)" if crashed else "")
          + f"; {results.missing} missing")
    _say_removed(out, earlier)
    return EXIT_OK


CASE_FOLDER = HOSTS["sweep"]
"""The folder of a sweep directory that ``sweep DIR --case N`` writes case ``N`` into by default
(``DIR/cases/N``): the one a sweep's directory hosts other outputs in
(:data:`scenarios.output.directory.HOSTS`)."""


def command_case(args: argparse.Namespace) -> int:
    """Run case ``args.case`` of the sweep stored in ``args.file`` again, in full, and write it as a run.

    The case's resolved scenario comes from the stored study; the outputs (tables, time series,
    plots, ``report.html``) go to ``--out`` or ``DIR/cases/N``, a directory claimed as
    ``slewbench run`` claims its own. The re-run's rows are compared with the stored ones.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``sweep`` arguments (``file``: the sweep directory, ``case``, ``out``,
        ``no_plots``, ``renderer``).

    Returns
    -------
    int
        The exit status (0; rows that differ from the stored ones are reported, not an error).

    Raises
    ------
    ScenarioError
        Options that do not go with ``--case``, or a case the study does not have (exit 2).
    OutputError
        The directory holds no sweep, or the output directory cannot be claimed (exit 2).
    """
    from scenarios.study.rerun import rerun_case, row_differences, stored_results

    clashing = [name for name, given in (("--report", args.report), ("--resume", args.resume),
                                         ("--dry-run", args.dry_run), ("--workers", args.workers is not None),
                                         ("--scheduler", args.scheduler)) if given]
    if clashing:
        raise ScenarioError("--case", f"re-runs one stored case in this process; it does not take {clashing[0]}")
    if not args.file:
        raise ScenarioError("--case", "give the sweep directory: slewbench sweep DIR --case N")
    directory = Path(args.file)
    if directory.is_file():  # the study file, as without --case: the sweep is in its output directory
        raise ScenarioError("--case", f"re-runs a case of a stored sweep: give the sweep's output directory (its "
                                      f"--out), not the file {args.file}: slewbench sweep DIR --case N")
    results, version = stored_results(directory)
    cases = results.study.cases
    if not 0 <= args.case < len(cases):
        raise ScenarioError("--case", f"expected a case of the study, 0 to {len(cases) - 1}, got {args.case}")
    case = cases[args.case]
    out = Path(args.out) if args.out else directory / CASE_FOLDER / str(args.case)
    # before running: a long case is never lost at the end (a directory holding another scenario's run is refused)
    check_run_directory(out, str(case.scenario.get("name", "")))
    with claimed_output_directory(out):  # an interrupted or failing re-run withdraws the claim, as a run's
        varied = ", ".join(f"{path}={value}" for path, value in case.varied.items())
        print(f"{results.study.name}: case {case.index} (grid point {case.point}, seed {case.seed})"
              + (f": {varied}" if varied else ""), flush=True)
        if version != package_version():
            print(f"note: the sweep was stored by slewbench {version}; this is {package_version()}", flush=True)
        rerun = rerun_case(results, args.case, progress=lambda line: print(line, flush=True))
        print()
        print(rerun.to_terminal())
        rerun.write(out, plots=not args.no_plots, renderer=getattr(args, "renderer", None))
        print(f"\nwrote {out}/ (results.json, results.csv, results.md, timeseries/"
              f"{'' if args.no_plots else ', PNG plots, report.html'})")
    renamed = suffix_note([row.label for row in rerun.rows], "results.json and results.csv")
    if renamed:
        print(renamed)
    record = results.records.get(case.key)
    if record is None:
        print(f"case {case.index} is not stored in {directory}/ (the sweep did not run it yet): nothing to compare")
        return EXIT_OK
    differences = row_differences(record["rows"], rerun)
    if differences:
        print(f"the re-run differs from the stored case in {len(differences)} column(s):")
        for line in differences[:20]:
            print(f"  {line}")
    else:
        print(f"the re-run's rows equal the stored case's ({len(rerun.rows)} row(s), every metric and requirement "
              "column; planning times and reuse aside)")
    return EXIT_OK


def _say_removed(out: Path, earlier: set[str]) -> None:
    """Name the files of ``out`` that an earlier write left and this one removed (plots, with ``--no-plots``)."""
    removed = sorted(earlier - written_files(out))
    if removed:
        print(f"removed {len(removed)} file(s) of the earlier output in {out}/ that this one did not write: "
              + ", ".join(removed))


CHECKING_LINE_S = 1.0
"""Off a terminal, how long the cases' check runs before its first progress line [s]: a study checked
faster says nothing."""


def _checking(name: str, clock: Any = time.monotonic, doing: str = "checking", done: str = "checked") -> Any:
    """A progress callback for the cases' checks (``progress(checked, total)`` of
    :func:`scenarios.study.spec.parse_study`): a bar on a terminal; elsewhere a line
    (``NAME: checking 180 cases, 40 checked, 1.0 s elapsed``) once the check has taken
    :data:`CHECKING_LINE_S`, then at most every
    :data:`~scenarios.study.engine.PROGRESS_LINE_S`, and one when it is done if any was said.
    ``doing`` and ``done`` word another pass over the cases (the dry run's findings: ``judging``)."""
    from scenarios.study.engine import PROGRESS_LINE_S

    started = clock()
    terminal = sys.stderr.isatty()
    state: dict[str, Any] = {}

    def show(checked: int, total: int) -> None:
        if not terminal:
            elapsed = clock() - started
            if checked >= total:
                if "said" in state:
                    print(f"{name}: {total} cases {done} in {elapsed:.1f} s", file=sys.stderr, flush=True)
            elif elapsed - state.get("said", CHECKING_LINE_S - PROGRESS_LINE_S) >= PROGRESS_LINE_S:
                state["said"] = elapsed
                print(f"{name}: {doing} {total} cases, {checked} {done}, {elapsed:.1f} s elapsed", file=sys.stderr,
                      flush=True)
            return
        if "bar" not in state:
            from tqdm import tqdm
            state["bar"] = tqdm(total=total, unit="case", desc=f"{doing} {name[:30]}", file=sys.stderr, leave=False,
                                mininterval=0.5)
        state["bar"].update(checked - state["bar"].n)
        if checked >= total:
            state["bar"].close()

    return show


def _output(args: argparse.Namespace, study: Study) -> Path:
    """The output directory, checked without writing anything."""
    from scenarios.study.store import (
        EARLIER_FORMATS,
        FORMAT,
        STORE_NAME,
        check_resume,
        store_format,
    )

    out = Path(args.out) if args.out else default_output_directory(study.name)
    try:
        earlier = store_format(out)
        stored = (out / STORE_NAME).exists() or (out / STORE_NAME).is_symlink()
    except OSError as error:  # a name too long for the file system, a parent that is a file ...
        raise OutputError(out, f"cannot be used: {error.strerror or error}") from None
    if earlier in EARLIER_FORMATS:
        raise OutputError(out, f"holds a sweep written by an earlier slewbench ({STORE_NAME} format {earlier!r}); "
                               f"it takes no new cases: redraw its report with `slewbench sweep --report {out}`, "
                               "or choose another --out to run the study")
    if stored and not args.resume:
        raise OutputError(out, f"already holds a sweep ({STORE_NAME}); pass --resume to continue it, "
                               "--report to redraw it, or choose another --out")
    if stored and earlier == FORMAT:  # another file is refused where the directory is claimed
        check_resume(out, study)  # the same study, its definition unchanged
    return out


def _created(out: Path) -> tuple[Path | None, bool]:
    """What a claim of ``out`` would create: the topmost missing folder (None: ``out`` exists), and
    whether ``out`` is an empty directory now."""
    missing = None
    for folder in [out, *out.absolute().parents]:
        if folder.exists():
            break
        missing = folder
    empty = missing is None and out.is_dir() and not any(out.iterdir())
    return missing, empty


def _undo(out: Path, missing: Path | None, empty: bool) -> None:
    """Remove what a sweep that could not start wrote: the folders it created, or what it put into a
    directory that was empty."""
    from scenarios.study.store import STORE_FILES

    if missing is not None:
        shutil.rmtree(missing, ignore_errors=True)
    elif empty:
        for name in (MARKER, *STORE_FILES):
            (out / name).unlink(missing_ok=True)


def _open(out: Path, study: Study) -> tuple[Path, SweepStore]:
    """Claim the directory and open the store with the study in it; on failure (a full disk) or
    Ctrl-C, undo."""
    from scenarios.study.report import resolved_study
    from scenarios.study.store import SweepStore, claim_sweep_directory, mark_incomplete

    missing, empty = _created(Path(out).absolute())
    try:
        directory = claim_sweep_directory(out)
        # the tables there (a resumed sweep's) stop describing the store from here: incomplete until rewritten
        mark_incomplete(directory)
        store = SweepStore(directory)
        try:
            store.set_meta("study", resolved_study(study))
            store.set_meta("version", package_version())
        except BaseException:
            store.close()
            raise
    except (OutputError, KeyboardInterrupt):
        _undo(Path(out).absolute(), missing, empty)
        raise
    except (OSError, ValueError, sqlite3.Error) as error:  # sqlite3.Error, or a store of another format
        _undo(Path(out).absolute(), missing, empty)
        raise OutputError(out, f"cannot start the sweep store: {getattr(error, 'strerror', None) or error}; nothing "
                               "was left behind") from None
    return directory, store


def command_sweep(args: argparse.Namespace) -> int:
    """Run (or resume) the study ``args.file``, or redraw a report (``args.report``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``sweep`` arguments (``file``, ``out``, ``workers``, ``scheduler``,
        ``resume``, ``no_plots``, ``report``).

    Returns
    -------
    int
        The exit status: 0 when every case is stored and none crashed (failed rows included: they
        are results), 1 when some crashed (:data:`~scenarios.cli.status.EXIT_CRASHED`; the tables
        are written), 130 when the sweep was interrupted (or its Dask cluster lost every worker).

    Raises
    ------
    ScenarioError
        A bad study, case, option or scheduler (exit 2; nothing written).
    OutputError
        An output directory slewbench must not or cannot write to (exit 2; nothing written), or a
        store that cannot be written while the sweep runs (the cases stored so far are kept).
    """
    from scenarios.study.engine import connect_scheduler, reachable, start_forkserver
    from scenarios.study.spec import load_study

    if args.case is not None:
        return command_case(args)
    if args.report:
        return command_report(args)
    if not args.file:
        raise ScenarioError("", "give a study file, or --report DIR")
    if args.workers is not None and not 1 <= args.workers <= 1024:
        raise ScenarioError("--workers", f"expected 1 to 1024, got {args.workers}")
    # Ctrl-C (or SIGTERM) before the first case: nothing is run or written, and the message says so
    # and where the sweep was (also when CasADi turned the KeyboardInterrupt into another error)
    phase = "while it started"
    try:
        try:
            scheduler = args.scheduler
            if not scheduler:
                start_forkserver()  # local workers' imports run while the study is expanded and checked
            elif not args.dry_run:  # a closed port is refused now, not after the cases are checked
                phase = f"while it connected to the Dask scheduler {scheduler}"
                reachable(scheduler, "--scheduler")
            phase = "while its cases were checked"
            found = None
            if args.dry_run:  # the cases' findings, from the loader's parse where the check parsed the case
                from scenarios.cli.commands import StudyFindings
                found = StudyFindings()
            def early_scheduler(execution: Any) -> None:  # execution.scheduler: refused before the cases too
                nonlocal phase
                if execution.scheduler and not scheduler and not args.dry_run:
                    phase = f"while it connected to the Dask scheduler {execution.scheduler}"
                    reachable(execution.scheduler, "execution.scheduler")
                    phase = "while its cases were checked"

            study = load_study(args.file, progress=_checking(Path(args.file).stem), parsed=found,
                               execution_read=early_scheduler)
            _check_interrupted(args)  # one that CasADi swallowed
            phase = "before its first case"
            if args.dry_run:
                if args.resume:  # what the real resume would refuse, it refuses (nothing is written either way)
                    _output(args, study)
                _list_cases(study, args.workers or study.execution.workers or _local_workers(), found,
                            local=not (scheduler or study.execution.scheduler), option=_workers_option(args),
                            name=Path(args.file).stem)
                return EXIT_OK
            where = "--scheduler" if scheduler else "execution.scheduler"
            scheduler = scheduler or study.execution.scheduler
            if not args.no_plots:
                import scenarios.study.plots  # noqa: F401  (fail now, not after the cases ran)
            out = _output(args, study)
            if scheduler:
                phase = f"while it connected to the Dask scheduler {scheduler}"
            cluster: DaskCluster | None = connect_scheduler(scheduler, where) if scheduler else None
        except Exception:
            _check_interrupted(args)  # a Ctrl-C that CasADi turned into an error
            raise
    except KeyboardInterrupt:  # an interrupted sweep exits 130, before its cases too
        print(f"slewbench: sweep interrupted {phase}; nothing was run or written", file=sys.stderr)
        return EXIT_INTERRUPTED
    try:
        return _run(args, study, out, cluster)
    finally:
        if cluster is not None:
            cluster.close()


DRY_RUN_SHOWN = 50
"""Cases ``sweep --dry-run`` lists one per line (the others are counted)."""


def _cluster_threads(cluster: DaskCluster | None) -> int | None:
    """The cluster's worker threads now, for the size note (``None``: no cluster, or it does not
    answer: a note never stops a sweep)."""
    if cluster is None:
        return None
    try:
        return cluster.workers()
    except Exception:  # noqa: BLE001 (the scheduler's answer only sizes a note)
        return None


def _local_workers() -> int:
    """The workers of a local pool by default (one per core available)."""
    from scenarios.study.engine import default_workers

    return default_workers()


def _workers_option(args: argparse.Namespace) -> str:
    """Where the number of workers was given: ``--workers``, else the study's ``execution.workers``."""
    return "--workers" if args.workers is not None else "execution.workers"


def _say_workers(workers: int | None, option: str) -> None:
    """Print :func:`~scenarios.cli.status.workers_note` for a local pool of ``workers``."""
    note = workers_note(workers, _local_workers(), option, "cases")
    if note:
        print(note, flush=True)


def _list_cases(study: Study, workers: int, found: StudyFindings | None = None, local: bool = True,
                option: str = "--workers", name: str | None = None) -> None:
    """Print what ``sweep`` would run: the checked cases and their varied values (nothing written),
    for a large study how to estimate its time (:func:`scenarios.study.spec.size_note`), and what
    ``validate`` finds in the cases (:func:`scenarios.cli.commands.study_findings`: a case whose
    rows cannot be ok, such as a slew longer than ``maneuver.duration`` by a planner's
    ``least_duration``; plausibility warnings)."""
    from scenarios.cli.commands import print_findings, study_findings
    from scenarios.study.spec import noise_note, size_note

    varied = [*study.grid_paths, *study.mc_paths]
    print(f"{study.name}: {len(study.cases)} cases, checked; nothing run, nothing written"
          + (f"; varying {', '.join(varied)}" if varied else ""))
    for note in (size_note(study, workers), noise_note(study)):
        if note:
            print(note)
    if local:
        _say_workers(workers, option)
    for case in study.cases[:DRY_RUN_SHOWN]:
        values = ", ".join(f"{path}={value}" for path, value in case.varied.items())
        print(f"  case {case.index} (grid point {case.point}, seed {case.seed}, key {case.key[:12]})"
              + (f": {values}" if values else ""))
    if len(study.cases) > DRY_RUN_SHOWN:
        print(f"  ... and {len(study.cases) - DRY_RUN_SHOWN} more")
    # what `validate` says of the cases, said the same way (a large study's take a while: said as its check is)
    findings = study_findings(study, found, _checking(name or study.name, doing="judging", done="judged"))
    if findings:
        print(f"{len(findings)} finding(s), as `slewbench validate` says them (cases whose rows cannot be ok, "
              "a slew longer than maneuver.duration among them; plausibility warnings):")
        print_findings(findings)


def resume_command(args: argparse.Namespace, out: Path) -> str:
    """The command that resumes an interrupted sweep: the study file, ``--out``, ``--resume`` and the
    options the user gave that change how it runs (``--workers``, ``--scheduler``, ``--no-plots``),
    each argument quoted for a POSIX shell (a path with a space).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``sweep`` arguments.
    out : Path
        The sweep's directory.

    Returns
    -------
    str
        ``slewbench sweep FILE --out DIR --resume [--workers N] [--scheduler ADDRESS] [--no-plots]``.
    """
    words = ["slewbench", "sweep", str(args.file), "--out", str(out), "--resume"]
    if args.workers is not None:
        words += ["--workers", str(args.workers)]
    if args.scheduler:
        words += ["--scheduler", args.scheduler]
    if args.no_plots:
        words.append("--no-plots")
    return shlex.join(words)


def _run(args: argparse.Namespace, study: Study, out: Path, cluster: DaskCluster | None) -> int:
    from scenarios.study.engine import sweep
    from scenarios.study.report import (
        collapse_note,
        requirement_lines,
        requirement_table,
        robustness_tables,
    )
    from scenarios.study.robustness import crashed_counts, robustness_lines
    from scenarios.study.spec import LARGE_STUDY, noise_note, size_note
    from scenarios.study.store import STORE_NAME, SweepStore, resume_counts

    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        out, store = _open(out, study)
    except KeyboardInterrupt:
        signal.signal(signal.SIGTERM, previous)
        print("slewbench: sweep interrupted before its first case; nothing was run", file=sys.stderr)
        return EXIT_INTERRUPTED
    start = time.perf_counter()
    try:
        with store:
            _check_interrupted(args)
            counts = resume_counts(store, (case.key for case in study.cases))  # crashed cases run again
            done = counts.kept
            print(f"{study.name}: {len(study.cases)} cases" + counts.describe()
                  + f", {cluster.address if cluster else 'local process pool'}", flush=True)
            for note in counts.notes():  # stored cases of an earlier version of the study
                print(note, flush=True)
            size = None if len(study.cases) <= LARGE_STUDY else size_note(
                study, args.workers or _cluster_threads(cluster) or study.execution.workers or _local_workers())
            for said in (size, noise_note(study)):
                if said:
                    print(said, flush=True)
            if cluster is None:
                _say_workers(args.workers or study.execution.workers, _workers_option(args))
            results = sweep(study, workers=args.workers, store=store, progress=True, cluster=cluster)
        _check_interrupted(args)  # a Ctrl-C lost on the way: the sweep's tables are not written
    except (SweepInterrupted, KeyboardInterrupt) as stop:  # KeyboardInterrupt: before the sweep took over
        if isinstance(stop, KeyboardInterrupt):
            with SweepStore(out, create=False) as stored:
                stop = SweepInterrupted(len({case.key for case in study.cases} - stored.keys()), len(study.cases))
        resume = resume_command(args, out)
        print(f"slewbench: sweep {'stopped: ' + stop.reason if stop.reason else 'interrupted'}; {stop.missing} of "
              f"{stop.total} cases are missing (finished cases are stored in {out / STORE_NAME}). Resume with:\n"
              f"  {resume}", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (sqlite3.Error, OSError) as error:  # the store could not take a case (a full disk)
        raise OutputError(out, f"the sweep store could not be written ({error}); the cases stored so far are "
                               f"kept: free some space and resume with `{resume_command(args, out)}`") from None
    finally:
        signal.signal(signal.SIGTERM, previous)
    earlier = written_files(out)
    try:
        files = results.write(out, plots=not args.no_plots, progress=True)
    except KeyboardInterrupt:
        print(f"slewbench: sweep interrupted while its tables were written; every case is stored in "
              f"{out / STORE_NAME} and the directory is marked incomplete. Write them with:\n"
              f"  {shlex.join(['slewbench', 'sweep', '--report', str(out)])}", file=sys.stderr)
        return EXIT_INTERRUPTED
    records = results.records.values()
    crashed = sum(record["status"] == "crashed" for record in records)
    not_ok = sum(record["status"] != "crashed" and any(r["status"] != "ok" for r in record["rows"])
                 for record in records)
    ran = len(study.cases) - done
    others = f"{not_ok} other{' has' if not_ok == 1 else 's have'} a row not ok"  # crashed cases are not counted again
    print(f"{ran} case{'s' if ran != 1 else ''} run in {time.perf_counter() - start:.1f} s"
          + (f" ({done} already stored, {len(study.cases)} in all)" if done else "")
          + f"; of the {len(records)} cases stored, {crashed} crashed and {others}; wrote {out}/ ({', '.join(files)})")
    _say_removed(out, earlier)
    rows = results.table()[1]
    labels: dict[Any, list[str]] = {}
    for row in rows:  # each case's rows (the same labels in every case, but for a study that varies one)
        labels.setdefault(row["case"], []).append(row["label"])
    for renamed in dict.fromkeys(suffix_note(case, "cases.csv") for case in labels.values()):
        if renamed:
            print(renamed)
    for said in (collapse_note(study), _final_note(study, rows)):
        if said:
            print(said)
    print("requirements (cases meeting each, of those scored; requirements.csv):")
    print("\n".join(requirement_lines(requirement_table(study, rows))))
    tables = robustness_tables(study, rows)
    if tables is not None:
        proportions, _, worst = tables
        print("robustness (fraction of the completed cases, Wilson 95 % interval; robustness.csv, "
              "sensitivity.csv, worst_cases.csv):")
        print("\n".join(robustness_lines(proportions, worst, crashed_counts(study, rows))))
        print(f"re-run a case in full: slewbench sweep {shlex.quote(str(out))} --case N")
    if crashed:
        print(crashed_message(list(records), len(study.cases), resume_command(args, out)), file=sys.stderr)
        return EXIT_CRASHED
    return EXIT_OK


def crashed_message(records: list[dict[str, Any]], total: int, resume: str) -> str:
    """What a sweep whose cases crashed says last (:func:`~scenarios.cli.status.crash_report`).

    Parameters
    ----------
    records : list of dict
        The stored records of the study's cases (``status``, ``rows``), crashed ones among them.
    total : int
        The study's number of cases.
    resume : str
        The command that runs the crashed cases again (:func:`resume_command`).

    Returns
    -------
    str
        The message, each crashed case's reason its first row's message.
    """
    reasons = [next((str(row.get("message") or "") for row in record["rows"]), "")
               for record in records if record["status"] == "crashed"]
    return crash_report(reasons, total, ("case", "cases"), "cases.csv", "the statistics and plots leave them out",
                        resume)


def _final_note(study: Study, rows: list[dict[str, Any]]) -> str | None:
    """:func:`scenarios.runner.final_accuracy_note` of the rows whose case states no ``requirements.final``."""
    from ocp.metrics import DEFAULT_SETTLING_TOLERANCE_DEG
    from scenarios.runner import final_accuracy_note

    cases = {case.index: case.scenario for case in study.cases}
    ends = []
    for row in rows:
        scenario = cases[row["case"]]
        if (scenario.get("requirements") or {}).get("final") is None:
            band = (scenario.get("simulation") or {}).get("settling_tolerance_deg") or DEFAULT_SETTLING_TOLERANCE_DEG
            error = row.get("cl.final_error_deg")
            ends.append((None if is_missing(error) else error, float(band)))
    return final_accuracy_note(ends, len(rows))


def add_sweep_parser(commands: Any) -> None:
    """Add the ``sweep`` subcommand to the ``slewbench`` parser.

    Parameters
    ----------
    commands : Any
        The ``argparse`` sub-parsers object of ``slewbench`` (from ``add_subparsers``).
    """
    parser = commands.add_parser("sweep", help="run a trade study (grid, zip, Monte Carlo) on many cases")
    parser.add_argument("file", nargs="?", help="study YAML file (with --case: the sweep directory)")
    parser.add_argument("--out", type=directory_argument, help="output directory (default: results/<study name>)")
    parser.add_argument("--workers", type=int, help="cases at once (default: execution.workers, else one per core)")
    parser.add_argument("--scheduler", help="Dask scheduler address (tcp://host:port) instead of local processes")
    parser.add_argument("--resume", action="store_true",
                        help="skip the cases already stored in --out; crashed cases run again")
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG plots and report.html")
    parser.add_argument("--dry-run", action="store_true",
                        help="check the study and list its cases; run nothing, write nothing")
    parser.add_argument("--report", metavar="DIR", type=directory_argument, help="redraw tables and plots of DIR from its store; run nothing")
    parser.add_argument("--case", metavar="N", type=int,
                        help="re-run case N of the sweep stored in DIR (given as the first argument) in full, "
                             "writing a run's outputs into --out (default: DIR/cases/N)")
    parser.set_defaults(handler=command_sweep)
