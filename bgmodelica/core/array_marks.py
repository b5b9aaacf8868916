"""Arrays of leaves known by construction (no Python loop over their elements needed).

A declared array (``Variable(shape=n)``), the derivatives of one and the arrays a group of
components written once reads hold leaves only; most also hold one unit. They are recorded
here by the id of their numpy array of leaves, weakly: block lowering and the unit check
then read one element instead of all of them.
"""

from __future__ import annotations

import weakref

import numpy as np

#: arrays of leaves and, among them, those of one unit
LEAVES: weakref.WeakValueDictionary[int, np.ndarray] = weakref.WeakValueDictionary()
ONE_UNIT: weakref.WeakValueDictionary[int, np.ndarray] = weakref.WeakValueDictionary()


def mark_leaves(items: np.ndarray, one_unit: bool) -> None:
    """Record that ``items`` (a numpy array owning its data) holds leaves only, and whether
    they share one unit."""
    LEAVES[id(items)] = items
    if one_unit:
        ONE_UNIT[id(items)] = items


def marked(items: np.ndarray, registry: weakref.WeakValueDictionary) -> bool:
    """Whether ``items``, or the array it is a view of, is in ``registry``."""
    base = items.base if isinstance(items.base, np.ndarray) else items
    return registry.get(id(base)) is base


def is_declared(items: np.ndarray) -> bool:
    """Whether ``items``, or the array it is a view of, holds the leaves of one declared
    array or of their derivatives (:func:`mark_leaves`)."""
    return marked(items, LEAVES)


def has_one_unit(items: np.ndarray) -> bool:
    """Whether ``items``, or the array it is a view of, holds leaves of one unit
    (:func:`mark_leaves`)."""
    return marked(items, ONE_UNIT)
