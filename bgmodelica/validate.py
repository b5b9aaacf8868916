"""Checks of user input before any work is done: simulation options, the output grid,
``--arg`` values, and the wrapping of exceptions raised by user code (parameter and start
values: :mod:`bgmodelica.value_checks`; output files, plot variables and ``--outputs``:
:mod:`bgmodelica.output_checks`).

Every check raises a :class:`~bgmodelica.errors.ModelError` subclass whose message names the
option, file, parameter or variable at fault; :func:`one_line` turns any message into the single
line the command line prints.
"""

from __future__ import annotations

import inspect
import json
import math
import os
import sysconfig
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .errors import (
    ConnectError,
    DeclarationError,
    EquationError,
    ModelError,
    OptionError,
    UserCodeError,
)

#: output grids with more points than this are refused whatever the memory
MAX_OUTPUT_POINTS = 50_000_000
#: CLI spelling of the options of :func:`bgmodelica.simulate`
_FLAGS = {"stop_time": "--stop-time", "interval": "--interval", "rtol": "--rtol",
          "atol": "--atol", "start_time": "start_time", "max_step": "max_step",
          "max_steps": "max_steps"}


# -- messages ----------------------------------------------------------------------------------

def one_line(message: str, limit: int = 2000) -> str:
    """``message`` on one line: list items (indented lines) are joined with ", " after their
    header, other lines with "; "."""
    out = ""
    in_list = False
    for raw in str(message).splitlines():
        line = raw.strip()
        if not line:
            continue
        item = raw[:1].isspace()
        if not out:
            out = line
        elif item and in_list:
            out += ", " + line
        else:
            sep = " " if out.endswith((":", ".")) else ("; " if not item else ": ")
            out += sep + line
            in_list = item
    if len(out) > limit:
        out = out[: limit - 3] + "..."
    return out


def _option(name: str) -> str:
    flag = _FLAGS.get(name, name)
    return f"{name} ({flag})" if flag != name else name


# -- simulation options --------------------------------------------------------------------------

def _real(name: str, value: Any, *, allow_none: bool = False) -> float | None:
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or value is None:
        raise OptionError(f"{_option(name)} must be a number, got {value!r}")
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise OptionError(f"{_option(name)} must be a number, got {value!r}") from None
    if not math.isfinite(out):
        raise OptionError(f"{_option(name)} is {value!r}: it must be a finite number")
    return out


def check_run_options(*, start_time: Any = 0.0, stop_time: Any = 1.0, interval: Any = None,
                      rtol: Any = 1e-6, atol: Any = None, max_step: Any = None,
                      max_steps: Any = 100000, solver: Any = "auto") -> dict[str, Any]:
    """Validate the options of :func:`bgmodelica.simulate`; returns them as floats/ints.

    Raises :class:`OptionError` naming the option: NaN, Inf, non-numbers, a stop time not
    after the start time, a zero or negative interval, tolerances or step limits <= 0.
    """
    t0 = _real("start_time", start_time)
    t1 = _real("stop_time", stop_time)
    if t1 <= t0:
        raise OptionError(f"{_option('stop_time')} = {t1:g} must be after the start time "
                          f"{t0:g} s")
    if not math.isfinite(t1 - t0):
        raise OptionError(f"{_option('stop_time')} = {t1:g}: the simulated span overflows")
    h = _real("interval", interval, allow_none=True)
    if h is not None and h <= 0:
        raise OptionError(f"{_option('interval')} = {h:g} must be positive (the output step "
                          "in seconds)")
    r = _real("rtol", rtol)
    if not 0 < r < 1:
        raise OptionError(f"{_option('rtol')} = {r:g} must be in (0, 1)")
    a = _real("atol", atol, allow_none=True)
    if a is not None and a <= 0:
        raise OptionError(f"{_option('atol')} = {a:g} must be positive")
    ms = _real("max_step", max_step, allow_none=True)
    if ms is not None and ms <= 0:
        raise OptionError(f"max_step = {ms:g} must be positive")
    if isinstance(max_steps, float) and max_steps.is_integer():
        max_steps = int(max_steps)                # 1e6
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) \
            or max_steps < 1:
        raise OptionError(f"max_steps must be a positive integer, got {max_steps!r}")
    if solver not in ("auto", "idas", "cvodes"):
        raise OptionError(f"solver must be 'auto', 'idas' or 'cvodes', got {solver!r}")
    return {"start_time": t0, "stop_time": t1, "interval": h, "rtol": r, "atol": a,
            "max_step": ms, "max_steps": int(max_steps)}


