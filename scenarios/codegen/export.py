"""``slewbench codegen``: a scenario's controller law, its saturation stage and every planner row's
reference as C, behind a flight interface (:mod:`scenarios.codegen`).

The output directory (claimed with :func:`scenarios.output.directory.claim_output_directory`, so a
user's files are never touched) receives:

* ``slewbench_<scenario>.c`` / ``.h``: CasADi-generated C (``<f>(arg, res, iw, w, mem)``,
  ``<f>_work``, ...) of ``slewbench_law(t, y, z, r) -> (u, z_next)`` (the layouts of
  :mod:`ocp.dynamics.layout`; one ``slewbench_law_<label>`` per controller when there are several),
  ``slewbench_saturate(u, h_w, dt) -> (u_applied, saturated)`` (the simulator's
  :meth:`~ocp.dynamics.actuators.ActuatorModel.apply_symbolic`), ``slewbench_segment`` (the table
  interpolation, :func:`~scenarios.codegen.tables.segment_function`) and, for closed-form rows,
  ``slewbench_reference_<row>(t) -> row``;
* ``slewbench_tables.c`` / ``.h``: every planned row's reference as a table
  (:func:`~scenarios.codegen.tables.tabulate`), ``slewbench_table_<row>``, through the scenario's
  closed-loop window and one sample (after T: the reference's torque-free coast, what the Python
  closed loop tracks there; past the table's end the last row is held);
* ``slewbench_step.c`` / ``.h``: the flight interface ``slewbench_step(t, measurement, params,
  command, state)`` over them (static work arrays, no allocation), with the ``slewbench_params``
  struct and its default initializer;
* ``example.c`` (a worked use), ``Makefile`` (``make``: ``lib<stem>.so`` and ``example``; ``make
  float``: single precision), ``README.md`` (the interface, each table's error and span, the
  requirements each row breaks) and ``interface.json`` (the functions, their inputs and outputs,
  the layouts, the tables).

Each planned row is planned, sampled and scored against the scenario's requirements as ``slewbench
run`` does (:func:`scenarios.runner.run`'s reference path,
:func:`scenarios.requirements.scoring.score_reference`); a row that breaks one is still exported,
with what it breaks (:attr:`CodegenReport.violations`), and ``SLEWBENCH_PARAMS_DEFAULT`` tracks the
first exported row that meets them and whose table meets its tolerances (when none does both, the
next best, with a warning saying what it misses).
"""
from __future__ import annotations

import json
import re
import shutil
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from controllers.allocation import SymbolicConstants
from ocp.dynamics.actuators import ActuatorModel
from ocp.dynamics.layout import REFERENCE_FIELDS, control_layout, reference_rows
from scenarios.codegen.tables import (
    ReferenceTable,
    TableError,
    TableTolerance,
    angle_text,
    segment_function,
    tabulate,
)
from scenarios.errors import ScenarioError
from scenarios.output.directory import (
    claim_output_directory,
    commit_outputs,
    new_staging,
)
from scenarios.output.names import row_stems
from scenarios.output.provenance import package_version
from scenarios.requirements.scoring import plant_limits, score_reference, violations
from scenarios.runner import closed_loop_window, plan_row
from scenarios.schema.loader import Scenario


