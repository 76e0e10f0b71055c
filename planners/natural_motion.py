"""Natural motions (nano-spacecraft paper, section IV): torque-free arcs of the spacecraft itself,
shot from the initial attitude to the target, then brought to rest.

* Axisymmetric body (two equal moments): ``ω`` in closed form (eq. 17-24); the attitude from the
  Lax-pair reduction (eq. 25-37), which is the closed form of :mod:`planners.spin_extremal` with the
  roll rate ``v = ω_s`` and spin offset ``λ − ω_s``, ``λ = ω_s (J − J_s)/J``, about the symmetry axis
  (eq. 17-18 print ``β = (J1 − J)/J``, the opposite sign; Euler's equations and eq. 34 agree with ours).
  The torque-free closed forms live in :mod:`planners.torque_free`.
* Asymmetric body: ``ω`` with Jacobi elliptic functions (Landau & Lifshitz §37) in both polhode
  regimes; the attitude by DOP853 integration of the kinematics (rtol 1e-12) with that ``ω``.
* Shooting: IPOPT finds ``ω(0)`` with ``vec(q_f* ⊗ q(T_arc)) = 0`` (3 equations) minimising the
  momentum ``‖I ω(0)‖²`` to spin up (the same is removed at the stop), over several starts.
  For the asymmetric body ``q(T_arc)`` comes from an RK4 CasADi graph; the result is checked with
  the elliptic solution.
* The arc lasts ``T − stop_time``; then ``stop: step`` sets the rate reference to zero (the paper's
  last 10 s of 110 s), or ``stop: smooth`` decelerates along the final body rate with a cubic
  (the shooting then targets the attitude after the stop). The feed-forward torque is zero on the
  arc; spin-up and stopping are paid for by the closed loop.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, Literal

import casadi as ca
import numpy as np

from ocp import Spacecraft, quat
from ocp import quat_casadi as qc
from ocp.dynamics.integration import rk4_step
from ocp.nlp.solve import solve_multistart, solver_options
from ocp.options import Range
from planners.base import Planner
from planners.problem import Array, ManeuverProblem
from planners.reference import (
    FailedReference,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)
from planners.torque_free import (
    asymmetric_rates,
    euler_rhs,
    symmetric_motion,
    symmetry_axis,
)

STOP_RESOLUTION = 1e-9
"""The shortest ``stop_time`` as a fraction of T: below it ``T − stop_time`` is T to rounding (1e-15 s
stops in a 120 s slew vanished and the row was ok while the reference ended turning)."""


class NaturalMotionReference(Reference):
    """Torque-free arc on ``[0, arc]`` from ``q0`` with ``ω(0) = omega0``, then the stop.

    The torque is zero on the arc; ω(0) is what the shooting chose, so ``omega0`` of the problem
    is declared free (the spin-up is left to the closed loop, as in the paper).

    Parameters
    ----------
    q0 : (4,) ndarray
        Initial attitude, scalar first, body to inertial (principal axes as the body axes).
    omega0 : (3,) ndarray
        Rate at the start of the arc [rad/s], principal axes.
    moments : (3,) ndarray
        Principal moments of inertia [kg m^2].
    arc : float
        Duration of the torque-free arc [s].
    duration : float
        T [s]; the stop occupies ``[arc, T]``.
    stop : {"step", "smooth"}
        ``step``: at rest with the attitude held after the arc; ``smooth``: a cubic deceleration
        along the final body rate.
    message : str
        Outcome description.
    stats : dict
        Solver statistics.
    """

    def __init__(self, q0: Array, omega0: Array, moments: Array, arc: float, duration: float, stop: str,
                 message: str, stats: dict[str, Any]) -> None:
        # ω(0) is what the shooting found (the spin-up is left to the closed loop, as in the paper).
        super().__init__("natural_motion", duration, np.diag(moments), message=message, stats=stats,
                         free_boundary={"omega0"}, breakpoints=[arc] if 0 < arc < duration else [])
        self.q0, self.omega0, self.moments, self.arc, self.stop = q0, omega0, moments, arc, stop
        self.axis = symmetry_axis(moments)
        if self.axis is None:
            from scipy.integrate import (
                solve_ivp,  # lazily: scipy.integrate pulls in scipy.optimize
            )

            solution = solve_ivp(lambda s, q: quat.kinematics(q, asymmetric_rates(s, omega0, moments)), (0, arc),
                                 quat.IDENTITY, method="DOP853", rtol=1e-12, atol=1e-13, dense_output=True)
            self._relative = _Relative(solution.sol)
        q_end, self.omega_end = self._arc(np.array([arc]))
        self.q_end, self.omega_end = q_end[0], self.omega_end[0]

    def _arc(self, t: Array) -> tuple[Array, Array]:
        if self.axis is not None:
            rates, q_rel = symmetric_motion(t, self.omega0, self.moments, self.axis)
            return quat.product(self.q0, np.stack(q_rel, axis=-1)), np.stack(rates, axis=-1)
        return quat.product(self.q0, self._relative(t)), asymmetric_rates(t, self.omega0, self.moments)

    def _evaluate(self, t: Array) -> ReferenceSample:
        q, omega = self._arc(np.minimum(t, self.arc))
        omega_dot = np.stack(euler_rhs(self.moments)(omega.T), axis=-1)
        after = t > self.arc
        if np.any(after):
            stop_time = self.duration - self.arc
            if self.stop == "smooth" and stop_time > 0:
                s = (t[after] - self.arc) / stop_time
                profile, rate = 1 - 3 * s**2 + 2 * s**3, (-6 * s + 6 * s**2) / stop_time
                angle = stop_time * (s - s**3 + 0.5 * s**4)  # ∫ profile dt
                q[after] = quat.product(self.q_end, quat.from_rotation_vector(angle[:, None] * self.omega_end))
                omega[after] = profile[:, None] * self.omega_end
                omega_dot[after] = rate[:, None] * self.omega_end
            else:
                q[after], omega[after], omega_dot[after] = self.q_end, 0.0, 0.0
        torque = np.zeros_like(omega)
        torque[after] = inverse_dynamics_torque(self.inertia, omega[after], omega_dot[after])
        return ReferenceSample(q, omega, omega_dot, torque)


class _Relative:
    """The asymmetric body's attitude relative to its start, ``t -> q_rel(t)`` (normalised dense
    output of the integration): a module-level callable so that a reference pickles."""

    def __init__(self, dense: Any) -> None:
        self.dense = dense

    def __call__(self, t: Array) -> Array:
        return quat.normalize(self.dense(t).T)


class RotatedReference(Reference):
    """A reference planned in principal axes, expressed in body axes (``v_B = V v_P``).

    Parameters
    ----------
    inner : Reference
        The reference in principal axes.
    axes : (3, 3) ndarray
        ``V``, principal axes as columns in body axes (a proper rotation).
    q_body_to_principal : (4,) ndarray
        The quaternion of ``Vᵀ`` (body to principal), scalar first: ``q_B = q_P ⊗ q``.
    """

    def __init__(self, inner: Reference, axes: Array, q_body_to_principal: Array) -> None:
        super().__init__(inner.planner, inner.duration, axes @ inner.inertia @ axes.T, inner.status,
                         inner.message + " (planned in principal axes)", inner.stats,
                         free_boundary=inner.free_boundary, breakpoints=inner.breakpoints)
        self.inner, self.axes, self.q_rotation = inner, axes, q_body_to_principal

    def _evaluate(self, t: Array) -> ReferenceSample:
        sample = self.inner.sample(t)
        return ReferenceSample(quat.product(sample.q, self.q_rotation), sample.omega @ self.axes.T,
                               sample.omega_dot @ self.axes.T, sample.torque @ self.axes.T)


class NaturalMotionPlanner(Planner):
    """Natural-motion planner for any valid inertia (planned in its principal axes)."""

    name = "natural_motion"
    example_options = ({}, {"stop": "smooth"})

    @dataclass(frozen=True)
    class Options:
        """Options of ``natural_motion`` (YAML ``planner.options``).

        Attributes
        ----------
        stop_time : float
            Time at the end of T spent stopping [s], positive (default 10 s, the paper's last
            10 s of 110 s); the arc lasts ``T − stop_time``. Zero is refused: the arc would end at
            T still turning, so ``ω(T)`` would be the arc's rate, not rest (the reference's one
            breakpoint is the end of the arc, which it declares only inside ``(0, T)``), and a stop
            at T itself, a rate step declared at a breakpoint at T, would be the arc's whole
            momentum as one impulse.
        stop : {"step", "smooth"}
            ``step`` (default, the paper): the rate reference drops to zero at the end of the arc;
            ``smooth``: a cubic deceleration along the final body rate over ``stop_time`` (the
            shooting then targets the attitude after the stop).
        rk4_steps : int
            RK4 steps of the asymmetric body's shooting graph, 4 to 5000 (default 60); multiplied by
            4, up to 16 × ``rk4_steps``, while the exact (elliptic) arc misses the target by more than
            1e-6 deg. Unused for an axisymmetric body (closed form).
        starts : int
            IPOPT starts of the shooting, 1 to 50 (default 3): the short and the long way round,
            then perturbed ones.
        """

        stop_time: Annotated[float, Range(gt=0.0)] = 10.0                     # s at the end of T spent stopping (> 0: ends at rest)
        stop: Literal["step", "smooth"] = "step"    # rate reference to zero at once (paper) or a cubic
        rk4_steps: Annotated[int, Range(ge=4, le=5000)] = 60                         # RK4 steps of the asymmetric shooting (refined x4 as needed)
        starts: Annotated[int, Range(ge=1, le=50)] = 3                             # IPOPT starts (short, long way round, perturbed)

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why a natural motion cannot take ``problem``.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan.

        Returns
        -------
        str or None
            The reason (no target attitude, a non-zero final rate: it ends at rest, or a
            ``stop_time`` that leaves no arc, or one too short for T to resolve), or ``None``.
        """
        if problem.omegaf is not None and np.any(problem.omegaf != 0):
            return "natural_motion ends at rest: maneuver.final.omega must be zero or null"
        if problem.duration <= self.options.stop_time:
            return f"stop_time {self.options.stop_time} s leaves no arc in T = {problem.duration} s"
        if self.options.stop_time < STOP_RESOLUTION * problem.duration:  # T − stop_time rounds to T
            return (f"stop_time {self.options.stop_time:g} s is below {STOP_RESOLUTION:g} of T = {problem.duration:g} s: "
                    f"the stop would vanish in rounding and the reference end at T still turning")
        return super().problem_error(problem)

    def _plan(self, problem: ManeuverProblem) -> Reference:
        assert problem.qf is not None  # problem_error refuses a free attitude
        if not problem.spacecraft.is_principal:
            # Plan in principal axes (columns of V, a proper rotation) and map the reference back.
            moments, axes = np.linalg.eigh(problem.spacecraft.inertia)
            axes[:, 2] *= np.linalg.det(axes)
            q_body_to_principal = quat.from_rotation_matrix(axes.T)  # v_P = Vᵀ v_B
            principal = ManeuverProblem(
                Spacecraft(moments), quat.product(problem.q0, quat.conjugate(q_body_to_principal)),
                axes.T @ problem.omega0, quat.product(problem.qf, quat.conjugate(q_body_to_principal)),
                problem.duration, None if problem.omegaf is None else axes.T @ problem.omegaf)
            reference = self._plan(principal)
            return reference if not reference.ok else RotatedReference(reference, axes, q_body_to_principal)
        arc = problem.duration - self.options.stop_time
        if arc <= 0:
            return FailedReference(self.name, f"stop_time {self.options.stop_time} s leaves no arc in T = "
                                   f"{problem.duration} s", "infeasible")
        moments = np.diag(problem.spacecraft.inertia).copy()
        solution = self._shoot(problem, moments, arc)
        if isinstance(solution, Reference):
            return solution
        omega0, stats = solution
        steps = self.options.rk4_steps
        while True:
            reference = NaturalMotionReference(problem.q0, omega0, moments, arc, problem.duration,
                                               self.options.stop, "", stats)
            error = np.rad2deg(quat.error_angle(reference.q(problem.duration), problem.qf))
            if symmetry_axis(moments) is not None or error <= 1e-6 or steps >= 16 * self.options.rk4_steps:
                break
            steps *= 4  # the RK4 graph was too coarse for this arc: polish from the found ω(0)
            refined = self._shoot(problem, moments, arc, steps, seeds=[omega0])
            if isinstance(refined, Reference):
                break
            omega0, stats = refined
        stats["rk4_steps"] = steps if symmetry_axis(moments) is None else None
        reference.stats = stats
        stats.update(omega0=omega0.tolist(), final_error_deg=float(error))
        reference.message = (f"natural arc from ω0 = {np.array2string(omega0, precision=5)} rad/s over "
                             f"{arc:g} s, stop '{self.options.stop}', final error {error:.2g} deg")
        if error > 1e-3:
            return FailedReference(self.name, f"shooting converged but the exact arc misses the target by "
                                   f"{error:.3g} deg (raise rk4_steps)", stats=stats)
        return reference

    def _shoot(self, problem: ManeuverProblem, moments: Array, arc: float, steps: int | None = None,
               seeds: list[Array] | None = None) -> tuple[Array, dict[str, Any]] | Reference:
        assert problem.qf is not None  # problem_error refuses a free attitude
        structure = (symmetry_axis(moments), self.options.stop, steps or self.options.rk4_steps)
        solver = self.solver_cache(problem).get(("natural_motion",) + structure, lambda: shooting_solver(*structure))
        target = quat.product(quat.conjugate(problem.q0), problem.qf)
        parameters = np.r_[moments, target, arc, problem.duration - arc]
        rotvec = quat.to_rotation_vector(target)
        angle = np.linalg.norm(rotvec)
        axis_vec = rotvec / angle if angle > 1e-12 else np.array([1.0, 0.0, 0.0])
        if seeds is None:
            rng = np.random.default_rng(0)
            seeds = [rotvec / arc, (angle - 2 * np.pi) * axis_vec / arc]
            seeds += [rotvec / arc + rng.normal(0, 0.3 * angle / arc + 1e-3, 3) for _ in range(self.options.starts - 2)]
        # Starts are distinct ways round (short, long, perturbed): all are tried (agree = 0).
        result = solve_multistart(solver, seeds, p=parameters, lbg=0, ubg=0, agree=0,
                                  feasibility_tolerance=1e-9, max_starts=self.options.starts)
        stats = result.stats()
        stats["momentum_sq"] = result.f
        if not result.success or result.x is None:
            return FailedReference(self.name, f"shooting did not reach the target from any start: "
                                   f"{result.statuses}", stats=stats)
        return result.x, stats


