"""Planner contract: :class:`ManeuverProblem` in, :class:`Reference` out.

A planner turns a manoeuvre problem into a reference motion. The base class :class:`Planner`
states the contract, :class:`Reference` what a reference provides (a :class:`ReferenceSample` of
``q``, ``ω``, ``ω̇`` and the rigid-body feed-forward torque at any times); one module per method
implements it; ``planners.PLANNERS`` (:mod:`planners.registry`) maps registry names to classes. The
extension guide :doc:`/extending/planner` walks through a complete example, and
:mod:`planners.conformance` checks the contract.

The parts of the contract live in :mod:`planners.problem` (:class:`ManeuverProblem`),
:mod:`planners.reference` (:class:`Reference`, :class:`ReferenceSample`, :class:`FailedReference`,
:func:`inverse_dynamics_torque`) and :mod:`planners.torque_free` (the continuation after T); the
package's face (:mod:`planners`) exports the names a planner needs.

Conventions: scalar-first Hamilton quaternions ``q`` rotating body vectors to inertial, body rate
``ω`` of the body relative to inertial in body axes, SI units (s, rad, rad/s, N m, kg m^2).
"""
from __future__ import annotations

import copy
import time
from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import replace
from typing import Any, ClassVar

from ocp import SolverCache
from ocp.options import Configurable
from planners.problem import ManeuverProblem
from planners.reference import (
    FailedReference,
    Reference,
)

__all__ = ["REQUIREMENT_KINDS", "REQUIREMENT_TOLERANCE", "Planner"]

REQUIREMENT_KINDS: tuple[str, ...] = ("pointing", "actuators", "rate")
"""The requirement kinds a planner may honour (:attr:`Planner.honours`)."""

REQUIREMENT_TOLERANCE = 1e-9
"""Relative slack on a requirement's bound, rounding and not a margin: a quantity at most
``(1 + REQUIREMENT_TOLERANCE)`` times its bound (the body-rate norm over the rate requirement, an
actuator's demand over ``1 − actuator_margin`` of its limit) meets it. One number for the scorer
(:mod:`scenarios.requirements.scoring`, its ratio and bound checks) and for a planner that honours
the kind and checks its reference densely (``collocation``'s dense check,
:data:`planners.collocation.requirements.BOUND_TOLERANCE`): a reference the planner calls within a
bound is never scored breaking it for the slack alone, nor refused for what the scorer accepts.
(The two grids still differ: the dense check reads :data:`~planners.collocation.requirements.DENSE_POINTS`
points per mesh interval, the scorer its own samples.)"""


