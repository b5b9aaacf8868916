"""Rich displays for Jupyter: evaluating a model, a compiled model or a result shows it.

- a component (``_repr_html_``): its class and description, the balance (equations vs
  unknowns), the parameters with values, units and descriptions, the top-level inputs and
  outputs, and for a bond graph its drawing with causal strokes;
- a compiled model: the structure of ``bgmodelica check`` (states, index, loops, events) and
  the parameter table;
- a result: a plot of the states (one subplot per unit, events marked) and a table of the
  recorded variables (unit, initial, final, min, max).

Every view is plain HTML (no JavaScript), so it also renders on GitHub and in exported
notebooks. Each view catches its own errors: a broken model shows the error message, never a
traceback in place of the output.
"""

from __future__ import annotations

import base64
import html
import io
from typing import Any

import numpy as np

#: rows shown in a table before "... N more"
MAX_ROWS = 40

_STYLE = ("<style>.bgm table{border-collapse:collapse;font-size:12px;margin:4px 0}"
          ".bgm th,.bgm td{padding:2px 8px;text-align:left;border-bottom:1px solid #ddd}"
          ".bgm td.num{text-align:right;font-family:monospace}"
          ".bgm .muted{color:#666}</style>")


def _esc(x: Any) -> str:
    return html.escape(str(x))


def _num(v: Any) -> str:
    if v is None:
        return ""
    try:
        return f"{float(v):.6g}"
    except (TypeError, ValueError):
        return _esc(v)


def html_table(header: list[str], rows: list[list[str]], numeric: set[int] = frozenset(),
               max_rows: int = MAX_ROWS) -> str:
    """An HTML table of already escaped cells; columns in ``numeric`` right-aligned."""
    head = "".join(f"<th>{h}</th>" for h in header)
    body = []
    for r in rows[:max_rows]:
        body.append("<tr>" + "".join(
            f"<td class='num'>{c}</td>" if k in numeric else f"<td>{c}</td>"
            for k, c in enumerate(r)) + "</tr>")
    if len(rows) > max_rows:
        body.append(f"<tr><td colspan='{len(header)}' class='muted'>... "
                    f"{len(rows) - max_rows} more</td></tr>")
    return f"<table><tr>{head}</tr>{''.join(body)}</table>"


def _wrap(title: str, body: str) -> str:
    return f"{_STYLE}<div class='bgm'><b>{title}</b>{body}</div>"


def _error(title: str, err: BaseException) -> str:
    return _wrap(_esc(title), f"<p class='muted'>cannot show it: {_esc(type(err).__name__)}: "
                              f"{_esc(err)}</p>")


def _parameter_table(info: dict[str, Any]) -> str:
    rows = [[_esc(p["name"]), _num(p["value"]) + (f" <span class='muted'>= "
                                                  f"{_esc(p['bound'])}</span>"
                                                  if p["bound"] else ""),
             _esc(p["unit"]), _esc(p["description"])] for p in info["parameters"]]
    if not rows:
        return ""
    return (f"<p>Parameters ({len(rows)})</p>"
            + html_table(["name", "value", "unit", "description"], rows, {1}))


def _interface(info: dict[str, Any]) -> str:
    parts = []
    for key in ("inputs", "outputs"):
        items = info.get(key) or []
        if items:
            parts.append(f"<p>{key.capitalize()} ({len(items)})</p>" + html_table(
                ["name", "unit", "description"],
                [[_esc(v["name"]), _esc(v["unit"]), _esc(v["description"])] for v in items]))
    states = info.get("states")
    if states:
        parts.append(f"<p>States ({len(states)})</p>" + html_table(
            ["name", "start", "unit", "description"],
            [[_esc(s["name"]), _num(s["start"]) + (" (fixed)" if s["fixed"] else ""),
              _esc(s["unit"]), _esc(s["description"])] for s in states], {1}))
    return "".join(parts)


def svg_of_figure(fig: Any) -> str:
    """A matplotlib figure as inline SVG text."""
    buf = io.StringIO()
    fig.savefig(buf, format="svg", bbox_inches="tight")
    text = buf.getvalue()
    return text[text.find("<svg"):]


