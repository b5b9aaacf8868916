"""Browsing commands of the ``bgmodelica`` command line: ``info MODEL`` and ``list [DOMAIN]``.

``info`` prints a model's parameters, inputs, outputs and states with units, defaults and
descriptions (like ``fmpy info``; ``--json`` for machines, ``--no-compile`` to skip the
compilation and the states). ``list`` browses the component library (``library/``): without
an argument the domains, with one (``thermal``, ``examples``, ``examples.hybrid``) the
components with the first line of their documentation and the reference to pass as MODEL.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from typing import Any


def cmd_info(args: argparse.Namespace) -> int:
    from .cli import _model_kwargs
    from .info import format_info, model_info
    from .loader import load_model

    model = load_model(args.model, **_model_kwargs(args.arg))
    info = model_info(model, compile_model=not args.no_compile)
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        print(format_info(info), end="")
    return 0


def cmd_list(args: argparse.Namespace) -> int:
    from .info import format_index, library_index

    index = library_index(args.domain)
    if args.json:
        print(json.dumps(index, indent=2))
    else:
        print(format_index(index), end="")
    return 0


def register(sub: Any, model_args: Callable[[argparse.ArgumentParser], None]) -> None:
    """Add ``info`` and ``list`` to the ``bgmodelica`` sub-command parser."""
    inf = sub.add_parser("info", help="parameters, inputs, outputs and states of a model")
    model_args(inf)
    inf.add_argument("--json", action="store_true", help="machine-readable output")
    inf.add_argument("--no-compile", action="store_true",
                     help="do not compile (faster; no states or structural index)")
    inf.set_defaults(func=cmd_info)
    lst = sub.add_parser("list", help="browse the component library")
    lst.add_argument("domain", nargs="?", default=None,
                     help="a library module (thermal, electrical, examples.hybrid, ...)")
    lst.add_argument("--json", action="store_true", help="machine-readable output")
    lst.set_defaults(func=cmd_list)


def autocomplete(parser: argparse.ArgumentParser) -> None:
    """Shell completion through ``argcomplete`` when it is installed (``pip install
    argcomplete; eval "$(register-python-argcomplete bgmodelica)"``); nothing otherwise."""
    try:
        import argcomplete
    except ImportError:
        return
    argcomplete.autocomplete(parser)
