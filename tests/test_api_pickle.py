"""References pickle and deep-copy: a ``costate_tpbvp`` reference (its Hamiltonian system keeps
CasADi call buffers, dropped on pickling and rebuilt on use), a ``natural_motion`` reference (its
attitude arc is a module-level callable, not a local lambda) and ``collocation`` references on both
transcriptions (their model's solver cache pickles empty). A round trip gives bit-identical
samples."""
import copy
import pickle
import warnings

import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem


def slew(moments):
    return ManeuverProblem(Spacecraft(moments, wheels=ReactionWheels.from_body_axes(max_torque=0.1)), quat.IDENTITY,
                           np.zeros(3), quat.from_axis_angle([0, 1, 0], np.pi / 2), 120.0, omegaf=np.zeros(3))


def assert_same_samples(a, b):
    t = np.linspace(0.0, a.duration, 241)
    sa, sb = a.sample(t), b.sample(t)
    for field in ("q", "omega", "omega_dot", "torque"):
        np.testing.assert_array_equal(getattr(sb, field), getattr(sa, field))
    assert (b.status, b.message, b.duration) == (a.status, a.message, a.duration)


# natural_motion: asymmetric moments take the integrated arc (the former lambda), symmetric the closed form
@pytest.mark.parametrize(("name", "options", "moments"), [("costate_tpbvp", {}, [19.5, 19.0, 12.6]),
                                                          ("natural_motion", {}, [19.5, 19.0, 12.6]),
                                                          ("natural_motion", {}, [19.0, 19.0, 12.6]),
                                                          ("collocation", {}, [19.5, 19.0, 12.6]),
                                                          ("collocation", {"transcription": "multiple_shooting",
                                                                           "intervals": 20}, [19.5, 19.0, 12.6])])
@pytest.mark.parametrize("how", ["pickle", "deepcopy"])
def test_reference_round_trip_gives_identical_samples(name, options, moments, how):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = PLANNERS[name](options).plan(slew(moments))
    assert reference.ok or reference.status == "violated", reference.message  # a reference either way
    reference.sample(np.linspace(0.0, reference.duration, 7))  # its call buffers exist before the copy
    again = pickle.loads(pickle.dumps(reference)) if how == "pickle" else copy.deepcopy(reference)
    assert_same_samples(reference, again)


@pytest.mark.parametrize("options", [{}, {"transcription": "multiple_shooting", "intervals": 20}])
def test_a_collocation_reference_pickles_without_the_built_solvers(options):
    # the reference keeps its model, and the model its solver cache: the built NLPs (14 MB after a
    # 50-interval collocation plan, 330 MB after a multiple-shooting one) stay behind; the states,
    # controls and model data are kilobytes
    problem = slew([19.5, 19.0, 12.6])
    reference = PLANNERS["collocation"](options).plan(problem)
    assert len(problem.model.solver_cache) > 0  # the plan built (and keeps) its solvers here
    assert len(pickle.dumps(reference)) < 200_000
    again = pickle.loads(pickle.dumps(reference))
    assert len(again.model.solver_cache) == 0
    # and samples the same motion, building what its sampling needs again
    times = np.linspace(0.0, reference.duration, 31)
    np.testing.assert_array_equal(again.sample(times).q, reference.sample(times).q)
