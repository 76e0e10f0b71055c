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


@pytest.mark.parametrize("argv", [["validate", "{file}"], ["list"], ["schema"]])
def test_an_interrupted_command_that_only_prints_says_nothing_was_written(argv, tmp_path, monkeypatch, capsys):
    """Ctrl-C in validate (a 100,000-case study takes minutes to check), list or schema said 'results
    not written or marked incomplete in the output manifest': there are no results nor manifest."""
    from scenarios.cli import commands

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    parser = commands.build_parser
    monkeypatch.setattr(commands, "build_parser", lambda: _with_handler(parser(), interrupt))
    (tmp_path / "s.yaml").write_text("name: x\n")
    assert commands.main([part.format(file=tmp_path / "s.yaml") for part in argv]) == 1
    assert capsys.readouterr().err.strip() == "slewbench: interrupted; nothing written"


def _with_handler(parser, handler):
    """``parser`` with every subcommand's handler replaced by ``handler``."""
    sub = next(action for action in parser._actions if action.dest == "command")
    for choice in sub.choices.values():
        choice.set_defaults(handler=handler)
    return parser
