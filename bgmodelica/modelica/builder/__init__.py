"""Instantiate Modelica classes as bgmodelica components.

Each Modelica class used by a model becomes a Python class created with ``type()``: a
:class:`~bgmodelica.Component` (or :class:`~bgmodelica.Connector`) subclass whose body holds
the declarations (``Parameter``, ``Variable``, ``Potential``, ``Flow``, ``Input``, ``Output``,
``Discrete``, ``Integer``, ``Boolean``; array elements as ``x[1]``, ``x[2]``...) and whose
``equations()`` / ``initial_equations()`` evaluate the class's Modelica equations (inherited
ones included) for the instance at hand. One Python class serves every instance with the same
structure (array sizes, conditional components); per-instance modifiers change the instance's
declarations, as ``Resistor(R=10)`` does in Python. Subcomponents are added to the instance,
component arrays as children named ``R[1]``, ``R[2]``...; MSL classes of :mod:`.msl` become
instances of the project's ``library`` classes.

Modelica semantics kept: modifiers are evaluated in the scope where they are written (outer
modifiers win over inner ones, ``each`` for arrays), parameters bound to expressions of other
parameters stay bound (changing one at simulation time updates the others), ``extends`` merges
the base class's elements and equations, structural values (array sizes, ``for`` ranges,
if-equations on parameters, conditional components) are evaluated when the model is built.
"""

from __future__ import annotations

from .base import NotConstant
from .classes import class_view, find_class, list_models
from .instantiate import experiment, instantiate
from .mods import top_mods

__all__ = ["NotConstant", "class_view", "experiment", "find_class", "instantiate", "list_models",
           "top_mods"]
