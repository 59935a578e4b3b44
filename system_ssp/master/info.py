"""The text `python -m system_ssp info` prints for a loaded system."""
from ..errors import SSPError


def describe_system(system):
    """Human-readable description (components, connectors with units, bindings, experiment)."""
    d = system.desc
    lines = [f"system {d.name!r} (root system {d.system_name!r}) from {d.display}"]
    lines.append(f"default experiment: startTime={d.start_time} stopTime={d.stop_time}")
    m = d.master
    if m.origin:
        lines.append(f"master annotation ({m.origin}): stepSize={m.step_size} algorithm={m.algorithm} "
                     f"order={m.order} stepMultiples={m.step_multiples} stopConditions={m.stop_conditions}")
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
    for c in system.comps:
        lines.append(f"component {c.name}: {c.decl.source} (model {c.md.modelName})")
        for v in c.md.modelVariables:
            if v.causality in ("input", "output"):
                u = system.var_unit(c, v.name)
                lines.append(f"  {v.causality:6s} {v.name} : {v.type}{f' [{u}]' if u else ''}")
        for pv in c.decl.parameters:
            lines.append(f"  bound  {pv.name} = {pv.value!r}{f' {pv.unit}' if pv.unit else ''}  ({pv.origin})")
    for pv in d.parameters:
        lines.append(f"system binding {pv.name} = {pv.value!r}{f' {pv.unit}' if pv.unit else ''}  ({pv.origin})")
    lines.append("connections:")
    for lk in system.links:
        extra = ""
        if lk.factor != 1.0 or lk.offset != 0.0:
            extra = f"  (x{lk.factor:g}{lk.offset:+g})"
        lines.append(f"  {system.comps[lk.src].name}.{lk.src_var} -> {system.comps[lk.dst].name}.{lk.dst_var}{extra}")
    return "\n".join(lines)
