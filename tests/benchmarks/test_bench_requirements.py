"""What scoring every requirement costs: at most 60 % of the run without it (budget
OVERHEAD_BUDGET).

Issue 27 set 10 % of a run's wall time, met while every requirement was scored at the samples
alone. Scoring between the samples (pointing, final error) and the demand's Runge-Kutta sub-steps
took it to +69..89 % (fcaf45b); one search over all intervals with a true rate bound, the models'
mapped functions built once, and a row's searches zoomed together brought it to about +30 %
(03fa46d: +29 %, median of 4 runs). History and profiles: docs/performance.rst
("Scoring requirements between the samples").

Measured on 2026-12-03 (load 3.4-8 on 2 cores), against 60119e1: this benchmark run alternately on
both (15 pairs a run, wall): +28.2, +19.1, +26.9, +26.9 % (median 26.9 %) against +20.1, +18.8,
+23.9, +25.5 % on 60119e1 (median 22.0 %): not resolved. CPU, four alternate processes of 10 pairs
each: overhead +23.0, +19.0, +20.4, +18.5 % against +26.6, +14.4, +19.3, +25.0 %; the scoring
calls' own CPU 46-55 ms a run against 51-66 ms. The pointing scores alone (one process taking
60119e1's module and this one in turn, 100 and 150 pairs): paired ratio 0.966 and 0.972, the 18
scores bit for bit. The 10 % target is not met; the scoring's CPU a run (about 50 ms) is the
pointing searches about 20 ms (NumPy call overhead: some 90 margin evaluations of 60-1300 points,
35 array operations each), the actuator demand about 12 ms, the environment's torque about 6 ms and
the unrealised torque about 2.4 ms (CasADi evaluation through
``controllers.allocation.model_rows``), the interpolants about 2.5 ms. The budget (1.25 times the
largest run seen before the last changes) guards against the search's old cost returning.

Measured on 2026-12-03 (load 4.0-5.6 on 2 cores), against 382b1fd, after the environment's torque
was evaluated once a reference (the demand's closed form takes the scorer's), the free start's
second demand asked only where a broken quantity's message needs it, and ``model_rows`` kept its
buffers and evaluated the rows past the last whole chunk by a smaller map: this benchmark run
alternately on both (15 pairs a run, wall): +20.8, +22.1, +22.9, +20.7 % (median 21.5 %) against
+35.6, +33.7, +36.0, +33.5 % on 382b1fd (median 34.8 %); CPU, three alternate processes of 15
pairs each: overhead +22.8, +22.7, +21.4 % against +29.8, +32.7, +34.7 %, the scoring's CPU 44-56 ms
a run against 62-72 ms; every score, status and message of 15 rows (this scenario and five more)
bit for bit. The 10 % target is not met: about half of what is left is the pointing searches of
both scopes (``ocp.geometry.pointing``: per requirement and per row) and their interpolants, then
the CasADi evaluations along each reference. The budget stays 60 %: single runs reached +42 % at
this load.

Measured on 2026-12-03 (load 4-7.5 on 2 cores), against b83f07a, after a row's searches found
their heads and sub-grids in one array and evaluated them, and each zoom, in one call (the moving
constraints' margins in one pass): this benchmark run alternately on both (15 pairs a run, wall,
two series of five): median +18.6 % (+16.4..+23.8) against +21.8 % (+13.9..+29.9); the searches
alone (one process taking both modules in turn, 150 pairs, CPU a run) 13.3 against 16.7 ms (paired
ratio 0.80); every score, status and message of 13 rows (this scenario and four more) bit for bit.
The 10 % target is not met: the searches do 20 % less work, not the 35-40 % it needs
(docs/performance.rst: what is left). The budget stays 60 %.

Measured on 2026-12-03 (load 2.9-4.1 on 2 cores), against b417048, after the actuator score found
each quantity's peak by one argmax (0.74 against 1.44 ms of CPU a run): this benchmark run
alternately on both (15 pairs a run, wall): median +20.6 % (+12.6..+21.5) against +21.4 %
(+17.7..+22.8); every score, status and message of 25 rows (five scenarios, four with a rate
requirement added, and this one) bit for bit. The 10 % target is not met: of the scoring's some
35 ms of CPU a run, the scorer's own arithmetic is about 3 ms; the rest is the pointing searches
and their interpolants (23.6 ms), the demand and its unrealised torque (8.4 ms) and the
environment's torque (4.8 ms, CasADi's virtual machine). The budget stays 60 %.

Measured on 2026-12-03 (load 1.5-9 on 2 cores), against f0e16c0, after the searches lost some array
operations (the rate bound's control points not stacked, windows and keep-in flips skipped where
they change nothing, the heads' samples normalised alone, a score's least margin in one pass) and
a reference tracked by several controllers had its pointing and rate scores computed once: ten
alternate processes each (15 pairs a process, CPU), overhead median +19.0 % (+17.3..+22.5) against
+21.7 % (+15.4..+25.2), the scoring's CPU 38.4 against 41.0 ms a run (not resolved); the searches
alone 0.93 of f0e16c0's (paired, 80 pairs); every score, status and message of 65 rows (the
scenarios but the studies, this one, and this one tracked by three controllers) bit for bit. The
10 % target is not met (docs/performance.rst). The budget stays 60 %.

The 12U CubeSat Sun keep-out scenario without its collocation row (the fast planners, where scoring
weighs most), with three pointing requirements (the star tracker off the Sun and the Moon, an
antenna off the Earth's limb: moving directions, tabulated), the actuator margin (the demand
through the controller's allocation) and a rate limit; the same run with scoring switched off
(the runner's private switch), run in pairs so that the machine's load falls on both alike; the
overhead is the median of the pairs' ratios (robust to the load drifting between pairs). Medians and
spreads (min, max) of both are printed and kept in the benchmark's extra info.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import yaml

import scenarios
from scenarios import runner

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "cubesat_12u_sun_keep_out.yaml"
ROUNDS = 15
OVERHEAD_BUDGET = 0.60
"""Largest accepted ratio of the run with scoring to the run without it, less one."""


def three_pointing_requirements() -> scenarios.Scenario:
    data = yaml.safe_load(SCENARIO.read_text())
    data["planners"] = [planner for planner in data["planners"] if planner["name"] != "collocation"]
    data["spacecraft"]["sensors"]["antenna"] = {"boresight": [0, 0, 1]}
    pointing = data["requirements"]["pointing"]
    pointing["st_moon"] = {"sensor": "star_tracker", "keep_out": "moon", "angle_deg": 10}
    pointing["antenna_limb"] = {"sensor": "antenna", "keep_out": "earth_limb", "angle_deg": 10}
    data["requirements"]["rate"] = {"max": 0.1}
    return scenarios.parse_scenario(data)


def timed(scenario: scenarios.Scenario, scoring: bool) -> float:
    runner._SCORE_REQUIREMENTS = scoring
    try:
        start = time.perf_counter()
        results = scenarios.run(scenario)
        elapsed = time.perf_counter() - start
    finally:
        runner._SCORE_REQUIREMENTS = True
    assert all(row.status == ("violated" if scoring else "ok") for row in results.rows)
    return elapsed


def test_scoring_every_requirement_costs_at_most_the_budget(benchmark):
    scenario = three_pointing_requirements()
    assert len(scenario.problem.pointing) == 3
    scenarios.run(scenario)  # warm the caches (CasADi builds, the shape polynomials' NLPs) for both alike
    on, off = [], []
    for _ in range(ROUNDS):
        off.append(timed(scenario, False))
        on.append(timed(scenario, True))
    benchmark.pedantic(timed, args=(scenario, True), rounds=1, iterations=1)
    median_on, median_off = float(np.median(on)), float(np.median(off))
    overhead = float(np.median(np.array(on) / np.array(off))) - 1.0
    benchmark.extra_info.update(on_median_s=median_on, off_median_s=median_off, on_min_s=min(on), on_max_s=max(on),
                                off_min_s=min(off), off_max_s=max(off), overhead=overhead)
    print(f"\nscoring on: median {median_on:.3f} s (min {min(on):.3f}, max {max(on):.3f}); "
          f"off: median {median_off:.3f} s (min {min(off):.3f}, max {max(off):.3f}); overhead (median of the "
          f"pairs' ratios) {overhead:+.1%}, of the medians {median_on / median_off - 1:+.1%}")
    assert overhead < OVERHEAD_BUDGET
