"""The interactive ``report.html`` of a run and of a trade study (issue 31, point 3).

Content, without a browser (oracles independent of the page's code):

* the rows table holds exactly the values of ``RunResults.to_dict()`` (read back from the JSON the
  page embeds, each column mapped to the nested row by this test's own reading of the column names),
  and every value of the rows is in it;
* a pointing requirement's margin trace equals the margin computed here from the simulated
  quaternions by plain NumPy (the angle between ``R(q) b`` and the fixed direction, less the cone),
  and ``PointingConstraint.margins`` too, at the samples the trace keeps; the trace keeps the
  worst sample, which equals the row's ``cl.req.<name>.min_margin_deg``;
* every time series holds at most 1000 points, and keeps the extremes of the full series;
* a study's cases table equals ``cases.csv`` as the ``csv`` module reads it;
* the page is self-contained (no script or link loaded from elsewhere, one plotly.js);
* ``report.html`` follows the output directory's ownership rules (manifest, a user's file).

In a real headless browser (Debian's Chromium driven by Selenium, ``tests/browser.py``; skipped with
the reason when the browser, its driver or Selenium is missing; ``.ci/run`` installs them): the page loads with no error
in the browser's console, every figure is drawn (SVG or canvas), the sign-off record's requirement
table shows the scenario's rate bound beside each row's peak rate (the simulated ‖ω‖'s maximum,
computed here), the tables sort on a header click
(the order read back from the page), the study's paged table sorts over all its rows and filters,
and a screenshot is a real picture.
"""
from __future__ import annotations

import csv
import dataclasses
import json
import re
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import scenarios
from ocp import quat
from scenarios.errors import OutputError
from scenarios.output.directory import MARKER, read_manifest
from scenarios.output.report.figures import margin_figure
from scenarios.output.report.run import run_report
from scenarios.output.writer import write_results
from scenarios.study.engine import sweep
from tests.browser import chromium, errors_in, needs_browser, open_page

KEEP_OUT = np.array([-1.0, 1.0, 0.0]) / np.sqrt(2.0)
"""The camera's keep-out direction: where its boresight (body y) points half-way through the slew."""
CONE_DEG = 20.0

SCENARIO = {
    "name": "html-report-test",
    "spacecraft": {"inertia": [10.0, 9.0, 6.0], "wheels": {"max_torque": 0.05, "max_momentum": 1.0},
                   "sensors": {"camera": {"boresight": [0.0, 1.0, 0.0]}}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.70710678, 0, 0, 0.70710678], "omega": [0, 0, 0]}},  # 90 deg about z
    "planners": [{"name": "eigenaxis", "label": "smooth", "options": {"profile": "smooth"}},
                 {"name": "eigenaxis", "label": "bang-bang", "options": {"profile": "min_time", "torque_fraction": 0.8}}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.05, "duration": 70.0},  # 1401 samples: the series are decimated
    "requirements": {"pointing": {"cam_keep_out": {"sensor": "camera", "keep_out": {"inertial": KEEP_OUT.tolist()},
                                                   "angle_deg": CONE_DEG}},
                     "rate": {"max": 0.05}, "final": {"after_s": 5.0, "error_deg": 0.5}},
}


def embedded(html: str) -> dict:
    """The JSON document a page embeds."""
    match = re.search(r'<script type="application/json" id="slewbench-data">(.*?)</script>', html, re.S)
    assert match, "the page embeds no data"
    return json.loads(match.group(1))


def trace_x(trace: dict) -> np.ndarray:
    """A trace's abscissa: ``x``, or ``x0 + k dx``."""
    if "x" in trace:
        return np.array([np.nan if v is None else v for v in trace["x"]], dtype=float)
    return trace["x0"] + trace["dx"] * np.arange(len(trace["y"]))


def closed_loop_trace(figure: dict, label: str) -> dict:
    """The margin figure's closed-loop curve of a row (named ``"<label>: min ..."``)."""
    found = [trace for trace in figure["data"] if trace.get("name", "").startswith(f"{label}: ")
             and trace.get("mode") == "lines"]
    assert len(found) == 1, [trace.get("name") for trace in figure["data"]]
    return found[0]


def trace_y(trace: dict) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in trace["y"]], dtype=float)


@pytest.fixture(scope="module")
def run_results():
    return scenarios.run(scenarios.parse_scenario(SCENARIO))


