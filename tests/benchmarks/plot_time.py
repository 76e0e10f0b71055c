"""Plot time does not grow (issue 31): ``slewbench run scenarios/eigenaxis_demo.yaml`` with its
plots, this checkout against an earlier commit, side by side. The command is the console script's
own entry point (:func:`scenarios.console.main`, which starts the plot process), run from each
checkout; ``python -m scenarios.cli`` has no plot process and draws in the run's process.

The earlier commit is checked out into a temporary ``git worktree`` (removed at the end). The two
commands alternate, the first of each pair alternating too, so that a change in the host's speed
(the shared VM's moves by 1.5x within a minute, ``host_speed.py``) falls on both alike. One
warm-up run of each fills the caches. Each run is also repeated with ``--no-plots``, in the same
alternation, to give the plots' own share. The load average is printed before and after.

Run: ``python tests/benchmarks/plot_time.py [--base REV] [--pairs N]`` (defaults ``main``, 8);
per kind of run, wall and CPU time (user + system of the command): medians, 10th and 90th
percentiles and the ratio of the medians (target: wall time of the whole command with plots, this
checkout over the base, at most 1.1; the CPU time is less sensitive to a loaded host).

Measured on 2026-12-02 on a quiet host (``--base 5e90e69 --pairs 12``, load average 0.4-1.2, twice):
with plots 1.296 s at the base against 1.233 s (ratio of the medians 0.951; per pair 0.969,
10th-90th percentile 0.879-1.121), CPU 2.053 s against 2.102 s (1.024); without plots 0.920 (CPU
0.837); the second run 1.333 s against 1.287 s (0.965; per pair 0.968, 0.806-1.106; CPU 1.052;
without plots 0.870). Target met. At load 3.1-3.7 (another job on the two cores) 1.083 (per pair
1.025, CPU 1.071) and 1.161 (per pair 1.016, CPU 1.093): under load the ratio of the medians moves
more than the per-pair ratio. Earlier that day, before ``scipy.linalg`` was imported lazily and
at load 4.3-6.8, 1.186; at the start of the day (before the PNG writer, the plot process's helper
and the report's batching) 1.337 with plots and 1.186 without (10 pairs, load 0.8-5.8). The
parts: docs/performance.rst.
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = Path("scenarios") / "eigenaxis_demo.yaml"
CONSOLE = "import sys; from scenarios.console import main; sys.exit(main())"
"""The ``slewbench`` console script (``[project.scripts]``), run from a checkout."""
TARGET_RATIO = 1.1
"""Largest ratio of the medians (with plots, this checkout over the base) that meets the target."""


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed_run(checkout: Path, out: Path, plots: bool) -> tuple[float, float]:
    """Wall time and CPU time (user + system) [s] of one ``run`` of the demo scenario in ``checkout``."""
    command = [sys.executable, "-c", CONSOLE, "run", str(SCENARIO), "--out", str(out)]
    command += [] if plots else ["--no-plots"]
    cpu, start = _children_cpu(), time.perf_counter()
    done = subprocess.run(command, cwd=checkout, capture_output=True, text=True, check=False)
    elapsed, cpu = time.perf_counter() - start, _children_cpu() - cpu
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} in {checkout} exited {done.returncode}:\n{done.stderr[-2000:]}")
    return elapsed, cpu


def compare(base: Path, new: Path, pairs: int, scratch: Path) -> dict[tuple[str, bool], list[tuple[float, float]]]:
    """Alternate the runs: per pair, both checkouts with and without plots, in alternating order."""
    times: dict[tuple[str, bool], list[tuple[float, float]]] = {(name, plots): [] for name in ("base", "new")
                                                                for plots in (True, False)}
    checkouts = {"base": base, "new": new}
    for name, checkout in checkouts.items():  # warm-up: caches
        timed_run(checkout, scratch / f"warm-{name}", True)
    for pair in range(pairs):
        order = ["base", "new"] if pair % 2 == 0 else ["new", "base"]
        for plots in (True, False) if pair % 2 == 0 else (False, True):
            for name in order:
                times[(name, plots)].append(timed_run(checkouts[name], scratch / f"{name}-{pair}-{plots}", plots))
    return times


def summary(times: dict[tuple[str, bool], list[tuple[float, float]]]) -> tuple[list[str], float]:
    """Lines of medians, spreads and ratios (wall time, then CPU time), and the ratio of the wall
    time medians with plots."""
    lines = []
    ratios = {}
    for column, what in ((0, "wall"), (1, "CPU ")):
        medians = {}
        for plots in (True, False):
            for name in ("base", "new"):
                values = np.asarray([t[column] for t in times[(name, plots)]])
                medians[(name, plots)] = float(np.median(values))
                p10, p90 = np.percentile(values, (10, 90))
                kind = "with plots" if plots else "no plots  "
                lines.append(f"{what} {kind} {name:4s}: median {np.median(values):.3f} s, "
                             f"p10 {p10:.3f} s, p90 {p90:.3f} s, n {values.size}")
            ratio = medians[("new", plots)] / medians[("base", plots)]
            ratios[(column, plots)] = ratio
            lines.append(f"{what} {'with plots' if plots else 'no plots  '} ratio new/base of the medians: {ratio:.3f}")
        per_pair = (np.asarray([t[column] for t in times[("new", True)]])
                    / np.asarray([t[column] for t in times[("base", True)]]))
        lines.append(f"{what} with plots, ratio per pair: median {np.median(per_pair):.3f}, "
                     f"p10 {np.percentile(per_pair, 10):.3f}, p90 {np.percentile(per_pair, 90):.3f}")
        lines.append(f"{what} plots' own share (median with - median without): "
                     f"base {medians[('base', True)] - medians[('base', False)]:.3f} s, "
                     f"new {medians[('new', True)] - medians[('new', False)]:.3f} s")
    return lines, ratios[(0, True)]


def main(argv: list[str] | None = None) -> float:
    """Run the comparison and print it.

    Parameters
    ----------
    argv : list of str, optional
        ``--base REV`` (the commit to compare with; default ``main``) and ``--pairs N`` (default 8).

    Returns
    -------
    float
        The ratio of the medians with plots, this checkout over the base.
    """
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="main", help="the commit to compare with (default main)")
    parser.add_argument("--pairs", type=int, default=8, help="alternating pairs (default 8)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="slewbench-plot-time-") as scratch_name:
        scratch = Path(scratch_name)
        base = scratch / "base"
        subprocess.run(["git", "worktree", "add", "--detach", str(base), args.base], cwd=ROOT, check=True,
                       capture_output=True)
        try:
            commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=base, capture_output=True,
                                    text=True, check=True).stdout.strip()
            print(f"base {args.base} ({commit}) against {ROOT}; {os.cpu_count()} CPUs, "
                  f"load average before {os.getloadavg()}", flush=True)
            times = compare(base, ROOT, args.pairs, scratch)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(base)], cwd=ROOT, check=False,
                           capture_output=True)
    lines, ratio = summary(times)
    print("\n".join(lines))
    verdict = "met" if ratio <= TARGET_RATIO else "NOT met"
    print(f"load average after {os.getloadavg()}; target ratio <= {TARGET_RATIO}: {verdict}")
    return ratio


if __name__ == "__main__":
    main()
