"""Run a trade study: every case on a local process pool (default), any
``concurrent.futures.Executor`` (a Dask client's ``get_executor()``, for one), or a Dask cluster
by address; finished cases go to the crash-safe store as they arrive.

A case that raises or exceeds ``case_timeout_s`` is a ``crashed`` row and the sweep goes on; on
any executor a task runs in :func:`scenarios.study.worker.run_chunk`, so that what it raised comes
back as a :class:`~scenarios.study.worker.TaskRaised`, told apart from a lost worker. A
case whose worker died is retried ``retries`` times (its stored ``attempts`` counts every start), and
so is one whose task raised what says the worker failed it
(:func:`scenarios.study.worker.worker_fault`: out of memory, a module missing on that worker).
On a local pool each worker writes the case it runs and when it started it into a shared slot
table (:func:`scenarios.study.worker.tracked_case`), so a worker's death is charged to the case
that worker was running, never to a case that was only queued; when the pool cannot tell (several
workers died at once), each case that was running is re-run alone, and one that kills its worker
alone is charged that death and the one it shared. A case's time limit counts from its start in
its worker. The local workers fork from a server that dies with the sweep, and they die with it
(:data:`scenarios.study.worker.PARENT_ENVIRONMENT`): a sweep killed outright leaves no process.

On Dask, :func:`connect_scheduler` checks that the address accepts a connection within
:data:`CONNECT_TIMEOUT_S`, answers as a Dask scheduler within :data:`HANDSHAKE_TIMEOUT_S` and
that it has workers (waiting at most :data:`WORKER_WAIT_S`) before
anything is written; cases go in chunks sized from the cases' run times (about
:data:`CHUNK_TARGET_S` each), and a sweep whose cluster stays without workers for
:data:`WORKER_WAIT_S` stops as if interrupted (resume it later).

The parent's own work per case (the store's commits, one per batch of results; collection;
progress) is kept small, so that it keeps up with many workers.
"""
from __future__ import annotations

import atexit
import collections
import contextlib
import json
import logging
import math
import multiprocessing
import os
import signal
import statistics
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import (
    FIRST_COMPLETED,
    Executor,
    Future,
    InvalidStateError,
    ProcessPoolExecutor,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ocp.errors import excerpt
from scenarios.errors import ScenarioError, SweepInterrupted, WorkersCannotStart
from scenarios.schema.study import scheduler_address
from scenarios.study.server import SAFE_PATH, SAFE_PATH_MARK, UNSET, USER_PYTHONPATH
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import SweepStore, encode_rows
from scenarios.study.types import Case, Study
from scenarios.study.worker import (
    PARENT_ENVIRONMENT,
    PRELOAD,
    SLOT_FIELDS,
    TaskRaised,
    WorkerFault,
    crashed_rows,
    run_case,
    run_chunk,
    start_local_worker,
    timed_out_message,
)

if TYPE_CHECKING:
    import pandas

_POLL_S = 0.5
MANAGER_JOIN_S = 10.0  # the longest a killed local pool's manager thread is waited for
_TIMEOUT_GRACE = 1.25  # the driver gives up on a case at this multiple of case_timeout_s (+ 5 s)
HANDSHAKE_TIMEOUT_S = 10.0
"""How long a Dask scheduler's address has to answer as a Dask scheduler [s]."""
CONNECT_TIMEOUT_S = 2.0
"""How long a Dask scheduler's host has to accept a TCP connection [s], checked before the
handshake: a closed port or a host name that does not resolve is refused at once (Dask's own
connect retries a refused connection until :data:`HANDSHAKE_TIMEOUT_S`), a host that does not
answer after this (down, unreachable, or a firewall that drops the connection). A host that is up
accepts a connection in a round trip, whatever its scheduler is doing (the kernel accepts it); 2 s
leaves room for one lost first packet, sent again after 1 s."""
WORKER_WAIT_S = 60.0
"""How long a sweep waits for a Dask cluster without workers: before it starts (then it is refused,
nothing written) and while it runs (then it stops like an interrupted sweep) [s]."""
CHUNK_TARGET_S = 0.5
"""Run time aimed at for one task of several cases, on a local pool or Dask [s]: the cost of a task
to the sweep (about half a millisecond on a local pool, a millisecond on Dask) is then shared by the
cases of the chunk."""
MAX_CHUNK = 64
"""Most cases in one task."""
MAX_WORKERS = 1024
"""Most cases run at once."""
PROGRESS_LINE_S = 30.0
"""Where standard error is not a terminal (continuous integration, ``nohup``, a notebook), the longest
time between two of the sweep's progress lines [s] (:class:`_Progress`)."""


@dataclass
class SweepResults:
    """The cases of a study and their records.

    Parameters
    ----------
    study : Study
        The expanded study.
    records : dict
        Case key -> ``{"status", "rows", "elapsed_s", "attempts"}`` as stored
        (:meth:`scenarios.study.store.SweepStore.records`; ``rows`` as
        :meth:`scenarios.output.results.Row.to_dict` gives them): the cases run by this call and
        those of the study found in the store (:func:`sweep` leaves out the cases stored for
        another study).
    workers : dict
        Worker (``host:pid``) -> solvers it built, for the workers of this call.
    cpu_s : dict
        Case key -> CPU time of the case in its worker [s], for the cases run by this call (not
        stored).
    worker_cpu_s : dict
        Worker (``host:pid``) -> CPU time of its process from its start to its last case [s]
        (start-up and imports included; not stored).

    Raises
    ------
    TypeError
        ``study`` is not a :class:`Study` or ``records`` not a dict.
    """

    study: Study
    records: dict[str, dict[str, Any]]
    workers: dict[str, int] = field(default_factory=dict)
    cpu_s: dict[str, float] = field(default_factory=dict)
    worker_cpu_s: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.study, Study):
            raise TypeError(f"study must be a scenarios.study.Study, got {type(self.study).__name__}")
        for name in ("records", "workers", "cpu_s", "worker_cpu_s"):
            if not isinstance(getattr(self, name), dict):
                raise TypeError(f"{name} must be a dict, got {type(getattr(self, name)).__name__}")

    @property
    def missing(self) -> int:
        """Cases of the study without a record."""
        return sum(case.key not in self.records for case in self.study.cases)

    def table(self) -> tuple[list[str], list[dict[str, Any]]]:
        """Columns and rows of ``cases.csv``: one row per case and planner.

        Returns
        -------
        columns : list of str
        rows : list of dict
            As :func:`scenarios.study.report.case_table`.
        """
        from scenarios.study.report import case_table
        return case_table(self.study, self.records)

    def to_dataframe(self) -> pandas.DataFrame:
        """``cases.csv`` as a pandas DataFrame (needs pandas installed).

        Returns
        -------
        pandas.DataFrame
            One row per case and planner; columns as :meth:`table`. ``plan_time_s`` and the
            metric columns are float, NaN where missing or non-finite (as
            :meth:`scenarios.output.results.RunResults.to_dataframe`).
        """
        from scenarios.output.tables import data_frame, numeric_columns
        columns, rows = self.table()
        return data_frame(columns, rows, numeric_columns())

    def write(self, directory: str | Path, plots: bool = True, progress: bool = False) -> list[str]:
        """Write cases.csv, summary.csv, summary.md, study.yaml and plots.

        Parameters
        ----------
        directory : str or Path
            The output directory (claimed for slewbench; only files it listed are replaced).
        plots : bool, optional
            Also draw the PNG figures.
        progress : bool, optional
            Show the files written so far on standard error (``slewbench sweep`` does): a bar
            on a terminal, elsewhere a line at most every 30 s and none for a quick write
            (:func:`write_progress`). Default False.

        Returns
        -------
        list of str
            The file names written (relative to ``directory``).

        Raises
        ------
        TypeError
            ``directory`` is not a path, or ``plots`` or ``progress`` not a bool.
        """
        if not isinstance(directory, (str, os.PathLike)):
            raise TypeError(f"directory must be a str or os.PathLike, got {type(directory).__name__}")
        for name, value in (("plots", plots), ("progress", progress)):
            if not isinstance(value, bool):
                raise TypeError(f"{name} must be True or False, got {excerpt(value)}")
        from scenarios.study.report import write_report
        return write_report(self, Path(directory), plots=plots, progress=progress)

    def __repr__(self) -> str:
        from scenarios.study.types import sweep_repr
        return sweep_repr(self.study, self.records)

    def _repr_html_(self) -> str:
        from scenarios.study.types import sweep_repr_html
        return sweep_repr_html(self.study, self.records)


