"""Matplotlib (Agg) figures of a run: one PNG per row and one overlay comparing the rows.

Drawing is the largest cost of a run with plots, and nearly all of it is text (tick labels,
legends, axis labels): lines and grids cost little. So it is kept cheap:

* figures are plain ``matplotlib.figure.Figure`` objects (no pyplot state), laid out once with
  fixed margins (no ``tight_layout`` or ``bbox_inches="tight"``, which cost a draw each);
* the per-row figure is built once per run and reused for every row of the same shape
  (:class:`RowFigure`): what does not change between rows (frames, the shared time axis, axis
  labels, legends, placed beside the panels so that no curve is drawn over them) is drawn once and
  kept as a bitmap; each row then draws only its curves, its value axes and its title on a copy
  of that bitmap, which is written as the PNG without a second draw;
* time series longer than a few points per pixel column are reduced to the minimum and maximum
  of each column (:func:`decimate`), which draws the same picture, peaks included.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, MaxNLocator, NullLocator

from ocp import quat
from scenarios.outputs import row_stems

AXIS_COLORS = ("tab:red", "tab:green", "tab:blue", "tab:purple")
DPI = 90
COMPRESS_LEVEL = 1
"""zlib level of the PNGs: level 1 encodes several times faster than the default 6 for ~20 % more bytes."""
SAVE: dict[str, Any] = {"dpi": DPI, "pil_kwargs": {"compress_level": COMPRESS_LEVEL}}
"""``savefig`` options of the figures drawn once."""
COLUMNS_PER_POINT = 2
"""Series longer than this many points per pixel column of the panel are decimated."""


def _log_axis(axis: Any) -> None:
    """A logarithmic y axis with plain ``1e-05`` labels (the default ``10⁻⁵`` labels go through
    mathtext, which parses every label and costs more than drawing the whole figure)."""
    axis.set_yscale("log")
    axis.yaxis.set_minor_locator(NullLocator())
    axis.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))


LABEL_OFFSET_IN = 0.82
"""Distance of a y label's centre left of its panel [in]: clear of seven-character tick labels
such as ``−0.0020``; less in a narrower left margin, so that the label stays inside the figure."""


def _label(axis: Any, text: str) -> None:
    """A y label at a fixed place left of the panel, drawn with the panel's frame (matplotlib's own
    y label is re-placed after the tick labels at every draw, which measures each of them), and
    at most six value ticks (every tick label is a text to draw)."""
    position, figure_width_in = axis.get_position(), axis.figure.get_figwidth()
    distance_in = min(LABEL_OFFSET_IN, position.x0 * figure_width_in - 0.12)  # inside the figure
    axis.text(-distance_in / (position.width * figure_width_in), 0.5, text, rotation=90, ha="center", va="center",
              transform=axis.transAxes)
    if axis.get_yscale() == "linear":
        axis.yaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))


def _time_axis(axis: Any) -> None:
    """The time axis: label at a fixed place (no measuring of the tick labels at each draw), at
    most eight ticks (shared by the panels above)."""
    axis.set_xlabel("time (s)")
    axis.xaxis.set_label_coords(0.5, -0.35 / axis.get_position().height / axis.figure.get_figheight())
    axis.xaxis.set_major_locator(MaxNLocator(nbins=7, steps=[1, 2, 2.5, 5, 10]))


def _held(values: np.ndarray) -> np.ndarray:
    """Zero-order-hold samples (one per interval) extended by the last one, for ``steps-post``."""
    return np.concatenate([values, values[-1:]])


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


class RowFigure:
    """The per-row figure (torque, rate, quaternion, error angles, wheel momenta), built once and
    redrawn for each row of the same shape (module docstring).

    Parameters
    ----------
    n_wheels : int
        Number of wheels (a fifth panel with their momenta when > 0).
    with_reference : bool
        Draw the reference dashed and the error to it.
    with_target : bool
        Draw the error to the target attitude.
    """

    def __init__(self, n_wheels: int, with_reference: bool, with_target: bool):
        self.figure = Figure(figsize=(10, 13 if n_wheels else 10.5), dpi=DPI)
        self.canvas = FigureCanvasAgg(self.figure)
        axes = self.figure.subplots(5 if n_wheels else 4, 1, sharex=True)
        self.figure.subplots_adjust(left=0.1, right=0.855, bottom=0.05, top=0.95, hspace=0.08)  # before the labels
        self.axes = axes

        def line(axis: Any, style: str = "-", **kw: Any) -> Any:
            return axis.plot([], [], style, **kw)[0]

        self.torque = [line(axes[0], color=AXIS_COLORS[i], drawstyle="steps-post", label=f"u_{'xyz'[i]}")
                       for i in range(3)]
        self.rate = [line(axes[1], color=AXIS_COLORS[i], label=f"ω_{'xyz'[i]}") for i in range(3)]
        self.quaternion = [line(axes[2], color=AXIS_COLORS[i], label=f"q{i}") for i in range(4)]
        self.reference: tuple[list[Any], list[Any], list[Any]] | None = None
        if with_reference:
            self.reference = ([line(axes[0], "--", color=AXIS_COLORS[i], lw=1) for i in range(3)],
                              [line(axes[1], "--", color=AXIS_COLORS[i], lw=1) for i in range(3)],
                              [line(axes[2], "--", color=AXIS_COLORS[i], lw=1) for i in range(4)])
        _log_axis(axes[3])
        self.to_target = line(axes[3], color="k", label="to target") if with_target else None
        self.to_reference = line(axes[3], color="tab:orange", label="to reference") if with_reference else None
        self.rate_norm = self.rate_max = None
        if not with_reference and not with_target:  # rate regulation (detumbling): the rate converges
            self.rate_norm = line(axes[3], color="k", label="‖ω‖")
            self.rate_max = line(axes[3], color="tab:gray", lw=1, label="max |ω_i|")
        self.wheels = [line(axes[4], label=f"h_w{i}") for i in range(n_wheels)] if n_wheels else []
        labels = ["body torque (N m)", "body rate (rad/s)", "quaternion",
                  "error angle (deg)" if with_reference or with_target else "body rate (rad/s)"]
        if n_wheels:
            labels.append("wheel momentum (N m s)")
        for axis, label in zip(axes, labels):
            _label(axis, label)
            axis.grid(alpha=0.3)
            if any(not item.get_label().startswith("_") for item in axis.get_lines()):
                # beside the panel: static (drawn once), and never over a curve
                axis.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, borderaxespad=0.0)
        self.title = self.figure.suptitle("")
        _time_axis(axes[-1])
        self._background: tuple[tuple[float, float], Any] | None = None

    def _dynamic(self) -> list[Any]:
        """What changes from row to row: value axes, curves, title."""
        artists: list[Any] = []
        for axis in self.axes:
            artists.append(axis.yaxis)
            artists.extend(axis.get_lines())
        artists.append(self.title)
        return artists

    def draw(self, row: Any, target_q: Any, path: Path) -> None:
        """Draw a row and write the PNG.

        Parameters
        ----------
        row : scenarios.runner.Row
            A row with a simulation (and a reference unless regulating).
        target_q : (4,) array_like or None
            Target attitude (scalar-first quaternion, body to inertial) for the error angle.
        path : pathlib.Path
            Where to write the PNG.
        """
        sim = row.simulation
        columns = int(self.axes[0].bbox.width)
        t = sim.t

        def put(item: Any, values: np.ndarray) -> None:
            item.set_data(*decimate(t, values, columns))

        for i in range(3):
            put(self.torque[i], _held(sim.applied_torque[:, i]))
            put(self.rate[i], sim.omega[:, i])
        for i in range(4):
            put(self.quaternion[i], sim.q[:, i])
        if self.reference is not None and self.to_reference is not None:
            ref = row.reference.sample(t)
            for lines, values in zip(self.reference, (ref.torque, ref.omega, ref.q)):
                for i, item in enumerate(lines):
                    put(item, values[:, i])
            put(self.to_reference, np.maximum(np.rad2deg(quat.error_angle(sim.q, ref.q)), 1e-9))
        if self.to_target is not None:
            put(self.to_target, np.maximum(np.rad2deg(quat.error_angle(sim.q, target_q)), 1e-9))
        if self.rate_norm is not None and self.rate_max is not None:
            put(self.rate_norm, np.maximum(np.linalg.norm(sim.omega, axis=1), 1e-12))
            put(self.rate_max, np.maximum(np.abs(sim.omega).max(axis=1), 1e-12))
        for i, item in enumerate(self.wheels):
            put(item, sim.wheel_momentum[:, i])
        for axis in self.axes:
            axis.relim()
            axis.autoscale_view()
        controller = f", {row.controller}" if getattr(row, "controller", None) else ""
        self.title.set_text(f"{row.label} ({row.planner or 'regulation'}{controller}): solid closed loop, "
                            "dashed reference")
        time_limits = tuple(self.axes[-1].get_xlim())
        canvas, dynamic = self.canvas, self._dynamic()
        if self._background is None or self._background[0] != time_limits:
            for artist in dynamic:
                artist.set_visible(False)
            canvas.draw()
            self._background = (time_limits, canvas.copy_from_bbox(self.figure.bbox))
            for artist in dynamic:
                artist.set_visible(True)
        else:
            canvas.restore_region(self._background[1])
        renderer = canvas.get_renderer()
        for artist in dynamic:
            artist.draw(renderer)
        _write_png(canvas, path)


def _write_png(canvas: FigureCanvasAgg, path: Path) -> None:
    """The canvas as it is drawn (no second draw, unlike ``savefig``) as a PNG."""
    from PIL import Image  # matplotlib's own PNG writer; imported with it

    width, height = canvas.get_width_height()
    image = Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
    image.save(path, format="png", dpi=(DPI, DPI), compress_level=COMPRESS_LEVEL)


def plot_cones(row: Any, path: Path) -> None:
    """Angle between each constrained boresight and its direction, closed loop and reference,
    against the cone's limit (the planner's stats carry the cones as imposed, margin included).

    Parameters
    ----------
    row : scenarios.runner.Row
        A row with a simulation and a reference whose ``stats["cones"]`` lists
        ``(boresight (body), direction (inertial), angle [rad], keep_out)``.
    path : pathlib.Path
        Where to write the PNG.
    """
    cones = row.reference.stats.get("cones", [])
    sim = row.simulation
    figure = Figure(figsize=(9, 3.2 * len(cones)))
    axes = figure.subplots(len(cones), 1, squeeze=False)
    reference_q = row.reference.q(sim.t)
    for axis, (boresight, direction, angle, keep_out) in zip(axes[:, 0], cones):
        for q, style, label in ((sim.q, "-", "closed loop"), (reference_q, "--", "reference")):
            pointing = quat.rotate(q, np.asarray(boresight))
            separation = np.rad2deg(np.arccos(np.clip(pointing @ np.asarray(direction), -1, 1)))
            axis.plot(sim.t, separation, style, label=label)
        axis.axhline(np.rad2deg(angle), color="r", lw=1, label=("keep-out" if keep_out else "keep-in") + " limit")
        axis.set_ylabel("boresight to direction (deg)")
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("time (s)")
    figure.suptitle(f"{row.label}: pointing constraints")
    figure.subplots_adjust(left=0.1, right=0.98, bottom=0.12 / len(cones), top=1 - 0.1 / len(cones), hspace=0.25)
    figure.savefig(path, **SAVE)


def plot_overlay(results: Any, path: Path) -> None:
    """Torque norm, and the error to the target attitude (to the target rate when the attitude is free).

    Parameters
    ----------
    results : scenarios.runner.RunResults
        The run (rows without a simulation are left out).
    path : pathlib.Path
        Where to write the PNG.
    """
    target_q, target_omega = results.scenario.problem.qf, results.scenario.problem.omegaf
    figure = Figure(figsize=(9, 7))
    top, bottom = figure.subplots(2, 1, sharex=True)
    figure.subplots_adjust(left=0.1, right=0.98, bottom=0.08, top=0.93, hspace=0.08)  # before the labels
    _log_axis(bottom)
    for row in results.rows:
        if row.simulation is None:
            continue
        sim = row.simulation
        norm = np.linalg.norm(sim.applied_torque, axis=1)
        top.plot(sim.t, _held(norm), drawstyle="steps-post", label=row.label)
        if target_q is not None:
            error = np.rad2deg(quat.error_angle(sim.q, target_q))
        elif target_omega is not None:
            error = np.linalg.norm(sim.omega - target_omega, axis=1)
        else:
            error = np.linalg.norm(sim.omega, axis=1)
        bottom.plot(sim.t, np.maximum(error, 1e-9), label=row.label)
    _label(top, "‖u‖ (N m)")
    _label(bottom, "error to target (deg)" if target_q is not None
           else "‖ω − ω_f‖ (rad/s)" if target_omega is not None else "‖ω‖ (rad/s)")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
    if top.get_lines():  # one legend: both panels have the same rows in the same colours
        top.legend(fontsize=8, loc="upper right")
    figure.suptitle(f"{results.scenario.name}: closed-loop comparison")
    _time_axis(bottom)
    figure.savefig(path, **SAVE)


def write_plots(results: Any, directory: Path, stems: list[str] | None = None) -> None:
    """One PNG per simulated row (``<stem>.png``, ``<stem>_cones.png`` with cones) and ``comparison.png``.

    Parameters
    ----------
    results : scenarios.runner.RunResults
        The run.
    directory : pathlib.Path
        Existing directory to write into.
    stems : list of str, optional
        The rows' file stems; ``None``: ``row_stems`` of the labels.
    """
    target_q = results.scenario.problem.qf
    stems = stems if stems is not None else row_stems([row.label for row in results.rows])
    figures: dict[tuple[int, bool, bool], RowFigure] = {}  # one per row shape, reused
    for row, stem in zip(results.rows, stems):
        if row.simulation is None:
            continue
        shape = (row.simulation.wheel_momentum.shape[1], row.reference is not None, target_q is not None)
        if shape not in figures:
            figures[shape] = RowFigure(*shape)
        figures[shape].draw(row, target_q, directory / f"{stem}.png")
        if row.reference is not None and row.reference.stats.get("cones"):
            plot_cones(row, directory / f"{stem}_cones.png")
    plot_overlay(results, directory / "comparison.png")