@pytest.fixture(scope="module")
def run_html(run_results):
    return run_report(run_results)


# ---------------------------------------------------------------- content


def nested_value(row: dict, column: str):
    """The value a column of ``results.csv`` names in ``Row.to_dict()``, read by this test's own
    rule: identity columns as they are; ``ref.``/``cl.`` a metric of ``reference``/``closed_loop``
    (``int_abs_u_x`` the first entry of ``int_abs_u``); ``<scope>.req.<name>.<field>`` a requirement
    score."""
    scopes = {"ref": "reference", "cl": "closed_loop"}
    parts = column.split(".")
    if len(parts) == 1:
        return row[column]
    scope = scopes[parts[0]]
    if parts[1] == "req":
        return ((row["requirements"] or {}).get(scope) or {}).get(parts[2], {}).get(parts[3])
    metrics = row[scope] or {}
    key = parts[1]
    if key not in metrics and key[-2:] in ("_x", "_y", "_z"):
        vector = metrics.get(key[:-2])
        return None if vector is None else vector["xyz".index(key[-1])]
    return metrics.get(key)


def plain(value):
    return None if isinstance(value, float) and not np.isfinite(value) else value


def test_rows_table_holds_exactly_the_rows_values(run_results, run_html):
    table = embedded(run_html)["tables"]["rows"]
    columns = [c["key"] for c in table["columns"]]
    expected = run_results.to_dict()["rows"]
    assert len(table["rows"]) == len(expected) == 2
    for values, row in zip(table["rows"], expected):
        for column, value in zip(columns, values):
            assert value == plain(nested_value(row, column)), column
    # nothing with a value is left out: every metric and requirement field of the rows is a column
    for row in expected:
        for scope, prefix in (("reference", "ref"), ("closed_loop", "cl")):
            for key, value in (row[scope] or {}).items():
                if key == "plan_time_s" or plain(value) is None:
                    continue
                names = [f"{prefix}.{key}_{a}" for a in "xyz"] if isinstance(value, list) else [f"{prefix}.{key}"]
                assert all(name in columns for name in names), names
            for name, fields in ((row["requirements"] or {}).get(scope) or {}).items():
                for field, value in fields.items():
                    if plain(value) is not None:
                        assert f"{prefix}.req.{name}.{field}" in columns
    units = {c["key"]: c["unit"] for c in table["columns"]}
    assert units["cl.final_error_deg"] == "deg" and units["ref.int_u2"] == "N² m² s"
    assert units["cl.req.cam_keep_out.min_margin_deg"] == "deg" and units["plan_time_s"] == "s"
    statuses = [values[columns.index("status")] for values in table["rows"]]
    assert statuses == ["violated", "violated"]  # both cross the keep-out cone


