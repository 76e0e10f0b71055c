"""The closed-loop function is cached per model by its structure (``Simulator.loop_cache``, kept
in the model's SolverCache): a simulator built again on the same model (``scenarios.run`` run
again) builds no closed loop and computes the same numbers; a change of what the build bakes in
(the truth plant's numbers, the integrator, its sub-steps and tolerances, the noise inputs, the
sensors, the law's gains) builds another, whose run equals a run on a model of its own; the store
keeps only the most recent builds, however many laws one model meets; the cache still pickles
empty."""
from __future__ import annotations

import pickle
import threading
from typing import Any

import numpy as np
import pytest

import ocp.native
from controllers import CONTROLLERS
from ocp import AttitudeModel, ReactionWheels, SensorNoise, Simulator, Spacecraft, quat
from ocp.dynamics.truth import Truth, TruthPlant
from ocp.estimation import Gyro, Mekf, SensorSuite, StarTracker

TARGET = (quat.normalize(np.array([0.6, 0.2, -0.5, 0.3])), None)
X0 = np.r_[quat.IDENTITY, 0.02, -0.01, 0.0, 0, 0, 0]
QUIET = SensorNoise(0.0, 0.0, seed=3)


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
        builds = simulator.loop_cache.builds
        results.append(simulator.run(controller, X0, 40.0, target=TARGET, noise=noise))
        loops.append(simulator.closed_loop_function(controller, noise))
    assert simulator.loop_cache.builds == builds  # the second: the loop and its run function found, nothing built
    assert loops[1][0] is loops[0][0] and loops[1][1] is loops[0][1]
    first, second = results
    assert first.path == second.path == "interpreted"
    for name in ("x", "commanded_u", "applied_u", "applied_torque", "saturated"):
        np.testing.assert_array_equal(getattr(second, name), getattr(first, name), err_msg=name)


def _suite(arw: float = 1e-5) -> SensorSuite:
    return SensorSuite(gyro=Gyro(arw=arw, rrw=1e-7), star_tracker=StarTracker(noise=[5e-5, 5e-5, 3e-4]),
                       estimator=Mekf(attitude_sigma=1e-2, bias_sigma=1e-4))


def _flown(model: AttitudeModel, case: dict[str, Any]) -> tuple[Simulator, np.ndarray]:
    """The states of the case's closed loop on ``model``: a run (``Simulator.run``), or, for cvodes
    (whose runs go through the Python loop), 20 samples of its closed-loop function, noise-free."""
    options = dict(case)
    inertia = options.pop("plant", None)
    sensors = options.pop("sensors", None)
    noise = options.pop("noise", SensorNoise(1e-3, 1e-4, seed=3))
    plant = None if inertia is None else TruthPlant(model, Truth(inertia=inertia))
    simulator, controller = _simulator(model, plant=plant, **options)
    if simulator.integrator == "rk4":
        return simulator, simulator.run(controller, X0, 40.0, target=TARGET, noise=noise, sensors=sensors).x
    controller.reset(model.spacecraft, simulator.sample_time, target=TARGET)
    loop, sample, _ = simulator.closed_loop_function(controller, QUIET)
    times = np.arange(21) * simulator.sample_time
    xz = np.concatenate([X0, controller.state_vector()])
    rows = np.hstack([controller.reference_rows(None, times[:-1]),  # the target's rows, as a run takes them
                      controller.reference_rows(None, times[1:])])
    return simulator, loop.evaluate(loop.run_function(sample, 20), xz, times, None, rows, np.zeros(3))[0]


