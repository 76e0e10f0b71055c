"""Cross-check of slewbench against Basilisk (needs the ``basilisk`` extra; skipped without it).

The law at one sample (fast): ``mrp_feedback`` against a transcription of Basilisk's C (no
Basilisk needed) and against Basilisk's own modules. The closed loops (slow):

One reference, two closed loops. slewbench: the scenario's model, the ``mrp_feedback`` law, the
zero-order hold at the scenario's sample time, RK4. Basilisk (AVS Lab, PyPI ``bsk``): a spacecraft
hub with balanced reaction wheels (``reactionWheelStateEffector``: the scenario's axes and torque
limits), ``simpleNav`` without noise, the reference read from the file slewbench exports
(``waypointReference``), ``attTrackingError``, ``mrpFeedback`` (``K``, ``P``, ``Ki = −1``: no
integral term) and ``rwMotorTorque`` (the body axes), the flight software in a task at the sample
time, the dynamics (RK4) in a task of its own at the integration step.

The equivalences the comparison relies on (``docs/guide/controllers.rst``, "Basilisk cross-check"):

* slewbench's inertia excludes the wheels' spin inertia about their axes; Basilisk's hub inertia of
  balanced wheels includes it: ``I_hub = I + Σ J_s ĝ ĝᵀ``, while ``mrpFeedback`` is given ``I``.
  Then both integrate ``I ω̇ = −ω × (I ω + A h_w) − A g`` with ``h_w = J_s (ĝᵀ ω + Ω)`` and
  ``ḣ_w = g``, whatever ``J_s`` is;
* the wheels clip their torque at the limit in both; the momentum limit is slewbench's alone, so the
  cases keep below it (asserted);
* the flight software samples at the waypoints, where ``waypointReference``'s linear interpolation
  returns the waypoints themselves (``tests/test_waypoint_export.py`` checks it with Basilisk's
  reader): the reference contributes no error.

What is left is the integrators': both are RK4 at the same step, on different variables
(quaternion and wheel momenta; MRPs and wheel speeds), so each has its own O(h⁴) error and the two
closed loops differ by at most the sum. The tolerance is that sum, measured: each simulator is run
again at half the step, and Richardson's estimate of its error is ``16/15`` of the change; the
bound is twice the sum of the two estimates (the factor covers the estimate's own error) plus
1e-12 (rounding over ~10⁴ steps). The difference must also fall with the step, by at least 8 when
the step halves (16 for fourth order), which a modelling difference would not do.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
import yaml

from controllers.tracking.mrp_feedback import MRPFeedback
from ocp import Measurement, ReactionWheels, Simulator, Spacecraft, quat
from scenarios.output.basilisk import write_waypoint_reference
from scenarios.schema.loader import Scenario, parse_scenario

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
MAX_RW = 36  # Basilisk's MAX_EFF_CNT: the size of its RW configuration arrays
NOMINAL_SPIN_INERTIA = 0.05  # kg m²: for wheels without one (any value gives the same motion, see above)
ROUNDING = 1e-12


@dataclass
class Loop:
    """A closed loop at the sample times: attitude, rate, wheel momenta, and its wall time."""

    t: np.ndarray
    q: np.ndarray
    omega: np.ndarray
    h: np.ndarray
    seconds: float


def scenario(name: str, edit: Any = None) -> Scenario:
    data = yaml.safe_load((SCENARIOS / name).read_text())
    if edit is not None:
        edit(data)
    return parse_scenario(data, SCENARIOS / name)


def short_mrp(q: np.ndarray) -> np.ndarray:
    q = q if q[0] >= 0 else -q
    return q[1:] / (1 + q[0])


def fly_slewbench(case: Scenario, reference: Any, gains: dict[str, float], step: float, duration: float) -> Loop:
    simulator = Simulator(case.problem.model, case.simulation.sample_time, "rk4", max_step=step)
    start = time.perf_counter()
    result = simulator.run(MRPFeedback(gains), case.true_initial_state, duration, reference=reference,
                           target=(case.problem.qf, case.problem.omegaf))
    return Loop(result.t, result.q, result.omega, result.wheel_momentum, time.perf_counter() - start)


def basilisk() -> SimpleNamespace:
    """Basilisk's modules, or a skip saying why."""
    pytest.importorskip("Basilisk", reason="the Basilisk cross-check needs bsk from PyPI (the 'basilisk' extra)")
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import (
        attTrackingError,
        mrpFeedback,
        rwMotorTorque,
        waypointReference,
    )
    from Basilisk.simulation import reactionWheelStateEffector, simpleNav, spacecraft
    from Basilisk.utilities import SimulationBaseClass, macros

    return SimpleNamespace(messaging=messaging, attTrackingError=attTrackingError, mrpFeedback=mrpFeedback,
                           rwMotorTorque=rwMotorTorque, waypointReference=waypointReference,
                           reactionWheelStateEffector=reactionWheelStateEffector, simpleNav=simpleNav,
                           spacecraft=spacecraft, SimulationBaseClass=SimulationBaseClass, macros=macros)


