"""The exit statuses of the ``slewbench`` command line, one set for every command, and the argument
handling every command shares (directory arguments, values that start with a minus sign).

May import: nothing of slewbench.
"""
from __future__ import annotations

import argparse
import re

__all__ = ["CRASH_REASONS_SHOWN", "EXIT_BAD_OUTPUT", "EXIT_BAD_SCENARIO", "EXIT_CRASHED", "EXIT_INTERNAL",
           "EXIT_INTERRUPTED", "EXIT_NOT_OK", "EXIT_OK", "INTERRUPTED_STATUS", "SWEEP_CRASH_CAUSES", "attached_values",
           "crash_report", "directory_argument", "interrupted_status", "workers_note"]

EXIT_OK = 0
"""The command completed (a run's failed and violated rows, a table's entries that are not ok
included: they are results), unless ``run --strict`` found a row, or ``table --strict`` an entry,
that is not ok, or a sweep's cases crashed (:data:`EXIT_CRASHED`)."""
EXIT_INTERNAL = 1
"""An internal error (a bug), or a run interrupted by Ctrl-C or SIGTERM."""
EXIT_NOT_OK = 1
"""``slewbench run --strict``: the run completed and wrote its results, and some row is not ``ok``
(``violated``, ``infeasible`` or ``failed``); ``slewbench table --strict``: the table's files are written, and some
entry of the table or of its held-out grid is not ``ok``; ``slewbench validate --strict``: the
scenario is valid, but a note says no row can be ok (an end point already breaks a requirement, a
slew longer than ``maneuver.duration``: ``infeasible``; a boundary rate above the rate bound:
``violated``): for users' continuous integration."""
EXIT_CRASHED = 1
"""``slewbench sweep``: every case ran and the tables are written, but some cases crashed (raised,
ran out of ``case_timeout_s`` or killed their worker): they have no result, and ``--resume`` runs
them again. ``slewbench table`` alike: its files are written, some entries crashed (raised or killed
their worker) or timed out (status ``timed_out``: the planner still solving when ``case_timeout_s``
ran out), and the same command run again into the same ``--out`` computes them again (a timed-out
one given more time with ``--case-timeout``). A numerical failure is a ``failed`` row (entry), a
result: it does not set this status."""
EXIT_BAD_SCENARIO = 2
"""A bad scenario or study file (or key of ``slewbench schema``): nothing was written."""
EXIT_BAD_OUTPUT = 2
"""An output location slewbench must not or cannot write to: nothing was touched."""
EXIT_INTERRUPTED = 130
"""A sweep stopped before every case finished (rerun it with ``--resume``), or a slew table before
every entry did (run the same command again into the same ``--out``)."""
INTERRUPTED_STATUS = {"sweep": EXIT_INTERRUPTED, "table": EXIT_INTERRUPTED}
"""The exit status of a command interrupted by Ctrl-C or SIGTERM, for the commands whose work is kept
and resumed; any other command's is :data:`EXIT_INTERNAL` (:func:`interrupted_status`)."""


def interrupted_status(command: str | None) -> int:
    """The exit status of ``command`` (``sweep``, ``run``, …) interrupted by Ctrl-C or SIGTERM.

    Parameters
    ----------
    command : str or None
        The command's name (the first argument of ``slewbench``); ``None`` when none was given.

    Returns
    -------
    int
        :data:`EXIT_INTERRUPTED` for a command in :data:`INTERRUPTED_STATUS`, else :data:`EXIT_INTERNAL`.
    """
    return INTERRUPTED_STATUS.get(command or "", EXIT_INTERNAL)


CRASH_REASONS_SHOWN = 3
"""Distinct reasons the closing message of a sweep or a table gives for its crashed cases or
entries (the most frequent first)."""


SWEEP_CRASH_CAUSES = "raised, ran out of case_timeout_s or killed their worker"
"""What makes a case ``crashed`` (a sweep's; a slew table's timed-out entries have their own status)."""


