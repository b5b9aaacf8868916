"""Nothing silently wrong: every bad input ends in ONE line on stderr, exit status 2, naming the
component, variable, connector, option or file at fault -- no traceback, no hang, no partial or
misleading output.

The corpus runs the command line in-process (``bgmodelica.cli.main``) on the models of
:mod:`bad_models` and on small files written for the purpose; a few cases run the real
``bgmodelica`` executable in a subprocess (no hang, no traceback).
"""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.cli import main
from bgmodelica.errors import ModelError, OptionError

HERE = Path(__file__).resolve().parent
MODELS = HERE / "bad_models.py"


def _line(tag: str) -> int:
    for k, text in enumerate(MODELS.read_text().splitlines(), start=1):
        if f"# LINE:{tag}" in text:
            return k
    raise AssertionError(tag)


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, str]:
    """Model files that do not parse or import, and a package with relative imports."""
    d = tmp_path_factory.mktemp("bad_files")
    (d / "syntax_error.py").write_text("from bgmodelica import Component\n\n"
                                       "class M(Component:\n    pass\n")
    (d / "import_error.py").write_text("import no_such_package_xyz  # noqa\n")
    (d / "module_raises.py").write_text("x = 1\nraise RuntimeError('module-level failure')\n")
    (d / "empty.py").write_text("# nothing here\n")
    (d / "notes.txt").write_text("not python\n")
    pkg = d / "bgm_user_pkg"
    (pkg / "models").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "models" / "__init__.py").write_text("")
    (pkg / "parts.py").write_text("R_DEFAULT = 3.0\n")
    (pkg / "models" / "circuit.py").write_text(
        "from ..parts import R_DEFAULT\n"
        "from . import helpers\n"
        "from bgmodelica import Component, connect\n"
        "from library.electrical import Capacitor, ConstantVoltage, Ground, Resistor\n\n"
        "class Circuit(Component):\n"
        "    src = ConstantVoltage(V=1.0)\n"
        "    R = Resistor(R=R_DEFAULT)\n"
        "    C = Capacitor(C=helpers.C, v=0.0)\n"
        "    gnd = Ground()\n\n"
        "    def equations(self):\n"
        "        yield connect(self.src.p, self.R.p)\n"
        "        yield connect(self.R.n, self.C.p)\n"
        "        yield connect(self.C.n, self.src.n)\n"
        "        yield connect(self.src.n, self.gnd.p)\n")
    (pkg / "models" / "helpers.py").write_text("C = 0.5\n")
    (pkg / "models" / "broken.py").write_text("from ..missing_module import X  # noqa\n")
    (d / "a_directory.py").mkdir()
    out = {k: str(d / k) for k in ("syntax_error.py", "import_error.py", "module_raises.py",
                                    "empty.py", "notes.txt", "a_directory.py")}
    out["pkg_ok"] = str(pkg / "models" / "circuit.py")
    out["pkg_broken"] = str(pkg / "models" / "broken.py")
    out["dir"] = str(d)
    (d / "existing_dir").mkdir()
    (d / "a_file.txt").write_text("I am a file\n")
    (d / "plot_dir.png").mkdir()
    out["existing_dir"] = str(d / "existing_dir")
    out["a_file"] = str(d / "a_file.txt")
    out["plot_dir"] = str(d / "plot_dir.png")
    out["out"] = str(d / "out.csv")
    return out


