"""Parameter and start values: from the SSD's bindings, the caller's parameter sets and
overrides, each checked against the FMU variable's type, finiteness and unit."""
import logging
import math
import numbers
from pathlib import Path

import numpy as np

from ..errors import SSPError
from ..ssp import reader
from ..ssp.units import conversion, describe
from .names import near, split_name

LOG = logging.getLogger("system_ssp.master")


def _bad(value, label, expected):
    return SSPError(f"{label}: {value!r} is not a valid value: expected {expected}")


def _real(value, label):
    if isinstance(value, bool):
        raise _bad(value, label, "a Real number")
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            raise _bad(value, label, "a Real number") from None
    elif isinstance(value, numbers.Real):
        value = float(value)
    else:
        raise _bad(value, label, "a Real number")
    if not math.isfinite(value):
        raise SSPError(f"{label}: {value!r} is not a valid value: expected a finite Real number")
    return value


def _integer(value, label):
    if isinstance(value, bool):
        raise _bad(value, label, "an Integer")
    if isinstance(value, str):
        try:
            value = int(value.strip())
        except ValueError:
            raise _bad(value, label, "an Integer") from None
    elif isinstance(value, numbers.Integral):
        value = int(value)
    elif isinstance(value, numbers.Real) and math.isfinite(value) and float(value).is_integer():
        value = int(value)
    else:
        raise _bad(value, label, "an Integer")
    if not -2**31 <= value < 2**31:
        raise SSPError(f"{label}: {value} is out of range for a 32-bit FMI Integer")
    return value


def _boolean(value, label):
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, numbers.Integral) and value in (0, 1):
        return bool(value)
    if isinstance(value, str) and value.strip().lower() in ("true", "false", "1", "0"):
        return value.strip().lower() in ("true", "1")
    raise _bad(value, label, "a Boolean (true/false)")


def _string(value, label):
    if isinstance(value, str):
        return value
    raise _bad(value, label, "a String")


_COERCE = {"Real": _real, "Integer": _integer, "Enumeration": _integer, "Boolean": _boolean, "String": _string}


def coerce(value, vtype, label):
    """Check and convert a caller/SSV value for an FMU variable of type `vtype`."""
    if vtype not in _COERCE:
        raise SSPError(f"{label}: variables of type {vtype} cannot be set")
    return _COERCE[vtype](value, label)


def settable(v):
    """Whether a variable may get a value before initialization (FMI 2.0 start values)."""
    if v.variability == "constant" or v.causality in ("independent", "calculatedParameter"):
        return False
    return v.causality in ("parameter", "input") or v.initial in ("exact", "approx")


def _convert_unit(system, value, unit, target, comp, units, where):
    """`value` in `unit` as a value in unit `target` (either None: unchanged)."""
    if unit is None or target is None or unit == target:
        return value
    su = system.units.unit(unit, comp, units, where)
    tu = system.units.unit(target, comp, None, where)
    conv = conversion(su, tu)
    if conv is None:
        raise SSPError(f"{where}: value in unit {unit!r} ({describe(su)}) cannot be converted to the "
                       f"variable's unit {target!r} ({describe(tu)})")
    return conv[0] * value + conv[1]


def transformed(system, pv, target_unit, comp, where):
    """(value, unit) of a parameter value `pv` that an .ssm entry maps with a LinearTransformation:
    converted to `target_unit` first, then transformed (SSP 1.0 section 7), or transformed in its
    own unit when the entry suppresses the unit conversion; pv's own (value, unit) otherwise."""
    if pv.transform is None:
        return pv.value, pv.unit
    _, factor, offset = pv.transform
    if pv.suppress:
        return factor * pv.value + offset, target_unit
    value = _convert_unit(system, pv.value, pv.unit, target_unit, comp, pv.units, where)
    return factor * value + offset, target_unit if pv.unit is not None else None


