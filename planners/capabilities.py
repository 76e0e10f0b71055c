"""Capabilities that references and planners may offer, checked by what they offer, not by name.

A controller that needs more than the :class:`~planners.base.Reference` contract (co-states, ...)
asks for a capability here; any planner whose references offer it qualifies.
"""
from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

from planners.problem import Array


@runtime_checkable
class CostateCarrier(Protocol):
    """A reference that offers its optimal states and co-states, and its optimal control law as a
    function of an estimated rate co-state (an indirect method's reference).

    ``state_and_costate(t) -> (x (n, 7), λ (n, 7))`` with ``x = [q, ω]`` at times ``t`` (s);
    ``feedback_torque(λ_ω, λ_ω_ref) -> u`` (N m, body axes) is the control for the estimated rate
    co-state ``λ_ω`` (the reference's own value ``λ_ω_ref`` fixes any normalisation).
    """

    duration: float

    def __init__(self, *args: Any, **kwargs: Any) -> None:  # typing would insert an unannotated one
        ...

    def state_and_costate(self, t: Any) -> tuple[Array, Array]:
        """Optimal states and co-states.

        Parameters
        ----------
        t : float or (n,) array_like
            Times [s] within ``[0, duration]``.

        Returns
        -------
        tuple of ndarray
            ``x (n, 7) = [q, ω]`` (scalar-first quaternion, body rate [rad/s], body axes) and
            ``λ (n, 7)``, its co-state.
        """
        ...

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array:
        """The optimal control for an estimated rate co-state.

        Parameters
        ----------
        lam_omega : (3,) ndarray
            Estimated rate co-state.
        lam_omega_reference : (3,) ndarray
            The reference's own rate co-state at the same time (fixes any normalisation).

        Returns
        -------
        (3,) ndarray
            Torque [N m], body axes.
        """
        ...


def minimises_time(planner: type, options: Any) -> bool:
    """Whether a planner chooses its references' duration by minimising time (a free final time),
    rather than planning over the scenario's ``T`` or a duration of its own that it does not
    minimise.

    Parameters
    ----------
    planner : type
        A planner class; it says so through a class method ``minimises_time(options)``.
    options : object
        The planner's parsed ``Options``.

    Returns
    -------
    bool
        ``True`` when it does (``False`` for planners without the class method).
    """
    return _declared(planner, "minimises_time", options)


def offers_costates(planner: type, options: Any) -> bool:
    """Whether a planner returns :class:`CostateCarrier` references whose control is a torque.

    Parameters
    ----------
    planner : type
        A planner class; it says so through a class method ``offers_costates(options)``.
    options : object
        The planner's parsed ``Options``.

    Returns
    -------
    bool
        ``True`` when it does (``False`` for planners without the class method).
    """
    return _declared(planner, "offers_costates", options)


def _declared(planner: type, capability: str, options: Any) -> bool:
    """What the planner's class method ``capability(options)`` says; ``False`` without one."""
    check = getattr(planner, capability, None)
    return bool(check(options)) if callable(check) else False
