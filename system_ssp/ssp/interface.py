"""An FMU's interface as a user sees it: every variable with its causality, type, unit, start
value, allowed range and description, read from the model description alone (nothing is
loaded). `compare` lists how two FMUs' interfaces differ, for `neighbor-cosim compare` and for
the checks of `replace`."""
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Optional

from fmpy import read_model_description

from ..errors import SSPError
from .fmi3_view import element_view
from .units import BUILTIN, SI_BASE_UNITS, Unit, conversion, describe

# what a connection or a binding can use: the variables an SSD declares as connectors
CONNECTOR_CAUSALITIES = ("input", "output", "parameter")


@dataclass(frozen=True)
class Variable:
    name: str
    causality: str
    type: str
    unit: Optional[str]
    start: Optional[str]
    min: Optional[str]
    max: Optional[str]
    description: str
    variability: str

    def as_dict(self):
        return asdict(self)

    def kind(self):
        """'input Real [m]' (what a connector of this variable is)."""
        return f"{self.causality} {self.type}" + (f" [{self.unit}]" if self.unit else "")


class FmuInterface:
    """The variables and unit definitions of one FMU (`FmuInterface.read(path)`)."""

    def __init__(self, path, model_name, model_identifier, guid, description, variables, units, fmi_version="2.0"):
        self.path = Path(path)
        self.fmi_version = fmi_version
        self.model_name = model_name
        self.model_identifier = model_identifier
        self.guid = guid
        self.description = description
        self.variables = variables  # {name: Variable}, model description order
        self.units = units  # {unit name: Unit}

    @classmethod
    def read(cls, path):
        path = Path(path)
        if not path.is_file():
            raise SSPError(f"{path}: FMU not found")
        try:
            md = read_model_description(str(path), validate=False)
        except Exception as exc:
            raise SSPError(f"{path}: not a readable FMU ({exc})") from None
        if md.coSimulation is None:
            raise SSPError(f"{path}: not a co-simulation FMU (FMI {md.fmiVersion}, model exchange only)")
        return cls.from_model_description(md, path)

    @classmethod
    def from_model_description(cls, md, path):
        """From an fmpy ModelDescription already read (`path`: the FMU it came from). An FMI 3.0
        FMU's variables are its element view (arrays as their elements, types as the master
        transfers them: system_ssp.ssp.fmi3_view), so an FMU and its FMI 2.0 twin compare equal."""
        variables = {}
        model_variables = md.modelVariables
        if md.fmiVersion.startswith("3."):
            model_variables = element_view(md)[0]
        for v in model_variables:
            dt = v.declaredType
            variables[v.name] = Variable(
                name=v.name, causality=v.causality, type=v.type, unit=variable_unit(v) if v.type == "Real" else None,
                start=None if v.start is None else str(v.start),
                min=_limit(v, dt, "min"), max=_limit(v, dt, "max"), description=v.description or "",
                variability=v.variability)
        return cls(Path(path), md.modelName, md.coSimulation.modelIdentifier, md.guid, md.description or "", variables,
                   unit_definitions(md), md.fmiVersion)

    def connectors(self):
        """The variables an SSD declares as connectors (inputs, outputs, parameters)."""
        return {n: v for n, v in self.variables.items() if v.causality in CONNECTOR_CAUSALITIES}

    def unit(self, name):
        """The Unit for a unit name of this FMU (its own definitions, then the product's table)."""
        if name in self.units:
            return self.units[name]
        if name in BUILTIN:
            return BUILTIN[name]
        raise SSPError(f"{self.path}: unit {name!r} has no definition")

    def as_dict(self):
        """The interface as JSON-ready data."""
        return {"path": str(self.path), "fmi_version": self.fmi_version, "model_name": self.model_name,
                "model_identifier": self.model_identifier,
                "guid": self.guid, "description": self.description,
                "variables": [v.as_dict() for v in self.variables.values()]}


def variable_unit(v):
    """The unit of an fmpy ScalarVariable: its own, else its declared type's (None if neither)."""
    if getattr(v, "unit", None):
        return v.unit
    dt = getattr(v, "declaredType", None)
    return getattr(dt, "unit", None) if dt is not None else None


