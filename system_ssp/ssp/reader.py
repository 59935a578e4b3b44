"""Reading SSP 1.0 system descriptions (.ssd), parameter sets (.ssv) and mappings (.ssm).

Every file is checked against the SSP 1.0 XML schemas shipped with FMPy (`fmpy/ssp/schema`).
The result is a plain description (`SystemDescription`) that the master turns into running
FMU instances; nothing here loads an FMU.

Parameter names coming out of this module are already prefixed (`prefix` attribute) and
mapped (`ssd:ParameterMapping` / `.ssm`): for a component binding they are variable names of
that component, for a binding on the root system they are `component.variable`.
"""
from collections import namedtuple
from dataclasses import dataclass, field
import difflib
import math
from typing import Any, Dict, Optional
from pathlib import Path
import urllib.parse

import fmpy
from lxml import etree

from ..errors import SSPError
from .schedule import Schedule, ScheduleMode, When
from .units import SI_BASE_UNITS, Unit

NS_SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
NS_SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
NS_SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
NS_SSM = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping"
NS_NC = "https://neighbor-cosim.org/ssp/master"
ANNOTATION_TYPE = "org.neighbor-cosim.master"
# The Open Simulation Platform's annotation (libcosim): the step of a fixed-step run, read as the
# system's step when ours gives none (osp:Algorithm/osp:FixedStepAlgorithm baseStepSize).
NS_OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
OSP_ANNOTATION_TYPE = "com.opensimulationplatform"
# OMSimulator's annotation of a system: its fixed-step master's step
# (oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster stepSize)
OMS_ANNOTATION_TYPE = "org.openmodelica"
# What an nc:When condition of our master annotation may test: an output, or a parameter (a
# choice fixed for the run, e.g. by a parameter set).
CONDITION_CAUSALITIES = ("output", "parameter")

NS = {"ssd": NS_SSD, "ssc": NS_SSC, "ssv": NS_SSV, "ssm": NS_SSM, "nc": NS_NC}

SCHEMA_FILES = {
    "ssd": "SystemStructureDescription.xsd",
    "ssv": "SystemStructureParameterValues.xsd",
    "ssm": "SystemStructureParameterMapping.xsd",
}
ROOT_TAGS = {
    "ssd": f"{{{NS_SSD}}}SystemStructureDescription",
    "ssv": f"{{{NS_SSV}}}ParameterSet",
    "ssm": f"{{{NS_SSM}}}ParameterMapping",
}
TYPE_TAGS = ("Real", "Integer", "Boolean", "String", "Enumeration", "Binary")
# SSP 2.0's sized types (FMI 3.0's), as the FMI 2.0 type a scalar of them is exchanged as
SSP2_TYPES = {"Float64": "Real", "Float32": "Real", **{f"{u}Int{n}": "Integer" for u in ("", "U")
                                                         for n in (8, 16, 32, 64)}}
# what SSP 2.0 adds that needs FMI 3.0 FMUs: refused by name (the master runs FMI 2.0 FMUs)
NEEDS_FMI3 = "it needs FMI 3.0 components; this master runs FMI 2.0 FMUs"

_schemas: Dict[tuple, Any] = {}


# SSP 2.0 (2025) keeps SSP 1.0's namespaces and says version="2.0"; its schemas are vendored.
SSP2_SCHEMA_DIR = Path(__file__).parent / "schema_ssp2"


def _schema(kind, version="1.0"):
    """The XML schema of an SSP file of `kind` ("ssd", "ssv", "ssm") in the standard's `version`
    (the root's version attribute): SSP 2.0's for "2.x", else SSP 1.0's (FMPy ships them)."""
    standard = "2" if version.strip().startswith("2") else "1"
    if (kind, standard) not in _schemas:
        folder = SSP2_SCHEMA_DIR if standard == "2" else Path(fmpy.__file__).parent / "ssp" / "schema"
        _schemas[(kind, standard)] = etree.XMLSchema(etree.parse(str(folder / SCHEMA_FILES[kind])))
    return _schemas[(kind, standard)]


def _q(prefix, tag):
    return f"{{{NS[prefix]}}}{tag}"


def _local(el):
    return etree.QName(el).localname


# A parameter value from an .ssv (or the caller), before it is matched to an FMU variable.
# type: "Real" | "Integer" | "Boolean" | "String" | "Enumeration"; unit: unit name or None;
# units: dict of Unit defined next to the value (the .ssv's ssv:Units); origin: "file:line";
# transform: an .ssm entry's LinearTransformation ("linear", factor, offset), applied by the master
# after the unit conversion to the target (SSP 1.0 section 7), or instead of it when the entry
# says suppressUnitConversion (`suppress`).
ParamValue = namedtuple("ParamValue", "name type value unit units origin transform suppress", defaults=(None, False))


