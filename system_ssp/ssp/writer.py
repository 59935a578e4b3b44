"""Writing SSP 1.0 systems (.ssd) and parameter sets (.ssv) from short Python descriptions.

The product's system generators (system_ssp.systems.generators) describe each system as a spec
(components, connections, parameter files, master settings, schedule) and write it with
`SystemWriter`. Every component lists all its inputs, outputs and parameters as SSD connectors
with the types and units of the built FMU (read from `fmu_dir`), connections are checked against
those connectors, numbers are written with full precision (repr), and every file is written
atomically. The output is byte-for-byte reproducible, which `python -m system_ssp.systems
--check` relies on.
"""
from pathlib import Path
import shutil
from xml.sax.saxutils import escape, quoteattr

from fmpy import read_model_description

from ..atomic import write_text_atomic
from ..errors import SSPError
from .reader import ANNOTATION_TYPE, CONDITION_CAUSALITIES, NS_NC, NS_SSC, NS_SSD, NS_SSV
from .units import SI_BASE_UNITS

NS_OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
NS = f'xmlns:ssd="{NS_SSD}" xmlns:ssc="{NS_SSC}" xmlns:ssv="{NS_SSV}"'


class GeneratorError(RuntimeError):
    """A system spec that does not match the FMUs (unknown variable, wrong causality or type)."""


def vec(name, values):
    """{name[1]: v1, name[2]: v2, ...}: a vector parameter as FMI structured names."""
    return {f"{name}[{i}]": v for i, v in enumerate(values, 1)}


def typed_value(value):
    if isinstance(value, bool):
        return f'<ssv:Boolean value="{str(value).lower()}"/>'
    if isinstance(value, int):
        return f'<ssv:Integer value="{int(value)}"/>'
    if isinstance(value, float):
        return f'<ssv:Real value="{float(value)!r}"/>'  # float(): numpy scalars repr as np.float64(..)
    return f"<ssv:String value={quoteattr(value)}/>"


def xml_comment(text):
    """`text` as the content of an XML comment, which may not hold "--" nor end with "-"."""
    text = str(text)
    while "--" in text:
        text = text.replace("--", "- -")
    return text + " " if text.endswith("-") else text


def ssv_text(name, description, params):
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<!-- {xml_comment(description)} -->',
             f'<ssv:ParameterSet xmlns:ssv="{NS_SSV}" version="1.0" name={quoteattr(name)}>',
             "  <ssv:Parameters>"]
    for key, value in params.items():
        lines.append(f'    <ssv:Parameter name={quoteattr(key)}>{typed_value(value)}</ssv:Parameter>')
    lines += ["  </ssv:Parameters>", "</ssv:ParameterSet>", ""]
    return "\n".join(lines)


def connector_xml(var):
    if var.type == "Real":
        t = f'<ssc:Real unit="{var.unit}"/>' if var.unit else "<ssc:Real/>"
    elif var.type == "Enumeration":  # SSP names the enumeration type (an FMU's declaredType)
        t = f'<ssc:Enumeration name={quoteattr(var.declaredType.name if var.declaredType else "")}/>'
    else:
        t = f"<ssc:{var.type}/>"
    return f'        <ssd:Connector name={quoteattr(var.name)} kind="{var.causality}">{t}</ssd:Connector>'


