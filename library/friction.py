"""The stick/slip state machine of the Modelica Standard Library's ``PartialFriction``,
shared by the translational and rotational friction elements (the same logic on forces or
torques, velocities or angular velocities).

Modes: ``FORWARD`` = 1 (sliding, relative velocity > 0), ``STUCK`` = 0, ``BACKWARD`` = -1
(sliding, < 0); ``UNKNOWN`` = 3 is the start value (the mode follows from the start velocity).
See Otter, Elmqvist & Mattsson, "Hybrid Modeling in Modelica based on the Synchronous Data
Flow Principle" (CACSD'99).
"""

from __future__ import annotations

from typing import Any

from bgmodelica import eq, if_else, initial, pre

__all__ = ["UNKNOWN", "FORWARD", "STUCK", "BACKWARD", "stick_slip_equations"]

UNKNOWN = 3     # before initialization: the mode follows from the start velocity
FORWARD = 1     # relative velocity > 0, sliding forward
STUCK = 0       # relative velocity = 0: locked, or about to start sliding
BACKWARD = -1   # relative velocity < 0, sliding backward


def stick_slip_equations(el: Any, v_rel: Any, a_rel_scaled: Any, lim0: Any, lim_max: Any,
                         v_small: Any, forward_allowed: Any = None,
                         backward_allowed: Any = None):
    """Equations of ``el.startForward``, ``el.startBackward``, ``el.locked``, ``el.mode`` and
    the relative acceleration (``a_rel_scaled``: ``a_relfric`` divided by its unit) in terms
    of the dimensionless path parameter ``el.sa``.

    v_rel: relative velocity of the frictional surfaces; lim0, lim_max: sliding and
    maximum static friction divided by their unit; v_small: velocity jump that restarts
    sliding the other way; forward_allowed / backward_allowed: optional Boolean expressions
    that block sliding in one direction (hard stops)."""
    pre_mode = pre(el.mode)
    break_fwd = (el.sa > lim_max) | (pre(el.startForward) & (el.sa > lim0))
    break_bwd = (el.sa < -lim_max) | (pre(el.startBackward) & (el.sa < -lim0))
    going_fwd = (eq(pre_mode, FORWARD) | el.startForward) & (v_rel > 0)
    going_bwd = (eq(pre_mode, BACKWARD) | el.startBackward) & (v_rel < 0)
    if forward_allowed is not None:
        break_fwd, going_fwd = break_fwd & forward_allowed, going_fwd & forward_allowed
    if backward_allowed is not None:
        break_bwd, going_bwd = break_bwd & backward_allowed, going_bwd & backward_allowed
    yield el.startForward == ((eq(pre_mode, STUCK) & break_fwd)
                              | (eq(pre_mode, BACKWARD) & (v_rel > v_small))
                              | (initial() & (v_rel > 0)))
    yield el.startBackward == ((eq(pre_mode, STUCK) & break_bwd)
                               | (eq(pre_mode, FORWARD) & (v_rel < -v_small))
                               | (initial() & (v_rel < 0)))
    yield el.locked == ~(eq(pre_mode, FORWARD) | el.startForward
                         | eq(pre_mode, BACKWARD) | el.startBackward)
    yield a_rel_scaled == if_else(
        el.locked, 0.0,
        if_else(el.startForward, el.sa - lim_max,
                if_else(el.startBackward, el.sa + lim_max,
                        if_else(eq(pre_mode, FORWARD), el.sa - lim_max, el.sa + lim_max))))
    yield el.mode == if_else(going_fwd, FORWARD, if_else(going_bwd, BACKWARD, STUCK))
