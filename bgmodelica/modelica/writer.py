"""Modelica text of names, numbers, expressions and equations, for the exporter
(:mod:`.export`): identifiers quoted where needed, numbers in their shortest exact form,
expressions fully parenthesized, symbols named by their path from the component that writes
them."""

from __future__ import annotations

import math
import re
from typing import Any

from ..core.component import Connection, Element
from ..core.expr import Equation, Leaf, Op
from ..core.hybrid import (
    _INITIAL,
    _TERMINAL,
    IfEquation,
    Reinit,
    RuntimeCall,
    SampleClock,
    TimeTable,
    When,
)
from ..core.variables import TIME, Symbol
from .errors import ModelicaExportError

KEYWORDS = frozenset("""algorithm and annotation block break class connect connector constant
constrainedby der discrete each else elseif elsewhen encapsulated end enumeration equation
expandable extends external false final flow for function if import impure in initial inner
input loop model not operator or outer output package parameter partial protected public pure
record redeclare replaceable return stream then true type when while within""".split())
IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_UNARY = {"sin": "sin", "cos": "cos", "tan": "tan", "exp": "exp", "log": "log", "sqrt": "sqrt",
          "asin": "asin", "acos": "acos", "atan": "atan", "sinh": "sinh", "cosh": "cosh",
          "tanh": "tanh", "fabs": "abs", "sign": "sign", "floor": "floor", "ceil": "ceil",
          "noEvent": "noEvent"}
_BINARY_FN = {"atan2": "atan2", "fmin": "min", "fmax": "max"}
_INFIX = {"+": "+", "-": "-", "*": "*", "/": "/", "<": "<", "<=": "<=", "!=": "<>",
          "==": "==", "and": "and", "or": "or"}


def ident(name: str) -> str:
    """``name`` as a Modelica identifier (quoted when it is not one)."""
    if IDENT.match(name) and name not in KEYWORDS:
        return name
    return "'" + name.replace("\\", "\\\\").replace("'", "\\'") + "'"


def string(text: str) -> str:
    """``text`` as a Modelica string literal (on one line)."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", " ") + '"'


def number(v: Any) -> str:
    """The shortest Modelica literal that reads back as exactly ``v``."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v) if v >= 0 else f"({v})"
    v = float(v)
    if not math.isfinite(v):
        raise ModelicaExportError(f"the value {v!r} cannot be written in Modelica")
    if v == 0.0:
        return "(-0.0)" if math.copysign(1.0, v) < 0 else "0"
    if v.is_integer() and abs(v) < 1e15:
        text = str(int(v))
    else:
        text = repr(v)
    return text if v > 0 else f"({text})"


class ModelTree:
    """Paths of the elements of a model."""

    def __init__(self, root: Element) -> None:
        self.root = root
        self.path: dict[int, tuple[str, ...]] = {}
        self.parent: dict[int, Element | None] = {}
        self.names: set[str] = set()
        stack: list[tuple[Element, tuple[str, ...], Element | None]] = [(root, (), None)]
        while stack:
            elem, path, parent = stack.pop()
            if id(elem) in self.path:
                raise ModelicaExportError(f"{'.'.join(path)}: the same {type(elem).__name__} "
                                          "instance is used twice in the model")
            self.path[id(elem)] = path
            self.parent[id(elem)] = parent
            self.names.update(elem._symbols)
            for name, child in elem._children.items():
                self.names.add(name)
                stack.append((child, path + (name,), elem))

    def where(self, elem: Element) -> str:
        p = self.path.get(id(elem), ())
        return ".".join(p) or "the model"

    def relative(self, base: Element, target: Element) -> tuple[str, ...] | None:
        """Path of ``target`` below ``base`` (None if it is not in its subtree)."""
        pb = self.path[id(base)]
        pt = self.path.get(id(target))
        if pt is None or pt[:len(pb)] != pb:
            return None
        return pt[len(pb):]


