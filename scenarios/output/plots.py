"""Matplotlib (Agg) figures of a run: one PNG per row, one overlay comparing the rows, and with
pointing requirements the margin of each against time and the sensors' boresights on the sky.

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

The pointing figures are drawn only for runs with pointing requirements. The margin against time
uses a symmetric logarithmic value axis, linear within the smallest margin any row reaches: a
dip of a fraction of a degree below zero shows as plainly as a pass at tens of degrees. Each
curve's minimum is the scored one (the results table's, evaluated between the samples too), marked
at its time and drawn as a point of the curve, so that a violation the samples miss still shows. The sky
map is Mollweide's equal-area projection of the whole sphere: every direction a boresight or a
cone can take is on one flat picture, areas (the cones) keep their proportions, and no part of
the sphere hides behind another as on a drawn 3-D globe.
"""
from __future__ import annotations

import struct
import textwrap
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import (
    FixedLocator,
    FuncFormatter,
    Locator,
    LogLocator,
    MaxNLocator,
    NullLocator,
)

from scenarios.output.plot_data import (
    DPI,
    EULER_SEQUENCE,
    MARGIN_MARGINS,
    MARGIN_PANEL_IN,
    MARGIN_WIDTH_IN,
    OVERLAY_AXES_WSPACE,
    OVERLAY_EDGES_IN,
    OVERLAY_GAP_IN,
    OVERLAY_MARGINS,
    OVERLAY_ROW_IN,
    OVERLAY_TIME_IN,
    OVERLAY_WIDTH_IN,
    MarginPanel,
    MarginSeries,
    OverlaySeries,
    PlotJob,
    RowSeries,
    RowShape,
    SkyPath,
    SkySeries,
    map_longitude,
    overlay_series,
    plot_jobs,
    row_figure_layout,
    torque_limit_label,
)

__all__ = [
    "COMPRESS_LEVEL",
    "LABEL_OFFSET_IN",
    "ROW_COLORS",
    "LogTicks",
    "RowFigure",
    "draw_jobs",
    "draw_margins",
    "draw_overlay",
    "draw_sky",
    "euler_names",
    "margin_axis",
    "margin_figure",
    "overlay_figure",
    "plot_overlay",
    "png_bytes",
    "sky_figure",
    "write_plots",
]

AXIS_COLORS = ("tab:red", "tab:green", "tab:blue")
"""Colours of the body axes x, y, z: of every per-axis curve (torque, rate, the quaternion's vector
part, the Euler angle about each axis, a wheel along the axis, the dipole)."""
QUATERNION_COLORS = ("tab:purple", *AXIS_COLORS)
"""Colours of the quaternion's components: the scalar part, then the vector part in the axes' colours."""
PROPER_EULER_COLOR = "tab:purple"
"""Colour of the third angle of a proper Euler sequence (its first rotates about the same axis)."""
WHEEL_COLORS = ("tab:orange", "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:gray", "gold", "navy")
"""Colours of wheels whose spin axes are not distinct body axes (those take the axis' colour)."""
FAILED_STYLE: dict[str, Any] = {"color": "0.55", "linestyle": ":"}
"""How a failed wheel's curves are drawn."""
ROW_COLORS = ("tab:blue", "tab:orange", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan",
              "tab:gray", "navy", "goldenrod")
"""Colours of the rows in the pointing figures (red and green are the keep-out and keep-in cones')."""
KEEP_COLORS = {True: "tab:red", False: "tab:green"}
"""Colour of a keep-out (``True``) and a keep-in (``False``) cone."""
COMPRESS_LEVEL = 1
"""zlib level of the PNGs: level 1 encodes several times faster than the default 6 for ~20 % more bytes."""
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
"""The first eight bytes of every PNG file."""


class LogTicks(Locator):
    """Ticks of a logarithmic axis that always has some: at most seven powers of ten, and within
    less than a decade 1, 2 and 5 times a power of ten, or evenly spaced numbers (matplotlib's own
    log locator has none there, and its minor ticks are left out here)."""

    def __call__(self) -> Any:
        """The ticks of the axis' view."""
        if self.axis is None:
            return np.array([])
        low, high = self.axis.get_view_interval()
        return self.tick_values(low, high)

    def tick_values(self, vmin: float, vmax: float) -> Any:
        """Tick positions for a view.

        Parameters
        ----------
        vmin, vmax : float
            The view's ends (positive).

        Returns
        -------
        ndarray
            The ticks (some may lie outside the view; matplotlib drops those).
        """
        low, high = sorted((float(vmin), float(vmax)))
        if not (low > 0 and np.isfinite(high)):
            return np.array([])
        decades = np.asarray(LogLocator(base=10.0, subs=(1.0,), numticks=7).tick_values(low, high), dtype=float)
        if np.count_nonzero((decades >= low) & (decades <= high)) >= 2:
            return decades
        powers = 10.0 ** np.arange(np.floor(np.log10(low)), np.ceil(np.log10(high)) + 1)
        nice = np.sort(np.outer(powers, [1.0, 2.0, 5.0]).ravel())
        inside = nice[(nice >= low) & (nice <= high)]
        return inside if inside.size >= 2 else MaxNLocator(nbins=4).tick_values(low, high)


def _log_axis(axis: Any) -> None:
    """A logarithmic y axis with plain ``1e-05`` labels (the default ``10⁻⁵`` labels go through
    mathtext, which parses every label and costs more than drawing the whole figure), and ticks
    however narrow its view (:class:`LogTicks`)."""
    axis.set_yscale("log")
    axis.yaxis.set_major_locator(LogTicks())
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


