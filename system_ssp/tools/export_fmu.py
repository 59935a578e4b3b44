"""`neighbor-cosim export-fmu SYSTEM --out X.fmu [--fmi 2|3]`: a whole system as one FMI
co-simulation FMU, for tools that import only FMUs (Simulink's FMU block, Dymola, a HIL rig).

The system is loaded and resolved by our master (its connections, every parameter set, mapping
and system parameter, its Gauss-Seidel order and step); the FMU is built by fmu-manipulation-
toolbox's FMU Container (a C runtime that embeds the system's FMUs unchanged and steps them in
that order at that step: no Python of its own, so the target needs what the embedded FMUs need,
CPython and numpy for ours). Its variables are the signals exported (by default every output of
every component, named component.variable) and every parameter of every component (its start the
value the system binds), with the units and descriptions of the components' FMUs and no direct
feedthrough declared (the container's outputs change only in a step). What a
host must allow, and what a container cannot do, is in docs/compose.md#exporting-a-system-as-one-fmu.
"""
import json
import logging
from pathlib import Path
import re
import shutil
import tempfile
import zipfile

from fmpy.validation import validate_fmu
from fmu_manipulation_toolbox.assembly import Assembly, AssemblyError
from fmu_manipulation_toolbox.container import FMUContainerError
from lxml import etree

from ..atomic import atomic_write, check_output_place
from ..errors import SSPError
from ..master import System
from ..master.plan import RunOptions
from ..master.planning import make_plan
from .console import ArgumentParser, positive_float, system_path

FMI_VERSIONS = (2, 3)


def _json_value(value):
    if hasattr(value, "item"):  # a numpy scalar
        value = value.item()
    return value


def container_description(system, plan, outputs, inputs, name):
    """The FMU Container's JSON description of the loaded `system` run as `plan`: the FMUs in
    the plan's order (stepped one after the other: Gauss-Seidel), its connections, every start
    value the master would apply, the exported outputs and inputs. SSPError for what a container
    cannot do."""
    comps = system.comps
    if plan.multiples and any(k != 1 for k in plan.multiples):
        slow = [comps[i].name for i, k in enumerate(plan.multiples) if k != 1]
        raise SSPError(f"{system.desc.display}: {', '.join(slow)} step every k-th step (nc:StepMultiple): a container "
                       "steps every FMU every step")
    files = {}  # component -> its FMU's file name in the container (unique; a.b and a_b both give a_b)
    for c in comps:
        stem = re.sub(r"[^A-Za-z0-9_]", "_", c.name)
        file, k = f"{stem}.fmu", 1
        while file in files.values():
            k += 1
            file = f"{stem}_{k}.fmu"
        files[c.index] = file
    links = []
    for lk in system.links:
        if lk.factor != 1.0 or lk.offset != 0.0 or lk.mapping:
            raise SSPError(f"{system.desc.display}: connection {lk.label} converts its value (a unit conversion or "
                           "a transformation), which a container's links cannot")
        links.append([files[lk.src], lk.src_var, files[lk.dst], lk.dst_var])
    start = [[files[ci], var, _json_value(v)] for (ci, var), v in plan.params.items()]
    exported = [[files[c.index], var, f"{c.name}.{var}"] for c, var in outputs]
    given = [[f"{c.name}.{var}", files[c.index], var] for c, var in inputs]
    return {"name": f"{name}.fmu", "mt": False, "profiling": False, "sequential": plan.algorithm == "gauss-seidel",
            "auto_link": False, "auto_input": False, "auto_output": False, "auto_parameter": True,
            "auto_local": False, "step_size": plan.step_size,
            "fmu": [files[i] for i in plan.order], "link": links, "start": start, "output": exported,
            "input": given}, files


def _signals(system, names, causality, what):
    """[(component, variable)] of `names` ("comp.var" or "comp.vector"), each of `causality`."""
    out = []
    for name in names:
        # the longest component name that prefixes `name` wins, as the master's split_name has it
        comp = next((c for c in sorted(system.comps, key=lambda c: -len(c.name)) if name.startswith(c.name + ".")),
                    None)
        var = name[len(comp.name) + 1:] if comp is not None else ""
        elements = ([var] if var in comp.vars else comp.whole(var)) if comp is not None else None
        if not elements:  # a vector name gives its elements; anything else is refused with close matches
            system.split_name(name, what)
        for v in elements:
            if comp.vars[v].causality != causality:
                raise SSPError(f"{what} {comp.name}.{v}: it is {comp.vars[v].causality}, expected {causality}")
            out.append((comp, v))
    return out


