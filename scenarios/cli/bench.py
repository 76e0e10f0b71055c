"""``slewbench bench``: run the benchmark suite (or some of its problems) through every planner that
applies and the installed peers, and write the leaderboard (Markdown, CSV, JSON and a plot of the
gap to the best known optimum against plan time).

Names are checked before anything runs (an unknown problem, planner or peer exits 2), and the
output directory is claimed before the first problem runs, so a long run is never lost at the end.
"""
from __future__ import annotations

import argparse
import sys
from typing import Any

from scenarios.cli.status import EXIT_OK, directory_argument

__all__ = ["add_bench_parser", "command_bench"]

DEFAULT_OUT = "bench"
"""The default output directory's name (``results/bench``)."""


def command_bench(args: argparse.Namespace) -> int:
    """Run the suite and write the leaderboard.

    Parameters
    ----------
    args : argparse.Namespace
        ``problems`` and ``planners`` (lists or ``None``), ``out``, ``no_peers``, ``no_plots``.

    Returns
    -------
    int
        The exit status (0; failed rows are results).

    Raises
    ------
    ScenarioError
        An unknown problem, planner or peer name (exit 2).
    OutputError
        The output directory is not slewbench's, or holds another command's output (exit 2).
    """
    from planners import PLANNERS
    from planners.errors import UnknownNameError
    from scenarios.bench import load_suite
    from scenarios.bench.leaderboard import run_bench
    from scenarios.bench.peers import PEERS
    from scenarios.errors import ScenarioError
    from scenarios.output.directory import claim_output_directory
    from scenarios.output.names import default_output_directory

    suite = load_suite()
    problems = args.problems or list(suite.problems)
    unknown = [name for name in problems if name not in suite.problems]
    if unknown:
        raise ScenarioError("--problems", str(UnknownNameError("problem", unknown[0], suite.problems)))
    for flag, names in (("--problems", args.problems or []), ("--planners", args.planners or [])):
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:  # a problem named twice ran twice: two identical rows in the leaderboard and its medians
            raise ScenarioError(flag, f"{twice[0]!r} is given {names.count(twice[0])} times; give each name once")
    peers = [] if args.no_peers else list(PEERS)
    planners = None
    if args.planners:
        unknown = [name for name in args.planners if name not in PLANNERS and name not in PEERS]
        if unknown:
            raise ScenarioError("--planners", str(UnknownNameError("planner or peer", unknown[0], [*PLANNERS, *PEERS])))
        planners = [name for name in args.planners if name in PLANNERS]
        if args.no_peers and not planners:
            raise ScenarioError("--planners", f"names only peers ({', '.join(args.planners)}) and --no-peers runs none: "
                                              "nothing would run")
        peers = [name for name in peers if name in args.planners]
    out = args.out or default_output_directory(DEFAULT_OUT)
    claim_output_directory(out, kind="bench")  # before running: a long run is never lost at the end
    print(f"slewbench bench: suite version {suite.version}, {len(problems)} problem(s)"
          + (f", peers {', '.join(peers)}" if peers else ", no peers"), flush=True)
    board = run_bench(suite, problems, planners, peers, progress=lambda line: print(line, flush=True))
    files = board.write(out, plots=not args.no_plots)
    print(f"{len(board.rows)} row(s), {board.reached_text()}, in {board.wall_time_s:.1f} s")
    for note in board.notes:
        print(f"note: {note}")
    print(f"wrote {out}/ ({', '.join(sorted(files))})")
    sys.stdout.flush()
    return EXIT_OK


def add_bench_parser(commands: Any) -> None:
    """Add the ``bench`` subcommand to the ``slewbench`` parser.

    Parameters
    ----------
    commands : Any
        The ``argparse`` sub-parsers object of ``slewbench`` (from ``add_subparsers``).
    """
    parser = commands.add_parser("bench", help="run the benchmark suite and write a leaderboard against the best "
                                               "known optima")
    parser.add_argument("--problems", nargs="+", metavar="NAME", help="only these problems of the suite (default: all)")
    parser.add_argument("--planners", nargs="+", metavar="NAME",
                        help="only these planners (registry names) and peers (fatrop, rockit, acados) "
                             "(default: every planner row of each problem and every installed peer)")
    parser.add_argument("--out", type=directory_argument, help=f"output directory (default: results/{DEFAULT_OUT})")
    parser.add_argument("--no-peers", action="store_true", help="run no peer")
    parser.add_argument("--no-plots", action="store_true", help="skip gap_vs_time.png")
    parser.set_defaults(handler=command_bench)
