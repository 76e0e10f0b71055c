"""Figures drawn cheaply must be the figures drawn plainly (issue 13): a row drawn on a reused
figure equals the same row drawn on a new one, pixel for pixel, and decimation keeps every peak."""
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image

from ocp import ReactionWheels, Spacecraft, quat
from planners.reference import ReferenceSample
from scenarios.output.plot_data import decimate, row_series
from scenarios.output.plots import RowFigure


class Reference:
    """A made-up reference (only drawing is tested): attitude about z, its rate and torque."""

    def __init__(self, scale):
        self.scale = scale

    def sample(self, t):
        angle = self.scale * np.sin(0.05 * t)
        q = np.stack([np.cos(angle / 2), 0 * t, 0 * t, np.sin(angle / 2)], axis=1)
        omega = np.stack([0 * t, 0 * t, self.scale * 0.05 * np.cos(0.05 * t)], axis=1)
        return ReferenceSample(q, omega, -0.05 * omega, 0.3 * omega)


def make_row(rng, label, scale, samples=300):
    t = np.linspace(0.0, 150.0, samples + 1)
    reference = Reference(scale)
    ref = reference.sample(t)
    q = quat.normalize(ref.q + rng.normal(0, 1e-3, ref.q.shape))
    x = np.hstack([q, ref.omega + rng.normal(0, 1e-4, (t.size, 3)), rng.normal(0, scale, (t.size, 3))])
    wheel_torque = rng.normal(0, 0.01 * scale, (samples, 3))
    simulation = SimpleNamespace(t=t, x=x, q=x[:, 0:4], omega=x[:, 4:7], wheel_momentum=x[:, 7:],
                                 applied_torque=-wheel_torque, applied_u=wheel_torque)
    return SimpleNamespace(label=label, planner="eigenaxis", controller="augmented_quaternion_feedback",
                           simulation=simulation, reference=reference)


def pixels(path):
    return np.asarray(Image.open(path).convert("RGB"))


def test_a_row_on_a_reused_figure_is_the_row_on_a_new_figure(tmp_path, rng):
    """Every row, not only the second: the static part drawn once must not depend on the row's
    values (the vertical spines' ends do, through the value limits: a corner pixel moved)."""
    target = quat.from_axis_angle([0, 0, 1], 1.0)
    spacecraft = Spacecraft([1.0, 2.0, 3.0], wheels=ReactionWheels(np.eye(3), max_torque=0.02, max_momentum=[1.0, 2.0, 3.0],
                                                                   spin_inertia=1e-3, failed=[1]))
    rows = [make_row(rng, name, scale) for name, scale in (("first", 1.0), ("second", 0.02), ("third", 3.0))]
    shape = row_series(rows[0], target, spacecraft).shape
    reused = RowFigure(*shape)
    for row in rows:  # the limit lines in view for the first and third rows, beyond it for the second
        reused.draw(row_series(row, target, spacecraft), tmp_path / f"{row.label}_reused.png")
        RowFigure(*shape).draw(row_series(row, target, spacecraft), tmp_path / f"{row.label}_new.png")
        np.testing.assert_array_equal(pixels(tmp_path / f"{row.label}_reused.png"),
                                      pixels(tmp_path / f"{row.label}_new.png"))
    assert not np.array_equal(pixels(tmp_path / "first_new.png"), pixels(tmp_path / "second_new.png"))


@pytest.mark.parametrize("n", [10, 1000, 100_003])
def test_decimation_keeps_the_envelope_and_the_ends(n, rng):
    t = np.linspace(0.0, 1.0, n)
    values = np.cumsum(rng.standard_normal((n, 2)), axis=0)
    t_kept, kept = decimate(t, values, 400)
    assert t_kept[0] == t[0] and t_kept[-1] == t[-1] and np.all(np.diff(t_kept) > 0)
    assert kept.shape[1] == 2 and np.all(np.isin(t_kept, t))
    assert kept[:, 0].max() == values[:, 0].max() and kept[:, 0].min() == values[:, 0].min()
    if n > 800:
        assert t_kept.size <= 2 * 400 + 2
        np.testing.assert_array_equal(kept, values[np.searchsorted(t, t_kept)])  # samples, not averages
        size = -(-n // 400)
        for start in range(0, n, size):  # each pixel column keeps its own extremes of the first series
            column = values[start:start + size, 0]
            assert column.max() in kept[:, 0] and column.min() in kept[:, 0]
    else:
        assert t_kept.size == n
