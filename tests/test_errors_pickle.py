"""Every exception class of slewbench survives :mod:`pickle` and :mod:`copy` with its class, text,
``args`` and attributes: a sweep's worker (a local process pool, a Dask worker) sends an exception
its task raises back to the sweep by pickling it.

The classes are found, not listed: every module of ``ocp``, ``planners``, ``controllers`` and
``scenarios`` is imported and every subclass of :class:`BaseException` defined there is checked (a
new exception class is covered without editing this file). Each is built from its constructor's
signature (a sample value per parameter, from its annotation).

Before the fix (an ``__init__`` whose parameters are not the exception's ``args``), unpickling
called ``ScenarioError(text)``, a ``TypeError``; in a local sweep whose task raised one, the pool's
manager thread could not read the result, the pool broke, and the sweep started new pools for the
same case without end (it hung).
"""
from __future__ import annotations

import copy
import importlib
import inspect
import os
import pickle
import pkgutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from ocp.errors import SlewbenchError
from scenarios.errors import ScenarioError

PACKAGES = ("ocp", "planners", "controllers", "scenarios")
ROOT = Path(__file__).resolve().parents[1]


def _import_everything() -> None:
    for name in PACKAGES:
        package = importlib.import_module(name)
        for module in pkgutil.walk_packages(package.__path__, f"{name}."):
            if module.name.rsplit(".", 1)[-1] != "__main__":  # runs the command line
                importlib.import_module(module.name)


def _subclasses(cls: type) -> list[type]:
    found = []
    for sub in cls.__subclasses__():
        found += [sub, *_subclasses(sub)]
    return found


def _ours(cls: type) -> bool:
    return cls.__module__.split(".")[0] in PACKAGES


_import_everything()
SLEWBENCH_ERRORS = sorted({SlewbenchError, *_subclasses(SlewbenchError)}, key=lambda c: f"{c.__module__}.{c.__qualname__}")
OTHERS = sorted({cls for cls in _subclasses(BaseException) if _ours(cls) and cls not in SLEWBENCH_ERRORS
                 # private ones are raised and caught within one call (scenarios.runner._NotKept carries a
                 # Reference out of a cache's build): never sent to another process
                 and not cls.__name__.startswith("_")},
                key=lambda c: f"{c.__module__}.{c.__qualname__}")


def _sample(name: str, annotation: str, position: int) -> object:
    """A value for a constructor parameter, from its annotation (text: ``from __future__ import annotations``)."""
    if annotation.split("|")[0].strip() == "int":
        return 7 + 4 * position
    if annotation.startswith("Iterable"):
        return ["beta", "alpha"]
    return f"<{name} {position}>"


def instance(cls: type[BaseException]) -> BaseException:
    """An instance of ``cls``: every parameter of a custom ``__init__`` given a sample value; a
    message for the others."""
    if not any("__init__" in vars(base) for base in cls.__mro__ if _ours(base)):
        return cls("what went wrong, 1.5 N m")
    parameters = list(inspect.signature(cls.__init__).parameters.values())[1:]
    assert all(p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) for p in parameters), cls
    positional = [_sample(p.name, str(p.annotation), at) for at, p in enumerate(parameters)
                  if p.kind is p.POSITIONAL_OR_KEYWORD]
    keywords = {p.name: _sample(p.name, str(p.annotation), at) for at, p in enumerate(parameters)
                if p.kind is p.KEYWORD_ONLY}
    return cls(*positional, **keywords)


def assert_same(copied: BaseException, error: BaseException) -> None:
    assert type(copied) is type(error)
    assert str(copied) == str(error)
    assert repr(copied) == repr(error)
    assert copied.args == error.args
    assert vars(copied) == vars(error)


def test_the_walk_finds_every_exception_module():
    names = {f"{cls.__module__}.{cls.__qualname__}" for cls in SLEWBENCH_ERRORS + OTHERS}
    assert {"scenarios.errors.ScenarioError", "scenarios.errors.OutputError", "ocp.errors.OptionsError",
            "planners.errors.UnknownNameError", "controllers.errors.ConformanceError",
            "scenarios.schema.plugins.PluginError", "scenarios.errors.PlausibilityWarning",
            "scenarios.errors.CaseTimeout"} <= names


@pytest.mark.parametrize("cls", SLEWBENCH_ERRORS + OTHERS, ids=lambda c: f"{c.__module__}.{c.__qualname__}")
@pytest.mark.parametrize("protocol", [0, pickle.DEFAULT_PROTOCOL, pickle.HIGHEST_PROTOCOL])
def test_every_exception_survives_pickle_with_its_text_and_attributes(cls, protocol):
    error = instance(cls)
    error.add_note("a note added on the way")
    assert_same(pickle.loads(pickle.dumps(error, protocol=protocol)), error)


