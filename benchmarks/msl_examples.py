"""The Modelica Standard Library's examples, loaded from source and checked against references.

For each example class (those of the regression references, plus every example with an
``experiment`` annotation in the ``Examples`` packages of Blocks, Electrical.Analog,
Mechanics.Rotational, Mechanics.Translational and Thermal.HeatTransfer), one process:
load (parse + instantiate), compile, simulate with the example's ``experiment`` settings,
write the comparison signals, compare them with the reference in its tube
(``check_msl.py``). Prints one row per example and the totals: loaded, simulated, matched,
and the seconds of parse, instantiate, compile and simulate.

    python benchmarks/msl_examples.py                       # all, MSL at ../shared/msl
    python benchmarks/msl_examples.py --msl DIR --refs DIR  # other folders
    python benchmarks/msl_examples.py Rotational.Examples.First Blocks   # a selection
    python benchmarks/msl_examples.py --cold                # an empty parse cache first

Exit status 0; the figures are the output. ``--json FILE`` writes the rows.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("Modelica.Blocks.Examples", "Modelica.Electrical.Analog.Examples",
            "Modelica.Mechanics.Rotational.Examples", "Modelica.Mechanics.Translational.Examples",
            "Modelica.Thermal.HeatTransfer.Examples")


#: examples of the reference set that the scan below may miss (nested or unusual layout)
ALSO = ("Blocks.Examples.BusUsage", "Blocks.Examples.FilterWithDifferentiation",
        "Blocks.Examples.Interaction1", "Blocks.Examples.Modulation",
        "Blocks.Examples.Rectifier12pulseFFT", "Blocks.Examples.SlewRateLimiter",
        "Mechanics.Rotational.Examples.LossyGearDemo2")


def examples(msl: Path, refs: Path | None) -> list[str]:
    """Reference folders, then the example classes with an experiment annotation."""
    names = {f"Modelica.{n}" for n in ALSO}
    if refs is not None and refs.is_dir():
        names |= {d.name for d in refs.iterdir() if d.is_dir() and d.name.startswith("Modelica.")}
    for pkg in PACKAGES:
        folder = msl / Path(*pkg.split("."))
        files = [folder / "package.mo"] if folder.is_dir() else [folder.with_suffix(".mo")]
        if folder.is_dir():
            files += sorted(folder.glob("*.mo"))
        for f in files:
            if not f.is_file():
                continue
            text = f.read_text(errors="replace")
            for m in re.finditer(r"^\s*(?:encapsulated\s+)?model\s+(\w+)\b(.*?)^\s*end\s+\1\s*;",
                                 text, re.S | re.M):
                body = m.group(2)
                if "experiment(" in body and "partial model" not in m.group(0)[:40]:
                    names.add(f"{pkg}.{m.group(1)}")
    return sorted(names)


def run_one(name: str, out_dir: Path) -> dict:
    """Load, compile and simulate one example in this process; the row as a dict."""
    import bgmodelica as bg
    from bgmodelica.modelica import experiment_of, load_class, parser

    row: dict = {"example": name, "loaded": False, "simulated": False}
    t0 = time.perf_counter()
    p0 = parser.parse_seconds() if hasattr(parser, "parse_seconds") else 0.0
    try:
        model = load_class(name)
    except Exception as err:  # noqa: BLE001 -- a row, not a traceback
        row["error"] = _one_line(err)
        return row
    t1 = time.perf_counter()
    parse = (parser.parse_seconds() - p0) if hasattr(parser, "parse_seconds") else 0.0
    row.update(loaded=True, parse=parse, instantiate=t1 - t0 - parse)
    try:
        compiled = bg.compile(model)
        t2 = time.perf_counter()
        row["compile"] = t2 - t1
        exp = experiment_of(model)
        result = bg.simulate(compiled, **exp)
        row["simulate"] = time.perf_counter() - t2
    except Exception as err:  # noqa: BLE001
        from bgmodelica.modelica.errors import locate_error

        locate_error(model, err)            # the example's file:line when none is named
        row["error"] = _one_line(err)
        return row
    row["simulated"] = True
    csv = out_dir / f"{name}.csv"
    result.to_csv(csv)
    row["csv"] = str(csv)
    return row


def _one_line(err: BaseException) -> str:
    text = " ".join(str(err).split())
    return f"{type(err).__name__}: {text}"[:300]


def check(csv: str, ref: Path) -> tuple[bool, str]:
    tool = ref.parent / "check_msl.py"
    done = subprocess.run([sys.executable, str(tool), csv, str(ref)], capture_output=True,
                          text=True)
    last = (done.stdout.strip().splitlines() or [done.stderr.strip()])[-1:]
    return done.returncode == 0, (last[0] if last else "")[:200]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("select", nargs="*", help="substrings of example names")
    ap.add_argument("--msl", default=str(ROOT.parent / "shared" / "msl"))
    ap.add_argument("--refs", default=str(ROOT.parent / "shared" / "msl-reference"))
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--cold", action="store_true", help="start with an empty parse cache")
    ap.add_argument("--json", help="write the rows to this file")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        print(json.dumps(run_one(args.one, Path(args.out))))
        return 0
    msl, refs = Path(args.msl), Path(args.refs)
    if not (msl / "Modelica" / "package.mo").is_file():
        print(f"no MSL at {msl} (give --msl DIR)")
        return 0
    env = dict(os.environ, MODELICAPATH=str(msl))
    out_dir = Path(tempfile.mkdtemp(prefix="msl-examples-"))
    if args.cold:
        env["BGMODELICA_CACHE"] = str(out_dir / "cache")
    names = [n for n in examples(msl, refs) if not args.select
             or any(s in n for s in args.select)]
    rows = []
    print(f"{'example':<58} {'load':>4} {'sim':>4} {'match':>5} {'parse':>6} {'inst':>6} "
          f"{'comp':>6} {'sim':>6} {'total':>6}")
    for name in names:
        t0 = time.perf_counter()
        try:
            done = subprocess.run([sys.executable, __file__, "--one", name, "--out",
                                   str(out_dir)], capture_output=True, text=True,
                                  timeout=args.timeout, env=env, cwd=ROOT)
            lines = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
            row = json.loads(lines[-1]) if lines else {
                "example": name, "loaded": False, "simulated": False,
                "error": (done.stderr.strip().splitlines() or ["crashed"])[-1][:300]}
        except subprocess.TimeoutExpired:
            row = {"example": name, "loaded": False, "simulated": False,
                   "error": f"timeout after {args.timeout:.0f} s"}
        row["total"] = time.perf_counter() - t0
        ref = refs / name
        row["has_reference"] = ref.is_dir()
        row["matched"] = None
        if row.get("simulated") and ref.is_dir():
            row["matched"], row["check"] = check(row["csv"], ref)
        rows.append(row)
        mark = {True: "yes", False: "no", None: "-"}
        print(f"{name.replace('Modelica.', ''):<58} {mark[row['loaded']]:>4} "
              f"{mark[row['simulated']]:>4} {mark[row['matched']]:>5} "
              + " ".join(f"{row.get(k, float('nan')):6.2f}" for k in
                         ("parse", "instantiate", "compile", "simulate", "total")), flush=True)
        if row.get("error"):
            print(f"    {row['error']}")
        elif row.get("matched") is False:
            print(f"    {row.get('check', '')}")
    n = len(rows)
    loaded = sum(r["loaded"] for r in rows)
    simulated = sum(r["simulated"] for r in rows)
    matched = sum(bool(r["matched"]) for r in rows)
    with_ref = sum(r["has_reference"] for r in rows)
    ok_totals = [r["total"] for r in rows if r["simulated"]]
    print(f"\n{n} examples: loaded {loaded}, simulated {simulated}, matched {matched} of "
          f"{with_ref} with a reference")
    if ok_totals:
        print(f"end to end: median {statistics.median(ok_totals):.2f} s, whole set "
              f"{sum(r['total'] for r in rows):.1f} s")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
