"""Plugins: a user's extensions (planners, controllers, field models ...) brought to the registries the schema reads.

A plugin is a module (or a callable of no arguments) that registers extensions when it is loaded,
by the same statements as code does (``PLANNERS[MyPlanner.name] = MyPlanner``,
:doc:`/extending/index`). Two routes lead to one:

* an installed distribution's entry point in the group :data:`ENTRY_POINT_GROUP`
  (``slewbench.plugins``), as pytest finds its ``pytest11`` plugins: in ``pyproject.toml``,
  ``[project.entry-points."slewbench.plugins"] cubic = "cubic_slew"``; ``pip install`` of the
  distribution is all the command line needs;
* the environment variable :data:`ENVIRONMENT_VARIABLE` (``SLEWBENCH_PLUGINS``): comma-separated
  module names (imported from ``sys.path``) or paths of ``.py`` files, for a module not packaged.

:func:`load_plugins` loads each plugin once per process: the command line calls it at start, and
the library face (:mod:`scenarios`) on first use of one of its names (``scenarios.load``,
``scenarios.sweep`` ...), so that a scenario file naming a plugin's planner loads the same from
Python as from the command line. It lives beside the schema because the schema is what reads the
registries; the registries of :data:`registries` are those a scenario or study names things in.

A plugin that fails to load, or that registers a name some registry already holds (a built-in's
or another plugin's), raises :class:`PluginError` naming the plugin and what went wrong; what it
had registered is taken out again. :func:`provider` says which plugin provided a name.

Imports :mod:`ocp`, :mod:`planners`, :mod:`controllers` (their registries) and
:mod:`scenarios.schema.study` (the value generators).
"""
from __future__ import annotations

import functools
import importlib
import importlib.util
import os
import sys
import threading
from collections.abc import Callable, MutableMapping
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from types import ModuleType
from typing import Any

from ocp.errors import SlewbenchError

__all__ = ["ENTRY_POINT_GROUP", "ENVIRONMENT_VARIABLE", "LoadedPlugin", "PluginError", "load_plugins",
           "loaded_plugins", "provider", "registries"]

ENTRY_POINT_GROUP = "slewbench.plugins"
"""The entry-point group whose entries are slewbench plugins (a module, or ``module:callable``)."""
ENVIRONMENT_VARIABLE = "SLEWBENCH_PLUGINS"
"""The environment variable of plugins not packaged: comma-separated module names or ``.py`` paths."""


class PluginError(SlewbenchError):
    """A plugin failed to load or registered a name already taken; the message names the plugin.

    The command line reports it with exit status 2, without a traceback.
    """


@dataclass
class LoadedPlugin:
    """A plugin loaded in this process and the names it registered.

    Attributes
    ----------
    label : str
        How it is named in messages and in ``slewbench list``: ``entry point 'cubic' = cubic_slew
        (slewbench-cubic 0.1)`` or ``SLEWBENCH_PLUGINS module cubic_slew``.
    provided : dict of str to list of str
        Registry kind (``"planner"``, ``"magnetic field model"`` ...) -> the names it registered.
    """

    label: str
    provided: dict[str, list[str]] = field(default_factory=dict)


_LOADED: dict[str, LoadedPlugin] = {}
"""Plugin key (``entry point <name>=<value>`` or ``SLEWBENCH_PLUGINS <entry>``) -> what it loaded."""
_LOCK = threading.RLock()
"""Held while plugins load: another thread waits for them; the loading thread may re-enter (a plugin
that uses the library face) and gets nothing more to load."""
_LOADING = False
"""Set while plugins load in the thread holding :data:`_LOCK`: a plugin that uses the library face
does not start loading again."""