def _time_axis(axis: Any, locator: Locator | None = None) -> None:
    """The time axis: label at a fixed place (no measuring of the tick labels at each draw), at
    most eight ticks (shared by the panels above) or those of ``locator``."""
    axis.set_xlabel("time (s)")
    axis.xaxis.set_label_coords(0.5, -0.35 / axis.get_position().height / axis.figure.get_figheight())
    axis.xaxis.set_major_locator(locator or MaxNLocator(nbins=7, steps=[1, 2, 2.5, 5, 10]))


PANEL_LABELS = {"torque": "body torque (N m)", "rate": "body rate (deg/s)", "quaternion": "quaternion (–)",
                "wheel_torque": "wheel torque (N m)", "wheel_momentum": "wheel momentum (N m s)",
                "wheel_speed": "wheel speed (rpm)", "dipole": "dipole (A m²)"}
"""Value-axis labels of the per-row figure's panels (the error panel's and the Euler angles' depend on the row)."""


def euler_names(sequence: str) -> tuple[str, list[str], list[str]]:
    """How the Euler angles of a sequence are named and coloured.

    Parameters
    ----------
    sequence : str
        A valid Euler sequence of digits (:func:`ocp.quat.sequence_axes`, checked where its series were
        computed: this module does not import the model).

    Returns
    -------
    label : str
        The panel's value-axis label, with the sequence and the unit (``"Euler 3-2-1 (deg)"``).
    names : list of str
        The legend's name of each angle, with its axis (``"ψ yaw (z)"`` for 3-2-1).
    colors : list of str
        Each angle's colour: its axis' (:data:`AXIS_COLORS`); the third of a proper sequence
        :data:`PROPER_EULER_COLOR`.
    """
    axes = tuple(int(digit) - 1 for digit in sequence)
    names = (["ψ yaw", "θ pitch", "φ roll"] if axes == (2, 1, 0)
             else [f"{symbol}{number}" for symbol, number in zip("αβγ", ("₁", "₂", "₃"))])
    colors = [AXIS_COLORS[a] for a in axes]
    if axes[0] == axes[2]:
        colors[2] = PROPER_EULER_COLOR
    label = f"Euler {'-'.join(str(a + 1) for a in axes)} (deg)"
    return label, [f"{name} ({'xyz'[a]})" for name, a in zip(names, axes)], colors