UNGUARDED = ("the local sweep workers died while they started, before any case. Usually the script that calls "
             "scenarios.sweep() calls it at its top level: each worker process imports the script again and would "
             "start a sweep of its own. Put the call under `if __name__ == \"__main__\":` in the script (see "
             "'From Python' in the guide's Trade studies page).")
"""What a sweep says when its local workers die while they start (the usual cause named)."""


def start_forkserver() -> multiprocessing.context.BaseContext:
    """Start (once per process) the server that local workers fork from, importing :data:`PRELOAD`.

    It returns at once: the server imports while the caller goes on (the CLI calls this before it
    expands the study), and the first worker waits until the imports are done. The server dies
    with this process (:data:`scenarios.study.worker.PARENT_ENVIRONMENT`), and the workers with it.
    It starts in Python's safe-path mode, so that a module in the current directory named as one of
    slewbench's packages (a user's ``controllers.py``) does not replace it in the workers
    (:mod:`scenarios.study.server`).

    Returns
    -------
    multiprocessing.context.BaseContext
        The ``forkserver`` context that local pools use.

    Raises
    ------
    SystemExit
        When called in a process that is starting (a worker importing the caller's script because
        the script calls :func:`sweep` outside ``if __name__ == "__main__":``): that worker ends,
        and the sweep that started it raises :class:`WorkersCannotStart`.
    """
    if getattr(multiprocessing.current_process(), "_inheriting", False):  # multiprocessing's own test
        # this process is a worker importing the caller's script: it cannot start one, and ends
        # quietly (the sweep that started it says why, once, as WorkersCannotStart)
        raise SystemExit("slewbench: a local sweep was started while a worker process imported the main script; put "
                         "the call of scenarios.sweep() under `if __name__ == \"__main__\":` in the script")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(list(PRELOAD))
    from multiprocessing import forkserver, resource_tracker
    # seen by the server only (it starts now, if not yet): the sweep it dies with, and safe-path mode
    # (the current directory off its sys.path; scenarios.study.server puts the environment back)
    # and this process's import path as its PYTHONPATH (the cwd's '' left out), so that the server
    # imports the workbench this process runs (a checkout on sys.path, not another copy installed)
    server_environment = {PARENT_ENVIRONMENT: str(os.getpid()), SAFE_PATH: os.environ.get(SAFE_PATH) or "1",
                          SAFE_PATH_MARK: "kept" if os.environ.get(SAFE_PATH) else "added",
                          "PYTHONPATH": os.pathsep.join(entry for entry in sys.path if entry),
                          USER_PYTHONPATH: os.environ.get("PYTHONPATH", UNSET)}
    previous = {name: os.environ.get(name) for name in server_environment}
    os.environ.update(server_environment)
    try:
        resource_tracker.ensure_running()  # first: starting it unblocks SIGINT (it blocks it around its own start)
        running = _forkserver_pid()
        with _sigint_blocked():
            forkserver.ensure_running()
        started = _forkserver_pid()
        if started is not None and started != running:  # started now, by slewbench: it stops it
            _STARTED.add(started)
    finally:
        for name, value in previous.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
    if not _STOP_AT_EXIT:
        atexit.register(_stop_forkserver, os.getpid())
        _STOP_AT_EXIT.append(True)
    return context


_STOP_AT_EXIT: list[bool] = []  # whether _stop_forkserver is registered to run at this process's exit
_STARTED: set[int] = set()  # process ids of the fork servers start_forkserver started (not the user's own)


def _forkserver_pid() -> int | None:
    """The process id of this process's ``multiprocessing`` fork server, if one was started."""
    from multiprocessing import forkserver
    return getattr(forkserver._forkserver, "_forkserver_pid", None)  # private, stable since 3.4


def _stop_forkserver(owner: int | None = None) -> None:
    """Kill the fork server of this process's local workers, if it runs, and with it every worker
    it forked, one still starting included (they die with it from their fork on:
    :data:`scenarios.study.worker.PARENT_ENVIRONMENT`).

    A sweep that stops before its end calls it, and the process that started the server at its
    exit (``owner``, its process id: a process forked from it does nothing), so that a server
    still importing, with Ctrl-C blocked, does not outlive a sweep interrupted before its first
    case. The next :func:`start_forkserver` starts a new server (``multiprocessing`` finds this
    one dead). A server slewbench did not start (the caller's program started it for pools of its
    own before its first sweep) is left alone.
    """
    pid = _forkserver_pid()
    if pid in _STARTED and owner in (None, os.getpid()):
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)


