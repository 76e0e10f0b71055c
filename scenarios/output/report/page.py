"""A self-contained interactive HTML page: sortable tables and plotly figures, opening offline.

:class:`Page` collects sections, tables (:class:`Column` headers with units; sorting on a header
click, paging and a text filter for long tables), plotly figures (plain figure dicts in plotly's
JSON form, drawn by plotly.js) and two widgets (a figure chosen from a list, a scatter of two
columns of a table chosen by the reader), and renders one HTML file:

* plotly.js is inlined once per page (the copy shipped with the ``plotly`` package), so the page
  opens without a network and loads nothing from elsewhere;
* the tables' and figures' data are one JSON document in the page (the script element of id
  ``slewbench-data``): table values exactly as computed (non-finite numbers ``null``), figure
  arrays rounded to :data:`FIGURE_DIGITS` significant digits;
* a small script (:data:`SCRIPT`) draws the tables and figures when the page loads.

Units: whatever the caller gives; :func:`column_unit` gives those of a run's and a study's result
columns (:data:`ocp.metrics.METRIC_INFO`, the requirement fields' :func:`~scenarios.requirements.fields.field_info`).
"""
from __future__ import annotations

import html
import importlib.util
import json
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from ocp.metrics import METRIC_INFO
from scenarios.output.report.figures import ATTITUDE_PX
from scenarios.output.tables import json_safe
from scenarios.requirements.fields import field_info, is_requirement_column
from scenarios.schema.columns import SCOPES, VECTOR_METRICS

__all__ = ["FIGURE_DIGITS", "PLOTLY_CONFIG", "Column", "Page", "column_unit", "figure_array", "figure_arrays", "plotly_js",
           "plotly_js_bytes"]

FIGURE_DIGITS = 7
"""Significant digits of the numbers in a figure's arrays (more than a hover label shows)."""
PLOTLY_CONFIG = {"displaylogo": False, "responsive": True, "scrollZoom": False,
                 "toImageButtonOptions": {"format": "png", "scale": 2}}
"""plotly.js's configuration of every figure of a page (the mode bar: zoom, pan, PNG export)."""


@cache
def plotly_js_bytes() -> bytes:
    """The plotly.js bundle shipped with the ``plotly`` package, as UTF-8 bytes (read once per process).

    Returns
    -------
    bytes
        The minified script, ready to inline (``</script`` escaped, should it ever occur).

    Raises
    ------
    ModuleNotFoundError
        When the ``plotly`` package is not installed.
    """
    spec = importlib.util.find_spec("plotly")  # finds the package without importing it
    if spec is None or not spec.submodule_search_locations:
        raise ModuleNotFoundError("the HTML report needs the plotly package (pip install plotly)", name="plotly")
    path = Path(next(iter(spec.submodule_search_locations))) / "package_data" / "plotly.min.js"
    text = path.read_bytes()
    text.decode("utf-8")  # raises if the file is not UTF-8, as reading it as text would
    return text.replace(b"</script", b"<\\/script")


def plotly_js() -> str:
    """The plotly.js bundle shipped with the ``plotly`` package (:func:`plotly_js_bytes` as text).

    Returns
    -------
    str
        The minified script, ready to inline (``</script`` escaped, should it ever occur).

    Raises
    ------
    ModuleNotFoundError
        When the ``plotly`` package is not installed.
    """
    return plotly_js_bytes().decode("utf-8")


def column_unit(column: str) -> str:
    """The unit of a result column (a run's ``results.csv``, a study's ``cases.csv``).

    Parameters
    ----------
    column : str
        ``ref.<metric>``, ``cl.<metric>`` (a vector metric's ``_x``, ``_y``, ``_z`` too),
        ``ref.req.<name>.<field>``, ``cl.req.<name>.<field>`` or ``plan_time_s``.

    Returns
    -------
    str
        The metric's unit from :data:`ocp.metrics.METRIC_INFO`; a requirement field's from
        :func:`~scenarios.requirements.fields.field_info` (``–`` for a ratio: ``ratio`` and an
        actuator's demand over its limit); ``s`` for ``plan_time_s``; empty for any other column
        (a requirement column whose requirement has no such field too).
    """
    parts = column.split(".")
    if is_requirement_column(column):
        try:
            return field_info(column).unit
        except KeyError:
            return ""
    if len(parts) == 2 and parts[0] in {prefix for _, prefix in SCOPES}:
        key = parts[1]
        base = key[:-2]
        if base in VECTOR_METRICS and key[-2:] in ("_x", "_y", "_z"):
            key = base
        info = METRIC_INFO.get(key)
        return info.unit if info is not None else ""
    return "s" if column == "plan_time_s" else ""


