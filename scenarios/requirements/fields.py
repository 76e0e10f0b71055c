"""The requirement fields, declared once: each field's unit, its words on an axis, the requirement
and scopes that give it, and its definition in the documentation.

A row's requirement scores are the result columns ``ref.req.<name>.<field>`` and
``cl.req.<name>.<field>`` (:mod:`scenarios.requirements.scoring` computes them). Every reader of
those columns asks :func:`field_info` what a field holds: the HTML report's units
(:func:`scenarios.output.report.column_unit`), the units line of ``results.md``
(:func:`scenarios.output.tables.to_markdown`), the axis labels of the figures
(:func:`scenarios.output.plot_data.column_quantity`), and the documentation's table of the fields
(written from :data:`REQUIREMENT_FIELDS` when the documentation is built).

The requirement of a column is read from its name: ``actuators``, ``rate`` and ``final`` are the
names of those requirements (a pointing requirement may not take one,
:data:`~scenarios.requirements.spec.RESERVED_NAMES`); any other name is a pointing requirement's.
The actuator requirement's fields per actuator quantity (``wheels_torque``, ``wheels_momentum``,
``magnetorquers_dipole``, ``torquers_torque``: one per actuator kind's command and its states,
:func:`controllers.allocation.demand_limits`; in the closed loop ``wheels_momentum`` and, under a
truth speed limit, ``wheels_speed``) are declared once for all quantities, as the patterns
``<quantity>`` and ``<quantity>_time_s``.

Every requirement's score also carries its verdict in that scope, the field :data:`VERDICT`
(``met``, a bool: ``ref.req.<name>.met``, ``cl.req.<name>.met``; :data:`VERDICT_UNIT` its unit): the
scoring's own, which the report's sign-off record and a study's counts read, never the row's message.
It is a verdict, not a measurement: no table averages it (a study counts it, ``requirements.csv``).

Plain data, importing nothing of slewbench: the plot process (:mod:`scenarios.output.plots`)
reads it without loading the model.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

__all__ = ["QUANTITY", "REQUIREMENT_FIELDS", "VERDICT", "VERDICT_UNIT", "RequirementField", "field_info",
           "is_requirement_column", "is_verdict_column", "requirement_kind"]

QUANTITY = "<quantity>"
"""The placeholder of an actuator quantity's name in the patterns of :data:`REQUIREMENT_FIELDS`."""

VERDICT = "met"
"""The field of a requirement's verdict in a scope (``ref.req.<name>.met``): true when the requirement
holds there (:attr:`scenarios.requirements.scoring.Score.met`), a bool, never a number."""
VERDICT_UNIT = "true/false"
"""The unit of :data:`VERDICT`: the readers that format a number by its unit (``–`` a ratio) leave it
alone."""

_SCOPE_PREFIXES = ("ref", "cl")
"""The scope prefixes of the requirement columns (:data:`scenarios.schema.columns.SCOPES`)."""
_MARK = "req"
"""The segment after the scope prefix of a requirement column
(:data:`scenarios.schema.columns.REQUIREMENT_MARK`)."""
_KINDS_BY_NAME = {"actuators": "actuators", "rate": "rate", "final": "final"}
"""The requirement names that are not a pointing requirement's, and their kind (the same word)."""


@dataclass(frozen=True)
class RequirementField:
    """One field of a requirement's score (a pattern for the actuator quantities' fields).

    Parameters
    ----------
    requirement : str
        The requirement kind that gives it: ``pointing``, ``actuators``, ``rate`` or ``final``.
    field : str
        Its name in the columns ``<scope>.req.<name>.<field>``; in the patterns of the actuator
        quantities, ``<quantity>`` stands for the quantity's name (``wheels_torque``).
    unit : str
        Its unit: ``deg``, ``s``, ``rad/s``, ``N m``, or ``–`` for a ratio.
    words : str
        What it is, for an axis label (``{quantity}`` stands for the quantity's name in words).
    meaning : str
        Its definition, for the documentation (reStructuredText inline markup).
    scopes : tuple of str
        The prefixes of the scopes that give it: ``ref`` (the reference), ``cl`` (the closed loop).

    Unit ``–`` is a ratio, :data:`VERDICT_UNIT` the verdict (a bool); every other unit a number's.
    """

    requirement: str
    field: str
    unit: str
    words: str
    meaning: str
    scopes: tuple[str, ...] = ("ref", "cl")


