"""Apply hand-written mutations one at a time and report which the chosen tests catch.

The checkout is never changed: its files (tracked and untracked, without ``.git``, caches and
results) are copied into a temporary folder once; each mutation replaces one exact snippet of one
file there (found by text, so it survives line moves; it must occur exactly once), runs the
mutation's tests with pytest in that copy (``-x``, first failure stops), and puts the file back
before the next one, whatever happens (a failure, a timeout, Ctrl-C). The copy is removed at the end.

Outcomes: ``caught`` (the tests failed, or ran past the time limit), ``survived`` (they passed),
``equivalent`` (the mutation is listed as not changing behaviour, with the reason; it is applied
and run all the same, and reported ``EQUIVALENT?`` if its tests fail, which would mean the reason
is wrong), ``error`` (the snippet is not found exactly once: the list needs updating).

Usage::

    python -m tests.mutation                  # every mutation, a table at the end
    python -m tests.mutation -k nlp -k radau  # those whose name contains one of the words
    python -m tests.mutation --list           # the mutations and their tests
    python -m tests.mutation --markdown out.md

Exit status: 0 when no mutation survived and none is in error, 1 otherwise.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
IGNORED = shutil.ignore_patterns(".git", "__pycache__", "*.pyc", ".pytest_cache", ".mypy_cache", "results",
                                 "_build", "*.so", ".hypothesis")


@dataclass(frozen=True)
class Mutation:
    """One plausible bug.

    Parameters
    ----------
    name : str
        Short unique name (``area-what``).
    file : str
        Path of the file, relative to the checkout.
    find : str
        Exact source text to replace; it must occur exactly once in the file.
    replace : str
        What it becomes.
    tests : tuple of str
        pytest arguments (files, ``file::test`` node ids, ``-k`` expressions) that should catch it;
        a handful of seconds.
    equivalent : str
        Empty, or why the mutation cannot change behaviour (then it is expected to survive).
    """

    name: str
    file: str
    find: str
    replace: str
    tests: tuple[str, ...]
    equivalent: str = ""


@dataclass
class Outcome:
    """The result of one mutation: ``caught``, ``survived``, ``equivalent``, ``EQUIVALENT?`` or
    ``error``, the seconds it took and what pytest (or the tool) said last."""

    mutation: Mutation
    result: str
    seconds: float
    detail: str = ""


def copy_tree(source: Path, target: Path) -> Path:
    """Copy the checkout ``source`` to ``target/tree`` (no VCS data, caches or results)."""
    tree = target / "tree"
    shutil.copytree(source, tree, ignore=IGNORED, symlinks=True)
    return tree


def run_tests(tree: Path, tests: Sequence[str], timeout: float) -> tuple[bool | None, str]:
    """Run pytest on ``tests`` in ``tree``: True if they pass, False if one fails, None on timeout."""
    command = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-o", "addopts=",
               "-m", "not slow", "--no-header", *tests]
    environment = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    try:
        completed = subprocess.run(command, cwd=tree, capture_output=True, text=True, timeout=timeout,
                                   env=environment, check=False)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {timeout:g} s"
    lines = [line for line in completed.stdout.strip().splitlines() if line.strip()]
    last = lines[-1] if lines else completed.stderr.strip()[-200:]
    if completed.returncode == 5:  # no tests collected: the list names tests that do not exist
        raise LookupError(f"no tests collected for {list(tests)}: {last}")
    return completed.returncode == 0, last


def apply_and_test(tree: Path, mutation: Mutation, timeout: float) -> Outcome:
    """Apply ``mutation`` in ``tree``, run its tests and restore the file, always."""
    path = tree / mutation.file
    start = time.perf_counter()
    try:
        original = path.read_text()
    except OSError as error:
        return Outcome(mutation, "error", 0.0, f"cannot read {mutation.file}: {error}")
    count = original.count(mutation.find)
    if count != 1:
        return Outcome(mutation, "error", 0.0, f"snippet found {count} times in {mutation.file}")
    try:
        path.write_text(original.replace(mutation.find, mutation.replace))
        try:
            passed, detail = run_tests(tree, mutation.tests, timeout)
        except LookupError as error:
            return Outcome(mutation, "error", time.perf_counter() - start, str(error))
    finally:
        path.write_text(original)
    if mutation.equivalent:
        result = "equivalent" if passed else "EQUIVALENT?"
    else:
        result = "survived" if passed else "caught"
    return Outcome(mutation, result, time.perf_counter() - start, detail)


def run(mutations: Iterable[Mutation], root: Path = ROOT, timeout: float = 300.0, baseline: bool = True,
        echo: bool = True) -> list[Outcome]:
    """Run ``mutations`` on a temporary copy of ``root``.

    Parameters
    ----------
    mutations : iterable of Mutation
        The mutations, applied one at a time.
    root : Path
        The checkout (never changed).
    timeout : float
        Seconds allowed to one mutation's tests (past it the mutation counts as caught).
    baseline : bool
        First run the union of their tests unmutated: they must pass, or nothing can be judged.
    echo : bool
        Print one line per mutation as it finishes.

    Returns
    -------
    list of Outcome
    """
    mutations = list(mutations)
    names = [m.name for m in mutations]
    if len(set(names)) != len(names):
        raise ValueError("mutation names must be unique")
    with tempfile.TemporaryDirectory(prefix="slewbench-mutation-") as folder:
        tree = copy_tree(root, Path(folder))
        if baseline:
            tests = sorted({test for m in mutations for test in m.tests})
            passed, detail = run_tests(tree, tests, timeout * 4)
            if not passed:
                raise RuntimeError(f"the chosen tests fail without any mutation: {detail}")
        outcomes = []
        for mutation in mutations:
            outcome = apply_and_test(tree, mutation, timeout)
            outcomes.append(outcome)
            if echo:
                print(f"{outcome.result:>11}  {outcome.seconds:6.1f} s  {mutation.name}  ({outcome.detail[:90]})",
                      flush=True)
        return outcomes


def table(outcomes: Sequence[Outcome]) -> str:
    """The outcomes as a Markdown table with a summary line."""
    lines = ["| mutation | file | result | seconds |", "|---|---|---|---|"]
    for o in outcomes:
        lines.append(f"| {o.mutation.name} | {o.mutation.file} | {o.result} | {o.seconds:.1f} |")
    counts = {key: sum(o.result == key for o in outcomes)
              for key in ("caught", "survived", "equivalent", "EQUIVALENT?", "error")}
    judged = counts["caught"] + counts["survived"]
    rate = 100.0 * counts["caught"] / judged if judged else 0.0
    summary = (f"{len(outcomes)} mutations: {counts['caught']} caught, {counts['survived']} survived, "
               f"{counts['equivalent']} equivalent ({counts['EQUIVALENT?']} listed as equivalent but caught), "
               f"{counts['error']} in error; caught {rate:.1f} % of those that change behaviour.")
    lines += ["", summary]
    survivors = [o for o in outcomes if o.result in ("survived", "error", "EQUIVALENT?")]
    if survivors:
        lines += ["", "To look at:"] + [f"- {o.mutation.name} ({o.result}): {o.detail}" for o in survivors]
    equivalents = [o for o in outcomes if o.result == "equivalent"]
    if equivalents:
        lines += ["", "Equivalent:"] + [f"- {o.mutation.name}: {o.mutation.equivalent}" for o in equivalents]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """The command line (module docstring)."""
    from tests.mutation.mutations import MUTATIONS

    parser = argparse.ArgumentParser(prog="python -m tests.mutation", description=__doc__.split("\n\n")[0])
    parser.add_argument("-k", action="append", default=[], metavar="WORD",
                        help="only mutations whose name contains WORD (repeatable)")
    parser.add_argument("--list", action="store_true", help="list the mutations and their tests, run nothing")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per mutation (default 300)")
    parser.add_argument("--no-baseline", action="store_true", help="skip the unmutated run of the chosen tests")
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = parser.parse_args(argv)
    chosen = [m for m in MUTATIONS if not args.k or any(word in m.name for word in args.k)]
    if args.list:
        for m in chosen:
            note = f"  [equivalent: {m.equivalent}]" if m.equivalent else ""
            print(f"{m.name}: {m.file}: {' '.join(m.tests)}{note}")
        return 0
    try:
        outcomes = run(chosen, timeout=args.timeout, baseline=not args.no_baseline)
    except KeyboardInterrupt:
        print("interrupted: the checkout was not changed", file=sys.stderr)
        return 130
    report = table(outcomes)
    print(report)
    if args.markdown:
        args.markdown.write_text(report + "\n")
    return 0 if all(o.result in ("caught", "equivalent") for o in outcomes) else 1
