"""Monte Carlo dispersions of a trade study: distributions drawn by inverse transform from unit
samples (plain random or a Latin hypercube from ``scipy.stats.qmc``), applied to a scenario path.

The forms are the study schema's (:mod:`scenarios.schema.study`): a distribution of the registry
:data:`~scenarios.schema.study.DISTRIBUTIONS` (``{normal: {mean, std}}``, ``{uniform: [low,
high]}``, scalars or vectors) sets the value; ``{scale: <distribution>}`` multiplies the base
scenario's value and ``{offset: <distribution>}`` adds to it
(:data:`~scenarios.schema.study.COMBINATIONS`); ``case_seed`` sets the case's own seed (for
``simulation.sensor_noise.seed``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from scenarios.schema.node import Node
from scenarios.schema.study import CASE_SEED, COMBINATIONS, DISTRIBUTIONS
from scenarios.study.paths import Step, get_path


@dataclass
class Dispersion:
    """A distribution of ``dimension`` independent components and how it meets the base value.

    Parameters
    ----------
    kind : str
        A distribution of :data:`~scenarios.schema.study.DISTRIBUTIONS` (``normal``,
        ``uniform``) or ``case_seed``.
    combine : str
        ``set`` (the draw is the value) or a combination of
        :data:`~scenarios.schema.study.COMBINATIONS`: ``scale`` (it multiplies the base value),
        ``offset`` (it is added to the base value).
    a : (n,) ndarray
        Mean (normal) or low bound (uniform) of each component, in the units of the scenario
        key (a ``_deg`` key: degrees); empty for ``case_seed``.
    b : (n,) ndarray
        Standard deviation (normal) or high bound (uniform) of each component, same units.
    vector : bool
        The value is a list of ``n`` numbers, not a scalar.
    """

    kind: str
    combine: str
    a: np.ndarray
    b: np.ndarray
    vector: bool

    @property
    def dimension(self) -> int:
        """Unit samples the dispersion consumes (0 for ``case_seed``)."""
        return 0 if self.kind == CASE_SEED.name else int(self.a.size)

    @property
    def needs_base(self) -> bool:
        """Whether :meth:`value` needs the base scenario's value (``scale`` and ``offset``)."""
        return self.combine != "set"

    def value(self, unit: np.ndarray, seed: int, base: Any) -> Any:
        """The dispersed value from unit samples and the base value.

        Parameters
        ----------
        unit : (dimension,) ndarray
            Unit samples in [0, 1), turned into the distribution by its inverse CDF.
        seed : int
            The case's seed (the value of ``case_seed``).
        base : Any
            The base scenario's value at the path (a number or a list; used by ``scale`` and
            ``offset``, else ignored).

        Returns
        -------
        Any
            The case's value: an int (``case_seed``), a float, or an ndarray for a vector.
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
            The base scenario's value at the path (used by ``scale`` and ``offset``).

        Returns
        -------
        ndarray or list of int
            The seeds for ``case_seed``; else one row per case (a float per case for a scalar, a
            row of the value's shape for a vector or a scaled list), not finite where a draw or
            its combination overflowed (NumPy's warnings silenced: the caller reports it).
        """
        if self.kind == CASE_SEED.name:
            return list(seeds)
        with np.errstate(all="ignore"):
            draws = DISTRIBUTIONS[self.kind].inverse_cdf(units, self.a, self.b)  # (cases, n)
            if not self.vector:
                draws = draws[:, 0]
            if self.combine == "set":
                return draws
            base_value = np.asarray(base, dtype=float)
            shape = draws.shape[1:]
            rank = max(base_value.ndim, len(shape))
            draws = draws.reshape((draws.shape[0],) + (1,) * (rank - len(shape)) + shape)
            return COMBINATIONS[self.combine][1](base_value, draws)


def _forms() -> str:
    def form(key: Any) -> str:
        return "{" + ", ".join(k.name for k in key.section.keys) + "}" if key.section else "..."
    distributions = ", ".join(f"{{{name}: {form(d.argument)}}}" for name, d in DISTRIBUTIONS.items())
    return f"{CASE_SEED.name}, {distributions} or {{{'|'.join(COMBINATIONS)}: <distribution>}}"


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
        of order, or a ``scale``/``offset`` of a base value that is not numbers of that shape.
    """
    if node.value == CASE_SEED.name:
        return Dispersion(CASE_SEED.name, "set", np.zeros(0), np.zeros(0), False)
    combine = "set"
    if isinstance(node.value, dict) and len(node.value) == 1 and next(iter(node.value)) in COMBINATIONS:
        combine = next(iter(node.value))
        node = COMBINATIONS[combine][0].value(node)
    if not isinstance(node.value, dict) or len(node.value) != 1 or next(iter(node.value)) not in DISTRIBUTIONS:
        raise node.error(f"expected {_forms()}; got {node.value!r:.80}")
    kind = next(iter(node.value))
    a, b, vector = DISTRIBUTIONS[kind].argument.value(node)
    if combine != "set":
        base_value = get_path(base, steps, node.path)
        try:
            array = np.asarray(base_value, dtype=float)
        except (TypeError, ValueError):
            raise node.error(f"{combine} needs a number or numbers in the base scenario, got {base_value!r:.60}") from None
        if vector and array.shape[-1:] != (a.size,):
            raise node.error(f"{a.size} components do not match the base value of shape {array.shape}")
    return Dispersion(kind, combine, a, b, vector)


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
