"""slewbench's symbolic core: quaternions, spacecraft, environment, model, simulator, metrics.

Pure numeric/symbolic layer (CasADi and NumPy); it knows nothing of planners, controllers or YAML.

Conventions throughout: SI units; quaternions scalar first ``[q0, q1, q2, q3]``, Hamilton product,
``q`` rotates body vectors into the inertial frame (``v_I = R(q) v_B``); ω is the body rate with
respect to the inertial frame in body axes [rad/s]; torques, dipoles and wheel axes in body axes.
"""
from ocp.cache import SolverCache
from ocp.dynamics.actuators import ActuatorModel, Command, Measurement
from ocp.dynamics.environment import (
                         CircularOrbit,
                         Environment,
                         TiltedDipole,
                         gravity_gradient_torque,
)
from ocp.dynamics.igrf import IGRFField
from ocp.dynamics.model import AttitudeModel
from ocp.dynamics.spacecraft import (
                         Magnetorquers,
                         ModelError,
                         ReactionWheels,
                         Spacecraft,
                         Torquers,
)
from ocp.metrics import (
                         METRIC_KEYS,
                         compute_metrics,
                         metric_violations,
                         metrics_from_reference,
                         metrics_from_simulation,
)
from ocp.simulation.simulator import (
                         SensorNoise,
                         SimulationError,
                         SimulationResult,
                         Simulator,
)

__all__ = [
    "ActuatorModel", "AttitudeModel", "CircularOrbit", "Command", "Environment", "IGRFField", "METRIC_KEYS",
    "Magnetorquers", "Measurement", "ModelError", "ReactionWheels", "SensorNoise",
    "SimulationError", "SimulationResult", "Simulator", "SolverCache", "Spacecraft", "TiltedDipole", "Torquers",
    "compute_metrics", "gravity_gradient_torque", "metric_violations", "metrics_from_reference", "metrics_from_simulation",
]