def shooting_solver(axis: int | None, stop: str, rk4_steps: int) -> ca.Function:
    """The IPOPT shooting on ω(0), built once per structure.

    Minimises ``‖I ω(0)‖²`` subject to ``vec(q_target* ⊗ q_rel) = 0``, with ``q_rel`` the attitude
    after the arc (and after a ``smooth`` stop) relative to the start.

    Parameters
    ----------
    axis : int or None
        Symmetry axis (closed form), or ``None`` for an asymmetric body (RK4 graph).
    stop : {"step", "smooth"}
        The stop law.
    rk4_steps : int
        RK4 steps over the arc (asymmetric body only).

    Returns
    -------
    casadi.Function
        ``nlpsol`` with decision ω(0) [rad/s] (principal axes) and parameters
        ``[I1, I2, I3 (kg m^2), q_target (4, relative to q0), arc (s), stop_time (s)]``.
    """
    omega0 = ca.SX.sym("omega0", 3)
    p = ca.SX.sym("p", 9)
    moments, target, arc, stop_time = [p[0], p[1], p[2]], p[3:7], p[7], p[8]
    if axis is not None:
        rates, q_rel = symmetric_motion(arc, [omega0[i] for i in range(3)], moments, axis, math=ca)
        q_rel, omega_end = ca.vertcat(*q_rel), ca.vertcat(*rates)
    else:
        q_rel, omega_end = _rk4_arc(omega0, moments, arc, rk4_steps)
    if stop == "smooth":
        q_rel = qc.product(q_rel, qc.from_rotation_vector(omega_end * stop_time / 2))
    miss = qc.product(qc.conjugate(target), q_rel)[1:]
    momentum = ca.sumsqr(ca.vertcat(*moments) * omega0)
    # A start that needs more than 15 iterations is heading for a poor, high-momentum optimum (the
    # long way round took 115 iterations to a 4e4 times larger objective): cut it short.
    options = solver_options("ipopt", 1e-12, 15, {"ipopt.constr_viol_tol": 1e-13})
    return ca.nlpsol("natural_motion", "ipopt", {"x": omega0, "p": p, "f": momentum, "g": miss}, options)


def _rk4_arc(omega0, moments, arc, steps: int):
    """Attitude (relative to t = 0) and rate after ``arc`` seconds of torque-free motion, RK4."""
    state = ca.SX.sym("state", 7)
    params = ca.SX.sym("params", 4)  # I1, I2, I3, step length
    euler = euler_rhs([params[0], params[1], params[2]])
    h = params[3]

    def rhs(x, _):
        q, w = x[:4], x[4:]
        return ca.vertcat(0.5 * qc.product(q, ca.vertcat(0, w)), *euler([w[0], w[1], w[2]]))

    step = ca.Function("rk4", [state, params], [rk4_step(rhs, state, 0, h)])
    final = ca.vertcat(1, 0, 0, 0, omega0)
    step_params = ca.vertcat(*moments, arc / steps)
    for _ in range(steps):
        final = step(final, step_params)
    return final[:4] / ca.norm_2(final[:4]), final[4:]
