"""The parser reads the Modelica Standard Library (a sample of it: the whole tree is
``benchmarks/msl_parse.py``), and malformed text gives one positioned line, never a
traceback."""

from __future__ import annotations

import os
import random
from pathlib import Path

import pytest

from bgmodelica.modelica import ast as A
from bgmodelica.modelica import load_modelica_text
from bgmodelica.modelica.errors import ModelicaError, ModelicaSyntaxError
from bgmodelica.modelica.parser import parse_file, parse_text

SAMPLED = ["Blocks", "Electrical/Analog", "Mechanics/Rotational", "Mechanics/Translational",
           "Thermal/HeatTransfer", "Math", "Utilities"]


def msl_root() -> Path | None:
    """``$BGMODELICA_MSL`` or ``<repo>/../shared/msl`` when it holds the library."""
    env = os.environ.get("BGMODELICA_MSL")
    root = Path(env) if env else Path(__file__).resolve().parents[3] / "shared" / "msl"
    return root if (root / "Modelica").is_dir() else None


def _sample() -> list[Path]:
    root = msl_root()
    if root is None:
        return []
    rnd = random.Random(7)
    out = [root / "Complex.mo", root / "Modelica" / "Units.mo"]
    for sub in SAMPLED:
        files = sorted((root / "Modelica" / sub).rglob("*.mo"))
        out += rnd.sample(files, min(8, len(files)))
    return out


@pytest.mark.skipif(msl_root() is None, reason="MSL source not found ($BGMODELICA_MSL or "
                    "../shared/msl)")
@pytest.mark.parametrize("path", _sample(), ids=lambda p: "/".join(p.parts[-2:]))
def test_msl_file_parses(path, tmp_path, monkeypatch):
    monkeypatch.setenv("BGMODELICA_CACHE", str(tmp_path))
    tree = parse_file(path, disk_cache=False)
    assert tree.classes and all(c.file == str(path) for c in tree.classes)


@pytest.mark.skipif(msl_root() is None, reason="MSL source not found")
def test_msl_constructs():
    root = msl_root()
    units = parse_file(root / "Modelica" / "Units.mo", disk_cache=False).classes[0]
    assert units.name == "Units"
    streams = parse_file(root / "Modelica" / "Utilities" / "Streams.mo",
                         disk_cache=False).classes[0]
    print_fn = next(e for e in streams.elements if getattr(e, "name", "") == "print")
    assert print_fn.purity == "impure" and print_fn.external is not None
    assert print_fn.external.function == "ModelicaInternal_print"


GARBAGE = [
    "", "\x00\x01", "model", "model M", "end M;", "model M end N;", "((((", "}}}", "'",
    "model M\n  Real x = ;\nend M;", "model M\nequation\n  (a, b) := f(x);\nend M;",
    "function f\nalgorithm\n  x := ;\nend f;", "function f\nexternal \"C\" y = ;\nend f;",
    "model M\n  import A.{;\nend M;", "package P\n  model extends end P;",
    "pure model M end M;", "operator operator record R end R;", "within ;;;",
    "model M\nalgorithm\n  when x then end if;\nend M;",
]


@pytest.mark.parametrize("text", GARBAGE)
def test_garbage_is_one_positioned_line(text):
    try:
        parse_text(text, "g.mo")
    except ModelicaSyntaxError as err:
        msg = str(err)
        assert msg.startswith("g.mo:") and "\n" not in msg, msg
        assert err.line >= 1 and err.column >= 1


def test_random_token_soup_never_tracebacks():
    words = ("model function end equation algorithm external if then else for loop when "
             "while protected import extends redeclare replaceable annotation := = ( ) [ ] "
             "{ } , ; . : + * ^ .* == and not true x y M 1 2.5 \"s\" pure operator break "
             "return encapsulated partial .{ enumeration").split()
    rnd = random.Random(3)
    for _ in range(300):
        text = " ".join(rnd.choice(words) for _ in range(rnd.randint(1, 30)))
        try:
            parse_text(text, "g.mo")
        except ModelicaError as err:
            assert str(err).startswith("g.mo:") and "\n" not in str(err)


def test_long_token_shortened_in_message():
    with pytest.raises(ModelicaSyntaxError) as info:
        parse_text("model M\n  Real x;\nequation\n  x = 1 \"" + "a" * 100 + "\" 2;\nend M;",
                   "g.mo")
    assert len(str(info.value)) < 200


@pytest.mark.parametrize("text, line, col, what", [
    ("model M\n  Real x;\n  function f\n    input Real u;\n    output Real y;\n"
     "  external \"C\";\n  end f;\nequation\n  x = 1;\nend M;\n", None, None, None),
    ("model B\n  Real x;\nexternal \"C\";\nend B;\nmodel M\n  extends B;\nend M;\n", 3, 1,
     "external function"),
])
def test_builder_refuses_an_external_clause_in_a_model(text, line, col, what):
    if what is None:                  # a function declared, never called: not refused
        load_modelica_text(text, "M", file="r.mo")
        return
    with pytest.raises(ModelicaError) as info:
        load_modelica_text(text, "M", file="r.mo")
    msg = str(info.value)
    assert msg.startswith(f"r.mo:{line}:{col}: unsupported Modelica construct: {what}"), msg


def test_statements_round_trip_through_pickle():
    import pickle
    cdef = parse_text("function f\nalgorithm\n  (a, , b) := g(1);\nend f;\n").classes[0]
    again = pickle.loads(pickle.dumps(cdef))
    (stmt,) = again.algorithms[0]
    assert isinstance(again.algorithms[0], A.Statements) and again.algorithms[0].pos == (2, 1)
    assert stmt.target.items[1] is None