CVODES = {"integrator": "cvodes", "rtol": 1e-10, "atol": 1e-12}
CHANGES = {  # what a build bakes in: a run on one model, then the change on it, against a fresh model
    "sub-steps": ({}, {"max_step": 0.5}),
    "noise inputs": ({}, {"noise": SensorNoise(0.0, 1e-4, seed=3)}),
    "gains": ({}, {"kp": 0.3}),
    "truth plant numbers": ({"plant": [2.0, 3.0, 4.0]}, {"plant": [2.5, 3.0, 4.0]}),  # one moment of inertia
    "a truth plant": ({}, {"plant": [2.5, 3.0, 4.0]}),
    "integrator": ({"noise": QUIET}, CVODES),  # rk4 with one sub-step, then cvodes (noise-free, as its loop)
    "cvodes rtol": (CVODES, {**CVODES, "rtol": 1e-4}),
    "cvodes atol": (CVODES, {**CVODES, "atol": 1e-4}),
    "sensor numbers": ({"noise": QUIET, "sensors": _suite(1e-5)},  # the gyro's noise, the MEKF's with it
                       {"noise": QUIET, "sensors": _suite(3e-3)}),
    "sensors": ({"noise": QUIET}, {"noise": QUIET, "sensors": _suite(1e-5)}),
}


@pytest.mark.parametrize("name", CHANGES)
def test_what_the_build_bakes_in_builds_another(name):
    base, change = CHANGES[name]
    model = _model()
    simulator, first = _flown(model, base)
    builds = simulator.loop_cache.builds
    simulator, changed = _flown(model, change)
    assert simulator.loop_cache.builds > builds, name  # its own loop
    reference = _flown(_model(), change)[1]  # built on a model of its own
    assert not np.array_equal(reference, first), name  # the change shows in the numbers
    np.testing.assert_array_equal(changed, reference, err_msg=name)


def test_the_closed_loops_a_model_keeps_stay_bounded_over_many_laws_and_a_recent_law_still_hits():
    """A gain swept on one simulator (as a study worker's): each law builds its loop and its run
    function; the model keeps at most ``MODEL_BUILDS`` of them (the law's last loops), one store in
    its SolverCache; the last law, run again on a new simulator, builds nothing and repeats its
    numbers; the first, evicted, is built again."""
    model = _model()
    simulator = Simulator(model, 1.0, max_step=1.0)
    laws = 3 * Simulator.MAX_BUILDS
    assert 2 * laws > Simulator.MODEL_BUILDS  # more builds than the store keeps
    runs = [simulator.run(CONTROLLERS["augmented_quaternion_feedback"]({"kp": 0.1 + 0.01 * k, "kd": 0.8}), X0, 40.0,
                          target=TARGET, noise=QUIET).x for k in range(laws)]
    store = simulator.loop_cache
    assert store.builds == 2 * laws
    assert len(store) == Simulator.MODEL_BUILDS and len(model.solver_cache) == 1
    for k, built in ((laws - 1, 0), (0, 2)):
        builds = store.builds
        again = _run(model, kp=0.1 + 0.01 * k, noise=QUIET).x
        assert store.builds == builds + built, k
        np.testing.assert_array_equal(again, runs[k])
    assert len(store) == Simulator.MODEL_BUILDS


def test_each_thread_builds_its_own_closed_loop():
    """The store is the thread's (CasADi functions are not thread-safe): another thread running the
    same law on the same model builds its own loop, and gets the same numbers."""
    model = _model()
    simulator, first = _flown(model, {})
    found: dict[str, Any] = {}

    def other() -> None:
        thread_simulator, found["x"] = _flown(model, {})
        found["store"] = thread_simulator.loop_cache

    thread = threading.Thread(target=other)
    thread.start()
    thread.join()
    assert found["store"] is not simulator.loop_cache and found["store"].builds == 2
    np.testing.assert_array_equal(found["x"], first)


def test_the_cache_pickles_empty_after_a_run():
    model = _model()
    simulator, _ = _flown(model, {})
    assert len(simulator.loop_cache) == 2 and len(model.solver_cache) == 1  # the loop and its run, in the store
    assert len(pickle.loads(pickle.dumps(model.solver_cache))) == 0


def test_a_failed_compile_is_not_kept(tmp_path, monkeypatch, capsys):
    """Without a compiler each run says so and runs interpreted: the failure is not cached."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(ocp.native, "find_compiler", lambda: None)
    model = _model()
    for _ in range(2):
        assert _run(model, compile=True).path == "interpreted"
        assert "interpreted" in capsys.readouterr().err
