"""Exception types. Every message speaks in model terms: component path, variable, equation."""

from __future__ import annotations


class ModelError(Exception):
    """Base class of every error bgmodelica raises about a model or its inputs."""


class DeclarationError(ModelError):
    """A component is declared or constructed wrongly (unknown modifier, bad value...)."""


class DuplicateNameError(DeclarationError):
    """Two subcomponents or declarations of one component share a name."""


class ConnectError(ModelError):
    """Two connectors cannot be connected (incompatible types, flow to potential...)."""


class EquationError(ModelError):
    """An equation is malformed (not ``lhs == rhs``, no unknowns, non-scalar...)."""


class UnitError(ModelError):
    """The units of an equation do not agree (names the component, the equation as written
    and the two units), or a value's unit cannot be converted to the declared one."""


class UnbalancedModelError(ModelError):
    """The number of equations differs from the number of unknowns, or the system is
    structurally singular. ``missing`` lists variables no equation determines, ``surplus`` the
    equations that over-determine the system (both as human-readable names with origins)."""

    def __init__(self, message: str, missing: list[str] | None = None,
                 surplus: list[str] | None = None) -> None:
        super().__init__(message)
        self.missing = missing or []
        self.surplus = surplus or []


class InitializationError(ModelError):
    """The initial-value problem is over- or under-determined or has no solution."""


class ParameterError(ModelError):
    """A parameter or start-value override names nothing, or its value is not a number."""


class ModelLoadError(ModelError):
    """A ``path/file.py:Name`` or ``module:Name`` model reference cannot be loaded."""


class SimulationError(ModelError):
    """The integrator failed. ``result`` holds the trajectory up to ``time_reached``."""

    def __init__(self, message: str, time_reached: float, result: object | None = None) -> None:
        super().__init__(message)
        self.time_reached = time_reached
        self.result = result


class AssertionViolation(SimulationError):
    """A model assertion (Modelica ``assert``) is false: the run stops at that output time;
    ``result`` holds the rows before it."""


class OptionError(ParameterError):
    """A simulation or command-line option is unusable (stop time, interval, tolerances,
    output file, plot variables or format, ``--arg`` value); the message names the option."""


class StateSelectError(DeclarationError):
    """``state_select`` declarations that contradict each other or the model's structure."""


class UserCodeError(ModelError):
    """User code raised an exception while a model was built (a constructor, an
    ``equations()`` method, a model file's module code). ``path`` is the component path,
    ``location`` the user's ``file:line``, ``__cause__`` the original exception."""

    def __init__(self, message: str, path: str = "", location: str = "") -> None:
        super().__init__(message)
        self.path = path
        self.location = location