@dataclass
class Connector:
    name: str
    kind: str
    type: Optional[str] = None  # declared type (ssc:Real, ...) or None
    unit: Optional[str] = None
    origin: str = ""


@dataclass
class Component:
    name: str
    source: str
    fmu_path: Path
    type: str
    connectors: dict = field(default_factory=dict)
    parameters: list = field(default_factory=list)  # [ParamValue], names = variable names
    origin: str = ""


@dataclass
class Connection:
    start_element: str  # None = system connector
    start_connector: str
    end_element: str
    end_connector: str
    transform: Optional[tuple] = None  # ("linear", factor, offset) | ("boolmap", {..}) | ("intmap", {..})
    suppress_unit_conversion: bool = False
    origin: str = ""

    def label(self):
        a = f"{self.start_element}.{self.start_connector}" if self.start_element else self.start_connector
        b = f"{self.end_element}.{self.end_connector}" if self.end_element else self.end_connector
        return f"{a} -> {b}"


@dataclass
class MasterSettings:
    """Contents of the `org.neighbor-cosim.master` annotation(s), and the step another tool's
    annotation gives (`osp_step_size`: OSP's baseStepSize)."""
    step_size: Optional[float] = None
    step_size_origin: str = ""  # file:line of the nc:Master that set step_size
    osp_step_size: Optional[float] = None
    osp_step_size_origin: str = ""
    osp_algorithm: Optional[str] = None  # "jacobi" for OSP's fixed-step algorithm
    oms_step_size: Optional[float] = None
    oms_step_size_origin: str = ""
    algorithm: Optional[str] = None
    order: Optional[list] = None
    order_origin: str = ""  # file:line of nc:Order
    step_multiples: dict = field(default_factory=dict)
    stop_conditions: list = field(default_factory=list)
    schedule: Optional[Schedule] = None
    record: Optional[list] = None  # nc:Record: the signals a run records unless told otherwise
    record_origin: str = ""
    origin: str = ""


@dataclass
class SystemDescription:
    path: Path  # the .ssd file
    display: str  # how files are named in messages
    name: str
    system_name: str
    components: list = field(default_factory=list)  # [Component] in SSD order
    system_connectors: dict = field(default_factory=dict)
    connections: list = field(default_factory=list)
    units: dict = field(default_factory=dict)  # name -> Unit (ssd:Units)
    start_time: Optional[float] = None
    stop_time: Optional[float] = None
    parameters: list = field(default_factory=list)  # root-system bindings, names comp.var
    master: MasterSettings = field(default_factory=MasterSettings)
    # the parameters of bindings with a mapping that the mapping leaves out, not applied (SSP 1.0
    # section 7): [(binding's file:line, component name or None for a system level, [names])]
    unmapped: list = field(default_factory=list)

    def component(self, name):
        for c in self.components:
            if c.name == name:
                return c
        return None


class FileNamer:
    """Turns a path on disk into the name used in messages (archive-relative for .ssp)."""

    def __init__(self, root=None, archive=None):
        self.root = Path(root) if root else None
        self.archive = archive

    def __call__(self, path):
        path = Path(path)
        if self.archive and self.root:
            try:
                return f"{self.archive}!/{path.relative_to(self.root).as_posix()}"
            except ValueError:
                pass
        return str(path)


def load_xml(path, kind, namer, validate=True):
    """Parse (and schema-check) an SSP file; SSPError names the file and line on failure."""
    display = namer(path)
    if not Path(path).is_file():
        raise SSPError(f"{display}: file not found")
    try:
        doc = etree.parse(str(path))
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if exc.lineno is not None else "?"
        raise SSPError(f"{display}:{line}: malformed XML: {exc.msg}") from None
    root = doc.getroot()
    version = (root.get("version") or "").strip()
    if version and not version.startswith(("1.", "2.")):
        raise SSPError(f"{display}:{root.sourceline}: SSP version {version!r}: this reader knows SSP 1.x and 2.0")
    if validate:
        schema = _schema(kind, version)
        if not schema.validate(doc):
            errors = [f"{display}:{e.line}: schema violation: {e.message}" for e in schema.error_log]
            more = f"\n(and {len(errors) - 5} more)" if len(errors) > 5 else ""
            raise SSPError("\n".join(errors[:5]) + more)
    elif root.tag != ROOT_TAGS[kind]:
        raise SSPError(f"{display}:{root.sourceline}: expected root element {ROOT_TAGS[kind]}, found {root.tag}")
    return root


