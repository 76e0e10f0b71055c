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

from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from scenarios.requirements.fields import field_info

DPI = 90
"""Resolution of every PNG [dots per inch]."""
ROW_WIDTH_IN = 10.0
"""Width of the per-row figure [in]."""
ROW_PANEL_IN = 2.34
"""Height of one panel of the per-row figure, its gap included [in]: the figure's height follows its panels."""
ROW_EDGES_IN = 0.65
"""Space above the top panel (the title) and below the bottom one (the time axis) [in]."""
ROW_MARGINS = {"left": 0.1, "right": 0.855, "hspace": 0.08}
"""``subplots_adjust`` of the per-row figure (fractions of the figure; top and bottom from
:func:`row_figure_layout`); the legends sit right of 0.855."""
OVERLAY_WIDTH_IN = 13.0
"""Width of the comparison figure [in]."""
OVERLAY_ROW_IN = 2.25
"""Height of one row of panels of the comparison figure, its gap included [in]."""
OVERLAY_EDGES_IN = (0.6, 0.55)
"""Space above the top panels (the title) and below the bottom ones (the time axis) [in]."""
OVERLAY_GAP_IN = 0.4
"""Vertical gap between two rows of panels of the comparison figure [in]."""
OVERLAY_TIME_IN = 0.35
"""Room for the time axis below the comparison figure's per-axis panels [in]."""
OVERLAY_MARGINS = {"left": 0.075, "right": 0.8, "wspace": 0.25}
"""Left and right edges of the comparison figure's panels (fractions of the figure; top and bottom from
:data:`OVERLAY_EDGES_IN`; the legend sits right of them), and the gap between the norm's and the
error's panels (a fraction of a panel's width: room for the error's value axis)."""
OVERLAY_AXES_WSPACE = 0.1
"""Gap between the comparison figure's per-axis panels (a fraction of a panel's width): they share one value axis."""
OVERLAY_WIDEST_PANEL = 0.5
"""The widest panel of the comparison figure (the norm's and the error's, half of it) as a fraction
of the panels' width: the curves are decimated to its pixel columns."""
MARGIN_WIDTH_IN = 11.0
"""Width of the pointing-margin figure [in]; its height is :data:`MARGIN_PANEL_IN` per requirement."""
MARGIN_PANEL_IN = 2.7
MARGIN_MARGINS = {"left": 0.09, "right": 0.7}
"""Left and right edges of the margin panels (fractions of the figure); the legends sit right of them."""
SKY_TRACK_POINTS = 2000
"""Most points of a boresight track on the sky map (a track is a curve on the sphere, not a time
series: it is thinned evenly in time, which keeps its shape at the map's resolution)."""
STILL_DEG = 0.05
"""A cone whose direction and angle change less than this over the run [deg] (the Sun's does over an
hour) is drawn once on the sky map, as a fixed one."""
CIRCLE_POINTS = 181
"""Points on a cone's boundary circle on the sky map."""
COLUMNS_PER_POINT = 2
"""Series longer than this many points per pixel column of the panel are decimated."""
FLOOR_DEG = 1e-9
"""Smallest angle drawn on the logarithmic error axes [deg] (an exact zero has no logarithm)."""
FLOOR_RATE = 1e-12
"""Smallest rate drawn on the logarithmic rate axes [rad/s]."""
RPM_PER_RAD_S = 60.0 / (2.0 * np.pi)
"""Revolutions per minute in one rad/s."""
DEG_PER_RAD = 180.0 / np.pi
"""Degrees in one radian: rates are drawn in deg/s."""
EULER_SEQUENCE = "321"
"""Default Euler sequence of the row figures: yaw about z, pitch about the new y, roll about the
newest x, from the inertial frame to the body (:func:`euler_angles`)."""