@contextlib.contextmanager
def _sigint_blocked() -> Iterator[None]:
    """Block Ctrl-C (SIGINT) in this thread while it starts the fork server, which inherits the block.

    Ctrl-C reaches the whole foreground process group, the server too, which imports the model for
    seconds after it starts: its KeyboardInterrupt traceback was printed into the sweep's
    "interrupted" message. The server starts with SIGINT blocked (a new process inherits the mask
    of the thread that started it), catches and ignores it once it has imported
    :mod:`scenarios.study.worker` (a Ctrl-C pending meanwhile included), and only then unblocks
    it; its workers inherit the handler: the sweep stops them itself (:meth:`_LocalPool.kill`,
    :func:`_stop_forkserver`; they also die with it). This process's handler is not touched, so its
    own Ctrl-C is not lost: its other threads take it, or this one once unblocked. Outside the main
    thread the server is started as it is (Python runs signal handlers in the main thread only).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def _descendants(pid: int) -> list[int]:
    """The processes that process ``pid`` started, and theirs, now (Linux's ``/proc``; elsewhere none)."""
    found: list[int] = []
    parents = [pid]
    while parents:
        parent = parents.pop()
        try:
            tasks = os.listdir(f"/proc/{parent}/task")
        except OSError:  # ended, or no /proc
            continue
        for task in tasks:
            try:
                with open(f"/proc/{parent}/task/{task}/children") as listed:
                    children = [int(child) for child in listed.read().split()]
            except OSError:
                continue
            found += children
            parents += children
    return found


class _LocalPool:
    """A process pool forked from the server, with its slot table (module docstring)."""

    def __init__(self, workers: int):
        from multiprocessing import forkserver
        context = start_forkserver()
        self.slots = context.Array("d", SLOT_FIELDS * workers, lock=False)
        server = getattr(forkserver._forkserver, "_forkserver_pid", None) or -1  # private, stable since 3.4
        self.executor = ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=start_local_worker,
                                            initargs=(self.slots, context.Lock(), server))
        self.ours: set[int] = set()  # workers this pool killed itself
        self.processes: Any = self.executor._processes  # private, stable since 3.8; kept after shutdown

    def running(self) -> dict[int, tuple[int, float]]:
        """Case index -> (worker pid, start time) of the cases the workers are running now."""
        found = {}
        for at in range(0, len(self.slots), SLOT_FIELDS):
            pid, index, start = self.slots[at:at + 3]
            if pid and index:
                found[int(index) - 1] = (int(pid), start)
        return found

    def started(self) -> set[int]:
        """Indices of the cases the workers are running or have finished (since their last results
        may not have reached the sweep)."""
        found = set(self.running())
        for at in range(0, len(self.slots), SLOT_FIELDS):
            if self.slots[at + 3]:
                found.add(int(self.slots[at + 3]) - 1)
        return found

    def kill(self) -> None:
        """Stop now, including a worker stuck in C code (it cannot be interrupted) and the processes
        a worker started (a C compiler, :mod:`ocp.simulation.compiled`), and wait for the
        pool's manager thread to end (its workers are dead: it ends at once), so that none of the
        pool's threads or pipes outlives the sweep: CPython 3.11's exit hook of ``concurrent.futures``
        could otherwise wake a manager thread whose pipe it was closing at the same moment
        ("Exception ignored ... OSError: [Errno 9] Bad file descriptor" after a sweep's error)."""
        for process in list(self.processes.values()):
            if process.is_alive():
                started = _descendants(process.pid)  # a C compiler it runs: it would go on alone
                self.ours.add(process.pid)
                process.kill()
                for pid in started:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(pid, signal.SIGKILL)
        self.executor.shutdown(wait=False, cancel_futures=True)
        manager = getattr(self.executor, "_executor_manager_thread", None)  # private, stable since 3.9
        if manager is not None and manager is not threading.current_thread():
            manager.join(timeout=MANAGER_JOIN_S)

    def claimed(self) -> int:
        """Workers that started (claimed their slot: their initializer ran)."""
        return sum(self.slots[at] != 0 for at in range(0, len(self.slots), SLOT_FIELDS))

    def culprits(self) -> set[int]:
        """Workers that ended by themselves (not stopped by the pool or by :meth:`kill`)."""
        found = set()
        for process in list(self.processes.values()):
            process.join(timeout=5.0)
            if process.exitcode is not None and process.exitcode != -signal.SIGTERM and process.pid not in self.ours:
                found.add(process.pid)
        return found


@dataclass
class _Batch:
    """Cases submitted together (one case, or a Dask chunk) and when their clock started."""

    keys: list[str]
    submitted: float
    started: float | None = None


def _duration(seconds: float) -> str:
    """``45s``, ``2m10s``, ``1h02m05s``."""
    whole = int(seconds)
    hours, minutes, rest = whole // 3600, whole // 60 % 60, whole % 60
    return f"{hours}h{minutes:02d}m{rest:02d}s" if hours else f"{minutes}m{rest:02d}s" if minutes else f"{rest}s"


class _Progress:
    """A sweep's progress on standard error: tqdm's bar (with the time left) on a terminal; elsewhere
    a plain line, ``NAME: 12/40 cases done, 3 not ok (1 crashed), 2m10s elapsed``, at most every
    :data:`PROGRESS_LINE_S` (also while no case finishes) and once at the end, so that a long
    sweep under continuous integration or ``nohup`` can be told from a hung one. ``units``: what
    one case and several are called (:attr:`~scenarios.study.types.Study.units`); ``timeouts_apart``:
    the crashed cases that ran out of ``case_timeout_s`` are said apart, ``(1 crashed, 2 timed
    out)`` (a slew table's, whose entries then have their own status, ``timed_out``)."""

    def __init__(self, name: str, total: int | None, clock: Callable[[], float] = time.monotonic,
                 units: tuple[str, str] = ("case", "cases"), timeouts_apart: bool = False):
        self.name, self.total, self.clock, self.units = name, total, clock, units
        self.timeouts_apart = timeouts_apart
        self.done = self.not_ok = self.crashed = self.timed_out = 0
        self.started = self.said = clock()
        self.bar: Any = None
        if sys.stderr.isatty():
            from tqdm import tqdm
            # without a total, tqdm writes a count and a rate: "7 files [00:02, 3.1 files/s]"
            self.bar = tqdm(total=total, unit=units[0] if total is not None else f" {units[1]}", desc=name[:40],
                            dynamic_ncols=True, file=sys.stderr, mininterval=0.5)
            if not (self.bar.ncols or 0) > 0:  # a terminal reporting no size (0 x 0):
                self.bar.dynamic_ncols, self.bar.ncols, self.bar.nrows = False, 80, None  # tqdm would draw nothing

    def line(self) -> str:
        """What the progress line says now."""
        counts = f", {self.not_ok} not ok" if self.not_ok else ""
        timed = self.timed_out if self.timeouts_apart else 0
        kinds = [f"{count} {kind}" for count, kind in ((self.crashed - timed, "crashed"), (timed, "timed out")) if count]
        counts += f" ({', '.join(kinds)})" if kinds else ""
        done = self.done if self.total is None else f"{self.done}/{self.total}"
        return f"{self.name}: {done} {self.units[1]} done{counts}, {_duration(self.clock() - self.started)} elapsed"

    def update(self, done: int, not_ok: int, crashed: int, timed_out: int = 0) -> None:
        """Cases stored: ``done`` more; ``not_ok`` and ``crashed`` cases so far (``timed_out`` of
        the crashed ones ran out of ``case_timeout_s``)."""
        self.done += done
        self.not_ok, self.crashed, self.timed_out = not_ok, crashed, timed_out
        if self.bar is not None:
            self.bar.set_postfix(not_ok=not_ok, refresh=False)
            self.bar.update(done)
        self.poll()

    def advance(self, done: int = 1) -> None:
        """Steps done: ``done`` more (a count without statuses: the files :func:`write_progress`
        counts)."""
        self.done += done
        if self.bar is not None:
            self.bar.update(done)
        self.poll()

    def poll(self) -> None:
        """Off a terminal, say where the sweep is if the last line is :data:`PROGRESS_LINE_S` old."""
        if self.bar is None and self.clock() - self.said >= PROGRESS_LINE_S:
            self._say()

    def close(self) -> None:
        """Close the bar, or say the last line (none for a sweep with nothing to run; with no total,
        none unless a line was said before: a quick count stays quiet)."""
        if self.bar is not None:
            self.bar.close()
        elif self.total if self.total is not None else self.said > self.started:
            self._say()

    def _say(self) -> None:
        self.said = self.clock()
        print(self.line(), file=sys.stderr, flush=True)


