"""Matplotlib (Agg) figures of a run: one PNG per row and one overlay comparing the rows."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
import numpy as np  # noqa: E402

from ocp import quat  # noqa: E402
from scenarios.outputs import row_stems  # noqa: E402

AXIS_COLORS = ("tab:red", "tab:green", "tab:blue", "tab:purple")


def _step(axis, t, values, **style):
    """Zero-order-hold samples as a step plot."""
    axis.step(t, np.vstack([values, values[-1:]]), where="post", **style)


def plot_row(row, target_q, path: Path) -> None:
    sim, reference = row.simulation, row.reference
    t = sim.t
    ref = reference.sample(t) if reference is not None else None
    n_w = sim.wheel_momentum.shape[1]
    fig, axes = plt.subplots(5 if n_w else 4, 1, figsize=(9, 13 if n_w else 10.5), sharex=True)
    for i in range(3):
        _step(axes[0], t, sim.applied_torque[:, i:i + 1], color=AXIS_COLORS[i], label=f"u_{'xyz'[i]}")
        if ref is not None:
            axes[0].plot(t, ref.torque[:, i], "--", color=AXIS_COLORS[i], lw=1)
        axes[1].plot(t, sim.omega[:, i], color=AXIS_COLORS[i], label=f"ω_{'xyz'[i]}")
        if ref is not None:
            axes[1].plot(t, ref.omega[:, i], "--", color=AXIS_COLORS[i], lw=1)
    for i in range(4):
        axes[2].plot(t, sim.q[:, i], color=AXIS_COLORS[i], label=f"q{i}")
        if ref is not None:
            axes[2].plot(t, ref.q[:, i], "--", color=AXIS_COLORS[i], lw=1)
    if target_q is not None:
        to_target = np.rad2deg(quat.error_angle(sim.q, target_q))
        axes[3].semilogy(t, np.maximum(to_target, 1e-9), color="k", label="to target")
    if ref is not None:
        axes[3].semilogy(t, np.maximum(np.rad2deg(quat.error_angle(sim.q, ref.q)), 1e-9), color="tab:orange",
                         label="to reference")
    if n_w:
        for i in range(n_w):
            axes[4].plot(t, sim.wheel_momentum[:, i], label=f"h_w{i}")
        axes[4].set_ylabel("wheel momentum (N m s)")
    axes[0].set_ylabel("body torque (N m)")
    axes[1].set_ylabel("body rate (rad/s)")
    axes[2].set_ylabel("quaternion")
    axes[3].set_ylabel("error angle (deg)")
    axes[-1].set_xlabel("time (s)")
    for axis in axes:
        axis.grid(alpha=0.3)
        axis.legend(loc="upper right", fontsize=8, ncol=4)
    fig.suptitle(f"{row.label} ({row.planner or 'regulation'}): solid closed loop, dashed reference")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_cones(row, path: Path) -> None:
    """Angle between each constrained boresight and its direction, closed loop and reference,
    against the cone's limit (the planner's stats carry the cones as imposed, margin included)."""
    cones = row.reference.stats.get("cones", [])
    sim = row.simulation
    fig, axes = plt.subplots(len(cones), 1, figsize=(9, 3.2 * len(cones)), squeeze=False)
    reference_q = row.reference.q(sim.t)
    for axis, (boresight, direction, angle, keep_out) in zip(axes[:, 0], cones):
        for q, style, label in ((sim.q, "-", "closed loop"), (reference_q, "--", "reference")):
            pointing = quat.rotate(q, np.asarray(boresight))
            separation = np.rad2deg(np.arccos(np.clip(pointing @ np.asarray(direction), -1, 1)))
            axis.plot(sim.t, separation, style, label=label)
        axis.axhline(np.rad2deg(angle), color="r", lw=1, label=("keep-out" if keep_out else "keep-in") + " limit")
        axis.set_ylabel("boresight to direction (deg)")
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8)
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle(f"{row.label}: pointing constraints")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_overlay(results, path: Path) -> None:
    """Torque norm, and the error to the target attitude (to the target rate when the attitude is free)."""
    target_q, target_omega = results.scenario.problem.qf, results.scenario.problem.omegaf
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    for row in results.rows:
        if row.simulation is None:
            continue
        sim = row.simulation
        norm = np.linalg.norm(sim.applied_torque, axis=1)
        top.step(sim.t, np.r_[norm, norm[-1]], where="post", label=row.label)
        error = (np.rad2deg(quat.error_angle(sim.q, target_q)) if target_q is not None
                 else np.linalg.norm(sim.omega - target_omega, axis=1))
        bottom.semilogy(sim.t, np.maximum(error, 1e-9), label=row.label)
    top.set_ylabel("‖u‖ (N m)")
    bottom.set_ylabel("error to target (deg)" if target_q is not None else "‖ω − ω_f‖ (rad/s)")
    bottom.set_xlabel("time (s)")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8)
    fig.suptitle(f"{results.scenario.name}: closed-loop comparison")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write_plots(results, directory: Path, stems: list[str] | None = None) -> None:
    """One PNG per simulated row (``<stem>.png``, ``<stem>_cones.png`` with cones) and
    ``comparison.png``; ``stems`` are the rows' file stems (default ``row_stems`` of the labels)."""
    target_q = results.scenario.problem.qf
    stems = stems if stems is not None else row_stems([row.label for row in results.rows])
    for row, stem in zip(results.rows, stems):
        if row.simulation is not None:
            plot_row(row, target_q, directory / f"{stem}.png")
            if row.reference is not None and row.reference.stats.get("cones"):
                plot_cones(row, directory / f"{stem}_cones.png")
    plot_overlay(results, directory / "comparison.png")