def fly_basilisk(case: Scenario, reference: Any, gains: dict[str, float], step: float, duration: float,
                 path: Path) -> Loop:
    bsk = basilisk()
    messaging, macros = bsk.messaging, bsk.macros
    spacecraft_model = case.problem.spacecraft
    wheels = spacecraft_model.wheels
    axes = np.asarray(wheels.axes, dtype=float)
    n = axes.shape[1]
    spin = np.full(n, NOMINAL_SPIN_INERTIA) if wheels.spin_inertia is None else np.asarray(wheels.spin_inertia)
    inertia = np.asarray(spacecraft_model.inertia, dtype=float)
    x0 = case.true_initial_state
    q0, omega0, h0 = x0[:4], x0[4:7], x0[7:7 + n]
    sample_time = case.simulation.sample_time
    times = np.arange(round(duration / sample_time) + 1) * sample_time
    waypoints = write_waypoint_reference(reference, times, path)

    sim = bsk.SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("dynamics", 20).addTask(sim.CreateNewTask("dynamicsTask", macros.sec2nano(step)))
    sim.CreateNewProcess("fsw", 10).addTask(sim.CreateNewTask("fswTask", macros.sec2nano(sample_time)))
    hub = bsk.spacecraft.Spacecraft()
    hub.ModelTag = "spacecraft"
    hub_inertia = inertia + sum(spin[i] * np.outer(axes[:, i], axes[:, i]) for i in range(n))
    hub.hub.IHubPntBc_B = hub_inertia.tolist()
    hub.hub.mHub = 100.0
    hub.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
    hub.hub.sigma_BNInit = [[v] for v in short_mrp(q0)]
    hub.hub.omega_BN_BInit = [[v] for v in omega0]
    effector = bsk.reactionWheelStateEffector.ReactionWheelStateEffector()
    effector.ModelTag = "wheels"
    for i in range(n):
        wheel = bsk.reactionWheelStateEffector.RWConfigPayload()
        axis = axes[:, i]
        transverse = np.cross(axis, [1.0, 0.0, 0.0])
        if np.linalg.norm(transverse) < 0.01:
            transverse = np.cross(axis, [0.0, 1.0, 0.0])
        transverse /= np.linalg.norm(transverse)
        wheel.gsHat_B = [[v] for v in axis]
        wheel.w2Hat0_B = [[v] for v in transverse]
        wheel.w3Hat0_B = [[v] for v in np.cross(axis, transverse)]
        wheel.Js = float(spin[i])
        wheel.Jt = wheel.Jg = 0.5 * wheel.Js
        wheel.rWB_B = [[0.0], [0.0], [0.0]]
        wheel.Omega = float(h0[i] / spin[i] - axis @ omega0)  # h = J_s (ĝᵀω + Ω)
        limit = float(wheels.max_torque[i])
        wheel.u_max = limit if np.isfinite(limit) else -1.0  # negative: no saturation
        wheel.u_min, wheel.fCoulomb, wheel.Omega_max, wheel.P_max = 0.0, 0.0, -1.0, -1.0
        wheel.RWModel = messaging.BalancedWheels
        effector.addReactionWheel(wheel)
    hub.addStateEffector(effector)
    sim.AddModelToTask("dynamicsTask", effector, 2)  # reads the held command before the hub integrates
    sim.AddModelToTask("dynamicsTask", hub, 1)
    navigation = bsk.simpleNav.SimpleNav()
    navigation.ModelTag = "navigation"
    navigation.scStateInMsg.subscribeTo(hub.scStateOutMsg)
    sim.AddModelToTask("dynamicsTask", navigation, 0)

    reference_module = bsk.waypointReference.WaypointReference()
    reference_module.ModelTag = "waypoints"
    for name, value in waypoints.basilisk_settings().items():
        setattr(reference_module, name, value)
    tracking = bsk.attTrackingError.attTrackingError()
    tracking.ModelTag = "tracking"
    tracking.attNavInMsg.subscribeTo(navigation.attOutMsg)
    tracking.attRefInMsg.subscribeTo(reference_module.attRefOutMsg)
    vehicle = messaging.VehicleConfigMsgPayload()
    vehicle.ISCPntB_B = inertia.ravel().tolist()
    vehicle_msg = messaging.VehicleConfigMsg().write(vehicle)
    configuration = messaging.RWArrayConfigMsgPayload()
    configuration.GsMatrix_B = axes.T.ravel().tolist() + [0.0] * (3 * (MAX_RW - n))
    configuration.JsList = spin.tolist() + [0.0] * (MAX_RW - n)
    configuration.uMax = [float(u) if np.isfinite(u) else -1.0 for u in wheels.max_torque] + [0.0] * (MAX_RW - n)
    configuration.numRW = n
    configuration_msg = messaging.RWArrayConfigMsg().write(configuration)
    feedback = bsk.mrpFeedback.mrpFeedback()
    feedback.ModelTag = "mrpFeedback"
    feedback.K, feedback.P, feedback.Ki, feedback.integralLimit = gains["k"], gains["p"], -1.0, 0.0
    feedback.guidInMsg.subscribeTo(tracking.attGuidOutMsg)
    feedback.vehConfigInMsg.subscribeTo(vehicle_msg)
    feedback.rwParamsInMsg.subscribeTo(configuration_msg)
    feedback.rwSpeedsInMsg.subscribeTo(effector.rwSpeedOutMsg)
    motor = bsk.rwMotorTorque.rwMotorTorque()
    motor.ModelTag = "rwMotorTorque"
    motor.controlAxes_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    motor.vehControlInMsg.subscribeTo(feedback.cmdTorqueOutMsg)
    motor.rwParamsInMsg.subscribeTo(configuration_msg)
    effector.rwMotorCmdInMsg.subscribeTo(motor.rwMotorTorqueOutMsg)
    for priority, module in enumerate((motor, feedback, tracking, reference_module)):
        sim.AddModelToTask("fswTask", module, 10 + priority)  # waypoints first, motor torques last

    states = hub.scStateOutMsg.recorder(macros.sec2nano(sample_time))
    speeds = effector.rwSpeedOutMsg.recorder(macros.sec2nano(sample_time))
    sim.AddModelToTask("dynamicsTask", states)
    sim.AddModelToTask("dynamicsTask", speeds)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(float(times[-1])))
    start = time.perf_counter()
    sim.ExecuteSimulation()
    seconds = time.perf_counter() - start
    sigma = np.asarray(states.sigma_BN)
    s2 = np.sum(sigma**2, axis=1, keepdims=True)
    q = np.hstack([(1 - s2) / (1 + s2), 2 * sigma / (1 + s2)])
    omega = np.asarray(states.omega_BN_B)
    h = spin * (omega @ axes + np.asarray(speeds.wheelSpeeds)[:, :n])
    return Loop(states.times() * 1e-9, q, omega, h, seconds)


