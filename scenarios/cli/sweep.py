"""``slewbench sweep``: run a trade study into a directory, resume it, or redraw its report.

Everything that can fail before a case runs is checked first: the study and every case (exit 2,
nothing written), then the output directory (exit 2 if it is not slewbench's, already holds a
sweep and ``--resume`` was not given, or holds a sweep of an earlier slewbench, which ``--report``
still redraws). An interrupted sweep exits 130 and says how to resume.
"""
from __future__ import annotations

import argparse
import signal
import sys
import time
from pathlib import Path
from typing import Any

from scenarios.cli.status import EXIT_INTERRUPTED, EXIT_OK
from scenarios.errors import OutputError, ScenarioError, SweepInterrupted
from scenarios.output.directory import MARKER, read_manifest
from scenarios.output.names import default_output_directory
from scenarios.output.provenance import package_version
from scenarios.study.engine import SweepResults, start_forkserver, sweep
from scenarios.study.report import resolved_study
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import (
    EARLIER_FORMATS,
    STORE_NAME,
    SweepStore,
    claim_sweep_directory,
    is_sweep_store,
    store_format,
)


def _open_store(out: Path) -> SweepStore:
    try:
        return SweepStore(out)
    except Exception as error:  # sqlite3.Error, or a store of another format
        raise OutputError(out, f"cannot open the sweep store: {error}") from None


def _terminate(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


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
    OutputError
        The directory holds no slewbench sweep (a sweep of an earlier slewbench whose store is
        still readable is redrawn).
    """
    out = Path(args.report)
    if read_manifest(out) is None or not is_sweep_store(out):
        raise OutputError(out, f"holds no slewbench sweep ({STORE_NAME} and {MARKER} expected)")
    with SweepStore(out, create=False) as store:
        data, version = store.get_meta("study"), store.get_meta("version")
        records = store.records()
    study = parse_study(data, version=version)
    results = SweepResults(study, records)
    files = results.write(out, plots=not args.no_plots)
    print(f"redrew {out}/ ({', '.join(files)}) from {len(records)} stored case(s); {results.missing} missing")
    return EXIT_OK


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
        The exit status: 0 when every case is stored (failed rows included), 130 when the sweep
        was interrupted.

    Raises
    ------
    ScenarioError
        A bad study, case or option (exit 2; nothing written).
    OutputError
        An output directory slewbench must not or cannot write to (exit 2; nothing written).
    """
    if args.report:
        return command_report(args)
    if not args.file:
        raise ScenarioError("", "give a study file, or --report DIR")
    if not args.scheduler:
        start_forkserver()  # local workers' imports run while the study is expanded and checked
    study = load_study(args.file)
    if args.scheduler:
        study.execution.scheduler = args.scheduler
    if args.workers is not None and not 1 <= args.workers <= 1024:
        raise ScenarioError("--workers", f"expected 1 to 1024, got {args.workers}")
    if not args.no_plots:
        import scenarios.study.plots  # noqa: F401  (fail now, not after the cases ran)
    out = Path(args.out) if args.out else default_output_directory(study.name)
    earlier = store_format(out)
    if earlier in EARLIER_FORMATS:
        raise OutputError(out, f"holds a sweep written by an earlier slewbench ({STORE_NAME} format {earlier!r}); "
                               f"it takes no new cases: redraw its report with `slewbench sweep --report {out}`, "
                               "or choose another --out to run the study")
    if (out / STORE_NAME).exists() and not args.resume:
        raise OutputError(out, f"already holds a sweep ({STORE_NAME}); pass --resume to continue it, "
                               "--report to redraw it, or choose another --out")
    out = claim_sweep_directory(out)
    start = time.perf_counter()
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        with _open_store(out) as store:
            store.set_meta("study", resolved_study(study))
            store.set_meta("version", package_version())
            done = sum(case.key in store.keys() for case in study.cases)
            print(f"{study.name}: {len(study.cases)} cases"
                  + (f", {done} already stored" if done else "")
                  + f", {args.scheduler or study.execution.scheduler or 'local process pool'}", flush=True)
            results = sweep(study, workers=args.workers, store=store, progress=True)
    except SweepInterrupted as stop:
        resume = f"slewbench sweep {args.file} --out {out} --resume"
        print(f"slewbench: sweep interrupted; {stop.missing} of {stop.total} cases are missing "
              f"(finished cases are stored in {out / STORE_NAME}). Resume with:\n  {resume}", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        signal.signal(signal.SIGTERM, previous)
    files = results.write(out, plots=not args.no_plots)
    crashed = sum(record["status"] == "crashed" for record in results.records.values())
    failed = sum(any(r["status"] != "ok" for r in record["rows"]) for record in results.records.values())
    print(f"{len(study.cases)} cases in {time.perf_counter() - start:.1f} s ({failed} with a failed row, "
          f"{crashed} crashed); wrote {out}/ ({', '.join(files)})")
    return EXIT_OK


def add_sweep_parser(commands: Any) -> None:
    """Add the ``sweep`` subcommand to the ``slewbench`` parser.

    Parameters
    ----------
    commands : Any
        The ``argparse`` sub-parsers object of ``slewbench`` (from ``add_subparsers``).
    """
    parser = commands.add_parser("sweep", help="run a trade study (grid, zip, Monte Carlo) on many cases")
    parser.add_argument("file", nargs="?", help="study YAML file")
    parser.add_argument("--out", help="output directory (default: results/<study name>)")
    parser.add_argument("--workers", type=int, help="cases at once (default: execution.workers, else one per core)")
    parser.add_argument("--scheduler", help="Dask scheduler address (tcp://host:port) instead of local processes")
    parser.add_argument("--resume", action="store_true", help="skip the cases already stored in --out")
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    parser.add_argument("--report", metavar="DIR", help="redraw tables and plots of DIR from its store; run nothing")
    parser.set_defaults(handler=command_sweep)