class SystemWriter:
    """Writes systems into `directory` (`<name>.ssd`) and parameter sets into
    `directory/parameters/`, with connectors read from the FMUs in `fmu_dir`."""

    def __init__(self, directory, fmu_dir):
        self.directory = Path(directory)
        self.parameters = self.directory / "parameters"
        self.fmu_dir = Path(fmu_dir)
        self.written = []
        self._fmus = {}
        self.fmu_files = {}  # FMUs outside fmu_dir: resource name -> path (system specs)

    def fmu_variables(self, fmu_name):
        """(model variables, {unit name: BaseUnit}) of build/fmus/<fmu_name>.fmu."""
        if fmu_name not in self._fmus:
            path = self.fmu_files.get(fmu_name, self.fmu_dir / f"{fmu_name}.fmu")
            if not path.is_file():
                raise GeneratorError(f"{path} not found: build the FMUs first (python build_fmus.py)")
            md = read_model_description(str(path))
            self._fmus[fmu_name] = (md.modelVariables, {u.name: u.baseUnit for u in md.unitDefinitions})
        return self._fmus[fmu_name]

    def _write(self, path, text):
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(path, text)
        self.written.append(path)

    def ssv(self, file_stem, description, params, name=None):
        """Write parameters/<file_stem>.ssv (ssv:ParameterSet name `name`, default file_stem)."""
        self._write(self.parameters / f"{file_stem}.ssv", ssv_text(name or file_stem, description, params))

    def ssv_copy(self, source_stem, file_stem):
        """parameters/<file_stem>.ssv with the content of parameters/<source_stem>.ssv (written
        before): the same parameter set under another system's name."""
        self._write(self.parameters / f"{file_stem}.ssv", (self.parameters / f"{source_stem}.ssv").read_text())

    def ssd(self, name, spec):
        """Write <name>.ssd from a spec: components as (instance, FMU model identifier, [parameter
        files in parameters/, without .ssv]), connections as (source, output, destination, input,
        n[, transform]) with n > 0 for structured names out[1]..out[n] or n = 0 for a scalar (transform:
        {"factor", "offset", "linear", "suppress"}, an ssc:LinearTransformation and/or
        suppressUnitConversion), optional "algorithm" (default gauss-seidel), "record" (the
        signals recorded by default, nc:Record),
        "parameters" (system parameters, see _system_parameters_xml) and "parameter_bindings", "stop"
        Boolean outputs, "order", "stop_time", "step_size", and "schedule": a schedule.Schedule
        for an nc:Schedule (the type the reader returns). libcosim applies only a component's
        first ParameterBinding: put the one that matters first."""
        self._write(self.directory / f"{name}.ssd", self.ssd_text(name, spec))

    def ssd_text(self, name, spec):
        all_units = {}
        comp_vars = {}
        out = ['<?xml version="1.0" encoding="UTF-8"?>',
               # Namespace on the root: libcosim's parser takes xmlns attributes on inner
               # elements for child elements.
               f'<ssd:SystemStructureDescription {NS} xmlns:osp="{NS_OSP}" version="1.0" name="{name}">',
               f'  <ssd:System name="{name}" description={quoteattr(spec["description"])}>']
        for inst, fmu, _ in spec["components"]:
            variables, units = self.fmu_variables(fmu)
            all_units.update(units)
            comp_vars[inst] = {v.name: v for v in variables}
        out += _system_parameters_xml(name, spec, comp_vars)
        out.append("    <ssd:Elements>")
        for inst, fmu, concerns in spec["components"]:
            variables, _ = self.fmu_variables(fmu)
            out.append(f'      <ssd:Component name="{inst}" type="application/x-fmu-sharedlibrary" '
                       f'source="resources/{fmu}.fmu">')
            out.append("        <ssd:Connectors>")
            out += ["  " + connector_xml(v) for v in variables if v.causality in ("input", "output", "parameter")]
            out.append("        </ssd:Connectors>")
            bindings = [f'<ssd:ParameterBinding source="parameters/{c}.ssv"/>' for c in concerns]
            if bindings:  # the schema refuses an empty ParameterBindings element
                out.append("        <ssd:ParameterBindings>")
                out += [f"          {b}" for b in bindings]
                out.append("        </ssd:ParameterBindings>")
            out.append("      </ssd:Component>")
        out.append("    </ssd:Elements>")
        links = []  # the schema refuses an empty ssd:Connections
        for src, sname, dst, dname, n, *transform in spec["connections"]:
            pairs = [(f"{sname}[{i}]", f"{dname}[{i}]") for i in range(1, n + 1)] if n else [(sname, dname)]
            tr = transform[0] if transform else {}
            for a, b in pairs:
                va, vb = comp_vars[src].get(a), comp_vars[dst].get(b)
                if va is None or vb is None or va.causality != "output" or vb.causality != "input":
                    raise GeneratorError(f"{name}: {src}.{a} -> {dst}.{b} is not output -> input")
                head = (f'      <ssd:Connection startElement="{src}" startConnector={quoteattr(a)} '
                        f'endElement="{dst}" endConnector={quoteattr(b)}'
                        + (' suppressUnitConversion="true"' if tr.get("suppress") else ""))
                if tr.get("linear"):
                    links += [head + ">", f'        <ssc:LinearTransformation factor="{float(tr["factor"])!r}" '
                              f'offset="{float(tr["offset"])!r}"/>', "      </ssd:Connection>"]
                else:
                    links.append(head + "/>")
        for pname, (_, targets) in spec.get("parameters", {}).items():
            for comp, var in targets:
                links.append(f'      <ssd:Connection startConnector={quoteattr(pname)} endElement="{comp}" '
                             f'endConnector={quoteattr(var)}/>')
        if links:
            out += ["    <ssd:Connections>", *links, "    </ssd:Connections>"]
        dt = spec["step_size"]
        for comp, var in spec.get("stop", []):
            if comp_vars[comp][var].type != "Boolean" or comp_vars[comp][var].causality != "output":
                raise GeneratorError(f"{name}: stop signal {comp}.{var} must be a Boolean output")
        out += ["    <ssd:Annotations>",
                f'      <ssc:Annotation type="{ANNOTATION_TYPE}">',
                f'        <nc:Master xmlns:nc="{NS_NC}" stepSize="{dt!r}" '
                f'algorithm="{spec.get("algorithm", "gauss-seidel")}">',
                *([f'          <nc:Order>{" ".join(spec["order"])}</nc:Order>'] if spec.get("order") else [])]
        out += [f'          <nc:StopCondition component="{c}" connector="{v}"/>' for c, v in spec.get("stop", [])]
        if spec.get("schedule"):
            out += _schedule_xml(name, spec["schedule"], comp_vars)
        if spec.get("record"):
            out.append(f'          <nc:Record>{escape(" ".join(spec["record"]))}</nc:Record>')
        out += ["        </nc:Master>", "      </ssc:Annotation>", "    </ssd:Annotations>", "  </ssd:System>"]
        if all_units:  # the schema refuses an empty ssd:Units
            out.append("  <ssd:Units>")
            for uname in sorted(all_units):
                bu = all_units[uname]
                attrs = " ".join(f'{k}="{getattr(bu, k)}"' for k in SI_BASE_UNITS if bu is not None and getattr(bu, k))
                out.append(f'    <ssc:Unit name="{uname}"><ssc:BaseUnit {attrs}/></ssc:Unit>')
            out.append("  </ssd:Units>")
        # libcosim takes its fixed step from this OSP annotation (our master reads its own).
        out += [f'  <ssd:DefaultExperiment startTime="0.0" stopTime="{spec["stop_time"]!r}">',
                "    <ssd:Annotations>",
                '      <ssc:Annotation type="com.opensimulationplatform">',
                '        <osp:Algorithm>',
                f'          <osp:FixedStepAlgorithm baseStepSize="{dt!r}"/>',
                "        </osp:Algorithm>",
                "      </ssc:Annotation>",
                "    </ssd:Annotations>",
                "  </ssd:DefaultExperiment>"]
        out += ["</ssd:SystemStructureDescription>", ""]
        return "\n".join(out)


