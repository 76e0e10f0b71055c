"""A slew table's files: ``slew_table.csv``, ``slew_table.nc``, ``fit.json`` and ``agility_envelope.png``.

``slew_table.nc`` is NetCDF-3 classic, written with :class:`scipy.io.netcdf_file` (no new
dependency): self-describing (every variable has ``units`` and ``long_name``; the global attributes
name the scenario, the spacecraft, the objective, slewbench's version and the date) and read by
xarray, netCDF4, MATLAB's ``ncread``, NCO and Panoply alike. Its dimensions are ``axis`` x ``angle``
(and ``held_out_axis`` x ``held_out_angle`` for the held-out grid); a status is a byte with CF
``flag_values`` / ``flag_meanings``, and so is ``best_known`` (0 where the planner knows a faster
feasible slew of the entry's problem, 1 where it knows none, the fill value where the question does
not apply: :attr:`scenarios.slewtable.compute.TablePart.best_known`).
"""
from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

import numpy as np

from scenarios.slewtable.compute import PART_NAMES, SlewTable, TablePart

__all__ = ["BEST_KNOWN_FILL", "CSV_COLUMNS", "STATUS_CODES", "TABLE_FILES", "best_known_text", "write_table_files"]

CSV_COLUMNS = ("grid", "axis_x", "axis_y", "axis_z", "angle_deg", "slew_time_s", "objective", "objective_value",
               "status", "best_known", "plan_time_s", "message")
"""Columns of ``slew_table.csv`` (axis: unit eigen-axis, body frame; ``best_known``:
:func:`best_known_text`)."""
BEST_KNOWN_FILL = -1
"""The fill value of ``best_known`` in ``slew_table.nc``: the question does not apply (no slew time,
or a ``min_energy`` table)."""
STATUS_CODES = ("ok", "violated", "failed", "crashed", "missing", "infeasible", "timed_out")
"""Entry status -> its code in the NetCDF file (the index; the later ones appended, so that the
earlier codes keep their values)."""
TABLE_FILES = ("slew_table.csv", "slew_table.nc", "fit.json", "agility_envelope.png")
"""The files a table writes (``fit.json`` only when there is a fit)."""


def _cell(value: float) -> str:
    return "" if not np.isfinite(value) else repr(float(value))


def best_known_text(flag: bool | None) -> str:
    """An entry's ``best_known`` cell in ``slew_table.csv``.

    Parameters
    ----------
    flag : bool or None
        :attr:`scenarios.slewtable.compute.TablePart.best_known` of the entry.

    Returns
    -------
    str
        ``false``: the planner knows a faster feasible slew of the entry's problem (its message
        says "not the best known" and names it; an ``ok`` entry is fitted all the same, its time
        achievable); ``true``: it knows none; empty: the question does not apply (no slew time, or
        a ``min_energy`` table).
    """
    return "" if flag is None else ("true" if flag else "false")


def write_csv(table: SlewTable, path: Path) -> None:
    """Write ``slew_table.csv``: one row per entry, the table's grid then the held-out grid.

    Parameters
    ----------
    table : SlewTable
        The computed table.
    path : Path
        The file.
    """
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(CSV_COLUMNS)
        for name in PART_NAMES:
            if name not in table.parts:
                continue
            part = table.parts[name]
            for i, axis in enumerate(part.axes):
                for k, angle in enumerate(part.angles_deg):
                    writer.writerow([name, *(repr(float(a)) for a in axis), repr(float(angle)),
                                     _cell(part.slew_time_s[i, k]), table.spec.objective,
                                     _cell(part.objective_value[i, k]), part.status[i][k],
                                     best_known_text(part.best_known[i][k]), _cell(part.plan_time_s[i, k]),
                                     part.message[i][k]])


