"""The study file's schema: its keys, the value generators of ``grid`` and ``zip`` entries and the
distributions of Monte Carlo dispersions.

A study varies a base scenario (:mod:`scenarios.study.spec` expands it into cases). Its keys are
declared here (:data:`STUDY`, :data:`MONTE_CARLO`, :data:`EXECUTION`) and read through them. A
``grid`` or ``zip`` entry is a list of values or ``{<generator>: <argument>}`` with a generator of
the registry :data:`VALUE_GENERATORS`; a dispersion draws from a distribution of the registry
:data:`DISTRIBUTIONS` (``{normal: ...}``, ``{uniform: ...}``), possibly wrapped in ``{scale: ...}``
or ``{offset: ...}`` (:data:`COMBINATIONS`), or is the word ``case_seed``. Each registry entry
declares its argument as a :class:`~scenarios.schema.keys.Key`, which reads it and describes it
in the schema reference.
"""
from __future__ import annotations

import json
import re
import types
import typing
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from controllers import CONTROLLERS
from ocp import METRIC_KEYS, quat
from ocp.errors import excerpt
from ocp.options import option_fields
from planners import PLANNERS
from scenarios.errors import ScenarioError
from scenarios.requirements.fields import (
    REQUIREMENT_FIELDS,
    VERDICT,
    is_requirement_column,
    is_verdict_column,
    requirement_kind,
)
from scenarios.schema.columns import (
    REQUIREMENT_MARK,
    VECTOR_METRICS,
    metric_columns,
)
from scenarios.schema.keys import (
    Described,
    Key,
    Section,
    choice,
    custom,
    mapping,
    number,
)
from scenarios.schema.loader import MAX_NAME, SCENARIO
from scenarios.schema.node import Node
from scenarios.schema.targets import axis_angle_quaternion, rotation_axis

__all__ = [
    "CASE_SEED",
    "COMBINATIONS",
    "DEFAULT_SUMMARY",
    "DISPERSION",
    "DISTRIBUTIONS",
    "EXECUTION",
    "GRID_ENTRY",
    "INDEPENDENT_KEYS",
    "MAX_CASES",
    "MAX_CASE_TIMEOUT_S",
    "MAX_PRINCIPAL_AXES_DEG",
    "MAX_SEED",
    "MAX_VALUES",
    "MAX_VARIED",
    "MAX_WORST",
    "MONTE_CARLO",
    "PRINCIPAL",
    "PRINCIPAL_DISPERSION",
    "ROBUSTNESS",
    "SCHEDULER_SCHEMES",
    "STUDY",
    "SYMMETRIC_KEYS",
    "THRESHOLD",
    "THRESHOLD_SENSES",
    "VALUE_GENERATORS",
    "Distribution",
    "ValueGenerator",
    "declared_key",
    "grid_values",
    "independent_key",
    "scheduler_address",
    "symmetric_key",
    "takes_integers",
]

MAX_CASES = 100_000
"""Most cases a study may expand to (grid points times Monte Carlo samples)."""
MAX_VALUES = 10_000
"""Most values of one ``grid`` or ``zip`` entry."""
MAX_VARIED = 100
"""Most scenario paths a study varies (``grid``, ``zip`` and ``monte_carlo.dispersions`` together)."""
MAX_CASE_TIMEOUT_S = 7 * 86400.0
"""Longest ``execution.case_timeout_s`` accepted [s] (a week)."""
MAX_SEED = 2**63 - 1
"""Largest ``monte_carlo.seed``."""
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss")
"""The schemes of a Dask scheduler's address (none given: ``tcp``)."""
DEFAULT_SUMMARY = tuple(metric_columns(vectors=False))
"""The metrics summarised when ``summary`` is not given: every scalar metric of the reference
(``ref.``) and of the closed loop (``cl.``)."""


# --- value generators of grid and zip entries -------------------------------------------------

@dataclass(frozen=True)
class ValueGenerator:
    """A value generator of ``grid`` and ``zip`` entries, written ``{<name>: <argument>}``.

    Parameters
    ----------
    argument : Key
        Reads and checks the argument; its ``name`` is the generator's name and its ``type``,
        ``meaning`` (and ``section`` for a mapping) describe it in the reference.
    generate : callable
        ``generate(argument, base) -> (values, recorded)``: the values set into the scenario and
        the values recorded in the tables (numbers or text), from the argument as read and the
        base scenario mapping.
    """

    argument: Key
    generate: Callable[[Any, Mapping[str, Any]], tuple[list[Any], list[Any]]]

    @property
    def name(self) -> str:
        """The generator's name (its argument's key)."""
        return self.argument.name