def write_progress(name: str, enabled: bool) -> Any:
    """The progress of writing a study's tables and figures, as a sweep's (:class:`_Progress`, no
    total: the figures that apply are known as they are drawn): tqdm's bar on a terminal
    (``NAME: writing: 7 files ...``); elsewhere a line at most every :data:`PROGRESS_LINE_S`, and
    one at the end only if one was said (a quick write says nothing).

    Parameters
    ----------
    name : str
        The study's name.
    enabled : bool
        Show it; False: a progress that does nothing.

    Returns
    -------
    object
        ``advance(n)`` after each ``n`` files written, ``close()`` at the end.
    """
    if not enabled:
        return _NoProgress()
    return _Progress(f"{name}: writing", None, units=("file", "files"))


class _NoProgress:
    """:func:`write_progress` when not shown."""

    def advance(self, done: int = 1) -> None:
        """Nothing."""

    def close(self) -> None:
        """Nothing."""


class _Engine:
    """The submit / collect loop; see the module docstring for the failure rules."""

    def __init__(self, study: Study, executor: Executor | None, workers: int, store: SweepStore | None,
                 progress: bool, task: Callable[[dict[str, Any]], dict[str, Any]], cluster: Any = None,
                 timeouts_apart: bool = False):
        self.study, self.store, self.task, self.cluster = study, store, task, cluster
        self.owned = executor is None
        self.workers = workers
        self.dask = not self.owned and (isinstance(executor, _ClusterExecutor)
                                        or type(executor).__module__.startswith("distributed"))
        self.chunked = self.owned or self.dask
        # a local pool gets one chunk ahead of its workers, so that none idles while the driver stores a
        # result; Dask two chunks per worker; other executors one case per worker
        self.window = workers + 1 if self.owned else workers * (2 if self.dask else 1)
        self.pool = _LocalPool(workers) if self.owned else None
        self.executor: Executor = self.pool.executor if self.pool is not None else executor  # type: ignore[assignment]
        self.timeout = study.execution.case_timeout_s
        self.limit = self.timeout * _TIMEOUT_GRACE + 5.0
        stored = store.records() if store is not None else {}
        # this study's stored cases only (a resumed study may have changed); a crashed one runs again
        self.records: dict[str, dict[str, Any]] = {case.key: stored[case.key] for case in study.cases
                                                   if case.key in stored}
        self.starts: dict[str, int] = collections.Counter()  # times started (stored as attempts)
        self.cases: dict[str, Case] = {}
        for case in study.cases:
            record = self.records.get(case.key)
            if record is None or record["status"] == "crashed":
                self.cases.setdefault(case.key, case)
                self.starts[case.key] = int(record["attempts"] or 0) if record is not None else 0
        self.finished: set[str] = set()  # cases recorded by this run
        self.pending = collections.deque(self.cases)
        self.suspects: collections.deque[str] = collections.deque()  # run alone, one at a time
        self.singles: collections.deque[str] = collections.deque()  # cases of a failed chunk, one per task
        self.in_flight: dict[Future, _Batch] = {}
        self.deaths: dict[str, int] = collections.Counter()  # worker deaths charged (against retries)
        self.shared: dict[str, int] = collections.Counter()  # deaths shared with others, charged if it dies alone
        self.worker_builds: dict[str, int] = {}
        self.cpu_s: dict[str, float] = {}
        self.worker_cpu_s: dict[str, float] = {}
        self.elapsed: collections.deque[float] = collections.deque(maxlen=64)
        self.not_ok = 0
        self.crashed = 0
        self.timed_out = 0  # of the crashed, those that ran out of case_timeout_s
        self.no_workers_since: float | None = None
        self.next_cluster_check = 0.0
        self.progress = (_Progress(study.name, len(self.cases), units=study.units, timeouts_apart=timeouts_apart)
                         if progress else None)

    # --- submitting ---------------------------------------------------------------------------

    def _payload(self, key: str) -> dict[str, Any]:
        case = self.cases[key]
        return {"key": key, "index": case.index, "scenario": case.scenario, "timeout_s": self.timeout}

    def _submit(self, keys: list[str]) -> None:
        now = time.monotonic()
        # a chunk of one case on a caller's executor too: what its task raises comes back as TaskRaised (a
        # worker fault as WorkerFault), told apart from a worker's death (and always rebuilt from its pickle)
        future: Future[Any] = self.executor.submit(run_chunk, self.task, [self._payload(key) for key in keys])
        for key in keys:
            self.starts[key] += 1  # taken back for a case a broken pool never started (_requeue)
        self.in_flight[future] = _Batch(keys, now)

    def _chunk_size(self) -> int:
        """Cases per task: about :data:`CHUNK_TARGET_S` of work (one case until cases have been
        timed), fewer near the end so that every worker gets a share."""
        if not self.chunked or len(self.elapsed) < min(self.workers, 8):
            return 1
        typical = statistics.median(self.elapsed) or 1e-3
        size = int(CHUNK_TARGET_S / typical)
        share = math.ceil(len(self.pending) / (2 * self.workers))
        return max(1, min(size, MAX_CHUNK, share))

    def _chunk_limit(self, size: int) -> float:
        """The driver's limit for a batch of ``size`` cases [s]: one case's, plus a generous share of
        the typical case's time for each other case (a chunk over it is run again case by case)."""
        typical = statistics.median(self.elapsed) if self.elapsed else self.timeout
        return self.limit + (size - 1) * max(4.0 * typical, 1.0)

    def _fill(self) -> None:
        if self.suspects:
            if not self.in_flight:
                key = self.suspects.popleft()
                self._submit([key])
            return
        while (self.singles or self.pending) and len(self.in_flight) < self.window:
            if self.singles:
                self._submit([self.singles.popleft()])
                continue
            size = self._chunk_size()
            self._submit([self.pending.popleft() for _ in range(min(size, len(self.pending)))])

    # --- collecting ---------------------------------------------------------------------------

    def _record(self, key: str, status: str, rows: list[dict[str, Any]], elapsed: float | None, batch: list,
                text: str | None = None) -> None:
        """Keep a finished case's record and queue it for the store (``text``: its rows encoded)."""
        attempts = max(self.starts[key], 1)
        self.records[key] = {"status": status, "rows": rows, "elapsed_s": elapsed, "attempts": attempts}
        self.finished.add(key)
        batch.append((key, status, encode_rows(rows) if text is None else text, elapsed, attempts))
        self.not_ok += any(row["status"] != "ok" for row in rows)
        self.crashed += status == "crashed"
        self.timed_out += status == "crashed" and bool(rows) and str(rows[0].get("message") or "").startswith(
            timed_out_message(self.timeout))

    def _commit(self, batch: list[tuple[str, str, str, float | None, int]]) -> None:
        """Commit finished cases in one transaction, then report them (a case shown done is stored)."""
        if not batch:
            return
        if self.store is not None:
            self.store.put_encoded(batch)
        if self.progress is not None:
            self.progress.update(len(batch), self.not_ok, self.crashed, self.timed_out)

    def _crash(self, key: str, message: str, batch: list) -> None:
        self._record(key, "crashed", crashed_rows(self.cases[key].scenario, message), None, batch)

    def _charge(self, key: str, deaths: int, why: str, batch: list, died: bool = True) -> None:
        """Charge ``deaths`` worker deaths (``died``) or worker faults (``why`` says which) to
        ``key``: crashed past ``retries``, else run again."""
        self.deaths[key] += deaths
        self.shared.pop(key, None)
        if self.deaths[key] > self.study.execution.retries:
            self._crash(key, f"{f'worker died ({why})' if died else why}; {self.starts[key]} attempt(s)", batch)
        else:
            self.pending.appendleft(key)

    def _raised(self, key: str, error: TaskRaised, batch: list) -> None:
        """What ``key``'s task raised: a worker fault charged as a death (run again up to
        ``retries`` times), anything else crashed at once, not run again (deterministic)."""
        if isinstance(error, WorkerFault):
            self._charge(key, 1, f"its task raised {error}", batch, died=False)
        else:
            self._crash(key, f"its task raised {error}", batch)

    def _result(self, key: str, result: dict[str, Any], batch: list) -> None:
        self.worker_builds[result["worker"]] = result["cache_builds"]
        text = result.get("rows_json")
        rows = json.loads(text) if text is not None else result["rows"]  # as stored: non-finite numbers null
        self._record(key, result["status"], rows, result["elapsed_s"], batch, text)
        if result.get("elapsed_s") is not None:
            self.elapsed.append(result["elapsed_s"])
        if result.get("cpu_s") is not None:
            self.cpu_s[key] = result["cpu_s"]
            self.worker_cpu_s[result["worker"]] = max(result["worker_cpu_s"], self.worker_cpu_s.get(result["worker"], 0.0))

    def _collect(self, done: set[Future]) -> None:
        batch: list = []
        broken = False
        for future in done:
            entry = self.in_flight.pop(future)
            if future.cancelled():
                # the sweep pops the futures it cancels first: this one the cluster dropped (a Dask
                # client that lost its scheduler, _settle): no worker died, its cases go back uncharged
                for key in entry.keys:
                    self.starts[key] -= 1
                self.pending.extendleft(sorted(entry.keys, key=lambda key: -self.cases[key].index))
                continue
            try:
                outcome = future.result()
            except BrokenProcessPool:
                if self.pool is not None:
                    broken = True
                    self.in_flight[future] = entry  # sorted out with the other cases of the pool below
                else:  # a pool the caller owns: it cannot be restarted from here
                    for key in entry.keys:
                        self._charge(key, 1, "its process ended abruptly", batch)
                continue
            except Exception as error:  # TaskRaised, or a lost worker (dask's KilledWorker, an executor's own failure)
                raised = error.key if isinstance(error, TaskRaised) and error.key in entry.keys else None
                if len(entry.keys) > 1 and isinstance(error, TaskRaised) and raised is not None:
                    # a chunk, and whose task raised is known
                    # the cases it finished before (their results lost with the chunk's) again, one per
                    # task; those after it were never started
                    at = entry.keys.index(raised)
                    for key in entry.keys[at + 1:]:
                        self.starts[key] -= 1
                    self.singles.extend(key for key in entry.keys if key != raised)
                    self._raised(raised, error, batch)
                elif len(entry.keys) > 1:  # a chunk: each of its cases again, one per task
                    self.singles.extend(entry.keys)
                elif isinstance(error, TaskRaised):
                    self._raised(entry.keys[0], error, batch)
                else:
                    self._charge(entry.keys[0], 1, excerpt(f"{type(error).__name__}: {error}", 300), batch)
                continue
            results = outcome if isinstance(outcome, list) else [outcome]
            for key, result in zip(entry.keys, results):
                self._result(key, result, batch)
        self._commit(batch)
        if broken:
            self._pool_broke()
        for key in list(self.shared):
            if key in self.finished:
                del self.shared[key]

    def _requeue(self, batches: list[_Batch], started: set[int], keep: set[str]) -> None:
        """Cases of a stopped pool run again, first (but those in ``keep``, dealt with by the caller).
        A chunk's cases run in order: those up to the last one a worker started were started, the
        others are not counted as started."""
        again = []
        for batch in batches:
            positions = [at for at, key in enumerate(batch.keys) if self.cases[key].index in started]
            last = max(positions, default=-1)
            for at, key in enumerate(batch.keys):
                if at > last:
                    self.starts[key] -= 1
                if key not in keep:
                    again.append(key)
        self.pending.extendleft(sorted(again, key=lambda key: -self.cases[key].index))

    def _new_pool(self) -> None:
        self.pool = _LocalPool(self.workers)
        self.executor = self.pool.executor

    def _pool_broke(self) -> None:
        """The local pool lost a worker: charge the case that worker was running; when the pool cannot
        tell, each case that was running runs alone (and owns this death if it dies alone)."""
        assert self.pool is not None
        running, started = self.pool.running(), self.pool.started()
        self.pool.kill()
        if not self.pool.claimed():  # every worker died before it could start: so would a new pool's
            raise WorkersCannotStart(UNGUARDED)
        culprits = self.pool.culprits()
        batches = list(self.in_flight.values())
        self.in_flight.clear()
        keys = [key for batch in batches for key in batch.keys]
        ran = sorted((key for key in keys if self.cases[key].index in running), key=lambda key: self.cases[key].index)
        guilty = [key for key in ran if running[self.cases[key].index][0] in culprits]
        suspects: list[str] = []
        if len(guilty) == 1 or (not culprits and len(ran) == 1):
            charged: str | None = (guilty or ran)[0]
        else:
            charged = None
            suspects = guilty or ([] if culprits else ran)  # a culprit between cases: no one to charge
            for key in suspects:
                self.shared[key] += 1
        self._requeue(batches, started, set(suspects) | ({charged} if charged is not None else set()))
        self.suspects.extend(suspects)
        batch: list = []
        if charged is not None:
            self._charge(charged, 1 + self.shared.get(charged, 0), "its process ended abruptly", batch)
        self._commit(batch)
        self._new_pool()

    # --- time limits and the cluster -----------------------------------------------------------

    def _clocks(self, now: float) -> list[tuple[float, Future, _Batch]]:
        """Batches in flight with the time their clock started (not on a local pool): a batch's clock
        starts when it is among the oldest ``workers`` batches in flight (cases wait behind the
        running ones)."""
        for position, batch in enumerate(self.in_flight.values()):  # in submission order
            if position >= self.workers:
                break
            if batch.started is None:
                batch.started = now
        return [(batch.started, future, batch) for future, batch in self.in_flight.items() if batch.started is not None]

    def _check_time(self) -> None:
        """Cases past the driver's limit (a worker stuck where the in-worker alarm cannot reach)."""
        if self.pool is not None:
            self._check_pool_time()
            return
        now = time.monotonic()
        late = [(future, batch) for start, future, batch in self._clocks(now)
                if now - start > self._chunk_limit(len(batch.keys))]
        batch_out: list = []
        for future, batch in late:
            self.in_flight.pop(future)
            future.cancel()
            if len(batch.keys) > 1:  # a chunk: its cases again, one by one, each with its own clock
                self.singles.extend(batch.keys)
                continue
            self._crash(batch.keys[0], f"timed out after {self.timeout:g} s (case_timeout_s); worker stopped", batch_out)
        self._commit(batch_out)

    def _check_pool_time(self) -> None:
        """On a local pool a case's clock starts when its worker starts it (the slot table): a late
        case is crashed, its worker stopped with the pool, and the other cases run again."""
        assert self.pool is not None
        now = time.monotonic()
        running = self.pool.running()
        late = [key for batch in self.in_flight.values() for key in batch.keys
                if self.cases[key].index in running and now - running[self.cases[key].index][1] > self.limit]
        if not late:
            return
        started = self.pool.started()
        self.pool.kill()
        batches = list(self.in_flight.values())
        self.in_flight.clear()
        self._requeue(batches, started, keep=set(late))
        batch_out: list = []
        for key in late:
            self._crash(key, f"timed out after {self.timeout:g} s (case_timeout_s); worker stopped", batch_out)
        self._commit(batch_out)
        self._new_pool()

    def _check_cluster(self) -> None:
        """A Dask cluster without workers: clocks wait, and after :data:`WORKER_WAIT_S` the sweep stops."""
        now = time.monotonic()
        if self.cluster is None or now < self.next_cluster_check:
            return
        self.next_cluster_check = now + 1.0
        if self.cluster.workers() > 0:  # the watch's last count (_WorkerWatch)
            self.no_workers_since = None
            return
        self.no_workers_since = self.no_workers_since or now
        for batch in self.in_flight.values():
            batch.started = None  # no case runs without a worker
        if now - self.no_workers_since > WORKER_WAIT_S:
            raise _ClusterLost(f"the Dask cluster has had no workers for {WORKER_WAIT_S:g} s")

    def run(self) -> None:
        try:
            while self.pending or self.suspects or self.in_flight:
                self._fill()
                done, _ = wait(list(self.in_flight), timeout=_POLL_S, return_when=FIRST_COMPLETED)
                self._collect(done)
                self._check_cluster()
                self._check_time()
                if self.progress is not None:
                    self.progress.poll()
        except BaseException:
            if self.pool is not None:
                # stopped before its end (Ctrl-C, an error): every worker now, also one the pool was
                # still starting (a Ctrl-C during its start left it out of the pool's processes; it
                # would start after the sweep and fail on the pool's queues, with a traceback)
                self.pool.kill()
                _stop_forkserver()
            raise
        else:
            if self.pool is not None:
                self.executor.shutdown(wait=True)
        finally:
            if self.progress is not None:
                self.progress.close()
            if self.pool is None:
                for future in self.in_flight:
                    future.cancel()


