"""Connections resolved against the FMUs: which output feeds which input, with the unit
conversion and transformation folded into one affine map (or an Integer/Boolean mapping), and
the direct-feedthrough graph that orders Gauss-Seidel steps."""
import dataclasses
import logging
from typing import NamedTuple, Optional

from ..errors import SSPError, option
from ..ssp.units import BUILTIN, conversion, describe
from .graph import toposort
from .names import near

NUMERIC = ("Real", "Integer", "Boolean", "Enumeration")
# how a variable's value travels and is recorded: Enumerations as Integers
KIND = {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean", "String": "String"}
RECORDABLE = NUMERIC + ("String",)
LOG = logging.getLogger("system_ssp.master")


class Link(NamedTuple):
    """One resolved connection: output `src_var` of component `src` feeds input `dst_var` of
    `dst`; a Real value is mapped as factor * value + offset, an Integer/Boolean through
    `mapping` (None: unchanged)."""
    src: int
    dst_var: str
    src_var: str
    dst: int
    vtype: str  # "Real" | "Integer" | "Boolean"
    factor: float
    offset: float
    mapping: Optional[dict]
    label: str


class UnitTable:
    """Unit lookup for a system: ssd:Units, then the component's FMU UnitDefinitions, then the
    product's table of common units, then any other FMU of the system."""

    def __init__(self, desc, comps):
        self.desc = desc
        self.comps = comps
        self.bracketed = set()  # "[m]"-style unit names read as their content (warned once each)

    def unit(self, name, comp=None, extra=None, where=""):
        if name is None:
            return None
        found = self._lookup(name, comp, extra)
        if found is None and len(name) > 2 and name[0] == "[" and name[-1] == "]":
            # CAD tools write a parameter's unit in brackets ("[m]" beside an ssc:Unit "m" in the same
            # file, as a parameter set of OMSimulator's test suite has it): read as the unit inside
            found = self._lookup(name[1:-1], comp, extra)
            if found is not None and name not in self.bracketed:
                self.bracketed.add(name)
                LOG.warning("%s: unit %r has no definition; read as %r (the unit in brackets, as CAD tools write it)",
                            where, name, name[1:-1])
        if found is None:
            raise SSPError(f"{where}: unit {name!r} has no definition (add it to ssd:Units)")
        return found

    def _lookup(self, name, comp, extra):
        for table in (extra or {}, self.desc.units, comp.unit_defs if comp else {}, BUILTIN):
            if name in table:
                return table[name]
        for c in self.comps:
            if name in c.unit_defs:
                return c.unit_defs[name]
        return None

    def convert(self, a, b, comp_a, comp_b, where):
        """(factor, offset) from unit name a to unit name b; identity if either is unknown."""
        if a is None or b is None or a == b:
            return 1.0, 0.0
        ua = self.unit(a, comp_a, where=where)
        ub = self.unit(b, comp_b, where=where)
        conv = conversion(ua, ub)
        if conv is None:
            raise SSPError(f"{where}: incompatible units {a!r} ({describe(ua)}) and {b!r} ({describe(ub)})")
        return conv

    @staticmethod
    def end_units(comp, var):
        """(unit of the FMU value, unit seen by the connection) for a component variable."""
        v = comp.vars[var]
        conn = comp.decl.connectors.get(var)
        fu = comp.fmu_unit(v)
        cu = conn.unit if conn is not None else None
        return (fu or cu), (cu or fu)

    def var_unit(self, comp, var):
        return self.end_units(comp, var)[0]


def _invert(tr, c):
    if tr is None:
        return None
    if tr[0] == "linear":
        if tr[1] == 0:
            raise SSPError(f"{c.origin}: connection {c.label()}: LinearTransformation with factor 0 cannot be "
                           "applied against the connection's start->end direction")
        return ("linear", 1.0 / tr[1], -tr[2] / tr[1])
    return (tr[0], {v: k for k, v in tr[1].items()})


def check_connector_units(comps, units):
    """Every Real connector's unit, connected or not, is defined and convertible to the unit of
    its FMU variable (an unconnected one is still the unit parameter values are read in)."""
    for comp in comps:
        for name, conn in comp.decl.connectors.items():
            if conn.unit is None or name not in comp.vars:
                continue
            fmu_unit = comp.fmu_unit(comp.vars[name])
            units.convert(conn.unit, fmu_unit, comp, comp, f"{conn.origin}: connector {comp.name}.{name}")


def valued_system_connectors(desc):
    """The system connectors (root or nested) whose value is given, not computed: those of kind
    parameter, and those of kind input that no connection feeds (at the top level nothing outside
    can: a binding or --set gives the value, as OMSimulator's do). An input connector that a
    component output or another connector feeds is a pass-through."""
    fed = {c.end_connector for c in desc.connections if c.end_element is None}
    return {name: sc for name, sc in desc.system_connectors.items()
            if sc.kind == "parameter" or (sc.kind == "input" and name not in fed)}


def _downstream(desc, name, seen=frozenset()):
    """[[connection, ...]]: the chains from system connector `name` through further system
    connectors (as written, start -> end) to each connection that reaches a component."""
    chains = []
    for c in desc.connections:
        if c.start_element is None and c.start_connector == name:
            if c.end_element is not None:
                chains.append([c])
                continue
            if c.end_connector in seen | {name}:
                raise SSPError(f"{c.origin}: connection {c.label()} closes a loop of system connectors")
            chains += [[c] + rest for rest in _downstream(desc, c.end_connector, seen | {name})]
        elif c.end_element is None and c.end_connector == name and c.start_element is not None:
            chains.append([c])  # the component's end written first: its causality decides (parameter_connections)
    return chains


def _parameter_connection_ids(desc):
    """id() of every connection on the way from a valued system connector to the component
    variables it gives its value to before the run (not links of the step loop)."""
    ids = set()
    for name in valued_system_connectors(desc):
        for chain in _downstream(desc, name):
            ids.update(id(c) for c in chain)
    return ids


def parameter_connections(desc, by_name):
    """{valued system connector: [(component info, variable, origin)]}: where each system
    parameter's (or unfed system input's) value goes, through nested systems' connectors. A
    parameter's targets must be parameters of their components; an input's, inputs or parameters."""
    valued = valued_system_connectors(desc)
    out = {name: [] for name in valued}
    for name, sc in valued.items():
        for chain in _downstream(desc, name):
            c = chain[-1]
            where = f"{c.origin}: connection {c.label()}"
            if c.end_element is None and c.start_element is None:
                continue  # ends at a system connector that feeds nothing further
            element, var = (c.end_element, c.end_connector) if c.end_element is not None else \
                (c.start_element, c.start_connector)
            comp = by_name.get(element)
            if comp is None:
                raise SSPError(f"{where}: no component named {element!r}{near(element, by_name)}")
            v = comp.vars.get(var)
            if v is None:
                raise SSPError(f"{where}: component {element!r} has no variable {var!r}{comp.not_a_variable(var)}")
            allowed = ("parameter",) if sc.kind == "parameter" else ("input", "parameter")
            if v.causality not in allowed:
                raise SSPError(f"{where}: {element}.{var} has causality {v.causality}; a system {sc.kind} can only "
                               f"set {' or '.join(a + 's' for a in allowed)}")
            if any(link.transform is not None for link in chain):
                raise SSPError(f"{where}: transformations on parameter connections are not supported")
            out[name].append((comp, var, c.origin))
    return out


SOURCE_CAUSALITIES = ("output", "calculatedParameter", "parameter")


def _end(desc, by_name, element, connector, c):
    """('comp', info, var) or ('sys', None, name) for one end of a connection."""
    if element is None:
        if connector not in desc.system_connectors:
            raise SSPError(f"{c.origin}: connection {c.label()}: the system has no connector {connector!r}"
                           f"{near(connector, desc.system_connectors)}")
        return ("sys", None, connector)
    comp = by_name.get(element)
    if comp is None:
        raise SSPError(f"{c.origin}: connection {c.label()}: no component named {element!r}"
                       f"{near(element, by_name)}")
    if connector not in comp.vars:
        raise SSPError(f"{c.origin}: connection {c.label()}: component {element!r} has no variable "
                       f"{connector!r}{comp.not_a_variable(connector)}")
    declared = comp.decl.connectors
    if declared and connector not in declared and connector.partition("[")[0] not in declared:
        # a component that lists its connectors lists all it is connected through (SSP 1.0);
        # one that lists none is taken to expose its FMU's variables
        raise SSPError(f"{c.origin}: connection {c.label()}: component {element!r} declares connectors but not "
                       f"{connector!r}{near(connector, declared)} (add an ssd:Connector for it)")
    return ("comp", comp, connector)


def _whole_arrays_expanded(connections, by_name):
    """The connections with each one between two whole arrays (an FMI 3.0 array, or a vector or
    matrix an FMI 2.0 FMU spells element by element, named without indices: `a.q_BN -> b.q_BN`)
    replaced by one connection per element, in row-major order; the two must have as many
    elements."""
    out = []
    for c in connections:
        a = by_name.get(c.start_element) if c.start_element else None
        b = by_name.get(c.end_element) if c.end_element else None
        wa = a.whole(c.start_connector) if a is not None else None
        wb = b.whole(c.end_connector) if b is not None else None
        if wa is None and wb is None:
            out.append(c)
            continue
        if wa is None or wb is None:
            whole, other = (c.start_connector, c.end_connector) if wa else (c.end_connector, c.start_connector)
            raise SSPError(f"{c.origin}: connection {c.label()}: {whole!r} is a whole array, {other!r} is not (connect "
                           "two arrays of the same size, or element to element)")
        if len(wa) != len(wb):
            raise SSPError(f"{c.origin}: connection {c.label()}: arrays of {len(wa)} and {len(wb)} elements (connect "
                           "arrays of the same size, or element to element)")
        out += [dataclasses.replace(c, start_connector=x, end_connector=y) for x, y in zip(wa, wb)]
    return out


def _role(e):
    """'sys', 'src' (an output or parameter), 'dst' (an input) or the causality of another end."""
    if e[0] == "sys":
        return "sys"
    caus = e[1].vars[e[2]].causality
    return "src" if caus in SOURCE_CAUSALITIES else ("dst" if caus == "input" else caus)


def _said(r):
    return r if r not in ("src", "dst") else ("output" if r == "src" else "input")


def resolve_connections(desc, comps, by_name, units):
    """[Link] for the SSD's connections: each joins an output to an input, directly or through
    system connectors (the root's, nested systems'), every input fed at most once."""
    half = []  # (src_end, dst_end, transform, suppress, connection)
    # a valued system connector's connections fan its value out before the run (parameter_connections)
    parameter_ids = _parameter_connection_ids(desc)
    for c in _whole_arrays_expanded([c for c in desc.connections if id(c) not in parameter_ids], by_name):
        a = _end(desc, by_name, c.start_element, c.start_connector, c)
        b = _end(desc, by_name, c.end_element, c.end_connector, c)
        ra, rb = _role(a), _role(b)
        transform = c.transform
        if ra == "sys" and rb == "sys":
            src, dst = a, b  # between system connectors: as written
        elif ra in ("src", "sys") and rb in ("dst", "sys"):
            src, dst = a, b
        elif rb in ("src", "sys") and ra in ("dst", "sys"):
            src, dst = b, a
            transform = _invert(transform, c)
        else:
            raise SSPError(f"{c.origin}: connection {c.label()} must join an output to an input "
                           f"(found {_said(ra)} and {_said(rb)})")
        half.append((src, dst, transform, c.suppress_unit_conversion, c))

    links = _links(desc, units, half)
    seen = {}
    for lk in links:
        key = (lk.dst, lk.dst_var)
        if key in seen:
            raise SSPError(f"input {comps[lk.dst].name}.{lk.dst_var} is connected twice: {seen[key]} and {lk.label}")
        seen[key] = lk.label
    return links


def _links(desc, units, half):
    """[Link] for the oriented connections `half`: component to component, and component through
    system connectors (root or nested, any number) to every component input they reach."""
    from_sys = {}  # system connector -> the half connections that leave it
    for h in half:
        if h[0][0] == "sys":
            from_sys.setdefault(h[0][2], []).append(h)

    def reach(name, chain, vias, seen):
        """(component end, chain, connectors passed) for every component input that system
        connector `name` feeds, directly or through further system connectors."""
        if name in seen:
            raise SSPError(f"{chain[-1][2].origin}: connection {chain[-1][2].label()}: system connectors form a "
                           f"loop through {name!r}")
        for _src, dst, tr, sup, c in from_sys.get(name, []):
            step = chain + [(tr, sup, c)]
            if dst[0] == "comp":
                yield dst, step, vias + [name]
            else:
                yield from reach(dst[2], step, vias + [name], seen | {name})

    links = []
    for src, dst, tr, sup, c in half:
        if src[0] == "comp" and dst[0] == "comp":
            links.append(_make_link(units, desc, src, dst, [(tr, sup, c)], c.label(), c.origin))
        elif src[0] == "comp":
            # component output -> system connector(s) -> component inputs
            for dst2, chain, vias in reach(dst[2], [(tr, sup, c)], [], frozenset()):
                label = " ; ".join(step[2].label() for step in chain)
                links.append(_make_link(units, desc, src, dst2, chain, label, chain[-1][2].origin, via=vias))
    return links


def _make_link(units, desc, src, dst, chain, label, origin, via=None):
    sc, sv = src[1], src[2]
    dc, dv = dst[1], dst[2]
    where = f"{origin}: connection {label}"
    st, dt = sc.vars[sv].type, dc.vars[dv].type
    if KIND.get(st, st) != KIND.get(dt, dt):
        raise SSPError(f"{where}: type mismatch: {sc.name}.{sv} is {st}, {dc.name}.{dv} is {dt}")
    if st not in RECORDABLE:
        raise SSPError(f"{where}: connections of type {st} are not supported")
    if st == "String" and any(tr is not None for tr, _, _ in chain):
        raise SSPError(f"{where}: a String connection cannot have a transformation")
    suppress = any(s for _, s, _ in chain)
    factor, offset, mapping = 1.0, 0.0, None
    if st == "Real":
        s_fmu, s_conn = units.end_units(sc, sv)
        d_fmu, d_conn = units.end_units(dc, dv)
        steps = [(s_fmu, s_conn, sc, sc)]
        for name in via or ():  # the system connectors passed, each in its own unit if it declares one
            vu = desc.system_connectors[name].unit
            steps.append((s_conn, vu or s_conn, sc, None))
            s_conn = vu or s_conn
        steps.append((s_conn, d_conn, sc, dc))
        steps.append((d_conn, d_fmu, dc, dc))
        # The connection's own transformation acts on connector values (start -> end units).
        conv_total = (1.0, 0.0)
        for i, (a, b, ca, cb) in enumerate(steps):
            if suppress and i != 0 and i != len(steps) - 1:
                continue
            f, o = units.convert(a, b, ca, cb, where)
            conv_total = (conv_total[0] * f, conv_total[1] * f + o)
            if i == 0:
                for tr, _, _ in chain:  # transformations in data-flow order, in source connector units
                    if tr is not None:
                        if tr[0] != "linear":
                            raise SSPError(f"{where}: {tr[0]} transformation on a Real connection")
                        conv_total = (conv_total[0] * tr[1], conv_total[1] * tr[1] + tr[2])
        factor, offset = conv_total
    else:
        for tr, _, _ in chain:
            if tr is None:
                continue
            if tr[0] == "linear":
                raise SSPError(f"{where}: LinearTransformation on a {st} connection is not supported")
            if mapping is None:
                mapping = dict(tr[1])
            else:
                mapping = {k: tr[1].get(v, v) for k, v in mapping.items()}
    return Link(sc.index, dv, sv, dc.index, KIND.get(st, st), factor, offset, mapping, label)


class FeedthroughGraph:
    """Which inputs are connected, which connected outputs depend directly on inputs, and the
    component edges p -> c that such outputs create (Gauss-Seidel must step p before c)."""

    def __init__(self, comps, links):
        n = len(comps)
        self.comps = comps
        self.connected_inputs = [set() for _ in range(n)]
        for lk in links:
            self.connected_inputs[lk.dst].add(lk.dst_var)
        self.edges = {}  # (p, c) -> [labels of the links that cause it]
        self.feedthrough_outputs = [set() for _ in range(n)]
        for lk in links:
            p = comps[lk.src]
            if p.depends_on_inputs(lk.src_var, self.connected_inputs[lk.src]):
                self.feedthrough_outputs[lk.src].add(lk.src_var)
                # a self-edge (a component feeding itself through feedthrough) is a loop too
                self.edges.setdefault((lk.src, lk.dst), []).append(lk.label)

    def order(self):
        """Component indices in dependency order, ties by SSD order; SSPError names the
        components of an algebraic loop."""
        order, cycle = toposort(len(self.comps), self.edges)
        if cycle:
            raise SSPError(f"algebraic loop (direct feedthrough cycle) between components: {self.describe(cycle)}; "
                           "Gauss-Seidel needs an acyclic order: break the loop or use "
                           f"{option('--algorithm jacobi', 'algorithm=' + repr('jacobi'))}")
        return order

    def describe(self, cycle):
        """The components of a feedthrough cycle, and those of them whose FMUs declare no output
        dependencies (which may be all that makes it a loop)."""
        names = " -> ".join(self.comps[i].name for i in cycle)
        silent = [self.comps[i].name for i in dict.fromkeys(cycle) if self.comps[i].undeclared]
        if silent:
            names += (f" ({', '.join(silent)} declare{'s' if len(silent) == 1 else ''} no output dependencies, so each "
                      "output is taken to depend on every input)")
        return names
