"""The components' initial equations (Modelica ``initial equation``) lowered to residuals in
the model's symbols, with their origins (mixed into the flattener)."""

from __future__ import annotations

import casadi as ca

from ..errors import ConnectError, DeclarationError, EquationError
from .component import Component
from .expr import Equation, to_sx
from .flatmodel import FlatEquation
from .variables import lookup


class InitialEquationsMixin:
    """``_initial_equations`` of :class:`~.flatten._Flattener` (it reads ``elements``,
    ``where``, ``paths``, ``all_sx`` and ``initial_sources``)."""

    def _initial_equations(self) -> list[FlatEquation]:
        """Lower the components' ``initial_equations()`` (Modelica ``initial equation``) to
        residuals in the model's symbols; the origin reads ``initial equation TEXT [where]``."""
        from ..validate import user_error

        out: list[FlatEquation] = []
        known = None
        for elem in self.elements:
            if not isinstance(elem, Component):
                continue
            where = self.where(elem)
            try:
                eqs = list(elem.all_initial_equations())
            except (ConnectError, DeclarationError, EquationError):
                raise
            except Exception as err:  # noqa: BLE001 -- user code: say where, no traceback
                raise user_error(err, f"{where}: initial_equations()",
                                 self.paths[id(elem)]) from None
            for eq in eqs:
                if isinstance(eq, Equation):
                    text = repr(eq)
                    res = ca.SX(to_sx(eq.lhs) - to_sx(eq.rhs))
                    self.initial_sources.append((eq, where))
                elif isinstance(eq, ca.SX) and eq.numel() == 1 and eq.is_op(ca.OP_EQ):
                    text = f"{eq.dep(0)} == {eq.dep(1)}"
                    res = eq.dep(0) - eq.dep(1)
                else:
                    raise EquationError(f"{where}: an initial equation must be written "
                                        f"'lhs == rhs', got {eq!r}")
                if known is None:
                    known = {x.element_hash() for x in ca.vertsplit(self.all_sx)}
                alien = [x for x in ca.symvar(res) if x.element_hash() not in known]
                if alien:
                    sym = lookup(alien[0])
                    what = str(alien[0])
                    hint = ""
                    if sym is not None and sym.der_of is not None:
                        hint = (f" ({sym.der_of.name} is not differentiated by the model's "
                                "equations, so its derivative is no variable of the model)")
                    raise EquationError(f"{where}: initial equation {text} uses {what}, which "
                                        f"is not part of the model{hint}")
                if not ca.symvar(res):
                    raise EquationError(f"{where}: initial equation {text} has no variables")
                out.append(FlatEquation(res, f"initial equation {text}   [{where}]"))
        return out