def _spaced(kind: str) -> Callable[[Node], tuple[float, float, int]]:
    def read(node: Node) -> tuple[float, float, int]:
        start, stop, count = node.vector(3)
        if count != int(count) or not 1 <= count <= MAX_VALUES:
            raise ScenarioError(f"{node.path}[2]", f"expected a count from 1 to {MAX_VALUES}, got "
                                                   f"{excerpt(node.value[2])}")  # as written (0, not 0.0)
        if kind == "geomspace" and (start <= 0 or stop <= 0):
            raise node.error("geomspace needs positive bounds")
        return float(start), float(stop), int(count)
    return read


def _spaced_values(node: Node, space: Callable[..., np.ndarray]) -> tuple[list[Any], list[Any]]:
    start, stop, count = _spaced(space.__name__)(node)
    with np.errstate(all="ignore"):  # bounds near the largest float: refused below, without NumPy's warnings
        array = space(start, stop, count)
    if not np.all(np.isfinite(array)):
        raise node.error(f"{space.__name__} from {start:g} to {stop:g} gives numbers that are not finite")
    values = [float(v) for v in array]
    return values, values


def _angles(node: Node) -> np.ndarray:
    if isinstance(node.value, list):
        if not 1 <= len(node.value) <= MAX_VALUES:
            raise node.error(f"expected a list of 1 to {MAX_VALUES} angles")
        return node.vector()
    return Node(grid_values(node, {})[0], node.path).vector()


AXIS_ANGLE = Section((
    custom("axis", "Rotation axis (any length but zero): each quaternion is the rotation from the identity about "
           "it, as the scenario's ``axis_angle`` attitude form in the inertial frame.",
           "list of 3 numbers", rotation_axis),
    custom("angle_deg", "Rotation angles: a list, or a generator such as ``{linspace: [0, 180, 7]}``.",
           "list of numbers or {generator: argument}", _angles, unit="deg"),
), "Quaternions of rotations about one axis.")


def _axis_angle(argument: dict[str, Any], base: Mapping[str, Any]) -> tuple[list[Any], list[Any]]:
    axis, angles_deg = argument["axis"], argument["angle_deg"]
    maneuver = base.get("maneuver", {})
    scalar_last = isinstance(maneuver, dict) and maneuver.get("quaternion_order") == "scalar_last"
    quaternions = []
    for angle in angles_deg:
        q = axis_angle_quaternion(axis, angle)  # the conversion of the scenario's axis_angle form
        quaternions.append([float(v) for v in (quat.to_scalar_last(q) if scalar_last else q)])
    return quaternions, [float(a) for a in angles_deg]


VALUE_GENERATORS: dict[str, ValueGenerator] = {generator.name: generator for generator in (
    ValueGenerator(custom("linspace", "``count`` evenly spaced numbers from ``start`` to ``stop`` (both included).",
                          "list [start, stop, count]", lambda node: _spaced_values(node, np.linspace),
                          bounds=f"count from 1 to {MAX_VALUES}"), lambda values, base: values),
    ValueGenerator(custom("geomspace", "``count`` numbers evenly spaced on a log scale from ``start`` to ``stop``.",
                          "list [start, stop, count]", lambda node: _spaced_values(node, np.geomspace),
                          bounds=f"start, stop > 0; count from 1 to {MAX_VALUES}"), lambda values, base: values),
    ValueGenerator(mapping("axis_angle", "Unit quaternions rotating by each angle about ``axis`` (in the order of "
                           "``maneuver.quaternion_order``); the tables record the angle [deg].", AXIS_ANGLE),
                   _axis_angle),
)}
"""The value generators of ``grid`` and ``zip`` entries: name -> :class:`ValueGenerator`. Register a
generator of your own by adding it under its name."""


def _listing(names: list[str], last: str) -> str:
    return ", ".join(names) if len(names) < 2 else f"{', '.join(names[:-1])} {last} {names[-1]}"


