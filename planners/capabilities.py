"""Capabilities that references and planners may offer, checked by what they offer, not by name.

A controller that needs more than the :class:`~planners.base.Reference` contract (co-states, ...)
asks for a capability here; any planner whose references offer it qualifies.
"""
from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

from planners.base import Array


@runtime_checkable
class CostateCarrier(Protocol):
    """A reference that offers its optimal states and co-states, and its optimal control law as a
    function of an estimated rate co-state (an indirect method's reference).

    ``state_and_costate(t) -> (x (n, 7), λ (n, 7))`` with ``x = [q, ω]`` at times ``t`` (s);
    ``feedback_torque(λ_ω, λ_ω_ref) -> u`` (N m, body axes) is the control for the estimated rate
    co-state ``λ_ω`` (the reference's own value ``λ_ω_ref`` fixes any normalisation).
    """

    duration: float

    def state_and_costate(self, t: Any) -> tuple[Array, Array]: ...

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array: ...


def offers_costates(planner: type, options: Any) -> bool:
    """Whether ``planner`` (a class) with ``options`` returns :class:`CostateCarrier` references
    whose control is a torque: it says so through a class method ``offers_costates(options)``."""
    check = getattr(planner, "offers_costates", None)
    return bool(check(options)) if callable(check) else False