def wheel_colors(n_wheels: int, wheel_axis: tuple[int, ...]) -> list[str]:
    """Colours of the wheels: a wheel along a body axis takes that axis' colour (:data:`AXIS_COLORS`)
    when no other wheel lies along it, the others :data:`WHEEL_COLORS` in turn.

    Parameters
    ----------
    n_wheels : int
        Number of wheels.
    wheel_axis : tuple of int
        Per wheel, the body axis (0, 1, 2) it spins about or -1 (empty: none known).

    Returns
    -------
    list of str
        A matplotlib colour per wheel.
    """
    axes = list(wheel_axis) if len(wheel_axis) == n_wheels else [-1] * n_wheels
    colors, spare = [], iter(WHEEL_COLORS * (1 + n_wheels // len(WHEEL_COLORS)))
    for axis in axes:
        colors.append(AXIS_COLORS[axis] if axis >= 0 and axes.count(axis) == 1 else next(spare))
    return colors


ROW_LEGEND_CHARS = 20
"""Longest line of a label in the row figure's legends (the body-torque limit's with wheels is wrapped)."""


class RowFigure:
    """The per-row figure, built once and redrawn for each row of the same shape (module docstring).

    Panels, top to bottom: body torque, body rate, quaternion, Euler angles, error angles (with an
    estimator in the loop, the knowledge error too); with
    wheels their motor torques and momenta, and speeds when their spin inertia is known; with
    magnetorquers their dipole. Every per-axis curve takes its axis' colour (:data:`AXIS_COLORS`).
    Actuator limits are dotted ``±`` lines (one black pair when every curve of the panel has the
    same limit, else one pair per curve in its colour; the body torque's bound the solid applied
    torque, and with wheels not the dashed reference, as their label says:
    :func:`~scenarios.output.plot_data.torque_limit_label`); failed wheels are grey, dotted and marked
    in the legend. The panels share one time axis, its ticks on the last panel.

    Parameters
    ----------
    n_wheels : int
        Number of wheels, failed ones included.
    with_reference : bool
        Draw the reference dashed and the error to it.
    with_target : bool
        Draw the error to the target attitude.
    failed : tuple of int, optional
        Indices of failed wheels.
    wheel_axis : tuple of int, optional
        Per wheel, the body axis it spins about or -1 (:func:`wheel_colors`).
    wheel_speed : bool, optional
        A wheel speed panel.
    dipole : bool, optional
        A magnetorquer dipole panel.
    limited : tuple of (str, bool) or (str, bool, bool), optional
        Panels with limit lines and whether their limits are common, and for the torque panel
        optionally whether its limit is the whole realised set (``False``: a conservative box,
        said in the legend) (:attr:`RowSeries.shape`).
    euler_sequence : str, optional
        The Euler angles' sequence (:func:`euler_names`); default
        :data:`scenarios.output.plot_data.EULER_SEQUENCE`.
    knowledge : bool, optional
        Draw the knowledge error (the attitude the controller was given, from the true one) on the
        error panel.
    """

    def __init__(self, n_wheels: int, with_reference: bool, with_target: bool, failed: tuple[int, ...] = (),
                 wheel_axis: tuple[int, ...] = (), wheel_speed: bool = False, dipole: bool = False,
                 limited: tuple[tuple[Any, ...], ...] = (), euler_sequence: str = EULER_SEQUENCE,
                 knowledge: bool = False):
        self.shape: RowShape = (n_wheels, with_reference, with_target, tuple(failed), tuple(wheel_axis),
                                wheel_speed, dipole, tuple(limited), euler_sequence, knowledge)
        names = ["torque", "rate", "quaternion", "euler", "error"]
        names += ["wheel_torque", "wheel_momentum"] if n_wheels else []
        names += ["wheel_speed"] if n_wheels and wheel_speed else []
        names += ["dipole"] if dipole else []
        figsize, margins = row_figure_layout(len(names))
        self.figure = Figure(figsize=figsize, dpi=DPI)
        self.canvas = FigureCanvasAgg(self.figure)
        axes = self.figure.subplots(len(names), 1)  # one time axis, drawn on the last panel (see prepare)
        self.figure.subplots_adjust(**margins)  # before the labels
        self.axes = axes
        panel = dict(zip(names, axes))

        def line(axis: Any, style: str | None = None, **kw: Any) -> Any:
            return (axis.plot([], [], style, **kw) if style else axis.plot([], [], **kw))[0]

        def curves(name: str, count: int, colors: list[str], label: str, **kw: Any) -> list[Any]:
            """One line per curve of a panel (none without the panel); failed wheels grey and dotted."""
            if name not in panel:
                return []
            items = []
            for i in range(count):
                dead = name.startswith("wheel") and i in failed
                style = {**kw, "color": colors[i], **(FAILED_STYLE if dead else {})}
                items.append(line(panel[name], label=label.format(i=i, axis="xyz"[i % 3]) + (" failed" if dead else ""),
                                  **style))
            return items

        axis_colors = list(AXIS_COLORS)
        euler_label, euler_legend, euler_colors = euler_names(euler_sequence)
        self.torque = curves("torque", 3, axis_colors, "u_{axis}", drawstyle="steps-post")
        self.rate = curves("rate", 3, axis_colors, "ω_{axis}")
        self.quaternion = [line(panel["quaternion"], color=QUATERNION_COLORS[i], label=f"q{i}") for i in range(4)]
        self.euler = [line(panel["euler"], color=euler_colors[i], label=euler_legend[i]) for i in range(3)]
        self.reference: tuple[list[Any], ...] | None = None
        if with_reference:
            self.reference = tuple([line(panel[name], "--", color=color, lw=1) for color in colors]
                                   for name, colors in (("torque", AXIS_COLORS), ("rate", AXIS_COLORS),
                                                        ("quaternion", QUATERNION_COLORS), ("euler", euler_colors)))
        error = panel["error"]
        _log_axis(error)
        self.to_target = line(error, color="k", label="to target") if with_target else None
        self.to_reference = line(error, color="tab:orange", label="to reference") if with_reference else None
        self.knowledge = line(error, color="tab:purple", lw=1, label="knowledge") if knowledge else None
        self.rate_norm = self.rate_max = None
        if not with_reference and not with_target:  # rate regulation (detumbling): the rate converges
            self.rate_norm = line(error, color="k", label="‖ω‖")
            self.rate_max = line(error, color="tab:gray", lw=1, label="max |ω_i|")
        colors = wheel_colors(n_wheels, tuple(wheel_axis))
        self.wheel_torque = curves("wheel_torque", n_wheels, colors, "g_w{i}", drawstyle="steps-post")
        self.wheels = curves("wheel_momentum", n_wheels, colors, "h_w{i}")
        self.wheel_speed = curves("wheel_speed", n_wheels, colors, "Ω_w{i}")
        self.dipole = curves("dipole", 3, axis_colors, "m_{axis}", drawstyle="steps-post")
        self.limit_lines: list[tuple[str, int | None, float, Any]] = []
        """(panel, curve index or None for a common limit, sign, line)."""
        self.off_scale: dict[str, Any] = {}
        """Per limited panel, the note shown when its limits lie beyond the view (:data:`LIMIT_VIEW_FACTOR`)."""
        for name, common, *exact in limited:
            if name not in panel:
                continue
            count = {"torque": 3, "dipole": 3}.get(name, n_wheels)
            items: list[int | None] = [None] if common else list(range(count))
            for index in items:
                color = "k" if index is None else (axis_colors if name in ("torque", "dipole") else colors)[index]
                for sign in (1.0, -1.0):
                    label = ("±limit" if common else "±limit (per curve)") if sign > 0 and index in (None, 0) else None
                    if label and name == "torque" and exact and not exact[0]:  # a skewed wheel array's box
                        label = "±box on all axes at once (conservative: one axis alone gets more)"
                    if label and name == "torque":
                        label = textwrap.fill(torque_limit_label(label, n_wheels > 0), ROW_LEGEND_CHARS)
                    self.limit_lines.append((name, index, sign, line(panel[name], linestyle=":", color=color,
                                                                     lw=1.3, label=label or "_limit")))
            self.off_scale[name] = panel[name].text(0.995, 0.96, "", transform=panel[name].transAxes, ha="right",
                                                    va="top", fontsize=7, color="0.3")
        self.panels = panel
        labels = {**PANEL_LABELS, "euler": euler_label,
                  "error": "error angle (deg)" if with_reference or with_target else "body rate (deg/s)"}
        self.time_grid: list[LineCollection] = []
        """Vertical grid lines of the panels above the last, at its time ticks: they have no ticks
        of their own (a tick costs three artists and a text to draw)."""
        for name, axis in panel.items():
            _label(axis, labels[name])
            if axis is axes[-1]:
                axis.grid(alpha=0.3)
            else:
                axis.xaxis.set_major_locator(NullLocator())
                axis.grid(alpha=0.3, axis="y")
                self.time_grid.append(_grid_lines(axis, "x"))
            if any(not item.get_label().startswith("_") for item in axis.get_lines()):
                # beside the panel: static (drawn once), and never over a curve
                axis.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, borderaxespad=0.0)
        # from a fixed distance below the top edge: its lines (at most TITLE_LINES) stay above the first panel
        self.title = self.figure.suptitle("", y=1.0 - TITLE_GAP_IN / figsize[1], va="top", fontsize=TITLE_FONT)
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
        artists.extend(self.off_scale.values())
        return artists

    @property
    def prepared(self) -> bool:
        """Whether the static part has been drawn (by :meth:`prepare`), for some time limits."""
        return self._background is not None

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
        pairs = list(zip(self.torque + self.rate + self.quaternion + self.euler + self.wheels + self.wheel_torque
                         + self.wheel_speed + self.dipole,
                         series.torque + series.rate + series.quaternion + series.euler + series.wheels
                         + series.wheel_torque + series.wheel_speed + series.dipole))
        if self.reference is not None and series.reference is not None:
            for items, curves in zip(self.reference, series.reference):
                pairs.extend(zip(items, curves))
        for item, curve in ((self.to_reference, series.to_reference), (self.to_target, series.to_target),
                            (self.rate_norm, series.rate_norm), (self.rate_max, series.rate_max),
                            (self.knowledge, series.knowledge)):
            if item is not None and curve is not None:
                pairs.append((item, curve))
        for item, curve in pairs:
            item.set_data(*curve)
        for *_, item in self.limit_lines:
            item.set_data([], [])
        for axis in self.axes:  # fitted to the curves; the limits are added below
            axis.relim()
            axis.autoscale_view()
        low, high = min(axis.get_xlim()[0] for axis in self.axes), max(axis.get_xlim()[1] for axis in self.axes)
        for axis in self.axes:  # one time axis
            axis.set_xlim(low, high, auto=None)
        span = [series.torque[0][0][0], series.torque[0][0][-1]] if series.torque and len(series.torque[0][0]) else []
        for name, index, sign, item in self.limit_lines:
            values = np.asarray(series.limits[name], dtype=float)
            finite = values[np.isfinite(values)]
            value = (finite.max() if finite.size else np.nan) if index is None else values[index]
            item.set_data(span, np.full(len(span), sign * value))
        for name, note in self.off_scale.items():
            values = np.asarray(series.limits[name], dtype=float)
            limit = float(np.nanmax(values)) if np.any(np.isfinite(values)) else np.nan
            low, high = self.panels[name].get_ylim()
            peak = max(abs(low), abs(high))
            if not np.isfinite(limit):
                note.set_text("")
            elif limit <= LIMIT_VIEW_FACTOR * peak:
                self.panels[name].set_ylim(min(low, -1.05 * limit), max(high, 1.05 * limit), auto=None)
                note.set_text("")
            else:
                common = any(index is None for panel, index, _, _ in self.limit_lines if panel == name)
                note.set_text(f"{'limit' if common else 'limits up to'} ±{limit:.3g} beyond the view")
        self.title.set_text("\n".join(textwrap.wrap(series.title, TITLE_CHARS, max_lines=TITLE_LINES, placeholder=" …")))
        time_limits = tuple(self.axes[-1].get_xlim())
        canvas, dynamic = self.canvas, self._dynamic()
        if self._background is None or self._background[0] != time_limits:
            ticks = [t for t in self.axes[-1].xaxis.get_majorticklocs() if low <= t <= high]
            for lines in self.time_grid:
                _set_grid_lines(lines, "x", ticks)
            for artist in dynamic:
                artist.set_visible(False)
            canvas.draw()
            self._background = (time_limits, canvas.copy_from_bbox(self.figure.bbox))
            for artist in dynamic:
                artist.set_visible(True)
        else:
            canvas.restore_region(self._background[1])

    def draw(self, series: RowSeries, path: Path | BinaryIO) -> None:
        """Draw a row's curves and write the PNG.

        Parameters
        ----------
        series : scenarios.output.plot_data.RowSeries
            The row's curves (:func:`scenarios.output.plot_data.row_series`), of this figure's shape.
        path : pathlib.Path or binary file
            Where to write the PNG (a file object: into it, e.g. a ``BytesIO``).
        """
        self.prepare(series)
        renderer = self.canvas.get_renderer()
        for artist in self._dynamic():
            artist.draw(renderer)
        _write_png(self.canvas, path)


def _png_chunk(kind: bytes, data: Any) -> bytes:
    """One PNG chunk: length, type, data and the CRC of type and data."""
    return (struct.pack(">I", len(data)) + kind + bytes(data)
            + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind))))