def run(capsys, argv: list[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(code: int, out: str, err: str, culprits: tuple[str, ...]) -> None:
    lines = err.strip("\n").splitlines()
    assert code == 2, (code, out, err)
    assert len(lines) == 1, err
    assert lines[0].startswith("error:"), err
    assert "Traceback" not in err and "Traceback" not in out
    assert out == "", out                       # no partial or misleading output
    for c in culprits:
        assert c in lines[0], (c, lines[0])


M = str(MODELS)
SIM = ["simulate"]
CHECK = ["check"]


def _m(name: str) -> str:
    return f"{M}:{name}"


# (argv with {placeholders}, culprits that the single error line must contain)
CASES = [
    # -- model language --------------------------------------------------------------------
    pytest.param(CHECK + [_m("SelfConnectPin")], ("connect(R.n, R.n)", "itself"),
                 id="self-connection-pin"),
    pytest.param(CHECK + [_m("SelfConnectSignal")], ("connect(u, u)", "itself"),
                 id="self-connection-signal"),
    pytest.param(CHECK + [_m("OutputToOutput")], ("two outputs", "a.y", "b.y"),
                 id="output-to-output"),
    pytest.param(CHECK + [_m("MissingEquation")],
                 ("unbalanced", "orphan", "likely cause", "appears in no equation"),
                 id="unbalanced-missing"),
    pytest.param(CHECK + [_m("SurplusEquation")], ("unbalanced", "surplus", "x-(2.*time)"),
                 id="unbalanced-surplus"),
    pytest.param(CHECK + [_m("Singular")], ("structurally singular", "b (declared"),
                 id="structurally-singular"),
    pytest.param(CHECK + [_m("NoGround")],
                 ("connection set {C.n, src.n} has no reference (ground)",),
                 id="missing-ground"),
    pytest.param(SIM + [_m("NoGroundStar"), "-o", "{out}"],
                 ("has no reference (ground)", "src.n", "L.n"), id="missing-ground-star"),
    pytest.param(CHECK + [_m("UnconnectedInput")], ("input g.u is not connected",),
                 id="unconnected-input"),
    pytest.param(CHECK + [_m("AlwaysVsNever")], ("StateSelectError", "ALWAYS", "NEVER",
                                                 "x (declared", "y (declared"),
                 id="stateselect-always-vs-never"),
    pytest.param(CHECK + [_m("NeverButState")], ("StateSelectError", "x", "NEVER",
                                                 "must be a state"),
                 id="stateselect-never-but-state"),
    pytest.param(CHECK + [_m("AlwaysNotDifferentiated")], ("StateSelectError", "w", "ALWAYS",
                                                           "never differentiated"),
                 id="stateselect-always-not-differentiated"),
    pytest.param(CHECK + [_m("AlwaysTooMany")], ("StateSelectError", "x1", "x2", "ALWAYS"),
                 id="stateselect-always-too-many"),
    pytest.param(CHECK + [_m("ParameterOfTime")], ("parameter k", "depends on time"),
                 id="parameter-bound-to-time"),
    pytest.param(CHECK + [_m("ParameterOfVariable")],
                 ("parameter load.R", "variable x"), id="parameter-bound-to-variable"),
    pytest.param(CHECK + [_m("ParameterOfInput")], ("parameter load.R", "input u"),
                 id="parameter-bound-to-input"),
    pytest.param(CHECK + [_m("RaisesInInit")],
                 ("UserCodeError", "RaisesInInit", "ValueError", "the user's bug",
                  f"bad_models.py:{_line('init')}"), id="user-code-init"),
    pytest.param(CHECK + [_m("RaisesInEquations")],
                 ("UserCodeError", "inner (Leaky)", "RuntimeError", "broken equations",
                  f"bad_models.py:{_line('equations')}"), id="user-code-equations"),
    pytest.param(CHECK + [_m("TypoInEquations")],
                 ("UserCodeError", "TypeError", f"bad_models.py:{_line('typo')}"),
                 id="user-code-typo"),
    pytest.param(CHECK + [_m("RaisesInSubcomponent")],
                 ("UserCodeError", "subcomponent part", "KeyError",
                  f"bad_models.py:{_line('clone')}"), id="user-code-subcomponent"),
    pytest.param(CHECK + [_m("NotAnEquation")], ("EquationError", "NotAnEquation", "x + 1"),
                 id="not-an-equation"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "n=0"],
                 ("UserCodeError", "ladder", "n >= 1", f"bad_models.py:{_line('ladder')}"),
                 id="user-code-function"),
    pytest.param(CHECK + [_m("not_a_model")], ("not_a_model", "returned int"),
                 id="function-returns-non-model"),
    pytest.param(CHECK + ["{syntax_error.py}:M"], ("does not parse", "syntax_error.py:3"),
                 id="file-does-not-parse"),
    pytest.param(CHECK + ["{import_error.py}:M"],
                 ("cannot import", "no_such_package_xyz", "import_error.py:1"),
                 id="file-import-error"),
    pytest.param(CHECK + ["{module_raises.py}:M"],
                 ("cannot import", "RuntimeError", "module-level failure", "module_raises.py:2"),
                 id="file-raises-at-import"),
    pytest.param(CHECK + ["{dir}/nope.py:M"], ("nope.py", "does not exist"),
                 id="file-missing"),
    pytest.param(CHECK + ["{empty.py}:M"], ("no model named 'M'",), id="name-missing"),
    pytest.param(CHECK + ["{notes.txt}:M"], ("notes.txt", "not a Python file"),
                 id="file-not-python"),
    pytest.param(CHECK + ["{a_directory.py}:M"], ("a_directory.py", "directory"),
                 id="file-is-directory"),
    pytest.param(CHECK + ["{pkg_broken}:X"], ("broken.py", "missing_module"),
                 id="package-file-relative-import-fails"),
    pytest.param(CHECK + ["no_such_module_xyz:M"], ("no module 'no_such_module_xyz'",),
                 id="module-missing"),
    pytest.param(CHECK + ["library.examples.circuits"], ("must be 'path/file.py:Name'",),
                 id="reference-without-name"),
    # -- --arg ------------------------------------------------------------------------------
    pytest.param(CHECK + [_m("ladder"), "--arg", "n"], ("--arg", "NAME=VALUE", "'n'"),
                 id="arg-without-value"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "=3"], ("--arg", "NAME=VALUE"),
                 id="arg-without-name"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "n=abc"], ("--arg n=abc", "an integer"),
                 id="arg-wrong-type"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "n=2.5"], ("--arg n=2.5", "an integer"),
                 id="arg-fractional-int"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "scale=NaN"], ("--arg scale", "finite"),
                 id="arg-nan"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "m=3"], ("--arg m", "takes no argument 'm'",
                                                          "n, scale"), id="arg-unknown-name"),
    pytest.param(CHECK + [_m("ladder"), "--arg", "n=2", "--arg", "n=3"],
                 ("--arg n", "twice"), id="arg-twice"),
    pytest.param(CHECK + [_m("RC"), "--arg", "nonsense=3"], ("RC", "'nonsense'"),
                 id="arg-unknown-modifier"),
    pytest.param(CHECK + ["library.examples.circuits:RCLadder", "--arg", "n=0"],
                 ("UserCodeError", "RCLadder", "n >= 1", "circuits.py"),
                 id="arg-rejected-by-library-model"),
    # -- parameters and start values ---------------------------------------------------------
    pytest.param(SIM + [_m("Bounded"), "--set", "k=-1", "-o", "{out}"],
                 ("parameter k = -1", "min = 0", "[0, 10]"), id="set-below-min"),
    pytest.param(SIM + [_m("Bounded"), "--set", "k=11", "-o", "{out}"],
                 ("parameter k = 11", "max = 10"), id="set-above-max"),
    pytest.param(SIM + [_m("Bounded"), "--set", "x=7", "-o", "{out}"],
                 ("start value of x = 7", "max = 5"), id="set-start-above-max"),
    pytest.param(SIM + [_m("DefaultOutOfRange"), "-o", "{out}"],
                 ("parameter k = -2", "min = 0"), id="default-below-min"),
    pytest.param(CHECK + [_m("DefaultOutOfRange")], ("parameter k = -2", "min = 0"),
                 id="check-default-below-min"),
    pytest.param(SIM + [_m("BoundOutOfRange"), "--set", "Rtot=-4", "-o", "{out}"],
                 ("parameter R1.R", "-2", "min = 0"), id="bound-parameter-below-min"),
    pytest.param(SIM + [_m("StartOutOfRange"), "-o", "{out}"],
                 ("start value of x = -9", "min = -5"), id="start-below-min"),
    pytest.param(SIM + [_m("NanParameter"), "-o", "{out}"], ("parameter k", "nan"),
                 id="parameter-nan"),
    pytest.param(SIM + [_m("NanStart"), "-o", "{out}"], ("start value of C.v", "inf"),
                 id="start-inf"),
    pytest.param(SIM + [_m("TextStart"), "-o", "{out}"],
                 ("start value of x", "'half a volt'", "not a number"), id="start-text"),
    pytest.param(SIM + [_m("RecursiveBindings"), "-o", "{out}"],
                 ("cycle", "c1.U -> c2.T -> c1.U"), id="bindings-cycle"),
    pytest.param(["export", _m("RecursiveBindings"), "-o", "{dir}/fmus"],
                 ("cycle", "c1.U -> c2.T -> c1.U"), id="bindings-cycle-export"),
    pytest.param(SIM + [_m("RC"), "--set", "R.R=nan", "-o", "{out}"], ("R.R", "not finite"),
                 id="set-nan"),
    pytest.param(SIM + [_m("RC"), "--set", "R.R=inf", "-o", "{out}"], ("R.R", "not finite"),
                 id="set-inf"),
    pytest.param(SIM + [_m("RC"), "--set", "R.R=ten", "-o", "{out}"], ("R.R", "'ten'"),
                 id="set-not-a-number"),
    pytest.param(SIM + [_m("RC"), "--set", "R.R", "-o", "{out}"], ("--set", "NAME=VALUE"),
                 id="set-without-value"),
    pytest.param(SIM + [_m("RC"), "--set", "R.Rx=2", "-o", "{out}"], ("'R.Rx'", "R.R"),
                 id="set-unknown-name"),
    pytest.param(SIM + [_m("LogOfNegative"), "-o", "{out}"],
                 ("undefined at the initial point", "der(x)", "log", "a = -1",
                  "[top level (LogOfNegative)]"), id="log-of-negative-at-t0"),
    pytest.param(SIM + [_m("DivisionByZero"), "-o", "{out}"],
                 ("undefined at the initial point", "der(x)", "division by zero", "a = 0"),
                 id="division-by-zero-at-t0"),
    pytest.param(SIM + [_m("SqrtOfNegative"), "-o", "{out}"],
                 ("undefined at the initial point", "y = ", "square root", "c = -4"),
                 id="sqrt-of-negative-at-t0"),
    pytest.param(SIM + [_m("RC"), "--set", "C.C=0", "-o", "{out}"],
                 ("undefined at the initial point", "division by zero", "C.C = 0"),
                 id="set-makes-division-by-zero"),
    # -- simulation options ------------------------------------------------------------------
    pytest.param(SIM + [_m("RC"), "--stop-time", "nan", "-o", "{out}"],
                 ("--stop-time", "nan"), id="stop-time-nan"),
    pytest.param(SIM + [_m("RC"), "--stop-time", "inf", "-o", "{out}"],
                 ("--stop-time", "inf"), id="stop-time-inf"),
    pytest.param(SIM + [_m("RC"), "--stop-time", "0", "-o", "{out}"],
                 ("--stop-time", "after the start time"), id="stop-time-zero"),
    pytest.param(SIM + [_m("RC"), "--stop-time", "-2", "-o", "{out}"],
                 ("--stop-time", "-2"), id="stop-time-negative"),
    pytest.param(SIM + [_m("RC"), "--stop-time", "abc", "-o", "{out}"],
                 ("--stop-time", "'abc'"), id="stop-time-not-a-number"),
    pytest.param(SIM + [_m("RC"), "--interval", "0", "-o", "{out}"],
                 ("--interval", "positive"), id="interval-zero"),
    pytest.param(SIM + [_m("RC"), "--interval", "-0.1", "-o", "{out}"],
                 ("--interval", "-0.1"), id="interval-negative"),
    pytest.param(SIM + [_m("RC"), "--interval", "nan", "-o", "{out}"],
                 ("--interval", "nan"), id="interval-nan"),
    pytest.param(SIM + [_m("RC"), "--interval", "inf", "-o", "{out}"],
                 ("--interval", "inf"), id="interval-inf"),
    pytest.param(SIM + [_m("RC"), "--interval", "1e-12", "-o", "{out}"],
                 ("1000000000001 points", "--interval"), id="grid-too-large"),
    pytest.param(SIM + [_m("RC"), "--stop-time", "1e300", "--interval", "1e-300",
                        "-o", "{out}"], ("points", "--interval"), id="grid-overflow"),
    pytest.param(SIM + [_m("RC"), "--rtol", "0", "-o", "{out}"], ("--rtol",),
                 id="rtol-zero"),
    pytest.param(SIM + [_m("RC"), "--rtol", "nan", "-o", "{out}"], ("--rtol", "nan"),
                 id="rtol-nan"),
    pytest.param(SIM + [_m("RC"), "--atol", "-1e-8", "-o", "{out}"], ("--atol",),
                 id="atol-negative"),
    pytest.param(SIM + ["library.examples.hybrid:BouncingBall", "--stop-time", "nan",
                        "-o", "{out}"], ("--stop-time", "nan"), id="hybrid-stop-time-nan"),
    pytest.param(SIM + ["library.examples.hybrid:BouncingBall", "--interval", "-1",
                        "-o", "{out}"], ("--interval",), id="hybrid-interval-negative"),
    pytest.param(SIM + [_m("NanLater"), "--stop-time", "2", "-o", "{out}"],
                 ("y is NaN at t = 1.004 s", "sqrt", "up to t = 1 s", "out.csv"),
                 id="nan-in-results"),
    pytest.param(SIM + [_m("NanLaterHybrid"), "--stop-time", "2", "-o", "{out}"],
                 ("y is NaN at t = 1.004 s", "up to t = 1 s"), id="nan-in-results-hybrid"),
    pytest.param(SIM + [_m("LosesSolution"), "--stop-time", "2", "--interval", "0.05",
                        "-o", "{out}"], ("failed after t = 1 s", "rows up to t = 1 s",
                                         "out.csv"), id="solver-failure-partial-rows"),
    # -- output files -------------------------------------------------------------------------
    pytest.param(SIM + [_m("RC"), "-o", "{existing_dir}"], ("-o", "existing_dir",
                                                           "directory"), id="output-is-dir"),
    pytest.param(SIM + [_m("RC"), "-o", "{a_file}/x.csv"], ("a_file.txt", "not a directory"),
                 id="output-under-a-file"),
    pytest.param(SIM + [_m("RC"), "-o", "/proc/bgm_forbidden/x.csv"],
                 ("-o", "/proc/bgm_forbidden/x.csv", "cannot write"),
                 id="output-unwritable"),
    pytest.param(SIM + [_m("RC"), "-o", "{out}", "--plot", "{dir}/plot.xyz"],
                 ("--plot", "plot.xyz", "unknown plot format"), id="plot-unknown-format"),
    pytest.param(SIM + [_m("RC"), "-o", "{out}", "--plot", "{dir}/plot"],
                 ("--plot", "no file extension"), id="plot-no-extension"),
    pytest.param(SIM + [_m("RC"), "-o", "{out}", "--plot", "{plot_dir}"],
                 ("--plot", "plot_dir.png", "directory"), id="plot-is-dir"),
    pytest.param(SIM + [_m("RC"), "-o", "{out}", "--plot", "{dir}/p.png", "--plot-vars",
                        "C.v", "C.vv"], ("--plot-vars", "'C.vv'", "did you mean"),
                 id="plot-unknown-variable"),
    pytest.param(SIM + [_m("RC"), "-o", "{out}", "--plot-vars", "C.v"],
                 ("--plot-vars", "--plot"), id="plot-vars-without-plot"),
    pytest.param(SIM + [_m("RC"), "-o", "{dir}/same.png", "--plot", "{dir}/same.png"],
                 ("same.png", "the same file"), id="output-same-as-plot"),
    pytest.param(SIM + [_m("RC"), "-o", "{out}", "--input", "{dir}/no_inputs.csv"],
                 ("--input", "no_inputs.csv", "no such file"), id="input-file-missing"),
    pytest.param(["draw", _m("RC"), "-o", "{dir}/drawing.xyz"],
                 ("-o", "drawing.xyz", "unknown plot format"), id="draw-unknown-format"),
    pytest.param(["export", _m("RC"), "--stop-time", "nan", "-o", "{dir}/fmus"],
                 ("--stop-time", "nan"), id="export-stop-time-nan"),
    pytest.param(["export", _m("RC"), "--step", "0", "-o", "{dir}/fmus"],
                 ("--step", "positive"), id="export-step-zero"),
    pytest.param(["export", _m("RC"), "-o", "{a_file}"], ("-o", "a_file.txt", "is a file"),
                 id="export-output-is-file"),
    pytest.param(["simulate", _m("RC"), "--no-such-option"], ("--no-such-option",),
                 id="unknown-option"),
]


