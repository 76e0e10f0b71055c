"""Monte Carlo dispersions of a trade study: distributions drawn by inverse transform from unit
samples (plain random or a Latin hypercube from ``scipy.stats.qmc``), applied to a scenario path.

The forms are the study schema's (:mod:`scenarios.schema.study`): a distribution of the registry
:data:`~scenarios.schema.study.DISTRIBUTIONS` (``{normal: {mean, std}}``, ``{uniform: [low,
high]}``, of a number, a vector or a matrix) sets the value; ``{scale: <distribution>}``
multiplies the base scenario's value and ``{offset: <distribution>}`` adds to it
(:data:`~scenarios.schema.study.COMBINATIONS`); ``case_seed`` sets the case's own seed (for
``simulation.sensor_noise.seed``). An inertia tensor (:data:`~scenarios.schema.study.SYMMETRIC_KEYS`)
stays symmetric: a matrix-shaped draw of it draws the upper triangle and mirrors it, and
``{principal: {moments_scale, axes_deg}}`` (:data:`~scenarios.schema.study.PRINCIPAL`) scales its
principal moments and turns its principal axes.

Each dispersion also names its *drawn quantities* (:meth:`Dispersion.drawn`): the numbers drawn
per case, one per independent component (a whole-tensor ``scale`` is one number, however many
elements it multiplies), which the sensitivity table correlates with the metrics.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ocp.errors import excerpt
from scenarios.errors import ScenarioError
from scenarios.schema.node import Node
from scenarios.schema.study import (
    CASE_SEED,
    COMBINATIONS,
    DISTRIBUTIONS,
    MAX_PRINCIPAL_AXES_DEG,
    PRINCIPAL,
    PRINCIPAL_DISPERSION,
    SYMMETRIC_KEYS,
    symmetric_key,
)
from scenarios.study.paths import Step, _describe, get_path

PRINCIPAL_NAME = PRINCIPAL_DISPERSION.name
"""The dispersion form of :data:`~scenarios.schema.study.PRINCIPAL_DISPERSION`."""


@dataclass
class Draw:
    """One distribution of a dispersion: its parameters and the shape of the value it draws.

    Parameters
    ----------
    kind : str
        A distribution of :data:`~scenarios.schema.study.DISTRIBUTIONS`.
    a, b : (n,) ndarray
        Its parameters (mean and standard deviation, low and high bounds), flattened row by row.
    shape : tuple of int
        The value's shape: ``()`` a number, ``(n,)`` a vector, ``(rows, columns)`` a matrix.
    symmetric : bool, optional
        A square matrix drawn as its upper triangle (diagonal included), each draw of ``[i][j]``
        also that of ``[j][i]`` (the parameters are symmetric).
    """

    kind: str
    a: np.ndarray
    b: np.ndarray
    shape: tuple[int, ...]
    symmetric: bool = False

    @property
    def independent(self) -> list[tuple[int, ...]]:
        """The indices of the components drawn independently (the upper triangle of a symmetric matrix)."""
        indices: list[tuple[int, ...]] = [tuple(int(i) for i in index) for index in np.ndindex(*self.shape)]
        return [index for index in indices if not self.symmetric or index[0] <= index[-1]]

    @property
    def dimension(self) -> int:
        """Unit samples the draw consumes."""
        return len(self.independent)

    def names(self) -> list[str]:
        """The independent components as suffixes of a path.

        Returns
        -------
        list of str
            ``""`` (a scalar), ``[k]`` or ``[i][j]`` per independent component (a symmetric
            matrix's upper triangle).
        """
        return ["".join(f"[{i}]" for i in index) for index in self.independent]

    def components(self, units: np.ndarray) -> np.ndarray:
        """The drawn independent components.

        Parameters
        ----------
        units : (cases, dimension) ndarray
            Unit samples in [0, 1), one column per independent component.

        Returns
        -------
        (cases, dimension) ndarray
            The components drawn from the distribution by its inverse CDF.
        """
        flat = [int(np.ravel_multi_index(index, self.shape)) if self.shape else 0 for index in self.independent]
        return DISTRIBUTIONS[self.kind].inverse_cdf(units, self.a[flat], self.b[flat])

    def values(self, units: np.ndarray) -> np.ndarray:
        """The drawn values, a symmetric matrix mirrored from its upper triangle.

        Parameters
        ----------
        units : (cases, dimension) ndarray
            Unit samples in [0, 1), one column per independent component.

        Returns
        -------
        (cases,) + shape ndarray
            One drawn value (scalar, vector or matrix) per case.
        """
        components = self.components(units)
        out = np.empty((units.shape[0], max(1, math.prod(self.shape))))
        for column, index in enumerate(self.independent):
            for where in {index, index[::-1]} if self.symmetric else {index}:
                out[:, int(np.ravel_multi_index(where, self.shape)) if self.shape else 0] = components[:, column]
        return out.reshape((units.shape[0],) + self.shape)


def _rotations(vectors_deg: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(cases, 3, 3)`` of rotation vectors [deg] (Rodrigues' formula)."""
    theta = np.radians(vectors_deg)
    angle = np.linalg.norm(theta, axis=1)
    axis = np.divide(theta, angle[:, None], out=np.zeros_like(theta), where=angle[:, None] > 0)
    k = np.zeros((theta.shape[0], 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -axis[:, 2], axis[:, 1], -axis[:, 0]
    k -= k.transpose(0, 2, 1)
    sin, cos = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + sin * k + (1.0 - cos) * k @ k


def principal_frame(base: Any) -> tuple[np.ndarray, np.ndarray]:
    """The principal moments and axes of an inertia tensor, axis ``k`` the one nearest body axis ``k``.

    Parameters
    ----------
    base : array_like
        3 principal moments (the axes are the body axes) or a symmetric 3x3 tensor.

    Returns
    -------
    moments : (3,) ndarray
        The moment about each axis.
    axes : (3, 3) ndarray
        The axes as columns, each with a non-negative component along its body axis: ``base`` is
        ``axes @ diag(moments) @ axes.T``. Of equal moments, the axes are those ``numpy.linalg.eigh``
        gives in their plane.
    """
    tensor = np.asarray(base, dtype=float)
    if tensor.shape == (3,):
        return tensor.copy(), np.eye(3)
    moments, axes = np.linalg.eigh(tensor)
    order = max(itertools.permutations(range(3)), key=lambda p: sum(abs(axes[k, p[k]]) for k in range(3)))
    axes = axes[:, list(order)]
    axes = axes * np.where(np.diag(axes) < 0, -1.0, 1.0)
    return moments[list(order)], axes


@dataclass
class Dispersion:
    """How a study disperses one scenario path: its draws and how they meet the base value.

    Parameters
    ----------
    kind : str
        A distribution of :data:`~scenarios.schema.study.DISTRIBUTIONS` (``normal``,
        ``uniform``), ``case_seed`` or ``principal``.
    combine : str
        ``set`` (the draw is the value), a combination of
        :data:`~scenarios.schema.study.COMBINATIONS` (``scale``: it multiplies the base value,
        ``offset``: it is added to it) or ``principal`` (the base tensor's principal moments
        scaled and its axes turned, :data:`~scenarios.schema.study.PRINCIPAL`).
    draws : dict of str to Draw
        The distributions drawn: ``""`` for ``set``, ``scale`` and ``offset``; ``moments_scale``
        and ``axes_deg`` (either may be absent) for ``principal``; none for ``case_seed``.
    """

    kind: str
    combine: str
    draws: dict[str, Draw] = field(default_factory=dict)

    @property
    def dimension(self) -> int:
        """Unit samples the dispersion consumes (0 for ``case_seed``)."""
        return sum(draw.dimension for draw in self.draws.values())

    @property
    def needs_base(self) -> bool:
        """Whether :meth:`values` needs the base scenario's value (``scale``, ``offset``, ``principal``)."""
        return self.combine != "set"

    def _split(self, units: np.ndarray) -> dict[str, np.ndarray]:
        out, column = {}, 0
        for name, draw in self.draws.items():
            out[name] = units[:, column:column + draw.dimension]
            column += draw.dimension
        return out

    def drawn(self, units: np.ndarray) -> tuple[list[str], np.ndarray]:
        """The drawn quantities: what each case draws, one number per independent component.

        Parameters
        ----------
        units : (cases, dimension) ndarray
            Unit samples in [0, 1), one row per case.

        Returns
        -------
        names : list of str
            Suffixes of the dispersed path naming each quantity: ``""`` (one number: a scalar, or
            the one factor of a whole-tensor ``scale``), ``[k]``, ``[i][j]`` (a matrix's upper
            triangle when symmetric), ``.principal.moments_scale[k]``, ``.principal.axes_deg[k]``.
        values : (cases, len(names)) ndarray
            The draws, in the distribution's units (a factor, an offset, a value, degrees).
        """
        if not self.draws:
            return [], np.zeros((units.shape[0], 0))
        names, values = [], []
        with np.errstate(all="ignore"):
            for (name, draw), part in zip(self.draws.items(), self._split(units).values()):
                prefix = f".{PRINCIPAL_NAME}.{name}" if name else ""
                names += [prefix + suffix for suffix in draw.names()]
                values.append(draw.components(part))
        return names, np.concatenate(values, axis=1)

    def value(self, unit: np.ndarray, seed: int, base: Any) -> Any:
        """The dispersed value from unit samples and the base value.

        Parameters
        ----------
        unit : (dimension,) ndarray
            Unit samples in [0, 1), turned into the distribution by its inverse CDF.
        seed : int
            The case's seed (the value of ``case_seed``).
        base : Any
            The base scenario's value at the path (a number or a list; used by ``scale``,
            ``offset`` and ``principal``, else ignored).

        Returns
        -------
        Any
            The case's value: an int (``case_seed``), a float, or an ndarray for a vector or matrix.
        """
        if self.kind == CASE_SEED.name:
            return seed
        value = self.values(np.asarray(unit, dtype=float).reshape(1, -1), [seed], base)
        return value[0] if isinstance(value, list) else value[0] if value.ndim > 1 else float(value[0])

    def values(self, units: np.ndarray, seeds: list[int], base: Any) -> np.ndarray | list[int]:
        """The dispersed values of many cases at once, each as :meth:`value` gives it.

        Parameters
        ----------
        units : (cases, dimension) ndarray
            Unit samples in [0, 1), one row per case.
        seeds : list of int
            The cases' seeds (the values of ``case_seed``).
        base : Any
            The base scenario's value at the path (used by ``scale``, ``offset`` and ``principal``).

        Returns
        -------
        ndarray or list of int
            The seeds for ``case_seed``; else one row per case (a float per case for a scalar, a
            row of the value's shape for a vector, a matrix or a scaled list), not finite where a
            draw or its combination overflowed (NumPy's warnings silenced: the caller reports it).
        """
        if self.kind == CASE_SEED.name:
            return list(seeds)
        parts = self._split(units)
        with np.errstate(all="ignore"):
            if self.combine == PRINCIPAL_NAME:
                return self._principal(parts, base)
            draws = self.draws[""].values(parts[""])  # (cases,) + shape
            if self.combine == "set":
                return draws
            base_value = np.asarray(base, dtype=float)
            shape = draws.shape[1:]
            rank = max(base_value.ndim, len(shape))
            draws = draws.reshape((draws.shape[0],) + (1,) * (rank - len(shape)) + shape)
            return COMBINATIONS[self.combine][1](base_value, draws)

    def _principal(self, parts: dict[str, np.ndarray], base: Any) -> np.ndarray:
        """``R V diag(s m) Vᵀ Rᵀ`` per case (:data:`~scenarios.schema.study.PRINCIPAL`)."""
        cases = next(iter(parts.values())).shape[0]
        moments, axes = principal_frame(base)
        scale = np.ones((cases, 3))
        if "moments_scale" in self.draws:
            scale = np.broadcast_to(self.draws["moments_scale"].values(parts["moments_scale"]).reshape(cases, -1),
                                    (cases, 3))
        turned = np.broadcast_to(axes, (cases, 3, 3))
        if "axes_deg" in self.draws:
            turned = _rotations(self.draws["axes_deg"].values(parts["axes_deg"])) @ axes
        tensor = (turned * (scale * moments)[:, None, :]) @ turned.transpose(0, 2, 1)
        return 0.5 * (tensor + tensor.transpose(0, 2, 1))  # symmetric to the last bit

    def refused(self, units: np.ndarray) -> tuple[int, str] | None:
        """The first case whose draw the dispersion refuses, and why.

        Parameters
        ----------
        units : (cases, dimension) ndarray
            The cases' unit samples.

        Returns
        -------
        (int, str) or None
            The case's index and the reason (a ``principal.axes_deg`` rotation beyond
            :data:`~scenarios.schema.study.MAX_PRINCIPAL_AXES_DEG`); ``None`` if none is refused.
        """
        if "axes_deg" not in self.draws or self.combine != PRINCIPAL_NAME:
            return None
        with np.errstate(all="ignore"):
            angles = np.linalg.norm(self.draws["axes_deg"].values(self._split(units)["axes_deg"]), axis=1)
        beyond = np.flatnonzero(~(angles <= MAX_PRINCIPAL_AXES_DEG))
        if not beyond.size:
            return None
        return int(beyond[0]), (f"principal.axes_deg draws a rotation of {angles[beyond[0]]:.6g} deg, beyond "
                                f"{MAX_PRINCIPAL_AXES_DEG:g} deg; narrow its distribution")


def _forms() -> str:
    def form(key: Any) -> str:
        return "{" + ", ".join(k.name for k in key.section.keys) + "}" if key.section else "..."
    distributions = ", ".join(f"{{{name}: {form(d.argument)}}}" for name, d in DISTRIBUTIONS.items())
    return (f"{CASE_SEED.name}, {distributions}, {{{'|'.join(COMBINATIONS)}: <distribution>}} or (an inertia tensor) "
            f"{{{PRINCIPAL_NAME}: {{{', '.join(k.name for k in PRINCIPAL.keys)}}}}}")


def _shape_text(shape: tuple[int, ...]) -> str:
    return "a number" if not shape else f"{shape[0]} numbers" if len(shape) == 1 else " x ".join(map(str, shape))


def _distribution(node: Node, symmetric: bool) -> Draw:
    """The distribution ``{<name>: <argument>}`` at ``node``; ``symmetric``: of a symmetric tensor."""
    if not isinstance(node.value, dict) or len(node.value) != 1 or next(iter(node.value)) not in DISTRIBUTIONS:
        raise node.error(f"expected {_forms()}; got {excerpt(node.value)}")
    kind = next(iter(node.value))
    a, b, shape = DISTRIBUTIONS[kind].argument.value(node)
    draw = Draw(kind, a, b, shape)
    if symmetric and len(shape) == 2:
        if shape != (3, 3):
            raise node.error(f"an inertia tensor is 3 x 3; got a matrix of {_shape_text(shape)}")
        for name, parameter in (("a", a), ("b", b)):
            matrix = parameter.reshape(3, 3)
            i, j = np.unravel_index(int(np.argmax(np.abs(matrix - matrix.T))), (3, 3))
            if matrix[i, j] != matrix[j, i]:
                which = {"normal": ("mean", "std"), "uniform": ("low", "high")}.get(kind, ("a", "b"))[name == "b"]
                raise node.error(f"a matrix dispersion of an inertia tensor needs symmetric parameters (the draw of "
                                 f"[i][j] is that of [j][i]): {which}[{i}][{j}] = {matrix[i, j]:g} but "
                                 f"{which}[{j}][{i}] = {matrix[j, i]:g}")
        draw.symmetric = True
    return draw


def _check_moment_factors(node: Node, draw: Draw, moments: np.ndarray | None) -> None:
    """Refuse a uniform draw of factors on an inertia tensor's moments that can reach a tensor that is
    not physical: a factor of 0 or less (not positive definite) or, given the principal ``moments``
    the factors multiply one by one, moments that break the triangle inequality. A normal draw has
    no bounds: a case that draws such a factor is refused at that case."""
    if draw.kind != "uniform":
        return
    factors_low, factors_high = np.asarray(draw.a, dtype=float), np.asarray(draw.b, dtype=float)
    if draw.shape == (3, 3):  # element by element: the diagonal's factors must stay > 0
        factors_low, factors_high = np.diag(factors_low.reshape(3, 3)), np.diag(factors_high.reshape(3, 3))
    if np.any(~(factors_low > 0)):
        raise node.error(f"a factor on an inertia tensor's moments (its diagonal) must be > 0 (a positive definite "
                         f"tensor), got a low bound of {float(np.min(factors_low)):g} in {excerpt(node.value)}; "
                         f"expected uniform bounds > 0")
    if moments is None or draw.shape == ():  # one factor for all: the moments keep their ratios
        return
    low, high = np.broadcast_to(factors_low, (3,)) * moments, np.broadcast_to(factors_high, (3,)) * moments
    for k in range(3):  # the worst draw: the other two at their low bounds, this one at its high
        if low[(k + 1) % 3] + low[(k + 2) % 3] < high[k] * (1 - 1e-12):
            raise node.error(
                f"these factors can draw principal moments that violate the triangle inequality: moment {k} "
                f"up to {high[k]:.6g} exceeds the other two at their lowest, {low[(k + 1) % 3]:.6g} + "
                f"{low[(k + 2) % 3]:.6g}; narrow the bounds")


def _principal(node: Node, base_value: Any, steps: list[Step]) -> Dispersion:
    """The ``principal`` dispersion at ``node`` (the mapping under ``principal``)."""
    if not symmetric_key(steps):
        raise node.error(f"{PRINCIPAL_NAME} disperses an inertia tensor ({', '.join(SYMMETRIC_KEYS)}), not this path")
    if np.asarray(base_value).shape not in ((3,), (3, 3)):
        raise node.error(f"{PRINCIPAL_NAME} needs the inertia in the base scenario (3 principal moments or the 3x3 "
                         f"tensor), got {excerpt(base_value)}")
    values = PRINCIPAL.read(node.mapping())
    draws: dict[str, Draw] = {}
    for name, sizes in (("moments_scale", ((), (3,))), ("axes_deg", ((3,),))):
        entry = values[name]
        if entry.value is None:
            continue
        draw = _distribution(entry, symmetric=False)
        if draw.shape not in sizes:
            raise entry.error(f"expected a distribution of {' or '.join(_shape_text(s) for s in sizes)}, got "
                              f"{_shape_text(draw.shape)}")
        draws[name] = draw
    if not draws:
        raise node.error("give moments_scale, axes_deg or both")
    moments, _ = principal_frame(base_value)
    scale = draws.get("moments_scale")
    if scale is not None:
        _check_moment_factors(values["moments_scale"], scale, moments)
    axes = draws.get("axes_deg")
    if axes is not None and axes.kind == "uniform":
        largest = max(float(np.linalg.norm(np.where(corner, axes.b, axes.a)))
                      for corner in itertools.product((False, True), repeat=3))
        if largest > MAX_PRINCIPAL_AXES_DEG:
            raise values["axes_deg"].error(f"these bounds reach a rotation of {largest:.6g} deg, beyond "
                                           f"{MAX_PRINCIPAL_AXES_DEG:g} deg")
    return Dispersion(PRINCIPAL_NAME, PRINCIPAL_NAME, draws)


def _base_value(base: dict[str, Any], steps: list[Step], where: str, combine: str) -> Any:
    """The base scenario's value that ``combine`` (``scale``, ``offset``, ``principal``) acts on; if
    the base scenario lacks it, an error that says how to fix that."""
    try:
        return get_path(base, steps, where)
    except ScenarioError as error:
        raise ScenarioError(error.path, f"{error.message}; {combine} acts on the base scenario's value: add "
                                        f"{_describe(steps)} to the base scenario (or draw the value itself, "
                                        f"without {combine})") from None


def parse_dispersion(node: Node, base: dict[str, Any], steps: list[Step]) -> Dispersion:
    """Parse the dispersion at ``node`` for the scenario path ``steps`` of ``base``.

    Parameters
    ----------
    node : Node
        The study entry ``monte_carlo.dispersions.<path>``.
    base : dict
        The base scenario mapping.
    steps : list of Step
        The parsed scenario path.

    Returns
    -------
    Dispersion

    Raises
    ------
    ScenarioError
        Naming the entry, for an unknown distribution, a negative standard deviation, bounds out
        of order, a ``scale``/``offset`` of a base value that is not numbers of that shape, a
        matrix dispersion of an inertia tensor with parameters that are not symmetric, a list of
        3 factors or offsets of a 3x3 tensor (it would break its symmetry), or a ``principal``
        dispersion whose bounds reach a tensor that is not physical.
    """
    if node.value == CASE_SEED.name:
        return Dispersion(CASE_SEED.name, "set")
    symmetric = symmetric_key(steps)
    if isinstance(node.value, dict) and len(node.value) == 1 and next(iter(node.value)) == PRINCIPAL_NAME:
        return _principal(node.get(PRINCIPAL_NAME), _base_value(base, steps, node.path, PRINCIPAL_NAME), steps)
    combine = "set"
    if isinstance(node.value, dict) and len(node.value) == 1 and next(iter(node.value)) in COMBINATIONS:
        combine = next(iter(node.value))
        node = COMBINATIONS[combine][0].value(node)
    draw = _distribution(node, symmetric)
    if combine != "set":
        base_value = _base_value(base, steps, node.path, combine)
        try:
            array = np.asarray(base_value, dtype=float)
        except (TypeError, ValueError):
            raise node.error(f"{combine} needs a number or numbers in the base scenario, got {base_value!r:.60}") from None
        shape = draw.shape
        if shape and array.shape[-len(shape):] != shape:
            hint = "; give a 3x3 matrix to disperse the tensor element by element" if array.shape == (3, 3) else ""
            raise node.error(f"{_shape_text(shape)} do not match the base value of shape {array.shape}{hint}")
        if symmetric and shape == (3,) and array.shape == (3, 3):
            raise node.error(f"{combine} by a list of 3 numbers would act on the tensor's columns and break its "
                             f"symmetry; give a number (the whole tensor), a symmetric 3x3 matrix (element by element) "
                             f"or {{{PRINCIPAL_NAME}: ...}} (principal moments and axes)")
        if symmetric and combine == "scale":
            _check_moment_factors(node, draw, array if array.shape == (3,) else None)
    return Dispersion(draw.kind, combine, {"": draw})


def draw_unit(method: str | None, dimension: int, samples: int, rng: np.random.Generator) -> np.ndarray:
    """Unit samples: independent uniforms, or a Latin hypercube design (``scipy.stats.qmc``).

    Parameters
    ----------
    method : str or None
        ``latin_hypercube``; anything else draws independent uniforms.
    dimension : int
        Components per sample.
    samples : int
        Number of samples.
    rng : numpy.random.Generator
        The source of randomness (seeded from the study's ``SeedSequence``).

    Returns
    -------
    (samples, dimension) ndarray
        Points in [0, 1).
    """
    if dimension == 0:
        return np.zeros((samples, 0))
    if method == "latin_hypercube":
        from scipy.stats import (
            qmc,  # lazily: 0.4 s to import, only for Latin hypercubes
        )

        return qmc.LatinHypercube(d=dimension, seed=rng).random(samples)
    return rng.random((samples, dimension))