def png_bytes(rgba: np.ndarray, dpi: float = DPI, level: int = COMPRESS_LEVEL) -> bytes:
    """An opaque RGBA image (an Agg canvas' buffer) as an 8-bit RGB PNG file, alpha dropped.

    Every scan line is stored unfiltered (PNG filter type 0) and the whole image deflated at
    ``level``: Pillow's writer tries all five filters on every line, which costs twice as much as
    the deflating itself and, on a figure's flat areas and thin lines, saves no bytes (its files
    are larger here). The pixels are the same as Pillow's ``convert("RGB")`` of the buffer.

    Parameters
    ----------
    rgba : numpy.ndarray
        ``(height, width, 4)`` unsigned bytes (``FigureCanvasAgg.buffer_rgba``); the alpha channel
        is left out (the figures are drawn on an opaque background).
    dpi : float, optional
        Resolution recorded in the file (the ``pHYs`` chunk, in pixels per metre as PNG has it).
    level : int, optional
        zlib level (:data:`COMPRESS_LEVEL`).

    Returns
    -------
    bytes
        The PNG file.
    """
    height, width = rgba.shape[:2]
    lines = np.empty((height, 1 + 3 * width), np.uint8)
    lines[:, 0] = 0  # filter type of each scan line: none
    np.ndarray((height, width, 3), np.uint8, lines, offset=1, strides=(1 + 3 * width, 3, 1))[...] = rgba[..., :3]
    per_metre = round(dpi / 0.0254)
    return b"".join([PNG_SIGNATURE,
                     _png_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)),  # 8-bit RGB
                     _png_chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
                     _png_chunk(b"IDAT", zlib.compress(lines.data, level)),
                     _png_chunk(b"IEND", b"")])


