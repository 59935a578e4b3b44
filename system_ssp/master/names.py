"""Names in messages: 'did you mean' suggestions and `component.variable` lookup."""
import difflib

from ..errors import SSPError


def near(name, candidates):
    """' (did you mean 'a', 'b'?)' for close matches among `candidates`, or ''."""
    close = difflib.get_close_matches(name, list(candidates), n=3, cutoff=0.6)
    return f" (did you mean {', '.join(repr(n) for n in close)}?)" if close else ""


def split_name(comps, name, what="variable"):
    """'component.variable' -> (ComponentInfo, variable name); SSPError with suggestions.
    Component names may contain dots: the longest component name that prefixes `name` wins."""
    if not isinstance(name, str):
        raise SSPError(f"{what} name must be a string 'component.variable', got {name!r}")
    for comp in sorted(comps, key=lambda c: -len(c.name)):
        if name.startswith(comp.name + "."):
            var = name[len(comp.name) + 1:]
            if var not in comp.vars:
                raise SSPError(f"{what} {name!r}: component {comp.name!r} has no variable {var!r}"
                               f"{comp.not_a_variable(var)}")
            return comp, var
    head = name.split(".", 1)[0]
    if "." not in name:
        raise SSPError(f"{what} {name!r}: expected 'component.variable'")
    raise SSPError(f"{what} {name!r}: unknown component {head!r}{near(head, [c.name for c in comps])} "
                   f"(components: {', '.join(c.name for c in comps)})")