@dataclass(frozen=True)
class Column:
    """A table column.

    Parameters
    ----------
    key : str
        Its name (a result column's name, as in the CSV files).
    unit : str, optional
        Unit of its values, shown under the name; empty: none.
    numeric : bool, optional
        Sorted as numbers (missing values last either way) and shown with 4 significant digits.
    meaning : str, optional
        What it is, shown when the pointer rests on the header.
    order : tuple of str, optional
        The sort order of a text column's values (``("crashed", "failed", "violated", "ok")``
        for a status); values not in it sort after them, alphabetically.
    """

    key: str
    unit: str = ""
    numeric: bool = False
    meaning: str = ""
    order: tuple[str, ...] = ()


def _rounded(array: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``array`` to :data:`FIGURE_DIGITS` significant digits (0 where not finite), and where it is finite."""
    finite = np.isfinite(array)
    magnitude = np.where(finite & (array != 0.0), np.abs(array), 1.0)
    scale = 10.0 ** (FIGURE_DIGITS - 1 - np.floor(np.log10(magnitude)))
    return np.where(finite, np.round(array * scale) / scale, 0.0), finite


def _blank(items: Any, keep: Any) -> Any:
    """Nested lists with ``None`` where ``keep`` (the same nesting) is false."""
    if isinstance(items, list):
        return [_blank(i, k) for i, k in zip(items, keep)]
    return items if keep else None


def figure_array(values: Any) -> list[Any]:
    """A figure's array in plain JSON form: :data:`FIGURE_DIGITS` significant digits, ``None``
    for a non-finite number.

    Parameters
    ----------
    values : array_like
        Numbers (any shape).

    Returns
    -------
    list
        Nested lists of floats and ``None``.
    """
    rounded, finite = _rounded(np.asarray(values, dtype=float))
    plain = rounded.tolist()
    return plain if finite.all() else _blank(plain, finite.tolist())


def figure_arrays(arrays: Sequence[Any]) -> list[list[Any]]:
    """:func:`figure_array` of each of many arrays, rounded together: the same lists, without
    NumPy's cost per call (a report's 3-D attitude figures hold thousands of arrays of two points).

    Parameters
    ----------
    arrays : sequence of array_like
        Numbers (each of any shape).

    Returns
    -------
    list
        Per array, nested lists of floats and ``None``.
    """
    values = [np.asarray(a, dtype=float) for a in arrays]
    if not values:
        return []
    ends = np.cumsum([a.size for a in values])
    rounded, finite = _rounded(np.concatenate([a.ravel() for a in values]))
    missing = np.concatenate([[0], np.cumsum(~finite)])  # non-finite numbers before each position
    plain = []
    for a, end, end_missing in zip(values, ends.tolist(), missing[ends].tolist()):
        start = end - a.size
        items = rounded[start:end].reshape(a.shape).tolist()
        plain.append(_blank(items, finite[start:end].reshape(a.shape).tolist()) if end_missing > missing[start]
                     else items)
    return plain


def _arrays(value: Any, found: dict[int, np.ndarray]) -> None:
    """The NumPy arrays in nested dicts, lists and tuples, by ``id``."""
    if isinstance(value, np.ndarray):
        found[id(value)] = value
    elif isinstance(value, dict):
        for item in value.values():
            _arrays(item, found)
    elif isinstance(value, (list, tuple)):
        for item in value:
            _arrays(item, found)


def _json(value: Any) -> str:
    """JSON text safe inside a ``<script>`` element (``</`` and ``<!--`` escaped); NumPy arrays as
    :func:`figure_array` makes them (all rounded at once, :func:`figure_arrays`), NumPy scalars as numbers."""
    found: dict[int, np.ndarray] = {}
    _arrays(value, found)  # the arrays stay alive in `value` while it is encoded: their ids are theirs
    lists = dict(zip(found, figure_arrays(list(found.values()))))

    def encode(item: Any) -> Any:
        if isinstance(item, np.ndarray):
            return lists[id(item)]
        if isinstance(item, np.generic):
            return item.item()
        raise TypeError(f"{type(item).__name__} is not JSON serialisable")

    text = json.dumps(value, allow_nan=False, separators=(",", ":"), ensure_ascii=False, default=encode)
    return text.replace("</", "<\\/").replace("<!--", "<\\u0021--")


class Page:
    """An HTML page of sections, tables and figures (module docstring).

    Parameters
    ----------
    title : str
        The page's title and first heading.
    lines : sequence of str, optional
        Lines of text under the title (plain text, escaped here).
    """

    def __init__(self, title: str, lines: Sequence[str] = ()) -> None:
        self.title = title
        self._head = [f"<h1>{html.escape(title)}</h1>"] + [f'<p class="meta">{html.escape(line)}</p>' for line in lines]
        self._body: list[str] = []
        self._sections: list[tuple[str, str]] = []
        self._data: dict[str, dict[str, Any]] = {"tables": {}, "figures": {}, "choices": {}, "explorers": {}}
        self._ids: set[str] = set()

    def _new_id(self, key: str) -> str:
        ident = "".join(c if c.isalnum() or c in "-_" else "-" for c in key)
        if not ident or ident in self._ids:
            raise ValueError(f"the page already has an element {ident!r}")
        self._ids.add(ident)
        return ident

    def section(self, title: str, text: str = "") -> None:
        """Start a section: a heading (listed in the page's contents) and a paragraph.

        Parameters
        ----------
        title : str
            The heading.
        text : str, optional
            A paragraph under it (plain text).
        """
        ident = self._new_id("section-" + title.lower())
        self._sections.append((ident, title))
        self._body.append(f'<h2 id="{ident}">{html.escape(title)}</h2>')
        if text:
            self.text(text)

    def text(self, text: str) -> None:
        """A paragraph of plain text.

        Parameters
        ----------
        text : str
            The paragraph (escaped here).
        """
        self._body.append(f"<p>{html.escape(text)}</p>")

    def table(self, key: str, columns: Sequence[Column], rows: Sequence[Sequence[Any]],
              page_size: int | None = None, caption: str = "", wrap: bool = False) -> str:
        """A sortable table: a click on a header sorts by that column, a second click reverses.

        Parameters
        ----------
        key : str
            Its element id (unique in the page).
        columns : sequence of Column
            The columns.
        rows : sequence of sequences
            One value per column for each row: numbers (non-finite ones shown as missing), text,
            bools (shown ``True``/``False``, as ``results.csv`` writes them), ``None`` (missing) or
            lists of numbers.
        page_size : int, optional
            Rows shown at once, with page buttons and a filter box; ``None``: all rows.
        caption : str, optional
            A line above the table.
        wrap : bool, optional
            Text cells shown whole, wrapped over lines (a record's words); by default a long text
            is cut on one line, whole when the pointer rests on it.

        Returns
        -------
        str
            The element id.
        """
        ident = self._new_id(key)
        if any(len(row) != len(columns) for row in rows):
            raise ValueError(f"table {key!r}: every row needs {len(columns)} values")
        self._data["tables"][ident] = {
            "columns": [{"key": c.key, "unit": c.unit, "numeric": c.numeric, "meaning": c.meaning,
                         "order": list(c.order)} for c in columns],
            "rows": json_safe([list(row) for row in rows]), "page_size": page_size}
        if caption:
            self._body.append(f'<p class="caption">{html.escape(caption)}</p>')
        self._body.append(f'<div class="sb-table{" sb-wrap" if wrap else ""}" id="{ident}"></div>')
        return ident

    def figure(self, key: str, figure: dict[str, Any], caption: str = "") -> str:
        """A plotly figure (hover, zoom, pan and PNG export from its mode bar).

        Parameters
        ----------
        key : str
            Its element id (unique in the page).
        figure : dict
            ``{"data": [...], "layout": {...}}`` and optionally ``"frames"``, in plotly's JSON form
            (NumPy arrays allowed).
        caption : str, optional
            A line above it.

        Returns
        -------
        str
            The element id.
        """
        ident = self._new_id(key)
        self._data["figures"][ident] = figure
        if caption:
            self._body.append(f'<p class="caption">{html.escape(caption)}</p>')
        self._body.append(f'<div class="sb-figure" id="{ident}"></div>')
        return ident

    def choice(self, key: str, label: str, options: Sequence[tuple[str, dict[str, Any]]]) -> str:
        """One figure at a time, chosen from a list (the first shown).

        Parameters
        ----------
        key : str
            The figure's element id (the list's is ``<key>-choice``).
        label : str
            What the list chooses (``row``).
        options : sequence of (str, dict)
            Names and figures (as :meth:`figure` takes them).

        Returns
        -------
        str
            The figure's element id.
        """
        ident = self._new_id(key)
        self._new_id(ident + "-choice")
        self._data["choices"][ident] = {"names": [name for name, _ in options],
                                        "figures": [figure for _, figure in options]}
        items = "".join(f'<option value="{i}">{html.escape(name)}</option>' for i, (name, _) in enumerate(options))
        self._body.append(f'<p class="controls"><label>{html.escape(label)} <select id="{ident}-choice">{items}'
                          f'</select></label></p><div class="sb-figure sb-3d" id="{ident}"></div>')
        return ident

    def explorer(self, key: str, table: str, group: str, x: str, y: str) -> str:
        """A scatter of two numeric columns of a table, chosen by the reader (a list column gives
        one choice per component), one colour per value of ``group``, with log-scale switches.

        Parameters
        ----------
        key : str
            Its element id.
        table : str
            The id of a table of this page (added before or after).
        group : str
            The column whose values colour the points (a row label).
        x, y : str
            The columns shown first (``name[i]`` for a component of a list column).

        Returns
        -------
        str
            The element id.
        """
        ident = self._new_id(key)
        self._data["explorers"][ident] = {"table": table, "group": group, "x": x, "y": y}
        self._body.append(
            f'<p class="controls" id="{ident}-controls"><label>x <select data-axis="x"></select></label> '
            f'<label><input type="checkbox" data-log="x"> log</label> &nbsp; '
            f'<label>y <select data-axis="y"></select></label> '
            f'<label><input type="checkbox" data-log="y"> log</label></p>'
            f'<div class="sb-figure" id="{ident}"></div>')
        return ident

    def render(self) -> str:
        """The page's HTML.

        Returns
        -------
        str
            One self-contained document (plotly.js, the data and the script inline):
            :meth:`render_bytes` as text.
        """
        return self.render_bytes().decode("utf-8")

    def render_bytes(self) -> bytes:
        """The page's HTML as the UTF-8 bytes of its file: plotly.js (most of the page) is copied
        in as read, never decoded into text and encoded again.

        Returns
        -------
        bytes
            One self-contained document (plotly.js, the data and the script inline).
        """
        for key, explorer in self._data["explorers"].items():
            if explorer["table"] not in self._data["tables"]:
                raise ValueError(f"explorer {key!r}: no table {explorer['table']!r} on the page")
        contents = "".join(f'<li><a href="#{ident}">{html.escape(title)}</a></li>' for ident, title in self._sections)
        nav = f'<nav><ul>{contents}</ul></nav>' if self._sections else ""
        data = _json({**self._data, "config": PLOTLY_CONFIG})
        head = "".join([
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">",
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">",
            f"<title>{html.escape(self.title)}</title><style>{STYLE}</style>", "<script>"])
        body = "".join([
            "</script></head><body>", *self._head, nav, *self._body,
            f'<script type="application/json" id="slewbench-data">{data}</script>',
            f"<script>{SCRIPT}</script></body></html>\n"])
        return b"".join([head.encode("utf-8"), plotly_js_bytes(), body.encode("utf-8")])


STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:1.2em 2em;color:#222;max-width:1500px}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.2em;margin-top:1.8em;border-bottom:1px solid #ccc}
p.meta{margin:.1em 0;color:#555}p.caption{margin:.8em 0 .2em;font-weight:600}
nav ul{list-style:none;padding:0;display:flex;flex-wrap:wrap;gap:.4em 1.2em}nav a{color:#1f5fa8}
.sb-table{overflow-x:auto;max-width:100%}
.sb-table table{border-collapse:collapse;font-size:12.5px;white-space:nowrap}
.sb-table th,.sb-table td{border:1px solid #ddd;padding:2px 6px;text-align:right}
.sb-table td.text{text-align:left;max-width:28em;overflow:hidden;text-overflow:ellipsis}
.sb-wrap td.text{max-width:48em;white-space:normal;overflow-wrap:anywhere}
.sb-table th{background:#f3f3f3;cursor:pointer;user-select:none;position:sticky;top:0;vertical-align:bottom}
.sb-table th .unit{display:block;font-weight:normal;color:#666;font-size:11px}
.sb-table th[aria-sort=ascending]::after{content:" \\25B2"}.sb-table th[aria-sort=descending]::after{content:" \\25BC"}
.sb-table td.missing{color:#aaa}
.status-ok{background:#e3f4e3}.status-violated{background:#fff1d6}.status-failed{background:#fbdcdc}
.status-crashed{background:#e9c4c4}
.sb-pager{margin:.3em 0;font-size:13px}.sb-pager button{margin-right:.3em}.sb-pager input{margin-left:1em}
.sb-figure{width:100%;min-height:300px}.sb-3d{height:{attitude}px}
p.controls{margin:.5em 0;font-size:14px}
""".replace("{attitude}", str(ATTITUDE_PX))  # the 3-D view's height (its figure's)
"""The page's style sheet."""

SCRIPT = r"""
(function () {
  "use strict";
  performance.mark("slewbench-script");
  var DATA = JSON.parse(document.getElementById("slewbench-data").textContent);
  var CONFIG = DATA.config;

  function missing(v) { return v === null || v === undefined || (typeof v === "number" && !isFinite(v)); }
  function number(v) {
    var a = Math.abs(v);
    if (Number.isInteger(v) && a < 1e15) { return String(v); }
    var text = (a >= 1e5 || a < 1e-3) ? v.toExponential(3) : String(Number(v.toPrecision(4)));
    return text.replace(/\.?0+e/, "e");
  }
  function shown(v) {
    if (missing(v)) { return "-"; }
    if (typeof v === "number") { return number(v); }
    if (typeof v === "boolean") { return v ? "True" : "False"; }  // as results.csv and results.md write it
    if (Array.isArray(v)) { return "[" + v.map(shown).join(", ") + "]"; }
    return String(v);
  }
  function rank(column, v) {
    var i = column.order.indexOf(v);
    return i < 0 ? column.order.length : i;
  }
  function compare(column, a, b) {
    var ma = missing(a), mb = missing(b);
    if (ma || mb) { return ma === mb ? 0 : (ma ? 1 : -1); }
    if (column.numeric && typeof a === "number" && typeof b === "number") { return a - b; }
    if (column.order.length) {
      var r = rank(column, a) - rank(column, b);
      if (r !== 0) { return r; }
    }
    return String(shown(a)).localeCompare(String(shown(b)));
  }

  function Table(element, spec) {
    this.element = element;
    this.spec = spec;
    this.order = spec.rows.map(function (row, i) { return i; });
    this.visible = this.order.slice();
    this.sortColumn = -1;
    this.descending = false;
    this.page = 0;
    this.filter = "";
    this.build();
  }
  Table.prototype.build = function () {
    var self = this, spec = this.spec;
    if (spec.page_size) {
      this.pager = document.createElement("div");
      this.pager.className = "sb-pager";
      this.element.appendChild(this.pager);
    }
    var table = document.createElement("table");
    var head = table.createTHead().insertRow();
    spec.columns.forEach(function (column, j) {
      var th = document.createElement("th");
      th.textContent = column.key;
      th.title = column.meaning || ("sort by " + column.key);
      th.setAttribute("aria-sort", "none");
      th.dataset.column = column.key;
      if (column.unit) {
        var unit = document.createElement("span");
        unit.className = "unit";
        unit.textContent = column.unit;
        th.appendChild(unit);
      }
      th.addEventListener("click", function () { self.sort(j); });
      head.appendChild(th);
    });
    this.head = head;
    this.body = table.createTBody();
    this.element.appendChild(table);
    this.draw();
  };
  Table.prototype.sort = function (j) {
    var spec = this.spec, column = spec.columns[j];
    this.descending = this.sortColumn === j ? !this.descending : false;
    this.sortColumn = j;
    var sign = this.descending ? -1 : 1;
    this.order.sort(function (a, b) {
      var va = spec.rows[a][j], vb = spec.rows[b][j];
      var ma = missing(va), mb = missing(vb);
      if (ma || mb) { return ma === mb ? a - b : (ma ? 1 : -1); }  // missing last either way
      return sign * compare(column, va, vb) || a - b;
    });
    Array.prototype.forEach.call(this.head.cells, function (th, k) {
      th.setAttribute("aria-sort", k === j ? (sign > 0 ? "ascending" : "descending") : "none");
    });
    this.apply();
  };
  Table.prototype.apply = function () {
    var rows = this.spec.rows, needle = this.filter.toLowerCase();
    this.visible = !needle ? this.order.slice() : this.order.filter(function (i) {
      return rows[i].some(function (v) { return shown(v).toLowerCase().indexOf(needle) >= 0; });
    });
    this.page = 0;
    this.draw();
  };
  Table.prototype.draw = function () {
    var self = this, spec = this.spec, size = spec.page_size || this.visible.length || 1;
    var pages = Math.max(1, Math.ceil(this.visible.length / size));
    this.page = Math.min(this.page, pages - 1);
    var first = this.page * size, shownRows = this.visible.slice(first, first + size);
    var body = document.createElement("tbody");
    shownRows.forEach(function (i) {
      var tr = body.insertRow();
      tr.dataset.row = i;
      spec.rows[i].forEach(function (v, j) {
        var td = tr.insertCell(), column = spec.columns[j];
        td.textContent = shown(v);
        if (missing(v)) { td.className = "missing"; }
        else if (typeof v !== "number") { td.className = "text"; td.title = shown(v); }
        else { td.title = String(v); }
        if (column.key === "status" && typeof v === "string") { td.className += " status-" + v; }
      });
    });
    this.body.parentNode.replaceChild(body, this.body);
    this.body = body;
    if (this.pager) { this.drawPager(pages, first, shownRows.length); }
  };
  Table.prototype.drawPager = function (pages, first, count) {
    var self = this, pager = this.pager;
    if (!pager.firstChild) {
      ["\u00ab", "\u2039", "\u203a", "\u00bb"].forEach(function (text, k) {
        var button = document.createElement("button");
        button.type = "button";
        button.textContent = text;
        button.addEventListener("click", function () {
          var last = Math.max(0, Math.ceil(self.visible.length / self.spec.page_size) - 1);
          self.page = [0, Math.max(0, self.page - 1), Math.min(last, self.page + 1), last][k];
          self.draw();
        });
        pager.appendChild(button);
      });
      this.status = document.createElement("span");
      pager.appendChild(this.status);
      var input = document.createElement("input");
      input.type = "search";
      input.placeholder = "filter rows";
      input.addEventListener("input", function () { self.filter = input.value; self.apply(); });
      pager.appendChild(input);
    }
    this.status.textContent = count ? ("rows " + (first + 1) + "\u2013" + (first + count) + " of " +
      this.visible.length + " (page " + (this.page + 1) + " of " + pages + ")") : "no rows";
  };

  var drawing = [];
  function plot(id, figure) {
    var element = document.getElementById(id);
    var done = Plotly.newPlot(element, figure.data, figure.layout, CONFIG).then(function () {
      if (figure.frames) { return Plotly.addFrames(element, figure.frames); }
    });
    drawing.push(done);
    return done;
  }

  function Explorer(id, spec) {
    var table = DATA.tables[spec.table], controls = document.getElementById(id + "-controls");
    var choices = [];
    table.columns.forEach(function (column, j) {
      var sample = table.rows.map(function (row) { return row[j]; }).filter(function (v) { return !missing(v); });
      if (!sample.length) { return; }
      if (sample.every(function (v) { return typeof v === "number"; })) {
        choices.push({name: column.key, unit: column.unit, get: function (row) { return row[j]; }});
      } else if (sample.every(function (v) { return Array.isArray(v); })) {
        for (var k = 0; k < sample[0].length; k++) {
          (function (k) {
            choices.push({name: column.key + "[" + k + "]", unit: column.unit,
                          get: function (row) { return Array.isArray(row[j]) ? row[j][k] : null; }});
          })(k);
        }
      }
    });
    var g = table.columns.map(function (c) { return c.key; }).indexOf(spec.group);
    var selects = controls.querySelectorAll("select"), logs = controls.querySelectorAll("input");
    Array.prototype.forEach.call(selects, function (select) {
      choices.forEach(function (choice, k) {
        var option = document.createElement("option");
        option.value = k;
        option.textContent = choice.name;
        select.appendChild(option);
      });
      var initial = choices.map(function (c) { return c.name; }).indexOf(spec[select.dataset.axis]);
      select.value = String(Math.max(0, initial));
    });
    function title(choice) { return choice.name + (choice.unit ? " (" + choice.unit + ")" : ""); }
    function draw() {
      var cx = choices[Number(selects[0].value)], cy = choices[Number(selects[1].value)];
      var groups = {}, names = [];
      table.rows.forEach(function (row, i) {
        var x = cx.get(row), y = cy.get(row), name = g >= 0 ? String(row[g]) : "rows";
        if (missing(x) || missing(y)) { return; }
        if (!groups[name]) { groups[name] = {x: [], y: [], text: []}; names.push(name); }
        groups[name].x.push(x);
        groups[name].y.push(y);
        groups[name].text.push("row " + (i + 1));
      });
      var data = names.map(function (name) {
        return {type: "scatter", mode: "markers", name: name, x: groups[name].x, y: groups[name].y,
                text: groups[name].text, marker: {size: 5, opacity: 0.7},
                hovertemplate: "%{text}<br>x %{x:.4g}<br>y %{y:.4g}<extra>%{fullData.name}</extra>"};
      });
      var layout = {height: 480, margin: {t: 30}, hovermode: "closest", legend: {orientation: "h", y: 1.08},
                    xaxis: {title: {text: title(cx)}, type: logs[0].checked ? "log" : "linear"},
                    yaxis: {title: {text: title(cy)}, type: logs[1].checked ? "log" : "linear"}};
      return Plotly.react(id, data, layout, CONFIG);
    }
    Array.prototype.forEach.call(selects, function (s) { s.addEventListener("change", draw); });
    Array.prototype.forEach.call(logs, function (s) { s.addEventListener("change", draw); });
    drawing.push(draw());
  }

  var tables = {};
  Object.keys(DATA.tables).forEach(function (id) { tables[id] = new Table(document.getElementById(id), DATA.tables[id]); });
  performance.mark("slewbench-tables");
  Object.keys(DATA.figures).forEach(function (id) { plot(id, DATA.figures[id]); });
  Object.keys(DATA.choices).forEach(function (id) {
    var spec = DATA.choices[id], select = document.getElementById(id + "-choice");
    if (spec.figures.length) { plot(id, spec.figures[0]); }
    select.addEventListener("change", function () {
      Plotly.purge(id);
      plot(id, spec.figures[Number(select.value)]);
    });
  });
  Object.keys(DATA.explorers).forEach(function (id) { Explorer(id, DATA.explorers[id]); });
  // "slewbench-drawn": every figure drawn (the promises of plotly.js resolved); "drawn" is then true
  window.slewbench = {data: DATA, tables: tables, drawn: false};
  Promise.all(drawing).then(function () {
    performance.mark("slewbench-drawn");
    window.slewbench.drawn = true;
  });
})();
"""
"""The page's script: builds the tables, draws the figures, wires the widgets."""