def _memory_bytes() -> int:
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def _size(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} PiB"


def output_grid(start_time: float, stop_time: float, interval: float | None,
                n_columns: int = 1, default_intervals: int = 500) -> np.ndarray:
    """The output times: ``start, start + h, start + 2h, ...`` below ``stop`` and then
    ``stop`` itself (``h`` = ``interval``; 500 equal intervals when None).

    A point within 1e-9 h of ``stop`` is ``stop``. Grids that would not fit in memory (with
    ``n_columns`` recorded values per point) are refused with their number of points.
    """
    span = stop_time - start_time
    if interval is None:
        return _increasing(np.linspace(start_time, stop_time, default_intervals + 1), None)
    q = span / interval
    n_full = math.floor(q + 1e-9) if math.isfinite(q) else math.inf
    n_points = n_full + 1 + (0 if n_full != math.inf and abs(q - n_full) <= 1e-9 else 1)
    need = n_points * (max(1, n_columns) + 1) * 8.0 * 2      # values + work arrays
    if n_points > MAX_OUTPUT_POINTS or need > 0.5 * _memory_bytes():
        count = f"{n_points:.0f}" if math.isfinite(n_points) else "infinitely many"
        fewer = ", record fewer variables (outputs=[...], --outputs)" if n_columns > 1 else ""
        raise OptionError(
            f"the output grid from {start_time:g} to {stop_time:g} s every {interval:g} s has "
            f"{count} points ({n_columns} values each, about {_size(need)}): too many to "
            f"hold (limit {MAX_OUTPUT_POINTS} points, {_size(0.5 * _memory_bytes())}); "
            f"raise the interval (--interval){fewer} or shorten the run")
    grid = start_time + np.arange(n_full + 1, dtype=float) * interval
    if stop_time - grid[-1] > 1e-9 * interval or len(grid) == 1:
        grid = np.append(grid, stop_time)
    else:
        grid[-1] = stop_time
    return _increasing(grid, interval)


def _increasing(grid: np.ndarray, interval: float | None) -> np.ndarray:
    """``grid`` if its times are distinct floating-point numbers, else :class:`OptionError`."""
    if len(grid) > 1 and np.all(np.diff(grid) > 0):
        return grid
    step = f"every {interval:g} s" if interval is not None else f"in {len(grid) - 1} steps"
    raise OptionError(f"the output grid from {grid[0]:g} to {grid[-1]:g} s {step} has points "
                      "that floating-point numbers cannot tell apart: lengthen the run "
                      "(--stop-time) or raise the interval (--interval)")


# -- command-line model arguments ----------------------------------------------------------------

def parse_model_args(items: Sequence[str]) -> dict[str, Any]:
    """``--arg NAME=VALUE`` items as keyword arguments (JSON values, else strings)."""
    out: dict[str, Any] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise OptionError(f"--arg expects NAME=VALUE, got {item!r}")
        if not (name.isidentifier() or all(p.isidentifier() for p in name.split("."))):
            raise OptionError(f"--arg {item!r}: {name!r} is not an argument name")
        if name in out:
            raise OptionError(f"--arg {name} is given twice")
        try:
            val = json.loads(value)
        except json.JSONDecodeError:
            val = value
        if isinstance(val, float) and not math.isfinite(val):
            raise OptionError(f"--arg {name}={value}: the value must be a finite number")
        out[name] = val
    return out


_TYPES = {"int": int, "float": float, "bool": bool, "str": str}