@pytest.mark.parametrize("cls", SLEWBENCH_ERRORS + OTHERS, ids=lambda c: f"{c.__module__}.{c.__qualname__}")
def test_every_exception_survives_copy_and_deepcopy(cls):
    error = instance(cls)
    assert_same(copy.copy(error), error)
    assert_same(copy.deepcopy(error), error)


def test_a_scenario_error_keeps_its_file_and_names_it_once_after_the_round_trip():
    error = ScenarioError("maneuver.duration", "must be > 0, got -1", "a.yaml")
    copied = pickle.loads(pickle.dumps(error))
    assert (copied.path, copied.message, copied.file) == ("maneuver.duration", "must be > 0, got -1", Path("a.yaml"))
    assert str(copied) == "a.yaml: maneuver.duration: must be > 0, got -1"
    assert isinstance(copied, ValueError)


# --- a study's worker raises -------------------------------------------------------------------

def scenario_error_task(payload):
    """A sweep's task (imported by the worker processes from this module) that raises a user's mistake."""
    raise ScenarioError("maneuver.duration", "must be > 0, got -1", "a.yaml")


class UsersOwnError(Exception):
    """A task's own exception that pickles but cannot be rebuilt from its pickle (its constructor
    takes two arguments, its ``args`` hold one text)."""

    def __init__(self, what, value):
        super().__init__(f"{what} went wrong at {value}")


def users_own_error_task(payload):
    """A sweep's task that raises an exception slewbench cannot make picklable."""
    raise UsersOwnError("the user's task", 42)


def memory_error_task(payload):
    """A sweep's task whose worker runs out of memory: the worker's fault, not the case's."""
    raise MemoryError("cannot allocate 80 GiB")


SWEEP_SCRIPT = textwrap.dedent("""
    import sys

    from scenarios.study.engine import sweep
    from scenarios.study.spec import parse_study
    from tests import test_errors_pickle
    from tests.test_sweep import BASE

    if __name__ == "__main__":
        for name in sys.argv[1:]:  # a sweep of its own for each task, one after the other
            task = getattr(test_errors_pickle, name)
            results = sweep(parse_study({"study": "raising", "scenario": BASE}), workers=1, task=task)
            for _, row in results.to_dataframe().iterrows():
                print(name, "|", row["status"], "|", row["message"], flush=True)
            for record in results.records.values():
                print(name, "| attempts |", record["attempts"], flush=True)
""")
RAISING_TASKS = ("scenario_error_task", "users_own_error_task", "memory_error_task")


@pytest.fixture(scope="module")
def raising_sweeps() -> tuple[subprocess.CompletedProcess, dict[str, list[tuple[str, str]]]]:
    """Both tasks' sweeps in one process of their own (one interpreter and fork server for both: a
    process each took 5 s of the 10): ``(completed, {task: [(status, message), ...]})``."""
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    completed = subprocess.run([sys.executable, "-c", SWEEP_SCRIPT, *RAISING_TASKS], cwd=ROOT, env=environment,
                               capture_output=True, text=True, timeout=120)
    rows: dict[str, list[tuple[str, str]]] = {}
    for line in completed.stdout.splitlines():
        name, status, message = line.split(" | ", 2)
        rows.setdefault(name, []).append((status, message))  # status "attempts": a case's starts
    return completed, rows


@pytest.mark.parametrize("task, expected", [
    ("scenario_error_task", "its task raised ScenarioError: a.yaml: maneuver.duration: must be > 0, got -1"),
    ("users_own_error_task", "its task raised UsersOwnError: the user's task went wrong at 42"),
])
def test_a_local_sweep_whose_task_raises_shows_the_error_s_message_and_ends(raising_sweeps, task, expected):
    """In its own process, so that a sweep that never ends (the old failure: the pool's result
    thread could not rebuild the exception, and a new pool ran the case again without end) is
    stopped (its workers die with it). What a task raises is its outcome, not a worker's death: the
    case is crashed with it at once (one attempt), not run again (it said "worker died (...); 2
    attempt(s)")."""
    completed, rows = raising_sweeps
    assert completed.returncode == 0, completed.stderr
    cases = [message for status, message in rows[task] if status == "attempts"]
    assert cases == ["1"], rows[task]
    planned = [(status, message) for status, message in rows[task] if status != "attempts"]
    assert len(planned) == 2  # the two planners' rows of the case
    for status, message in planned:
        assert status == "crashed"
        assert message.startswith(expected) and "worker died" not in message, message