def independent_margin_deg(t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The keep-out margin from first principles: the boresight (body y) in inertial axes is the
    second column of the rotation matrix of q, written out here; its angle from KEEP_OUT (by atan2,
    accurate at any angle) less the cone."""
    q0, q1, q2, q3 = q.T
    boresight = np.stack([2 * (q1 * q2 - q0 * q3), 1 - 2 * (q1**2 + q3**2), 2 * (q2 * q3 + q0 * q1)], axis=1)
    sine = np.linalg.norm(np.cross(boresight, KEEP_OUT), axis=1)
    return np.degrees(np.arctan2(sine, boresight @ KEEP_OUT)) - CONE_DEG


def test_margin_trace_equals_the_margin_of_the_simulated_attitude(run_results, run_html):
    figure = embedded(run_html)["figures"]["margin-0"]
    constraint = run_results.scenario.problem.pointing[0]
    for row in run_results.rows:
        sim = row.simulation
        full = independent_margin_deg(sim.t, sim.q)
        # PointingConstraint takes the angle by arccos, whose rounding error is eps/θ: 4e-8 deg where
        # the boresight passes 3e-7 rad from the direction (the middle of this slew)
        np.testing.assert_allclose(np.degrees(constraint.margins(sim.t, sim.q)), full, rtol=0, atol=1e-7)
        trace = closed_loop_trace(figure, row.label)
        x, y = trace_x(trace), trace_y(trace)
        assert len(y) <= 1001 < len(sim.t)  # decimated (and the scored minimum)
        record = row.requirements["closed_loop"]["cam_keep_out"]
        worst, when = record["min_margin_deg"], record["min_margin_time_s"]
        # the score takes the margin between samples too: the boresight passes through the keep-out
        # direction between two samples (the samples' least margin is 1.7e-5 deg above), where the
        # margin is the cone's -half-angle
        assert worst < full.min() and worst == pytest.approx(-CONE_DEG, abs=1e-6)
        # that scored point is a point of the curve, at its time; the others are samples
        scored = np.flatnonzero(np.isclose(x, when, rtol=5e-7, atol=0) & np.isclose(y, worst, rtol=5e-7, atol=0))
        assert scored.size == 1
        x, y = np.delete(x, scored), np.delete(y, scored)
        index = np.searchsorted(sim.t, x)
        np.testing.assert_allclose(sim.t[index], x, rtol=1e-9, atol=1e-9)
        # 7 significant digits are written (a relative difference below 5e-7) of PointingConstraint's
        # margins (1e-7 deg from the oracle, above)
        np.testing.assert_allclose(y, np.degrees(constraint.margins(sim.t, sim.q))[index], rtol=5e-7, atol=0)
        np.testing.assert_allclose(y, full[index], rtol=5e-7, atol=1e-7)
        assert y.min() == pytest.approx(full.min(), rel=5e-7, abs=1e-7)
        # the legend gives the table's minimum, and the marker sits on it
        assert trace["name"] == f"{row.label}: min {worst:+.4g}° at {when:.4g} s"
        marker = next(t for t in figure["data"] if t.get("name") == f"{row.label} minimum")
        assert marker["x"] == [pytest.approx(when, rel=5e-7)] and marker["y"] == [pytest.approx(worst, rel=5e-7)]
    reference = [trace for trace in figure["data"] if " ref: min " in trace.get("name", "")]
    assert len(reference) == 2
    zero = [trace for trace in figure["data"] if trace.get("name", "").startswith("zero")]
    assert zero and set(zero[0]["y"]) == {0.0}


def test_a_margin_outside_its_window_is_not_drawn(run_results):
    """A requirement that applies from 10 s to 40 s: no point of its margin outside, a break at each end."""
    windowed = dataclasses.replace(run_results.scenario.problem.pointing[0], window=(10.0, 40.0))
    figure = json.loads(json.dumps(margin_figure(windowed, run_results.rows), default=lambda a: a.tolist()))
    trace = closed_loop_trace(figure, run_results.rows[0].label)
    x, y = trace_x(trace), trace_y(trace)
    scored = run_results.rows[0].requirements["closed_loop"]["cam_keep_out"]["min_margin_time_s"]
    keep = ~np.isclose(x, scored, rtol=0, atol=1e-9)  # the scored minimum (of the whole run) is put in
    x, y = x[keep], y[keep]
    drawn = np.isfinite(y)
    assert 10.0 - 1e-9 <= x[drawn].min() < 10.1 and 39.9 < x[drawn].max() <= 40.0 + 1e-9
    assert np.all(np.isnan(y[~drawn]) | ~np.isfinite(x[~drawn]))  # outside: gaps only


def test_time_series_are_decimated_and_keep_their_extremes(run_results, run_html):
    row = run_results.rows[1]
    figure = embedded(run_html)["figures"]["row-1"]
    traces = {trace["name"]: trace for trace in figure["data"]}
    assert all(len(trace["y"]) <= 1000 for trace in figure["data"])
    sim = row.simulation
    for name, full in (("ωx", np.degrees(sim.omega[:, 0])), ("ωz", np.degrees(sim.omega[:, 2])),
                       ("wheel 2", sim.wheel_momentum[:, 2])):
        y = trace_y(traces[name])
        assert len(y) < len(sim.t)
        assert y.max() == pytest.approx(full.max(), rel=5e-7) and y.min() == pytest.approx(full.min(), rel=5e-7)
    error = trace_y(traces["to target"])
    angle = np.degrees(quat.error_angle(sim.q, run_results.scenario.problem.qf))
    assert error[0] == pytest.approx(angle[0], rel=5e-7) and error[0] == pytest.approx(90.0, abs=1e-3)
    # the limits drawn are the scenario's: ±0.05 N m on each wheel axis, ±1 N m s, 0.05 rad/s, 0.5 deg
    limits = {name: trace["y"][0] for name, trace in traces.items() if "limit" in name or "≤" in name}
    assert sorted(limits.values()) == pytest.approx(sorted([0.05, 1.0, np.degrees(0.05), 0.5]), rel=1e-12), limits


def test_the_sky_track_is_the_boresight_direction(run_results, run_html):
    figure = embedded(run_html)["figures"]["sky-0"]
    row = run_results.rows[0]
    track = next(trace for trace in figure["data"] if trace.get("name") == row.label)
    times = np.array([np.nan if v is None else v for v in track["customdata"]])
    keep = np.isfinite(times)
    index = np.searchsorted(row.simulation.t, times[keep])
    direction = quat.rotate(row.simulation.q[index], [0.0, 1.0, 0.0])
    ra = np.degrees(np.arctan2(direction[:, 1], direction[:, 0])) % 360
    dec = np.degrees(np.arcsin(direction[:, 2]))
    shown_ra = np.array(track["text"], dtype=float)[keep] % 360
    np.testing.assert_allclose(np.cos(np.radians(shown_ra - ra)), 1.0, atol=1e-10)
    np.testing.assert_allclose(np.array(track["y"], dtype=float)[keep], dec, atol=1e-5)
    # starts on +Y (RA 90), ends on -X (RA 180): the slew turns the camera by 90 deg about z
    assert shown_ra[0] == pytest.approx(90.0, abs=1e-3) and shown_ra[-1] == pytest.approx(180.0, abs=0.1)


def test_the_page_is_self_contained(run_html):
    assert not re.search(r"<(script|link|img|iframe)\b[^>]*\b(src|href)\s*=", run_html, re.I)  # nothing loaded
    markup = re.sub(r"(<script\b[^>]*>).*?(</script>)", r"\1\2", run_html, flags=re.S | re.I)  # scripts' text out
    assert len(markup) < len(run_html) / 50
    assert not re.search(r"\b(src|href)\s*=\s*[\"']?\s*(https?:)?//", markup, re.I)
    assert run_html.count("plotly.js v") == 1  # one copy of plotly.js
    data = embedded(run_html)
    assert set(data["figures"]) == {"row-0", "row-1", "margin-0", "sky-0"}
    assert data["choices"]["attitude"]["names"] == ["smooth", "bang-bang"]
    frames = data["choices"]["attitude"]["figures"][0]["frames"]
    assert 2 <= len(frames) <= 100


def test_the_written_report_follows_the_output_rules(run_results, tmp_path):
    out = tmp_path / "run"
    write_results(run_results, out, plots=True)
    manifest = read_manifest(out)
    assert manifest["complete"] and "report.html" in manifest["files"] and (out / "report.html").is_file()
    assert embedded((out / "report.html").read_text(encoding="utf-8"))["tables"]["rows"]["rows"]
    write_results(run_results, out, plots=False)  # without plots: no report, and none left behind
    assert not (out / "report.html").exists() and "report.html" not in read_manifest(out)["files"]
    # a user's report.html in slewbench's directory is never replaced
    (out / "report.html").write_text("mine")
    with pytest.raises(OutputError, match="report.html"):
        write_results(run_results, out, plots=True)
    assert (out / "report.html").read_text() == "mine"
    assert "report.html" not in read_manifest(out)["files"]
    # nor is a directory of a user's files claimed
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "report.html").write_text("mine")
    with pytest.raises(OutputError):
        write_results(run_results, foreign, plots=True)
    assert (foreign / "report.html").read_text() == "mine" and not (foreign / MARKER).exists()


STUDY = {"study": "html-study-test", "scenario": {k: v for k, v in SCENARIO.items() if k != "requirements"},
         "grid": {"planners[0].options.profile": ["smooth", "trapezoidal"]},
         "monte_carlo": {"samples": 30, "seed": 7, "dispersions": {
             "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [0.5, 0.5, 0.5]}}}},
         "summary": ["cl.final_error_deg", "cl.int_u"]}


def test_arrays_rounded_together_are_each_array_rounded_alone(rng):
    """The report's arrays are rounded in one batch (figure_arrays): each comes back in its own
    shape, to seven significant digits of its own values (checked against the decimal rounding
    of Python's formatting), None exactly where it is not finite, as figure_array gives it alone."""
    from scenarios.output.report.page import FIGURE_DIGITS, figure_array, figure_arrays

    arrays = [rng.normal(size=2) * 10.0 ** rng.integers(-12, 12), np.array([0.0, np.nan, -np.inf, 1e-300]),
              rng.normal(size=(3, 4)) * 1e5, np.empty(0), np.array(7.0), np.full((2, 2), np.inf),
              rng.normal(size=61), [1.0, 2.5], np.arange(5)]
    together = figure_arrays(arrays)
    assert together == [figure_array(a) for a in arrays]
    for values, plain in zip(arrays, together):
        values = np.asarray(values, dtype=float)
        flat = np.asarray(plain, dtype=object).ravel().tolist() if values.ndim else [plain]
        assert np.shape(np.asarray(plain, dtype=object)) == values.shape
        for value, kept in zip(values.ravel().tolist(), flat):
            if not np.isfinite(value):
                assert kept is None
            else:  # within half a unit of the seventh significant digit, and that decimal itself
                assert kept == pytest.approx(float(f"{value:.{FIGURE_DIGITS}g}"), rel=1e-15, abs=0.0)


@pytest.fixture(scope="module")
def study_out(tmp_path_factory):
    study = json.loads(json.dumps(STUDY))
    study["scenario"]["planners"] = study["scenario"]["planners"][:1]
    study["scenario"]["simulation"] = {"sample_time": 0.5, "duration": 70.0}
    with ThreadPoolExecutor(1) as pool:
        results = sweep(study, pool)
    out = tmp_path_factory.mktemp("study")
    results.write(out, plots=True)
    return out


def test_the_study_cases_table_equals_cases_csv(study_out):
    data = embedded((study_out / "report.html").read_text(encoding="utf-8"))
    table = data["tables"]["cases"]
    columns = [c["key"] for c in table["columns"]]
    with (study_out / "cases.csv").open(newline="") as handle:
        lines = list(csv.DictReader(handle))
    assert len(table["rows"]) == len(lines) == 60
    for values, line in zip(table["rows"], lines):
        for column, value in zip(columns, values):
            text = line[column]
            if value is None:
                assert text == "", column
            elif isinstance(value, list):  # a dispersed vector
                assert value == json.loads(text), column
            elif isinstance(value, bool):  # a requirement's verdict
                assert str(value) == text, column
            elif isinstance(value, (int, float)):
                assert value == float(text), column
            else:
                assert value == text, column
    # the columns left out have no value in any case
    for column in set(lines[0]) - set(columns):
        assert all(line[column] == "" for line in lines), column
    with (study_out / "requirements.csv").open(newline="") as handle:
        requirements = list(csv.DictReader(handle))
    shown = data["tables"]["requirements"]
    keys = [c["key"] for c in shown["columns"]]
    assert [[str(v) if not isinstance(v, float) else v for v in row] for row in shown["rows"]] == [
        [float(line[k]) if k.startswith(("fraction", "wilson")) else line[k] for k in keys] for line in requirements]
    assert {f"histogram-{k}" for k in range(2)} == set(data["figures"])
    # each row label's histogram counts its cases, over bins spanning its values
    for k, column in enumerate(STUDY["summary"]):
        for trace in data["figures"][f"histogram-{k}"]["data"]:
            label = trace["name"].rsplit(" (", 1)[0]
            mine = [float(line[column]) for line in lines if line["label"] == label and line[column] != ""]
            assert sum(trace["y"]) == len(mine) == 60 and trace["y"][0] == trace["y"][-1] == 0
            assert trace["x"][0] == pytest.approx(min(mine), rel=1e-6) and trace["x"][-1] == pytest.approx(max(mine), rel=1e-6)
    assert data["explorers"]["explorer"]["x"] == "simulation.initial_attitude_error_deg[0]"


# ---------------------------------------------------------------- in a browser


@pytest.fixture(scope="module")
def browser():
    with chromium() as driver:
        yield driver


def column_order(driver, table: str, column: str) -> list:
    """The values of ``column`` in the rows the page shows, in their order (read from the page's data
    through the rows' indices)."""
    return driver.execute_script(
        "var spec = window.slewbench.data.tables[arguments[0]];"
        "var j = spec.columns.map(function (c) { return c.key; }).indexOf(arguments[1]);"
        "return Array.prototype.map.call(document.querySelectorAll('#' + arguments[0] + ' tbody tr'),"
        "  function (tr) { return spec.rows[Number(tr.dataset.row)][j]; });", table, column)


def click_header(driver, table: str, column: str) -> str:
    header = driver.find_element("css selector", f'#{table} th[data-column="{column}"]')
    header.click()
    return header.get_attribute("aria-sort")


def figures_drawn(driver) -> dict[str, int]:
    return driver.execute_script(
        "var out = {}; document.querySelectorAll('.sb-figure').forEach(function (e) {"
        "  out[e.id] = e.querySelectorAll('svg.main-svg').length + e.querySelectorAll('canvas').length; });"
        "return out;")


def check_screenshot(driver, path: Path) -> None:
    from PIL import Image

    driver.save_screenshot(str(path))
    assert path.stat().st_size > 20_000
    image = np.asarray(Image.open(path).convert("L"), dtype=float)
    assert image.shape[0] > 500 and image.std() > 10  # not a blank page


@pytest.fixture(scope="module")
def run_page(run_html, tmp_path_factory) -> Path:
    """The run's ``report.html``, written once for the browser tests."""
    page = tmp_path_factory.mktemp("run-report") / "report.html"
    page.write_text(run_html, encoding="utf-8")
    return page


@needs_browser
def test_the_run_report_in_a_browser(browser, run_results, run_page, tmp_path):
    page = run_page
    log = open_page(browser, page)
    assert not errors_in(log), errors_in(log)
    drawn = figures_drawn(browser)
    assert set(drawn) == {"row-0", "row-1", "margin-0", "sky-0", "attitude"} and all(drawn.values()), drawn
    assert browser.get_window_size()["width"] == 1400  # the wide window of the layout check
    assert_titles_and_buttons_clear(browser)
    assert browser.execute_script("return document.querySelector('#attitude canvas') !== null")  # the 3-D scene
    column = "cl.int_u"
    assert click_header(browser, "rows", column) == "ascending"
    values = column_order(browser, "rows", column)
    assert values == sorted(values) and values[0] < values[1]
    assert click_header(browser, "rows", column) == "descending"
    assert column_order(browser, "rows", column) == sorted(values, reverse=True)
    assert column_order(browser, "rows", "label") in (["smooth", "bang-bang"], ["bang-bang", "smooth"])
    # the sign-off record is drawn: the rate bound of the scenario beside each row's peak rate
    cells = browser.execute_script(
        "return Array.from(document.querySelectorAll('#requirement-scores tbody tr')).map("
        "function (tr) { return Array.from(tr.cells).map(function (td) { return td.textContent; }); });")
    rates = [cells_ for cells_ in cells if cells_[1:4] == ["closed loop", "rate", "peak_rate"]]
    assert [cells_[0] for cells_ in rates] == ["smooth", "bang-bang"] and all(c[5] == "≤ 0.05" for c in rates)
    for cells_, row in zip(rates, run_results.rows):
        peak = np.max(np.linalg.norm(row.simulation.omega, axis=1))
        assert float(cells_[6]) == pytest.approx(peak, rel=1e-3)  # shown with 4 significant digits
    # the second row's 3-D view replaces the first without an error
    from selenium.webdriver.support.ui import Select

    Select(browser.find_element("id", "attitude-choice")).select_by_index(1)
    time.sleep(0.5)
    assert "bang-bang" in browser.execute_script("return document.querySelector('#attitude .gtitle').textContent")
    assert not errors_in(browser.get_log("browser"))
    check_screenshot(browser, tmp_path / "run.png")


@needs_browser
def test_the_run_reports_verdicts_read_as_in_results_csv(browser, run_results, run_page, tmp_path):
    """The per-requirement verdicts (``<scope>.req.<name>.met``, bools) are shown in the page's rows
    table as ``results.csv`` writes them (``True``/``False``, read back by the ``csv`` module), not as
    JSON's ``true``/``false``."""
    write_results(run_results, tmp_path / "run", plots=False)
    with open(tmp_path / "run" / "results.csv", newline="", encoding="utf-8") as handle:
        csv_rows = list(csv.DictReader(handle))
    verdicts = [column for column in csv_rows[0] if column.count(".") == 3 and column.endswith(".met")]
    assert {"ref.req.cam_keep_out.met", "cl.req.cam_keep_out.met", "cl.req.rate.met"} <= set(verdicts)
    if browser.current_url != run_page.resolve().as_uri():  # else shown by the test above: the
        open_page(browser, run_page)  # cells are read by row index, whichever order it sorted them in
    cells = browser.execute_script(
        "var keys = window.slewbench.data.tables.rows.columns.map(function (c) { return c.key; });"
        "return Array.prototype.map.call(document.querySelectorAll('#rows tbody tr'), function (tr) {"
        "  var out = {}; Array.prototype.forEach.call(tr.cells, function (td, j) { out[keys[j]] = td.textContent; });"
        "  return [Number(tr.dataset.row), out]; });")
    assert len(cells) == len(csv_rows) == 2
    shown = set()
    for index, texts in cells:
        for column in verdicts:
            assert texts[column] == csv_rows[index][column], (index, column)
            shown.add(texts[column])
    assert shown == {"True", "False"}  # both verdicts occur (the keep-out is broken, not every requirement)


@needs_browser
def test_the_study_report_in_a_browser(browser, study_out, tmp_path):
    log = open_page(browser, study_out / "report.html")
    assert not errors_in(log), errors_in(log)
    drawn = figures_drawn(browser)
    assert set(drawn) == {"histogram-0", "histogram-1", "explorer"} and all(drawn.values()), drawn
    column = "cl.final_error_deg"
    values = driver_values(browser, "cases", column)
    assert len(values) == 60 and len(column_order(browser, "cases", column)) == 50  # one page of 50 rows
    # sorting orders every row, not the page shown: page 1 holds the 50 smallest, page 2 the rest
    assert click_header(browser, "cases", column) == "ascending"
    assert column_order(browser, "cases", column) == sorted(values)[:50]
    pager = browser.find_elements("css selector", "#cases .sb-pager button")
    pager[2].click()  # next page
    assert column_order(browser, "cases", column) == sorted(values)[50:]
    assert click_header(browser, "cases", column) == "descending"
    assert column_order(browser, "cases", column) == sorted(values, reverse=True)[:50]
    # the filter keeps the rows that mention the text
    search = browser.find_element("css selector", "#cases input[type=search]")
    search.send_keys("trapezoidal")
    kept = column_order(browser, "cases", "planners[0].options.profile")
    assert kept == ["trapezoidal"] * 30
    check_screenshot(browser, tmp_path / "study.png")


def driver_values(driver, table: str, column: str) -> list:
    return driver.execute_script(
        "var spec = window.slewbench.data.tables[arguments[0]];"
        "var j = spec.columns.map(function (c) { return c.key; }).indexOf(arguments[1]);"
        "return spec.rows.map(function (row) { return row[j]; });", table, column)


OVERLAPS = """
function box(e) { var r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; }
function meet(a, b) { return a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]; }
var out = [];
document.querySelectorAll('.sb-figure').forEach(function (figure) {
  var title = figure.querySelector('.gtitle'), bar = figure.querySelector('.modebar');
  if (title && bar && meet(box(title), box(bar))) { out.push(figure.id + ': the title under the mode bar'); }
  if (title && box(title)[0] < box(figure)[0] - 1) { out.push(figure.id + ': the title runs off the figure'); }
  figure.querySelectorAll('.updatemenu-button').forEach(function (button) {
    figure.querySelectorAll('.slider-label').forEach(function (label) {
      if (meet(box(button), box(label))) { out.push(figure.id + ': a button over the slider label ' + label.textContent); }
    });
  });
  var slider = figure.querySelector('.slider-container');
  if (slider && box(slider)[3] > box(figure)[3] + 1) { out.push(figure.id + ': the slider runs below the figure'); }
});
return out;
"""


def assert_titles_and_buttons_clear(driver) -> None:
    """No figure's title lies under plotly's mode bar (top right) or runs off the figure, the 3-D
    view's play and pause buttons cover none of its slider's labels, and the slider lies within the
    figure's element (the page just opened)."""
    time.sleep(0.5)
    assert driver.execute_script("return document.querySelectorAll('.sb-figure .modebar').length") >= 4
    assert driver.execute_script("return document.querySelectorAll('#attitude .slider-label').length") >= 5
    assert driver.execute_script(OVERLAPS) == []


@needs_browser
def test_titles_clear_the_mode_bar_and_the_buttons_clear_the_slider_in_a_narrow_window(browser, run_html, tmp_path):
    """As in a wide window (1400 px, checked on the page of ``test_the_run_report_in_a_browser``),
    at 800 px."""
    page = tmp_path / "report.html"
    page.write_text(run_html, encoding="utf-8")
    browser.set_window_size(800, 1000)
    try:
        open_page(browser, page)
        assert_titles_and_buttons_clear(browser)
    finally:
        browser.set_window_size(1400, 1000)
