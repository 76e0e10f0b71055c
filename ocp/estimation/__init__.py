"""Attitude sensors and the attitude estimator of the closed loop.

What lives here: the sensor models, a Farrenkopf gyro (angle and rate random walk, bias), a star
tracker (per-axis noise in its own frame, rate, outages, exclusion cones about bright bodies) and a magnetometer bias
(:mod:`~ocp.estimation.sensors`); the multiplicative extended Kalman filter, gyro propagation and
star tracker updates, in NumPy and CasADi (:mod:`~ocp.estimation.mekf`); and both as one step of
the closed loop with its noise drawn in advance (:mod:`~ocp.estimation.loop`), which
:mod:`ocp.simulation` runs in its Python loop and in its CasADi closed loop.

May import: NumPy, CasADi, :mod:`ocp.dynamics` and the top-level modules of :mod:`ocp`; never
:mod:`ocp.simulation`, :mod:`ocp.geometry`, :mod:`ocp.transcription` or :mod:`ocp.nlp`.
"""
from ocp.estimation.loop import (
    BLINDED,
    SENSOR_NOISE_SIZE,
    SENSOR_STATE_SIZE,
    SensorSuite,
    draw_sensor_noise,
    initial_sensor_state,
    sensor_step,
    sensor_step_symbolic,
)
from ocp.estimation.mekf import (
    Mekf,
    propagate,
    propagate_symbolic,
    update,
    update_symbolic,
)
from ocp.estimation.sensors import Exclusion, Gyro, Magnetometer, StarTracker

__all__ = ["BLINDED", "SENSOR_NOISE_SIZE", "SENSOR_STATE_SIZE", "Exclusion", "Gyro", "Magnetometer", "Mekf", "SensorSuite", "StarTracker",
           "draw_sensor_noise", "initial_sensor_state", "propagate", "propagate_symbolic", "sensor_step",
           "sensor_step_symbolic", "update", "update_symbolic"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
