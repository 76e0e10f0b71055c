"""Run a trade study: every case on a local process pool (default), any
``concurrent.futures.Executor`` (a Dask client's ``get_executor()``, for one), or a Dask cluster
by address; finished cases go to the crash-safe store as they arrive.

A case that raises or exceeds ``case_timeout_s`` is a ``crashed`` row and the sweep goes on. A
case whose worker died is retried ``retries`` times; when several cases were running on a local
pool that broke, each is re-run alone so that only the one that kills its worker is charged.
"""
from __future__ import annotations

import collections
import multiprocessing
import os
import sys
import time
from concurrent.futures import (
    FIRST_COMPLETED,
    Executor,
    Future,
    ProcessPoolExecutor,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from scenarios.errors import SweepInterrupted
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import SweepStore
from scenarios.study.types import Case, Study
from scenarios.study.worker import PRELOAD, crashed_rows, run_case

if TYPE_CHECKING:
    import pandas

_POLL_S = 0.5
_TIMEOUT_GRACE = 1.25  # the driver gives up on a case at this multiple of case_timeout_s (+ 5 s)


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
        those found in the store.
    workers : dict
        Worker (``host:pid``) -> solvers it built, for the workers of this call.
    cpu_s : dict
        Case key -> CPU time of the case in its worker [s], for the cases run by this call (not
        stored).
    worker_cpu_s : dict
        Worker (``host:pid``) -> CPU time of its process from its start to its last case [s]
        (start-up and imports included; not stored).
    """

    study: Study
    records: dict[str, dict[str, Any]]
    workers: dict[str, int] = field(default_factory=dict)
    cpu_s: dict[str, float] = field(default_factory=dict)
    worker_cpu_s: dict[str, float] = field(default_factory=dict)

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

    def write(self, directory: str | Path, plots: bool = True) -> list[str]:
        """Write cases.csv, summary.csv, summary.md, study.yaml and plots.

        Parameters
        ----------
        directory : str or Path
            The output directory (claimed for slewbench; only files it listed are replaced).
        plots : bool, optional
            Also draw the PNG figures.

        Returns
        -------
        list of str
            The file names written (relative to ``directory``).
        """
        from scenarios.study.report import write_report
        return write_report(self, Path(directory), plots=plots)


def start_forkserver() -> multiprocessing.context.BaseContext:
    """Start (once per process) the server that local workers fork from, importing :data:`PRELOAD`.

    It returns at once: the server imports while the caller goes on (the CLI calls this before it
    expands the study), and the first worker waits until the imports are done.

    Returns
    -------
    multiprocessing.context.BaseContext
        The ``forkserver`` context that local pools use.
    """
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(list(PRELOAD))
    from multiprocessing import forkserver
    forkserver.ensure_running()
    return context


def _local_pool(workers: int) -> ProcessPoolExecutor:
    """Worker processes forked from a server that has imported the workbench once."""
    return ProcessPoolExecutor(max_workers=workers, mp_context=start_forkserver())


def _kill_pool(pool: Executor) -> None:
    """Stop a local pool now, including a worker stuck in C code (it cannot be interrupted)."""
    for process in list(getattr(pool, "_processes", {}).values()):  # private, stable since 3.8
        if process.is_alive():
            process.kill()
    pool.shutdown(wait=False, cancel_futures=True)


class _Engine:
    """The submit / collect loop; see the module docstring for the failure rules."""

    def __init__(self, study: Study, executor: Executor | None, workers: int, store: SweepStore | None,
                 progress: bool, task: Callable[[dict[str, Any]], dict[str, Any]]):
        self.study, self.store, self.task = study, store, task
        self.owned = executor is None
        self.workers = workers
        # a local pool gets one case ahead of its workers, so that none idles while the driver stores a
        # result; other executors get one case per worker, so that a case's clock starts when it runs
        self.window = workers + 1 if self.owned else workers
        self.executor: Executor = _local_pool(workers) if executor is None else executor
        self.timeout = study.execution.case_timeout_s
        self.records: dict[str, dict[str, Any]] = dict(store.records()) if store is not None else {}
        self.cases: dict[str, Case] = {}
        for case in study.cases:
            if case.key not in self.records:
                self.cases.setdefault(case.key, case)
        self.pending = collections.deque(self.cases)
        self.suspects: collections.deque[str] = collections.deque()
        self.in_flight: dict[Future, tuple[str, float]] = {}
        self.attempts: dict[str, int] = collections.Counter()
        self.worker_builds: dict[str, int] = {}
        self.cpu_s: dict[str, float] = {}
        self.worker_cpu_s: dict[str, float] = {}
        self.failures = 0
        self.bar = None
        if progress:
            from tqdm import tqdm
            self.bar = tqdm(total=len(self.cases), unit="case", desc=study.name, dynamic_ncols=True,
                            disable=not sys.stderr.isatty(), file=sys.stderr)
            if not self.bar.disable and not (self.bar.ncols or 0) > 0:  # a terminal reporting no size (0 x 0):
                self.bar.dynamic_ncols, self.bar.ncols, self.bar.nrows = False, 80, None  # tqdm would draw nothing

    def _submit(self, key: str) -> None:
        payload = {"key": key, "scenario": self.cases[key].scenario, "timeout_s": self.timeout}
        self.in_flight[self.executor.submit(self.task, payload)] = (key, time.monotonic())

    def _finish(self, key: str, status: str, rows: list[dict[str, Any]], elapsed: float | None,
                attempts: int | None = None) -> None:
        attempts = self.attempts[key] + 1 if attempts is None else attempts
        record = {"status": status, "rows": rows, "elapsed_s": elapsed, "attempts": attempts}
        if self.store is not None:
            self.store.put(key, status, rows, elapsed, attempts)
        self.records[key] = record
        self.failures += any(row["status"] != "ok" for row in rows)
        if self.bar is not None:
            self.bar.set_postfix(failures=self.failures, refresh=False)
            self.bar.update(1)

    def _died(self, keys: list[str], why: str) -> None:
        """Cases whose worker died: one alone is charged an attempt; several are re-run alone."""
        if len(keys) > 1 and self.owned:
            self.suspects.extend(keys)
            return
        for key in keys:
            self.attempts[key] += 1
            if self.attempts[key] > self.study.execution.retries:
                self._finish(key, "crashed", crashed_rows(
                    self.cases[key].scenario, f"worker died ({why}); {self.attempts[key]} attempt(s)"),
                    None, self.attempts[key])
            elif self.owned:
                self.suspects.append(key)
            else:
                self.pending.appendleft(key)

    def _restart_pool(self) -> list[str]:
        """Replace a broken or stuck local pool; returns the keys that were running on it."""
        keys = [key for key, _ in self.in_flight.values()]
        self.in_flight.clear()
        _kill_pool(self.executor)
        self.executor = _local_pool(self.workers)
        return keys

    def _fill(self) -> None:
        if self.suspects:
            if not self.in_flight:
                self._submit(self.suspects.popleft())
            return
        while self.pending and len(self.in_flight) < self.window:
            self._submit(self.pending.popleft())

    def _collect(self, done: set[Future]) -> None:
        broken: list[str] = []
        for future in done:
            key, _ = self.in_flight.pop(future)
            try:
                result = future.result()
            except BrokenProcessPool as error:
                if self.owned:
                    broken.append(key)
                else:  # a pool the caller owns: it cannot be restarted from here
                    self._died([key], f"{type(error).__name__}: {error}"[:300])
                continue
            except Exception as error:  # a lost worker on a cluster (dask's KilledWorker, ...)
                self._died([key], f"{type(error).__name__}: {error}"[:300])
                continue
            self.worker_builds[result["worker"]] = result["cache_builds"]
            self._finish(key, result["status"], result["rows"], result["elapsed_s"])
            if result.get("cpu_s") is not None:
                self.cpu_s[key] = result["cpu_s"]
                self.worker_cpu_s[result["worker"]] = max(result["worker_cpu_s"],
                                                          self.worker_cpu_s.get(result["worker"], 0.0))
        if broken:
            self._died(broken + self._restart_pool(), "its process ended abruptly")

    def _check_time(self) -> None:
        """Cases past the driver's limit (a worker stuck where the in-worker alarm cannot reach).
        On a local pool only the oldest is charged (the others may have waited behind it); the
        pool is restarted and the others run again."""
        limit = self.timeout * _TIMEOUT_GRACE + 5.0
        now = time.monotonic()
        late = sorted(((start, key, future) for future, (key, start) in self.in_flight.items()
                       if now - start > limit), key=lambda item: item[0])
        for _, key, future in late[:1] if self.owned else late:
            self.in_flight.pop(future)
            future.cancel()
            self._finish(key, "crashed", crashed_rows(
                self.cases[key].scenario, f"timed out after {self.timeout:g} s (case_timeout_s); worker stopped"), None)
        if late and self.owned:
            self.pending.extendleft(reversed(self._restart_pool()))

    def run(self) -> None:
        try:
            while self.pending or self.suspects or self.in_flight:
                self._fill()
                done, _ = wait(list(self.in_flight), timeout=_POLL_S, return_when=FIRST_COMPLETED)
                self._collect(done)
                self._check_time()
        finally:
            if self.bar is not None:
                self.bar.close()
            if self.owned:
                if self.in_flight:
                    _kill_pool(self.executor)
                else:
                    self.executor.shutdown(wait=True)
            else:
                for future in self.in_flight:
                    future.cancel()


def default_workers() -> int:
    """One worker per core available to this process.

    Returns
    -------
    int
        The number of cores this process may run on (at least 1).
    """
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def dask_executor(address: str) -> tuple[Executor, int, Callable[[], None]]:
    """A Dask cluster's executor.

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
        The scheduler cannot be reached (``execution.scheduler``).
    """
    from distributed import Client
    try:
        client = Client(address, timeout="20s")
    except OSError as error:
        from scenarios.errors import ScenarioError
        raise ScenarioError("execution.scheduler", f"cannot reach the Dask scheduler at {address}: {error}") from None
    threads = sum(client.nthreads().values()) or 1
    return client.get_executor(), threads, client.close


def sweep(study: Study | dict[str, Any] | str | Path, executor: Executor | None = None, *,
          workers: int | None = None, store: SweepStore | None = None, progress: bool = False,
          task: Callable[[dict[str, Any]], dict[str, Any]] = run_case) -> SweepResults:
    """Run every case of a trade study.

    Parameters
    ----------
    study : Study, dict, str or Path
        A :class:`Study`, a study mapping, or the path of a study file.
    executor : concurrent.futures.Executor or None, optional
        Any executor (a Dask client's ``get_executor()``, a process pool); None: a local process
        pool with ``workers`` processes, or the Dask cluster named by the study's
        ``execution.scheduler``.
    workers : int or None, optional
        Cases run at once (None: the study's ``execution.workers``, else one per core).
    store : SweepStore or None, optional
        Where finished cases are committed (and skipped when already there); None: memory only.
    progress : bool, optional
        Show a progress bar (only when stderr is a terminal).
    task : callable, optional
        The worker function, payload dict -> result dict (:func:`scenarios.study.worker.run_case`;
        tests replace it).

    Returns
    -------
    SweepResults
        Every case's record; :meth:`SweepResults.to_dataframe` gives the ``cases.csv`` table.

    Raises
    ------
    SweepInterrupted
        On Ctrl-C (or SIGTERM turned into KeyboardInterrupt): committed cases stay in the store.
    """
    if isinstance(study, (str, Path)):
        study = load_study(study)
    elif isinstance(study, dict):
        study = parse_study(study)
    close = None
    if executor is None and study.execution.scheduler:
        executor, threads, close = dask_executor(study.execution.scheduler)
        workers = workers or threads
    workers = workers or study.execution.workers or default_workers()
    engine = _Engine(study, executor, workers, store, progress, task)
    try:
        engine.run()
    except KeyboardInterrupt:
        results = SweepResults(study, engine.records, engine.worker_builds, engine.cpu_s, engine.worker_cpu_s)
        raise SweepInterrupted(results.missing, len(study.cases)) from None
    finally:
        if close is not None:
            close()
    return SweepResults(study, engine.records, engine.worker_builds, engine.cpu_s, engine.worker_cpu_s)
