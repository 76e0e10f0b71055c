"""Typed options (:mod:`ocp.options`): each documented rule of a :class:`~ocp.options.Range` and of the
types, on a small options class of its own, at and beside each bound. The oracle is the module's
documented contract (``> gt`` excludes the bound, ``<= le`` includes it, numbers finite unless
``finite=False``, a bool is no integer, a matrix has its declared shape); the error names the path,
the value and the range."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated

import pytest

from ocp.errors import OptionsError
from ocp.options import Range, parse_options


@dataclass(frozen=True)
class Options:
    gain: Annotated[float, Range(gt=0.0, le=2.0)] = 1.0
    scale: Annotated[float, Range(ge=0.0, finite=False)] = 1.0
    weight: Annotated[float, Range(ge=0.0)] = 0.0
    count: Annotated[int, Range(ge=1)] = 1
    matrix: Annotated[list[list[float]] | None, Range(shape=(2, 2))] = None


@pytest.mark.parametrize("key, value, ok", [
    ("gain", 0.0, False), ("gain", 1e-300, True), ("gain", 2.0, True), ("gain", 2.0 + 1e-12, False),
    ("gain", math.inf, False), ("gain", math.nan, False), ("scale", math.inf, True), ("scale", math.nan, False),
    ("weight", 1e300, True), ("weight", math.inf, False), ("weight", [1.0], False),
    ("count", 1, True), ("count", True, False), ("count", 0, False),
    ("matrix", [[1.0, 0.0], [0.0, 1.0]], True), ("matrix", [[1.0, 0.0], [0.0]], False),
    ("matrix", [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], False),
])
def test_each_documented_bound_and_type_rule(key, value, ok):
    if ok:
        parsed = parse_options(Options, {key: value}, "planners[0].options")
        assert getattr(parsed, key) == value
    else:
        with pytest.raises(OptionsError) as error:
            parse_options(Options, {key: value}, "planners[0].options")
        assert str(error.value).startswith(f"planners[0].options.{key}")