def _component_value(system, comp, var, pv):
    """(value, unit) of a bound or file value `pv` for comp.var, transformed when its .ssm entry
    has a LinearTransformation (to a Real or Integer variable only)."""
    if pv.transform is None:
        return pv.value, pv.unit
    v = comp.vars.get(var)
    if v is not None and v.type not in ("Real", "Integer"):
        raise SSPError(f"{pv.origin}: {comp.name}.{var}: a LinearTransformation maps a value to a {v.type} variable")
    return transformed(system, pv, system.units.var_unit(comp, var) if v is not None else None, comp,
                       f"{pv.origin}: {comp.name}.{var}")


def resolve_parameter(system, comp, var, value, vtype=None, unit=None, units=None, origin="", label=None):
    """Check one value for comp.var; returns the value converted to the FMU's type and unit."""
    label = label or f"{comp.name}.{var}"
    where = f"{origin}: {label}" if origin else label
    v = comp.vars.get(var)
    if v is None:
        raise SSPError(f"{where}: component {comp.name!r} has no variable {var!r}{comp.not_a_variable(var)}")
    if not settable(v):
        raise SSPError(f"{where}: cannot be set (causality {v.causality}, variability {v.variability}, "
                       f"initial {v.initial}); only parameters, inputs and variables with a start value can")
    if v.type == "Enumeration" and isinstance(value, str) and vtype == "Enumeration":
        items = {it.name: int(it.value) for it in getattr(v.declaredType, "items", [])}
        if value not in items:
            raise SSPError(f"{where}: {value!r} is not an item of enumeration {v.declaredType.name}")
        value = items[value]
    if vtype is not None and vtype != v.type:
        ok = (vtype == "Integer" and v.type in ("Real", "Enumeration")) or (vtype == "Real" and v.type == "Integer"
                                                                            and float(value).is_integer())
        if not ok:
            raise SSPError(f"{where}: value {value!r} of type {vtype} given, but the variable has type {v.type}")
    value = coerce(value, v.type, where)
    if unit is not None and v.type == "Real":
        value = _convert_unit(system, value, unit, system.units.var_unit(comp, var), comp, units, where)
    return value


def read_parameter_set(system, ps):
    """A caller's parameter set: a path, or a name inside the .ssp (at its root or in resources/).
    A relative path that names a file both here and inside the .ssp is read from here, with a
    warning naming both (the other one is not read)."""
    p = Path(ps)
    if system.archive_root is not None and not p.is_absolute():
        cand = [system.archive_root / ps, system.archive_root / "resources" / ps]
        inside = next((c for c in cand if c.is_file()), None)
        if inside is not None and p.is_file():
            LOG.warning("parameter set %r: using %s from the working directory, not %s inside %s", ps,
                        p.resolve(), inside.relative_to(system.archive_root).as_posix(), system.path)
        elif inside is not None:
            p = inside
    if not p.is_file():
        where = f" (also looked inside {system.path})" if system.archive_root is not None else ""
        raise SSPError(f"parameter set {ps!r}: file not found{where}")
    return reader.read_parameter_set_file(p, system.namer, system.validate)


