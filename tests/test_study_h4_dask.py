"""A Dask scheduler address that cannot be a scheduler is refused fast and said plainly, and a sweep
stopped on Dask leaves no traceback in the log.

* A closed port is refused in well under :data:`HANDSHAKE_TIMEOUT_S` (Dask's own connect retries a
  refused connection until its timeout: 10 s before), saying the connection was refused; a host
  name that does not resolve likewise, naming it.
* A listener that speaks another protocol (an SSH banner: Dask reads its first 8 bytes as a frame
  length of exabytes) is "not Dask's protocol", not ``MemoryError: Unable to allocate 3 EiB``.
* ``slewbench sweep --scheduler`` with a closed port exits 2 before it checks the study's cases
  (which takes seconds for a study that disperses the inertia).
* Cancelling the futures of :attr:`DaskCluster.executor` while their tasks finish (what an
  interrupted sweep does) logs nothing: Dask's ``client.get_executor()`` set the result of a task
  that finished meanwhile on the cancelled future, and tornado logged ``InvalidStateError`` with
  its traceback into the sweep's output (seen on ``timeout -s INT 20 slewbench sweep ... --scheduler``).
"""
from __future__ import annotations

import logging
import socket
import threading
import time
from pathlib import Path

import pytest

from scenarios.errors import ScenarioError
from scenarios.study.engine import HANDSHAKE_TIMEOUT_S, DaskCluster, connect_scheduler


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def test_a_closed_port_is_refused_at_once():
    port = _closed_port()
    start = time.monotonic()
    with pytest.raises(ScenarioError) as raised:
        connect_scheduler(f"tcp://127.0.0.1:{port}", "--scheduler")
    elapsed = time.monotonic() - start
    assert elapsed < 3.0 < HANDSHAKE_TIMEOUT_S, elapsed
    message = str(raised.value)
    assert message.startswith("--scheduler: ")
    assert f"tcp://127.0.0.1:{port}" in message and "refused" in message


def test_a_host_that_does_not_resolve_is_refused_at_once_by_name():
    start = time.monotonic()
    with pytest.raises(ScenarioError) as raised:
        connect_scheduler("tcp://no-such-host.invalid:8786", "execution.scheduler")
    assert time.monotonic() - start < 3.0
    message = str(raised.value)
    assert message.startswith("execution.scheduler: ") and "'no-such-host.invalid'" in message
    assert "resolve" in message