def registries() -> dict[str, MutableMapping[str, Any]]:
    """The registries a plugin may add to, by the kind of thing they hold.

    Every built-in registration has happened when this returns (``igrf`` registers itself when its
    module is imported), so that what a plugin adds is told apart from what slewbench ships.

    Returns
    -------
    dict of str to mutable mapping
        ``"planner"`` (:data:`planners.PLANNERS`), ``"controller"`` (:data:`controllers.CONTROLLERS`),
        ``"transcription"`` (:data:`ocp.transcription.TRANSCRIPTIONS`), ``"magnetic field model"``
        (:data:`ocp.dynamics.environment.MAGNETIC_FIELDS`), ``"orbit kind"``
        (:data:`ocp.dynamics.orbits.ORBITS`), ``"actuator kind"``
        (:data:`ocp.dynamics.actuator_kinds.ACTUATOR_KINDS`) and ``"study value generator"``
        (:data:`scenarios.schema.study.VALUE_GENERATORS`).
    """
    import ocp.dynamics.igrf  # noqa: F401  (registers igrf in MAGNETIC_FIELDS)
    from controllers import CONTROLLERS
    from ocp.dynamics.actuator_kinds import ACTUATOR_KINDS
    from ocp.dynamics.environment import MAGNETIC_FIELDS
    from ocp.dynamics.orbits import ORBITS
    from ocp.transcription import TRANSCRIPTIONS
    from planners import PLANNERS
    from scenarios.schema.study import VALUE_GENERATORS

    return {"planner": PLANNERS, "controller": CONTROLLERS, "transcription": TRANSCRIPTIONS,
            "magnetic field model": MAGNETIC_FIELDS, "orbit kind": ORBITS, "actuator kind": ACTUATOR_KINDS,
            "study value generator": VALUE_GENERATORS}


def _environment_entries() -> list[str]:
    """The entries of :data:`ENVIRONMENT_VARIABLE`, blanks dropped."""
    return [entry.strip() for entry in os.environ.get(ENVIRONMENT_VARIABLE, "").split(",") if entry.strip()]


FILE_MODULE_PREFIX = "slewbench_plugin_"
"""A plugin file ``x.py`` is imported as the module ``slewbench_plugin_x``: a file named after a
module already imported (``controllers.py``, ``yaml.py``) must not replace it."""


def _import_file(path: str) -> ModuleType:
    """Import a ``.py`` file as the module :data:`FILE_MODULE_PREFIX` + its stem (kept in
    ``sys.modules``); a module already imported from that very file (the user's script imported it)
    is that module, not a second copy whose registrations would clash with the first's."""
    file = Path(path).expanduser()
    if not file.is_file():
        raise FileNotFoundError(f"no file {str(file)!r}")
    resolved = file.resolve()
    for module in list(sys.modules.values()):
        origin = getattr(module, "__file__", None)
        if origin is not None and Path(origin).resolve() == resolved:
            return module
    name = FILE_MODULE_PREFIX + file.stem
    spec = importlib.util.spec_from_file_location(name, file)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot import {str(file)!r} as a module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def _pending() -> list[tuple[str, str, Callable[[], Any]]]:
    """``(key, label, load)`` of every plugin not loaded yet: entry points first, then the variable's."""
    found: list[tuple[str, str, Callable[[], Any]]] = []
    for entry in sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=lambda e: (e.name, e.value)):
        distribution = getattr(entry, "dist", None)
        where = f" ({distribution.name} {distribution.version})" if distribution is not None else ""
        found.append((f"entry point {entry.name}={entry.value}",
                      f"entry point {entry.name!r} = {entry.value}{where}", entry.load))
    for text in _environment_entries():
        if text.endswith(".py"):
            found.append((f"{ENVIRONMENT_VARIABLE} {text}", f"{ENVIRONMENT_VARIABLE} file {text}",
                          functools.partial(_import_file, text)))
        elif "/" in text or os.sep in text or Path(text).is_file():  # imported as a module name, it was told
            # "No module named 'small'" and to give ./small.py (small.yaml), or a relative-import TypeError
            found.append((f"{ENVIRONMENT_VARIABLE} {text}", f"{ENVIRONMENT_VARIABLE} entry {text}",
                          functools.partial(_not_a_plugin, text)))
        else:
            found.append((f"{ENVIRONMENT_VARIABLE} {text}", f"{ENVIRONMENT_VARIABLE} module {text}",
                          functools.partial(importlib.import_module, text)))
    return [item for item in found if item[0] not in _LOADED]


def _not_a_plugin(text: str) -> None:
    """Refuse a ``SLEWBENCH_PLUGINS`` entry that is a path but not a ``.py`` file."""
    kind = "a directory" if Path(text).is_dir() else "a file" if Path(text).exists() else "a path"
    raise ValueError(f"{text} is {kind}, not a .py file or a module name: give the path of a .py file "
                     f"or a module importable from sys.path (mypackage.plugins)")


