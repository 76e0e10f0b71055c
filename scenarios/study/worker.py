"""What a trade-study worker runs: one resolved case in, plain rows out.

A worker receives plain data (the case's scenario mapping, parsed here with
:func:`scenarios.parse_scenario`), never CasADi objects, and returns a dict of plain values. Each
worker process keeps one :class:`ocp.SolverCache` for its whole life, so a collocation NLP is
built once per worker thread and structure (a cache keeps each thread's builds apart); a
process-wide lock runs one case at a time per process (IPOPT's linear solvers are not
thread-safe), so a Dask worker should be started with ``--nthreads 1`` and as many processes as
cores.

Cases come several to a task (:func:`run_chunk`), each encoding its rows as the store keeps them.
In a local pool's worker each case is tracked (:func:`tracked_case`): the worker writes the case it
runs and when it started it into a slot table shared with the sweep, which so knows whose case
killed a worker and how long a case has run. The local workers, and the server they fork from, die
with the sweep (:func:`start_local_worker`, :data:`PARENT_ENVIRONMENT`).
"""
from __future__ import annotations

import errno
import functools
import os
import signal
import socket
import threading
import time
import traceback
from collections.abc import Callable
from typing import Any

from ocp import SolverCache
from ocp.cache import RecentCache
from scenarios.errors import CaseTimeout
from scenarios.output.renderer import die_with_parent
from scenarios.output.results import Row
from scenarios.schema.labels import row_labels
from scenarios.study.store import encode_rows

PRELOAD = ("scenarios.study.server", "scenarios.study.worker", "scenarios.runner", "scipy.integrate", "scipy.optimize",
           "scipy.special")
"""Modules imported once by the process that local workers fork from: first
:mod:`scenarios.study.server` (the current directory off its import path), then the workbench, and
the SciPy modules that planners import lazily on their first case (about 0.6 s that every fresh
worker would otherwise pay; with 40 cases of 0.13 s that alone was a 12 % overhead)."""

PARENT_ENVIRONMENT = "SLEWBENCH_SWEEP_PARENT"
"""Environment variable holding the process id of a sweep that starts local workers
(:func:`scenarios.study.engine.start_forkserver` sets it): a direct child of that process which
imports this module (the server local workers fork from) dies with it."""


def _ignore_interrupt(signum: int, frame: Any) -> None:
    """Ctrl-C in the fork server and its workers: nothing (the sweep stops them itself)."""


_forker: dict[str, int] = {}  # the process id of the process forking now (in the fork server's family)


def _before_fork() -> None:
    _forker["pid"] = os.getpid()


def _die_with_server(server: int) -> None:
    """In a process just forked: if the fork server ``server`` forked it (a worker), die with the
    server from now on (a process a worker forks is left alone)."""
    if _forker.get("pid") == server:
        die_with_parent(signal.SIGKILL, server)


if os.environ.get(PARENT_ENVIRONMENT) == str(os.getppid()):  # the fork server of a sweep: dies with it
    die_with_parent(signal.SIGKILL, os.getppid())
    # every worker dies with the server from its fork on, also one still starting (its own
    # scenarios.study.worker.start_local_worker has not run yet), so that killing the server
    # (scenarios.study.engine._stop_forkserver) stops every worker, silently
    os.register_at_fork(before=_before_fork, after_in_child=functools.partial(_die_with_server, os.getpid()))
    # started with Ctrl-C blocked (scenarios.study.engine._sigint_blocked): caught and ignored from
    # now on, here and in the workers (the sweep stops them), a pending one included, then unblocked.
    # Caught, not SIG_IGN: a process that a worker starts (the C compiler of ocp.simulation.compiled)
    # takes Ctrl-C's default action again (an ignored signal stays ignored across exec)
    signal.signal(signal.SIGINT, _ignore_interrupt)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

SLOT_FIELDS = 4
"""Numbers per worker in a local pool's slot table: the worker's process id, the index + 1 of the
case it runs (0: none), when it started it (``time.monotonic()``, the same clock in every process
of the machine) and the index + 1 of the last case it finished."""

