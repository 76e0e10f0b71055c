"""``gap_vs_time.png`` of ``slewbench bench``: each planner or peer keeps its colour and marker from
run to run (whatever else the run holds), and the legend sits outside the data.

Oracles: the registries' order (:data:`planners.PLANNERS`, :data:`scenarios.bench.peers.PEERS`),
read here, and matplotlib's own bounding boxes of the drawn legend and axes.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib.figure
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_hex

from planners import PLANNERS
from scenarios.bench.leaderboard import BenchRow, Leaderboard
from scenarios.bench.peers import PEERS
from scenarios.bench.suite import load_suite


def bench_row(planner: str, kind: str, gap_rel: float, time_s: float) -> BenchRow:
    return BenchRow("p", planner, planner, kind, "ok", 1.0 + gap_rel, gap_rel, gap_rel, False, time_s, None, "-",
                    plan_cpu_s=time_s)


def drawn(board: Leaderboard, tmp_path: Path, monkeypatch) -> matplotlib.figure.Figure:
    """The figure :meth:`Leaderboard.plot` draws (kept as it is printed)."""
    kept = []
    original = FigureCanvasAgg.print_png

    def keep(self, *args, **kwargs):
        kept.append(self.figure)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(FigureCanvasAgg, "print_png", keep)
    board.plot(tmp_path / "gap_vs_time.png")
    assert (tmp_path / "gap_vs_time.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    return kept[-1]


def styles(figure) -> dict[str, tuple[str, tuple]]:
    """Legend label -> (edge colour, marker path vertices) of each scatter."""
    axis = figure.axes[0]
    found = {}
    for collection in axis.collections:
        path = collection.get_paths()[0]
        found[collection.get_label()] = (to_hex(collection.get_edgecolor()[0]),
                                         tuple(map(tuple, path.vertices.round(6))))
    return found


def test_a_planner_keeps_its_style_whichever_others_run(tmp_path, monkeypatch):
    suite = load_suite()
    planners, peers = list(PLANNERS), list(PEERS)
    full = Leaderboard(suite, [], [bench_row(name, "planner", 1e-3 * (k + 1), 0.1 * (k + 1))
                                   for k, name in enumerate(planners)]
                       + [bench_row(name, "peer", 2e-3, 0.5) for name in peers])
    # a run with the last planner and the last peer only, in another order
    subset = Leaderboard(suite, [], [bench_row(peers[-1], "peer", 2e-3, 0.5),
                                     bench_row(planners[-1], "planner", 1e-3, 0.1)])
    a = styles(drawn(full, tmp_path, monkeypatch))
    b = styles(drawn(subset, tmp_path, monkeypatch))
    for name in (planners[-1], f"{peers[-1]} (peer)"):
        assert a[name] == b[name], name
    # every planner and peer of the registries has its own colour and marker
    assert len(set(a.values())) == len(a) == len(planners) + len(peers)
    # the style is the registry order, not the order of appearance
    from scenarios.bench.leaderboard import _plot_style

    assert _plot_style(planners[0], "planner") == {"color": "C0", "marker": "o"}
    assert _plot_style(peers[0], "peer")["color"] == f"C{len(planners) % 10}"


def test_the_legend_is_outside_the_data(tmp_path, monkeypatch):
    suite = load_suite()
    board = Leaderboard(suite, [], [bench_row(name, "planner", 10.0 ** -(k + 2), 10.0 ** (k - 2))
                                    for k, name in enumerate(PLANNERS)])
    figure = drawn(board, tmp_path, monkeypatch)
    axis = figure.axes[0]
    renderer = figure.canvas.get_renderer()
    legend = axis.get_legend().get_window_extent(renderer)
    box = axis.get_window_extent(renderer)
    assert legend.x0 >= box.x1, "the legend overlaps the axes"
    assert legend.x1 <= figure.bbox.x1 + 0.5, "the legend runs off the figure"


@pytest.mark.parametrize("kind", ["planner", "peer"])
def test_a_name_outside_the_registries_has_a_fixed_style(kind):
    from scenarios.bench.leaderboard import _plot_style

    assert _plot_style("not_registered", kind) == _plot_style("not_registered", kind)


def test_the_plot_draws_the_rows_whose_plan_is_ok(tmp_path, monkeypatch):
    """The gap is judged on the plan: a row whose plan keeps every requirement but whose closed loop
    breaks one (keep_out_melton_scaled's collocation) is drawn; a row whose plan breaks one is not."""
    planners = list(PLANNERS)
    tracked_badly = BenchRow("p", planners[0], planners[0], "planner", "violated", 1.0, 1e-4, 1e-4, True, 0.1, None,
                             "-", "", "ok", plan_cpu_s=0.1)
    plan_broken = BenchRow("p", planners[1], planners[1], "planner", "violated", 1.0, 1e-4, 1e-4, False, 0.1, None,
                           "-", "", "violated", plan_cpu_s=0.1)
    labels = set(styles(drawn(Leaderboard(load_suite(), [], [tracked_badly, plan_broken]), tmp_path, monkeypatch)))
    assert labels == {planners[0]}