def resolve_uri(uri, base_dir):
    """A relative (or file:) URI from an SSP file, as a path on disk."""
    parsed = urllib.parse.urlparse(uri)
    if parsed.scheme in ("http", "https"):
        raise SSPError(f"remote sources are not supported: {uri}")
    if parsed.scheme == "file":
        return Path(urllib.parse.unquote(parsed.path))
    p = Path(urllib.parse.unquote(uri))
    return p if p.is_absolute() else Path(base_dir) / p


def _float_attr(el, name, origin, default=None):
    v = el.get(name)
    if v is None:
        return default
    try:
        x = float(v)
    except ValueError:
        raise SSPError(f"{origin}: attribute {name}={v!r} is not a number") from None
    if not math.isfinite(x):  # factors, offsets, times and step sizes: a NaN or inf fills a run with NaN
        raise SSPError(f"{origin}: attribute {name}={v!r}: expected a finite number")
    return x


def parse_units(parent, namer):
    """ssc:Unit children of an ssd:Units / ssv:Units element -> {name: Unit}."""
    units = {}
    if parent is None:
        return units
    for u in parent.findall("ssc:Unit", NS):
        origin = f"{namer(u.getroottree().docinfo.URL)}:{u.sourceline}"
        b = u.find("ssc:BaseUnit", NS)
        exps, factor, offset = (0,) * 8, 1.0, 0.0
        if b is not None:
            try:
                exps = tuple(int(b.get(n, "0")) for n in SI_BASE_UNITS)
            except ValueError:
                raise SSPError(f"{origin}: ssc:BaseUnit exponents must be integers") from None
            factor = _float_attr(b, "factor", origin, 1.0)
            offset = _float_attr(b, "offset", origin, 0.0)
        name = _required(u, "name", origin)
        units[name] = Unit(name, exps, factor, offset)
    return units


def _required(el, attr, origin):
    """The value of a required attribute (the schema says so; without validation we check)."""
    value = el.get(attr)
    if value is None or not value.strip():
        raise SSPError(f"{origin}: <{etree.QName(el).localname}> needs a non-empty {attr} attribute")
    return value


def _type_child(el, namer):
    """The ssc type element (Real, Integer, ..., SSP 2.0's Float64, Int32, ...) under a
    connector, or None. SSP 2.0's clocks and arrays (ssc:Clock, ssc:Dimension) are refused."""
    found = None
    for child in el:
        if not isinstance(child.tag, str) or etree.QName(child).namespace != NS_SSC:
            continue
        tag = _local(child)
        if tag in ("Clock", "Dimension"):
            what = "a clock connector (ssc:Clock)" if tag == "Clock" else "an array connector (ssc:Dimension)"
            raise SSPError(f"{_where(child, namer)}: connector {el.get('name')!r} is {what} of SSP 2.0: "
                           f"{NEEDS_FMI3}")
        if tag in TYPE_TAGS or tag in SSP2_TYPES:
            found = child
    return found


def _type_name(el):
    """The FMI 2.0 type name of an ssc/ssv type element (SSP 2.0's Float64 -> Real, ...)."""
    return SSP2_TYPES.get(_local(el), _local(el))


def _parse_transform(parent, origin):
    for child in parent:
        tag = _local(child) if isinstance(child.tag, str) else ""
        if tag == "LinearTransformation":
            return ("linear", _float_attr(child, "factor", origin, 1.0), _float_attr(child, "offset", origin, 0.0))
        if tag in ("BooleanMappingTransformation", "IntegerMappingTransformation",
                   "EnumerationMappingTransformation"):
            conv = {"BooleanMappingTransformation": _parse_bool,
                    "IntegerMappingTransformation": int}.get(tag, str)
            mapping = {}
            for e in child.findall("ssc:MapEntry", NS):
                try:
                    mapping[conv(e.get("source"))] = conv(e.get("target"))
                except ValueError:
                    raise SSPError(f"{origin}: bad MapEntry {e.get('source')!r} -> {e.get('target')!r}") from None
            kind = {"BooleanMappingTransformation": "boolmap",
                    "IntegerMappingTransformation": "intmap"}.get(tag, "enummap")
            return (kind, mapping)
    return None


def _parse_bool(text):
    t = str(text).strip().lower()
    if t in ("true", "1"):
        return True
    if t in ("false", "0"):
        return False
    raise ValueError(f"not a Boolean: {text!r}")