def unit_definitions(md):
    """{unit name: Unit} of an fmpy ModelDescription's UnitDefinitions."""
    units = {}
    for u in md.unitDefinitions:
        b = u.baseUnit
        exps = tuple(int(getattr(b, n, 0) or 0) for n in SI_BASE_UNITS) if b is not None else (0,) * len(SI_BASE_UNITS)
        factor = float(b.factor) if b is not None and b.factor is not None else 1.0
        offset = float(b.offset) if b is not None and b.offset is not None else 0.0
        units[u.name] = Unit(u.name, exps, factor, offset)
    return units


def _limit(v, dt, which):
    value = getattr(v, which, None)
    if value is None and dt is not None:
        value = getattr(dt, which, None)
    return None if value is None else str(value)


def unit_conversion(from_unit, from_fmu, to_unit, to_fmu):
    """(factor, offset) taking a value in `from_unit` to `to_unit` (None: both dimensionless or
    unnamed, the identity), or None when the units are not convertible."""
    if from_unit == to_unit or from_unit is None or to_unit is None:
        return 1.0, 0.0
    return conversion(from_fmu.unit(from_unit), to_fmu.unit(to_unit))


@dataclass(frozen=True)
class Difference:
    """One difference between interfaces A and B: `name`, and what each has (None: absent)."""
    name: str
    a: Optional[str]
    b: Optional[str]
    note: str = ""


def compare(a, b):
    """How the connectors of FmuInterface `a` and `b` differ: [Difference], A's order then B's
    extra variables. Same name with another causality or type, units that do not convert, or a
    variable only one has; a convertible unit is listed with its conversion."""
    out = []
    ca, cb = a.connectors(), b.connectors()
    for name, va in ca.items():
        vb = cb.get(name)
        if vb is None:
            out.append(Difference(name, va.kind(), None, "only in A"))
        elif (va.causality, va.type) != (vb.causality, vb.type):
            out.append(Difference(name, va.kind(), vb.kind(), "causality or type differ"))
        elif va.unit != vb.unit:
            conv = unit_conversion(va.unit, a, vb.unit, b)
            note = (f"convertible: B = {conv[0]:g} * A + {conv[1]:g}" if conv is not None else
                    f"units not convertible ({describe(a.unit(va.unit))} vs {describe(b.unit(vb.unit))})")
            out.append(Difference(name, va.kind(), vb.kind(), note))
    for name, vb in cb.items():
        if name not in ca:
            out.append(Difference(name, None, vb.kind(), "only in B"))
    return out


def describe_fmu(fmu, bound=None):
    """Text listing every variable of FmuInterface `fmu` with its start value, unit, range and
    description; `bound` {variable: where} marks the parameters a system binds."""
    bound = bound or {}
    version = ("FMI 3.0, arrays as their elements" if fmu.fmi_version.startswith("3.") else f"FMI {fmu.fmi_version}")
    lines = [f"FMU {fmu.model_name} ({fmu.path.name}, {version}): {fmu.description}".rstrip(": ")]
    sections = (("inputs", ("input",)), ("outputs", ("output",)), ("parameters", ("parameter",)),
                ("other variables", ("calculatedParameter", "local", "independent")))
    for title, causalities in sections:
        vs = [v for v in fmu.variables.values() if v.causality in causalities]
        if not vs:
            continue
        lines.append(f"{title} ({len(vs)}):")
        for v in vs:
            lines.append("  " + variable_line(v, bound.get(v.name), v.name in bound))
    return "\n".join(lines)


def variable_line(v, where=None, is_bound=False):
    """One variable: name, type, unit, start, range, description; a parameter says whether (and
    where) a system binds it."""
    rng = ""
    if v.min is not None or v.max is not None:
        rng = f" in [{v.min if v.min is not None else '-inf'}, {v.max if v.max is not None else 'inf'}]"
    start = f" = {v.start}" if v.start is not None else ""
    unit = f" [{v.unit}]" if v.unit else ""
    mark = ""
    if v.causality == "parameter":
        mark = f"  (bound: {where})" if is_bound else "  (not bound: start value)"
    text = f"{v.name} : {v.type}{unit}{start}{rng}"
    return f"{text:<48} {v.description}{mark}".rstrip()
