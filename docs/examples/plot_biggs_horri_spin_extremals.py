"""
Spin-stabilized extremals (Biggs & Horri)
=========================================

Biggs & Horri, *Optimal geometric motion planning for spin-stabilized spacecraft*, section V: the
SSTL micro-satellite (I = [19.5, 19, 12.6] kg m²) spins at v = 0.2 rad/s about roll and is
re-pointed from q = [1, 0, 0, 0] to [0, 0, 1, 0] in T = 200 s. The closed-form extremal
(``spin_extremal``) is the reference; the augmented quaternion feedback of eq. 38 tracks it under a
1 s zero-order hold with the body torque bounded by 0.1 N m, for the three gain sets of eq. 41.

The example runs the shipped scenarios ``biggs_horri_spin_repoint_{low,medium,high}.yaml`` as they
are (nothing is reduced: the three runs take well under a second each), prints the optimisation
and tracking tables against the paper's values, and draws the equivalent of the paper's Figs. 1-5
(torque for high and low gains, rate and attitude tracking, quaternion errors).
"""

# %%
# Run the three gain sets
# -----------------------
# The scenario files ship inside the :mod:`scenarios` package. Each has five rows: the optimal
# extremal for k = 0, the paper's printed parameters (eq. 35), the weight k = 3.9e-3 that
# reproduces the paper's k = 1/10 trajectory under our J2, the paper's own k = 0 parameters, and
# an eigenaxis slew for comparison.
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import scenarios
from ocp import quat

SHIPPED = Path(scenarios.__file__).parent
runs = {}
for gains in ("low", "medium", "high"):
    scenario = scenarios.load(SHIPPED / f"biggs_horri_spin_repoint_{gains}.yaml")
    runs[gains] = scenarios.run(scenario)
rows = {gains: {row.label: row for row in results.rows} for gains, results in runs.items()}

# %%
# The optimisation (k = weight of J = J1 + k J2)
# -----------------------------------------------
# The paper's values, as printed (``scenarios/REPRODUCTION.md``, "Optimisation"):
#
# ========== ======== ========== ========= ========== ========
# paper      r        c          β         J1         J2
# ========== ======== ========== ========= ========== ========
# k = 0      0.6754   −3.65e-8   −56.1358  2.2e-7     5.5684
# k = 1/10   0.0157   −7.19e-8   0.4204    4.2081e-6  0.0026
# ========== ======== ========== ========= ========== ========
#
# Ours, recomputed here: with k = 0 every branch K T/2 = π/2 + nπ reaches the target and we keep
# the lowest-energy one, r = π/T = 0.015708, β = 0.420352 (the paper's k = 1/10 trajectory),
# J2 = 0.8223. The paper's k = 0 parameters evaluate, under our definitions, to J1 = 7.4e-5 and
# J2 = 1736. **Discrepancy recorded**: the paper's J values do not follow from its definitions;
# with its printed eq. 35 parameters J2 = ∫‖u‖² dt = 0.8223, not 0.0026 (0.0026 is our J1 at
# k = 1/10: the printed J1 and J2 may have been swapped or taken from another weighting). The
# weight that reproduces the paper's trajectory under a J2 consistent with eq. 31 is k ≈ 3.9e-3,
# which gives J1 = 4.22e-6 (paper 4.2081e-6). Eq. 11 as printed also swaps two coefficients (see
# the "Formulas" table of ``REPRODUCTION.md``); the closed form used here is the corrected one.
table = pd.DataFrame({
    label: {key: row.reference.stats[key] for key in ("r", "c", "beta", "J1", "J2")}
    for label, row in rows["low"].items() if row.planner == "spin_extremal"
}).T
with pd.option_context("display.float_format", "{:.6g}".format):
    print(table.to_string())

# %%
# The torque amplitudes of eq. 37 for the paper's eq. 35 parameters: paper
# [0.000789567, 0.0813672, 0.0411548] N m, ours below (``REPRODUCTION.md``: agreement to 2e-4).
paper_amplitudes = np.array([0.000789567, 0.0813672, 0.0411548])
ours = np.array(rows["low"]["paper eq.35-37"].reference.stats["torque_amplitudes"])
print("eq. 37 amplitudes [N m], paper:", paper_amplitudes)
print("eq. 37 amplitudes [N m], ours: ", ours.round(7))
print("largest relative difference:", f"{np.max(np.abs(ours / paper_amplitudes - 1)):.1e}")