def grid_values(node: Node, base: Mapping[str, Any]) -> tuple[list[Any], list[Any]]:
    """The values of one ``grid`` or ``zip`` entry: a list, or ``{<generator>: <argument>}``.

    Parameters
    ----------
    node : Node
        The entry (``grid.<scenario path>``).
    base : mapping
        The base scenario mapping (a generator may read it, e.g. the quaternion order).

    Returns
    -------
    values : list
        The values set into the scenario.
    recorded : list
        The values recorded in the tables (lists and mappings as JSON text).

    Raises
    ------
    ScenarioError
        At the entry: an empty or too long list, an unknown generator or a bad argument.
    """
    spec = node.value
    if isinstance(spec, list):
        if not spec or len(spec) > MAX_VALUES:
            raise node.error(f"expected a list of 1 to {MAX_VALUES} values")
        return list(spec), [v if not isinstance(v, (list, dict)) else json.dumps(v) for v in spec]
    names = list(VALUE_GENERATORS)
    if not isinstance(spec, dict) or len(spec) != 1:
        raise node.error(f"expected a list of values or one of {', '.join(names)}; got {spec!r:.80}")
    (kind, _), = spec.items()
    generator = VALUE_GENERATORS.get(kind)
    if generator is None:
        raise node.error(f"unknown value generator {kind!r}; expected {_listing(names, 'or')}")
    return generator.generate(generator.argument.value(node), base)


GRID_ENTRY = custom("<path>", "A scenario path (``maneuver.duration``, ``planners[1].options.weight``, "
                    "``planners[label=smooth].options.weight``) and its values: a list, or a value generator "
                    "(listed below).", f"list of 1 to {MAX_VALUES} values or {{generator: argument}}", None)
"""A ``grid`` or ``zip`` entry, keyed by the scenario path it varies."""


# --- distributions of dispersions --------------------------------------------------------------

@dataclass(frozen=True)
class Distribution:
    """A distribution of Monte Carlo dispersions, written ``{<name>: <argument>}`` and drawn by
    inverse transform of unit samples.

    Parameters
    ----------
    argument : Key
        Reads the argument into ``(a, b, shape)``: two ``(n,)`` arrays of parameters (in the
        units of the scenario key dispersed, flattened row by row) and the shape of the value:
        ``()`` a number, ``(n,)`` a list of ``n`` numbers, ``(rows, columns)`` a matrix; its
        ``name`` is the distribution's.
    inverse_cdf : callable
        ``inverse_cdf(unit, a, b) -> draws``: unit samples in [0, 1) turned into draws, each
        ``(n,)`` array.
    """

    argument: Key
    inverse_cdf: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]

    @property
    def name(self) -> str:
        """The distribution's name (its argument's key)."""
        return self.argument.name


def _parameter(node: Node) -> np.ndarray:
    """A distribution's parameter: a number, a list of numbers or a matrix (a list of equal-length
    lists of numbers, such as a 3x3 tensor), as a 0-, 1- or 2-d array of finite floats."""
    if isinstance(node.value, list) and node.value and all(isinstance(row, list) for row in node.value):
        rows = [Node(row, f"{node.path}[{i}]").vector() for i, row in enumerate(node.value)]
        if len({row.size for row in rows}) != 1:
            raise node.error(f"expected a matrix (rows of equal length), got rows of {[row.size for row in rows]} "
                             "numbers")
        return np.array(rows)
    return node.vector() if isinstance(node.value, list) else np.asarray(node.number(), dtype=float)


def _numbers(first: Node, second: Node) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    a = _parameter(first)
    b = _parameter(second)
    if b.shape != a.shape:
        def shape(x: np.ndarray) -> str:
            return "a number" if x.ndim == 0 else " x ".join(map(str, x.shape))
        raise second.error(f"expected the shape of {first.path.rsplit('.', 1)[-1]} ({shape(a)}), got {shape(b)}")
    return a.ravel(), b.ravel(), a.shape


_PARAMETER = "number, list of numbers or matrix"

NORMAL = Section((
    custom("mean", "Mean of each component (a list: the value is a vector; a list of lists: a matrix, element by "
           "element).", _PARAMETER, None),
    custom("std", "Standard deviation of each component (as many as ``mean``).", _PARAMETER, None,
           bounds=">= 0"),
), "A normal distribution per component.")

UNIFORM = Section((
    custom("low", "Low bound of each component (a list: the value is a vector; a list of lists: a matrix, element "
           "by element).", _PARAMETER, None),
    custom("high", "High bound of each component (as many as ``low``).", _PARAMETER, None, bounds=">= low"),
), "A uniform distribution per component, written ``[low, high]`` or ``{low, high}``.")


def _normal(node: Node) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    values = NORMAL.read(node)
    a, b, shape = _numbers(values["mean"], values["std"])
    if np.any(b < 0):
        raise values["std"].error(f"a standard deviation cannot be negative, got {excerpt(values['std'].value)}")
    return a, b, shape


