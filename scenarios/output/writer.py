"""Writing a run's results into an output directory slewbench owns: the tables, one time series per
row, the figures and the interactive report, staged and committed together
(:mod:`scenarios.output.directory` holds the ownership rules, :doc:`/outputs` the layout).
"""
from __future__ import annotations

import csv
import json
import shutil
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scenarios.errors import ANOTHER_DIRECTORY, OutputError
from scenarios.output.directory import (
    check_output_directory,
    claimed_output_directory,
    commit_outputs,
    new_staging,
    read_manifest,
)
from scenarios.output.names import row_stems
from scenarios.output.plot_data import knowledge_series
from scenarios.output.tables import to_csv, to_json, to_markdown

if TYPE_CHECKING:
    from scenarios.output.results import Row, RunResults
    from scenarios.schema.loader import Scenario

__all__ = ["check_run_directory", "plot_streamer", "run_files", "write_results", "write_timeseries"]


def write_timeseries(row: Row, path: Path) -> None:
    """Write a row's closed-loop time series as CSV.

    Columns: ``t`` [s], ``q0..q3`` (body to inertial, scalar first), ``omega_x..z`` [rad/s, body],
    ``h_w0..`` [N m s], ``u_x..z`` the applied body torque [N m, body] held from ``t`` (blank on
    the last line), ``ref_q0..3``, ``ref_omega_x..z`` [rad/s] and ``ref_omega_dot_x..z`` [rad/s², reference
    body axes] (blank without a reference); with a star tracker in the loop (an estimator), then
    ``known_q0..3``, the attitude the controller was given at ``t``, and ``knowledge_error_deg``,
    its angle from the true attitude [deg] (:func:`scenarios.output.plot_data.knowledge_series`; blank on the last line),
    and ``blinded``, which of the star tracker's exclusions held its boresight at ``t`` (an integer:
    bit i for the i-th of ``exclusion_deg``, 0 for none; :attr:`ocp.SimulationResult.blinded`;
    blank on the last line). Non-finite values are blank (:func:`scenarios.output.tables.csv_cell`).

    Parameters
    ----------
    row : Row
        A result row with a ``simulation`` (and its ``reference``, or ``None``).
    path : Path
        The CSV file to write.
    """
    sim = row.simulation
    if sim is None:
        raise ValueError(f"row {row.label!r} has no closed-loop simulation to write")
    n_w = sim.wheel_momentum.shape[1]
    header = (["t", "q0", "q1", "q2", "q3", "omega_x", "omega_y", "omega_z"]
              + [f"h_w{i}" for i in range(n_w)] + ["u_x", "u_y", "u_z"]
              + ["ref_q0", "ref_q1", "ref_q2", "ref_q3", "ref_omega_x", "ref_omega_y", "ref_omega_z",
                 "ref_omega_dot_x", "ref_omega_dot_y", "ref_omega_dot_z"])
    torque = np.vstack([sim.applied_torque, np.full((1, 3), np.nan)])
    if row.reference is not None:
        sample = row.reference.sample(sim.t)
        ref = np.hstack([sample.q, sample.omega, sample.omega_dot])
    else:
        ref = np.full((sim.t.size, 10), np.nan)
    table = np.hstack([sim.t[:, None], sim.x, torque, ref])
    knowledge = knowledge_series(sim)
    if knowledge is not None:
        known, error = knowledge
        header += ["known_q0", "known_q1", "known_q2", "known_q3", "knowledge_error_deg"]
        table = np.hstack([table, known, error[:, None]])
    finite = np.isfinite(table).tolist()
    # csv_cell of each value, without its checks per cell (every value is a float here): the repr
    # of a finite value, blank otherwise
    lines: Iterator[list[str]] = ([repr(v) if ok else "" for v, ok in zip(line, keep)]
                                  for line, keep in zip(table.tolist(), finite))
    blinded = getattr(sim, "blinded", None)  # None without a star tracker
    if blinded is not None:  # the bits as integers, at t_0 ... t_(N-1): none at the final time
        header.append("blinded")
        bits = [str(int(bit)) for bit in blinded] + [""] * (sim.t.size - len(blinded))
        lines = (line + [bit] for line, bit in zip(lines, bits))
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows(lines)