_slot: dict[str, Any] = {}  # this local worker's slot table and its place in it


def start_local_worker(slots: Any, lock: Any, parent: int) -> None:
    """Initialise a worker of a local pool: die with the process that forked it, and claim a slot.

    The fork server dies with the sweep (:data:`PARENT_ENVIRONMENT`) and its workers with it, so a
    sweep killed outright leaves no process behind. The slot tells the sweep which case each
    worker was running when one died (:func:`tracked_case`).

    Parameters
    ----------
    slots : multiprocessing.Array
        The pool's slot table, :data:`SLOT_FIELDS` doubles per worker (shared memory).
    lock : multiprocessing.Lock
        Guards the claiming of slots.
    parent : int
        The process id of the fork server the worker was started from (not positive: unknown, this
        process's parent now).
    """
    die_with_parent(signal.SIGKILL, parent if parent > 0 else os.getppid())
    with lock:
        for index in range(len(slots) // SLOT_FIELDS):
            if slots[index * SLOT_FIELDS] == 0:
                slots[index * SLOT_FIELDS] = os.getpid()
                _slot.update(table=slots, index=index)
                return


def tracked_case(task: Callable[[dict[str, Any]], dict[str, Any]], payload: dict[str, Any]) -> dict[str, Any]:
    """Run ``task(payload)`` in a local worker, its case and start time written in the worker's slot.

    Parameters
    ----------
    task : callable
        The worker function (:func:`run_case`).
    payload : dict
        Its argument; ``payload["index"]`` is the case's index.

    Returns
    -------
    dict
        What ``task`` returns.
    """
    table, index = _slot.get("table"), _slot.get("index", 0)
    if table is None:
        return task(payload)
    at = index * SLOT_FIELDS
    table[at + 2] = time.monotonic()
    table[at + 1] = payload["index"] + 1
    try:
        return task(payload)
    finally:
        table[at + 3] = payload["index"] + 1
        table[at + 1] = 0


def run_chunk(task: Callable[[dict[str, Any]], dict[str, Any]], payloads: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Run several cases in one task, one after the other, each tracked (:func:`tracked_case`: in a
    local pool's worker, its slot names the case running).

    Parameters
    ----------
    task : callable
        The worker function (:func:`run_case`).
    payloads : list of dict
        Its arguments, one per case.

    Returns
    -------
    list of dict
        What ``task`` returns for each, in order, its ``rows`` as the store's JSON text under
        ``rows_json`` (:func:`scenarios.study.store.encode_rows`).
    """
    results = []
    for payload in payloads:
        try:
            result = dict(tracked_case(task, payload))
        except Exception as error:
            text = f"{type(error).__name__}: {error}"
            text = text if len(text) <= 1000 else f"{text[:1000]}... (cut)"
            raise (WorkerFault if worker_fault(error) else TaskRaised)(text, payload.get("key")) from None
        result["rows_json"] = encode_rows(result.pop("rows"))  # the store's text, made here in parallel
        results.append(result)
    return results


class TaskRaised(RuntimeError):
    """What a case's task raised, carried out of the worker as its type's name and text.

    An exception leaves a worker process pickled; one that cannot be rebuilt from its pickle (a
    task's own class whose constructor takes other arguments than its ``args``) would break a local
    pool's result thread, and the pool would be started again for the same case without end. This
    class always pickles, and tells the sweep that the task raised (a deterministic outcome: the
    case is ``crashed`` at once, not run again as after a worker's death).

    Parameters
    ----------
    text : str
        ``"TYPE: TEXT"`` of the exception the task raised (cut at 1000 characters).
    key : str or None
        The key of the case whose task raised (of the several a chunk runs), if known.
    """

    def __init__(self, text: str, key: str | None = None) -> None:
        super().__init__(text, key)  # both in args: the pickle rebuilds them
        self.text, self.key = text, key

    def __str__(self) -> str:
        return self.text


class WorkerFault(TaskRaised):
    """What a case's task raised where the worker, not the case, failed (:func:`worker_fault`): the
    case runs again, as after a worker's death, up to ``execution.retries`` times.

    Parameters
    ----------
    text : str
        ``"TYPE: TEXT"`` of the exception the task raised (cut at 1000 characters).
    key : str or None
        The key of the case whose task raised, if known.
    """


RESOURCE_ERRNOS = frozenset({errno.ENOMEM, errno.ENOSPC, errno.EMFILE, errno.ENFILE, errno.EAGAIN})
"""``OSError`` numbers of a worker's exhausted resources (memory, disk, file handles, processes)."""


def worker_fault(error: BaseException) -> bool:
    """Whether an exception a case's task raised says that its worker failed it rather than the case
    itself: a ``MemoryError`` (the worker's memory, which another attempt, or another worker, may
    have), an ``ImportError`` (a module missing on one worker of a mixed cluster) or an ``OSError``
    of an exhausted resource (:data:`RESOURCE_ERRNOS`). Any other exception is the case's outcome.

    Parameters
    ----------
    error : BaseException
        What the task raised.

    Returns
    -------
    bool
    """
    return isinstance(error, (MemoryError, ImportError)) or (
        isinstance(error, OSError) and error.errno in RESOURCE_ERRNOS)


_PLUGINS_LOADED = False
"""Whether this worker process has loaded the plugins (:func:`scenarios.schema.plugins.load_plugins`,
once per process: its scan of the entry points costs about 2 ms)."""


def _plugins_loaded() -> None:
    global _PLUGINS_LOADED
    _PLUGINS_LOADED = True


@functools.cache
def worker_state() -> tuple[SolverCache, RecentCache, threading.Lock, RecentCache]:
    """This process's caches and case lock (created on first use, kept for its life).

    Returns
    -------
    cache : SolverCache
        The planners' builds (NLPs), kept across cases.
    simulators : RecentCache
        The last simulators built (:func:`scenarios.runner.run`'s ``simulators``).
    lock : threading.Lock
        Held while a case runs, so that a process runs one case at a time.
    references : RecentCache
        The last successful references planned (:func:`scenarios.runner.run`'s ``references``):
        a case whose planner and design problem are an earlier case's, run by the same thread,
        reuses its reference. Like every :class:`~ocp.SolverCache`, the three caches keep each
        thread's entries apart: a worker plans a reference, and builds a solver or simulator, once
        per thread that meets it (once per worker started with ``--nthreads 1``).
    """
    return SolverCache(), RecentCache(), threading.Lock(), RecentCache(size=8)


def _labels(entries: list[Any]) -> list[str]:
    """The labels of planner or controller mappings (a label defaults to the name, as the schema says)."""
    return [str(entry.get("label", entry.get("name"))) for entry in entries]


def crashed_rows(scenario: dict[str, Any], message: str) -> list[dict[str, Any]]:
    """One ``crashed`` row per row the runner makes for ``scenario``, carrying ``message``.

    The rows are labelled as the runner labels them (:func:`scenarios.schema.labels.row_labels`),
    from the scenario's mapping: the case may have crashed before or while it was parsed.

    Parameters
    ----------
    scenario : dict
        The case's scenario mapping (plain YAML data, checked when the study was expanded).
    message : str
        Why the case crashed.

    Returns
    -------
    list of dict
        Plain rows (:meth:`scenarios.output.results.Row.to_dict`, status ``crashed``, no metrics).
    """
    planners = scenario.get("planners") or []
    controllers = scenario.get("controllers") or [scenario.get("controller") or {}]
    return [Row(label, None if i is None else planners[i].get("name"), "crashed", message, None, None, None,
                controller=controllers[j].get("name")).to_dict()
            for label, i, j in row_labels(_labels(planners), _labels(controllers))]


def _on_alarm(signum: int, frame: Any) -> None:
    raise CaseTimeout


def timed_out_message(timeout_s: float) -> str:
    """The message of a case's ``crashed`` rows when it ran out of time (its record keeps how long it ran).

    Parameters
    ----------
    timeout_s : float
        The study's ``case_timeout_s`` [s].

    Returns
    -------
    str
        ``timed out after <limit> s (case_timeout_s)``.
    """
    return f"timed out after {timeout_s:g} s (case_timeout_s)"


def run_case(payload: dict[str, Any]) -> dict[str, Any]:
    """Run one case.

    The time limit is kept twice. Where a signal can be used (the main thread of a local worker), an
    alarm raises :class:`~scenarios.errors.CaseTimeout` when the limit is reached; it derives from
    :class:`BaseException`, so that no handler of the code run catches it. And a case whose
    measured time exceeds the limit is a timed-out ``crashed`` case whatever it returned: a case in
    a thread (a Dask worker's), where there is no alarm, or one whose C code swallowed the alarm's
    exception (a CasADi call it interrupted failed with CasADi's own ``NotImplementedError``).
    Ctrl-C (:class:`KeyboardInterrupt`) is not caught: it stops the worker.

    Parameters
    ----------
    payload : dict
        ``{"key": str, "scenario": mapping, "timeout_s": float}``: the case key, its resolved
        scenario (plain data) and its time limit [s].

    Returns
    -------
    dict
        ``key``, ``status`` (``ok``: the runner finished within the time limit, whatever its rows
        say; ``crashed``: the case raised or ran out of time), ``rows``
        (:meth:`scenarios.output.results.Row.to_dict` of each row), ``elapsed_s`` (wall time [s]),
        ``cpu_s`` (CPU time of the case [s]), ``worker_cpu_s`` (CPU time of the worker process
        since it started [s]), ``worker`` (host:pid) and ``cache_builds`` (solvers built by this
        worker so far).
    """
    from scenarios.runner import run
    from scenarios.schema.loader import parse_scenario
    from scenarios.schema.plugins import load_plugins

    cache, simulators, lock, references = worker_state()
    data, timeout = payload["scenario"], float(payload["timeout_s"])
    alarm = threading.current_thread() is threading.main_thread() and hasattr(signal, "setitimer")
    timed_out = False
    with lock:
        start, cpu_start = time.perf_counter(), time.process_time()
        previous = signal.signal(signal.SIGALRM, _on_alarm) if alarm else None
        try:
            try:
                if alarm:
                    signal.setitimer(signal.ITIMER_REAL, timeout)
                if not _PLUGINS_LOADED:  # a fork server's worker does not inherit the parent's registries
                    load_plugins()
                    _plugins_loaded()
                scenario = parse_scenario(data, inapplicable_rows=True)  # a planner the case does not suit: failed rows
                results = run(scenario, cache=cache, simulators=simulators, references=references)
                status, rows = "ok", [row.to_dict() for row in results.rows]
            finally:  # disarmed first: an alarm due now is raised here, inside the outer try
                if alarm:
                    signal.setitimer(signal.ITIMER_REAL, 0.0)
        except CaseTimeout:
            timed_out = True
        except Exception as error:  # a case that raises is a row, the sweep goes on
            detail = traceback.format_exc(limit=-3).strip().splitlines()
            where = next((line.strip() for line in reversed(detail) if line.strip().startswith("File")), "")
            status, rows = "crashed", crashed_rows(data, f"{type(error).__name__}: {error} ({where})"[:1000])
        finally:
            if alarm:
                signal.signal(signal.SIGALRM, previous)
        elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu_start
        if timed_out or elapsed > timeout:  # out of time, whether or not the alarm's exception got through
            status, rows = "crashed", crashed_rows(data, timed_out_message(timeout))
            references.clear()  # a plan the alarm cut short is not to be reused (none should be kept)
    return {"key": payload["key"], "status": status, "rows": rows, "elapsed_s": elapsed, "cpu_s": cpu,
            "worker_cpu_s": time.process_time(),
            "worker": f"{socket.gethostname()}:{os.getpid()}", "cache_builds": cache.builds}
