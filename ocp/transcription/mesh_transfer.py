"""Multipliers of a solution on one mesh, carried to another mesh of the same transcription.

The stage-wise layout of :mod:`ocp.transcription.base` gives every mesh interval the same block of
variables ``[s_k, c_k]`` and constraints ``[gap_k, path_k]``; each entry of a block sits at a
relative position ``r`` in its interval (``s_k`` at 0, ``gap_k`` at 1, a Radau point at ``τ_j``).
As the mesh is refined the multipliers converge to functions of time, up to a known scale:

* equality constraints that do not carry the step ``h`` (the gaps ``s_{k+1} − F(s_k, c_k)`` of
  integrated states, Radau's ``X D_j − h f(x_j, u_j)``, the initial and terminal conditions):
  their multipliers tend to the costate (times the quadrature weight, which is the same on both
  meshes), independent of ``h``;
* bounds and path inequalities, and the gaps of copied interval variables (multiple shooting's
  ``u_{k+1} = c_k``, ``Transcription.step_scaled_gaps``): their multipliers are a density times
  the quadrature weight times ``h``, so they scale with ``h``.

:func:`transfer_multipliers` resamples entry by entry, linearly in time (constant beyond the ends),
and rescales by the ratio of the steps. Either mesh may be non-uniform (its nodes given as
fractions of T, :attr:`~ocp.transcription.base.Transcription.nodes`): the entries are then placed
and rescaled by each interval's own step. The result is the warm start of a solve on the fine mesh
from a coarse-mesh optimum (IPOPT ``warm_start_init_point``): the barrier can then start small.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

LAYOUT_KEYS = ("n_path", "n_terminal", "path_equality", "c_position", "path_position", "gap_step_scaled")
"""Entries of ``NLP.layout`` the transfer needs (written by ``Transcription.build``)."""


def _resample(values: Array, positions: Array, source: int, target: int, rows: int) -> Array:
    """Rows ``k = 0 … rows − 1`` of entries sampled at normalised times ``(k + r_e) / target``, read
    from ``values`` (one row per interval of ``source`` intervals, entry ``e`` at ``(k + r_e) / source``)."""
    k = np.arange(rows, dtype=float)[:, None]
    u = np.clip((k + positions[None, :]) * (source / target) - positions[None, :], 0.0, values.shape[0] - 1.0)
    low = np.minimum(np.floor(u).astype(int), max(values.shape[0] - 2, 0))
    high = np.minimum(low + 1, values.shape[0] - 1)
    frac = u - low
    return ((1.0 - frac) * np.take_along_axis(values, low, axis=0)
            + frac * np.take_along_axis(values, high, axis=0))


def _resample_nodes(values: Array, positions: Array, source: Array, target: Array,
                    rows: int) -> tuple[Array, Array]:
    """:func:`_resample` between meshes of nodes ``source`` and ``target`` (fractions of T): the
    values read linearly in time (constant beyond the ends), and per target row the ratio of its
    interval's step to the source step at its middle. ``values`` has one row per source interval
    (entry ``e`` at ``t_k + r_e h_k``) or, for the stage states (``rows`` one more than the target's
    intervals), one per source node."""
    n_source, n_target = source.size - 1, target.size - 1
    k_t = np.minimum(np.arange(rows), n_target - 1)
    k_s = np.arange(values.shape[0])
    step_t, step_s = np.diff(target), np.diff(source)
    out = np.empty((rows, values.shape[1]))
    for e, r in enumerate(positions):
        if values.shape[0] == n_source + 1:  # at the nodes
            times_s, times_t = source, target[:rows]
        else:
            times_s, times_t = source[k_s] + r * step_s[k_s], target[k_t] + r * step_t[k_t]
        out[:, e] = np.interp(times_t, times_s, values[:, e])
    holder = np.clip(np.searchsorted(source, target[k_t] + 0.5 * step_t[k_t], side="right") - 1, 0, n_source - 1)
    return out, (step_t[k_t] / step_s[holder])[:, None]


def transfer_multipliers(source: Any, target: Any, lam_x: Array, lam_g: Array, source_nodes: Array | None = None,
                         target_nodes: Array | None = None) -> tuple[Array, Array] | None:
    """Bound and constraint multipliers of ``source``'s solution resampled onto ``target``'s mesh.

    Parameters
    ----------
    source, target : NLP
        Built NLPs of the same transcription and problem structure (``ocp.transcription.problem.NLP``), on
        any numbers of intervals; their ``layout`` carries :data:`LAYOUT_KEYS`.
    lam_x : (source.n_w,) ndarray
        Bound multipliers at the source's solution.
    lam_g : (len(source.lbg),) ndarray
        Constraint multipliers at the source's solution.
    source_nodes, target_nodes : (N + 1,) ndarray or None
        The meshes' nodes as fractions of T when either is non-uniform
        (:attr:`~ocp.transcription.base.Transcription.nodes`); ``None`` (default): both uniform.

    Returns
    -------
    tuple of ndarray or None
        ``(lam_x, lam_g)`` in the target's layout, or ``None`` when the two layouts differ beyond the
        number of intervals (or one of them does not describe its layout).
    """
    if not all(key in source.layout and key in target.layout for key in LAYOUT_KEYS):
        return None
    ns, nc = target.n_stage_state, target.n_interval
    n_path, n_terminal = target.layout["n_path"], target.layout["n_terminal"]
    if (source.n_stage_state, source.n_interval, source.layout["n_path"], source.layout["n_terminal"]) != (
            ns, nc, n_path, n_terminal) or any(
            not np.array_equal(source.layout[key], target.layout[key]) for key in ("path_equality", "gap_step_scaled")):
        return None
    nz, nb = ns + nc, ns + n_path
    n_source, n_target = (source.n_w - ns) // nz, (target.n_w - ns) // nz
    n_initial = len(source.lbg) - n_source * nb - n_terminal
    if lam_x.size != source.n_w or lam_g.size != len(source.lbg) or n_initial < 0:
        return None
    if source_nodes is None and target_nodes is None:
        ratio = n_source / n_target  # h_target / h_source: bounds and inequalities scale with h

        def resample(values: Array, positions: Array, rows: int) -> tuple[Array, Array | float]:
            return _resample(values, positions, n_source, n_target, rows), ratio
    else:
        nodes_s = np.arange(n_source + 1) / n_source if source_nodes is None else np.asarray(source_nodes, float)
        nodes_t = np.arange(n_target + 1) / n_target if target_nodes is None else np.asarray(target_nodes, float)
        if nodes_s.size != n_source + 1 or nodes_t.size != n_target + 1:
            return None

        def resample(values: Array, positions: Array, rows: int) -> tuple[Array, Array | float]:
            return _resample_nodes(values, positions, nodes_s, nodes_t, rows)
    Z = lam_x[:nz * n_source].reshape(n_source, nz)
    S = np.vstack([Z[:, :ns], lam_x[None, nz * n_source:]])
    S_new, step = resample(S, np.zeros(ns), n_target + 1)
    S_new = S_new * step
    C_new, step = resample(Z[:, ns:], np.asarray(target.layout["c_position"], float), n_target)
    C_new = C_new * step
    x_out = np.concatenate([np.hstack([S_new[:-1], C_new]).ravel(), S_new[-1]])

    rows = np.concatenate([lam_g[:nb], lam_g[nb + n_initial:nb + n_initial + (n_source - 1) * nb]]).reshape(n_source, nb)
    gap_scaled = np.asarray(target.layout["gap_step_scaled"], bool)
    gap_new, step = resample(rows[:, :ns], np.ones(ns), n_target)
    gap_new = np.where(gap_scaled[None, :], gap_new * step, gap_new)
    equality = np.asarray(target.layout["path_equality"], bool)
    path_new, step = resample(rows[:, ns:], np.asarray(target.layout["path_position"], float), n_target)
    path_new = np.where(equality[None, :], path_new, path_new * step)
    blocks = np.hstack([gap_new, path_new])
    g_out = np.concatenate([blocks[0], lam_g[nb:nb + n_initial], blocks[1:].ravel(), lam_g[len(lam_g) - n_terminal:]])
    return x_out, g_out