@dataclass
class CodegenReport:
    """What :func:`generate` wrote.

    Parameters
    ----------
    directory : Path
        The absolute output directory.
    files : dict of str to int, optional
        Files written (name -> size in bytes).
    functions : list of str, optional
        Names of the CasADi-generated C functions (``slewbench_law``, ``slewbench_saturate``, ...).
    tables : dict of str to TableError, optional
        Planner rows exported as tables (label -> the table's error against the reference).
    skipped : dict of str to str, optional
        Planner rows not exported (label -> reason: the plan failed).
    violations : dict of str to list of str, optional
        Exported rows whose reference breaks the scenario's requirements, scored as ``slewbench run``
        scores it (:func:`scenarios.requirements.scoring.score_reference`): label -> what breaks,
        one sentence per requirement.
    default : str or None, optional
        The row whose table ``SLEWBENCH_PARAMS_DEFAULT`` tracks (``None``: regulation).
    default_reason : str, optional
        Why that row (or regulation), in words.
    notes : list of str, optional
        What of the scenario the C does not hold (:func:`not_generated`: its sensors and estimator).
    """

    directory: Path
    files: dict[str, int] = field(default_factory=dict)
    functions: list[str] = field(default_factory=list)
    tables: dict[str, TableError] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    violations: dict[str, list[str]] = field(default_factory=dict)
    default: str | None = None
    default_reason: str = ""
    notes: list[str] = field(default_factory=list)

    def summary(self) -> list[str]:
        """What ``slewbench codegen`` prints: the files, the functions, each table's error (naming
        the quantities that miss their tolerance), a warning per row that breaks the requirements,
        the skipped rows and the default reference.

        Returns
        -------
        list of str
            One line each.
        """
        lines = [f"wrote {self.directory}/: " + ", ".join(f"{name} ({size} bytes)" for name, size in self.files.items()),
                 "functions: " + ", ".join(self.functions)]
        lines += [f"  table of row {label!r}: {error.summary()}" for label, error in self.tables.items()]
        lines += [f"  warning: row {label!r} breaks the scenario's requirements: {'; '.join(broken)}"
                  for label, broken in self.violations.items()]
        lines += [f"  no C reference for row {label!r}: {reason}" for label, reason in self.skipped.items()]
        lines.append(f"default reference (SLEWBENCH_PARAMS_DEFAULT): {self.default_reason}")
        lines += [f"note: {note}" for note in self.notes]
        return lines


def not_generated(scenario: Scenario) -> list[str]:
    """What of ``scenario``'s closed loop the generated C does not hold, one sentence each: its
    sensor models and its estimator (``simulation.sensors``, ``simulation.estimator``), which the
    simulation put between the plant and the law, while ``slewbench_step`` takes the measurement
    as given.

    Parameters
    ----------
    scenario : Scenario
        The scenario exported.

    Returns
    -------
    list of str
        Empty when the simulation fed the law the (noisy) state itself.
    """
    suite = scenario.simulation.sensors
    if suite is None:
        return []
    named = [name for name, part in (("gyro", suite.gyro), ("star tracker", suite.star_tracker),
                                     ("magnetometer", suite.magnetometer)) if part is not None]
    if suite.estimator is not None:
        return [f"simulation.estimator (an MEKF, with the {', '.join(named)}) is not generated: slewbench_step's "
                "measurement is the attitude and rate your own estimator gives (in the simulation the law read "
                "the MEKF's attitude and the gyro's rate less its bias estimate)"]
    return [f"simulation.sensors ({', '.join(named)}) are models of the simulation, not generated: "
            "slewbench_step's measurement is what your sensors give"]


def c_identifier(text: str) -> str:
    """A C identifier made of ``text``'s letters and digits (``_`` elsewhere).

    Parameters
    ----------
    text : str
        A scenario name or a row stem.

    Returns
    -------
    str
        ASCII letters, digits and single ``_`` (CasADi refuses ``__`` in a function's name), starting
        with a letter (``n`` before a leading digit; ``x`` when nothing is left).
    """
    stem = re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_") or "x"
    return stem if not stem[0].isdigit() else f"n{stem}"


def _renamed(function: ca.Function, name: str) -> ca.Function:
    """``function`` (SX) under another name, same inputs and outputs."""
    inputs = function.sx_in()
    return ca.Function(name, inputs, function.call(inputs), function.name_in(), function.name_out())


def _unique(name: str, taken: set[str]) -> str:
    """``name``, suffixed when taken (stems a-b and a_b make the same identifier)."""
    candidate, k = name, 1
    while candidate in taken:
        candidate, k = f"{name}_{k}", k + 1
    taken.add(candidate)
    return candidate


def _template(name: str, values: dict[str, str]) -> str:
    """A template of ``scenarios/codegen/templates`` with its ``@KEY@`` fields filled."""
    text = files("scenarios.codegen").joinpath("templates").joinpath(name).read_text()
    for key, value in values.items():
        text = text.replace(f"@{key}@", value)
    left = re.findall(r"@[A-Z_]+@", text)
    if left:
        raise RuntimeError(f"template {name}: unfilled fields {sorted(set(left))}")
    return text


def _c_numbers(values: Any) -> str:
    """Numbers as a C initializer list (round-trip exact, ``INFINITY`` never needed here)."""
    flat = np.asarray(values, dtype=float).ravel()
    return ", ".join(repr(float(v)) for v in flat) if flat.size else "0.0"


