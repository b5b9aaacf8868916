"""What a model declares, for people: ``bgmodelica info MODEL`` and the notebook views.

:func:`model_info` collects the parameters (value, unit, description; bound ones with their
expression), the top-level inputs and outputs, and -- after compilation -- the states with
their start values, the equation count and the structural index. :func:`format_info` prints
it like ``fmpy info``. :func:`library_index` lists the component library for
``bgmodelica list [DOMAIN]``.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from typing import Any

import casadi as ca


def first_paragraph(doc: str | None) -> str:
    """The first paragraph of a docstring, on one line."""
    if not doc:
        return ""
    text = inspect.cleandoc(doc).split("\n\n")[0]
    return " ".join(text.split())


def _expr_text(expr: Any, names: dict[int, str]) -> str:
    sx = ca.SX(expr)
    syms = [s for s in ca.symvar(sx) if s.element_hash() in names]
    if syms:
        sx = ca.substitute(sx, ca.vertcat(*syms),
                           ca.vertcat(*[ca.SX.sym(names[s.element_hash()]) for s in syms]))
    return str(sx)


def _value(v: Any) -> Any:
    """A number, or None for an expression (a bound parameter)."""
    if isinstance(v, ca.SX) and not v.is_constant():
        return None                      # float() of a symbolic SX is nan, not an error
    try:
        return float(v)
    except (TypeError, ValueError, RuntimeError):
        return None


def model_info(model: Any, *, compile_model: bool = True) -> dict[str, Any]:
    """Parameters, inputs, outputs (and with ``compile_model`` the states and structure) of
    a component or a compiled model, as plain data (JSON-ready)."""
    from .compiler import CompiledModel, compile
    from .core.flatten import flatten

    compiled = model if isinstance(model, CompiledModel) else None
    source = compiled.source if compiled is not None else model
    if compiled is None and compile_model:
        compiled = compile(model)
    flat = compiled.reduced.model if compiled is not None else flatten(model)
    names = flat.names()
    values: dict[str, float] = {}
    if compiled is not None:
        values = compiled.dae.parameter_values(compiled.dae.p_default)
    cls = type(source) if source is not None else None
    info: dict[str, Any] = {
        "model": compiled.name if compiled is not None else flat.name,
        "class": f"{cls.__module__}.{cls.__qualname__}" if cls is not None else "",
        "description": first_paragraph(cls.__doc__) if cls is not None else "",
    }
    params = []
    for q in flat.parameters:
        raw = q.decl.value
        bound = None if _value(raw) is not None else _expr_text(raw, names)
        params.append({"name": q.name, "value": values.get(q.name, _value(raw)),
                       "unit": q.decl.unit, "description": q.decl.description,
                       "bound": bound, "min": q.decl.min, "max": q.decl.max})
    info["parameters"] = params
    info["inputs"] = [{"name": u.name, "unit": u.decl.unit, "description": u.decl.description,
                       "start": _value(getattr(u.decl, "start", None))} for u in flat.inputs]
    # outputs may be aliases of other variables after compilation: read them before
    raw = flatten(source) if compiled is not None and source is not None else flat
    info["outputs"] = [{"name": v.name, "unit": v.decl.unit,
                        "description": v.decl.description}
                       for v in raw.variables
                       if v.decl.kind == "output" and v.component == "" and v.der_of < 0]
    if compiled is None:
        info["equations"] = len(flat.equations)
        info["unknowns"] = len(flat.unknowns)
        info["balanced"] = info["equations"] == info["unknowns"]
        return info
    decls = {v.name: v.decl for v in flat.variables}
    dae = compiled.dae
    fixed = {dae.names[k] for k, _ in dae.fixed}
    info["states"] = [{"name": n, "unit": decls[n].unit if n in decls else "",
                       "start": float(x0), "fixed": n in fixed,
                       "description": decls[n].description if n in decls else ""}
                      for n, x0 in zip(dae.state_names, dae.x_start, strict=False)]
    info["equations"] = compiled.balance.n_equations
    info["unknowns"] = compiled.balance.n_unknowns
    info["balanced"] = compiled.balance.balanced
    info["structural_index"] = compiled.reduced.index
    info["algebraic_variables"] = len(compiled.sorted.algebraic)
    info["events"] = dae.hybrid is not None
    return info


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _table(rows: list[list[str]], header: list[str], indent: str = "  ") -> list[str]:
    widths = [max(len(r[k]) for r in [header, *rows]) for k in range(len(header))]
    out = [indent + "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)).rstrip()]
    for r in rows:
        out.append(indent + "  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True))
                   .rstrip())
    return out


def format_info(info: dict[str, Any]) -> str:
    """The text of ``bgmodelica info``."""
    lines = ["", "Model Info", ""]
    facts = [("Model", info["model"]), ("Class", info["class"]),
             ("Description", info["description"] or "-"),
             ("Equations", f"{info['equations']} for {info['unknowns']} unknowns ("
              + ("balanced" if info["balanced"] else "UNBALANCED") + ")")]
    if "states" in info:
        facts += [("States", str(len(info["states"]))),
                  ("Algebraic", str(info["algebraic_variables"])),
                  ("Structural index", str(info["structural_index"])),
                  ("Events", "yes" if info["events"] else "no")]
    facts += [("Parameters", str(len(info["parameters"]))),
              ("Inputs", str(len(info["inputs"]))), ("Outputs", str(len(info["outputs"])))]
    width = max(len(k) for k, _ in facts) + 2
    lines += [f"  {k.ljust(width)}{v}" for k, v in facts]
    sections = [
        ("Parameters", info["parameters"], ["Name", "Value", "Unit", "Description"],
         lambda p: [p["name"], _fmt(p["value"]) + (f" (= {p['bound']})" if p["bound"] else ""),
                    p["unit"], p["description"]]),
        ("Inputs", info["inputs"], ["Name", "Start", "Unit", "Description"],
         lambda p: [p["name"], _fmt(p["start"]), p["unit"], p["description"]]),
        ("Outputs", info["outputs"], ["Name", "Unit", "Description"],
         lambda p: [p["name"], p["unit"], p["description"]]),
        ("States", info.get("states", []), ["Name", "Start", "Unit", "Description"],
         lambda p: [p["name"], _fmt(p["start"]) + (" (fixed)" if p["fixed"] else ""),
                    p["unit"], p["description"]]),
    ]
    for title, items, header, row in sections:
        if not items:
            continue
        lines += ["", f"{title} ({len(items)})", ""]
        lines += _table([row(p) for p in items], header)
    return "\n".join(lines) + "\n"


# -- the library ------------------------------------------------------------------------------


def _components(module: Any) -> list[tuple[str, str]]:
    from .core.component import Component, Connector

    public = getattr(module, "__all__", None)
    out = []
    for name, obj in vars(module).items():
        if name.startswith("_") or (public is not None and name not in public):
            continue
        if inspect.isclass(obj) and issubclass(obj, (Component, Connector)) and \
                obj.__module__ == module.__name__:
            out.append((name, first_paragraph(obj.__doc__)))
    return sorted(out, key=lambda item: item[0].lower())


def library_domains(package: str = "library") -> dict[str, Any]:
    """Module name (relative to ``package``, dotted) -> module, for every module of the
    component library that defines components (the main jobs excluded)."""
    root = importlib.import_module(package)
    out: dict[str, Any] = {}
    for mod in pkgutil.walk_packages(root.__path__, f"{package}."):
        if mod.name.rsplit(".", 1)[-1].startswith("_") or mod.name.endswith("main_job"):
            continue
        module = importlib.import_module(mod.name)
        if _components(module):
            out[mod.name[len(package) + 1:]] = module
    return out


def library_index(domain: str | None = None, package: str = "library") -> dict[str, Any]:
    """``{"domains": [{name, doc, components}]}`` or, for ``domain`` (a module such as
    ``thermal`` or ``examples.hybrid``, or a package such as ``examples``), its components
    ``{"domain", "doc", "components": [{name, ref, doc}]}``."""
    domains = library_domains(package)
    if domain is None:
        return {"domains": [{"name": n, "doc": first_paragraph(m.__doc__),
                             "components": len(_components(m))}
                            for n, m in sorted(domains.items())]}
    chosen = {n: m for n, m in domains.items() if n == domain or n.startswith(domain + ".")}
    if not chosen:
        from .errors import ModelLoadError

        raise ModelLoadError(f"no library domain {domain!r}; domains: "
                             + ", ".join(sorted(domains)))
    comps = [{"name": c, "ref": f"{m.__name__}:{c}", "doc": doc}
             for n, m in sorted(chosen.items()) for c, doc in _components(m)]
    doc = first_paragraph(importlib.import_module(f"{package}.{domain}").__doc__)
    return {"domain": domain, "doc": doc, "components": comps}


def format_index(index: dict[str, Any], width: int = 100) -> str:
    """The text of ``bgmodelica list``."""

    def cut(text: str, room: int) -> str:
        return text if len(text) <= room else text[: max(room - 3, 0)] + "..."

    if "domains" in index:
        rows = index["domains"]
        w = max(len(r["name"]) for r in rows) + 2
        lines = ["Library domains (bgmodelica list DOMAIN for the components):", ""]
        lines += [f"  {r['name'].ljust(w)}{str(r['components']).rjust(3)}  "
                  + cut(r["doc"], width - w - 9) for r in rows]
        return "\n".join(lines) + "\n"
    rows = index["components"]
    w = max(len(r["name"]) for r in rows) + 2
    lines = [f"{index['domain']}: {index['doc']}"]
    module = None
    for r in rows:
        mod = r["ref"].split(":")[0]
        if mod != module:
            module = mod
            lines += ["", f"{mod}:"]
        lines.append(f"  {r['name'].ljust(w)}" + cut(r["doc"], max(width - w - 2, 30)))
    return "\n".join(lines) + "\n"