@pytest.fixture
def banner_server():
    """A listener that greets every connection with an SSH banner and keeps it open."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(4)
    kept: list[socket.socket] = []

    def serve() -> None:
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            conn.sendall(b"SSH-2.0-OpenSSH_9.6\r\n")
            kept.append(conn)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    yield server.getsockname()[1]
    server.close()
    for conn in kept:
        conn.close()


def test_another_protocol_is_said_to_be_one_not_a_memory_error(banner_server):
    with pytest.raises(ScenarioError) as raised:
        connect_scheduler(f"tcp://127.0.0.1:{banner_server}", "--scheduler")
    message = str(raised.value)
    assert "MemoryError" not in message and "EiB" not in message, message
    assert "not in Dask's protocol" in message and f"tcp://127.0.0.1:{banner_server}" in message


def test_sweep_with_a_closed_scheduler_exits_2_before_checking_the_cases(tmp_path, monkeypatch, capsys):
    from scenarios.cli.commands import main
    from scenarios.study import spec

    def load_study(*args, **kwargs):
        raise AssertionError("the cases were checked before the scheduler")

    monkeypatch.setattr(spec, "load_study", load_study)
    port = _closed_port()
    status = main(["sweep", "scenarios/study_truth_inertia_monte_carlo.yaml", "--out", str(tmp_path / "sw"),
                   "--scheduler", f"tcp://127.0.0.1:{port}"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert f"--scheduler: no Dask scheduler answered at tcp://127.0.0.1:{port}: nothing listens there" in err
    assert "Traceback" not in err
    assert not (tmp_path / "sw").exists()


def _quick(x: int) -> int:
    time.sleep(0.001)
    return x


def test_cancelling_a_clusters_futures_while_tasks_finish_logs_nothing(caplog):
    distributed = pytest.importorskip("distributed")
    errors: list[logging.LogRecord] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            if record.levelno >= logging.ERROR:
                errors.append(record)

    handler = Keep()
    loggers = [logging.getLogger(name) for name in ("tornado.application", "distributed.client", "asyncio")]
    for logger in loggers:
        logger.addHandler(handler)
    try:
        with (distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=2, worker_dashboard_address=None,
                                       dashboard_address=None) as cluster,
              distributed.Client(cluster) as client, DaskCluster(cluster.scheduler_address, client) as dask):
            for trial in range(5):
                executor = dask.executor
                futures = [executor.submit(_quick, 1000 * trial + i) for i in range(300)]
                time.sleep(0.05)
                for future in futures:
                    future.cancel()
                time.sleep(0.1)
            # the executor still gives results (and what a task raised)
            assert [f.result(timeout=10) for f in [dask.executor.submit(_quick, i) for i in range(3)]] == [0, 1, 2]
            with pytest.raises(ZeroDivisionError):
                dask.executor.submit(divmod, 1, 0).result(timeout=10)
            time.sleep(0.2)
    finally:
        for logger in loggers:
            logger.removeHandler(handler)
    assert not errors, [record.getMessage()[:200] for record in errors]


def _slow_case(payload):
    """A case's rows after 0.3 s (the sweep's main loop checks its cluster meanwhile)."""
    from scenarios.study.worker import run_case

    time.sleep(0.3)
    return run_case(payload)


def test_a_sweep_on_a_cluster_never_waits_for_the_scheduler_in_its_main_thread(monkeypatch):
    """The worker count the sweep needs (at its start, and every second to notice a cluster without
    workers) is asked in a thread of its own: a Ctrl-C that lands in the main thread while it waits
    in ``distributed.utils.sync`` made tornado log ``NameError: cannot access free variable
    'future'`` with its traceback (1 of 3 interrupted runs of a 500-case study)."""
    distributed = pytest.importorskip("distributed")
    import copy

    from scenarios.study.engine import sweep
    from tests.test_sweep import BASE

    asked_in: list[str] = []
    counted = DaskCluster.workers

    def workers(self):
        asked_in.append(threading.current_thread().name)
        return counted(self)

    monkeypatch.setattr(DaskCluster, "workers", workers)
    study = {"study": "h4-watch", "scenario": copy.deepcopy(BASE),
             "grid": {"maneuver.final.q": [[0.9238795, 0.3826834, 0, 0], [0.7071068, 0.7071068, 0, 0],
                                           [0.9659258, 0.258819, 0, 0], [0.8660254, 0.5, 0, 0]]}}
    with (distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                   host="127.0.0.1", dashboard_address=None,
                                   worker_dashboard_address=None) as cluster,
          connect_scheduler(cluster.scheduler_address) as dask):
        asked_in.clear()  # connect_scheduler's own checks are before any case
        results = sweep(study, cluster=dask, task=_slow_case)
    assert len(results.to_dataframe()) >= 4
    assert asked_in, "the worker count was never asked"
    assert threading.main_thread().name not in asked_in, asked_in


def test_cancelling_after_the_client_closed_logs_nothing():
    """A sweep whose scheduler went away cancels its futures on a closed client: that raised
    ``ClosedClientError`` in the future's callback, and ``concurrent.futures`` logged "exception
    calling callback" with two tracebacks per future."""
    distributed = pytest.importorskip("distributed")
    errors: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            if record.levelno >= logging.ERROR:
                errors.append(record.getMessage())

    handler = Keep()
    logger = logging.getLogger("concurrent.futures")
    logger.addHandler(handler)
    try:
        with distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None,
                                      worker_dashboard_address=None) as cluster:
            with distributed.Client(cluster) as client:
                dask = DaskCluster(cluster.scheduler_address, client)
                futures = [dask.executor.submit(time.sleep, 0.5) for _ in range(3)]
                # the state Dask leaves a client in when it could not reconnect (_reconnect: "closing
                # client"), with tasks submitted while it tried still pending
                client.status = "closed"
                try:
                    for future in futures:
                        future.cancel()
                finally:
                    client.status = "running"
    finally:
        logger.removeHandler(handler)
    assert not errors, errors


