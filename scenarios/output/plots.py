"""Matplotlib (Agg) figures of a run: one PNG per row and one overlay comparing the rows.

This is the drawing half: it draws the series of :mod:`scenarios.output.plot_data` (computed from the
run) and imports nothing of the model, so that a separate process can draw while the run
computes (:mod:`scenarios.output.renderer`). :func:`write_plots` does both halves in this process.

Drawing is the largest cost of a run with plots, and nearly all of it is text (tick labels,
legends, axis labels): lines and grids cost little. So it is kept cheap:

* figures are plain ``matplotlib.figure.Figure`` objects (no pyplot state), laid out once with
  fixed margins (no ``tight_layout`` or ``bbox_inches="tight"``, which cost a draw each);
* the per-row figure is built once and reused for every row of the same shape
  (:class:`RowFigure`): what does not change between rows (frames, the shared time axis, axis
  labels, legends, placed beside the panels so that no curve is drawn over them) is drawn once and
  kept as a bitmap; each row then draws only its curves, its value axes and its title on a copy
  of that bitmap, which is written as the PNG without a second draw;
* time series arrive decimated to the panels' pixel columns (:func:`scenarios.output.plot_data.decimate`).
"""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, MaxNLocator, NullLocator

from scenarios.output.plot_data import (
    DPI,
    OVERLAY_FIGSIZE_IN,
    OVERLAY_MARGINS,
    ROW_FIGSIZE_IN,
    ROW_HEIGHT_NO_WHEELS_IN,
    ROW_MARGINS,
    ConeSeries,
    OverlaySeries,
    PlotJob,
    RowSeries,
    cone_series,
    overlay_series,
    plot_jobs,
)

__all__ = [
    "COMPRESS_LEVEL",
    "LABEL_OFFSET_IN",
    "SAVE",
    "RowFigure",
    "draw_cones",
    "draw_jobs",
    "draw_overlay",
    "plot_cones",
    "plot_overlay",
    "write_plots",
]

AXIS_COLORS = ("tab:red", "tab:green", "tab:blue", "tab:purple")
COMPRESS_LEVEL = 1
"""zlib level of the PNGs: level 1 encodes several times faster than the default 6 for ~20 % more bytes."""
SAVE: dict[str, Any] = {"dpi": DPI, "pil_kwargs": {"compress_level": COMPRESS_LEVEL}}
"""``savefig`` options of the figures drawn once."""


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
    _fixed_axis_labels(axis)
    if axis.get_yscale() == "linear":
        axis.yaxis.set_major_locator(MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]))


def _fixed_axis_labels(axis: Any) -> None:
    """Matplotlib's own axis labels placed once (they stay empty here, or are placed by
    :func:`_time_axis`): a label placed automatically is re-placed at every draw after measuring the
    tick labels of the panel and of every panel sharing its axis, about a fifth of a row's draw."""
    axis.yaxis.set_label_coords(-0.1, 0.5)
    if not axis.get_xlabel():
        axis.xaxis.set_label_coords(0.5, -0.1)


def _time_axis(axis: Any) -> None:
    """The time axis: label at a fixed place (no measuring of the tick labels at each draw), at
    most eight ticks (shared by the panels above)."""
    axis.set_xlabel("time (s)")
    axis.xaxis.set_label_coords(0.5, -0.35 / axis.get_position().height / axis.figure.get_figheight())
    axis.xaxis.set_major_locator(MaxNLocator(nbins=7, steps=[1, 2, 2.5, 5, 10]))


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
        self.shape = (n_wheels, with_reference, with_target)
        self.figure = Figure(figsize=(ROW_FIGSIZE_IN[0], ROW_FIGSIZE_IN[1] if n_wheels else ROW_HEIGHT_NO_WHEELS_IN),
                             dpi=DPI)
        self.canvas = FigureCanvasAgg(self.figure)
        axes = self.figure.subplots(5 if n_wheels else 4, 1, sharex=True)
        self.figure.subplots_adjust(**ROW_MARGINS)  # before the labels
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
        """What changes from row to row: value axes, curves, title, and the vertical spines (their
        ends are placed through the value limits, so rounding can move a corner pixel)."""
        artists: list[Any] = []
        for axis in self.axes:
            artists.extend([axis.yaxis, axis.spines["left"], axis.spines["right"]])
            artists.extend(axis.get_lines())
        artists.append(self.title)
        return artists

    def prepare(self, series: RowSeries) -> None:
        """Set a row's curves and limits, and have the static part for its time limits drawn
        (drawn now if it is not yet, else restored): what :meth:`draw` does before the row's own
        artists. A plot process prepares a figure once before it forks, so that both drawers
        share the static part (:mod:`scenarios.output.renderer`).

        Parameters
        ----------
        series : scenarios.output.plot_data.RowSeries
            The row's curves (:func:`scenarios.output.plot_data.row_series`), of this figure's shape.
        """
        if series.shape != self.shape:
            raise ValueError(f"a row of shape {series.shape} drawn on a figure of shape {self.shape}")
        pairs = list(zip(self.torque + self.rate + self.quaternion + self.wheels,
                         series.torque + series.rate + series.quaternion + series.wheels))
        if self.reference is not None and series.reference is not None:
            for items, curves in zip(self.reference, series.reference):
                pairs.extend(zip(items, curves))
        for item, curve in ((self.to_reference, series.to_reference), (self.to_target, series.to_target),
                            (self.rate_norm, series.rate_norm), (self.rate_max, series.rate_max)):
            if item is not None and curve is not None:
                pairs.append((item, curve))
        for item, curve in pairs:
            item.set_data(*curve)
        for axis in self.axes:
            axis.relim()
            axis.autoscale_view()
        self.title.set_text(series.title)
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

    def draw(self, series: RowSeries, path: Path) -> None:
        """Draw a row's curves and write the PNG.

        Parameters
        ----------
        series : scenarios.output.plot_data.RowSeries
            The row's curves (:func:`scenarios.output.plot_data.row_series`), of this figure's shape.
        path : pathlib.Path
            Where to write the PNG.
        """
        self.prepare(series)
        renderer = self.canvas.get_renderer()
        for artist in self._dynamic():
            artist.draw(renderer)
        _write_png(self.canvas, path)