def parse_ssv(root, namer):
    """An ssv:ParameterSet element -> [ParamValue]."""
    display = namer(root.getroottree().docinfo.URL) if root.getroottree().docinfo.URL else "(inline)"
    units = parse_units(root.find("ssv:Units", NS), namer)
    values = []
    ssp2 = (root.get("version") or "").strip().startswith("2")
    params = root.find("ssv:Parameters", NS)
    for p in ([] if params is None else params.findall("ssv:Parameter", NS)):
        origin = f"{display}:{p.sourceline}"
        name = _required(p, "name", origin)
        tv = None
        for child in p:
            if not isinstance(child.tag, str) or etree.QName(child).namespace not in (NS_SSV, NS_SSC):
                continue
            if _local(child) == "Dimension":  # SSP 2.0: an array value
                raise SSPError(f"{origin}: parameter {name!r} is an array (ssc:Dimension, SSP 2.0): {NEEDS_FMI3}")
            if etree.QName(child).namespace == NS_SSV and (_local(child) in TYPE_TAGS or _local(child) in SSP2_TYPES):
                tv = child
                break
        if tv is None:
            raise SSPError(f"{origin}: parameter {name!r} has no value")
        kind = _type_name(tv)
        raw = tv.get("value")
        if ssp2 and raw is not None and len(raw.split()) > 1 and kind not in ("String", "Enumeration"):
            # SSP 2.0 lists array values (a String's, an Enumeration item's spaces are its own)
            raise SSPError(f"{origin}: parameter {name!r}: {raw!r} is an array value (SSP 2.0): {NEEDS_FMI3}")
        if raw is None and tv.find("ssv:Value", NS) is not None:  # SSP 2.0: String/Enumeration/Binary arrays
            raise SSPError(f"{origin}: parameter {name!r} has ssv:Value elements (an SSP 2.0 array): {NEEDS_FMI3}")
        try:
            if kind == "Real":
                value = float(raw)
            elif kind == "Integer":
                value = int(raw)
            elif kind == "Boolean":
                value = _parse_bool(raw)
            elif kind == "String":
                value = raw
            elif kind == "Enumeration":
                value = raw  # an item name, resolved against the FMU's type later
            else:
                raise SSPError(f"{origin}: parameter {p.get('name')!r}: {kind} values are not supported")
        except (TypeError, ValueError):
            raise SSPError(f"{origin}: parameter {p.get('name')!r}: {raw!r} is not a valid {kind}") from None
        values.append(ParamValue(p.get("name"), kind, value, tv.get("unit") if kind == "Real" else None, units, origin))
    return values


def refuse_duplicates(values):
    """A name set twice in one parameter set is refused when the set applies it (which value was
    meant?); a CAD tool's set may repeat parameters its mapping leaves out (system_ssp.ssp
    parse_bindings only checks what it applies)."""
    seen = {}
    for v in values:
        if v.name in seen:
            line = seen[v.name].origin.rpartition(":")[2]
            raise SSPError(f"{v.origin}: parameter {v.name!r} is already set on line {line} of this parameter set")
        seen[v.name] = v
    return values


def parse_ssm(root, namer):
    """An ssm:ParameterMapping element -> {source name: [(target name, transform, suppress, origin)]}.

    One source may feed several targets (an entry each). An entry with an empty source maps
    nothing: no parameter has an empty name (OMSimulator writes such entries as a template, one per
    parameter of the component, for the user to fill in)."""
    display = namer(root.getroottree().docinfo.URL) if root.getroottree().docinfo.URL else "(inline)"
    mapping = {}  # source -> [(target, transform, suppress, origin)]
    for e in root.findall("ssm:MappingEntry", NS):
        origin = f"{display}:{e.sourceline}"
        if e.get("source") is None:  # required by the schema; a file read without validation
            raise SSPError(f"{origin}: <MappingEntry> needs a source attribute (the parameter it maps)")
        target = _required(e, "target", origin)
        source = e.get("source").strip()
        if not source:
            continue
        mapping.setdefault(source, []).append((target, _parse_transform(e, origin),
                                               e.get("suppressUnitConversion", "false") == "true", origin))
    return mapping


def _mapped(v, target, transform, suppress, morigin):
    """The value `v` of a parameter set as an .ssm entry (at `morigin`) maps it to `target`: an
    Integer/Boolean/Enumeration mapping applied now, a LinearTransformation left to the master
    (after the unit conversion, which needs the target's unit)."""
    origin = f"{v.origin} (mapped by {morigin})"
    if transform is None:
        return v._replace(name=target, origin=origin)
    if transform[0] == "linear":
        if v.type not in ("Real", "Integer"):
            raise SSPError(f"{morigin}: LinearTransformation on {v.type} parameter {v.name!r}")
        return v._replace(name=target, type="Real", value=float(v.value), origin=origin, transform=transform,
                          suppress=suppress)
    return v._replace(name=target, value=transform[1].get(v.value, v.value), origin=origin)


