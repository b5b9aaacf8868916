"""Parse every ``.mo`` file of the Modelica Standard Library: files parsed / failed, and the
time of a cold run (no disk cache: every file parsed) and of a warm one (every file loaded
from the disk cache of :mod:`bgmodelica.modelica.ast_cache`), each in a fresh process so the
in-process cache plays no part. Also the cold parse time of ``Modelica/Blocks/Sources.mo``.

The cache goes to a temporary folder (``$BGMODELICA_CACHE`` is set for the child runs).

    python benchmarks/msl_parse.py [--msl PATH]     # default $BGMODELICA_MSL or ../shared/msl
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, sys, time
from pathlib import Path
from bgmodelica.modelica.parser import parse_file
root = Path(sys.argv[1])
files = sorted(root.rglob("*.mo"))
failed = []
t = time.perf_counter()
for f in files:
    try:
        parse_file(f)
    except Exception as err:
        failed.append(f"{type(err).__name__}: {err}")
print(json.dumps({"files": len(files), "failed": failed, "seconds": time.perf_counter() - t}))
"""


def run(msl: Path, cache: str) -> dict:
    env = dict(os.environ, BGMODELICA_CACHE=cache, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", CHILD, str(msl)], env=env, cwd=ROOT,
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    default = os.environ.get("BGMODELICA_MSL") or str(ROOT.parent / "shared" / "msl")
    ap.add_argument("--msl", default=default)
    msl = Path(ap.parse_args().msl)
    if not (msl / "Modelica").is_dir():
        sys.exit(f"no Modelica Standard Library at {msl}")
    sys.path.insert(0, str(ROOT))
    from bgmodelica.modelica.parser import _lark, parse_text

    sources = msl / "Modelica" / "Blocks" / "Sources.mo"
    text = sources.read_text(encoding="utf-8")
    _lark()
    t = time.perf_counter()
    parse_text(text, str(sources))
    print(f"Modelica/Blocks/Sources.mo ({len(text) // 1000} kB): parsed in "
          f"{time.perf_counter() - t:.2f} s")
    with tempfile.TemporaryDirectory() as cache:
        cold = run(msl, cache)
        warm = run(msl, cache)
    for name, res in (("cold", cold), ("warm", warm)):
        print(f"{name}: {res['files']} files, {res['files'] - len(res['failed'])} parsed, "
              f"{len(res['failed'])} failed, {res['seconds']:.1f} s")
    for msg in cold["failed"][:20]:
        print("  " + msg)


if __name__ == "__main__":
    main()
