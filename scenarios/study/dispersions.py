"""Monte Carlo dispersions of a trade study: distributions drawn by inverse transform from unit
samples (plain random or a Latin hypercube from ``scipy.stats.qmc``), applied to a scenario path.

``{normal: {mean, std}}`` and ``{uniform: [low, high]}`` (scalars or vectors) set the value;
``{scale: <distribution>}`` multiplies the base scenario's value and ``{offset: <distribution>}``
adds to it; ``case_seed`` sets the case's own seed (for ``simulation.sensor_noise.seed``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from scenarios.schema.node import Node
from scenarios.study.paths import Step, get_path

_EPS = 1e-12  # keeps the normal's inverse CDF finite at u = 0


@dataclass
class Dispersion:
    """A distribution of ``dimension`` independent components and how it meets the base value.

    Parameters
    ----------
    kind : str
        ``normal``, ``uniform`` or ``case_seed``.
    combine : str
        ``set`` (the draw is the value), ``scale`` (it multiplies the base value) or ``offset``
        (it is added to the base value).
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
        return 0 if self.kind == "case_seed" else int(self.a.size)

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
        if self.kind == "case_seed":
            return seed
        if self.kind == "normal":
            from scipy.special import (
                ndtri,  # lazily: scipy is slow to import for plain runs
            )

            draw = self.a + self.b * ndtri(np.clip(unit, _EPS, 1.0 - _EPS))  # the normal's inverse CDF
        else:
            draw = self.a + unit * (self.b - self.a)
        draw = draw if self.vector else float(draw[0])
        if self.combine == "set":
            return draw
        base = np.asarray(base, dtype=float)
        return base * draw if self.combine == "scale" else base + draw


def _pair(node: Node, kind: str) -> tuple[np.ndarray, np.ndarray, bool]:
    """(a, b, vector) of a normal or uniform entry."""
    if kind == "normal":
        spec = node.mapping()
        first, second = spec.get("mean", required=True), spec.get("std", required=True)
    else:
        spec = node
        if isinstance(node.value, list):
            if len(node.value) != 2:
                raise node.error(f"expected [low, high], got {node.value!r:.80}")
            first, second = Node(node.value[0], f"{node.path}[0]"), Node(node.value[1], f"{node.path}[1]")
        else:
            spec = node.mapping()
            first, second = spec.get("low", required=True), spec.get("high", required=True)
    vector = isinstance(first.value, list)
    a = first.vector() if vector else np.atleast_1d(first.number())
    b = second.vector(a.size) if vector else np.atleast_1d(second.number())
    if kind == "normal" and np.any(b < 0):
        raise second.error(f"a standard deviation cannot be negative, got {second.value!r}")
    if kind == "uniform" and np.any(b < a):
        raise node.error(f"expected low <= high, got {node.value!r:.80}")
    if isinstance(spec.value, dict):
        spec.finish()
    return a, b, vector


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
    if node.value == "case_seed":
        return Dispersion("case_seed", "set", np.zeros(0), np.zeros(0), False)
    combine = "set"
    if isinstance(node.value, dict) and len(node.value) == 1 and next(iter(node.value)) in ("scale", "offset"):
        combine = next(iter(node.value))
        node = node.get(combine)
    if not isinstance(node.value, dict) or len(node.value) != 1 or next(iter(node.value)) not in ("normal", "uniform"):
        raise node.error(f"expected case_seed, {{normal: {{mean, std}}}}, {{uniform: [low, high]}} or "
                         f"{{scale|offset: <distribution>}}; got {node.value!r:.80}")
    kind = next(iter(node.value))
    a, b, vector = _pair(node.get(kind), kind)
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
