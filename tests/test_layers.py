"""The house's structure: which module may import which, faces, ``__all__`` and docstrings.

* No import runs back up. Packages: ``ocp`` < ``planners`` < ``controllers`` < ``scenarios``. Inside
  them the layers of :data:`GROUPS` may import what :data:`ALLOWED` lists (``ocp``: its top-level
  modules < ``dynamics`` < ``geometry``, ``simulation``, ``transcription`` (which imports ``geometry``);
  ``nlp`` beside them; ``scenarios``: errors < requirements < schema < output < runner < codegen < study < bench, slewtable < cli < console). Every import counts,
  inside functions too, except those under ``if TYPE_CHECKING:``; importing a face counts as
  importing every module it covers. A face may import its own package's modules.
* A module's ``__all__`` lists only names it defines (faces excepted); no docstring or comment says
  "split from" or "re-export"; every face has a docstring and an ``__all__`` whose names resolve.
* Every "May import:" of a face agrees with the table and with the imports of its modules.

Each rule is also run on a tree with a planted breach, which it must report.
"""
from __future__ import annotations

import ast
import importlib
import re
import types
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("ocp", "planners", "controllers", "scenarios")
"""From the bottom up: a package may import those before it."""

GROUPS: dict[str, tuple[str, ...]] = {
    # ocp: the top-level modules, then the subpackages
    "ocp": ("ocp.errors", "ocp.options", "ocp.quat", "ocp.quat_casadi", "ocp.cache", "ocp.fast_call", "ocp.native",
            "ocp.metrics"),
    "ocp.dynamics": ("ocp.dynamics",),
    "ocp.geometry": ("ocp.geometry",),
    "ocp.estimation": ("ocp.estimation",),
    "ocp.simulation": ("ocp.simulation",),
    "ocp.transcription": ("ocp.transcription",),
    "ocp.nlp": ("ocp.nlp",),
    # planners: the contract and the planners of one module, then the subpackages
    "planners": ("planners.errors", "planners.base", "planners.problem", "planners.reference",
                 "planners.registry", "planners.capabilities", "planners.conformance", "planners.torque_free", "planners.eigenaxis",
                 "planners.spin_extremal", "planners.natural_motion", "planners.shape_polynomial"),
    "planners.collocation": ("planners.collocation",),
    "planners.costate": ("planners.costate",),
    # controllers: the contract, its checks, then each family of laws
    "controllers.contract": ("controllers.errors", "controllers.allocation", "controllers.base"),
    "controllers.conformance": ("controllers.conformance",),
    "controllers.none": ("controllers.none",),
    "controllers.tracking": ("controllers.tracking",),
    "controllers.detumbling": ("controllers.detumbling",),
    "controllers.two_wheel": ("controllers.two_wheel",),
    # scenarios, from the bottom up
    "scenarios.errors": ("scenarios.errors", "scenarios._faces"),
    "scenarios.requirements": ("scenarios.requirements",),
    "scenarios.schema": ("scenarios.schema",),
    "scenarios.output": ("scenarios.output",),
    "scenarios.runner": ("scenarios.runner",),
    "scenarios.codegen": ("scenarios.codegen",),
    "scenarios.study": ("scenarios.study",),
    "scenarios.bench": ("scenarios.bench",),
    "scenarios.slewtable": ("scenarios.slewtable",),
    "scenarios.cli": ("scenarios.cli",),
    "scenarios.console": ("scenarios.console",),
}
"""Layers inside the packages, by module (or subpackage) name."""

_SCENARIOS = ["scenarios.errors", "scenarios.requirements", "scenarios.schema", "scenarios.output", "scenarios.runner", "scenarios.codegen",
              "scenarios.study", "scenarios.bench", "scenarios.slewtable", "scenarios.cli", "scenarios.console"]