def _system_parameters_xml(name, spec, comp_vars):
    """The system's parameter connectors and their ParameterBindings: spec "parameters" =
    {name: (description, [(component, parameter), ...])}, each given once (in the system's
    "parameter_bindings" files, names without a component) and handed by parameter connections to
    every component parameter listed; all targets share one type and unit."""
    params = spec.get("parameters", {})
    if not params:
        return []
    out = ["    <ssd:Connectors>"]
    for pname, (description, targets) in params.items():
        kinds = set()
        for comp, var in targets:
            v = comp_vars.get(comp, {}).get(var)
            if v is None or v.causality != "parameter":
                raise GeneratorError(f"{name}: system parameter {pname}: {comp}.{var} is not a parameter")
            kinds.add((v.type, v.unit if v.type == "Real" else None))
        if len(kinds) != 1:
            raise GeneratorError(f"{name}: system parameter {pname}: its targets differ in type or unit: {kinds}")
        vtype, unit = kinds.pop()
        t = f'<ssc:Real unit="{unit}"/>' if vtype == "Real" and unit else f"<ssc:{vtype}/>"
        out.append(f"      <!-- {xml_comment(description)} -->")
        out.append(f'      <ssd:Connector name={quoteattr(pname)} kind="parameter">{t}</ssd:Connector>')
    out.append("    </ssd:Connectors>")
    files = spec.get("parameter_bindings", [])
    if files:
        out.append("    <ssd:ParameterBindings>")
        out += [f'      <ssd:ParameterBinding source="parameters/{f}.ssv"/>' for f in files]
        out.append("    </ssd:ParameterBindings>")
    return out


