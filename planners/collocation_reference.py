"""The reference of an optimal-control solution, and seeds for the NLP from other references.

Collocation: within each interval the state is the degree-``d`` Lagrange polynomial through the
interval start and the Radau points, the control the degree-``d−1`` polynomial through the Radau
points (the transcription's own representation). Multiple shooting: controls are piecewise linear
as optimised; states are cubic Hermite between nodes with the model's derivatives.
The feed-forward torque is the optimal control expressed for ``I ω̇ = −ω × I ω + u``:
``u = τ_actuators − ω × A h_w + τ_environment``, and ``ω̇`` comes from the model, so both agree.
"""
from __future__ import annotations

import numpy as np

from ocp import quat
from planners.base import Array, ManeuverProblem, Reference, ReferenceSample


def _lagrange(points: Array, tau: Array) -> Array:
    """Basis values (len(tau), len(points)) of the Lagrange polynomials through ``points``."""
    basis = np.ones((tau.size, points.size))
    for r, p_r in enumerate(points):
        for s, p_s in enumerate(points):
            if s != r:
                basis[:, r] *= (tau - p_s) / (p_r - p_s)
    return basis


class CollocationReference(Reference):
    """Evaluates the optimal states and controls of a transcribed problem."""

    def __init__(self, problem: ManeuverProblem, transcription, duration: float, states: Array, controls: Array,
                 stats: dict):
        nodes = np.arange(1, transcription.intervals) * duration / transcription.intervals
        if transcription.name == "collocation":
            # The state polynomials join continuously at the mesh nodes, their slopes and the
            # controls do not; the dynamics hold at the Radau points inside each interval.
            radau = transcription.tau[1:-1] if transcription.tau[-1] == 1.0 else transcription.tau[1:]
            inner = ((np.arange(transcription.intervals)[:, None] + radau[None, :]) * duration
                     / transcription.intervals).ravel()
            breakpoints = nodes
        else:  # cubic Hermite states with the model's derivatives at the nodes: C¹, exact at the nodes
            inner, breakpoints = nodes, np.zeros(0)
        super().__init__("collocation", duration, problem.spacecraft.inertia, stats=stats,
                         free_boundary=(), breakpoints=breakpoints, enforced_times=inner)
        self.model, self.transcription = problem.model, transcription
        self.states, self.controls = states, controls
        self.intervals = transcription.intervals
        self.disturbance = problem.model.default_parameters

    def _state_control(self, t: Array) -> tuple[Array, Array]:
        N, h = self.intervals, self.duration / self.intervals
        k = np.minimum((t / h).astype(int), N - 1)
        tau = t / h - k
        if self.transcription.name == "collocation":
            d = self.transcription.degree
            x_basis = _lagrange(self.transcription.tau, tau)
            u_basis = _lagrange(self.transcription.tau[1:], tau)
            X = self.states.reshape(self.model.nx, N, d + 1)
            U = self.controls.reshape(self.model.nu, N, d)
            x = np.einsum("tik,tk->ti", X[:, k, :].transpose(1, 0, 2), x_basis)
            u = np.einsum("tik,tk->ti", U[:, k, :].transpose(1, 0, 2), u_basis)
            return x, u
        u = (1 - tau)[:, None] * self.controls[:, k].T + tau[:, None] * self.controls[:, k + 1].T
        x0, x1 = self.states[:, k].T, self.states[:, k + 1].T
        f0 = self._rhs(x0, self.controls[:, k].T, k * h)
        f1 = self._rhs(x1, self.controls[:, k + 1].T, (k + 1) * h)
        h00, h10, h01, h11 = 2 * tau**3 - 3 * tau**2 + 1, tau**3 - 2 * tau**2 + tau, -2 * tau**3 + 3 * tau**2, tau**3 - tau**2
        x = h00[:, None] * x0 + h10[:, None] * h * f0 + h01[:, None] * x1 + h11[:, None] * h * f1
        return x, u

    def control(self, t) -> Array:
        """The optimal actuator control ``u(t)`` (layout of ``model.control_slices``) within ``[0, T]``."""
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


def _seed_states_controls(problem: ManeuverProblem, reference: Reference, times: Array):
    """States and actuator controls along a reference: wheel momenta from conservation of the total
    momentum, controls by mapping the reference torque to the actuators."""
    sample = reference.sample(times)
    spacecraft, model = problem.spacecraft, problem.model
    axes = spacecraft.wheel_axes
    x = np.zeros((times.size, model.nx))
    x[:, 0:4], x[:, 4:7] = sample.q, sample.omega
    u = np.zeros((times.size, model.nu))
    body_momentum = sample.omega @ spacecraft.inertia.T
    if model.n_wheels:
        total = quat.rotate(problem.q0, spacecraft.inertia @ problem.omega0 + axes @ problem.wheel_momentum0)
        wheel_total = quat.rotate_inverse(sample.q, np.broadcast_to(total, sample.q.shape[:-1] + (3,))) - body_momentum
        x[:, 7:] = wheel_total @ np.linalg.pinv(axes).T
        wheel_torque = sample.torque + np.cross(sample.omega, x[:, 7:] @ axes.T)
        u[:, model.control_slices["wheels"]] = -wheel_torque @ np.linalg.pinv(axes).T
    elif "torquers" in model.control_slices:
        u[:, model.control_slices["torquers"]] = sample.torque
    return x, u


def seed_vector(problem: ManeuverProblem, transcription, nlp, reference: Reference) -> Array:
    """An initial guess for ``nlp`` in its decision-vector layout, from ``reference``."""
    duration = reference.duration if nlp.layout["free_time"] else problem.duration
    N = transcription.intervals
    h = duration / N
    if transcription.name == "collocation":
        d = transcription.degree
        x_times = (np.arange(N)[:, None] + transcription.tau[None, :]).ravel() * h
        u_times = (np.arange(N)[:, None] + transcription.tau[None, 1:]).ravel() * h
        x, _ = _seed_states_controls(problem, reference, x_times)
        _, u = _seed_states_controls(problem, reference, u_times)
        x_end, _ = _seed_states_controls(problem, reference, np.array([duration]))
        torque = np.abs(reference.torque(u_times))
        blocks = [x.reshape(N, d + 1, -1).reshape(-1), u.reshape(-1)]
        if nlp.layout["S"]:
            blocks.append(torque.reshape(-1))
        blocks.append(x_end.ravel())
    else:
        times = np.linspace(0, duration, N + 1)
        x, u = _seed_states_controls(problem, reference, times)
        blocks = [x.reshape(-1), u.reshape(-1)]
    if nlp.layout["free_time"]:
        blocks.append([duration])
    return np.concatenate(blocks)