SATURATION_PARAMETERS: dict[str, dict[str, str]] = {
    "wheels": {"max_torque": "wheel_max_torque", "max_momentum": "wheel_max_momentum"},
    "magnetorquers": {"_axis_limit": "dipole_limit"},
    "torquers": {"_axis_limit": "torquer_limit"},
}
"""Per actuator kind (its ``name``): the attributes its symbolic saturation reads that become
parameters, and their names in ``slewbench_params``. A kind not listed keeps its limits compiled in."""


class _Limits:
    """An actuator whose limits are symbols, for its own ``saturate_symbolic``."""

    def __init__(self, actuator: Any, overrides: dict[str, ca.SX]) -> None:
        self._actuator, self._overrides = actuator, overrides

    def __getattr__(self, name: str) -> Any:
        if name in self._overrides:
            return self._overrides[name]
        return getattr(self._actuator, name)

    def saturate_symbolic(self, u: Any, state: Any, dt: Any) -> Any:
        return type(self._actuator).saturate_symbolic(self, u, state, dt)


def _saturation(spacecraft: Any, constants: SymbolicConstants) -> ca.Function:
    """The simulator's saturation stage (:meth:`ActuatorModel.apply_symbolic`) as a function of the
    command, the wheel momenta and the parameters (limits of :data:`SATURATION_PARAMETERS`, the hold
    ``sample_time``)."""
    slices, nu = control_layout(spacecraft)
    actuators = ActuatorModel(spacecraft, slices, nu)
    blocks: list[Any] = []
    for actuator, where, state in actuators._blocks:
        names = SATURATION_PARAMETERS.get(actuator.name, {})
        overrides = {attribute: constants.get(name, getattr(actuator, attribute)) for attribute, name in names.items()}
        blocks.append((_Limits(actuator, overrides) if overrides else actuator, where, state))
    actuators._blocks = blocks  # the same saturation, reading its limits from the parameters
    n_states = sum(a.state_size for a in spacecraft.actuators)
    u, h = ca.SX.sym("u", nu), ca.SX.sym("h_w", n_states)
    applied, saturated = actuators.apply_symbolic(u, h, constants.get("sample_time", 0.0))
    return ca.Function("slewbench_saturate", [u, h, constants.vector()], [ca.SX(applied), ca.SX(saturated)],
                       ["u", "h_w", "p"], ["u_applied", "saturated"])


def parameters_offset(parameters: list[dict[str, Any]], name: str) -> slice:
    """Where parameter ``name`` sits in the parameter vector ``p``.

    Parameters
    ----------
    parameters : list of dict
        The parameters' descriptions (``name``, ``shape``, ``offset``).
    name : str

    Returns
    -------
    slice
    """
    entry = next(p for p in parameters if p["name"] == name)
    return slice(entry["offset"], entry["offset"] + int(np.prod(entry["shape"], dtype=int)))


def _c_value(value: float) -> str:
    """One number in C (round-trip exact; ``INFINITY`` for an absent limit)."""
    if np.isinf(value):
        return "INFINITY" if value > 0 else "-INFINITY"
    return repr(float(value))


def _parameter_code(constants: SymbolicConstants) -> tuple[str, str, str, list[dict[str, Any]]]:
    """The struct fields, their default initializer, the packing into the parameter vector (CasADi's
    column-major order) and their description."""
    fields, defaults, pack, described = [], [], [], []
    offset = 0
    for name, (symbol, value) in constants.symbols.items():
        rows, columns = symbol.shape
        array = np.asarray(value, dtype=float).reshape(rows, columns, order="F") if value.ndim < 2 else value
        if value.ndim == 0:
            fields.append(f"    double {name};")
            defaults.append(_c_value(float(value)))
            pack.append(f"    pv_[{offset}] = (casadi_real) p->{name};")
        elif value.ndim == 1:
            fields.append(f"    double {name}[{rows}];")
            defaults.append("{ " + ", ".join(_c_value(v) for v in value) + " }")
            pack.append(f"    for (i = 0; i < {rows}; ++i) pv_[{offset} + i] = (casadi_real) p->{name}[i];")
        else:
            fields.append(f"    double {name}[{rows}][{columns}];  /* row-major */")
            defaults.append("{ " + ", ".join("{ " + ", ".join(_c_value(v) for v in row) + " }" for row in array) + " }")
            pack.append(f"    for (i = 0; i < {rows}; ++i) for (j = 0; j < {columns}; ++j) "
                        f"pv_[{offset} + {rows} * j + i] = (casadi_real) p->{name}[i][j];")
        described.append({"name": name, "shape": list(value.shape), "offset": offset,
                          "default": np.asarray(value, dtype=float).tolist()})
        offset += rows * columns
    return "\n".join(fields), ", ".join(defaults), "\n".join(pack), described