class Planner(Configurable, ABC):
    """Base class of every planner.

    Contract
    --------
    * ``name`` is the registry key; ``Options`` is a ``@dataclass(frozen=True)`` of the planner's
      options, each field typed with its range (``Annotated[float, Range(gt=0.0)]``) and a
      default (the YAML ``options:`` mapping is checked against it; relations between options go
      in ``Options.__post_init__``, raising ``InvalidOption``).
    * ``plan(problem)`` returns a :class:`Reference` and sets its ``plan_time_s``. A numerical
      failure (no convergence, infeasible bounds) is returned as a reference with
      ``status="failed"`` or ``"infeasible"`` and a message; ``plan`` does not raise for it.
    * ``problem_error(problem)`` says, cheaply, why the planner cannot take a problem (``None``
      if it can); the scenario loader reports it against the planner's YAML entry and ``plan``
      returns it as a failed reference. By default a planner needs a target attitude.
    * Planners never read YAML and never simulate.
    * ``cache`` (constructor) is an explicit :class:`~ocp.cache.SolverCache` for what the planner
      builds (NLPs); without one, the planner keeps its builds in the model's own cache
      (``problem.model.solver_cache``).
    * The reference meets the problem's boundary conditions ``q(0) = q0``, ``ω(0) = ω0``,
      ``q(T) = qf`` and ``ω(T) = ωf`` (when not ``None``), except those it declares in
      ``Reference.free_boundary``; it satisfies ``q̇ = ½ q ⊗ [0, ω]``, its ``omega_dot`` is the
      derivative of its ``omega`` and its torque the inverse dynamics ``I ω̇ + ω × I ω``.
    * ``example_options`` lists option sets for the conformance test.
    * ``closed_form``: its references are closed-form expressions of time and implement
      :meth:`Reference.symbolic_evaluator`, every one of them (not ``None``), equal to
      :meth:`Reference.sample` at ``t`` clamped to ``[0, T]``: ``slewbench codegen`` exports them as
      C on this declaration alone, and the ``closed_form`` conformance check
      (:func:`planners.conformance.check_closed_form`) compares the two. Without the declaration a
      reference may still offer an evaluator (one a planner of several kinds of reference
      inherits); it is neither exported nor checked.
    * ``deterministic`` (default True): a plan depends only on the planner's class, its options and
      the problem: planned again, by a fresh instance, with its solver cache empty or full, the
      same problem gives the same reference, bit for bit (a multistart seeds its random starts; a
      time limit may only make it fail). A trade study's worker reuses a reference for a case whose
      planning inputs are an earlier case's (:func:`scenarios.runner.planning_key`) on this
      declaration alone; the ``deterministic`` conformance check
      (:func:`planners.conformance.check_deterministic`) plans one problem twice and compares. A
      planner whose plans may differ (an unseeded random start, a result that depends on the wall
      clock or on what its cache held) declares ``deterministic = False``: every row is then planned.
    * ``cheap``: it plans in milliseconds (a closed form or a small parameter search, not a
      trajectory optimisation), so ``collocation`` plans it as a start by default
      (``seed_planners: auto``) wherever :meth:`start_error` accepts the problem (by default
      where :meth:`problem_error` does; a planner whose start may leave out a condition the
      method it starts imposes says so there).
    * ``least_duration(problem)`` says, cheaply and without optimising (a closed form, a small
      search), the least duration its reference for ``problem`` can take, or ``None`` (the
      default) when it cannot say: ``slewbench validate`` predicts from it a slew that ends after
      ``maneuver.duration``, the time budget (the row ``infeasible``,
      :func:`scenarios.requirements.scoring.late_slew`), before anything is planned.
    * ``honours`` names the scenario requirements (:data:`REQUIREMENT_KINDS`) the planner imposes
      on its references (:meth:`honoured`: with given options): ``"pointing"`` (``problem.pointing``, every window and moving direction
      included), ``"actuators"`` (the actuators' limits tightened by ``problem.actuator_margin``),
      ``"rate"`` (``problem.max_rate``). A planner that honours a kind imposes it and checks its
      reference densely (not only at its own points); a reference that still misses returns as a
      failed reference, or keeps its status and says in its message and stats by how much it
      misses (``collocation`` does: ``stats["dense_check"]``). One that does not honour a kind still
      plans, and the scenario scores what it made, as it scores every row.

    Parameters
    ----------
    options : mapping, Options or None, optional
        Option values (the YAML ``options:`` mapping, checked against ``Options``), an ``Options``
        instance, or ``None`` for the defaults.
    path : str, optional
        YAML path of the options, named in error messages (default ``"options"``).
    cache : ocp.SolverCache or None, optional
        Where the planner keeps what it builds (NLPs); ``None`` (default): the model's own cache.

    Raises
    ------
    ocp.options.OptionsError
        For an unknown option, a value of the wrong type or out of its declared range, or a
        relation ``Options.__post_init__`` refuses; the message names ``path`` and the option.
    TypeError
        If ``Options`` is not a dataclass (the ``@dataclass(frozen=True)`` decorator is missing).
    """

    example_options: ClassVar[tuple[Mapping[str, Any], ...]] = ({},)
    """Option sets that exercise the planner's distinct kinds of reference (profiles, objectives);
    the conformance test (tests/test_planner_conformance.py) plans the standard problems with each."""

    closed_form: ClassVar[bool] = False
    """Whether every reference it returns implements :meth:`Reference.symbolic_evaluator`, equal to
    its ``sample`` (``t`` clamped to ``[0, T]``): ``slewbench codegen`` exports the evaluator as C
    for a planner that declares it, and only then; the conformance check verifies it."""

    deterministic: ClassVar[bool] = True
    """Whether a plan is fixed by the class, its options and the problem, bit for bit: a trade study
    reuses a reference of identical planning inputs only for a planner that declares it; the
    conformance check verifies it."""

    cheap: ClassVar[bool] = False
    """Whether it plans in milliseconds, so that ``collocation`` seeds from it by default."""

    honours: ClassVar[frozenset[str]] = frozenset()
    """The requirement kinds (of :data:`REQUIREMENT_KINDS`) the planner imposes on its references
    whatever its options (:meth:`honoured` adds those some options impose)."""

    @classmethod
    def honoured(cls, options: Any) -> frozenset[str]:
        """The requirement kinds the planner imposes with these options: :attr:`honours`, and in a
        subclass whose options decide (``shape_polynomial``'s ``duration: rate_limit``) those too.

        Parameters
        ----------
        options : Options
            The planner's parsed options.

        Returns
        -------
        frozenset of str
            Kinds of :data:`REQUIREMENT_KINDS`.
        """
        return cls.honours

    def __init__(self, options: Mapping[str, Any] | Any | None = None, path: str = "options",
                 cache: SolverCache | None = None) -> None:
        super().__init__(options, path)
        self.cache = cache

    def with_cache(self, cache: SolverCache | None) -> Planner:
        """This planner, its options as validated, building into ``cache`` (no second validation).

        Parameters
        ----------
        cache : ocp.SolverCache or None
            Where the returned planner keeps what it builds; ``None``: the model's own cache.

        Returns
        -------
        Planner
            ``self`` when it already uses ``cache``; else a shallow copy that does.
        """
        if cache is self.cache:
            return self
        planner = copy.copy(self)
        planner.cache = cache
        return planner

    def solver_cache(self, problem: ManeuverProblem) -> SolverCache:
        """The cache to build into.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem being planned.

        Returns
        -------
        ocp.SolverCache
            The one given to the constructor, else ``problem.model.solver_cache``.
        """
        return self.cache if self.cache is not None else problem.model.solver_cache

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why this planner cannot plan ``problem``: a cheap check, without solving.

        The scenario loader reports the message against the planner's YAML entry and :meth:`plan`
        returns it as a :class:`FailedReference`. The default needs a target attitude.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan.

        Returns
        -------
        str or None
            The reason, naming the YAML key to change; ``None`` if the planner can take it.
        """
        if problem.qf is None:
            return f"planner {self.name} needs a target attitude (maneuver.final.q)"
        return None

    def least_duration(self, problem: ManeuverProblem) -> float | None:
        """The least duration of the reference this planner would plan for ``problem``, said
        cheaply, without optimising; ``None`` when it cannot say so (the default).

        ``slewbench validate`` compares it with ``maneuver.duration``, every planner's time budget:
        a planner whose least duration exceeds the budget has an ``infeasible`` row, said before
        planning. Only a planner that knows its duration in closed form (or by a search of
        milliseconds) overrides this; a lower bound is enough, a guess is not.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan (:meth:`problem_error` accepts it).

        Returns
        -------
        float or None
            The least duration [s], or ``None``.
        """
        return None

    def start_error(self, problem: ManeuverProblem) -> str | None:
        """Why this planner cannot give a start (a warm start, a seed) for ``problem``.

        A start need not meet every condition of the problem: the method it starts imposes them.
        The default is :meth:`problem_error`; a planner that refuses a problem as a row but still
        plans a useful start for it (:meth:`plan_start`) overrides both.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem another method will solve from the start.

        Returns
        -------
        str or None
            The reason; ``None`` if :meth:`plan_start` can plan a start for it.
        """
        return self.problem_error(problem)

    def plan(self, problem: ManeuverProblem) -> Reference:
        """Plan the manoeuvre.

        Parameters
        ----------
        problem : ManeuverProblem
            The slew to plan.

        Returns
        -------
        Reference
            The reference motion, with ``plan_time_s`` set to the wall time [s]; a
            :class:`FailedReference` (status ``"failed"`` or ``"infeasible"``) when
            :meth:`problem_error` refuses the problem or the method fails numerically (an
            ``OverflowError`` or ``FloatingPointError`` of the method, e.g. for ``T = 1e300`` s,
            gives a failed reference too).

        Raises
        ------
        TypeError
            If ``problem`` is not a :class:`ManeuverProblem`.
        """
        if not isinstance(problem, ManeuverProblem):
            raise TypeError(f"{type(self).__name__}.plan(problem): problem must be a planners.ManeuverProblem, got "
                            f"{type(problem).__name__}")
        start = time.perf_counter()
        error = self.problem_error(problem)
        if error:
            reference: Reference = FailedReference(self.name, error)
        else:
            try:
                reference = self._plan(problem)
            except (OverflowError, FloatingPointError) as failure:  # a numerical failure: a failed row, not a crash
                reference = FailedReference(self.name, f"numerical failure: {type(failure).__name__}: {failure} "
                                                       f"(duration {problem.duration:g} s)")
        reference.plan_time_s = time.perf_counter() - start
        return reference

    def plan_start(self, problem: ManeuverProblem) -> Reference:
        """Plan a reference that starts another method (a warm start, a cold start, a seed): on
        ``problem``, or, where that fails and the problem bounds the rate, on the problem without
        the bound (a start need not meet it: the method it starts imposes it; the eigenaxis quintic
        faster than ``max_rate`` is infeasible as a row, not as a start).

        Parameters
        ----------
        problem : ManeuverProblem
            The slew to plan.

        Returns
        -------
        Reference
            As :meth:`plan`; the failure on ``problem`` when both fail.
        """
        reference = self.plan(problem)
        if not reference.ok and problem.rate_bound(None) is not None:
            unbounded = self.plan(replace(problem, max_rate=None, rate_requirement=None))
            if unbounded.ok:
                return unbounded
        return reference

    @abstractmethod
    def _plan(self, problem: ManeuverProblem) -> Reference:
        """The method itself, on a problem :meth:`problem_error` accepted.

        Parameters
        ----------
        problem : ManeuverProblem
            The slew to plan.

        Returns
        -------
        Reference
            The reference, or a :class:`FailedReference` for a numerical failure (never raise).
        """
