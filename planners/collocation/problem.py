"""The problem side of ``collocation``: pointing cones from their YAML form, and the variables'
bounds from the spacecraft."""
from __future__ import annotations

import numpy as np

from ocp import quat
from ocp.dynamics.layout import actuator_blocks
from ocp.errors import InvalidOption, excerpt
from ocp.transcription import Cone
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


def parse_cone(spec: dict, keep_out: bool, margin: float = 0.0, where: str = "cone") -> Cone:
    """A :class:`Cone` from ``{boresight, direction, angle_deg}``, tightened by ``margin`` (rad).

    Parameters
    ----------
    spec : ``boresight`` (body axes) and ``direction`` (inertial) as 3-vectors, ``angle_deg`` the
        cone's half-angle in degrees, in (0, 180).
    keep_out : the boresight must stay outside (``True``) or inside (``False``) the cone.
    margin : rad by which the cone is tightened.
    where : the option's path (``keep_out[0]``) for error messages.

    Returns
    -------
    Cone
        The (tightened) cone, unit vectors, angle in rad.

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


def endpoint_cone_error(cones: tuple[Cone, ...], names: list[str], q0: Array, qf: Array | None) -> str | None:
    """Which cones the initial or final attitude breaks (no trajectory can then meet them).

    Parameters
    ----------
    cones : tuple of Cone
        The (tightened) cones of the problem, unit vectors, half-angles [rad].
    names : list of str
        Each cone's option path (``keep_out[0]``), in the order of ``cones``.
    q0 : (4,) array_like
        Initial attitude (body to inertial, scalar first).
    qf : (4,) array_like or None
        Final attitude; ``None``: free, not checked.

    Returns
    -------
    str or None
        A message naming each broken cone, the attitude and the angle between the boresight
        and the direction [deg]; ``None`` when both endpoints meet every cone.
    """
    broken = []
    for cone, name in zip(cones, names):
        for label, q in (("initial", q0), ("final", qf)):
            if q is None:
                continue
            angle = float(np.arccos(np.clip(np.dot(quat.rotate(q, cone.boresight), cone.direction), -1.0, 1.0)))
            if (angle < cone.angle) if cone.keep_out else (angle > cone.angle):
                side = "inside" if cone.keep_out else "outside"
                broken.append(f"{name}: the {label} attitude puts the boresight {np.rad2deg(angle):.4g} deg from "
                              f"the direction, {side} the cone of {np.rad2deg(cone.angle):.4g} deg "
                              f"(angle_deg tightened by cone_margin_deg)")
    return "; ".join(broken) or None


def variable_bounds(problem: ManeuverProblem, max_rate: float | None) -> tuple[Array, Array, Array, Array]:
    """Per-point bounds of the model state and the actuator controls.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its spacecraft's actuators and model layout).
    max_rate : float or None
        Body-rate bound per axis [rad/s]; ``None``: none.

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
        u_low[block.control], u_high[block.control] = block.actuator.control_bounds()
        states_low[block.state], states_high[block.state] = block.actuator.state_bounds()
    return x_low, x_high, u_low, u_high
