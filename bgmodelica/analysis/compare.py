"""Structural (bond graph) and numeric (linearization) controllability and observability side
by side, for ``bgmodelica check`` of a bond graph.

The structural verdicts (paper Theorems 1 and 2: causal paths from the sources / to the
detectors, BGD ranks) are *generic*: they hold for almost all parameter values. The numeric
ranks are those of the model linearized at an operating point (the start values by default),
computed by the staircase form (:mod:`.controllability`); they can drop at special parameter
values or operating points (a modulus that vanishes there). Sources count as numeric inputs
when their value is a free parameter or a model input (``Se(E=...)``, ``Se(signal=True)``),
detectors as outputs (their ``y``). The compiled model may have more states than the
structural analysis counts: the structural states are the energy variables of the storage
elements in integral causality, the compiled ones add e.g. the displacements integrated by
``Dq`` detectors that modulated elements read.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca

__all__ = ["Comparison", "compare_bond_graph"]


@dataclass
class Comparison:
    """Structural vs numeric properties of one bond graph model."""

    inputs: dict[str, str] = field(default_factory=dict)       # source -> model name
    outputs: dict[str, str] = field(default_factory=dict)      # detector -> variable
    skipped: dict[str, str] = field(default_factory=dict)      # source -> why not an input
    structural: dict[str, Any] = field(default_factory=dict)   # kind -> StructuralProperty
    numeric: dict[str, Any] = field(default_factory=dict)      # kind -> RankResult
    states: list[str] = field(default_factory=list)
    point: str = ""
    error: str = ""
    notes: list[str] = field(default_factory=list)
    tol: float = 0.0
    titles: dict[str, str] = field(default_factory=dict)       # element -> "name (Se:U1)"

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"inputs": dict(self.inputs), "outputs": dict(self.outputs),
                               "not_inputs": dict(self.skipped), "operating_point": self.point,
                               "numeric_states": list(self.states), "notes": list(self.notes),
                               "tolerance": self.tol}
        if self.error:
            out["error"] = self.error
        for kind in ("controllability", "observability"):
            s, n = self.structural.get(kind), self.numeric.get(kind)
            out[kind] = {
                "structural": None if s is None else {"ok": s.ok, "rank": s.rank, "n": s.n,
                                                      "unconnected": list(s.unconnected)},
                "numeric": None if n is None else {"ok": n.ok, "rank": n.rank, "n": n.n,
                                                   "modes": n.to_dict()["modes"],
                                                   "margin": n.to_dict()["margin"]}}
        return out

    def to_text(self) -> str:
        lines = ["Structural vs numeric controllability/observability"
                 + (f" (numeric: linearized at the {self.point})" if self.point else "")]
        if self.inputs:
            lines.append("  inputs:  " + ", ".join(f"{self.titles.get(k, k)} = {v}"
                                                   for k, v in self.inputs.items()))
        if self.skipped:
            lines.append("  not numeric inputs: " + "; ".join(
                f"{k} ({v})" for k, v in self.skipped.items()))
        if self.outputs:
            lines.append("  outputs: " + ", ".join(f"{self.titles.get(k, k)} -> {v}"
                                                   for k, v in self.outputs.items()))
        if self.error:
            lines.append(f"  numeric: not available: {self.error}")
        width = 34
        lines.append(f"  {'':16}{'structural (generic)':<{width}}numeric")
        for kind in ("controllability", "observability"):
            s, n = self.structural.get(kind), self.numeric.get(kind)
            mat = "[A B]" if kind == "controllability" else "[A; C]"
            left = "-" if s is None else (f"{'yes' if s.ok else 'NO'}, BGD rank {mat} "
                                          f"{s.rank}/{s.n}")
            if n is None:
                right = "-"
            else:
                margin = "" if n.margin == float("inf") else f", margin {n.margin:.2g}"
                right = f"{'yes' if n.ok else 'NO'}, rank {n.rank}/{n.n}{margin}"
                if n.modes:
                    word = "uncontrollable" if kind == "controllability" else "unobservable"
                    right += f"; {word} modes " + ", ".join(_c(m) for m in n.modes[:6])
            lines.append(f"  {kind:<16}{left:<{width}}{right}")
        if self.states:
            lines.append("  numeric states: " + ", ".join(self.states))
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def _c(v: complex) -> str:
    return f"{v.real:.4g}" if abs(v.imag) < 1e-12 * max(1.0, abs(v)) else \
        f"{v.real:.4g}{v.imag:+.4g}j"


def _source_input(compiled, node: str) -> tuple[str | None, str]:
    """The free parameter or input that sets source ``node``, or (None, why not)."""
    dae = compiled.dae
    free = {q.name for q in dae.parameters}
    inputs = {u.name for u in dae.inputs}
    bound = {q.name: q for q in getattr(dae, "bound", [])}
    for suffix in ("E", "F"):
        name = f"{node}.{suffix}"
        if name in free:
            return name, ""
        if name in bound:
            value = ca.SX(bound[name].decl.value)
            for _ in range(len(bound) + 1):          # follow chains of plain bindings
                if value.is_symbolic():
                    hit = next((q for q in dae.parameters if ca.is_equal(q.sx, value)), None)
                    if hit is not None:
                        return hit.name, ""
                    nxt = next((q for q in bound.values() if ca.is_equal(q.sx, value)), None)
                    if nxt is None:
                        break
                    value = ca.SX(nxt.decl.value)
                else:
                    break
            return None, "its value is an expression of parameters"
    name = f"{node}.u"
    if name in inputs:
        return name, ""
    from ..overrides import resolve_alias

    kept, _ = resolve_alias(name, dae.aliases, free | inputs, dae.observed_index)
    if kept in inputs or kept in free:
        return kept, ""
    if kept in dae.observed_index:
        expr = dae.observed[dae.observed_index[kept]]
        for k, u in enumerate(dae.inputs):
            if ca.is_equal(expr, dae.p[len(dae.parameters) + k]) or \
                    ca.is_equal(-expr, dae.p[len(dae.parameters) + k]):
                return u.name, ""
    return None, "its value is no parameter or input of the model"


def compare_bond_graph(model: Any, compiled: Any, report: Any = None,
                       tol: float | None = None) -> Comparison:
    """Structural and numeric properties of ``model`` (a component holding bond graphs),
    compiled as ``compiled``; ``report`` (:func:`bgmodelica.bondgraph.analyze`) is recomputed
    with the sources that are numeric inputs."""
    from ..bondgraph import analyze
    from ..bondgraph.graph import DETECTORS, SOURCES
    from .controllability import DEFAULT_TOL, controllability, observability
    from .linearize import linearize_at
    from .steady_state import operating_point

    out = Comparison(tol=DEFAULT_TOL if tol is None else tol)
    report = report if report is not None else analyze(model)
    graph = report.graph
    out.titles = {n.name: f"{n.name} ({n.title})" for n in graph.nodes.values()}
    for node in graph.nodes.values():
        if node.kind in SOURCES and not node.zero:
            name, why = _source_input(compiled, node.name)
            title = f"{node.name} ({node.title})"
            if name is None:
                out.skipped[title] = why
            else:
                out.inputs[node.name] = name
    observed = compiled.dae.observed_index
    aliases = compiled.dae.aliases
    for node in graph.nodes.values():
        if node.kind in DETECTORS:
            y = f"{node.name}.y"
            if y in observed or y in aliases:
                out.outputs[node.name] = y
    try:
        rep = analyze(model, inputs=list(out.inputs), outputs=list(out.outputs)) \
            if (out.inputs and out.outputs) else report
    except Exception:  # noqa: BLE001 -- fall back to every source / detector
        rep = report
    if out.inputs:
        out.structural["controllability"] = rep.controllability
    if out.outputs:
        out.structural["observability"] = rep.observability
    if not out.inputs and not out.outputs:
        out.error = "no source is set by a parameter or input, and no detector"
        return out
    try:
        point = operating_point(compiled)
        lin = linearize_at(point, inputs=list(out.inputs.values()),
                           outputs=list(out.outputs.values()))
    except Exception as err:  # noqa: BLE001 -- report, do not fail the check
        out.error = str(err).splitlines()[0][:200]
        return out
    out.point = f"start values, t = {point.t:g} s"
    out.states = list(lin.states)
    if out.inputs:
        out.numeric["controllability"] = controllability(lin.A, lin.B, tol=tol,
                                                         states=lin.states)
    if out.outputs:
        out.numeric["observability"] = observability(lin.A, lin.C, tol=tol, states=lin.states)
    n_struct = len(report.bgi.integral)
    if len(lin.states) != n_struct:
        out.notes.append(
            f"the structural analysis counts {n_struct} states (energy variables of the "
            f"storage elements in integral causality: {', '.join(report.bgi.integral)}); the "
            f"compiled model has {len(lin.states)} (it also integrates e.g. displacements "
            "that modulated elements read)")
    for kind in ("controllability", "observability"):
        s, n = out.structural.get(kind), out.numeric.get(kind)
        if s is None or n is None:
            continue
        if s.ok and not n.ok:
            out.notes.append(
                f"{kind}: structurally generic, but numerically rank {n.rank}/{n.n} at this "
                "point: the rank drops at these parameter values or this operating point")
        elif not s.ok and n.ok:
            out.notes.append(f"{kind}: numerically full rank here although the structural "
                             "test fails (check the sources/detectors counted)")
    return out
