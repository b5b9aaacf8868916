"""Property-based check of the array path for models of leaf components joined by ``connect``
(hypothesis): random electrical networks of resistors, capacitors, inductors and sources (small
ones, sometimes with a group of 64 or more components of one class, written once; unconnected
pins, repeated and redundant connections; random parameters and start values, some fixed)
compile to the scalar pipeline's DAE, or go the scalar way with a reason and then compile as
the scalar pipeline compiles them (or fail with its error).

Most networks are drawn index 1 and explicit by construction (a tree of capacitors and
voltage sources gives every node its voltage, the other branches hang between those nodes)
and must take the array path (unless fixed starts of aliases conflict); the others are drawn
freely (algebraic loops, capacitor loops, floating nodes, parts with both pins on one node...)
and may go either way. The networks the property found wrong are kept as examples below.

The default settings are derandomized (the same examples on every run, for CI); set
``HYPOTHESIS_PROFILE=explore`` to search with fresh random examples.
"""

from __future__ import annotations

import os
import random
from dataclasses import dataclass, field
from typing import Any

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, event, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import bgmodelica as bg  # noqa: E402
from bgmodelica import Component  # noqa: E402
from bgmodelica.array_path import ArrayCompiledModel, compile_arrays, why_not  # noqa: E402
from bgmodelica.compiler import _compile  # noqa: E402
from bgmodelica.core.flatten_vectorized import array_equations, component_groups  # noqa: E402
from library.electrical import (  # noqa: E402
    Capacitor,
    ConstantCurrent,
    ConstantVoltage,
    Ground,
    Inductor,
    Resistor,
    SineCurrent,
    SineVoltage,
    StepVoltage,
)

from .test_array_path_components import _same_dae  # noqa: E402

EXPLORE = os.environ.get("HYPOTHESIS_PROFILE") == "explore"
FUZZ = settings(max_examples=300, deadline=None, database=None, derandomize=False,
                suppress_health_check=[HealthCheck.too_slow]) if EXPLORE else \
    settings(max_examples=30, deadline=None, derandomize=True,
             suppress_health_check=[HealthCheck.too_slow])

#: kind -> (class, name prefixes)
KINDS: dict[str, tuple[type, tuple[str, ...]]] = {
    "R": (Resistor, ("R", "res")),
    "C": (Capacitor, ("C", "cap_")),
    "L": (Inductor, ("L", "coil")),
    "V": (ConstantVoltage, ("V", "battery")),
    "Vsin": (SineVoltage, ("S", "ac")),
    "Vstep": (StepVoltage, ("step",)),
    "I": (ConstantCurrent, ("I", "feed")),
    "Isin": (SineCurrent, ("J", "acfeed")),
}
SOURCES = {"V", "Vsin", "Vstep", "I", "Isin"}
GROUP_SIZE = (64, 72)


# -- descriptions ------------------------------------------------------------------------------

@dataclass
class Part:
    """A one-port of kind ``kind`` from node ``p`` to node ``n`` (0: ground; None: its pin is
    left unconnected); ``grounds``: which Ground component each pin on node 0 joins."""

    kind: str
    p: int | None
    n: int | None
    mods: dict[str, Any]
    grounds: tuple[int, int] = (0, 0)


@dataclass
class Net:
    """A drawn network, built into a fresh component by :func:`build`."""

    parts: list[Part]
    n_grounds: int
    prefixes: dict[str, str]
    chain: bool                       # a node's pins joined in a chain (else a star)
    extra: list[tuple[str, int, int]] = field(default_factory=list)   # repeated links
    seed: int = 0                     # orientation and order of the connections
    order: str = "drawn"              # order of the components: drawn, grounds-last, shuffled
    shuffle_links: bool = False
    explicit: bool = True             # index 1 and explicit by construction
    group: str = "none"

    @property
    def fixes_algebraics(self) -> bool:
        """Whether a variable other than a state has a fixed start (two of them, or one and a
        state, may be aliases of one another with different values)."""
        return any(map(_fixed, (value for part in self.parts for key, mod in part.mods.items()
                                for value in (mod.values() if key in ("p", "n") else [mod])
                                if key in ("p", "n", "i", "v")
                                and (part.kind, key) not in (("C", "v"), ("L", "i")))))


def _fixed(modifier: Any) -> bool:
    """Whether a start modifier fixes the start."""
    return not isinstance(modifier, dict) or bool(modifier.get("fixed"))


class Circuit(Component):
    """The top level: leaf components and connections only."""


