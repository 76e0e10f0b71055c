"""Writing a run's output directory atomically: everything goes to a temporary sibling that is
moved into place only once complete, so an interrupted run never leaves a directory that
looks finished."""
from __future__ import annotations

import csv
import os
import re
import shutil
import tempfile
from pathlib import Path

import numpy as np

from scenarios.tables import to_csv, to_json, to_markdown


def safe_name(label: str) -> str:
    """A file name for a row label."""
    return re.sub(r"[^A-Za-z0-9_.=-]+", "_", label).strip("_") or "row"


def write_timeseries(row, path: Path) -> None:
    """t, q, ω, h_w, applied body torque (held from t_k; blank on the last line), reference q, ω."""
    sim = row.simulation
    n_w = sim.wheel_momentum.shape[1]
    header = (["t", "q0", "q1", "q2", "q3", "omega_x", "omega_y", "omega_z"]
              + [f"h_w{i}" for i in range(n_w)] + ["u_x", "u_y", "u_z"]
              + ["ref_q0", "ref_q1", "ref_q2", "ref_q3", "ref_omega_x", "ref_omega_y", "ref_omega_z"])
    torque = np.vstack([sim.applied_torque, np.full((1, 3), np.nan)])
    if row.reference is not None:
        sample = row.reference.sample(sim.t)
        ref = np.hstack([sample.q, sample.omega])
    else:
        ref = np.full((sim.t.size, 7), np.nan)
    table = np.hstack([sim.t[:, None], sim.x, torque, ref])
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        for line in table:
            writer.writerow(["" if np.isnan(v) else repr(float(v)) for v in line])


def write_results(results, directory: str | Path, plots: bool = True) -> None:
    target = Path(directory).resolve()
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.partial-", dir=target.parent))
    try:
        (staging / "results.json").write_text(to_json(results))
        (staging / "results.csv").write_text(to_csv(results))
        (staging / "results.md").write_text(to_markdown(results))
        series = staging / "timeseries"
        series.mkdir()
        for row in results.rows:
            if row.simulation is not None:
                write_timeseries(row, series / f"{safe_name(row.label)}.csv")
        if plots:
            from scenarios.plots import write_plots
            write_plots(results, staging)
        if target.exists():
            previous = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            os.replace(target, previous / "old")
            os.replace(staging, target)
            shutil.rmtree(previous, ignore_errors=True)
        else:
            os.replace(staging, target)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