def png_of_figure(fig: Any, dpi: int = 100) -> str:
    """A matplotlib figure as an ``<img>`` tag with an embedded PNG."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    data = base64.b64encode(buf.getvalue()).decode("ascii")
    return f"<img src='data:image/png;base64,{data}'/>"


def bond_graph_svg(model: Any) -> str:
    """The drawing of a bond graph (causal strokes) as SVG text, without touching the
    notebook's matplotlib backend."""
    import tempfile
    from pathlib import Path

    import matplotlib

    from .bondgraph import draw

    # draw() selects the Agg backend for files; in a notebook that would switch the inline
    # backend off, so the selection is skipped here (draw closes its figure after saving)
    use = matplotlib.use
    matplotlib.use = lambda *args, **kwargs: None
    try:
        with tempfile.TemporaryDirectory(prefix="bgm_draw_") as tmp:
            path = draw(model, Path(tmp) / "graph.svg")
            text = path.read_text()
    finally:
        matplotlib.use = use
    return text[text.find("<svg"):]


def component_html(model: Any) -> str:
    """The notebook view of a component (see the module docstring)."""
    from .info import model_info

    name = type(model).__name__
    try:
        info = model_info(model, compile_model=False)
    except Exception as err:  # noqa: BLE001 -- a display never raises
        return _error(f"{name} (component)", err)
    balance = (f"{info['equations']} equations, {info['unknowns']} unknowns: "
               + ("balanced" if info["balanced"] else "<b>not balanced</b>"))
    body = (f"<p>{_esc(info['description'])}</p>" if info["description"] else "") \
        + f"<p class='muted'>{_esc(info['class'])} &middot; {balance}</p>" \
        + _parameter_table(info) + _interface(info)
    try:
        from .bondgraph import BondGraph

        if isinstance(model, BondGraph):
            body += "<p>Bond graph (integral causality)</p>" + bond_graph_svg(model)
    except Exception as err:  # noqa: BLE001
        body += f"<p class='muted'>no drawing: {_esc(err)}</p>"
    return _wrap(f"{_esc(info['model'])} ({_esc(name)})", body)


def compiled_html(compiled: Any) -> str:
    """The notebook view of a compiled model."""
    from .info import model_info

    try:
        s = compiled.summary()
        info = model_info(compiled)
    except Exception as err:  # noqa: BLE001
        return _error(f"{compiled.name} (compiled)", err)
    facts = [("equations", f"{s['equations']} for {s['unknowns']} unknowns ("
              + ("balanced" if s["balanced"] else "UNBALANCED") + ")"),
             ("structural index", s["structural_index"]),
             ("states", ", ".join(s["states"]) or "-"),
             ("dummy derivatives", ", ".join(s["dummy_derivatives"]) or "-"),
             ("algebraic variables", len(s["algebraic_variables"])),
             ("algebraic loops", ", ".join(f"size {lp['size']} ({lp['kind']})"
                                           for lp in s["algebraic_loops"]) or "-"),
             ("events", "yes" if s.get("events") else "no"),
             ("compile time", f"{compiled.compile_time:.3f} s")]
    body = html_table(["", ""], [[_esc(k), _esc(v)] for k, v in facts])
    body += _parameter_table(info) + _interface({**info, "states": None})
    return _wrap(f"{_esc(compiled.name)} (compiled model)", body)


def result_html(result: Any, names: list[str] | None = None) -> str:
    """The notebook view of a result: a plot and a table of the variables."""
    from .plotting import plot_result

    n = len(result.time)
    try:
        head = (f"<p class='muted'>{n} points, t = {float(result.time[0]):g} .. "
                f"{float(result.time[-1]):g} s" if n else "<p class='muted'>no points")
        ev = result.meta.get("event_times") or []
        if ev:
            head += f", {len(ev)} events (two rows at each: left and right limit)"
        if "run_seconds" in result.meta:
            head += f", run {float(result.meta['run_seconds']):.3f} s"
        head += "</p>"
        shown = names or list(result.meta.get("states", []))[:6] or list(result.names)[:6]
        plot = ""
        if n and shown:
            fig = plot_result(result, shown, detached=True, figsize=(6.4, 1.0 + 1.5 * len(
                {result.unit(x) for x in shown})))
            plot = png_of_figure(fig)
        rows = []
        for name in result.all_names():
            v = np.asarray(result[name], dtype=float)
            rows.append([_esc(name), _esc(result.unit(name)), _num(v[0]) if n else "",
                         _num(v[-1]) if n else "", _num(np.nanmin(v)) if n else "",
                         _num(np.nanmax(v)) if n else ""])
        table = html_table(["variable", "unit", "initial", "final", "min", "max"], rows,
                           {2, 3, 4, 5})
    except Exception as err:  # noqa: BLE001
        return _error("Result", err)
    return _wrap(f"Result ({len(result.all_names())} variables)", head + plot + table)
