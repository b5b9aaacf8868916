"""Bond-graph library: adapters to other domains and the paper's models."""

from .adapters import FlangeAdapter, PinAdapter
from .paper import (
    ARM_MODULI,
    DCMotor,
    DCMotorDrive,
    RotatingArm,
    TwoLinkArm,
    TwoLinkManipulator,
)

__all__ = ["FlangeAdapter", "PinAdapter", "DCMotor", "DCMotorDrive", "RotatingArm",
           "TwoLinkArm", "TwoLinkManipulator", "ARM_MODULI"]