def _tables_files(tables: dict[str, tuple[str, Any]]) -> tuple[str, str]:
    """``slewbench_tables.h`` and ``.c``: one ``slewbench_table_<row>`` per exported row."""
    header = ["/* slewbench_tables.h: every planned row's reference as a table (slewbench codegen). */",
              "#ifndef SLEWBENCH_TABLES_H", "#define SLEWBENCH_TABLES_H", '#include "slewbench_step.h"', ""]
    source = ['/* slewbench_tables.c: generated by slewbench codegen. */', '#include "slewbench_tables.h"', ""]
    for label, (name, table) in tables.items():
        header.append(f"/* row {label!r}: {_table_words(table)} */")
        header.append(f"extern const slewbench_table {name};")
        source.append(f"static const double {name}_times[{table.times.size}] = {{ {_c_numbers(table.times)} }};")
        source.append(f"static const double {name}_rows[{table.rows.size}] = {{ {_c_numbers(table.rows)} }};")
        source.append(f"const slewbench_table {name} = {{ {table.times.size}, {name}_times, {name}_rows }};")
        source.append("")
    header += ["", "#endif /* SLEWBENCH_TABLES_H */", ""]
    return "\n".join(header), "\n".join(source)


def _table_words(table: ReferenceTable) -> str:
    """What a table covers and what it gives past its end, in words (plain numbers)."""
    duration, end = table.manoeuvre_duration, table.end
    words = f"{table.times.size} nodes over [0, {end:g}] s"
    if end > duration:
        words += f": the manoeuvre to T = {duration:g} s, then its torque-free coast"
    last = table.rows[-1]
    rate = float(np.linalg.norm(last[4:7]))
    words += f"; after {end:g} s it holds its last row"
    if rate > 0.0:
        words += f" (omega {rate:.3g} rad/s with q fixed: no motion)"
    return words