def _referenced_or_inline(el, inline_path, kind, parse, what, origin, namer, base_dir, component_dir, validate):
    """Parse the file `el` references (source, sourceBase) or its inline element; None if neither."""
    src = el.get("source")
    if src:
        base = component_dir if (el.get("sourceBase") == "component" and component_dir) else base_dir
        path = resolve_uri(src, base)
        if not path.is_file():
            raise SSPError(f"{origin}: {what} {src!r} not found (tried {namer(path)})")
        return parse(load_xml(path, kind, namer, validate), namer)
    inline = el.find(inline_path, NS)
    return None if inline is None else parse(inline, namer)


def parse_bindings(el, namer, base_dir, validate, component_dir=None, unmapped=None):
    """ssd:ParameterBindings under a component or system -> [ParamValue] (prefixed, mapped).

    A binding with a parameter mapping applies the parameters its entries map, under the names
    they map them to, and no other (SSP 1.0 section 7: "All parameters of the parameter source
    which are not referenced in a mapping entry will not be applied"); those left out are listed in
    `unmapped` as (binding's file:line, [names]). An entry whose source the parameter set does not
    have maps nothing: refused with the entry's file and line."""
    out = []
    bindings = el.find("ssd:ParameterBindings", NS)
    if bindings is None:
        return out
    for b in bindings.findall("ssd:ParameterBinding", NS):
        ssd_display = namer(b.getroottree().docinfo.URL)
        origin = f"{ssd_display}:{b.sourceline}"
        btype = b.get("type", "application/x-ssp-parameter-set")
        if btype != "application/x-ssp-parameter-set":
            raise SSPError(f"{origin}: parameter binding type {btype!r} is not supported")
        values = _referenced_or_inline(b, "ssd:ParameterValues/ssv:ParameterSet", "ssv", parse_ssv, "parameter set",
                                       origin, namer, base_dir, component_dir, validate)
        if values is None:
            raise SSPError(f"{origin}: parameter binding has neither a source nor inline ssv:ParameterSet")
        m = b.find("ssd:ParameterMapping", NS)
        mapping = None
        if m is not None:
            mapping = _referenced_or_inline(m, "ssm:ParameterMapping", "ssm", parse_ssm, "parameter mapping",
                                            origin, namer, base_dir, component_dir, validate)
        prefix = b.get("prefix", "")
        values = [v._replace(name=prefix + v.name) for v in values]
        if mapping is None:
            out.extend(refuse_duplicates(values))
            continue
        refuse_duplicates([v for v in values if v.name in mapping])
        by_name = {v.name: v for v in values}
        for source, entries in mapping.items():
            if source not in by_name:
                target, morigin = entries[0][0], entries[0][3]
                close = difflib.get_close_matches(source, list(by_name), n=3, cutoff=0.6)
                hint = f" (did you mean {', '.join(map(repr, close))}?)" if close else ""
                raise SSPError(f"{morigin}: mapping entry {source!r} -> {target!r} maps nothing: the parameter set "
                               f"bound at {origin} has no parameter {source!r}{hint}")
        for v in values:
            for target, transform, suppress, morigin in mapping.get(v.name, ()):
                out.append(_mapped(v, target, transform, suppress, morigin))
        left_out = [v.name for v in values if v.name not in mapping]
        if left_out and unmapped is not None:
            unmapped.append((origin, left_out))
    return out


def _parse_connectors(el, namer):
    out = {}
    conns = el.find("ssd:Connectors", NS)
    if conns is None:
        return out
    for c in conns.findall("ssd:Connector", NS):
        t = _type_child(c, namer)
        corigin = f"{namer(c.getroottree().docinfo.URL)}:{c.sourceline}"
        name = _required(c, "name", corigin)
        out[name] = Connector(
            name=name, kind=_required(c, "kind", corigin),
            type=_type_name(t) if t is not None else None,
            unit=t.get("unit") if (t is not None and _type_name(t) == "Real") else None,
            origin=corigin)
    return out


