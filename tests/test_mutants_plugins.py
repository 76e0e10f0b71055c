"""Gaps the mutation check found in plugin loading (scenarios.schema.plugins), in this process.

Each plugin is loaded once per process (a second call loads nothing and keeps what the first
recorded), and a plugin that uses the library face while it loads (which calls
:func:`~scenarios.schema.plugins.load_plugins` again) gets nothing more to load. The plugins are
files written here; the process's plugin record is isolated per test and the registered names are
taken out again.
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

from planners import PLANNERS
from scenarios.schema import plugins


@pytest.fixture
def isolated(monkeypatch: pytest.MonkeyPatch):
    """An empty plugin record and no entry points; the planners registered removed at the end."""
    monkeypatch.setattr(plugins, "_LOADED", {})
    monkeypatch.setattr(plugins.metadata, "entry_points", lambda group=None: [])
    before = set(PLANNERS)
    modules = set(sys.modules)
    yield monkeypatch
    for name in set(PLANNERS) - before:
        del PLANNERS[name]
    for name in set(sys.modules) - modules:
        if name.startswith(plugins.FILE_MODULE_PREFIX):
            del sys.modules[name]


def test_a_plugin_is_loaded_once_and_stays_the_provider(isolated, tmp_path: Path) -> None:
    (tmp_path / "once.py").write_text("from planners import PLANNERS\nPLANNERS['mutants_once'] = PLANNERS['eigenaxis']\n")
    isolated.setenv(plugins.ENVIRONMENT_VARIABLE, str(tmp_path / "once.py"))
    first = plugins.load_plugins()
    assert [p.provided for p in first] == [{"planner": ["mutants_once"]}]
    assert plugins.load_plugins() == []  # nothing new: not loaded again
    assert plugins.provider("planner", "mutants_once") == f"SLEWBENCH_PLUGINS file {tmp_path / 'once.py'}"
    assert [p.provided for p in plugins.loaded_plugins()] == [{"planner": ["mutants_once"]}]


def test_a_plugin_that_loads_plugins_while_loading_gets_nothing_more(isolated, tmp_path: Path) -> None:
    (tmp_path / "nested.py").write_text("from planners import PLANNERS\nfrom scenarios.schema import plugins\n"
                                        "PLANNERS['mutants_nested'] = PLANNERS['eigenaxis']\n"
                                        "NESTED = plugins.load_plugins()\n")
    isolated.setenv(plugins.ENVIRONMENT_VARIABLE, str(tmp_path / "nested.py"))
    loaded = plugins.load_plugins()
    assert [p.provided for p in loaded] == [{"planner": ["mutants_nested"]}]
    assert sys.modules[plugins.FILE_MODULE_PREFIX + "nested"].NESTED == []
