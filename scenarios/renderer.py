"""A separate process that draws a run's figures, so that importing matplotlib overlaps the run.

Importing matplotlib costs about as much as importing slewbench and running the demo scenario
(0.6-0.9 s each on the 2-core reference machine), and drawing needs neither the model nor the
run's objects: only the arrays of :mod:`scenarios.plot_data`. So ``slewbench run`` forks this
process first thing, before it imports the model (:mod:`scenarios.console`). The child imports the
drawing half (:mod:`scenarios.plots`, which imports matplotlib but not the model) and waits. The run
sends it the figures to draw (file names and series, pickled through a pipe) and the directory
to write them into. The child draws them there and answers.

The process is used only where forking this early is safe and cheap: Linux, and a parent with one
thread (a fork copies only the calling thread). The child limits its BLAS to one thread before it
imports NumPy, so it never has threads either. Everywhere else, and whenever the process fails,
the caller draws the same figures itself (:func:`scenarios.plots.draw_jobs`): the PNGs are the
same, pixel for pixel.
"""
from __future__ import annotations

import os
import pickle
import signal
import sys
import traceback
from pathlib import Path
from typing import Any

SINGLE_THREAD_ENVIRONMENT = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""Set to 1 in the child before it imports NumPy: drawing needs no BLAS threads."""
COST = {"background": 2.5, "row": 1.0, "other": 1.3}
"""Relative drawing costs (about 0.1 s each on the reference machine): the static part of a per-row
figure (drawn once per process and row shape), one row on it, any other figure."""


class RenderingFailed(RuntimeError):
    """The plot process could not draw the figures (it ended early, or drawing raised)."""


def _thread_count() -> int:
    """Threads of this process, as the kernel counts them (native ones included)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return 2  # unknown: assume threads, do not fork


class Renderer:
    """The parent's handle on a plot process (module docstring); :meth:`start` creates one.

    Parameters
    ----------
    pid : int
        The child's process id.
    send_fd, receive_fd : int
        The parent's ends of the two pipes: to the child, from the child.
    """

    def __init__(self, pid: int, send_fd: int, receive_fd: int):
        self.pid = pid
        self._fds = [send_fd, receive_fd]
        self._running = True

    @classmethod
    def start(cls) -> Renderer | None:
        """Fork the plot process, if this platform and process allow it (module docstring).

        Returns
        -------
        Renderer or None
            The handle; ``None`` where the figures are to be drawn in this process.
        """
        if not sys.platform.startswith("linux") or _thread_count() != 1:
            return None
        to_child, from_parent = os.pipe()[::-1]  # (write end, read end)
        from_child, to_parent = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            os.close(to_child)
            os.close(from_child)
            _serve(from_parent, to_parent)
        os.close(from_parent)
        os.close(to_parent)
        return cls(pid, to_child, from_child)

    def draw(self, jobs: list[Any], directory: Path) -> None:
        """Have the child draw ``jobs`` into ``directory`` and wait until it has written them.

        Parameters
        ----------
        jobs : list of (str, series)
            File names and series (:func:`scenarios.plot_data.plot_jobs`).
        directory : pathlib.Path
            Existing directory to write into (the run's staging directory).

        Raises
        ------
        RenderingFailed
            The child ended early or drawing raised; nothing the child wrote is to be trusted.
        """
        if not self._running:
            raise RenderingFailed("the plot process has already drawn or stopped")
        send_fd, receive_fd = self._fds
        self._fds = []
        try:
            with os.fdopen(send_fd, "wb") as stream:
                pickle.dump((str(directory), jobs), stream, protocol=pickle.HIGHEST_PROTOCOL)
            with os.fdopen(receive_fd, "rb") as stream:
                status, detail = pickle.load(stream)
        except (OSError, EOFError, pickle.UnpicklingError) as error:
            self.close()
            raise RenderingFailed(f"the plot process ended early ({type(error).__name__})") from None
        self._reap()
        if status != "ok":
            raise RenderingFailed(f"the plot process failed: {detail.strip().splitlines()[-1]}")

    def _reap(self) -> None:
        """Wait for the child's exit (it exits once it has answered)."""
        if self._running:
            self._running = False
            os.waitpid(self.pid, 0)

    def close(self) -> None:
        """Stop the child if it is still running (the run failed or was interrupted); idempotent."""
        for fd in self._fds:
            os.close(fd)
        self._fds = []
        if self._running:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self._reap()


def split(jobs: list[Any]) -> tuple[list[Any], list[Any]]:
    """Share figures between two processes so that both finish at about the same time.

    Greedy, largest first: each figure goes where the total cost (:data:`COST`) stays lower,
    counting the static part of a per-row figure once for each process that draws a row of
    that shape.

    Parameters
    ----------
    jobs : list of (str, series)
        File names and series (:func:`scenarios.plot_data.plot_jobs`).

    Returns
    -------
    tuple of two lists
        The two shares, each in the original order.
    """
    from scenarios.plot_data import RowSeries

    costs, shapes = [0.0, 0.0], [set(), set()]  # type: ignore[var-annotated]
    share = [0] * len(jobs)
    order = sorted(range(len(jobs)), key=lambda k: isinstance(jobs[k][1], RowSeries))  # others first
    for k in order:
        series = jobs[k][1]
        row = isinstance(series, RowSeries)
        added = [COST["row"] + (COST["background"] if series.shape not in shapes[b] else 0.0) if row
                 else COST["other"] for b in (0, 1)]
        b = 0 if costs[0] + added[0] <= costs[1] + added[1] else 1
        costs[b] += added[b]
        share[k] = b
        if row:
            shapes[b].add(series.shape)
    return ([job for job, b in zip(jobs, share) if b == 0], [job for job, b in zip(jobs, share) if b == 1])


def _draw_in_two(jobs: list[Any], directory: Path) -> None:
    """Draw ``jobs`` in this process and a fork of it (the child of :func:`_serve`, which has one
    thread); raise if either fails."""
    from scenarios.plots import draw_jobs

    mine, theirs = split(jobs)
    if not mine or not theirs:
        draw_jobs(jobs, directory)
        return
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            draw_jobs(theirs, directory)
            code = 0
        finally:
            os._exit(code)
    try:
        draw_jobs(mine, directory)
    finally:
        _, status = os.waitpid(pid, 0)
    if status != 0:
        raise RuntimeError(f"the second drawing process failed (wait status {status})")


def _serve(receive_fd: int, send_fd: int) -> None:
    """The child: import the drawing half, draw what the parent sends, answer, exit.

    Exits with ``os._exit`` (never returns): nothing of the parent's state inherited by the fork
    (buffered output, ``atexit`` handlers) runs twice. Ctrl-C and SIGTERM end it without a
    traceback; the parent reports them.
    """
    code = 1
    try:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        for name in SINGLE_THREAD_ENVIRONMENT:
            os.environ[name] = "1"
        import scenarios.plots  # noqa: F401  (matplotlib, while the parent runs)

        with os.fdopen(receive_fd, "rb") as stream:
            try:
                directory, jobs = pickle.load(stream)
            except EOFError:  # the parent ended without plots to draw
                os._exit(0)
        try:
            _draw_in_two(jobs, Path(directory))
            reply: tuple[str, str] = ("ok", "")
        except Exception:  # reported to the parent, which draws in its own process and raises there
            reply = ("error", traceback.format_exc())
        with os.fdopen(send_fd, "wb") as stream:
            pickle.dump(reply, stream)
        code = 0
    except BaseException:  # noqa: BLE001 (the child never lets anything escape into the parent's code)
        code = 1
    finally:
        os._exit(code)
