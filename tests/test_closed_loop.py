"""The closed loop as one CasADi function (interpreted or compiled) computes what the Python
loop computes: same seeds, same noise, every shipped scenario (issue 13)."""
from pathlib import Path

import numpy as np
import pytest

import ocp.native
from controllers import CONTROLLERS
from ocp import (
    AttitudeModel,
    ReactionWheels,
    SensorNoise,
    SimulationError,
    Simulator,
    Spacecraft,
    Torquers,
    quat,
)
from planners import PLANNERS
from scenarios.schema.loader import load

SCENARIOS = sorted(p for p in Path(__file__).resolve().parents[1].joinpath("scenarios").glob("*.yaml")
                   if not p.name.startswith("study_"))  # trade studies are not scenarios
QUICK = ("eigenaxis_demo.yaml", "nano_eigenaxis_pd.yaml", "biggs_horri_spin_repoint_high.yaml")


def both_paths(scenario, reference, noise, **simulator_options):
    spec, problem = scenario.simulation, scenario.problem
    duration = spec.duration or max(problem.duration, reference.duration if reference else 0.0)
    results = []
    for python_loop in (True, False):
        simulator = Simulator(problem.model, spec.sample_time, spec.integrator, max_step=spec.max_step,
                              python_loop=python_loop, **simulator_options)
        controller = CONTROLLERS[scenario.controller.name](scenario.controller.options)
        results.append(simulator.run(controller, scenario.true_initial_state, duration, reference=reference,
                                     target=(problem.qf, problem.omegaf), noise=noise))
    return results


def assert_same(python, symbolic, tolerance=1e-9):
    assert python.path == "python"
    for name in ("x", "commanded_u", "applied_u", "applied_torque"):
        a, b = getattr(python, name), getattr(symbolic, name)
        assert a.shape == b.shape
        np.testing.assert_allclose(b, a, rtol=0, atol=tolerance, err_msg=name)
    np.testing.assert_array_equal(symbolic.saturated, python.saturated)
    np.testing.assert_array_equal(symbolic.t, python.t)


def check_scenario(path, all_planners):
    scenario = load(path)
    references = [None]
    if scenario.planners:
        references = []
        for spec in scenario.planners if all_planners else scenario.planners[:1]:
            reference = PLANNERS[spec.name](spec.options).plan(scenario.problem)
            if reference.ok:
                references.append(reference)
        assert references, f"no planner of {path.name} succeeded"
    symbolic = CONTROLLERS[scenario.controller.name](scenario.controller.options).symbolic_error() is None
    for reference in references:
        # The scenario's own noise (if any), and a seeded noise on attitude and rate.
        for noise in (scenario.simulation.noise, SensorNoise(np.deg2rad(0.01), 1e-5, seed=7)):
            python, other = both_paths(scenario, reference, noise)
            assert other.path == ("interpreted" if symbolic else "python")
            assert_same(python, other)


@pytest.mark.parametrize("name", QUICK)
def test_symbolic_path_equals_the_python_loop(name):
    check_scenario(next(p for p in SCENARIOS if p.name == name), all_planners=False)


@pytest.mark.slow
@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_symbolic_path_equals_the_python_loop_on_every_shipped_scenario(path):
    check_scenario(path, all_planners=True)


def small_loop(**options):
    """A 40 s regulation with wheels at 1 s samples and one RK4 step per sample (a quick build)."""
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05, max_momentum=0.3))
    simulator = Simulator(AttitudeModel(spacecraft), 1.0, max_step=1.0, **options)
    target = (quat.normalize(np.array([0.6, 0.2, -0.5, 0.3])), None)
    x0 = np.r_[quat.IDENTITY, 0.02, -0.01, 0.0, 0, 0, 0]
    controller = CONTROLLERS["augmented_quaternion_feedback"]({"kp": 0.2, "kd": 0.8})
    return simulator.run(controller, x0, 40.0, target=target, noise=SensorNoise(1e-3, 1e-4, seed=3))


def test_compiled_loop_equals_the_python_loop_and_is_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    python = small_loop(python_loop=True)
    compiled = small_loop(compile=True)
    assert compiled.path == "compiled"
    assert python.saturated.any()  # the wheel limits are exercised
    assert_same(python, compiled)
    libraries = list((tmp_path / "slewbench").glob("*.so"))
    assert len(libraries) == 1
    # The same law and model again: loaded from the cache, the compiler is not run.
    monkeypatch.setattr(ocp.native.subprocess, "run", lambda *a, **k: pytest.fail("rebuilt a cached build"))
    assert_same(python, small_loop(compile=True))


def test_without_a_compiler_the_loop_runs_interpreted_with_a_one_line_notice(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(ocp.native, "find_compiler", lambda: None)
    result = small_loop(compile=True)
    assert result.path == "interpreted"
    notice = capsys.readouterr().err
    assert notice.count("\n") == 1 and "interpreted" in notice and "compiler" in notice
    assert not (tmp_path / "slewbench").exists()


def test_divergence_of_a_symbolic_loop_is_reported():
    spacecraft = Spacecraft([2.0, 3.0, 4.0], torquers=Torquers())
    controller = CONTROLLERS["augmented_quaternion_feedback"]({"kp": 50.0, "kd": 400.0})  # k_d T >> 2
    simulator = Simulator(AttitudeModel(spacecraft), 1.0)
    with pytest.raises(SimulationError, match="non-finite"):
        simulator.run(controller, np.r_[1, 0, 0, 0, 0.1, 0, 0], 100.0, target=(quat.IDENTITY, None))


def test_grid_sampled_reference_is_the_reference(rng):
    from ocp.simulation.simulator import GridSampledReference
    from planners import ManeuverProblem

    problem = ManeuverProblem(Spacecraft([2.0, 3.0, 4.0]), quat.IDENTITY, np.zeros(3), quat.random_unit(rng), 30.0)
    reference = PLANNERS["eigenaxis"]().plan(problem)
    grid = np.arange(31) * 1.0
    served = GridSampledReference(reference, grid)
    assert served.duration == reference.duration and served.planner == "eigenaxis"
    for t in (3.0, np.array([4.0, 5.0]), 2.5, np.array([1.0, 1.5])):  # on and off the grid
        for got, expected in zip(served.sample(t), reference.sample(t)):
            assert np.shape(got) == np.shape(expected)
            np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)
