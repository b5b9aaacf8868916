"""SSP 1.0 (System Structure and Parameterization) set-ups: the system structure and
writing ``.ssp`` archives.

An ``.ssp`` is a zip with ``SystemStructure.ssd`` (XML, namespaces ``ssd``/``ssc``/``ssv``)
and the FMUs under ``resources/``. The SSD describes one ``<ssd:System>`` with

* ``<ssd:Elements>``: ``<ssd:Component>`` per FMU instance (``source="resources/X.fmu"``,
  ``type="application/x-fmu-sharedlibrary"``), each with its ``<ssd:Connectors>`` (``kind`` =
  input / output / parameter, type ``<ssc:Real unit=...>``) and ``<ssd:ParameterBindings>``
  (inline ``<ssv:ParameterSet>`` of ``<ssv:Parameter name=...><ssv:Real value=... unit=.../>``);
* ``<ssd:Connections>``: ``<ssd:Connection startElement startConnector endElement
  endConnector>`` from an output to an input;

plus ``<ssd:Units>`` (``<ssc:Unit>`` with ``<ssc:BaseUnit>`` exponents) and
``<ssd:DefaultExperiment startTime stopTime>``. A vendor annotation
(``type="org.bgmodelica.cosim"``) on the default experiment records the master settings the
set-up was made for (``stepSize``, ``order``, ``extrapolation``); readers ignoring it lose
nothing else.

Reading is in :mod:`.ssp_read` (:func:`~.ssp_read.read_ssp`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..fmi.units import BASE, parse_unit
from .errors import (
    DuplicateElementError,
    SspFormatError,
    UnknownConnectorError,
)

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
BGM_NS = "https://bgmodelica.org/cosim"
ANNOTATION_TYPE = "org.bgmodelica.cosim"
FMU_TYPE = "application/x-fmu-sharedlibrary"
SSD_NAME = "SystemStructure.ssd"

for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)
ET.register_namespace("bgm", BGM_NS)


def qname(prefix: str, tag: str) -> str:
    """``{uri}tag`` of ``tag`` in the namespace ``prefix`` (``ssd``, ``ssc``, ``ssv``)."""
    return f"{{{NS[prefix]}}}{tag}"


@dataclass
class SspConnector:
    """A connector of a component: ``kind`` is input, output, parameter (SSP kinds)."""

    name: str
    kind: str
    type: str = "Real"
    unit: str = ""
    description: str = ""


@dataclass
class SspComponent:
    """One FMU instance of the system."""

    name: str
    source: str                                  # as written in the SSD
    connectors: list[SspConnector] = field(default_factory=list)
    parameters: dict[str, Any] = field(default_factory=dict)   # numbers; str for String
    type: str = FMU_TYPE
    implementation: str = "any"                  # any, CoSimulation, ModelExchange
    fmu_path: Path | None = None                 # the FMU file (resolved)
    description: str = ""
    parameter_units: dict[str, str] = field(default_factory=dict)   # unit given in the SSV

    def connector(self, name: str) -> SspConnector | None:
        for c in self.connectors:
            if c.name == name:
                return c
        return None


@dataclass(frozen=True)
class SspConnection:
    """``start_element.start_connector -> end_element.end_connector``."""

    start_element: str
    start_connector: str
    end_element: str
    end_connector: str

    @property
    def start(self) -> str:
        return f"{self.start_element}.{self.start_connector}"

    @property
    def end(self) -> str:
        return f"{self.end_element}.{self.end_connector}"

    def __str__(self) -> str:
        return f"{self.start} -> {self.end}"


@dataclass
class SystemStructure:
    """A flat co-simulation system: components (FMU instances), connections, experiment."""

    name: str
    elements: list[SspComponent]
    connections: list[SspConnection]
    start_time: float = 0.0
    stop_time: float | None = None
    description: str = ""
    master: dict[str, Any] = field(default_factory=dict)   # step_size, order, extrapolation
    root: Path | None = None          # where a read archive was extracted

    def element(self, name: str) -> SspComponent:
        for e in self.elements:
            if e.name == name:
                return e
        raise UnknownConnectorError(
            f"system {self.name!r} has no element {name!r} (elements: "
            f"{', '.join(e.name for e in self.elements)})")

    @property
    def element_names(self) -> list[str]:
        return [e.name for e in self.elements]


def system_from_fmus(name: str, fmus: Mapping[str, str | Path],
                     connections: Iterable[tuple[str, str, str, str]],
                     parameters: Mapping[str, Mapping[str, float]] | None = None,
                     start_time: float = 0.0, stop_time: float | None = None,
                     description: str = "", master: Mapping[str, Any] | None = None
                     ) -> SystemStructure:
    """Build a :class:`SystemStructure` from FMU files: element name -> FMU path; the
    connectors are the FMUs' inputs and outputs (with their units) plus the bound parameters;
    ``connections`` are ``(from element, output, to element, input)``; ``parameters`` maps
    element -> {parameter: value}."""
    from .fmu import read_fmu_info

    parameters = parameters or {}
    elements = []
    for el, path in fmus.items():
        info = read_fmu_info(path)
        conns = [SspConnector(v.name, v.causality, v.type, v.unit, v.description)
                 for v in info.variables.values() if v.causality in ("input", "output")]
        bound = dict(parameters.get(el, {}))
        for pname in bound:
            var = info.variables.get(pname)
            if var is None or not var.settable:
                raise UnknownConnectorError(
                    f"element {el!r} ({Path(path).name}) has no parameter or input {pname!r}")
            if var.causality == "parameter":
                conns.append(SspConnector(pname, "parameter", var.type, var.unit))
        elements.append(SspComponent(el, f"resources/{Path(path).name}", conns,
                                     {k: v if isinstance(v, str) else float(v)
                                      for k, v in bound.items()},
                                     fmu_path=Path(path),
                                     description=info.description.description or ""))
    if stop_time is None:
        stops = [read_fmu_info(p).description.defaultExperiment for p in fmus.values()]
        stops = [float(d.stopTime) for d in stops if d is not None and d.stopTime is not None]
        stop_time = max(stops) if stops else None
    conns = [SspConnection(*c) for c in connections]
    return SystemStructure(name, elements, conns, start_time, stop_time, description,
                           dict(master or {}))


# -- writing ------------------------------------------------------------------------------

def _num(x: float) -> str:
    return repr(float(x))


def _units_element(parent: ET.Element, units: Iterable[str]) -> None:
    units = sorted({u for u in units if u})
    if not units:
        return
    ue = ET.SubElement(parent, qname("ssd", "Units"))
    for u in units:
        d = parse_unit(u)
        unit = ET.SubElement(ue, qname("ssc", "Unit"), name=u)
        attrs = {}
        if d.exponents is not None:
            attrs = {k: str(d.exponents[k]) for k in BASE if d.exponents.get(k)}
            if d.factor != 1.0:
                attrs["factor"] = _num(d.factor)
            if d.offset != 0.0:
                attrs["offset"] = _num(d.offset)
        ET.SubElement(unit, qname("ssc", "BaseUnit"), attrs)


def ssd_xml(system: SystemStructure) -> bytes:
    """The ``SystemStructure.ssd`` document of ``system``."""
    root = ET.Element(qname("ssd", "SystemStructureDescription"),
                      {"version": "1.0", "name": system.name, "generationTool": "bgmodelica"})
    if system.description:
        root.set("description", system.description)
    sysel = ET.SubElement(root, qname("ssd", "System"), name=system.name)
    elements = ET.SubElement(sysel, qname("ssd", "Elements"))
    used_units: list[str] = []
    for comp in system.elements:
        attrs = {"name": comp.name, "type": comp.type, "source": comp.source}
        if comp.implementation and comp.implementation != "any":
            attrs["implementation"] = comp.implementation
        if comp.description:
            attrs["description"] = comp.description
        ce = ET.SubElement(elements, qname("ssd", "Component"), attrs)
        if comp.connectors:
            cs = ET.SubElement(ce, qname("ssd", "Connectors"))
            for c in comp.connectors:
                ca = {"name": c.name, "kind": c.kind}
                if c.description:
                    ca["description"] = c.description
                cn = ET.SubElement(cs, qname("ssd", "Connector"), ca)
                ET.SubElement(cn, qname("ssc", c.type), {"unit": c.unit} if c.unit else {})
                used_units.append(c.unit)
        if comp.parameters:
            pbs = ET.SubElement(ce, qname("ssd", "ParameterBindings"))
            pb = ET.SubElement(pbs, qname("ssd", "ParameterBinding"))
            pv = ET.SubElement(pb, qname("ssd", "ParameterValues"))
            ps = ET.SubElement(pv, qname("ssv", "ParameterSet"), version="1.0",
                               name=f"{comp.name}_parameters")
            params = ET.SubElement(ps, qname("ssv", "Parameters"))
            for pname, value in comp.parameters.items():
                p = ET.SubElement(params, qname("ssv", "Parameter"), name=pname)
                conn = comp.connector(pname)
                kind = conn.type if conn is not None else "Real"
                if isinstance(value, str) or kind == "String":
                    ET.SubElement(p, qname("ssv", "String"), value=str(value))
                    continue
                if kind == "Boolean":
                    ET.SubElement(p, qname("ssv", "Boolean"), value="true" if value else "false")
                    continue
                if kind in ("Integer", "Enumeration"):
                    ET.SubElement(p, qname("ssv", "Integer"), value=str(int(value)))
                    continue
                ra = {"value": _num(value)}
                unit = comp.parameter_units.get(pname) or (conn.unit if conn is not None
                                                          else "")
                if unit:
                    ra["unit"] = unit
                ET.SubElement(p, qname("ssv", "Real"), ra)
    if system.connections:
        cons = ET.SubElement(sysel, qname("ssd", "Connections"))
        for c in system.connections:
            ET.SubElement(cons, qname("ssd", "Connection"), startElement=c.start_element,
                          startConnector=c.start_connector, endElement=c.end_element,
                          endConnector=c.end_connector)
    _units_element(root, used_units)
    exp_attrs = {"startTime": _num(system.start_time)}
    if system.stop_time is not None:
        exp_attrs["stopTime"] = _num(system.stop_time)
    exp = ET.SubElement(root, qname("ssd", "DefaultExperiment"), exp_attrs)
    if system.master:
        anns = ET.SubElement(exp, qname("ssd", "Annotations"))
        ann = ET.SubElement(anns, qname("ssc", "Annotation"), type=ANNOTATION_TYPE)
        ET.SubElement(ann, f"{{{BGM_NS}}}Master",
                      {_camel(k): _text(v) for k, v in system.master.items()})
    ET.indent(root, space="  ")
    text = ET.tostring(root, encoding="unicode")
    return ('<?xml version="1.0" encoding="UTF-8"?>\n' + text + "\n").encode("utf-8")


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return repr(value) if isinstance(value, float) else str(value)


def _camel(key: str) -> str:
    head, *rest = key.split("_")
    return head + "".join(r.capitalize() for r in rest)


def write_ssp(system: SystemStructure, path: str | Path) -> Path:
    """Write ``system`` as an ``.ssp`` archive with its FMUs in ``resources/``; every
    component's ``source`` is rewritten to ``resources/<file>.fmu`` (one copy per distinct
    FMU file, shared by the components that use it). Returns the path."""
    path = Path(path)
    dup = sorted({n for n in system.element_names if system.element_names.count(n) > 1})
    if dup:
        raise DuplicateElementError(f"system {system.name!r}: element name(s) used twice: "
                                    f"{', '.join(dup)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    names: dict[Path, str] = {}
    taken: set[str] = set()
    for comp in system.elements:
        if comp.fmu_path is None:
            raise SspFormatError(f"element {comp.name!r}: no FMU file to pack (fmu_path)")
        src = Path(comp.fmu_path).resolve()
        if not src.is_file():
            raise SspFormatError(f"element {comp.name!r}: FMU {src} does not exist")
        if src not in names:
            stem, k, candidate = src.stem, 1, src.name
            while candidate in taken:
                k += 1
                candidate = f"{stem}_{k}.fmu"
            names[src] = candidate
            taken.add(candidate)
        comp.source = f"resources/{names[src]}"
    tmp = path.with_name(path.name + ".part")
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.writestr(zipfile.ZipInfo(SSD_NAME, (2000, 1, 1, 0, 0, 0)), ssd_xml(system))
            for src, name in names.items():
                info = zipfile.ZipInfo(f"resources/{name}", (2000, 1, 1, 0, 0, 0))
                info.compress_type = zipfile.ZIP_STORED     # an FMU is already a zip
                zf.writestr(info, src.read_bytes())
        tmp.replace(path)
    except BaseException:
        tmp.unlink(missing_ok=True)                     # no partial archive
        raise
    return path