def _unlimited(data: dict[str, Any]) -> None:
    data["spacecraft"]["wheels"].pop("max_torque")


def _collocation_with_errors(data: dict[str, Any]) -> None:
    data["simulation"]["initial_attitude_error_deg"] = [3.0, -2.0, 1.5]
    data["simulation"]["initial_rate_error"] = [0.002, -0.001, 0.0015]


CASES = {
    # the spin paper's repointing on its 0.1 N m wheels (saturated nearly throughout), planned by the
    # paper's spin extremal; gains of the scenario's size (kp 0.025, kd 0.16 times I ~ 17 kg m²)
    "spin_paper_wheels": ("biggs_horri_spin_repoint_wheels.yaml", None, {"k": 0.8, "p": 2.7}),
    # the same slew on unlimited wheels: no saturation
    "spin_paper_unlimited_wheels": ("biggs_horri_spin_repoint_wheels.yaml", _unlimited, {"k": 0.8, "p": 2.7}),
    # minimum-energy collocation slew, non-diagonal inertia, 0.1 N m / 4 N m s wheels, from an
    # initial attitude and rate error
    "collocation_min_energy": ("collocation_min_energy.yaml", _collocation_with_errors, {"k": 2.0, "p": 8.0}),
}


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(quat.error_angle(a, b)))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_basilisk_and_slewbench_closed_loops_agree(name: str, tmp_path: Path) -> None:
    file, edit, gains = CASES[name]
    case = scenario(file, edit)
    reference = case.planners[0].planner.plan(case.problem)
    assert reference.ok, reference.message
    duration = case.simulation.duration or case.problem.duration
    step = 0.05  # s: slewbench's default RK4 step
    loops = {}
    for h in (step, step / 2, step / 4):
        loops["slewbench", h] = fly_slewbench(case, reference, gains, h, duration)
        loops["basilisk", h] = fly_basilisk(case, reference, gains, h, duration, tmp_path / f"waypoints_{h:g}.txt")
    ours, theirs = loops["slewbench", step], loops["basilisk", step]
    assert theirs.t.shape == ours.t.shape
    np.testing.assert_allclose(theirs.t, ours.t, atol=1e-9)
    limit = np.asarray(case.problem.spacecraft.wheels.max_momentum)
    assert np.all(np.abs(ours.h) < limit), "the momentum limit (slewbench's alone) must not be reached"

    # Richardson: each integrator's error at `step`, from the change when the step is halved
    def richardson(simulator: str, field: str) -> float:
        fine, coarse = loops[simulator, step / 2], loops[simulator, step]
        if field == "q":
            return 16 / 15 * _angle(coarse.q, fine.q)
        return 16 / 15 * float(np.max(np.abs(getattr(coarse, field) - getattr(fine, field))))

    measured, allowed = {}, {}
    for field in ("q", "omega", "h"):
        allowed[field] = 2 * (richardson("slewbench", field) + richardson("basilisk", field)) + ROUNDING
    reference_q = reference.q(ours.t)
    error_ours, error_theirs = quat.error_angle(ours.q, reference_q), quat.error_angle(theirs.q, reference_q)
    measured["q"] = _angle(theirs.q, ours.q)  # rad between the two attitudes
    measured["error"] = float(np.max(np.abs(error_theirs - error_ours)))  # the attitude error histories
    measured["omega"] = float(np.max(np.abs(theirs.omega - ours.omega)))
    measured["h"] = float(np.max(np.abs(theirs.h - ours.h)))
    half = (_angle(loops["basilisk", step / 2].q, loops["slewbench", step / 2].q),
            _angle(loops["basilisk", step / 4].q, loops["slewbench", step / 4].q))
    print(f"\n{name}: max attitude error {np.max(error_ours):.4g} rad; between the loops at h = {step:g} s: "
          f"attitude {measured['q']:.3g} rad (allowed {allowed['q']:.3g}), error angle {measured['error']:.3g} rad, "
          f"rate {measured['omega']:.3g} rad/s (allowed {allowed['omega']:.3g}), wheel momentum "
          f"{measured['h']:.3g} N m s (allowed {allowed['h']:.3g}); at h/2, h/4: {half[0]:.3g}, {half[1]:.3g} rad; "
          f"wall time slewbench {ours.seconds:.3f} s, Basilisk {theirs.seconds:.3f} s")
    assert measured["q"] <= allowed["q"]
    assert measured["error"] <= allowed["q"]  # |θ_a − θ_b| ≤ angle between the attitudes
    assert measured["omega"] <= allowed["omega"]
    assert measured["h"] <= allowed["h"]
    # the difference is the integrators': it falls with the step (fourth order: by 16 per halving)
    assert half[0] <= measured["q"] / 8 + ROUNDING
    assert half[1] <= half[0] / 8 + ROUNDING