def _write_png(canvas: FigureCanvasAgg, path: Path | BinaryIO) -> None:
    """The canvas as it is drawn (no second draw, unlike ``savefig``) as a PNG (:func:`png_bytes`)."""
    data = png_bytes(np.asarray(canvas.buffer_rgba()))
    if isinstance(path, Path):
        path.write_bytes(data)
    else:
        path.write(data)


def _draw_png(figure: Figure, path: Path | BinaryIO) -> None:
    """Draw a figure once on an Agg canvas and write it as a PNG (:func:`_write_png`)."""
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    _write_png(canvas, path)


LEGEND_CHARS = 34
"""Longest line of a row's label in the comparison figure's legend (a longer label is wrapped)."""
TITLE_CHARS = 100
"""Longest line of a row figure's title (a longer one is wrapped)."""
TITLE_LINES = 2
"""Most lines of a row figure's title (a longer one is cut, ``…``): they fit above the first panel."""
TITLE_FONT = 11.0
"""Font size of a row figure's title [pt]."""
TITLE_GAP_IN = 0.08
"""Space above a row figure's title [in]: with :data:`TITLE_LINES` lines of :data:`TITLE_FONT` it ends
above the first panel (:data:`scenarios.output.plot_data.ROW_EDGES_IN` below the top)."""
LINE_STYLES = ("-", "--", "-.", ":")
"""Line styles of the rows in the comparison figure, in turn with :data:`ROW_COLORS`: rows whose curves
lie on one another still show (a dashed line over a solid one)."""


STATUS_MARKERS = {"violated": {"marker": "X", "markevery": 0.12, "ms": 6},
                  "failed": {"marker": "o", "markevery": 0.12, "ms": 6, "markerfacecolor": "none"},
                  "crashed": {"marker": "o", "markevery": 0.12, "ms": 6, "markerfacecolor": "none"}}
"""Markers along the error curve (and the legend's line) of a row that is not ok in the comparison
figure (its legend says the status)."""


def _row_style(k: int, status: str = "ok") -> dict[str, Any]:
    """Colour, line style and width of row ``k`` in the comparison figure (the first rows widest, so
    that a later row drawn over them leaves their edges in view), with the markers of its status
    (:data:`STATUS_MARKERS`) when ``status`` is given."""
    return {"color": _row_color(k), "linestyle": LINE_STYLES[k % len(LINE_STYLES)], "lw": max(1.0, 2.2 - 0.4 * k),
            **STATUS_MARKERS.get(status, {})}


def _legend_text(label: str, status: str, breach: str, final: str) -> str:
    """A row's entry in the comparison figure's legend: its label, its status when not ok (what it
    breaks), its final values."""
    lines = textwrap.wrap(label, LEGEND_CHARS)
    if status != "ok":
        lines += textwrap.wrap(status.upper() + (": " + breach if breach else ""), LEGEND_CHARS,
                               initial_indent="  ", subsequent_indent="    ")
    return "\n".join(lines + (["  " + part for part in final.split(", ")] if final else []))


def _grid_lines(axis: Any, which: str, values: Any = ()) -> LineCollection:
    """Grid lines where the axis has no ticks (the look of :meth:`Axes.grid` with ``alpha=0.3``): one
    collection, out of the data limits (:func:`_set_grid_lines` moves them)."""
    lines = LineCollection([], colors="#b0b0b0", alpha=0.3, linewidths=0.8, zorder=0.5,
                           transform=axis.get_xaxis_transform() if which == "x" else axis.get_yaxis_transform())
    axis.add_collection(lines, autolim=False)
    _set_grid_lines(lines, which, values)
    return lines


def _set_grid_lines(lines: LineCollection, which: str, values: Any) -> None:
    """Put grid lines of :func:`_grid_lines` at ``values`` (data coordinates of their axis)."""
    lines.set_segments([[(v, 0.0), (v, 1.0)] if which == "x" else [(0.0, v), (1.0, v)] for v in values])