def _readme(scenario: Scenario, stem: str, law: str, tables: dict[str, tuple[str, Any]],
            errors: dict[str, TableError], skipped: dict[str, str], tolerance: TableTolerance,
            parameters: list[tuple[str, list[int], list[str]]], law_reads: set[str], reads_rows: bool,
            violations_by_row: dict[str, list[str]], default_reason: str) -> str:
    lines = [f"# C export of scenario `{scenario.name}` (slewbench codegen)", "",
             "Build: `make` (the library `lib" + stem + ".so` and `./example`), `make float` (single precision).",
             "", "## Flight interface (`slewbench_step.h`)", "",
             "```c", "slewbench_state s;", "slewbench_params p = SLEWBENCH_PARAMS_DEFAULT;",
             "slewbench_init(&s);",
             "/* every SLEWBENCH_SAMPLE_TIME seconds: */",
             "slewbench_step(t, &measurement, &p, &command, &s);  /* 0: ok */", "```", "",
             ("`slewbench_step` reads the reference rows at `t` and `t + sample_time` from `p.reference` (a table "
             "of `slewbench_tables.h`; `NULL`: regulation to `p.target`), calls the law "
             f"(`{law}`), then, when `p.saturate` is 1, the saturation stage of the simulator "
             "(`slewbench_saturate`: failed wheels give nothing, wheel torque clipped to its limit and so that "
             "the momentum stays within its limit over the hold, dipole and torquer torques clipped per axis or "
             "scaled). `command.u` is the law's command, `command.u_applied` what the actuators apply. "
             "It uses static work arrays sized from the generated `_work` functions (checked by "
             "`slewbench_init`), no allocation, and is not re-entrant."), "",
             "`example.c` is a worked use.", "",
             *[line for note in not_generated(scenario) for line in (f"Not generated: {note}.", "")],
             "## Parameters (`slewbench_params`)", "",
             ("The numbers the generated functions read as inputs (matrices row-major in the struct); the "
             "defaults (`SLEWBENCH_PARAMS_DEFAULT`) are the scenario's. Numbers a law does not read through "
             "its parameters are compiled into it: change them by regenerating."), "",
             "| field | shape | read by |", "|---|---|---|"]
    for name, shape, readers in parameters:
        lines.append(f"| `{name}` | {shape or 'scalar'} | {', '.join(readers) or 'nothing'} |")
    lines += ["| `saturate` | int | `slewbench_step`: 1 applies the saturation stage |",
              "| `reference` | table pointer | `slewbench_step`: the table to track; `NULL`: regulation to `target` |",
              "| `target` | 13 | the regulation row `[q_f, omega_f, 0, 0]` |", ""]
    if not reads_rows:
        lines += [(f"The law `{law}` compiles its target in and reads no reference: `reference` and `target` "
                  "are not read."), ""]
    if "sample_time" not in law_reads:
        lines += [(f"The law `{law}` compiles the sample time in: `params.sample_time` must equal "
                  "`SLEWBENCH_SAMPLE_TIME` (`slewbench_step` returns `SLEWBENCH_ESAMPLE` otherwise)."), ""]
    lines += [
             "## Reference tables", "",
             ("Interpolation (`slewbench_reference_row`; the same as `scenarios.codegen.tables.interpolate` in "
             "Python): the interval is the last node with `t_k <= t` (`t` clamped to the table); `q` cubic "
             "Hermite with derivatives `0.5 q (x) [0, omega]`, then renormalised; `omega` cubic Hermite with "
             "derivatives `omega_dot`; `omega_dot` and `torque` linear. Nodes: a uniform grid refined until the "
             "tolerances hold inside every interval (attitude "
             f"{tolerance.attitude_rad:g} rad, rate {tolerance.rate:g} and omega_dot/torque {tolerance.linear:g} "
             f"relative to their largest component, at most {tolerance.max_intervals} intervals), with the "
             "reference's own points (collocation's nodes) and its breakpoints (a node one double before each for the "
             "left limit, one double after it for the right limit, and the breakpoint's own node with the side of the "
             "jump the reference gives there)."),
             "", ("Error against the continuous reference, largest over seven points of every interval "
             "(s = 1/8, ..., 7/8 of its length; the midpoint is where a smooth reference's error peaks) and at "
             "every node (a breakpoint's included):"), "",
             ("| row | table | nodes | span [s] | attitude | rate [rad/s] | omega_dot [rad/s^2] | torque [N m] | "
              "tolerances met |"),
             "|---|---|---|---|---|---|---|---|---|"]
    for label, (name, table) in tables.items():
        e = errors[label]
        met = "yes" if e.met else "NO: " + ", ".join(e.failed)
        lines.append(f"| {label} | `{name}` | {table.times.size} | 0 to {table.end:g} (T = {table.manoeuvre_duration:g}) | "
                     f"{angle_text(e.attitude_rad)} | {e.rate:.3g} | {e.acceleration:.3g} | {e.torque:.3g} | {met} |")
    for label, reason in skipped.items():
        lines.append(f"| {label} | not exported: {reason} | | | | | | | |")
    lines += ["", ("Span: each table runs through the scenario's closed-loop window and one sample (every time "
                   "`slewbench_step` reads in the simulated run); after the reference's T it holds the reference's "
                   "torque-free coast (torque zero), the motion the Python closed loop tracks there. Past the "
                   "table's end `slewbench_reference_row` holds the last row (`t` is clamped): for a reference "
                   "still rotating at the end that is no motion (q fixed, omega not zero); regenerate with a longer "
                   "`simulation.duration` to track it longer.")]
    lines += ["", "## Requirements and the default reference", "",
              ("Each exported row's reference is scored against the scenario's requirements as `slewbench run` "
               "scores it (the reference on its own sampling, through the closed-loop window)."), ""]
    for label in tables:
        broken = violations_by_row.get(label)
        lines.append(f"- {label}: " + ("breaks " + "; ".join(broken) if broken else "meets them"))
    lines += ["", f"`SLEWBENCH_PARAMS_DEFAULT`: {default_reason}"]
    return "\n".join(lines) + "\n"