class _ClusterLost(Exception):
    """The Dask cluster stayed without workers."""


class _WorkerWatch:
    """A Dask cluster's worker threads, counted about every second in a thread of its own, so that
    the sweep's main thread never waits in a call to the cluster while it runs: a Ctrl-C that
    lands in the main thread while it waits for the scheduler's answer (``distributed.utils.sync``)
    makes Dask cancel a future it has not made yet, and tornado logs a ``NameError`` with its
    traceback into the output of the interrupted sweep.

    Parameters
    ----------
    cluster : DaskCluster
        The cluster to watch.
    """

    def __init__(self, cluster: DaskCluster):
        self.cluster = cluster
        self.counted = threading.Event()
        self.stopped = threading.Event()
        self.value = 0
        self.error: Exception | None = None
        self.thread = threading.Thread(target=self._watch, name="slewbench-dask-workers", daemon=True)
        self.thread.start()

    def _watch(self) -> None:
        while not self.stopped.is_set():
            try:
                self.value = self.cluster.workers()
            except Exception as error:  # noqa: BLE001 (given to the main thread, which raises it)
                self.error = error
                self.counted.set()
                return
            self.counted.set()
            self.stopped.wait(1.0)

    def workers(self) -> int:
        """The last count (waiting for the first one).

        Returns
        -------
        int
            The cluster's worker threads.

        Raises
        ------
        _ClusterLost
            The client closed (it could not reconnect to its scheduler).
        Exception
            What the count raised.
        """
        self.counted.wait()
        if self.cluster.client.status == "closed":
            raise _ClusterLost(_client_closed(self.cluster.address))
        if self.error is not None:
            raise self.error
        return self.value

    def close(self) -> None:
        """Stop counting (a count under way ends on its own)."""
        self.stopped.set()