def _annotations(el, kind):
    """The ssc:Annotation elements of type `kind` directly under `el` (SSP 1.0: ssd:System and
    ssd:DefaultExperiment hold ssd:Annotations, of type ssc:TAnnotations; some tools write
    ssc:Annotations)."""
    anns = el.find("ssd:Annotations", NS)
    if anns is None:
        anns = el.find("ssc:Annotations", NS)
    return [] if anns is None else [a for a in anns.findall("ssc:Annotation", NS) if a.get("type") == kind]


def parse_master_annotation(el, namer, settings):
    """Read `org.neighbor-cosim.master` annotations under `el` into `settings` (later wins)."""
    for ann in _annotations(el, ANNOTATION_TYPE):
        origin = f"{namer(ann.getroottree().docinfo.URL)}:{ann.sourceline}"
        masters = [c for c in ann if isinstance(c.tag, str)]
        if len(masters) != 1 or masters[0].tag != _q("nc", "Master"):
            raise SSPError(f"{origin}: annotation {ANNOTATION_TYPE} must contain exactly one "
                           f"<nc:Master xmlns:nc=\"{NS_NC}\"> element")
        m = masters[0]
        settings.origin = origin
        unknown = set(m.attrib) - {"stepSize", "algorithm"}
        if unknown:
            raise SSPError(f"{origin}: unknown attribute(s) on nc:Master: {', '.join(sorted(unknown))}")
        if m.get("stepSize") is not None:
            h = _float_attr(m, "stepSize", origin)
            if not (h > 0 and math.isfinite(h)):
                raise SSPError(f"{origin}: nc:Master stepSize must be a positive number, got {m.get('stepSize')!r}")
            settings.step_size = h
            settings.step_size_origin = origin
        if m.get("algorithm") is not None:
            settings.algorithm = m.get("algorithm")
        for child in m:
            if not isinstance(child.tag, str):
                continue
            corigin = f"{namer(child.getroottree().docinfo.URL)}:{child.sourceline}"
            if child.tag == _q("nc", "Order"):
                settings.order = (child.text or "").split()
                settings.order_origin = corigin
            elif child.tag == _q("nc", "StepMultiple"):
                comp, mult = child.get("component"), child.get("multiple")
                try:
                    k = int(mult)
                except (TypeError, ValueError):
                    k = 0
                if not comp or k < 1:
                    raise SSPError(f"{corigin}: nc:StepMultiple needs component=\"name\" and multiple=\"k\" (k >= 1)")
                settings.step_multiples[comp] = k
            elif child.tag == _q("nc", "StopCondition"):
                comp, conn = child.get("component"), child.get("connector")
                if not comp or not conn:
                    raise SSPError(f"{corigin}: nc:StopCondition needs component=\"name\" and connector=\"name\"")
                settings.stop_conditions.append(f"{comp}.{conn}")
            elif child.tag == _q("nc", "Schedule"):
                settings.schedule = _parse_schedule(child, namer)
            elif child.tag == _q("nc", "Record"):
                settings.record = (child.text or "").split()
                settings.record_origin = corigin
            else:
                raise SSPError(f"{corigin}: unknown element {child.tag} in nc:Master "
                               "(expected nc:Order, nc:StepMultiple, nc:StopCondition, nc:Schedule, nc:Record)")


def parse_osp_annotation(el, namer, settings):
    """The step of OSP's fixed-step algorithm (libcosim's `com.opensimulationplatform` annotation
    under `el`) into `settings.osp_step_size`; the annotation's other content is libcosim's own."""
    for ann in _annotations(el, OSP_ANNOTATION_TYPE):
        for fixed in ann.iterfind(f"{{{NS_OSP}}}Algorithm/{{{NS_OSP}}}FixedStepAlgorithm"):
            settings.osp_step_size, settings.osp_step_size_origin = _step_attr(
                fixed, "baseStepSize", "osp:FixedStepAlgorithm", namer)
            # libcosim's fixed-step algorithm steps every component from the values at t (Jacobi)
            settings.osp_algorithm = "jacobi"


def parse_oms_annotation(el, namer, settings):
    """The step of OMSimulator's fixed-step master (its `org.openmodelica` annotation of the root
    system) into `settings.oms_step_size`; the rest of the annotation is OMSimulator's own."""
    for ann in _annotations(el, OMS_ANNOTATION_TYPE):
        for fixed in ann.iter():
            if isinstance(fixed.tag, str) and _local(fixed) == "FixedStepMaster" and fixed.get("stepSize"):
                settings.oms_step_size, settings.oms_step_size_origin = _step_attr(
                    fixed, "stepSize", "oms:FixedStepMaster", namer)


