"""Bond-graph library: adapters to other domains, the paper's models and switched (hybrid)
bond graphs."""

from .adapters import FlangeAdapter, PinAdapter
from .paper import (
    ARM_MODULI,
    DCMotor,
    DCMotorDrive,
    RotatingArm,
    TwoLinkArm,
    TwoLinkManipulator,
)
from .switched import SwitchedDCMotor, SwitchedRC, SwitchedRL

__all__ = ["FlangeAdapter", "PinAdapter", "DCMotor", "DCMotorDrive", "RotatingArm",
           "TwoLinkArm", "TwoLinkManipulator", "ARM_MODULI", "SwitchedRL", "SwitchedRC",
           "SwitchedDCMotor"]