@pytest.mark.slow
def test_the_cross_check_tells_a_one_percent_different_gain(tmp_path: Path) -> None:
    """The comparison has teeth: Basilisk flown with ``K`` 1 % higher than slewbench's law is told
    apart from it by far more than the two agree by."""
    file, edit, gains = CASES["spin_paper_unlimited_wheels"]
    case = scenario(file, edit)
    reference = case.planners[0].planner.plan(case.problem)
    duration = case.problem.duration
    ours = fly_slewbench(case, reference, gains, 0.05, duration)
    same = fly_basilisk(case, reference, gains, 0.05, duration, tmp_path / "same.txt")
    other = fly_basilisk(case, reference, {**gains, "k": 1.01 * gains["k"]}, 0.05, duration, tmp_path / "other.txt")
    agree, differ = _angle(same.q, ours.q), _angle(other.q, ours.q)
    print(f"\nK and 1.01 K: {differ:.3g} rad apart; same K: {agree:.3g} rad")
    assert agree < 1e-8
    assert differ > 1e3 * agree


# ------------------------------------------------------------------------------------------------
# The law alone, at one sample: slewbench's mrp_feedback against Basilisk's modules
# ------------------------------------------------------------------------------------------------

def _tilde(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _mrp2c(sigma: np.ndarray) -> np.ndarray:
    """Basilisk's MRP2C: the direction cosine matrix [BN] of σ_B/N (Schaub & Junkins eq. 3.150)."""
    s2 = sigma @ sigma
    tilde = _tilde(sigma)
    return np.eye(3) + (8 * tilde @ tilde - 4 * (1 - s2) * tilde) / (1 + s2) ** 2


def _sub_mrp(s1: np.ndarray, s2: np.ndarray) -> np.ndarray:
    """Basilisk's subMRP (rigidBodyKinematics.c), line by line: σ of frame 1 relative to frame 2."""
    s1 = s1.copy()
    det = 1 + (s1 @ s1) * (s2 @ s2) + 2 * (s1 @ s2)
    if abs(det) < 0.1:
        s1 = -s1 / (s1 @ s1)
        det = 1 + (s1 @ s1) * (s2 @ s2) + 2 * (s1 @ s2)
    q = (2 * np.cross(s1, s2) + (1 - s2 @ s2) * s1 - (1 - s1 @ s1) * s2) / det
    return -q / (q @ q) if q @ q > 1 else q


def _basilisk_transcription(q: np.ndarray, omega: np.ndarray, h: np.ndarray, q_ref: np.ndarray,
                            omega_ref: np.ndarray, omega_dot_ref: np.ndarray, inertia: np.ndarray,
                            axes: np.ndarray, spin: np.ndarray, k: float, p: float, law_type: int) -> np.ndarray:
    """waypointReference's inputs, attTrackingError, mrpFeedback (``controlLawType``, Ki < 0) and
    rwMotorTorque, transcribed from Basilisk's C in its own variables: the wheel motor torques."""
    sigma_bn, sigma_rn = short_mrp(q), short_mrp(q_ref)
    dcm_bn, dcm_rn = _mrp2c(sigma_bn), _mrp2c(sigma_rn)
    omega_rn_n, domega_rn_n = dcm_rn.T @ omega_ref, dcm_rn.T @ omega_dot_ref  # the file's ω_RN, in N
    sigma_br = _sub_mrp(sigma_bn, sigma_rn)
    omega_rn_b, domega_rn_b = dcm_bn @ omega_rn_n, dcm_bn @ domega_rn_n
    omega_br_b = omega - omega_rn_b
    wheel_speeds = h / spin - axes.T @ omega  # Ω from h_s = J_s (ĝᵀ ω + Ω)
    lr = k * sigma_br + p * omega_br_b
    momentum = inertia @ omega + sum(spin[i] * (omega @ axes[:, i] + wheel_speeds[i]) * axes[:, i]
                                     for i in range(axes.shape[1]))
    lr = lr - np.cross(omega_rn_b if law_type == 0 else omega, momentum)
    lr = lr + inertia @ (np.cross(omega, omega_rn_b) - domega_rn_b)
    lr = -lr  # the torque requested on the body
    return np.asarray(-axes.T @ np.linalg.inv(axes @ axes.T) @ lr)  # rwMotorTorque: [Gs] u_s = −L_r


def _random_case(seed: int) -> dict[str, Any]:
    rng = np.random.default_rng(seed)
    inertia = np.array([[19.5, 0.4, -0.3], [0.4, 19.0, 0.5], [-0.3, 0.5, 12.6]])
    axes = np.column_stack([np.eye(3), np.ones(3) / np.sqrt(3)]) + rng.normal(0, 0.05, (3, 4))
    axes /= np.linalg.norm(axes, axis=0)
    return {"inertia": inertia, "axes": axes, "spin": rng.uniform(0.01, 0.1, 4),
            "q": quat.random_unit(rng), "omega": rng.normal(0, 0.1, 3), "h": rng.normal(0, 2.0, 4),
            "q_ref": quat.random_unit(rng), "omega_ref": rng.normal(0, 0.1, 3),
            "omega_dot_ref": rng.normal(0, 0.01, 3), "k": 1.3, "p": 4.7, "law_type": seed % 2}


def _slewbench_wheel_torque(case: dict[str, Any]) -> np.ndarray:
    law = MRPFeedback({"k": case["k"], "p": case["p"],
                       "gyroscopic_rate": ("reference", "body")[case["law_type"]]})
    law.reset(Spacecraft(case["inertia"], wheels=ReactionWheels(case["axes"])), 0.5)
    reference = SimpleNamespace(sample=lambda t: SimpleNamespace(
        q=np.tile(case["q_ref"], (len(t), 1)), omega=np.tile(case["omega_ref"], (len(t), 1)),
        omega_dot=np.tile(case["omega_dot_ref"], (len(t), 1)), torque=np.zeros((len(t), 3))))
    command = law(3.0, Measurement(3.0, case["q"], case["omega"], case["h"]), reference)
    return np.asarray(command.wheel_torque)


@pytest.mark.parametrize("seed", range(6))
def test_mrp_feedback_is_basilisks_law(seed: int) -> None:
    """Against a transcription of Basilisk's C in its own algebra (MRP subtraction, MRP direction
    cosines, inertial rates, wheel speeds), at random states, references and skewed wheels, for
    both ``controlLawType`` (``gyroscopic_rate``)."""
    case = _random_case(seed)
    expected = _basilisk_transcription(**{k: case[k] for k in ("q", "omega", "h", "q_ref", "omega_ref",
                                                                "omega_dot_ref", "inertia", "axes", "spin", "k",
                                                                "p", "law_type")})
    np.testing.assert_allclose(_slewbench_wheel_torque(case), expected, rtol=1e-11, atol=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_mrp_feedback_is_basilisks_modules(seed: int) -> None:
    """Against Basilisk's own attTrackingError, mrpFeedback and rwMotorTorque, one update from
    stand-alone messages (the reference as waypointReference would give it, in inertial axes)."""
    bsk = basilisk()
    messaging = bsk.messaging
    case = _random_case(seed)
    n = case["axes"].shape[1]
    sim = bsk.SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("p").addTask(sim.CreateNewTask("task", bsk.macros.sec2nano(0.5)))
    navigation = messaging.NavAttMsgPayload()
    navigation.sigma_BN = short_mrp(case["q"]).tolist()
    navigation.omega_BN_B = case["omega"].tolist()
    rotation = quat.rotation_matrix(case["q_ref"])  # the exporter's R(q*): ω_RN in N components
    reference = messaging.AttRefMsgPayload()
    reference.sigma_RN = short_mrp(case["q_ref"]).tolist()
    reference.omega_RN_N = (rotation @ case["omega_ref"]).tolist()
    reference.domega_RN_N = (rotation @ case["omega_dot_ref"]).tolist()
    speeds = messaging.RWSpeedMsgPayload()
    speeds.wheelSpeeds = (case["h"] / case["spin"] - case["axes"].T @ case["omega"]).tolist() + [0.0] * (MAX_RW - n)
    vehicle = messaging.VehicleConfigMsgPayload()
    vehicle.ISCPntB_B = case["inertia"].ravel().tolist()
    configuration = messaging.RWArrayConfigMsgPayload()
    configuration.GsMatrix_B = case["axes"].T.ravel().tolist() + [0.0] * (3 * (MAX_RW - n))
    configuration.JsList = case["spin"].tolist() + [0.0] * (MAX_RW - n)
    configuration.uMax = [-1.0] * n + [0.0] * (MAX_RW - n)
    configuration.numRW = n
    messages = [messaging.NavAttMsg().write(navigation), messaging.AttRefMsg().write(reference),
                messaging.RWSpeedMsg().write(speeds), messaging.VehicleConfigMsg().write(vehicle),
                messaging.RWArrayConfigMsg().write(configuration)]
    tracking = bsk.attTrackingError.attTrackingError()
    tracking.attNavInMsg.subscribeTo(messages[0])
    tracking.attRefInMsg.subscribeTo(messages[1])
    feedback = bsk.mrpFeedback.mrpFeedback()
    feedback.K, feedback.P, feedback.Ki, feedback.integralLimit = case["k"], case["p"], -1.0, 0.0
    feedback.controlLawType = case["law_type"]
    feedback.guidInMsg.subscribeTo(tracking.attGuidOutMsg)
    feedback.vehConfigInMsg.subscribeTo(messages[3])
    feedback.rwParamsInMsg.subscribeTo(messages[4])
    feedback.rwSpeedsInMsg.subscribeTo(messages[2])
    motor = bsk.rwMotorTorque.rwMotorTorque()
    motor.controlAxes_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    motor.vehControlInMsg.subscribeTo(feedback.cmdTorqueOutMsg)
    motor.rwParamsInMsg.subscribeTo(messages[4])
    for priority, module in enumerate((motor, feedback, tracking)):
        module.ModelTag = f"module{priority}"
        sim.AddModelToTask("task", module, 10 + priority)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(0)
    sim.ExecuteSimulation()
    theirs = np.asarray(motor.rwMotorTorqueOutMsg.read().motorTorque)[:n]
    np.testing.assert_allclose(_slewbench_wheel_torque(case), theirs, rtol=1e-11, atol=1e-12)
