"""An exported AEM a consumer can trust at a rate jump and trace to its run.

* A reference whose body rate jumps (natural motion's step stop) is written as one segment per
  stretch between its jumps: no segment's span holds the jump inside it, the last row before the
  jump carries the rate the reference has on that side and the first row after it the rate on its
  side (the planner's own one-sided values, :meth:`planners.Reference.breakpoint_sides`, and the
  scenario's final rate, zero), and the independent reader ``ccsds-ndm-py`` reads the segments;
  a reference whose rate does not jump (a bang-bang eigenaxis slew, whose ω̇ does) stays one
  segment, and so does every closed loop.
* The header comments name the run directory, the seed and each dispersed truth value, as the
  scenario states them.
"""
from __future__ import annotations

import datetime

import numpy as np
import pytest

import scenarios
from scenarios.output.aem import rate_jump_starts, read_aem
from scenarios.output.export import export_run
from scenarios.output.writer import write_results

EPOCH = datetime.datetime(2027, 3, 20, 12)
SEED = 31337
TRUTH_INERTIA = [[0.0112, 0.0003, 0.0], [0.0003, 0.049, 0.0], [0.0, 0.0, 0.051]]
SCENARIO = {  # nano_natural_vs_eigenaxis.yaml with an epoch, a truth model and a seed
    "name": "aem-jump-test",
    "epoch": "2027-03-20T12:00:00Z",
    "spacecraft": {"inertia": [0.0109, 0.05, 0.05], "wheels": {"max_torque": 0.01}},
    "maneuver": {"quaternion_order": "scalar_last", "duration": 110.0,
                 "initial": {"q": [0, 0, 0, 1], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0.5, 0.5, 0.5], "omega": [0, 0, 0]}},
    "planners": [{"name": "natural_motion", "label": "natural", "options": {"stop_time": 10.0, "stop": "step"}},
                 {"name": "eigenaxis", "label": "bang", "options": {"profile": "min_time", "torque_fraction": 0.8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 1.0, "kd": 1.6}},
    "truth": {"spacecraft": {"inertia": TRUTH_INERTIA}},
    "simulation": {"sample_time": 0.1, "sensor_noise": {"seed": SEED}},
}


def seconds(tag: str) -> float:
    """Seconds from the epoch of a UTC time tag (nanosecond digits; no leap second in this run)."""
    day, fraction = tag.split(".")
    return (datetime.datetime.fromisoformat(day) - EPOCH).total_seconds() + float("0." + fraction)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    results = scenarios.run(scenarios.parse_scenario(SCENARIO))
    out = tmp_path_factory.mktemp("aem") / "run"
    write_results(results, out, plots=False)
    report = export_run(out, "aem")
    return results, out, report.directory


