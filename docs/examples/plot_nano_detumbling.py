"""
Detumbling with B-dot and time-delayed feedback (nano-spacecraft paper)
=======================================================================

The nano-spacecraft paper, section III: UKube-1 (J = diag(0.0109, 0.05, 0.05) kg m²) with
magnetorquers only (0.1 A m² per axis) in a 600 km, 97.79° circular orbit under the tilted dipole
of eq. 6-8, tumbling at ω0 = [0.52, 0.52, 0.52] rad/s, is detumbled by B-dot (eq. 12, a backward
difference of the magnetometer reading) and by time-delayed feedback control (TDFC, eq. 11, a
difference over τ = 2 s), first ideally and then with 1e-5 T of magnetometer noise.

The ideal case runs ``nano_detumble.yaml`` as shipped (60,000 s). **Reduced**: the noisy case
``nano_detumble_noisy.yaml`` is run over 50,000 s instead of its 300,000 s, which keeps the
gallery light: TDFC detumbles inside that window (at the same time as in the full one) and B-dot
does not, and the full window's B-dot time is quoted from ``scenarios/REPRODUCTION.md``. Our
criterion depends on the window when a law's rate floor sits near the bound, as B-dot's does
with noise: over 100,000 s it would "detumble" at 88,794 s, only to rise above 0.01 rad/s again
before 300,000 s.

"Detumbled" is our ``detumble_time_s``: the first time after which max|ω_i| < 0.01 rad/s holds to
the end of the window. The paper gives neither its gains, its sample time nor its criterion; the
scenarios use K_b = 2e4 A m² s/T, K_t = 1e4 A m²/T (so that K_t τ = K_b), 1 s samples.
"""

# %%
# The ideal case, as shipped
# --------------------------
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import scenarios
from scenarios.schema import read_yaml

SHIPPED = Path(scenarios.__file__).parent
ideal = scenarios.run(scenarios.load(SHIPPED / "nano_detumble.yaml"))

# %%
# The noisy case over a shorter window
# ------------------------------------
# A scenario file is a plain mapping: read it with the scenario reader (which, unlike plain YAML
# 1.1, reads ``2.0e4`` as a number), change what the example reduces, and parse it with
# :func:`scenarios.parse_scenario`, which checks it exactly as :func:`scenarios.load` does.
path = SHIPPED / "nano_detumble_noisy.yaml"
data = read_yaml(path)
print("shipped window:", data["maneuver"]["duration"], "s")
data["maneuver"]["duration"] = 50_000.0
noisy = scenarios.run(scenarios.parse_scenario(data, source=path))

# %%
# Detumbling times against the paper
# ----------------------------------
# The paper's times are 35,000 s (B-dot) and 46,500 s (TDFC) ideally, 290,000 s and 58,000 s with
# noise. ``REPRODUCTION.md`` records ours as 19,689 s / 26,638 s ideally and 277,907 s / 38,447 s
# with noise (seed 1, full 300,000 s window).
#
# What reproduces is the ordering: without noise B-dot detumbles first; with noise TDFC detumbles
# 7-9 times sooner, because B-dot's backward difference amplifies the noise and its dipole
# saturates on noise for most samples, while TDFC's difference over 2 s keeps a signal.
# **Discrepancy recorded**: the absolute times do not reproduce, and cannot be expected to: they
# depend strongly on the gains, the sample time and the criterion, none of which the paper gives
# (at 0.2 s samples, for instance, the ideal times are 18,941 s and 19,364 s; ``REPRODUCTION.md``
# tabulates the sensitivities).
paper = {("ideal", "B-dot"): 35_000, ("ideal", "TDFC"): 46_500,
         ("noise 1e-5 T", "B-dot"): 290_000, ("noise 1e-5 T", "TDFC"): 58_000}
recorded = {("ideal", "B-dot"): 19_689, ("ideal", "TDFC"): 26_638,
            ("noise 1e-5 T", "B-dot"): 277_907, ("noise 1e-5 T", "TDFC"): 38_447}
table = []
for case, results in (("ideal", ideal), ("noise 1e-5 T", noisy)):
    for row in results.rows:
        window = row.simulation.t[-1]
        time = row.closed_loop_metrics["detumble_time_s"]
        table.append({"case": case, "law": row.label, "paper [s]": paper[case, row.label],
                      "REPRODUCTION.md [s]": recorded[case, row.label],
                      "this run [s]": f"{time:,.0f}" if time is not None else f"> {window:,.0f}",
                      "final |ω| [rad/s]": row.closed_loop_metrics["final_rate"]})
print(pd.DataFrame(table).to_string(index=False))

# %%
# Figs. 1-4: the body rates under both laws
# -----------------------------------------
# max|ω_i| on a logarithmic scale, with the 0.01 rad/s criterion. Both laws end near twice the
# orbital rate: magnetic laws null the rate relative to the field, which turns at about 2n along a
# polar orbit.
fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
for axis, (case, results) in zip(axes, (("ideal", ideal), ("noise 1e-5 T", noisy))):
    for row in results.rows:
        sim = row.simulation
        axis.semilogy(sim.t / 1000.0, np.max(np.abs(sim.omega), axis=1), label=row.label, linewidth=0.8)
    axis.axhline(0.01, color="k", linestyle=":", linewidth=0.8)
    axis.set_title(case)
    axis.set_xlabel("t [1000 s]")
axes[0].set_ylabel("max |ω_i| [rad/s]")
axes[0].legend()
fig.tight_layout()

# %%
# The magnetic torque m × B applied to the body (the paper's torque panels), ideal case: it falls
# with the rate, because both laws command a dipole proportional to the field's rate of change
# in body axes (saturated at 0.1 A m² per axis while the body tumbles).
fig, axis = plt.subplots(figsize=(8, 3.4))
for row in ideal.rows:
    sim = row.simulation
    axis.semilogy(sim.t[:-1:10] / 1000.0, np.linalg.norm(sim.applied_torque[::10], axis=1), label=row.label,
                  linewidth=0.6, alpha=0.8)
axis.set_xlabel("t [1000 s]")
axis.set_ylabel("|m × B| [N m]")
axis.set_title("ideal case, every tenth sample")
axis.legend()
fig.tight_layout()
