"""A separate process that draws a run's figures, so that importing matplotlib overlaps the run.

Importing matplotlib costs about as much as importing slewbench and running the demo scenario
(0.6-0.9 s each on the 2-core reference machine), and drawing needs neither the model nor the
run's objects: only the arrays of :mod:`scenarios.output.plot_data`. So ``slewbench run`` forks this
process first thing, before it imports the model (:mod:`scenarios.console`). The child imports the
drawing half (:mod:`scenarios.output.plots`, which imports matplotlib but not the model) and waits. The run
sends it each row's figure as soon as the row is done (:meth:`Renderer.stream`), and the figures
of the whole run (the comparison, the margins, the sky) as soon as the last row is: the child draws
them into memory while the run goes on; when figures wait while it draws (rows done faster than
they are drawn, the whole run's figures after the last row), a fork of the child (a helper) draws a
share of them into memory meanwhile, on the static parts the child has drawn already
(:func:`_start_helper`). At the end the run sends whatever is left and the directory
to write into (:meth:`Renderer.submit`); the child writes the figures it has drawn, draws the others
there and answers.

The process is used only where forking this early is safe and cheap: Linux, and a parent with one
thread (a fork copies only the calling thread). The child limits its BLAS to one thread before it
imports NumPy, so it never has threads either. Everywhere else, and whenever the process fails,
the caller draws the same figures itself (:func:`scenarios.output.plots.draw_jobs`): the PNGs are the
same, pixel for pixel.
"""
from __future__ import annotations

import atexit
import functools
import io
import os
import pickle
import select
import signal
import struct
import sys
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