class ExpressionWriter:
    """Modelica text of expressions, equations and connect() ends, each symbol named by its
    path from the component that writes it."""

    def __init__(self, tree: ModelTree) -> None:
        self.tree = tree
        self.lift: Any = None          # Exporter.lift: a reference outside a component

    # -- expressions -------------------------------------------------------------------------
    def sym_path(self, sym: Symbol, base: Element, what: str) -> str:
        owner = sym.owner
        rel = self.tree.relative(base, owner) if isinstance(owner, Element) else None
        if rel is None:
            raise ModelicaExportError(
                f"{self.tree.where(base)} ({type(base).__name__}): {what} uses {sym.name} of "
                f"{self._describe(owner)}, which is outside this component; Modelica "
                "components can refer only to their own elements")
        return ".".join(ident(p) for p in rel + (sym.name,))

    def _describe(self, owner: Any) -> str:
        if isinstance(owner, Element):
            where = ".".join(self.tree.path.get(id(owner), ())) or "?"
            return f"{type(owner).__name__} {where}"
        return "no component"

    def leaf(self, sym: Any, base: Element, what: str) -> str:
        if sym is TIME:
            return "time"
        if sym is _INITIAL:
            return "initial()"
        if sym is _TERMINAL:
            return "terminal()"
        if isinstance(sym, SampleClock):
            return (f"sample({self.expr(sym.start, base, what)}, "
                    f"{self.expr(sym.interval, base, what)})")
        if isinstance(sym, TimeTable) or getattr(sym, "name", "") == "table.c1":
            raise ModelicaExportError(
                f"{self.tree.where(base)} ({type(base).__name__}): time tables (time_table, "
                "TimeTable) cannot be written as Modelica yet")
        if not isinstance(sym, Symbol) or sym.owner is None:
            raise ModelicaExportError(f"{self.tree.where(base)}: {what} uses "
                                      f"{getattr(sym, 'name', sym)!r}, which has no Modelica "
                                      "form")
        root = sym
        while root.der_of is not None or root.pre_of is not None:
            root = root.der_of if root.der_of is not None else root.pre_of
        if self.lift is not None and isinstance(root.owner, Element) \
                and self.tree.relative(base, root.owner) is None:
            return self.lift(base, sym, what)
        if sym.der_of is not None:
            return f"der({self.leaf(sym.der_of, base, what)})"
        if sym.pre_of is not None:
            return f"pre({self.leaf(sym.pre_of, base, what)})"
        return self.sym_path(sym, base, what)

    def expr(self, e: Any, base: Element, what: str) -> str:
        if isinstance(e, Leaf):
            return self.leaf(e.sym, base, what)
        if isinstance(e, Op):
            op, args = e.op, e.args
            table = _table_of(e)
            if table is not None:
                return self.table(table, base)
            if op in _INFIX:
                return (f"({self.expr(args[0], base, what)} {_INFIX[op]} "
                        f"{self.expr(args[1], base, what)})")
            if op == "**":
                return f"({self.expr(args[0], base, what)}^{self.expr(args[1], base, what)})"
            if op == "neg":
                return f"(-{self.expr(args[0], base, what)})"
            if op == "not":
                return f"(not {self.expr(args[0], base, what)})"
            if op in _UNARY:
                return f"{_UNARY[op]}({self.expr(args[0], base, what)})"
            if op in _BINARY_FN:
                return (f"{_BINARY_FN[op]}({self.expr(args[0], base, what)}, "
                        f"{self.expr(args[1], base, what)})")
            if op == "if_else":
                return (f"(if {self.expr(args[0], base, what)} then "
                        f"{self.expr(args[1], base, what)} else "
                        f"{self.expr(args[2], base, what)})")
            raise ModelicaExportError(f"{self.tree.where(base)}: operation {op!r} in {what} "
                                      "has no Modelica form")
        if isinstance(e, (bool, int, float)):
            return number(e)
        if hasattr(e, "is_symbolic") or type(e).__module__.startswith("casadi"):
            raise ModelicaExportError(
                f"{self.tree.where(base)} ({type(base).__name__}): {what} is a CasADi "
                "expression; only equations written with bgmodelica expressions can be "
                "exported")
        raise ModelicaExportError(f"{self.tree.where(base)}: cannot write {e!r} in Modelica")

    def table(self, table: TimeTable, base: Element) -> str:
        """A time table as an if-expression of time (its breakpoints stay time events)."""
        if table.extrapolation == "periodic":
            raise ModelicaExportError(
                f"{self.tree.where(base)} ({type(base).__name__}): a time table with "
                "periodic extrapolation cannot be written as Modelica yet")
        times = [float(t) for t in table.times]
        values = [float(v) for v in table.values]
        linear = table.interpolation == "linear"
        n = len(times)

        def segment(a: int, b: int) -> str:
            dt = times[b] - times[a]
            if not linear or dt <= 0.0:
                return number(values[a] if not linear else values[b])
            c1 = (values[b] - values[a]) / dt
            c0 = values[a] - c1 * times[a]
            return f"({number(c0)} + ({number(c1)} * time))" if c1 != 0.0 else number(c0)

        pieces: list[tuple[float, str]] = []
        if n > 1 and table.extrapolation == "linear" and linear:
            pieces.append((times[0], segment(0, 1)))
        else:
            pieces.append((times[0], number(values[0])))
        for i in range(1, n):
            if times[i] > times[i - 1]:
                pieces.append((times[i], segment(i - 1, i) if linear else number(values[i - 1])))
        if n > 1 and table.extrapolation == "linear" and linear:
            last = segment(n - 2, n - 1)
        else:
            last = number(values[-1])
        out = "(if " + " elseif ".join(f"(time < {number(t)}) then {v}" for t, v in pieces)
        return out + f" else {last})"

    # -- equations ---------------------------------------------------------------------------
    def equation(self, eq: Any, base: Element, indent: str) -> list[str]:
        if isinstance(eq, Equation):
            what = "an equation"
            return [f"{indent}{self.expr(eq.lhs, base, what)} = "
                    f"{self.expr(eq.rhs, base, what)};"]
        if isinstance(eq, Connection):
            return [f"{indent}connect({self.end(eq.a, base)}, {self.end(eq.b, base)});"]
        if isinstance(eq, When):
            out = []
            for k, (cond, stmts) in enumerate(eq.branches):
                head = "when" if k == 0 else "elsewhen"
                out.append(f"{indent}{head} {self.expr(cond, base, 'a when-condition')} then")
                for st in stmts:
                    if isinstance(st, RuntimeCall):
                        raise ModelicaExportError(f"{st.text}: a function call run on numbers "
                                                  "at events cannot be written back")
                    if isinstance(st, Reinit):
                        out.append(f"{indent}  reinit({self.leaf(st.target, base, 'reinit')}, "
                                   f"{self.expr(st.value, base, 'reinit')});")
                    else:
                        out.extend(self.equation(st, base, indent + "  "))
            out.append(f"{indent}end when;")
            return out
        if isinstance(eq, IfEquation):
            out = []
            for k, (cond, eqs) in enumerate(eq.branches):
                head = "if" if k == 0 else "elseif"
                out.append(f"{indent}{head} {self.expr(cond, base, 'an if-condition')} then")
                for sub in eqs:
                    out.extend(self.equation(sub, base, indent + "  "))
            out.append(f"{indent}else")
            for sub in eq.otherwise:
                out.extend(self.equation(sub, base, indent + "  "))
            out.append(f"{indent}end if;")
            return out
        raise ModelicaExportError(
            f"{self.tree.where(base)} ({type(base).__name__}): the equation {eq!r} has no "
            "Modelica form (CasADi expressions cannot be exported)")

    def end(self, x: Any, base: Element) -> str:
        if isinstance(x, Element):
            rel = self.tree.relative(base, x)
            if rel is None or not rel:
                raise ModelicaExportError(f"{self.tree.where(base)}: connect() of a connector "
                                          "outside the component")
            return ".".join(ident(p) for p in rel)
        if isinstance(x, Leaf):
            return self.leaf(x.sym, base, "connect()")
        raise ModelicaExportError(f"{self.tree.where(base)}: connect({x!r}) has no Modelica "
                                  "form")


def _table_of(e: Op) -> TimeTable | None:
    """The table of ``table + table.c1*time`` (what :func:`bgmodelica.time_table` builds)."""
    if e.op != "+" or len(e.args) != 2:
        return None
    a, b = e.args
    if not (isinstance(a, Leaf) and isinstance(a.sym, TimeTable)):
        return None
    if isinstance(b, Op) and b.op == "*" and isinstance(b.args[0], Leaf) \
            and b.args[0].sym is a.sym.c1 and isinstance(b.args[1], Leaf) \
            and b.args[1].sym is TIME:
        return a.sym
    return None
