"""A sweep on a caller's own executor (not Dask, not the local pool) words what a task raised by
what happened, ``its task raised TYPE: text``, and does not run the case again (a deterministic
outcome); a worker fault (``MemoryError``) runs again ``execution.retries`` times, worded the same
way, and an executor that loses its worker still says the worker died.

Oracle: the wording and attempt counts of the local pool for the same tasks
(tests/test_errors_pickle.py), counted here by the executor's submissions: 2 cases, retries 1.
"""
from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool

import pytest

from scenarios.study.engine import sweep
from scenarios.study.spec import parse_study
from tests.study_scale_tasks import cheap_task
from tests.test_sweep import InlineExecutor, study_data


def value_error_task(payload):
    if payload["scenario"]["maneuver"]["duration"] == 40.0:
        raise ValueError("the user's task went wrong at 42")
    return cheap_task(payload)


def memory_error_task(payload):
    if payload["scenario"]["maneuver"]["duration"] == 40.0:
        raise MemoryError("no room")
    return cheap_task(payload)


class LosingExecutor(InlineExecutor):
    """Loses the worker of the 40 s case, as a process pool whose child died says it."""

    def submit(self, fn, *args, **kwargs):
        payloads = args[-1] if isinstance(args[-1], list) else [args[-1]]
        if any(payload["scenario"]["maneuver"]["duration"] == 40.0 for payload in payloads):
            self.submitted += 1
            future = Future()
            future.set_exception(BrokenProcessPool("a child process terminated abruptly"))
            return future
        return super().submit(fn, *args, **kwargs)


def messages(results):
    return {record["rows"][0]["message"]: (record["status"], record["attempts"]) for record in results.records.values()}


def study():
    return parse_study(study_data(grid={"maneuver.duration": [30.0, 40.0]}, execution={"retries": 1}))


@pytest.mark.parametrize("make", [InlineExecutor, lambda: ThreadPoolExecutor(1)])
def test_a_raising_task_is_crashed_at_once_with_what_it_raised(make):
    executor = make()
    try:
        results = sweep(study(), executor, task=value_error_task)
    finally:
        executor.shutdown()
    said = messages(results)
    assert said == {"": ("ok", 1), "its task raised ValueError: the user's task went wrong at 42": ("crashed", 1)}, said
    if isinstance(executor, InlineExecutor):
        assert executor.submitted == 2  # not run again


def test_a_worker_fault_runs_again_and_says_what_the_task_raised():
    executor = InlineExecutor()
    said = messages(sweep(study(), executor, task=memory_error_task))
    assert said == {"": ("ok", 1), "its task raised MemoryError: no room; 2 attempt(s)": ("crashed", 2)}, said
    assert executor.submitted == 3


def test_an_executor_that_loses_its_worker_still_says_so():
    executor = LosingExecutor()
    said = messages(sweep(study(), executor, task=cheap_task))
    assert said == {"": ("ok", 1), "worker died (its process ended abruptly); 2 attempt(s)": ("crashed", 2)}, said
