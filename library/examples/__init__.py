"""Example models: circuits, DC motor drives, rotational mechanics.

Each is a :class:`bgmodelica.Component` class (``RCLadder`` takes the number of sections).

    import bgmodelica as bg
    from library.examples import RC
    result = bg.simulate(RC(), stop_time=5.0)
"""

from .circuits import RC, RCLadder, RCLadderArrays, RCLadderVector, SeriesRLC
from .mechanics import GearedInertias, TorsionOscillator
from .motors import DCMotor, PIDSpeedControl

__all__ = ["RC", "SeriesRLC", "RCLadder", "RCLadderArrays", "RCLadderVector",
           "DCMotor", "PIDSpeedControl", "GearedInertias",
           "TorsionOscillator"]

#: Every example by name, with the constructor to call.
EXAMPLES = {name: globals()[name] for name in __all__}