SINGLE_THREAD_ENVIRONMENT = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""Set to 1 in the child before it imports NumPy: drawing needs no BLAS threads."""
COST = {"row": 1.0, "other": 2.5}
"""Relative drawing costs of one row on its figure, whose static part is drawn before the fork
(:func:`_draw_in_two`), and of any other figure (measured, CPU: a row 0.06-0.11 s; the comparison
per axis 2.6-3.2 rows, the margins about 2, the sky about 3)."""
PIPE_BYTES = 1 << 20
"""Capacity asked for the pipe to the child (Linux's ``F_SETPIPE_SZ``; 1 MiB is the unprivileged
limit): a streamed row's series (about 80 kB pickled for the demo scenario, more than the default
64 kB) is written at once while the child is busy drawing, and the run does not wait for it."""
FRAME_HEADER = "<Q"
"""Each message to the child is its pickle's length (8 bytes, little-endian) and the pickle: the
child reads whole messages from the pipe itself, so that ``select`` tells whether another one
is waiting (a buffered reader could hold one unseen)."""
F_SETPIPE_SZ = 1031
"""``fcntl`` command that sets a pipe's capacity (Linux; the constant is not in Python 3.11's ``fcntl``)."""
STOP_TIMEOUT_S = 5.0
"""How long :meth:`Renderer.close` lets the plot process stop its fork and exit before killing it [s]."""


class RenderingFailed(RuntimeError):
    """The plot process could not draw the figures (it ended early, or drawing raised)."""


def die_with_parent(signum: int, parent: int) -> None:
    """Have the kernel send ``signum`` to this (just started) process when its parent ends, so that
    a helper process (a plot process, a trade study's worker) never works on for a parent that is
    gone (killed, or ended by a signal it does not handle); exit at once if the parent has already
    gone. Linux only (``prctl``); elsewhere nothing is set.

    Parameters
    ----------
    signum : int
        The signal the kernel sends (``signal.SIGKILL``, ``signal.SIGTERM``).
    parent : int
        The parent's process id as the caller knew it before this process started.
    """
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signum)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # no prctl: the closed pipe still ends an idle plot process
        pass
    if os.getppid() != parent:
        os._exit(1)


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
        self._submitted = False
        self.streamed: dict[str, Any] = {}
        """File names of the figures sent by :meth:`stream` (drawn by the child into memory), and
        what each was computed from (its ``source``)."""

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
        import fcntl  # POSIX only: after the platform check

        to_child, from_parent = os.pipe()[::-1]  # (write end, read end)
        try:
            fcntl.fcntl(to_child, F_SETPIPE_SZ, PIPE_BYTES)
        except OSError:  # a lower limit: a large row then waits until the child reads it
            pass
        from_child, to_parent = os.pipe()
        parent = os.getpid()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            os.close(to_child)
            os.close(from_child)
            _serve(from_parent, to_parent, parent)
        os.close(from_parent)
        os.close(to_parent)
        return cls(pid, to_child, from_child)

    def draw(self, jobs: list[Any], directory: Path) -> None:
        """Have the child draw ``jobs`` into ``directory`` and wait until it has written them
        (:meth:`submit`, then :meth:`wait`).

        Parameters
        ----------
        jobs : list of (str, series)
            File names and series (:func:`scenarios.output.plot_data.plot_jobs`).
        directory : pathlib.Path
            Existing directory to write into (the run's staging directory).

        Raises
        ------
        RenderingFailed
            The child ended early or drawing raised; nothing the child wrote is to be trusted.
        """
        self.submit(jobs, directory)
        self.wait()

    def stream(self, job: tuple[str, Any], source: Any) -> None:
        """Send one figure to the child, which draws it into memory while the caller runs on;
        :meth:`submit` later has it written (or dropped). Nothing happens once the child has
        drawn, stopped or failed: :meth:`submit` then reports it, and the caller draws everything.

        Parameters
        ----------
        job : (str, series)
            File name and series (:func:`scenarios.output.plot_data.row_job`,
            :func:`scenarios.output.plot_data.plot_jobs`).
        source : object
            What the series was computed from (a row, the run's rows), kept in :attr:`streamed`
            for the caller to decide at the end whether the figure is still the one to write.
        """
        if not self._running or len(self._fds) != 2 or self._submitted:
            return
        try:
            self._send(("row", job))
        except OSError:
            self.close()  # submit raises RenderingFailed
            return
        self.streamed[job[0]] = source

    def _send(self, message: tuple[Any, ...]) -> None:
        """Pickle ``message`` into the pipe to the child (closing the child on Ctrl-C or SIGTERM).
        Unbuffered: a signal while the pipe is full stops the child at once (no buffered rest to
        flush into a pipe nobody reads)."""
        payload = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
        data = memoryview(struct.pack(FRAME_HEADER, len(payload)) + payload)
        try:
            while data:
                data = data[os.write(self._fds[0], data):]
        except OSError:  # the child has gone: the caller says what that means
            raise
        except BaseException:  # Ctrl-C, SIGTERM: the child stops before the caller removes `directory`
            self.close()
            raise

    def submit(self, jobs: list[Any], directory: Path, keep: set[str] | frozenset[str] = frozenset()) -> None:
        """Send ``jobs`` to the child and return while it draws (the caller then works on, for
        instance on ``report.html``, and calls :meth:`wait` before it uses ``directory``'s figures).

        Parameters
        ----------
        jobs : list of (str, series)
            File names and series (:func:`scenarios.output.plot_data.plot_jobs`) still to draw.
        directory : pathlib.Path
            Existing directory to write into (the run's staging directory).
        keep : set of str, optional
            File names of figures sent by :meth:`stream` to write into ``directory`` too (any other
            streamed figure is dropped).

        Raises
        ------
        RenderingFailed
            The child has already drawn or stopped, or ended before it took the jobs.
        """
        if not self._running or len(self._fds) != 2:
            raise RenderingFailed("the plot process has already drawn or stopped")
        try:
            self._send(("draw", str(directory), jobs, sorted(keep)))
        except OSError as error:
            self.close()
            raise RenderingFailed(f"the plot process ended early ({type(error).__name__})") from None
        self._submitted = True

    def wait(self) -> None:
        """Wait until the child has written the figures sent by :meth:`submit`, and reap it.

        Raises
        ------
        RenderingFailed
            Nothing was submitted, the child ended early or drawing raised; nothing the child wrote
            is to be trusted.
        """
        if not self._submitted:
            raise RenderingFailed("no figures were sent to the plot process")
        self._submitted = False
        try:
            with os.fdopen(self._fds[1], "rb", closefd=False) as stream:
                status, detail = pickle.load(stream)
        except (OSError, EOFError, pickle.UnpicklingError) as error:
            self.close()
            raise RenderingFailed(f"the plot process ended early ({type(error).__name__})") from None
        except BaseException:  # Ctrl-C, SIGTERM: both drawers stop before the caller removes `directory`
            self.close()
            raise
        self._close_fds()
        self._reap()
        if status != "ok":
            raise RenderingFailed(f"the plot process failed: {detail.strip().splitlines()[-1]}")

    def _reap(self) -> None:
        """Wait for the child's exit (it exits once it has answered)."""
        if self._running:
            self._running = False
            os.waitpid(self.pid, 0)

    def _close_fds(self) -> None:
        for fd in self._fds:
            os.close(fd)
        self._fds = []

    def close(self) -> None:
        """Stop the child if it is still running (the run failed or was interrupted); idempotent.

        The child is asked with SIGTERM, on which it kills and reaps its own fork (:func:`_serve`),
        so that when this returns neither draws any more; SIGKILL after :data:`STOP_TIMEOUT_S`.
        """
        self._close_fds()
        if not self._running:
            return
        try:
            os.kill(self.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        deadline = time.monotonic() + STOP_TIMEOUT_S
        while os.waitpid(self.pid, os.WNOHANG)[0] == 0:
            if time.monotonic() > deadline:
                os.kill(self.pid, signal.SIGKILL)
                os.waitpid(self.pid, 0)
                break
            time.sleep(0.005)
        self._running = False


def split(jobs: list[Any]) -> tuple[list[Any], list[Any]]:
    """Share figures between two processes so that both finish at about the same time.

    Greedy, largest first: each figure goes where the total cost (:data:`COST`) stays lower. The
    static parts of the per-row figures are drawn before the fork and shared (:func:`_draw_in_two`),
    so they are not counted.

    Parameters
    ----------
    jobs : list of (str, series)
        File names and series (:func:`scenarios.output.plot_data.plot_jobs`).

    Returns
    -------
    tuple of two lists
        The two shares, each in the original order.
    """
    from scenarios.output.plot_data import RowSeries

    costs = [0.0, 0.0]
    share = [0] * len(jobs)
    order = sorted(range(len(jobs)), key=lambda k: isinstance(jobs[k][1], RowSeries))  # others first
    for k in order:
        cost = COST["row"] if isinstance(jobs[k][1], RowSeries) else COST["other"]
        b = 0 if costs[0] <= costs[1] else 1
        costs[b] += cost
        share[k] = b
    return ([job for job, b in zip(jobs, share) if b == 0], [job for job, b in zip(jobs, share) if b == 1])


def _draw_in_two(jobs: list[Any], directory: Path, forks: list[int], figures: dict[Any, Any]) -> None:
    """Draw ``jobs`` in this process and a fork of it (the child of :func:`_serve`, which has one
    thread; the fork's pid is in ``forks`` while it runs); raise if either fails.

    The static part of each row shape's figure is drawn first (:meth:`RowFigure.prepare` with the
    first row of that shape) unless ``figures`` (row figures by shape, those the streamed rows were
    drawn on) has it, so that the fork inherits it instead of drawing it again.
    """
    from scenarios.output.plot_data import RowSeries
    from scenarios.output.plots import RowFigure, draw_jobs

    for _, series in jobs:
        if isinstance(series, RowSeries) and series.shape not in figures:
            figures[series.shape] = RowFigure(*series.shape)
            figures[series.shape].prepare(series)
    mine, theirs = split(jobs)
    if not mine or not theirs or _thread_count() != 1:  # a fork copies only the calling thread
        draw_jobs(jobs, directory, figures)
        return
    pid = _fork(lambda: draw_jobs(theirs, directory, figures), forks)
    try:
        draw_jobs(mine, directory, figures)
    finally:
        _, status = os.waitpid(pid, 0)
        forks.remove(pid)
    if status != 0:
        raise RuntimeError(f"the second drawing process failed (wait status {status})")


class _Helper(NamedTuple):
    """A fork of the plot process drawing streamed figures into memory (:func:`_start_helper`)."""

    pid: int
    fd: int
    """The read end of the pipe its answer comes through."""
    jobs: list[Any]
    """The figures it draws: (file name, series)."""


def _draw_into_memory(jobs: list[Any], figures: dict[Any, Any]) -> dict[str, bytes]:
    """Draw ``jobs`` into PNG bytes by file name (row figures on ``figures``, by shape)."""
    from scenarios.output.plot_data import RowSeries
    from scenarios.output.plots import DRAW, RowFigure

    drawn = {}
    for name, series in jobs:
        buffer = io.BytesIO()
        if isinstance(series, RowSeries):
            figure = figures.get(series.shape) or figures.setdefault(series.shape, RowFigure(*series.shape))
            figure.draw(series, buffer)
        else:
            DRAW[type(series)](series, buffer)
        drawn[name] = buffer.getvalue()
    return drawn


def _prepare_first(pending: list[Any], figures: dict[Any, Any]) -> bool:
    """If the next figure is a row of a shape without a drawn static part, build its figure and
    draw that part (:meth:`RowFigure.prepare`) and say so: the row itself and whatever else has come
    meanwhile can then be shared with a helper, which inherits the static part."""
    from scenarios.output.plot_data import RowSeries
    from scenarios.output.plots import RowFigure

    series = pending[0][1] if pending else None
    if not isinstance(series, RowSeries) or (series.shape in figures and figures[series.shape].prepared):
        return False
    figures.setdefault(series.shape, RowFigure(*series.shape)).prepare(series)
    return True


def _share(pending: list[Any], figures: dict[Any, Any]) -> tuple[list[Any], list[Any]]:
    """What the plot process keeps and what a helper draws of the streamed figures not drawn yet:
    shared by :func:`split`, once the static part of every row shape among them is drawn (a
    helper inherits it); before that, the helper takes only the figures other than rows, so that
    no static part is drawn twice."""
    from scenarios.output.plot_data import RowSeries

    rows = [job for job in pending if isinstance(job[1], RowSeries)]
    if any(series.shape not in figures or not figures[series.shape].prepared for _, series in rows):
        return rows, [job for job in pending if not isinstance(job[1], RowSeries)]
    return split(pending)


def _start_helper(jobs: list[Any], figures: dict[Any, Any], forks: list[int], close: tuple[int, ...]) -> _Helper:
    """Fork a helper that draws ``jobs`` into memory (:func:`_draw_into_memory`, on the figures
    inherited from ``figures``) and answers through a pipe with ``("ok", {name: bytes})`` or
    ``("error", traceback)``, then exits. Its pid is in ``forks`` while it runs (:func:`_stop`);
    ``close``: the plot process's ends of its pipes to the run, which the helper does not use."""
    read_fd, write_fd = os.pipe()

    def answer() -> None:
        for fd in (read_fd, *close):
            os.close(fd)
        try:
            reply: tuple[str, Any] = ("ok", _draw_into_memory(jobs, figures))
        except Exception:  # noqa: BLE001 (reported to the plot process, which reports it to the run)
            reply = ("error", traceback.format_exc())
        with os.fdopen(write_fd, "wb") as stream:
            pickle.dump(reply, stream, protocol=pickle.HIGHEST_PROTOCOL)

    pid = _fork(answer, forks)
    os.close(write_fd)
    return _Helper(pid, read_fd, jobs)


def _fork(work: Callable[[], None], forks: list[int]) -> int:
    """Fork a child of the plot process that runs ``work`` and exits (status 0 when it returned, 1
    when it raised); return its pid, which is in ``forks`` (:func:`_stop`) until the caller reaps it.

    The stop signals are blocked from before the fork until the pid is in ``forks``, so that a stop
    never misses the child; the child takes their default actions and dies with the plot process.
    """
    stopping = {signal.SIGINT, signal.SIGTERM}
    parent = os.getpid()
    signal.pthread_sigmask(signal.SIG_BLOCK, stopping)
    pid = os.fork()
    if pid == 0:
        code = 1
        try:
            for signum in stopping:
                signal.signal(signum, signal.SIG_DFL)
            signal.pthread_sigmask(signal.SIG_UNBLOCK, stopping)
            die_with_parent(signal.SIGKILL, parent)
            work()
            code = 0
        finally:
            os._exit(code)
    forks.append(pid)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, stopping)
    return pid


def _collect(helper: _Helper, forks: list[int]) -> tuple[dict[str, bytes], list[Any], str]:
    """Wait for a helper's answer and reap it.

    Returns
    -------
    drawn : dict
        PNG bytes by file name.
    undrawn : list
        Its jobs, when it ended without answering (killed): to be drawn by the plot process.
    failure : str
        The traceback of a drawing that raised (empty if none).
    """
    try:
        with os.fdopen(helper.fd, "rb") as stream:
            status, detail = pickle.load(stream)
    except (OSError, EOFError, pickle.UnpicklingError):
        status, detail = "gone", None
    os.waitpid(helper.pid, 0)
    forks.remove(helper.pid)
    if status == "ok":
        return detail, [], ""
    if status == "error":
        return {}, [], detail
    return {}, list(helper.jobs), ""


def _stop(forks: list[int], signum: int, frame: Any) -> None:
    """The plot process's Ctrl-C and SIGTERM: kill and reap its running fork (``forks``, kept by
    :func:`_draw_in_two`), then exit (no traceback; the parent reports the interruption)."""
    for pid in forks:
        try:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
        except OSError:
            pass
    _exit(1)


def _exit(code: int) -> None:
    """Run the exit handlers registered in the plot process (matplotlib's removal of a temporary
    cache directory it made where its own is not writable), then exit without running anything
    inherited from the parent (``os._exit``)."""
    atexit._run_exitfuncs()
    os._exit(code)


def _read_exactly(fd: int, size: int) -> bytes | None:
    """``size`` bytes from ``fd`` (``None`` at the end of the stream before all of them came)."""
    chunks, left = [], size
    while left:
        chunk = os.read(fd, min(left, 1 << 20))
        if not chunk:
            return None
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _receive(fd: int) -> Any:
    """The next message of :meth:`Renderer._send` (a frame of :data:`FRAME_HEADER`), or ``None``
    when the parent has closed the pipe."""
    header = _read_exactly(fd, struct.calcsize(FRAME_HEADER))
    if header is None:
        return None
    payload = _read_exactly(fd, struct.unpack(FRAME_HEADER, header)[0])
    return None if payload is None else pickle.loads(payload)


def _waiting(fd: int) -> bool:
    """Whether the pipe has something to read now (a message, or its end)."""
    return bool(select.select([fd], [], [], 0.0)[0])


def _serve(receive_fd: int, send_fd: int, parent: int) -> None:
    """The child: import the drawing half, draw what the parent sends, answer, exit.

    Exits with ``os._exit`` (never returns): nothing of the parent's state inherited by the fork
    (buffered output, ``atexit`` handlers) runs twice; the exit handlers registered here do run
    (:func:`_exit`). Ctrl-C and SIGTERM, and the end of the parent (``parent``, its pid), end it
    and its fork (:func:`_stop`).
    """
    code = 1
    try:
        atexit._clear()  # the parent's: they run in the parent
        forks: list[int] = []
        signal.signal(signal.SIGINT, functools.partial(_stop, forks))
        signal.signal(signal.SIGTERM, functools.partial(_stop, forks))
        die_with_parent(signal.SIGTERM, parent)
        for name in SINGLE_THREAD_ENVIRONMENT:
            os.environ[name] = "1"
        # matplotlib, while the parent runs
        from scenarios.output.plots import RowFigure

        figures: dict[Any, RowFigure] = {}
        drawn: dict[str, bytes] = {}
        pending: list[tuple[str, Any]] = []  # streamed, not drawn yet
        helper: _Helper | None = None  # a fork drawing some of them meanwhile
        failure, final = "", None
        while final is None:
            # take every message already sent; wait for one only when there is nothing to draw
            while final is None and (not pending or _waiting(receive_fd)):
                message = _receive(receive_fd)
                if message is None:  # the parent ended without plots to draw
                    _exit(0)
                if message[0] == "draw":
                    final = message
                else:
                    pending.append(message[1])
            if helper is not None and final is None and _waiting(helper.fd):  # it has answered
                more, undrawn, failed = _collect(helper, forks)
                drawn.update(more)
                pending.extend(undrawn)
                failure, helper = failure or failed, None
            if final is None and not failure:  # idle: streamed figures, drawn into memory
                try:
                    if _prepare_first(pending, figures):
                        continue  # a new row shape's static part drawn: share what waits now
                    if helper is None and len(pending) > 1 and _thread_count() == 1:
                        pending, theirs = _share(pending, figures)
                        if theirs:
                            helper = _start_helper(theirs, figures, forks, (receive_fd, send_fd))
                    drawn.update(_draw_into_memory([pending.pop(0)], figures) if pending else {})
                except Exception:  # reported with the answer
                    failure = traceback.format_exc()
            elif final is None:
                pending.clear()
        _, directory, jobs, keep = final
        try:
            if failure:
                raise RuntimeError(f"drawing a streamed figure failed: {failure}")
            for name in keep:
                if name in drawn:
                    (Path(directory) / name).write_bytes(drawn[name])
            # the streamed figures not drawn yet (all of them, when the run ended before matplotlib
            # was imported) are drawn with the rest, shared between this process and its fork,
            # while a helper still draws its share
            late = [job for job in pending if job[0] in keep]
            helping = {name for name, _ in helper.jobs} if helper is not None else set()
            missing = set(keep) - set(drawn) - {name for name, _ in late} - helping
            if missing:
                raise RuntimeError(f"figures to keep that were never streamed: {sorted(missing)}")
            _draw_in_two(late + jobs, Path(directory), forks, figures)
            if helper is not None:
                more, undrawn, failed = _collect(helper, forks)
                helper = None
                if failed:
                    raise RuntimeError(f"drawing a streamed figure failed: {failed}")
                more.update(_draw_into_memory([job for job in undrawn if job[0] in keep], figures))
                for name in keep:
                    if name in more:
                        (Path(directory) / name).write_bytes(more[name])
            reply: tuple[str, str] = ("ok", "")
        except Exception:  # reported to the parent, which draws in its own process and raises there
            reply = ("error", traceback.format_exc())
        if helper is not None:  # not needed any more (this process failed): stopped and reaped
            os.kill(helper.pid, signal.SIGKILL)
            _collect(helper, forks)
        with os.fdopen(send_fd, "wb") as stream:
            pickle.dump(reply, stream)
        code = 0
    except BaseException:  # noqa: BLE001 (the child never lets anything escape into the parent's code)
        code = 1
    finally:
        _exit(code)
