"""Co-state feedback (Vepa section 4, eq. 40-42): the optimal control of an indirect reference as
a feedback law.

Locally ``λ ≈ P x`` (eq. 40), with ``x = [q, ω]`` and ``P`` slowly varying. At each sample ``P`` is
fitted to the reference's states and co-states at ``window_samples`` times ``window_step`` apart
(the paper's ``t − nΔt``, n = 0…4; the window is shifted to stay inside ``[0, t_f]``), by least
squares constrained to symmetric non-negative definite matrices (eq. 42, second part):

    min ½ Σ_k ‖P x_k − λ_k‖² + ½ ρ ‖P‖²_F   subject to  P = Pᵀ ⪰ 0,

solved by accelerated projected gradient, warm-started from the previous sample. The window's
states span few directions; the small ridge ``ρ`` (relative to the data) gives the minimum-norm
answer in the others. The control is the reference's optimal control law evaluated at the
estimated co-state ``λ̂ = λ_ref + P (x − x_ref)`` (eq. 41-42); for the steering form that is
``u = −r⁻¹ Gᵀ λ̂_ω`` with ``r`` taken on the reference. After ``t_f`` the law applies no torque.
It tracks any reference that offers co-states (``planners.capabilities.CostateCarrier``) from a
planner that says so (``offers_costates``), e.g. ``costate_tpbvp``'s torque forms.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np

from controllers.base import Array, Controller
from ocp import Command, Measurement, Spacecraft
from ocp.options import Range
from planners.capabilities import CostateCarrier, offers_costates


def project_psd(matrix: Array) -> Array:
    """Nearest symmetric non-negative definite matrix in the Frobenius norm.

    Parameters
    ----------
    matrix : (n, n) ndarray
        A square matrix (its symmetric part is projected).

    Returns
    -------
    (n, n) ndarray
        The symmetric part with its negative eigenvalues set to zero.
    """
    values, vectors = np.linalg.eigh(0.5 * (matrix + matrix.T))
    return (vectors * np.maximum(values, 0.0)) @ vectors.T


def fit_costate_gain(states: Array, costates: Array, ridge: float = 1e-4, start: Array | None = None,
                     iterations: int = 200, tolerance: float = 1e-9) -> Array:
    """Symmetric non-negative definite ``P`` with ``P x_k ≈ λ_k`` for rows ``x_k``, ``λ_k``.

    The symmetric least-squares problem has a closed form in the eigenbasis of ``G = Σ x_k x_kᵀ``:
    ``P̃_ij = C̃_ij / ((d_i + d_j)/2 + ρ)`` with ``C = sym(Σ λ_k x_kᵀ)``. If that is not
    non-negative definite, accelerated projected gradient takes over from its projection
    (from ``start`` if given).

    Parameters
    ----------
    states : (m, n) array_like
        States ``x_k`` as rows (``[q, ω]``: scalar-first quaternion and body rate [rad/s], n = 7).
    costates : (m, n) array_like
        Co-states ``λ_k`` as rows, in the units of the reference's objective.
    ridge : float, optional
        Tikhonov weight ρ relative to the largest eigenvalue of ``G`` (dimensionless).
    start : (n, n) ndarray or None, optional
        Warm start of the projected gradient (the previous sample's ``P``); ``None``: the
        projection of the unconstrained solution.
    iterations : int, optional
        Most projected-gradient iterations.
    tolerance : float, optional
        Stop once an iteration changes ``P`` by less than this, relative to ``‖P‖_F``.

    Returns
    -------
    (n, n) ndarray
        ``P``, symmetric non-negative definite.
    """
    X, L = np.asarray(states, dtype=float).T, np.asarray(costates, dtype=float).T
    gram = X @ X.T
    d, V = np.linalg.eigh(gram)
    rho = ridge * max(d[-1], 1e-300)
    cross = L @ X.T
    rotated = V.T @ (0.5 * (cross + cross.T)) @ V
    P = V @ (rotated / (0.5 * (d[:, None] + d[None, :]) + rho)) @ V.T
    if np.linalg.eigvalsh(P)[0] >= 0:
        return P
    lipschitz = d[-1] + rho
    P = project_psd(P if start is None else start)
    Y, momentum = P.copy(), 1.0
    for _ in range(iterations):
        gradient = Y @ gram - cross + rho * Y
        P_next = project_psd(Y - 0.5 * (gradient + gradient.T) / lipschitz)
        momentum_next = 0.5 * (1 + np.sqrt(1 + 4 * momentum**2))
        Y = P_next + (momentum - 1) / momentum_next * (P_next - P)
        change = np.linalg.norm(P_next - P)
        P, momentum = P_next, momentum_next
        if change <= tolerance * max(float(np.linalg.norm(P)), 1e-300):
            break
    return P


class CostateFeedback(Controller):
    """Vepa's co-state feedback law (see the module docstring)."""

    name = "costate_feedback"
    needs_reference = True

    def symbolic_error(self) -> str | None:
        return ("the co-state gain P is fitted at run time by constrained least squares over a window "
                "of the reference's states and co-states (an iterative projected-gradient solve) and "
                "the control calls the reference's own system; neither is a fixed CasADi expression")

    @dataclass(frozen=True)
    class Options:
        """Options of ``costate_feedback`` (the YAML keys under the controller's ``options``).

        Parameters
        ----------
        window_samples : int, 2 to 1000
            Number of fit points ``t − nΔt``, n = 0 … ``window_samples`` − 1 (the paper's n = 0…4:
            default 5), shifted to stay inside ``[0, t_f]``.
        window_step : float > 0 or None
            Δt [s] between fit points; ``None`` (default): the sample time.
        ridge : float, >= 0
            Tikhonov weight ρ of the fit, relative to the largest eigenvalue of ``Σ x_k x_kᵀ``
            (dimensionless); it picks the minimum-norm ``P`` in the directions the window's states
            do not span.
        """

        window_samples: Annotated[int, Range(ge=2, le=1000)] = 5
        window_step: Annotated[float | None, Range(gt=0.0)] = None
        ridge: Annotated[float, Range(ge=0.0)] = 1e-4

    def planner_error(self, planner: str, options: Any) -> str | None:
        """Refuse a planner whose references offer no co-states with a torque control.

        Parameters
        ----------
        planner : str
            Registry name of the planner.
        options : object
            The planner's parsed ``Options`` (the control form depends on them).

        Returns
        -------
        str or None
            The reason and the planners that offer co-states, or ``None`` when the law can track it.
        """
        from planners import (
            PLANNERS,  # the registry, complete once scenarios are parsed
        )

        if planner in PLANNERS and offers_costates(PLANNERS[planner], options):
            return None
        offering = sorted(name for name, cls in PLANNERS.items() if callable(getattr(cls, "offers_costates", None)))
        return (f"controller {self.name} tracks references that offer co-states with a torque control; "
                f"planners offering them (for some options): {offering}")

    def reset(self, spacecraft: Spacecraft, sample_time: float, target: Any = None) -> None:
        super().reset(spacecraft, sample_time, target)
        self.gain: Array | None = None
        self.gains: list[tuple[float, Array]] = []  # (t, P) per sample, for inspection

    def window(self, t: float, duration: float) -> Array:
        """The fit times of the sample at ``t``.

        Parameters
        ----------
        t : float
            Sample time instant [s].
        duration : float
            The reference's duration t_f [s].

        Returns
        -------
        (window_samples,) ndarray
            Times ``t − nΔt`` [s] in increasing order, shifted to lie in ``[0, duration]``.
        """
        step = self.options.window_step or self.sample_time
        span = step * (self.options.window_samples - 1)
        first = min(max(t - span, 0.0), max(duration - span, 0.0))
        return first + step * np.arange(self.options.window_samples)

    def __call__(self, t: float, measurement: Measurement, reference: Any) -> Command:
        if not isinstance(reference, CostateCarrier):
            raise ValueError(f"controller {self.name} needs a reference that offers co-states")
        if t >= reference.duration:
            return self.allocate(np.zeros(3), measurement)
        states, costates = reference.state_and_costate(self.window(t, reference.duration))
        self.gain = fit_costate_gain(states, costates, self.options.ridge, start=self.gain)
        self.gains.append((t, self.gain))
        x_ref, lam_ref = (a[0] for a in reference.state_and_costate(t))
        q = measurement.q if measurement.q @ x_ref[0:4] >= 0 else -measurement.q  # same hemisphere
        lam = lam_ref + self.gain @ (np.concatenate([q, measurement.omega]) - x_ref)
        torque = reference.feedback_torque(lam[4:7], lam_ref[4:7])
        return self.allocate(torque, measurement)