def _uniform(node: Node) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    if isinstance(node.value, list):
        if len(node.value) != 2:
            raise node.error(f"expected [low, high], got {excerpt(node.value)}")
        a, b, shape = _numbers(Node(node.value[0], f"{node.path}[0]"), Node(node.value[1], f"{node.path}[1]"))
    else:
        values = UNIFORM.read(node)
        a, b, shape = _numbers(values["low"], values["high"])
    if np.any(b < a):
        raise node.error(f"expected low <= high, got {excerpt(node.value)}")
    return a, b, shape


_EPS = 1e-12  # keeps the normal's inverse CDF finite at u = 0


def _normal_inverse_cdf(unit: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    from scipy.special import ndtri  # lazily: scipy is slow to import for plain runs
    return a + b * ndtri(np.clip(unit, _EPS, 1.0 - _EPS))


def _uniform_inverse_cdf(unit: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a + unit * (b - a)


DISTRIBUTIONS: dict[str, Distribution] = {distribution.name: distribution for distribution in (
    Distribution(custom("normal", "Normal draws: ``{mean, std}``.", "mapping", _normal, section=NORMAL),
                 _normal_inverse_cdf),
    Distribution(custom("uniform", "Uniform draws: ``[low, high]`` or ``{low, high}``.", "list [low, high] or mapping",
                        _uniform, section=UNIFORM), _uniform_inverse_cdf),
)}
"""The distributions of dispersions: name -> :class:`Distribution`."""

COMBINATIONS: dict[str, tuple[Key, Callable[[np.ndarray, Any], Any]]] = {
    "scale": (custom("scale", "The base scenario's value times the draw.", "{distribution: argument}", None),
              lambda base, draw: base * draw),
    "offset": (custom("offset", "The base scenario's value plus the draw.", "{distribution: argument}", None),
               lambda base, draw: base + draw),
}
"""How a draw meets the base scenario's value when it does not replace it: name -> (its key,
``combine(base, draw)``)."""

CASE_SEED = custom("case_seed", "The case's own seed (for ``simulation.sensor_noise.seed``), written as the word "
                   "``case_seed``.", "the word case_seed", None)
"""The dispersion that sets a case's own seed."""

SYMMETRIC_KEYS = ("spacecraft.inertia", "truth.spacecraft.inertia")
"""Scenario keys holding a symmetric 3x3 tensor (or its 3 principal moments). A study that varies
one element ``<key>[i][j]`` sets ``<key>[j][i]`` to the same value; a matrix-shaped dispersion of
the key draws the upper triangle and mirrors it (its parameters must be symmetric); and the key
takes the ``principal`` dispersion (:data:`PRINCIPAL`)."""


def symmetric_key(steps: Sequence[Step]) -> bool:
    """Whether ``steps`` names one of :data:`SYMMETRIC_KEYS` (the whole key, no index).

    Parameters
    ----------
    steps : sequence of Step
        The parsed scenario path.

    Returns
    -------
    bool
    """
    return all(isinstance(step, str) for step in steps) and ".".join(map(str, steps)) in SYMMETRIC_KEYS


MAX_PRINCIPAL_AXES_DEG = 180.0
"""Largest rotation of the principal axes a ``principal.axes_deg`` draw may reach [deg] (a uniform
bound; a normal draw beyond it is refused at its case)."""

PRINCIPAL = Section((
    custom("moments_scale", "Factor on each principal moment of the base tensor: ``{<distribution>: <argument>}`` "
           "of a number (one factor for the three) or of 3 numbers, the moment about the principal axis nearest "
           "body axis x, y, z; absent: 1.", "{distribution: argument}", None, default=None,
           bounds="> 0, the scaled moments meeting the triangle inequality (a uniform's bounds)"),
    custom("axes_deg", "Rotation vector (body frame) turning the base tensor's principal axes: "
           "``{<distribution>: <argument>}`` of 3 numbers, the rotation's angle their norm; absent: none.",
           "{distribution: argument}", None, unit="deg", default=None,
           bounds=f"angle <= {MAX_PRINCIPAL_AXES_DEG:g} (a uniform's corners; a normal draw beyond it refuses "
                  "its case)"),
), "Dispersion of an inertia tensor in its principal frame: the case's tensor is "
   "``R V diag(s m) Vᵀ Rᵀ`` with ``V diag(m) Vᵀ`` the base tensor (its eigendecomposition), ``s`` the moment "
   "factors and ``R`` the rotation of ``axes_deg``: symmetric, positive definite while the factors are "
   "positive, with the principal axes turned by exactly the rotation's angle.")
"""The keys of the ``principal`` dispersion (:data:`PRINCIPAL_DISPERSION`)."""

PRINCIPAL_DISPERSION = custom(
    "principal", "For an inertia tensor (" + ", ".join(f"``{key}``" for key in SYMMETRIC_KEYS) + ") only: its "
    "principal moments scaled and its principal axes rotated, ``{principal: {moments_scale: <distribution>, "
    "axes_deg: <distribution>}}`` (at least one of the two). " + PRINCIPAL.meaning,
    "mapping {moments_scale, axes_deg}", None, section=PRINCIPAL)
"""The ``principal`` dispersion of a key of :data:`SYMMETRIC_KEYS`: ``{principal: {moments_scale:
<distribution>, axes_deg: <distribution>}}``, its keys :data:`PRINCIPAL`."""

DISPERSION = custom("<path>", "A scenario path and how it is dispersed: ``{<distribution>: <argument>}`` (the draw "
                    "is the value), ``{scale|offset: {<distribution>: <argument>}}``, ``case_seed``, or, for an "
                    "inertia tensor (``spacecraft.inertia``, ``truth.spacecraft.inertia``), ``{principal: "
                    "{moments_scale: <distribution>, axes_deg: <distribution>}}``: its principal moments scaled "
                    "and its principal axes rotated, the tensor kept symmetric and positive definite. A matrix "
                    "parameter (a 3x3 ``low``, ``high``, ``mean`` or ``std``) disperses a matrix element by "
                    "element; for an inertia tensor it must be symmetric, and the draw of element ``[i][j]`` is "
                    "that of ``[j][i]`` too. Dispersing (or varying) one product of inertia "
                    "``<tensor>[i][j]`` sets ``[j][i]`` to the same value.",
                    "mapping or the word case_seed", None)
"""A ``monte_carlo.dispersions`` entry, keyed by the scenario path it disperses."""


# --- the study's own keys ----------------------------------------------------------------------

def _samples(node: Node) -> int:
    samples = node.integer()
    if not 1 <= samples <= MAX_CASES:
        raise node.error(f"expected 1 to {MAX_CASES}, got {samples}")
    return samples


def _seed(node: Node) -> int:
    return node.integer(0, MAX_SEED)


def _name(node: Node) -> str:
    name = node.string()
    if not name.strip() or len(name) > MAX_NAME:
        raise node.error(f"expected a non-empty name of at most {MAX_NAME} characters, got {excerpt(name)}")
    return name


def _entries(node: Node) -> Node:
    return Node({}, node.path) if node.is_null() else node.mapping()


MONTE_CARLO = Section((
    custom("samples", "Monte Carlo samples per grid point.", "integer", _samples,
           bounds=f"1 to {MAX_CASES} cases in all"),
    choice("method", "``random``: independent uniforms; ``latin_hypercube``: a Latin hypercube per grid point "
           "(``scipy.stats.qmc``).", ("random", "latin_hypercube"), default="random"),
    custom("seed", "The study's seed: case ``i`` has ``SeedSequence(seed).spawn(n)[i].generate_state(1)[0]``.",
           "integer", _seed, default=0, bounds=f">= 0 and <= {MAX_SEED}"),
    custom("dispersions", "Scenario path -> dispersion (see the dispersions below).", "mapping",
           lambda node: node.mapping()),
), "Samples per grid point and what they disperse.")


def _workers(node: Node) -> int | None:
    if node.value == "auto" or node.is_null():
        return None
    workers = node.integer()
    if not 1 <= workers <= 1024:
        raise node.error(f"expected auto or 1 to 1024, got {workers}")
    return workers


_ADDRESS = re.compile(r"^(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?"
                      r"(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9.-]{0,251}[A-Za-z0-9])?):(?P<port>[0-9]{1,5})$")


def scheduler_address(text: Any, where: str) -> str:
    """A Dask scheduler's address, checked before anything connects to it.

    Parameters
    ----------
    text : Any
        The address as given: ``[scheme://]host:port`` with a scheme of
        :data:`SCHEDULER_SCHEMES` (none: ``tcp``), a host name, an IPv4 address or an IPv6
        address in brackets (``tcp://[::1]:8786``), and a port from 1 to 65535.
    where : str
        Where it was given (``execution.scheduler``, ``--scheduler``), for the message.

    Returns
    -------
    str
        The address with its scheme (``tcp://`` added when none was given).

    Raises
    ------
    ScenarioError
        At ``where``, for anything else (the value shown cut to 80 characters).
    """
    example = "expected an address such as tcp://127.0.0.1:8786"
    if not isinstance(text, str):
        raise ScenarioError(where, f"{example}, got {excerpt(text)}")
    match = _ADDRESS.match(text.strip())
    if match is None:
        raise ScenarioError(where, f"{example} ([scheme://]host:port), got {excerpt(text)}")
    scheme = (match["scheme"] or "tcp").lower()
    if scheme not in SCHEDULER_SCHEMES:
        raise ScenarioError(where, f"unknown scheme {excerpt(scheme)}; expected one of {', '.join(SCHEDULER_SCHEMES)}")
    if not 1 <= int(match["port"]) <= 65535:
        raise ScenarioError(where, f"expected a port from 1 to 65535, got {match['port']}")
    return f"{scheme}://{match['host']}:{int(match['port'])}"


def _scheduler(node: Node) -> str | None:
    return None if node.value is None else scheduler_address(node.value, node.path)


def _retries(node: Node) -> int:
    retries = node.integer()
    if not 0 <= retries <= 10:
        raise node.error(f"expected 0 to 10, got {retries}")
    return retries


EXECUTION = Section((
    custom("workers", "Cases run at once on the local process pool; ``auto``: one per core.", "integer, auto or null",
           _workers, default="auto", bounds="1 to 1024"),
    custom("scheduler", "Address of a Dask scheduler (``tcp://host:8786``); ``null``: the local process pool.",
           "text or null", _scheduler, default=None),
    number("case_timeout_s", "Wall time after which a case is stopped and becomes a ``crashed`` row.", unit="s",
           default=600.0, positive=True, maximum=MAX_CASE_TIMEOUT_S),
    custom("retries", "How many times a case whose worker died, or failed it (out of memory, a module missing), "
           "is run again.", "integer", _retries, default=1, bounds="0 to 10"),
), "How the cases run.")


_UNSET = object()


def _metric_column(metric: str, where: str, bound: object = _UNSET) -> str:
    """``metric`` when it names a metric column or a requirement column that holds a number, else an
    error at ``where`` (``bound``: the threshold's value given for it, named in the error)."""
    if isinstance(metric, str) and is_verdict_column(metric):
        prefix, _, name, _ = metric.split(".")
        kind = requirement_kind(name)
        numbers = [f"{prefix}.{REQUIREMENT_MARK}.{name}.{declared.field}" for declared in REQUIREMENT_FIELDS
                   if declared.requirement == kind and declared.field != VERDICT and prefix in declared.scopes]
        given = "" if bound is _UNSET else f" (given the bound {excerpt(bound)})"
        scope = "reference" if prefix == "ref" else "closed loop"
        if not numbers:  # a kind of requirement never scored in this scope (final in the reference)
            raise ScenarioError(where, f"{metric!r}: requirement {name!r} ({kind}) is not scored in the {scope}, so it has no "
                                       f"verdict there{given}; expected a number column such as a metric "
                                       f"(cl.final_error_deg) or a requirement's field in a scope that scores it")
        raise ScenarioError(where, f"{metric!r} is whether requirement {name!r} is met in the "
                                   f"{'reference' if prefix == 'ref' else 'closed loop'}, true or false (its verdict: "
                                   f"requirements.csv counts the cases that meet it), not a number to "
                                   f"{'summarise' if bound is _UNSET else 'bound'}{given}; expected a number "
                                   f"column such as {', '.join(numbers)}")
    if not isinstance(metric, str) or metric not in metric_columns() and not is_requirement_column(metric):
        scalars = [key for key in METRIC_KEYS if key != "plan_time_s" and key not in VECTOR_METRICS]
        vectors = ", ".join(f"cl.{key}_x" for key in VECTOR_METRICS)
        raise ScenarioError(where, f"expected ref.<metric> or cl.<metric> with a metric of {scalars}, or one axis "
                                   f"of a vector metric ({vectors}, _y, _z), or a requirement's "
                                   f"ref.req.<name>.<field>, got {excerpt(metric)}")
    return metric


def _summary(node: Node) -> list[str]:
    if isinstance(node.value, Described) or node.is_null():
        return list(DEFAULT_SUMMARY)
    return [_metric_column(item.string(), f"summary[{index}]") for index, item in enumerate(node.items())]


THRESHOLD_SENSES = ("at_most", "at_least")
"""How a ``robustness.thresholds`` entry compares a metric with its bound: a bare number is ``at_most``."""
MAX_WORST = 100
"""Most worst cases listed per planner row and metric (``robustness.worst``)."""


def _thresholds(node: Node) -> dict[str, tuple[str, float]]:
    """``robustness.thresholds``: metric column -> ``(sense, bound)``."""
    thresholds = {}
    mapped = _entries(node)
    for metric in mapped.value:
        entry = mapped.get(metric)
        _metric_column(metric, entry.path, entry.value)
        if isinstance(entry.value, dict):
            if len(entry.value) != 1 or next(iter(entry.value)) not in THRESHOLD_SENSES:
                raise entry.error(f"expected a number (the metric at most it) or {{at_most: number}} or "
                                  f"{{at_least: number}}, got {excerpt(entry.value)}")
            sense = next(iter(entry.value))
            thresholds[metric] = (sense, entry.get(sense).number())
        else:
            thresholds[metric] = ("at_most", entry.number())
    return thresholds


def _worst(node: Node) -> int:
    return node.integer(1, MAX_WORST)


THRESHOLD = Section((
    number("at_most", "The metric meets the threshold when at most this (a bare number means the same).",
           default=None, nullable=True),
    number("at_least", "The metric meets the threshold when at least this (a margin, say).", default=None,
           nullable=True),
), "A bound on a metric column (``cl.final_error_deg``, ``cl.req.<name>.<field>``), in its unit: a number, "
   "``{at_most: number}`` or ``{at_least: number}``.")

ROBUSTNESS = Section((
    custom("thresholds", "Metric column -> bound: the robustness table gives, per planner row, the fraction of "
           "the completed cases whose metric is at most the bound (``{at_least: bound}``: at least it), with its "
           "Wilson 95 % interval, beside the fraction meeting every requirement. A case without a value (a failed "
           "row) does not meet it.", "mapping of metric columns to a number, {at_most: number} or "
           "{at_least: number}", _thresholds, default={}, section=THRESHOLD, named=True),
    custom("worst", "How many worst cases are listed per planner row and summary metric (the largest values; the "
           "smallest for a metric with an ``at_least`` threshold).", "integer", _worst, default=5,
           bounds=f"1 to {MAX_WORST}"),
), "The robustness outputs of a Monte Carlo study: probabilities of meeting the requirements and thresholds, "
   "rank correlations of the summary metrics with the dispersed parameters, the worst cases.")


STUDY = Section((
    custom("study", f"The study's name (names ``results/<study>/`` by default; at most {MAX_NAME} characters).",
           "text", _name),
    custom("scenario", "The base scenario: a file path relative to the study file, or the scenario mapping itself.",
           "text or mapping", None),
    custom("grid", "Scenario path -> values; the cases are the cartesian product (the last key varies fastest).",
           "mapping", _entries, default={}),
    custom("zip", "Scenario path -> values, lists of equal length varied together (one more grid axis).",
           "mapping", _entries, default={}),
    mapping("monte_carlo", "Monte Carlo samples per grid point; absent or ``null``: none.", MONTE_CARLO, default=None,
            null="none"),
    custom("summary", "The metrics summarised per planner label (and grid point): ``ref.<metric>`` or "
           "``cl.<metric>``, a vector's component as ``<metric>_x``, or a requirement's "
           "``ref.req.<name>.<field>`` (``cl.req...``) that some case gives.", "list of text or null", _summary,
           default=Described("every scalar metric, ref. and cl.")),
    mapping("execution", "How the cases run.", EXECUTION, default={}, null="defaults"),
    mapping("robustness", "The robustness outputs (``robustness.csv``, ``sensitivity.csv``, ``worst_cases.csv``): "
            "thresholds on metrics and how many worst cases to list.", ROBUSTNESS, default={}, null="defaults"),
    custom("resolved", "Written by slewbench into the stored ``study.yaml`` (version, case seeds) and ignored "
           "when read.", "mapping", None, default=None),
), "A trade study file.")


# --- the scenario keys a study varies -----------------------------------------------------------

Step = str | int | tuple[str, str]
"""One step of a scenario path: a mapping key, a list index or a ``(key, value)`` selector."""

INDEPENDENT_KEYS = (
    "simulation.initial_attitude_error_deg",
    "simulation.initial_rate_error",
    "simulation.sensor_noise.attitude_deg",
    "simulation.sensor_noise.rate",
    "simulation.sensor_noise.seed",
    "simulation.sensor_noise.magnetic_field",
    "simulation.settling_tolerance_deg",
    "simulation.fine_settling_tolerance_deg",
    "simulation.detumble_tolerance",
)
"""Scenario keys that no check of the scenario as a whole reads: the loader's verdict on a scenario
is its verdict on the key's value alone (the key's own reader) and on the rest of the scenario.
A study checks the values it gives these keys with their readers, and runs the whole loader once
per combination of its other values (:mod:`scenarios.study.spec`). Add a key here only when
nothing but its reader, and the run itself, reads it; ``tests/test_study_validation.py`` compares
both verdicts. One exception, decided per scenario: a controller whose law is defined on part of
the attitudes (the two-wheel laws) checks the start as simulated, initial errors applied
(:func:`scenarios.schema.checks.reads_the_simulated_start`), and a study parses every case of such a
scenario whole."""


def declared_key(steps: Sequence[Step]) -> Key | None:
    """The scenario key the schema declares at a path of mapping keys (list entries of a key that
    holds entries, such as ``planners[0]``, pass through).

    Parameters
    ----------
    steps : sequence of Step
        The parsed scenario path.

    Returns
    -------
    Key or None
        The key (its reader checks a value), or None where the schema declares none (a planner's
        or controller's options, an unknown key).
    """
    section: Section | None = SCENARIO
    key: Key | None = None
    for step in steps:
        if isinstance(step, str):
            if section is None or key is not None and key.entries:
                return None
            try:
                key = section[step]
            except KeyError:
                return None
            section = key.section
        elif key is None or not key.entries:
            return None
        else:
            key = Key(key.name, "mapping", key.meaning, None, section=key.section)  # one entry of the list
    return key


def independent_key(steps: Sequence[Step]) -> Key | None:
    """The key at ``steps`` when it is one of :data:`INDEPENDENT_KEYS`, with a reader.

    Parameters
    ----------
    steps : sequence of Step
        The parsed scenario path.

    Returns
    -------
    Key or None
        The key, or None when the path is not an independent key.
    """
    if not all(isinstance(step, str) for step in steps) or ".".join(map(str, steps)) not in INDEPENDENT_KEYS:
        return None
    key = declared_key(steps)
    return key if key is not None and key.read is not None else None


def _option_type(steps: Sequence[Step], base: Mapping[str, Any]) -> Any:
    """The type of a planner's or controller's option at ``steps`` (``planners[i].options.<name>``,
    ``controller.options.<name>``, ``controllers[i].options.<name>``), from the entry's name in
    ``base``; None when the path is not an option of a registered component."""
    registries: dict[str, Mapping[str, Any]] = {"planners": PLANNERS, "controllers": CONTROLLERS,
                                                "controller": CONTROLLERS}
    head = steps[0] if steps else None
    if not isinstance(head, str) or head not in registries:
        return None
    entry: Any = base.get(head)
    rest = list(steps[1:])
    if head != "controller":
        if not rest or not isinstance(entry, list):
            return None
        step = rest.pop(0)
        if isinstance(step, int):
            entry = entry[step] if -len(entry) <= step < len(entry) else None
        elif isinstance(step, tuple):
            found = [item for item in entry if isinstance(item, dict) and str(item.get(step[0])) == step[1]]
            entry = found[0] if len(found) == 1 else None
        else:
            return None
    if len(rest) != 2 or rest[0] != "options" or not isinstance(entry, dict):
        return None
    name = entry.get("name")
    component = registries[head].get(name) if isinstance(name, str) else None
    if component is None:
        return None
    field = option_fields(component.Options).get(str(rest[1]))
    return None if field is None else field[0]


def takes_integers(steps: Sequence[Step], base: Mapping[str, Any]) -> bool | None:
    """Whether the scenario key at ``steps`` takes an integer (the keys ``case_seed`` may set).

    Parameters
    ----------
    steps : sequence of Step
        The parsed scenario path.
    base : mapping
        The base scenario (it names the planner or controller of an option path).

    Returns
    -------
    bool or None
        True for an integer key of the scenario schema (``simulation.sensor_noise.seed``), or a
        planner's or controller's option typed ``int`` (or ``int | None``); False for any other
        key the schema declares; None where it declares none (the scenario loader then refuses an
        unknown key).
    """
    key = declared_key(steps)
    if key is not None:
        return key.type == "integer"
    annotation = _option_type(steps, base)
    if annotation is None:
        return None
    if annotation is int:
        return True
    return typing.get_origin(annotation) in (typing.Union, types.UnionType) and int in typing.get_args(annotation)
