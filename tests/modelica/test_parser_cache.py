"""The disk cache of parsed Modelica files (keyed by content and parser version)."""

from __future__ import annotations

import os

import pytest

from bgmodelica.modelica import ast_cache, parser

TEXT = "package P\n  model M\n    Real x;\n  equation\n    x = 1;\n  end M;\nend P;\n"


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("BGMODELICA_CACHE", str(folder))
    parser._CACHE.clear()
    yield folder / "modelica-ast"
    parser._CACHE.clear()


def _entries(folder):
    return sorted(folder.glob("*/*.pickle"))


def test_second_parse_is_a_load(cache_dir, tmp_path, monkeypatch):
    f = tmp_path / "a.mo"
    f.write_text(TEXT)
    first = parser.parse_file(f)
    assert len(_entries(cache_dir)) == 1
    parser._CACHE.clear()
    monkeypatch.setattr(parser, "_parse", lambda *a: pytest.fail("parsed again"))
    second = parser.parse_file(f)
    assert second is not first
    assert second.classes[0].elements[0].name == "M"
    assert second.classes[0].elements[0].parent is second.classes[0]


def test_file_name_is_the_path_read_this_time(cache_dir, tmp_path):
    a, b = tmp_path / "a.mo", tmp_path / "sub" / "b.mo"
    b.parent.mkdir()
    a.write_text(TEXT)
    b.write_text(TEXT)
    parser.parse_file(a)
    tree = parser.parse_file(b)
    assert len(_entries(cache_dir)) == 1
    assert tree.file == str(b)
    p = tree.classes[0]
    assert p.file == str(b) and p.elements[0].file == str(b)


def test_corrupt_entry_is_ignored_and_rewritten(cache_dir, tmp_path):
    f = tmp_path / "a.mo"
    f.write_text(TEXT)
    parser.parse_file(f)
    (entry,) = _entries(cache_dir)
    entry.write_bytes(b"not a pickle")
    parser._CACHE.clear()
    tree = parser.parse_file(f)
    assert tree.classes[0].name == "P"
    assert entry.read_bytes() != b"not a pickle"
    parser._CACHE.clear()
    assert parser.parse_file(f).classes[0].name == "P"


def test_edited_file_is_parsed_again(cache_dir, tmp_path):
    f = tmp_path / "a.mo"
    f.write_text(TEXT)
    parser.parse_file(f)
    f.write_text(TEXT.replace("x = 1", "x = 2"))
    os.utime(f, ns=(1, 1))
    tree = parser.parse_file(f)
    assert tree.classes[0].elements[0].equations[0].rhs.value == 2
    assert len(_entries(cache_dir)) == 2


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs a non-root POSIX user")
def test_read_only_cache_dir_skips_caching(tmp_path, monkeypatch):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    monkeypatch.setenv("BGMODELICA_CACHE", str(ro))
    parser._CACHE.clear()
    f = tmp_path / "a.mo"
    f.write_text(TEXT)
    assert parser.parse_file(f).classes[0].name == "P"
    ro.chmod(0o700)


def test_unwritable_cache_is_silent(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("BGMODELICA_CACHE", str(blocker))   # a file, not a folder
    parser._CACHE.clear()
    f = tmp_path / "a.mo"
    f.write_text(TEXT)
    assert parser.parse_file(f).classes[0].name == "P"
    assert ast_cache.load(f.read_bytes(), "x.mo") is None
