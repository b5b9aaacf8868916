"""Algorithm sections, external clauses and class prefixes in the syntax tree."""

from __future__ import annotations

import pytest

from bgmodelica.modelica import ast as A
from bgmodelica.modelica.errors import ModelicaSyntaxError
from bgmodelica.modelica.parser import parse_text


def _cls(text: str) -> A.ClassDef:
    return parse_text(text, "t.mo").classes[0]


def _stmts(body: str, decls: str = "Real x; Real y; Integer i;") -> tuple:
    cdef = _cls(f"function f\n  {decls}\nalgorithm\n{body}\nend f;\n")
    assert len(cdef.algorithms) == 1
    return cdef.algorithms[0]


def test_assignment_and_call():
    a, c = _stmts("  x := 2*y;\n  assert(x > 0, \"positive\");")
    assert isinstance(a, A.Assign) and a.target.dotted == "x" and isinstance(a.value, A.BinOp)
    assert isinstance(c, A.StmtCall) and c.call.func.dotted == "assert"
    assert a.pos == (4, 3) and c.pos == (5, 3)


def test_section_position_and_statements_tuple():
    cdef = _cls("model M\n  Real x;\nalgorithm\n  x := 1;\nalgorithm\nend M;\n")
    assert [len(s) for s in cdef.algorithms] == [1, 0]
    assert cdef.algorithms[0].pos == (3, 1) and cdef.algorithms[1].pos == (5, 1)
    assert isinstance(cdef.algorithms[0], tuple)


def test_initial_algorithm():
    cdef = _cls("model M\n  Real x;\ninitial algorithm\n  x := 1;\nend M;\n")
    assert cdef.algorithms == [] and len(cdef.initial_algorithms) == 1


def test_while_for_break_return():
    (w, f) = _stmts("  while x < 10 loop\n    x := x + 1;\n    if x > 5 then break; end if;\n"
                    "  end while;\n  for k in 1:3, j loop\n    return;\n  end for;")
    assert isinstance(w, A.StmtWhile) and isinstance(w.condition, A.BinOp)
    assert isinstance(w.body[0], A.Assign) and isinstance(w.body[1], A.StmtIf)
    assert isinstance(w.body[1].branches[0][1][0], A.Break)
    assert isinstance(f, A.StmtFor) and [n for n, _ in f.indices] == ["k", "j"]
    assert isinstance(f.indices[0][1], A.Range) and f.indices[1][1] is None
    assert isinstance(f.body[0], A.Return)


def test_if_elseif_else():
    (s,) = _stmts("  if x > 1 then\n    y := 1;\n  elseif x > 0 then\n    y := 2;\n    y := 3;\n"
                  "  else\n    y := 4;\n  end if;")
    assert isinstance(s, A.StmtIf) and len(s.branches) == 2
    assert [len(b) for _, b in s.branches] == [1, 2] and len(s.otherwise) == 1


def test_when_elsewhen():
    (s,) = _stmts("  when x > 1 then\n    reinit(x, 0);\n  elsewhen y > 1 then\n    y := 0;\n"
                  "  end when;")
    assert isinstance(s, A.StmtWhen) and len(s.branches) == 2
    assert isinstance(s.branches[0][1][0], A.StmtCall)
    assert s.branches[0][1][0].call.func.dotted == "reinit"


def test_tuple_assignment_with_omitted_outputs():
    (s, t) = _stmts("  (x, , y) := g(1, n=2);\n  (x) := g(1);")
    assert isinstance(s, A.Assign) and isinstance(s.target, A.TupleExpr)
    assert [r.dotted if r else None for r in s.target.items] == ["x", None, "y"]
    assert isinstance(s.value, A.Call) and s.value.kwargs.keys() == {"n"}
    assert isinstance(t.target, A.TupleExpr) and len(t.target.items) == 1


def test_tuple_equation():
    cdef = _cls("model M\n  Real a, b;\nequation\n  (a, b) = g(time);\n  c = (a);\nend M;\n")
    eq, eq2 = cdef.equations
    assert isinstance(eq, A.EqSimple) and isinstance(eq.lhs, A.TupleExpr)
    assert isinstance(eq.rhs, A.Call) and isinstance(eq2.rhs, A.Ref)


