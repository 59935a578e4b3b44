"""The co-simulation master: loads an SSP 1.0 system of FMI 2.0 co-simulation FMUs and runs it.

See the package docstring (`system_ssp/__init__.py`) for the annotation format and the
semantics of the algorithms. Layout of this module:

- `System`: loads the system once (schema checks, model descriptions, extracted FMUs, resolved
  connections with unit conversion, dependency graph). `System.run(...)` instantiates fresh FMU
  instances, initializes, steps, records, and always frees the instances.
- `simulate(...)`: `System(path).run(...)` in one call.
- `Result`: recorded trajectories (numpy structured array) and run summary.

Hot loops call the FMUs' C functions directly (fmpy's loaded ctypes functions) with value
reference arrays and value buffers built once per run; connected outputs of all components
live in one numpy buffer per type, so setting a component's inputs is one `np.take` (plus
the affine transformation when the connection has one) and one fmi2Set* call.
"""
from collections import namedtuple
import ctypes
import difflib
import heapq
import math
import numbers
import os
from pathlib import Path
import shutil
import tempfile
import time
import zipfile

import numpy as np

from .errors import SSPError
from . import ssd as ssdmod
from .ssd import FileNamer
from .units import BUILTIN, Unit, conversion, describe

ALGORITHMS = ("gauss-seidel", "jacobi")
_NUMERIC = ("Real", "Integer", "Boolean", "Enumeration")
_CTYPE = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Enumeration": ctypes.c_int, "Boolean": ctypes.c_int}
_NPTYPE = {"Real": np.float64, "Integer": np.int32, "Enumeration": np.int32, "Boolean": np.int32}
_KIND = {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean"}
_STATUS = ["ok", "warning", "discard", "error", "fatal", "pending"]
PROGRESS_MIN_STEPS = 2000

Link = namedtuple("Link", "src dst_var src_var dst vtype factor offset mapping label")


class Result:
    """Outcome of a run.

    data:        numpy structured array, field 'time' then 'component.variable' fields
                 (float64 for Real, int64 for Integer/Enumeration, bool for Boolean).
    stop_time:   time of the last communication point reached.
    stop_reason: "reached stop time" or "stop condition comp.var at t=... s".
    steps:       number of communication steps taken.
    final:       {'component.variable': value} for every input and output at the end.
    wall_time:   seconds spent in run() (instantiation to freeing).
    """

    def __init__(self, data, stop_time, stop_reason, steps, final, wall_time, start_time, step_size,
                 algorithm, order, messages):
        self.data = data
        self.stop_time = stop_time
        self.stop_reason = stop_reason
        self.steps = steps
        self.final = final
        self.wall_time = wall_time
        self.start_time = start_time
        self.step_size = step_size
        self.algorithm = algorithm
        self.order = order
        self.messages = messages
        self.modes = None  # scheduled runs: {mode: {"steps", "simulated_time"}}
        self.profile = None  # profile=True on a scheduled run: wall seconds per component and master

    @property
    def names(self):
        return list(self.data.dtype.names[1:])

    def __getitem__(self, name):
        return self.data[name]

    def __repr__(self):
        return (f"Result(steps={self.steps}, stop_time={self.stop_time!r}, stop_reason={self.stop_reason!r}, "
                f"signals={len(self.data.dtype.names) - 1}, wall_time={self.wall_time:.3f})")

    def write_csv(self, path):
        write_csv_atomic(self.data, path)


def write_csv_atomic(data, path):
    """Write `data` as CSV via a temporary file in the same folder, renamed on success."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise SSPError(f"output file {path}: folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", newline="") as f:
            names = data.dtype.names
            f.write(",".join(names) + "\n")
            fmts = []
            for n in names:
                k = data.dtype[n].kind
                fmts.append("%d" if k in "iub" else "%s")  # %s: shortest round-trip repr
            cols = [data[n].astype(np.int64) if data.dtype[n].kind == "b" else data[n] for n in names]
            if len(data):
                table = np.empty(len(data), dtype=[(str(i), c.dtype) for i, c in enumerate(cols)])
                for i, c in enumerate(cols):
                    table[str(i)] = c
                np.savetxt(f, table, fmt=fmts, delimiter=",")
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _near(name, candidates):
    near = difflib.get_close_matches(name, list(candidates), n=3, cutoff=0.6)
    return f" (did you mean {', '.join(repr(n) for n in near)}?)" if near else ""


def _coerce(value, vtype, label):
    """Check and convert a caller/SSV value for an FMU variable of type `vtype`."""
    def bad(expected):
        return SSPError(f"{label}: {value!r} is not a valid value: expected {expected}")

    if vtype == "Real":
        if isinstance(value, bool):
            raise bad("a Real number")
        if isinstance(value, str):
            try:
                value = float(value.strip())
            except ValueError:
                raise bad("a Real number") from None
        elif isinstance(value, numbers.Real):
            value = float(value)
        else:
            raise bad("a Real number")
        if not math.isfinite(value):
            raise SSPError(f"{label}: {value!r} is not a valid value: expected a finite Real number")
        return value
    if vtype in ("Integer", "Enumeration"):
        if isinstance(value, bool):
            raise bad("an Integer")
        if isinstance(value, str):
            try:
                value = int(value.strip())
            except ValueError:
                raise bad("an Integer") from None
        elif isinstance(value, numbers.Integral):
            value = int(value)
        elif isinstance(value, numbers.Real) and math.isfinite(value) and float(value).is_integer():
            value = int(value)
        else:
            raise bad("an Integer")
        if not -2**31 <= value < 2**31:
            raise SSPError(f"{label}: {value} is out of range for a 32-bit FMI Integer")
        return value
    if vtype == "Boolean":
        if isinstance(value, (bool, np.bool_)):
            return bool(value)
        if isinstance(value, numbers.Integral) and value in (0, 1):
            return bool(value)
        if isinstance(value, str) and value.strip().lower() in ("true", "false", "1", "0"):
            return value.strip().lower() in ("true", "1")
        raise bad("a Boolean (true/false)")
    if vtype == "String":
        if isinstance(value, str):
            return value
        raise bad("a String")
    raise SSPError(f"{label}: variables of type {vtype} cannot be set")


class _CompInfo:
    """Static (per System) information about one component."""

    def __init__(self, index, decl, md, unzipdir):
        self.index = index
        self.name = decl.name
        self.decl = decl
        self.md = md
        self.unzipdir = unzipdir
        self.vars = {v.name: v for v in md.modelVariables}
        self.unit_defs = {}
        for u in md.unitDefinitions:
            b = u.baseUnit
            if b is None:
                self.unit_defs[u.name] = Unit(u.name, (0,) * 8, 1.0, 0.0)
            else:
                exps = tuple(int(getattr(b, n, 0) or 0) for n in ("kg", "m", "s", "A", "K", "mol", "cd", "rad"))
                self.unit_defs[u.name] = Unit(u.name, exps, float(b.factor if b.factor is not None else 1.0),
                                              float(b.offset if b.offset is not None else 0.0))
        # output name -> set of input names it depends on directly (None = all inputs)
        self.deps = {}
        for unknown in md.outputs:
            d = unknown.dependencies
            self.deps[unknown.variable.name] = None if d is None else {v.name for v in d}
        self.inputs = [v.name for v in md.modelVariables if v.causality == "input"]

    def var_type(self, v):
        return v.type

    def fmu_unit(self, v):
        if getattr(v, "unit", None):
            return v.unit
        dt = getattr(v, "declaredType", None)
        return getattr(dt, "unit", None) if dt is not None else None

    def depends_on_inputs(self, out_name, connected_inputs):
        d = self.deps.get(out_name, None)
        if out_name not in self.deps or d is None:
            return bool(self.inputs)
        return bool(d & connected_inputs) if connected_inputs is not None else bool(d)


class System:
    """A loaded SSP system. Call `run()` any number of times; each run uses fresh FMU instances.

    Use as a context manager (or call `close()`) to delete the extracted files.
    """

    def __init__(self, path, validate=True):
        self._tmp = Path(tempfile.mkdtemp(prefix="system_ssp_"))
        try:
            self._load(Path(path), validate)
        except BaseException:
            self.close()
            raise

    # ---- loading ------------------------------------------------------------------------
    def _load(self, path, validate):
        self.path = path
        self.validate = validate
        if not path.exists():
            raise SSPError(f"{path}: file not found")
        if path.is_dir():
            path = path / "SystemStructure.ssd"
            self.namer = FileNamer()
            ssd_path = path
        elif path.suffix.lower() == ".ssp":
            root = self._tmp / "ssp"
            try:
                with zipfile.ZipFile(path) as z:
                    for n in z.namelist():
                        target = (root / n).resolve()
                        if not str(target).startswith(str(root.resolve())):
                            raise SSPError(f"{path}: archive member {n!r} points outside the archive")
                    z.extractall(root)
            except zipfile.BadZipFile as exc:
                raise SSPError(f"{path}: not a valid .ssp (zip) archive: {exc}") from None
            ssd_path = root / "SystemStructure.ssd"
            if not ssd_path.is_file():
                raise SSPError(f"{path}: archive has no SystemStructure.ssd at its root")
            self.namer = FileNamer(root, str(path))
            self.archive_root = root
        else:
            ssd_path = path
            self.namer = FileNamer()
        self.archive_root = getattr(self, "archive_root", None)
        self.desc = ssdmod.parse_ssd(ssd_path, self.namer, validate)
        if not self.desc.components:
            raise SSPError(f"{self.desc.display}: the system has no components")
        self._load_fmus()
        self._resolve_connections()

    def _load_fmus(self):
        from fmpy import extract, read_model_description

        self.comps = []
        self.by_name = {}
        for i, decl in enumerate(self.desc.components):
            if not decl.fmu_path.is_file():
                raise SSPError(f"{decl.origin}: component {decl.name!r}: FMU file not found "
                               f"(source={decl.source!r}, tried {self.namer(decl.fmu_path)}); the product's "
                               "systems are packed with their FMUs by `python build_fmus.py` into build/ssp/")
            try:
                md = read_model_description(str(decl.fmu_path), validate=self.validate)
            except Exception as exc:  # fmpy raises various exceptions for broken FMUs
                raise SSPError(f"component {decl.name!r}: cannot read the model description of "
                               f"{self.namer(decl.fmu_path)}: {exc}") from None
            if md.fmiVersion != "2.0" or md.coSimulation is None:
                raise SSPError(f"component {decl.name!r}: {self.namer(decl.fmu_path)} is not an FMI 2.0 "
                               "co-simulation FMU")
            unzipdir = extract(str(decl.fmu_path), unzipdir=str(self._tmp / "fmu" / f"{i}_{decl.name}"))
            info = _CompInfo(i, decl, md, unzipdir)
            for cname, conn in decl.connectors.items():
                v = info.vars.get(cname)
                if v is None:
                    raise SSPError(f"{conn.origin}: connector {cname!r} of component {decl.name!r} has no matching "
                                   f"variable in {self.namer(decl.fmu_path)}{_near(cname, info.vars)}")
                if conn.type and conn.type != v.type and not (conn.type == "Integer" and v.type == "Enumeration"):
                    raise SSPError(f"{conn.origin}: connector {decl.name}.{cname} is declared {conn.type} but the "
                                   f"FMU variable is {v.type}")
            self.comps.append(info)
            self.by_name[decl.name] = info

    # ---- units --------------------------------------------------------------------------
    def _unit(self, name, comp=None, extra=None, where=""):
        if name is None:
            return None
        for table in (extra or {}, self.desc.units, comp.unit_defs if comp else {}, BUILTIN):
            if name in table:
                return table[name]
        for c in self.comps:
            if name in c.unit_defs:
                return c.unit_defs[name]
        raise SSPError(f"{where}: unit {name!r} has no definition (add it to ssd:Units)")

    def _convert(self, a, b, comp_a, comp_b, where):
        """(factor, offset) from unit name a to unit name b; identity if either is unknown."""
        if a is None or b is None or a == b:
            return 1.0, 0.0
        ua = self._unit(a, comp_a, where=where)
        ub = self._unit(b, comp_b, where=where)
        conv = conversion(ua, ub)
        if conv is None:
            raise SSPError(f"{where}: incompatible units {a!r} ({describe(ua)}) and {b!r} ({describe(ub)})")
        return conv

    def _end_units(self, comp, var):
        """(unit of the FMU value, unit seen by the connection) for a component variable."""
        v = comp.vars[var]
        conn = comp.decl.connectors.get(var)
        fu = comp.fmu_unit(v)
        cu = conn.unit if conn is not None else None
        return (fu or cu), (cu or fu)

    def var_unit(self, comp, var):
        return self._end_units(comp, var)[0]

    # ---- connections --------------------------------------------------------------------
    def _end(self, element, connector, c):
        """('comp', info, var) or ('sys', None, name) for one end of a connection."""
        if element is None:
            if connector not in self.desc.system_connectors:
                raise SSPError(f"{c.origin}: connection {c.label()}: the system has no connector {connector!r}"
                               f"{_near(connector, self.desc.system_connectors)}")
            return ("sys", None, connector)
        comp = self.by_name.get(element)
        if comp is None:
            raise SSPError(f"{c.origin}: connection {c.label()}: no component named {element!r}"
                           f"{_near(element, self.by_name)}")
        if connector not in comp.vars:
            raise SSPError(f"{c.origin}: connection {c.label()}: component {element!r} has no variable "
                           f"{connector!r}{_near(connector, comp.vars)}")
        return ("comp", comp, connector)

    def _resolve_connections(self):
        src_causal = ("output", "calculatedParameter", "parameter")
        half = []  # (src_end, dst_end, transform, suppress, connection)
        for c in self.desc.connections:
            a = self._end(c.start_element, c.start_connector, c)
            b = self._end(c.end_element, c.end_connector, c)

            def role(e):
                if e[0] == "sys":
                    return "sys"
                caus = e[1].vars[e[2]].causality
                return "src" if caus in src_causal else ("dst" if caus == "input" else caus)

            ra, rb = role(a), role(b)
            transform = c.transform
            if ra in ("src", "sys") and rb in ("dst", "sys") and not (ra == "sys" and rb == "sys"):
                src, dst = a, b
            elif rb in ("src", "sys") and ra in ("dst", "sys") and not (ra == "sys" and rb == "sys"):
                src, dst = b, a
                transform = _invert(transform, c)
            else:
                raise SSPError(f"{c.origin}: connection {c.label()} must join an output to an input "
                               f"(found {ra if ra not in ('src', 'dst') else ('output' if ra == 'src' else 'input')} "
                               f"and {rb if rb not in ('src', 'dst') else ('output' if rb == 'src' else 'input')})")
            if src[0] == "sys" and dst[0] == "sys":
                raise SSPError(f"{c.origin}: connection {c.label()} joins two system connectors")
            half.append((src, dst, transform, c.suppress_unit_conversion, c))

        links = []
        for src, dst, tr, sup, c in half:
            if src[0] == "comp" and dst[0] == "comp":
                links.append(self._make_link(src, dst, [(tr, sup, c)], c.label(), c.origin))
            elif dst[0] == "sys":
                # component output -> system connector -> component inputs
                for src2, dst2, tr2, sup2, c2 in half:
                    if src2[0] == "sys" and src2[2] == dst[2] and dst2[0] == "comp":
                        label = f"{c.label()} ; {c2.label()}"
                        links.append(self._make_link(src, dst2, [(tr, sup, c), (tr2, sup2, c2)], label, c2.origin,
                                                     via=dst[2]))
        # every input at most once
        seen = {}
        for lk in links:
            key = (lk.dst, lk.dst_var)
            if key in seen:
                raise SSPError(f"input {self.comps[lk.dst].name}.{lk.dst_var} is connected twice: "
                               f"{seen[key]} and {lk.label}")
            seen[key] = lk.label
        self.links = links
        self._build_graph()

    def _make_link(self, src, dst, chain, label, origin, via=None):
        sc, sv = src[1], src[2]
        dc, dv = dst[1], dst[2]
        where = f"{origin}: connection {label}"
        st, dt = sc.vars[sv].type, dc.vars[dv].type
        if _KIND.get(st, st) != _KIND.get(dt, dt):
            raise SSPError(f"{where}: type mismatch: {sc.name}.{sv} is {st}, {dc.name}.{dv} is {dt}")
        if st not in _NUMERIC:
            raise SSPError(f"{where}: connections of type {st} are not supported")
        suppress = any(s for _, s, _ in chain)
        factor, offset, mapping = 1.0, 0.0, None
        if st == "Real":
            s_fmu, s_conn = self._end_units(sc, sv)
            d_fmu, d_conn = self._end_units(dc, dv)
            steps = [(s_fmu, s_conn, sc, sc)]
            if via is not None:
                vu = self.desc.system_connectors[via].unit
                steps.append((s_conn, vu or s_conn, sc, None))
                s_conn = vu or s_conn
            steps.append((s_conn, d_conn, sc, dc))
            steps.append((d_conn, d_fmu, dc, dc))
            # The connection's own transformation acts on connector values (start -> end units).
            conv_total = (1.0, 0.0)
            for i, (a, b, ca, cb) in enumerate(steps):
                if suppress and i != 0 and i != len(steps) - 1:
                    continue
                f, o = self._convert(a, b, ca, cb, where)
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
        return Link(sc.index, dv, sv, dc.index, _KIND.get(st, st), factor, offset, mapping, label)

    def _build_graph(self):
        n = len(self.comps)
        connected_in = [set() for _ in range(n)]
        for lk in self.links:
            connected_in[lk.dst].add(lk.dst_var)
        self.connected_inputs = connected_in
        # feedthrough edges p -> c, with the link labels that cause them
        self.edges = {}
        self.feedthrough_outputs = [set() for _ in range(n)]
        for lk in self.links:
            p = self.comps[lk.src]
            if p.depends_on_inputs(lk.src_var, connected_in[lk.src]):
                self.feedthrough_outputs[lk.src].add(lk.src_var)
                # a self-edge (a component feeding itself through feedthrough) is a loop too
                self.edges.setdefault((lk.src, lk.dst), []).append(lk.label)

    def default_order(self):
        """Components in dependency order (feedthrough edges), ties by SSD order.

        Raises SSPError naming the components of an algebraic loop."""
        order, cycle = _toposort(len(self.comps), self.edges)
        if cycle:
            names = " -> ".join(self.comps[i].name for i in cycle)
            raise SSPError(f"algebraic loop (direct feedthrough cycle) between components: {names}; "
                           "Gauss-Seidel needs an acyclic order: break the loop or use algorithm='jacobi'")
        return [self.comps[i].name for i in order]

    # ---- names --------------------------------------------------------------------------
    def split_name(self, name, what="variable"):
        """'component.variable' -> (_CompInfo, variable name); SSPError with suggestions."""
        if not isinstance(name, str):
            raise SSPError(f"{what} name must be a string 'component.variable', got {name!r}")
        for comp in sorted(self.comps, key=lambda c: -len(c.name)):
            if name.startswith(comp.name + "."):
                var = name[len(comp.name) + 1:]
                if var not in comp.vars:
                    raise SSPError(f"{what} {name!r}: component {comp.name!r} has no variable {var!r}"
                                   f"{_near(var, comp.vars)}")
                return comp, var
        head = name.split(".", 1)[0]
        if "." not in name:
            raise SSPError(f"{what} {name!r}: expected 'component.variable'")
        raise SSPError(f"{what} {name!r}: unknown component {head!r}{_near(head, self.by_name)} "
                       f"(components: {', '.join(c.name for c in self.comps)})")

    # ---- parameters ---------------------------------------------------------------------
    def _settable(self, v):
        if v.variability == "constant" or v.causality in ("independent", "calculatedParameter"):
            return False
        return v.causality in ("parameter", "input") or v.initial in ("exact", "approx")

    def resolve_parameter(self, comp, var, value, vtype=None, unit=None, units=None, origin="", label=None):
        """Check one value for comp.var; returns the value converted to the FMU's type and unit."""
        label = label or f"{comp.name}.{var}"
        where = f"{origin}: {label}" if origin else label
        v = comp.vars.get(var)
        if v is None:
            raise SSPError(f"{where}: component {comp.name!r} has no variable {var!r}{_near(var, comp.vars)}")
        if not self._settable(v):
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
        value = _coerce(value, v.type, where)
        if unit is not None and v.type == "Real":
            target = self.var_unit(comp, var)
            if target is not None and target != unit:
                su = self._unit(unit, comp, units, where)
                tu = self._unit(target, comp, None, where)
                conv = conversion(su, tu)
                if conv is None:
                    raise SSPError(f"{where}: value in unit {unit!r} ({describe(su)}) cannot be converted to the "
                                   f"variable's unit {target!r} ({describe(tu)})")
                value = conv[0] * value + conv[1]
        return value

    def collect_parameters(self, parameter_sets=None, parameters=None):
        """All start values for a run: {(comp index, var): value}, later sources overriding earlier."""
        out = {}

        def put(comp, var, pv):
            out[(comp.index, var)] = self.resolve_parameter(comp, var, pv.value, pv.type, pv.unit, pv.units,
                                                            pv.origin, f"{comp.name}.{var}")

        for comp in self.comps:
            for pv in comp.decl.parameters:
                if pv.name not in comp.vars:
                    raise SSPError(f"{pv.origin}: parameter {pv.name!r} bound to component {comp.name!r}: no such "
                                   f"variable{_near(pv.name, comp.vars)}")
                put(comp, pv.name, pv)
        for pv in self.desc.parameters:
            comp, var = self.split_name(pv.name, f"{pv.origin}: parameter")
            put(comp, var, pv)
        for ps in parameter_sets or []:
            for pv in self._read_parameter_set(ps):
                try:
                    comp, var = self.split_name(pv.name, "parameter")
                except SSPError as exc:
                    raise SSPError(f"{pv.origin}: {exc}") from None
                put(comp, var, pv)
        for name, value in (parameters or {}).items():
            comp, var = self.split_name(name, "parameter")
            out[(comp.index, var)] = self.resolve_parameter(comp, var, value, None, None, None, "", name)
        return out

    def _read_parameter_set(self, ps):
        p = Path(ps)
        if not p.is_file() and self.archive_root is not None:
            cand = [self.archive_root / ps, self.archive_root / "resources" / ps]
            p = next((c for c in cand if c.is_file()), p)
        if not p.is_file():
            where = f" (also looked inside {self.path})" if self.archive_root is not None else ""
            raise SSPError(f"parameter set {ps!r}: file not found{where}")
        return ssdmod.read_parameter_set_file(p, self.namer, self.validate)

    # ---- info ---------------------------------------------------------------------------
    def info(self):
        """Human-readable description (components, connectors with units, bindings, experiment)."""
        d = self.desc
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
            lines.append("default Gauss-Seidel order: " + ", ".join(self.default_order()))
        except SSPError as exc:
            lines.append(f"default Gauss-Seidel order: none ({exc})")
        for c in self.comps:
            lines.append(f"component {c.name}: {c.decl.source} (model {c.md.modelName})")
            for v in c.md.modelVariables:
                if v.causality in ("input", "output"):
                    u = self.var_unit(c, v.name)
                    lines.append(f"  {v.causality:6s} {v.name} : {v.type}{f' [{u}]' if u else ''}")
            for pv in c.decl.parameters:
                lines.append(f"  bound  {pv.name} = {pv.value!r}{f' {pv.unit}' if pv.unit else ''}  ({pv.origin})")
        for pv in d.parameters:
            lines.append(f"system binding {pv.name} = {pv.value!r}{f' {pv.unit}' if pv.unit else ''}  ({pv.origin})")
        lines.append("connections:")
        for lk in self.links:
            extra = ""
            if lk.factor != 1.0 or lk.offset != 0.0:
                extra = f"  (x{lk.factor:g}{lk.offset:+g})"
            lines.append(f"  {self.comps[lk.src].name}.{lk.src_var} -> {self.comps[lk.dst].name}.{lk.dst_var}{extra}")
        return "\n".join(lines)

    # ---- running ------------------------------------------------------------------------
    def run(self, stop_time=None, step_size=None, start_time=None, parameters=None, parameter_sets=None,
            outputs=None, algorithm=None, order=None, step_multiples=None, stop_when=None, output_file=None,
            progress=False, record_every=1, schedule=True, profile=False):
        """Run one simulation with fresh FMU instances; see `system_ssp.simulate` for arguments.
        schedule=False runs a system that has an nc:Schedule with the fixed step instead."""
        from .run import Run

        wall0 = time.perf_counter()
        plan = self._plan(stop_time, step_size, start_time, parameters, parameter_sets, outputs, algorithm,
                          order, step_multiples, stop_when, record_every)
        plan["profile"] = bool(profile)
        plan["schedule"] = self._plan_schedule(plan) if (schedule and self.desc.master.schedule) else None
        result = Run(self, plan).execute(progress)
        result.wall_time = time.perf_counter() - wall0
        if output_file is not None:
            write_csv_atomic(result.data, output_file)
        return result

    def _plan(self, stop_time, step_size, start_time, parameters, parameter_sets, outputs, algorithm, order,
              step_multiples, stop_when, record_every):
        d, m = self.desc, self.desc.master
        start = start_time if start_time is not None else (d.start_time if d.start_time is not None else 0.0)
        stop = stop_time if stop_time is not None else d.stop_time
        h = step_size if step_size is not None else m.step_size
        if stop is None:
            raise SSPError(f"{d.display}: no stop time: pass stop_time (CLI --stop-time) or set "
                           "ssd:DefaultExperiment stopTime")
        if h is None:
            raise SSPError(f"{d.display}: no step size: pass step_size (CLI --step-size) or give one in the "
                           f"{ssdmod.ANNOTATION_TYPE} annotation (nc:Master stepSize)")
        for label, x in (("start time", start), ("stop time", stop), ("step size", h)):
            if isinstance(x, bool) or not isinstance(x, numbers.Real) or not math.isfinite(x):
                raise SSPError(f"{label} must be a finite number, got {x!r}")
        start, stop, h = float(start), float(stop), float(h)
        if h <= 0:
            raise SSPError(f"step size must be positive, got {h}")
        if stop < start:
            raise SSPError(f"stop time {stop} is before start time {start}")
        algo = algorithm or m.algorithm or "gauss-seidel"
        if algo not in ALGORITHMS:
            raise SSPError(f"unknown algorithm {algo!r} (expected one of: {', '.join(ALGORITHMS)})")

        names = [c.name for c in self.comps]
        if order is None:
            order = m.order
        if order is not None:
            if isinstance(order, str):
                order = order.replace(",", " ").split()
            order = list(order)
            unknown = [o for o in order if o not in self.by_name]
            dup = sorted({o for o in order if order.count(o) > 1})
            missing = [n for n in names if n not in order]
            if unknown or dup or missing:
                parts = []
                if unknown:
                    parts.append("unknown " + ", ".join(f"{u!r}{_near(u, names)}" for u in unknown))
                if dup:
                    parts.append("listed more than once: " + ", ".join(dup))
                if missing:
                    parts.append("missing: " + ", ".join(missing))
                raise SSPError(f"component order {order}: must name every component exactly once ("
                               + "; ".join(parts) + ")")
            order_idx = [self.by_name[o].index for o in order]
        elif algo == "gauss-seidel":
            order_idx = [self.by_name[o].index for o in self.default_order()]
        else:
            order_idx = list(range(len(self.comps)))

        mult = [1] * len(self.comps)
        sm = dict(m.step_multiples)
        sm.update(step_multiples or {})
        for name, k in sm.items():
            if name not in self.by_name:
                raise SSPError(f"step multiple for unknown component {name!r}{_near(name, names)}")
            if isinstance(k, bool) or not isinstance(k, numbers.Integral) or k < 1:
                raise SSPError(f"step multiple of {name!r} must be an integer >= 1, got {k!r}")
            mult[self.by_name[name].index] = int(k)

        stops = []
        for s in (list(m.stop_conditions) if stop_when is None else list(stop_when)):
            comp, var = self.split_name(s, "stop condition")
            v = comp.vars[var]
            if v.type != "Boolean":
                raise SSPError(f"stop condition {s!r} must be a Boolean variable, it is {v.type}")
            stops.append((comp.index, var))

        if outputs is None:
            rec = [(c.index, v.name) for c in self.comps for v in c.md.modelVariables
                   if v.causality in ("input", "output") and v.type in _NUMERIC]
        else:
            if isinstance(outputs, str):
                outputs = [o for o in outputs.split(",") if o]
            rec = []
            for o in outputs:
                comp, var = self.split_name(o, "output")
                if comp.vars[var].type not in _NUMERIC:
                    raise SSPError(f"output {o!r}: variables of type {comp.vars[var].type} cannot be recorded")
                if (comp.index, var) not in rec:
                    rec.append((comp.index, var))
        if isinstance(record_every, bool) or not isinstance(record_every, numbers.Integral) or record_every < 1:
            raise SSPError(f"record_every must be an integer >= 1, got {record_every!r}")

        n_float = (stop - start) / h
        n_steps = int(round(n_float))
        if abs(n_float - n_steps) > 1e-9 * max(1.0, n_float):
            n_steps = int(math.ceil(n_float))
        params = self.collect_parameters(parameter_sets, parameters)
        return dict(start=start, stop=stop, h=h, n_steps=n_steps, algorithm=algo, order=order_idx, mult=mult,
                    stops=stops, record=rec, params=params, record_every=int(record_every))

    def _plan_schedule(self, plan):
        """Resolve the SSD's nc:Schedule against the loaded FMUs (names, types, causality)."""
        sched = self.desc.master.schedule
        if plan["algorithm"] != "gauss-seidel":
            raise SSPError(f"{sched.origin}: nc:Schedule runs with gauss-seidel only, not {plan['algorithm']!r}")
        if any(k != 1 for k in plan["mult"]):
            raise SSPError(f"{sched.origin}: nc:Schedule sets its own steps; step multiples cannot be combined "
                           "with it")
        names = [c.name for c in self.comps]

        def output(comp, conn, types, what, origin):
            if comp not in self.by_name:
                raise SSPError(f"{origin}: {what} names unknown component {comp!r}{_near(comp, names)}")
            c = self.by_name[comp]
            if conn not in c.vars:
                raise SSPError(f"{origin}: {what} names unknown variable {comp}.{conn}{_near(conn, list(c.vars))}")
            v = c.vars[conn]
            if v.causality != "output" or v.type not in types:
                raise SSPError(f"{origin}: {what} {comp}.{conn} must be an output of type "
                               f"{' or '.join(types)} (it is a {v.causality} {v.type})")
            return c.index, conn, _KIND[v.type]

        modes = []
        for m in sched.modes:
            if m.active is None:
                active = [True] * len(self.comps)
            else:
                unknown = [a for a in m.active if a not in self.by_name]
                if unknown:
                    raise SSPError(f"{m.origin}: nc:Mode {m.name!r} active lists unknown component(s) "
                                   + ", ".join(f"{u!r}{_near(u, names)}" for u in unknown))
                active = [c.name in m.active for c in self.comps]
            conds = [output(c, v, ("Integer", "Enumeration", "Boolean"), f"nc:When of mode {m.name!r}", m.origin)[:2]
                     + (vals,) for c, v, vals in m.conditions]
            mult = [1] * len(self.comps)
            for comp, k in m.every.items():
                if comp not in self.by_name:
                    raise SSPError(f"{m.origin}: nc:Mode {m.name!r} every names unknown component "
                                   f"{comp!r}{_near(comp, names)}")
                if not active[self.by_name[comp].index]:
                    raise SSPError(f"{m.origin}: nc:Mode {m.name!r} every names {comp!r}, which is not active "
                                   "in that mode")
                mult[self.by_name[comp].index] = k
            modes.append(dict(name=m.name, h=m.step_size, active=active, every=m.record_every, conds=conds,
                              mult=mult))
        events = [output(c, v, ("Real",), "nc:NextEvent", sched.origin)[:2] for c, v in sched.events]
        return dict(modes=modes, events=events, origin=sched.origin)

    # ---- cleanup ------------------------------------------------------------------------
    def close(self):
        if getattr(self, "_tmp", None) is not None:
            shutil.rmtree(self._tmp, ignore_errors=True)
            self._tmp = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


def _invert(tr, c):
    if tr is None:
        return None
    if tr[0] == "linear":
        if tr[1] == 0:
            raise SSPError(f"{c.origin}: connection {c.label()}: LinearTransformation with factor 0 cannot be "
                           "applied against the connection's start->end direction")
        return ("linear", 1.0 / tr[1], -tr[2] / tr[1])
    return (tr[0], {v: k for k, v in tr[1].items()})


def _toposort(n, edges):
    """Kahn's algorithm, ties by index. Returns (order, None) or (partial, cycle list)."""
    succ = [[] for _ in range(n)]
    indeg = [0] * n
    for (p, c) in edges:
        if p == c:
            return [], [p, p]
        succ[p].append(c)
        indeg[c] += 1
    heap = [i for i in range(n) if indeg[i] == 0]
    heapq.heapify(heap)
    order = []
    while heap:
        i = heapq.heappop(heap)
        order.append(i)
        for c in succ[i]:
            indeg[c] -= 1
            if indeg[c] == 0:
                heapq.heappush(heap, c)
    if len(order) == n:
        return order, None
    # find one cycle among the remaining nodes
    remaining = {i for i in range(n) if indeg[i] > 0}
    start = min(remaining)
    path, seen = [start], {start: 0}
    node = start
    while True:
        nxt = next(c for c in succ[node] if c in remaining)
        if nxt in seen:
            return order, path[seen[nxt]:] + [nxt]
        seen[nxt] = len(path)
        path.append(nxt)
        node = nxt


def simulate(path, stop_time=None, step_size=None, start_time=None, parameters=None, parameter_sets=None,
             outputs=None, algorithm=None, order=None, step_multiples=None, stop_when=None, output_file=None,
             progress=False, validate=True, record_every=1, schedule=True, profile=False):
    """Load and run an SSP system; returns a `Result`. See the package docstring."""
    with System(path, validate=validate) as system:
        return system.run(stop_time=stop_time, step_size=step_size, start_time=start_time, parameters=parameters,
                          parameter_sets=parameter_sets, outputs=outputs, algorithm=algorithm, order=order,
                          step_multiples=step_multiples, stop_when=stop_when, output_file=output_file,
                          progress=progress, record_every=record_every, schedule=schedule, profile=profile)