def check_model_args(obj: Any, kwargs: dict[str, Any], label: str) -> dict[str, Any]:
    """Check ``kwargs`` against the signature of the model constructor ``obj`` (names and
    the types of the defaults or annotations); returns them converted (3.0 -> 3 for an int)."""
    if not kwargs:
        return kwargs
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return kwargs
    params = sig.parameters
    var_kw = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
    named = {n: p for n, p in params.items()
             if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD,
                           inspect.Parameter.KEYWORD_ONLY)}
    out = dict(kwargs)
    for name, value in kwargs.items():
        p = named.get(name)
        if p is None:
            if var_kw:
                continue
            raise OptionError(f"--arg {name}: {label} takes no argument {name!r}; it takes: "
                              f"{', '.join(named) or 'none'}")
        want = _expected_type(p)
        if want is None:
            continue
        if want is int and isinstance(value, float) and value.is_integer():
            value = int(value)
        if want is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, want) or (want is int and isinstance(value, bool)):
            default = "" if p.default is inspect.Parameter.empty else f", default {p.default!r}"
            shown = value if isinstance(value, str) else json.dumps(value)
            raise OptionError(f"--arg {name}={shown}: {label} expects {_article(want)} for "
                              f"{name}{default}")
        out[name] = value
    return out


def _article(t: type) -> str:
    return {int: "an integer", float: "a number", bool: "true or false",
            str: "a string"}[t]


def _expected_type(p: inspect.Parameter) -> type | None:
    ann = p.annotation
    if isinstance(ann, str):
        ann = _TYPES.get(ann.strip())
    if ann in (int, float, bool, str):
        return ann
    d = p.default
    if d is not inspect.Parameter.empty and d is not None and type(d) in (int, float, bool):
        return type(d)
    return None


# -- exceptions raised by user code --------------------------------------------------------------

_PKG = str(Path(__file__).resolve().parent)
_SYSTEM = {str(Path(p).resolve()) for key in ("stdlib", "platstdlib", "purelib", "platlib")
           if (p := sysconfig.get_paths().get(key))}


def _is_user_file(filename: str) -> bool:
    if filename.startswith("<"):
        return False
    try:
        f = str(Path(filename).resolve())
    except OSError:
        return False
    if f.startswith(_PKG + os.sep):
        return False
    return not any(f.startswith(s + os.sep) for s in _SYSTEM)


def user_location(exc: BaseException) -> str:
    """``file:line (in function)`` of the innermost frame of ``exc``'s traceback in user code
    (not bgmodelica, not the standard library or installed packages); "" if none."""
    frames = traceback.extract_tb(exc.__traceback__)
    if isinstance(exc, SyntaxError) and exc.filename:
        return f"{_short(exc.filename)}:{exc.lineno}"
    for fr in reversed(frames):
        if _is_user_file(fr.filename):
            return f"{_short(fr.filename)}:{fr.lineno} (in {fr.name})"
    return ""


def _short(filename: str) -> str:
    try:
        rel = os.path.relpath(filename)
    except ValueError:
        return filename
    return rel if not rel.startswith("..") else filename


def user_error(exc: BaseException, what: str, path: str = "") -> UserCodeError:
    """A :class:`UserCodeError` for ``exc`` raised by user code while doing ``what``."""
    loc = user_location(exc)
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    msg = f"{what} raised {type(exc).__name__}" + (f": {text}" if text else "") \
        + (f" at {loc}" if loc else "")
    err = UserCodeError(msg, path, loc)
    err.__cause__ = exc
    return err


def nested_user_error(err: UserCodeError, key: str, cls: str) -> UserCodeError:
    """``err`` raised while building subcomponent ``key`` (class ``cls``): the path grows."""
    path = f"{key}.{err.path}" if err.path else key
    detail = getattr(err, "detail", None) or str(err)
    new = UserCodeError(f"building subcomponent {path}: {detail}", path, err.location)
    new.detail = detail
    new.__cause__ = err.__cause__
    return new