# %%
# Tracking with the three gain sets
# ---------------------------------
# The paper's claim (Figs. 1-2): with the low gains (k_p, k_d) = (0.025, 0.16) the torque stays
# within 0.1 N m and approaches eq. 37; with the high gains (0.5, 4.5) it exceeds 0.1 N m. Both
# hold here. ``REPRODUCTION.md`` adds two facts the paper does not state: the high gains are
# unstable under a 1 s hold without saturation (k_d T = 4.5 > 2: only the 0.1 N m limit keeps the
# loop bounded, chattering in saturation), and real 0.1 N m reaction wheels cannot fly this slew
# (the wheel torque u + ω × h reaches 0.78 N m; ``biggs_horri_spin_repoint_wheels.yaml``).
#
# ``REPRODUCTION.md`` records the tracking table below as re-measured on 2026-12-01: low gains
# peak 0.087 N m, final error 0.080°, RMS 0.78°; medium 0.061° / 0.64° (saturated on the first
# sample only); high 1.75° / 2.18°, saturated throughout. Its earlier values (low 1.38° / 1.49°,
# medium 0.53° / 0.81°) predate the law's held torque right to second order over each sample
# (``hold_compensation``, on by default). The initial errors ([2, −2, 1]° and
# [0, 0.002, −0.002] rad/s) are ours: the paper gives none.
tracking = {}
for gains in rows:
    metrics = rows[gains]["paper eq.35-37"].closed_loop_metrics
    tracking[gains] = {"peak actuator torque |τ_i| [N m]": metrics["peak_actuator_torque"],
                       "saturated samples": metrics["saturation_fraction"],
                       "final error [deg]": metrics["final_error_deg"],
                       "RMS tracking error [deg]": metrics["rms_error_deg"]}
tracking = pd.DataFrame(tracking).T
with pd.option_context("display.float_format", "{:.4g}".format):
    print(tracking.to_string())

# %%
# Figs. 1-2: the body torque for the high and the low gains
# ---------------------------------------------------------
# The applied torque (after the 0.1 N m limit) against the reference's feed-forward torque, the
# trigonometric torque of eq. 37.
fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
for axis, gains in zip(axes, ("high", "low")):
    row = rows[gains]["paper eq.35-37"]
    sim = row.simulation
    reference_torque = row.reference.torque(sim.t)
    for i, colour in enumerate(("C0", "C1", "C2")):
        axis.step(sim.t[:-1], sim.applied_torque[:, i], where="post", color=colour, label=f"u{i + 1}")
        axis.plot(sim.t, reference_torque[:, i], color=colour, linestyle=":", linewidth=1)
    axis.axhline(0.1, color="k", linewidth=0.5)
    axis.axhline(-0.1, color="k", linewidth=0.5)
    axis.set_title(f"{gains} gains (dotted: eq. 37)")
    axis.set_xlabel("t [s]")
axes[0].set_ylabel("body torque [N m]")
axes[0].legend(loc="lower right")
fig.tight_layout()

# %%
# Figs. 3-5: rate tracking, attitude tracking and quaternion errors
# ------------------------------------------------------------------
# Low gains (solid) against high gains (dashed, pale; they chatter in saturation). As in the
# paper, the high gains do not track better during the transient.
fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
for gains, style, alpha in (("high", "--", 0.45), ("low", "-", 1.0)):
    row = rows[gains]["paper eq.35-37"]
    sim = row.simulation
    reference = row.reference.sample(sim.t)
    error = quat.error(sim.q, reference.q)
    for i, colour in enumerate(("C0", "C1", "C2")):
        axes[0].plot(sim.t, sim.omega[:, i] - reference.omega[:, i], style, color=colour, alpha=alpha)
        axes[1].plot(sim.t, sim.q[:, i + 1], style, color=colour, alpha=alpha)
        axes[2].plot(sim.t, error[:, i + 1], style, color=colour, alpha=alpha)
axes[0].set_title("ω − ω* [rad/s]")
axes[1].set_title("q1, q2, q3 (dotted: reference)")
times = np.linspace(0.0, 200.0, 201)
axes[1].plot(times, rows["low"]["paper eq.35-37"].reference.q(times)[:, 1:], ":", color="k", linewidth=0.8)
axes[2].set_title("error quaternion, vector part")
for axis in axes:
    axis.set_xlabel("t [s]")
fig.tight_layout()