def overlay_figure(series: OverlaySeries) -> Figure:
    """The rows overlaid: per body axis (columns x, y, z) the body rate and the wheels' momentum
    in body axes, the three axes of a quantity on one value scale; below, the torque norm and the
    error to the target (logarithmic). Each row has its colour and line style, and a row that is
    not ok markers along its error curve (:data:`STATUS_MARKERS`); the legend, beside the panels, gives
    each row's status when not ok (and the pointing violations its records give) and its final
    values. (The torque per axis, with the actuators' limits,
    is in each row's figure.)

    Parameters
    ----------
    series : scenarios.output.plot_data.OverlaySeries
        The curves (:func:`scenarios.output.plot_data.overlay_series`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure, on an Agg canvas.
    """
    per_axis = [(series.rate, "body rate (deg/s)")] if any(series.rate) else []
    if per_axis and any(series.wheel_momentum):
        per_axis.append((series.wheel_momentum, "wheel momentum (N m s)"))
    rows = len(per_axis) + 1
    top, bottom = OVERLAY_EDGES_IN
    height = rows * OVERLAY_ROW_IN + top + bottom + (OVERLAY_TIME_IN if per_axis else 0.0)
    figure = Figure(figsize=(OVERLAY_WIDTH_IN, height), dpi=DPI)
    FigureCanvasAgg(figure)
    sides = {"left": OVERLAY_MARGINS["left"], "right": OVERLAY_MARGINS["right"]}
    # the norm and the error below, each with its value axis; the per-axis panels above, close together
    lower = figure.add_gridspec(1, 2, **sides, wspace=OVERLAY_MARGINS["wspace"], bottom=bottom / height,
                                top=(bottom + OVERLAY_ROW_IN - OVERLAY_GAP_IN) / height)
    norm = figure.add_subplot(lower[0, 0])
    error = figure.add_subplot(lower[0, 1], sharex=norm)
    _log_axis(error)
    handles = []
    statuses = series.statuses or ["ok"] * len(series.labels)
    for k, (torque, curve) in enumerate(zip(series.torque, series.error)):
        norm.plot(*torque, drawstyle="steps-post", **_row_style(k))
        handles.append(error.plot(*curve, **_row_style(k, statuses[k]))[0])
    _label(norm, "‖u‖ (N m)")
    _label(error, series.error_label)
    for axis in (norm, error):
        axis.grid(alpha=0.3)
        _time_axis(axis)
    # The per-axis panels of a quantity share one value scale, on the x panel's axis, and the time
    # span of the panels below, its ticks on the last row. Elsewhere their grids are lines at those
    # ticks: a tick costs three artists and a text to draw, and a panel without ticks draws no label.
    norm.autoscale_view()
    limits = norm.get_xlim()
    times = [t for t in MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10]).tick_values(*limits)
             if limits[0] <= t <= limits[1]]
    upper = figure.add_gridspec(max(len(per_axis), 1), 3, **sides, wspace=OVERLAY_AXES_WSPACE,
                                hspace=OVERLAY_GAP_IN / (OVERLAY_ROW_IN - OVERLAY_GAP_IN),
                                bottom=(bottom + OVERLAY_ROW_IN + OVERLAY_TIME_IN) / height, top=1 - top / height)
    for r, (curves, label) in enumerate(per_axis):
        panels = [figure.add_subplot(upper[r, i]) for i in range(3)]
        for i, axis in enumerate(panels):
            for k, row in enumerate(curves):
                if row:
                    axis.plot(*row[i], **_row_style(k))
            axis.set_xlim(limits)
            if r == len(per_axis) - 1:
                _time_axis(axis, FixedLocator(times))
                axis.grid(alpha=0.3, axis="x")
            else:
                axis.xaxis.set_major_locator(NullLocator())
                _grid_lines(axis, "x", times)
            if r == 0:
                axis.set_title(f"body {'xyz'[i]} axis", fontsize=10)
        low, high = min(a.get_ylim()[0] for a in panels), max(a.get_ylim()[1] for a in panels)
        panels[0].set_ylim(low, high)
        _label(panels[0], label)
        panels[0].grid(alpha=0.3, axis="y")
        values = [v for v in panels[0].yaxis.get_majorticklocs() if low <= v <= high]
        for axis in panels[1:]:
            axis.set_ylim(low, high)
            axis.yaxis.set_major_locator(NullLocator())
            _grid_lines(axis, "y", values)
    if handles:
        count = len(series.labels)
        texts = [_legend_text(label, status, breach, final) for label, status, breach, final in
                 zip(series.labels, statuses, series.breaches or [""] * count, series.finals or [""] * count)]
        figure.legend(handles, texts, loc="upper left",
                      bbox_to_anchor=(OVERLAY_MARGINS["right"] + 0.01, 1 - top / height),
                      fontsize=8, borderaxespad=0.0, handlelength=3.0, labelspacing=0.9)
    figure.suptitle(series.title)
    return figure


def draw_overlay(series: OverlaySeries, path: Path | BinaryIO) -> None:
    """:func:`overlay_figure` as a PNG.

    Parameters
    ----------
    series : scenarios.output.plot_data.OverlaySeries
        The curves (:func:`scenarios.output.plot_data.overlay_series`).
    path : pathlib.Path or binary file
        Where to write the PNG (a file object: into it).
    """
    _draw_png(overlay_figure(series), path)


def _row_color(k: int) -> str:
    return ROW_COLORS[k % len(ROW_COLORS)]


def _nice_up(value: float) -> float:
    """The smallest of 1, 2, 5 times a power of ten that is at least ``value`` (> 0)."""
    power = 10.0 ** np.floor(np.log10(value))
    return float(next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= value * (1 - 1e-12)))


LIMIT_VIEW_FACTOR = 3.0
"""A panel's view is widened to its actuator limits when they are at most this many times its
largest value; beyond, the curves keep the view and a note gives the limit."""
MARGIN_LINEAR_DEG = (1e-4, 1.0)
"""Bounds of the linear part of the margin axis [deg] (:func:`margin_axis`)."""
MARGIN_PAD = 0.08
"""Room left below the lowest and above the highest margin, as a fraction of the axis (in its scale)."""


def margin_axis(axis: Any, low: float, high: float, closest: float) -> None:
    """Scale and limits of a margin axis, so that a small violation shows beside large margins.

    The value axis is symmetric-logarithmic (matplotlib's ``symlog``): linear within
    ``±linthresh``, logarithmic beyond. ``linthresh`` is the smallest margin any row reaches in
    magnitude (``closest``), rounded up to 1, 2 or 5 times a power of ten and kept within
    :data:`MARGIN_LINEAR_DEG`: the margin nearest zero (a 0.2° dip into the cone, or a 0.01°
    clearance) lies at the edge of the linear part or beyond it, a visible distance from the zero
    line, whether the other margins reach 1° or 150°. The limits leave :data:`MARGIN_PAD` of
    the axis (in its own scale) below ``min(low, -linthresh / 2)`` and above ``high``, so that the
    zero line and some of the violated side are always in view.

    Parameters
    ----------
    axis : matplotlib.axes.Axes
        The panel.
    low, high : float
        Smallest and largest margin drawn [deg] (NaN: none).
    closest : float
        Smallest magnitude among the rows' minimum margins [deg] (NaN: none).
    """
    linthresh = float(np.clip(_nice_up(max(closest, MARGIN_LINEAR_DEG[0])) if np.isfinite(closest) else 1.0,
                              *MARGIN_LINEAR_DEG))
    axis.set_yscale("symlog", linthresh=linthresh, linscale=1.0)
    low = min(low if np.isfinite(low) else 0.0, -linthresh / 2)
    high = max(high if np.isfinite(high) else 0.0, linthresh)
    scale = axis.yaxis.get_transform()
    bottom, top = scale.transform(np.array([low, high]))
    pad = MARGIN_PAD * (top - bottom)
    bottom, top = scale.inverted().transform(np.array([bottom - pad, top + pad]))
    axis.set_ylim(bottom, top)
    ticks = [0.0]
    for side, end in ((1.0, top), (-1.0, bottom)):
        decades = [10.0 ** k for k in range(int(np.floor(np.log10(linthresh))) + 1, 4)
                   if 10.0 ** k < abs(end) and 10.0 ** k > 1.5 * linthresh]
        decades = decades[::2] if len(decades) > 4 else decades
        ticks += [side * v for v in [linthresh] + decades if v <= abs(end)]
    axis.yaxis.set_major_locator(FixedLocator(sorted(ticks)))
    axis.yaxis.set_minor_locator(NullLocator())
    axis.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))


