"""Direct optimal control on the full model (IPOPT): the workbench's numerical reference.

Objectives: ``min_energy`` ∫‖τ‖² dt (default), ``min_l1`` ∫Σ|τ_i| dt (slack variables),
``min_time`` (free T, the scenario's T is the upper bound), and ``weighted``
(``energy_weight``, ``l1_weight``, ``time_weight``). τ is the actuators' body torque.
Constraints: actuator bounds (wheel torques, dipoles, torquers), wheel momentum bounds, a body-rate
bound ``max_rate`` (per axis), fixed or free final rate, keep-out / keep-in cones.
The transcription (``collocation``: Legendre-Gauss-Radau, or ``multiple_shooting``) is injected from
:data:`ocp.transcription.TRANSCRIPTIONS`; the NLP is built once per problem structure and cached
on the model. Starts: the reference of the ``warm_start`` planner (or, with ``multistart`` > 0, that many randomly
perturbed copies of it) and the ``seed_planners``; the best converged optimum is kept.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np

from ocp.transcription import TRANSCRIPTIONS, Cone, OptimalControlProblem
from ocp.options import InvalidOption, OptionsError, Range, excerpt
from planners.base import FailedReference, ManeuverProblem, Planner, Reference
from planners.collocation_reference import CollocationReference, seed_vector

CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")
INFEASIBLE = ("Infeasible_Problem_Detected", "Restoration_Failed")


def _cone_vector(spec: dict, key: str, where: str) -> np.ndarray:
    value = spec[key]
    if (not isinstance(value, (list, tuple)) or len(value) != 3
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise InvalidOption(f"{where}.{key}", f"expected 3 numbers, got {excerpt(value)}")
    vector = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(vector)) or not np.linalg.norm(vector) > 0:
        raise InvalidOption(f"{where}.{key}", f"expected a finite non-zero vector, got {excerpt(value)}")
    return vector / np.linalg.norm(vector)


def parse_cone(spec: dict, keep_out: bool, margin: float = 0.0, where: str = "cone") -> Cone:
    """A :class:`Cone` from ``{boresight, direction, angle_deg}``, tightened by ``margin`` (rad).

    Parameters
    ----------
    spec : ``boresight`` (body axes) and ``direction`` (inertial) as 3-vectors, ``angle_deg`` the
        cone's half-angle in degrees, in (0, 180).
    keep_out : the boresight must stay outside (``True``) or inside (``False``) the cone.
    margin : rad by which the cone is tightened.
    where : the option's path (``keep_out[0]``) for error messages.

    Raises
    ------
    InvalidOption
        Naming ``where`` and the offending key.
    """
    keys = {"boresight", "direction", "angle_deg"}
    if not isinstance(spec, dict) or set(spec) != keys:
        raise InvalidOption(where, f"a cone needs exactly the keys {sorted(keys)}, got {excerpt(spec)}")
    boresight, direction = _cone_vector(spec, "boresight", where), _cone_vector(spec, "direction", where)
    angle = spec["angle_deg"]
    if not isinstance(angle, (int, float)) or isinstance(angle, bool) or not 0.0 < angle < 180.0:
        raise InvalidOption(f"{where}.angle_deg", f"expected a number in (0, 180) degrees, got {excerpt(angle)}")
    tightened = float(np.deg2rad(angle)) + (margin if keep_out else -margin)
    if not 0.0 < tightened < np.pi:
        raise InvalidOption(f"{where}.angle_deg", f"{angle} deg leaves no cone once tightened by cone_margin_deg")
    return Cone(tuple(boresight), tuple(direction), tightened, keep_out)


class CollocationPlanner(Planner):
    """Direct optimal control planner (see the module docstring)."""

    name = "collocation"
    example_options = ({"intervals": 20}, {"intervals": 20, "transcription": "multiple_shooting"})

    @dataclass(frozen=True)
    class Options:
        objective: Literal["min_energy", "min_l1", "min_time", "weighted"] = "min_energy"
        intervals: Annotated[int, Range(ge=1, le=2000)] = 50
        degree: Annotated[int, Range(ge=1, le=9)] = 3
        transcription: Literal["collocation", "multiple_shooting"] = "collocation"
        warm_start: str = "eigenaxis"            # registered planner whose reference seeds the NLP
        warm_start_options: dict = field(default_factory=dict)  # its options, e.g. {profile: min_time}
        seed_planners: list[str] = field(default_factory=list)
        multistart: Annotated[int, Range(ge=0, le=50)] = 0                      # > 0: try this many randomly perturbed copies of the warm
                                                 # start (1 %, then 5 %) instead of the warm start itself
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
            from planners import PLANNERS  # the registry is complete once options are parsed

            for name in [self.warm_start, *self.seed_planners]:
                if name not in PLANNERS or name == "collocation":
                    raise InvalidOption("warm_start", f"{name!r} is not another registered planner; "
                                     f"expected one of {sorted(set(PLANNERS) - {'collocation'})}")
            try:
                PLANNERS[self.warm_start](self.warm_start_options, path="warm_start_options")
            except OptionsError as error:
                raise InvalidOption(error.path, error.message) from None
            if self.objective == "weighted" and not (self.energy_weight or self.l1_weight or self.time_weight):
                raise InvalidOption("objective", "weighted needs a positive energy_weight, l1_weight or time_weight")
            if self.transcription == "multiple_shooting" and (self.keep_out or self.keep_in or self.objective == "min_l1"
                                                              or (self.objective == "weighted" and self.l1_weight)):
                raise ValueError("multiple_shooting supports energy and time objectives without cones; "
                                 "use transcription: collocation for L1 costs and keep-out / keep-in cones")
            for index, spec in enumerate(self.keep_out):
                parse_cone(spec, True, np.deg2rad(self.cone_margin_deg), f"keep_out[{index}]")
            for index, spec in enumerate(self.keep_in):
                parse_cone(spec, False, np.deg2rad(self.cone_margin_deg), f"keep_in[{index}]")

    def _ocp(self, problem: ManeuverProblem) -> OptimalControlProblem:
        o = self.options
        weights = {"min_energy": (1.0, 0.0, 0.0), "min_l1": (0.0, 1.0, 0.0), "min_time": (0.0, 0.0, 1.0),
                   "weighted": (o.energy_weight, o.l1_weight, o.time_weight)}[o.objective]
        margin = np.deg2rad(o.cone_margin_deg)
        cones = tuple(parse_cone(c, True, margin) for c in o.keep_out) + tuple(parse_cone(c, False, margin) for c in o.keep_in)
        return OptimalControlProblem(problem.model, *weights, free_time=weights[2] > 0,
                                     fixed_final_rate=problem.omegaf is not None, cones=cones)

    def _nlp(self, problem: ManeuverProblem, ocp: OptimalControlProblem):
        o = self.options
        key = (ocp.energy_weight, ocp.l1_weight, ocp.time_weight, ocp.free_time, ocp.fixed_final_rate, ocp.cones,
               o.transcription, o.intervals, o.degree, o.tolerance, o.max_iterations)
        def build():
            transcription = TRANSCRIPTIONS[o.transcription](o.intervals, *([o.degree] if o.transcription == "collocation" else []))
            options = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.tol": o.tolerance,
                       "ipopt.max_iter": o.max_iterations, "show_eval_warnings": False}
            return transcription, transcription.build(ocp, options)

        # The model's numbers are baked into the graph: a shared cache needs them in the key.
        return self.solver_cache(problem).get(("collocation", problem.model.fingerprint, key), build)

    def _bounds(self, problem: ManeuverProblem, nlp, duration: float):
        """lbx/ubx in the layout of the decision vector."""
        spacecraft, model = problem.spacecraft, problem.model
        x_low, x_high = np.full(model.nx, -np.inf), np.full(model.nx, np.inf)
        x_low[0:4], x_high[0:4] = -1.5, 1.5
        if self.options.max_rate is not None:
            x_low[4:7], x_high[4:7] = -self.options.max_rate, self.options.max_rate
        u_low, u_high = np.full(model.nu, -np.inf), np.full(model.nu, np.inf)
        slices = model.control_slices
        if spacecraft.wheels is not None:
            x_low[7:], x_high[7:] = -spacecraft.wheels.max_momentum, spacecraft.wheels.max_momentum
            limit = np.where(spacecraft.wheels.working, spacecraft.wheels.max_torque, 0.0)
            u_low[slices["wheels"]], u_high[slices["wheels"]] = -limit, limit
        if "dipole" in slices:
            u_low[slices["dipole"]], u_high[slices["dipole"]] = -spacecraft.magnetorquers.max_dipole, spacecraft.magnetorquers.max_dipole
        if "torquers" in slices:
            u_low[slices["torquers"]], u_high[slices["torquers"]] = -spacecraft.torquers.max_torque, spacecraft.torquers.max_torque
        n_blocks, _, x_points = nlp.layout["X"]
        _, _, u_points = nlp.layout["U"]
        low = [np.tile(x_low, n_blocks * x_points), np.tile(u_low, n_blocks * u_points), np.zeros(nlp.layout["S"])]
        high = [np.tile(x_high, n_blocks * x_points), np.tile(u_high, n_blocks * u_points), np.full(nlp.layout["S"], np.inf)]
        if self.options.transcription == "collocation":
            low.append(x_low), high.append(x_high)
        if nlp.layout["free_time"]:
            low.append([1e-3 * duration]), high.append([duration])
        return np.concatenate(low), np.concatenate(high)

    def _starts(self, problem: ManeuverProblem) -> list[Reference]:
        from planners import PLANNERS

        starts = []
        requested = [(self.options.warm_start, self.options.warm_start_options)]
        requested += [(name, None) for name in self.options.seed_planners]
        for name, options in requested:
            reference = PLANNERS[name](options).plan(problem)
            if reference.ok:
                starts.append(reference)
        return starts

    def _plan(self, problem: ManeuverProblem) -> Reference:
        ocp = self._ocp(problem)
        transcription, nlp = self._nlp(problem, ocp)
        starts = self._starts(problem)
        if not starts:
            return FailedReference(self.name, f"no start: the warm-start planner {self.options.warm_start!r} failed")
        disturbance = problem.model.default_parameters
        omegaf = np.zeros(3) if problem.omegaf is None else problem.omegaf
        params = np.concatenate([problem.initial_state, problem.qf, omegaf, [problem.duration], disturbance])
        lbx, ubx = self._bounds(problem, nlp, problem.duration)
        rng = np.random.default_rng(0)
        guesses = [seed_vector(problem, transcription, nlp, ref) for ref in starts]
        if self.options.multistart:
            # A warm start can sit exactly on a stationary point (the eigenaxis slew is one for minimum
            # time on a symmetric body: 179 IPOPT iterations to the poorer 15.85 s there, against ~45
            # from any perturbed copy to 14.50 s). Perturbed copies cover it and escape such points.
            warm = guesses.pop(0)
            scale = np.abs(warm) + 1e-3
            guesses = [warm + rng.normal(0, 1, warm.size) * scale * (0.01 if k == 0 else 0.05)
                       for k in range(self.options.multistart)] + guesses
        best, best_cost, statuses, iterations = None, np.inf, [], 0
        for guess in guesses:
            result = nlp.solver(x0=np.clip(guess, lbx, ubx), p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg)
            stats = nlp.solver.stats()
            statuses.append(stats["return_status"])
            iterations += stats["iter_count"]
            if stats["return_status"] in CONVERGED and float(result["f"]) < best_cost:
                best, best_cost = result["x"], float(result["f"])
        stats = {"ipopt_status": statuses, "iterations": iterations, "objective": best_cost,
                 "transcription": transcription.name, "intervals": self.options.intervals}
        if best is None:
            status = "infeasible" if all(s in INFEASIBLE for s in statuses) else "failed"
            return FailedReference(self.name, f"IPOPT did not converge from any start: {sorted(set(statuses))}",
                                   status, stats=stats)
        T, nodes, states, controls = (v.full() for v in nlp.unpack(best, params))
        T = T.item()
        reference = CollocationReference(problem, transcription, T, states, controls, stats)
        norm_error = float(np.max(np.abs(np.linalg.norm(states[0:4], axis=0) - 1)))
        reference.stats.update(duration=T, max_quaternion_norm_error=norm_error,
                     cones=[(c.boresight, c.direction, c.angle, c.keep_out) for c in ocp.cones])
        reference.message = (f"{self.options.objective} by {transcription.name} (N={self.options.intervals}): "
                             f"objective {best_cost:.6g}, T = {T:.4g} s, IPOPT {statuses}")
        return reference