def _default_row(labels: list[str], broken: dict[str, list[str]], tracks: bool,
                 scored: bool = True, missed: dict[str, tuple[str, ...]] | None = None) -> tuple[str | None, str]:
    """The row ``SLEWBENCH_PARAMS_DEFAULT`` tracks, and why: the first exported row that meets the
    requirements and whose table meets its tolerances; else the first that meets the requirements,
    else the first whose table meets its tolerances, else the first exported row (each with a
    warning saying what it misses); none (regulation) when the law reads no reference or no row is
    exported. ``scored``: the scenario has requirements to meet; ``missed``: label -> the quantities
    its table misses (:attr:`TableError.failed`), absent or empty when met."""
    if not tracks:
        return None, "regulation to the target (the law reads no reference)"
    if not labels:
        return None, "regulation to the target (no row was exported)"
    missed = missed or {}
    ok = [label for label in labels if label not in broken]
    exact = [label for label in labels if not missed.get(label)]
    good = [label for label in ok if label in exact]
    pick = (good or ok or exact or labels)[0]
    wants = (["that meets the scenario's requirements"] if ok and scored else []) + \
        (["whose table meets its tolerances"] if pick in exact else [])
    text = f"track row {pick!r}, the first exported row" + (" " + " and ".join(wants) if wants else "")
    if not scored:
        text += " (the scenario states no requirement to meet)"
    before = labels[:labels.index(pick)]
    skipped = [f"{label!r} " + ("breaks the requirements" if label in broken and ok else
                                f"misses its table's tolerances ({', '.join(missed[label])})") for label in before]
    if skipped:
        text += f" ({'; '.join(skipped)})"
    warnings = ([] if ok else ["every exported row breaks the scenario's requirements"]) + \
        ([] if pick in exact else [f"its table misses its tolerances ({', '.join(missed[pick])}), as does every "
                                   + ("exported row's" if not ok else "table of a row that meets the requirements")])
    return pick, text + "".join(f"; WARNING: {warning}" for warning in warnings)


