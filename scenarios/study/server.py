"""The first thing the process that local sweep workers fork from does: keep the user's working
directory off its import path.

That process (multiprocessing's fork server) is started as ``python -c ...``, which puts the
current directory first on ``sys.path``; the modules it imports (:data:`scenarios.study.worker.PRELOAD`)
are inherited by every worker forked from it. A ``controllers.py`` (or ``planners.py``, ``ocp.py``,
``scenarios.py``) in the directory a sweep was started from would then be imported in place of
slewbench's package, and every case of the sweep would crash. So
:func:`scenarios.study.engine.start_forkserver` starts it in Python's safe-path mode
(``PYTHONSAFEPATH``, Python 3.11 and later: nothing is put before the installed packages), and
this module, imported first, takes the current directory (``''``) off ``sys.path`` where that mode
does not exist (Python 3.10: the packages the workbench imports after this module are found where
the sweep's own process finds them; a ``scenarios.py`` there still shadows the package this module
is in).

The server is also given the sweep's own ``sys.path`` as its ``PYTHONPATH`` (``''``, the current
directory, left out): it imports the workbench the sweep runs (a checkout the sweep found first, a
notebook's ``sys.path.insert``), not another copy installed. The workers themselves take the
sweep's ``sys.path`` and working directory when they start
(``multiprocessing``'s own preparation): a plugin module found by the sweep's process
(``SLEWBENCH_PLUGINS``, an entry point) is found by its workers, and relative paths resolve as
they do in the sweep. What this module changes in the server's environment is put back before
any worker forks, so that a worker's own child processes run in Python's usual mode.

May import: nothing of slewbench (it runs before the workbench is imported).
"""
from __future__ import annotations

import os
import sys

__all__ = ["SAFE_PATH", "SAFE_PATH_MARK", "UNSET", "USER_PYTHONPATH", "isolate_import_path"]

SAFE_PATH = "PYTHONSAFEPATH"
"""Python's environment variable of safe-path mode (``-P``): no directory of the script or of
``-c`` is put first on ``sys.path``."""
SAFE_PATH_MARK = "SLEWBENCH_SAFE_PATH"
"""Set while a sweep starts its fork server: ``added`` when the sweep set :data:`SAFE_PATH` for it
(it is taken out of the server's environment again), ``kept`` when the user had set it."""


USER_PYTHONPATH = "SLEWBENCH_USER_PYTHONPATH"
"""Set while a sweep starts its fork server: the user's ``PYTHONPATH`` (or :data:`UNSET`), which the
server puts back (the sweep gives the server its own ``sys.path`` as ``PYTHONPATH``)."""
UNSET = "<unset>"
"""The value of :data:`USER_PYTHONPATH` when the user had no ``PYTHONPATH``."""


def isolate_import_path() -> None:
    """In the fork server of a sweep (:data:`SAFE_PATH_MARK` set), take the current directory off
    ``sys.path`` and restore the environment the sweep had; elsewhere, nothing.

    Runs when this module is imported.
    """
    mark = os.environ.pop(SAFE_PATH_MARK, None)
    if mark is None:
        return
    if mark == "added":
        os.environ.pop(SAFE_PATH, None)
    user = os.environ.pop(USER_PYTHONPATH, UNSET)
    if user == UNSET:
        os.environ.pop("PYTHONPATH", None)
    else:
        os.environ["PYTHONPATH"] = user
    sys.path[:] = [entry for entry in sys.path if entry != ""]


isolate_import_path()