def test_the_reference_is_split_at_its_rate_jump(exported):
    results, _, directory = exported
    reference = results.rows[0].reference
    (jump,) = reference.breakpoints  # natural motion's step stop, at 100 s
    segments = read_aem((directory / "natural.reference.aem").read_text()).segments
    assert len(segments) == 2
    spans = [(seconds(s.metadata["START_TIME"]), seconds(s.metadata["STOP_TIME"])) for s in segments]
    for segment, (start, stop) in zip(segments, spans):
        assert (seconds(segment.metadata["USEABLE_START_TIME"]), seconds(segment.metadata["USEABLE_STOP_TIME"])) \
            == (start, stop)
        assert (seconds(segment.epochs[0]), seconds(segment.epochs[-1])) == (start, stop)
        assert not start < jump < stop  # no segment holds the jump inside its span
    assert spans[0][1] <= jump <= spans[1][0] and spans[1][0] - spans[0][1] == pytest.approx(0.1, abs=1e-9)
    _, sides = reference.breakpoint_sides()
    before, after = np.split(sides.omega, 2)
    assert np.linalg.norm(after[0] - before[0]) > 0.02  # the jump: 0.0217 rad/s
    last, first = np.radians(segments[0].values[-1, 4:]), np.radians(segments[1].values[0, 4:])
    assert spans[0][1] == pytest.approx(jump, abs=1e-9)  # the sample at the jump holds the rate before it
    np.testing.assert_allclose(last, before[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(first, after[0], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(first, np.zeros(3))  # at rest after the stop: the scenario's final rate


def test_a_rate_that_does_not_jump_stays_one_segment(exported):
    _, _, directory = exported
    for name in ("natural.closed_loop.aem", "bang.reference.aem", "bang.closed_loop.aem"):
        assert len(read_aem((directory / name).read_text()).segments) == 1, name


def test_the_independent_reader_reads_the_segments(exported):
    ndm = pytest.importorskip("ccsds_ndm", reason="ccsds-ndm-py (the `test` extra) reads AEMs independently")
    _, _, directory = exported
    message = ndm.from_str((directory / "natural.reference.aem").read_text())
    message.validate()
    first, second = message.segments
    assert first.metadata.stop_time < second.metadata.start_time
    assert first.data.attitude_states_epochs[-1] == first.metadata.stop_time
    assert second.data.attitude_states_epochs[0] == second.metadata.start_time
    np.testing.assert_array_equal(second.data.attitude_states_numpy[0, 4:], np.zeros(3))


def test_the_header_traces_the_run_its_seed_and_its_truth(exported):
    _, out, directory = exported
    comments = read_aem((directory / "natural.reference.aem").read_text()).comments
    assert f"run directory {out.absolute()}" in comments
    assert f"provenance seeds.simulation.sensor_noise.seed = {SEED}" in comments
    for i, row in enumerate(TRUTH_INERTIA):
        assert f"truth.spacecraft.inertia[{i}] = {row}" in comments
    assert all(len(line) <= 240 for line in comments)


def test_jump_starts_from_samples_and_from_a_recorded_time():
    t = np.arange(0.0, 10.01, 0.5)
    omega_dot = np.tile([1e-4, 0.0, 0.0], (t.size, 1))  # a steady spin-up (5e-5 rad/s a step) ...
    omega = t[:, None] * omega_dot
    omega[t > 4.0] += [0.0, 1e-3, 0.0]  # ... with a jump of 1e-3 rad/s after t = 4 s
    assert rate_jump_starts(t, omega, omega_dot) == [9]
    assert rate_jump_starts(t, omega, None) == [9]  # the derivative from the neighbouring steps
    smooth = t[:, None] * omega_dot
    assert rate_jump_starts(t, smooth, omega_dot) == []
    # a jump smaller than what ω̇ explains over a step is found only from its recorded time, on the
    # side of the larger change: the sample at 4 s holds the rate before it
    small = smooth.copy()
    small[t > 4.0] += [5e-5, 0.0, 0.0]
    assert rate_jump_starts(t, small, omega_dot) == []
    assert rate_jump_starts(t, small, omega_dot, [4.0]) == [9]
    assert rate_jump_starts(t, small, omega_dot, [4.2]) == [9]
    assert rate_jump_starts(t, small, omega_dot, [0.0, 11.0, float("nan")]) == []


def test_segments_of_aem_text_and_a_segment_of_one_sample():
    """A stop at the last sample interval (natural motion stopped at T between samples) leaves a
    one-line segment: both readers read it, its span is its one time tag."""
    from scenarios.output.aem import aem_text

    t = np.arange(6) * 0.5
    q = np.tile([1.0, 0.0, 0.0, 0.0], (6, 1))
    omega = np.zeros((6, 3))
    omega[:5, 2] = 0.01  # at rest from the last sample on
    text = aem_text("2027-03-20T12:00:00Z", t, q, omega, object_name="x", segment_starts=[5])
    first, second = read_aem(text).segments
    assert (len(first.epochs), len(second.epochs)) == (5, 1)
    # degree + 1 lines to interpolate over: the 5-line segment keeps degree 3, the one line has none
    assert first.metadata["INTERPOLATION_DEGREE"] == "3" and "INTERPOLATION_DEGREE" not in second.metadata
    split = read_aem(aem_text("2027-03-20T12:00:00Z", t, q, omega, object_name="x", segment_starts=[4])).segments
    assert [segment.metadata["INTERPOLATION_DEGREE"] for segment in split] == ["3", "1"]  # 4 lines, 2
    assert second.metadata["START_TIME"] == second.metadata["STOP_TIME"] == second.epochs[0] \
        == "2027-03-20T12:00:02.500000000"
    np.testing.assert_array_equal(np.radians(first.values[-1, 4:]), [0.0, 0.0, 0.01])
    np.testing.assert_array_equal(second.values[0, 4:], [0.0, 0.0, 0.0])
    ndm = pytest.importorskip("ccsds_ndm", reason="ccsds-ndm-py (the `test` extra) reads AEMs independently")
    message = ndm.from_str(text)
    message.validate()
    assert [len(s.data.attitude_states_epochs) for s in message.segments] == [5, 1]
    for bad in ([0], [6]):
        with pytest.raises(ValueError, match="segment starts"):
            aem_text("2027-03-20T12:00:00Z", t, q, omega, object_name="x", segment_starts=bad)
