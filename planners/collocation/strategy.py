"""How ``collocation`` searches: the tuned constants of ``multistart: auto`` and of the coarse-to-fine
mesh transfer, the perturbation floor of its first start, and merging the record of a failed solve
into its fallback's. The planner (:mod:`planners.collocation.planner`) applies them.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ocp.nlp.solve import NLPResult
from ocp.transcription import NLP, OptimalControlProblem, Transcription
from planners.problem import Array

AUTO_RESTART = 0.05
"""Relative perturbation of the restarts of ``multistart: auto`` when the final time is free."""
AUTO_PIECES = 4
"""Pieces each interval holding a switch is split in by ``switch_refinement: auto`` (where the
estimated error of T exceeds ``mesh_tolerance``): XTE's 28.6312691 s on 50 intervals becomes
28.6304443 s (+3.7e-5 s of the published 28.6304077 s, +3.8e-5 s of the switch-time shooting's
28.6304068 s); 2 pieces leave +1.6e-4 s. The error of T falls as the square of the switching
intervals' length (8.6e-4 s, 1.6e-4 s, 3.7e-5 s for 1, 2 and 4 pieces), so 4 pieces bring an
estimate up to about 16 times ``mesh_tolerance`` within it; where the refined estimate is still
above it, the refinement's record and the reference's message say so."""
AUTO_FIRST = 0.03
"""Relative perturbation of the first start of ``multistart: auto`` when the final time is free: each
decision variable moves by ``AUTO_FIRST × (|value| + floor)`` (normal noise), the floor half the
range of a bounded control (actuator torques, dipoles; 1e-3 elsewhere), so that the torques about
the axes where the warm start has none are perturbed at the scale of the actuators. Ten random
minimum-time slews (B&W, the full-inertia case and eight random inertias and slews, ten noise
seeds each; 8 intervals): 24 IPOPT iterations on average against 30 for a 1 % perturbation
floored at 1e-3, the best optimum found in 97 % of the starts against 91 % (3 % and 5 % did the
same, 10 % slightly worse)."""
SEED_TOLERANCE = 1e-5
"""Solver tolerance (at the least) of the coarse-mesh solve of a fixed final time: its optimum only
seeds the full mesh, whose discretisation moves it far more (the spin paper's minimum energy 0.02012
on 8 intervals, 0.01855 on 50). 32 random fixed-time minimum-energy problems (random principal
inertias, slews, spins, durations, free or zero final rates; warm starts ``spin_extremal`` or
``eigenaxis``): 357 coarse iterations against 428 at the default 1e-10, the full-mesh iterations
unchanged (109), the same optima; 1e-4 and 1e-3 save a few more coarse iterations and cost full-mesh
ones (51 against 49 on 16 of them). The 18 fixed-time cases of
``tests/benchmarks/iteration_counts.py``: 282 coarse and 202 full-mesh iterations against 320 and
205, the same optima (the spin paper's case 26 + 4 against 28 + 4); minimum time, whose coarse
optimum is certified or confirmed, keeps the option's tolerance."""
SEED_FATROP = {"fatrop.mu_init": 1e-3}
"""FATROP's options for the coarse seed of a fixed final time, which FATROP solves when the
``solver`` option is IPOPT (the default) for a transcription whose ``fatrop_seed`` is true (Radau
collocation) and an objective without an L1 term; IPOPT then solves the full mesh from FATROP's
optimum and multipliers as before. If FATROP does not converge, IPOPT solves the seed (the failed
attempt is in the stats as ``coarse_fatrop``). Why: FATROP's Riccati iteration on the 8-interval
Radau mesh costs about 0.8 ms against IPOPT's 1.0 ms with MUMPS (9.0 M against 7.5 M instructions
per iteration, but fewer inertia corrections), and it starts nearer the central path at ``mu_init``
1e-3 (its default 0.1: 22.5 ms against 17 ms for the spin paper's seed; 14 fixed-time cases of
``tests/benchmarks/iteration_counts.py``: fewer iterations on 11, the same optima, one better).
Measured, stop 24, interleaved in one process against the IPOPT seed:
- the spin paper's case: the plan's median time 0.82-0.85x in three runs (47.7 against 56.1 ms at
  the host's fast speed), 21 coarse iterations against 26, the same optimum;
- 98 fixed-time minimum-energy problems (the 18 of ``iteration_counts.py``, 80 random spin-like
  and rest-to-rest ones): the same optimum on 95, a lower one on 2 (0.7427 to 0.2027, 1.4498 to
  0.6425), a higher one on 1 (0.1354 to 0.2709, a case that moves with almost any change of the
  path); CPU per plan 0.76x on the 95 whose FATROP seed converged; FATROP stopped (its restoration
  failed) on 3 hard ones (two where IPOPT's seed also fails or takes 176 iterations), which then
  cost 0.3-0.6 s more each; over the 98, 0.94-0.98x;
- 24 problems on reaction wheels (orthogonal and pyramid) and with gravity gradient: the same
  optima, CPU 0.91x.
Not for multiple shooting (its ``fatrop_seed`` is false): on 30 of those problems 3 lower and 3
higher optima, the spin case 0.0266 against 0.01855, CPU 1.05x. Not with an L1 term: FATROP failed
on 9 of 16 random ``min_l1`` problems (stop 23)."""
POLISH_MU_INIT = 1e-4
"""IPOPT's initial barrier parameter (its default 0.1) for the full-mesh solve from a coarse-mesh
optimum: the seed is near the optimum, so the barrier need not start wide. N = 50 from N = 8:
the spin paper's minimum energy 7 iterations against 12, Bilimoria & Wie's minimum time 15
against 18, the full-inertia minimum time 12 against 16 (same optima; 1e-6 takes 22-23 on the
minimum-time cases, where the bounds are active)."""
TRANSFER_WARM_START = {"mu_init": 1e-7, "bound_push": 1e-3, "mult_bound_push": 1e-4}
"""IPOPT's warm start (:func:`ocp.nlp.solve.warm_start_options`) of the full-mesh solve from a coarse-mesh
optimum with its multipliers carried over (:mod:`ocp.transcription.mesh_transfer`); falls back to the start
without multipliers (:data:`POLISH_MU_INIT`) if it does not converge. The guess is pushed 1e-3
inside its bounds and the bound multipliers start at 1e-4 at least: the coarse active set is near,
not at, the fine one. N = 50 from N = 8: the spin paper's minimum energy 4 iterations against 7,
Bilimoria & Wie's minimum time 10 against 15, the full-inertia one 10 against 12 (same optima).
Neighbouring values do about as well (mu_init 1e-8 to 1e-5, pushes 1e-4 to 1e-2: 24 to 29
iterations over the three); a multiplier push of 1e-2 does not (34 to 41), nor IPOPT's tiny pushes
of a same-mesh warm start (1e-9: 20 and 12 on the minimum-time cases)."""

COARSE_MIN_TIME_OPTIONS = {"ipopt.perturb_inc_fact": 2.5, "ipopt.bound_push": 0.1, "ipopt.bound_frac": 0.1}
"""IPOPT's options for the cold starts of minimum time (a free final time, no energy or L1 term, no
cones) on ``coarse_intervals``: the inertia correction's growth factor and the initial point's
distance from the bounds.

``perturb_inc_fact`` 2.5 (IPOPT's default 8): the Hessian perturbation δw grows by 2.5 per rejected
trial factorization after the first of an iteration. Near the eigenaxis saddle of Bilimoria & Wie
the coarse iterations need δw > 0 and IPOPT tries several δw per iteration (δw = 0 first, then its
last δw cut by ``perturb_dec_fact``, then grown); growing by 8 overshoots, and the larger δw
shortens the steps. Measured 2026-12-04 against IPOPT's default (the same optima):

- Bilimoria & Wie's two coarse starts 32 + 19 iterations against 39 + 22, 112 MUMPS numerical
  factorizations against 128 over the coarse solves of it and the full-inertia case (print level 7);
  callgrind over the plans of Bilimoria & Wie, the full inertia and the spin paper's case 616 M
  instructions in IPOPT against 683 M (0.90x; 3: 645 M, 4: 628 M);
- ``tests/benchmarks/iteration_counts.py``: only Bilimoria & Wie changes (61 coarse iterations
  against 51; its shot optimum the same, switch times within 1e-15 s); XTE 40 + 28 against 50 + 26,
  Bilimoria & Wie at 90 deg 37 + 29 against 42 + 28, at 45 deg 37 + 41 against 45 + 51 (1.74709403,
  the same minimum to 4e-11), at 135 deg 23 + 20 against 22 + 20.

Its neighbours on Bilimoria & Wie (factorizations of the two cases' coarse solves): 2 142, 2.2
130, 2.7 115, 3 119, 3.5 116, 4 114, 5 121, 20 137. With ``perturb_dec_fact`` 0.2 or 0.25, or
``first_hessian_perturbation`` 1e-3 or 1e-2, or ``perturb_inc_fact_first`` 50 or 300 besides, no
better (110 to 133). ``min_refinement_steps`` 0: 679 M against 683 M, the same iterations (not
worth a constant).

``bound_push`` = ``bound_frac`` 0.1 (IPOPT's default 0.01) with the growth factor 2.5: the seeds'
controls, at their bounds on a bang-bang start, are moved 0.1 of the way in, where the barrier's
first steps no longer fight the bounds. Measured 2026-12-04 against 2.5 alone
(``iteration_counts.py``, the 23 minimum-time cases; the fixed-time cases do not use it): 919
coarse iterations against 981 and 600 full-mesh against 641; Bilimoria & Wie 42 against 51 (its
two seeds still agree); every optimum the same to 1e-11 but mt17's, which reaches the lower of the
two minima the docs name (10.22393 s against 10.30034 s: the best known, found before only by
FATROP's coarse solve or 6 coarse intervals). ``slewbench bench`` (collocation only): the same
optimum on every problem, iterations 46 against 54 on Bilimoria & Wie 180 deg, 48 against 66 at 90
deg, 9 against 23 at 45 deg, 27 against 117 on the norm-bounded eigenaxis case, 70 against 68 on
XTE. With 0.05 instead: 944 coarse iterations, mt17 at 10.22393 too. Side by side with acados
(``test_side_by_side_acados``, 9 rounds, load 0.1-0.6): Bilimoria & Wie 81.9 ms against 95.3 ms
before, 0.89x acados [0.88..0.92] against 1.03x [1.00..1.07] (acados with HPIPM's default QP
cap; given the cap 8 and the QP warm start, 1.71x: ``tests/benchmarks/test_bench_min_time.py``).
(At stop 51, with the growth factor 8, the same pushes sent the spin-extremal seed of Bilimoria & Wie to another coarse minimum, 3.28326
against 3.24349; with 2.5 both seeds end at 3.24349, except on an AVX-512 host where NumPy's AVX-512 kernels move the
spin-extremal seed's rounding: 3.28326 there, 2026-12-04, ``tests/test_collocation_seeds.py``.) ``alpha_for_y`` ``min-dual-infeas`` (104
factorizations) also reaches mt17's lower minimum; not measured further."""

COARSE_INTERIOR_POINT = {key.removeprefix("ipopt."): value for key, value in COARSE_MIN_TIME_OPTIONS.items()}
"""The options (IPOPT's names) of the compiled interior point (:mod:`ocp.nlp.interior_point`) that solves
the cold starts of minimum time on ``coarse_intervals`` where the compiled factorisation is
available: :data:`COARSE_MIN_TIME_OPTIONS`, the same iterates as IPOPT under them. It takes IPOPT's
iterates (Bilimoria & Wie's two coarse starts: 23 + 24 iterations against IPOPT's 22 + 24, the same
optima) in about a third of IPOPT's time (0.28-0.39x a start on Bilimoria & Wie, the full inertia and
XTE, 2026-12-05, ``tests/benchmarks/test_bench_interior_point.py``); a start it cannot finish (it has
no restoration phase) is IPOPT's from its beginning: one start of the minimum-time cases of
``tests/benchmarks/iteration_counts.py`` (mt11) and one of the 32 coarse starts of 30 random
minimum-time slews on torquers and wheels, 2026-12-05; every optimum the same as IPOPT's, to 5e-12."""

TRANSFER_MAX_INTERVALS = 150
"""Largest full mesh solved from the coarse optimum with its multipliers carried over (IPOPT's
``warm_start_init_point``, :data:`TRANSFER_WARM_START`); beyond it the full mesh starts from the
coarse optimum alone (:data:`POLISH_MU_INIT`). With the default options, the 30 deg wheel slew of
``tests/test_collocation_mesh_transfer.py`` on 300, 400 and 500 intervals ran over 120 s (killed)
in MUMPS's first factorisation of that warm start ("INFO(1) = -9 ... reallocating", about 30 s per
attempt), with the carried multipliers or zeros and for ``mu_init`` 1e-7 or 1e-4, while the same
seed without ``warm_start_init_point`` converged in 0.9 s and 200 intervals took 1 s. The tuning
above is on 40 to 50 intervals; 150 is the largest mesh of the test suite (multiple shooting's
full-inertia minimum time)."""

TRANSFER_L1_BARRIER = {"ipopt.mu_strategy": "adaptive"}
"""Added to :data:`TRANSFER_WARM_START` for an objective with an L1 term and no energy term
(``min_l1``; its optimum is bang-off-bang, many torque slacks at their bounds): IPOPT's adaptive
barrier (quality-function oracle) instead of the monotone one from 1e-7, which crawls (steps cut to
α ≈ 1e-3 by the fraction-to-the-boundary rule) when the coarse point is far from the fine central
path. 16 random fixed-time ``min_l1`` problems (principal inertias 10-20 kg m², 0.1 N m torquers,
0-0.3 rad/s spins, 60-250 s, two seeds, 40 intervals): 226 full-mesh iterations against 587 (one
case 212 against 17, another 139 against 17), the same optima to the tolerance (closer to a tight
solve: smaller complementarity gaps). Not for the others: with an energy term (``weighted``, L1
weight 0.1) 172 against 151; on the 41 cases of ``tests/benchmarks/iteration_counts.py`` 502 against
523 but 5-8 % more instructions per plan (its oracle's extra solves). The adaptive strategy
ignores ``mu_init`` (IPOPT reads it in the monotone mode only: 1e-7, 1e-2 and 0.1 give the same
iterates); the pushes of :data:`TRANSFER_WARM_START` still apply. ``weighted`` with L1 and time
weights and no energy term (free final time) takes it too: 10 problems, 136 full-mesh iterations
against 213."""

TRANSFER_MIN_TIME_BARRIER = {"ipopt.mu_strategy": "adaptive", "ipopt.mu_oracle": "probing",
                             "ipopt.corrector_type": "affine"}
"""Added to :data:`TRANSFER_WARM_START` for minimum time (a free final time, no energy or L1 term) without
cones: IPOPT's adaptive barrier with Mehrotra's probing oracle and an affine-scaling corrector step,
its line search kept. The full-mesh solve from the coarse optimum and its multipliers (measured
2026-12-02 against the monotone barrier from 1e-7, the same seeds, optima the same to 1e-7
relative unless said):

- Bilimoria & Wie 7 IPOPT iterations against 10, the full-inertia case 6 against 10, XTE 7
  against 10; that solve alone (CPU, 15 alternating rounds) 27.4 against 31.0 ms and 25.6 against
  31.7 ms (0.88x, 0.81x): an iteration costs 26-35 % more (the oracle's and the corrector's extra
  back-solves); the whole plan 0.98x, 0.90x and 0.96x (21 alternating rounds, load 3.5);
- the 23 minimum-time cases of ``tests/benchmarks/iteration_counts.py``: 224 full-mesh iterations
  against 321, more on two (mt11 20 against 19, mt17 17 against 15);
- the suite's and the scenarios' minimum-time problems without cones (Bilimoria & Wie at 180, 90
  and 45 deg, the full inertia, XTE, the norm-bounded eigenaxis, ``collocation_min_time.yaml``):
  66 against 77 (45 deg 25 against 21: 1.7470935 against 1.7470940, where the 50-interval mesh
  has several minima within 1e-6, direct solves reach 1.7470928 and 1.7470936; the norm-bounded
  eigenaxis 7 against 5);
- 15 more on three reaction wheels, with a rate-norm bound (re-solved on the same mesh by this
  warm start), from a spin with a free final rate and with a per-axis rate box: 144 against 208;
- ``transcription: multiple_shooting`` on seven of those (Bilimoria & Wie, the full inertia, mt0,
  mt3, mt5, mt11, mt17): 150 against 179 (B&W 19 against 28; mt0 79 against 78, mt5 18 against
  17), the same optima to 2e-9.

IPOPT's ``mehrotra_algorithm`` (the same three with the line search off) did as well on the first
two but took mt0 61 against 51 and mt11 28 against 19; the probing oracle alone 11 and 10
iterations, the corrector alone 10 and 10. Not with cones: Melton's keep-out case ends at another
local minimum of the full mesh (2.589954 against 2.589941, 19 iterations either way). Not with an
energy term: ``time_regularization``'s regularised transfer on two wheels 40 against 23. Not for a
fixed final time: the spin-like sp4 of ``iteration_counts.py`` 63 against 47. Not on the coarse
mesh (cold starts): Bilimoria & Wie 117 coarse iterations against 63, and other minima on two of
23 cases. The adaptive strategy ignores ``mu_init``; the pushes of :data:`TRANSFER_WARM_START`
still apply."""

AGREE_RTOL = 1e-6
"""Relative agreement of two starts' objectives (:func:`ocp.nlp.solve.solve_multistart`'s
``rtol``): what early stopping and ``stats["seeds"]["agreed"]`` count as the same optimum."""
AGREE_ATOL = 1e-12
"""Absolute agreement of two starts' objectives (``atol``), beside :data:`AGREE_RTOL`."""


def seed_record(result: NLPResult, guesses: int, labels: Sequence[str]) -> dict:
    """``stats["seeds"]`` of a multistart: how many starts were tried, how many agreed on the
    best optimum, and where it came from.

    Parameters
    ----------
    result : NLPResult
        The multistart's outcome (its starts in the order tried).
    guesses : int
        How many of ``labels`` are the starts proper; the rest are fallbacks, tried in order only
        while no start had converged (:func:`ocp.nlp.solve.solve_multistart`); starts after
        those are restarts from the best point.
    labels : sequence of str
        Where each start, then each fallback, comes from (a planner's name, ``"eigenaxis
        perturbed 1"``, ...).

    Returns
    -------
    dict
        ``tried`` (starts solved), ``agreed`` (converged starts whose objective agrees with the
        best one within :data:`AGREE_RTOL`, :data:`AGREE_ATOL`; 0 without one) and ``best_from``
        (the best start's label, ``"restart k"`` for the k-th restart, ``""`` without one).
    """
    names: list[str] = []
    fallbacks = list(labels[guesses:])
    restarts = 0
    for index, start in enumerate(result.starts):
        if index < guesses:
            names.append(labels[index] if index < len(labels) else f"start {index}")
        elif fallbacks and not any(s.converged for s in result.starts[:index]):
            names.append(fallbacks.pop(0))
        else:
            restarts += 1
            names.append(f"restart {restarts}")
    agreed = 0
    if result.success:
        agreed = sum(s.converged and abs(s.f - result.f) <= AGREE_ATOL + AGREE_RTOL * abs(result.f)
                     for s in result.starts)
    best = "" if result.best_start is None else names[result.best_start]
    return {"tried": len(result.starts), "agreed": int(agreed), "best_from": best}


def control_floor(transcription: Transcription, ocp: OptimalControlProblem, nlp: NLP, u_low: Array,
                  u_high: Array) -> Array:
    """The ``floor`` of :func:`ocp.nlp.solve.perturbed` for a decision vector of ``nlp``.

    Parameters
    ----------
    transcription : Transcription
        The transcription ``nlp`` was built by (its variable layout).
    ocp : OptimalControlProblem
        What is optimised.
    nlp : NLP
        The built NLP.
    u_low, u_high : (nu,) ndarray
        Bounds of the actuator controls (model units: N m, A m²).

    Returns
    -------
    ndarray
        Per decision variable, half the range of a bounded control, 1e-3 for every other
        variable (states, a free T, slacks, unbounded controls).
    """
    free = np.full(ocp.model.nx, np.inf)
    low, high = transcription.bounds(ocp, nlp, -free, free, u_low, u_high, np.inf)
    with np.errstate(invalid="ignore"):  # a free T: [1e-3, 1] × inf
        half = 0.5 * (high - low)
    return np.where(np.isfinite(half) & (half > 0), half, 1e-3)


def merged(first: NLPResult, second: NLPResult) -> NLPResult:
    """A fallback's result with the record of the solve that failed before it.

    Parameters
    ----------
    first : NLPResult
        The solve that failed (e.g. the full mesh from a coarse optimum).
    second : NLPResult
        The fallback solve after it.

    Returns
    -------
    NLPResult
        ``second`` with the starts, iterations and time of ``first`` counted first.
    """
    best = None if second.best_start is None else second.best_start + len(first.starts)
    return replace(second, starts=first.starts + second.starts, iterations=first.iterations + second.iterations,
                   time_s=first.time_s + second.time_s, best_start=best)

DENSE_ROUNDS = 3
"""Most re-solves, each tighter where the dense check of the last solution found a requirement broken
between the mesh points (:mod:`planners.collocation.requirements`)."""
SEED_CONE_PAD = float(np.deg2rad(2.0))
"""How far outside a keep-out cone a start that enters it is bent [rad]
(:func:`planners.collocation.reference.cone_avoiding_sampler`)."""
SEED_BOUND_RTOL = 1e-6
"""Relative gap by which a minimum time counts as slower than a feasible start's own duration
(:meth:`planners.collocation.planner.CollocationPlanner._seed_bound`): the same as
:data:`AGREE_RTOL`, what the multistart counts as the same optimum."""
SEED_BOUND_ATOL = 1e-6
"""Absolute tolerance of the boundary conditions of a start checked as an upper bound (unit
quaternion, rad/s, N m s): a start that misses its target by more is no feasible slew."""
