"""Sphinx configuration of slewbench's documentation.

Build (warnings are errors; the repository root must be importable)::

    sphinx-build -W --keep-going -b html docs docs/_build

Before the build, this file writes the pages that the code produces (all of them gitignored):

* ``reference/schema.rst``: the scenario schema, from ``scenarios.schema.reference.schema_rst()``;
* ``api/``: one page per package and subpackage, documenting exactly the names of its ``__all__``;
* ``_generated/*.inc``: fragments included by the hand-written pages: the metric table (from
  ``ocp.metrics.METRIC_INFO``), the requirement fields' table (from
  ``scenarios.requirements.fields.REQUIREMENT_FIELDS``) and the file layouts and names of the outputs (from
  ``scenarios.output`` and ``scenarios.study``).

Nothing here reaches the network: no intersphinx, no remote images.
"""
from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import re
import sys
import tempfile
import warnings
from pathlib import Path
from types import GenericAlias, ModuleType, SimpleNamespace
from typing import Any

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))

PACKAGES = ("ocp", "planners", "controllers", "scenarios")
"""The import packages; every package and subpackage among them is a "face" with an ``__all__``."""

# -- Project -----------------------------------------------------------------------------------
project = "slewbench"
author = "slewbench contributors"
copyright = "slewbench contributors"
release = re.search(r'^version = "([^"]+)"', (ROOT / "pyproject.toml").read_text(), re.MULTILINE).group(1)
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
]
exclude_patterns = ["_build", "_generated", "examples", "Thumbs.db", ".DS_Store"]
templates_path: list[str] = []
html_theme = "alabaster"
html_static_path: list[str] = []
html_title = "slewbench"
html_theme_options = {"description": "Spacecraft attitude manoeuvre planning on one CasADi model",
                      "fixed_sidebar": True, "page_width": "1180px", "sidebar_width": "240px"}
# MathJax is loaded by the reader's browser when a page has math; the build itself fetches nothing.

# -- autodoc, autosummary, numpydoc --------------------------------------------------------------
add_module_names = False
autosummary_generate = False          # the API pages are written below, not by autosummary
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_typehints = "none"            # the numpydoc sections give every type, with its unit
autodoc_preserve_defaults = True
numpydoc_show_class_members = False   # autodoc documents the members; numpydoc's tables would repeat them
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = False

NUMPYDOC_CUSTOM_SECTIONS = ("Contract", "Symbolic form", "Control frame", "Status policy", "Early stopping",
                            "Fallbacks", "Warm starts with multipliers", "Restarts", "Ties")
"""Sections of slewbench's docstrings beyond numpydoc's own (which would drop them): each is moved
to the end of the extended summary under a rubric of its name. Any other unknown section is a
build warning."""

# -- sphinx-gallery ------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",          # every plot_*.py is executed
    "abort_on_example_error": True,
    "download_all_examples": False,
    # docs/auto_examples is generated and gitignored, but it stays in the checkout between builds,
    # and sphinx-gallery re-runs an example only when the example's own source changes: a page
    # then shows what an older library printed (a collocation message of hours before). The
    # examples' output depends on the library, so every build runs them all (about 20 s).
    "run_stale_examples": True,
}


# ================================================================================================
# Pages generated from the code
# ================================================================================================

