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
unchanged. For a magnetorquer the entry is the dipole: its integral is kept, the torque's
``∫ m × B`` only to first order in the field's turn over the interval.

The blocks scaled as a whole (:attr:`CollocationReference.scaled_blocks`: a redundant wheel array
on which the allocation is imposed, such as a four-wheel pyramid, or torquers beside two wheels)
are shifted as a whole: in an interval where the block leaves its bounds, by the vector ``c`` in
the directions the allocation's equalities leave (``E c = 0``, the null space of the block's rows
of :func:`~planners.collocation.allocation.allocation_constraints`; none on an entry held at zero
by its bounds, a failed wheel) for which ``mean scaled(p + c) = mean p`` on the interval's
midpoints, so the shifted block is still the allocation of its torque. The map ``c -> mean
scaled(p + c)`` is continuous and piecewise smooth but not monotone, so ``c`` is found by a
Newton search with step lengths, damping and a fixed-point step to choose from, each taken only
where it lowers the residual (``_block_offsets``). Where the points of an arc pass a vertex of
the box by the solver's bound relaxation (all four wheels at their limits), no ``c`` reaches the
mean: an offset that does not halve the residual is dropped (:data:`IMPULSE_GAIN`;
:attr:`CollocationReference.impulse_residuals` records what is left). Flown open loop
(2026-12-02), the user's pyramid (120°, non-principal inertia) minimum time ends 0.0176° from its
target instead of 0.155° scaled alone, a 30° pyramid's (100°) 0.0104° instead of 0.603°.

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

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp import quat
from ocp.cache import RecentCache
from ocp.dynamics.integration import rk4_step
from ocp.dynamics.model import AttitudeModel
from ocp.fast_call import matrices
from ocp.geometry import PointingConstraint
from ocp.transcription.base import Transcription
from planners.collocation.allocation import allocation_constraints
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
IMPULSE_ITERATIONS = 40
"""Steps at most of the search for a scaled block's offset (``_block_offsets``; on a pyramid's
switches it reaches the residual's floor in about 10, linearly: points on an arc at a vertex of the
box sit where the scaling's derivative jumps)."""
IMPULSE_GAIN = 0.5
"""A scaled block's offset is kept where it leaves at most this fraction of the impulse residual it
had without one. Where it does not, the loss is not the interpolation's overshoot: an arc along a
vertex of the block's box (a pyramid's four wheels at their limits) whose points pass the bounds by
the solver's relaxation (IPOPT's ``bound_relax_factor``, 1e-8 N m absolute below 1 N m) has a
mean outside what the scaled block reaches, by that much, whatever the offset."""
IMPULSE_TOLERANCE = 1e-14
"""A scaled block's offset is found when its impulse residual (projected on the block's allowed
directions) is within this fraction of the block's largest bound."""
IMPULSE_STALL = 0.01
"""The search for a scaled block's offset ends on an interval when its best step reduces the residual
by less than this fraction (the step is taken)."""


def _scaled(values: Array, low: Array, high: Array) -> Array:
    """A block of controls (rows per time, ``(..., nb)``) scaled down as a whole until each entry is
    within its bound, its direction kept."""
    bound = np.where(values > 0, high, -low)
    ratio = np.divide(np.abs(values), bound, out=np.zeros_like(values), where=bound > 0)
    return values / np.maximum(ratio.max(axis=-1, initial=1.0), 1.0)[..., None]


def _allowed_directions(rows: Array | None, low: Array, high: Array) -> Array:
    """An orthonormal basis ``(nb, r)`` of the offsets a scaled block may take: those the
    allocation's equalities leave (the null space of the block's columns of ``rows``, ``E c = 0``)
    and with no component on an entry held at zero by its bounds (a failed wheel)."""
    fixed = np.eye(low.size)[~(high > low)]
    constraints = fixed if rows is None else np.vstack([rows, fixed])
    if constraints.shape[0] == 0:
        return np.eye(low.size)
    _, singular, right = np.linalg.svd(constraints)
    rank = int(np.sum(singular > 1e-9 * max(float(singular.max(initial=0.0)), 1e-300)))
    return cast(Array, right[rank:].T)


def _flown_block(values: Array, offset: Array, low: Array, high: Array) -> Array:
    """A scaled block's control flown on an interval's points: ``values`` ``(..., K, M, nb)`` plus
    ``offset`` ``(..., K, nb)``, scaled as a whole and clipped as ``CollocationReference._state_control``
    reads it."""
    return np.clip(_scaled(values + offset[..., None, :], low, high), low, high)


