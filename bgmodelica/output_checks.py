"""Checks of what a run writes and shows: output and plot files (writable, a known format,
not the same file twice), plot variables, and ``--outputs`` patterns (names and globs).

Every check raises :class:`~bgmodelica.errors.OptionError` naming the option and the file or
variable at fault.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .errors import OptionError


def check_output_file(path: str | Path, option: str = "-o") -> Path:
    """Refuse an output path that is a directory, lies under a file, or cannot be written;
    nothing is created or changed."""
    path = Path(path)
    if str(path) == "" or path.name in ("", ".", ".."):
        raise OptionError(f"{option} {str(path)!r}: not a file name")
    if len(os.fsencode(path.name)) > 255:          # the usual NAME_MAX of file systems
        short = path.name[:40] + "..." + path.name[-8:]
        raise OptionError(f"{option} {short}: file name too long ({len(os.fsencode(path.name))}"
                          " bytes, at most 255); give a shorter one with -o FILE")
    if path.is_dir():
        raise OptionError(f"{option} {path}: is an existing directory, not a file")
    if path.exists() and not path.is_file():
        import stat

        if not stat.S_ISCHR(path.stat().st_mode):       # /dev/null is fine
            raise OptionError(f"{option} {path}: exists and is not a regular file")
    parent = path.parent if str(path.parent) else Path(".")
    probe = parent
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise OptionError(f"{option} {path}: {probe} is a file, not a directory")
    if path.exists():
        if not os.access(path, os.W_OK):
            raise OptionError(f"{option} {path}: the file is not writable")
        return path
    try:
        fd, tmp = tempfile.mkstemp(dir=probe, prefix=".bgm-probe-")
    except OSError as err:
        raise OptionError(f"{option} {path}: cannot write in {probe} "
                          f"({err.strerror or err})") from None
    os.close(fd)
    os.unlink(tmp)
    return path


def plot_formats() -> list[str]:
    from matplotlib.backend_bases import FigureCanvasBase

    return sorted(FigureCanvasBase.get_supported_filetypes())


def check_plot_file(path: str | Path, option: str = "--plot") -> Path:
    """A writable plot path whose extension matplotlib can produce."""
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    formats = plot_formats()
    if not fmt:
        raise OptionError(f"{option} {path}: no file extension; use one of "
                          f"{', '.join('.' + f for f in formats)}")
    if fmt not in formats:
        raise OptionError(f"{option} {path}: unknown plot format '.{fmt}'; use one of "
                          f"{', '.join('.' + f for f in formats)}")
    return check_output_file(path, option)


def check_distinct_outputs(*paths: tuple[str, str | Path | None]) -> None:
    """No two outputs (``(option, path)``) may be the same file."""
    seen: dict[Path, str] = {}
    for option, p in paths:
        if p is None:
            continue
        key = Path(p).resolve()
        if key in seen:
            raise OptionError(f"{option} {p}: the same file as {seen[key]}")
        seen[key] = f"{option} {p}"


def check_plot_vars(names: Sequence[str], compiled: Any) -> None:
    """Every name in ``names`` is a variable, alias or parameter of ``compiled``."""
    import difflib

    dae = compiled.dae
    known = set(dae.names) | set(getattr(dae, "aliases", {}) or {}) \
        | set(compiled.flat.aliases) | {q.name for q in compiled.reduced.model.parameters} \
        | {"time"}
    for n in names:
        if n not in known:
            close = difflib.get_close_matches(n, sorted(known), n=4, cutoff=0.6)
            hint = f"; did you mean {', '.join(close)}?" if close else ""
            raise OptionError(f"--plot-vars: {n!r} is not a variable of {compiled.name}{hint}")


def _glob(pattern: str) -> Any:
    """A dotted-name glob as a regular expression: ``*`` and ``?`` stay inside one part of
    the name (``C*.v`` is ``C1.v``, not ``C1.n.v``), ``**`` crosses dots."""
    import re

    parts = re.split(r"(\*\*|\*|\?)", pattern)
    table = {"**": ".*", "*": "[^.]*", "?": "[^.]"}
    return re.compile("".join(table.get(x, re.escape(x)) for x in parts))


def expand_outputs(patterns: Sequence[str], compiled: Any) -> list[str]:
    """The variable names matching ``patterns`` (names or globs, comma-separated items
    allowed; see :func:`_glob`), in model order; :class:`OptionError` naming a pattern that
    matches nothing."""
    import difflib

    names = list(compiled.dae.names) + sorted(getattr(compiled.dae, "aliases", {}) or {})
    out: list[str] = []
    seen: set[str] = set()
    for item in patterns:
        for pat in (p.strip() for p in item.split(",")):
            if not pat:
                continue
            if any(c in pat for c in "*?"):
                match = _glob(pat).fullmatch
                hits = [n for n in names if match(n)]
            else:
                hits = [pat] if pat in names else []
            if not hits:
                close = difflib.get_close_matches(pat, names, n=3)
                raise OptionError(f"--outputs {pat!r}: no such variable"
                                  + (f"; did you mean {', '.join(close)}?" if close else ""))
            for n in hits:
                if n not in seen:
                    seen.add(n)
                    out.append(n)
    return out
