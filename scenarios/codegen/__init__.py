"""Flight C of a scenario (``slewbench codegen``): the controller law, the simulator's saturation
stage and every planner row's reference as a table, behind a flight interface
``slewbench_step(t, measurement, params, command, state)``.

* :mod:`~scenarios.codegen.tables`: a reference as a table, the one interpolation that reads it
  (NumPy and CasADi, generated as C) and the table's stated error against the reference;
* :mod:`~scenarios.codegen.export`: the output directory: CasADi-generated functions, the tables,
  the C templates (``templates/``: the wrapper, the worked example, the Makefile) filled in.

May import: :mod:`ocp`, :mod:`planners`, :mod:`controllers`, :mod:`scenarios.errors`,
:mod:`scenarios.requirements`, :mod:`scenarios.schema`, :mod:`scenarios.output` and
:mod:`scenarios.runner`. The names below are
imported on first use (CasADi's code generator is only for this command).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from scenarios._faces import lazy_face

if TYPE_CHECKING:
    from scenarios.codegen.export import CodegenReport, c_identifier, generate
    from scenarios.codegen.tables import (
        ReferenceTable,
        TableError,
        TableReference,
        TableTolerance,
        interpolate,
        segment_function,
        tabulate,
    )

_HOMES = {"CodegenReport": "scenarios.codegen.export", "c_identifier": "scenarios.codegen.export",
          "generate": "scenarios.codegen.export", "ReferenceTable": "scenarios.codegen.tables",
          "TableError": "scenarios.codegen.tables", "TableReference": "scenarios.codegen.tables",
          "TableTolerance": "scenarios.codegen.tables", "interpolate": "scenarios.codegen.tables",
          "segment_function": "scenarios.codegen.tables", "tabulate": "scenarios.codegen.tables"}

__all__ = ["CodegenReport", "ReferenceTable", "TableError", "TableReference", "TableTolerance", "c_identifier",
           "generate", "interpolate", "segment_function", "tabulate"]
__getattr__, __dir__ = lazy_face(__name__, _HOMES)