MINIMUM_MARKER = "v"
"""Marker of each curve's minimum margin in the margin figure (filled for the closed loop, open for
the reference)."""


def _minimum_text(worst: float | None, lowest: tuple[float, float] | None, scored: bool) -> str:
    """A legend's account of a curve's minimum margin."""
    if worst is None:
        return "no sample in the window"
    when = f" at {lowest[0]:.4g} s" if lowest is not None else ""
    return f"min {worst:+.4g}°{when}" + ("" if scored else " (samples)")


def _margin_panel(axis: Any, panel: MarginPanel, series: MarginSeries) -> None:
    """One requirement's panel of :func:`margin_figure`."""
    drawn: list[np.ndarray] = []
    handles = []
    marked = False
    for k, label in enumerate(series.labels):
        color = _row_color(k)
        for curve, worst, lowest, scored, style, name in (
                (panel.reference[k], panel.worst_reference[k], _at(panel.lowest_reference, k),
                 _at(panel.scored_reference, k, False), "--", "reference"),
                (panel.closed_loop[k], panel.worst_closed_loop[k], _at(panel.lowest_closed_loop, k),
                 _at(panel.scored_closed_loop, k, False), "-", "closed loop")):
            if curve is None:
                continue
            t, margin = curve
            handles.append(axis.plot(t, margin, style, color=color, lw=1.4 if style == "-" else 1.1,
                                     label=f"{label}, {name}: {_minimum_text(worst, lowest, scored)}")[0])
            axis.fill_between(t, margin, 0.0, where=margin < 0, interpolate=True, color=color, alpha=0.35, lw=0)
            drawn.append(margin)
            if lowest is not None:
                axis.plot([lowest[0]], [lowest[1]], MINIMUM_MARKER, color=color, ms=7, zorder=5,
                          markerfacecolor=color if name == "closed loop" else "white", markeredgewidth=1.2,
                          label=f"_minimum {k} {name}")
                drawn.append(np.array([lowest[1]]))
                marked = True
    if marked:
        handles.append(Line2D([], [], linestyle="none", marker=MINIMUM_MARKER, color="0.3", ms=7,
                              label="each curve's minimum (the results table's)"))
    values = np.concatenate(drawn) if drawn else np.array([np.nan])
    closest = [abs(w) for w in panel.worst_reference + panel.worst_closed_loop if w is not None]
    finite = values[np.isfinite(values)]
    margin_axis(axis, float(finite.min()) if finite.size else np.nan, float(finite.max()) if finite.size else np.nan,
                min(closest) if closest else np.nan)
    bottom = axis.get_ylim()[0]
    axis.axhspan(bottom, 0.0, color="tab:red", alpha=0.08, lw=0)
    axis.axhline(0.0, color="k", lw=1.2, label="zero: the limit")
    start, end = panel.window
    if start > 0:
        axis.axvspan(0.0, start, color="0.5", alpha=0.15, lw=0)
    if end < series.end:
        axis.axvspan(end, series.end, color="0.5", alpha=0.15, lw=0)
    axis.set_ylim(bottom, axis.get_ylim()[1])
    axis.set_title(panel.title, fontsize=9, loc="left")
    axis.set_ylabel("margin (deg)")
    axis.grid(alpha=0.3)
    axis.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7, borderaxespad=0.0)


def _at(values: list[Any], k: int, default: Any = None) -> Any:
    """``values[k]``, or ``default`` past its end."""
    return values[k] if k < len(values) else default


def margin_figure(series: MarginSeries) -> Figure:
    """The margin of every pointing requirement against time: one panel per requirement, each row's
    reference dashed and closed loop solid (colours of :data:`ROW_COLORS`), the zero line black,
    the violated side tinted red and each violation filled, the time outside the requirement's
    window grey, the value axis of :func:`margin_axis`; the legends beside the panels give each
    curve's minimum margin.

    Parameters
    ----------
    series : scenarios.output.plot_data.MarginSeries
        The curves (:func:`scenarios.output.plot_data.margin_series`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure, on an Agg canvas.
    """
    count = max(len(series.panels), 1)
    height = count * MARGIN_PANEL_IN + 1.1
    figure = Figure(figsize=(MARGIN_WIDTH_IN, height), dpi=DPI)
    FigureCanvasAgg(figure)
    axes = figure.subplots(count, 1, sharex=True, squeeze=False)[:, 0]
    figure.subplots_adjust(**MARGIN_MARGINS, top=1 - 0.75 / height, bottom=0.55 / height, hspace=0.42)
    for axis, panel in zip(axes, series.panels):
        _margin_panel(axis, panel, series)
    axes[-1].set_xlim(0.0, series.end)
    axes[-1].set_xlabel("time (s)")
    figure.suptitle(series.title, fontsize=10)
    return figure


def draw_margins(series: MarginSeries, path: Path | BinaryIO) -> None:
    """:func:`margin_figure` as a PNG.

    Parameters
    ----------
    series : scenarios.output.plot_data.MarginSeries
        The curves (:func:`scenarios.output.plot_data.margin_series`).
    path : pathlib.Path or binary file
        Where to write the PNG (a file object: into it).
    """
    _draw_png(margin_figure(series), path)