def write_netcdf(table: SlewTable, path: Path) -> None:
    """Write ``slew_table.nc`` (NetCDF-3 classic, module docstring).

    Parameters
    ----------
    table : SlewTable
        The computed table.
    path : Path
        The file.
    """
    from scipy.io import netcdf_file

    from scenarios.output.provenance import package_version, utc_stamp
    spec = table.spec
    objective_units = "s" if spec.objective == "min_time" else "N2 m2 s"
    objective_name = "slew time (the minimised objective)" if spec.objective == "min_time" else \
        "integral of the squared body torque norm over the slew (the minimised objective)"
    with netcdf_file(path, "w", version=1) as nc:
        nc.title = f"slewbench slew table: {spec.name}"
        nc.Conventions = "CF-1.8"
        nc.scenario = spec.name
        nc.scenario_file = spec.source.name if spec.source is not None else ""
        nc.spacecraft = json.dumps(spec.base.get("spacecraft"), sort_keys=True)
        nc.objective = spec.objective
        nc.planner = "collocation"
        nc.planner_options = json.dumps(spec.planner_options, sort_keys=True)
        nc.slew = "rest to rest from the identity attitude, about a body eigen-axis by an angle"
        nc.quaternion_convention = "scalar first, body to inertial"
        nc.slewbench_version = package_version()
        nc.date_created = utc_stamp()
        nc.status_codes = " ".join(f"{i}={s}" for i, s in enumerate(STATUS_CODES))
        if spec.duration is not None:
            nc.duration_s = float(spec.duration)
        # what makes the times depend on the start attitude and the date (the slews start at the
        # identity at the epoch): the pointing requirements and the environment, as written
        nc.epoch = str(spec.base.get("epoch") or "")
        nc.requirements = json.dumps(spec.base.get("requirements"), sort_keys=True, default=str)
        nc.environment = json.dumps(spec.base.get("environment"), sort_keys=True, default=str)
        for name, prefix in (("table", ""), ("held_out", "held_out_"), ("check", "check_")):
            part = table.parts.get(name)
            if part is None or (name != "table" and not len(part.axes)):
                continue
            nc.createDimension(f"{prefix}axis", len(part.axes))
            nc.createDimension(f"{prefix}angle", len(part.angles_deg))
            dims = (f"{prefix}axis", f"{prefix}angle")
            for j, c in enumerate("xyz"):
                v = nc.createVariable(f"{prefix}axis_{c}", "d", (f"{prefix}axis",))
                v[:] = part.axes[:, j]
                v.units = "1"
                v.long_name = f"eigen-axis {c} component, body frame (unit vector)"
            v = nc.createVariable(f"{prefix}angle", "d", (f"{prefix}angle",))
            v[:] = np.asarray(part.angles_deg, dtype=float)
            v.units = "degree"
            v.long_name = "slew angle about the eigen-axis"
            _data(nc, f"{prefix}slew_time", dims, part.slew_time_s, "s", "rest-to-rest slew time")
            _data(nc, f"{prefix}objective_value", dims, part.objective_value, objective_units, objective_name)
            _data(nc, f"{prefix}plan_time", dims, part.plan_time_s, "s", "planner wall time")
            v = nc.createVariable(f"{prefix}status", "b", dims)
            v[:] = np.array([[STATUS_CODES.index(s) if s in STATUS_CODES else STATUS_CODES.index("crashed")
                              for s in row] for row in part.status], dtype=np.int8).reshape(part.slew_time_s.shape)
            v.units = "1"
            v.long_name = "entry status"
            v.flag_values = np.arange(len(STATUS_CODES), dtype=np.int8)
            v.flag_meanings = " ".join(STATUS_CODES)
            v = nc.createVariable(f"{prefix}best_known", "b", dims)
            v[:] = np.array([[BEST_KNOWN_FILL if flag is None else int(flag) for flag in row] for row in part.best_known],
                            dtype=np.int8).reshape(part.slew_time_s.shape)
            v.units = "1"
            v.long_name = ("whether the planner knows no faster feasible slew of the entry's problem (0: it knows "
                           "one, named in the entry's message; the entry keeps its own, achievable time)")
            v._FillValue = np.int8(BEST_KNOWN_FILL)
            v.flag_values = np.array([0, 1], dtype=np.int8)
            v.flag_meanings = "false true"


def _data(nc: Any, name: str, dims: tuple[str, str], values: np.ndarray, units: str, long_name: str) -> None:
    v = nc.createVariable(name, "d", dims)
    v[:] = values
    v.units = units
    v.long_name = long_name
    v._FillValue = np.nan
    v.missing_value = np.nan