def test_a_task_that_runs_out_of_memory_runs_again_as_after_a_worker_s_death(raising_sweeps):
    """A ``MemoryError`` (like an ``ImportError`` on one worker of a mixed cluster) says the worker
    failed the case, not the case itself: it runs again, ``execution.retries`` times (1 by default),
    before its rows are crashed with what it raised and its attempts (one attempt before, as any
    exception a task raises)."""
    completed, rows = raising_sweeps
    assert completed.returncode == 0, completed.stderr
    assert [message for status, message in rows["memory_error_task"] if status == "attempts"] == ["2"]
    planned = [(status, message) for status, message in rows["memory_error_task"] if status != "attempts"]
    assert len(planned) == 2
    for status, message in planned:
        assert status == "crashed"
        assert message == "its task raised MemoryError: cannot allocate 80 GiB; 2 attempt(s)", message


def raises_at_sixty_task(payload):
    """A sweep's task that runs a case, but raises where its duration is 60 s: a MemoryError (the
    worker's fault) or, in a study named ``deterministic``, a ScenarioError (the case's own)."""
    from scenarios.study.worker import run_case
    if payload["scenario"]["maneuver"]["duration"] == 60.0:
        if payload["scenario"]["name"].startswith("deterministic"):
            raise ScenarioError("maneuver.duration", "must not be 60", "a.yaml")
        raise MemoryError("cannot allocate 80 GiB")
    return run_case(payload)


CHUNK_SCRIPT = textwrap.dedent("""
    import copy
    import sys

    from scenarios.study.engine import sweep
    from scenarios.study.spec import parse_study
    from tests import test_errors_pickle
    from tests.test_sweep import BASE

    if __name__ == "__main__":
        for name, retries in (("memory", 0), ("memory", 1), ("deterministic", 1)):
            scenario = {**copy.deepcopy(BASE), "name": name}
            study = {"study": name, "scenario": scenario, "execution": {"retries": retries},
                     "grid": {"maneuver.duration": [30.0 + k for k in range(40)]}}
            results = sweep(parse_study(study), workers=2, task=test_errors_pickle.raises_at_sixty_task)
            for record in results.records.values():
                row = record["rows"][0]
                print(name, retries, "|", row["status"], "|", record["attempts"], "|", row["message"], flush=True)
""")


def test_a_chunk_s_raising_case_is_charged_alone_and_runs_retries_times():
    """40 cheap cases go several to a task: the case whose task raised is known by its key, so a
    worker fault is charged to it alone (run ``retries`` + 1 times in all; a chunk that raised was
    not counted before, and the case ran twice with ``retries: 0``, 4 times with 1) and the case's
    own error crashes it at once (it ran again, alone, after its chunk raised)."""
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    completed = subprocess.run([sys.executable, "-c", CHUNK_SCRIPT], cwd=ROOT, env=environment,
                               capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    runs: dict[tuple[str, str], list[tuple[str, int, str]]] = {}
    for line in completed.stdout.splitlines():
        study, status, attempts, message = line.split(" | ", 3)
        runs.setdefault(tuple(study.split()), []).append((status, int(attempts), message))
    for (name, retries), expected in ((("memory", "0"), (1, "its task raised MemoryError: cannot allocate 80 GiB; "
                                                            "1 attempt(s)")),
                                      (("memory", "1"), (2, "its task raised MemoryError: cannot allocate 80 GiB; "
                                                            "2 attempt(s)")),
                                      (("deterministic", "1"), (1, "its task raised ScenarioError: a.yaml: "
                                                                   "maneuver.duration: must not be 60"))):
        rows = runs[(name, retries)]
        assert len(rows) == 40
        crashed = [(attempts, message) for status, attempts, message in rows if status == "crashed"]
        assert crashed == [expected], (name, retries, crashed)
        assert all(status == "ok" for status, _, _ in rows if status != "crashed")


@pytest.mark.parametrize("error, fault", [
    (MemoryError(), True), (ModuleNotFoundError("No module named 'ppigrf'"), True), (ImportError("x"), True),
    (OSError(28, "No space left on device"), True), (OSError(24, "Too many open files"), True),
    (FileNotFoundError(2, "No such file", "igrf.shc"), False), (ValueError("x"), False),
    (ScenarioError("maneuver.duration", "must be > 0, got -1"), False), (RuntimeError("x"), False)])
def test_a_worker_fault_is_told_from_the_case_s_own_error(error, fault):
    from scenarios.study.worker import worker_fault
    assert worker_fault(error) is fault


def test_a_dask_worker_s_error_reaches_the_client_as_itself():
    distributed = pytest.importorskip("distributed")
    import logging
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                           dashboard_address=None, silence_logs=logging.CRITICAL)
    with cluster, distributed.Client(cluster) as client:
        error = client.submit(scenario_error_task, {}).exception(timeout=60)
    assert_same(error, ScenarioError("maneuver.duration", "must be > 0, got -1", "a.yaml"))
