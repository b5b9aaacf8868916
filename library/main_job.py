"""The main job: ``python -m library.main_job [OUTDIR]``.

Simulates the paper's two-link robot arm driven by two DC motors under per-joint PID control,
writes trajectories (CSV), figures (PNG) and a summary; then the later stages (FMU export,
co-simulation check) when they are available.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def main(argv: list[str]) -> int:
    outdir = Path(argv[0] if argv else "results")
    outdir.mkdir(parents=True, exist_ok=True)
    from library.robots.main_job import run

    summary = run(outdir)
    (outdir / "summary.json").write_text(json.dumps(summary, indent=2, default=str))
    print(f"summary -> {outdir / 'summary.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
