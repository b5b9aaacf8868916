"""Every code block of the README and of the docs runs.

- ```` ```python ```` blocks of one file run in order in one namespace (a page reads like a
  session), in a temporary folder: files they write land there.
- ```` ```bash ```` blocks whose commands all start with ``bgmodelica`` run command by command
  (continuation lines joined, ``#`` comments dropped) in a temporary folder that links the
  read-only folders ``library/``, ``docs/``, ``tests/`` and ``benchmarks/``.
- A block is skipped only with an explicit marker on the line before its fence (blank lines
  allowed between): ``<!-- test: skip (reason) -->``. Any other python or bash block that
  cannot run (a bash block with another command) fails the inventory test, so no example
  goes unchecked by accident.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FILES = [ROOT / "README.md", ROOT / "fmus" / "README.md",
         *sorted((ROOT / "docs").rglob("*.md"))]
#: read-only folders of the repository that examples name by relative path (``fmus/`` is not
#: linked: examples write there)
LINKED = ("library", "docs", "tests", "benchmarks")
SKIP = re.compile(r"<!--\s*test:\s*skip\b(.*?)-->")
FENCE = re.compile(r"^```([A-Za-z0-9_+-]*)\s*$")


@dataclass
class Block:
    path: Path
    line: int            # 1-based line of the opening fence
    lang: str
    code: str
    skip: str | None     # the reason given by the marker, or None

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def blocks_of(path: Path) -> list[Block]:
    lines = path.read_text().splitlines()
    out: list[Block] = []
    k = 0
    while k < len(lines):
        m = FENCE.match(lines[k])
        if not m:
            k += 1
            continue
        lang, start = m.group(1).lower(), k
        end = k + 1
        while end < len(lines) and not lines[end].startswith("```"):
            end += 1
        prev = start - 1
        while prev >= 0 and not lines[prev].strip():
            prev -= 1
        marker = SKIP.search(lines[prev]) if prev >= 0 else None
        out.append(Block(path, start + 1, lang, "\n".join(lines[start + 1:end]) + "\n",
                         marker.group(1).strip(" ()") or "marked" if marker else None))
        k = end + 1
    return out


def commands(code: str) -> list[str]:
    """The commands of a bash block: continuation lines joined, comments and blanks dropped."""
    joined = code.replace("\\\n", " ")
    out = []
    for line in joined.splitlines():
        words = shlex.split(line, comments=True)
        if words:
            out.append(line)
    return out


def runnable_bash(block: Block) -> bool:
    cmds = commands(block.code)
    return bool(cmds) and all(shlex.split(c, comments=True)[0] == "bgmodelica" for c in cmds)


ALL = [b for f in FILES if f.exists() for b in blocks_of(f)]
PYTHON_FILES = sorted({b.path for b in ALL if b.lang == "python" and not b.skip})
BASH = [b for b in ALL if b.lang in ("bash", "sh", "console", "shell") and not b.skip]


def test_every_block_runs_or_is_marked():
    assert (ROOT / "README.md") in {b.path for b in ALL}
    unrunnable = [b.where for b in BASH if not runnable_bash(b)]
    assert not unrunnable, ("bash blocks with commands other than `bgmodelica` need a "
                            "'<!-- test: skip (reason) -->' marker: " + ", ".join(unrunnable))
    unknown = [b.where for b in ALL if b.lang in ("py", "python3", "ipython")]
    assert not unknown, f"write ```python for Python blocks: {unknown}"


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    for name in LINKED:
        (tmp_path / name).symlink_to(ROOT / name, target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("path", PYTHON_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_python_blocks(path, workdir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    namespace: dict = {"__name__": f"__docs_{path.stem}__"}
    try:
        for block in blocks_of(path):
            if block.lang != "python" or block.skip:
                continue
            code = compile(block.code, block.where, "exec")
            try:
                exec(code, namespace)  # noqa: S102 -- the documentation's own examples
            except Exception as err:
                raise AssertionError(f"{block.where}: {type(err).__name__}: {err}") from err
    finally:
        plt.close("all")


@pytest.mark.parametrize("block", [b for b in BASH if runnable_bash(b)],
                         ids=lambda b: b.where)
def test_bash_blocks(block, workdir, capsys):
    """Each command runs through :func:`bgmodelica.cli.main` in this process (as the
    ``bgmodelica`` script would, without paying the interpreter start-up per command)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from bgmodelica.cli import main

    try:
        for cmd in commands(block.code):
            args = shlex.split(cmd, comments=True)[1:]
            code = main(args)
            out = capsys.readouterr()
            assert code == 0, (f"{block.where}: `{cmd.strip()}` exited {code}:\n"
                               f"{out.out[-2000:]}\n{out.err[-2000:]}")
    finally:
        plt.close("all")