def collect_parameters(system, parameter_sets=None, parameters=None):
    """All start values for a run: {(comp index, var): value}, later sources overriding earlier:
    the SSD's component bindings, the (nested, then root) systems' bindings, `parameter_sets`,
    `parameters`. One exception, as OMSimulator has it: among the SSD's bindings, a system
    parameter connected to a component variable wins over a value bound to that variable directly,
    wherever either is bound (docs/master.md, "Parameters")."""
    out = {}
    fan_out = system.parameter_links
    from_system = {}  # (comp index, var) -> the system parameter that gave its value in the SSD's bindings
    in_ssd = [True]  # still reading the SSD's own bindings (the caller's values come after, and win)

    def put(comp, var, pv):
        if in_ssd[0] and (comp.index, var) in from_system:
            LOG.info("%s: %s.%s = %r not applied: system parameter %r is connected to it and gives its value",
                     pv.origin, comp.name, var, pv.value, from_system[(comp.index, var)])
            return
        value, unit = _component_value(system, comp, var, pv)
        out[(comp.index, var)] = resolve_parameter(system, comp, var, value, pv.type, unit, pv.units, pv.origin,
                                                   f"{comp.name}.{var}")

    def put_system(name, value, vtype=None, unit=None, units=None, origin=""):
        """A system parameter (an SSD system connector of kind parameter, or of kind input that
        nothing drives): its value goes to every component variable it is connected to, converted
        to each one's unit."""
        connector = system.desc.system_connectors[name]
        for comp, var, _ in fan_out[name]:
            out[(comp.index, var)] = resolve_parameter(
                system, comp, var, value, vtype, unit if unit is not None else connector.unit, units, origin,
                f"{name} (system parameter) -> {comp.name}.{var}")
            if in_ssd[0]:
                from_system[(comp.index, var)] = name

    def named(name, where):
        """(component, variable) of a 'component.variable' name, or None for a system parameter."""
        if name in fan_out:
            return None
        if isinstance(name, str) and "." not in name and fan_out:
            raise SSPError(f"{where} {name!r}: not a system parameter{near(name, fan_out)} (system parameters and "
                           "undriven system inputs: "
                           f"{', '.join(fan_out)}) and not 'component.variable'")
        return split_name(system.comps, name, where)

    def put_named(pv, where):
        """A bound or file value: to a component's parameter or fanned out as a system parameter."""
        try:
            target = named(pv.name, where)
        except SSPError as exc:
            raise SSPError(f"{pv.origin}: {exc}") from None
        if target is None:  # transformed by its .ssm entry (if any) in the connector's unit
            value, unit = transformed(system, pv, system.desc.system_connectors[pv.name].unit, None,
                                      f"{pv.origin}: {pv.name} (system parameter)")
            put_system(pv.name, value, pv.type, unit, pv.units, pv.origin)
        else:
            put(*target, pv)

    for comp in system.comps:
        for pv in comp.decl.parameters:
            if pv.name not in comp.vars:
                raise SSPError(f"{pv.origin}: parameter {pv.name!r} bound to component {comp.name!r}: no such "
                               f"variable{near(pv.name, comp.vars)}")
            put(comp, pv.name, pv)
    for pv in system.desc.parameters:
        put_named(pv, "parameter")
    in_ssd[0] = False
    for ps in parameter_sets or []:
        for pv in read_parameter_set(system, ps):
            put_named(pv, "parameter")
    for name, value in (parameters or {}).items():
        target = named(name, "parameter")
        if target is None:
            put_system(name, value)
        else:
            comp, var = target
            out[(comp.index, var)] = resolve_parameter(system, comp, var, value, None, None, None, "", name)
    return out


def unmapped_warnings(system):
    """One warning per parameter binding whose mapping leaves out parameters that name something
    in the system: SSP 1.0 section 7 has them not applied (and the master does not apply them),
    OMSimulator applies them by their names. Parameters that name nothing (a CAD tool's set, of
    which the mapping takes a few) are left out without a word."""
    texts = []
    for origin, comp_name, names in system.desc.unmapped:
        if comp_name is not None:
            named = [n for n in names if n in system.by_name[comp_name].vars]
        else:
            named = [n for n in names if n in system.parameter_links or _names_a_variable(system, n)]
        if named:
            shown = ", ".join(named[:5]) + (f" and {len(named) - 5} more" if len(named) > 5 else "")
            texts.append(f"{origin}: the parameter mapping of this binding leaves out {len(named)} parameter"
                         f"{'s' if len(named) > 1 else ''} of its set that name{'' if len(named) > 1 else 's'} "
                         f"a variable ({shown}): not applied, as SSP 1.0 section 7 says (OMSimulator applies them by "
                         "their names; add mapping entries to apply them)")
    return texts


def _names_a_variable(system, name):
    try:
        split_name(system.comps, name, "parameter")
    except SSPError:
        return False
    return True