_POINTING = (
    RequirementField(
        "pointing", "min_margin_deg", "deg", "min margin",
        "Smallest margin inside the requirement's window: the angle between the boresight and the direction "
        "less the cone (keep-out), or the cone less the angle (keep-in); negative when violated; null when no "
        "sample lies in the window. Between the samples too (reference and closed loop), the window's edges "
        "included."),
    RequirementField(
        "pointing", "time_in_violation_s", "s", "time in violation",
        "Time with a negative margin inside the window, the zero crossings interpolated linearly between the "
        "points scored (the samples' sub-grid)."),
    RequirementField(
        "pointing", "first_violation_s", "s", "first violation",
        "When the margin first goes negative (interpolated); null if it never does."),
    RequirementField(
        "pointing", "min_margin_time_s", "s", "time of min margin",
        "When the margin is smallest."),
)
_ACTUATORS = (
    RequirementField(
        "actuators", QUANTITY, "–", "peak {quantity} / limit",
        "Peak demand over the limit, through the row's controller's allocation: ``wheels_torque`` (motor "
        "torque over ``max_torque``), ``wheels_momentum`` (over ``max_momentum``), ``magnetorquers_dipole`` "
        "(over ``max_dipole``), ``torquers_torque`` (over ``max_torque``), the largest over the elements and "
        "samples; only quantities with a limit; a declared free start's momentum the wheels cannot take is "
        "asked too, as a constant torque over the manoeuvre (:func:`~scenarios.requirements.scoring.start_torque`). "
        "Met at most ``1 − margin``; null when the demand is not "
        "finite (nan, inf), which breaks the requirement. In the closed loop (``cl.``), the flown wheels' "
        "own ``wheels_momentum``, ``|h_i|`` over the limit at the samples, and under a truth speed limit "
        "``wheels_speed``, ``|Ω_i|`` (the speed relative to the body) over ``truth.wheels.max_speed_rpm`` "
        "(:func:`~scenarios.requirements.scoring.closed_loop_wheels`): the simulator holds a wheel at its "
        "limit by cutting its motor torque, so reaching 1 breaks the requirement.", ("ref", "cl")),
    RequirementField(
        "actuators", f"{QUANTITY}_time_s", "s", "time of peak {quantity}",
        "When that peak occurs (the first sample where the demand is not finite, when it is not).", ("ref", "cl")),
    RequirementField(
        "actuators", "rate_jump", "rad/s", "rate jump",
        "The largest jump of the reference's body rate (0 without one): across a breakpoint (natural "
        "motion's step stop), or at t = 0 from the manoeuvre's initial rate when the reference does not "
        "declare ``omega0`` free (a declared free start is an initial tracking error, "
        "``initial_rate_error``, left to the closed loop). No finite torque gives a jump: any jump (over "
        "1e-6 rad/s) breaks the requirement. Its momentum ``I Δω`` goes to the wheels at once, in "
        "``wheels_momentum``.", ("ref",)),
    RequirementField(
        "actuators", "rate_jump_time_s", "s", "time of rate jump",
        "When that jump happens; null without one.", ("ref",)),
    RequirementField(
        "actuators", "unrealised_torque", "N m", "unrealised torque",
        "The largest torque the reference asks that the allocation's commands do not give "
        "(:func:`~controllers.allocation.unrealised_torque`): torque about an axis no working actuator spans "
        "(one wheel, failed wheels without torquers; along the field for magnetorquers alone), which no "
        "limit shows, since nothing is commanded for it; with the torque that removes a declared free "
        "start's momentum the wheels cannot take over the manoeuvre "
        "(:func:`~scenarios.requirements.scoring.start_torque`). Above 1 % of the reference's peak torque "
        "(:data:`~scenarios.requirements.scoring.UNREALISED_TOLERANCE`) it breaks the requirement; null "
        "when it is not finite.", ("ref",)),
    RequirementField(
        "actuators", "unrealised_torque_time_s", "s", "time of unrealised torque",
        "When that torque is asked; null when every torque asked is given.", ("ref",)),
    RequirementField(
        "actuators", "unrealised_torque_allowed", "N m", "unrealised torque allowed",
        "The most ``unrealised_torque`` may be: 1 % of the reference's peak torque (at least 1e-14 N m, "
        "rounding for a reference that asks no torque); null when that peak is not finite.", ("ref",)),
)
_RATE = (
    RequirementField("rate", "peak_rate", "rad/s", "peak rate",
                     "The largest ‖ω‖ (at the samples only)."),
    RequirementField("rate", "peak_time_s", "s", "time of peak rate", "When it occurs."),
    RequirementField("rate", "ratio", "–", "peak rate / bound",
                     "``peak_rate`` over ``requirements.rate.max`` (met at most 1)."),
)
_FINAL = (
    RequirementField(
        "final", "worst_error_deg", "deg", "worst final error",
        "From ``T + after_s`` to the end: the largest error angle to ``maneuver.final.q`` (where the "
        "manoeuvre ends turning, to the target's motion after T: ``ocp.metrics.target_motion``), between "
        "the samples too (the attitude interpolated as for pointing).", ("cl",)),
    RequirementField(
        "final", "worst_rate_error", "rad/s", "worst final rate error",
        "From ``T + after_s`` to the end: the largest ‖ω − ω_f‖ (ω_f the target's rate, as for the "
        "error; **at the samples only**).", ("cl",)),
    RequirementField(
        "final", "from_s", "s", "final window start",
        "Where that stretch starts, ``T + after_s`` (T: the reference's duration).", ("cl",)),
)