def _block_offsets(values: Array, low: Array, high: Array, basis: Array) -> tuple[Array, Array]:
    """Per interval, the offset ``c`` (in the span of ``basis``) after which the scaled block keeps
    the interval's impulse, ``mean scaled(p + c) = mean p`` on its midpoints.

    The map ``c -> mean scaled(p + c)`` is continuous and piecewise smooth, not monotone (the
    radial scaling onto a box is not a projection), so a Newton step on the residual projected on
    the basis is tried with several step lengths, a Levenberg-Marquardt step with several dampings
    and the fixed-point step ``−residual``, all intervals at once; each interval takes the candidate
    with the least residual norm when it is less than its current one (from ``c = 0``: never worse
    than no shift) and stops when it is within :data:`IMPULSE_TOLERANCE` of the bound or no
    candidate improves.

    Parameters
    ----------
    values : (K, M, nb) ndarray
        The block's polynomial on the midpoints of K intervals.
    low, high : (nb,) ndarray
        The block's bounds.
    basis : (nb, r) ndarray
        Orthonormal directions the offset may take (``_allowed_directions``).

    Returns
    -------
    offsets : (K, nb) ndarray
        ``c`` per interval (the best found).
    residuals : (K, nb) ndarray
        ``mean scaled(p + c) − mean p`` per interval with that ``c``.
    """
    K, r = values.shape[0], basis.shape[1]
    target = values.mean(axis=1)
    finite = np.concatenate([np.abs(low[np.isfinite(low)]), np.abs(high[np.isfinite(high)])])
    tolerance = IMPULSE_TOLERANCE * float(finite.max(initial=0.0))
    # |c_i| within the per-entry bisection's bracket: beyond it the block is at its bounds throughout
    reach = np.abs(values).max(axis=(1, 2)) + float(np.max(np.where(np.isfinite(low), np.abs(low), 0.0)
                                                           + np.where(np.isfinite(high), np.abs(high), 0.0)))

    def residual(z: Array, k: NDArray[np.intp]) -> Array:  # intervals k, z (..., k, r) -> on the basis (..., k, r)
        return cast(Array, (_flown_block(values[k], z @ basis.T, low, high).mean(axis=-2) - target[k]) @ basis)

    def jacobian(z: Array, k: NDArray[np.intp]) -> Array:  # (k, r, r): d residual / d z
        x = values[k] + (z @ basis.T)[:, None, :]
        bound = np.where(x > 0, high, -low)
        ratio = np.divide(np.abs(x), bound, out=np.zeros_like(x), where=bound > 0)
        star = ratio.argmax(axis=-1)
        rho = np.maximum(ratio.max(axis=-1), 1.0)
        s = x / rho[..., None]
        s_star = np.take_along_axis(s, star[..., None], axis=-1)[..., 0]  # ±bound where scaled
        # x / ρ(x), ρ = |x_i*| / b_i*: d(x / ρ) = (1 − s e_i*ᵀ / s_i*) dx / ρ, on the basis
        moved = (basis - s[..., None] * basis[star][..., None, :]
                 / np.where(rho > 1.0, s_star, 1.0)[..., None, None]) / rho[..., None, None]
        per_point = np.where((rho > 1.0)[..., None, None], moved, basis)
        return cast(Array, basis.T @ per_point.mean(axis=1))

    z = np.zeros((K, r))
    current = residual(z, np.arange(K))
    norm = np.linalg.norm(current, axis=-1)
    initial = norm.copy()
    active = norm > tolerance
    lengths = np.array([1.0, 0.5, 0.25, 0.125, 1 / 16, 1 / 64])
    dampings = np.array([1e-2, 1.0, 1e2])
    identity = np.eye(r)
    for _ in range(IMPULSE_ITERATIONS):
        if not np.any(active):
            break
        (a,) = np.nonzero(active)
        J, R = jacobian(z[a], a), current[a]
        with np.errstate(all="ignore"):  # a singular system's step is not finite: never taken (below)
            newton = -np.einsum("kij,kj->ki", np.linalg.pinv(J, rcond=1e-12), R)
            JtJ, JtR = np.einsum("kji,kjl->kil", J, J), np.einsum("kji,kj->ki", J, R)
            scale = np.trace(JtJ, axis1=1, axis2=2)[:, None, None] / r + 1e-300
            marquardt = -np.linalg.solve(JtJ[:, None] + dampings[None, :, None, None] * scale[:, None] * identity,
                                         JtR[:, None, :, None])[..., 0]
            steps = np.concatenate([lengths[None, :, None] * newton[:, None, :], marquardt, -R[:, None, :]],
                                   axis=1)  # (k, C, r)
            trial = z[a][:, None, :] + steps
            size = np.abs(trial @ basis.T).max(axis=-1)
            trial *= np.minimum(1.0, reach[a][:, None] / np.maximum(size, 1e-300))[..., None]
            trial_residual = np.moveaxis(residual(np.moveaxis(trial, 1, 0), a), 0, 1)  # (k, C, r)
            trial_norm = np.linalg.norm(trial_residual, axis=-1)
        trial_norm[~np.isfinite(trial_norm)] = np.inf
        best = trial_norm.argmin(axis=1)
        rows = np.arange(a.size)
        better = trial_norm[rows, best] < norm[a]
        # a step that gains less than IMPULSE_STALL ends the search (the residual's floor reached)
        active[a[trial_norm[rows, best] >= (1.0 - IMPULSE_STALL) * norm[a]]] = False
        chosen = a[better]
        z[chosen] = trial[rows, best][better]
        current[chosen] = trial_residual[rows, best][better]
        norm[chosen] = trial_norm[rows, best][better]
        active &= norm > tolerance
    z[norm > IMPULSE_GAIN * initial] = 0.0  # the loss is not the interpolation's (docstring)
    offsets = z @ basis.T
    return offsets, _flown_block(values, offsets, low, high).mean(axis=1) - target


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
        their offsets keep those equalities (the rows of
        :func:`~planners.collocation.allocation.allocation_constraints` for the spacecraft);
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
        self._impulse_residuals: Array | None = None

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
            interval (found on :data:`IMPULSE_POINTS` midpoints per interval). For an entry in no
            :attr:`scaled_blocks`, ``∫ clip(p + c) = ∫ p`` over the interval (the same midpoint
            rule both sides, solved by bisection: ``clip(p + c)`` is monotone in ``c``); for a
            scaled block, the block's vector with ``∫ scaled(p + c) = ∫ p`` in the directions its
            allocation leaves (``_block_offsets``; zeros where it cannot be reached,
            :attr:`impulse_residuals`). Zeros without :attr:`control_bounds`.
        """
        if self._impulse_offsets is None:
            self._impulse_offsets, self._impulse_residuals = self._offsets()
        return self._impulse_offsets

    @property
    def impulse_residuals(self) -> Array:
        """Per interval and entry of the :attr:`scaled_blocks`, how far the offsets found leave the
        impulse (module docstring): the mean of the flown control minus that of the polynomial on
        the interval's :data:`IMPULSE_POINTS` midpoints.

        Returns
        -------
        (N, nu) ndarray
            In the controls' units; nonzero only in the scaled blocks of the intervals where they
            leave their bounds: within :data:`IMPULSE_TOLERANCE` of the bound where the impulse is
            reached, else the least residual found (the pyramids' switches of the module
            docstring: 1e-8 N m, the points' overshoot of the bounds by the solver's relaxation),
            or without an offset where none gains :data:`IMPULSE_GAIN` (never more than without
            one). Zeros elsewhere (the entries clipped one by one reach theirs by bisection).
        """
        if self._impulse_residuals is None:
            self._impulse_offsets, self._impulse_residuals = self._offsets()
        return self._impulse_residuals

    def _offsets(self) -> tuple[Array, Array]:
        N, nu = self.intervals, self.model.nu
        offsets, residuals = np.zeros((N, nu)), np.zeros((N, nu))
        if self.control_bounds is None or self.duration <= 0.0:
            return offsets, residuals
        low, high = self.control_bounds
        shifted = np.ones(nu, dtype=bool)
        for block in self.scaled_blocks:
            shifted[block] = False
        tau = (np.arange(IMPULSE_POINTS) + 0.5) / IMPULSE_POINTS
        if self.transcription.mesh is None:
            t = ((np.arange(N)[:, None] + tau[None, :]) * (self.duration / N)).ravel()
        else:
            t = (self.transcription.fractions(np.arange(N)[:, None], tau[None, :]) * self.duration).ravel()
        p = self._interpolated(t)[1].reshape(N, IMPULSE_POINTS, nu)
        slack = IMPULSE_SLACK * np.maximum(np.abs(np.where(np.isfinite(low), low, 0.0)),
                                           np.abs(np.where(np.isfinite(high), high, 0.0)))
        outside = np.any((p > high + slack) | (p < low - slack), axis=1)
        k, i = np.nonzero(outside & shifted)
        if k.size:
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
        blocks = [(block, np.flatnonzero(np.any(outside[:, block], axis=1))) for block in self.scaled_blocks]
        blocks = [(block, k) for block, k in blocks if k.size]
        rows = allocation_constraints(self.model.spacecraft) if blocks else None
        for block, k in blocks:
            block_rows = None if rows is None else rows[:, block][np.any(rows[:, block] != 0.0, axis=1)]
            basis = _allowed_directions(block_rows, low[block], high[block])
            if basis.shape[1]:
                offsets[k, block], residuals[k, block] = _block_offsets(p[k][:, :, block], low[block],
                                                                        high[block], basis)
        return offsets, residuals

    def _state_control(self, t: Array, left: bool = False) -> tuple[Array, Array]:
        """The reference's states and controls: :meth:`_interpolated`, the controls shifted by
        :attr:`impulse_offsets` and saturated at :attr:`control_bounds` (the :attr:`scaled_blocks`
        scaled as a whole, the others clipped; the states are not: a wheel momentum's overshoot is
        the solution's)."""
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
        return matrices(_mapped(self.model, "rhs", n), x.T, u.T, times, np.tile(self.disturbance[:, None], n))[0].T

    def _evaluate(self, t: Array) -> ReferenceSample:
        x, u = self._state_control(t)
        n = t.size
        x_dot = self._rhs(x, u, t)
        actuator = matrices(_mapped(self.model, "body_torque", n), x.T, u.T, t)[0].T
        environment = matrices(_mapped(self.model, "environment_torque", n), x.T, t,
                               np.tile(self.disturbance[:, None], n))[0].T
        omega = x[:, 4:7]
        wheel_momentum = x[:, 7:] @ self.model.spacecraft.wheel_axes.T
        torque = actuator - np.cross(omega, wheel_momentum) + environment
        return ReferenceSample(quat.normalize(x[:, 0:4]), omega, x_dot[:, 4:7], torque)


MAPS_KEPT = 8
"""Mapped functions a model keeps for the collocation reference and its certificate (one per
function and sample count), the most recently used (:class:`~ocp.cache.RecentCache`): a study
meeting many sample counts keeps this many, not one per count."""


def _mapped(model: AttitudeModel, name: str, n: int, build: Callable[[], ca.Function] | None = None) -> ca.Function:
    """The model's function ``name`` (``rhs``, ``body_torque``, ``environment_torque``), or
    ``build()``, mapped over ``n`` points; kept with the model's :data:`MAPS_KEPT` most recently
    used maps (in its ``solver_cache``).

    Parameters
    ----------
    model : ocp.AttitudeModel
        The model.
    name : str
        Its ``casadi.Function`` attribute, or the name the map of ``build()`` is kept under.
    n : int
        Points (columns) per call.
    build : callable, optional
        Builds the function to map (called only when its map is not kept); ``None``: the model's
        attribute ``name``.

    Returns
    -------
    casadi.Function
        The function mapped over ``n`` points.
    """
    maps = model.solver_cache.get(("collocation", "maps"), lambda: RecentCache(MAPS_KEPT))
    return maps.get((name, n), lambda: (getattr(model, name) if build is None else build()).map(n))


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
        torque = matrices(_mapped(model, "body_torque", t.size), x.T, u.T, t)[0].T
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


BANG_BANG_SUBSTEPS = 4
"""RK4 steps between consecutive Radau points of :func:`bang_bang_solution`: on 50 intervals its
final state is within 1.1e-11 (Bilimoria & Wie 180°), 6.8e-12 (full inertia) and 6.4e-11 (XTE) of
DOP853's at 1e-13 with the same switch times (2 steps: 1.7e-10, 1.1e-10, 1e-9), in under a
millisecond."""


def switch_mesh(switch_times: Array, duration: float, intervals: int) -> Array:
    """A mesh with a node at every switch of a bang-bang control.

    Parameters
    ----------
    switch_times : (m,) ndarray
        The switch times [s], sorted, inside ``(0, duration)`` (coinciding ones are one node).
    duration : float
        T [s].
    intervals : int
        Mesh intervals in all (at least one per arc: more where there are more arcs).

    Returns
    -------
    (N + 1,) ndarray
        The nodes as fractions of T, increasing from 0 to 1: each arc divided into equal intervals,
        their numbers as near the arc's share of ``intervals`` as whole numbers allow (largest
        remainders).
    """
    edges = np.concatenate([[0.0], np.asarray(switch_times, dtype=float) / duration, [1.0]])
    edges = edges[np.concatenate([[True], np.diff(edges) > 1e-12])]  # coinciding switches: one node
    edges[-1] = 1.0
    lengths = np.diff(edges)
    share = lengths * max(int(intervals), lengths.size)
    counts = np.maximum(np.floor(share).astype(int), 1)
    for k in np.argsort(counts - share)[:max(max(int(intervals), lengths.size) - int(counts.sum()), 0)]:
        counts[k] += 1  # the largest remainders
    nodes = [edges[0]] + [a + (b - a) * np.arange(1, n + 1) / n for a, b, n in zip(edges[:-1], edges[1:], counts)]
    mesh = np.concatenate([np.atleast_1d(n) for n in nodes])
    mesh[-1] = 1.0
    return mesh


def _radau_steps(model: AttitudeModel, tau: Array) -> ca.Function:
    """``(x0, u, h, d) -> (x(h), [x(τ_0 h) … x(τ_d h)])``: the state of ``x0`` under the constant
    control ``u`` over one interval of length ``h`` [s], read at its Radau points (RK4,
    :data:`BANG_BANG_SUBSTEPS` steps between consecutive points; disturbance ``d`` [N m]; the time
    rides along as the last state)."""
    xt, u, h, d = ca.SX.sym("xt", model.nx + 1), ca.SX.sym("u", model.nu), ca.SX.sym("h"), ca.SX.sym("d", 3)
    state, columns = xt, [xt[:-1]]
    for a, b in zip(tau[:-1], tau[1:]):
        step = (b - a) * h / BANG_BANG_SUBSTEPS
        for _ in range(BANG_BANG_SUBSTEPS):
            x, t = state[:-1], state[-1]
            state = ca.vertcat(rk4_step(lambda y, time: model.rhs(y, u, time, d), x, t, step), t + step)
        columns.append(state[:-1])
    return ca.Function("radau_steps", [xt, u, h, d], [state, ca.horzcat(*columns)])


def bang_bang_solution(model: AttitudeModel, transcription: Transcription, x0: Array, switch_times: Array,
                       arc_controls: Array, duration: float, disturbance: Array) -> tuple[Array, Array]:
    """The states and controls of a bang-bang control at a transcription's points, the states
    integrated (not collocated): a :class:`CollocationReference` of the exact trajectory.

    Parameters
    ----------
    model : AttitudeModel
        The spacecraft model (torquers, or reaction wheels whose momenta it integrates too).
    transcription : Transcription
        Radau collocation (``tau``, ``degree``) on a mesh with a node at every switch
        (:func:`switch_mesh`).
    x0 : (nx,) ndarray
        The initial state.
    switch_times : (m,) ndarray
        The switch times [s], sorted.
    arc_controls : (m + 1, nu) ndarray
        The control on each arc.
    duration : float
        T [s].
    disturbance : (3,) ndarray
        The disturbance torque [N m].

    Returns
    -------
    states : (nx, N (d + 1)) ndarray
        ``[x_k0, x_k1 … x_kd]`` per interval (``unpack``'s layout), from RK4 with
        :data:`BANG_BANG_SUBSTEPS` steps between consecutive points.
    controls : (nu d, N) ndarray
        Each interval's arc control at its ``d`` Radau points.
    """
    tau = np.asarray(getattr(transcription, "tau"), dtype=float)
    N, d = transcription.intervals, tau.size - 1
    nodes = transcription.nodes * duration
    middles = 0.5 * (nodes[:-1] + nodes[1:])
    arc = np.searchsorted(np.asarray(switch_times, dtype=float), middles)  # every switch is a node
    u = np.asarray(arc_controls, dtype=float)[arc].T  # (nu, N)
    # kept with the model's maps (_mapped), one per degree and number of intervals
    maps = model.solver_cache.get(("collocation", "maps"), lambda: RecentCache(MAPS_KEPT))
    accumulate = maps.get((f"bang-bang radau steps {d} {BANG_BANG_SUBSTEPS}", N),
                          lambda: _radau_steps(model, tau).mapaccum("accumulate", N, [0], [0]))
    _, points = matrices(accumulate, np.append(x0, 0.0), u, np.diff(nodes)[None, :], np.tile(disturbance[:, None], N))
    return points, np.tile(u, (d, 1))
