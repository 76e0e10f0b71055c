"""The reference of an optimal-control solution, and seeds for the NLP from other references (bent
round the keep-out cones they enter).

Between its points the solution is interpolated by the transcription itself
(``Transcription.interpolate``: Lagrange polynomials for collocation, cubic Hermite for shooting);
the reference's controls are that interpolant saturated at the box bounds the NLP imposed on them at
the points (a bang-bang control's polynomial overshoots its bound between the points, an artefact of
the interpolation the solution does not ask for), its states are the interpolant as it is.

The state polynomial integrates the unsaturated control, whose overshoot carries part of the impulse
of a switch inside an interval: clipped alone, the control loses it (Bilimoria & Wie, N = 50: the
saturated control flown open loop ended 0.55° from the target, the full inertia case 0.38° and 2e-3
rad/s). So in an interval where a control entry leaves its bounds, the entry is shifted by the
constant that gives the saturated control the interval's impulse of the unsaturated one,
``∫ clip(p + c) dt = ∫ p dt`` (:attr:`CollocationReference.impulse_offsets`; the integral lies within
the bounds times h, the Radau quadrature of values within them, so such a ``c`` exists): flown open
loop the slews end 0.0099° and 0.0068° from their targets. Entries within their bounds are read
unchanged. The blocks scaled as a whole (below: a redundant or skewed wheel array, on which the
allocation is imposed) are not shifted: there the clip's loss remains (a four-wheel pyramid's
minimum time flown open loop: 0.40°). For a magnetorquer the entry is the dipole: its integral is
kept, the torque's ``∫ m × B`` only to first order in the field's turn over the interval.

The feed-forward torque is the optimal control expressed for ``I ω̇ = −ω × I ω + u``:
``u = τ_actuators − ω × A h_w + τ_environment``, and ``ω̇`` comes from the model under the
saturated control, so torque and ``ω̇`` agree with each other. Where the saturation acts they do not
agree with the time derivative of the interpolated ``ω`` inside the interval (the polynomial's
overshoot is not flown); at the points they agree (the solution meets its bounds there) except in
the shifted intervals, whose points are therefore no enforced times
(:attr:`CollocationReference.enforced_times`), and over each interval the impulses agree.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, cast

import numpy as np

from ocp import quat
from ocp.geometry import PointingConstraint
from ocp.transcription.base import Transcription
from planners.problem import Array, ManeuverProblem
from planners.reference import Reference, ReferenceSample

IMPULSE_POINTS = 64
"""Midpoints per interval on which :attr:`CollocationReference.impulse_offsets` finds where a control
leaves its bounds and matches the impulses (the midpoint rule's error on a degree-2 polynomial with
its clipped kinks: about 1e-5 of a switch's impulse)."""
IMPULSE_SLACK = 1e-6
"""An entry leaves its bounds when it passes them by more than this fraction of the larger bound (a
bang arc's polynomial through points within the solver's tolerance of the bound passes it by about
that: the impulse its clip loses is negligible)."""
IMPULSE_BISECTIONS = 60
"""Bisection steps for each offset (the bracket, a few times the bound, halved 60 times)."""


def _scaled(values: Array, low: Array, high: Array) -> Array:
    """A block of controls (rows per time, ``(..., nb)``) scaled down as a whole until each entry is
    within its bound, its direction kept."""
    bound = np.where(values > 0, high, -low)
    ratio = np.divide(np.abs(values), bound, out=np.zeros_like(values), where=bound > 0)
    return values / np.maximum(ratio.max(axis=-1, initial=1.0), 1.0)[..., None]


class CollocationReference(Reference):
    """Evaluates the optimal states and controls of a transcribed problem.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its model and spacecraft).
    transcription : Transcription
        The transcription that produced the solution (it interpolates it).
    duration : float
        T [s].
    states, controls : ndarray
        The solution at the transcription's points (``NLP.unpack``'s layout): model states
        ``[q, ω, h_w]`` and actuator controls, one column per point.
    stats : dict
        Planner statistics.
    control_bounds : tuple of (nu,) ndarray, optional
        ``(u_low, u_high)``: the bounds the NLP imposed on the controls at the points (the actuator
        limits scaled by ``1 − actuator_margin`` and any tightening; ``±inf``: none), in the layout
        of ``model.control_slices`` [N m, A m^2]. Between the points the interpolated controls are
        saturated at them (at the points, where the solution meets them, this changes nothing);
        ``None`` (default): read as interpolated.
    scaled_blocks : tuple of slice, optional
        Blocks of the controls saturated as a whole, scaled down until each entry is within its
        bound (their direction kept), instead of clipped entry by entry: the blocks on which the
        planner imposed the controllers' allocation (:mod:`planners.collocation.allocation`), whose
        equalities a clip would break between the points (a pyramid's wheel torques clipped to
        their bounds leave the row space of the axes: 1.0008 times the limit through ``A⁺``);
        default none.
    """

    def __init__(self, problem: ManeuverProblem, transcription: Transcription, duration: float, states: Array,
                 controls: Array, stats: dict[str, Any], control_bounds: tuple[Array, Array] | None = None,
                 scaled_blocks: tuple[slice, ...] = ()) -> None:
        breakpoints, inner = transcription.smoothness(duration)
        super().__init__("collocation", duration, problem.spacecraft.inertia, stats=stats,
                         free_boundary=(), breakpoints=breakpoints, enforced_times=inner)
        self.model, self.transcription = problem.model, transcription
        self.states, self.controls = states, controls
        self.intervals = transcription.intervals
        self.disturbance = problem.model.default_parameters
        self.control_bounds = control_bounds
        self.scaled_blocks = scaled_blocks
        self._impulse_offsets: Array | None = None

    def _interpolated(self, t: Array, left: bool = False) -> tuple[Array, Array]:
        """States and controls as the transcription interpolates them (controls not saturated)."""
        return self.transcription.interpolate(self.model, self.states, self.controls, self.duration, t, left)

    @property
    def enforced_times(self) -> Array | None:
        """The times where the dynamics are imposed and the reference reads them as solved: the
        transcription's points, less those of the intervals whose controls
        :attr:`impulse_offsets` shifts (there the control flown is not the solution's at the
        points, so ``ω̇`` is not the derivative of the interpolated ``ω``).

        Returns
        -------
        (n,) ndarray or None
            Times [s], sorted.
        """
        times = self._enforced_times
        if times is None or self.control_bounds is None or times.size == 0:
            return times
        shifted = np.any(self.impulse_offsets != 0.0, axis=1)
        if not np.any(shifted):
            return times
        # a point at a node τ_d = 1 belongs to the interval it ends (the Radau point of that interval)
        return times[~shifted[self.transcription.interval_index(self.duration, times, left=True)]]

    @enforced_times.setter
    def enforced_times(self, times: Array | None) -> None:
        self._enforced_times = times

    @property
    def impulse_offsets(self) -> Array:
        """Per interval and control entry, the constant ``c`` added to the entry's polynomial ``p``
        before it is clipped to its bounds (module docstring).

        Returns
        -------
        (N, nu) ndarray
            ``c`` in the controls' units: nonzero only where ``p`` leaves its bounds inside the
            interval (found on :data:`IMPULSE_POINTS` midpoints per interval) and the entry is in no
            :attr:`scaled_blocks`; there ``∫ clip(p + c) = ∫ p`` over the interval (the same
            midpoint rule both sides, solved by bisection: ``clip(p + c)`` is monotone in ``c``).
            Zeros without :attr:`control_bounds`.
        """
        if self._impulse_offsets is None:
            self._impulse_offsets = self._offsets()
        return self._impulse_offsets

    def _offsets(self) -> Array:
        N, nu = self.intervals, self.model.nu
        offsets = np.zeros((N, nu))
        if self.control_bounds is None or self.duration <= 0.0:
            return offsets
        low, high = self.control_bounds
        shifted = np.ones(nu, dtype=bool)
        for block in self.scaled_blocks:
            shifted[block] = False
        tau = (np.arange(IMPULSE_POINTS) + 0.5) / IMPULSE_POINTS
        t = ((np.arange(N)[:, None] + tau[None, :]) * (self.duration / N)).ravel()
        p = self._interpolated(t)[1].reshape(N, IMPULSE_POINTS, nu)
        slack = IMPULSE_SLACK * np.maximum(np.abs(np.where(np.isfinite(low), low, 0.0)),
                                           np.abs(np.where(np.isfinite(high), high, 0.0)))
        k, i = np.nonzero(np.any((p > high + slack) | (p < low - slack), axis=1) & shifted)
        if k.size == 0:
            return offsets
        values, lo, hi = p[k, :, i], low[i][:, None], high[i][:, None]
        impulse = values.mean(axis=1)
        finite = np.where(np.isfinite(lo), np.abs(lo), 0.0) + np.where(np.isfinite(hi), np.abs(hi), 0.0)
        a = -(np.abs(values).max(axis=1) + finite[:, 0])  # clip(p + a) = low (or p + a < impulse)
        b = -a  # clip(p + b) = high (or p + b > impulse)
        for _ in range(IMPULSE_BISECTIONS):
            c = 0.5 * (a + b)
            below = np.clip(values + c[:, None], lo, hi).mean(axis=1) < impulse
            a, b = np.where(below, c, a), np.where(below, b, c)
        offsets[k, i] = 0.5 * (a + b)
        return offsets

    def _state_control(self, t: Array, left: bool = False) -> tuple[Array, Array]:
        """The reference's states and controls: :meth:`_interpolated`, the controls saturated at
        :attr:`control_bounds` (the :attr:`scaled_blocks` scaled as a whole, the others shifted by
        :attr:`impulse_offsets` and clipped; the states are not: a wheel momentum's overshoot is the
        solution's)."""
        x, u = self._interpolated(t, left)
        if self.control_bounds is not None:
            low, high = self.control_bounds
            u = u + self.impulse_offsets[self.transcription.interval_index(self.duration, t, left)]
            for block in self.scaled_blocks:  # scaled as a whole: the allocation's equalities kept
                u[:, block] = _scaled(u[:, block], low[block], high[block])
            u = np.clip(u, low, high)
        return x, u

    def control(self, t: float | Array) -> Array:
        """The optimal actuator control.

        Parameters
        ----------
        t : float or (n,) array_like
            Times [s], clipped to ``[0, T]``.

        Returns
        -------
        (nu,) or (n, nu) ndarray
            Controls in the layout of ``model.control_slices`` (wheel torques [N m], dipoles
            [A m^2], torquer torques [N m]).
        """
        times = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        controls = self._state_control(times)[1]
        return controls[0] if np.ndim(t) == 0 else controls

    def _rhs(self, x: Array, u: Array, t: Array) -> Array:
        n = x.shape[0]
        times = np.broadcast_to(t, (n,))
        return self.model.rhs.map(n)(x.T, u.T, times, np.tile(self.disturbance[:, None], n)).full().T

    def _evaluate(self, t: Array) -> ReferenceSample:
        x, u = self._state_control(t)
        n = t.size
        x_dot = self._rhs(x, u, t)
        actuator = self.model.body_torque.map(n)(x.T, u.T, t).full().T
        environment = self.model.environment_torque.map(n)(x.T, t, np.tile(self.disturbance[:, None], n)).full().T
        omega = x[:, 4:7]
        wheel_momentum = x[:, 7:] @ self.model.spacecraft.wheel_axes.T
        torque = actuator - np.cross(omega, wheel_momentum) + environment
        return ReferenceSample(quat.normalize(x[:, 0:4]), omega, x_dot[:, 4:7], torque)


def states_controls(problem: ManeuverProblem, reference: Reference, times: Array) -> tuple[Array, Array, ReferenceSample]:
    """The model's states and actuator controls along another planner's reference.

    Wheel momenta from the conservation of the total momentum (the stored momentum of
    ``problem.wheel_momentum0`` included; a failed wheel keeps its own), the wheel torques ``g = −A⁺ (u + ω × A h_w)`` for the
    reference's torque ``u`` (:attr:`~ocp.ReactionWheels.pseudo_inverse`: a failed wheel is given
    nothing), or the torquers' torque ``u``; other actuators' controls zero.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (model, spacecraft, initial state and wheel momentum).
    reference : Reference
        The reference.
    times : (n,) ndarray
        Times [s].

    Returns
    -------
    x : (n, nx) ndarray
        ``[q, ω, h_w]`` per time.
    u : (n, nu) ndarray
        Controls in the layout of ``model.control_slices``.
    sample : ReferenceSample
        The reference at ``times``.
    """
    sample = reference.sample(times)
    spacecraft, model = problem.spacecraft, problem.model
    axes = spacecraft.wheel_axes
    x = np.zeros((times.size, model.nx))
    x[:, 0:4], x[:, 4:7] = sample.q, sample.omega
    u = np.zeros((times.size, model.nu))
    body_momentum = sample.omega @ spacecraft.inertia.T
    if model.n_wheels:
        wheels = spacecraft.wheels
        assert wheels is not None  # n_wheels > 0
        wheel_momentum = cast(Array, problem.wheel_momentum0)  # zeros when not given (ManeuverProblem)
        total = quat.rotate(problem.q0, spacecraft.inertia @ problem.omega0 + axes @ wheel_momentum)
        held = np.where(wheels.working, 0.0, wheel_momentum)  # a failed wheel keeps its momentum (no torque)
        wheel_total = (quat.rotate_inverse(sample.q, np.broadcast_to(total, sample.q.shape[:-1] + (3,)))
                       - body_momentum - axes @ held)
        x[:, 7:] = wheel_total @ wheels.pseudo_inverse.T + held
        wheel_torque = sample.torque + np.cross(sample.omega, x[:, 7:] @ axes.T)
        u[:, model.control_slices["wheels"]] = -wheel_torque @ wheels.pseudo_inverse.T
    elif "torquers" in model.control_slices:
        u[:, model.control_slices["torquers"]] = sample.torque
    return x, u, sample


def seed_sampler(problem: ManeuverProblem, reference: Reference) -> Callable[[Array], tuple[Array, Array, Array]]:
    """The seed of a transcription along another planner's reference.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (model, initial wheel momentum).
    reference : Reference
        The seeding reference.

    Returns
    -------
    callable
        ``sample(times [s]) -> (x (n, nx), u (n, nu), |torque| (n, 3) [N m])``, the form a
        transcription's ``stage_guess`` seeds from.
    """

    def sample(times: Array) -> tuple[Array, Array, Array]:
        x, u, sample = states_controls(problem, reference, times)
        return x, u, np.abs(sample.torque)

    return sample


def solution_sampler(reference: CollocationReference) -> Callable[[Array], tuple[Array, Array, Array]]:
    """The seed of a transcription along another transcription's solution, read natively.

    Unlike :func:`seed_sampler`, the states and actuator controls are the solution's own,
    interpolated by its transcription (no inverse dynamics, no mapping of the torque to the
    actuators; the quaternion normalised as :meth:`Reference.sample` does): the seed of a fine
    mesh from a coarse-mesh optimum of the same problem. At a node of the solution's mesh the
    controls are read from the interval that ends there (``interpolate(left=True)``), as a Radau
    point ``τ_d = 1`` of the seeded mesh belongs to the interval it ends; the interval that starts
    there would give its control polynomial extrapolated to ``τ = 0``, wrong across a switch. The
    nodes of 8 and 50 intervals meet at T/2, where Bilimoria & Wie's slew switches: the seed's
    collocation residual 0.13 there (the largest) disappears and the full-mesh solve takes 10
    IPOPT iterations instead of 12 (same optimum; 28 other minimum-time and minimum-energy cases
    unchanged).

    Parameters
    ----------
    reference : CollocationReference
        The solution.

    Returns
    -------
    callable
        ``sample(times [s]) -> (x (n, nx), u (n, nu), |τ| (n, 3) [N m])``, τ the actuators' body
        torque, times clipped to ``[0, T]``.
    """
    model = reference.model

    def sample(times: Array) -> tuple[Array, Array, Array]:
        t = np.clip(np.asarray(times, dtype=float), 0.0, reference.duration)
        x, u = reference._interpolated(t, left=True)  # as solved (IPOPT pushes a seed into its bounds)
        x[:, 0:4] = quat.normalize(x[:, 0:4])  # as Reference.sample does
        torque = model.body_torque.map(t.size)(x.T, u.T, t).full().T
        return x, u, np.abs(torque)

    return sample


def cone_sides(sample: Callable[[Array], tuple[Array, Array, Array]], constraints: tuple[PointingConstraint, ...],
               duration: float, points: int = 401) -> tuple[list[Array | None], bool]:
    """Per keep-out constraint, the side a seed goes round its cone (:func:`cone_avoiding_sampler`).

    Where the seed's boresight comes nearest the cone's centre, the side is the direction from the
    centre towards it (on the sphere); when it passes through the centre (within 0.1 deg, the
    eigenaxis seed of a symmetric case), the side is perpendicular to its path there.

    Parameters
    ----------
    sample : callable
        The seed, ``sample(times) -> (x, u, |τ|)``.
    constraints : tuple of PointingConstraint
        The constraints imposed.
    duration : float
        The seed's duration [s].
    points : int, optional
        Samples of the seed searched for the closest approach.

    Returns
    -------
    sides : list of (3,) ndarray or None
        A unit vector, inertial frame, per constraint (perpendicular to the direction at the
        closest approach; :func:`cone_avoiding_sampler` projects it on the plane perpendicular to a
        moving direction); ``None`` for a keep-in or a constraint the seed never enters.
    central : bool
        Whether the seed passes within half a cone's angle of its centre, where neither side is
        clearly nearer.
    """
    t = np.linspace(0.0, duration, points)
    q = quat.normalize(sample(t)[0][:, 0:4])
    sides: list[Array | None] = []
    central = False
    for constraint in constraints:
        margin = constraint.margins(t, q)
        if not constraint.keep_out or not np.any(margin < 0.0):
            sides.append(None)
            continue
        pointing, centres = quat.rotate(q, constraint.boresight), constraint.direction(t)
        nearest = int(np.nanargmin(np.where(np.isfinite(margin), -np.einsum("ij,ij->i", pointing, centres), np.nan)))
        centre = centres[nearest]
        central |= bool(pointing[nearest] @ centre > np.cos(0.5 * constraint.limit([t[nearest]])[0]))
        radial = pointing[nearest] - (pointing[nearest] @ centre) * centre
        if np.linalg.norm(radial) > np.sin(np.deg2rad(0.1)):
            sides.append(radial / np.linalg.norm(radial))
            continue
        before, after = pointing[max(nearest - 1, 0)], pointing[min(nearest + 1, points - 1)]
        side = np.cross(centre, after - before)
        sides.append(side / np.linalg.norm(side) if np.linalg.norm(side) > 0 else None)
    return sides, central


def cone_avoiding_sampler(sample: Callable[[Array], tuple[Array, Array, Array]],
                          constraints: tuple[PointingConstraint, ...], sides: list[Array | None],
                          pad: float) -> Callable[[Array], tuple[Array, Array, Array]]:
    """A seed bent round the keep-out cones it enters.

    The eigenaxis seed of a slew whose boresight passes through a cone's centre is a poor start:
    the solver must choose a side with nothing to choose it by (one start of the issue's 12U case
    ran to its iteration limit). Here, where the seed's boresight ``p`` lies within ``limit + pad``
    of the centre ``d``, the attitude is turned (in inertial axes) about ``d × s``, ``s`` the
    constraint's side (:func:`cone_sides`), by the least angle that takes ``p`` to ``limit + pad``
    from ``d``: the boresight then runs along the cone's rim on that side. Body rates, wheel
    momenta and controls are the seed's own (a start need not be consistent).

    Parameters
    ----------
    sample : callable
        The seed, ``sample(times) -> (x, u, |τ|)``.
    constraints : tuple of PointingConstraint
        The constraints imposed (only those with a side are used).
    sides : list of (3,) ndarray or None
        :func:`cone_sides` (or the opposite sides).
    pad : float
        How far outside the cone the seed is put [rad].

    Returns
    -------
    callable
        ``sample(times) -> (x, u, |τ|)`` with the attitudes bent.
    """

    def bent(times: Array) -> tuple[Array, Array, Array]:
        x, u, torque = sample(times)
        x = np.array(x, dtype=float)
        q = quat.normalize(x[:, 0:4])
        for constraint, side in zip(constraints, sides):
            if side is None:
                continue
            centre = constraint.direction(times)
            sideways = side - (centre @ side)[:, None] * centre
            sideways /= np.linalg.norm(sideways, axis=1, keepdims=True)
            pointing = quat.rotate(q, constraint.boresight)
            a, b = np.einsum("ij,ij->i", pointing, centre), np.einsum("ij,ij->i", pointing, sideways)
            radius, phase = np.hypot(a, b), np.arctan2(b, a)
            target = np.cos(constraint.limit(times) + pad)
            with np.errstate(invalid="ignore", divide="ignore"):
                reach = np.arccos(np.clip(target / radius, -1.0, 1.0))
            turn = np.where(constraint.in_window(times) & (a > target) & (radius > np.abs(target)),
                            np.maximum(reach - phase, 0.0), 0.0)
            # about d × s: d turns towards s (the boresight away from d, round the side s)
            q = quat.normalize(quat.product(quat.from_axis_angle(np.cross(centre, sideways), turn), q))
        x[:, 0:4] = q
        return x, u, torque

    return bent
