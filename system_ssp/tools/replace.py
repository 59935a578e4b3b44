"""Replacing one component's FMU in an SSP system, checked: `replace_component` and the
commands `neighbor-cosim replace` and `neighbor-cosim compare`.

Like OMSimulator's replaceSubModel, but nothing is written unless the new FMU fits:

- every connection of the component needs a connector of the same name, causality and type in
  the new FMU, with a unit that converts to the old one; a unit that differs is converted in the
  connection itself (ssc:LinearTransformation with suppressUnitConversion="true", composed with
  the connection's own transformation), so hosts that ignore units get the same values;
- the master annotation's references to the component's connectors (stop conditions, schedule
  conditions, next-event signals) must find them too;
- every parameter bound to the component must exist in the new FMU with the same type; the
  ones that do not are refused, or, with `drop_unmatched`, left out (the component's bindings are
  then rewritten into one parameter set, parameters/<component>.replaced.ssv, values without a
  unit given in the old FMU's unit so that the new FMU gets them converted);
- the result is loaded by the master (SSP schemas, connections, units) before it is written.

A refusal (`ReplaceRefused`) lists every mismatch: the connector or parameter, what the system
needs, what the new FMU has.
"""
from dataclasses import asdict, dataclass, field
import json
import os
from pathlib import Path
import shutil
import tempfile
from typing import List, Optional, Tuple
import zipfile

from lxml import etree

from .. import archive
from ..atomic import atomic_write, check_output_place
from ..errors import SSPError
from ..master import System
from ..ssp import reader
from ..ssp.interface import FmuInterface, compare, unit_conversion
from ..ssp.reader import NS, NS_SSC, NS_SSV
from ..ssp.units import SI_BASE_UNITS
from .console import ArgumentParser


class ReplaceRefused(SSPError):
    """The new FMU does not fit: `mismatches` is [(what, name, needed, found)]."""

    def __init__(self, message, mismatches):
        super().__init__(message)
        self.mismatches = mismatches


@dataclass
class ReplaceReport:
    component: str
    old_fmu: str
    new_fmu: str
    connections: int = 0
    conversions: List[Tuple[str, float, float]] = field(default_factory=list)  # (connection, factor, offset)
    parameters_kept: List[str] = field(default_factory=list)
    dropped: List[Tuple[str, str, str]] = field(default_factory=list)  # (parameter, where it was bound, why)
    new_parameters: List[str] = field(default_factory=list)  # parameters only the new FMU has (start values)
    bindings_rewritten: Optional[str] = None
    out: Optional[Path] = None

    def text(self):
        lines = [f"replaced {self.component}: {self.old_fmu} -> {self.new_fmu} ({self.connections} connections "
                 f"checked)"]
        for label, f, o in self.conversions:
            lines.append(f"  unit conversion written into {label}: x {f:g} {o:+g}")
        if self.parameters_kept:
            lines.append(f"  parameters kept ({len(self.parameters_kept)}): {', '.join(self.parameters_kept)}")
        for name, where, why in self.dropped:
            lines.append(f"  dropped parameter {name} ({where}): {why}")
        if self.new_parameters:
            lines.append(f"  parameters only the new FMU has, at their start values: {', '.join(self.new_parameters)}")
        if self.bindings_rewritten:
            lines.append(f"  the component's bindings rewritten into {self.bindings_rewritten}")
        if self.out is not None:
            lines.append(f"written {self.out}")
        return "\n".join(lines)


def _q(prefix, tag):
    return f"{{{NS[prefix]}}}{tag}"


def _unpack(source, root):
    """Copy the system at `source` (.ssp, folder or .ssd) into folder `root`; the SSD's path there."""
    source = Path(source)
    if not source.exists():
        raise SSPError(f"{source}: not found")
    if not source.is_dir() and source.suffix.lower() not in (".ssp", ".ssd"):
        raise SSPError(f"{source}: expected a system: an .ssp archive, an .ssd file or a folder with "
                       "SystemStructure.ssd")
    if source.is_dir():
        shutil.copytree(source, root, dirs_exist_ok=True)
        ssd = root / "SystemStructure.ssd"
    elif source.suffix.lower() == ".ssp":
        archive.extract(source, root)
        ssd = root / "SystemStructure.ssd"
    else:
        shutil.copytree(source.parent, root, dirs_exist_ok=True)
        ssd = root / source.name
    if not ssd.is_file():
        raise SSPError(f"{source}: no SystemStructure.ssd")
    return ssd