def _schedule_xml(name, schedule, comp_vars):
    """nc:Schedule lines, checked against the FMUs' variables."""
    def check(comp, var, types, causalities=("output",)):
        v = comp_vars.get(comp, {}).get(var)
        if v is None or v.causality not in causalities or v.type not in types:
            raise GeneratorError(f"{name}: schedule signal {comp}.{var} must be {' or '.join(causalities)} of type "
                                 f"{' or '.join(types)}")

    out = ["          <nc:Schedule>"]
    for mode in schedule.modes:
        for comp in list(mode.active or []) + list(mode.every):
            if comp not in comp_vars:
                raise GeneratorError(f"{name}: schedule mode {mode.name} lists unknown component {comp}")
        attrs = f'name="{mode.name}" stepSize="{mode.step_size!r}"'
        if mode.active is not None:
            attrs += f' active="{" ".join(mode.active)}"'
        if mode.record_every != 1:
            attrs += f' recordEvery="{mode.record_every}"'
        if mode.every:
            attrs += f' every="{" ".join(f"{c}:{k}" for c, k in mode.every.items())}"'
        if not mode.conditions:
            out.append(f"            <nc:Mode {attrs}/>")
            continue
        out.append(f"            <nc:Mode {attrs}>")
        for comp, var, values in mode.conditions:
            check(comp, var, ("Integer", "Enumeration", "Boolean"), CONDITION_CAUSALITIES)
            out.append(f'              <nc:When component="{comp}" connector="{var}" '
                       f'values="{" ".join(str(int(v)) for v in values)}"/>')
        out.append("            </nc:Mode>")
    for comp, var in schedule.events:
        check(comp, var, ("Real",))
        out.append(f'            <nc:NextEvent component="{comp}" connector="{var}"/>')
    out.append("          </nc:Schedule>")
    return out


def single_fmu_system(fmu, folder):
    """A system of one component, the FMU `fmu`, written into `folder` (SystemStructure.ssd and
    resources/<Model>.fmu): how `run MODEL.fmu` runs an FMU alone. The component is named after
    the FMU's model identifier; the FMU's DefaultExperiment (if any) becomes the system's.
    Returns the SSD's path."""
    fmu, folder = Path(fmu), Path(folder)
    try:  # checked as a component when the system is loaded (leniently, or strictly)
        md = read_model_description(str(fmu), validate=False)
    except Exception as exc:  # fmpy raises several kinds for a file that is not an FMU
        raise SSPError(f"{fmu}: not an FMU that can be read ({exc})") from None
    if md.coSimulation is None:
        raise SSPError(f"{fmu}: has no co-simulation interface (model exchange only), which the master needs")
    name = md.coSimulation.modelIdentifier
    (folder / "resources").mkdir(parents=True, exist_ok=True)
    shutil.copyfile(fmu, folder / "resources" / f"{name}.fmu")
    de = md.defaultExperiment
    times = "" if de is None else "".join(f' {attr}="{value}"' for attr, value in (
        ("startTime", de.startTime), ("stopTime", de.stopTime)) if value is not None)
    ssd = folder / "SystemStructure.ssd"
    write_text_atomic(ssd, "\n".join([
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<ssd:SystemStructureDescription {NS} version="1.0" name={quoteattr(name)}>',
        f'  <ssd:System name={quoteattr(name)} description={quoteattr(f"{fmu.name} alone")}>',
        "    <ssd:Elements>",
        f'      <ssd:Component name={quoteattr(name)} type="application/x-fmu-sharedlibrary" '
        f'source="resources/{name}.fmu"/>',
        "    </ssd:Elements>",
        "  </ssd:System>",
        *([f"  <ssd:DefaultExperiment{times}/>"] if times else []),
        "</ssd:SystemStructureDescription>", ""]))
    return ssd