def _step_attr(el, attr, what, namer):
    """(step, file:line) of another tool's step attribute `attr` on `el`: a positive number."""
    origin = _where(el, namer)
    h = _float_attr(el, attr, origin)
    if h is None or h <= 0:
        raise SSPError(f"{origin}: {what} {attr} must be a positive number, got {el.get(attr)!r}")
    return h, origin


def _where(e, namer):
    return f"{namer(e.getroottree().docinfo.URL)}:{e.sourceline}"


def _parse_schedule(el, namer):
    """nc:Schedule: nc:Mode entries (each with nc:When conditions) and nc:NextEvent signals."""
    origin = _where(el, namer)
    modes, events, names = [], [], set()
    for child in el:
        if not isinstance(child.tag, str):
            continue
        o = _where(child, namer)
        if child.tag == _q("nc", "NextEvent"):
            comp, conn = child.get("component"), child.get("connector")
            if not comp or not conn:
                raise SSPError(f"{o}: nc:NextEvent needs component=\"name\" and connector=\"name\"")
            events.append((comp, conn))
            continue
        if child.tag != _q("nc", "Mode"):
            raise SSPError(f"{o}: unknown element {child.tag} in nc:Schedule (expected nc:Mode, nc:NextEvent)")
        modes.append(_parse_mode(child, o, namer, names))
    if not modes:
        raise SSPError(f"{origin}: nc:Schedule needs at least one nc:Mode")
    for m in modes[:-1]:
        if not m.conditions:
            raise SSPError(f"{m.origin}: nc:Mode {m.name!r} has no nc:When, so it always matches; only the "
                           "last mode may be unconditional (modes are tried in order)")
    return Schedule(modes=tuple(modes), events=tuple(events), origin=origin)


def _parse_mode(child, o, namer, names):
    """One nc:Mode element (at `o`, file:line) with its nc:When conditions; `names`: the mode
    names taken so far (this one is added)."""
    unknown = set(child.attrib) - {"name", "stepSize", "active", "recordEvery", "every"}
    if unknown:
        raise SSPError(f"{o}: unknown attribute(s) on nc:Mode: {', '.join(sorted(unknown))}")
    name = child.get("name")
    if not name or name in names:
        raise SSPError(f"{o}: nc:Mode needs a unique name=\"...\", got {name!r}")
    names.add(name)
    h = _float_attr(child, "stepSize", o)
    if h is None or not (h > 0 and math.isfinite(h)):
        raise SSPError(f"{o}: nc:Mode {name!r} stepSize must be a positive number, got {child.get('stepSize')!r}")
    try:
        every = int(child.get("recordEvery", "1"))
    except ValueError:
        every = 0
    if every < 1:
        raise SSPError(f"{o}: nc:Mode {name!r} recordEvery must be an integer >= 1, "
                       f"got {child.get('recordEvery')!r}")
    active = child.get("active")
    multiples = {}
    for item in (child.get("every") or "").split():
        comp, _, k = item.partition(":")
        try:
            k = int(k)
        except ValueError:
            k = 0
        if not comp or k < 1:
            raise SSPError(f"{o}: nc:Mode {name!r} every=\"{child.get('every')}\": expected "
                           "\"component:k ...\" with integers k >= 1")
        multiples[comp] = k
    conditions = []
    for w in child:
        if not isinstance(w.tag, str):
            continue
        wo = _where(w, namer)
        if w.tag != _q("nc", "When"):
            raise SSPError(f"{wo}: unknown element {w.tag} in nc:Mode (expected nc:When)")
        comp, conn, values = w.get("component"), w.get("connector"), w.get("values")
        try:
            vals = tuple(int(v) for v in (values or "").split())
        except ValueError:
            vals = ()
        if not comp or not conn or not vals:
            raise SSPError(f"{wo}: nc:When needs component=\"name\", connector=\"name\" and "
                           "values=\"integers\" (Booleans: 0 or 1)")
        conditions.append(When(comp, conn, vals))
    return ScheduleMode(name=name, step_size=h, active=None if active is None else tuple(active.split()),
                        record_every=every, conditions=tuple(conditions), every=multiples, origin=o)