def _fix_parameters(root, fmi, by_name, starts):
    """What the container writes of the parameters it exposes, corrected: a String's start is the
    value the system binds (the container writes it behind a line break), and FMI 3.0's array
    aggregates of an FMI 2.0 FMU's elements (no start, which FMI 3.0 requires of a parameter;
    the elements are there) go."""
    holder = root.find("ModelVariables")
    for el in list(holder):
        if not isinstance(el.tag, str) or el.get("causality") != "parameter":
            continue
        if fmi == 3 and el.get("start") is None and el.find("Start") is None and el.find("Dimension") is not None:
            holder.remove(el)
            continue
        name = el.get("name")
        if name not in by_name:
            continue
        comp, var = by_name[name]
        if comp.vars[var].type != "String":
            continue
        value = starts.get((comp.index, var), comp.vars[var].start)
        if value is None:
            continue
        if fmi == 2 and el.find("String") is not None:
            el.find("String").set("start", str(value))
        elif fmi == 3 and el.find("Start") is not None:
            el.find("Start").set("value", str(value))


def _finish_model_description(fmu, system, outputs, inputs, fmi, about, starts):
    """The container's modelDescription.xml with what it leaves out: each variable's unit (and the
    unit definitions), the system's description, and, FMI 2.0, its outputs' dependencies (none:
    a container's outputs change only in a step). Rewritten in place, every other member kept."""
    with zipfile.ZipFile(fmu) as z:
        members = {i.filename: (i, z.read(i.filename)) for i in z.infolist()}
    root = etree.fromstring(members["modelDescription.xml"][1])
    by_name = {f"{c.name}.{v}": (c, v) for c in system.comps for v in c.vars}
    _drop_shadowed_locals(root, fmi)
    _fix_parameters(root, fmi, by_name, starts)
    units = {}
    for el in root.iter():
        if not isinstance(el.tag, str) or el.get("name") not in by_name:
            continue
        comp, var = by_name[el.get("name")]
        unit = comp.vars[var].unit if comp.vars[var].type == "Real" else None
        if unit is None and comp.vars[var].declaredType is not None:
            unit = getattr(comp.vars[var].declaredType, "unit", None)
        if not unit:
            continue
        typed = el if fmi == 3 else el.find("Real")
        if typed is not None:
            typed.set("unit", unit)
            units[unit] = next((u for u in comp.md.unitDefinitions if u.name == unit), None)
    root.set("description", about)
    root.set("generationTool", f"neighbor-cosim export-fmu with {root.get('generationTool', 'FMUContainer')}")
    if units:
        holder = etree.Element("UnitDefinitions")
        for unit in sorted(units):
            u = etree.SubElement(holder, "Unit", name=unit)
            base = units[unit].baseUnit if units[unit] is not None else None
            if base is not None:
                attrs = {k: str(getattr(base, k)) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad", "factor",
                                                             "offset") if getattr(base, k, None) not in (None, 0)}
                if fmi == 2 and attrs.get("factor") == "1.0":
                    attrs.pop("factor")
                etree.SubElement(u, "BaseUnit", **attrs)
        old = root.find("UnitDefinitions")
        if old is not None:
            root.remove(old)
        anchor = root.find("ModelExchange" if root.find("ModelExchange") is not None else "CoSimulation")
        anchor.addnext(holder)
    if fmi == 2:
        for unknown in root.iterfind("ModelStructure/Outputs/Unknown"):
            unknown.set("dependencies", "")
        for unknown in root.iterfind("ModelStructure/InitialUnknowns/Unknown"):
            unknown.set("dependencies", "")
    else:
        for unknown in root.iterfind("ModelStructure/Output"):
            unknown.set("dependencies", "")
    text = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
    with atomic_write(fmu, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as z:
        for name, (info, data) in members.items():
            z.writestr(info, text if name == "modelDescription.xml" else data)


def _drop_shadowed_locals(root, fmi):
    """The container lists the values its links carry as local variables named component.variable;
    where such a name is also an exported output's, the local goes (a name is unique in an FMU;
    the container's binary knows its variables by value reference, not by name). FMI 2.0's
    ModelStructure refers to variables by position: renumbered."""
    holder = root.find("ModelVariables")
    variables = [v for v in holder if isinstance(v.tag, str)]
    exported = {v.get("name") for v in variables if v.get("causality") in ("output", "input", "parameter")}
    keep = [v for v in variables if not (v.get("causality") == "local" and v.get("name") in exported)]
    if len(keep) == len(variables):
        return
    position = {id(v): k for k, v in enumerate(keep, 1)}
    renumber = {str(k): str(position[id(v)]) for k, v in enumerate(variables, 1) if id(v) in position}
    for v in variables:
        if id(v) not in position:
            holder.remove(v)
    if fmi == 2:
        for unknown in root.iterfind("ModelStructure//Unknown"):
            unknown.set("index", renumber[unknown.get("index")])
            deps = unknown.get("dependencies")
            if deps:
                unknown.set("dependencies", " ".join(renumber[d] for d in deps.split()))


def export_fmu(source, out, fmi=2, outputs=None, inputs=None, step_size=None):
    """Write `out` (.fmu): the system at `source` as one co-simulation FMU (FMI `fmi`), exporting
    `outputs` (names comp.var; default every output) and `inputs` (unconnected component inputs
    the host sets). Returns what the FMU exports: {"outputs": [...], "inputs": [...], "step_size":,
    "left_out": [what of the system the FMU does not do]}."""
    if fmi not in FMI_VERSIONS:
        raise SSPError(f"--fmi {fmi!r}: expected 2 or 3")
    out = check_output_place(out, "--out", (".fmu",))

    with System(source) as system:
        plan = make_plan(system, RunOptions(step_size=step_size, schedule=False))
        outs = (_signals(system, outputs, "output", "--outputs") if outputs else
                [(c, v.name) for c in system.comps for v in c.md.modelVariables if v.causality == "output"
                 and v.type in ("Real", "Integer", "Boolean")])
        ins = _signals(system, inputs or [], "input", "--inputs")
        fed = {(lk.dst, lk.dst_var) for lk in system.links}
        for c, v in ins:
            if (c.index, v) in fed:
                raise SSPError(f"--inputs {c.name}.{v}: a connection of the system feeds it; the host can set only an "
                               "input nothing feeds")
        name = re.sub(r"[^A-Za-z0-9_]", "_", Path(out).stem) or "system"
        left_out = []
        m = system.desc.master
        if m.schedule is not None:
            left_out.append(f"its nc:Schedule (the FMU steps at the fixed {plan.step_size:g} s)")
        if plan.stops:
            left_out.append("its stop conditions (" + ", ".join(f"{system.comps[ci].name}.{v}" for ci, v in plan.stops)
                            + ": exported as outputs, a host stops on them)")
        about = (f"{system.desc.system_name}: the system {Path(str(source)).name} as one FMU (neighbor-cosim "
                 f"export-fmu, step {plan.step_size:g} s, {plan.algorithm}, order "
                 f"{' '.join(system.comps[i].name for i in plan.order)})")
        with tempfile.TemporaryDirectory(prefix="neighbor_export_") as tmp:
            work = Path(tmp)
            doc, files = container_description(system, plan, outs, ins, name)
            for c in system.comps:
                shutil.copyfile(c.decl.fmu_path, work / files[c.index])
            (work / "container.json").write_text(json.dumps(doc, indent=1))
            logger = logging.getLogger("fmu_manipulation_toolbox")
            level, logger.level = logger.level, logging.CRITICAL  # its notes on unconnected inputs: ours report them
            try:
                assembly = Assembly(work / "container.json", fmu_directory=work)
                assembly.make_fmu(fmi_version=fmi)
            except (AssemblyError, FMUContainerError) as exc:
                raise SSPError(f"{source}: the FMU container refused the system: {exc}") from None
            finally:
                logger.level = level
            built = work / f"{name}.fmu"
            if not built.is_file():
                raise SSPError(f"{source}: the FMU container wrote no FMU (its log says why)")
            _finish_model_description(built, system, outs, ins, fmi, about, plan.params)
            problems = validate_fmu(str(built))  # kept only when FMPy finds it a valid FMU
            if problems:
                raise SSPError(f"{source}: the exported FMU is not valid ({len(problems)} problems; the first: "
                               f"{problems[0].strip()})")
            with atomic_write(out, "wb") as f:  # a half-written FMU never takes the name
                f.write(built.read_bytes())
    return {"outputs": [f"{c.name}.{v}" for c, v in outs], "inputs": [f"{c.name}.{v}" for c, v in ins],
            "step_size": plan.step_size, "left_out": left_out}


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim export-fmu", description=__doc__.split("\n\n")[0])
    ap.add_argument("system", help=".ssp, .ssd, a folder with SystemStructure.ssd, or a shipped system's name")
    ap.add_argument("--out", required=True, help="the FMU to write (.fmu)")
    ap.add_argument("--fmi", type=int, default=2, choices=FMI_VERSIONS, help="FMI version (default 2)")
    ap.add_argument("--outputs", help="signals to export, comma-separated component.variable (default: every output)")
    ap.add_argument("--inputs", help="unconnected component inputs the host sets, comma-separated component.variable")
    ap.add_argument("--step-size", type=positive_float, help="the FMU's step (default: the system's)")
    args = ap.parse_args(argv)
    split = lambda text: [s for s in (text or "").split(",") if s]  # noqa: E731
    done = export_fmu(system_path(args.system), args.out, args.fmi, split(args.outputs), split(args.inputs),
                      args.step_size)
    print(f"wrote {args.out}: FMI {args.fmi}.0 co-simulation, step {done['step_size']:g} s, "
          f"{len(done['outputs'])} outputs, {len(done['inputs'])} inputs")
    for what in done["left_out"]:
        print(f"not in the FMU: {what}")
    return 0
