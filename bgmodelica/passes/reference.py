"""Floating networks: connection sets whose potentials have no reference (a missing ground).

The potentials of a circuit without a ground appear in its equations only as differences:
shifting all of them by one constant leaves every equation unchanged, so they are determined
only up to that constant and the model is singular (whatever the equation counts say). This
pass finds such networks on the flat model before alias elimination and names one of their
connection sets, instead of the symptom a later stage would report (a redundant equation of
some capacitor, a singular matrix).

A network is a set of potential variables (and variables equal to them) that appear together
in equations. It is floating when none of them is differentiated (an integrated potential,
such as an inertia's angle, is referenced by its initial value) and the directional
derivative of every equation touching it, along "all potentials of the network + 1", vanishes
at two random points.
"""

from __future__ import annotations

from collections import defaultdict

import casadi as ca
import numpy as np

from ..core.flatmodel import FlatModel
from ..core.variables import KIND_POTENTIAL
from ..errors import UnbalancedModelError
from .symbolic import incidence


class _Union:
    def __init__(self, n: int) -> None:
        self.parent = list(range(n))

    def find(self, a: int) -> int:
        while self.parent[a] != a:
            self.parent[a] = self.parent[self.parent[a]]
            a = self.parent[a]
        return a

    def union(self, a: int, b: int) -> None:
        ra, rb = self.find(a), self.find(b)
        if ra != rb:
            self.parent[ra] = rb


def floating_networks(model: FlatModel) -> list[list[int]]:
    """Variable indices of each floating network (potentials and their equal aliases)."""
    variables = model.variables
    pots = [i for i, v in enumerate(variables) if v.decl.kind == KIND_POTENTIAL]
    if not pots or not model.equations:
        return []
    n = len(variables)
    same = _Union(n)                    # a = +1 * b links
    for eq in model.equations:
        if eq.alias is not None:
            a, b, s = eq.alias
            if abs(float(s) - 1.0) < 1e-15:
                same.union(a, b)
    pot_roots = {same.find(i) for i in pots}
    shift = [i for i in range(n) if same.find(i) in pot_roots and variables[i].der_of < 0]
    shift_set = set(shift)
    rows = incidence([e.residual for e in model.equations], [v.sx for v in variables])
    net = _Union(n)
    touching: list[int] = []
    anchored: list[int] = []            # in an equation with no other potential (a ground)
    for k, row in enumerate(rows):
        members = [j for j in row if j in shift_set]
        if not members:
            continue
        touching.append(k)
        if len(members) == 1:
            anchored.append(members[0])
        for j in members[1:]:
            net.union(members[0], j)
    grounded = {net.find(j) for j in anchored}
    groups: dict[int, list[int]] = defaultdict(list)
    for j in shift:
        groups[net.find(j)].append(j)
    candidates = []
    for root, members in groups.items():
        if root in grounded:
            continue
        if any(variables[j].der >= 0 for j in members):
            continue                    # integrated: referenced by its initial value
        if not any(variables[j].decl.kind == KIND_POTENTIAL for j in members):
            continue
        candidates.append(members)
    if not candidates:
        return []
    eqs_of: dict[int, list[int]] = defaultdict(list)
    root_of = {j: net.find(j) for j in shift}
    for k in touching:
        for root in {root_of[j] for j in rows[k] if j in shift_set}:
            eqs_of[root].append(k)
    candidates = [m for m in candidates if eqs_of.get(net.find(m[0]))]
    if not candidates:
        return []
    return [m for m in candidates if _invariant(model, m, eqs_of[net.find(m[0])])]


def _invariant(model: FlatModel, members: list[int], eqs: list[int]) -> bool:
    """Whether every equation in ``eqs`` is unchanged by a common shift of ``members``."""
    res = ca.vertcat(*[model.equations[k].residual for k in eqs])
    v = ca.vertcat(*[model.variables[j].sx for j in members])
    d = ca.jtimes(res, v, ca.DM.ones(len(members), 1))
    syms = ca.symvar(d)
    if not syms:
        return bool(np.all(np.asarray(ca.DM(ca.evalf(d))).ravel() == 0))
    f = ca.Function("bgm_shift", [ca.vertcat(*syms)], [d])
    rng = np.random.default_rng(12345)
    for _ in range(2):
        point = rng.uniform(0.5, 1.5, len(syms))
        with np.errstate(all="ignore"):
            out = np.asarray(f(point), dtype=float).ravel()
        if not np.all(np.isfinite(out)) or np.max(np.abs(out)) > 1e-9:
            return False
    return True


def _connector(name: str) -> str:
    return name.rpartition(".")[0] or name


#: models with more equations are checked only once another check has failed (the search
#: costs about 40 us per equation)
EAGER_LIMIT = 2000