def row_figure_layout(n_panels: int) -> tuple[tuple[float, float], dict[str, float]]:
    """Size and margins of a per-row figure of ``n_panels`` panels.

    Parameters
    ----------
    n_panels : int
        Number of stacked panels.

    Returns
    -------
    figsize : (float, float)
        Width and height [in].
    margins : dict
        ``subplots_adjust`` arguments (fractions of the figure).
    """
    height = n_panels * ROW_PANEL_IN + 2 * ROW_EDGES_IN
    return (ROW_WIDTH_IN, height), {**ROW_MARGINS, "top": 1 - ROW_EDGES_IN / height, "bottom": ROW_EDGES_IN / height}


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
        last sample: the drawn envelope and every peak are those of the full series. NaN (a gap)
        is ignored in a bin that has numbers, and kept once from a bin that has none.
    """
    n = t.size
    if n <= COLUMNS_PER_POINT * max(columns, 1):
        return t, values
    size = -(-n // columns)  # samples per bin
    pad = size * columns - n
    key = values if values.ndim == 1 else values[:, 0]
    padded = np.concatenate([key, np.repeat(key[-1:], pad)]).reshape(columns, size)
    start = np.arange(columns) * size
    gaps = np.isnan(padded)  # NaN (a gap in the curve) is never an extreme; a bin of NaN only keeps one
    low = np.minimum(start + np.where(gaps, np.inf, padded).argmin(axis=1), n - 1)
    high = np.minimum(start + np.where(gaps, -np.inf, padded).argmax(axis=1), n - 1)
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


def continuous_quaternions(q: np.ndarray, like: np.ndarray | None = None) -> np.ndarray:
    """A quaternion series drawn without sign jumps: ``q`` and ``-q`` are the same attitude, and a
    series that switches between them (a solver, a canonical form ``q0 >= 0``) or a reference on
    the other sign from its closed loop looks like a failure in a plot.

    Parameters
    ----------
    q : (N, 4) ndarray
        Quaternions, scalar first, in time order.
    like : (N, 4) ndarray, optional
        A series on the same times to share a hemisphere with (the closed loop, for its reference).

    Returns
    -------
    (N, 4) ndarray
        The same attitudes, each ``+q_k`` or ``-q_k``: every sample after the first on the side of
        the one before (non-negative dot product), the whole series on the side of ``like`` (the sum
        of the samples' dot products with it non-negative) or, without ``like``, starting with a
        non-negative scalar part.
    """
    # the model's helper (ocp.quat.continuous), in the process that ran it (module docstring)
    from ocp import quat

    q = np.array(q, dtype=float)
    if len(q) == 0:
        return q
    q = quat.continuous(q)
    side = np.einsum("ij,ij->", q, like) if like is not None else q[0, 0]
    return -q if side < 0 else q


def euler_angles(q: np.ndarray, sequence: str = EULER_SEQUENCE) -> np.ndarray:
    """Euler angles of an attitude series, in degrees and unwrapped in time.

    The angles ``(α, β, γ)`` of the sequence ``a-b-c`` satisfy ``R(q) = R_a(α) R_b(β) R_c(γ)``
    (``R(q)`` body to inertial): from the inertial frame, a rotation about axis ``a``, then about
    the new ``b``, then about the newest ``c`` reach the body axes. For ``"321"`` they are yaw,
    pitch and roll.

    Parameters
    ----------
    q : (N, 4) ndarray
        Unit quaternions, scalar first, body to inertial, in time order (their signs do not matter).
    sequence : str, optional
        The rotation axes (:func:`ocp.quat.sequence_axes`); default :data:`EULER_SEQUENCE`.

    Returns
    -------
    (N, 3) ndarray
        The angles in the order of the sequence [deg]. The middle one lies in [-90, 90] (Tait-Bryan)
        or [0, 180] (proper); the outer ones start in (-180, 180] and are unwrapped (no jump of
        360°). At gimbal lock (middle angle ±90° or 0, 180°) only their sum or difference is defined.
    """
    # the model's helper (ocp.quat.to_euler), in the process that ran it (module docstring)
    from ocp import quat

    return np.rad2deg(np.unwrap(quat.to_euler(np.asarray(q, dtype=float), sequence), axis=0))


Curve = tuple[np.ndarray, np.ndarray]
"""A drawn curve: times [s] and values, decimated."""

RowShape = tuple[Any, ...]
"""What fixes a per-row figure's static part (:attr:`RowSeries.shape`): rows of one shape share a figure."""

LIMITED_PANELS = ("torque", "wheel_torque", "wheel_momentum", "wheel_speed", "dipole")
"""Panels of the per-row figure that can carry actuator limit lines (keys of :attr:`RowSeries.limits`)."""


def knowledge_series(sim: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """The attitude the controller was given at each sample and its error, with a star tracker in
    the loop (the attitude behind ``final_knowledge_error_deg`` and ``max_knowledge_error_deg``,
    :func:`ocp.metrics.metrics_from_simulation`).

    Parameters
    ----------
    sim : ocp.SimulationResult
        The closed-loop run (its ``sensors`` and ``sensor_state``).

    Returns
    -------
    (known, error) or None
        ``known`` (N+1, 4): the attitude given at ``t_0 … t_(N−1)`` (the MEKF's estimate, or the
        last star tracker reading; scalar first, body to inertial), NaN at the final time;
        ``error`` (N+1,): its angle from the true attitude [deg], NaN at the final time. ``None``
        without a star tracker.
    """
    from ocp import quat
    from ocp.metrics import _known_attitude

    given = _known_attitude(sim)
    if given is None:
        return None
    given = np.asarray(given, dtype=float)
    known = np.full((sim.t.size, 4), np.nan)
    known[:given.shape[0]] = given
    error = np.full(sim.t.size, np.nan)
    error[:given.shape[0]] = np.rad2deg(quat.error_angle(given, np.asarray(sim.q)[:given.shape[0]]))
    return known, error


@dataclass
class RowSeries:
    """The curves of one row's figure: body torque, rate, quaternion, Euler angles, error angles,
    and per actuator (wheel torque, momentum and speed; magnetorquer dipole) with their limits.

    Parameters
    ----------
    n_wheels : int
        Number of wheels, failed ones included (wheel torque and momentum panels when > 0).
    with_reference : bool
        The reference is drawn dashed and the error to it in orange.
    with_target : bool
        The error to the target attitude is drawn.
    title : str
        The figure's title.
    torque, rate : list of Curve
        Applied body torque [N m] (held) and body rate [deg/s], per body axis (x, y, z).
    quaternion : list of Curve
        Attitude, scalar first (body to inertial), without sign jumps
        (:func:`continuous_quaternions`).
    reference : tuple of lists of Curve, optional
        The reference's torque, rate, quaternion (on the closed loop's side) and Euler angles
        (``with_reference``).
    to_target, to_reference : Curve, optional
        Error angles [deg] to the target attitude and to the reference attitude.
    rate_norm, rate_max : Curve, optional
        ``‖ω‖`` and ``max |ω_i|`` [deg/s] (regulation without a target attitude).
    wheels : list of Curve
        Wheel momenta [N m s].
    failed : tuple of int, optional
        Indices of the failed wheels (drawn grey and dotted, marked in the legend).
    wheel_axis : tuple of int, optional
        Per wheel, the body axis (0, 1, 2) its spin axis lies along, or -1 (its colour follows).
    wheel_torque : list of Curve, optional
        Wheel motor torques [N m] (held), applied.
    wheel_speed : list of Curve, optional
        Wheel speeds [rpm] (``h_w / J_s``; only when the wheels' spin inertia is known).
    dipole : list of Curve, optional
        Magnetorquer dipole [A m^2] (held), applied, per body axis.
    limits : dict of str to tuple of float, optional
        Actuator limits drawn as ``±`` lines, per panel of :data:`LIMITED_PANELS`, one value per
        curve of the panel (NaN: none): the per-axis body torque the actuators can apply on all
        axes at once [N m], wheel torque [N m], momentum [N m s] and speed [rpm], dipole [A m^2].
    euler : list of Curve, optional
        Euler angles [deg] of ``euler_sequence`` (:func:`euler_angles`), in its order.
    euler_sequence : str, optional
        Their sequence (default :data:`EULER_SEQUENCE`).
    knowledge : Curve, optional
        The knowledge error [deg]: the angle of the attitude the controller was given from the
        true one (:func:`knowledge_series`), with a star tracker in the loop.
    torque_box_exact : bool, optional
        Whether the body-torque limit (``limits["torque"]``) is the whole set the actuators give
        (``Spacecraft.torque_box_is_exact``; default ``True``); else a conservative box inside it
        (a skewed wheel array: along one body axis the wheels give more), which the legend says.
    """

    n_wheels: int
    with_reference: bool
    with_target: bool
    title: str
    torque: list[Curve]
    rate: list[Curve]
    quaternion: list[Curve]
    reference: tuple[list[Curve], ...] | None = None
    to_target: Curve | None = None
    to_reference: Curve | None = None
    rate_norm: Curve | None = None
    rate_max: Curve | None = None
    wheels: list[Curve] = field(default_factory=list)
    failed: tuple[int, ...] = ()
    wheel_axis: tuple[int, ...] = ()
    wheel_torque: list[Curve] = field(default_factory=list)
    wheel_speed: list[Curve] = field(default_factory=list)
    dipole: list[Curve] = field(default_factory=list)
    limits: dict[str, tuple[float, ...]] = field(default_factory=dict)
    euler: list[Curve] = field(default_factory=list)
    euler_sequence: str = EULER_SEQUENCE
    knowledge: Curve | None = None
    torque_box_exact: bool = True

    @property
    def shape(self) -> RowShape:
        """``(n_wheels, with_reference, with_target, failed, wheel_axis, wheel speed panel, dipole
        panel, limit styles, Euler sequence, knowledge error)``, the arguments of
        :class:`scenarios.output.plots.RowFigure`: rows of one shape share a figure. A limit style
        is ``(panel, common)``: ``common`` when every limit of the panel is the same (one black pair
        of lines), else one pair per curve; the torque panel's is ``(panel, common, False)`` where
        its limit is a conservative box (:attr:`torque_box_exact`)."""
        styles = tuple((panel, _common(values)) if panel != "torque" or self.torque_box_exact
                       else (panel, _common(values), False)
                       for panel, values in self.limits.items() if np.any(np.isfinite(values)))
        return (self.n_wheels, self.with_reference, self.with_target, tuple(self.failed), tuple(self.wheel_axis),
                bool(self.wheel_speed), bool(self.dipole), styles, self.euler_sequence, self.knowledge is not None)


def _common(values: tuple[float, ...]) -> bool:
    """Whether the finite limits of a panel are all equal."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    return bool(finite.size and np.all(np.abs(finite - finite[0]) <= 1e-12 * np.abs(finite[0])))


def _limits(values: Any, keep: Any = True) -> tuple[float, ...]:
    """Finite limits as floats (zero included: an axis no actuator reaches), NaN for unlimited or
    dropped (``keep`` False) entries."""
    values = np.asarray(values, dtype=float)
    usable = np.isfinite(values) & (values >= 0) & np.asarray(keep, dtype=bool)
    return tuple(float(v) for v in np.where(usable, values, np.nan))


WHEELS_TORQUE_NOTE = " (solid only; wheels bound Iω̇+ω×H)"
"""Appended to the body-torque limit's label with wheels (:func:`torque_limit_label`)."""


def torque_limit_label(label: str, wheels: bool) -> str:
    """The legend label of the body-torque panel's limit lines, shared by the run figures.

    The lines are the per-axis box of the actuators' torque on the body (``−A g`` of the wheels
    plus the torquers'; ``Spacecraft.body_torque_limit``), the solid curves. The dashed reference
    is the rigid body's ``I ω̇ + ω × I ω`` (:class:`planners.Reference`); wheels give
    ``I ω̇ + ω × H``, ``H`` with the wheels' momentum, so with wheels the reference may cross the
    lines while every wheel is within its own limit (three body-axis wheels, a non-principal
    inertia, a minimum-time eigenaxis slew from rest: the reference 1.14 x the line, the wheels
    at 1.00). Without wheels the two are the same torque and the lines bound both.

    Parameters
    ----------
    label : str
        The label without the note, e.g. ``"limit ±0.05 N m"``.
    wheels : bool
        Whether the spacecraft has reaction wheels (failed ones included: their momentum is in ``H``).

    Returns
    -------
    str
        ``label``, with :data:`WHEELS_TORQUE_NOTE` when ``wheels``.
    """
    return label + WHEELS_TORQUE_NOTE if wheels else label


def wheel_axes(axes: np.ndarray) -> tuple[int, ...]:
    """The body axis each wheel spins about, when it lies along one.

    Parameters
    ----------
    axes : (3, n) ndarray
        Unit spin axes, body frame.

    Returns
    -------
    tuple of int
        Per wheel, 0, 1 or 2 when its axis is ``±x``, ``±y`` or ``±z`` (within 1e-9), else -1.
    """
    return tuple(int(np.argmax(np.abs(a))) if np.max(np.abs(a)) > 1 - 1e-9 else -1 for a in np.asarray(axes).T)


def row_series(row: Any, target_q: Any, spacecraft: Any, euler_sequence: str = EULER_SEQUENCE,
               target_omega: Any = None) -> RowSeries:
    """The curves of a simulated row, decimated to the per-row figure's panels.

    Parameters
    ----------
    row : scenarios.output.results.Row
        A row with a simulation (and a reference unless regulating).
    target_q : (4,) array_like or None
        Target attitude (scalar-first quaternion, body to inertial) for the error angle.
    spacecraft : ocp.Spacecraft
        The simulated spacecraft: its actuators fix the actuator panels and their limit lines.
    euler_sequence : str, optional
        The Euler angles' sequence (:func:`euler_angles`); default :data:`EULER_SEQUENCE`.
    target_omega : (3,) array_like or None, optional
        The manoeuvre's final body rate [rad/s]: where it is not zero the error to the target is
        measured, after ``T``, to where the target has turned (:func:`ocp.metrics.target_motion`,
        as the metrics do).

    Returns
    -------
    RowSeries
        What :class:`scenarios.output.plots.RowFigure` draws.
    """
    # the model's helpers, in the process that ran it (module docstring)
    from ocp import quat, target_motion
    from ocp.dynamics.layout import control_layout

    sim = row.simulation
    t = sim.t
    columns = panel_columns(ROW_WIDTH_IN, ROW_MARGINS)

    def curve(values: np.ndarray) -> Curve:
        return decimate(t, values, columns)

    def held_curves(values: np.ndarray) -> list[Curve]:
        return [curve(held(values[:, i])) for i in range(values.shape[1])]

    n_wheels = spacecraft.n_wheels
    with_reference, with_target = row.reference is not None, target_q is not None
    controller = f", {row.controller}" if getattr(row, "controller", None) else ""
    q = continuous_quaternions(sim.q)
    series = RowSeries(
        n_wheels, with_reference, with_target,
        f"{row.label} ({row.planner or 'regulation'}{controller}): "
        + ("solid closed loop, dashed reference" if with_reference else "closed loop"),
        held_curves(sim.applied_torque), [curve(DEG_PER_RAD * sim.omega[:, i]) for i in range(3)],
        [curve(q[:, i]) for i in range(4)], wheels=[curve(sim.wheel_momentum[:, i]) for i in range(n_wheels)],
        euler_sequence=euler_sequence)
    euler = euler_angles(q, euler_sequence)
    series.euler = [curve(euler[:, i]) for i in range(3)]
    slices, _ = control_layout(spacecraft)
    wheels, magnetorquers = spacecraft.wheels, spacecraft.magnetorquers
    if magnetorquers is None and (wheels is not None or spacecraft.torquers is not None):
        # the largest per-axis box the allocation realises at every corner (Spacecraft.body_torque_limit):
        # the whole realised set for wheels along the body axes or torquers, a conservative box inside it
        # for a skewed wheel array (Spacecraft.torque_box_is_exact); magnetorquers' torque depends on the field.
        # It bounds the solid applied torque; with wheels not the dashed reference (torque_limit_label).
        series.limits["torque"] = _limits(spacecraft.body_torque_limit())
        series.torque_box_exact = spacecraft.torque_box_is_exact()
    if wheels is not None:
        series.failed, series.wheel_axis = tuple(wheels.failed), wheel_axes(wheels.axes)
        series.wheel_torque = held_curves(sim.applied_u[:, slices["wheels"]])
        series.limits["wheel_torque"] = _limits(wheels.max_torque, wheels.working)
        series.limits["wheel_momentum"] = _limits(wheels.max_momentum, wheels.working)
        if wheels.spin_inertia is not None:
            speed = sim.wheel_momentum / wheels.spin_inertia * RPM_PER_RAD_S
            series.wheel_speed = [curve(speed[:, i]) for i in range(n_wheels)]
            series.limits["wheel_speed"] = _limits(wheels.max_momentum / wheels.spin_inertia * RPM_PER_RAD_S,
                                                   wheels.working)
    if magnetorquers is not None:
        series.dipole = held_curves(sim.applied_u[:, slices["dipole"]])
        series.limits["dipole"] = _limits(magnetorquers.max_dipole)
    if with_reference:
        ref = row.reference.sample(t)
        ref_q = continuous_quaternions(ref.q, like=q)
        ref_euler = euler_angles(ref_q, euler_sequence)
        ref_euler += 360.0 * np.round((euler[0] - ref_euler[0]) / 360.0)  # the same turn as the closed loop
        series.reference = tuple([curve(values[:, i]) for i in range(values.shape[1])]
                                 for values in (ref.torque, DEG_PER_RAD * ref.omega, ref_q, ref_euler))
        series.to_reference = curve(np.maximum(np.rad2deg(quat.error_angle(sim.q, ref.q)), FLOOR_DEG))
    if with_target:
        targets = target_motion(target_q, target_omega, row.reference, t)[0]
        assert targets is not None  # with_target
        series.to_target = curve(np.maximum(np.rad2deg(quat.error_angle(sim.q, targets)), FLOOR_DEG))
    if not with_reference and not with_target:  # rate regulation (detumbling): the rate converges
        series.rate_norm = curve(DEG_PER_RAD * np.maximum(np.linalg.norm(sim.omega, axis=1), FLOOR_RATE))
        series.rate_max = curve(DEG_PER_RAD * np.maximum(np.abs(sim.omega).max(axis=1), FLOOR_RATE))
    knowledge = knowledge_series(sim)
    if knowledge is not None:
        given = np.isfinite(knowledge[1])
        series.knowledge = decimate(t[given], np.maximum(knowledge[1][given], FLOOR_DEG), columns)
    return series


@dataclass
class OverlaySeries:
    """The comparison figure: every row's curves overlaid, per body axis (rate, wheels' momentum)
    and in norm (torque, error).

    Parameters
    ----------
    title : str
        The figure's title.
    error_label : str
        The error panel's y label (what the error is, with its unit).
    labels : list of str
        Row labels, in the rows' order.
    torque : list of Curve
        ``‖u‖`` [N m] (held) per row.
    error : list of Curve
        Error to the target per row: angle [deg] to the target attitude, or rate error [deg/s]
        when the attitude is free.
    rate : list of list of Curve, optional
        Per row, the body rate [deg/s] per body axis (x, y, z); empty: no per-axis panels.
    wheel_momentum : list of list of Curve, optional
        Per row, the wheels' momentum in body axes, ``A h_w`` [N m s], per axis; empty lists
        without wheels.
    finals : list of str, optional
        Per row, its final values in words (the legend gives them, so that rows whose curves lie
        on one another are told apart).
    statuses : list of str, optional
        Per row, its status (``ok``, ``violated``, ``failed``; :class:`scenarios.output.results.Row`).
    breaches : list of str, optional
        Per row, what it breaks in words (:func:`breach_text`; empty when nothing is recorded).
    """

    title: str
    error_label: str
    labels: list[str]
    torque: list[Curve]
    error: list[Curve]
    rate: list[list[Curve]] = field(default_factory=list)
    wheel_momentum: list[list[Curve]] = field(default_factory=list)
    finals: list[str] = field(default_factory=list)
    statuses: list[str] = field(default_factory=list)
    breaches: list[str] = field(default_factory=list)


def breach_text(row: Any) -> str:
    """What a row breaks, from its requirement records: each pointing requirement the reference or
    the closed loop spends time in violation of, and that time.

    Parameters
    ----------
    row : scenarios.output.results.Row
        The row (its ``requirements``).

    Returns
    -------
    str
        For example ``"st_sun violated ref 16.9 s, cl 24.1 s"``, several joined by ``"; "``;
        empty when no pointing violation is recorded (the row's message says the rest).
    """
    found: dict[str, list[str]] = {}
    for scope, records in (getattr(row, "requirements", None) or {}).items():
        for name, record in (records or {}).items():
            inside = record.get("time_in_violation_s") if isinstance(record, dict) else None
            margin = record.get("min_margin_deg") if isinstance(record, dict) else None
            if inside is not None and margin is not None and margin < 0:
                found.setdefault(name, []).append(f"{'cl' if scope == 'closed_loop' else 'ref'} {inside:.3g} s")
    return "; ".join(f"{name} violated {', '.join(times)}" for name, times in found.items())


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
    from ocp import quat, target_motion

    problem = results.scenario.problem
    target_q, target_omega = problem.qf, problem.omegaf
    wheels = problem.spacecraft.wheels
    columns = panel_columns(OVERLAY_WIDTH_IN * OVERLAY_WIDEST_PANEL, OVERLAY_MARGINS)
    error_label, unit = (("error to target (deg)", "deg") if target_q is not None
                         else ("‖ω − ω_f‖ (deg/s)", "deg/s") if target_omega is not None
                         else ("‖ω‖ (deg/s)", "deg/s"))
    series = OverlaySeries(f"{results.scenario.name}: closed-loop comparison", error_label, [], [], [])
    for row in results.rows:
        if row.simulation is None:
            continue
        sim = row.simulation
        targets, target_rates = target_motion(target_q, target_omega, row.reference, sim.t)  # as the metrics
        if targets is not None:
            error = np.rad2deg(quat.error_angle(sim.q, targets))
        elif target_rates is not None:
            error = DEG_PER_RAD * np.linalg.norm(sim.omega - target_rates, axis=1)
        else:
            error = DEG_PER_RAD * np.linalg.norm(sim.omega, axis=1)

        def curve(values: np.ndarray, t: np.ndarray = sim.t) -> Curve:
            return decimate(t, values, columns)

        series.labels.append(row.label)
        status = getattr(row, "status", "ok")
        series.statuses.append(status)
        series.breaches.append(breach_text(row) if status != "ok" else "")
        series.torque.append(curve(held(np.linalg.norm(sim.applied_torque, axis=1))))
        series.error.append(curve(np.maximum(error, FLOOR_DEG)))
        series.rate.append([curve(DEG_PER_RAD * sim.omega[:, i]) for i in range(3)])
        finals = [f"final {error[-1]:.3g} {unit}"]
        if wheels is not None and sim.wheel_momentum.shape[1]:
            body = sim.wheel_momentum @ np.asarray(wheels.axes, dtype=float).T
            series.wheel_momentum.append([curve(body[:, i]) for i in range(3)])
            finals.append(f"‖A h_w‖ {np.linalg.norm(body[-1]):.3g} N m s")
        else:
            series.wheel_momentum.append([])
        series.finals.append(", ".join(finals))
    return series


def _vector_text(v: Any) -> str:
    """A short ``[1, 0, 0]`` form of a vector (three significant digits)."""
    return "[" + ", ".join(f"{float(x):.3g}" for x in np.asarray(v, dtype=float).ravel()) + "]"


def sensor_text(boresight: Any) -> str:
    """How a sensor is named in the figures: its body boresight.

    Parameters
    ----------
    boresight : (3,) array_like
        Unit boresight, body axes.

    Returns
    -------
    str
        ``"boresight [1, 0, 0] (body)"``.
    """
    return f"boresight {_vector_text(boresight)} (body)"


def requirement_text(constraint: Any) -> str:
    """A pointing requirement in words: its name, what it asks (sensor, kind, angle, direction), the
    boresight, and the window when it is not the whole run.

    Parameters
    ----------
    constraint : ocp.geometry.PointingConstraint
        The requirement. Its ``description`` says what it asks (the scenario's requirements give
        ``"star_tracker keep-out 30 deg about sun"``); without one, the kind, angle and direction
        are written here.

    Returns
    -------
    str
        For example ``"st_sun: star_tracker keep-out 30 deg about sun; boresight [1, 0, 0] (body)"``;
        a cone that grows (the Earth's limb) says so.
    """
    what = constraint.description or (
        f"{'keep-out' if constraint.keep_out else 'keep-in'} {np.rad2deg(constraint.angle):.4g} deg about "
        + (f"inertial {_vector_text(constraint.directions[0])}" if not constraint.moving else "a moving direction"))
    grows = " (+ the Earth's apparent radius)" if np.any(np.asarray(constraint.growth) > 0) else ""
    start, end = constraint.window
    window = f", {start:g}-{end:g} s" if start > 0 or np.isfinite(end) else ""
    return f"{constraint.name}: {what}{grows}; {sensor_text(constraint.boresight)}{window}"


def pointing_constraints(results: Any) -> list[Any]:
    """The pointing requirements a run's figures show.

    The scenario's (``results.scenario.problem.pointing``), then cones a planner imposed from its
    own options (a reference's ``stats["cones"]``: ``(boresight, direction, angle [rad],
    keep_out)``) that none of those already is (same kind, boresight and fixed direction), named
    after the row and the option (``"keep-out: keep_out[0] option"``).

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.

    Returns
    -------
    list of ocp.geometry.PointingConstraint
    """
    from ocp.geometry import PointingConstraint

    constraints = list(results.scenario.problem.pointing)

    def known(boresight: np.ndarray, direction: np.ndarray, keep_out: bool) -> bool:
        return any(c.keep_out == keep_out and not c.moving and np.allclose(c.boresight, boresight, atol=1e-9)
                   and np.allclose(c.directions[0], direction, atol=1e-9) for c in constraints)

    for row in results.rows:
        reference = row.reference
        if reference is None or not getattr(reference, "ok", False):
            continue
        counts = {True: 0, False: 0}
        for boresight, direction, angle, keep_out in reference.stats.get("cones", []):
            keep_out = bool(keep_out)
            option = f"{'keep_out' if keep_out else 'keep_in'}[{counts[keep_out]}]"
            counts[keep_out] += 1
            boresight = np.asarray(boresight, dtype=float) / np.linalg.norm(boresight)
            direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
            if not known(boresight, direction, keep_out):
                constraints.append(PointingConstraint(f"{row.label}: {option} option", boresight, keep_out,
                                                      float(angle), directions=direction[None, :]))
    return constraints


class Motion(NamedTuple):
    """A row's attitude along the run, as the pointing figures sample it.

    Attributes
    ----------
    label : str
        The row's label.
    reference, closed_loop : (t (N,), q (N, 4)) or None
        Times [s] and attitudes (scalar first, body to inertial) of the reference and of the
        closed loop; ``None`` where the row has none.
    """

    label: str
    reference: tuple[np.ndarray, np.ndarray] | None
    closed_loop: tuple[np.ndarray, np.ndarray] | None


REFERENCE_SAMPLES = 2001
"""Samples of a reference that has no closed loop to share its times with."""


def motions(results: Any) -> list[Motion]:
    """Every row's reference and closed loop, sampled: a row with a simulation on its times (the
    reference too), a row with only a reference on :data:`REFERENCE_SAMPLES` times over its duration.
    Rows with neither (a failed planner) are left out.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.

    Returns
    -------
    list of Motion
    """
    found = []
    for row in results.rows:
        reference = row.reference if row.reference is not None and getattr(row.reference, "ok", False) else None
        sim = row.simulation
        if sim is None and reference is None:
            continue
        t = np.asarray(sim.t) if sim is not None else np.linspace(0.0, row.reference.duration, REFERENCE_SAMPLES)
        found.append(Motion(row.label, (t, reference.q(t)) if reference is not None else None,
                            (t, np.asarray(sim.q)) if sim is not None else None))
    return found


@dataclass
class MarginPanel:
    """One pointing requirement's margin against time, every row.

    Parameters
    ----------
    title : str
        The requirement, its sensor and its direction (:func:`requirement_text`).
    window : (float, float)
        The requirement's window [s].
    reference, closed_loop : list of Curve or None
        Per row (in :attr:`MarginSeries.labels` order), the margin [deg] (``angle − limit`` for a
        keep-out, ``limit − angle`` for a keep-in; negative when violated, NaN outside the window).
    worst_reference, worst_closed_loop : list of float or None
        Per row, the smallest margin [deg]: the scored one (the row's requirement record,
        ``min_margin_deg``, the value the results table gives: the scoring evaluates the margin
        between the samples too) when the row has it, else the smallest over the drawn samples.
    lowest_reference, lowest_closed_loop : list of (float, float) or None
        Per row, where that smallest margin lies: its time [s] and the margin [deg] (the scored
        ``min_margin_time_s`` and ``min_margin_deg``, else the lowest sample). The scored point is
        also a point of the row's curve (inserted at its time), so that a dip the samples miss, a
        violation between two samples, is drawn.
    scored_reference, scored_closed_loop : list of bool
        Per row, whether the minimum is the scored one (``False``: the samples' own).
    """

    title: str
    window: tuple[float, float]
    reference: list[Curve | None]
    closed_loop: list[Curve | None]
    worst_reference: list[float | None]
    worst_closed_loop: list[float | None]
    lowest_reference: list[tuple[float, float] | None] = field(default_factory=list)
    lowest_closed_loop: list[tuple[float, float] | None] = field(default_factory=list)
    scored_reference: list[bool] = field(default_factory=list)
    scored_closed_loop: list[bool] = field(default_factory=list)


@dataclass
class MarginSeries:
    """The margin of every pointing requirement against time, one panel per requirement.

    Parameters
    ----------
    title : str
        The figure's title.
    labels : list of str
        The rows (their colours are shared with the sky map).
    end : float
        The end of the time axis [s].
    panels : list of MarginPanel
        One per requirement.
    """

    title: str
    labels: list[str]
    end: float
    panels: list[MarginPanel]


def _worst(margin: np.ndarray) -> float | None:
    return float(np.nanmin(margin)) if np.any(np.isfinite(margin)) else None


def scored_minimum(row: Any, scope: str, name: str) -> tuple[float, float | None] | None:
    """A row's scored minimum margin of a pointing requirement: the value of its results table.

    Parameters
    ----------
    row : scenarios.output.results.Row
        The row (its ``requirements``: scores by scope, requirement name and field,
        :mod:`scenarios.requirements.scoring`).
    scope : str
        ``"reference"`` or ``"closed_loop"``.
    name : str
        The requirement's name.

    Returns
    -------
    (float, float or None) or None
        ``min_margin_deg`` [deg] and ``min_margin_time_s`` [s] (``None`` when not recorded);
        ``None`` when the row has no finite scored minimum for it.
    """
    records = getattr(row, "requirements", None) or {}
    record = (records.get(scope) or {}).get(name) or {}
    margin, when = record.get("min_margin_deg"), record.get("min_margin_time_s")
    if margin is None or not np.isfinite(margin):
        return None
    return float(margin), (float(when) if when is not None and np.isfinite(when) else None)


def with_point(curve: Curve, when: float, value: float) -> Curve:
    """A curve with one more point, at its time (a point already at that time is replaced).

    Parameters
    ----------
    curve : Curve
        Increasing times [s] (NaN at a gap) and values.
    when, value : float
        The point.

    Returns
    -------
    Curve
        The times and values with the point in time order.
    """
    t, values = curve
    ordered = np.maximum.accumulate(np.where(np.isnan(t), -np.inf, t))  # a gap (NaN) sorts with the time before it
    at = int(np.searchsorted(ordered, when))
    if at < t.size and t[at] == when:
        values = values.copy()
        values[at] = value
        return t, values
    return np.insert(t, at, when), np.insert(values, at, value)


def margin_series(results: Any, constraints: list[Any] | None = None, sampled: list[Motion] | None = None) -> MarginSeries:
    """The pointing-margin figure's curves.

    Each curve is the margin at the row's samples; where the row's requirement record gives the
    scored minimum (:func:`scored_minimum`, evaluated by the scoring between the samples too) and
    its time, that point is put into the curve and is the minimum the legend gives, so that the
    figure shows the table's number, and a violation between two samples.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.
    constraints : list of ocp.geometry.PointingConstraint, optional
        The requirements; ``None``: :func:`pointing_constraints` of ``results``.
    sampled : list of Motion, optional
        The rows' motions; ``None``: :func:`motions` of ``results``.

    Returns
    -------
    MarginSeries
        What :func:`scenarios.output.plots.draw_margins` draws.
    """
    constraints = pointing_constraints(results) if constraints is None else constraints
    rows = motions(results) if sampled is None else sampled
    by_label = {row.label: row for row in results.rows}
    columns = panel_columns(MARGIN_WIDTH_IN, MARGIN_MARGINS)
    ends = [float(m[0][-1]) for motion in rows for m in (motion.reference, motion.closed_loop) if m is not None]
    end = max(ends) if ends else float(results.scenario.problem.duration)  # the run, not a duration bound
    panels = []
    for constraint in constraints:
        panel = MarginPanel(requirement_text(constraint), constraint.window, [], [], [], [])
        for motion in rows:
            row = by_label.get(motion.label)
            for scope, curves, worst, lowest, scored, attitude in (
                    ("reference", panel.reference, panel.worst_reference, panel.lowest_reference,
                     panel.scored_reference, motion.reference),
                    ("closed_loop", panel.closed_loop, panel.worst_closed_loop, panel.lowest_closed_loop,
                     panel.scored_closed_loop, motion.closed_loop)):
                if attitude is None:
                    curves.append(None)
                    worst.append(None)
                    lowest.append(None)
                    scored.append(False)
                    continue
                margin = np.rad2deg(constraint.margins(*attitude))
                curve = decimate(attitude[0], margin, columns)
                record = scored_minimum(row, scope, constraint.name) if row is not None else None
                point: tuple[float, float] | None = None
                if record is not None and record[1] is not None:
                    point = (record[1], record[0])
                    curve = with_point(curve, *point)
                elif record is None and np.any(np.isfinite(margin)):
                    at = int(np.nanargmin(margin))
                    point = (float(attitude[0][at]), float(margin[at]))
                curves.append(curve)
                worst.append(record[0] if record is not None else _worst(margin))
                lowest.append(point)
                scored.append(record is not None)
        panels.append(panel)
    return MarginSeries(f"{results.scenario.name}: pointing margins (negative: violated); solid closed loop, "
                        "dashed reference", [motion.label for motion in rows], end, panels)


SkyPath = tuple[np.ndarray, np.ndarray]
"""A path on the sky: right ascension in [0, 360) and declination [deg], NaN where the map's
longitude wraps (:func:`sky_path`)."""


def map_longitude(ra_deg: np.ndarray) -> np.ndarray:
    """Where a right ascension lies on the full-sky map: the map is centred on RA 0 and, as a
    star chart seen from inside the sphere, RA grows to the left.

    Parameters
    ----------
    ra_deg : ndarray
        Right ascension [deg].

    Returns
    -------
    ndarray
        Map longitude in (-180, 180] [deg], ``-RA`` wrapped.
    """
    return -(((np.asarray(ra_deg, dtype=float) + 180.0) % 360.0) - 180.0)


def sky_path(vectors: np.ndarray) -> SkyPath:
    """Right ascension and declination of inertial directions, broken where the map wraps.

    Parameters
    ----------
    vectors : (N, 3) ndarray
        Directions, inertial frame (need not be unit).

    Returns
    -------
    SkyPath
        RA in [0, 360) and Dec in [-90, 90] [deg]; a NaN pair is inserted between two points
        whose map longitudes (:func:`map_longitude`) lie more than 180° apart, so that a drawn
        path does not cross the whole map.
    """
    v = np.asarray(vectors, dtype=float)
    v = v / np.linalg.norm(v, axis=1, keepdims=True)
    ra = np.rad2deg(np.arctan2(v[:, 1], v[:, 0])) % 360.0
    dec = np.rad2deg(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    breaks = np.flatnonzero(np.abs(np.diff(map_longitude(ra))) > 180.0) + 1
    return np.insert(ra, breaks, np.nan), np.insert(dec, breaks, np.nan)


def cone_circle(direction: np.ndarray, angle: float, points: int = CIRCLE_POINTS) -> np.ndarray:
    """The directions at ``angle`` from ``direction``: a cone's boundary on the sphere.

    Parameters
    ----------
    direction : (3,) ndarray
        The cone's axis (unit), inertial frame.
    angle : float
        Half-angle [rad].
    points : int, optional
        Points on the circle (the first repeated as the last).

    Returns
    -------
    (points, 3) ndarray
        Unit vectors, inertial frame.
    """
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    helper = np.eye(3)[int(np.argmin(np.abs(d)))]
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    phi = np.linspace(0.0, 2.0 * np.pi, points)[:, None]
    return np.cos(angle) * d + np.sin(angle) * (np.cos(phi) * e1 + np.sin(phi) * e2)


@dataclass
class SkyCone:
    """A pointing requirement's cone on the sky map.

    Parameters
    ----------
    label : str
        The requirement's name.
    keep_out : bool
        Keep-out (drawn red) or keep-in (green).
    boundaries : list of SkyPath
        The cone's boundary (its limit, the Earth's radius included) at the start of the run (or
        of its window) and, when the direction or the limit moves more than :data:`STILL_DEG`, at
        its end.
    centre : SkyPath
        The direction over the run (one point when it does not move).
    discs : list of SkyPath
        The Earth's disc (radius: the cone's growth) at the start and end, when the cone grows.
    """

    label: str
    keep_out: bool
    boundaries: list[SkyPath]
    centre: SkyPath
    discs: list[SkyPath]


@dataclass
class SkyPanel:
    """One sensor's boresight on the sky, every row, with the cones of its requirements.

    Parameters
    ----------
    title : str
        The sensor (:func:`sensor_text`) and the names of its requirements.
    reference, closed_loop : list of SkyPath or None
        Per row, the boresight's inertial direction along the reference and the closed loop.
    cones : list of SkyCone
        The requirements on this sensor.
    """

    title: str
    reference: list[SkyPath | None]
    closed_loop: list[SkyPath | None]
    cones: list[SkyCone]


@dataclass
class SkySeries:
    """The boresights of every sensor with a pointing requirement on a full-sky map.

    Parameters
    ----------
    title : str
        The figure's title.
    labels : list of str
        The rows (colours shared with the margin figure).
    panels : list of SkyPanel
        One per sensor (boresight).
    """

    title: str
    labels: list[str]
    panels: list[SkyPanel]


def _thinned(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At most :data:`SKY_TRACK_POINTS` samples, evenly in index, the last kept."""
    step = -(-len(t) // SKY_TRACK_POINTS)
    keep = np.unique(np.append(np.arange(0, len(t), step), len(t) - 1))
    return t[keep], q[keep]


def sky_series(results: Any, constraints: list[Any] | None = None, sampled: list[Motion] | None = None) -> SkySeries:
    """The sky map's paths: per sensor, each row's boresight track and the requirements' cones.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.
    constraints : list of ocp.geometry.PointingConstraint, optional
        The requirements; ``None``: :func:`pointing_constraints` of ``results``.
    sampled : list of Motion, optional
        The rows' motions; ``None``: :func:`motions` of ``results``.

    Returns
    -------
    SkySeries
        What :func:`scenarios.output.plots.draw_sky` draws.
    """
    from ocp import quat

    constraints = pointing_constraints(results) if constraints is None else constraints
    rows = motions(results) if sampled is None else sampled
    end = max([results.scenario.problem.duration]
              + [float(m[0][-1]) for motion in rows for m in (motion.reference, motion.closed_loop) if m is not None])
    sensors: dict[tuple[float, ...], list[Any]] = {}
    for constraint in constraints:
        sensors.setdefault(tuple(np.round(constraint.boresight, 9)), []).append(constraint)
    thinned = [tuple(None if m is None else _thinned(*m) for m in (motion.reference, motion.closed_loop))
               for motion in rows]
    panels = []
    for boresight, group in sensors.items():
        panel = SkyPanel(f"{sensor_text(boresight)}: {', '.join(c.name for c in group)}", [], [], [])
        for reference, closed_loop in thinned:
            for paths, attitude in ((panel.reference, reference), (panel.closed_loop, closed_loop)):
                paths.append(None if attitude is None else sky_path(quat.rotate(attitude[1], np.asarray(boresight))))
        for constraint in group:
            start, stop = max(constraint.window[0], 0.0), min(constraint.window[1], end)
            times = np.linspace(start, stop, 200)
            path, limits = constraint.direction(times), constraint.limit(times)
            moves = (np.rad2deg(np.arccos(np.clip(path @ path[0], -1.0, 1.0))).max() > STILL_DEG
                     or np.rad2deg(np.ptp(limits)) > STILL_DEG)
            keep = [0, len(times) - 1] if moves else [0]
            directions, limits = path[keep], limits[keep]
            growth = limits - constraint.angle
            centre = path if moves else directions
            panel.cones.append(SkyCone(
                constraint.name, constraint.keep_out,
                [sky_path(cone_circle(d, a)) for d, a in zip(directions, limits)], sky_path(centre),
                [sky_path(cone_circle(d, g)) for d, g in zip(directions, growth) if g > 0]))
        panels.append(panel)
    return SkySeries(f"{results.scenario.name}: sensor boresights on the sky (inertial frame); solid closed loop, "
                     "dashed reference", [motion.label for motion in rows], panels)


PlotJob = tuple[str, "RowSeries | OverlaySeries | MarginSeries | SkySeries"]
"""A figure to draw: its file name in the output directory and its series."""

MARGINS_FILE = "margins.png"
"""The pointing-margin figure of a run with pointing requirements."""
SKY_FILE = "sky.png"
"""The sky map of a run with pointing requirements."""
COMPARISON_FILE = "comparison.png"
"""The rows overlaid (:class:`OverlaySeries`)."""


def _euler_sequence(results_or_scenario: Any, euler_sequence: str | None) -> str:
    """The row figures' Euler sequence as digits ("321"): ``euler_sequence``, else the scenario's."""
    from ocp import quat

    if euler_sequence is None:
        scenario = getattr(results_or_scenario, "scenario", results_or_scenario)
        euler_sequence = getattr(scenario, "euler_sequence", EULER_SEQUENCE)
    # a bad sequence fails before any series is computed; "zyx" is drawn as "321"
    return "".join(str(axis + 1) for axis in quat.sequence_axes(euler_sequence))


def row_job(row: Any, stem: str, scenario: Any, euler_sequence: str | None = None) -> PlotJob | None:
    """A simulated row's figure, as in :func:`plot_jobs`: what a run sends its plot process as soon
    as the row is done (:meth:`scenarios.output.renderer.Renderer.stream`).

    Parameters
    ----------
    row : scenarios.output.results.Row
        A finished row.
    stem : str
        Its file stem (:func:`scenarios.output.names.row_stems` of the run's labels).
    scenario : scenarios.schema.loader.Scenario
        The run's scenario (its target attitude, spacecraft and ``plots.euler_sequence``).
    euler_sequence : str, optional
        As in :func:`plot_jobs`.

    Returns
    -------
    (str, RowSeries) or None
        ``<stem>.png`` and the row's series; ``None`` for a row without a simulation (no figure).
    """
    if row.simulation is None:
        return None
    problem = scenario.problem
    return f"{stem}.png", row_series(row, problem.qf, problem.spacecraft, _euler_sequence(scenario, euler_sequence),
                                        problem.omegaf)


def plot_jobs(results: Any, stems: list[str] | None = None, euler_sequence: str | None = None,
              drawn: Collection[str] = ()) -> list[PlotJob]:
    """The figures of a run: one per simulated row (``<stem>.png``, :func:`row_job`), with pointing
    requirements :data:`MARGINS_FILE` and :data:`SKY_FILE`, and :data:`COMPARISON_FILE`.

    Parameters
    ----------
    results : scenarios.output.results.RunResults
        The run.
    stems : list of str, optional
        The rows' file stems; ``None``: ``row_stems`` of the labels.
    euler_sequence : str, optional
        The row figures' Euler sequence (:func:`euler_angles`); ``None`` (default): the scenario's
        (``plots.euler_sequence``; :data:`EULER_SEQUENCE` unless given).
    drawn : collection of str, optional
        File names of figures drawn already (streamed to the plot process): left out, their series
        not computed.

    Returns
    -------
    list of (str, series)
        File names and series, in drawing order (rows, the pointing figures, the overlay last).
    """
    from scenarios.output.names import row_stems

    euler_sequence = _euler_sequence(results, euler_sequence)
    stems = stems if stems is not None else row_stems([row.label for row in results.rows])
    jobs: list[PlotJob] = []
    for row, stem in zip(results.rows, stems):
        if f"{stem}.png" not in drawn and (job := row_job(row, stem, results.scenario, euler_sequence)) is not None:
            jobs.append(job)
    constraints = pointing_constraints(results) if not {MARGINS_FILE, SKY_FILE} <= set(drawn) else []
    sampled = motions(results) if constraints else []
    if sampled and MARGINS_FILE not in drawn:
        jobs.append((MARGINS_FILE, margin_series(results, constraints, sampled)))
    if sampled and SKY_FILE not in drawn:
        jobs.append((SKY_FILE, sky_series(results, constraints, sampled)))
    if COMPARISON_FILE not in drawn:
        jobs.append((COMPARISON_FILE, overlay_series(results)))
    return jobs


# --- axis names of the result columns --------------------------------------------------------------

SCOPE_NAMES = {"ref": "reference", "cl": "closed-loop"}
"""How a column's scope prefix (``ref.``, ``cl.``) reads on an axis."""
METRIC_NAMES = {"int_u2": "∫‖u‖² dt", "int_u": "∫‖u‖ dt", "int_abs_u": "∫|u_i| dt",
                "int_dipole": "∫‖m‖ dt", "int_actuator_torque": "∫‖τ_act‖ dt", "rms_error_deg": "RMS error", "duration_s": "manoeuvre time",
                "plan_time_s": "plan time"}
"""Metrics whose key does not read as words (the others: the key without its unit suffix, spaced)."""


def _words(key: str) -> str:
    """A key without its unit suffix, spaced: ``settling_time_s`` -> ``settling time``."""
    return key.removesuffix("_deg").removesuffix("_s").replace("_", " ")


def column_quantity(column: str) -> tuple[str, str]:
    """What a result column holds, for an axis: its name in words and its unit.

    Parameters
    ----------
    column : str
        A metric column (``cl.final_error_deg``, ``ref.int_abs_u_x``), a requirement column
        (``cl.req.<name>.<field>``) or ``plan_time_s``.

    Returns
    -------
    name : str
        For example ``"closed-loop final error"``, ``"reference ∫‖u‖ dt"``, ``"closed-loop st_sun:
        min margin"``.
    unit : str
        Its unit (:data:`ocp.metrics.METRIC_INFO`, or the requirement field's,
        :func:`~scenarios.requirements.fields.field_info`): ``"deg"``,
        ``"N m s"``, ``"–"`` for a ratio.

    Raises
    ------
    KeyError
        A column that is none of these (a requirement column whose requirement has no such field too).
    """
    from ocp.metrics import METRIC_INFO  # the metric table (plain data)

    scope, _, rest = column.partition(".")
    if not rest:
        if column in METRIC_INFO:
            return METRIC_NAMES.get(column, _words(column)), METRIC_INFO[column].unit
        raise KeyError(f"not a result column: {column!r}")
    prefix = SCOPE_NAMES[scope]
    if rest.startswith("req."):
        name = rest.split(".")[1]
        info = field_info(column)  # the requirement fields' one declaration; KeyError for no such field
        return f"{prefix} {name}: {info.words}", info.unit
    key, axis = rest, ""
    if key not in METRIC_INFO and key[-2:] in ("_x", "_y", "_z") and key[:-2] in METRIC_INFO:
        key, axis = key[:-2], key[-1]
    if key not in METRIC_INFO:
        raise KeyError(f"not a result column: {column!r}")
    name = METRIC_NAMES.get(key, _words(key))
    if axis:
        name = name.replace("_i", f"_{axis}") if "_i" in name else f"{name} {axis}"
    return f"{prefix} {name}", METRIC_INFO[key].unit


def axis_label(name: str, unit: str) -> str:
    """An axis label: ``"<name> (<unit>)"``, ``(–)`` for a quantity without a unit.

    Parameters
    ----------
    name : str
        The quantity in words.
    unit : str
        Its unit; empty: none.

    Returns
    -------
    str
    """
    return f"{name} ({unit or '–'})"
