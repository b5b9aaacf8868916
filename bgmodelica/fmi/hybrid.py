"""Export of hybrid models (events): the CasADi event functions and the tables of the C runtime.

The FMU evaluates the same CasADi functions as the native event loop
(:func:`bgmodelica.events.functions.build`): the event step (relation indicators, their time
derivatives, when-conditions, when-assignments, reinit values, ``pre()`` sources) and the
state-event indicators, with the algebraic variables ``z`` eliminated by CasADi's
code-generatable ``fast_newton`` rootfinder (as in the model function), and with the parameter
vector split as the FMU holds it: ``p`` (free parameters), ``u`` (inputs) and ``d`` (the
discrete slots that the native loop keeps at the end of its ``p``). The event logic itself is
``templates/bgm_events.c``, a port of :mod:`bgmodelica.events.loop`.

Discrete variables are exported with their FMI types (``Discrete`` -> Real/Float64,
``Integer`` -> Integer/Int32, ``Boolean`` -> Boolean), ``variability="discrete"``, causality
local: those assigned in ``when`` clauses with ``initial="exact"`` and their declared start
(the ``pre`` value at initialization, settable before initialization), those defined by
equations (e.g. ``diode.off``) as ``initial="calculated"``. Table data are compiled into the
C code (``bgm_hybrid_data.c``).

``reinit`` of a variable that index reduction demoted from the states (the pendulum's ``vy``
when ``x, vx`` are the states) re-initializes the states consistently as the native loop does:
the re-initialized variables are fixed and the states they determine are solved with the
model's algebraic equations (a code-generatable Newton solve from the values before the
event); the event sets those states.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from ..backends.casadi_dae import CasadiDAE
from ..events.functions import build
from .spec import FmuSpecError

DV_TYPES = ("Real", "Integer", "Boolean")
EXTRAPOLATIONS = {"hold": 0, "periodic": 1, "linear": 2}


@dataclass(frozen=True)
class DiscreteVariable:
    """An exported discrete variable. ``slot``: index in ``d`` of a when-assigned variable
    (its start is settable), -1 for one defined by an equation (calculated)."""

    name: str
    type: str                  # "Real", "Integer" or "Boolean"
    start: float | None        # None: calculated
    unit: str = ""
    description: str = ""
    slot: int = -1


@dataclass(frozen=True)
class TableData:
    c0: int                    # slots of the coefficients in d
    c1: int
    times: tuple[float, ...]
    values: tuple[float, ...]
    hold: bool
    extrapolation: str
    source: tuple[str, str] | None = None   # (file path, column): read from the resources
    resource: str = ""                      # the file's name in the FMU's resources folder


@dataclass
class HybridSpec:
    """Everything the C event runtime needs (see the module docstring).

    Functions, all ``(t, x, u, p, d)``: ``step`` -> (g, dgdt, cond, assign, reinit, pre, dv),
    ``indicators`` -> the state relations' indicators, ``samples`` -> (start, interval) of
    every clock."""

    d_names: list[str]
    d_start: list[float]
    relations: list[str]
    rel_slot: list[int]
    rel_strict: list[bool]
    state_rel: list[int]
    time_rel: list[int]
    whens: list[list[int]]                       # per when: its branches (cond indices)
    assigns: list[list[tuple[int, int]]]         # per branch: (slot, position in assign)
    reinits: list[list[tuple[int, float, int]]]  # per branch: (state, sign, position)
    pre: list[tuple[int, bool, str]]             # (slot, source is discrete, source name)
    sample_slots: list[int]
    tables: list[TableData]
    initial_slot: int
    terminal_slot: int
    discretes: list[DiscreteVariable]
    step: Any = None
    indicators: Any = None
    samples: Any = None
    #: the pre() slots also follow their sources after every completed integrator step
    #: (Newton guesses of dynamic state selection, :mod:`bgmodelica.fmi.state_sets`)
    track_pre: bool = False

    @property
    def nd(self) -> int:
        return len(self.d_names)

    @property
    def nz(self) -> int:
        return len(self.state_rel)

    def validate(self, nx: int, seen: dict[str, str]) -> None:
        for v in self.discretes:
            if v.type not in DV_TYPES:
                raise FmuSpecError(f"discrete variable {v.name!r}: type {v.type!r}")
            if v.name in seen:
                raise FmuSpecError(f"variable name {v.name!r} used twice ({seen[v.name]} and "
                                   "discrete)")
            seen[v.name] = "discrete"
            if v.start is not None and not math.isfinite(float(v.start)):
                raise FmuSpecError(f"discrete {v.name!r}: start value {v.start!r} is not "
                                   "finite")
        for k in range(self.nz):
            name = indicator_name(k)
            if name in seen:
                raise FmuSpecError(f"variable name {name!r} is reserved for event indicators")
        for branch in self.reinits:
            for s, _, _ in branch:
                if not 0 <= s < nx:
                    raise FmuSpecError(f"reinit of state {s} out of range")


def indicator_name(k: int) -> str:
    """Name of the exported variable of event indicator ``k`` (FMI 3.0 Model Exchange)."""
    return f"_event_indicator_{k + 1}"


def check_exportable(dae: CasadiDAE, name: str) -> None:
    """Refuse what the FMU runtime cannot reproduce (with the reason); every reinit target
    must be a state or a variable the states determine (checked when the events are built)."""
    build(dae)


def _consistent_reinit(dae: CasadiDAE, branch: list[tuple[str, int]], t, x, z, pfull,
                       reinit) -> tuple[list[int], ca.MX]:
    """A reinit branch that restarts variables demoted from the states: the native
    consistent re-initialization (``HybridSimulator._consistent`` with the re-initialized
    variables fixed), as a code-generatable Newton solve started from the values before the
    event. Returns the states it sets and their values."""
    from ..backends.casadi_init import init_structure

    pinned_value: dict[int, ca.MX] = {}
    fixed, cond_value = [], {}
    for var, pos in branch:
        rep, sign = dae.aliases.get(var, (var, 1.0))
        value = sign * reinit[pos]
        k = dae.observed_index[rep]
        fixed.append((k, 0.0))
        if rep in dae.state_names:
            pinned_value[dae.state_names.index(rep)] = value
        else:
            cond_value[k] = value
    st = init_structure(replace(dae, fixed=fixed, initial=dae.initial[:0],
                                initial_labels=[]))
    conds = [k for k, _ in st.conditions]
    pinned = [i for i in range(dae.x.numel()) if i not in set(st.free)]
    vals = ca.SX.sym("vals", len(conds))
    unknown = ca.vertcat(*[dae.x[i] for i in st.free], dae.z)
    known = ca.vertcat(*[dae.x[i] for i in pinned]) if pinned else ca.SX(0, 1)
    res = ca.vertcat(*[dae.observed[k] - vals[j] for j, k in enumerate(conds)], dae.alg)
    g = ca.Function("reinit_g", [unknown, ca.vertcat(known, dae.p, dae.t, vals)], [res])
    solver = ca.rootfinder("reinit_solve", "fast_newton", g,
                           {"abstol": 1e-12, "max_iter": 50})
    known_v = ca.vertcat(*[pinned_value.get(i, x[i]) for i in pinned]) if pinned \
        else ca.MX(0, 1)
    w = solver(ca.vertcat(*[x[i] for i in st.free], z),
               ca.vertcat(known_v, pfull, t, *[cond_value[k] for k in conds]))
    states = sorted(set(st.free) | set(pinned_value))
    value_of = {i: w[j] for j, i in enumerate(st.free)}
    value_of.update(pinned_value)
    return states, ca.vertcat(*[value_of[i] for i in states])


def consistent_start(dae: CasadiDAE, p: np.ndarray):
    """The native start (``HybridSimulator._initialize`` before the initial event iteration):
    consistent (x0, z0) with the relations at their values there, and the parameter vector
    (discrete slots included) at that point."""
    from ..events.loop import HybridSimulator

    sim = HybridSimulator(dae, np.array(p, dtype=float), 1e-10, 1e-12, None, 100000, [])
    fn = sim.fn
    t0 = 0.0
    sim._update_tables(t0)
    x, z = sim._consistent(t0, None)
    for _ in range(sim.opts.max_iterations):
        g, dgdt, *_ = sim._step(t0, x, z)
        vals = sim._relation_values(t0, g, dgdt)
        if np.array_equal(vals, sim.p[fn.rel_slot]):
            break
        sim.p[fn.rel_slot] = vals
        x, z = sim._consistent(t0, None)
    return np.asarray(x, dtype=float), np.asarray(z, dtype=float), sim.p.copy()


def discrete_variables(dae: CasadiDAE, flat, by_name: dict) -> tuple[list[DiscreteVariable],
                                                                       list[ca.SX]]:
    """The exported discrete variables and their SX (in terms of t, x, z, dae.p)."""
    out: list[DiscreteVariable] = []
    exprs: list[ca.SX] = []
    slot_of = {d.name: k for k, d in enumerate(dae.discretes)}
    decls = {d.name: d.decl for d in dae.discretes}
    decls.update({v.name: v.decl for v in flat.variables})
    nv = dae.n_variables
    for name in dae.names[nv:]:          # assigned in when-clauses: discrete slots
        k = slot_of.get(name)
        if k is None:
            continue
        decl = decls[name]
        out.append(DiscreteVariable(name, getattr(decl, "type_name", "Real"),
                                    float(decl.start), getattr(decl, "unit", "") or "",
                                    getattr(decl, "description", "") or "", k))
        exprs.append(dae.observed[dae.observed_index[name]])
    for name in dae.names[:nv]:          # defined by equations
        if name not in dae.discrete_names:
            continue
        decl = decls.get(name)
        out.append(DiscreteVariable(name, getattr(decl, "type_name", "Real"), None,
                                    getattr(decl, "unit", "") or "",
                                    getattr(decl, "description", "") or ""))
        exprs.append(dae.observed[dae.observed_index[name]])
    known = {v.name for v in out}
    for alias, (rep, sign) in sorted(flat.aliases.items()):
        if rep not in known or alias in known or alias.startswith("der("):
            continue
        base = next(v for v in out if v.name == rep)
        out.append(replace(base, name=alias, start=None, slot=-1))
        exprs.append(sign * dae.observed[dae.observed_index[rep]])
    return out, exprs


def build_hybrid(dae: CasadiDAE, flat, by_name: dict, z_of, pfull_of) -> HybridSpec:
    """The :class:`HybridSpec` of ``dae``. ``z_of(t, x, pfull)``: the algebraic variables
    (MX, fast_newton) or None without them; ``pfull_of(p, u, d)``: the native ``p``."""
    fn = build(dae)
    hyb = dae.hybrid
    if fn.calls is not None:
        text = next(c[4] for branch in fn.call_of for c in branch)
        raise FmuSpecError(f"{text}: a function run on numbers at events cannot be exported "
                           "to an FMU")
    nb = dae.n_base
    nx, nu, np_, nd = dae.x.numel(), len(dae.inputs), len(dae.parameters), len(dae.discretes)
    t = ca.MX.sym("t")
    x = ca.MX.sym("x", nx)
    u = ca.MX.sym("u", nu)
    p = ca.MX.sym("p", np_)
    d = ca.MX.sym("d", nd)
    pfull = pfull_of(p, u, d)
    z = z_of(t, x, pfull) if z_of is not None else ca.MX(0, 1)
    dvars, dexprs = discrete_variables(dae, flat, by_name)
    dv_f = ca.Function("dv", [dae.t, dae.x, dae.z, dae.p],
                       [ca.densify(ca.vertcat(*dexprs)) if dexprs else ca.SX(0, 1)])
    g, dgdt, cond, assign, reinit, pre, _obs = fn.step(t, x, z, pfull)
    dv = dv_f(t, x, z, pfull)
    args, names = [t, x, u, p, d], ["t", "x", "u", "p", "d"]
    # relations on inputs (constant for the native loop, which feeds inputs as time tables)
    # change with the importer's inputs: state events in the FMU
    u_sx = dae.p[np_:nb]
    on_input = [k for k in fn.time_rel
                if nu and ca.depends_on(hyb.relations[k].indicator, u_sx)]
    state_rel = sorted(list(fn.state_rel) + on_input)
    time_rel = [k for k in fn.time_rel if k not in on_input]
    if on_input:
        ind = g[state_rel] if state_rel else ca.MX(0, 1)
    else:
        ind = fn.indicators(t, x, z, pfull)
    indicators = ca.Function("evind", args, [ind], names, ["z"])
    samp = ca.vertcat(*[ca.vertcat(s.start, s.interval) for s in hyb.samples]) \
        if hyb.samples else ca.SX(0, 1)
    samp_f = ca.Function("samp", [dae.p], [ca.densify(samp)])
    samples = ca.Function("evsamp", args, [samp_f(pfull)], names, ["samples"])

    reinits, extra = [], [reinit]
    n_reinit = reinit.numel()
    for branch in fn.reinit_of:
        reps = [dae.aliases.get(var, (var, 1.0)) for var, _ in branch]
        if all(rep in dae.state_names for rep, _ in reps):
            reinits.append([(dae.state_names.index(rep), float(sign), pos)
                            for (rep, sign), (_, pos) in zip(reps, branch, strict=True)])
            continue
        states, values = _consistent_reinit(dae, branch, t, x, z, pfull, reinit)
        reinits.append([(i, 1.0, n_reinit + j) for j, i in enumerate(states)])
        extra.append(values)
        n_reinit += len(states)
    reinit = ca.vertcat(*extra)
    step = ca.Function("evstep", args, [g, dgdt, cond, assign, reinit, pre, dv], names,
                       ["g", "dgdt", "cond", "assign", "reinit", "pre", "dv"])
    tables = [TableData(tb.c0, tb.c1, tuple(float(v) for v in np.asarray(tb.times).ravel()),
                        tuple(float(v) for v in np.asarray(tb.values).ravel()),
                        tb.interpolation == "hold", tb.extrapolation,
                        getattr(tb, "source", None),
                        f"tables/{k}_{Path(tb.source[0]).name}"
                        if getattr(tb, "source", None) else "")
              for k, tb in enumerate(hyb.tables)]
    for tb in tables:
        if tb.extrapolation not in EXTRAPOLATIONS or not tb.times:
            raise FmuSpecError(f"time table with extrapolation {tb.extrapolation!r} and "
                               f"{len(tb.times)} points cannot be exported")
    return HybridSpec(
        d_names=[q.name for q in dae.discretes],
        d_start=[float(q.decl.start) for q in dae.discretes],
        relations=[r.text for r in hyb.relations],
        rel_slot=[int(s) - nb for s in fn.rel_slot],
        rel_strict=[bool(s) for s in fn.strict],
        state_rel=state_rel, time_rel=time_rel,
        whens=[list(ids) for ids in fn.branch_of],
        assigns=[[(pidx - nb, pos) for pidx, pos in branch] for branch in fn.assign_of],
        reinits=reinits,
        pre=[(int(s) - nb, bool(disc), name) for s, disc, (_, name)
             in zip(fn.pre_slot, fn.pre_discrete, hyb.pre, strict=True)],
        sample_slots=[s.slot for s in hyb.samples],
        tables=tables, initial_slot=hyb.initial, terminal_slot=hyb.terminal,
        discretes=dvars, step=step, indicators=indicators, samples=samples)


# ------------------------------------------------------------------------------ C sources

def _c_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", " ") + '"'


def _ints(name: str, values: list[int], size: str) -> str:
    body = ", ".join(str(int(v)) for v in values) if values else "0"
    return f"const int {name}[{size}] = {{{body}}};\n"


def _doubles(name: str, values: list[float], size: str) -> str:
    body = ", ".join(repr(float(v)) for v in values) if values else "0.0"
    return f"const double {name}[{size}] = {{{body}}};\n"


def _strings(name: str, values: list[str], size: str) -> str:
    body = ", ".join(_c_string(v) for v in values) if values else '""'
    return f"const char *const {name}[{size}] = {{{body}}};\n"


def header_lines(h: HybridSpec, prefix: str, n_indicator_vars: int) -> list[str]:
    """``#define`` lines for ``bgm_model_data.h``."""
    n_cond = sum(len(w) for w in h.whens)
    return [
        "#define BGM_HYBRID 1",
        f"#define BGM_ND {h.nd}",
        f"#define BGM_NREL {len(h.relations)}",
        f"#define BGM_NZ {h.nz}",
        f"#define BGM_NTREL {len(h.time_rel)}",
        f"#define BGM_NWHEN {len(h.whens)}",
        f"#define BGM_NCOND {n_cond}",
        f"#define BGM_NASSIGN {sum(len(b) for b in h.assigns)}",
        f"#define BGM_NREINIT {sum(len(b) for b in h.reinits)}",
        f"#define BGM_NASSIGNV {h.step.numel_out(3)}",
        f"#define BGM_NREINITV {h.step.numel_out(4)}",
        f"#define BGM_NPRE {len(h.pre)}",
        f"#define BGM_NSAMP {len(h.sample_slots)}",
        f"#define BGM_NTAB {len(h.tables)}",
        f"#define BGM_NTABPTS {sum(len(tb.times) for tb in h.tables)}",
        f"#define BGM_NDV {len(h.discretes)}",
        f"#define BGM_NZV {n_indicator_vars}",
        f"#define BGM_INITIAL_SLOT {h.initial_slot}",
        f"#define BGM_TERMINAL_SLOT {h.terminal_slot}",
        f"#define BGM_PRE_TRACKS {int(h.track_pre)}",
        f"#define BGM_CASADI_EVSTEP {prefix}evstep",
        f"#define BGM_CASADI_EVIND {prefix}evind",
        f"#define BGM_CASADI_EVSAMP {prefix}evsamp",
    ]


