"""The cyclic garbage collector around the tool's large allocations.

Building and compiling a model allocate many long-lived objects and few cycles: a model of
10,000 sections is a million tracked objects. Left to the collector's usual policy, each
such block is scanned when it ends (a young collection of everything it made, 15-25 % of
the construction) and again as it ages, for no garbage found. :func:`gc_paused` pauses the
collector during such a block and, for a large one, moves what it made straight to the
oldest generation, whose scans are rare.

The oldest generation is collected in full only when what survived earlier collections has
grown by a quarter, and objects moved there this way are not counted in that growth: a model
tree is cyclic (symbols and their owners), so models built and dropped in a loop would pile
up uncollected. They are counted here instead, and :func:`collect_if_due`, called before a
model is built, collects in full once the moved objects outnumber those alive after the
last full collection (and a million): the amortized cost stays one scan per object.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["collect_if_due", "gc_paused", "pause", "resume"]

_LARGE = 100_000          # objects made by a block worth moving to the oldest generation
_MINIMUM = 1_000_000      # moved objects that never call for a full collection

_moved = 0                # objects moved to the oldest generation since the last full one
_alive = 0                # objects tracked after the last full collection made here


@contextmanager
def gc_paused(new_model: bool = False) -> Iterator[None]:
    """Pause the cyclic garbage collector (the graph algorithms and model construction
    allocate many small objects, which makes it trigger often for nothing). Usable as a
    decorator. A block that made many objects moves them to the oldest generation;
    ``new_model``: the block builds a model (see :func:`collect_if_due`)."""
    enabled = pause(new_model)
    try:
        yield
    finally:
        if enabled:
            resume()


def pause(new_model: bool = False) -> bool:
    """Pause the collector; whether it was running (then :func:`resume` it). Before a new
    model (``new_model``) the models dropped since the last full collection may be due."""
    if not gc.isenabled():
        return False
    if new_model:
        collect_if_due()
    gc.disable()
    return True


def resume() -> None:
    """Restart the collector paused by :func:`pause`, the objects made meanwhile moved to
    the oldest generation when they are many."""
    global _moved
    made = gc.get_count()[0]
    if made > _LARGE:
        gc.freeze()
        gc.unfreeze()
        _moved += made
    gc.enable()


def collect_if_due() -> None:
    """Collect in full when the objects moved by :func:`gc_paused` since the last full
    collection outnumber those then alive (and a million); nothing while the collector is
    paused or disabled."""
    global _alive
    if gc.isenabled() and _moved > max(_MINIMUM, _alive):
        gc.collect()
        _alive = len(gc.get_objects())


def _on_collection(phase: str, info: dict[str, Any]) -> None:
    """A full collection, ours or another's, clears the count of moved objects."""
    global _moved
    if phase == "stop" and info.get("generation") == 2:
        _moved = 0


gc.callbacks.append(_on_collection)
