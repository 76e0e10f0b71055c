"""Matplotlib (Agg) figures of a run: one PNG per row and one overlay comparing the rows.

Drawing is the largest cost of a run with plots, so it is kept cheap: figures are plain
``matplotlib.figure.Figure`` objects (no pyplot state), laid out once with fixed margins (no
``tight_layout``, which measures every text), and the per-row figure is built once per run and
reused for every row by replacing its lines' data (:class:`RowFigure`).
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, NullLocator

from ocp import quat
from scenarios.outputs import row_stems

AXIS_COLORS = ("tab:red", "tab:green", "tab:blue", "tab:purple")
DPI = 90
SAVE = {"dpi": DPI, "pil_kwargs": {"compress_level": 1}}
"""PNG options: zlib level 1 encodes several times faster than the default 6 for ~20 % more bytes."""


def _log_axis(axis: Any) -> None:
    """A logarithmic y axis with plain ``1e-05`` labels (the default ``10⁻⁵`` labels go through
    mathtext, which parses every label and costs more than drawing the whole figure)."""
    axis.set_yscale("log")
    axis.yaxis.set_minor_locator(NullLocator())
    axis.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))


def _held(values: np.ndarray) -> np.ndarray:
    """Zero-order-hold samples (one per interval) extended by the last one, for ``steps-post``."""
    return np.concatenate([values, values[-1:]])


class RowFigure:
    """The per-row figure (torque, rate, quaternion, error angles, wheel momenta), built once and
    redrawn for each row of the same shape.

    Parameters
    ----------
    n_wheels : number of wheels (a fifth panel with their momenta when > 0).
    with_reference : draw the reference dashed and the error to it.
    with_target : draw the error to the target attitude.
    """

    def __init__(self, n_wheels: int, with_reference: bool, with_target: bool):
        self.figure = Figure(figsize=(9, 13 if n_wheels else 10.5))
        axes = self.figure.subplots(5 if n_wheels else 4, 1, sharex=True)
        self.axes = axes

        def line(axis: Any, style: str = "-", **kw: Any) -> Any:
            return axis.plot([], [], style, **kw)[0]

        self.torque = [line(axes[0], color=AXIS_COLORS[i], drawstyle="steps-post", label=f"u_{'xyz'[i]}")
                       for i in range(3)]
        self.rate = [line(axes[1], color=AXIS_COLORS[i], label=f"ω_{'xyz'[i]}") for i in range(3)]
        self.quaternion = [line(axes[2], color=AXIS_COLORS[i], label=f"q{i}") for i in range(4)]
        self.reference = None
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
            axis.set_ylabel(label)
            axis.grid(alpha=0.3)
            if axis.get_lines() and any(not l.get_label().startswith("_") for l in axis.get_lines()):
                axis.legend(loc="upper right", fontsize=8, ncol=4)
        axes[-1].set_xlabel("time (s)")
        self.title = self.figure.suptitle("")
        self.figure.subplots_adjust(left=0.1, right=0.98, bottom=0.05, top=0.95, hspace=0.08)

    def draw(self, row: Any, target_q: Any, path: Path) -> None:
        """Put ``row``'s simulation (and reference) into the lines and write the PNG at ``path``."""
        sim = row.simulation
        t = sim.t
        for i in range(3):
            self.torque[i].set_data(t, _held(sim.applied_torque[:, i]))
            self.rate[i].set_data(t, sim.omega[:, i])
        for i in range(4):
            self.quaternion[i].set_data(t, sim.q[:, i])
        if self.reference is not None:
            ref = row.reference.sample(t)
            for lines, values in zip(self.reference, (ref.torque, ref.omega, ref.q)):
                for i, item in enumerate(lines):
                    item.set_data(t, values[:, i])
            self.to_reference.set_data(t, np.maximum(np.rad2deg(quat.error_angle(sim.q, ref.q)), 1e-9))
        if self.to_target is not None:
            self.to_target.set_data(t, np.maximum(np.rad2deg(quat.error_angle(sim.q, target_q)), 1e-9))
        if self.rate_norm is not None:
            self.rate_norm.set_data(t, np.maximum(np.linalg.norm(sim.omega, axis=1), 1e-12))
            self.rate_max.set_data(t, np.maximum(np.abs(sim.omega).max(axis=1), 1e-12))
        for i, item in enumerate(self.wheels):
            item.set_data(t, sim.wheel_momentum[:, i])
        for axis in self.axes:
            axis.relim()
            axis.autoscale_view()
        controller = f", {row.controller}" if getattr(row, "controller", None) else ""
        self.title.set_text(f"{row.label} ({row.planner or 'regulation'}{controller}): solid closed loop, "
                            "dashed reference")
        self.figure.savefig(path, **SAVE)


def plot_cones(row: Any, path: Path) -> None:
    """Angle between each constrained boresight and its direction, closed loop and reference,
    against the cone's limit (the planner's stats carry the cones as imposed, margin included)."""
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
    """Torque norm, and the error to the target attitude (to the target rate when the attitude is free)."""
    target_q, target_omega = results.scenario.problem.qf, results.scenario.problem.omegaf
    figure = Figure(figsize=(9, 7))
    top, bottom = figure.subplots(2, 1, sharex=True)
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
    top.set_ylabel("‖u‖ (N m)")
    bottom.set_ylabel("error to target (deg)" if target_q is not None
                      else "‖ω − ω_f‖ (rad/s)" if target_omega is not None else "‖ω‖ (rad/s)")
    bottom.set_xlabel("time (s)")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
        if axis.get_lines():
            axis.legend(fontsize=8, loc="upper right")
    figure.suptitle(f"{results.scenario.name}: closed-loop comparison")
    figure.subplots_adjust(left=0.1, right=0.98, bottom=0.08, top=0.93, hspace=0.08)
    figure.savefig(path, **SAVE)


def write_plots(results: Any, directory: Path, stems: list[str] | None = None) -> None:
    """One PNG per simulated row (``<stem>.png``, ``<stem>_cones.png`` with cones) and
    ``comparison.png``; ``stems`` are the rows' file stems (default ``row_stems`` of the labels)."""
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