def _fill(text: str, files: dict[str, str]) -> str:
    for key, value in files.items():
        text = text.replace("{" + key + "}", value)
    return text


@pytest.mark.parametrize(("argv", "culprits"), CASES)
def test_bad_input(capsys, files, argv, culprits):
    code, out, err = run(capsys, [_fill(a, files) for a in argv])
    assert_one_line_error(code, out, err, tuple(_fill(c, files) for c in culprits))


# -- what the errors leave behind ------------------------------------------------------------

def test_nothing_existing_is_destroyed(capsys, tmp_path):
    out = tmp_path / "keep.csv"
    out.write_text("precious\n")
    for argv in (["simulate", _m("RC"), "-o", str(out), "--plot", str(tmp_path / "x.bad")],
                 ["simulate", _m("RC"), "-o", str(out), "--stop-time", "nan"],
                 ["simulate", _m("NoGround"), "-o", str(out)],
                 ["simulate", _m("LogOfNegative"), "-o", str(out)]):
        code, _, err = run(capsys, argv)
        assert code == 2 and len(err.strip().splitlines()) == 1
        assert out.read_text() == "precious\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.csv"]


def test_solver_failure_writes_the_good_rows(capsys, tmp_path):
    out = tmp_path / "partial.csv"
    out.write_text("an older result\n")
    code, stdout, err = run(capsys, ["simulate", _m("LosesSolution"), "--stop-time", "2",
                                     "--interval", "0.05", "-o", str(out)])
    assert code == 2 and stdout == "" and len(err.strip().splitlines()) == 1
    rows = list(csv.reader(out.open()))
    times = np.array([float(r[0]) for r in rows[1:]])
    assert rows[0][0] == "time" and times[-1] == 1.0 and len(times) == 21
    assert np.allclose(times, np.arange(21) * 0.05, atol=1e-12)
    assert f"{len(times)} rows up to t = 1 s written to {out}" in err
    z = np.array([float(r[rows[0].index("z")]) for r in rows[1:]])
    assert np.allclose(z, np.sqrt(1 - times**2), atol=1e-5)


