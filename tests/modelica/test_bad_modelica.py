"""Malformed, forbidden or unsupported Modelica through ``bgmodelica check``: exit code 2 and
one ``error:`` line naming ``file:line`` and the construct, never a traceback, a hang or a
silent acceptance.

Each file of ``bad/`` holds one construct; its header says what is expected:
``// expect: LINE PHRASE`` (the line the message names, a phrase it contains) and optionally
``// model: NAME`` (the class to check, ``M`` by default).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest

from bgmodelica.cli import main
from bgmodelica.modelica.parser import MAX_TEXT_BYTES

BAD = Path(__file__).with_name("bad")
FILES = sorted(BAD.glob("*.mo"))

#: files that cannot carry a header
EXPECT = {"empty.mo": (1, "no class")}


def _expectation(path: Path) -> tuple[str, int, str]:
    head = path.read_bytes()[:400].decode("utf-8", "replace")
    model = re.search(r"^// model: (\S+)", head, re.M)
    found = re.search(r"^// expect: (\d+) (.+)$", head, re.M)
    line, phrase = (int(found.group(1)), found.group(2).strip()) if found \
        else EXPECT[path.name]
    return (model.group(1) if model else "M"), line, phrase


def _check_one_line(capsys, argv: list[str]) -> tuple[int, str]:
    code = main(argv)
    captured = capsys.readouterr()
    err = captured.err
    assert "Traceback" not in err and "Traceback" not in captured.out
    lines = err.strip().splitlines()
    if code != 0:
        assert len(lines) == 1, err
        assert lines[0].startswith("error: "), err
    return code, lines[0] if lines else ""


def test_corpus_is_there():
    assert len(FILES) >= 25


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_bad_input(path, capsys):
    model, line, phrase = _expectation(path)
    code, msg = _check_one_line(capsys, ["check", f"{path}:{model}"])
    assert code == 2, msg
    assert re.search(rf"{re.escape(str(path))}:{line}(:\d+)?: ", msg), msg
    assert phrase.lower() in msg.lower(), msg


def test_deeply_nested_parentheses(tmp_path, capsys):
    """10^5 nested parentheses: read, or refused in one line (never a RecursionError)."""
    n = 100_000
    good = tmp_path / "deep.mo"
    good.write_text("model M\n  Real x;\nequation\n  x = " + "(" * n + "time" + ")" * n
                    + ";\nend M;\n")
    code, msg = _check_one_line(capsys, ["check", f"{good}:M"])
    assert code == 0 or f"{good}:4" in msg, msg
    bad = tmp_path / "deep_bad.mo"
    bad.write_text("model M\n  Real x;\nequation\n  x = " + "(" * n + "time" + ")" * (n - 1)
                   + ";\nend M;\n")
    code, msg = _check_one_line(capsys, ["check", f"{bad}:M"])
    assert code == 2 and f"{bad}:4:" in msg, msg


def test_long_sum_expression(tmp_path, capsys):
    """A sum of 10^5 terms (a left-nested tree as deep): built, or refused in one line."""
    path = tmp_path / "long.mo"
    path.write_text("model M\n  Real x;\nequation\n  x = " + " + ".join(["time"] * 100_000)
                    + ";\nend M;\n")
    code, msg = _check_one_line(capsys, ["check", f"{path}:M"])
    assert code == 0 or str(path) in msg, msg


def test_huge_file_is_refused_quickly(tmp_path, capsys):
    """A 50 MB file is refused by its size (:data:`MAX_TEXT_BYTES`) before it is read."""
    path = tmp_path / "huge.mo"
    line = "  parameter Real p = 1.5 \"a parameter with a long description\";\n"
    with path.open("w") as f:
        f.write("model M\n")
        f.write(line * (50 * 2**20 // len(line)))
        f.write("end M;\n")
    assert path.stat().st_size > MAX_TEXT_BYTES
    t0 = time.perf_counter()
    code, msg = _check_one_line(capsys, ["check", f"{path}:M"])
    assert code == 2 and f"{path}:1:1: " in msg and "too large" in msg, msg
    assert time.perf_counter() - t0 < 10


def test_der_of_a_real_parameter_is_zero():
    """Not an error: the specification makes der() of a Real parameter zero."""
    import bgmodelica as bg
    from bgmodelica.modelica import load_modelica_text

    model = load_modelica_text("model M\n  parameter Real p = 2;\n  Real x;\nequation\n"
                               "  x = der(p) + 1;\nend M;\n", "M")
    res = bg.simulate(bg.compile(model), stop_time=1.0)
    assert abs(float(res["x"][-1]) - 1.0) < 1e-12
