"""The public objects print as one short line at a prompt (their full content is in their
attributes, ``summary()`` and the notebook views)."""

from __future__ import annotations

import re

import bgmodelica as bg
from library.examples import RCLadder


def test_compiled_model_and_its_stages_print_one_short_line():
    model = bg.compile(RCLadder(n=50))
    text = repr(model)
    assert re.fullmatch(r"CompiledModel\(RCLadder: 50 states, \d+ algebraic, \d+ parameters, "
                        r"compiled in [0-9.e-]+ s\)", text), text
    for part in (model.flat, model.reduced, model.sorted, model.dae, model.balance,
                 bg.flatten(RCLadder(n=50))):
        shown = repr(part)
        assert "\n" not in shown and len(shown) < 160, shown
    assert "<table" in model._repr_html_()            # the rich view stays rich