def check_references(model: FlatModel, force: bool = False) -> None:
    """Raise :class:`UnbalancedModelError` naming a connection set of a floating network.
    Large models (more than :data:`EAGER_LIMIT` equations) only with ``force``."""
    if not force and len(model.equations) > EAGER_LIMIT:
        return
    floating = floating_networks(model)
    if not floating:
        return
    variables = model.variables
    members = floating[0]
    sets = _connection_sets(model, members)
    chosen = max(sets, key=lambda s: (len(s), sum(c.rsplit(".", 1)[-1] == "n" for c in s),
                                      [-ord(ch) for ch in ",".join(s)])) if sets else []
    comps = sorted({variables[j].component for j in members if variables[j].component},
                   key=lambda c: [variables[j].component for j in members].index(c))
    shown = chosen[:6] + ([f"... ({len(chosen)} connectors)"] if len(chosen) > 6 else [])
    what = f"connection set {{{', '.join(shown)}}}" if chosen else \
        f"the potential {variables[members[0]].name}"
    more = f" (and {len(floating) - 1} other floating network(s))" if len(floating) > 1 else ""
    names = [variables[j].name for j in members if variables[j].decl.kind == KIND_POTENTIAL]
    who = (", ".join(comps[:8]) + (", ..." if len(comps) > 8 else "")) if comps \
        else f"model {model.name}"
    raise UnbalancedModelError(
        f"{what} has no reference (ground): the potentials of the network of {who} enter "
        f"its equations only as differences, so they are fixed only up to a constant{more}; "
        "connect a ground (or another reference) to it", missing=names)


def _connection_sets(model: FlatModel, members: list[int]) -> list[list[str]]:
    """The connection sets (connector paths) of the potentials ``members``, from the alias
    equations between them."""
    variables = model.variables
    pot = [j for j in members if variables[j].decl.kind == KIND_POTENTIAL]
    inset = set(pot)
    u = _Union(len(variables))
    for eq in model.equations:
        if eq.alias is not None and eq.origin.startswith("connection set"):
            a, b, _ = eq.alias
            if a in inset and b in inset:
                u.union(a, b)
    groups: dict[int, list[str]] = defaultdict(list)
    for j in pot:
        groups[u.find(j)].append(_connector(variables[j].name))
    return [sorted(set(g)) for g in groups.values()]


def likely_causes(model: FlatModel, missing: list[int], rows: list[list[int]],
                  surplus: list[int] = ()) -> list[str]:
    """Likely causes of an unbalanced or singular model, given the variables ``missing``
    (indices) that no equation determines and the ``surplus`` equations (indices): an
    unconnected input, a component whose connectors are connected to each other (a shorted
    source), a variable that appears in no equation."""
    used: set[int] = {j for row in rows for j in row}
    variables = model.variables
    linked = set(model.aliases) | {rep for rep, _ in model.aliases.values()}
    out = [f"input {v.name} is not connected (connect an output to it)"
           for v in variables if v.decl.kind == "input" and v.name not in linked]
    involved = [variables[j].component for j in missing if variables[j].component]
    for i in surplus:
        origin = model.equations[i].origin
        if not origin.startswith(("connection set", "unconnected", "d/dt")):
            involved.append(origin.split(" (")[0])
    shorted = {}
    for comp in dict.fromkeys(involved):
        pair = _shorted(model, comp)
        if pair:
            shorted[comp] = pair
            out.append(f"{comp}.{pair[0]} and {comp}.{pair[1]} are connected to each other "
                       f"({comp} is short-circuited)")
    for j in missing:
        v = variables[j]
        if v.decl.kind == "input" or v.component in shorted:
            continue
        if j not in used and (v.der < 0 or v.der not in used):
            what = "output" if v.decl.kind == "output" else "variable"
            out.append(f"{what} {v.name} appears in no equation (its equation is missing)")
    return out


def _shorted(model: FlatModel, comp: str) -> tuple[str, str] | None:
    """Two connectors of component ``comp`` whose potentials are one variable."""
    prefix = comp + "."
    reps: dict[tuple[str, float], str] = {}
    names = [v.name for v in model.variables if v.decl.kind == KIND_POTENTIAL] \
        + list(model.aliases)
    for name in names:
        if not name.startswith(prefix):
            continue
        parts = name[len(prefix):].split(".")
        if len(parts) != 2:
            continue
        rep = model.aliases.get(name, (name, 1.0))
        key = (f"{rep[0]}/{parts[1]}", float(rep[1]))
        if key[1] != 1.0:
            continue
        other = reps.setdefault(key, parts[0])
        if other != parts[0]:
            return tuple(sorted((other, parts[0])))
    return None