def default_workers() -> int:
    """One worker per core available to this process.

    Returns
    -------
    int
        The number of cores this process may run on (at least 1).
    """
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def _reach(address: str, where: str) -> None:
    """Open and close a TCP connection to the scheduler's host and port within
    :data:`CONNECT_TIMEOUT_S`, or raise a :class:`ScenarioError` at ``where`` saying why not."""
    import socket

    from distributed.comm.addressing import parse_address, parse_host_port

    host, port = parse_host_port(parse_address(address)[1])
    none = f"no Dask scheduler answered at {address}"
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except socket.gaierror as error:
        raise ScenarioError(where, f"{none}: its host {excerpt(host)} does not resolve "
                                   f"({error.strerror or error}); is the name right?") from None
    except ConnectionRefusedError:
        raise ScenarioError(where, f"{none}: nothing listens there (connection refused); is one running "
                                   f"there, on that port?") from None
    except TimeoutError:
        raise ScenarioError(where, f"{none}: no connection within {CONNECT_TIMEOUT_S:g} s (the host is down "
                                   f"or unreachable, or a firewall drops it)") from None
    except OSError as error:
        raise ScenarioError(where, f"{none}: cannot connect "
                                   f"({excerpt(error.strerror or str(error), 200)})") from None


def reachable(address: str, where: str = "execution.scheduler") -> str:
    """Check that a Dask scheduler's address is well formed and that its host accepts a TCP
    connection there within :data:`CONNECT_TIMEOUT_S`: the quick part of :func:`connect_scheduler`,
    to refuse a closed port before a study's cases are checked.

    Parameters
    ----------
    address : str
        ``[scheme://]host:port`` (:func:`scenarios.schema.study.scheduler_address`).
    where : str, optional
        Where the address was given, for messages.

    Returns
    -------
    str
        The address with its scheme.

    Raises
    ------
    ScenarioError
        At ``where``: a malformed address, a host that does not resolve, a closed port, a host
        that does not answer.
    """
    address = scheduler_address(address, where)
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise ScenarioError(where, "a Dask scheduler needs the distributed package (pip install distributed)") from None
    _reach(address, where)
    return address


