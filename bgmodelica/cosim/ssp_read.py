"""Reading SSP 1.0 archives (``.ssp``) and system structure descriptions (``.ssd``):
:func:`read_ssp`, :func:`parse_ssd`.

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
from pathlib import Path
from typing import Any

from .archive import SafeZip, normalize, unsafe_reason
from .errors import DuplicateElementError, SspFormatError, UnsafeArchiveError
from .ssp import (
    ANNOTATION_TYPE,
    FMU_TYPE,
    NS,
    SSD_NAME,
    SspComponent,
    SspConnection,
    SspConnector,
    SystemStructure,
    qname,
)


def _snake(key: str) -> str:
    return "".join("_" + c.lower() if c.isupper() else c for c in key)


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
        for ann in exp.iter(qname("ssc", "Annotation")):
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