def _import_hint(label: str, error: BaseException) -> str:
    """What to check when a plugin's own module is not found."""
    if isinstance(error, ModuleNotFoundError) and label.startswith(f"{ENVIRONMENT_VARIABLE} module"):
        return (f" (is its directory on sys.path? the `slewbench` command does not add the current directory: "
                f"set PYTHONPATH, or give the file, {ENVIRONMENT_VARIABLE}=./{error.name or 'module'}.py)")
    return ""


_PACKAGES = ("ocp", "planners", "controllers", "scenarios")


def _owner(value: Any) -> str:
    """Who registered a name no plugin provided: slewbench, or the code of this process (a script
    that registered before the plugins loaded), by the module of the registered class."""
    module = str(getattr(value, "__module__", "") or "")
    return "slewbench" if module.split(".")[0] in _PACKAGES else f"code in this process ({module or 'unknown module'})"


def _load_one(label: str, load: Callable[[], Any], kinds: dict[str, MutableMapping[str, Any]]) -> LoadedPlugin:
    """Load one plugin, compare the registries before and after, and undo it on failure or a clash."""
    before = {kind: dict(registry) for kind, registry in kinds.items()}

    def undo() -> None:
        for kind, registry in kinds.items():
            for name in [name for name in registry if name not in before[kind]]:
                del registry[name]
            for name, value in before[kind].items():
                if registry.get(name) is not value:
                    registry[name] = value

    try:
        loaded = load()
        if isinstance(loaded, type):
            raise TypeError(f"it names the class {loaded.__name__}: name its module (which registers it) "
                            f"or a function of no arguments that registers it")
        if callable(loaded) and not isinstance(loaded, ModuleType):
            loaded()  # an entry point naming a function: it registers when called
    except (Exception, SystemExit) as error:  # any failure of a user's code (sys.exit too) is the plugin's
        undo()
        raise PluginError(f"plugin {label} failed to load: {type(error).__name__}: {error}"
                          f"{_import_hint(label, error)}") from error
    clashes = [f"{kind} {name!r} (already provided by {provider(kind, name) or _owner(value)})"
               for kind, registry in kinds.items() for name, value in before[kind].items()
               if name not in registry or registry[name] is not value]
    if clashes:
        undo()
        raise PluginError(f"plugin {label} registers a name already taken, refused: {'; '.join(clashes)}; "
                          f"register it under a name of its own (its class's `name`)")
    plugin = LoadedPlugin(label)
    for kind, registry in kinds.items():
        new = [name for name in registry if name not in before[kind]]
        if new:
            plugin.provided[kind] = new
    return plugin


def load_plugins() -> list[LoadedPlugin]:
    """Load every plugin not loaded yet: the entry points of :data:`ENTRY_POINT_GROUP`, then the
    modules and files of :data:`ENVIRONMENT_VARIABLE`.

    Each plugin is loaded once per process; a call after the first loads only plugins that
    appeared since (a variable changed, a distribution installed). A plugin that fails is not
    remembered, so a later call tries it again.

    Returns
    -------
    list of LoadedPlugin
        The plugins this call loaded (empty when all were loaded already).

    Raises
    ------
    PluginError
        A plugin that fails to import or run (its exception's type and message are in the
        message), or that registers a name already taken. The plugins before it stay loaded; it and
        those after it are not.
    """
    global _LOADING
    with _LOCK:  # another thread waits until the plugins are registered
        if _LOADING:
            return []
        _LOADING = True
        try:
            kinds = registries()
            done = []
            for key, label, load in _pending():
                _LOADED[key] = plugin = _load_one(label, load, kinds)
                done.append(plugin)
            return done
        finally:
            _LOADING = False


def loaded_plugins() -> list[LoadedPlugin]:
    """The plugins loaded in this process, in the order they were loaded.

    Returns
    -------
    list of LoadedPlugin
        Each with the names it registered.
    """
    return list(_LOADED.values())


def provider(kind: str, name: str) -> str | None:
    """The plugin that registered ``name`` in the registry of ``kind``, if a plugin did.

    Parameters
    ----------
    kind : str
        A key of :func:`registries` (``"planner"``).
    name : str
        A registered name.

    Returns
    -------
    str or None
        The plugin's :attr:`LoadedPlugin.label`; ``None`` for a name slewbench ships or code registered.
    """
    for plugin in _LOADED.values():
        if name in plugin.provided.get(kind, ()):
            return plugin.label
    return None

