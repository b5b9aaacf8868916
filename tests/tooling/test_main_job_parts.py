"""Pieces of the main job (library/main_job.py): the FMU build cache and the stage lines.
The whole job runs in `bash scripts/main.sh` (about a minute), not here."""

from __future__ import annotations

import zipfile
from pathlib import Path

import library.main_job as job

ROOT = Path(__file__).resolve().parents[2]


def test_build_cache_reuses_the_binary(tmp_path, monkeypatch):
    from bgmodelica.fmi import build, export
    from bgmodelica.fmi.from_model import export_model
    from library.examples.control import DCMotorIO

    monkeypatch.setattr(export, "compile_shared_library", build.compile_shared_library)
    calls = []
    real = build.compile_shared_library

    def counting(*args, **kwargs):
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(build, "compile_shared_library", counting)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")     # the same generation date
    job.use_build_cache(str(tmp_path / "cache"))
    first = export_model(DCMotorIO(), tmp_path / "a", fmu_type="cs")
    second = export_model(DCMotorIO(), tmp_path / "b", fmu_type="cs")
    assert len(calls) == 1                                  # the second build hit the cache
    assert len(list((tmp_path / "cache").iterdir())) == 1
    with zipfile.ZipFile(first) as a, zipfile.ZipFile(second) as b:
        assert sorted(a.namelist()) == sorted(b.namelist())
        for name in a.namelist():
            assert a.read(name) == b.read(name), name       # byte-identical FMUs


def test_stage_lines(capsys):
    stages = job.Stages()
    stages.done("figures", 1.234, "a.png, b.png")
    line = capsys.readouterr().out.strip()
    assert line.startswith("[") and line.endswith("figures: a.png, b.png (1.2 s)")
    assert stages.seconds == {"figures": 1.23}


def test_nothing_points_into_the_repository():
    text = (ROOT / "library" / "main_job.py").read_text()
    assert "parents[1]" not in text and "FMU_DIR" not in text
    assert (ROOT / "fmus" / "README.md").is_file()          # the folder stays, documented
