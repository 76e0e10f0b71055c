"""
Two-wheel control of an underactuated satellite (Horri & Palmer)
================================================================

Horri & Palmer, *Practical implementation of attitude control algorithms for an underactuated
satellite*, section VI.A: UoSAT-12 (I = diag(40.45, 42.09, 42.36) kg m²) has lost its z wheel and
must return from rest at q = [0.2, 0.2, 0.2, 0.8246] (scalar last) to the identity with the two
remaining 20 mN m wheels, under a 1 s zero-order hold. Four of the paper's laws, with the paper's
gains, are flown over 10,000 s: the singular zero-momentum law (eq. 13), the singular nonlinear
control "snlc" (eq. 24), the min-norm law (eq. 25) and the gain-scheduled min-norm law (eq. 30).
The optimal two-wheel manoeuvre (``collocation``, minimum time, z wheel failed) gives the lower
bound of their settling times; it is our addition, the paper offers no such comparison.

The shipped ``horri_palmer_two_wheels.yaml`` runs as it is (nothing reduced). Readings the paper
forced on us (``scenarios/REPRODUCTION.md``): the printed initial quaternion has norm 0.894 and is
normalised (a 45.57° error); the paper's three-wheel phase before t0 = 500 s is not given, so the
two-wheel phase starts here at t = 0 from rest; a1 = a2 = 0.025 saturate the singular terms of all
four laws; K is in N m s/rad (eq. 31's units; read in 1/s as eq. 14 writes it, the loop diverges
under the 1 s hold). Eq. 25 is printed with the wrong sign (it raises V); the corrected law is used.
"""

# %%
# Run the scenario
# ----------------
# One planner (the minimum-time slew) and four controllers: four rows, each pairing the optimal
# slew's time with one law's closed loop (the laws regulate to the target and ignore the
# reference).
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import scenarios
from ocp import compute_metrics, quat
from ocp.metrics import settling_time

SHIPPED = Path(scenarios.__file__).parent
scenario = scenarios.load(SHIPPED / "horri_palmer_two_wheels.yaml")
results = scenarios.run(scenario)
optimal = results.rows[0].reference
print(optimal.message)
laws = {row.label.split(" / ")[1]: row for row in results.rows}

# %%
# Settling times and integrated torque
# ------------------------------------
# The paper's criteria, q4 within 1 ± 0.02 and 1 ± 0.01, are error angles of 22.96° and 16.22°,
# not the "about 0.5°" the paper states; the table gives both and 0.5°. The paper integrates
# ∫‖u‖ dt from t0 to an unstated final time; ours is given up to the 16.22° time and over the
# whole window. The paper's values (its times measured from t0 = 500 s):
#
# ============================== ============== ============== ===========
# law                            q4 ± 0.02 [s]  q4 ± 0.01 [s]  ∫‖u‖ [N m s]
# ============================== ============== ============== ===========
# zero momentum (eq. 13)         2452.1         2956.5         19.2
# snlc (eq. 24)                  2918.8         7072.9         19.62
# gain-scheduled min-norm        521.5          1748.4         9.84
# ============================== ============== ============== ===========
#
# **Discrepancy recorded**: the paper's numbers do not reproduce; without its three-wheel phase
# (the state at t0) and its final time a like-for-like comparison is impossible. With the paper's
# gains the high-gain mode of eq. 30 never engages (‖u_hg‖∞ >= 0.275 N m along the run, far above
# ε = 0.02 N m), so the gain-scheduled law is the plain min-norm law row for row; where the paper
# reports a 41 % shorter fine settling time than the zero-momentum law's (1748.4 s against
# 2956.5 s), ours is 12 % (959 s against 1085 s; 14 % against snlc's 1111 s), and to
# 0.5° the min-norm laws are slower, chattering on the hold while q3 decays through the saturated
# singular term (``REPRODUCTION.md``: the min-norm law reaches 0.5° at 13,000 s in a 40,000 s run).
# ``REPRODUCTION.md`` records the same times and integrals as this run.
table = {}
for law, row in laws.items():
    sim, metrics = row.simulation, row.closed_loop_metrics
    error_deg = np.degrees(quat.error_angle(sim.q, scenario.problem.qf))
    fine = metrics["fine_settling_time_s"]
    settled = int(np.searchsorted(sim.t, fine))  # the samples up to the 16.22° time
    to_fine = compute_metrics(sim.t[:settled + 1], sim.q[:settled + 1], sim.omega[:settled + 1],
                              sim.applied_torque[:settled], scenario.problem.qf)
    half_degree = settling_time(sim.t, error_deg, 0.5)
    table[law] = {"22.96° [s]": metrics["settling_time_s"], "16.22° [s]": fine,
                  "0.5° [s]": "not within 10,000 s" if half_degree is None else half_degree,
                  "∫‖u‖ to 16.22° [N m s]": to_fine["int_u"],
                  "∫‖u‖ 0-10,000 s [N m s]": metrics["int_actuator_torque"]}  # u: the wheels' torque