def check_export_args(args: Any) -> None:
    """``bgmodelica export`` options: a finite positive stop time and step, and an output
    directory that is not a file."""
    t1 = _real("--stop-time", args.stop_time, allow_none=True)
    if t1 is not None and t1 <= 0:
        raise OptionError(f"--stop-time = {t1:g} must be positive")
    step = _real("--step", args.step, allow_none=True)
    if step is not None and step <= 0:
        raise OptionError(f"--step = {step:g} must be positive")
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise OptionError(f"-o {out}: is a file; FMUs are written into a directory")


# -- model building --------------------------------------------------------------------------

def guarded_equations(elem: Any, where: str, path: str, blocks: bool = False) -> list[Any]:
    """``list(elem.all_equations(blocks))``, with an exception raised by the user's
    ``equations()`` turned into a :class:`UserCodeError` naming the component ``where`` and
    the user's file and line, and model errors raised there prefixed with ``where``."""
    try:
        return list(elem.all_equations(blocks))
    except UserCodeError:
        raise
    except (ConnectError, DeclarationError, EquationError) as err:
        if str(err).startswith(where):
            raise
        try:
            again = type(err)(f"{where}: {err}")
        except TypeError:
            raise err from None
        raise again from None
    except ModelError:
        raise
    except Exception as err:  # noqa: BLE001 -- user code: say where, no traceback
        raise user_error(err, f"{where}: equations()", path) from err


def check_binding(name: str, value: Any, leaves: list, full: dict[int, str]) -> None:
    """A parameter may be bound to an expression of parameters only: not of time, variables,
    inputs or discrete variables (they vary during a run). ``leaves``: the symbols of the
    expression; ``full``: id(symbol) -> dotted name."""
    from .core.variables import KIND_PARAMETER

    for leaf in leaves:
        decl = getattr(leaf, "decl", None)
        if decl is None:               # time
            raise DeclarationError(f"parameter {name} is bound to {value!r}, which depends "
                                   "on time: a parameter is constant during a run; declare "
                                   f"{name.rpartition('.')[2]} as a Variable with an "
                                   "equation instead")
        if decl.kind != KIND_PARAMETER:
            what = full.get(id(leaf), getattr(leaf, "name", "?"))
            raise DeclarationError(
                f"parameter {name} is bound to {value!r}, which depends on the {decl.kind} "
                f"{what}: a parameter is constant during a run; bind it to parameters only, "
                "or declare it as a Variable with an equation")


def check_binding_cycles(bindings: dict[str, list[str]]) -> None:
    """Refuse parameter bindings that depend on themselves (``a = b``, ``b = a``), naming the
    cycle. ``bindings``: parameter -> the parameters its binding uses."""
    state: dict[str, int] = {}                    # 1: on the current path, 2: done
    for root in bindings:
        if state.get(root):
            continue
        path: list[str] = []
        stack: list[tuple[str, int]] = [(root, 0)]
        while stack:
            node, k = stack.pop()
            if k == 0:
                state[node] = 1
                path.append(node)
            deps = bindings.get(node, [])
            if k < len(deps):
                stack.append((node, k + 1))
                nxt = deps[k]
                if state.get(nxt) == 1:
                    cycle = path[path.index(nxt):] + [nxt]
                    raise DeclarationError(
                        "parameter bindings form a cycle: " + " -> ".join(cycle) + " (each "
                        "is bound to an expression of the next); bind one of them to a value")
                if not state.get(nxt):
                    stack.append((nxt, 0))
            else:
                state[node] = 2
                path.pop()


def check_sx_binding(name: str, value: Any) -> None:
    """:func:`check_binding` for a binding given as a CasADi SX expression."""
    import casadi as ca

    from .core.variables import TIME, lookup

    for s in ca.symvar(value):
        if s.element_hash() == TIME.sx.element_hash():
            check_binding(name, value, [object()], {})
        sym = lookup(s)
        if sym is not None:
            check_binding(name, value, [sym], {id(sym): sym.name})
