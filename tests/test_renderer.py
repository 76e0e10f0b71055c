"""The plot process of ``slewbench run`` (issue 13: the run with plots within 1.5 s): the figures
it draws are the figures drawn in process, pixel for pixel; a failed plot process costs nothing but
time; an interrupted run leaves no process behind; the work is shared evenly."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from scenarios.console import draws_plots
from scenarios.plot_data import OverlaySeries, RowSeries
from scenarios.renderer import COST, split

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "scenarios" / "eigenaxis_demo.yaml"


def _python(code: str, *args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    """``code`` in a new interpreter (one thread, nothing imported: where the plot process starts)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "PYTHONPATH": str(REPO)})


def _pixels(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def test_the_plot_process_draws_what_the_run_process_draws(tmp_path):
    """Oracle: the same jobs drawn in process (``draw_jobs``) by the script's own process."""
    done = _python("""
        import sys
        from pathlib import Path
        from scenarios.renderer import Renderer
        renderer = Renderer.start()
        assert renderer is not None, "no plot process on a one-thread Linux process"
        import scenarios
        from scenarios.plot_data import plot_jobs
        from scenarios.plots import draw_jobs
        results = scenarios.run(scenarios.load(sys.argv[1]))
        jobs = plot_jobs(results)
        forked, here = Path(sys.argv[2]) / "forked", Path(sys.argv[2]) / "here"
        forked.mkdir(); here.mkdir()
        renderer.draw(jobs, forked)
        renderer.close()
        draw_jobs(jobs, here)
        print(" ".join(name for name, _ in jobs))
    """, str(DEMO), str(tmp_path))
    assert done.returncode == 0, done.stderr
    names = done.stdout.split()
    assert sorted(names) == ["bang-coast-bang.png", "comparison.png", "min-time.png", "smooth.png"]
    assert sorted(p.name for p in (tmp_path / "forked").iterdir()) == sorted(names)
    for name in names:
        np.testing.assert_array_equal(_pixels(tmp_path / "forked" / name), _pixels(tmp_path / "here" / name))


def test_a_dead_plot_process_costs_only_time(tmp_path):
    """The plot process killed before it draws: the run draws the figures itself, says so on one
    line, and writes complete results."""
    done = _python("""
        import os, signal, sys
        from scenarios.renderer import Renderer
        renderer = Renderer.start()
        os.kill(renderer.pid, signal.SIGKILL)
        import scenarios
        results = scenarios.run(scenarios.load(sys.argv[1]))
        results.write(sys.argv[2], renderer=renderer)
        renderer.close()
    """, str(DEMO), str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    assert "the plot process ended early" in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    for name in ("smooth.png", "bang-coast-bang.png", "min-time.png", "comparison.png", "results.json"):
        assert (tmp_path / "out" / name).is_file(), name


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(v) for v in path.read_text().split()] if path.exists() else []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the plot process exists on Linux only")
def test_sigterm_during_a_run_stops_the_plot_process_too(tmp_path):
    slow = tmp_path / "slow.yaml"
    slow.write_text(DEMO.read_text().replace("duration: 140.0", "duration: 100000.0").replace(
        "sample_time: 0.5", "sample_time: 0.01"))
    process = subprocess.Popen([sys.executable, "-m", "scenarios.console", "run", str(slow), "--out",
                                str(tmp_path / "out")], cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
    deadline, children = time.time() + 60, []
    while not children and time.time() < deadline and process.poll() is None:
        children = _children(process.pid)
        time.sleep(0.05)
    assert children, "no plot process was started"
    time.sleep(1.0)  # into the run
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode != 0 and "Traceback" not in err
    for pid in children:  # reaped by the run: gone, not a zombie nor an orphan
        assert not Path(f"/proc/{pid}").exists()


def _row(shape: tuple[int, bool, bool]) -> RowSeries:
    return RowSeries(*shape, "", [], [], [])


def _cost(share: list) -> float:
    rows = [s for _, s in share if isinstance(s, RowSeries)]
    return (COST["row"] * len(rows) + COST["background"] * len({s.shape for s in rows})
            + COST["other"] * (len(share) - len(rows)))


@pytest.mark.parametrize("rows,shapes", [(1, 1), (3, 1), (10, 1), (6, 2), (0, 0)])
def test_the_figures_are_shared_evenly_and_each_drawn_once(rows, shapes):
    jobs = [(f"r{k}.png", _row((k % shapes, True, True))) for k in range(rows)]
    jobs.append(("comparison.png", OverlaySeries("", "", [], [], [])))
    mine, theirs = split(jobs)
    assert sorted(n for n, _ in mine + theirs) == sorted(n for n, _ in jobs)
    for share in (mine, theirs):  # the original order within each share
        assert [n for n, _ in share] == [n for n, _ in jobs if n in {m for m, _ in share}]
    total_alone = _cost(jobs)
    # Never worse than drawing alone; balanced to within one figure plus one static part.
    assert max(_cost(mine), _cost(theirs)) <= total_alone
    assert abs(_cost(mine) - _cost(theirs)) <= COST["row"] + COST["background"] + 1e-9


def test_only_run_with_plots_starts_a_plot_process():
    assert draws_plots(["run", "a.yaml"]) and draws_plots(["run", "a.yaml", "--out", "d"])
    for argv in (["run", "a.yaml", "--no-plots"], ["run", "-h"], ["validate", "a.yaml"], ["sweep", "s.yaml"], []):
        assert not draws_plots(argv)


def test_the_package_imports_nothing_heavy_until_used():
    """The plot process is forked after ``import scenarios.console``: nothing may have loaded NumPy,
    CasADi or matplotlib by then (they would start threads, and their import is what overlaps)."""
    done = _python("""
        import sys
        import scenarios.console
        heavy = sorted(m for m in ("numpy", "casadi", "matplotlib", "scipy", "yaml") if m in sys.modules)
        print(heavy)
        import scenarios
        scenarios.run, scenarios.ScenarioError  # the public names still resolve
    """)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_the_drawing_half_imports_no_model():
    """The plot process imports ``scenarios.plots`` only: never the model (CasADi) or the run."""
    done = _python("""
        import sys
        import scenarios.plots
        print(sorted(m for m in ("casadi", "ocp", "planners", "controllers", "scipy") if m in sys.modules))
    """)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


def test_a_run_without_a_plot_process_is_unchanged(tmp_path):
    """Library use (no renderer) still draws every figure, in process."""
    import scenarios

    results = scenarios.run(scenarios.load(DEMO))
    results.write(tmp_path / "out")
    assert {p.name for p in (tmp_path / "out").glob("*.png")} == {
        "smooth.png", "bang-coast-bang.png", "min-time.png", "comparison.png"}