ALLOWED: dict[str, set[str]] = {
    "ocp": {"ocp"},
    "ocp.dynamics": {"ocp", "ocp.dynamics"},
    "ocp.geometry": {"ocp", "ocp.dynamics", "ocp.geometry"},
    "ocp.estimation": {"ocp", "ocp.dynamics", "ocp.estimation"},
    "ocp.simulation": {"ocp", "ocp.dynamics", "ocp.estimation", "ocp.simulation"},
    "ocp.transcription": {"ocp", "ocp.dynamics", "ocp.geometry", "ocp.transcription"},
    "ocp.nlp": {"ocp", "ocp.nlp"},
    "planners": {"planners"},
    "planners.collocation": {"planners", "planners.collocation"},
    "planners.costate": {"planners", "planners.costate"},
    "controllers.contract": {"controllers.contract"},
    "controllers.conformance": {"controllers.contract", "controllers.conformance"},
    **{family: {"controllers.contract", family}
       for family in ("controllers.none", "controllers.tracking", "controllers.detumbling", "controllers.two_wheel")},
    **{layer: set(_SCENARIOS[:index + 1]) for index, layer in enumerate(_SCENARIOS)},
}
"""Layers of its own package that a layer may import (every module of a package before it too)."""

KNOWN_BREACHES: dict[str, str] = {}
"""Breaches of the rules reported to the lead and not fixed yet (each must still occur)."""


@dataclass(frozen=True)
class Module:
    """One module of the tree: its name, source and whether it is a package's ``__init__``."""

    name: str
    source: str
    face: bool


def source_tree(root: Path = ROOT) -> dict[str, Module]:
    """Every module of the four packages, by dotted name (a package by its own name)."""
    tree = {}
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            parts = path.relative_to(root).with_suffix("").parts
            face = parts[-1] == "__init__"
            name = ".".join(parts[:-1] if face else parts)
            tree[name] = Module(name, path.read_text(), face)
    return tree


TREE = source_tree()


def _type_checking(node: ast.AST) -> bool:
    if not isinstance(node, ast.If):
        return False
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _nodes(node: ast.AST):
    """Every node under ``node`` except the bodies of ``if TYPE_CHECKING:``."""
    for child in ast.iter_child_nodes(node):
        if _type_checking(child):
            for other in child.orelse:  # type: ignore[attr-defined]
                yield other
                yield from _nodes(other)
            continue
        yield child
        yield from _nodes(child)


