"""The ``slewbench`` console script: starts the plot process of ``run``, then the command line.

``slewbench run`` with plots forks its plot process (:mod:`scenarios.renderer`) here, before
anything imports NumPy or the model: the child then imports matplotlib while this process
imports slewbench and runs the scenario. Every other command, and ``python -m scenarios.cli``,
goes straight to :func:`scenarios.cli.main`. This module imports only the standard library and
the lazy :mod:`scenarios` package.
"""
from __future__ import annotations

import sys

from scenarios.renderer import Renderer


def draws_plots(argv: list[str]) -> bool:
    """Whether the command line asks for ``run`` with plots (a bad one is reported by the parser).

    Parameters
    ----------
    argv : list of str
        Arguments without the program name.

    Returns
    -------
    bool
        ``run`` without ``--no-plots`` and without a help request.
    """
    return argv[:1] == ["run"] and not {"--no-plots", "-h", "--help"} & set(argv)


def main(argv: list[str] | None = None) -> int:
    """Run the ``slewbench`` command line, with a plot process for ``run``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (without the program name); ``None``: ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status of :func:`scenarios.cli.main`.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    renderer = Renderer.start() if draws_plots(argv) else None
    try:
        from scenarios.cli import main as command_line  # the model, after the fork

        return command_line(argv, renderer=renderer)
    finally:
        if renderer is not None:
            renderer.close()


if __name__ == "__main__":
    sys.exit(main())