def plot_streamer(scenario: Any, renderer: Any) -> Callable[[Row], None]:
    """A run's ``on_row`` (:func:`scenarios.runner.run`) that sends each simulated row's figure to
    the plot process as soon as the row is done, and the figures of the whole run (comparison,
    margins, sky) once the last row is (:meth:`scenarios.output.renderer.Renderer.stream`), so that
    they are drawn while the run goes on; :func:`write_results` then has them written.

    Parameters
    ----------
    scenario : scenarios.schema.loader.Scenario
        The scenario about to run (its rows' labels give the file stems).
    renderer : scenarios.output.renderer.Renderer
        The plot process.

    Returns
    -------
    callable
        ``on_row(row)``.
    """
    from scenarios.output.plot_data import plot_jobs, row_job
    from scenarios.output.results import RunResults
    from scenarios.schema.labels import row_labels

    labels = [label for label, *_ in row_labels([planner.label for planner in scenario.planners],
                                                 [c.label for c in scenario.controllers])]
    stems = row_stems(labels)
    rows: list[Row] = []

    def on_row(row: Row) -> None:
        rows.append(row)
        if len(rows) > len(labels) or row.label != labels[len(rows) - 1]:
            return  # not the rows announced: the figures are drawn at the end
        job = row_job(row, stems[len(rows) - 1], scenario)
        if job is not None:
            renderer.stream(job, row)
        if len(rows) == len(labels):  # the last row: the whole run's figures
            drawn = {f"{stem}.png" for stem in stems}
            for job in plot_jobs(RunResults(scenario, list(rows)), stems, drawn=drawn):
                renderer.stream(job, tuple(rows))

    return on_row


def _still_valid(results: RunResults, stems: list[str], streamed: dict[str, Any]) -> set[str]:
    """The streamed figures (:attr:`Renderer.streamed`) that are this run's: a row's figure drawn
    from the row written under its file name, a whole-run figure drawn from exactly these rows."""
    rows = {f"{stem}.png": row for row, stem in zip(results.rows, stems) if row.simulation is not None}
    every = tuple(results.rows)
    return {name for name, source in streamed.items()
            if rows.get(name) is source
            or (isinstance(source, tuple) and len(source) == len(every) and all(a is b for a, b in zip(source, every)))}


def _write_plots(results: RunResults, staging: Path, stems: list[str], renderer: Any) -> None:
    """The run's figures and ``report.html`` into ``staging``. With a plot process, the figures not
    streamed to it already (:func:`plot_streamer`) are sent to it and the report is built here
    while it draws; without one (or if it fails), both are made in this process."""
    from scenarios.output.plot_data import plot_jobs
    from scenarios.output.report.run import run_page

    if renderer is not None:
        from scenarios.output.renderer import RenderingFailed

        keep = _still_valid(results, stems, renderer.streamed)
        try:
            renderer.submit(plot_jobs(results, stems, drawn=keep), staging, keep)
        except RenderingFailed as error:
            print(f"slewbench: {error}; drawing the plots in this process", file=sys.stderr)
            renderer = None
    (staging / "report.html").write_bytes(run_page(results).render_bytes())  # run_report's text, as UTF-8
    if renderer is not None:
        try:
            renderer.wait()
            return
        except RenderingFailed as error:
            print(f"slewbench: {error}; drawing the plots in this process", file=sys.stderr)
    from scenarios.output.plots import draw_jobs

    draw_jobs(plot_jobs(results, stems), staging)


def run_files(scenario: Scenario, plots: bool = True) -> list[str]:
    """The files a run of ``scenario`` writes (:func:`write_results`) when its rows simulate, known
    before it plans: what :func:`~scenarios.output.directory.claim_output_directory` checks up front.

    Parameters
    ----------
    scenario : Scenario
        The scenario about to run (its rows' labels give the file stems).
    plots : bool, optional
        With the PNG figures and ``report.html``.

    Returns
    -------
    list of str
        Relative paths: the tables, a time series per row and, with ``plots``, a figure per row,
        ``comparison.png`` and ``report.html`` (a row whose plan fails has no time series or
        figure). The pointing figures, drawn only where the scenario or a planner's reference has
        cones, are left to the check at the commit (:func:`~scenarios.output.directory.commit_outputs`).
    """
    from scenarios.output.plot_data import COMPARISON_FILE
    from scenarios.schema.labels import row_labels

    labels = [label for label, _, _ in row_labels([spec.label for spec in scenario.planners],
                                                  [spec.label for spec in scenario.controllers])]
    stems = row_stems(labels)
    files = ["results.json", "results.csv", "results.md", *(f"timeseries/{stem}.csv" for stem in stems)]
    if plots:
        files += [*(f"{stem}.png" for stem in stems), COMPARISON_FILE, "report.html"]
    return files