def _pack(folder, ssd, out):
    """Zip `folder` as an .ssp at `out` (the SSD as SystemStructure.ssd), atomically."""
    with atomic_write(out, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(ssd, "SystemStructure.ssd")
        for p in sorted(folder.rglob("*")):
            if p.is_file() and p != ssd:
                z.write(p, p.relative_to(folder).as_posix())


def _connector_el(var):
    el = etree.Element(_q("ssd", "Connector"), name=var.name, kind=var.causality)
    t = etree.SubElement(el, f"{{{NS_SSC}}}{var.type}")
    if var.type == "Real" and var.unit:
        t.set("unit", var.unit)
    return el


def _declared_unit(comp_el, name):
    """The unit a component's SSD connector declares for `name` (None if not declared)."""
    for c in comp_el.findall("ssd:Connectors/ssd:Connector", NS):
        if c.get("name") == name:
            t = c.find("ssc:Real", NS)
            return t.get("unit") if t is not None else None
    return None


def _transform(conn_el):
    """(factor, offset) of a connection's LinearTransformation (identity if none); None for a
    mapping transformation (not composable with a unit conversion)."""
    for child in conn_el:
        if not isinstance(child.tag, str) or etree.QName(child).namespace != NS_SSC:
            continue
        if etree.QName(child).localname == "LinearTransformation":
            return float(child.get("factor", "1")), float(child.get("offset", "0"))
        if etree.QName(child).localname.endswith("MappingTransformation"):
            return None
    return 1.0, 0.0


def _set_transform(conn_el, factor, offset):
    for child in list(conn_el):
        if isinstance(child.tag, str) and etree.QName(child).localname == "LinearTransformation":
            conn_el.remove(child)
    lt = etree.Element(f"{{{NS_SSC}}}LinearTransformation", factor=repr(factor), offset=repr(offset))
    conn_el.insert(0, lt)
    conn_el.set("suppressUnitConversion", "true")


def _compose(outer, inner):
    """outer(inner(x)) for affine maps (factor, offset)."""
    return outer[0] * inner[0], outer[0] * inner[1] + outer[1]


def replace_component(source, component, new_fmu, out, drop_unmatched=False):
    """Replace the FMU of `component` in the system at `source` by `new_fmu` and write the
    result to `out` (.ssp). Returns a ReplaceReport; raises ReplaceRefused (nothing written)
    when the new FMU does not fit."""
    out = check_output_place(out, "--out", (".ssp",))
    new = FmuInterface.read(new_fmu)
    with tempfile.TemporaryDirectory(prefix="neighbor_replace_") as tmp:
        # every member of the new FMU checked (names, CRC, sizes) before the system is touched, so
        # that a damaged FMU is named, not the temporary system it would be packed into
        archive.extract(new_fmu, Path(tmp) / "new_fmu", str(new_fmu))
        root = Path(tmp) / "system"
        ssd = _unpack(source, root)
        report = _replace_in_folder(root, ssd, component, new, drop_unmatched, source)
        try:  # the master loads it: schemas, FMUs, connections and their units
            with System(ssd):
                pass
        except SSPError as exc:
            raise SSPError(f"the replaced system does not load: {exc}") from None
        _pack(root, ssd, out)
    report.out = out
    return report


def _replace_in_folder(root, ssd, component, new, drop_unmatched, source):
    r = _Replacement(root, ssd, component, new, source)
    r.check_connections()
    r.check_annotation()
    r.check_parameters(drop_unmatched)
    if r.mismatches:
        lines = [f"{source}: {new.path.name} cannot replace {component} ({r.old_path.name}): "
                 f"{len(r.mismatches)} mismatch(es); nothing written"]
        lines += [f"  {what}: {name}: needs {needed}, {new.path.name} has {found}"
                  for what, name, needed, found in r.mismatches]
        raise ReplaceRefused("\n".join(lines), r.mismatches)
    r.write()
    return r.report


class _Replacement:
    """One replace in an unpacked system: the checks collect mismatches, `write` edits the files."""

    def __init__(self, root, ssd, component, new, source):
        self.root, self.ssd, self.component, self.new, self.source = root, ssd, component, new, source
        self.tree = reader.load_xml(ssd, "ssd", reader.FileNamer(root, str(source))).getroottree()
        self.system, self.local, self.ancestors = self._find(self.tree.getroot().find("ssd:System", NS), component)
        # the component's siblings: its connections name them by their names in its own system
        self.comps = {c.get("name"): c for c in self.system.findall("ssd:Elements/ssd:Component", NS)}
        self.comp_el = self.comps[self.local]
        self.old_path = reader.resolve_uri(self.comp_el.get("source"), root)
        self.old = FmuInterface.read(self.old_path)
        self.fmus = {component: self.old}
        self.report = ReplaceReport(component, self.old_path.name, new.path.name)
        self.mismatches = []
        self.conversions = []  # (connection element, (factor, offset))
        self.kept, self.dropped, self.bound = [], [], []

    def _find(self, root_system, component):
        """(the system element holding `component`, its name there, [(system element, dotted
        prefix)] from the root down to that system): a nested system's component is named by its
        path, `sub.deeper.g2`."""
        system, prefix, local, ancestors = root_system, "", component, []
        while True:
            ancestors.append((system, prefix))
            if any(c.get("name") == local for c in system.findall("ssd:Elements/ssd:Component", NS)):
                return system, local, ancestors
            nested = {e.get("name"): e for e in system.findall("ssd:Elements/ssd:System", NS)}
            head = next((n for n in nested if local.startswith(f"{n}.")), None)
            if head is None:
                names = [prefix + c.get("name") for s, prefix in _systems(root_system)
                         for c in s.findall("ssd:Elements/ssd:Component", NS)]
                raise SSPError(f"{self.source}: no component {component!r} (components: {', '.join(names)})")
            system, prefix, local = nested[head], f"{prefix}{head}.", local[len(head) + 1:]

    def fmu_of(self, name):
        if name not in self.fmus:
            self.fmus[name] = FmuInterface.read(reader.resolve_uri(self.comps[name].get("source"), self.root))
        return self.fmus[name]

    def unit_of(self, name, comp_name):
        return _declared_unit(self.comps[comp_name], name) or self.fmu_of(comp_name).variables[name].unit

    # ---- checks ------------------------------------------------------------------------------
    def check_connections(self):
        for c in self.system.findall("ssd:Connections/ssd:Connection", NS):
            for end, other_end in (("start", "end"), ("end", "start")):
                if c.get(f"{end}Element") == self.local:
                    self.report.connections += 1
                    self._check_connection(c, end, other_end)

    def _check_connection(self, c, end, other_end):
        name = c.get(f"{end}Connector")
        label = (f"connection {c.get('startElement') or '(system)'}.{c.get('startConnector')} -> "
                 f"{c.get('endElement') or '(system)'}.{c.get('endConnector')}")
        ov, nv = self.old.variables.get(name), self.new.variables.get(name)
        needed = ov.kind() if ov is not None else "a connector"
        if nv is None:
            self.mismatches.append((label, name, needed, "no such variable"))
            return
        if ov is not None and (ov.causality, ov.type) != (nv.causality, nv.type):
            self.mismatches.append((label, name, needed, nv.kind()))
            return
        old_unit = _declared_unit(self.comp_el, name) or (ov.unit if ov else None)
        if nv.type != "Real" or old_unit == nv.unit or nv.unit is None or old_unit is None:
            return
        total, why = self._conversion(c, end, other_end, nv, old_unit)
        if total is None:
            self.mismatches.append((label, name, f"unit {old_unit}", f"unit {nv.unit} ({why})"))
        else:
            self.conversions.append((c, total))
            self.report.conversions.append((label, total[0], total[1]))

    def _conversion(self, c, end, other_end, nv, old_unit):
        """The connection's new transformation (from the other end's connector unit to the new
        FMU's unit, or back), composed with its own; (None, why) when there is none."""
        other = c.get(f"{other_end}Element")
        if not other:
            return None, "a system connector: convert by hand"
        other_unit = self.unit_of(c.get(f"{other_end}Connector"), other)
        tr = _transform(c)
        if tr is None:
            return None, "the connection maps values: no room for a unit conversion"
        suppressed = c.get("suppressUnitConversion", "false") in ("true", "1")
        old, new, other_fmu = self.old, self.new, self.fmu_of(other)
        if nv.causality == "input" and end == "end":  # other -> tr -> [to old unit] -> new unit
            to_old = (1.0, 0.0) if suppressed else unit_conversion(other_unit, other_fmu, old_unit, old)
            old_to_new = unit_conversion(old_unit, old, nv.unit, new)
            if to_old is None or old_to_new is None:
                return None, "not convertible"
            return _compose(old_to_new, _compose(to_old, tr)), ""
        if nv.causality == "output" and end == "start":  # new unit -> old unit -> tr -> [to other]
            new_to_old = unit_conversion(nv.unit, new, old_unit, old)
            from_old = (1.0, 0.0) if suppressed else unit_conversion(old_unit, old, other_unit, other_fmu)
            if new_to_old is None or from_old is None:
                return None, "not convertible"
            return _compose(from_old, _compose(tr, new_to_old)), ""
        return None, "the connection is written against the data flow: convert by hand"

    def check_annotation(self):
        """The master annotation's references to the component's connectors (stop conditions,
        schedule conditions, next-event signals)."""
        for el in self.tree.getroot().iter():
            if not isinstance(el.tag, str) or el.get("component") != self.component or el.get("connector") is None:
                continue
            name = el.get("connector")
            ov, nv = self.old.variables.get(name), self.new.variables.get(name)
            if nv is None or (ov is not None and (ov.causality, ov.type) != (nv.causality, nv.type)):
                where = f"{self.ssd.name}:{el.sourceline} {etree.QName(el).localname}"
                self.mismatches.append((where, name, ov.kind() if ov else "a variable",
                                        nv.kind() if nv else "no such variable"))

    def check_parameters(self, drop_unmatched):
        namer = reader.FileNamer(self.root, str(self.source))
        self.bound = reader.parse_bindings(self.comp_el, namer, self.root, False)
        for pv in self.bound:
            reason = self._parameter_misfit(pv)
            if reason is None:
                self.kept.append(pv)
                continue
            self.dropped.append((pv, reason))
            if not drop_unmatched:
                nv = self.new.variables.get(pv.name)
                self.mismatches.append((f"parameter bound at {pv.origin}", pv.name,
                                        self.old.variables[pv.name].kind() if pv.name in self.old.variables
                                        else "a parameter", f"{nv.kind() if nv else 'no such variable'} ({reason}; "
                                        "--drop-unmatched leaves it out)"))
        for system, prefix in self.ancestors:  # values the enclosing systems bind to it, by its path there
            for pv in reader.parse_bindings(system, namer, self.root, False):
                name = prefix + pv.name
                var = name[len(self.component) + 1:] if name.startswith(f"{self.component}.") else None
                if var is not None and var not in self.new.variables:
                    self.mismatches.append((f"system-level parameter bound at {pv.origin}", pv.name, "a parameter",
                                            "no such variable (edit that parameter set)"))

    def _parameter_misfit(self, pv):
        """Why a bound value cannot go to the new FMU (None: it can): no such settable variable,
        another type, a unit that does not convert."""
        nv, ov = self.new.variables.get(pv.name), self.old.variables.get(pv.name)
        if nv is None or nv.causality not in ("parameter", "input"):
            return "not a parameter of the new FMU"
        if ov is not None and ov.type != nv.type:
            return "another type"
        unit = pv.unit or (ov.unit if ov is not None else None)
        if nv.type == "Real" and unit and nv.unit and unit != nv.unit:
            unit_fmu = self.old if pv.unit is None or pv.unit in self.old.units else self.new
            try:
                convertible = unit_conversion(unit, unit_fmu, nv.unit, self.new) is not None
            except SSPError:
                convertible = False
            if not convertible:
                return f"unit {unit} does not convert to {nv.unit}"
        return None

    # ---- the edit ----------------------------------------------------------------------------
    def write(self):
        report, old, new, comp_el = self.report, self.old, self.new, self.comp_el
        for c, (f, o) in self.conversions:
            _set_transform(c, f, o)
        report.parameters_kept = [pv.name for pv in self.kept]
        report.dropped = [(pv.name, pv.origin, why) for pv, why in self.dropped]
        bound_names = {pv.name for pv in self.bound}
        report.new_parameters = [n for n, v in new.variables.items()
                                 if v.causality == "parameter" and n not in bound_names and n not in old.variables]
        unit_changed = any(pv.type == "Real" and pv.unit is None and pv.name in old.variables
                           and old.variables[pv.name].unit != new.variables[pv.name].unit for pv in self.kept)
        if self.dropped or unit_changed:
            report.bindings_rewritten = _rewrite_bindings(self.root, comp_el, self.component, self.kept, old)
        connectors = comp_el.find("ssd:Connectors", NS)
        new_connectors = etree.Element(_q("ssd", "Connectors"))
        for v in new.connectors().values():
            new_connectors.append(_connector_el(v))
        if connectors is not None:
            connectors.getparent().replace(connectors, new_connectors)
        else:
            comp_el.insert(0, new_connectors)
        _add_units(self.tree.getroot(), new)
        every = {id(c): c for c in self.tree.getroot().iter(_q("ssd", "Component"))}  # at any depth
        comp_el.set("source", _place_fmu(self.root, every, comp_el, new, self.old_path))
        self.tree.write(str(self.ssd), xml_declaration=True, encoding="UTF-8")


def _rewrite_bindings(root, comp_el, component, kept, old):
    """One parameter set with the kept values, bound instead of the component's bindings."""
    rel = f"parameters/{component}.replaced.ssv"
    ps = etree.Element(f"{{{NS_SSV}}}ParameterSet", nsmap={"ssv": NS_SSV}, version="1.0", name=f"{component}.replaced")
    params = etree.SubElement(ps, f"{{{NS_SSV}}}Parameters")
    for pv in kept:
        p = etree.SubElement(params, f"{{{NS_SSV}}}Parameter", name=pv.name)
        value = pv.value
        text = (("true" if value else "false") if pv.type == "Boolean" else repr(value) if pv.type == "Real"
                else str(value))
        t = etree.SubElement(p, f"{{{NS_SSV}}}{pv.type}", value=text)
        unit = pv.unit or (old.variables[pv.name].unit if pv.type == "Real" and pv.name in old.variables else None)
        if pv.type == "Real" and unit:
            t.set("unit", unit)
    units = {pv.unit for pv in kept if pv.unit} | {old.variables[pv.name].unit for pv in kept
                                                   if pv.type == "Real" and pv.name in old.variables
                                                   and old.variables[pv.name].unit}
    defs = [u for u in sorted(units) if u in old.units]
    if defs:
        uel = etree.SubElement(ps, f"{{{NS_SSV}}}Units")
        for name in defs:
            uel.append(_unit_el(old.units[name]))
    path = root / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    etree.ElementTree(ps).write(str(path), xml_declaration=True, encoding="UTF-8", pretty_print=True)
    bindings = comp_el.find("ssd:ParameterBindings", NS)
    if bindings is not None:
        comp_el.remove(bindings)
    bindings = etree.SubElement(comp_el, _q("ssd", "ParameterBindings"))
    etree.SubElement(bindings, _q("ssd", "ParameterBinding"), source=rel)
    return rel


def _unit_el(unit):
    el = etree.Element(f"{{{NS_SSC}}}Unit", name=unit.name)
    attrs = {n: str(e) for n, e in zip(SI_BASE_UNITS, unit.exponents) if e}
    if unit.factor != 1.0:
        attrs["factor"] = repr(unit.factor)
    if unit.offset != 0.0:
        attrs["offset"] = repr(unit.offset)
    etree.SubElement(el, f"{{{NS_SSC}}}BaseUnit", attrs)
    return el


def _add_units(root_el, new):
    """ssd:Units gets the new FMU's unit definitions it lacks (the SSD defines the units its
    connectors use)."""
    units = root_el.find("ssd:Units", NS)
    used = {v.unit for v in new.connectors().values() if v.unit}
    missing = [u for u in sorted(used) if u in new.units]
    if units is None:
        if not missing:
            return
        units = etree.Element(_q("ssd", "Units"))
        de = root_el.find("ssd:DefaultExperiment", NS)
        if de is not None:
            de.addprevious(units)
        else:
            root_el.append(units)
    have = {u.get("name") for u in units.findall("ssc:Unit", NS)}
    for name in missing:
        if name not in have:
            units.append(_unit_el(new.units[name]))


def _systems(system, prefix=""):
    """(system element, dotted prefix of its components) of `system` and every nested one."""
    yield system, prefix
    for nested in system.findall("ssd:Elements/ssd:System", NS):
        yield from _systems(nested, f"{prefix}{nested.get('name')}.")


def _place_fmu(root, comps, comp_el, new, old_path):
    """Copy the new FMU into resources/ (a name no other file has) and drop the old one when no
    other component uses it; the new source attribute."""
    resources = root / "resources"
    resources.mkdir(exist_ok=True)
    others = [c for c in comps.values() if c is not comp_el
              and reader.resolve_uri(c.get("source"), root).resolve() == old_path.resolve()]
    if not others and old_path.is_file():
        os.unlink(old_path)
    target = resources / f"{new.model_identifier}.fmu"
    k = 2
    while target.exists():
        target = resources / f"{new.model_identifier}_{k}.fmu"
        k += 1
    shutil.copyfile(new.path, target)
    return target.relative_to(root).as_posix()


def compare_text(a, b):
    """`neighbor-cosim compare` output for FmuInterfaces a and b."""
    diffs = compare(a, b)
    head = f"A = {a.path.name} ({a.model_name}), B = {b.path.name} ({b.model_name})"
    if not diffs:
        return head + "\nsame connectors: every input, output and parameter has the same name, causality, type and unit"
    width = max(len(d.name) for d in diffs)
    lines = [head, f"{len(diffs)} difference(s) in the connectors (inputs, outputs, parameters):"]
    for d in diffs:
        lines.append(f"  {d.name:<{width}}  A: {d.a or '-'}  B: {d.b or '-'}  ({d.note})")
    return "\n".join(lines)


def main_replace(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim replace", description="Replace one component's FMU in an SSP "
                                 "system, checked against its connections, units, annotation and parameters.")
    ap.add_argument("system", help=".ssp, .ssd or a folder with SystemStructure.ssd")
    ap.add_argument("component", help="the component (instance) name")
    ap.add_argument("fmu", help="the FMU that takes its place")
    ap.add_argument("--out", required=True, help="the new system (.ssp); nothing is written on a refusal")
    ap.add_argument("--drop-unmatched", action="store_true",
                    help="leave out parameters bound to the component that the new FMU does not have")
    args = ap.parse_args(argv)
    print(replace_component(args.system, args.component, args.fmu, args.out, args.drop_unmatched).text())
    return 0


def main_compare(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim compare", description="The differences between two FMUs' "
                                 "interfaces (inputs, outputs, parameters: name, causality, type, unit).")
    ap.add_argument("a", help="the first FMU (.fmu)")
    ap.add_argument("b", help="the FMU to compare it with (.fmu)")
    ap.add_argument("--json", action="store_true", help="the differences as JSON, for tools")
    args = ap.parse_args(argv)
    a, b = FmuInterface.read(args.a), FmuInterface.read(args.b)
    if args.json:
        print(json.dumps([asdict(d) for d in compare(a, b)], indent=1))
    else:
        print(compare_text(a, b))
    return 0
