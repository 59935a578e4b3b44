"""`neighbor-cosim flatten SYSTEM.ssp --out FLAT.ssp`: the same system without system parameters,
for hosts that do not read them.

Our systems give each physical value once, as a parameter connector of the system (SSP 1.0:
ssd:Connector kind="parameter" on ssd:System, a system-level ParameterBinding for its value and
connections without startElement to every component parameter that uses it). libcosim refuses
such a connection ("No such node (<xmlattr>.startElement)"). The flattened copy writes each
system parameter's value, as our master resolves it, into the first ParameterBinding of every
component it reaches (the one libcosim applies; added if the component has none) and removes the
system's parameter connectors, their connections and the system-level bindings (a value those set
for a component's variable directly goes into that component's binding too). The result runs
the same in any host; what it loses is the single place to change a value.
"""
from pathlib import Path
import tempfile

from lxml import etree

from ..atomic import check_output_place
from ..errors import SSPError
from ..master import System
from ..master.names import split_name
from ..master.parameters import collect_parameters
from ..ssp.reader import NS, NS_SSV
from .replace import _pack, _unpack
from .console import ArgumentParser


def flatten_system_parameters(source, out):
    """Write `out` (.ssp): `source` with its system parameters folded into component bindings.
    Returns {system parameter: [component.variable, ...]} of what was folded."""
    check_output_place(out, "--out", (".ssp",))
    with System(source) as system:
        names = set(system.parameter_links)
        links = {name: targets for name, targets in system.parameter_links.items() if targets}
        values = collect_parameters(system)
        # what the system-level bindings set directly (component.variable) goes to the components too
        direct = [split_name(system.comps, pv.name, pv.origin) for pv in system.desc.parameters
                  if pv.name not in names]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        ssd = _unpack(source, root)
        tree = etree.parse(str(ssd))
        sys_el = tree.getroot().find("ssd:System", NS)
        nested = sys_el.find("ssd:Elements/ssd:System", NS)
        if nested is not None:  # its components and connectors are not the root's to fold into
            raise SSPError(f"{source}: nested system {nested.get('name')!r}: flatten works on flat systems "
                           "(components directly under the root system)")
        per_component = {}
        for comp, var in [(c, v) for targets in links.values() for c, v, _ in targets] + direct:
            per_component.setdefault(comp.name, {})[var] = values[(comp.index, var)]
        for comp_el in sys_el.find("ssd:Elements", NS).findall("ssd:Component", NS):
            if comp_el.get("name") in per_component:
                _fold(root, tree.getroot().get("name"), comp_el, per_component[comp_el.get("name")])
        connectors = sys_el.find("ssd:Connectors", NS)
        for c in ([] if connectors is None else connectors.findall("ssd:Connector", NS)):
            if c.get("kind") == "parameter":
                connectors.remove(c)
        if connectors is not None and not len(connectors.findall("ssd:Connector", NS)):
            sys_el.remove(connectors)
        conns = sys_el.find("ssd:Connections", NS)
        for c in list(conns.findall("ssd:Connection", NS)):
            if ((c.get("startElement") is None and c.get("startConnector") in names)
                    or (c.get("endElement") is None and c.get("endConnector") in names)):
                conns.remove(c)
        bindings = sys_el.find("ssd:ParameterBindings", NS)
        if bindings is not None:
            sys_el.remove(bindings)  # their values are in the components' bindings now
        tree.write(str(ssd), xml_declaration=True, encoding="UTF-8")
        _pack(root, ssd, Path(out))
    with System(out):  # loads: schemas, connections, parameters
        pass
    return {name: [f"{c.name}.{v}" for c, v, _ in targets] for name, targets in links.items()}


def _fold(root, system_name, comp_el, params):
    """Set `params` ({variable: value}) in the component's first bound parameter set."""
    bindings = comp_el.find("ssd:ParameterBindings", NS)
    first = None if bindings is None else bindings.find("ssd:ParameterBinding", NS)
    if first is not None and (first.get("source") is None or first.get("prefix") or len(first)):
        raise SSPError(f"component {comp_el.get('name')}: only a plain file binding can take the system parameters")
    name = f"parameters/flattened/{system_name}.{comp_el.get('name')}.ssv"
    if first is None:
        ssv = etree.Element(f"{{{NS_SSV}}}ParameterSet", nsmap={"ssv": NS_SSV}, version="1.0", name=name)
        etree.SubElement(ssv, f"{{{NS_SSV}}}Parameters")
        if bindings is None:
            bindings = etree.SubElement(comp_el, f"{{{NS['ssd']}}}ParameterBindings")
        first = etree.SubElement(bindings, f"{{{NS['ssd']}}}ParameterBinding", source=name)
    else:
        ssv = etree.parse(str(root / first.get("source"))).getroot()
        first.set("source", name)
    holder = ssv.find("ssv:Parameters", NS)
    present = {p.get("name"): p for p in holder.findall("ssv:Parameter", NS)}
    for var, value in params.items():
        el = present.get(var)
        if el is None:
            el = etree.SubElement(holder, f"{{{NS_SSV}}}Parameter", name=var)
        for child in list(el):
            el.remove(child)
        # the value in the FMU variable's own unit (collect_parameters converted it): no unit attribute
        if isinstance(value, bool):
            tag, text = "Boolean", str(value).lower()
        elif isinstance(value, int):
            tag, text = "Integer", str(value)
        elif isinstance(value, float):
            tag, text = "Real", repr(value)
        else:
            tag, text = "String", str(value)
        etree.SubElement(el, f"{{{NS_SSV}}}{tag}", value=text)
    path = root / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(etree.tostring(ssv, xml_declaration=True, encoding="UTF-8", pretty_print=True))


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim flatten", description=__doc__.split("\n\n")[0])
    ap.add_argument("system", help=".ssp, .ssd or a folder with SystemStructure.ssd")
    ap.add_argument("--out", required=True, help="the flattened system (.ssp)")
    args = ap.parse_args(argv)
    folded = flatten_system_parameters(args.system, args.out)
    for name, targets in folded.items():
        print(f"{name} -> {', '.join(targets)}")
    print(f"wrote {args.out}")
    return 0
