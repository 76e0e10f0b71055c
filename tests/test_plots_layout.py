"""Layout of the PNG row figure: a title that wraps onto two lines (the two-wheel scenario's rows,
``horri_palmer_two_wheels.yaml``) stays above the first panel.

Oracle: matplotlib's own bounding boxes of the drawn title and panel.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, quat
from scenarios.output.plot_data import row_series
from scenarios.output.plots import RowFigure


def two_wheel_row(label: str, samples: int = 200):
    t = np.linspace(0.0, 100.0, samples + 1)
    q = quat.from_axis_angle([0, 0, 1], 0.01 * t)
    x = np.hstack([q, np.zeros((t.size, 3)), np.zeros((t.size, 3))])
    simulation = SimpleNamespace(t=t, x=x, q=q, omega=x[:, 4:7], wheel_momentum=x[:, 7:],
                                 applied_torque=np.zeros((samples, 3)), applied_u=np.zeros((samples, 3)))
    return SimpleNamespace(label=label, planner="collocation", controller="gain_scheduled_min_norm",
                           simulation=simulation, reference=None)


@pytest.mark.parametrize("label", ["short", "optimal two-wheel (min time) / gain-scheduled min-norm (eq. 30)",
                                   "a label so long " * 20])
def test_the_row_title_stays_above_the_first_panel(tmp_path, label):
    spacecraft = Spacecraft([1.0, 2.0, 3.0], wheels=ReactionWheels(np.eye(3), max_torque=0.02, max_momentum=0.1,
                                                                   failed=[2]))
    series = row_series(two_wheel_row(label), quat.from_axis_angle([0, 0, 1], 1.0), spacecraft)
    figure = RowFigure(*series.shape)
    figure.draw(series, tmp_path / "row.png")
    renderer = figure.figure.canvas.get_renderer()
    title = figure.title.get_window_extent(renderer)
    first = figure.axes[0].get_window_extent(renderer)
    assert title.y0 > first.y1, f"the title reaches {first.y1 - title.y0:.1f} px into the first panel"
    assert title.y1 <= figure.figure.bbox.y1 and title.x0 >= 0 and title.x1 <= figure.figure.bbox.x1
    assert len(figure.title.get_text().splitlines()) == (1 if label == "short" else 2)
