"""SSP 1.0 (System Structure and Parameterization) set-ups: write and read ``.ssp`` archives.

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

The reader accepts what the writer produces and the common variations: any namespace
prefixes, parameter sets in separate ``.ssv`` files (``<ssd:ParameterBinding
source="resources/x.ssv">``, with an optional ``prefix`` stripped from the parameter names)
and FMUs referenced relative to the archive. Only flat systems (no nested ``<ssd:System>``)
of FMU components are supported.

Reading is defensive: the archive is checked as a whole by :class:`~.archive.SafeZip`
(unsafe member names, symbolic links, duplicates, zip bombs, truncation) before anything is
extracted; component sources must be plain relative paths inside the archive; two
components, two connectors of one component or two values in one parameter set with the
same name are refused (:class:`~.errors.DuplicateElementError`), and so are non-numeric,
non-finite or (for Integer/Boolean) non-integral parameter values. Extraction writes only
into the extraction folder and removes what it wrote if it fails.
"""

from __future__ import annotations

import atexit
import math
import shutil
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..fmi.units import BASE, parse_unit
from .archive import SafeZip, normalize, unsafe_reason
from .errors import (
    DuplicateElementError,
    SspFormatError,
    UnknownConnectorError,
    UnsafeArchiveError,
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


def _q(prefix: str, tag: str) -> str:
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
    ue = ET.SubElement(parent, _q("ssd", "Units"))
    for u in units:
        d = parse_unit(u)
        unit = ET.SubElement(ue, _q("ssc", "Unit"), name=u)
        attrs = {}
        if d.exponents is not None:
            attrs = {k: str(d.exponents[k]) for k in BASE if d.exponents.get(k)}
            if d.factor != 1.0:
                attrs["factor"] = _num(d.factor)
            if d.offset != 0.0:
                attrs["offset"] = _num(d.offset)
        ET.SubElement(unit, _q("ssc", "BaseUnit"), attrs)


def ssd_xml(system: SystemStructure) -> bytes:
    """The ``SystemStructure.ssd`` document of ``system``."""
    root = ET.Element(_q("ssd", "SystemStructureDescription"),
                      {"version": "1.0", "name": system.name, "generationTool": "bgmodelica"})
    if system.description:
        root.set("description", system.description)
    sysel = ET.SubElement(root, _q("ssd", "System"), name=system.name)
    elements = ET.SubElement(sysel, _q("ssd", "Elements"))
    used_units: list[str] = []
    for comp in system.elements:
        attrs = {"name": comp.name, "type": comp.type, "source": comp.source}
        if comp.implementation and comp.implementation != "any":
            attrs["implementation"] = comp.implementation
        if comp.description:
            attrs["description"] = comp.description
        ce = ET.SubElement(elements, _q("ssd", "Component"), attrs)
        if comp.connectors:
            cs = ET.SubElement(ce, _q("ssd", "Connectors"))
            for c in comp.connectors:
                ca = {"name": c.name, "kind": c.kind}
                if c.description:
                    ca["description"] = c.description
                cn = ET.SubElement(cs, _q("ssd", "Connector"), ca)
                ET.SubElement(cn, _q("ssc", c.type), {"unit": c.unit} if c.unit else {})
                used_units.append(c.unit)
        if comp.parameters:
            pbs = ET.SubElement(ce, _q("ssd", "ParameterBindings"))
            pb = ET.SubElement(pbs, _q("ssd", "ParameterBinding"))
            pv = ET.SubElement(pb, _q("ssd", "ParameterValues"))
            ps = ET.SubElement(pv, _q("ssv", "ParameterSet"), version="1.0",
                               name=f"{comp.name}_parameters")
            params = ET.SubElement(ps, _q("ssv", "Parameters"))
            for pname, value in comp.parameters.items():
                p = ET.SubElement(params, _q("ssv", "Parameter"), name=pname)
                conn = comp.connector(pname)
                kind = conn.type if conn is not None else "Real"
                if isinstance(value, str) or kind == "String":
                    ET.SubElement(p, _q("ssv", "String"), value=str(value))
                    continue
                if kind == "Boolean":
                    ET.SubElement(p, _q("ssv", "Boolean"), value="true" if value else "false")
                    continue
                if kind in ("Integer", "Enumeration"):
                    ET.SubElement(p, _q("ssv", "Integer"), value=str(int(value)))
                    continue
                ra = {"value": _num(value)}
                unit = comp.parameter_units.get(pname) or (conn.unit if conn is not None
                                                          else "")
                if unit:
                    ra["unit"] = unit
                ET.SubElement(p, _q("ssv", "Real"), ra)
    if system.connections:
        cons = ET.SubElement(sysel, _q("ssd", "Connections"))
        for c in system.connections:
            ET.SubElement(cons, _q("ssd", "Connection"), startElement=c.start_element,
                          startConnector=c.start_connector, endElement=c.end_element,
                          endConnector=c.end_connector)
    _units_element(root, used_units)
    exp_attrs = {"startTime": _num(system.start_time)}
    if system.stop_time is not None:
        exp_attrs["stopTime"] = _num(system.stop_time)
    exp = ET.SubElement(root, _q("ssd", "DefaultExperiment"), exp_attrs)
    if system.master:
        anns = ET.SubElement(exp, _q("ssd", "Annotations"))
        ann = ET.SubElement(anns, _q("ssc", "Annotation"), type=ANNOTATION_TYPE)
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


def _snake(key: str) -> str:
    return "".join("_" + c.lower() if c.isupper() else c for c in key)


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


# -- reading ------------------------------------------------------------------------------

def _local(tag: str) -> tuple[str, str]:
    if tag.startswith("{"):
        uri, _, name = tag[1:].partition("}")
        return uri, name
    return "", tag


def _children(el: ET.Element, ns: str, name: str) -> list[ET.Element]:
    return [c for c in el if _local(c.tag) == (NS[ns], name)]


def _child(el: ET.Element, ns: str, name: str) -> ET.Element | None:
    found = _children(el, ns, name)
    return found[0] if found else None


def _float(text: str | None, what: str) -> float:
    try:
        value = float(text)   # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise SspFormatError(f"{what}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise SspFormatError(f"{what}: {text!r} is not finite")
    return value


def _parameter_set(ps: ET.Element, where: str, prefix: str = "",
                   units: dict[str, str] | None = None) -> dict[str, Any]:
    if _local(ps.tag) != (NS["ssv"], "ParameterSet"):
        raise SspFormatError(f"{where}: expected <ssv:ParameterSet>, found <{ps.tag}>")
    out: dict[str, Any] = {}
    params = _child(ps, "ssv", "Parameters")
    for p in _children(params, "ssv", "Parameter") if params is not None else []:
        name = p.get("name")
        if not name:
            raise SspFormatError(f"{where}: <ssv:Parameter> without a name")
        if prefix and name.startswith(prefix):
            name = name[len(prefix):]
        if name in out:
            raise DuplicateElementError(f"{where}: parameter {name!r} is given twice in one "
                                        "parameter set")
        value = None
        for typ in ("Real", "Integer", "Boolean", "String"):
            v = _child(p, "ssv", typ)
            if v is not None:
                text = v.get("value")
                what = f"{where}: parameter {name}"
                if typ == "String":
                    value = text or ""
                elif typ == "Boolean":
                    if text not in ("true", "false", "1", "0"):
                        raise SspFormatError(f"{what}: {text!r} is not a Boolean (true/false)")
                    value = 1.0 if text in ("true", "1") else 0.0
                else:
                    value = _float(text, what)
                    if typ == "Integer" and value != int(value):
                        raise SspFormatError(f"{what}: {text!r} is not an Integer")
                if typ == "Real" and v.get("unit") and units is not None:
                    units[name] = v.get("unit")
                break
        if value is None:
            raise SspFormatError(f"{where}: parameter {name!r} has no Real/Integer/Boolean/"
                                 "String value")
        out[name] = value
    return out


def _read_bindings(comp_el: ET.Element, where: str, zf: Any,
                   units: dict[str, str] | None = None) -> dict[str, float]:
    """The parameter values of a component (later bindings override earlier ones, as in
    SSP); ``zf``: a :class:`~.archive.SafeZip` or a :class:`zipfile.ZipFile`."""
    out: dict[str, float] = {}
    pbs = _child(comp_el, "ssd", "ParameterBindings")
    for pb in _children(pbs, "ssd", "ParameterBinding") if pbs is not None else []:
        prefix = pb.get("prefix", "")
        if _child(pb, "ssd", "ParameterMapping") is not None:
            raise SspFormatError(f"{where}: parameter mappings (.ssm) are not supported")
        source = pb.get("source")
        if source:
            reason = unsafe_reason(source)
            if reason is not None:
                raise UnsafeArchiveError(f"{where}: parameter file {source!r} has {reason} "
                                         "(only files inside the archive can be referenced)")
            name = normalize(source)
            try:
                data = zf.read(name, f"{where}: parameter file") if isinstance(zf, SafeZip) \
                    else zf.read(name)
            except KeyError:
                raise SspFormatError(f"{where}: parameter file {source!r} is not in the "
                                     "archive") from None
            try:
                doc = ET.fromstring(data)
            except ET.ParseError as err:
                raise SspFormatError(f"{where}: {source} is not well-formed XML: {err}") \
                    from None
            out.update(_parameter_set(doc, f"{where} ({source})", prefix, units))
        values = _child(pb, "ssd", "ParameterValues")
        if values is not None:
            for ps in values:
                out.update(_parameter_set(ps, where, prefix, units))
    return out


def parse_ssd(text: bytes, zf: Any = None) -> SystemStructure:
    """Parse an SSD document (``zf``: the archive, a :class:`~.archive.SafeZip` or a
    :class:`zipfile.ZipFile`, for the ``.ssv`` files it refers to)."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as err:
        raise SspFormatError(f"{SSD_NAME} is not well-formed XML: {err}") from None
    if _local(root.tag) != (NS["ssd"], "SystemStructureDescription"):
        raise SspFormatError(f"{SSD_NAME}: the root element is <{root.tag}>, expected "
                             f"<ssd:SystemStructureDescription> ({NS['ssd']})")
    if root.get("version") not in ("1.0", "1.0.1", "2.0", None):
        raise SspFormatError(f"{SSD_NAME}: unsupported SSP version {root.get('version')!r}")
    sysel = _child(root, "ssd", "System")
    if sysel is None:
        raise SspFormatError(f"{SSD_NAME}: no <ssd:System>")
    sys_name = sysel.get("name") or root.get("name") or "system"
    elements: list[SspComponent] = []
    els = _child(sysel, "ssd", "Elements")
    for el in list(els) if els is not None else []:
        kind = _local(el.tag)[1]
        if kind == "System":
            raise SspFormatError(f"{SSD_NAME}: nested system {el.get('name')!r} is not "
                                 "supported (flatten it)")
        if kind != "Component":
            raise SspFormatError(f"{SSD_NAME}: element <{kind}> {el.get('name')!r} is not "
                                 "supported (only FMU components)")
        name, source = el.get("name"), el.get("source")
        if not name or not source:
            raise SspFormatError(f"{SSD_NAME}: a <ssd:Component> lacks its name or source")
        if any(e.name == name for e in elements):
            raise DuplicateElementError(f"{SSD_NAME}: two components are named {name!r}; "
                                        "element names must be unique")
        typ = el.get("type", FMU_TYPE)
        if typ != FMU_TYPE:
            raise SspFormatError(f"component {name!r}: type {typ!r} is not an FMU "
                                 f"({FMU_TYPE})")
        conns = []
        cs = _child(el, "ssd", "Connectors")
        for c in _children(cs, "ssd", "Connector") if cs is not None else []:
            ctype, unit = "Real", ""
            for t in c:
                uri, tname = _local(t.tag)
                if uri == NS["ssc"] and tname in ("Real", "Integer", "Boolean", "String",
                                                   "Enumeration", "Binary"):
                    ctype, unit = tname, t.get("unit", "")
            cname = c.get("name", "")
            if not cname:
                raise SspFormatError(f"{SSD_NAME}: a connector of component {name!r} has no "
                                     "name")
            if any(k.name == cname for k in conns):
                raise DuplicateElementError(f"{SSD_NAME}: component {name!r} declares the "
                                            f"connector {cname!r} twice")
            conns.append(SspConnector(cname, c.get("kind", "unspecified"), ctype,
                                      unit, c.get("description", "")))
        punits: dict[str, str] = {}
        params = _read_bindings(el, f"component {name!r}", zf, punits) \
            if zf is not None else {}
        elements.append(SspComponent(name, source, conns, params, typ,
                                     el.get("implementation", "any"),
                                     description=el.get("description", ""),
                                     parameter_units=punits))
    connections = []
    cons = _child(sysel, "ssd", "Connections")
    for c in _children(cons, "ssd", "Connection") if cons is not None else []:
        try:
            connections.append(SspConnection(c.attrib["startElement"], c.attrib["startConnector"],
                                             c.attrib["endElement"], c.attrib["endConnector"]))
        except KeyError as err:
            raise SspFormatError(f"{SSD_NAME}: a connection lacks {err.args[0]} (connections "
                                 "to the system's own connectors are not supported)") from None
    start, stop, master = 0.0, None, {}
    exp = _child(root, "ssd", "DefaultExperiment")
    if exp is not None:
        start = _float(exp.get("startTime", "0"), "DefaultExperiment startTime")
        if exp.get("stopTime") is not None:
            stop = _float(exp.get("stopTime"), "DefaultExperiment stopTime")
        for ann in exp.iter(_q("ssc", "Annotation")):
            if ann.get("type") == ANNOTATION_TYPE:
                for m in ann:
                    for k, v in m.attrib.items():
                        master[_snake(k)] = _auto(v)
    if "step_size" in master:
        master["step_size"] = _float(str(master["step_size"]),
                                     "DefaultExperiment annotation stepSize")
    if stop is not None and not stop > start:
        raise SspFormatError(f"{SSD_NAME}: DefaultExperiment stopTime {stop!r} is not after "
                             f"startTime {start!r}")
    return SystemStructure(sys_name, elements, connections, start, stop,
                           root.get("description", ""), master)


def _auto(text: str) -> Any:
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    return {"true": True, "false": False}.get(text, text)


def read_ssp(path: str | Path, extract_to: str | Path | None = None) -> SystemStructure:
    """Read an ``.ssp`` archive; its FMUs are extracted to ``extract_to`` (default: a new
    temporary directory, removed at exit; ``system.root``) and each component's ``fmu_path``
    points there. The archive is checked first (:class:`~.archive.SafeZip`); component
    sources must be relative paths of members of the archive. Errors:
    :class:`~.errors.SspFormatError`, :class:`~.errors.UnsafeArchiveError`,
    :class:`~.errors.DuplicateElementError`."""
    path = Path(path)
    with SafeZip(path, "SSP", SSD_NAME, error=SspFormatError) as zf:
        system = parse_ssd(zf.read(SSD_NAME), zf)
        sources: dict[str, str] = {}
        for comp in system.elements:
            reason = unsafe_reason(comp.source)
            if reason is not None:
                raise UnsafeArchiveError(
                    f"{path}: component {comp.name!r} refers to {comp.source!r}, which has "
                    f"{reason}; only FMUs inside the archive can be used")
            src = normalize(comp.source)
            if src not in zf.members:
                raise SspFormatError(f"{path}: component {comp.name!r} refers to {comp.source!r}"
                                     ", which is not in the archive")
            sources[comp.name] = src
        created = extract_to is None
        if extract_to is not None:
            root = Path(extract_to)
        else:
            root = Path(tempfile.mkdtemp(prefix="bgm_ssp_"))
            atexit.register(shutil.rmtree, root, True)
        written: dict[str, Path] = {}
        try:
            for comp in system.elements:
                src = sources[comp.name]
                if src not in written:      # one copy per member, fresh (never a stale file)
                    written[src] = zf.extract_member(src, root, src,
                                                     f"component {comp.name!r}: source")
                comp.fmu_path = written[src]
        except BaseException:
            if created:
                shutil.rmtree(root, ignore_errors=True)
            else:
                for f in written.values():
                    f.unlink(missing_ok=True)
            raise
    system.root = root
    return system