def _written_scenario(directory: str | Path) -> str | None:
    """The name of the scenario whose run ``directory`` holds: the ``scenario`` of the
    ``results.json`` its run manifest lists.

    Parameters
    ----------
    directory : str or Path
        An output directory (need not exist).

    Returns
    -------
    str or None
        The scenario's name; ``None`` when the directory holds no run's ``results.json``
        slewbench wrote, or one that does not name its scenario.
    """
    path = Path(directory).expanduser()
    manifest = read_manifest(path) if path.is_dir() else None
    if manifest is None or manifest.get("kind", "run") != "run" or "results.json" not in manifest["files"]:
        return None
    try:
        name = json.loads((path / "results.json").read_text()).get("scenario")
    except (OSError, ValueError, AttributeError):
        return None
    return name if isinstance(name, str) else None


def check_run_directory(directory: str | Path, scenario: str, expected: list[str] | None = None) -> Path:
    """Every check a run's output directory must pass before the run plans, writing nothing: those
    of :func:`~scenarios.output.directory.check_output_directory`, and that the directory holds no
    run of another scenario (a run replaces only an earlier run of its own scenario, :doc:`/outputs`).

    Parameters
    ----------
    directory : str or Path
        The run's output directory.
    scenario : str
        The name of the scenario about to run.
    expected : list of str, optional
        The files the run may write (:func:`run_files`).

    Returns
    -------
    Path
        The absolute directory.

    Raises
    ------
    OutputError
        The directory is not slewbench's to write, or holds the run of another scenario (its
        ``results.json`` names it).
    """
    target = check_output_directory(directory, "run", expected or ())
    earlier = _written_scenario(target)
    if earlier is not None and earlier != scenario:
        raise OutputError(directory, f"holds the run of scenario {earlier!r}, not {scenario!r}: a run replaces only an "
                                     "earlier run of its own scenario; " + ANOTHER_DIRECTORY + ", or delete that run "
                                     "first (nothing was touched)")
    return target


def write_results(results: RunResults, directory: str | Path, plots: bool = True, renderer: Any = None) -> Path:
    """Write ``results.json/csv/md``, ``timeseries/<row>.csv``, the PNG plots and ``report.html``
    into ``directory``.

    The directory is checked (:func:`check_run_directory`: a directory holding the run of another
    scenario is refused) and claimed first (:func:`~scenarios.output.directory.claimed_output_directory`); the files are staged
    inside it and committed together (:func:`commit_outputs`). A failure or an interruption before
    the commit leaves no new directory behind (the claim is withdrawn: only what it made is
    removed), and an earlier run there as it was.

    Parameters
    ----------
    results : RunResults
        The rows of a scenario run.
    directory : str or Path
        The output directory.
    plots : bool, optional
        Also draw the PNG figures and write the interactive ``report.html``
        (:func:`scenarios.output.report.run.run_report`).
    renderer : scenarios.output.renderer.Renderer, optional
        A plot process to draw them (:mod:`scenarios.output.renderer`); if it fails, they are drawn in this
        process after a one-line notice on stderr. ``None``: drawn in this process.

    Returns
    -------
    Path
        The absolute output directory.

    Raises
    ------
    OutputError
        The directory is not slewbench's to write, or holds the run of another scenario.
    """
    check_run_directory(directory, results.scenario.name)
    # a failure or an interruption before the commit withdraws the claim: a directory this call made
    # (or the marker it put in an empty one) is removed, an earlier run there stays as it was
    with claimed_output_directory(directory) as target:
        staging = new_staging(target)
        try:
            (staging / "results.json").write_text(to_json(results))
            (staging / "results.csv").write_text(to_csv(results))
            (staging / "results.md").write_text(to_markdown(results))
            series = staging / "timeseries"
            series.mkdir()
            stems = row_stems([row.label for row in results.rows])
            for row, stem in zip(results.rows, stems):
                if row.simulation is not None:
                    write_timeseries(row, series / f"{stem}.csv")
            if plots:
                _write_plots(results, staging, stems, renderer)
            commit_outputs(target, staging, kind="run")
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    return target
