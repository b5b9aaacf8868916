"""Export every model of the library's example, robot and bond-graph modules as an FMI 2.0
Model Exchange FMU and check it with fmpy's ``validate_fmu``: prints one line per model
(export seconds, problems) and the count; exits non-zero when one fails. A class that does
not compile on its own as a balanced model (an adapter meant to be connected) is a part and
is listed as skipped.

    PYTHONPATH=. .venv/bin/python benchmarks/fmu_library_sweep.py [OUT_DIR]
"""

from __future__ import annotations

import importlib
import inspect
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fmpy.validation import validate_fmu  # noqa: E402

import bgmodelica as bg  # noqa: E402
from bgmodelica import Component  # noqa: E402
from bgmodelica.errors import UnbalancedModelError  # noqa: E402
from bgmodelica.fmi.from_model import export_model  # noqa: E402

MODULES = ("library.examples.circuits", "library.examples.constrained",
           "library.examples.control", "library.examples.hybrid",
           "library.examples.mechanics", "library.examples.motors",
           "library.examples.reference", "library.examples.thermal",
           "library.examples.splits", "library.robots.robot", "library.robots.digital",
           "library.bondgraph.adapters", "library.bondgraph.paper",
           "library.bondgraph.switched")


def models() -> list[tuple[str, type]]:
    """``(module:Name, class)`` of every top-level model that builds without arguments."""
    out = []
    for name in MODULES:
        mod = importlib.import_module(name)
        for attr in getattr(mod, "__all__", []):
            obj = getattr(mod, attr)
            if not (inspect.isclass(obj) and issubclass(obj, Component)):
                continue
            try:
                obj()
            except TypeError:
                continue            # needs arguments: a part, not a model
            out.append((f"{name}:{attr}", obj))
    return out


def main() -> int:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
    failed = 0
    found = models()
    parts = 0
    for label, cls in found:
        t0 = time.perf_counter()
        try:
            compiled = bg.compile(cls())
        except UnbalancedModelError as err:     # a part (an adapter): nothing to simulate
            parts += 1
            print(f"part   0.0 s  {label}  {str(err).splitlines()[0][:120]}", flush=True)
            continue
        try:
            path = export_model(compiled, out / label.replace(":", "_"), fmi_version=2,
                                fmu_type="me")
            problems = validate_fmu(str(path))
        except Exception as err:  # noqa: BLE001 -- reported per model
            problems = [f"{type(err).__name__}: {str(err).splitlines()[0][:160]}"]
        dt = time.perf_counter() - t0
        failed += bool(problems)
        print(f"{'FAIL' if problems else 'ok  '} {dt:6.1f} s  {label}"
              + (f"  {problems[0]}" if problems else ""), flush=True)
    n = len(found) - parts
    print(f"{n - failed}/{n} models export and validate ({parts} parts skipped)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