def test_external_with_output_and_args():
    cdef = _cls('function f\n  input Real u;\n  output Real y;\nexternal "C" y = cf(u, 2)\n'
                '  annotation(Library="m");\nend f;\n')
    ext = cdef.external
    assert ext.language == "C" and ext.output.dotted == "y" and ext.function == "cf"
    assert len(ext.args) == 2 and ext.annotation.args[0].name == "Library"
    assert ext.pos == (4, 1)


def test_external_defaults():
    cdef = _cls("function f\n  input Real u;\n  output Real y;\nexternal;\nend f;\n")
    assert cdef.external.function is None and cdef.external.language == "C"
    cdef = _cls('function f\n  input Real u;\nexternal "FORTRAN 77" g(u);\nend f;\n')
    assert cdef.external.language == "FORTRAN 77" and cdef.external.output is None


@pytest.mark.parametrize("prefix, purity, kind", [
    ("pure function", "pure", "function"), ("impure function", "impure", "function"),
    ("operator record", "", "operator record"), ("operator function", "", "operator function"),
    ("partial impure function", "impure", "function"), ("operator", "", "operator"),
])
def test_class_prefixes(prefix, purity, kind):
    cdef = _cls(f"{prefix} f\nend f;\n")
    assert (cdef.purity, cdef.kind) == (purity, kind)
    assert cdef.partial == prefix.startswith("partial")


def test_encapsulated_and_protected():
    cdef = _cls("encapsulated package P\n  model A end A;\nprotected\n  constant Real c = 1;\n"
                "  model B end B;\npublic\n  Real d;\nend P;\n")
    assert cdef.encapsulated and cdef.protected == frozenset({"c", "B"})
    assert [e.name for e in cdef.elements] == ["A", "c", "B", "d"]
    assert not _cls("model M end M;").encapsulated


def test_partial_application_and_named_arguments():
    (s,) = _stmts("  x := h(function k(w=5), 0, tol=1e-3);")
    call = s.value
    assert isinstance(call.args[0], A.PartialFunction) and call.args[0].func == "k"
    assert isinstance(call.args[0].kwargs["w"], A.Num) and "tol" in call.kwargs


def test_class_extends_and_import_list():
    pkg = _cls("package P\n  import A.B.{c, d};\n  redeclare model extends Base(x=1) \"d\"\n"
               "  end Base;\nend P;\n")
    imports = [e for e in pkg.elements if isinstance(e, A.Import)]
    assert [i.name for i in imports] == ["A.B.c", "A.B.d"]
    ext = pkg.elements[-1]
    assert ext.name == "Base" and ext.class_extends.args[0].name == "x"
    assert ext.description == "d" and "redeclare" in ext.element_prefixes


def test_constrainedby_description():
    cdef = _cls("model M\n  replaceable package Medium = P constrainedby Q\n"
                "    \"Medium\" annotation(choicesAllMatching=true);\n"
                "  replaceable R r constrainedby S(k=1) \"the r\";\nend M;\n")
    med, r = cdef.elements
    assert med.description == "Medium" and med.annotation is not None
    assert r.constrainedby == "S" and r.description == "the r"


@pytest.mark.parametrize("text", [
    "model M\n  Real x;\nalgorithm\n  x = 1;\nend M;\n",
    "function f\nalgorithm\n  (x, y) := 3;\nend f;\n",
    "model M\n  Real x;\nalgorithm\n  while x loop\nend M;\n",
])
def test_malformed_statements_positioned(text):
    with pytest.raises(ModelicaSyntaxError) as info:
        parse_text(text, "bad.mo")
    assert str(info.value).startswith("bad.mo:") and "\n" not in str(info.value)


def test_class_extends_end_name_mismatch():
    with pytest.raises(ModelicaSyntaxError) as info:
        parse_text("package P\n  redeclare model extends A\n  end B;\nend P;\n", "bad.mo")
    assert str(info.value).startswith("bad.mo:3:7: class A is closed by 'end B'")


def test_builder_refuses_class_extends():
    from bgmodelica.modelica import ModelicaError, load_modelica_text
    text = ("package P\n  model A\n    Real x;\n  equation\n    x = 1;\n  end A;\n"
            "  model extends A\n  end A;\nend P;\n")
    with pytest.raises(ModelicaError) as info:
        load_modelica_text(text, "P.A", file="e.mo")
    assert "unsupported Modelica construct: class extends" in str(info.value)
