"""The options of ``collocation`` (split from :mod:`planners.collocation`, whose planner's
``Options`` this is): YAML keys, valid ranges and the checks that relate several of them."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np

from ocp.options import InvalidOption, OptionsError, Range
from ocp.transcription import TRANSCRIPTIONS
from planners.collocation_problem import parse_cone

MAX_RK4_STEPS = 1000
"""Largest ``intervals × substeps`` of ``multiple_shooting``: the NLP build expands every RK4 step
(10 × 100 and 50 × 20 steps built in 20 s on a shared machine, 200 × 100 ran over 120 s; the
default 50 × 4 is 200)."""


@dataclass(frozen=True)
class CollocationOptions:
    """Options of ``collocation`` (YAML keys; see the README's planner table).

    Attributes
    ----------
    objective : str
        ``min_energy`` ∫‖τ‖² dt (default), ``min_l1`` ∫Σ|τ_i| dt, ``min_time`` (free T, the
        scenario's duration its upper bound) or ``weighted``; τ the actuators' body torque [N m].
    intervals : int
        Mesh intervals.
    degree : int
        Radau points per interval (``collocation``).
    transcription : str
        ``collocation`` (Legendre-Gauss-Radau) or ``multiple_shooting``.
    substeps : int
        RK4 steps per interval (``multiple_shooting``; ``intervals × substeps`` at most
        :data:`MAX_RK4_STEPS`).
    solver : str
        ``ipopt`` (default) or ``fatrop``.
    warm_start : str
        Registered planner whose reference seeds the NLP (default ``eigenaxis``; ``collocation``
        itself with its own ``warm_start_options``).
    warm_start_options : dict
        The warm-start planner's options.
    seed_planners : list of str
        Further planners whose references are starts (each at most once).
    multistart : int or "auto"
        ``auto`` (default): for a free final time a perturbed copy of the warm start
        (:data:`AUTO_FIRST`), then, unless its optimum satisfies the second-order sufficient
        conditions (:mod:`ocp.second_order`), restarts from the best point perturbed by 5 %
        until one agrees with it (the warm start itself if the copy does not converge); for a
        fixed final time the warm start. n > 0: n perturbed copies; 0: the warm start itself.
    agree : int
        Stop once this many starts agree on the best objective (0: try all); with ``multistart:
        auto``, a best point that satisfies the second-order sufficient conditions counts as one
        of them.
    time_regularization : float
        ``min_time`` only: ε > 0 first solves min T + ε ∫‖τ‖² dt / Σ τ_max² (τ_max the wheels'
        and torquers' torque bounds [N m]) from the starts, then polishes plain minimum time
        from that optimum and its multipliers; 0 (default): off.
    coarse_intervals : int
        With ``multistart: auto``, the starts are first solved on this many intervals (for a
        free final time the whole multistart; for a fixed one only without cones and with at
        least twice as many ``intervals``, and to the looser tolerance
        :data:`~planners.collocation_strategy.SEED_TOLERANCE`: that optimum is only a seed) and the
        full mesh is solved once from that optimum and its multipliers carried over (IPOPT, its
        barrier adaptive for an L1 term without an energy term; with ``time_regularization`` the
        regularised optimum, then polished on the full mesh; falling back to that optimum alone
        with the barrier starting at 1e-4, then to the full-mesh solve from the starts); 0 or >=
        ``intervals``: off. Default 8.
    energy_weight, l1_weight, time_weight : float
        Weights of ``weighted`` [1/(N² m² s), 1/(N m s), 1/s].
    max_rate : float or None
        Body-rate bound per axis [rad/s]; ``None``: none.
    keep_out, keep_in : list of dict
        Cones ``{boresight (body), direction (inertial), angle_deg}``.
    cone_margin_deg : float
        Cones are imposed this much tighter [deg], so that they hold between the points.
    tolerance : float
        Solver tolerance (scaled KKT error); the coarse seed of a fixed final time
        (``coarse_intervals``) is solved to 1e-5 at the tightest
        (:data:`~planners.collocation_strategy.SEED_TOLERANCE`).
    max_iterations : int
        Solver iterations per start.
    """

    objective: Literal["min_energy", "min_l1", "min_time", "weighted"] = "min_energy"
    intervals: Annotated[int, Range(ge=1, le=2000)] = 50
    degree: Annotated[int, Range(ge=1, le=9)] = 3
    transcription: Literal["collocation", "multiple_shooting"] = "collocation"
    substeps: Annotated[int, Range(ge=1, le=100)] = 4       # RK4 steps per interval (multiple_shooting)
    solver: Literal["ipopt", "fatrop"] = "ipopt"
    warm_start: str = "eigenaxis"            # registered planner whose reference seeds the NLP
    warm_start_options: dict = field(default_factory=dict)  # its options, e.g. {profile: min_time}
    seed_planners: list[str] = field(default_factory=list)
    multistart: Annotated[int | Literal["auto"], Range(ge=0, le=50)] = "auto"
    agree: Annotated[int, Range(ge=0, le=50)] = 2  # stop once this many starts agree on the best optimum (0: try all)
    time_regularization: Annotated[float, Range(ge=0.0, le=1.0)] = 0.0
    coarse_intervals: Annotated[int, Range(ge=0, le=2000)] = 8
    energy_weight: Annotated[float, Range(ge=0.0)] = 1.0               # for objective "weighted"
    l1_weight: Annotated[float, Range(ge=0.0)] = 0.0
    time_weight: Annotated[float, Range(ge=0.0)] = 0.0
    max_rate: Annotated[float | None, Range(gt=0.0)] = None  # rad/s, per body axis
    keep_out: list[dict] = field(default_factory=list)  # {boresight, direction, angle_deg}
    keep_in: list[dict] = field(default_factory=list)
    cone_margin_deg: Annotated[float, Range(ge=0.0, lt=90.0)] = 0.01            # cones are imposed this much tighter, so that they
                                             # hold between the points where they are imposed
    tolerance: Annotated[float, Range(gt=0.0, lt=1.0)] = 1e-10
    max_iterations: Annotated[int, Range(ge=1, le=100000)] = 500

    def __post_init__(self) -> None:
        from planners import (
            PLANNERS,  # the registry is complete once options are parsed
        )

        # A collocation warm start is planned with its own options (say min_energy, itself warm
        # started from eigenaxis): the way into min_time where a kinematic seed is too far
        # (two wheels). Only its own warm start may nest further; the depth is the YAML's.
        for index, name in enumerate([self.warm_start, *self.seed_planners]):
            if name not in PLANNERS or (name == "collocation" and index > 0):
                where = "warm_start" if index == 0 else f"seed_planners[{index - 1}]"
                raise InvalidOption(where, f"{name!r} is not another registered planner; expected one of "
                                           f"{sorted(set(PLANNERS) - {'collocation'})} (or collocation as warm_start)")
        for index, name in enumerate(self.seed_planners):
            if name in self.seed_planners[:index]:  # the same reference again: the same start solved twice
                raise InvalidOption(f"seed_planners[{index}]", f"{name!r} is listed twice; expected each planner once")
        if self.transcription == "multiple_shooting" and self.intervals * self.substeps > MAX_RK4_STEPS:
            raise InvalidOption("substeps", f"{self.intervals} intervals x {self.substeps} substeps = "
                                            f"{self.intervals * self.substeps} RK4 steps; expected at most "
                                            f"{MAX_RK4_STEPS} (every step is expanded into the NLP)")
        try:
            PLANNERS[self.warm_start](self.warm_start_options, path="warm_start_options")
        except OptionsError as error:
            raise InvalidOption(error.path, error.message) from None
        if self.time_regularization and self.objective != "min_time":
            raise InvalidOption("time_regularization", f"applies to objective min_time only, not {self.objective!r}")
        if self.objective == "weighted" and not (self.energy_weight or self.l1_weight or self.time_weight):
            raise InvalidOption("objective", "weighted needs a positive energy_weight, l1_weight or time_weight")
        l1 = self.objective == "min_l1" or (self.objective == "weighted" and self.l1_weight > 0)
        refused = TRANSCRIPTIONS[self.transcription].problem_error(l1, bool(self.keep_out or self.keep_in))
        if refused:
            raise ValueError(refused)
        for index, spec in enumerate(self.keep_out):
            parse_cone(spec, True, np.deg2rad(self.cone_margin_deg), f"keep_out[{index}]")
        for index, spec in enumerate(self.keep_in):
            parse_cone(spec, False, np.deg2rad(self.cone_margin_deg), f"keep_in[{index}]")