def _parse_system(system, path, desc, namer, base_dir, validate):
    """The elements, bindings and connections of `system` into the flat `desc`: the root when
    `path` is "", else a nested system at dotted `path` ("outer.inner"). Its components are named
    `path.name`; a nested system's connectors join desc.system_connectors as `path.connector`, and
    a connection that ends at one names it with element None, as one at a root connector does.
    Bindings of a nested system name what is inside it; they are read before the enclosing
    system's, so that the outer level wins (the later binding wins)."""
    display = namer(desc.path)
    prefix = f"{path}." if path else ""
    nested = {}  # local name of a nested system -> its connectors
    elements = system.find("ssd:Elements", NS)
    for el in ([] if elements is None else elements):
        if not isinstance(el.tag, str):
            continue
        origin = f"{display}:{el.sourceline}"
        tag = _local(el)
        if tag == "SignalDictionaryReference":
            raise SSPError(f"{origin}: signal dictionary references are not supported")
        if tag not in ("Component", "System"):
            continue
        local = _required(el, "name", origin)
        name = prefix + local
        if local in nested or desc.component(name) is not None:
            raise SSPError(f"{origin}: duplicate element name {local!r} in system "
                           f"{path or desc.system_name!r}")
        if tag == "System":
            nested[local] = _parse_connectors(el, namer)
            for cname, conn in nested[local].items():
                desc.system_connectors[f"{name}.{cname}"] = conn
            _parse_system(el, name, desc, namer, base_dir, validate)
            continue
        ctype = el.get("type", "application/x-fmu-sharedlibrary")
        if ctype != "application/x-fmu-sharedlibrary":
            raise SSPError(f"{origin}: component {name!r} has type {ctype!r}; only FMUs are supported")
        source = _required(el, "source", origin)
        comp = Component(name=name, source=source, fmu_path=resolve_uri(source, base_dir), type=ctype,
                         connectors=_parse_connectors(el, namer), origin=origin)
        left_out = []
        comp.parameters = parse_bindings(el, namer, base_dir, validate, component_dir=None, unmapped=left_out)
        desc.unmapped += [(origin, name, names) for origin, names in left_out]
        desc.components.append(comp)

    left_out = []
    desc.parameters.extend(v._replace(name=prefix + v.name)
                           for v in parse_bindings(system, namer, base_dir, validate, unmapped=left_out))
    desc.unmapped += [(origin, None, [prefix + n for n in names]) for origin, names in left_out]

    def end(element, connector, origin):
        """(element, connector) of a connection end in the flat description."""
        if element is None:  # this system's own connector
            return None, prefix + connector
        if element in nested:
            if connector not in nested[element]:
                close = difflib.get_close_matches(connector, list(nested[element]), n=3, cutoff=0.6)
                hint = f" (did you mean {', '.join(map(repr, close))}?)" if close else ""
                raise SSPError(f"{origin}: nested system {prefix + element!r} has no connector {connector!r}{hint}")
            return None, f"{prefix}{element}.{connector}"
        return prefix + element, connector

    conns = system.find("ssd:Connections", NS)
    for c in ([] if conns is None else conns.findall("ssd:Connection", NS)):
        origin = f"{display}:{c.sourceline}"
        start = end(c.get("startElement") or None, _required(c, "startConnector", origin), origin)
        stop = end(c.get("endElement") or None, _required(c, "endConnector", origin), origin)
        desc.connections.append(Connection(
            start_element=start[0], start_connector=start[1], end_element=stop[0], end_connector=stop[1],
            transform=_parse_transform(c, origin),
            suppress_unit_conversion=c.get("suppressUnitConversion", "false") in ("true", "1"),
            origin=origin))


def parse_ssd(ssd_path, namer, validate=True):
    """Read a .ssd file (and the .ssv/.ssm files it references) into a SystemDescription."""
    ssd_path = Path(ssd_path)
    base_dir = ssd_path.parent
    root = load_xml(ssd_path, "ssd", namer, validate)
    display = namer(ssd_path)
    system = root.find("ssd:System", NS)
    if system is None:
        raise SSPError(f"{display}: no ssd:System element")
    desc = SystemDescription(path=ssd_path, display=display, name=root.get("name"),
                             system_name=system.get("name"))
    desc.units = parse_units(root.find("ssd:Units", NS), namer)
    desc.system_connectors = _parse_connectors(system, namer)
    _parse_system(system, "", desc, namer, base_dir, validate)

    parse_master_annotation(system, namer, desc.master)
    parse_oms_annotation(system, namer, desc.master)
    de = root.find("ssd:DefaultExperiment", NS)
    if de is not None:
        origin = f"{display}:{de.sourceline}"
        desc.start_time = _float_attr(de, "startTime", origin)
        desc.stop_time = _float_attr(de, "stopTime", origin)
        parse_master_annotation(de, namer, desc.master)
        parse_osp_annotation(de, namer, desc.master)
    return desc


def read_parameter_set_file(path, namer, validate=True):
    """A caller-supplied .ssv (names `component.variable`) -> [ParamValue]."""
    return refuse_duplicates(parse_ssv(load_xml(path, "ssv", namer, validate), namer))

