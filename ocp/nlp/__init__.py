"""Solving NLPs: one solve path for every optimising planner, and the second-order check.

What lives here: solver options, the status policy, multistart with warm starts and the result
objects (:mod:`~ocp.nlp.solve`); the second-order sufficient conditions at a converged point
(:mod:`~ocp.nlp.second_order`); the certificate of a converged point, its KKT residuals unscaled and
in the solver's scaling, the second-order check and Pontryagin's switching agreement in one record
(:mod:`~ocp.nlp.certificate`); IPOPT's interior point on a compiled sparse LDLᵀ for small
equality-constrained NLPs with bounds, called as an ``nlpsol`` is (:mod:`~ocp.nlp.interior_point`),
and that factorisation with its inertia (:mod:`~ocp.nlp.sparse_ldl`, a C kernel compiled at first
use).

May import: CasADi, NumPy, SciPy and the top-level modules of :mod:`ocp`; it knows
nothing of attitude, models or transcriptions.
"""
from ocp.nlp.certificate import (
                                 KKTResiduals,
                                 Switching,
                                 certificate,
                                 certify,
                                 kkt_residuals,
                                 necessary_conditions_certificate,
                                 seed_counts,
                                 summary_line,
                                 switching_agreement,
                                 with_costate_gap,
)
from ocp.nlp.interior_point import InteriorPoint
from ocp.nlp.second_order import SecondOrderCheck, second_order_check
from ocp.nlp.solve import (
                           NLPResult,
                           StartResult,
                           converged,
                           perturbed,
                           solve_multistart,
                           solver_options,
                           status_name,
                           warm_start_options,
)

__all__ = ["InteriorPoint", "KKTResiduals", "NLPResult", "SecondOrderCheck", "StartResult", "Switching",
           "certificate", "certify", "converged", "kkt_residuals", "necessary_conditions_certificate",
           "perturbed", "second_order_check", "seed_counts", "solve_multistart", "solver_options", "status_name",
           "summary_line", "switching_agreement", "warm_start_options", "with_costate_gap"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
