"""The FMI 3.0 model description of an FMU, written from the FMI 2.0 one the builder completes
(one declaration, two standards).

The wrappers declare vectors and matrices element by element (`q_BN[1]` .. `q_BN[4]`,
`dcm_BN[1,1]` .. `dcm_BN[3,3]`), which FMI 2.0 needs. FMI 3.0 has arrays: each run of elements
that forms a whole vector or a whole matrix in row-major order, with consecutive value references
and the same causality, variability, initial, type and unit, becomes one array variable with
`<Dimension start="n"/>` (a matrix: two), whose value reference is its first element's. The
runtime's loader expands it again (`arrays=` in neighbor_runtime.txt). Types: Real -> Float64,
Integer -> Int32, Boolean and String as they are. Units, descriptions, causality, variability,
initial, start values, the default experiment, output dependencies and initial unknowns are
carried over; dependencies name value references, as FMI 3.0 wants.
"""
import re
from xml.etree import ElementTree as ET
import zipfile

TYPES = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "String": "String"}
_ELEMENT = re.compile(r"^(?P<base>.+)\[(?P<i>\d+)(?:,(?P<j>\d+))?\]$")
# how a wrapper describes one element (neighbor_fmu_support: "... (component 2)"; matrices name
# the element): removed for the array's description
_ELEMENT_WORDS = [re.compile(r" \(component \d+\)$"), re.compile(r" element \(\d+,\d+\)")]


def _scalar(sv):
    """(type element name, type element) of an FMI 2.0 ScalarVariable."""
    for child in sv:
        if child.tag in TYPES:
            return child.tag, child
    raise ValueError(f"variable {sv.get('name')}: no type element")


def _signature(sv):
    kind, typ = _scalar(sv)
    return (kind, sv.get("causality"), sv.get("variability"), sv.get("initial"), typ.get("unit"))


def _array_shape(run):
    """(dimensions) when the ScalarVariables `run` (same base name, in declaration order) are a
    whole vector [1..n] or a whole matrix [1,1]..[r,c] in row-major order with consecutive value
    references and one signature; else None."""
    indices = []
    for sv in run:
        m = _ELEMENT.match(sv.get("name"))
        indices.append((int(m["i"]),) if m["j"] is None else (int(m["i"]), int(m["j"])))
    vrs = [int(sv.get("valueReference")) for sv in run]
    if vrs != list(range(vrs[0], vrs[0] + len(vrs))) or len({_signature(sv) for sv in run}) != 1:
        return None
    if all(len(ix) == 1 for ix in indices):
        return (len(run),) if [ix[0] for ix in indices] == list(range(1, len(run) + 1)) else None
    if all(len(ix) == 2 for ix in indices):
        rows, cols = max(ix[0] for ix in indices), max(ix[1] for ix in indices)
        expected = [(i, j) for i in range(1, rows + 1) for j in range(1, cols + 1)]
        return (rows, cols) if indices == expected else None
    return None


def _runs(variables):
    """[(name, [ScalarVariable], dimensions or None)]: elements of one base name that follow each
    other grouped; everything else alone."""
    out, i = [], 0
    while i < len(variables):
        m = _ELEMENT.match(variables[i].get("name"))
        if m:
            j = i + 1
            while j < len(variables):
                mj = _ELEMENT.match(variables[j].get("name"))
                if not mj or mj["base"] != m["base"]:
                    break
                j += 1
            run = variables[i:j]
            shape = _array_shape(run) if len(run) > 1 else None
            if shape:
                out.append((m["base"], run, shape))
            else:
                out.extend((sv.get("name"), [sv], None) for sv in run)
            i = j
        else:
            out.append((variables[i].get("name"), [variables[i]], None))
            i += 1
    return out


def _description(text, shape):
    if not shape or not text:
        return text
    for pattern in _ELEMENT_WORDS:
        text = pattern.sub("", text)
    return text


def fmi3_model_description(fmi2_xml, token, can_get_set_state):
    """(FMI 3.0 modelDescription.xml bytes, {array value reference: number of elements}, value
    reference of time) from the completed FMI 2.0 description `fmi2_xml` (bytes); `token` is the
    instantiation token."""
    src = ET.fromstring(fmi2_xml)
    cs2 = src.find("CoSimulation")
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": src.get("modelName"), "instantiationToken": token,
        **{k: src.get(k) for k in ("description", "author", "version", "license") if src.get(k) is not None},
        "generationTool": f"neighbor-cosim (from {src.get('generationTool')})",
        "variableNamingConvention": "structured"})
    ET.SubElement(root, "CoSimulation", {
        "modelIdentifier": cs2.get("modelIdentifier"),
        "needsExecutionTool": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false",
        "canGetAndSetFMUState": "true" if can_get_set_state else "false",
        "canSerializeFMUState": "false",
        "providesDirectionalDerivatives": "false",
        "providesAdjointDerivatives": "false",
        "providesPerElementDependencies": "false",
        "canHandleVariableCommunicationStepSize": cs2.get("canHandleVariableCommunicationStepSize", "true"),
        "providesIntermediateUpdate": "false",
        "canReturnEarlyAfterIntermediateUpdate": "false",
        "hasEventMode": "false",
    })
    units = src.find("UnitDefinitions")
    if units is None:
        units = ET.Element("UnitDefinitions")
    if not any(u.get("name") == "s" for u in units):  # time's unit
        ET.SubElement(ET.SubElement(units, "Unit", name="s"), "BaseUnit", s="1")
        units[:] = sorted(units, key=lambda u: u.get("name"))
    root.append(units)
    cats = src.find("LogCategories")
    if cats is not None:
        out = ET.SubElement(root, "LogCategories")
        for c in cats:
            ET.SubElement(out, "Category", name=c.get("name"),
                          description=c.get("description", "").replace("fmi2", "fmi3"))
    exp = src.find("DefaultExperiment")
    if exp is not None:
        root.append(exp)
    variables = src.find("ModelVariables").findall("ScalarVariable")
    element_to_array, arrays, time_vr = _model_variables(ET.SubElement(root, "ModelVariables"), variables)
    index_to_vr = {i + 1: int(sv.get("valueReference")) for i, sv in enumerate(variables)}
    _model_structure(ET.SubElement(root, "ModelStructure"), src.find("ModelStructure"),
                     lambda index: element_to_array[index_to_vr[int(index)]])
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8"), arrays, time_vr


