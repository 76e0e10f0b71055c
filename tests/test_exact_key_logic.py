"""ocp.cache.exact_key's contract, case by case: equal values give equal keys (a dict or a set
however built, an array however laid out in memory, NaN), different values different keys (a bool
and an int, a big int and its float, arrays of one byte string but another shape or dtype, two
dataclass types with the same fields, dicts with the same values under other keys); and the
model's token of an object without an exact key goes with the object.

Oracles: Python's and NumPy's own equality (``==``, ``np.array_equal``) and type identity for what
is equal; values built by hand to share their bytes or their items.
"""
from __future__ import annotations

import dataclasses
import gc
import math

import numpy as np
import pytest

from ocp.cache import exact_key


def test_a_bool_is_not_the_int_it_equals():
    assert True == 1 and False == 0  # noqa: E712 - Python's equality would merge them: the key must not
    assert exact_key(True) != exact_key(1) and exact_key(False) != exact_key(0)
    assert exact_key(np.bool_(True)) != exact_key(np.int64(1))
    assert exact_key({"flag": True}) != exact_key({"flag": 1})
    assert exact_key(True) == exact_key(np.bool_(True))


def test_an_int_is_exact_past_the_floats_precision():
    big = 2**53
    assert float(big) == float(big + 1)  # one float for two ints
    assert exact_key(big) != exact_key(big + 1)
    assert exact_key(np.int64(big + 1)) == exact_key(big + 1)


def test_nan_keys_equal_themselves_and_signed_zeros_do_not():
    assert exact_key(float("nan")) == exact_key(np.float64("nan")) == exact_key(math.nan)
    assert exact_key([1.0, float("nan")]) == exact_key([1.0, float("nan")])
    assert exact_key(0.0) != exact_key(-0.0)


def test_arrays_of_the_same_bytes_but_another_shape_or_dtype_differ():
    a = np.arange(6.0)
    assert a.reshape(2, 3).tobytes() == a.reshape(3, 2).tobytes()
    assert exact_key(a.reshape(2, 3)) != exact_key(a.reshape(3, 2))
    assert exact_key(a) != exact_key(a.reshape(1, 6))
    zeros_int, zeros_float = np.zeros(3, dtype=np.int64), np.zeros(3, dtype=np.float64)
    assert zeros_int.tobytes() == zeros_float.tobytes()
    assert exact_key(zeros_int) != exact_key(zeros_float)
    one = np.array([1.0], dtype=np.float32)
    assert exact_key(one) != exact_key(one.view(np.int32))


def test_an_array_keys_the_same_however_it_is_laid_out_in_memory():
    c_order = np.arange(12.0).reshape(3, 4)
    fortran = np.asfortranarray(c_order)
    transposed_back = np.ascontiguousarray(c_order.T).T  # a view in Fortran order
    assert np.array_equal(c_order, fortran) and np.array_equal(c_order, transposed_back)
    assert not fortran.flags.c_contiguous
    assert exact_key(fortran) == exact_key(c_order) == exact_key(transposed_back)
    assert exact_key(c_order[:, ::2]) == exact_key(np.array([[0.0, 2.0], [4.0, 6.0], [8.0, 10.0]]))


@dataclasses.dataclass(frozen=True)
class _Dipole:
    strength: float


@dataclasses.dataclass(frozen=True)
class _Quadrupole:
    strength: float


def test_two_dataclass_types_with_the_same_fields_differ():
    assert dataclasses.astuple(_Dipole(1.0)) == dataclasses.astuple(_Quadrupole(1.0))
    assert exact_key(_Dipole(1.0)) != exact_key(_Quadrupole(1.0))
    assert exact_key(_Dipole(1.0)) == exact_key(_Dipole(1.0))


def test_a_dict_keys_by_its_items_not_its_order_nor_its_values_alone():
    first = {"kp": 0.2, "kd": 0.6, "nested": {"a": [1, 2], "b": (3.0,)}}
    second = {"nested": {"b": (3.0,), "a": [1, 2]}, "kd": 0.6, "kp": 0.2}
    assert first == second and list(first) != list(second)
    assert exact_key(first) == exact_key(second)
    assert exact_key({"kp": 0.2}) != exact_key({"kd": 0.2})
    assert exact_key({"kp": 0.2, "kd": 0.6}) != exact_key({"kp": 0.6, "kd": 0.2})


def test_a_set_keys_by_its_items_not_its_iteration_order():
    first, second = set(), set()
    for item in (1, 9, 17):  # equal hashes modulo the table's size: where each sits depends on the order
        first.add(item)
    for item in (17, 9, 1):
        second.add(item)
    assert first == second
    if list(first) == list(second):
        pytest.skip("this Python iterates both sets in one order")
    assert exact_key(first) == exact_key(second) == exact_key(frozenset((9, 1, 17)))
    assert exact_key({1, 9}) != exact_key({1, 17})


class _Opaque:
    """An object of no kind exact_key knows."""


def test_an_objects_token_goes_with_the_object():
    from ocp import AttitudeModel, Environment, Spacecraft
    from ocp.dynamics import model as model_module

    gc.collect()
    before = len(model_module._TOKENS)
    fingerprints = set()
    for _ in range(20):
        environment = Environment()
        object.__setattr__(environment, "magnetic_field", _Opaque())  # no exact statement: a token
        fingerprints.add(AttitudeModel(Spacecraft([1.0, 2.0, 3.0]), environment).fingerprint)
        assert len(model_module._TOKENS) == before + 1  # kept while the environment lives
        del environment
    gc.collect()
    assert len(fingerprints) == 20  # each environment object its own
    assert len(model_module._TOKENS) == before  # and no entry outlives its object