def _identity(address: str, timeout_s: float) -> dict[str, Any]:
    """Ask ``address`` who it is, over Dask's protocol, giving up after ``timeout_s``; runs in a
    thread of its own so that it works under a caller's running event loop."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    from distributed.comm import connect

    async def ask() -> Any:
        comm = await connect(address, timeout=timeout_s)
        try:
            await comm.write({"op": "identity"})
            return await comm.read()
        finally:
            comm.abort()

    def run() -> Any:
        return asyncio.run(asyncio.wait_for(ask(), timeout_s))

    pool = ThreadPoolExecutor(1, thread_name_prefix="slewbench-handshake")
    try:
        return pool.submit(run).result(timeout=timeout_s + 5.0)
    finally:
        pool.shutdown(wait=False)


def _drop(record: logging.LogRecord) -> bool:
    """A logging filter that passes nothing."""
    return False


class _ClusterExecutor(Executor):
    """A Dask client's tasks as ``concurrent.futures`` futures, as ``client.get_executor()`` gives
    them, but quiet when they are cancelled: Dask's executor sets the outcome of a task that
    finished (or was cancelled) while its future was being cancelled on that cancelled future, and
    tornado logs the ``InvalidStateError`` (or ``FutureCancelledError``) with its traceback, into
    the output of every interrupted sweep. Here a task's outcome goes to its future unless that
    future was cancelled, and cancelling the future cancels the task on the cluster."""

    def __init__(self, client: Any, address: str = ""):
        self.client, self.address = client, address

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future[Any]:
        if self.client.status == "closed":
            raise _ClusterLost(_client_closed(self.address))
        task = self.client.submit(fn, *args, **kwargs)
        future: Future[Any] = Future()

        def cancel_task(done: Future[Any]) -> None:
            # a closed client's tasks went with it (Dask raises ClosedClientError: the callback's
            # traceback would be logged into the sweep's output)
            if done.cancelled() and task.status == "pending" and self.client.status == "running":
                with contextlib.suppress(Exception):  # closed meanwhile: as above
                    task.cancel()

        future.add_done_callback(cancel_task)
        task.add_done_callback(lambda task: _settle(future, task))
        return future


def _client_closed(address: str) -> str:
    """Why a sweep stops whose Dask client closed."""
    return (f"lost the Dask scheduler at {address}: its client could not reconnect and closed; "
            f"restart the scheduler (and its workers) there")


def _settle(future: Future[Any], task: Any) -> None:
    """Give a finished Dask task's outcome to its future (in Dask's callback thread); a future that
    was cancelled meanwhile keeps nothing."""
    if future.cancelled():
        return
    try:
        if task.status == "cancelled":
            if future.cancel():
                future.set_running_or_notify_cancel()  # wakes a wait() on it
            return
        try:
            value = task.result()
        except BaseException as error:  # noqa: BLE001 (what the task raised, or the cluster's failure)
            future.set_exception(error)
        else:
            future.set_result(value)
    except InvalidStateError:  # cancelled while the outcome was fetched: nobody waits for it
        pass


@dataclass
class DaskCluster:
    """A Dask cluster the sweep connected to (:func:`connect_scheduler`), and a context manager
    that closes its client on leaving the block.

    Close the client before the cluster's scheduler stops (``with LocalCluster(...) as cluster,
    connect_scheduler(cluster.scheduler_address) as dask:`` closes ``dask`` first): a client whose
    scheduler went away tries to reconnect in the background and Dask logs ``Failed to reconnect
    to scheduler ...`` as an error.

    Parameters
    ----------
    address : str
        The scheduler's address.
    client : distributed.Client
        The client connected to it.
    """

    address: str
    client: Any

    @property
    def executor(self) -> Executor:
        """The client's tasks as a ``concurrent.futures`` executor (as ``client.get_executor()``,
        without Dask's log noise when its futures are cancelled)."""
        return _ClusterExecutor(self.client, self.address)

    def workers(self) -> int:
        """Worker threads the scheduler knows now.

        Returns
        -------
        int
            The sum of the workers' threads (0: no worker).
        """
        info = self.client.scheduler_info()
        return sum(int(worker.get("nthreads", 1)) for worker in info.get("workers", {}).values())

    def close(self) -> None:
        """Close the client (the cluster goes on); closing it again does nothing. A client whose
        scheduler already went away is closed without Dask's reconnection error in the log."""
        if self.client.status == "closed":
            return
        if self.client.status != "connecting":
            self.client.close()
            return
        # the scheduler is gone and the client is retrying it: its giving up is no news here (for
        # the moment of the close, the filter holds back any other client's records too)
        logger = logging.getLogger("distributed.client")
        logger.addFilter(_drop)
        try:
            self.client.close()
        finally:
            logger.removeFilter(_drop)

    def __enter__(self) -> DaskCluster:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def connect_scheduler(address: str, where: str = "execution.scheduler", wait_s: float | None = None) -> DaskCluster:
    """Connect to a Dask scheduler, or refuse at once: a malformed address, a host that does not
    resolve or accept a connection within :data:`CONNECT_TIMEOUT_S` (a closed port), an address
    that does not answer as a Dask scheduler within :data:`HANDSHAKE_TIMEOUT_S` (a web server),
    or a scheduler without workers after ``wait_s``.

    Parameters
    ----------
    address : str
        ``[scheme://]host:port`` (:func:`scenarios.schema.study.scheduler_address`).
    where : str, optional
        Where the address was given (``execution.scheduler`` or ``--scheduler``), for messages.
    wait_s : float or None, optional
        How long to wait for a first worker [s]; None: :data:`WORKER_WAIT_S`.

    Returns
    -------
    DaskCluster
        The connected client: close it with ``close()``, or connect in a ``with`` block.

    Raises
    ------
    ScenarioError
        At ``where``, saying what is wrong (exit status 2 on the command line; nothing written).
    """
    import distributed

    address = reachable(address, where)
    wait_s = WORKER_WAIT_S if wait_s is None else wait_s
    try:
        identity = _identity(address, HANDSHAKE_TIMEOUT_S)
    except (TimeoutError, OSError) as error:
        why = "no answer" if isinstance(error, TimeoutError) or "Timed out" in str(error) else excerpt(str(error), 200)
        raise ScenarioError(where, f"no Dask scheduler answered at {address} within {HANDSHAKE_TIMEOUT_S:g} s "
                                   f"({why}; something accepts connections there); is it the scheduler's port "
                                   f"(8786 by default; not its dashboard's)?") from None
    except MemoryError:  # Dask read another protocol's first bytes as the length of a frame
        raise ScenarioError(where, f"{address} answered, but not in Dask's protocol (another service listens "
                                   f"there); is it the scheduler's port (8786 by default)?") from None
    except Exception as error:  # anything that is not Dask's protocol
        raise ScenarioError(where, f"{address} did not answer as a Dask scheduler "
                                   f"({type(error).__name__}: {excerpt(str(error), 200)})") from None
    if not isinstance(identity, dict) or identity.get("type") != "Scheduler":
        raise ScenarioError(where, f"{address} answered, but not as a Dask scheduler ({excerpt(identity, 100)})")
    deadline = time.monotonic() + wait_s
    while not identity.get("workers") and time.monotonic() < deadline:
        time.sleep(min(1.0, max(0.0, deadline - time.monotonic())))
        identity = _identity(address, HANDSHAKE_TIMEOUT_S)
    if not identity.get("workers"):
        raise ScenarioError(where, f"the Dask scheduler at {address} has no workers (waited {wait_s:g} s); start "
                                   f"some with `dask worker {address} --nthreads 1`")
    try:
        client = distributed.Client(address, timeout=f"{HANDSHAKE_TIMEOUT_S}s")
    except (OSError, TimeoutError) as error:
        raise ScenarioError(where, f"cannot connect to the Dask scheduler at {address}: "
                                   f"{excerpt(str(error), 200)}") from None
    return DaskCluster(address, client)


