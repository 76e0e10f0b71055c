"""The ``slewbench`` console script: starts the plot process of ``run``, then the command line.

``slewbench run`` with plots forks its plot process (:mod:`scenarios.output.renderer`) here, before
anything imports NumPy or the model: the child then imports matplotlib while this process
imports slewbench and runs the scenario. Every other command, and ``python -m scenarios.cli``,
goes straight to :func:`scenarios.cli.commands.main`. This module imports only the standard library,
the lazy :mod:`scenarios` faces and :mod:`scenarios.output.renderer` (which imports no model).
"""
from __future__ import annotations

import signal
import sys
from typing import Any

from scenarios.cli.status import interrupted_status
from scenarios.output.renderer import Renderer


def _interrupt(signum: int, frame: Any) -> None:
    """SIGTERM while the model loads: stop like Ctrl-C, so that the plot process is reaped."""
    raise KeyboardInterrupt


def draws_plots(argv: list[str]) -> bool:
    """Whether the command line asks for ``run`` with plots (a bad one is reported by the parser).

    Parameters
    ----------
    argv : list of str
        Arguments without the program name.

    Returns
    -------
    bool
        ``run`` without ``--no-plots`` and without a help request (either also as the unambiguous
        abbreviations argparse accepts, such as ``--no-plot`` or ``--he``).
    """
    return argv[:1] == ["run"] and not any(
        arg == "-h" or (len(arg) > 2 and ("--no-plots".startswith(arg) or "--help".startswith(arg)))
        for arg in argv[1:])


def main(argv: list[str] | None = None) -> int:
    """Run the ``slewbench`` command line, with a plot process for ``run``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (without the program name); ``None``: ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status of :func:`scenarios.cli.commands.main` (if interrupted before it started:
        :func:`scenarios.cli.status.interrupted_status`).
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    renderer = Renderer.start() if draws_plots(argv) else None
    try:
        previous = signal.signal(signal.SIGTERM, _interrupt)
    except ValueError:  # not the main thread: signals are not ours to handle
        previous = None
    try:
        try:
            from scenarios.cli.commands import (
                main as command_line,  # the model, after the fork
            )
        except KeyboardInterrupt:  # Ctrl-C or SIGTERM while the model loads: nothing written yet
            print("slewbench: interrupted; nothing written", file=sys.stderr)
            return interrupted_status(argv[0] if argv else None)
        return command_line(argv, renderer=renderer)  # handles SIGTERM itself from here on
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if renderer is not None:
            renderer.close()


if __name__ == "__main__":
    sys.exit(main())
