r"""What an optimal-control problem asks for, and what a transcription builds from it.

:class:`OptimalControlProblem` (objective weights, free final time, final rate, path constraints:
pointing cones as :class:`~ocp.geometry.PointingConstraint`\ s and a bound on the body-rate norm)
is the problem; :class:`Interval` is one mesh interval as a transcription builds it and :class:`NLP`
the assembled, built problem (see :mod:`ocp.transcription.base`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.dynamics.model import AttitudeModel
from ocp.geometry import PointingConstraint

Array = NDArray[np.float64]


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
    cones : tuple of ocp.geometry.PointingConstraint
        Pointing constraints along the path, as imposed (a planner passes them already tightened);
        a moving direction is evaluated at each point's own time.
    max_rate : float or None
        Bound on the body-rate norm ``‖ω‖`` [rad/s], imposed where the cones are; ``None``: none
        (a per-axis bound is a bound on the state variables instead, set by the planner).

    Notes
    -----
    Windows. With a fixed final time a transcription's points have known times (``T`` is a
    parameter), and a cone whose window does not cover the whole run is switched off at the points
    outside it: its constraint there is the constant ``-1`` (``if_else`` on the parameters, no
    discontinuity in the decision variables). With a free final time the points' times are
    unknown before the solve, and a windowed cone is imposed over the whole run (conservative: a
    superset of its window).
    """

    model: AttitudeModel
    energy_weight: float = 1.0
    l1_weight: float = 0.0
    time_weight: float = 0.0
    free_time: bool = False
    fixed_final_rate: bool = True
    cones: tuple[PointingConstraint, ...] = ()
    max_rate: float | None = None

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

    @property
    def n_path(self) -> int:
        """Number of path constraints at each point (:meth:`path_constraints`)."""
        return len(self.cones) + (self.max_rate is not None)

    def path_constraints(self, x: Any, t: Any) -> list[Any]:
        """The cones' constraints and the rate-norm bound at one point.

        Parameters
        ----------
        x : (nx,) CasADi expression
            Model state (its first four entries are the quaternion, the next three the body rate).
        t : CasADi scalar
            The point's time [s] (a moving direction is interpolated there; a window is tested
            there when the final time is fixed).

        Returns
        -------
        list of CasADi scalar expressions
            :attr:`n_path` constraints ``g <= 0``: one per cone
            (:meth:`~ocp.geometry.PointingConstraint.expression`, the constant ``-1`` outside its
            window), then ``‖ω‖² / max_rate² − 1`` with a rate bound.
        """
        constraints = []
        for cone in self.cones:
            g = cone.expression(x[0:4], t)
            start, end = cone.window
            if not self.free_time and (start > 0.0 or np.isfinite(end)):
                inside = 1
                if start > 0.0:
                    inside = inside * (t >= start)
                if np.isfinite(end):
                    inside = inside * (t <= end)
                g = ca.if_else(inside, g, -1.0)
            constraints.append(g)
        if self.max_rate is not None:
            constraints.append(ca.sumsqr(x[4:7]) / self.max_rate**2 - 1.0)
        return constraints


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

    The arrays (``lbg``, ``ubg``, those in ``layout``) are made read-only here: an NLP is shared
    by every plan of its cache entry.
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

    def __post_init__(self) -> None:
        # A built NLP is shared by every plan of its cache entry: its arrays are read-only.
        for value in (self.lbg, self.ubg, *self.layout.values()):
            if isinstance(value, np.ndarray):
                value.setflags(write=False)


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