def test_nan_result_keeps_the_finite_rows(capsys, tmp_path):
    out = tmp_path / "nan.csv"
    code, _, err = run(capsys, ["simulate", _m("NanLater"), "--stop-time", "2",
                                "--interval", "0.25", "-o", str(out)])
    assert code == 2 and "y is NaN at t = 1.25 s" in err
    rows = list(csv.reader(out.open()))
    assert [float(r[0]) for r in rows[1:]] == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert all(v.lower() != "nan" for r in rows[1:] for v in r)


def test_package_file_with_relative_imports_loads(capsys, files, tmp_path):
    out = tmp_path / "pkg.csv"
    code, stdout, err = run(capsys, ["simulate", f"{files['pkg_ok']}:Circuit",
                                     "--stop-time", "0.5", "-o", str(out)])
    assert code == 0, err
    assert "Circuit" in stdout and out.is_file()
    code, stdout, _ = run(capsys, ["check", f"{files['pkg_ok']}:Circuit"])
    assert code == 0 and "balanced" in stdout


# -- the output grid is exactly what was asked ---------------------------------------------

def test_exact_output_grid(capsys, tmp_path):
    out = tmp_path / "grid.csv"
    code, _, err = run(capsys, ["simulate", _m("RC"), "--stop-time", "2", "--interval", "0.3",
                                "-o", str(out)])
    assert code == 0, err
    times = [float(r[0]) for r in list(csv.reader(out.open()))[1:]]
    assert times == pytest.approx([0, 0.3, 0.6, 0.9, 1.2, 1.5, 1.8, 2.0], abs=1e-12)


