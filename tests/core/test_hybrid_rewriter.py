"""The hybrid rewriter's memo must not mistake a new expression for a freed one at the same
address (an if-equation branch residual is a temporary: a wrong hit swapped equations)."""

from bgmodelica.core.expr import Op
from bgmodelica.core.flatten_hybrid import HybridDraft, _Rewriter
from bgmodelica.core.variables import Symbol, Variable


def test_temporaries_rewritten_one_by_one_keep_their_own_terms():
    x = Symbol("x", Variable(), owner=None)
    rewriter = _Rewriter(HybridDraft())
    for k in range(200):
        # rewritten (its relation becomes a slot), so the result is a new node and the
        # temporary itself is freed after each round
        temp = Op("add", (Op("<", (x.leaf, 1.0)), float(k)))
        out = rewriter.rewrite(temp, "here")
        assert out.args[1] == float(k), f"round {k} got the terms of another expression"
