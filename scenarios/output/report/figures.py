"""The interactive figures of a run, as plotly figure dicts (the JSON form plotly.js draws).

* :func:`row_figure`: one simulated row against time, panels sharing the time axis: the error
  angle, the body rate, the applied torque and the wheel momenta, the reference dashed, the limits
  dotted (the body-torque box of the actuators, the wheels' momentum limit, the rate and final
  requirements);
* :func:`margin_figure`: one pointing requirement's margin against time for every simulated row
  (closed loop solid, reference dashed), with the zero line;
* :func:`sky_figure`: the constrained boresight's track on the celestial sphere (right ascension
  and declination in the run's inertial frame) for every row, with the cone at its start, middle
  and end and the path of its direction;
* :func:`attitude_figure`: the attitude in 3-D (body axes and sensor boresights in the inertial
  frame, the pointing directions and cones), with a time slider and play button.

Every time series is reduced to at most :data:`MAX_POINTS` points per trace
(:func:`scenarios.output.plot_data.decimate` keeps each bin's extremes, so peaks stay), the tracks
on the sphere by uniform thinning with the worst-margin sample kept. Units: time s, angles deg,
rates deg/s, torque N m, momentum N m s; frames as :doc:`/architecture` defines them.
"""
from __future__ import annotations

import textwrap
from collections.abc import Sequence
from typing import Any

import numpy as np

from ocp import quat, target_motion
from ocp.geometry.pointing import PointingConstraint
from scenarios.output.plot_data import (
    decimate,
    held,
    knowledge_series,
    scored_minimum,
    torque_limit_label,
    with_point,
)

__all__ = ["AXIS_COLOURS", "MAX_POINTS", "abscissa", "attitude_figure", "margin_figure", "radec", "row_figure", "sky_figure",
           "thin", "title_layout"]

MAX_POINTS = 1000
"""Most points of one trace (a time series or a track)."""
FRAMES = 100
"""Most time steps of the 3-D view's slider."""
SLIDER_START = 0.17
"""Where the 3-D view's time slider starts (a fraction of the plot's width): its play and pause
buttons sit left of it."""
SLIDER_PX = 90
"""Room below the 3-D view for its time slider (value, rail, tick labels) [px]."""
ATTITUDE_PX = 770
"""Height of the 3-D view [px], title and slider included (its page element has it too, so that
the page does not move when another row is shown)."""
AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")
"""Body axes x, y, z (and a wheel along one of them)."""
_OTHER_COLOURS = ("#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#ff7f0e")
_ROW_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
                "#17becf")
"""Rows in the margin and sky figures (no red: the limits and cones are red)."""
_LIMIT = {"color": "#b00", "dash": "dot", "width": 1.2}
_FLOOR_DEG = 1e-9
"""Smallest error angle on the logarithmic axis [deg]."""


TITLE_CHARS = 80
"""Longest line of a figure's title (a longer one is wrapped): at 14 px it fits the plot of an
800 px wide page."""
MODEBAR_PX = 42
"""Height kept free above a figure's title for plotly's mode bar (its buttons, top right) [px]."""
TITLE_LINE_PX = 19
"""Height of one line of a figure's title [px]."""


def title_layout(text: str, plot_height: float) -> tuple[dict[str, Any], int]:
    """A figure's title below the mode bar, left-aligned and wrapped, and the top margin it needs.

    Parameters
    ----------
    text : str
        The title.
    plot_height : float
        The figure's height without the top margin [px] (the title is placed in the container's
        coordinates, a fraction of the whole height).

    Returns
    -------
    title : dict
        The layout's ``title``: wrapped at :data:`TITLE_CHARS` (``<br>``), its top
        :data:`MODEBAR_PX` below the figure's, so that the mode bar never covers it.
    top : int
        The top margin [px]: the mode bar's room, the title's lines and a gap.
    """
    lines = textwrap.wrap(text, TITLE_CHARS) or [""]
    top = MODEBAR_PX + TITLE_LINE_PX * len(lines) + 12
    return ({"text": "<br>".join(lines), "font": {"size": 14}, "x": 0.0, "xref": "paper", "xanchor": "left",
             "y": 1.0 - MODEBAR_PX / (plot_height + top), "yref": "container", "yanchor": "top"}, top)


