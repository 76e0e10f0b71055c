"""The Dask client of :func:`scenarios.study.connect_scheduler` is closed: in a ``with`` block (the
studies guide's pattern, the client closed before the cluster's scheduler stops, so Dask logs no
``Failed to reconnect``), by ``close()`` any number of times, and by slewbench itself wherever it
connects (``slewbench sweep --scheduler``, a study's ``execution.scheduler``), on success, error
and Ctrl-C alike."""
from __future__ import annotations

import copy
import logging
import os
import re
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.study import engine
from scenarios.study.engine import DaskCluster, connect_scheduler
from tests.test_sweep import BASE

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[1]
STUDIES_GUIDE = ROOT / "docs" / "guide" / "studies.rst"
RECONNECT = "Failed to reconnect"


def local_cluster() -> distributed.LocalCluster:
    """One worker thread in this process, over TCP (slewbench refuses ``inproc://`` addresses)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                        host="127.0.0.1", dashboard_address=None)


@pytest.fixture(scope="module")
def cluster():
    with local_cluster() as started:
        yield started


class Records(logging.Handler):
    """The records of the ``distributed.client`` logger while it is installed."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(f"{record.levelname} {record.getMessage()}")


@pytest.fixture
def client_log():
    logger = logging.getLogger("distributed.client")
    records = Records()
    logger.addHandler(records)
    yield records
    logger.removeHandler(records)


def study_file(folder: Path, **parts) -> Path:
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "dask-client", "scenario": copy.deepcopy(BASE),
                                    "grid": {"maneuver.final.q": [[0.9238795, 0.3826834, 0, 0], [0.7071068, 0.7071068, 0, 0]]},
                                    **parts}))
    return path


def spy(monkeypatch) -> list[DaskCluster]:
    """Every DaskCluster the code under test connects (the real connection)."""
    connected: list[DaskCluster] = []

    def connecting(*args, **kwargs):
        connected.append(connect_scheduler(*args, **kwargs))
        return connected[-1]

    monkeypatch.setattr(engine, "connect_scheduler", connecting)
    return connected


# --- the context manager and close() ------------------------------------------------------------

def test_the_with_form_closes_the_client_before_the_cluster_stops(tmp_path, client_log):
    with local_cluster() as started, connect_scheduler(started.scheduler_address, wait_s=10.0) as dask:
        assert isinstance(dask, DaskCluster) and dask.client.status == "running"
        results = engine.sweep(study_file(tmp_path), cluster=dask)
        assert dask.client.status == "running"  # sweep leaves a cluster it is given open
    assert results.missing == 0
    assert dask.client.status == "closed"  # not "connecting": it does not go after the stopped scheduler
    assert not [m for m in client_log.messages if m.startswith("ERROR")], client_log.messages


def test_leaving_the_block_on_an_error_closes_the_client(cluster):
    with pytest.raises(RuntimeError, match="in the block"):
        with connect_scheduler(cluster.scheduler_address, wait_s=10.0) as dask:
            raise RuntimeError("in the block")
    assert dask.client.status == "closed"


def test_close_is_idempotent(cluster):
    dask = connect_scheduler(cluster.scheduler_address, wait_s=10.0)
    dask.close()
    assert dask.client.status == "closed"
    dask.close()
    with dask:  # a block around a closed client closes nothing again, and raises nothing
        pass
    assert dask.client.status == "closed"


def test_closing_a_client_whose_scheduler_stopped_logs_no_reconnection_error(client_log):
    with local_cluster() as started:
        dask = connect_scheduler(started.scheduler_address, wait_s=10.0)
    assert dask.client.status == "connecting"  # Dask goes after the stopped scheduler ...
    dask.close()  # ... and gives up when told, which is no error here
    assert dask.client.status == "closed"
    assert not [m for m in client_log.messages if m.startswith("ERROR")], client_log.messages


# --- slewbench's own clients --------------------------------------------------------------------

def test_a_sweep_through_the_scheduler_option_leaves_no_client_open(tmp_path, cluster, monkeypatch):
    connected = spy(monkeypatch)
    status = main(["sweep", str(study_file(tmp_path)), "--out", str(tmp_path / "out"), "--no-plots",
                   "--scheduler", cluster.scheduler_address])
    assert status == 0 and (tmp_path / "out" / "cases.csv").exists()
    assert len(connected) == 1 and connected[0].client.status == "closed"


