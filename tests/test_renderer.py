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
from scenarios.output.plot_data import OverlaySeries, RowSeries
from scenarios.output.renderer import COST, split

REPO = Path(__file__).resolve().parents[1]
DEMO = REPO / "scenarios" / "eigenaxis_demo.yaml"
KEEP_OUT = REPO / "scenarios" / "collocation_keep_out.yaml"


def _python(code: str, *args: str, timeout: float = 300, env: dict[str, str] | None = None
            ) -> subprocess.CompletedProcess:
    """``code`` in a new interpreter (one thread, nothing imported: where the plot process starts)."""
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], cwd=REPO, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "PYTHONPATH": str(REPO), **(env or {})})


def _pixels(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


@pytest.fixture(scope="module")
def demo_jobs(tmp_path_factory) -> Path:
    """The demo's plot jobs (``plot_jobs`` of its run), pickled once for the tests whose script
    draws them: the run is not what those tests are about, and each run costs seconds."""
    import pickle

    import scenarios
    from scenarios.output.plot_data import plot_jobs

    path = tmp_path_factory.mktemp("demo-jobs") / "jobs.pickle"
    path.write_bytes(pickle.dumps(plot_jobs(scenarios.run(scenarios.load(DEMO)))))
    return path


def test_the_plot_process_draws_what_the_run_process_draws(tmp_path, demo_jobs):
    """Oracle: the same jobs drawn in process (``draw_jobs``) by the script's own process."""
    done = _python("""
        import pickle, sys
        from pathlib import Path
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        assert renderer is not None, "no plot process on a one-thread Linux process"
        from scenarios.output.plots import draw_jobs
        jobs = pickle.loads(Path(sys.argv[1]).read_bytes())
        forked, here = Path(sys.argv[2]) / "forked", Path(sys.argv[2]) / "here"
        forked.mkdir(); here.mkdir()
        renderer.draw(jobs, forked)
        renderer.close()
        draw_jobs(jobs, here)
        print(" ".join(name for name, _ in jobs))
    """, str(demo_jobs), str(tmp_path))
    assert done.returncode == 0, done.stderr
    names = done.stdout.split()
    assert sorted(names) == ["bang-coast-bang.png", "comparison.png", "min-time.png", "smooth.png"]
    assert sorted(p.name for p in (tmp_path / "forked").iterdir()) == sorted(names)
    for name in names:
        np.testing.assert_array_equal(_pixels(tmp_path / "forked" / name), _pixels(tmp_path / "here" / name))


@pytest.mark.parametrize("scenario", [DEMO, KEEP_OUT], ids=["demo", "keep_out"])
def test_figures_streamed_during_the_run_are_those_drawn_in_process(tmp_path, scenario):
    """Each row's figure goes to the plot process as soon as the row is done (``on_row``), before
    the next row is planned, and the whole run's figures (comparison; margins and sky with a
    pointing requirement) with the last row; the streamed figures, written at the end, are those
    drawn in process pixel for pixel (oracle: ``draw_jobs`` in the script's own process), and a
    streamed figure the run does not keep is drawn again, not written as streamed. A user's
    ``savefig.format`` does not change what is written into memory (PNG, as into a ``.png`` file)."""
    rc = tmp_path / "rc"
    rc.mkdir()
    (rc / "matplotlibrc").write_text("savefig.format: jpg\n")
    done = _python("""
        import sys
        from pathlib import Path
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        assert renderer is not None, "no plot process on a one-thread Linux process"
        import scenarios
        from scenarios.output.plot_data import plot_jobs
        from scenarios.output.plots import draw_jobs
        from scenarios.output.writer import plot_streamer
        scenario = scenarios.load(sys.argv[1])
        stream = plot_streamer(scenario, renderer)
        def on_row(row):
            stream(row)
            print(row.label, "|", ",".join(sorted(renderer.streamed)))
        results = scenarios.run(scenario, on_row=on_row)
        forked, here = Path(sys.argv[2]) / "forked", Path(sys.argv[2]) / "here"
        forked.mkdir(); here.mkdir()
        first = sorted(renderer.streamed)[0]
        keep = set(renderer.streamed) - {first}
        print("dropped", first)
        renderer.submit(plot_jobs(results, drawn=keep), forked, keep)
        renderer.wait()
        renderer.close()
        jobs = plot_jobs(results)
        draw_jobs(jobs, here)
        print("jobs", " ".join(sorted(name for name, _ in jobs)))
    """, str(scenario), str(tmp_path), env={"MATPLOTLIBRC": str(rc)})
    assert done.returncode == 0, done.stderr
    *streaming, dropped, jobs = done.stdout.splitlines()
    names = jobs.split()[1:]
    if scenario == DEMO:  # streamed one by one, as the rows finish (the demo's rows in order)
        assert streaming == ["smooth | smooth.png", "bang-coast-bang | bang-coast-bang.png,smooth.png",
                             "min-time | bang-coast-bang.png,comparison.png,min-time.png,smooth.png"]
    else:  # the pointing figures come with the last row
        assert {"margins.png", "sky.png", "comparison.png"} <= set(names)
        assert not {"margins.png", "sky.png", "comparison.png"} & set(streaming[-2].split("|")[1].split(","))
        assert streaming[-1].split("|")[1].strip().split(",") == names
    # the dropped figure was drawn again from the submitted jobs, not lost
    assert sorted(p.name for p in (tmp_path / "forked").iterdir()) == names
    for name in names:
        assert (tmp_path / "forked" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        np.testing.assert_array_equal(_pixels(tmp_path / "forked" / name), _pixels(tmp_path / "here" / name))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the plot process exists on Linux only")
@pytest.mark.parametrize("kill_helper", [False, True])
def test_figures_streamed_faster_than_drawn_are_shared_with_a_helper(tmp_path, kill_helper, demo_jobs):
    """Figures that wait while the idle plot process draws are shared with a fork of it (a helper,
    drawing into memory) without waiting for the run's end; what both drew is written, pixel for
    pixel the figures drawn in process. A helper killed while it draws costs only time: the plot
    process draws its figures itself."""
    done = _python("""
        import pickle, sys, os, signal, time
        from pathlib import Path
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        from scenarios.output.plots import draw_jobs
        base = pickle.loads(Path(sys.argv[1]).read_bytes())
        # two copies of the demo's four figures: eight waiting, enough for the plot process to
        # share with a helper while it draws the first
        jobs = [(f"{k}-{name}", series) for k in range(2) for name, series in base]
        for job in jobs:
            renderer.stream(job, None)
        children = Path(f"/proc/{renderer.pid}/task/{renderer.pid}/children")
        deadline, helpers = time.monotonic() + 60.0, []
        while not helpers and time.monotonic() < deadline:
            helpers = children.read_text().split()
            time.sleep(0.002)
        print("helper", len(helpers))
        if sys.argv[3] == "True" and helpers:
            os.kill(int(helpers[0]), signal.SIGKILL)
        out, here = Path(sys.argv[2]) / "out", Path(sys.argv[2]) / "here"
        out.mkdir(); here.mkdir()
        renderer.submit([], out, {name for name, _ in jobs})
        renderer.wait()
        draw_jobs(base, here)  # the copies share a series: each figure is drawn here once
        print("jobs", " ".join(sorted(name for name, _ in jobs)))
    """, str(demo_jobs), str(tmp_path), str(kill_helper))
    assert done.returncode == 0, done.stderr
    helper, jobs = done.stdout.splitlines()
    assert helper == "helper 1"
    names = jobs.split()[1:]
    assert len(names) == 8
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == names
    for name in names:  # "<copy>-<figure>" against the figure drawn here
        np.testing.assert_array_equal(_pixels(tmp_path / "out" / name),
                                      _pixels(tmp_path / "here" / name.split("-", 1)[1]))


def test_a_plot_process_dying_while_rows_stream_costs_only_time(tmp_path):
    """The plot process killed after the first row was streamed: the later rows are not sent, the
    run draws every figure itself (the streamed one too), says so on one line, and writes
    complete results."""
    done = _python("""
        import os, signal, sys, time
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        import scenarios
        from scenarios.output.writer import plot_streamer
        scenario = scenarios.load(sys.argv[1])
        stream = plot_streamer(scenario, renderer)
        def on_row(row):
            stream(row)
            if len(renderer.streamed) == 1 and not killed:
                os.kill(renderer.pid, signal.SIGKILL)
                killed.append(True)
                while open(f"/proc/{renderer.pid}/stat").read().split(")")[-1].split()[0] != "Z":
                    time.sleep(0.01)  # dead (its pipe closed), not yet reaped
        killed = []
        results = scenarios.run(scenario, on_row=on_row)
        print(sorted(renderer.streamed))
        results.write(sys.argv[2], renderer=renderer)
        renderer.close()
    """, str(DEMO), str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "['smooth.png']"
    assert "the plot process has already drawn or stopped" in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    for name in ("smooth.png", "bang-coast-bang.png", "min-time.png", "comparison.png", "results.json"):
        assert (tmp_path / "out" / name).is_file(), name


def test_a_dead_plot_process_costs_only_time(tmp_path):
    """The plot process killed before it draws: the run draws the figures itself, says so on one
    line, and writes complete results."""
    done = _python("""
        import os, signal, sys
        from scenarios.output.renderer import Renderer
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


def test_report_html_is_built_while_the_plot_process_draws_and_a_death_meanwhile_costs_only_time(tmp_path):
    """``report.html`` is built after the figures went to the plot process and before the run
    waits for them; the plot process killed in between (inside the report's build): the run draws
    the figures itself, says so on one line, and writes complete results."""
    done = _python("""
        import os, signal, sys
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        import scenarios
        import scenarios.output.report.run as report
        build = report.run_page  # what the writer builds report.html with
        def killing(results):
            assert renderer._submitted, "report.html built before the figures were sent"
            os.kill(renderer.pid, signal.SIGKILL)
            return build(results)
        report.run_page = killing
        results = scenarios.run(scenarios.load(sys.argv[1]))
        results.write(sys.argv[2], renderer=renderer)
        renderer.close()
    """, str(DEMO), str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    assert "the plot process ended early" in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    for name in ("smooth.png", "bang-coast-bang.png", "min-time.png", "comparison.png", "results.json",
                 "report.html"):
        assert (tmp_path / "out" / name).is_file(), name


def test_waiting_with_nothing_sent_is_a_rendering_failure():
    done = _python("""
        from scenarios.output.renderer import Renderer, RenderingFailed
        renderer = Renderer.start()
        assert renderer is not None, "no plot process on a one-thread Linux process"
        try:
            renderer.wait()
        except RenderingFailed as error:
            print(error)
        finally:
            renderer.close()
    """)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "no figures were sent to the plot process"


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(v) for v in path.read_text().split()] if path.exists() else []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the plot process exists on Linux only")
def test_sigterm_during_a_run_stops_the_plot_process_too(tmp_path):
    slow = tmp_path / "slow.yaml"  # about 3 s per row (200 000 samples): the signal lands in row 2
    slow.write_text(DEMO.read_text().replace("duration: 140.0", "duration: 20000.0").replace(
        "sample_time: 0.5", "sample_time: 0.1"))
    process = subprocess.Popen([sys.executable, "-m", "scenarios.console", "run", str(slow), "--out",
                                str(tmp_path / "out")], cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
    assert process.stdout is not None
    first = process.stdout.readline()  # the first row is done: the run is under way
    assert first.startswith("[1/3] smooth: ok"), (first, process.communicate(timeout=120))
    children = _children(process.pid)
    assert children, "no plot process was started"
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 1 and "interrupted" in err and "Traceback" not in err, err
    assert not (tmp_path / "out" / "results.json").exists()
    for pid in children:  # reaped by the run: gone, not a zombie nor an orphan
        assert not Path(f"/proc/{pid}").exists()


def _row(shape: tuple[int, bool, bool]) -> RowSeries:
    return RowSeries(*shape, "", [], [], [])


def _cost(share: list) -> float:
    """Drawing cost after the fork (the static parts are drawn before it, once)."""
    rows = [s for _, s in share if isinstance(s, RowSeries)]
    return COST["row"] * len(rows) + COST["other"] * (len(share) - len(rows))


@pytest.mark.parametrize("rows,shapes", [(1, 1), (3, 1), (10, 1), (6, 2), (0, 0)])
def test_the_figures_are_shared_evenly_and_each_drawn_once(rows, shapes):
    jobs = [(f"r{k}.png", _row((k % shapes, True, True))) for k in range(rows)]
    jobs.append(("comparison.png", OverlaySeries("", "", [], [], [])))
    mine, theirs = split(jobs)
    assert sorted(n for n, _ in mine + theirs) == sorted(n for n, _ in jobs)
    for share in (mine, theirs):  # the original order within each share
        assert [n for n, _ in share] == [n for n, _ in jobs if n in {m for m, _ in share}]
    total_alone = _cost(jobs)
    # Never worse than drawing alone; balanced to within the largest figure.
    assert max(_cost(mine), _cost(theirs)) <= total_alone
    assert abs(_cost(mine) - _cost(theirs)) <= max(COST.values()) + 1e-9


def test_only_run_with_plots_starts_a_plot_process():
    assert draws_plots(["run", "a.yaml"]) and draws_plots(["run", "a.yaml", "--out", "d"])
    for argv in (["run", "a.yaml", "--no-plots"], ["run", "-h"], ["validate", "a.yaml"], ["sweep", "s.yaml"], [],
                 ["run", "a.yaml", "--no-plot"], ["run", "a.yaml", "--n"], ["run", "--he"]):  # argparse abbreviations
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
    """The plot process imports ``scenarios.output.plots`` only: never the model (CasADi) or the run."""
    done = _python("""
        import sys
        import scenarios.output.plots
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


def _gone(pid: int) -> bool:
    """Not running: no such process, or a zombie (reaped by init or by whoever adopted it)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the plot process exists on Linux only")
def test_an_interrupted_draw_stops_both_plot_processes_before_it_returns(tmp_path, demo_jobs):
    """Ctrl-C or SIGTERM while the plot processes draw: when ``draw`` raises, the plot process and
    its fork are gone (reaped, not left to init) and write nothing more (the caller removes the
    staging folder next)."""
    done = _python("""
        import os, pickle, signal, sys, time
        from pathlib import Path
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        jobs = pickle.loads(Path(sys.argv[1]).read_bytes())
        jobs = [(f"{k}-{name}", series) for k in range(8) for name, series in jobs]  # a long draw
        directory, forks = Path(sys.argv[2]), []

        def tick(signum, frame):  # interrupt once the plot process has forked its second drawer
            path = Path(f"/proc/{renderer.pid}/task/{renderer.pid}/children")
            forks.extend(int(v) for v in path.read_text().split()) if path.exists() else None
            if forks:
                signal.setitimer(signal.ITIMER_REAL, 0)
                raise KeyboardInterrupt

        signal.signal(signal.SIGALRM, tick)
        signal.setitimer(signal.ITIMER_REAL, 0.02, 0.02)
        try:
            renderer.draw(jobs, directory)
            print("not interrupted")
        except KeyboardInterrupt:
            written = sorted(os.listdir(directory))
            for pid in [renderer.pid] + forks:
                print(pid, Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
                      if Path(f"/proc/{pid}").exists() else "gone")
            time.sleep(1.0)
            print("written-afterwards", len(set(os.listdir(directory)) - set(written)))
    """, str(demo_jobs), str(tmp_path))
    assert done.returncode == 0, done.stderr
    states = dict(line.split() for line in done.stdout.splitlines())
    assert states.pop("written-afterwards") == "0", done.stdout
    assert len(states) == 2 and set(states.values()) == {"gone"}, states


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the plot process exists on Linux only")
def test_the_plot_processes_stop_when_the_run_is_killed(tmp_path):
    """SIGKILL of ``slewbench run`` while its plot process draws the streamed rows: it stops too
    (with any fork of its own), instead of drawing on for a process that is gone."""
    many = tmp_path / "many.yaml"
    rows = "".join(f"  - {{name: eigenaxis, label: r{k}, options: {{profile: smooth}}}}\n" for k in range(24))
    text = DEMO.read_text()
    start, end = text.index("planners:\n"), text.index("controller:")
    many.write_text(text[:start] + "planners:\n" + rows + text[end:])
    process = subprocess.Popen([sys.executable, "-m", "scenarios.console", "run", str(many), "--out",
                                str(tmp_path / "out")], cwd=REPO, stdout=subprocess.PIPE,
                               stderr=subprocess.DEVNULL, text=True)
    for line in process.stdout:  # rows 1 and 2 done: both streamed, the plot process is drawing
        if line.startswith("[2/24]"):
            break
    command = Path(f"/proc/{process.pid}/cmdline").read_bytes()  # read once the run has started
    # the plot process is a fork of the run (the same command line), unlike a tool the run calls
    drawers = [pid for pid in _children(process.pid) if Path(f"/proc/{pid}/cmdline").read_bytes() == command]
    assert len(drawers) == 1, "no plot process while the rows stream"
    drawers += _children(drawers[0])
    process.kill()
    process.wait(timeout=60)
    process.stdout.close()
    deadline = time.time() + 0.5
    while not all(_gone(pid) for pid in drawers) and time.time() < deadline:
        time.sleep(0.01)
    assert all(_gone(pid) for pid in drawers)


@pytest.mark.parametrize("interrupt", ["raise KeyboardInterrupt", "os.kill(os.getpid(), signal.SIGTERM); time.sleep(5)"])
def test_an_interruption_while_the_model_is_imported_is_reported_without_a_traceback(tmp_path, interrupt):
    """Ctrl-C or SIGTERM before the command line is loaded (while the plot process imports
    matplotlib and this process imports the model): the interrupted line, status 1, and the plot
    process reaped (not left to run on as an orphan)."""
    done = _python("""
        import os, signal, sys, time
        from pathlib import Path
        import scenarios.console
        from scenarios.output.renderer import Renderer

        class Interrupting:  # Ctrl-C while scenarios.cli.commands is being imported
            def find_spec(self, name, path=None, target=None):
                if name == "scenarios.cli.commands":
                    INTERRUPT

        started = []
        start = Renderer.start
        Renderer.start = classmethod(lambda cls: started.append(start()) or started[-1])
        sys.meta_path.insert(0, Interrupting())
        status = scenarios.console.main(["run", sys.argv[1], "--out", sys.argv[2]])
        assert started and started[0] is not None
        pid = started[0].pid
        print(status, "gone" if not Path(f"/proc/{pid}").exists() else "left")
    """.replace("INTERRUPT", interrupt), str(DEMO), str(tmp_path / "out"))
    assert "Traceback" not in done.stderr, done.stderr
    assert done.stdout.split() == ["1", "gone"], (done.stdout, done.stderr)
    assert "interrupted" in done.stderr
    assert not (tmp_path / "out").exists()


def test_the_submodules_are_attributes_of_the_package_as_before():
    """Library code written against the eager package (``import scenarios`` then
    ``scenarios.schema.loader.load``) still works; an unknown name is still an AttributeError."""
    done = _python("""
        import scenarios
        assert scenarios.schema.loader.load is scenarios.load
        assert scenarios.runner.RunResults is scenarios.RunResults
        assert scenarios.errors.ScenarioError is scenarios.ScenarioError
        scenarios.study.spec.parse_study, scenarios.study.engine.sweep, scenarios.schema.read
        try:
            scenarios.no_such_name
        except AttributeError as error:
            print("AttributeError", error)
        print(hasattr(scenarios, "__wrapped__"))
    """)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["AttributeError module 'scenarios' has no attribute 'no_such_name'", "False"]


def test_the_second_drawer_is_forked_only_from_a_single_thread(tmp_path, monkeypatch):
    """A plot process that somehow has threads (a BLAS ignoring its thread variables) draws
    everything itself: a fork of a threaded process can deadlock (and warns on Python 3.12+)."""
    from scenarios.output import renderer

    def no_fork() -> int:
        raise AssertionError("forked a process with threads")

    monkeypatch.setattr(renderer, "_thread_count", lambda: 3)
    monkeypatch.setattr(renderer.os, "fork", no_fork)
    t = np.linspace(0.0, 10.0, 11)
    overlay = OverlaySeries("t", "error (deg)", ["a"], [(t, t)], [(t, 1 + t)])
    renderer._draw_in_two([("a.png", overlay), ("b.png", overlay)], tmp_path, [], {})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the plot process exists on Linux only")
@pytest.mark.parametrize("draw", [True, False])
def test_the_plot_process_removes_the_temporary_matplotlib_directory(tmp_path, draw, demo_jobs):
    """Where matplotlib's own directory cannot be written (a read-only home in CI or a container),
    it makes a temporary one and removes it at exit: the plot process must too, having drawn or
    having been stopped (``python -m scenarios.cli`` leaves nothing there either)."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    (tmp_path / "file").write_text("")  # MPLCONFIGDIR below it cannot be made
    done = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import os, pickle, sys, time
        from pathlib import Path
        from scenarios.output.renderer import Renderer
        renderer = Renderer.start()
        jobs = pickle.loads(Path(sys.argv[1]).read_bytes())
        if sys.argv[3] == "True":
            renderer.draw(jobs, Path(sys.argv[2]))
        else:  # matplotlib imported, nothing to draw (a bad --out, a failed write)
            deadline = time.monotonic() + 60.0
            while not any(Path(os.environ["TMPDIR"]).iterdir()) and time.monotonic() < deadline:
                time.sleep(0.01)  # until the plot process has made matplotlib's temporary directory
            time.sleep(3.0)
        renderer.close()
    """), str(demo_jobs), str(tmp_path), str(draw)], cwd=REPO, capture_output=True, text=True, timeout=300, check=False,
                          env={**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(scratch),
                               "MPLCONFIGDIR": str(tmp_path / "file" / "not-a-directory")})
    assert done.returncode == 0, done.stderr
    assert "temporary cache directory" in done.stderr  # the situation under test
    assert sorted(p.name for p in scratch.iterdir()) == []
