"""Integrator settings chosen from the model: the linear solver of the Newton iterations and
just-in-time compilation of the model functions.

Linear solver (CasADi's interfaces, all direct): ``"qr"`` (CasADi's sparse QR),
``"csparse"`` (sparse LU), ``"lapacklu"`` and ``"lapackqr"`` (dense LAPACK). Measured through
``simulate``
(IDAS, 10 s, best of 3; ``benchmarks/linear_solvers.py``), seconds:

=================  =======  ========  ========
model              qr       csparse   lapacklu
=================  =======  ========  ========
RC ladder n=10     0.0152   0.0146    0.0161
RC ladder n=100    0.0458   0.0459    0.0424
RC ladder n=1000   0.286    0.339     2.32
RC ladder n=10000  3.24     3.56      -
robot (10 states)  0.0335   0.0509    0.0464
=================  =======  ========  ========

Dense LU is level with the sparse solvers up to about a hundred unknowns, slower on the
robot and an order of magnitude slower at a thousand; sparse QR is level with or ahead of
sparse LU at every size. So ``"auto"`` takes sparse QR at every size (the measured table is
the reason; rerun the benchmark on another machine before changing it).

JIT: ``jit=True`` has CasADi generate C for the residual and Jacobian functions the
integrator evaluates and compile them with the system C compiler (``cc``) without
optimization (``-O0``: the generated code is straight-line, and optimizing it costs far more
compile time than it saves: ``-O1`` takes 23 s instead of 5 s on the 1000-section ladder
for a 1.4x faster run); ``jit="O1"`` or ``"O2"`` asks for more. It pays off for long or
repeated runs; ``benchmarks/jit_crossover.py`` measures the crossover (on the shared
development machine the robot gained 1.25-1.66x per 10-s run in three of four runs, after
0.1-0.3 s of compilation, i.e. from about 10-30 runs; the fourth, noisy run showed no gain).
"""

from __future__ import annotations

import shutil
from typing import Any

from .errors import OptionError

LINEAR_SOLVERS = ("auto", "qr", "csparse", "lapacklu", "lapackqr")


def linear_solver_for(n_unknowns: int, requested: str = "auto") -> str:
    """The CasADi linear solver for a model with ``n_unknowns`` integrated unknowns (sparse
    QR for ``"auto"``, see the module docstring)."""
    if requested not in LINEAR_SOLVERS:
        raise OptionError(f"linear_solver must be one of {', '.join(LINEAR_SOLVERS)}, "
                          f"got {requested!r}")
    if requested != "auto":
        return requested
    del n_unknowns            # measured: no size where another solver wins
    return "qr"


def compiler() -> str | None:
    """The system C compiler used for JIT (``cc``, ``gcc`` or ``clang``), or None."""
    for name in ("cc", "gcc", "clang"):
        if shutil.which(name):
            return name
    return None


JIT_LEVELS = ("O0", "O1", "O2", "O3")


def jit_options(jit: bool | str) -> dict[str, Any]:
    """CasADi options that JIT-compile an integrator's functions (empty when ``jit`` is
    False; True is ``"O0"``); :class:`OptionError` when no C compiler is installed."""
    if not (isinstance(jit, bool) or jit in JIT_LEVELS):
        raise OptionError(f"jit must be True, False or one of {', '.join(JIT_LEVELS)}, "
                          f"got {jit!r}")
    if jit is False:
        return {}
    level = "O0" if jit is True else jit
    cc = compiler()
    if cc is None:
        raise OptionError("jit=True needs a C compiler (cc, gcc or clang) on the PATH; "
                          "none was found: install one or run with jit=False")
    return {"jit": True, "compiler": "shell",
            "jit_options": {"compiler": cc, "flags": [f"-{level}"], "verbose": False}}


def integrator_settings(n_unknowns: int, linear_solver: str = "auto",
                        jit: bool | str = False) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(options for ca.integrator, what was chosen for result.meta)``."""
    chosen = linear_solver_for(n_unknowns, linear_solver)
    opts: dict[str, Any] = {"linear_solver": chosen, **jit_options(jit)}
    meta = {"linear_solver": chosen, "linear_solver_choice": "auto" if linear_solver == "auto"
            else "given", "jit": ("O0" if jit is True else jit) if jit else False}
    return opts, meta