@pytest.mark.parametrize(("stop", "interval", "expected"), [
    (2.0, 0.3, [0, 0.3, 0.6, 0.9, 1.2, 1.5, 1.8, 2.0]),
    (1.0, 0.1, [k / 10 for k in range(11)]),
    (1.0, 0.25, [0, 0.25, 0.5, 0.75, 1.0]),
    (0.5, 2.0, [0, 0.5]),
    (3.0, 1.0, [0, 1, 2, 3]),
])
def test_exact_grid_api(stop, interval, expected):
    from library.examples.circuits import RC

    res = bg.simulate(RC(), stop_time=stop, interval=interval)
    assert res.time == pytest.approx(expected, abs=1e-12)
    assert res.time[-1] == stop


def test_exact_grid_hybrid():
    from library.examples.hybrid import BouncingBall

    res = bg.simulate(BouncingBall(), stop_time=0.7, interval=0.3)
    grid = sorted(set(res.time) - set(res.meta["event_times"]))
    assert grid == pytest.approx([0, 0.3, 0.6, 0.7], abs=1e-12)


# -- the Python API raises the typed errors ----------------------------------------------------

@pytest.mark.parametrize("options", [
    {"stop_time": float("nan")}, {"stop_time": float("inf")}, {"stop_time": 0.0},
    {"stop_time": -1.0}, {"stop_time": "soon"}, {"interval": 0.0}, {"interval": -1.0},
    {"interval": float("nan")}, {"rtol": -1.0}, {"atol": float("inf")}, {"max_step": 0.0},
    {"max_steps": 0}, {"solver": "euler"}, {"stop_time": 1.0, "start_time": 2.0},
])
def test_api_options(options):
    from library.examples.circuits import RC

    with pytest.raises(OptionError):
        bg.simulate(RC(), **options)


