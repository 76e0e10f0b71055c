"""What the figures of a run show, as plain arrays: the numeric half of the plots.

Nothing here imports matplotlib, and the model's quaternion helpers are imported only by the
functions that compute series: the drawing half (:mod:`scenarios.output.plots`) imports this module for
its layout and series types, in a process that need not load the model. So the series are computed
where the run happened and can be drawn in another process (:mod:`scenarios.output.renderer`), and tests
can check the numbers without drawing.

Series longer than a few points per pixel column of their panel are reduced to the minimum and
maximum of each column (:func:`decimate`), which draws the same picture, peaks included; the
figure layouts below fix the pixel columns without a figure.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

DPI = 90
"""Resolution of every PNG [dots per inch]."""
ROW_FIGSIZE_IN = (10.0, 13.0)
"""Size of the per-row figure with wheels [in]; without wheels its height is :data:`ROW_HEIGHT_NO_WHEELS_IN`."""
ROW_HEIGHT_NO_WHEELS_IN = 10.5
ROW_MARGINS = {"left": 0.1, "right": 0.855, "bottom": 0.05, "top": 0.95, "hspace": 0.08}
"""``subplots_adjust`` of the per-row figure (fractions of the figure); the legends sit right of 0.855."""
OVERLAY_FIGSIZE_IN = (9.0, 7.0)
OVERLAY_MARGINS = {"left": 0.1, "right": 0.98, "bottom": 0.08, "top": 0.93, "hspace": 0.08}
COLUMNS_PER_POINT = 2
"""Series longer than this many points per pixel column of the panel are decimated."""
FLOOR_DEG = 1e-9
"""Smallest angle drawn on the logarithmic error axes [deg] (an exact zero has no logarithm)."""
FLOOR_RATE = 1e-12
"""Smallest rate drawn on the logarithmic rate axes [rad/s]."""


def panel_columns(figure_width_in: float, margins: dict[str, float]) -> int:
    """Pixel columns of a full-width panel.

    Parameters
    ----------
    figure_width_in : float
        Figure width [in].
    margins : dict
        ``left`` and ``right`` edges of the panels (fractions of the figure width).

    Returns
    -------
    int
        The panel's width in pixels at :data:`DPI` (as matplotlib's ``int(axis.bbox.width)``).
    """
    return int(figure_width_in * DPI * (margins["right"] - margins["left"]))


def decimate(t: np.ndarray, values: np.ndarray, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """A time series reduced to what ``columns`` pixel columns can show.

    Parameters
    ----------
    t : (N,) ndarray
        Increasing times [s].
    values : (N,) or (N, k) ndarray
        Samples at ``t`` (columns decimated together, on the same times).
    columns : int
        Pixel columns the series spans.

    Returns
    -------
    t, values : ndarray
        Unchanged when ``N <= COLUMNS_PER_POINT * columns``; else, per bin of consecutive
        samples (``columns`` bins), the samples at each column's minimum and maximum in time
        order (for ``(N, k)`` values those of the first column, the others alongside), and the
        last sample: the drawn envelope and every peak are those of the full series.
    """
    n = t.size
    if n <= COLUMNS_PER_POINT * max(columns, 1):
        return t, values
    size = -(-n // columns)  # samples per bin
    pad = size * columns - n
    key = values if values.ndim == 1 else values[:, 0]
    padded = np.concatenate([key, np.repeat(key[-1:], pad)]).reshape(columns, size)
    start = np.arange(columns) * size
    low = np.minimum(start + padded.argmin(axis=1), n - 1)
    high = np.minimum(start + padded.argmax(axis=1), n - 1)
    keep = np.unique(np.concatenate([[0, n - 1], low, high]))
    return t[keep], values[keep]


def held(values: np.ndarray) -> np.ndarray:
    """Zero-order-hold samples (one per interval) extended by the last one, for ``steps-post``.

    Parameters
    ----------
    values : (N - 1, ...) ndarray
        One sample per interval.

    Returns
    -------
    (N, ...) ndarray
        The samples and the last one again.
    """
    return np.concatenate([values, values[-1:]])


Curve = tuple[np.ndarray, np.ndarray]
"""A drawn curve: times [s] and values, decimated."""


@dataclass
class RowSeries:
    """The curves of one row's figure (torque, rate, quaternion, error angles, wheel momenta).

    Parameters
    ----------
    n_wheels : int
        Number of wheels (a fifth panel with their momenta when > 0).
    with_reference : bool
        The reference is drawn dashed and the error to it in orange.
    with_target : bool
        The error to the target attitude is drawn.
    title : str
        The figure's title.
    torque, rate : list of Curve
        Applied body torque [N m] (held) and body rate [rad/s], per body axis (x, y, z).
    quaternion : list of Curve
        Attitude, scalar first (body to inertial).
    reference : tuple of three lists of Curve, optional
        The reference's torque, rate and quaternion (``with_reference``).
    to_target, to_reference : Curve, optional
        Error angles [deg] to the target attitude and to the reference attitude.
    rate_norm, rate_max : Curve, optional
        ``‖ω‖`` and ``max |ω_i|`` [rad/s] (regulation without a target attitude).
    wheels : list of Curve
        Wheel momenta [N m s].
    """

    n_wheels: int
    with_reference: bool
    with_target: bool
    title: str
    torque: list[Curve]
    rate: list[Curve]
    quaternion: list[Curve]
    reference: tuple[list[Curve], list[Curve], list[Curve]] | None = None
    to_target: Curve | None = None
    to_reference: Curve | None = None
    rate_norm: Curve | None = None
    rate_max: Curve | None = None
    wheels: list[Curve] = field(default_factory=list)

    @property
    def shape(self) -> tuple[int, bool, bool]:
        """``(n_wheels, with_reference, with_target)``: rows of one shape share a figure."""
        return self.n_wheels, self.with_reference, self.with_target


def row_series(row: Any, target_q: Any) -> RowSeries:
    """The curves of a simulated row, decimated to the per-row figure's panels.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A row with a simulation (and a reference unless regulating).
    target_q : (4,) array_like or None
        Target attitude (scalar-first quaternion, body to inertial) for the error angle.

    Returns
    -------
    RowSeries
        What :class:`scenarios.output.plots.RowFigure` draws.
    """
    # the model's helpers, in the process that ran it (module docstring)
    from ocp import quat

    sim = row.simulation
    t = sim.t
    columns = panel_columns(ROW_FIGSIZE_IN[0], ROW_MARGINS)

    def curve(values: np.ndarray) -> Curve:
        return decimate(t, values, columns)

    n_wheels = sim.wheel_momentum.shape[1]
    with_reference, with_target = row.reference is not None, target_q is not None
    controller = f", {row.controller}" if getattr(row, "controller", None) else ""
    series = RowSeries(
        n_wheels, with_reference, with_target,
        f"{row.label} ({row.planner or 'regulation'}{controller}): solid closed loop, dashed reference",
        [curve(held(sim.applied_torque[:, i])) for i in range(3)], [curve(sim.omega[:, i]) for i in range(3)],
        [curve(sim.q[:, i]) for i in range(4)], wheels=[curve(sim.wheel_momentum[:, i]) for i in range(n_wheels)])
    if with_reference:
        ref = row.reference.sample(t)
        series.reference = tuple([curve(values[:, i]) for i in range(values.shape[1])]  # type: ignore[assignment]
                                 for values in (ref.torque, ref.omega, ref.q))
        series.to_reference = curve(np.maximum(np.rad2deg(quat.error_angle(sim.q, ref.q)), FLOOR_DEG))
    if with_target:
        series.to_target = curve(np.maximum(np.rad2deg(quat.error_angle(sim.q, target_q)), FLOOR_DEG))
    if not with_reference and not with_target:  # rate regulation (detumbling): the rate converges
        series.rate_norm = curve(np.maximum(np.linalg.norm(sim.omega, axis=1), FLOOR_RATE))
        series.rate_max = curve(np.maximum(np.abs(sim.omega).max(axis=1), FLOOR_RATE))
    return series


@dataclass
class OverlaySeries:
    """The comparison figure: torque norm and error to the target, one curve per row.

    Parameters
    ----------
    title : str
        The figure's title.
    error_label : str
        The lower panel's y label (what the error is, with its unit).
    labels : list of str
        Row labels, in the rows' order.
    torque : list of Curve
        ``‖u‖`` [N m] (held) per row.
    error : list of Curve
        Error to the target per row: angle [deg] to the target attitude, or rate error [rad/s]
        when the attitude is free.
    """

    title: str
    error_label: str
    labels: list[str]
    torque: list[Curve]
    error: list[Curve]


def overlay_series(results: Any) -> OverlaySeries:
    """The comparison figure's curves (rows without a simulation are left out).

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.

    Returns
    -------
    OverlaySeries
        What :func:`scenarios.output.plots.draw_overlay` draws.
    """
    # the model's helpers, in the process that ran it (module docstring)
    from ocp import quat

    target_q, target_omega = results.scenario.problem.qf, results.scenario.problem.omegaf
    columns = panel_columns(OVERLAY_FIGSIZE_IN[0], OVERLAY_MARGINS)
    error_label = ("error to target (deg)" if target_q is not None
                   else "‖ω − ω_f‖ (rad/s)" if target_omega is not None else "‖ω‖ (rad/s)")
    series = OverlaySeries(f"{results.scenario.name}: closed-loop comparison", error_label, [], [], [])
    for row in results.rows:
        if row.simulation is None:
            continue
        sim = row.simulation
        if target_q is not None:
            error = np.rad2deg(quat.error_angle(sim.q, target_q))
        elif target_omega is not None:
            error = np.linalg.norm(sim.omega - target_omega, axis=1)
        else:
            error = np.linalg.norm(sim.omega, axis=1)
        series.labels.append(row.label)
        series.torque.append(decimate(sim.t, held(np.linalg.norm(sim.applied_torque, axis=1)), columns))
        series.error.append(decimate(sim.t, np.maximum(error, FLOOR_DEG), columns))
    return series


@dataclass
class ConeSeries:
    """Angle between each constrained boresight and its direction, closed loop and reference.

    Parameters
    ----------
    title : str
        The figure's title.
    t : (N,) ndarray
        Times [s].
    cones : list of dict
        Per cone: ``closed_loop`` and ``reference`` separations [deg] (N,), ``limit_deg`` (the
        cone's angle as imposed, margin included) and ``keep_out`` (bool).
    """

    title: str
    t: np.ndarray
    cones: list[dict[str, Any]]


def cone_series(row: Any) -> ConeSeries:
    """The pointing-constraint curves of a row whose planner imposed cones.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A row with a simulation and a reference whose ``stats["cones"]`` lists
        ``(boresight (body), direction (inertial), angle [rad], keep_out)``.

    Returns
    -------
    ConeSeries
        What :func:`scenarios.output.plots.draw_cones` draws.
    """
    # the model's helpers, in the process that ran it (module docstring)
    from ocp import quat

    sim = row.simulation
    reference_q = row.reference.q(sim.t)
    cones = []
    for boresight, direction, angle, keep_out in row.reference.stats.get("cones", []):
        separations = {}
        for name, q in (("closed_loop", sim.q), ("reference", reference_q)):
            pointing = quat.rotate(q, np.asarray(boresight))
            separations[name] = np.rad2deg(np.arccos(np.clip(pointing @ np.asarray(direction), -1, 1)))
        cones.append({**separations, "limit_deg": float(np.rad2deg(angle)), "keep_out": bool(keep_out)})
    return ConeSeries(f"{row.label}: pointing constraints", np.asarray(sim.t), cones)


PlotJob = tuple[str, "RowSeries | OverlaySeries | ConeSeries"]
"""A figure to draw: its file name in the output directory and its series."""


def plot_jobs(results: Any, stems: list[str] | None = None) -> list[PlotJob]:
    """The figures of a run: one per simulated row (``<stem>.png``, ``<stem>_cones.png`` with
    cones) and ``comparison.png``.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.
    stems : list of str, optional
        The rows' file stems; ``None``: ``row_stems`` of the labels.

    Returns
    -------
    list of (str, series)
        File names and series, in drawing order (rows, each followed by its cones; the overlay last).
    """
    from scenarios.output.names import row_stems

    target_q = results.scenario.problem.qf
    stems = stems if stems is not None else row_stems([row.label for row in results.rows])
    jobs: list[PlotJob] = []
    for row, stem in zip(results.rows, stems):
        if row.simulation is None:
            continue
        jobs.append((f"{stem}.png", row_series(row, target_q)))
        if row.reference is not None and row.reference.stats.get("cones"):
            jobs.append((f"{stem}_cones.png", cone_series(row)))
    jobs.append(("comparison.png", overlay_series(results)))
    return jobs