def _write(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` unless it already holds it (an unchanged page is not rebuilt)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def _title(text: str, underline: str = "=") -> str:
    return f"{text}\n{underline * len(text)}\n"


def _literal_list(items: list[str]) -> str:
    return ", ".join(f"``{item}``" for item in items)


def _escape_bars(text: str) -> str:
    """Escape ``|`` outside inline literals: in a definition it is an absolute value, never a
    substitution reference."""
    parts = re.split(r"(``.*?``)", text)
    return "".join(part if part.startswith("``") else part.replace("|", r"\|") for part in parts)


# -- the schema reference --------------------------------------------------------------------------

def write_schema_reference() -> None:
    """``reference/schema.rst`` from the validating code."""
    from scenarios.schema.reference import schema_rst

    _write(DOCS / "reference" / "schema.rst", schema_rst())


# -- the API reference -----------------------------------------------------------------------------

def faces() -> list[ModuleType]:
    """Every package and subpackage of :data:`PACKAGES` (private ones left out), top-down."""
    found = []
    for name in PACKAGES:
        package = importlib.import_module(name)
        found.append(package)
        for info in pkgutil.walk_packages(package.__path__, prefix=f"{name}."):
            if info.ispkg and not any(part.startswith("_") for part in info.name.split(".")):
                found.append(importlib.import_module(info.name))
    return found


def _import_homes(face: ModuleType) -> dict[str, str]:
    """Name -> module it is imported from, read from the face's source (its ``from X import``
    statements, type-checking ones included) and its lazy ``_HOMES`` table."""
    homes: dict[str, str] = {}
    tree = ast.parse(inspect.getsource(face))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                homes[alias.asname or alias.name] = node.module
    homes.update(getattr(face, "_HOMES", {}))
    return homes


def home_of(face: ModuleType, name: str, obj: Any) -> str:
    """The module that defines ``name`` (the face itself for a name it defines)."""
    module = getattr(obj, "__module__", None)
    if (inspect.isclass(obj) or inspect.isfunction(obj)) and module and module in sys.modules \
            and getattr(sys.modules[module], getattr(obj, "__qualname__", ""), None) is obj:
        return module
    return _import_homes(face).get(name, face.__name__)


def _directive(obj: Any) -> str:
    if inspect.isclass(obj):
        return "autoexception" if issubclass(obj, BaseException) else "autoclass"
    if inspect.isfunction(obj) or inspect.isbuiltin(obj):
        return "autofunction"
    return "autodata"


def api_entries() -> tuple[list[ModuleType], dict[str, list[tuple[str, str, Any]]], dict[str, str]]:
    """The faces, their public names as ``(name, canonical path, object)``, and where each
    canonical path is documented (the deepest face exporting it whose package holds its home)."""
    found = faces()
    names: dict[str, list[tuple[str, str, Any]]] = {}
    exporters: dict[str, list[str]] = {}
    for face in found:
        entries = []
        for name in face.__all__:
            obj = getattr(face, name)  # resolves the lazy faces' names (PEP 562)
            path = f"{home_of(face, name, obj)}.{name}"
            entries.append((name, path, obj))
            exporters.setdefault(path, []).append(face.__name__)
        names[face.__name__] = entries
    owner = {}
    for path, exporting in exporters.items():
        holding = [f for f in exporting if path.startswith(f + ".")]
        owner[path] = max(holding or exporting, key=lambda f: (f.count("."), -exporting.index(f)))
    return found, names, owner


def _face_page(face: ModuleType, entries: list[tuple[str, str, Any]], owner: dict[str, str]) -> str:
    name = face.__name__
    lines = [f".. This page is generated by docs/conf.py from the ``__all__`` of {name}; do not edit.", "",
             _title(name), f".. automodule:: {name}", "   :no-members:", ""]
    if entries:
        lines += [".. rubric:: Public names", "", ".. autosummary::", "   :nosignatures:", ""]
        # Relative to the page's module (autosummary resolves them from there).
        lines += [f"   ~{path.removeprefix(name + '.')}" for _, path, _ in sorted(entries, key=lambda e: e[0].lower())]
        lines.append("")
    own = [(n, p, o) for n, p, o in entries if owner[p] == name]
    elsewhere = sorted({owner[p] for _, p, _ in entries if owner[p] != name})
    if elsewhere:
        lines += ["Names documented with their subpackage: "
                  + ", ".join(f":mod:`{face_name}`" for face_name in elsewhere) + ".", ""]
    modules = [info.name for info in pkgutil.iter_modules(face.__path__, prefix=f"{name}.")
               if not info.ispkg and not info.name.rsplit(".", 1)[1].startswith("_")]
    for _, path, obj in own:
        directive = _directive(obj)
        lines.append(f".. {directive}:: {path}")
        if directive == "autodata" and len(repr(obj)) > 120:
            lines.append("   :no-value:")
        lines.append("")
        if isinstance(obj, dict) and obj and all(inspect.isclass(v) for v in obj.values()):
            lines += [f"   A registry: {len(obj)} names, each the key of one class.", "",
                      "   .. list-table::", "      :header-rows: 1", "",
                      "      * - name", "        - class"]
            for key, cls in obj.items():
                lines += [f"      * - ``{key}``", f"        - :class:`~{cls.__module__}.{cls.__qualname__}`"]
            lines.append("")
    if modules:
        lines += [_title("Modules", "-"), ("What each module of the package holds (its docstring), and the public "
                                           "names it defines that no package exports (those above are documented "
                                           "once, with their package)."), ""]
        for module in modules:
            lines += [_title(f"``{module}``", "~"), f".. automodule:: {module}", "   :no-members:", ""]
            for path, obj in module_entries(importlib.import_module(module), owner):
                directive = _directive(obj)
                lines.append(f".. {directive}:: {path}")
                if directive == "autodata" and len(repr(obj)) > 120:
                    lines.append("   :no-value:")
                lines.append("")
    return "\n".join(lines)


def module_entries(module: ModuleType, owner: dict[str, str]) -> list[tuple[str, Any]]:
    """The public names of a module that no face documents, as ``(canonical path, object)``: its
    ``__all__`` when it has one, else the classes and functions it defines whose names have no
    leading underscore (the public API of ``tests/public_api.py``, which holds each to a numpydoc
    docstring)."""
    names = getattr(module, "__all__", None)
    if names is None:
        names = [name for name, obj in vars(module).items() if not name.startswith("_")
                 and (inspect.isclass(obj) or inspect.isfunction(obj)) and obj.__module__ == module.__name__]
    entries = []
    for name in names:
        obj = getattr(module, name)
        if inspect.ismodule(obj) or isinstance(obj, GenericAlias):
            continue  # a module is documented on its own; a type alias (Array) has nothing to document
        path = f"{module.__name__}.{name}"
        canonical = f"{getattr(obj, '__module__', module.__name__)}.{getattr(obj, '__qualname__', name)}"
        if path in owner or canonical in owner or canonical != path and (inspect.isclass(obj) or inspect.isfunction(obj)):
            continue  # documented with a package, or defined elsewhere (documented with its own module)
        entries.append((path, obj))
    return entries


def write_api_pages() -> None:
    """``api/index.rst`` and one page per face."""
    found, names, owner = api_entries()
    api = DOCS / "api"
    wanted = {"index.rst"}
    for face in found:
        page = f"{face.__name__}.rst"
        wanted.add(page)
        _write(api / page, _face_page(face, names[face.__name__], owner))
    for stale in api.glob("*.rst"):
        if stale.name not in wanted:
            stale.unlink()
    index = [".. This page is generated by docs/conf.py; do not edit.", "", _title("API reference"),
             ("One page per package and subpackage (a *face*): its docstring says what lives there and what it "
              "may import (:doc:`../architecture`), and the page documents exactly the names of its "
              "``__all__``. A name exported by several faces is documented once, with the subpackage that "
              "defines it, and listed on the others."), ""]
    for package in PACKAGES:
        members = [f.__name__ for f in found if f.__name__ == package or f.__name__.startswith(package + ".")]
        index += [_title(f"``{package}``", "-"), ".. toctree::", "   :maxdepth: 1", ""]
        index += [f"   {member}" for member in members]
        index.append("")
    _write(api / "index.rst", "\n".join(index))


# -- the metric table ------------------------------------------------------------------------------

def write_metric_table() -> None:
    """``_generated/metric_table.inc``: a list table of ``ocp.metrics.METRIC_INFO``."""
    from ocp.metrics import METRIC_INFO, METRIC_KEYS

    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 22 12 66", "",
             "   * - key", "     - unit", "     - definition"]
    for key in METRIC_KEYS:
        info = METRIC_INFO[key]
        lines += [f"   * - ``{key}``", f"     - {info.unit}", f"     - {_escape_bars(info.meaning)}"]
    _write(DOCS / "_generated" / "metric_table.inc", "\n".join(lines) + "\n")


def write_requirement_field_table() -> None:
    """``_generated/requirement_fields.inc``: a list table of
    ``scenarios.requirements.fields.REQUIREMENT_FIELDS`` (a pointing requirement's fields under
    ``<name>``, the others under the requirement's own name)."""
    from scenarios.requirements.fields import REQUIREMENT_FIELDS

    lines = [".. list-table::", "   :header-rows: 1", "   :widths: 28 8 8 56", "",
             "   * - field", "     - unit", "     - scopes", "     - definition"]
    for info in REQUIREMENT_FIELDS:
        name = "<name>" if info.requirement == "pointing" else info.requirement
        lines += [f"   * - ``{name}.{info.field}``", f"     - {info.unit}",
                  f"     - {', '.join(info.scopes)}", f"     - {_escape_bars(info.meaning)}"]
    _write(DOCS / "_generated" / "requirement_fields.inc", "\n".join(lines) + "\n")


# -- the outputs ------------------------------------------------------------------------------------

def _timeseries_header() -> list[str]:
    """The header ``write_timeseries`` writes, for a three-wheel row, read back from the file."""
    import numpy as np

    from scenarios.output.writer import write_timeseries

    n_w, samples = 3, 2
    simulation = SimpleNamespace(t=np.arange(samples + 1.0), x=np.zeros((samples + 1, 7 + n_w)),
                                 wheel_momentum=np.zeros((samples + 1, n_w)), applied_torque=np.zeros((samples, 3)))
    row = SimpleNamespace(label="row", simulation=simulation, reference=None)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "row.csv"
        write_timeseries(row, path)  # type: ignore[arg-type]
        return path.read_text().splitlines()[0].split(",")


def write_output_fragments() -> None:
    """``_generated/*.inc``: column lists, reserved names and markers of the outputs."""
    from scenarios.output.directory import MARKER, STAGING_PREFIX
    from scenarios.output.names import MAX_STEM, RESERVED
    from scenarios.output.tables import row_columns
    from scenarios.study.report import STATISTICS
    from scenarios.study.store import STORE_FILES

    generated = DOCS / "_generated"
    _write(generated / "results_csv_columns.inc", _literal_list(row_columns()) + "\n")
    _write(generated / "timeseries_columns.inc", _literal_list(_timeseries_header()) + "\n")
    _write(generated / "cases_csv_columns.inc",
           "``case``, ``seed``, *one column per varied path*, " + _literal_list(row_columns()) + "\n")
    _write(generated / "summary_statistics.inc", _literal_list(list(STATISTICS)) + "\n")
    _write(generated / "reserved_stems.inc", _literal_list(sorted(RESERVED)) + "\n")
    _write(generated / "store_files.inc", _literal_list(list(STORE_FILES)) + "\n")
    # Single values, used inline through substitutions (rst_prolog below).
    _write(generated / "names.inc", "\n".join([
        f".. |MARKER| replace:: ``{MARKER}``",
        f".. |STAGING_PREFIX| replace:: ``{STAGING_PREFIX}*``",
        f".. |MAX_STEM| replace:: {MAX_STEM}",
    ]) + "\n")


write_schema_reference()
write_api_pages()
write_metric_table()
write_requirement_field_table()
write_output_fragments()


# ================================================================================================
# numpydoc: custom sections, and its warnings as build warnings
# ================================================================================================

_NUMPYDOC_SECTIONS = {"Parameters", "Returns", "Yields", "Receives", "Other Parameters", "Raises", "Warns",
                      "Warnings", "See Also", "Notes", "References", "Examples", "Attributes", "Methods"}


def _section_title(lines: list[str], i: int) -> str | None:
    """The section title at line ``i`` (a text line underlined by dashes at least as long)."""
    if i + 1 >= len(lines):
        return None
    title, rule = lines[i].strip(), lines[i + 1].strip()
    if title and rule and set(rule) == {"-"} and len(rule) >= len(title) and not lines[i][:1].isspace():
        return title
    return None


def move_custom_sections(app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]) -> None:
    """Move each custom section (:data:`NUMPYDOC_CUSTOM_SECTIONS`) to the end of the extended
    summary as a rubric, where numpydoc keeps it; warn about any other unknown section."""
    from sphinx.util import logging

    blocks: list[tuple[str | None, list[str]]] = [(None, [])]
    i = 0
    while i < len(lines):
        title = _section_title(lines, i)
        if title is not None:
            blocks.append((title, []))
            i += 2
            continue
        blocks[-1][1].append(lines[i])
        i += 1
    custom = [(t, body) for t, body in blocks[1:] if t is not None and t not in _NUMPYDOC_SECTIONS]
    if not custom:
        return
    for title, _ in custom:
        if title not in NUMPYDOC_CUSTOM_SECTIONS:
            logging.getLogger(__name__).warning(
                f"unknown docstring section {title!r} in {name} (numpydoc drops it): use a numpydoc section "
                "or add it to NUMPYDOC_CUSTOM_SECTIONS in docs/conf.py", type="numpydoc", subtype="section")
    out = list(blocks[0][1])
    while out and not out[-1].strip():
        out.pop()
    for title, body in custom:
        out += ["", f".. rubric:: {title}", "", *body]
        while out and not out[-1].strip():
            out.pop()
    out.append("")
    for title, body in blocks[1:]:
        if title in _NUMPYDOC_SECTIONS:
            out += [title, "-" * len(title), *body]
    lines[:] = out


_show_warning = warnings.showwarning


def _numpydoc_warning(message: Any, category: type[Warning], filename: str, lineno: int,
                      file: Any = None, line: str | None = None) -> None:
    """numpydoc reports docstring problems as Python warnings, which Sphinx does not count: make
    them build warnings (``-W`` fails on them)."""
    if "numpydoc" in filename.replace("\\", "/"):
        unknown = re.match(r"Unknown section (.+?) in the docstring", str(message))
        if unknown and unknown.group(1).lower() in {s.lower() for s in NUMPYDOC_CUSTOM_SECTIONS}:
            return  # numpydoc's signature lookup parses the raw docstring; the page has the section
        from sphinx.util import logging

        logging.getLogger(__name__).warning(f"numpydoc: {message}", type="numpydoc", subtype="docstring")
        return
    _show_warning(message, category, filename, lineno, file, line)


warnings.filterwarnings("always", module=r"numpydoc(\..*)?")
warnings.showwarning = _numpydoc_warning

rst_prolog = (DOCS / "_generated" / "names.inc").read_text()


# ================================================================================================
# Cross-references of the hand-written pages
# ================================================================================================

GENERATED_PAGES = ("api/", "reference/", "auto_examples/")
"""Pages the build writes from the code; every other page is hand-written."""
UNRESOLVED_ELSEWHERE: frozenset[tuple[str, str]] = frozenset()
"""``(page, target)`` references known not to resolve, on pages outside the branch that added the
check: reported to their owners, to be fixed on the page and removed here."""


def warn_unresolved(app: Any, env: Any, node: Any, contnode: Any) -> None:
    """A Python cross-reference of a hand-written page (``:func:``, ``:class:``, ``:mod:``, ...)
    that names no documented object is a build warning (``-W`` fails on it), as ``nitpicky`` would
    make it; over the generated API pages ``nitpicky`` would report some 400 references to
    Python's and NumPy's types in docstrings, which are plain text by choice (no intersphinx)."""
    from sphinx.util import logging

    doc, target = node.get("refdoc", ""), node.get("reftarget", "")
    if node.get("refdomain") != "py" or doc.startswith(GENERATED_PAGES):
        return
    if (doc, target) in UNRESOLVED_ELSEWHERE:
        return
    logging.getLogger(__name__).warning(
        f"py:{node.get('reftype')} reference target not found: {target} (a hand-written page's cross-reference must "
        f"name a documented object: the API pages document each face's __all__ and each module's public names)",
        location=node, type="ref", subtype="hand_written")


def setup(app: Any) -> None:
    """Run :func:`move_custom_sections` before numpydoc reads the docstrings, and check the
    hand-written pages' cross-references (:func:`warn_unresolved`)."""
    app.connect("autodoc-process-docstring", move_custom_sections, priority=400)
    app.connect("missing-reference", warn_unresolved)