def test_api_nan_result_error_keeps_rows():
    from bgmodelica.errors import SimulationError

    from .bad_models import NanLater as Model

    with pytest.raises(SimulationError) as err:
        bg.simulate(Model(), stop_time=2.0, interval=0.5)
    assert "y is NaN at t = 1.5 s" in str(err.value)
    assert list(err.value.result.time) == [0.0, 0.5, 1.0]
    assert err.value.time_reached == 1.0


def test_user_code_error_keeps_the_cause():
    from bgmodelica.errors import UserCodeError

    from .bad_models import RaisesInEquations

    with pytest.raises(UserCodeError) as err:
        bg.compile(RaisesInEquations())
    assert isinstance(err.value.__cause__, RuntimeError)
    assert f"bad_models.py:{_line('equations')}" in err.value.location
    assert isinstance(err.value, ModelError)


# -- the real executable: no hang, no traceback ------------------------------------------------

def _exe(*argv: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "bgmodelica.cli", *argv], capture_output=True,
                          text=True, timeout=timeout, cwd=HERE.parent.parent,
                          env={**os.environ, "PYTHONPATH": str(HERE.parent.parent)})


@pytest.mark.parametrize(("argv", "culprit"), [
    (["simulate", "library.examples.circuits:RC", "--stop-time", "nan"], "--stop-time"),
    (["simulate", _m("RaisesInInit"), "--stop-time", "1"], "the user's bug"),
    (["simulate", _m("LogOfNegative"), "-o", os.devnull], "log"),
])
def test_executable_one_line_no_hang(argv, culprit):
    done = _exe(*argv, timeout=120)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and culprit in lines[0], done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_large_floating_network_is_named():
    """Above the eager limit the ground search runs once a later check has failed."""
    from bgmodelica import Component
    from bgmodelica.errors import UnbalancedModelError
    from bgmodelica.passes.reference import EAGER_LIMIT
    from library.electrical import Capacitor, Resistor, SineVoltage

    m = Component(name="floating_ladder")
    m.add("src", SineVoltage(V=1.0, f=10.0))
    node = m.src.p
    n = EAGER_LIMIT // 10 + 1
    for k in range(1, n + 1):
        r = m.add(f"R{k}", Resistor(R=1.0))
        c = m.add(f"C{k}", Capacitor(C=1.0, v=0.0))
        m.connect(node, r.p)
        m.connect(r.n, c.p)
        m.connect(c.n, m.src.n)
        node = r.n
    with pytest.raises(UnbalancedModelError) as err:
        bg.compile(m)
    assert str(err.value).startswith("connection set {C1.n, ")
    assert f"... ({n + 1} connectors)}} has no reference (ground)" in str(err.value)