def build(net: Net) -> Circuit:
    """A fresh component of the network ``net`` (the same description gives the same model)."""
    rng = random.Random(net.seed)
    model = Circuit()
    counts: dict[str, int] = {}
    comps = []
    for part in net.parts:
        cls, _ = KINDS[part.kind]
        counts[part.kind] = counts.get(part.kind, 0) + 1
        comps.append((f"{net.prefixes[part.kind]}{counts[part.kind]}", cls(**part.mods)))
    grounds = [(f"ground{g}" if g else "ground", Ground()) for g in range(net.n_grounds)]
    items = comps + grounds if net.order == "grounds-last" else grounds + comps
    if net.order == "shuffled":
        rng.shuffle(items)
    for name, comp in items:
        model.add(name, comp)
    pins: dict[int, list[Any]] = {}
    links: list[tuple[Any, Any]] = []
    for part, (_, comp) in zip(net.parts, comps, strict=True):
        for node, pin, g in ((part.p, comp.p, part.grounds[0]), (part.n, comp.n, part.grounds[1])):
            if node == 0:
                links.append((pin, grounds[g % len(grounds)][1].p))
            elif node is not None:
                pins.setdefault(node, []).append(pin)
    for members in pins.values():
        for k in range(1, len(members)):
            links.append((members[k - 1] if net.chain else members[0], members[k]))
    links = [(b, a) if rng.random() < 0.5 else (a, b) for a, b in links]
    crowded = [members for members in pins.values() if len(members) > 1]
    for how, x, y in net.extra:                 # repeated, reversed and redundant links
        if how == "cycle" and crowded:
            members = crowded[x % len(crowded)]
            i, j = y % len(members), (y + 1 + x) % len(members)
            if i != j:
                links.append((members[i], members[j]))
        elif how != "cycle" and links:
            a, b = links[x % len(links)]
            links.append((b, a) if how == "reversed" else (a, b))
    if net.shuffle_links:
        rng.shuffle(links)
    for a, b in links:
        model.connect(a, b)
    return model


# -- strategies --------------------------------------------------------------------------------

values = st.floats(0.1, 10.0, allow_nan=False)
starts = st.floats(-2.0, 2.0, allow_nan=False)


@st.composite
def start_modifier(draw, key: str) -> dict[str, Any]:
    """No start, a guess, or a fixed start of ``key``."""
    how = draw(st.sampled_from(["none", "guess", "fixed", "fixed", "dict-fixed"]))
    if how == "none":
        return {}
    s = draw(starts)
    if how == "guess":
        return {key: {"start": s, "fixed": False}}
    if how == "fixed":
        return {key: s}
    return {key: {"start": s, "fixed": True, "nominal": draw(values)}}


@st.composite
def modifiers(draw, kind: str) -> dict[str, Any]:
    """Random parameters (sometimes left at their defaults) and starts of a part."""
    mods = draw(pin_starts()) if draw(st.integers(0, 2)) == 0 else {}
    given_values = draw(st.booleans()) or draw(st.booleans())
    if kind == "R":
        if given_values:
            mods["R"] = draw(values)
        if draw(st.integers(0, 4)) == 0:       # now and then a start on an algebraic variable
            mods.update(draw(start_modifier(draw(st.sampled_from(["i", "v"])))))
        return mods
    if kind in ("C", "L"):
        key, state = ("C", "v") if kind == "C" else ("L", "i")
        if given_values:
            mods[key] = draw(values)
        if kind == "L" and draw(st.sampled_from([True, True, True, False])):
            # the start on a pin's current (n.i = -i), carried with its sign to the inductor's
            # current, which represents it in its alias class; at most a guess on i itself
            s = draw(starts)
            mods[draw(st.sampled_from(["n", "n", "p"]))] = \
                {"i": s if draw(st.booleans()) else {"start": s, "fixed": False}}
            if draw(st.booleans()):
                mods["i"] = {"start": draw(starts), "fixed": False}
            return mods
        return {**mods, **draw(start_modifier(state))}
    if not given_values:
        return mods
    return {**mods, **_source_values(draw, kind)}


@st.composite
def pin_starts(draw) -> dict[str, Any]:
    """A start of a pin's current or voltage: in an alias class a fixed one outranks a
    variable with fewer dots, and it is carried (times the sign) to an inductor's current."""
    key, s = draw(st.sampled_from(["i", "i", "v"])), draw(starts)
    mod = {key: s} if draw(st.booleans()) else {key: {"start": s, "fixed": False}}
    return {draw(st.sampled_from(["p", "n"])): mod}


def _source_values(draw, kind: str) -> dict[str, Any]:
    """Random parameters of a source."""
    if kind == "V":
        return {"V": draw(values)}
    if kind == "I":
        return {"I": draw(values)}
    if kind == "Vsin":
        return {"V": draw(values), "f": draw(values), "phase": draw(starts),
                "offset": draw(starts)}
    if kind == "Isin":
        return {"I": draw(values), "f": draw(values)}
    return {"V": draw(values), "start_time": draw(values)}          # Vstep