def dask_executor(address: str) -> tuple[Executor, int, Callable[[], None]]:
    """A Dask cluster's executor (:func:`connect_scheduler`).

    Parameters
    ----------
    address : str
        The scheduler's address, for example ``tcp://127.0.0.1:8786``.

    Returns
    -------
    executor : concurrent.futures.Executor
        The client's executor.
    threads : int
        Worker threads of the cluster (cases run at once).
    close : callable
        Closes the client.

    Raises
    ------
    ScenarioError
        As :func:`connect_scheduler`.
    """
    cluster = connect_scheduler(address)
    return cluster.executor, max(cluster.workers(), 1), cluster.close


def _check_arguments(study: Any, executor: Any, workers: Any, store: Any, progress: Any, task: Any,
                     cluster: Any) -> None:
    if not isinstance(study, (Study, dict, str, os.PathLike)):
        raise TypeError(f"study must be a Study, a study mapping or a path, got {type(study).__name__}")
    if executor is not None and not isinstance(executor, Executor):
        raise TypeError(f"executor must be a concurrent.futures.Executor or None, got {type(executor).__name__}")
    if workers is not None and (not isinstance(workers, int) or isinstance(workers, bool)
                                or not 1 <= workers <= MAX_WORKERS):
        raise ValueError(f"workers must be an integer from 1 to {MAX_WORKERS} or None, got {excerpt(workers)}")
    if store is not None and not isinstance(store, SweepStore):
        raise TypeError(f"store must be a SweepStore or None, got {type(store).__name__}")
    if not isinstance(progress, bool):
        raise TypeError(f"progress must be True or False, got {excerpt(progress)}")
    if not callable(task):
        raise TypeError(f"task must be a callable (payload dict -> result dict), got {excerpt(task)}")
    if cluster is not None and not isinstance(cluster, DaskCluster):
        raise TypeError(f"cluster must be a DaskCluster or None, got {type(cluster).__name__}")


def sweep(study: Study | dict[str, Any] | str | os.PathLike[str], executor: Executor | None = None, *,
          workers: int | None = None, store: SweepStore | None = None, progress: bool = False,
          task: Callable[[dict[str, Any]], dict[str, Any]] = run_case, cluster: DaskCluster | None = None,
          timeouts_apart: bool = False) -> SweepResults:
    """Run every case of a trade study.

    Parameters
    ----------
    study : Study, dict, str or os.PathLike
        A :class:`Study`, a study mapping, or the path of a study file.
    executor : concurrent.futures.Executor or None, optional
        Any executor (a Dask client's ``get_executor()``, a process pool); None: a local process
        pool with ``workers`` processes, or the Dask cluster ``cluster``, or the one named by the
        study's ``execution.scheduler`` (:func:`connect_scheduler`).
    workers : int or None, optional
        Cases run at once, 1 to 1024 (None: the study's ``execution.workers``, else one per core;
        on Dask, the cluster's worker threads).
    store : SweepStore or None, optional
        Where finished cases are committed; None: memory only. A case stored there is skipped, but
        a ``crashed`` one (it raised, ran out of time or killed its worker: an outcome of the
        execution, not of the physics) runs again and its record is replaced; its ``attempts``
        go on counting. Stored cases that are not the study's are left alone and out of the
        results (:func:`scenarios.study.store.resume_counts` counts them).
    progress : bool, optional
        Show the progress on stderr: a bar on a terminal, else a line at most every
        :data:`PROGRESS_LINE_S` and one at the end.
    task : callable, optional
        The worker function, payload dict -> result dict (:func:`scenarios.study.worker.run_case`;
        tests replace it). On a local pool it must be importable by the worker processes.
    cluster : DaskCluster or None, optional
        A Dask cluster already connected (:func:`connect_scheduler`; the command line connects
        before it writes anything); this call does not close it.
    timeouts_apart : bool, optional
        The progress says the crashed cases that ran out of ``case_timeout_s`` apart (``2 not ok
        (1 crashed, 1 timed out)``), for a caller that gives them their own status (a slew
        table's ``timed_out``); default: all ``crashed``, as their rows are.

    Returns
    -------
    SweepResults
        Every case's record; :meth:`SweepResults.to_dataframe` gives the ``cases.csv`` table.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C (or SIGTERM turned into KeyboardInterrupt), or a Dask cluster left without
        workers for :data:`WORKER_WAIT_S`: committed cases stay in the store.
    ScenarioError
        A bad study, or a scheduler that cannot be used (:func:`connect_scheduler`).
    WorkersCannotStart
        The local workers died while they started, before any case (a script calling this
        function outside ``if __name__ == "__main__":``: the message says so).
    TypeError, ValueError
        An argument of the wrong type or out of range, named in the message.
    """
    _check_arguments(study, executor, workers, store, progress, task, cluster)
    if isinstance(study, (str, os.PathLike)):
        study = load_study(study)
    elif isinstance(study, dict):
        study = parse_study(study)
    own = None
    if executor is None and cluster is None and study.execution.scheduler:
        cluster = own = connect_scheduler(study.execution.scheduler)
    watch = _WorkerWatch(cluster) if cluster is not None else None
    try:
        if executor is None and watch is not None:
            executor = cluster.executor  # type: ignore[union-attr]
            workers = workers or max(watch.workers(), 1)
        workers = workers or study.execution.workers or default_workers()
        engine = _Engine(study, executor, workers, store, progress, task, watch, timeouts_apart)
        try:
            engine.run()
        except KeyboardInterrupt:
            results = SweepResults(study, engine.records, engine.worker_builds, engine.cpu_s, engine.worker_cpu_s)
            raise SweepInterrupted(results.missing, len(study.cases)) from None
        except _ClusterLost as lost:
            results = SweepResults(study, engine.records, engine.worker_builds, engine.cpu_s, engine.worker_cpu_s)
            raise SweepInterrupted(results.missing, len(study.cases), str(lost)) from None
    finally:
        if watch is not None:
            watch.close()
        if own is not None:
            own.close()
    return SweepResults(study, engine.records, engine.worker_builds, engine.cpu_s, engine.worker_cpu_s)
