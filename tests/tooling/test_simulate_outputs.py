"""``simulate --outputs`` (names and globs) and the bulk CSV writer."""

from __future__ import annotations

import csv

import numpy as np

import bgmodelica as bg
from bgmodelica.cli import main
from library.examples.circuits import RCLadder

MODEL = "library.examples.circuits:RCLadder"


def test_outputs_by_name_and_glob(tmp_path, capsys):
    out = tmp_path / "ladder.csv"
    code = main(["simulate", MODEL, "--arg", "n=12", "--outputs", "C1*.v,source.i",
                 "--outputs", "R2.i", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    header = out.read_text().splitlines()[0].split(",")
    assert sorted(header) == sorted(["time", "C1.v", "C10.v", "C11.v", "C12.v", "source.i",
                                     "R2.i"])
    ref = bg.simulate(RCLadder(12))
    back = bg.Result.read_csv(out)
    for name in header[1:]:
        np.testing.assert_allclose(back[name], ref[name], rtol=1e-11, atol=1e-12)


def test_unknown_output_pattern_is_one_line(tmp_path, capsys):
    code = main(["simulate", MODEL, "--arg", "n=3", "--outputs", "C1.vv",
                 "-o", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert "--outputs 'C1.vv'" in err and "did you mean C1.v" in err
    assert not (tmp_path / "x.csv").exists()


def test_bulk_csv_matches_the_csv_module(tmp_path):
    res = bg.simulate(RCLadder(5), stop_time=0.5)
    path = res.to_csv(tmp_path / "r.csv", units=True)
    with path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["time", *res.all_names()]
    table = np.array(rows[2:], dtype=float)
    assert table.shape == (len(res.time), 1 + len(res.all_names()))
    expected = np.column_stack([res.time] + [res[n] for n in res.all_names()])
    np.testing.assert_array_equal(table, np.array([[float(f"{v:.12g}") for v in r]
                                                   for r in expected]))


def test_bgmodelica_alone_prints_the_commands(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    assert "simulate" in out and "export" in out and "check" in out


def test_result_repr_is_one_short_line():
    res = bg.simulate(RCLadder(200), stop_time=2.0)
    text = repr(res)
    assert text == f"Result(RCLadder: {len(res.all_names())} variables, 501 points, t = 0..2 s)"
    assert len(text) < 80