def _oriented(draw, kind: str, a: int | None, b: int | None, mods: dict) -> Part:
    """A part between ``a`` and ``b``, either way round, its ground pins on random grounds."""
    if draw(st.booleans()):
        a, b = b, a
    return Part(kind, a, b, mods, (draw(st.integers(0, 3)), draw(st.integers(0, 3))))


@st.composite
def explicit_parts(draw) -> tuple[list[Part], int, int]:
    """An index 1, explicit network: node ``k`` gets its voltage from a capacitor or a voltage
    source to an earlier node (0: ground), a tree; then branches between those nodes:
    resistors, inductors, current sources, a resistor in series with an inductor or a
    capacitor (through a node of their own), a resistor or capacitor with a pin left
    unconnected. Returns the parts, the number of nodes given a voltage by the tree and the
    number of nodes used."""
    n = draw(st.integers(1, 5))
    parts: list[Part] = []
    for k in range(1, n + 1):
        kind = draw(st.sampled_from(["C", "C", "C", "V", "Vsin"]))
        parts.append(_oriented(draw, kind, k, draw(st.integers(0, k - 1)), draw(modifiers(kind))))
    nodes = n
    node = st.integers(0, n)
    for branch in draw(st.lists(st.sampled_from(["R", "R", "L", "RL", "RC", "I", "Isin",
                                                 "R-open", "C-open"]), max_size=8)):
        a, b = draw(node), draw(node)
        if branch in ("RL", "RC"):
            nodes += 1
            other = "L" if branch == "RL" else "C"
            ends = [(a, nodes), (nodes, b)]
            kinds = ["R", other] if draw(st.booleans()) else [other, "R"]
            for kind, (u, v) in zip(kinds, ends, strict=True):
                parts.append(_oriented(draw, kind, u, v, draw(modifiers(kind))))
        elif branch.endswith("-open"):
            kind = branch[0]
            parts.append(_oriented(draw, kind, a, None, draw(modifiers(kind))))
        else:
            parts.append(_oriented(draw, branch, a, b, draw(modifiers(branch))))
    if not any(part.kind in SOURCES for part in parts):
        kind = draw(st.sampled_from(["I", "Isin"]))
        parts.append(_oriented(draw, kind, draw(node), draw(node), draw(modifiers(kind))))
    return parts, n, nodes


@st.composite
def free_parts(draw) -> tuple[list[Part], int, int]:
    """Parts between random nodes (or with a pin unconnected): algebraic loops, loops of
    capacitors and sources, floating nodes, parts with both pins on one node, inductors cut
    off... now and then a step source (not smooth: the scalar way)."""
    n = draw(st.integers(1, 4))
    end = st.one_of(st.integers(0, n), st.just(None)) if draw(st.booleans()) \
        else st.integers(0, n)
    smooth = sorted(set(KINDS) - {"Vstep"})
    kinds = draw(st.lists(st.sampled_from(smooth), min_size=2, max_size=8))
    if not any(kind in SOURCES for kind in kinds):
        kinds.append(draw(st.sampled_from(sorted(SOURCES - {"Vstep"}))))
    if draw(st.sampled_from([False] * 7 + [True])):
        kinds.insert(draw(st.integers(0, len(kinds))), "Vstep")
    parts = [_oriented(draw, kind, draw(end), draw(end), draw(modifiers(kind))) for kind in kinds]
    return parts, n, n


def group_parts(kind: str, size: int, seed: int, known: int, nodes: int) -> list[Part]:
    """``size`` sections between the nodes ``0..known`` (values from ``seed``; new nodes
    numbered from ``nodes + 1``): a ladder of resistors and capacitors to ground, parallel RC
    branches, resistors, or resistors in series with inductors."""
    rng = random.Random(seed)
    fixing = rng.choice(["all", "none", "mixed"])

    def start(key: str) -> dict[str, Any]:
        s = round(rng.uniform(-2.0, 2.0), 3)
        fixed = fixing == "all" or (fixing == "mixed" and rng.random() < 0.5)
        return {key: s} if fixed else {key: {"start": s, "fixed": False}}

    def r() -> Part:
        return Part("R", 0, 0, {"R": round(rng.uniform(0.2, 5.0), 4)},
                    (rng.randrange(4), rng.randrange(4)))

    def flip(part: Part, a: int, b: int) -> Part:
        part.p, part.n = (b, a) if rng.random() < 0.3 else (a, b)
        return part

    parts: list[Part] = []
    prev = rng.randint(0, known)
    for _ in range(size):
        a, b = rng.randint(0, known), rng.randint(0, known)
        if kind in ("ladder", "rc-branches"):
            nodes += 1
            c = Part("C", 0, 0, {"C": round(rng.uniform(0.1, 2.0), 4), **start("v")})
            parts += [flip(r(), prev if kind == "ladder" else a, nodes), flip(c, nodes, 0)]
            if kind == "ladder":
                prev = nodes
        elif kind == "resistors":
            parts.append(flip(r(), a, b))
        else:                                       # rl-branches
            nodes += 1
            ind = Part("L", 0, 0, {"L": round(rng.uniform(0.1, 2.0), 4), **start("i")})
            parts += [flip(r(), a, nodes), flip(ind, nodes, b)]
    return parts


