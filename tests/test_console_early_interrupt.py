"""A Ctrl-C while ``slewbench`` still imports its model: nothing is written, and the exit status is the
one :mod:`scenarios.cli.status` declares for the command (a sweep's or a table's 130, which says
"resume it"; 1 for the other commands)."""
from __future__ import annotations

import sys
import types

import pytest

from scenarios import console


class _Interrupting(types.ModuleType):
    """Stands for ``scenarios.cli.commands`` while it imports: Ctrl-C arrives."""

    def __getattr__(self, name):
        raise KeyboardInterrupt


@pytest.mark.parametrize(("argv", "status"), [(["sweep", "study.yaml"], 130), (["table", "scenario.yaml"], 130), (["run", "scenario.yaml", "--no-plots"], 1),
                                              (["validate", "scenario.yaml"], 1)])
def test_interrupt_while_the_model_imports(monkeypatch, capsys, argv, status):
    monkeypatch.setitem(sys.modules, "scenarios.cli.commands", _Interrupting("scenarios.cli.commands"))
    assert console.main(argv) == status
    assert capsys.readouterr().err.strip() == "slewbench: interrupted; nothing written"
