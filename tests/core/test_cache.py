"""Disk cache of compiled models: hits, misses on structure or code changes, parameter
values taken from the model asked for, damaged entries, the command line."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import cache as disk
from library.examples import RC, RCLadderVector


def entries(folder):
    return sorted(folder.glob("*/*.bgmc"))


def test_second_compile_is_a_load_with_identical_results(tmp_path):
    first = bg.compile(RCLadderVector(30), cache=tmp_path)
    assert "cache_store" in first.timings and len(entries(tmp_path)) == 1
    second = bg.compile(RCLadderVector(30), cache=tmp_path)
    assert set(second.timings) == {"cache_load"}
    a = bg.simulate(first, stop_time=0.5, interval=0.05)
    b = bg.simulate(second, stop_time=0.5, interval=0.05)
    assert all(np.array_equal(a[n], b[n]) for n in a.names)
    assert second.summary()["states"] == first.summary()["states"]


def test_an_entry_holds_the_model_symbols_not_the_whole_tree(tmp_path):
    """Eliminated alias variables are not stored: the flat models' symbols are rows of the
    models' own columns, not of flattening's vector of every symbol of the tree."""
    from library.examples import RCLadder

    first = bg.compile(RCLadder(40), cache=tmp_path)
    assert len(first.flat.aliases) > 100
    second = bg.compile(RCLadder(40), cache=tmp_path)
    assert set(second.timings) == {"cache_load"}
    for model in (second.flat, second.reduced.model):
        for items in (model.variables, model.parameters):
            rows = {v.at[0].numel() for v in items if v.at is not None}
            assert rows <= {len(items)}
    a = bg.simulate(first, stop_time=0.2, interval=0.02)
    b = bg.simulate(second, stop_time=0.2, interval=0.02)
    assert all(np.array_equal(a[n], b[n]) for n in a.names)


def test_parameter_values_come_from_the_model_not_the_entry(tmp_path):
    bg.compile(RC(), cache=tmp_path)
    hit = bg.compile(RC(**{"resistor.R": 500.0}), cache=tmp_path)    # tau = 0.5 s
    assert set(hit.timings) == {"cache_load"}
    res = bg.simulate(hit, stop_time=2.0, interval=0.1, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(res["capacitor.v"] - 10 * (1 - np.exp(-res.time / 0.5)))) < 1e-7
    assert res.parameters["resistor.R"] == 500.0


def test_structure_start_values_and_units_mode_are_part_of_the_key(tmp_path):
    keys = {disk.model_key(RCLadderVector(5)), disk.model_key(RCLadderVector(6)),
            disk.model_key(RCLadderVector(5, v=[0.0] * 5)), disk.model_key(RC())}
    assert len(keys) == 4
    assert disk.model_key(RCLadderVector(5, R=[2.0] * 5)) == disk.model_key(RCLadderVector(5))
    bg.compile(RC(), cache=tmp_path)
    assert "cache_store" in bg.compile(RC(), cache=tmp_path, units="off").timings


def test_a_code_change_misses(tmp_path, monkeypatch):
    pkg = tmp_path / "cachedmodels_pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    src = textwrap.dedent("""
        from bgmodelica import Component, Parameter, Variable, der

        class Decay(Component):
            x = Variable(start=1.0, fixed=True)
            a = Parameter(1.0, unit="1/s")

            def equations(self):
                yield der(self.x) == -{k} * self.a * self.x
        """)
    (pkg / "model.py").write_text(src.format(k=1.0))
    monkeypatch.syspath_prepend(str(tmp_path))
    mod = importlib.import_module("cachedmodels_pkg.model")
    store = tmp_path / "store"
    bg.compile(mod.Decay(), cache=store)
    (pkg / "model.py").write_text(src.format(k=2.0) + "\n# changed\n")
    mod = importlib.reload(mod)
    again = bg.compile(mod.Decay(), cache=store)
    assert "cache_store" in again.timings                       # a miss: recompiled
    res = bg.simulate(again, stop_time=1.0, interval=0.5, rtol=1e-10, atol=1e-12)
    assert res["x"][-1] == pytest.approx(np.exp(-2.0), rel=1e-8)


def test_uncacheable_model_compiles_without_an_entry(tmp_path):
    m = RC()
    m.helper = object()                       # nothing the key can describe
    with pytest.raises(disk.Uncacheable, match="helper"):
        disk.model_key(m)
    compiled = bg.compile(m, cache=tmp_path)
    assert "cache_store" not in compiled.timings and not entries(tmp_path)


def test_damaged_entry_is_recompiled_and_replaced(tmp_path):
    bg.compile(RC(), cache=tmp_path)
    (entry,) = entries(tmp_path)
    entry.write_bytes(b"not a pickle")
    again = bg.compile(RC(), cache=tmp_path)
    assert "cache_store" in again.timings
    assert set(bg.compile(RC(), cache=tmp_path).timings) == {"cache_load"}
    assert disk.clear(tmp_path) == 1 and not entries(tmp_path)


def test_cli_cache_flag(tmp_path):
    env_cmd = [sys.executable, "-m", "bgmodelica.cli", "check", "library.examples:RC",
               "--cache", "--json"]
    env = dict(os.environ, BGMODELICA_CACHE=str(tmp_path))
    for _ in range(2):
        out = subprocess.run(env_cmd, capture_output=True, text=True, check=True, env=env)
    assert '"cache_load"' in out.stdout and len(entries(tmp_path)) == 1


def test_a_compiled_model_referring_to_a_component_is_not_stored(tmp_path):
    """The store refuses objects it cannot describe (a model element, a CasADi Function)
    instead of pickling them along."""
    compiled = bg.compile(RC())
    compiled.dae.hybrid = RC()            # a component where none may be
    assert disk.store(compiled, tmp_path, "k" * 64) is None
    assert not list(tmp_path.rglob("*.bgmc"))


def test_imperative_equations_key_by_dotted_names():
    """An imperative equation enters the key with the dotted names of its symbols (a
    derivative as ``der(...)``); one that uses a symbol of another model is uncacheable."""
    from bgmodelica import Component, Variable, der

    class Tank(Component):
        h = Variable(start=1.0)

    def model(rate: float, other: Tank | None = None) -> Component:
        m = Component(name="Tanks")
        a, b = m.add("a", Tank()), m.add("b", Tank())
        m.equation(der(a.h) == -rate * a.h, b.h == (other or a).h)
        return m

    assert disk.model_key(model(1.0)) == disk.model_key(model(1.0))
    assert disk.model_key(model(1.0)) != disk.model_key(model(2.0))
    with pytest.raises(disk.Uncacheable, match="not part of the model"):
        disk.model_key(model(1.0, other=Tank()))
    m = model(1.0)
    writer = disk._KeyWriter({id(m): "", id(m.a): "a", id(m.b): "b"})
    assert writer.name(m.a._symbols["h"].der) == "der(a.h)"


def test_an_entry_that_loads_slower_than_compiling_is_dropped(tmp_path, monkeypatch):
    first = bg.compile(RCLadderVector(30), cache=tmp_path)
    built = sum(v for k, v in first.timings.items() if k != "cache_store")
    seen = []

    def slow(compile_seconds, load_seconds):          # as if loading had cost more
        seen.append((compile_seconds, load_seconds))
        return False

    monkeypatch.setattr(disk, "pays", slow)
    hit = bg.compile(RCLadderVector(30), cache=tmp_path)     # this load still counts
    assert set(hit.timings) == {"cache_load"}
    assert seen == [(pytest.approx(built, rel=1e-12), hit.timings["cache_load"])]
    assert not entries(tmp_path)
    (note,) = tmp_path.glob("*/*.nocache")
    assert set(json.loads(note.read_text())) == {"compile_s", "load_s"}
    monkeypatch.undo()
    third = bg.compile(RCLadderVector(30), cache=tmp_path)   # compiled, nothing stored
    assert "cache_skipped" in third.timings and "flatten" in third.timings
    assert "cache_store" not in third.timings and not entries(tmp_path)
    a = bg.simulate(first, stop_time=0.5, interval=0.05)
    b = bg.simulate(third, stop_time=0.5, interval=0.05)
    assert all(np.array_equal(a[n], b[n]) for n in a.names)
    disk.clear(tmp_path)                                     # the note goes too
    assert not list(tmp_path.glob("*/*.nocache"))
    assert "cache_store" in bg.compile(RCLadderVector(30), cache=tmp_path).timings


def test_only_a_clear_loss_drops_an_entry():
    assert disk.pays(1.0, 0.9) and disk.pays(1.0, 1.0) and not disk.pays(1.0, 1.2)
    assert disk.pays(0.01, disk.MIN_LOSS)        # small models: noise, not a loss
    assert not disk.pays(0.01, disk.MIN_LOSS + 0.01)
