"""slewbench's symbolic core: quaternions, spacecraft, environment, model, simulator, metrics, NLPs.

Pure numeric and symbolic layer (CasADi, NumPy, SciPy); it knows nothing of planners, controllers
or YAML. Subpackages, from the bottom up; each may import the top-level modules and the
subpackages it names:

* top-level modules: :mod:`~ocp.errors` (the exceptions and their base :class:`SlewbenchError`),
  :mod:`~ocp.options` (typed options), :mod:`~ocp.quat` and :mod:`~ocp.quat_casadi` (quaternion
  algebra), :mod:`~ocp.cache` (solver caches), :mod:`~ocp.fast_call` (low-overhead calls of CasADi
  functions), :mod:`~ocp.native` (the C compiler and the cache of its builds), :mod:`~ocp.metrics`
  (the common score);
* :mod:`ocp.dynamics`: the spacecraft, its actuators, orbits and environment, the assembled model;
* :mod:`ocp.geometry`: pointing constraints and the directions they are measured from (the Sun,
  the Moon, the Earth, the orbital velocity; imports :mod:`ocp.dynamics`);
* :mod:`ocp.estimation`: attitude sensors and the MEKF of the closed loop (imports
  :mod:`ocp.dynamics`);
* :mod:`ocp.simulation`: the closed-loop simulator (imports :mod:`ocp.dynamics` and
  :mod:`ocp.estimation`);
* :mod:`ocp.transcription`: optimal-control problems and their NLPs (imports :mod:`ocp.dynamics`
  and :mod:`ocp.geometry`);
* :mod:`ocp.nlp`: solving NLPs and the second-order check (imports neither of the above).

Conventions throughout: SI units; quaternions scalar first ``[q0, q1, q2, q3]``, Hamilton product,
``q`` rotates body vectors into the inertial frame (``v_I = R(q) v_B``); ω is the body rate with
respect to the inertial frame in body axes [rad/s]; torques, dipoles and wheel axes in body axes.
"""
from ocp.cache import SolverCache
from ocp.dynamics.actuator_kinds import Magnetorquers, ReactionWheels, Torquers
from ocp.dynamics.actuators import ActuatorModel, Command, Measurement
from ocp.dynamics.environment import (
                        Environment,
                        TiltedDipole,
                        gravity_gradient_torque,
)
from ocp.dynamics.igrf import IGRFField
from ocp.dynamics.model import AttitudeModel
from ocp.dynamics.orbits import CircularOrbit, KeplerianOrbit, TLEOrbit
from ocp.dynamics.spacecraft import Spacecraft
from ocp.errors import (
                        CompilerUnavailable,
                        InvalidOption,
                        ModelError,
                        OptionsError,
                        SimulationError,
                        SlewbenchError,
)
from ocp.metrics import (
                        METRIC_KEYS,
                        compute_metrics,
                        metric_violations,
                        metrics_from_reference,
                        metrics_from_simulation,
                        target_motion,
)
from ocp.simulation.simulator import SensorNoise, SimulationResult, Simulator

__all__ = [
    "ActuatorModel", "AttitudeModel", "CircularOrbit", "Command", "CompilerUnavailable", "Environment", "IGRFField",
    "InvalidOption", "KeplerianOrbit", "METRIC_KEYS", "Magnetorquers", "Measurement", "ModelError", "OptionsError",
    "ReactionWheels", "SensorNoise", "SimulationError", "SimulationResult", "Simulator", "SlewbenchError",
    "SolverCache", "Spacecraft", "TLEOrbit", "TiltedDipole", "Torquers", "compute_metrics", "gravity_gradient_torque",
    "metric_violations", "metrics_from_reference", "metrics_from_simulation", "target_motion",
]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
