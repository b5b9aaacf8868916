"""Griffe extension for the docs build (mkdocs.yml): the docstrings use Sphinx roles
(``:class:`~pkg.Name```, ``:func:`name```, ``:mod:`...```); render them as inline code
(``Name``; the ``~`` keeps the last component, as Sphinx does)."""

from __future__ import annotations

import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|exc|obj|ref):`(~?)([^`<]+?)(?:\s*<[^>]+>)?`")


def _replace(match: re.Match) -> str:
    tilde, target = match.groups()
    target = target.strip()
    if tilde:
        target = target.split(".")[-1]
    return f"`{target}`"


class RstRoles(griffe.Extension):
    """Rewrite Sphinx cross-reference roles into Markdown inline code."""

    def on_instance(self, *, obj: Any, **kwargs: Any) -> None:
        doc = getattr(obj, "docstring", None)
        if doc is not None and doc.value and ":" in doc.value:
            doc.value = _ROLE.sub(_replace, doc.value)