def test_a_subclass_declaring_a_connector_under_a_variable_name_is_refused():
    from bgmodelica.errors import DuplicateNameError
    from library.electrical import Pin

    class Base(bg.Component):
        p = bg.Variable()

    class Sub(Base):
        p = Pin()

    with pytest.raises(DuplicateNameError, match="'p' already exists"):
        Sub()


def test_start_value_with_a_unit_is_converted():
    class Decay(bg.Component):
        x = bg.Variable(start="500 mV", fixed=True, unit="V")
        k = bg.Parameter(1.0, unit="1/s")

        def equations(self):
            yield bg.der(self.x) == -self.k * self.x

    res = bg.simulate(Decay(), stop_time=1.0, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(res["x"], 0.5 * np.exp(-res.time), atol=1e-8)
    res = bg.simulate(Decay(x="2 V"), stop_time=1.0, rtol=1e-10, atol=1e-12)
    assert res["x"][0] == 2.0


def test_model_name_too_long_for_a_file_name(capsys, tmp_path):
    name = "M" + "a" * 300
    path = tmp_path / "long.py"
    path.write_text("from bgmodelica import Component, Variable, der\n\n"
                    f"class {name}(Component):\n"
                    "    x = Variable(start=1.0, fixed=True)\n\n"
                    "    def equations(self):\n"
                    "        yield der(self.x) == -self.x\n")
    code, out, err = run(capsys, ["simulate", f"{path}:{name}"])
    assert_one_line_error(code, out, err, ("file name too long", "-o FILE"))


def test_a_grid_of_too_many_values_names_the_ways_out():
    """Too many values to hold: the refusal says how many, and that fewer variables (or a
    longer interval) fit; with one column there is nothing to drop."""

    from bgmodelica.errors import OptionError
    from bgmodelica.validate import output_grid

    with pytest.raises(OptionError, match=r"1001 points \(10000000 values each.*--outputs"):
        output_grid(0.0, 10.0, 0.01, n_columns=10_000_000)
    with pytest.raises(OptionError) as err:
        output_grid(0.0, 1.0, 1e-12)
    assert "--outputs" not in str(err.value) and "--interval" in str(err.value)
