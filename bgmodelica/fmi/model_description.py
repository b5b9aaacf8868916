"""``modelDescription.xml`` for FMI 2.0 and FMI 3.0.

The variable layout comes from :mod:`bgmodelica.fmi.variables`; the ``<ModelStructure>``
dependencies from the CasADi sparsity (:func:`bgmodelica.fmi.codegen.dependencies`):

* FMI 2.0 refers to variables by their 1-based ``index`` in ``<ModelVariables>``; the order of
  ``<Derivatives>`` defines the order of the continuous-state vector, so they are listed in
  state order.  ``<InitialUnknowns>`` lists, sorted by index, the outputs, the calculated states
  (spec with ``init``) and all state derivatives; their dependencies are the knowns of
  Initialization Mode (inputs, parameters, exact states).
* FMI 3.0 refers to value references; ``<Output>``, ``<ContinuousStateDerivative>`` (state order)
  and ``<InitialUnknown>`` follow the same rules.

Dotted names are kept as they are (``variableNamingConvention="structured"``). The root's
``description`` is the first paragraph of the model's docstring and ``generationDateAndTime``
the export time in UTC (``$SOURCE_DATE_EPOCH`` when set).

Hybrid specs (models with events): discrete variables get their FMI type (Real/Float64,
Integer/Int32, Boolean); Model Exchange declares the event indicators
(``numberOfEventIndicators`` in FMI 2.0, ``<EventIndicator>`` elements referring to the
indicator variables in FMI 3.0); FMI 3.0 Co-Simulation may return early from ``fmi3DoStep``
(at events, when the importer allows it); the log category ``logEvents`` reports events.
"""

from __future__ import annotations

import hashlib
import os
import xml.etree.ElementTree as ET
from datetime import datetime, timezone

from .codegen import Dependencies
from .spec import FmuSpec
from .units import BASE, unit_definitions
from .variables import FmiVariable, VariableTable

GENERATION_TOOL = "bgmodelica"

LOG_CATEGORIES = (
    ("logStatusWarning", "Messages with status Warning"),
    ("logStatusError", "Messages with status Error (always reported)"),
    ("logSolver", "Statistics of the embedded Co-Simulation solver"),
)


def _num(value: float) -> str:
    text = repr(float(value))
    return {"inf": "INF", "-inf": "-INF", "nan": "NaN"}.get(text, text)


