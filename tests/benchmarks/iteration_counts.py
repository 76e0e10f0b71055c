"""Iteration counts of ``collocation``'s coarse and full-mesh solves over a broad, seeded set
(issue 16: deterministic counts, unlike wall times on a shared machine). The full mesh is IPOPT's;
the coarse seed of a fixed final time is FATROP's (``SEED_FATROP``; ``coarse_solver`` names it),
and when FATROP stops and IPOPT takes the seed over, ``coarse`` is IPOPT's count and
``coarse_fatrop`` FATROP's (else 0).

Cases: the three of ``test_bench_min_time.py`` (Bilimoria & Wie, the full-inertia minimum time,
the spin paper's minimum energy from the spin extremal); 21 random minimum-time slews (full
inertias with principal moments 2-20 kg m² satisfying the triangle inequality, random axes,
60-180°, |u_i| <= 1 N m, rest to rest; two seeded streams); 7 random fixed-time minimum-energy
slews (moments 8-25 kg m², 0.1 N m, initial rates ~0.02 rad/s, T 100-200 s, final rate fixed or
free); 5 spin-like ones warm-started from ``spin_extremal`` (principal inertia, roll rate
0.1-0.3 rad/s, 150-250 s); 5 tight minimum-energy ones (T 1.15x a rest-to-rest bang-bang estimate
about the largest moment: the torque bounds are active; some are infeasible).

Run: ``python tests/benchmarks/iteration_counts.py [--coarse-min-time N] [--coarse-fixed N]
[--switch-refinement N] [--only a,b]``; one JSON line per case (coarse and full-mesh iterations, the
coarse solver, objective; with ``--switch-refinement`` (the option, on the minimum-time cases) also
the refined solve's iterations and intervals, counted in ``full``).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys

import numpy as np

sys.path[:0] = [str(pathlib.Path(__file__).parents[2]), str(pathlib.Path(__file__).parent)]

from test_bench_min_time import CASES, spin_paper_case

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem


def random_inertia(rng: np.random.Generator, low: float, high: float) -> tuple[np.ndarray, np.ndarray]:
    """A full inertia [kg m²] with principal moments in [low, high] (triangle inequality, 5 % margin)."""
    while True:
        moments = rng.uniform(low, high, 3)
        if moments.sum() - 2 * moments.max() > 0.05 * moments.max():
            break
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    inertia = rotation @ np.diag(moments) @ rotation.T
    return 0.5 * (inertia + inertia.T), moments


def unit(rng: np.random.Generator) -> np.ndarray:
    axis = rng.normal(size=3)
    return axis / np.linalg.norm(axis)


def min_time_slew(rng: np.random.Generator) -> ManeuverProblem:
    inertia, moments = random_inertia(rng, 2.0, 20.0)
    axis, angle = unit(rng), np.deg2rad(rng.uniform(60, 180))
    bound = 4 * np.sqrt(angle * moments.max())  # T's upper bound [s], about 2x the optimum
    return ManeuverProblem(Spacecraft(inertia, torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle(axis, angle), float(bound), omegaf=np.zeros(3))


def cases() -> list[tuple[str, str, ManeuverProblem]]:
    """(name, kind, problem): kind ``min_time``, ``min_energy`` or ``spin`` (spin-extremal warm start)."""
    out = [(name, "min_time", make()) for name, (make, _) in sorted(CASES.items())]
    out.append(("spin_paper", "spin", spin_paper_case()))
    rng = np.random.default_rng(20261124)
    out += [(f"mt{i}", "min_time", min_time_slew(rng)) for i in range(9)]
    for i in range(7):
        inertia, _ = random_inertia(rng, 8.0, 25.0)
        axis, angle = unit(rng), np.deg2rad(rng.uniform(60, 180))
        rates, duration = rng.normal(scale=0.02, size=3), float(rng.uniform(100, 200))
        out.append((f"me{i}", "min_energy", ManeuverProblem(
            Spacecraft(inertia, torquers=Torquers(0.1)), quat.IDENTITY, rates, quat.from_axis_angle(axis, angle),
            duration, omegaf=np.zeros(3) if i % 2 == 0 else None)))
    for i in range(5):
        moments = np.sort(rng.uniform(10, 25, 3))[::-1]
        axis, angle = unit(rng), np.deg2rad(rng.uniform(90, 180))
        roll, duration = float(rng.uniform(0.1, 0.3)), float(rng.uniform(150, 250))
        out.append((f"sp{i}", "spin", ManeuverProblem(Spacecraft(list(moments), torquers=Torquers(0.1)), [1, 0, 0, 0],
                                                      [roll, 0, 0], quat.from_axis_angle(axis, angle), duration)))
    for i in range(5):
        inertia, moments = random_inertia(rng, 8.0, 25.0)
        axis, angle = unit(rng), np.deg2rad(rng.uniform(60, 180))
        rates = rng.normal(scale=0.03, size=3)
        duration = float(1.15 * 2 * np.sqrt(angle * moments.max() / 0.1))
        out.append((f"mx{i}", "min_energy", ManeuverProblem(Spacecraft(inertia, torquers=Torquers(0.1)), quat.IDENTITY,
                                                            rates, quat.from_axis_angle(axis, angle), duration,
                                                            omegaf=np.zeros(3))))
    rng2 = np.random.default_rng(77)
    out += [(f"mt{i}", "min_time", min_time_slew(rng2)) for i in range(9, 21)]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--coarse-min-time", type=int, default=None)
    parser.add_argument("--coarse-fixed", type=int, default=None)
    parser.add_argument("--switch-refinement", type=int, default=None)
    parser.add_argument("--only", default="")
    args = parser.parse_args()
    only = set(filter(None, args.only.split(",")))
    for name, kind, problem in cases():
        if only and name not in only:
            continue
        options: dict = {"objective": "min_time"} if kind == "min_time" else {"intervals": 50}
        if kind == "spin":
            options["warm_start"] = "spin_extremal"
        coarse = args.coarse_min_time if kind == "min_time" else args.coarse_fixed
        if coarse is not None:
            options["coarse_intervals"] = coarse
        if args.switch_refinement is not None and kind == "min_time":
            options["switch_refinement"] = args.switch_refinement
        reference = PLANNERS["collocation"](options).plan(problem)
        stats = reference.stats
        print(json.dumps({"name": name, "ok": reference.ok, "coarse": stats.get("coarse", {}).get("iterations", 0),
                          "coarse_solver": stats.get("coarse", {}).get("solver"),
                          "coarse_fatrop": stats.get("coarse_fatrop", {}).get("iterations", 0),
                          "full": stats.get("iterations"), "objective": stats.get("objective"),
                          **({"refined": stats["switch_refinement"]} if "switch_refinement" in stats else {})}),
              flush=True)


if __name__ == "__main__":
    main()
