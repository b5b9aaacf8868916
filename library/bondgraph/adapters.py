"""Adapters between a bond-graph power port and the connectors of other domains.

Both are one-port bond-graph elements of kind ``X`` (free causality in the analysis: the
outside world decides). Their bond has the default half-arrow *into* the adapter: power
entering the adapter from the bond graph leaves it through the other connector, so
``e * f_bond + (power into the adapter from the other side) = 0`` at every instant.

* :class:`FlangeAdapter`: bond effort = torque [N.m], bond flow = angular speed [rad/s] of
  ``flange`` (library.rotational.Flange): ``f = der(flange.phi)``, ``flange.tau = -e``. A
  positive effort drives the connected rotational component like a ``Torque`` source.
* :class:`PinAdapter`: bond effort = voltage ``p.v - n.v`` [V], bond flow = current [A]
  delivered through ``p`` into the external circuit and back through ``n``:
  ``p.v - n.v = e``, ``p.i = -f``, ``n.i = f`` (library.electrical.Pin).
"""

from __future__ import annotations

from bgmodelica import der
from bgmodelica.bondgraph import BGElement, PowerPort, bond_flow
from library.electrical import Pin
from library.rotational import Flange

__all__ = ["FlangeAdapter", "PinAdapter"]


class FlangeAdapter(BGElement):
    """Bond port ``port`` <-> rotational ``flange`` (effort = torque, flow = speed)."""

    kind = "X"
    port = PowerPort()
    flange = Flange()

    def equations(self):
        yield bond_flow(self.port) == der(self.flange.phi)
        yield self.flange.tau == -self.port.e


class PinAdapter(BGElement):
    """Bond port ``port`` <-> electrical pin pair ``p``, ``n`` (effort = voltage, flow =
    current out of ``p`` through the external circuit into ``n``)."""

    kind = "X"
    port = PowerPort()
    p = Pin()
    n = Pin()

    def equations(self):
        yield self.p.v - self.n.v == self.port.e
        yield self.p.i == -bond_flow(self.port)
        yield self.p.i + self.n.i == 0