def generation_date() -> str:
    """Now in UTC as ISO 8601 (``2026-11-28T13:20:00Z``), or the time of
    ``$SOURCE_DATE_EPOCH`` [s] when set (reproducible builds)."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    when = datetime.now(timezone.utc)
    if epoch.isdigit():
        when = datetime.fromtimestamp(int(epoch), timezone.utc)
    return when.replace(microsecond=0).strftime("%Y-%m-%dT%H:%M:%SZ")


def instantiation_token(*parts: str) -> str:
    """A GUID-formatted token derived from a hash of ``parts``."""
    h = hashlib.sha256("\x00".join(parts).encode("utf-8")).hexdigest()
    return "{" + "-".join((h[:8], h[8:12], h[12:16], h[16:20], h[20:32])) + "}"


def _units(table: VariableTable, parent: ET.Element) -> None:
    defs = unit_definitions([v.unit for v in table.variables])
    if not defs:
        return
    ud = ET.SubElement(parent, "UnitDefinitions")
    for d in defs:
        unit = ET.SubElement(ud, "Unit", name=d.name)
        if d.exponents is None:
            continue
        attrs = {k: str(d.exponents[k]) for k in BASE if d.exponents.get(k)}
        if d.factor != 1.0:
            attrs["factor"] = _num(d.factor)
        if d.offset != 0.0:
            attrs["offset"] = _num(d.offset)
        ET.SubElement(unit, "BaseUnit", attrs)


def _log_categories(parent: ET.Element, hybrid: bool = False) -> None:
    lc = ET.SubElement(parent, "LogCategories")
    extra = (("logEvents", "Events (time, state and sample events) and event iterations"),)
    for name, description in LOG_CATEGORIES + (extra if hybrid else ()):
        ET.SubElement(lc, "Category", name=name, description=description)


def _experiment(spec: FmuSpec, parent: ET.Element) -> None:
    attrs = {"startTime": _num(spec.start_time), "stopTime": _num(spec.stop_time),
             "tolerance": _num(spec.tolerance)}
    if spec.step_size is not None:
        attrs["stepSize"] = _num(spec.step_size)
    ET.SubElement(parent, "DefaultExperiment", attrs)


def _common_attrs(v: FmiVariable) -> dict[str, str]:
    attrs = {"name": v.name, "valueReference": str(v.vr)}
    if v.description:
        attrs["description"] = v.description
    attrs["causality"] = v.causality
    attrs["variability"] = v.variability
    if v.initial is not None and v.causality not in ("input", "independent"):
        attrs["initial"] = v.initial
    return attrs


def _type_attrs(v: FmiVariable, version: int, table: VariableTable) -> dict[str, str]:
    attrs: dict[str, str] = {}
    if v.unit:
        attrs["unit"] = v.unit
    if v.derivative_of is not None:
        ref = table.variables[v.derivative_of]
        attrs["derivative"] = str(ref.fmi2_index if version == 2 else ref.vr)
    if v.min is not None:
        attrs["min"] = _num(v.min)
    if v.max is not None:
        attrs["max"] = _num(v.max)
    if v.nominal is not None:
        attrs["nominal"] = _num(v.nominal)
    if v.start is not None:
        attrs["start"] = _num(v.start)
    if v.type == "Integer":
        attrs.pop("unit", None)
        for key in ("min", "max", "start"):
            if key in attrs:
                attrs[key] = str(int(round(float(attrs[key]))))
    elif v.type == "Boolean":
        attrs = {"start": "true" if v.start else "false"} if v.start is not None else {}
    return attrs


_TYPE_ELEMENTS = {2: {"Real": "Real", "Integer": "Integer", "Boolean": "Boolean"},
                  3: {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}}


def _structure_entries(table: VariableTable, deps: Dependencies, has_init: bool):
    """Yield (kind, variable, dependency variables) with kind in outputs/derivatives/initial."""
    states = table.of_kind("state")
    derivs = table.of_kind("derivative")
    inputs = table.of_kind("input")
    params = table.of_kind("parameter")
    outputs = table.of_kind("output")

    def ct(pair: tuple[list[int], list[int]]) -> list[FmiVariable]:
        xs, us = pair
        return [states[i] for i in xs] + [inputs[i] for i in us]

    def init(trip: tuple[list[int], list[int], list[int]]) -> list[FmiVariable]:
        xs, us, ps = trip
        return sorted([states[i] for i in xs] + [inputs[i] for i in us]
                      + [params[i] for i in ps], key=lambda v: v.vr)

    for o in sorted(outputs + [s for s in states if s.causality == "output"],
                    key=lambda v: v.vr):
        yield "output", o, [o] if o.kind == "state" else ct(deps.outputs[o.index])
    for d in derivs:
        yield "derivative", d, ct(deps.derivatives[d.index])
    initial: list[tuple[FmiVariable, list[FmiVariable]]] = []
    for o in outputs:
        initial.append((o, init(deps.init_outputs[o.index])))
    if has_init:
        for s in states:
            initial.append((s, init(deps.init_states[s.index])))
    for d in derivs:
        initial.append((d, init(deps.init_derivatives[d.index])))
    for var, dep in sorted(initial, key=lambda e: e[0].vr):
        yield "initial", var, dep


def model_description_xml(spec: FmuSpec, table: VariableTable, deps: Dependencies,
                          version: int, model_identifier: str, token: str,
                          interfaces: tuple[str, ...], source_files: list[str]) -> bytes:
    """Return the ``modelDescription.xml`` document for ``version`` 2 or 3."""
    if version not in (2, 3):
        raise ValueError("FMI version must be 2 or 3")
    root = ET.Element("fmiModelDescription")
    root.set("fmiVersion", "2.0" if version == 2 else "3.0")
    root.set("modelName", spec.model_name)
    root.set("guid" if version == 2 else "instantiationToken", token)
    if spec.description:
        root.set("description", spec.description)
    root.set("generationTool", GENERATION_TOOL)
    root.set("generationDateAndTime", generation_date())
    root.set("variableNamingConvention", "structured")
    hybrid = spec.hybrid is not None
    # the Newton guesses of dynamic state selection follow the completed steps
    needs_step = "true" if hybrid and spec.hybrid.track_pre else "false"
    if version == 2:
        n_ind = spec.hybrid.nz if hybrid and "me" in interfaces else 0
        root.set("numberOfEventIndicators", str(n_ind))

    if version == 2:
        caps = {"canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
                "providesDirectionalDerivative": "true", "canNotUseMemoryManagementFunctions":
                "true"}
        if "me" in interfaces:
            me = ET.SubElement(root, "ModelExchange", modelIdentifier=model_identifier,
                               completedIntegratorStepNotNeeded="false" if needs_step == "true"
                               else "true", **caps)
            _source_files(me, source_files)
        if "cs" in interfaces:
            cs = ET.SubElement(root, "CoSimulation", modelIdentifier=model_identifier,
                               canHandleVariableCommunicationStepSize="true",
                               canInterpolateInputs="false", maxOutputDerivativeOrder="0",
                               **caps)
            _source_files(cs, source_files)
    else:
        caps = {"canGetAndSetFMUState": "true", "canSerializeFMUState": "true",
                "providesDirectionalDerivatives": "true"}
        if "me" in interfaces:
            ET.SubElement(root, "ModelExchange", modelIdentifier=model_identifier,
                          needsCompletedIntegratorStep=needs_step, **caps)
        if "cs" in interfaces:
            early = {"mightReturnEarlyFromDoStep": "true"} if hybrid else {}
            ET.SubElement(root, "CoSimulation", modelIdentifier=model_identifier,
                          canHandleVariableCommunicationStepSize="true",
                          maxOutputDerivativeOrder="0", hasEventMode="true", **early, **caps)

    _units(table, root)
    _log_categories(root, hybrid)
    _experiment(spec, root)

    mv = ET.SubElement(root, "ModelVariables")
    for v in table.variables:
        element = _TYPE_ELEMENTS[version][v.type]
        if version == 2:
            sv = ET.SubElement(mv, "ScalarVariable", _common_attrs(v))
            ET.SubElement(sv, element, _type_attrs(v, 2, table))
        else:
            ET.SubElement(mv, element, {**_common_attrs(v), **_type_attrs(v, 3, table)})

    ms = ET.SubElement(root, "ModelStructure")
    entries = list(_structure_entries(table, deps, spec.init is not None))
    if version == 2:
        groups = (("Outputs", "output"), ("Derivatives", "derivative"),
                  ("InitialUnknowns", "initial"))
        for tag, kind in groups:
            selected = [e for e in entries if e[0] == kind]
            if not selected:
                continue
            group = ET.SubElement(ms, tag)
            for _, var, dep in selected:
                ET.SubElement(group, "Unknown", index=str(var.fmi2_index),
                              dependencies=" ".join(str(d.fmi2_index) for d in dep))
    else:
        tags = {"output": "Output", "derivative": "ContinuousStateDerivative",
                "initial": "InitialUnknown"}
        for kind in ("output", "derivative", "initial"):
            for _, var, dep in (e for e in entries if e[0] == kind):
                ET.SubElement(ms, tags[kind], valueReference=str(var.vr),
                              dependencies=" ".join(str(d.vr) for d in dep))
        for var in table.of_kind("indicator"):
            ET.SubElement(ms, "EventIndicator", valueReference=str(var.vr))

    ET.indent(root, space="  ")
    return _serialize(root)


def _source_files(parent: ET.Element, files: list[str]) -> None:
    if not files:
        return
    sf = ET.SubElement(parent, "SourceFiles")
    for f in files:
        ET.SubElement(sf, "File", name=f)


def build_description_xml(model_identifier: str, source_files: list[str]) -> bytes:
    """FMI 3.0 ``sources/buildDescription.xml``."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    conf = ET.SubElement(root, "BuildConfiguration", modelIdentifier=model_identifier)
    fs = ET.SubElement(conf, "SourceFileSet", language="C99")
    for f in source_files:
        ET.SubElement(fs, "SourceFile", name=f)
    ET.SubElement(conf, "Library", name="m")
    ET.indent(root, space="  ")
    return _serialize(root)


def _serialize(root: ET.Element) -> bytes:
    text = ET.tostring(root, encoding="unicode")
    return ('<?xml version="1.0" encoding="UTF-8"?>\n' + text + "\n").encode("utf-8")