with pd.option_context("display.float_format", "{:.4g}".format):
    print(pd.DataFrame(table).T.to_string())

# %%
# The minimum time as a lower bound
# ---------------------------------
# ``REPRODUCTION.md``: T = 136.64 s (50 intervals, degree 3), checked by a second transcription
# (multiple shooting, 136.74 s at N = 50, 136.661 s at N = 100) and by restarts (three of five
# perturbed restarts return to it, two stop at poorer points: it is the best optimum found, not a
# proven bound); the control is bang-bang on both working wheels. No law comes within a factor of
# 36 of it to 0.5°.
print(f"minimum two-wheel slew time T = {optimal.duration:.2f} s (REPRODUCTION.md: 136.64 s)")
for law, values in table.items():
    if not isinstance(values["0.5° [s]"], str):
        print(f"  {law}: settles to 0.5° in {values['0.5° [s]'] / optimal.duration:.1f} T")

# %%
# Figs. 1, 2, 6 and 7: attitude responses and wheel torques
# ----------------------------------------------------------
# Left, the error angle of the four laws (the paper's attitude off-pointing, Fig. 7) with the
# settling bands and the minimum time; the min-norm rows coincide. Middle, the wheel torques of
# the zero-momentum law over its first 1,500 s (Fig. 1). Right, the optimal slew's wheel torques:
# bang-bang at ±20 mN m, the z wheel idle (the collocation polynomial meets the bound at its
# points and overshoots between them at the two switches).
fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
for law, row in laws.items():
    sim = row.simulation
    error_deg = np.degrees(quat.error_angle(sim.q, scenario.problem.qf))
    axes[0].semilogy(sim.t, error_deg, label=law, linewidth=0.8)
for band in (22.9567, 16.2192, 0.5):
    axes[0].axhline(band, color="k", linestyle=":", linewidth=0.6)
axes[0].axvline(optimal.duration, color="r", linewidth=0.8, label="minimum time T")
axes[0].set_ylim(1e-2, 100.0)
axes[0].set_xlabel("t [s]")
axes[0].set_ylabel("error angle [deg]")
axes[0].legend(fontsize=7)

sim = laws["zero momentum (eq. 13)"].simulation
early = sim.t[:-1] < 1500.0
axes[1].step(sim.t[:-1][early], 1000 * sim.applied_u[early], where="post", linewidth=0.8)
axes[1].set_title("zero momentum (eq. 13)")
axes[1].set_xlabel("t [s]")
axes[1].set_ylabel("wheel torque [mN m]")
axes[1].legend(["x", "y", "z (failed)"], fontsize=7)

t = np.linspace(0.0, optimal.duration, 600)
axes[2].plot(t, 1000 * optimal.control(t))
axes[2].set_title(f"minimum time, T = {optimal.duration:.2f} s")
axes[2].set_xlabel("t [s]")
fig.tight_layout()