def _on_map(path: SkyPath) -> tuple[np.ndarray, np.ndarray]:
    """A sky path in the map's coordinates [rad] (:func:`scenarios.output.plot_data.map_longitude`)."""
    ra, dec = path
    return np.deg2rad(map_longitude(ra)), np.deg2rad(dec)


def sky_figure(series: SkySeries) -> Figure:
    """The sensors' boresights on the sky: one full-sky map (Mollweide, right ascension growing to
    the left, declination up, inertial frame) per sensor; each row's closed loop solid (start ○,
    end □) and reference dashed, in the colours of the margin figure; each requirement's cone
    drawn as its boundary (red keep-out, green keep-in; solid at the start of the run, dash-dot
    at the end for a moving direction), the path of its centre dotted and its name at the centre,
    and the Earth's disc filled blue for a cone that grows by the Earth's apparent radius.

    Parameters
    ----------
    series : scenarios.output.plot_data.SkySeries
        The paths (:func:`scenarios.output.plot_data.sky_series`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure, on an Agg canvas.
    """
    count = max(len(series.panels), 1)
    height = count * 5.0 + 0.7
    figure = Figure(figsize=(12.0, height), dpi=DPI)
    FigureCanvasAgg(figure)
    figure.subplots_adjust(left=0.04, right=0.7, top=1 - 0.6 / height, bottom=0.3 / height, hspace=0.25)
    for index, panel in enumerate(series.panels):
        axis = figure.add_subplot(count, 1, index + 1, projection="mollweide")
        axis.grid(alpha=0.35)
        for k, label in enumerate(series.labels):
            color = _row_color(k)
            reference, closed_loop = panel.reference[k], panel.closed_loop[k]
            if reference is not None:
                axis.plot(*_on_map(reference), "--", color=color, lw=1.1, label=f"{label}, reference")
            if closed_loop is not None:
                x, y = _on_map(closed_loop)
                axis.plot(x, y, "-", color=color, lw=1.5, label=f"{label}, closed loop")
                ends = np.flatnonzero(np.isfinite(x))
                axis.plot(x[ends[0]], y[ends[0]], "o", mfc="none", color=color, ms=6)
                axis.plot(x[ends[-1]], y[ends[-1]], "s", mfc="none", color=color, ms=6)
        for cone in panel.cones:
            color = KEEP_COLORS[cone.keep_out]
            kind = "keep-out" if cone.keep_out else "keep-in"
            for number, boundary in enumerate(cone.boundaries):
                axis.plot(*_on_map(boundary), "-" if number == 0 else "-.", color=color, lw=1.6,
                          label=f"{cone.label} ({kind}){' at the end' if number else ''}")
            x, y = _on_map(cone.centre)
            axis.plot(x, y, ":" if len(x) > 1 else "+", color=color, ms=9, mew=2, zorder=4)
            axis.text(x[0], y[0], f" {cone.label}", color=color, fontsize=8, va="top",
                      bbox={"facecolor": "white", "alpha": 0.7, "linewidth": 0, "pad": 1})
            for number, disc in enumerate(cone.discs):
                dx, dy = _on_map(disc)
                filled = bool(np.all(np.isfinite(dx)))  # a disc that does not wrap round the map is filled
                if filled:
                    axis.fill(dx, dy, color="tab:blue", alpha=0.2, lw=0, label="Earth disc" if number == 0 else None)
                axis.plot(dx, dy, color="tab:blue", lw=1.0, label="Earth disc" if number == 0 and not filled else None)
        axis.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{(-np.rad2deg(x)) % 360:.0f}°"))
        axis.tick_params(labelsize=8)
        axis.set_xlabel("right ascension (deg)", fontsize=9)
        axis.set_ylabel("declination (deg)", fontsize=9)
        axis.set_title(panel.title, fontsize=10, pad=12)
        axis.legend(loc="upper left", bbox_to_anchor=(1.03, 1.0), fontsize=7, borderaxespad=0.0)
    figure.suptitle(series.title + "; closed loop start ○, end □", fontsize=10)
    return figure


def draw_sky(series: SkySeries, path: Path | BinaryIO) -> None:
    """:func:`sky_figure` as a PNG.

    Parameters
    ----------
    series : scenarios.output.plot_data.SkySeries
        The paths (:func:`scenarios.output.plot_data.sky_series`).
    path : pathlib.Path or binary file
        Where to write the PNG (a file object: into it).
    """
    _draw_png(sky_figure(series), path)


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


def draw_jobs(jobs: list[PlotJob], directory: Path, figures: dict[RowShape, RowFigure] | None = None) -> None:
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


DRAW: dict[type, Callable[[Any, Path | BinaryIO], None]] = {OverlaySeries: draw_overlay, MarginSeries: draw_margins,
                                                  SkySeries: draw_sky}
"""How each kind of series other than a row is drawn."""


def write_plots(results: Any, directory: Path, stems: list[str] | None = None,
                euler_sequence: str | None = None) -> None:
    """The figures of :func:`scenarios.output.plot_data.plot_jobs`: one PNG per simulated row
    (``<stem>.png``), ``margins.png`` and ``sky.png`` with pointing requirements, and ``comparison.png``.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.
    directory : pathlib.Path
        Existing directory to write into.
    stems : list of str, optional
        The rows' file stems; ``None``: ``row_stems`` of the labels.
    euler_sequence : str, optional
        The row figures' Euler sequence (:func:`scenarios.output.plot_data.euler_angles`), such as
        ``"313"``; ``None`` (default): the scenario's (``plots.euler_sequence``, ``"321"`` unless given).
    """
    draw_jobs(plot_jobs(results, stems, euler_sequence), directory)
