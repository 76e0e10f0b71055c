"""
Natural motions against the eigenaxis slew (nano-spacecraft paper)
==================================================================

The nano-spacecraft paper, section IV: UKube-1 (J = diag(0.0109, 0.05, 0.05) kg m²) on reaction
wheels slews from [0, 0, 0, 1] to [0.5, 0.5, 0.5, 0.5] (scalar last, as printed) in 110 s, the
last 10 s at rest. Three manoeuvres are compared:

* the natural (torque-free) motion of the axisymmetric body, tracked by the augmented quaternion
  feedback with the wheel term (eq. 40): ``nano_natural_vs_eigenaxis.yaml``, row "natural motion";
* a smooth eigenaxis reference tracked by the same law: same file, row "eigenaxis planner";
* the eigenaxis manoeuvre that the PD law of eq. 39 produces by itself, regulating to the target:
  ``nano_eigenaxis_pd.yaml``.

The scenarios run as shipped (0.1 s samples; the paper gives no sample time). The gains are ours:
the paper tuned its own "until the minimum torque manoeuvre which satisfied the boundary
conditions was found" and gives none; ``scenarios/REPRODUCTION.md`` records the grid sweep that
chose them (re-run with the current law, it would now give the natural motion a lower stiffness,
for 6 % less torque; the scenario keeps its gains).
"""

# %%
# Run both scenarios
# ------------------
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import scenarios
from ocp import quat

SHIPPED = Path(scenarios.__file__).parent
tracked = scenarios.run(scenarios.load(SHIPPED / "nano_natural_vs_eigenaxis.yaml"))
regulated = scenarios.run(scenarios.load(SHIPPED / "nano_eigenaxis_pd.yaml"))
rows = {row.label: row for row in tracked.rows + regulated.rows}
for row in rows.values():
    print(f"{row.label}: {row.status}; {row.message}")

# %%
# Torque per axis, ∫|u_i| dt
# --------------------------
# The paper's values: natural motion [0.0195, 0.0152, 0.0243] N m s, eigenaxis PD law
# [0.1013, 0.1252, 0.0973] N m s, so the natural motion saves 82 % of the total torque.
#
# What reproduces is the ranking: the natural motion needs the least torque, and less than a
# smooth eigenaxis reference tracked by the same law. **Discrepancy recorded**: our totals are 24
# (natural motion) and 35 (PD law) times smaller than the paper's, whose gains, sample time, noise
# and perturbations are not given, so its magnitudes cannot be reproduced; the saving is 74 % in
# ``REPRODUCTION.md`` (paper 82 %). ``int_abs_u`` is the control torque on the rigid body in both
# scopes (``docs/metrics.rst``); in the wheels' own torque, which leaves out the gyroscopic torque
# their stored momentum supplies, the saving is 59 % (which of the two the paper integrates is not
# established). A physical floor limits it for a rest-to-rest slew: any such
# manoeuvre must spin up and stop, so a natural arc saves only the mid-course torque (the
# momentum to give the body at the start is printed below).
paper = {"natural motion": [0.0195, 0.0152, 0.0243], "eigenaxis_pd": [0.1013, 0.1252, 0.0973]}
table = {}
for label, row in rows.items():
    int_abs_u = row.closed_loop_metrics["int_abs_u"]
    table[label] = {"x": int_abs_u[0], "y": int_abs_u[1], "z": int_abs_u[2], "sum (ours)": sum(int_abs_u),
                    "sum (paper)": sum(paper[label]) if label in paper else np.nan,
                    "final error [deg]": row.closed_loop_metrics["final_error_deg"]}
table = pd.DataFrame(table).T
with pd.option_context("display.float_format", "{:.4g}".format):
    print(table.to_string())
saving = 1 - table.loc["natural motion", "sum (ours)"] / table.loc["eigenaxis_pd", "sum (ours)"]
print(f"natural motion against the PD eigenaxis manoeuvre: {100 * saving:.0f} % less torque (paper: 82 %)")
natural_reference = rows["natural motion"].reference
spin_up = natural_reference.inertia @ natural_reference.omega(0.0)
print(f"spin-up momentum of the natural arc |I ω*(0)| = {np.linalg.norm(spin_up):.2e} N m s")

# %%
# ``REPRODUCTION.md`` records, for the natural motion, ∫|u| = [0.00036, 0.00100, 0.00111] N m s
# (Σ 0.0025, a 74 % saving; the wheels' torque [0.00036, 0.00157, 0.00171], Σ 0.0036, 59 %) and a torque that peaks at 1.24e-3 N m while the body spins up (paper:
# "of the order of 1e-3 N m"), and once more, 7.7e-3 N m for a single sample, at 100 s, where the
# reference's rate steps to zero (``stop: step``) and the hold-compensated feed-forward puts that
# step into one 0.1 s hold (its values before that feed-forward, Σ 0.0039 and a 1.3e-3 N m peak,
# are kept there as history):
natural = rows["natural motion"].simulation
first_second = natural.t[:-1] < 1.0
print(f"peak |u_i| while spinning up: {np.abs(natural.applied_torque[first_second]).max():.2e} N m; "
      f"over the whole run: {np.abs(natural.applied_torque).max():.2e} N m")

# %%
# Figs. 5-10: rates, quaternions and torques of both manoeuvres
# -------------------------------------------------------------
# Left, the natural motion (the paper's Figs. 5-7); right, the eigenaxis manoeuvre of the PD law
# (Figs. 8-10). Quaternions are drawn scalar last, as the paper prints them.
fig, axes = plt.subplots(3, 2, figsize=(10, 8), sharex=True)
for column, label in enumerate(("natural motion", "eigenaxis_pd")):
    sim = rows[label].simulation
    axes[0, column].plot(sim.t, sim.omega)
    axes[1, column].plot(sim.t, quat.to_scalar_last(sim.q))
    axes[2, column].step(sim.t[:-1], sim.applied_torque, where="post")
    axes[0, column].set_title(label)
    axes[2, column].set_xlabel("t [s]")
axes[0, 0].set_ylabel("ω [rad/s]")
axes[1, 0].set_ylabel("q (scalar last)")
axes[2, 0].set_ylabel("body torque [N m]")
axes[0, 0].legend(["x", "y", "z"], loc="upper right")
axes[1, 0].legend(["q1", "q2", "q3", "q4"], loc="center right")
axes[2, 0].set_ylim(-1.5e-3, 1.5e-3)  # the single-sample stop at 100 s leaves the axis
fig.tight_layout()