@cache
def _raw_imports(source: str, package: str) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """``(module, names)`` of every import statement (``names`` empty for ``import x``), relative
    ones resolved against ``package``, outside ``if TYPE_CHECKING:``."""
    found: list[tuple[str, tuple[str, ...]]] = []
    for node in _nodes(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(alias.name, ()) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
            found.append((base, tuple(alias.name for alias in node.names)))
    return tuple(found)


def imports(module: Module, tree: dict[str, Module]) -> list[str]:
    """The modules of the tree that ``module`` imports (``from X import m`` of a submodule ``m`` is
    ``X.m``; of a name, ``X``), at any depth but under ``if TYPE_CHECKING:``."""
    found = []
    package = module.name if module.face else module.name.rpartition(".")[0]
    for base, names in _raw_imports(module.source, package):
        found += [f"{base}.{name}" if f"{base}.{name}" in tree else base for name in names] if names else [base]
    return [name for name in dict.fromkeys(found) if name.split(".")[0] in PACKAGES]


@cache
def group(name: str) -> str | None:
    """The layer of a module (the longest matching prefix of :data:`GROUPS`), ``None`` for the
    faces of the four packages."""
    best, length = None, -1
    for layer, members in GROUPS.items():
        for member in members:
            if (name == member or name.startswith(member + ".")) and len(member) > length:
                best, length = layer, len(member)
    return best


def covered(name: str, tree: dict[str, Module]) -> list[str]:
    """What importing ``name`` imports: a module itself; a face, every module under it."""
    if not tree[name].face:
        return [name]
    return [other for other in tree if other.startswith(name + ".") and not tree[other].face]


def breaches(tree: dict[str, Module]) -> dict[str, str]:
    """Every import that runs back up, as ``"importer imports imported"`` to the layers involved."""
    found = {}
    for module in tree.values():
        package = module.name.split(".")[0]
        mine = group(module.name)
        for imported in imports(module, tree):
            if imported not in tree:
                found[f"{module.name} imports {imported}"] = "no such module"
                continue
            other = imported.split(".")[0]
            if PACKAGES.index(other) < PACKAGES.index(package):
                continue
            if PACKAGES.index(other) > PACKAGES.index(package):
                found[f"{module.name} imports {imported}"] = f"{package} may not import {other}"
                continue
            if module.face and (imported == module.name or imported.startswith(module.name + ".")):
                continue  # a face imports its own modules
            if mine is None:
                continue  # the package's face: its own package
            for target in covered(imported, tree):
                if group(target) not in ALLOWED[mine]:
                    found[f"{module.name} imports {imported}"] = (
                        f"layer {mine} may import {sorted(ALLOWED[mine])}, not {group(target)} ({target})")
                    break
    return found


def test_every_module_belongs_to_a_layer():
    lost = [name for name in TREE if group(name) is None and name not in PACKAGES]
    assert not lost, f"modules outside every layer of GROUPS (add them to the table): {lost}"


def test_no_import_runs_back_up():
    found = breaches(TREE)
    new = {k: v for k, v in found.items() if k not in KNOWN_BREACHES}
    assert not new, "imports that run back up:\n" + "\n".join(f"{k}: {v}" for k, v in new.items())
    fixed = set(KNOWN_BREACHES) - set(found)
    assert not fixed, f"fixed, remove from KNOWN_BREACHES: {fixed}"


def _planted(name: str, extra: str, tree: dict[str, Module] = TREE) -> dict[str, Module]:
    module = tree[name]
    return {**tree, name: Module(name, module.source + "\n" + extra + "\n", module.face)}


@pytest.mark.parametrize("name,extra,breach", [
    ("ocp.dynamics.model", "from ocp.simulation.simulator import Simulator", "ocp.dynamics.model imports ocp.simulation.simulator"),
    ("ocp.simulation.compiled", "def f():\n    import ocp.transcription.base", "ocp.simulation.compiled imports ocp.transcription.base"),
    ("ocp.transcription.problem", "from ocp.simulation import Simulator", "ocp.transcription.problem imports ocp.simulation"),
    ("ocp.nlp.solve", "from ocp.dynamics import model", "ocp.nlp.solve imports ocp.dynamics.model"),
    ("ocp.metrics", "from ocp import Simulator", "ocp.metrics imports ocp"),
    ("planners.base", "from controllers.base import Controller", "planners.base imports controllers.base"),
    ("controllers.detumbling.bdot", "from controllers.tracking import eigenaxis_pd", "controllers.detumbling.bdot imports controllers.tracking.eigenaxis_pd"),
    ("scenarios.output.tables", "from scenarios.runner import RunResults", "scenarios.output.tables imports scenarios.runner"),
    ("scenarios.schema.node", "from . import loader\nfrom ..study import spec", "scenarios.schema.node imports scenarios.study.spec"),
])
def test_a_planted_upward_import_is_caught(name, extra, breach):
    assert breach not in breaches(TREE)
    assert breach in breaches(_planted(name, extra))


def test_type_checking_imports_and_own_modules_do_not_count():
    tree = _planted("ocp.dynamics.model", "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                                          "    from ocp.simulation.simulator import Simulator")
    assert not any(k.startswith("ocp.dynamics.model ") for k in breaches(tree))
    tree = _planted("ocp.dynamics", "from ocp.dynamics.layout import control_layout")
    assert not any(k.startswith("ocp.dynamics ") for k in breaches(tree))


# --- faces, __all__ and docstrings --------------------------------------------------------------

@cache
def _all(module: Module) -> list[str] | None:
    for node in ast.parse(module.source).body:
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(node, ast.AnnAssign) else []
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return list(ast.literal_eval(node.value))  # type: ignore[arg-type]
    return None


@cache
def _defined(module: Module) -> set[str]:
    """Names a module's own top-level statements define (not the names it imports)."""
    names: set[str] = set()
    tree = ast.parse(module.source)
    top = [node for statement in tree.body for node in ([statement] if not _type_checking(statement) else [])]
    for node in top:  # module level only: a name bound inside a function is not the module's
        if isinstance(node, ast.If):  # e.g. a platform branch: its direct statements
            top.extend(node.body + node.orelse)
            continue
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
    return names


def foreign_names(tree: dict[str, Module]) -> dict[str, list[str]]:
    """Names in the ``__all__`` of a module (not a face) that the module does not define."""
    found = {}
    for module in tree.values():
        listed = _all(module)
        if module.face or listed is None:
            continue
        foreign = [name for name in listed if name not in _defined(module)]
        if foreign:
            found[module.name] = foreign
    return found


SPLIT = re.compile(r"split\s+from|re-?\s*exports?\b", re.IGNORECASE)


def split_remarks(tree: dict[str, Module]) -> dict[str, list[str]]:
    """Lines that say a module was split from another or re-exports names."""
    return {m.name: [line.strip() for line in m.source.splitlines() if SPLIT.search(line)]
            for m in tree.values() if SPLIT.search(m.source)}


def test_no_module_lists_names_it_does_not_define():
    found = foreign_names(TREE)
    assert not found, f"__all__ lists names defined elsewhere (import them from their module): {found}"


def test_no_docstring_or_comment_speaks_of_splits_or_re_exports():
    found = split_remarks(TREE)
    assert not found, f"say what the module is, not where it came from: {found}"


def test_planted_re_export_and_split_remark_are_caught():
    tree = _planted("ocp.metrics", "__all__ = ['compute_metrics', 'quat']")
    assert foreign_names(tree) == {"ocp.metrics": ["quat"]}
    tree = _planted("ocp.metrics", "def _helper():\n    above = 1\n    return above\n__all__ = ['compute_metrics', 'above']")
    assert foreign_names(tree) == {"ocp.metrics": ["above"]}  # a function's local is not the module's name
    tree = _planted("ocp.metrics", "# split from ocp.quat; it re-exports normalize")
    assert "ocp.metrics" in split_remarks(tree)


FACES = [name for name, module in TREE.items() if module.face]


def face_problems(module: types.ModuleType) -> list[str]:
    """What a face lacks: a docstring, an ``__all__``, names of it that resolve (lazy ones imported)."""
    problems = []
    if not module.__doc__ or len(module.__doc__.strip()) < 40:
        problems.append("no docstring saying what lives there")
    listed = getattr(module, "__all__", None)
    if not isinstance(listed, list) or not listed:
        return [*problems, "no __all__"]
    missing = [name for name in listed if not hasattr(module, name)]
    if missing:
        problems.append(f"__all__ names that do not resolve: {missing}")
    shadowed = [name for name in listed if name not in missing and isinstance(getattr(module, name), types.ModuleType)]
    if shadowed:  # a public name that is also a submodule's: the first import binds the module over it
        problems.append(f"__all__ names that resolve to a module: {shadowed}")
    if len(set(listed)) != len(listed):
        problems.append("__all__ repeats a name")
    return problems


@pytest.mark.parametrize("name", FACES)
def test_every_face_has_a_docstring_and_an_all_whose_names_resolve(name):
    assert face_problems(importlib.import_module(name)) == []


def test_planted_face_defects_are_caught():
    from scenarios._faces import lazy_face

    bare = types.ModuleType("bare")
    assert face_problems(bare) == ["no docstring saying what lives there", "no __all__"]
    lazy = types.ModuleType("lazy", "A face whose names are imported on first use, one of them from the wrong home.")
    lazy.__all__ = ["to_csv", "nowhere"]
    lazy.__getattr__, _ = lazy_face("scenarios.output", {"to_csv": "scenarios.output.plots",  # type: ignore[attr-defined]
                                                         "nowhere": "scenarios.output.tables"})
    assert face_problems(lazy) == ["__all__ names that do not resolve: ['to_csv', 'nowhere']"]
    shadow = types.ModuleType("shadow", "A face one of whose public names is also the name of its submodule.")
    shadow.__all__ = ["names"]
    shadow.names = importlib.import_module("scenarios.output.names")  # type: ignore[attr-defined]
    assert face_problems(shadow) == ["__all__ names that resolve to a module: ['names']"]


# --- "May import:" in the faces' docstrings ------------------------------------------------------

LAZY_FACES = "scenarios._faces"
"""The helper lazy faces are built with: a face's machinery, not a dependency of its modules."""
MAY_IMPORT = re.compile(r"May import:(.*?)(?:\n\s*\n|\Z)", re.DOTALL)
FORBIDDING = re.compile(r"\bnever\b|\bnothing else\b|\bnothing imports\b")
MENTION = re.compile(r"((?:top-level|contract) modules of )?:mod:`~?([\w.]+)`")


def _may_import(module: Module) -> tuple[list[tuple[str, bool]], list[str]] | None:
    """``([(allowed module, top-level modules only)], [forbidden modules])`` of a face's
    "May import:" paragraph, or None."""
    docstring = ast.get_docstring(ast.parse(module.source)) or ""
    match = MAY_IMPORT.search(docstring)
    if match is None:
        return None
    text = " ".join(match.group(1).split())
    split = FORBIDDING.search(text)
    allowed, forbidden = (text[:split.start()], text[split.start():]) if split else (text, "")
    return ([(m.group(2), bool(m.group(1))) for m in MENTION.finditer(allowed)],
            [m.group(2) for m in MENTION.finditer(forbidden)])


def _covers(mention: str, top_only: bool, name: str, face: str) -> bool:
    """Whether the mention of ``mention`` in the face ``face`` allows importing ``name``."""
    if name == mention:
        return True
    if not name.startswith(mention + "."):
        return False
    if mention == face.split(".")[0] and top_only:  # the package's top-level modules only
        return group(name) == group(mention + ".errors")
    return True


def import_claims(tree: dict[str, Module]) -> dict[str, list[str]]:
    """Where a face's "May import:" disagrees with the table or with its modules' imports."""
    found: dict[str, list[str]] = {}
    for face in (m for m in tree.values() if m.face):
        claims = _may_import(face)
        if claims is None:
            continue
        allowed, forbidden = claims
        problems = []
        layer = group(face.name)
        package = face.name.split(".")[0]
        for mention, top_only in allowed:
            same = mention.split(".")[0] == package
            if not same:
                if PACKAGES.index(mention.split(".")[0]) > PACKAGES.index(package):
                    problems.append(f"claims it may import {mention}, a package above it")
            elif layer is not None and (mention != package or top_only):  # "everything of X" is not checked
                target = mention if mention != package else f"{package}.errors"
                if group(target) not in ALLOWED[layer]:
                    problems.append(f"claims it may import {mention}; the table says {sorted(ALLOWED[layer])}")
        for mention in forbidden:
            if mention.split(".")[0] == package and mention != package and layer is not None \
                    and group(mention) in ALLOWED[layer]:
                problems.append(f"claims it never imports {mention}, which the table allows")
        for module in tree.values():
            if not (module.name == face.name or module.name.startswith(face.name + ".")):
                continue
            for imported in imports(module, tree):
                if imported == face.name or imported.startswith(face.name + ".") or imported == LAZY_FACES:
                    continue  # its own modules, or (a face) the machinery of lazy faces
                if not any(_covers(m, top, imported, face.name) for m, top in allowed):
                    problems.append(f"{module.name} imports {imported}, which it does not list")
                if any(imported == m or imported.startswith(m + ".") for m in forbidden if m != package):
                    problems.append(f"{module.name} imports {imported}, which it says it never imports")
        if problems:
            found[face.name] = problems
    return found


def test_may_import_agrees_with_the_table_and_the_imports():
    found = import_claims(TREE)
    assert not found, "\n".join(f"{face}: {p}" for face, problems in found.items() for p in problems)


def test_planted_disagreements_in_may_import_are_caught():
    face = TREE["controllers.detumbling"]
    lying = face.source.replace("May import: :mod:`ocp` and :mod:`controllers.base`.",
                                "May import: :mod:`ocp`.")
    assert lying != face.source
    tree = {**TREE, face.name: Module(face.name, lying, True)}
    assert any("controllers.base" in p for p in import_claims(tree)["controllers.detumbling"])
    face = TREE["ocp.simulation"]
    bold = face.source.replace("May import: :mod:`ocp.dynamics`", "May import: :mod:`ocp.transcription`, :mod:`ocp.dynamics`")
    assert bold != face.source
    tree = {**TREE, face.name: Module(face.name, bold, True)}
    assert any("ocp.transcription" in p for p in import_claims(tree)["ocp.simulation"])