def thin(t: np.ndarray, *values: np.ndarray) -> np.ndarray:
    """The samples a trace keeps: all when few, else each bin's extremes
    (:func:`scenarios.output.plot_data.decimate`); non-finite samples are never kept.

    Parameters
    ----------
    t : (N,) ndarray
        Increasing times [s].
    *values : (N,) ndarray
        The series whose extremes must stay (the union of their kept samples is returned).

    Returns
    -------
    ndarray of int
        Increasing sample indices, at most :data:`MAX_POINTS` per series.
    """
    keep: list[np.ndarray] = []
    columns = (MAX_POINTS - 2) // 2
    for series in values:
        finite = np.flatnonzero(np.isfinite(series))
        if finite.size == 0:
            continue
        index, _ = decimate(finite.astype(float), series[finite], columns)  # "times": the sample indices
        keep.append(np.asarray(index).astype(int))
    if not keep:
        return np.zeros(0, dtype=int)
    return np.unique(np.concatenate(keep))


def _gapped(t: np.ndarray, index: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``t[index]``, ``values[index]`` with a gap (NaN, drawn as a break) where ``index`` skips a
    non-finite sample."""
    x, y = t[index].astype(float), values[index].astype(float)
    bad = np.concatenate([[0], np.cumsum(~np.isfinite(values))])  # non-finite samples before each index
    skipped = bad[index[1:]] - bad[index[:-1] + 1] if index.size > 1 else np.zeros(0, dtype=int)
    holes = np.flatnonzero(skipped > 0) + 1
    return np.insert(x, holes, np.nan), np.insert(y, holes, np.nan)


def abscissa(x: np.ndarray) -> dict[str, Any]:
    """A trace's times: ``x0`` and ``dx`` when they are uniform (half the data), else ``x``.

    Parameters
    ----------
    x : (N,) ndarray
        The trace's times [s] (NaN at gaps).

    Returns
    -------
    dict
        ``{"x0": x[0], "dx": step}`` when ``N >= 3``, every time is finite and each step equals the
        first within 1e-9 of it; else ``{"x": x}``.
    """
    if x.size >= 3 and np.all(np.isfinite(x)):
        steps = np.diff(x)
        if steps[0] > 0 and np.max(np.abs(steps - steps[0])) <= 1e-9 * steps[0]:
            return {"x0": float(x[0]), "dx": float(steps[0])}
    return {"x": x}


def _trace(t: np.ndarray, values: np.ndarray, name: str, panel: int, colour: str, *, dash: str = "solid",
           group: str | None = None, legend: bool = True, shape: str = "linear", unit: str = "",
           point: tuple[float, float] | None = None) -> dict[str, Any]:
    """A time-series trace, thinned (:func:`thin`); ``point``: a (time, value) put into it at its time."""
    index = thin(t, values)
    x, y = _gapped(t, index, values)
    if point is not None:
        x, y = with_point((x, y), *point)
    return {"type": "scatter", "mode": "lines", "name": name, **abscissa(x), "y": y, "xaxis": f"x{panel}",
            "yaxis": f"y{panel}", "legend": f"legend{panel}" if panel > 1 else "legend",
            "legendgroup": group or name, "showlegend": legend,
            "line": {"color": colour, "dash": dash, "width": 1.5, "shape": shape},
            "hovertemplate": f"%{{y:.4g}} {unit}<extra>{name}</extra>"}


def _limit(t: np.ndarray, level: float, name: str, panel: int, both: bool, colour: str | None = None,
           start: float | None = None) -> dict[str, Any]:
    """A dotted horizontal limit at ``level`` (and ``-level``), from ``start`` (default the first time)."""
    t0, t1 = float(t[0]) if start is None else start, float(t[-1])
    x: list[Any] = [t0, t1]
    y: list[Any] = [level, level]
    if both:
        x += [None, t0, t1]
        y += [None, -level, -level]
    line = dict(_LIMIT, color=colour or _LIMIT["color"])
    return {"type": "scatter", "mode": "lines", "name": name, "x": x, "y": y, "xaxis": f"x{panel}",
            "yaxis": f"y{panel}", "legend": f"legend{panel}" if panel > 1 else "legend", "line": line,
            "hoverinfo": "skip"}


def _torque_limit_lines(spacecraft: Any) -> list[tuple[float, str, str | None]]:
    """The dotted limits of the torque panel: the largest per-axis box the controllers' allocation
    realises at every corner (``Spacecraft.body_torque_limit``).

    Where that box is the whole realised set (wheels along the body axes, torquers) a torque is
    realised exactly when each component is within it, and the lines are labelled ``limit``.
    Where it is not (a skewed wheel array: a four-wheel pyramid gives more along a single body
    axis, ``Spacecraft.torque_along``, than on every axis at once) they are labelled ``per-axis
    box ... (conservative)``: within them the torque is surely realised, beyond them not surely
    unrealised. They bound the solid curves, the actuators' torque on the body; with wheels the
    label says they do not bound the dashed reference (:func:`~scenarios.output.plot_data.torque_limit_label`).

    Parameters
    ----------
    spacecraft : ocp.Spacecraft
        The actuators.

    Returns
    -------
    list of (float, str, str or None)
        Per line: its level [N m] (drawn at ``±``), its legend name, its colour (``None``: the
        common one); one line when the three bounds are equal, else one per axis with a finite
        positive bound.
    """
    limits = spacecraft.body_torque_limit()
    exact = spacecraft.torque_box_is_exact()
    wheels = spacecraft.wheels is not None
    finite = [float(v) for v in limits if np.isfinite(v) and v > 0]
    if len(finite) == 3 and np.ptp(finite) <= 1e-12 * max(finite):
        name = f"limit ±{finite[0]:.3g} N m" if exact else f"per-axis box ±{finite[0]:.3g} N m (conservative)"
        return [(finite[0], torque_limit_label(name, wheels), None)]
    return [(float(limits[i]), torque_limit_label(f"τ{axis} limit ±{limits[i]:.3g}" if exact
                                                  else f"τ{axis} box ±{limits[i]:.3g} (conservative)", wheels),
             AXIS_COLOURS[i])
            for i, axis in enumerate("xyz") if np.isfinite(limits[i]) and limits[i] > 0]


def _panels(layout: dict[str, Any], titles: Sequence[tuple[str, str]], log: Sequence[bool]) -> None:
    """Stacked panels sharing the time axis, each with its legend at its right."""
    n, gap = len(titles), 0.05
    height = (1.0 - gap * (n - 1)) / n
    for k, ((title, unit), logarithmic) in enumerate(zip(titles, log), start=1):
        top = 1.0 - (k - 1) * (height + gap)
        suffix = "" if k == 1 else str(k)
        layout[f"yaxis{suffix}"] = {"domain": [top - height, top], "title": {"text": f"{title} ({unit})"},
                                    "type": "log" if logarithmic else "linear", "exponentformat": "power"}
        layout[f"xaxis{suffix}"] = {"anchor": f"y{k}", "showticklabels": True,
                                    **({"matches": "x"} if k > 1 else {}),
                                    **({"title": {"text": "time (s)"}} if k == n else {})}
        layout[f"legend{suffix}"] = {"x": 1.01, "y": top, "yanchor": "top", "xanchor": "left",
                                     "font": {"size": 11}, "tracegroupgap": 2}


def _wheel_colours(axes: np.ndarray) -> list[str]:
    """A wheel along a body axis takes that axis's colour; the others, colours of their own."""
    colours, others = [], iter(_OTHER_COLOURS * 4)
    for axis in np.asarray(axes, dtype=float).T:
        along = [i for i in range(3) if abs(abs(axis[i]) - 1.0) < 1e-9]
        colours.append(AXIS_COLOURS[along[0]] if along else next(others))
    return colours


def row_figure(row: Any, scenario: Any) -> dict[str, Any]:
    """One simulated row against time (module docstring).

    Panels: the error angle to the reference (orange) and to the target (black) [deg, log] (in
    regulation without a target attitude, ``‖ω‖`` [deg/s, log]), and with a star tracker in the
    loop the knowledge error (purple: the attitude the controller was given, from the true one,
    :func:`scenarios.output.plot_data.knowledge_series`); the body rate per body axis and
    its norm [deg/s]; the actuators' applied torque per body axis [N m] (held over each sample);
    the wheels' momenta [N m s] when there are wheels. The reference is dashed; dotted limits: the
    per-axis torque box of the controllers' allocation (``Spacecraft.body_torque_limit``, labelled
    conservative where the realised set is no box; it bounds the solid applied torque, and with
    wheels not the dashed reference ``I ω̇ + ω × I ω``, as its label says), each wheel's momentum limit,
    ``requirements.rate`` on ``‖ω‖`` and ``requirements.final`` on the error after ``T + after_s``.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A row with a ``simulation``.
    scenario : scenarios.schema.loader.Scenario
        The scenario run (spacecraft limits, target, requirements).

    Returns
    -------
    dict
        A plotly figure (``data``, ``layout``).
    """
    sim = row.simulation
    problem, requirements = scenario.problem, scenario.requirements
    t = np.asarray(sim.t, dtype=float)
    spacecraft = problem.spacecraft
    wheels = spacecraft.wheels
    n_wheels = sim.wheel_momentum.shape[1]
    reference = row.reference.sample(t) if row.reference is not None else None
    data: list[dict[str, Any]] = []
    target = problem.qf
    if reference is not None or target is not None:
        error_title: tuple[str, str] = ("error angle", "deg")
        if reference is not None:
            data.append(_trace(t, np.maximum(np.rad2deg(quat.error_angle(sim.q, reference.q)), _FLOOR_DEG),
                               "to reference", 1, "#ff7f0e", unit="deg"))
        if target is not None:
            moving = target_motion(target, problem.omegaf, row.reference, t)[0]  # as the metrics measure it
            assert moving is not None  # q_f given
            data.append(_trace(t, np.maximum(np.rad2deg(quat.error_angle(sim.q, moving)), _FLOOR_DEG),
                               "to target", 1, "#222222", unit="deg"))
        final = requirements.final
        if final is not None and final.error_deg is not None:
            data.append(_limit(t, final.error_deg, f"final ≤ {final.error_deg:g} deg", 1, False,
                               start=problem.duration + final.after_s))
    else:
        error_title = ("‖ω‖", "deg/s")
        data.append(_trace(t, np.maximum(np.rad2deg(np.linalg.norm(sim.omega, axis=1)), _FLOOR_DEG), "‖ω‖", 1,
                           "#222222", unit="deg/s"))
    knowledge = knowledge_series(sim)
    if knowledge is not None:
        given = np.isfinite(knowledge[1])
        data.append(_trace(t[given], np.maximum(knowledge[1][given], _FLOOR_DEG), "knowledge error", 1,
                           "#9467bd", unit="deg"))
    omega = np.rad2deg(sim.omega)
    for i, axis in enumerate("xyz"):
        data.append(_trace(t, omega[:, i], f"ω{axis}", 2, AXIS_COLOURS[i], group=f"rate {axis}", unit="deg/s"))
        if reference is not None:
            data.append(_trace(t, np.rad2deg(reference.omega[:, i]), f"ω{axis} ref", 2, AXIS_COLOURS[i], dash="dash",
                               group=f"rate {axis}", legend=False, unit="deg/s"))
    data.append(_trace(t, np.linalg.norm(omega, axis=1), "‖ω‖", 2, "#888888", unit="deg/s"))
    if requirements.rate is not None:
        bound = float(np.rad2deg(requirements.rate.max_rate))
        data.append(_limit(t, bound, f"‖ω‖ ≤ {bound:.3g} deg/s", 2, False))
    torque = held(np.asarray(sim.applied_torque, dtype=float))
    for i, axis in enumerate("xyz"):
        data.append(_trace(t, torque[:, i], f"τ{axis}", 3, AXIS_COLOURS[i], group=f"torque {axis}", shape="hv",
                           unit="N m"))
        if reference is not None:
            data.append(_trace(t, reference.torque[:, i], f"τ{axis} ref", 3, AXIS_COLOURS[i], dash="dash",
                               group=f"torque {axis}", legend=False, unit="N m"))
    data.extend(_limit(t, level, name, 3, True, colour) for level, name, colour in _torque_limit_lines(spacecraft))
    titles = [error_title, ("body rate", "deg/s"), ("applied torque", "N m")]
    log = [True, False, False]
    if n_wheels:
        colours = _wheel_colours(wheels.axes)
        failed = set(wheels.failed)
        for i in range(n_wheels):
            name = f"wheel {i}" + (" (failed)" if i in failed else "")
            data.append(_trace(t, sim.wheel_momentum[:, i], name, 4, colours[i], unit="N m s",
                               dash="dashdot" if i in failed else "solid"))
        momentum = np.asarray(wheels.max_momentum, dtype=float)
        if np.all(np.isfinite(momentum)) and np.ptp(momentum) <= 1e-12 * momentum.max():
            data.append(_limit(t, float(momentum[0]), f"limit ±{momentum[0]:.3g} N m s", 4, True))
        else:
            for i, limit in enumerate(momentum):
                if np.isfinite(limit):
                    data.append(_limit(t, float(limit), f"wheel {i} limit ±{limit:.3g}", 4, True, colours[i]))
        titles.append(("wheel momentum", "N m s"))
        log.append(False)
    controller = f", {row.controller}" if row.controller else ""
    title, top = title_layout(f"{row.label} ({row.planner or 'regulation'}{controller}): solid closed loop, "
                              "dashed reference", 200 * len(titles) + 40)
    layout: dict[str, Any] = {"title": title, "height": 200 * len(titles) + 40 + top,
                              "margin": {"l": 70, "r": 170, "t": top, "b": 45}, "hovermode": "x unified"}
    _panels(layout, titles, log)
    return {"data": data, "layout": layout}


def _simulated(rows: Sequence[Any]) -> list[tuple[int, Any]]:
    return [(k, row) for k, row in enumerate(rows) if row.simulation is not None]


def margin_figure(constraint: PointingConstraint, rows: Sequence[Any]) -> dict[str, Any]:
    """A pointing requirement's margin against time for every simulated row, and the zero line.

    Parameters
    ----------
    constraint : ocp.geometry.PointingConstraint
        The requirement's constraint (``Scenario.problem.pointing``).
    rows : sequence of Row
        The run's rows (those without a simulation are left out).

    Returns
    -------
    dict
        A plotly figure: per row the closed loop's margin (solid) and its reference's (dashed),
        :meth:`~ocp.geometry.pointing.PointingConstraint.margins` in degrees at the simulation's
        samples (decimated; gaps outside the window); negative is violated. Each curve's legend
        gives its minimum: the scored one of the row's requirement record (the results table's,
        :func:`scenarios.output.plot_data.scored_minimum`: evaluated between the samples too),
        which is also a point of the curve, at its time, and marked (▼); without a record, the
        samples' own.
    """
    data: list[dict[str, Any]] = []
    end = 0.0
    for k, row in _simulated(rows):
        sim = row.simulation
        t = np.asarray(sim.t, dtype=float)
        end = max(end, float(t[-1]))
        colour = _ROW_COLOURS[k % len(_ROW_COLOURS)]
        curves = [("closed_loop", sim.q, row.label, "solid")]
        if row.reference is not None:
            curves.append(("reference", row.reference.q(t), f"{row.label} ref", "dash"))
        for scope, q, name, dash in curves:
            margin = np.rad2deg(constraint.margins(t, q))
            record = scored_minimum(row, scope, constraint.name)
            point: tuple[float, float] | None = None
            if record is not None and record[1] is not None:
                point = (record[1], record[0])
            trace = _trace(t, margin, name, 1, colour, dash=dash, group=row.label, unit="deg", point=point)
            if record is None and np.any(np.isfinite(margin)):
                at = int(np.nanargmin(margin))
                point = (float(t[at]), float(margin[at]))
            worst = record[0] if record is not None else (point[1] if point is not None else None)
            if worst is not None:
                trace["name"] = (f"{name}: min {worst:+.4g}°" + (f" at {point[0]:.4g} s" if point is not None else "")
                                 + ("" if record is not None else " (samples)"))
            data.append(trace)
            if point is not None:
                data.append({"type": "scatter", "mode": "markers", "name": f"{name} minimum", "x": [point[0]],
                             "y": [point[1]], "legendgroup": row.label, "showlegend": False,
                             "marker": {"symbol": "triangle-down" if dash == "solid" else "triangle-down-open",
                                        "size": 10, "color": colour},
                             "hovertemplate": f"min %{{y:.4g}} deg at %{{x:.4g}} s<extra>{name}</extra>"})
    data.append({"type": "scatter", "mode": "lines", "name": "zero (violated below)", "x": [0.0, end], "y": [0.0, 0.0],
                 "line": _LIMIT, "hoverinfo": "skip"})
    title, top = title_layout(f"{constraint.name}: {constraint.description}: margin (solid closed loop, dashed "
                              "reference; ▼ each curve's minimum, the results table's)", 330)
    layout = {"title": title, "height": 330 + top, "margin": {"l": 70, "r": 30, "t": top, "b": 45},
              "hovermode": "x unified", "xaxis": {"title": {"text": "time (s)"}},
              "yaxis": {"title": {"text": "margin (deg)"}}}
    return {"data": data, "layout": layout}


def radec(vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Right ascension and declination of directions.

    Parameters
    ----------
    vectors : (N, 3) ndarray
        Directions, inertial frame (any length).

    Returns
    -------
    ra, dec : (N,) ndarray
        Right ascension in [0, 360) and declination in [-90, 90] [deg].
    """
    v = np.asarray(vectors, dtype=float)
    v = v / np.linalg.norm(v, axis=1, keepdims=True)
    ra = np.mod(np.rad2deg(np.arctan2(v[:, 1], v[:, 0])), 360.0)
    return ra, np.rad2deg(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))


def _wrapped(ra: np.ndarray, dec: np.ndarray, extra: np.ndarray | None = None,
             centre: float = 180.0) -> tuple[np.ndarray, ...]:
    """Right ascension within 180 deg of ``centre`` (the map's middle) [deg], and the arrays with a
    gap (NaN) where a track crosses the map's edge (no line across the map)."""
    ra = centre + np.mod(np.asarray(ra, dtype=float) - centre + 180.0, 360.0) - 180.0
    at = np.flatnonzero(np.abs(np.diff(ra)) > 180.0) + 1
    arrays = (ra, dec) if extra is None else (ra, dec, extra)
    return tuple(np.insert(np.asarray(a, dtype=float), at, np.nan) for a in arrays)


def _circle(direction: np.ndarray, radius: float, points: int = 121) -> np.ndarray:
    """Unit vectors at angle ``radius`` [rad] about ``direction`` (a cone's edge on the sphere)."""
    d = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    helper = np.eye(3)[int(np.argmin(np.abs(d)))]
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    phi = np.linspace(0.0, 2.0 * np.pi, points)
    return (np.cos(radius) * d[None, :] + np.sin(radius) * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2))


def _track_index(t: np.ndarray, margin: np.ndarray) -> np.ndarray:
    """Uniformly thinned samples of a track, with the worst-margin sample."""
    n = t.size
    index = np.unique(np.round(np.linspace(0, n - 1, min(n, MAX_POINTS - 1))).astype(int))
    if np.any(np.isfinite(margin)):
        index = np.unique(np.append(index, int(np.nanargmin(margin))))
    return index


STILL_DEG = 0.05
"""A direction and cone that move less than this over the run [deg] are drawn once."""


def _moves(constraint: PointingConstraint, end: float) -> bool:
    """Whether the cone visibly moves over ``[0, end]`` (direction or half-angle by :data:`STILL_DEG`)."""
    if not constraint.moving:
        return False
    times = np.linspace(0.0, end, 50)
    directions = constraint.direction(times)
    turn = np.rad2deg(np.arccos(np.clip(directions @ directions[0], -1.0, 1.0))).max()
    return bool(turn > STILL_DEG or np.rad2deg(np.ptp(constraint.limit(times))) > STILL_DEG)


def _cone_times(constraint: PointingConstraint, end: float) -> list[float]:
    return [0.0, end / 2.0, end] if _moves(constraint, end) else [0.0]


def sky_figure(constraint: PointingConstraint, rows: Sequence[Any], frame: str) -> dict[str, Any]:
    """The constrained boresight on the celestial sphere for every simulated row, and the cone.

    Parameters
    ----------
    constraint : ocp.geometry.PointingConstraint
        The requirement's constraint.
    rows : sequence of Row
        The run's rows.
    frame : str
        The inertial frame's name (``Scenario.frame``), for the axes.

    Returns
    -------
    dict
        A plotly figure: right ascension (increasing to the left, as the sky is seen; the
        direction at the start in the middle, the ticks giving the true value) against declination
        [deg]; per row the closed loop's boresight (solid) and its reference's
        (dashed), hover giving the time; the cone's edge (red for a keep-out, green for a keep-in)
        at the start and, for a moving direction, at the middle and end of the run, and the
        direction's path.
    """
    data: list[dict[str, Any]] = []
    end = 0.0
    centre = float(radec(constraint.direction(0.0))[0][0])  # the direction in the map's middle
    for k, row in _simulated(rows):
        sim = row.simulation
        t = np.asarray(sim.t, dtype=float)
        end = max(end, float(t[-1]))
        colour = _ROW_COLOURS[k % len(_ROW_COLOURS)]
        tracks = [("", sim.q, "solid")]
        if row.reference is not None:
            tracks.append((" ref", row.reference.q(t), "dash"))
        for suffix, q, dash in tracks:
            index = _track_index(t, constraint.margins(t, q))
            ra, dec = radec(quat.rotate(q[index], constraint.boresight))
            x, y, when = _wrapped(ra, dec, t[index], centre)
            data.append({"type": "scatter", "mode": "lines", "name": row.label + suffix, "x": x, "y": y,
                         "customdata": when, "text": np.mod(x, 360.0), "legendgroup": row.label, "showlegend": not suffix,
                         "line": {"color": colour, "dash": dash, "width": 1.6},
                         "hovertemplate": "RA %{text:.2f} deg, Dec %{y:.2f} deg<br>t %{customdata:.1f} s"
                                          f"<extra>{row.label}{suffix}</extra>"})
            start = quat.rotate(q[0], constraint.boresight)[None, :]
            ra0, dec0 = _wrapped(*radec(start), centre=centre)
            data.append({"type": "scatter", "mode": "markers", "x": ra0, "y": dec0,
                         "legendgroup": row.label, "showlegend": False, "hoverinfo": "skip",
                         "marker": {"color": colour, "size": 7, "symbol": "circle-open" if suffix else "circle"}})
    colour = "#c00000" if constraint.keep_out else "#008000"
    kind = "keep-out" if constraint.keep_out else "keep-in"
    for j, moment in enumerate(_cone_times(constraint, end)):
        radius = float(constraint.limit(moment)[0])
        ra, dec = radec(_circle(constraint.direction(moment)[0], radius))
        x, y = _wrapped(ra, dec, centre=centre)
        data.append({"type": "scatter", "mode": "lines", "name": f"{kind} cone at {moment:.0f} s", "x": x, "y": y,
                     "line": {"color": colour, "width": 2, "dash": ["solid", "dash", "dot"][j]}, "hoverinfo": "skip"})
    moves = _moves(constraint, end)
    times = np.linspace(0.0, end, 200) if moves else np.zeros(1)
    ra, dec = radec(constraint.direction(times))
    x, y, when_list = _wrapped(ra, dec, times, centre)
    data.append({"type": "scatter", "mode": "lines+markers" if moves else "markers",
                 "name": f"direction ({constraint.description.split(' about ')[-1]})", "x": x, "y": y,
                 "customdata": when_list, "text": np.mod(x, 360.0), "marker": {"color": colour, "symbol": "x", "size": 6},
                 "line": {"color": colour, "width": 1},
                 "hovertemplate": "RA %{text:.2f} deg, Dec %{y:.2f} deg<br>t %{customdata:.1f} s<extra>direction</extra>"})
    ticks = np.arange(np.ceil((centre - 180.0) / 30.0) * 30.0, centre + 180.0 + 1e-9, 30.0)
    title, top = title_layout(f"{constraint.name}: {constraint.description}: boresight on the celestial sphere "
                              f"({frame})", 420)
    layout = {"title": title, "height": 420 + top, "margin": {"l": 70, "r": 30, "t": top, "b": 45},
              "hovermode": "closest",
              "xaxis": {"title": {"text": "right ascension (deg), increasing to the left"},
                        "range": [centre + 180.0, centre - 180.0], "tickvals": ticks,
                        "ticktext": [f"{v % 360:g}" for v in ticks]},
              "yaxis": {"title": {"text": "declination (deg)"}, "range": [-90, 90], "dtick": 30,
                        "scaleanchor": "x", "scaleratio": 1}}
    return {"data": data, "layout": layout}


def attitude_figure(row: Any, scenario: Any) -> dict[str, Any]:
    """The attitude of one simulated row in 3-D, with a time slider and play button.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A row with a ``simulation``.
    scenario : scenarios.schema.loader.Scenario
        The scenario (its sensors through ``requirements.pointing``, its pointing constraints and
        inertial frame).

    Returns
    -------
    dict
        A plotly figure with ``frames`` (at most :data:`FRAMES` times): in inertial axes, the body
        axes x, y, z (red, green, blue, unit length), each constrained sensor's boresight, each
        pointing direction and its cone's edge at that time, and, fixed, the boresights' tracks
        over the run.
    """
    sim = row.simulation
    t = np.asarray(sim.t, dtype=float)
    q = np.asarray(sim.q, dtype=float)
    steps = np.unique(np.round(np.linspace(0, t.size - 1, min(t.size, FRAMES))).astype(int))
    sensors: dict[str, np.ndarray] = {}
    for requirement in scenario.requirements.pointing:
        sensors.setdefault(requirement.sensor.name, requirement.sensor.boresight)
    constraints = list(scenario.problem.pointing)
    sensor_colours = dict(zip(sensors, _OTHER_COLOURS))

    rotations = dict(zip(steps.tolist(), quat.rotation_matrix(q[steps])))
    moves = {constraint.name: _moves(constraint, float(t[-1])) for constraint in constraints}

    def arrow(vector: np.ndarray, name: str, colour: str, width: float = 6, dash: str = "solid") -> dict[str, Any]:
        tip = np.asarray(vector, dtype=float)
        return {"type": "scatter3d", "mode": "lines+text", "name": name, "x": np.array([0.0, tip[0]]),
                "y": np.array([0.0, tip[1]]), "z": np.array([0.0, tip[2]]), "text": ["", name],
                "textposition": "top center", "line": {"color": colour, "width": width, "dash": dash},
                "hoverinfo": "name"}

    def pointing(constraint: PointingConstraint, when: float) -> list[dict[str, Any]]:
        direction = constraint.direction(when)[0]
        colour = "#c00000" if constraint.keep_out else "#008000"
        edge = _circle(direction, float(constraint.limit(when)[0]), 61)
        return [arrow(1.15 * direction, constraint.description.split(" about ")[-1], colour, 3, "dash"),
                {"type": "scatter3d", "mode": "lines", "name": f"{constraint.name} cone", "x": edge[:, 0],
                 "y": edge[:, 1], "z": edge[:, 2], "line": {"color": colour, "width": 3}, "hoverinfo": "name"}]

    def moving(k: int) -> list[dict[str, Any]]:
        rotation = rotations[k]
        traces = [arrow(rotation[:, i], f"body {axis}", AXIS_COLOURS[i]) for i, axis in enumerate("xyz")]
        traces += [arrow(rotation @ boresight, name, sensor_colours[name], 5) for name, boresight in sensors.items()]
        for constraint in constraints:
            if moves[constraint.name]:
                traces += pointing(constraint, float(t[k]))
        return traces

    data = moving(int(steps[0]))
    animated = list(range(len(data)))
    for constraint in constraints:
        if not moves[constraint.name]:  # drawn once
            data += pointing(constraint, 0.0)
    index = np.unique(np.round(np.linspace(0, t.size - 1, min(t.size, MAX_POINTS))).astype(int))
    for name, boresight in sensors.items():
        path = quat.rotate(q[index], boresight)
        data.append({"type": "scatter3d", "mode": "lines", "name": f"{name} track", "x": path[:, 0], "y": path[:, 1],
                     "z": path[:, 2], "customdata": t[index],
                     "line": {"color": sensor_colours[name], "width": 2, "dash": "dot"},
                     "hovertemplate": "t %{customdata:.1f} s<extra>" + name + " track</extra>"})
    for i, axis in enumerate("XYZ"):
        tip = np.eye(3)[i] * 1.3
        data.append({"type": "scatter3d", "mode": "lines+text", "name": f"inertial {axis}", "x": [0.0, tip[0]],
                     "y": [0.0, tip[1]], "z": [0.0, tip[2]], "text": ["", axis], "showlegend": i == 0,
                     "legendgroup": "inertial", "line": {"color": "#aaaaaa", "width": 2}, "hoverinfo": "skip"})
    coordinates = ("x", "y", "z")  # a frame changes only the coordinates of the moving traces
    frames = [{"name": f"{t[k]:.6g}", "data": [{c: trace[c] for c in coordinates} for trace in moving(int(k))],
               "traces": animated} for k in steps]
    immediate = {"mode": "immediate", "frame": {"duration": 0, "redraw": True}, "transition": {"duration": 0}}
    # the buttons left of the slider, level with its rail: never over its tick labels
    slider = {"active": 0, "currentvalue": {"prefix": "t = ", "suffix": " s"}, "pad": {"t": 10},
              "x": SLIDER_START, "len": 1.0 - SLIDER_START, "xanchor": "left", "y": 0.0, "yanchor": "top",
              "steps": [{"label": f"{t[k]:.4g}", "method": "animate", "args": [[f"{t[k]:.6g}"], immediate]}
                        for k in steps]}
    play = {"type": "buttons", "showactive": False, "x": SLIDER_START, "y": 0.0, "xanchor": "right", "yanchor": "top",
            "direction": "left", "pad": {"t": 40, "r": 10},
            "buttons": [{"label": "play", "method": "animate",
                         "args": [None, {"frame": {"duration": 80, "redraw": True}, "fromcurrent": True,
                                         "transition": {"duration": 0}}]},
                        {"label": "pause", "method": "animate", "args": [[None], immediate]}]}
    frame = scenario.frame
    span = [-1.35, 1.35]
    title, top = title_layout(f"{row.label}: attitude in the {frame} frame (body axes, boresights, "
                              "pointing directions and cones)", ATTITUDE_PX)
    title["y"] = 1.0 - MODEBAR_PX / ATTITUDE_PX  # the whole height is fixed
    layout = {"title": title, "height": ATTITUDE_PX, "margin": {"l": 10, "r": 10, "t": top, "b": SLIDER_PX},
              "scene": {"aspectmode": "cube", "xaxis": {"range": span, "title": {"text": "X"}},
                        "yaxis": {"range": span, "title": {"text": "Y"}},
                        "zaxis": {"range": span, "title": {"text": "Z"}}},
              "sliders": [slider], "updatemenus": [play], "uirevision": "keep"}
    return {"data": data, "layout": layout, "frames": frames}