def test_a_sweep_whose_client_closed_stops_at_once_saying_so():
    """A client that could not reconnect to its scheduler closes itself (Dask: 10 s); the sweep then
    stops like an interrupted one at once, saying the scheduler went away, where it waited 60 s more
    for workers and said "no workers"."""
    distributed = pytest.importorskip("distributed")
    import copy

    from scenarios.errors import SweepInterrupted
    from scenarios.study.engine import sweep
    from tests.test_sweep import BASE

    study = {"study": "h4-gone", "scenario": copy.deepcopy(BASE),
             "grid": {"maneuver.final.q": [[0.9238795, 0.3826834, 0, 0], [0.7071068, 0.7071068, 0, 0],
                                           [0.9659258, 0.258819, 0, 0], [0.8660254, 0.5, 0, 0]]}}
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                  host="127.0.0.1", dashboard_address=None,
                                  worker_dashboard_address=None) as cluster:
        dask = connect_scheduler(cluster.scheduler_address)
        closer = threading.Timer(0.5, dask.client.close)
        closer.start()
        start = time.monotonic()
        with pytest.raises(SweepInterrupted) as raised:
            sweep(study, cluster=dask, task=_slow_case)
        closer.join()
    assert time.monotonic() - start < 5.0
    assert "client" in raised.value.reason and cluster.scheduler_address in raised.value.reason, raised.value.reason


class _DropsItsFirstTask:
    """An executor whose first task is dropped as a Dask client that lost its scheduler drops its
    tasks (the future cancelled, not by the sweep: ``_settle``); the others run at once."""

    def __init__(self):
        self.dropped = False

    def submit(self, fn, /, *args, **kwargs):
        from concurrent.futures import Future

        future = Future()
        if not self.dropped:
            self.dropped = True
            future.cancel()
            future.set_running_or_notify_cancel()
        else:
            future.set_result(fn(*args, **kwargs))
        return future


def test_a_task_the_cluster_dropped_is_run_again_not_stored_crashed(tmp_path):
    # before: the cancelled future's CancelledError was charged as a worker death, and with
    # retries 0 the case was stored crashed ("worker died ('CancelledError: ')"), never run again
    # on a resume; seen with a Dask client closed while single-case tasks were in flight
    import copy
    from concurrent.futures import Executor

    from scenarios.study.engine import sweep
    from scenarios.study.store import SweepStore
    from tests.test_sweep import BASE

    class Dropping(_DropsItsFirstTask, Executor):
        pass

    study = {"study": "dropped", "scenario": copy.deepcopy(BASE), "execution": {"retries": 0},
             "grid": {"maneuver.duration": [30.0, 40.0]}}
    results = sweep(study, executor=Dropping(), workers=1, store=SweepStore(tmp_path))
    table = results.to_dataframe()
    assert sorted(set(table["case"])) == [0, 1] and set(table["status"]) == {"ok"}, table[["case", "status"]]


def test_a_closed_scheduler_in_the_study_file_is_refused_before_the_cases(tmp_path, monkeypatch, capsys):
    # before: execution.scheduler was checked only after every case (1 min 44 s for 100,000 cases)
    import shutil

    import yaml

    from scenarios.cli.commands import main
    from scenarios.study import spec

    def cases(self):
        raise AssertionError("the cases were checked before the scheduler")

    monkeypatch.setattr(spec._Expansion, "cases", cases)
    port = _closed_port()
    shutil.copy(Path("scenarios") / "eigenaxis_truth.yaml", tmp_path / "eigenaxis_truth.yaml")
    study = yaml.safe_load((Path("scenarios") / "study_truth_inertia_monte_carlo.yaml").read_text())
    study["execution"] = {"scheduler": f"tcp://127.0.0.1:{port}"}
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(study, sort_keys=False))
    status = main(["sweep", str(tmp_path / "study.yaml"), "--out", str(tmp_path / "sw")])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "execution.scheduler: no Dask scheduler answered at" in err and str(port) in err
    assert "Traceback" not in err and not (tmp_path / "sw").exists()
