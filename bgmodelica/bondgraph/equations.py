"""Causal equations of a bond graph, read off the causal strokes, in text and LaTeX: the
junction / transformer relations (paper Table V), the element laws (Table VI) and, by
substitution along the causal paths, the state equations.

Notation: bond ``k`` carries effort ``e_k`` and flow ``f_k`` (along its half-arrow); an I
element on bond k has momentum ``p_k`` (``dp_k/dt = e_k``), a C element displacement ``q_k``
(``dq_k/dt = f_k``). A modulus is written with the element's label (``k2``, ``r1``); the
definitions of modulated moduli are listed separately. A switch ``Sw`` appears as a resistor
of modulus ``Ron if on else 1/Goff`` (its resistive form, the same causality in both modes).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .causality import Causality
from .graph import JUNCTIONS, SWITCHES, Graph, strong_bond


# -- a tiny expression tree, printable as text or LaTeX -----------------------------------
class Ex:
    prec = 9

    def text(self) -> str:  # pragma: no cover - abstract
        raise NotImplementedError

    def latex(self) -> str:  # pragma: no cover - abstract
        raise NotImplementedError


@dataclass
class Sym(Ex):
    t: str
    tex: str
    prec = 9

    def text(self) -> str:
        return self.t

    def latex(self) -> str:
        return self.tex


@dataclass
class Sum(Ex):
    terms: list[tuple[int, Ex]]
    prec = 1

    def _fmt(self, f) -> str:
        if not self.terms:
            return "0"
        out = []
        for k, (s, t) in enumerate(self.terms):
            body = f(t)
            if t.prec <= 1:
                body = f"({body})" if f is _text else rf"\left({body}\right)"
            if k == 0:
                out.append(("-" if s < 0 else "") + body)
            else:
                out.append((" - " if s < 0 else " + ") + body)
        return "".join(out)

    def text(self) -> str:
        return self._fmt(_text)

    def latex(self) -> str:
        return self._fmt(_latex)


@dataclass
class Prod(Ex):
    a: Ex
    b: Ex
    prec = 2

    def text(self) -> str:
        return f"{_paren(self.a, 2, _text)}*{_paren(self.b, 2, _text)}"

    def latex(self) -> str:
        return rf"{_paren(self.a, 2, _latex)}\,{_paren(self.b, 2, _latex)}"


@dataclass
class Quot(Ex):
    a: Ex
    b: Ex
    prec = 2

    def text(self) -> str:
        return f"{_paren(self.a, 2, _text)}/{_paren(self.b, 3, _text)}"

    def latex(self) -> str:
        return rf"\frac{{{self.a.latex()}}}{{{self.b.latex()}}}"


@dataclass
class Der(Ex):
    a: Ex
    prec = 9

    def text(self) -> str:
        return f"d({self.a.text()})/dt"

    def latex(self) -> str:
        return rf"\frac{{d}}{{dt}}\left({self.a.latex()}\right)"


def _text(e: Ex) -> str:
    return e.text()


def _latex(e: Ex) -> str:
    return e.latex()


def _paren(e: Ex, prec: int, f) -> str:
    body = f(e)
    if e.prec < prec:
        return f"({body})" if f is _text else rf"\left({body}\right)"
    return body


def neg(e: Ex) -> Ex:
    return Sum([(-1, e)])


def _is_zero(t: Ex) -> bool:
    return isinstance(t, Sym) and t.t == "0"


def add(terms: list[tuple[int, Ex]]) -> Ex:
    flat: list[tuple[int, Ex]] = []
    for s, t in terms:
        if _is_zero(t):
            continue
        if isinstance(t, Sum):
            flat.extend((s * s2, t2) for s2, t2 in t.terms)
        else:
            flat.append((s, t))
    if not flat:
        return Sym("0", "0")
    if len(flat) == 1 and flat[0][0] > 0:
        return flat[0][1]
    return Sum(flat)


def div(a: Ex, b: Ex) -> Ex:
    if _is_zero(a):
        return a
    if isinstance(a, Sum) and len(a.terms) == 1:            # (-x)/m -> -(x/m)
        s, t = a.terms[0]
        return add([(s, div(t, b))])
    return Quot(a, b)


def mul(a: Ex, b: Ex) -> Ex:
    if _is_zero(a) or _is_zero(b):
        return Sym("0", "0")
    if isinstance(b, Sum) and len(b.terms) == 1:           # a*(-x) -> -(a*x)
        s, t = b.terms[0]
        return add([(s, mul(a, t))])
    return Prod(a, b)


def _tex_name(name: str) -> str:
    """``lc1`` -> ``l_{c1}``-ish subscripts: trailing digits become a subscript."""
    head = name.rstrip("0123456789")
    digits = name[len(head):]
    greek = {"omega": r"\omega", "tau": r"\tau", "alpha": r"\alpha", "theta": r"\theta",
             "w": r"\omega"}
    head_tex = greek.get(head, head if len(head) <= 1 else rf"\mathrm{{{head}}}")
    if not digits:
        return head_tex
    return f"{head_tex}_{{{digits}}}"


def var(kind: str, k: int) -> Sym:
    return Sym(f"{kind}{k}", f"{kind}_{{{k}}}")


def param(node_symbol: str) -> Sym:
    if node_symbol.isidentifier():
        return Sym(node_symbol, _tex_name(node_symbol))
    return Sym(f"({node_symbol})", rf"\left(\mathrm{{{node_symbol}}}\right)")


# -- the causal equations ------------------------------------------------------------------
@dataclass
class CausalEquation:
    """``lhs = rhs`` for one element; ``element`` is its name, ``kind`` its title."""

    element: str
    title: str
    lhs: Ex
    rhs: Ex
    dynamic: bool = False

    def text(self) -> str:
        return f"{self.lhs.text()} = {self.rhs.text()}"

    def latex(self) -> str:
        return f"{self.lhs.latex()} = {self.rhs.latex()}"


@dataclass
class CausalEquations:
    """Junction-structure equations (Table V), element equations (Table VI), modulus
    definitions and the state equations of the integral-causality storage elements."""

    junctions: list[CausalEquation] = field(default_factory=list)
    elements: list[CausalEquation] = field(default_factory=list)
    moduli: dict[str, str] = field(default_factory=dict)
    states: list[CausalEquation] = field(default_factory=list)
    implicit: list[str] = field(default_factory=list)

    def to_text(self) -> str:
        lines = ["Junction structure (Table V):"]
        lines += [f"  {eq.title:<14} {eq.text()}" for eq in self.junctions]
        lines.append("Elements (Table VI):")
        lines += [f"  {eq.title:<14} {eq.text()}" for eq in self.elements]
        if self.moduli:
            lines.append("Moduli:")
            lines += [f"  {k} = {v}" for k, v in self.moduli.items()]
        lines.append("State equations:")
        lines += [f"  {eq.text()}" for eq in self.states]
        if self.implicit:
            lines.append("  (implicit: derivative causality on "
                         + ", ".join(self.implicit) + ")")
        return "\n".join(lines)

    def to_latex(self) -> str:
        def table(caption: str, rows: list[CausalEquation]) -> list[str]:
            out = [r"\begin{table}[h]", r"\centering", rf"\caption{{{caption}}}",
                   r"\begin{tabular}{ll}", r"\hline", r"Element & Equation \\", r"\hline"]
            for eq in rows:
                title = eq.title.replace("_", r"\_")
                out.append(rf"{title} & ${eq.latex()}$ \\")
            out += [r"\hline", r"\end{tabular}", r"\end{table}"]
            return out

        lines = table("Junction structure", self.junctions)
        lines += table("Elements", self.elements)
        if self.moduli:
            lines.append(r"\begin{align*}")
            for k, v in self.moduli.items():
                body = v.replace("_", r"\_")
                lines.append(rf"  {_tex_name(k)} &= \mathtt{{{body}}} \\")
            lines.append(r"\end{align*}")
        lines.append(r"\begin{align*}")
        lines += [rf"  {eq.lhs.latex()} &= {eq.rhs.latex()} \\" for eq in self.states]
        lines.append(r"\end{align*}")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {"junctions": [{"element": e.element, "equation": e.text()}
                              for e in self.junctions],
                "elements": [{"element": e.element, "equation": e.text()}
                             for e in self.elements],
                "moduli": dict(self.moduli),
                "states": [e.text() for e in self.states], "implicit": list(self.implicit)}


def causal_equations(c: Causality) -> CausalEquations:
    """Write the causal equations of the causal graph ``c`` (see module docstring)."""
    g: Graph = c.graph
    eto = c.effort_to
    inc = g.incidence()
    out = CausalEquations()
    define: dict[tuple[str, int], Ex] = {}     # ("e"|"f", bond) -> defining expression
    states: list[tuple[str, int, str]] = []     # (storage name, bond, "p"/"q")

    def e(k):
        return var("e", k)

    def f(k):
        return var("f", k)

    def sgn(b, name):                           # +1 if the bond points into `name`
        return 1 if b.points_into(name) else -1

    for n in g.nodes.values():
        bonds = [b for b in inc[n.name] if b.number in eto]
        name, title = n.name, n.title
        m = param(n.symbol)
        if n.modulus:
            out.moduli[n.symbol] = n.modulus
        if n.kind in JUNCTIONS:
            s = strong_bond(n, bonds, eto)
            if s is None:
                continue
            others = [b for b in bonds if b is not s]
            common, summed = ("e", "f") if n.kind == "0" else ("f", "e")
            for b in others:
                lhs, rhs = var(common, b.number), var(common, s.number)
                out.junctions.append(CausalEquation(name, title, lhs, rhs))
                define[(common, b.number)] = rhs
            # sum of the other variable with half-arrow signs
            ss = sgn(s, name)
            rhs = add([(-ss * sgn(b, name), var(summed, b.number)) for b in others])
            out.junctions.append(CausalEquation(name, title, var(summed, s.number), rhs))
            define[(summed, s.number)] = rhs
            continue
        if n.kind in ("TF", "MTF", "GY", "MGY"):
            if len(bonds) != 2:
                continue
            # modulus convention: port "p1" is the first; e1 = m e2, f2 = m f1 (TF);
            # e1 = r f2, e2 = r f1 (GY)
            b1 = next((b for b in bonds if b.port_at(name) in ("p1", "")), bonds[0])
            b2 = bonds[1] if b1 is bonds[0] else bonds[0]
            i1, i2 = b1.number, b2.number
            in1, in2 = eto[i1] == name, eto[i2] == name
            eqs: list[tuple[Sym, Ex]] = []
            if n.kind in ("TF", "MTF"):
                if in1 == in2:
                    continue
                if in2:        # effort in at port 2, flow in at port 1
                    eqs = [(e(i1), mul(m, e(i2))), (f(i2), mul(m, f(i1)))]
                else:
                    eqs = [(e(i2), Quot(e(i1), m)), (f(i1), Quot(f(i2), m))]
            else:
                if in1 != in2:
                    continue
                if in1:        # efforts in: flows out
                    eqs = [(f(i2), Quot(e(i1), m)), (f(i1), Quot(e(i2), m))]
                else:
                    eqs = [(e(i1), mul(m, f(i2))), (e(i2), mul(m, f(i1)))]
            for lhs, rhs in eqs:
                out.junctions.append(CausalEquation(name, title, lhs, rhs))
                define[(lhs.t[0], int(lhs.t[1:]))] = rhs
            continue
        if not bonds:
            continue
        k = bonds[0].number
        into = eto[k] == name
        src = param(n.symbol)
        if n.kind == "Se":
            rhs = Sym("0", "0") if n.zero else src
            out.elements.append(CausalEquation(name, title, e(k), rhs))
            define[("e", k)] = rhs
        elif n.kind == "Sf":
            rhs = Sym("0", "0") if n.zero else src
            out.elements.append(CausalEquation(name, title, f(k), rhs))
            define[("f", k)] = rhs
        elif n.kind == "De":
            out.elements.append(CausalEquation(name, title, f(k), Sym("0", "0")))
            define[("f", k)] = Sym("0", "0")
        elif n.kind == "Df":
            out.elements.append(CausalEquation(name, title, e(k), Sym("0", "0")))
            define[("e", k)] = Sym("0", "0")
        elif n.kind == "R" or n.kind in SWITCHES:
            if n.kind in SWITCHES:       # resistive form: e = (Ron if on else 1/Goff)*f
                out.moduli[n.symbol] = ("Ron if on else 1/Goff (resistive switch), on: "
                                        + (n.mode or "?"))
            if into:
                rhs = Quot(e(k), m)
                out.elements.append(CausalEquation(name, title, f(k), rhs))
                define[("f", k)] = rhs
            else:
                rhs = mul(m, f(k))
                out.elements.append(CausalEquation(name, title, e(k), rhs))
                define[("e", k)] = rhs
        elif n.kind in ("I", "C"):
            xs = "p" if n.kind == "I" else "q"
            x = var(xs, k)
            integral = c.storage.get(name) == "integral"
            drive, out_v = ("e", "f") if n.kind == "I" else ("f", "e")
            if integral:
                states.append((name, k, xs))
                out.elements.append(CausalEquation(name, title, Der(x), var(drive, k), True))
                rhs = Quot(x, m)
                out.elements.append(CausalEquation(name, title, var(out_v, k), rhs))
                define[(out_v, k)] = rhs
            else:
                rhs = mul(m, Der(var(out_v, k)))
                out.elements.append(CausalEquation(name, title, var(drive, k), rhs, True))
                define[(drive, k)] = rhs
                out.implicit.append(name)

    def expand(ex: Ex, seen: frozenset) -> Ex:
        if isinstance(ex, Sym):
            key = (ex.t[:1], ex.t[1:])
            if key[0] in ("e", "f") and key[1].isdigit():
                kk = (key[0], int(key[1]))
                if kk in define and kk not in seen:
                    return expand(define[kk], seen | {kk})
            return ex
        if isinstance(ex, Sum):
            return add([(s, expand(t, seen)) for s, t in ex.terms])
        if isinstance(ex, Prod):
            return mul(expand(ex.a, seen), expand(ex.b, seen))
        if isinstance(ex, Quot):
            return div(expand(ex.a, seen), expand(ex.b, seen))
        if isinstance(ex, Der):
            return Der(expand(ex.a, seen))
        return ex

    for name, k, xs in states:
        drive = "e" if xs == "p" else "f"
        key = (drive, k)
        rhs = expand(define[key], frozenset({key})) if key in define else var(drive, k)
        out.states.append(CausalEquation(name, g.nodes[name].title, Der(var(xs, k)), rhs,
                                         True))
    return out