def generate(scenario: Scenario, out: str | Path, tolerance: TableTolerance | None = None) -> CodegenReport:
    """Write the C export of ``scenario`` into ``out`` (see the module docstring).

    Parameters
    ----------
    scenario : Scenario
        A loaded scenario.
    out : str or Path
        The output directory (new, empty, or written by slewbench before).
    tolerance : TableTolerance or None, optional
        What each reference table must meet; ``None``: the defaults.

    Returns
    -------
    CodegenReport
        The directory, files, generated functions, exported tables and skipped planner rows.

    Raises
    ------
    ScenarioError
        The controller has no symbolic law (with its reason).
    OutputError
        ``out`` is not slewbench's to write (:func:`scenarios.output.directory.claim_output_directory`).
    """
    tolerance = tolerance or TableTolerance()
    problem, spec = scenario.problem, scenario.simulation
    laws = []
    for controller_spec in scenario.controllers:
        controller = controller_spec.controller
        reason = controller.symbolic_error()
        if reason is not None:
            raise ScenarioError(f"{controller_spec.path}.name",
                                f"controller {controller.name} cannot be exported as C: {reason}")
        laws.append(controller)
    directory = claim_output_directory(out, kind="codegen")
    stem = f"slewbench_{c_identifier(scenario.name)}"
    report = CodegenReport(directory, notes=not_generated(scenario))
    functions: list[ca.Function] = []
    taken: set[str] = {"slewbench_saturate", "slewbench_segment"}
    spacecraft = problem.spacecraft
    interface: dict[str, Any] = {
        "scenario": scenario.name, "controller": laws[0].name, "sample_time_s": spec.sample_time,
        "library": f"lib{stem}.so", "laws": {}, "references": {}, "tables": {},
    }
    law_stems = row_stems([c.label for c in scenario.controllers])
    z0: Any = None
    constants = SymbolicConstants()
    law_parameters: dict[str, tuple[list[ca.SX], list[ca.SX], SymbolicConstants]] = {}
    law_reads: dict[str, set[str]] = {}
    reads_rows: dict[str, bool] = {}
    for controller, controller_spec, law_stem in zip(laws, scenario.controllers, law_stems):
        controller.reset(spacecraft, spec.sample_time, target=(problem.qf, problem.omegaf))
        law = controller.symbolic_law()
        # One controller: "slewbench_law"; several: one function per controller, named by its label.
        name = _unique("slewbench_law" if len(laws) == 1 else f"slewbench_law_{c_identifier(law_stem)}", taken)
        # The first law shares its parameters with the saturation stage (slewbench_step); others have their own.
        own = constants if z0 is None else SymbolicConstants()
        own.get("sample_time", float(spec.sample_time))
        inputs, outputs = controller.parametric_law(own)
        law_reads[name] = {key for key, (symbol, _) in own.symbols.items()
                           if ca.depends_on(ca.vertcat(*outputs), ca.vec(symbol))}
        reads_rows[name] = bool(ca.depends_on(ca.vertcat(*outputs), inputs[3]))
        law_parameters[name] = (inputs, outputs, own)
        z0 = law.state0 if z0 is None else z0
        description = {
            "controller": controller.name, "label": controller_spec.label,
            "inputs": {"t": 1, "y": law.function.nnz_in(1), "z": law.function.nnz_in(2), "r": 2 * REFERENCE_FIELDS},
            "outputs": {"u": law.function.nnz_out(0), "z_next": law.function.nnz_out(1)},
            "z0": law.state0.tolist(),
            "y_layout": "[q (4), omega (3, rad/s), h_w (n_w, N m s), b (3, T; zeros without a field model)]",
            "r_layout": ("reference rows [q, omega, omega_dot, torque] at t and t + sample_time (the target rows "
                         "for a law that regulates)"),
            "u_layout": {key: [s.start, s.stop] for key, s in control_layout(spacecraft)[0].items()},
        }
        interface["laws"][name] = description
        if len(laws) == 1:
            interface["slewbench_law"] = description
    saturation = _saturation(spacecraft, constants)  # adds the limits to the first law's parameters
    for name, (inputs, outputs, own) in law_parameters.items():
        functions.append(ca.Function(name, [*inputs, own.vector()], outputs, ["t", "y", "z", "r", "p"], ["u", "z_next"]))
        interface["laws"][name]["inputs"]["p"] = int(own.vector().numel())
        interface["laws"][name]["parameters"] = _parameter_code(own)[3]
        interface["laws"][name]["reads_parameters"] = sorted(law_reads[name])
        interface["laws"][name]["reads_r"] = reads_rows[name]
    step_law = functions[0].name()
    functions += [saturation, segment_function("slewbench_segment")]
    tables: dict[str, tuple[str, Any]] = {}
    stems = row_stems([p.label for p in scenario.planners])
    for planner_spec, row in zip(scenario.planners, stems):
        # the reference as `slewbench run` plans and samples it for its scores
        reference, _, sampled = plan_row(scenario, planner_spec, None, scoring=True)
        if not reference.ok:
            report.skipped[planner_spec.label] = f"the plan {reference.status}: {reference.message}"
            continue
        assert sampled is not None  # scoring=True samples it
        scores = score_reference(scenario.requirements, problem, *sampled, laws[0], reference,
                                 plant_limits(scenario.truth))
        broken = violations({"reference": scores})
        if broken:
            report.violations[planner_spec.label] = broken
        # through every time the closed loop reads: its window, then the reference one sample ahead
        table, error = tabulate(reference, tolerance, closed_loop_window(scenario, reference) + spec.sample_time)
        table_name = _unique(f"slewbench_table_{c_identifier(row)}", taken)
        tables[planner_spec.label] = (table_name, table)
        report.tables[planner_spec.label] = error
        interface["tables"][planner_spec.label] = {
            "table": table_name, "nodes": int(table.times.size), "duration_s": reference.duration,
            "end_s": table.end, "after_end": "holds the last row",
            "requirements_met": not broken, "violations": broken,
            "error": {"attitude_rad": error.attitude_rad, "rate_rad_s": error.rate,
                      "omega_dot_rad_s2": error.acceleration, "torque_N_m": error.torque,
                      "points_checked": error.points, "tolerances_met": error.met,
                      "tolerances_failed": list(error.failed)}}
        evaluator = reference.symbolic_evaluator() if planner_spec.planner.closed_form else None
        if evaluator is not None:
            name = _unique(f"slewbench_reference_{c_identifier(row)}", taken)
            functions.append(_renamed(evaluator, name))
            interface["references"][planner_spec.label] = {"function": name, "duration_s": reference.duration,
                                                           "output": "row [q, omega, omega_dot, torque] (13)"}
    tracks = bool(getattr(laws[0], "tracks_reference", False) or getattr(laws[0], "needs_reference", False))
    report.default, report.default_reason = _default_row(list(tables), report.violations, tracks,
                                                         bool(scenario.requirements),
                                                         {label: error.failed for label, error in report.tables.items()})
    default_reference = None if report.default is None else tables[report.default][0]
    target = reference_rows(None, [0.0], (problem.qf, problem.omegaf))[0]
    slices, nu = control_layout(spacecraft)
    u_layout = "[" + ", ".join(f"{key} ({s.stop - s.start})" for key, s in slices.items()) + "]"
    work = [f.sz_arg() for f in functions], [f.sz_res() for f in functions], \
        [f.sz_iw() for f in functions], [f.sz_w() for f in functions]
    parameter_fields, parameter_defaults, parameter_pack, parameters = _parameter_code(constants)
    saturation_output = ca.vertcat(*saturation.call(saturation.sx_in()))
    saturation_reads = {key for key, (symbol, _) in constants.symbols.items()
                        if ca.depends_on(saturation_output, ca.vec(saturation.sx_in(2)[parameters_offset(parameters, key)]))}
    readers = [(p["name"], p["shape"], [who for who, reads in ((step_law, law_reads[step_law]),
                                                               ("slewbench_saturate", saturation_reads))
                                        if p["name"] in reads]) for p in parameters]
    for p, (_, _, who) in zip(parameters, readers):
        p["read_by"] = who
    interface["parameters"] = parameters
    values = {"SCENARIO": scenario.name, "CONTROLLER": laws[0].name, "VERSION": package_version(),
              "N_WHEELS": str(spacecraft.n_wheels), "NU": str(nu), "NZ": str(int(np.size(z0))),
              "U_LAYOUT": u_layout, "SAMPLE_TIME": repr(float(spec.sample_time)),
              "DEFAULT_REFERENCE": "0" if default_reference is None else f"&{default_reference}",
              "DEFAULT_REFERENCE_TEXT": (report.default_reason + ("" if default_reference is None else
                                                                  f", {default_reference}")).replace("*/", "* /"),
              "TARGET": _c_numbers(target), "GENERATED": stem, "LAW": step_law,
              "SZ_ARG": str(max(1, *work[0])), "SZ_RES": str(max(1, *work[1])),
              "SZ_IW": str(max(1, *work[2])), "SZ_W": str(max(1, *work[3])),
              "Z0": _c_numbers(z0), "STEM": stem,
              "DEFAULT_DECLARATION": ("" if default_reference is None else
                                      f"extern const slewbench_table {default_reference}; /* slewbench_tables.c */"),
              "PARAM_FIELDS": parameter_fields, "PARAM_DEFAULTS": parameter_defaults, "PACK": parameter_pack,
              "NP": str(max(1, int(constants.vector().numel()))),
              "BAKES_SAMPLE_TIME": "0" if "sample_time" in law_reads[step_law] else "1",
              "TRACKS": "1" if tracks else "0"}
    interface["skipped"] = dict(report.skipped)
    interface["not_generated"] = list(report.notes)
    interface["step"] = {"law": step_law, "saturation": "slewbench_saturate", "segment": "slewbench_segment",
                         "default_reference": default_reference, "default_row": report.default,
                         "default_reason": report.default_reason, "target": target.tolist()}
    tables_h, tables_c = _tables_files(tables)
    staging = new_staging(directory)
    try:
        generator = ca.CodeGenerator(f"{stem}.c", {"with_header": True})
        for function in functions:
            generator.add(function)
        generator.generate(f"{staging}/")
        texts = {"slewbench_step.h": _template("slewbench_step.h.in", values), "slewbench_step.c": _template("slewbench_step.c.in", values),
                 "example.c": _template("example.c.in", values), "Makefile": _template("Makefile.in", values),
                 "slewbench_tables.h": tables_h, "slewbench_tables.c": tables_c,
                 "README.md": _readme(scenario, stem, step_law, tables, report.tables, report.skipped, tolerance,
                                      readers, law_reads[step_law], reads_rows[step_law], report.violations,
                                      report.default_reason),
                 "interface.json": json.dumps(interface, indent=1) + "\n"}
        for name, text in texts.items():
            (staging / name).write_text(text)
        report.files = {path.name: path.stat().st_size for path in sorted(staging.iterdir())}
        commit_outputs(directory, staging, kind="codegen")
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    report.functions = [f.name() for f in functions]
    return report