def data_source(h: HybridSpec, model_name: str) -> str:
    """``bgm_hybrid_data.c``: the tables of the event runtime (see bgm_events.h)."""
    n_cond = sum(len(w) for w in h.whens)
    order = [b for w in h.whens for b in w]
    when_first = [0]
    for w in h.whens:
        when_first.append(when_first[-1] + len(w))
    assign_first, assign_slot, assign_pos = [0], [], []
    reinit_first, reinit_state, reinit_pos, reinit_sign = [0], [], [], []
    for b in range(n_cond):
        for slot, pos in h.assigns[b]:
            assign_slot.append(slot)
            assign_pos.append(pos)
        assign_first.append(len(assign_slot))
        for s, sign, pos in h.reinits[b]:
            reinit_state.append(s)
            reinit_sign.append(sign)
            reinit_pos.append(pos)
        reinit_first.append(len(reinit_state))
    tab_first = [0]
    for tb in h.tables:
        tab_first.append(tab_first[-1] + len(tb.times))
    out = [
        "/* Generated by bgmodelica.fmi: event data of " + model_name + " */",
        '#include "bgm_core.h"',
        "",
        _doubles("bgm_d_start", h.d_start, "BGM_NDA"),
        _strings("bgm_d_names", h.d_names, "BGM_NDA"),
        _ints("bgm_rel_slot", h.rel_slot, "BGM_NRELA"),
        _ints("bgm_rel_strict", [int(s) for s in h.rel_strict], "BGM_NRELA"),
        _strings("bgm_rel_text", h.relations, "BGM_NRELA"),
        _ints("bgm_state_rel", h.state_rel, "BGM_NZA"),
        _ints("bgm_time_rel", h.time_rel, "BGM_NTRELA"),
        _ints("bgm_when_first", when_first, "BGM_NWHENA + 1"),
        _ints("bgm_when_branch", order, "BGM_NCONDA"),
        _ints("bgm_assign_first", assign_first, "BGM_NCONDA + 1"),
        _ints("bgm_assign_slot", assign_slot, "BGM_NASSIGNA"),
        _ints("bgm_assign_pos", assign_pos, "BGM_NASSIGNA"),
        _ints("bgm_reinit_first", reinit_first, "BGM_NCONDA + 1"),
        _ints("bgm_reinit_state", reinit_state, "BGM_NREINITA"),
        _ints("bgm_reinit_pos", reinit_pos, "BGM_NREINITA"),
        _doubles("bgm_reinit_sign", reinit_sign, "BGM_NREINITA"),
        _ints("bgm_pre_slot", [s for s, _, _ in h.pre], "BGM_NPREA"),
        _ints("bgm_pre_discrete", [int(dsc) for _, dsc, _ in h.pre], "BGM_NPREA"),
        _strings("bgm_pre_names", [f"pre({n})" for _, _, n in h.pre], "BGM_NPREA"),
        _ints("bgm_sample_slot", h.sample_slots, "BGM_NSAMPA"),
        _ints("bgm_tab_c0", [tb.c0 for tb in h.tables], "BGM_NTABA"),
        _ints("bgm_tab_c1", [tb.c1 for tb in h.tables], "BGM_NTABA"),
        _ints("bgm_tab_first", tab_first, "BGM_NTABA + 1"),
        _ints("bgm_tab_hold", [int(tb.hold) for tb in h.tables], "BGM_NTABA"),
        _ints("bgm_tab_extrap", [EXTRAPOLATIONS[tb.extrapolation] for tb in h.tables],
              "BGM_NTABA"),
        _doubles("bgm_tab_times", [v for tb in h.tables for v in tb.times], "BGM_NTABPTSA"),
        _doubles("bgm_tab_values", [v for tb in h.tables for v in tb.values], "BGM_NTABPTSA"),
        _strings("bgm_tab_file", [tb.resource for tb in h.tables], "BGM_NTABA"),
        _strings("bgm_tab_column", [tb.source[1] if tb.source else "" for tb in h.tables],
                 "BGM_NTABA"),
        _ints("bgm_dv_type", [DV_TYPES.index(v.type) for v in h.discretes], "BGM_NDVA"),
        _ints("bgm_dv_slot", [v.slot for v in h.discretes], "BGM_NDVA"),
    ]
    return "\n".join(out)
