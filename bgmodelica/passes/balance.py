"""Balance check: as many equations as unknowns, and a structurally regular system.

Derivatives count with their variable (``x`` and ``der(x)`` are one unknown). When the counts
differ or the system is structurally singular, a maximum matching (Dulmage-Mendelsohn) tells
which variables no equation determines and which equations are surplus.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.flatmodel import FlatModel
from ..errors import UnbalancedModelError
from ..structure.compiled import derivative_bases, remap_rows
from ..structure.diagnosis import dulmage_mendelsohn
from ..structure.matching import maximum_matching
from .reference import likely_causes
from .symbolic import model_incidence


@dataclass(frozen=True)
class BalanceReport:
    """Counts of a flat model: equations, unknowns (derivatives not counted), states guess."""

    n_equations: int
    n_unknowns: int

    @property
    def balanced(self) -> bool:
        return self.n_equations == self.n_unknowns


def check_balance(model: FlatModel, max_listed: int = 12) -> BalanceReport:
    """Raise :class:`UnbalancedModelError` naming the culprits unless the model is balanced."""
    unknowns = model.unknowns
    report = BalanceReport(len(model.equations), len(unknowns))
    base = derivative_bases([v.der_of for v in model.variables])
    column = np.full(len(model.variables), -1, dtype=np.int64)
    column[unknowns] = np.arange(len(unknowns))
    inc = model_incidence(model)
    eq_vars = remap_rows(inc, column[base])
    for k, row in enumerate(eq_vars):
        if not row:
            raise UnbalancedModelError(
                f"equation has no unknowns: {model.describe(k)}; it is either "
                "redundant (0 = 0) or contradictory",
                surplus=[model.describe(k)])
    matching = maximum_matching(eq_vars, len(unknowns))
    if report.balanced and matching.size == len(unknowns):
        return report
    dm = dulmage_mendelsohn(eq_vars, len(unknowns), matching)
    missing = [model.variables[unknowns[j]].origin for j in dm.underdetermined_vars
               if matching.var_to_eq[j] < 0]
    surplus = [model.describe(i) for i in dm.overdetermined_eqs
               if matching.eq_to_var[i] < 0]
    head = (f"model {model.name} is unbalanced: {report.n_equations} equations for "
            f"{report.n_unknowns} unknowns" if not report.balanced else
            f"model {model.name} is structurally singular ({report.n_equations} equations and "
            "unknowns, but some equations constrain the same variables)")
    lines = [head]
    causes = likely_causes(model, [unknowns[j] for j in dm.underdetermined_vars
                                   if matching.var_to_eq[j] < 0], inc,
                           [i for i in dm.overdetermined_eqs if matching.eq_to_var[i] < 0])
    if causes:
        lines.append("likely cause: " + "; ".join(causes[:3]))
    if missing:
        lines.append(f"no equation determines {len(missing)} variable(s):")
        lines += [f"  {m}" for m in missing[:max_listed]]
        if len(missing) > max_listed:
            lines.append(f"  ... and {len(missing) - max_listed} more")
    if surplus:
        lines.append(f"{len(surplus)} equation(s) are surplus (over-determine their variables):")
        lines += [f"  {s}" for s in surplus[:max_listed]]
        if len(surplus) > max_listed:
            lines.append(f"  ... and {len(surplus) - max_listed} more")
    raise UnbalancedModelError("\n".join(lines), missing=missing, surplus=surplus)
