"""What `neighbor-cosim info` prints for a loaded system: the experiment, the master settings,
every component's variables (inputs, outputs and all parameters with start value, unit, range,
description, and where each parameter is bound), the connections; `system_info` is the same as
data (`--json`)."""
import dataclasses

from ..errors import SSPError
from ..ssp.interface import FmuInterface, variable_line
from .names import split_name
from .planning import step_size_of


def describe_system(system):
    """Human-readable description (components, connectors with units, bindings, experiment)."""
    d = system.desc
    lines = [f"system {d.name!r} (root system {d.system_name!r}) from {d.display}"]
    lines.append(f"default experiment: startTime={d.start_time} stopTime={d.stop_time}")
    m = d.master
    if m.origin:
        lines.append(f"master annotation ({m.origin}): stepSize={m.step_size} algorithm={m.algorithm} "
                     f"order={m.order} stepMultiples={m.step_multiples} stopConditions={m.stop_conditions}")
    try:
        h, source = step_size_of(system)
        lines.append(f"step size: {h:g} s from {source}")
    except SSPError as exc:
        lines.append(f"step size: none ({exc})")
    if m.schedule:
        lines.append(f"schedule ({m.schedule.origin}): first matching mode wins")
        for mode in m.schedule.modes:
            when = " and ".join(f"{c}.{v} in {{{', '.join(str(x) for x in sorted(vals))}}}"
                                for c, v, vals in mode.conditions) or "always"
            active = " ".join(mode.active) if mode.active is not None else "all"
            every = ("; stepped every k-th step: " + ", ".join(f"{c} {k}" for c, k in mode.every.items())
                     if mode.every else "")
            lines.append(f"  mode {mode.name}: when {when}: step {mode.step_size:g} s, active {active}{every}")
        for c, v in m.schedule.events:
            lines.append(f"  steps land on {c}.{v}")
    try:
        lines.append("default Gauss-Seidel order: " + ", ".join(system.default_order()))
    except SSPError as exc:
        lines.append(f"default Gauss-Seidel order: none ({exc})")
    bound = bindings(system)
    for c in system.comps:
        lines.append(f"component {c.name}: {c.decl.source} (model {c.md.modelName})")
        fmu = FmuInterface.from_model_description(c.md, c.decl.fmu_path)
        for v in fmu.variables.values():
            if v.causality in ("input", "output"):  # the unit the connection sees (FMU or SSD connector)
                u = system.var_unit(c, v.name)
                lines.append(f"  {v.causality:6s} " + variable_line(dataclasses.replace(v, unit=u)))
        for v in fmu.variables.values():
            if v.causality == "parameter":
                where = bound.get((c.name, v.name))
                text = f"{where[0]!r} at {where[1]}" if where else None
                lines.append("  param  " + variable_line(v, text, where is not None))
    for pv in d.parameters:
        lines.append(f"system binding {pv.name} = {pv.value!r}{f' {pv.unit}' if pv.unit else ''}  ({pv.origin})")
    lines.append("connections:")
    for lk in system.links:
        extra = ""
        if lk.factor != 1.0 or lk.offset != 0.0:
            extra = f"  (x{lk.factor:g}{lk.offset:+g})"
        lines.append(f"  {system.comps[lk.src].name}.{lk.src_var} -> {system.comps[lk.dst].name}.{lk.dst_var}{extra}")
    return "\n".join(lines)


def bindings(system):
    """{(component, variable): (value, where)} of every value the SSD binds (component bindings,
    then the root system's, later ones winning)."""
    out = {}
    for c in system.comps:
        for pv in c.decl.parameters:
            out[(c.name, pv.name)] = (pv.value, pv.origin)
    for pv in system.desc.parameters:
        if pv.name in system.parameter_links:  # a system parameter: to the variables it is connected to
            for comp, var, _ in system.parameter_links[pv.name]:
                out[(comp.name, var)] = (pv.value, f"{pv.origin} through system connector {pv.name}")
            continue
        try:
            comp, var = split_name(system.comps, pv.name)  # component names may hold dots (nested systems)
        except SSPError:
            continue  # run refuses it, naming it
        out[(comp.name, var)] = (pv.value, pv.origin)
    return out


def system_info(system):
    """The system as data: experiment, master settings, components with every variable (bound
    parameters with their value and where), connections."""
    d, m = system.desc, system.desc.master
    bound = bindings(system)
    comps = []
    for c in system.comps:
        fmu = FmuInterface.from_model_description(c.md, c.decl.fmu_path)
        variables = []
        for v in fmu.variables.values():
            item = v.as_dict()
            if v.causality in ("input", "output"):
                item["unit"] = system.var_unit(c, v.name)
            if v.causality == "parameter":
                value, where = bound.get((c.name, v.name), (None, None))
                item.update(bound=where, value=value)
            variables.append(item)
        comps.append({"name": c.name, "source": c.decl.source, "model": c.md.modelName, "guid": c.md.guid,
                      "variables": variables})
    try:
        step = dict(zip(("size", "from"), step_size_of(system)))
    except SSPError:
        step = {"size": None, "from": None}
    return {"name": d.name, "file": d.display, "start_time": d.start_time, "stop_time": d.stop_time,
            "step": step, "master": {"step_size": m.step_size, "algorithm": m.algorithm, "order": m.order,
                       "stop_conditions": [list(s) if isinstance(s, tuple) else s for s in m.stop_conditions]},
            "components": comps,
            "connections": [{"from": f"{system.comps[lk.src].name}.{lk.src_var}",
                             "to": f"{system.comps[lk.dst].name}.{lk.dst_var}", "factor": lk.factor,
                             "offset": lk.offset} for lk in system.links]}
