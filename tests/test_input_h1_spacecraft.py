"""``Spacecraft`` refuses an inertia of anything but real numbers, naming the value: NumPy reads
``True`` as 1, ``1+0j`` as 1 (with only a ComplexWarning), ``"2"`` in an object array as 2 and a
date as its count of seconds, so each built a spacecraft of unit or made-up moments."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from ocp import Spacecraft
from ocp.errors import ModelError


@pytest.mark.parametrize("inertia, named", [
    ([True, True, True], "True (bool) is no real number"),
    ([1.0, True, 1.0], "True (bool) is no real number"),
    (np.array([True, True, True]), "an array of booleans (dtype bool)"),
    ([[1, 0, 0], [0, 1, 0], [0, 0, np.True_]], "np.True_ (bool) is no real number"),
    ([1 + 0j, 1, 1], "(1+0j) (complex) is no real number"),
    (np.array([1.0, 1.0, 1.0], dtype=complex), "an array of complex numbers (dtype complex128)"),
    (np.array([1, "2", 2], dtype=object), "'2' (str) is no real number"),
    ([None, 1.0, 1.0], "None (NoneType) is no real number"),
    (np.array([1, 1, 1], dtype="timedelta64[s]"), "an array of durations"),
    (np.array([1, 1, 1], dtype="datetime64[s]"), "an array of dates"),
])
def test_an_inertia_of_no_real_numbers_is_a_value_error_naming_it(inertia, named):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way
        with pytest.raises(ValueError) as raised:
            Spacecraft(inertia)
    assert isinstance(raised.value, ModelError) and raised.value.field == "inertia"
    message = str(raised.value)
    assert message.startswith("inertia: expected 3 principal moments or a 3x3 matrix of numbers, got "), message
    assert named in message, message


@pytest.mark.parametrize("inertia", [(1, 2, 2), np.array([1, 2, 2]), [np.int64(1), np.float16(2), 2.0],
                                     np.array([1.0, 2.0, 2.0], dtype=object), [[1, 0, 0], [0, 2, 0], [0, 0, 2]]])
def test_real_numbers_of_any_numeric_type_are_accepted(inertia):
    assert np.array_equal(np.diag(Spacecraft(inertia).inertia), [1.0, 2.0, 2.0])