@pytest.mark.parametrize("raised, exit_status", [(KeyboardInterrupt, 130), (RuntimeError, 1)])
def test_a_sweep_through_the_scheduler_option_that_stops_leaves_no_client_open(tmp_path, cluster, monkeypatch,
                                                                               raised, exit_status):
    connected = spy(monkeypatch)

    def stopped(*args, **kwargs):
        raise raised("stopped")

    monkeypatch.setattr(engine, "sweep", stopped)
    status = main(["sweep", str(study_file(tmp_path)), "--out", str(tmp_path / "out"), "--no-plots",
                   "--scheduler", cluster.scheduler_address])
    assert status == exit_status
    assert len(connected) == 1 and connected[0].client.status == "closed"


@pytest.mark.parametrize("fails", [False, True])
def test_a_study_naming_its_scheduler_leaves_no_client_open(tmp_path, cluster, monkeypatch, fails):
    connected = spy(monkeypatch)
    study = study_file(tmp_path, execution={"scheduler": cluster.scheduler_address})
    if fails:
        def failing(*args):
            raise RuntimeError("engine")

        monkeypatch.setattr(engine, "_Engine", failing)
        with pytest.raises(RuntimeError, match="engine"):
            engine.sweep(study)
    else:
        assert engine.sweep(study).missing == 0
    assert len(connected) == 1 and connected[0].client.status == "closed"


# --- the studies guide's example, as a script -----------------------------------------------------

def dask_example() -> str:
    """The studies guide's Python block that starts a LocalCluster."""
    blocks = re.findall(r"^\.\. code-block:: python\n\n((?:(?: {3}.*)?\n)+)", STUDIES_GUIDE.read_text(),
                        flags=re.MULTILINE)
    found = [textwrap.dedent(block) for block in blocks if "LocalCluster" in block]
    assert len(found) == 1, "docs/guide/studies.rst has one Python block on a LocalCluster"
    return found[0]


def run_timed(script: str, folder: Path) -> tuple[float, float, str, str]:
    """Run ``script`` (which prints ``DONE`` as its last output) from the repository root: the
    seconds to ``DONE``, the seconds from ``DONE`` to the process's exit, stdout, stderr."""
    path = folder / "example.py"
    path.write_text(script + '\nprint("DONE", flush=True)\n')
    start = time.monotonic()
    process = subprocess.Popen([sys.executable, str(path)], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    try:
        out, done = [], None
        for line in process.stdout:
            out.append(line)
            if line.strip() == "DONE":
                done = time.monotonic()
        error = process.stderr.read()
        process.wait(timeout=120)
    finally:
        process.kill()
        process.wait()
    end = time.monotonic()
    assert process.returncode == 0 and done is not None, "".join(out)[-2000:] + error[-3000:]
    return done - start, end - done, "".join(out), error


def check_exit(folder: Path, script: str) -> None:
    _, exit_s, out, error = run_timed(script, folder)
    assert RECONNECT not in error and " - ERROR - " not in error, error[-3000:]
    # after its last output the script ends as any slewbench script does (about 1 s on this
    # machine): no client left retrying a stopped scheduler, which Dask gives 10 s
    assert exit_s < 5.0, (exit_s, error[-2000:])
    assert "cl.int_u" in out


def test_the_guides_dask_pattern_on_a_small_study_exits_cleanly(tmp_path):
    """The guide's block on a two-case study, its one worker a thread of the script (about 5 s)."""
    script = dask_example()
    shipped = '"scenarios/study_planners_vs_slew_angle.yaml"'
    workers = "LocalCluster(n_workers=2, threads_per_worker=1,"
    assert shipped in script and workers in script
    script = script.replace(shipped, repr(str(study_file(tmp_path)))).replace(
        workers, 'LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1",')
    check_exit(tmp_path, script)


@pytest.mark.slow  # the shipped study on two local workers: about 30 s
def test_the_guides_dask_example_as_written_exits_cleanly(tmp_path):
    check_exit(tmp_path, dask_example())