def _write_png(canvas: FigureCanvasAgg, path: Path) -> None:
    """The canvas as it is drawn (no second draw, unlike ``savefig``) as a PNG."""
    from PIL import Image  # matplotlib's own PNG writer; imported with it

    width, height = canvas.get_width_height()
    image = Image.frombuffer("RGBA", (width, height), canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
    image.save(path, format="png", dpi=(DPI, DPI), compress_level=COMPRESS_LEVEL)


def draw_cones(series: ConeSeries, path: Path) -> None:
    """Angle between each constrained boresight and its direction, closed loop and reference,
    against the cone's limit.

    Parameters
    ----------
    series : scenarios.output.plot_data.ConeSeries
        The curves (:func:`scenarios.output.plot_data.cone_series`).
    path : pathlib.Path
        Where to write the PNG.
    """
    count = len(series.cones)
    figure = Figure(figsize=(9, 3.2 * count))
    axes = figure.subplots(count, 1, squeeze=False)
    for axis, cone in zip(axes[:, 0], series.cones):
        axis.plot(series.t, cone["closed_loop"], "-", label="closed loop")
        axis.plot(series.t, cone["reference"], "--", label="reference")
        axis.axhline(cone["limit_deg"], color="r", lw=1, label=("keep-out" if cone["keep_out"] else "keep-in") + " limit")
        axis.set_ylabel("boresight to direction (deg)")
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("time (s)")
    figure.suptitle(series.title)
    figure.subplots_adjust(left=0.1, right=0.98, bottom=0.12 / count, top=1 - 0.1 / count, hspace=0.25)
    figure.savefig(path, **SAVE)


def draw_overlay(series: OverlaySeries, path: Path) -> None:
    """Torque norm, and the error to the target, one curve per row.

    Parameters
    ----------
    series : scenarios.output.plot_data.OverlaySeries
        The curves (:func:`scenarios.output.plot_data.overlay_series`).
    path : pathlib.Path
        Where to write the PNG.
    """
    figure = Figure(figsize=OVERLAY_FIGSIZE_IN)
    top, bottom = figure.subplots(2, 1, sharex=True)
    figure.subplots_adjust(**OVERLAY_MARGINS)  # before the labels
    _log_axis(bottom)
    for label, torque, error in zip(series.labels, series.torque, series.error):
        top.plot(*torque, drawstyle="steps-post", label=label)
        bottom.plot(*error, label=label)
    _label(top, "‖u‖ (N m)")
    _label(bottom, series.error_label)
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
    if top.get_lines():  # one legend: both panels have the same rows in the same colours
        top.legend(fontsize=8, loc="upper right")
    figure.suptitle(series.title)
    _time_axis(bottom)
    figure.savefig(path, **SAVE)


def plot_cones(row: Any, path: Path) -> None:
    """:func:`draw_cones` of :func:`scenarios.output.plot_data.cone_series` of ``row``.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A row with a simulation and a reference whose ``stats["cones"]`` lists the cones.
    path : pathlib.Path
        Where to write the PNG.
    """
    draw_cones(cone_series(row), path)


def plot_overlay(results: Any, path: Path) -> None:
    """:func:`draw_overlay` of :func:`scenarios.output.plot_data.overlay_series` of ``results``.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run (rows without a simulation are left out).
    path : pathlib.Path
        Where to write the PNG.
    """
    draw_overlay(overlay_series(results), path)


def draw_jobs(jobs: list[PlotJob], directory: Path, figures: dict[tuple[int, bool, bool], RowFigure] | None = None
              ) -> None:
    """Draw figures into ``directory``, reusing one :class:`RowFigure` per row shape.

    Parameters
    ----------
    jobs : list of (str, series)
        File names and their series (:func:`scenarios.output.plot_data.plot_jobs`).
    directory : pathlib.Path
        Existing directory to write into.
    figures : dict, optional
        Row figures by shape (:attr:`RowSeries.shape`) to draw on, e.g. prepared ones
        (:meth:`RowFigure.prepare`); the figures of other shapes are added to it. ``None``: new ones.
    """
    figures = {} if figures is None else figures
    for name, series in jobs:
        if isinstance(series, RowSeries):
            figure = figures.get(series.shape) or figures.setdefault(series.shape, RowFigure(*series.shape))
            figure.draw(series, directory / name)
        else:
            DRAW[type(series)](series, directory / name)


DRAW: dict[type, Callable[[Any, Path], None]] = {OverlaySeries: draw_overlay, ConeSeries: draw_cones}
"""How each kind of series other than a row is drawn."""


def write_plots(results: Any, directory: Path, stems: list[str] | None = None) -> None:
    """One PNG per simulated row (``<stem>.png``, ``<stem>_cones.png`` with cones) and ``comparison.png``.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.
    directory : pathlib.Path
        Existing directory to write into.
    stems : list of str, optional
        The rows' file stems; ``None``: ``row_stems`` of the labels.
    """
    draw_jobs(plot_jobs(results, stems), directory)
