"""The problem side of ``collocation``: its own pointing cones from their YAML form, the endpoints
checked against every pointing constraint, and the variables' bounds from the spacecraft."""
from __future__ import annotations

import numpy as np

from ocp.dynamics.layout import actuator_blocks
from ocp.errors import InvalidOption, excerpt
from ocp.geometry import PointingConstraint
from planners.problem import Array, ManeuverProblem


def _cone_vector(spec: dict, key: str, where: str) -> np.ndarray:
    value = spec[key]
    if (not isinstance(value, (list, tuple)) or len(value) != 3
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise InvalidOption(f"{where}.{key}", f"expected 3 numbers, got {excerpt(value)}")
    vector = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(vector)) or not np.linalg.norm(vector) > 0:
        raise InvalidOption(f"{where}.{key}", f"expected a finite non-zero vector, got {excerpt(value)}")
    return vector / np.linalg.norm(vector)


def parse_cone(spec: dict, keep_out: bool, margin: float = 0.0, where: str = "cone") -> PointingConstraint:
    """The pointing constraint of a ``keep_out`` or ``keep_in`` option entry.

    Parameters
    ----------
    spec : dict
        ``boresight`` (body axes) and ``direction`` (inertial) as 3-vectors, ``angle_deg`` the
        cone's half-angle [deg], in (0, 180).
    keep_out : bool
        The boresight must stay outside (``True``) or inside (``False``) the cone.
    margin : float, optional
        How much tighter [rad] the planner imposes the cone (``cone_margin_deg``); the tightened
        cone must still be a cone.
    where : str, optional
        The option's path (``keep_out[0]``): the constraint's name and the path of error messages.

    Returns
    -------
    PointingConstraint
        Named ``where``, the direction fixed over the whole run, the angle as given [rad] (not
        tightened: :meth:`~ocp.geometry.PointingConstraint.tightened` gives what is imposed).

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
    return PointingConstraint(where, boresight, keep_out, float(np.deg2rad(angle)), directions=direction[None, :],
                              description=f"inertial {np.round(direction, 6).tolist()}")


def endpoint_cone_error(constraints: tuple[PointingConstraint, ...], q0: Array, qf: Array | None, duration: float,
                        free_time: bool = False) -> str | None:
    """Which pointing constraints the initial or final attitude breaks (no trajectory can then meet them).

    Parameters
    ----------
    constraints : tuple of PointingConstraint
        The constraints as the planner imposes them (tightened, windows as imposed).
    q0 : (4,) array_like
        Initial attitude (body to inertial, scalar first), checked at t = 0.
    qf : (4,) array_like or None
        Final attitude, checked at t = ``duration``; ``None``: free, not checked.
    duration : float
        The final time [s] (its upper bound when free).
    free_time : bool, optional
        The final time is free: a windowed constraint is then imposed over the whole run
        (:class:`ocp.transcription.OptimalControlProblem`), so both ends are checked whatever the
        window; the final attitude is not checked against a moving direction (its time is unknown).

    Returns
    -------
    str or None
        A message naming each broken constraint, the attitude, the angle between the boresight
        and the direction and the cone's limit [deg]; ``None`` when both ends meet every constraint.
    """
    broken = []
    for constraint in constraints:
        for label, q, t in (("initial", q0, 0.0), ("final", qf, duration)):
            if q is None or (free_time and label == "final" and constraint.moving):
                continue
            if not free_time and not constraint.in_window(t)[0]:
                continue
            angle = float(constraint.angles([t], [q])[0])
            limit = float(constraint.limit([t])[0])
            if (angle < limit) if constraint.keep_out else (angle > limit):
                side = "inside" if constraint.keep_out else "outside"
                broken.append(f"{constraint.name}: the {label} attitude puts the boresight {np.rad2deg(angle):.4g} deg "
                              f"from the direction, {side} the cone of {np.rad2deg(limit):.4g} deg (the angle "
                              f"tightened by cone_margin_deg" + (", its window imposed over the whole run with a "
                                                                 "free final time: a fixed final time imposes it "
                                                                 "in its window only" if free_time else "") + ")")
    return "; ".join(broken) or None


def variable_bounds(problem: ManeuverProblem, max_rate: float | None,
                    scale: float = 1.0) -> tuple[Array, Array, Array, Array]:
    """Per-point bounds of the model state and the actuator controls.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its spacecraft's actuators and model layout).
    max_rate : float or None
        Body-rate bound per axis [rad/s]; ``None``: none.
    scale : float, optional
        Factor on every actuator bound (controls and actuator states: torques, dipoles, wheel
        momenta), in (0, 1]: ``1 − actuator_margin`` for the actuator requirement; default 1.

    Returns
    -------
    tuple of ndarray
        ``(x_low, x_high)`` (nx,): quaternion within ±1.5, body rate [rad/s], wheel momenta
        [N m s]; ``(u_low, u_high)`` (nu,): wheel torques [N m] (0 for a failed wheel), dipoles
        [A m^2], torquer torques [N m], in the layout of ``model.control_slices``; ``±inf``: none.
    """
    spacecraft, model = problem.spacecraft, problem.model
    x_low, x_high = np.full(model.nx, -np.inf), np.full(model.nx, np.inf)
    x_low[0:4], x_high[0:4] = -1.5, 1.5
    if max_rate is not None:
        x_low[4:7], x_high[4:7] = -max_rate, max_rate
    u_low, u_high = np.full(model.nu, -np.inf), np.full(model.nu, np.inf)
    states_low, states_high = x_low[7:], x_high[7:]  # views: the actuators' states
    for block in actuator_blocks(spacecraft):
        low, high = block.actuator.control_bounds()
        u_low[block.control], u_high[block.control] = scale * low, scale * high
        low, high = block.actuator.state_bounds()
        states_low[block.state], states_high[block.state] = scale * low, scale * high
    return x_low, x_high, u_low, u_high
