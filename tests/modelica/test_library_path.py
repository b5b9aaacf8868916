"""Libraries on the Modelica library path: package folders, package.order, within, lazy
loading, MODELICAPATH and --modelica-path, names as MODEL references."""

from __future__ import annotations

import math

import pytest

import bgmodelica as bg
from bgmodelica.cli import main
from bgmodelica.modelica import ModelicaError, load_class, load_modelica
from bgmodelica.modelica import library_path as LP


def _write(root, rel, text):
    p = root / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text)
    return p


@pytest.fixture
def lib(tmp_path, monkeypatch):
    """A library ``Lib`` stored as folders: Lib/package.mo, Lib/Parts/package.mo with a
    package.order, one file per class, and an examples file."""
    root = tmp_path / "libs"
    _write(root, "Lib/package.mo", 'package Lib "A test library"\n'
           "  constant Real k = 2;\nend Lib;\n")
    _write(root, "Lib/package.order", "Parts\nExamples\n")
    _write(root, "Lib/Parts/package.mo", "within Lib;\npackage Parts\nend Parts;\n")
    _write(root, "Lib/Parts/package.order", "Decay\nBroken\n")
    _write(root, "Lib/Parts/Decay.mo", "within Lib.Parts;\nmodel Decay\n"
           "  parameter Real a = 1;\n  Real x(start = 1, fixed = true);\nequation\n"
           "  der(x) = -a*k*x;\nend Decay;\n")
    _write(root, "Lib/Parts/Broken.mo", "within Lib.Other;\nmodel Broken\nend Broken;\n")
    _write(root, "Lib/Examples.mo", "within Lib;\npackage Examples\n"
           "  model Twice\n    Parts.Decay d(a = 0.5);\n"
           "    annotation(experiment(StopTime = 2));\n  end Twice;\nend Examples;\n")
    monkeypatch.setenv("MODELICAPATH", str(root))
    monkeypatch.setattr(LP, "_extra", [])
    LP.clear()
    yield root
    LP.clear()


def test_class_from_the_library_path(lib):
    model = load_class("Lib.Examples.Twice")
    res = bg.simulate(model, stop_time=2.0, rtol=1e-9, atol=1e-12)
    # der(x) = -a*k*x with a = 0.5 (modifier) and k = 2 (package constant)
    assert res["d.x"][-1] == pytest.approx(math.exp(-2.0), rel=1e-5)


def test_only_what_is_used_is_read(lib, monkeypatch):
    from bgmodelica.modelica import parser

    read = []
    original = parser.parse_file
    monkeypatch.setattr(parser, "parse_file", lambda p: read.append(str(p)) or original(p))
    load_class("Lib.Parts.Decay")
    assert not any(r.endswith("Broken.mo") or r.endswith("Examples.mo") for r in read)


def test_within_naming_another_package_is_refused(lib):
    with pytest.raises(ModelicaError, match=r"Broken\.mo:1:1: within Lib\.Other names "
                                            r"another package"):
        load_class("Lib.Parts.Broken")


def test_unknown_class_suggests(lib):
    with pytest.raises(ModelicaError, match="did you mean Lib.Parts.Decay"):
        load_class("Lib.Parts.Decai")


def test_package_order(lib):
    from bgmodelica.modelica.library_path import resolve, stored_names

    assert stored_names(resolve("Lib.Parts").cdef) == ["Decay", "Broken"]


def test_file_of_a_package_folder(lib):
    model = load_modelica(lib / "Lib" / "package.mo", "Lib.Examples.Twice")
    assert bg.simulate(model, stop_time=0.1)["d.x"][0] == 1.0


def test_no_library_on_the_path(tmp_path, monkeypatch):
    monkeypatch.setenv("MODELICAPATH", str(tmp_path))
    monkeypatch.setattr(LP, "_extra", [])
    LP.clear()
    with pytest.raises(ModelicaError, match="no package Nope on the Modelica library path"):
        load_class("Nope.A")


def test_cli_takes_library_names_and_modelica_path(lib, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("MODELICAPATH", "")        # restored after the test: main() sets it
    LP.clear()
    out = tmp_path / "twice.csv"
    code = main(["simulate", "Lib.Examples.Twice", "--modelica-path", str(lib), "-o",
                 str(out)])
    assert code == 0, capsys.readouterr().err
    header = out.read_text().splitlines()[0]
    assert "d.x" in header
    last = out.read_text().splitlines()[-1].split(",")
    assert float(last[0]) == pytest.approx(2.0)


def test_modelica_path_must_exist(capsys, monkeypatch):
    monkeypatch.setenv("MODELICAPATH", "")
    assert main(["check", "Lib.X", "--modelica-path", "/nonexistent/folder"]) == 2
    assert "no such folder" in capsys.readouterr().err