@st.composite
def networks(draw) -> Net:
    """An explicit or a free network, maybe with a group, its connections in a random order
    and shape (chain or star, some repeated), its components named and ordered at random."""
    explicit = draw(st.sampled_from([True] * 4 + [False]))
    parts, known, nodes = draw(explicit_parts() if explicit else free_parts())
    group = draw(st.sampled_from(["ladder", "rc-branches", "resistors", "rl-branches"])) \
        if draw(st.booleans()) else "none"
    if group != "none":
        more = group_parts(group, draw(st.integers(*GROUP_SIZE)), draw(st.integers(0, 2**16)),
                           known, nodes)
        at = draw(st.integers(0, len(parts)))
        parts = parts[:at] + more + parts[at:]
    extra = draw(st.lists(st.tuples(st.sampled_from(["again", "reversed", "cycle"]),
                                    st.integers(0, 50), st.integers(0, 50)), max_size=3))
    return Net(parts=parts, n_grounds=draw(st.integers(1, 3)),
               prefixes={kind: draw(st.sampled_from(prefixes))
                         for kind, (_, prefixes) in KINDS.items()},
               chain=draw(st.booleans()), extra=extra, seed=draw(st.integers(0, 2**16)),
               order=draw(st.sampled_from(["drawn", "grounds-last", "shuffled"])),
               shuffle_links=draw(st.booleans()), explicit=explicit, group=group)


# -- the property --------------------------------------------------------------------------------

def _outcome(call) -> tuple:
    """What a compile gives: the names of its variables, states and parameters and its
    aliases, or its error's type and message."""
    try:
        dae = call().dae
    except Exception as err:  # noqa: BLE001 -- compared between the two pipelines
        return type(err), str(err)
    return dae.names, dae.state_names, [q.name for q in dae.parameters], dae.aliases


def _check(net: Net) -> str:
    """The property for one network; what happened to it (for the statistics)."""
    model = build(net)
    fast = compile_arrays(model, minimum=0)
    kind = "explicit" if net.explicit else "free"
    if net.group != "none":             # classes of 64 or more, their equations written once
        written = sum(array_equations(items) is not None for _, items in component_groups(model))
        kind += f", classes written once: {written}"
    if fast is not None:
        assert isinstance(fast, ArrayCompiledModel)
        try:
            slow = _compile(build(net), None)
        except Exception as err:  # noqa: BLE001 -- a mismatch: reported as such
            pytest.fail("the array path compiled a model the scalar pipeline refuses: "
                        f"{type(err).__name__}: {err}")
        _same_dae(fast.dae, slow.dae)
        return f"array path ({kind})"
    reason = why_not(model, minimum=0)
    assert isinstance(reason, str) and reason
    if net.explicit:                    # the generator's share of the array path
        assert net.fixes_algebraics and "conflicting fixed start values" in reason, \
            f"an explicit network went the scalar way: {reason}"
    assert _outcome(lambda: bg.compile(model)) \
        == _outcome(lambda: bg.compile(build(net), array_path=False))
    return f"scalar way ({kind}): {reason.split(':')[0]}"


@FUZZ
@given(networks())
def test_random_networks_give_the_scalar_pipelines_dae_or_go_the_scalar_way(net):
    event(_check(net))


#: the first names of the parts (the prefixes of the networks written out below)
PLAIN = {kind: prefixes[0] for kind, (_, prefixes) in KINDS.items()}
#: networks with a part whose two pins are on one node, which the property above found
SHORTED = {
    # structurally singular (nothing determines node 1's voltage; I1.i = I1.I and
    # I1.p.i = 0 over-determine the current), as the scalar pipeline says
    "capacitor-and-current-source": [Part("C", 1, 1, {}), Part("I", 1, 0, {})],
    "resistor-and-current-source": [Part("R", 1, 1, {}), Part("I", 1, 0, {})],
    # well posed: C1.v = 0 is a constraint, the scalar pipeline reduces the index (no state)
    "capacitor-and-resistor-to-ground": [Part("R", 0, 1, {}), Part("C", 1, 1, {})],
}


@pytest.mark.parametrize("parts", list(SHORTED.values()), ids=list(SHORTED))
def test_parts_with_both_pins_on_one_node(parts):
    # The array path took these with p.v - n.v (zero once the aliases are substituted) as
    # the pivot of the node's voltage: -inf values, and a state where the scalar pipeline
    # has none or an error.
    _check(Net(parts=parts, n_grounds=1, prefixes=PLAIN, chain=False, explicit=False))
