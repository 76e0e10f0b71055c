"""The closed-loop function is cached in the model's SolverCache by its structure: a simulator built
again on the same model (``scenarios.run`` run again) builds no closed loop and computes the same
numbers; a change of what the build bakes in (the hold's sub-steps, the noise inputs, the law's
gains) builds another; the cache still pickles empty."""
from __future__ import annotations

import pickle

import numpy as np

import ocp.simulation.compiled
from controllers import CONTROLLERS
from ocp import AttitudeModel, ReactionWheels, SensorNoise, Simulator, Spacecraft, quat

TARGET = (quat.normalize(np.array([0.6, 0.2, -0.5, 0.3])), None)
X0 = np.r_[quat.IDENTITY, 0.02, -0.01, 0.0, 0, 0, 0]


def _model() -> AttitudeModel:
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05, max_momentum=0.3))
    return AttitudeModel(spacecraft)


def _simulator(model: AttitudeModel, max_step: float = 1.0, kp: float = 0.2, **options):
    simulator = Simulator(model, 1.0, max_step=max_step, **options)
    return simulator, CONTROLLERS["augmented_quaternion_feedback"]({"kp": kp, "kd": 0.8})


def _run(model: AttitudeModel, max_step: float = 1.0, noise: SensorNoise | None = None, kp: float = 0.2,
         **options):
    simulator, controller = _simulator(model, max_step, kp, **options)
    return simulator.run(controller, X0, 40.0, target=TARGET,
                         noise=noise if noise is not None else SensorNoise(1e-3, 1e-4, seed=3))


def test_a_second_simulator_on_the_same_model_builds_no_closed_loop():
    model = _model()
    noise = SensorNoise(1e-3, 1e-4, seed=3)
    results, loops = [], []
    for _ in range(2):
        simulator, controller = _simulator(model)
        builds = model.solver_cache.builds
        results.append(simulator.run(controller, X0, 40.0, target=TARGET, noise=noise))
        loops.append(simulator.closed_loop_function(controller, noise))
    assert model.solver_cache.builds == builds  # the second: the loop and its run function found, nothing built
    assert loops[1][0] is loops[0][0] and loops[1][1] is loops[0][1]
    first, second = results
    assert first.path == second.path == "interpreted"
    for name in ("x", "commanded_u", "applied_u", "applied_torque", "saturated"):
        np.testing.assert_array_equal(getattr(second, name), getattr(first, name), err_msg=name)


def test_what_the_build_bakes_in_builds_another():
    model = _model()
    _run(model)
    for change in ({"max_step": 0.5}, {"noise": SensorNoise(0.0, 1e-4, seed=3)}, {"kp": 0.3}):
        builds = model.solver_cache.builds
        changed = _run(model, **change)
        assert model.solver_cache.builds == builds + 2, change  # its loop and its run function
        reference = _run(_model(), **change)  # built on a model of its own
        np.testing.assert_array_equal(changed.x, reference.x, err_msg=str(change))


def test_the_cache_pickles_empty_after_a_run():
    model = _model()
    _run(model)
    assert len(model.solver_cache) >= 2
    assert len(pickle.loads(pickle.dumps(model.solver_cache))) == 0


def test_a_failed_compile_is_not_kept(tmp_path, monkeypatch, capsys):
    """Without a compiler each run says so and runs interpreted: the failure is not cached."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(ocp.simulation.compiled, "find_compiler", lambda: None)
    model = _model()
    for _ in range(2):
        assert _run(model, compile=True).path == "interpreted"
        assert "interpreted" in capsys.readouterr().err
