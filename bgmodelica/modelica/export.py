"""Write any bgmodelica model as self-contained Modelica text.

The model becomes one Modelica ``model`` named after it, with one nested class per distinct
component (connectors as ``connector``): a class holds its declarations with their units,
start/fixed/nominal/min/max/stateSelect attributes and the equations of its instance
(inherited ones included, ``der``, ``pre``, ``when``/``reinit``, if-equations, ``sample``,
``initial()``), written with the component's own names. Instances that differ only by
parameter values or start values share a class; the differences are modifiers where the
instance is declared (``Resistor R1(R = 0.5, v(start = 1.0, fixed = true))``), placed in the
innermost component that sees everything a bound value refers to
(``source(V = V)`` for a source bound to the model's parameter ``V``). Instances whose
equations differ (a PI versus a PID controller) get classes of their own.

Expressions are written fully parenthesized with numbers in their shortest exact form, so
that :func:`bgmodelica.load_modelica` rebuilds the same expression trees: an exported model
loads back with the same variables, the same equations in the same order and identical
simulation results. Names that are not Modelica identifiers (array elements ``R[1]`` of an
imported model) are written as quoted identifiers (``'R[1]'``).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from ..core.component import Component, Connector, Element
from ..core.expr import Expr, Leaf, Op
from ..core.variables import (
    KIND_FLOW,
    KIND_INPUT,
    KIND_OUTPUT,
    KIND_PARAMETER,
    Boolean,
    Discrete,
    Integer,
    StateSelect,
    Symbol,
)
from .errors import ModelicaExportError
from .writer import IDENT, KEYWORDS, ExpressionWriter, ModelTree, ident, number, string

# -- declarations ---------------------------------------------------------------------------------


def _type_and_prefix(decl: Any, connector: bool) -> tuple[str, str]:
    kind = decl.kind
    if kind == KIND_PARAMETER:
        return "parameter ", "Real"
    if isinstance(decl, Boolean):
        base = "Boolean"
    elif isinstance(decl, Integer):
        base = "Integer"
    else:
        base = "Real"
    if kind == KIND_FLOW:
        return "flow ", base
    if kind == KIND_INPUT:
        return "input ", base
    if kind == KIND_OUTPUT:
        return "output ", base
    if isinstance(decl, Discrete) and base == "Real":
        return "discrete ", base
    return "", base


def _attr_text(decl: Any, base_type: str, fields: list[str] | None, writer: ExpressionWriter,
               where: Element) -> list[str]:
    """Attribute modifiers of a declaration (all that differ from the defaults, or the
    listed ``fields``)."""
    out = []
    is_param = decl.kind == KIND_PARAMETER

    def want(f: str, default_differs: bool) -> bool:
        return (f in fields) if fields is not None else default_differs

    if base_type == "Real" and want("unit", bool(decl.unit)) and decl.unit:
        out.append(f"unit = {string(decl.unit)}")
    if not is_param:
        start = decl.start
        if want("start", start != 0 or decl.fixed or base_type == "Boolean" and bool(start)):
            if base_type == "Boolean":
                out.append(f"start = {'true' if start else 'false'}")
            else:
                out.append(f"start = {_num_literal(start, base_type)}")
        if want("fixed", bool(decl.fixed)):
            out.append(f"fixed = {'true' if decl.fixed else 'false'}")
        if base_type == "Real" and want("nominal", decl.nominal != 1.0):
            out.append(f"nominal = {number(float(decl.nominal))}")
        if base_type == "Real" and want("state_select",
                                        decl.state_select != StateSelect.DEFAULT):
            out.append(f"stateSelect = StateSelect.{decl.state_select.name.lower()}")
    for f in ("min", "max"):
        v = getattr(decl, f, None)
        if want(f, v is not None) and v is not None:
            out.append(f"{f} = {_num_literal(v, base_type)}")
    return out


def _num_literal(v: Any, base_type: str) -> str:
    if base_type == "Integer":
        if float(v).is_integer():
            return number(int(v))
    return number(v if not isinstance(v, bool) else float(v))


def _same(a: Any, b: Any) -> bool:
    if a is b:
        return True
    if isinstance(a, Expr) or isinstance(b, Expr):
        return False
    try:
        return type(a) is type(b) and a == b or (
            isinstance(a, (int, float)) and isinstance(b, (int, float)) and float(a) == float(b)
            and math.copysign(1, float(a)) == math.copysign(1, float(b)))
    except (TypeError, ValueError):
        return False


_COMPARED = ("value", "start", "fixed", "nominal", "min", "max", "state_select", "unit")


def _class_decl(elem: Element, name: str, sym: Symbol) -> Any:
    """The declaration a class body states for ``name``: the Python class's, or for a symbol
    declared on the instance only (bond-graph elements) the same with a neutral value."""
    decl = type(elem)._declarations.get(name)
    if decl is not None:
        return decl
    if sym.decl.kind == KIND_PARAMETER:
        from dataclasses import replace

        return replace(sym.decl, value=0.0)
    return sym.decl


def _differences(decl: Any, default: Any) -> list[str]:
    out = []
    for f in _COMPARED:
        if hasattr(decl, f) and not _same(getattr(decl, f), getattr(default, f, None)):
            out.append(f)
    return out


class _ModNode:
    """Modifications written where a subcomponent is declared (nested by path)."""

    __slots__ = ("attrs", "sub")

    def __init__(self) -> None:
        self.attrs: dict[str, str] = {}          # symbol name -> "name(...) = value"
        self.sub: dict[str, _ModNode] = {}

    def text(self) -> str:
        parts = list(self.attrs.values())
        parts += [f"{ident(k)}{v.text()}" for k, v in self.sub.items()]
        return f"({', '.join(parts)})" if parts else ""


class Exporter:
    """Collects the classes of one model."""

    def __init__(self, model: Component, name: str | None = None) -> None:
        if not isinstance(model, Component):
            raise ModelicaExportError(f"cannot export {model!r}: not a Component")
        self.model = model
        self.tree = ModelTree(model)
        self.writer = ExpressionWriter(self.tree)
        self.name = name or model.name or type(model).__name__
        if not IDENT.match(self.name) or self.name in KEYWORDS:
            self.name = re.sub(r"\W", "_", self.name) or "Model"
        self.mods: dict[int, _ModNode] = {}        # id(element) -> its children's modifiers
        self.classes: dict[tuple[str, str], str] = {}   # (python class, body) -> class name
        self.order: list[tuple[str, str, str]] = []     # (kind, name, text)
        self.taken: set[str] = set(self.tree.names) | {self.name} | KEYWORDS | {
            "Real", "Integer", "Boolean", "String", "StateSelect", "Modelica", "time"}
        self.lifted: dict[int, dict[str, str]] = {}     # id(element) -> name -> declaration
        self._lift_names: dict[int, dict[str, str]] = {}
        self.writer.lift = self.lift
        self.signals: dict[str, str] = {}

    # -- modifications -----------------------------------------------------------------------
    def _place_modifications(self) -> None:
        """Every declaration that differs from its class's default becomes a modifier in the
        innermost enclosing component that sees all it refers to."""
        stack: list[Element] = [self.model]
        while stack:
            elem = stack.pop()
            stack.extend(elem._children.values())
            if elem is self.model:
                continue
            for name, sym in elem._symbols.items():
                default = _class_decl(elem, name, sym)
                diff = _differences(sym.decl, default)
                if diff:
                    self._add_mod(elem, sym, diff)

    def _add_mod(self, owner: Element, sym: Symbol, diff: list[str]) -> None:
        tree = self.tree
        comp = owner
        while isinstance(comp, Connector) and tree.parent.get(id(comp)) is not None:
            comp = tree.parent[id(comp)]
        place = tree.parent.get(id(comp)) or comp
        decl = sym.decl
        value = getattr(decl, "value", None)
        if "value" in diff and isinstance(value, Expr):
            leaves: list = []
            _leaves(value, leaves)
            while True:
                if all(isinstance(getattr(s, "owner", None), Element)
                       and tree.relative(place, s.owner) is not None for s in leaves):
                    break
                up = tree.parent.get(id(place))
                if up is None:
                    raise ModelicaExportError(
                        f"parameter {tree.where(owner)}.{sym.name} is bound to {value!r}, "
                        "which refers to something outside the model")
                place = up
        rel = tree.relative(place, owner)
        if rel is None or (place is owner and owner is not self.model):
            raise ModelicaExportError(f"{tree.where(owner)}.{sym.name}: cannot place its "
                                      "modifier")
        node = self.mods.setdefault(id(place), _ModNode())
        for part in rel:
            node = node.sub.setdefault(part, _ModNode())
        _, base_type = _type_and_prefix(decl, False)
        what = f"the modifier of {tree.where(owner)}.{sym.name}"
        attrs = _attr_text(decl, base_type, [f for f in diff if f != "value"], self.writer,
                           place)
        text = ident(sym.name) + (f"({', '.join(attrs)})" if attrs else "")
        if "value" in diff:
            text += f" = {self.writer.expr(value, place, what)}"
        node.attrs[sym.name] = text

    # -- classes -----------------------------------------------------------------------------
    def class_of(self, elem: Element) -> str:
        """The Modelica class name for ``elem`` (its text registered once)."""
        body = self._body(elem, top=False)
        kind = "connector" if isinstance(elem, Connector) else "model"
        key = (f"{kind} {type(elem).__module__}.{type(elem).__qualname__}", body)
        name = self.classes.get(key)
        if name is not None:
            return name
        name = self._fresh(type(elem).__name__)
        self.classes[key] = name
        doc = _doc(elem)
        head = f"  {kind} {name}" + (f" {string(doc)}" if doc else "")
        self.order.append((kind, name, f"{head}\n{body}  end {name};\n"))
        return name

    def signal_class(self, kind: str) -> str:
        """``connector RealInput = input Real`` (or RealOutput), declared once: signals of
        components must be connectors to be connected in Modelica."""
        name = self.signals.get(kind)
        if name is None:
            direction = "input" if kind == KIND_INPUT else "output"
            name = self._fresh("RealInput" if kind == KIND_INPUT else "RealOutput")
            self.signals[kind] = name
            self.order.insert(0, ("connector", name,
                                  f"  connector {name} = {direction} Real;\n"))
        return name

    def _fresh(self, base: str) -> str:
        base = re.sub(r"\W", "_", base) or "C"
        if not IDENT.match(base):
            base = "C_" + base
        name = base
        k = 2
        while name in self.taken:
            name = f"{base}_{k}"
            k += 1
        self.taken.add(name)
        return name

    def _body(self, elem: Element, top: bool) -> str:
        lines: list[str] = []
        ind = "  " if top else "    "
        connector = isinstance(elem, Connector)
        writer = self.writer
        for name, sym in elem._symbols.items():
            decl = sym.decl if top else _class_decl(elem, name, sym)
            prefix, base_type = _type_and_prefix(decl, connector)
            attrs = _attr_text(decl, base_type, None, writer, elem)
            type_name = base_type
            if not connector and decl.kind in (KIND_INPUT, KIND_OUTPUT) and base_type == "Real":
                type_name, prefix = self.signal_class(decl.kind), ""     # connect()-able
            text = f"{ind}{prefix}{type_name} {ident(name)}"
            if attrs:
                text += f"({', '.join(attrs)})"
            if decl.kind == KIND_PARAMETER:
                value = decl.value
                text += f" = {writer.expr(value, elem, f'the binding of {name}')}"
            if decl.description:
                text += f" {string(decl.description)}"
            lines.append(text + ";")
        children: list[str] = []
        for name, child in elem._children.items():
            cls = self.class_of(child)
            node = self.mods.get(id(elem))
            mod = node.sub.get(name) if node is not None else None
            children.append(f"{ind}{cls} {ident(name)}{mod.text() if mod else ''};")
        eq_lines: list[str] = []
        if isinstance(elem, Component):
            eqs = self._equations(elem, elem.all_equations, "equations()")
            if eqs:
                eq_lines.append(f"{ind[:-2]}equation")
                for eq in eqs:
                    eq_lines.extend(writer.equation(eq, elem, ind))
            ieqs = self._equations(elem, elem.all_initial_equations, "initial_equations()")
            if ieqs:
                eq_lines.append(f"{ind[:-2]}initial equation")
                for eq in ieqs:
                    eq_lines.extend(writer.equation(eq, elem, ind))
        lifted = [f"{ind}{text}" for text in self.lifted.get(id(elem), {}).values()]
        lines = lines + lifted + children + eq_lines
        return "".join(line + "\n" for line in lines)

    def lift(self, base: Element, sym: Symbol, what: str) -> str:
        """A reference of ``base``'s equations to ``sym`` outside ``base``: a local
        parameter / variable of ``base`` bound by a modifier where both are visible (Modelica
        components see only their own elements)."""
        tree = self.tree
        root = sym
        while root.der_of is not None or root.pre_of is not None:
            root = root.der_of if root.der_of is not None else root.pre_of
        place = tree.parent.get(id(base))
        while place is not None and tree.relative(place, root.owner) is None:
            place = tree.parent.get(id(place))
        if place is None:
            raise ModelicaExportError(
                f"{tree.where(base)} ({type(base).__name__}): {what} uses {sym.name} of "
                f"{self.writer._describe(root.owner)}, which is not part of the model")
        text = self.writer.leaf(sym, place, what)
        known = self._lift_names.setdefault(id(base), {})
        name = known.get(text)
        if name is None:
            stem = "ext_" + (re.sub(r"\W+", "_", text).strip("_") or "value")
            name = stem
            k = 2
            taken = set(base._symbols) | set(base._children) | set(known.values())
            while name in taken:
                name = f"{stem}_{k}"
                k += 1
            known[text] = name
            unit = f'(unit = {string(sym.decl.unit)})' if getattr(sym.decl, "unit", "") else ""
            if sym.decl.kind == KIND_PARAMETER and sym.der_of is None and sym.pre_of is None:
                decl = f"parameter Real {ident(name)}{unit} = 0 \"= {text} (outside)\";"
            else:
                decl = f"Real {ident(name)}{unit} \"= {text} (outside)\";"
            self.lifted.setdefault(id(base), {})[name] = decl
            node = self.mods.setdefault(id(place), _ModNode())
            for part in tree.relative(place, base) or ():
                node = node.sub.setdefault(part, _ModNode())
            node.attrs[name] = f"{ident(name)} = {text}"
        return ident(name)

    def _equations(self, elem: Component, fn: Any, what: str) -> list:
        from ..errors import ModelError

        try:
            return list(fn())
        except ModelError:
            raise
        except Exception as err:  # noqa: BLE001 -- user code: say where
            raise ModelicaExportError(f"{self.tree.where(elem)} ({type(elem).__name__}): "
                                      f"{what} raised {type(err).__name__}: {err}") from None

    def text(self, experiment: dict[str, float] | None = None) -> str:
        self._place_modifications()
        body = self._body(self.model, top=True)
        doc = _doc(self.model)
        out = ["// Written by bgmodelica (export-mo): self-contained, one class per distinct "
               "component.\n",
               f"model {self.name}" + (f" {string(doc)}" if doc else "") + "\n"]
        for _, _, text in self.order:
            out.append(text)
        out.append(body)
        if experiment:
            items = ", ".join(f"{k} = {number(float(v))}" for k, v in experiment.items())
            out.append(f"  annotation(experiment({items}));\n")
        out.append(f"end {self.name};\n")
        return "".join(out)


def _doc(elem: Element) -> str:
    doc = type(elem).__doc__ or ""
    if type(elem) in (Component, Connector):
        return ""
    first = doc.strip().split("\n\n")[0]
    return " ".join(first.split())


def _leaves(e: Any, out: list) -> None:
    if isinstance(e, Leaf):
        out.append(e.sym)
    elif isinstance(e, Op):
        for a in e.args:
            _leaves(a, out)


_EXPERIMENT_KEYS = {"start_time": "StartTime", "stop_time": "StopTime", "interval": "Interval",
                    "rtol": "Tolerance", "StartTime": "StartTime", "StopTime": "StopTime",
                    "Interval": "Interval", "Tolerance": "Tolerance"}


def export_modelica(model: Component, path: str | Path | None = None, *,
                    name: str | None = None, experiment: dict[str, float] | None = None) -> str:
    """The Modelica text of ``model``; written to ``path`` when given.

    name: the Modelica model name (default: the component's name or class name).
    experiment: ``StartTime``/``StopTime``/``Interval``/``Tolerance`` (or ``start_time``,
    ``stop_time``, ``interval``, ``rtol``) for the experiment annotation; by default the
    model's own ``experiment`` (a model loaded from Modelica) if any.
    """
    exp_in = experiment if experiment is not None else model.__dict__.get("_mo_experiment")
    exp: dict[str, float] = {}
    for k, v in (exp_in or {}).items():
        key = _EXPERIMENT_KEYS.get(k)
        if key is None:
            raise ModelicaExportError(f"experiment: unknown setting {k!r} (StartTime, "
                                      "StopTime, Interval, Tolerance)")
        if v is not None:
            exp[key] = float(v)
    order = ("StartTime", "StopTime", "Interval", "Tolerance")
    exp = {k: exp[k] for k in order if k in exp}
    text = Exporter(model, name).text(exp)
    if path is not None:
        p = Path(path)
        try:
            p.write_text(text, encoding="utf-8")
        except OSError as err:
            raise ModelicaExportError(f"cannot write {p}: {err.strerror or err}") from None
    return text
