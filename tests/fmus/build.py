"""Build the C test FMUs of this folder (Model Exchange and Co-Simulation in one binary each)
with the system C compiler against the FMI headers fmpy ships.

    from build import build_fmu          # tests/fmus on sys.path (conftest)
    path = build_fmu("Feedthrough", out_dir)       # -> out_dir/Feedthrough.fmu

Models (C sources in ``src/``, runtime ``src/glue3.c``):

* ``Feedthrough`` - every FMI 3.0 type (Float32/64, Int8..UInt64, Boolean, String, Binary,
  Enumeration) from an input to an output, plus fixed + tunable parameters;
* ``StateSpace`` - der(x) = A x + B u, y = C x + D u with array variables sized by
  structural parameters;
* ``Resource`` - reads ``resources/y.txt`` at initialization, outputs its first byte;
* ``Countdown`` - an Int32 counter stepped down by time events; asks to terminate at 0; the
  counter also as a String (``left 3``) and a Binary (``03 a5``) output;
* ``Feedthrough2`` - FMI 2.0: Real, Integer, Boolean, String and Enumeration inputs fed
  through, with the outputs' dependencies declared, and the Integer input as a String
  output ``Int32_text`` (runtime ``src/glue2.c``).

The others are FMI 3.0 (runtime ``src/glue3.c``).

The FMUs support getting and setting the FMU state (rollback).
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
import zipfile
from importlib import resources
from pathlib import Path
from xml.sax.saxutils import quoteattr

SRC = Path(__file__).resolve().parent / "src"

# name, value reference, type, causality, variability, start[, dimensions[, attributes]]
_FEED = [("time", 0, "Float64", "independent", "continuous", None)]
_FEED_TYPES = [("Float32_continuous", "Float32", "continuous", "0"),
               ("Float64_continuous", "Float64", "continuous", "0"),
               ("Float64_discrete", "Float64", "discrete", "0"),
               ("Int8", "Int8", "discrete", "0"), ("UInt8", "UInt8", "discrete", "0"),
               ("Int16", "Int16", "discrete", "0"), ("UInt16", "UInt16", "discrete", "0"),
               ("Int32", "Int32", "discrete", "0"), ("UInt32", "UInt32", "discrete", "0"),
               ("Int64", "Int64", "discrete", "0"), ("UInt64", "UInt64", "discrete", "0"),
               ("Boolean", "Boolean", "discrete", "false"),
               ("String", "String", "discrete", "Set me!"),
               ("Binary", "Binary", "discrete", "666f6f"),
               ("Enumeration", "Enumeration", "discrete", "1")]
for _k, (_name, _type, _var, _start) in enumerate(_FEED_TYPES):
    _FEED.append((f"{_name}_input", 2 * _k + 1, _type, "input", _var, _start))
    _FEED.append((f"{_name}_output", 2 * _k + 2, _type, "output", _var, None))
_FEED += [("Float64_fixed_parameter", 31, "Float64", "parameter", "fixed", "1"),
          ("Float64_tunable_parameter", 32, "Float64", "parameter", "tunable", "2"),
          ("Float64_parameter_sum", 33, "Float64", "output", "continuous", None)]

_SS_A = "0 1 0 -2 -0.5 0 0 0 -3"
_SS_I = "1 0 0 0 1 0 0 0 1"
_SS = [("time", 0, "Float64", "independent", "continuous", None),
       ("m", 1, "UInt64", "structuralParameter", "fixed", "3"),
       ("n", 2, "UInt64", "structuralParameter", "fixed", "3"),
       ("r", 3, "UInt64", "structuralParameter", "fixed", "3"),
       ("A", 4, "Float64", "parameter", "fixed", _SS_A, (2, 2)),
       ("B", 5, "Float64", "parameter", "fixed", _SS_I, (2, 1)),
       ("C", 6, "Float64", "parameter", "fixed", _SS_I, (3, 2)),
       ("D", 7, "Float64", "parameter", "fixed", "0 0 0 0 0 0 0 0 0", (3, 1)),
       ("x0", 8, "Float64", "parameter", "fixed", "1 0 0.5", (2,)),
       ("u", 9, "Float64", "input", "continuous", "0 0 0", (1,)),
       ("y", 10, "Float64", "output", "continuous", None, (3,)),
       ("x", 11, "Float64", "local", "continuous", None, (2,)),
       ("der(x)", 12, "Float64", "local", "continuous", None, (2,), 'derivative="11"')]

_RES = [("time", 0, "Float64", "independent", "continuous", None),
        ("y", 1, "Int32", "output", "discrete", None)]

_COUNT = [("time", 0, "Float64", "independent", "continuous", None),
          ("start", 1, "Int32", "parameter", "fixed", "3"),
          ("counter", 2, "Int32", "output", "discrete", None),
          ("x", 3, "Float64", "output", "continuous", None),
          ("der(x)", 4, "Float64", "local", "continuous", None, (), 'derivative="3"'),
          ("label", 5, "String", "output", "discrete", None),
          ("code", 6, "Binary", "output", "discrete", None)]

MODELS = {
    # name: (C file, token, variables, outputs, states (vr, derivative vr), step size)
    "Feedthrough": ("feedthrough.c", "{bgm-test-feedthrough}", _FEED,
                    [v[1] for v in _FEED if v[3] == "output"], [], 0.1),
    "StateSpace": ("statespace.c", "{bgm-test-statespace}", _SS, [10], [(11, 12)], 0.05),
    "Resource": ("resource.c", "{bgm-test-resource}", _RES, [1], [], 0.1),
    "Countdown": ("countdown.c", "{bgm-test-countdown}", _COUNT, [2, 3, 5, 6], [(3, 4)],
                  0.25),
}


_FEED2 = [("time", 0, "Real", "independent", "continuous", None),
          ("Float64_continuous_input", 1, "Real", "input", "continuous", "0"),
          ("Float64_continuous_output", 2, "Real", "output", "continuous", None),
          ("Float64_discrete_input", 3, "Real", "input", "discrete", "0"),
          ("Float64_discrete_output", 4, "Real", "output", "discrete", None),
          ("Int32_input", 5, "Integer", "input", "discrete", "0"),
          ("Int32_output", 6, "Integer", "output", "discrete", None),
          ("Boolean_input", 7, "Boolean", "input", "discrete", "false"),
          ("Boolean_output", 8, "Boolean", "output", "discrete", None),
          ("String_input", 9, "String", "input", "discrete", "Set me!"),
          ("String_output", 10, "String", "output", "discrete", None),
          ("Enumeration_input", 11, "Enumeration", "input", "discrete", "1"),
          ("Enumeration_output", 12, "Enumeration", "output", "discrete", None),
          ("Float64_fixed_parameter", 13, "Real", "parameter", "fixed", "1"),
          ("Float64_tunable_parameter", 14, "Real", "parameter", "tunable", "2"),
          ("Float64_parameter_sum", 15, "Real", "output", "continuous", None),
          ("Int32_text", 16, "String", "output", "discrete", None)]

#: FMI 2.0 models: name -> (C file, GUID, variables, output vr -> input vr it feeds from)
MODELS2 = {"Feedthrough2": ("feedthrough2.c", "{bgm-test-feedthrough2}", _FEED2,
                            {2: 1, 4: 3, 6: 5, 8: 7, 10: 9, 12: 11, 15: None, 16: 5})}


def model_description2(name: str) -> str:
    """The FMI 2.0 ``modelDescription.xml`` of the test FMU ``name``."""
    _, guid, variables, feeds = MODELS2[name]
    body = ""
    for vname, vr, typ, causality, variability, start in variables:
        attrs = f' start={quoteattr(start)}' if start is not None else ""
        if typ == "Enumeration":
            attrs = ' declaredType="Option"' + attrs
        initial = ' initial="calculated"' if causality == "output" else ""
        body += (f'    <ScalarVariable name={quoteattr(vname)} valueReference="{vr}" '
                 f'causality="{causality}" variability="{variability}"{initial}>'
                 f'<{typ}{attrs}/></ScalarVariable>\n')
    outputs = "".join(
        f'      <Unknown index="{vr + 1}" dependencies="{"" if src is None else src + 1}"/>\n'
        for vr, src in feeds.items())
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="2.0" modelName="{name}" guid="{guid}" '
            f'generationTool="bgmodelica test FMUs" numberOfEventIndicators="0">\n'
            f'  <ModelExchange modelIdentifier="{name}" canGetAndSetFMUstate="true"/>\n'
            f'  <CoSimulation modelIdentifier="{name}" canGetAndSetFMUstate="true" '
            f'canHandleVariableCommunicationStepSize="true"/>\n'
            f'  <TypeDefinitions>\n    <SimpleType name="Option">\n      <Enumeration>\n'
            f'        <Item name="Option 1" value="1"/>\n        <Item name="Option 2" '
            f'value="2"/>\n      </Enumeration>\n    </SimpleType>\n  </TypeDefinitions>\n'
            f'  <DefaultExperiment startTime="0" stopTime="2" stepSize="0.1"/>\n'
            f'  <ModelVariables>\n{body}  </ModelVariables>\n'
            f'  <ModelStructure>\n    <Outputs>\n{outputs}    </Outputs>\n'
            f'    <InitialUnknowns>\n{outputs}    </InitialUnknowns>\n'
            f'  </ModelStructure>\n</fmiModelDescription>\n')


def _variable_xml(v: tuple) -> str:
    name, vr, typ, causality, variability, start = v[:6]
    dims = v[6] if len(v) > 6 else ()
    extra = v[7] if len(v) > 7 else ""
    attrs = f'name={quoteattr(name)} valueReference="{vr}" causality="{causality}" ' \
            f'variability="{variability}"'
    if typ == "Enumeration":
        attrs += ' declaredType="Option"'
    if extra:
        attrs += " " + extra
    if causality == "output" and variability == "continuous" and typ.startswith("Float"):
        attrs += ' initial="calculated"'
    children = "".join(f'<Dimension valueReference="{d}"/>' for d in dims)
    if start is not None:
        if typ in ("String", "Binary"):
            children = f"<Start value={quoteattr(start)}/>" + children
        else:
            attrs += f" start={quoteattr(start)}"
    return f"    <{typ} {attrs}>{children}</{typ}>\n" if children else \
        f"    <{typ} {attrs}/>\n"


def model_description(name: str) -> str:
    """The ``modelDescription.xml`` of the test FMU ``name``."""
    _, token, variables, outputs, states, step = MODELS[name]
    structure = "".join(f'    <Output valueReference="{vr}"/>\n' for vr in outputs)
    structure += "".join(f'    <ContinuousStateDerivative valueReference="{d}"/>\n'
                         for _, d in states)
    unknowns = sorted(set(outputs) | {d for _, d in states} | {x for x, _ in states})
    structure += "".join(f'    <InitialUnknown valueReference="{vr}"/>\n' for vr in unknowns)
    body = "".join(_variable_xml(v) for v in variables)
    types = ""
    if name == "Feedthrough":
        types = ('  <TypeDefinitions>\n    <EnumerationType name="Option">\n'
                 '      <Item name="Option 1" value="1"/>\n'
                 '      <Item name="Option 2" value="2"/>\n'
                 '    </EnumerationType>\n  </TypeDefinitions>\n')
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="3.0" modelName="{name}" '
            f'instantiationToken="{token}" generationTool="bgmodelica test FMUs">\n'
            f'  <ModelExchange modelIdentifier="{name}" canGetAndSetFMUState="true"/>\n'
            f'  <CoSimulation modelIdentifier="{name}" canGetAndSetFMUState="true" '
            f'canHandleVariableCommunicationStepSize="true" canReturnEarlyAfterIntermediateUpdate='
            f'"false" hasEventMode="false"/>\n'
            f'{types}'
            f'  <DefaultExperiment startTime="0" stopTime="2" stepSize="{step}"/>\n'
            f'  <ModelVariables>\n{body}  </ModelVariables>\n'
            f'  <ModelStructure>\n{structure}  </ModelStructure>\n'
            f'</fmiModelDescription>\n')


def _compiler() -> str:
    for cc in ("cc", "gcc", "clang"):
        if shutil.which(cc):
            return cc
    raise RuntimeError("no C compiler (cc, gcc or clang) to build the test FMUs")


def build_fmu(name: str, out_dir: str | Path, resource_text: str | None = "A") -> Path:
    """Compile the test FMU ``name`` and zip it into ``out_dir/name.fmu`` (Linux x86-64).
    ``resource_text``: the content of ``resources/y.txt`` (Resource; None: no file)."""
    fmi2 = name in MODELS2
    source = (MODELS2 if fmi2 else MODELS)[name][0]
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    headers = Path(str(resources.files("fmpy"))) / "c-code"
    with tempfile.TemporaryDirectory() as tmp:
        lib = Path(tmp) / f"{name}.so"
        run = subprocess.run([_compiler(), "-shared", "-fPIC", "-O1", "-std=gnu99",
                              f"-I{headers}", f"-I{SRC}", "-o", str(lib), str(SRC / source)],
                             capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise RuntimeError(f"compiling {source} failed:\n{run.stderr}")
        fmu = out_dir / f"{name}.fmu"
        with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.writestr("modelDescription.xml",
                        model_description2(name) if fmi2 else model_description(name))
            zf.write(lib, f"binaries/{'linux64' if fmi2 else 'x86_64-linux'}/{name}.so")
            if name == "Resource" and resource_text is not None:
                zf.writestr("resources/y.txt", resource_text)
            for src in (("glue2.c",) if fmi2 else ("glue3.h", "glue3.c")) + (source,):
                zf.write(SRC / src, f"sources/{src}")
    return fmu