def _model_variables(mv, variables):
    """Fill ModelVariables `mv` from the FMI 2.0 ScalarVariables; ({element's value reference: its
    FMI 3.0 variable's}, {array value reference: elements}, time's value reference)."""
    element_to_array, arrays = {}, {}
    # FMI 3.0 declares the independent variable; the model's own value references stay as they
    # are, so time takes the next free one (the loader answers it: `time=` in the runtime config)
    time_vr = max((int(sv.get("valueReference")) for sv in variables), default=-1) + 1
    ET.SubElement(mv, "Float64", name="time", valueReference=str(time_vr), causality="independent",
                  variability="continuous", description="Simulation time", unit="s")
    for name, run, shape in _runs(variables):
        first = run[0]
        kind, typ = _scalar(first)
        vr = int(first.get("valueReference"))
        attrs = {"name": name, "valueReference": str(vr)}
        for key in ("description", "causality", "variability", "initial"):
            value = _description(first.get(key), shape) if key == "description" else first.get(key)
            if value is not None:
                attrs[key] = value
        if typ.get("unit") is not None:
            attrs["unit"] = typ.get("unit")
        starts = [_scalar(sv)[1].get("start") for sv in run]
        has_start = all(s is not None for s in starts)
        if kind != "String" and has_start:
            attrs["start"] = " ".join(starts)
        el = ET.SubElement(mv, TYPES[kind], attrs)
        if kind == "String" and has_start:
            for s in starts:
                ET.SubElement(el, "Start", value=s)
        for size in shape or ():
            ET.SubElement(el, "Dimension", start=str(size))
        for sv in run:
            element_to_array[int(sv.get("valueReference"))] = vr
        if shape:
            arrays[vr] = len(run)
    return element_to_array, arrays, time_vr


def _model_structure(ms, structure, variable_of):
    """Fill ModelStructure `ms` from the FMI 2.0 one: an array's elements' Unknowns become one,
    with the union of their dependencies (`variable_of(index)`: the FMI 3.0 value reference of
    the FMI 2.0 variable at that index)."""
    for section, tag in (("Outputs", "Output"), ("InitialUnknowns", "InitialUnknown")):
        unknowns = {}  # the FMI 3.0 variable -> its elements' dependencies (None: not stated)
        holder = structure.find(section)
        for unknown in [] if holder is None else holder:
            vr = variable_of(unknown.get("index"))
            deps = unknown.get("dependencies")
            if deps is None:
                unknowns[vr] = None
            elif unknowns.get(vr, {}) is not None:
                unknowns.setdefault(vr, {}).update(dict.fromkeys(variable_of(d) for d in deps.split()))
        for vr, deps in unknowns.items():
            attrs = {"valueReference": str(vr)}
            if deps is not None:
                attrs["dependencies"] = " ".join(map(str, sorted(deps)))
            ET.SubElement(ms, tag, attrs)


FEATURES_BEGIN = "<!-- fmi3 features: written by system_ssp.fmi3_description.features_table; do not edit -->"
FEATURES_END = "<!-- end fmi3 features -->"


def features_table(fmus):
    """The docs' table of the FMI 3.0 features each FMU (an FMI 3.0 .fmu path) uses: its array
    variables with their shapes, its variable types, whether it can get and set its state."""
    lines = ["| FMU | arrays | types | FMU state |", "|---|---|---|---|"]
    for path in sorted(fmus, key=lambda p: p.stem):
        with zipfile.ZipFile(path) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
        arrays, types = [], []
        for v in root.find("ModelVariables"):
            if v.get("causality") == "independent":
                continue
            dims = [d.get("start") for d in v.findall("Dimension")]
            if dims:
                arrays.append(f"`{v.get('name')}`[{','.join(dims)}]")
            if v.tag not in types:
                types.append(v.tag)
        state = "get/set" if root.find("CoSimulation").get("canGetAndSetFMUState") == "true" else "no"
        types = [t for t in TYPES.values() if t in types]
        lines.append(f"| {path.stem} | {', '.join(arrays) or '-'} | {', '.join(types)} | {state} |")
    return "\n".join(lines)
