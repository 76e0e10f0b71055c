"""Row labels: how a scenario's planner and controller labels name the rows of its run.

One function, :func:`row_labels`, for the schema's check, the runner and a trade study's worker
(which labels a crashed case's rows from the scenario's mapping). Imports only
:mod:`scenarios.errors`.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from scenarios.errors import ScenarioError

SEPARATOR = " / "
"""Between the planner's and the controller's label in a row label (several controllers)."""


class RowLabel(NamedTuple):
    """One row of a run: its label and the planner and controller it pairs.

    Parameters
    ----------
    label : str
        The row's label in the tables and file names.
    planner : int or None
        Index of the planner in the scenario's ``planners`` list; ``None`` in regulation mode.
    controller : int
        Index of the controller in the scenario's controllers (``controller`` is index 0).
    """

    label: str
    planner: int | None
    controller: int


def row_labels(planners: Sequence[str], controllers: Sequence[str]) -> list[RowLabel]:
    """The rows of a scenario, in run order, and their labels, which must be distinct.

    With planners, one row per planner and controller (planner-major), labelled with the planner's
    label when there is one controller and ``"<planner label> / <controller label>"`` with
    several. Without planners (regulation mode), one row per controller, labelled with the
    controller's label.

    Parameters
    ----------
    planners : sequence of str
        The planners' labels, in the scenario's order (empty: regulation mode).
    controllers : sequence of str
        The controllers' labels, in the scenario's order (at least one).

    Returns
    -------
    list of RowLabel
        One per row, labels pairwise distinct.

    Raises
    ------
    ScenarioError
        Two rows with the same label: at ``planners[i].label`` or ``controllers[j].label`` when two
        planners or two controllers share a label, at ``controllers[j].label`` when two different
        pairs make the same combined label.
    """
    if not planners:
        rows = [RowLabel(label, None, j) for j, label in enumerate(controllers)]
    elif len(controllers) == 1:
        rows = [RowLabel(label, i, 0) for i, label in enumerate(planners)]
    else:
        rows = [RowLabel(f"{planner}{SEPARATOR}{controller}", i, j)
                for i, planner in enumerate(planners) for j, controller in enumerate(controllers)]
    seen: dict[str, RowLabel] = {}
    for row in rows:
        first = seen.setdefault(row.label, row)
        if first is not row:
            raise _collision(first, row, planners, controllers)
    return rows


def _collision(first: RowLabel, second: RowLabel, planners: Sequence[str], controllers: Sequence[str]) -> ScenarioError:
    """The error for two rows with one label, at the entry that made the second."""
    if second.planner is None or (first.planner == second.planner and len(controllers) > 1):
        label = controllers[second.controller]
        return ScenarioError(f"controllers[{second.controller}].label",
                             f"duplicate label {label!r}; give each controller its own label")
    if first.controller == second.controller:
        return ScenarioError(f"planners[{second.planner}].label",
                             f"duplicate label {planners[second.planner]!r}; give each row its own label")
    return ScenarioError(f"controllers[{second.controller}].label",
                         f"row label {second.label!r} is made twice (planners[{first.planner}] with "
                         f"controllers[{first.controller}], planners[{second.planner}] with "
                         f"controllers[{second.controller}]); choose labels without {SEPARATOR!r}")
