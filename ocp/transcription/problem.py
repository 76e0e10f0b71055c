r"""What an optimal-control problem asks for, and what a transcription builds from it.

:class:`OptimalControlProblem` (objective weights, free final time, final rate, pointing
:class:`Cone`\ s) is the problem; :class:`Interval` is one mesh interval as a transcription builds
it and :class:`NLP` the assembled, built problem (see :mod:`ocp.transcription.base`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat_casadi as qc
from ocp.dynamics.model import AttitudeModel

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Cone:
    """Pointing constraint: the body ``boresight`` stays at least (keep-out) or at most (keep-in)
    ``angle`` from the inertial unit ``direction``.

    Parameters
    ----------
    boresight : (3,) tuple of float
        Unit vector, body axes.
    direction : (3,) tuple of float
        Unit vector, inertial frame.
    angle : float
        Cone half-angle [rad].
    keep_out : bool
        ``True``: the boresight stays outside the cone; ``False``: inside.
    """

    boresight: tuple[float, float, float]
    direction: tuple[float, float, float]
    angle: float
    keep_out: bool = True

    def expression(self, q: Any) -> Any:
        """The constraint as ``g <= 0`` (satisfied when non-positive).

        Parameters
        ----------
        q : (4,) CasADi expression
            Attitude quaternion (scalar first, body to inertial).

        Returns
        -------
        CasADi scalar expression
            Cosine of the boresight-direction angle minus ``cos(angle)`` (keep-out), or the
            negative (keep-in).
        """
        pointing = ca.mtimes(qc.rotation_matrix(q), ca.DM(self.boresight))
        cosine = ca.dot(pointing, ca.DM(self.direction))
        return cosine - np.cos(self.angle) if self.keep_out else np.cos(self.angle) - cosine


@dataclass(frozen=True)
class OptimalControlProblem:
    """What to optimise. Structural fields shape the NLP; values are passed at solve time.

    Parameters
    ----------
    model : AttitudeModel
        The spacecraft model (state ``x = [q, ω, h_w]``, control ``u`` of its actuators).
    energy_weight : float
        Weight of ∫‖τ‖² dt, τ the actuators' body torque [N m] (objective in N² m² s).
    l1_weight : float
        Weight of ∫Σ|τ_i| dt [N m s] (slack variables).
    time_weight : float
        Weight of the final time T [s].
    free_time : bool
        T is a decision variable (bounded by the problem's duration) instead of a parameter.
    fixed_final_rate : bool
        The final body rate is constrained to ``ω_f``.
    cones : tuple of Cone
        Pointing constraints along the path.
    """

    model: AttitudeModel
    energy_weight: float = 1.0
    l1_weight: float = 0.0
    time_weight: float = 0.0
    free_time: bool = False
    fixed_final_rate: bool = True
    cones: tuple[Cone, ...] = ()

    @property
    def uses_slack(self) -> bool:
        """Whether the cost needs L1 slack variables (``l1_weight > 0``)."""
        return self.l1_weight > 0

    def stage_cost(self, x: Any, u: Any, t: Any, slack: Any = None) -> Any:
        """The running cost's integrand.

        Parameters
        ----------
        x : (nx,) CasADi expression
            Model state.
        u : (nu,) CasADi expression
            Actuator controls.
        t : CasADi scalar
            Time [s].
        slack : (3,) CasADi expression or None
            L1 slacks bounding ``|τ_i|`` [N m] (``None`` without an L1 cost).

        Returns
        -------
        CasADi scalar expression
            ``energy_weight ‖τ‖² + l1_weight Σ slack``.
        """
        torque = self.model.actuator_torque(x, u, t)
        cost = self.energy_weight * ca.sumsqr(torque)
        if slack is not None:
            cost += self.l1_weight * ca.sum1(slack)
        return cost

    def path_constraints(self, x: Any) -> list[Any]:
        """The cones' constraints at one state.

        Parameters
        ----------
        x : (nx,) CasADi expression
            Model state (its first four entries are the quaternion).

        Returns
        -------
        list of CasADi scalar expressions
            One ``g <= 0`` per cone.
        """
        return [cone.expression(x[0:4]) for cone in self.cones]


@dataclass
class NLP:
    """A transcribed problem: a built solver and how to read its solution.

    Parameters
    ----------
    solver : casadi.Function
        The ``nlpsol`` function (inputs ``x0, p, lbx, ubx, lbg, ubg, lam_x0, lam_g0``).
    n_w : int
        Number of decision variables.
    unpack : casadi.Function
        ``unpack(w, p) -> (T [s], states, controls)`` in the transcription's own point layout.
    lbg, ubg : ndarray
        Constraint bounds.
    free_time : bool
        T is a decision variable (the last entry of every stage state).
    n_stage_state : int
        Size of a stage state ``s_k`` (T included when free).
    n_interval : int
        Size of an interval's own variables ``c_k``.
    layout : dict
        Transcription-specific notes on the layout (may be empty).
    """

    solver: ca.Function
    n_w: int
    unpack: ca.Function
    lbg: Array
    ubg: Array
    free_time: bool
    n_stage_state: int
    n_interval: int
    layout: dict[str, Any] = field(default_factory=dict)


@dataclass
class Interval:
    """One mesh interval, built by a transcription.

    Parameters
    ----------
    function : casadi.Function
        ``function(s, c, t0, h, d) -> (next, path, cost)`` with ``s`` the stage state without T,
        ``c`` the interval's variables, ``t0`` its start time [s], ``h`` its length [s], ``d`` the
        disturbance parameter (body torque [N m]); ``next`` is the stage state the interval reaches.
    n_state : int
        Size of ``s`` (without T).
    n_interval : int
        Size of ``c``.
    path_lower, path_upper : ndarray
        Bounds of ``path`` (``path_lower <= path <= path_upper``).
    """

    function: ca.Function
    n_state: int
    n_interval: int
    path_lower: Array
    path_upper: Array
