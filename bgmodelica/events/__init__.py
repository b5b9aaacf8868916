"""Hybrid simulation: the event loop and the CasADi functions it evaluates."""

from .loop import EventError, EventOptions, HybridSimulator

__all__ = ["EventError", "EventOptions", "HybridSimulator"]