def crash_report(reasons: list[str], total: int, noun: tuple[str, str], where: str, consequence: str,
                 command: str, causes: str = SWEEP_CRASH_CAUSES) -> str:
    """What a command whose cases crashed says last (on standard error): how many, why, and how to
    run them again (:data:`EXIT_CRASHED`).

    Parameters
    ----------
    reasons : list of str
        One message per crashed case, in the order met (an empty one reads "no message").
    total : int
        The number of cases.
    noun : tuple of str
        The case's name, singular and plural (``("case", "cases")``, ``("entry", "entries")``).
    where : str
        The file whose ``status`` column shows them crashed (``cases.csv``).
    consequence : str
        What their missing results mean for the outputs.
    command : str
        The command that runs them again.
    causes : str, optional
        What makes one crashed, said in brackets: :data:`SWEEP_CRASH_CAUSES` by default; a slew
        table's ``"raised or killed their worker"`` (its entries that ran out of time are
        ``timed_out``, reported apart).

    Returns
    -------
    str
        ``slewbench: N of M <nouns> crashed ...``, the :data:`CRASH_REASONS_SHOWN` most frequent
        reasons with their counts, and ``command``; empty when none crashed.
    """
    if not reasons:
        return ""
    counts: dict[str, int] = {}
    for reason in reasons:
        counts[reason or "no message"] = counts.get(reason or "no message", 0) + 1
    ranked = sorted(counts.items(), key=lambda item: -item[1])  # stable: equal counts in the order met

    def many(count: int) -> str:
        return f"{count} {noun[0] if count == 1 else noun[1]}"

    lines = [(f"slewbench: {len(reasons)} of {many(total)} crashed ({causes}): they have no result (status crashed "
              f"in {where}; {consequence}). Why:")]
    lines += [f"  {many(count)}: {reason}" for reason, count in ranked[:CRASH_REASONS_SHOWN]]
    if len(ranked) > CRASH_REASONS_SHOWN:
        lines.append(f"  ... and {len(ranked) - CRASH_REASONS_SHOWN} other reason(s) ({where}, status crashed)")
    lines += [f"Run them again (the {noun[1]} already stored are kept) with:", f"  {command}"]
    return "\n".join(lines)


def directory_argument(text: str) -> str:
    """An output directory given on the command line (``argparse`` ``type``): refuses an empty one.

    ``--out ""`` used to fall back to the default ``results/<name>`` without a word; ``--out -``
    (a dash usually means standard output) made a directory named ``-``.

    Parameters
    ----------
    text : str
        The argument as given.

    Returns
    -------
    str
        ``text``, unchanged.

    Raises
    ------
    argparse.ArgumentTypeError
        For an empty or blank path, or ``-`` (argparse exits 2 with the option's name).
    """
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path: give the output directory")
    if text.strip() == "-":
        raise argparse.ArgumentTypeError("'-' is not standard output here: slewbench writes a directory of files, "
                                         "give its path (./- for a directory named '-')")
    return text


_NUMBERS = re.compile(r"-\.?\d[\d.eE+\-]*(,[\d.eE+\-]*)*")
"""A number or comma-separated list of numbers whose first one is negative."""


def attached_values(argv: list[str], parser: argparse.ArgumentParser) -> list[str]:
    """The arguments with an option's value that starts with a minus sign attached to it.

    ``argparse`` reads ``--angles -10,90`` as two options (it takes a lone negative number such as
    ``-10`` as a value, not a list), and stops with "expected one argument" instead of checking
    the value. Such a value becomes ``--angles=-10,90``, which the option then checks.

    Parameters
    ----------
    argv : list of str
        The arguments, without the program name.
    parser : argparse.ArgumentParser
        The parser they are for: only its long options that take a value (its sub-commands'
        included) are joined to what follows them; a flag (``--no-plots -1``, ``-1`` a file) is not.

    Returns
    -------
    list of str
        The same arguments, each long option that takes a value, written without ``=`` and
        followed by a number or a comma-separated list of numbers that starts with a minus sign,
        joined to it by ``=``; nothing after ``--``.
    """
    valued = _valued_options(parser)
    out: list[str] = []
    for index, argument in enumerate(argv):
        if argument == "--":  # the rest is positional
            return out + argv[index:]
        if out and out[-1] in valued and _NUMBERS.fullmatch(argument):
            out[-1] = f"{out[-1]}={argument}"
        else:
            out.append(argument)
    return out


def _valued_options(parser: argparse.ArgumentParser) -> set[str]:
    """The long option strings of ``parser`` and its sub-commands that take a value."""
    found: set[str] = set()
    for action in parser._actions:  # argparse has no public list of a parser's actions
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                found |= _valued_options(sub)
        elif action.nargs != 0:
            found.update(option for option in action.option_strings if option.startswith("--"))
    return found


def workers_note(workers: int | None, cores: int, option: str, units: str) -> str | None:
    """The note of a command given more local workers than cores: not an error, but each of its
    cases then shares a core, runs slower, and its plan and simulation times are inflated.

    Parameters
    ----------
    workers : int or None
        The workers asked for (None: the default, one per core).
    cores : int
        The cores this process may run on (its CPU affinity, where the system says it).
    option : str
        Where the number was given (``--workers``, ``execution.workers``).
    units : str
        What the workers run, plural (``cases``, ``entries``).

    Returns
    -------
    str or None
        ``note: --workers 8 is more than the 2 cores ...``; None when ``workers`` is at most ``cores``.
    """
    if workers is None or workers <= cores:
        return None
    return (f"note: {option} {workers} is more than the {cores} core{'s' if cores != 1 else ''} this process may "
            f"run on: the {units} share them, so each runs slower and its plan and simulation times in the tables "
            "are inflated")