def _verdict(kind: str, scopes: tuple[str, ...]) -> tuple[RequirementField]:
    """The verdict field (:data:`VERDICT`) of a requirement kind, first among its fields."""
    return (RequirementField(
        kind, VERDICT, VERDICT_UNIT, "met",
        "Whether the requirement holds in that scope (``true``, ``false``): the scoring's verdict on the whole "
        "requirement, on which the row's status (``violated`` when one is ``false``) and the report's "
        "sign-off record rest; in a study, counted per requirement and scope (``requirements.csv``), never "
        "averaged.", scopes),)


REQUIREMENT_FIELDS: tuple[RequirementField, ...] = (
    _verdict("pointing", ("ref", "cl")) + _POINTING + _verdict("actuators", ("ref", "cl")) + _ACTUATORS
    + _verdict("rate", ("ref", "cl")) + _RATE + _verdict("final", ("cl",)) + _FINAL)
"""Every requirement field, by requirement kind in column order, each kind's verdict (:data:`VERDICT`)
first (the actuator quantities' fields as the patterns ``<quantity>`` and ``<quantity>_time_s``)."""


def is_requirement_column(column: str) -> bool:
    """Whether a column holds a requirement score (``ref.req.<name>.<field>``, ``cl.req.<name>.<field>``).

    Parameters
    ----------
    column : str
        A column name.

    Returns
    -------
    bool
        True for ``<prefix>.req.<name>.<field>`` with a scope prefix and non-empty name and field
        (a verdict, :func:`is_verdict_column`, too).
    """
    parts = column.split(".")
    return len(parts) == 4 and parts[0] in _SCOPE_PREFIXES and parts[1] == _MARK and all(parts[2:])


def is_verdict_column(column: str) -> bool:
    """Whether a column is a requirement's verdict: ``ref.req.<name>.met`` or ``cl.req.<name>.met``.

    Parameters
    ----------
    column : str
        A column name.

    Returns
    -------
    bool
        True for a requirement column (``<scope>.req.<name>.<field>``) whose field is :data:`VERDICT`.
    """
    return is_requirement_column(column) and column.rsplit(".", 1)[1] == VERDICT


def requirement_kind(name: str) -> str:
    """The kind of the requirement of a name (the ``<name>`` of ``<scope>.req.<name>.<field>``).

    Parameters
    ----------
    name : str
        A requirement's name.

    Returns
    -------
    str
        ``actuators``, ``rate`` or ``final`` for those names; ``pointing`` for any other.
    """
    return _KINDS_BY_NAME.get(name, "pointing")


def _lookup(kind: str, field: str) -> RequirementField | None:
    """The declaration of ``field`` in a requirement of ``kind``, an actuator quantity's pattern
    filled in (its words too); None when that kind has no such field."""
    for declared in REQUIREMENT_FIELDS:
        if declared.requirement == kind and declared.field == field:
            return declared
    if kind != "actuators" or not field:
        return None
    quantity, timed = (field.removesuffix("_time_s"), True) if field.endswith("_time_s") else (field, False)
    if not quantity:
        return None
    pattern = next(d for d in _ACTUATORS if d.field == (f"{QUANTITY}_time_s" if timed else QUANTITY))
    return replace(pattern, field=field, words=pattern.words.format(quantity=quantity.replace("_", " ")))


def field_info(column_or_field: str) -> RequirementField:
    """What a requirement field holds: its unit, words and definition.

    Parameters
    ----------
    column_or_field : str
        A requirement column ``<scope>.req.<name>.<field>`` (``ref.req.st_sun.min_margin_deg``), a
        ``<name>.<field>`` (``actuators.rate_jump``) or a bare field (``peak_rate``; a field no
        pointing, rate or final requirement has is read as an actuator quantity's).

    Returns
    -------
    RequirementField
        The field's declaration in :data:`REQUIREMENT_FIELDS`; for an actuator quantity's field,
        the pattern's with ``field`` the field itself and the quantity in ``words``.

    Raises
    ------
    KeyError
        When the requirement named has no such field (``ref.req.st_sun.peak_rate``: a pointing
        requirement has no peak rate), or the text is no requirement field.
    """
    parts = column_or_field.split(".")
    if len(parts) == 4 and parts[0] in _SCOPE_PREFIXES and parts[1] == _MARK:
        name, field = parts[2], parts[3]
    elif len(parts) == 2:
        name, field = parts
    elif len(parts) == 1:
        for declared in REQUIREMENT_FIELDS:
            if declared.field == column_or_field:
                return declared
        name, field = "actuators", column_or_field
    else:
        raise KeyError(f"not a requirement field or column: {column_or_field!r}")
    found = _lookup(requirement_kind(name), field) if name else None
    if found is None:
        raise KeyError(f"not a field of the {requirement_kind(name)} requirement {name!r}: {column_or_field!r}")
    return found