def write_plot(table: SlewTable, path: Path) -> None:
    """Draw ``agility_envelope.png``: slew time against angle (the axes' band and per-axis lines)
    and a map of the slew time over the sphere at the largest angle.

    Parameters
    ----------
    table : SlewTable
        The computed table.
    path : Path
        The file.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    part: TablePart = table.parts["table"]
    angles = np.asarray(part.angles_deg)
    times = np.where(part.ok, part.slew_time_s, np.nan)
    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    for row in times:
        left.plot(angles, row, color="0.75", lw=0.6)
    with np.errstate(all="ignore"):
        if np.isfinite(times).any(axis=0).all():
            low, mid, high = np.nanmin(times, 0), np.nanmedian(times, 0), np.nanmax(times, 0)
            left.fill_between(angles, low, high, color="C0", alpha=0.25, label="band over the axes (min to max)")
            left.plot(angles, mid, color="C0", lw=2, label="median over the axes")
    if table.fit is not None:
        fine = np.linspace(0.0, angles[-1], 200)
        for label, axis, color in (("fit, body x", [1, 0, 0], "C1"), ("fit, body y", [0, 1, 0], "C2"),
                                   ("fit, body z", [0, 0, 1], "C3")):
            values = table.fit.many_axis_angle(np.tile(axis, (len(fine), 1)), np.deg2rad(fine))
            left.plot(fine, values, color=color, lw=1.2, ls="--", label=label)
    left.set_xlabel("slew angle [deg]")
    left.set_ylabel(f"{'minimum ' if table.spec.objective == 'min_time' else ''}slew time [s]")
    left.set_title(f"{table.spec.name}: {table.spec.objective}, {len(part.axes)} axes")
    left.grid(True, alpha=0.3)
    if left.get_legend_handles_labels()[0]:  # none when no entry is ok and there is no fit
        left.legend(fontsize=8, loc="upper left")
    k = len(angles) - 1
    axes = part.axes
    lon = np.rad2deg(np.arctan2(axes[:, 1], axes[:, 0]))
    lat = np.rad2deg(np.arcsin(np.clip(axes[:, 2], -1, 1)))
    values = times[:, k]
    if table.fit is not None:
        grid_lon, grid_lat = np.meshgrid(np.linspace(-180, 180, 181), np.linspace(-90, 90, 91))
        la, lo = np.deg2rad(grid_lat.ravel()), np.deg2rad(grid_lon.ravel())
        directions = np.column_stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)])
        fitted = table.fit.many_axis_angle(directions, np.full(len(directions), np.deg2rad(angles[k])))
        mesh = right.pcolormesh(grid_lon, grid_lat, fitted.reshape(grid_lon.shape), shading="auto", cmap="viridis")
        right.scatter(lon, lat, c=values, cmap="viridis", norm=mesh.norm, edgecolors="k", s=30)
    else:
        mesh = right.scatter(lon, lat, c=values, cmap="viridis", edgecolors="k", s=30)
    figure.colorbar(mesh, ax=right, label=f"slew time at {angles[k]:g} deg [s]")
    right.set_xlabel("eigen-axis longitude in the body x-y plane [deg]")
    right.set_ylabel("eigen-axis latitude from the body x-y plane [deg]")
    right.set_title(f"over the sphere at {angles[k]:g} deg (dots: table entries, map: fit)")
    right.set_xlim(-180, 180)
    right.set_ylim(-90, 90)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def write_table_files(table: SlewTable, folder: Path, plots: bool = True) -> list[str]:
    """Write a table's files into ``folder`` (a staging folder).

    Parameters
    ----------
    table : SlewTable
        The computed table.
    folder : Path
        Where to write.
    plots : bool, optional
        Also draw ``agility_envelope.png``.

    Returns
    -------
    list of str
        The file names written.
    """
    written = []
    write_csv(table, folder / "slew_table.csv")
    written.append("slew_table.csv")
    write_netcdf(table, folder / "slew_table.nc")
    written.append("slew_table.nc")
    if table.fit is not None:
        table.fit.save(folder / "fit.json")
        written.append("fit.json")
    if plots:
        write_plot(table, folder / "agility_envelope.png")
        written.append("agility_envelope.png")
    return written
