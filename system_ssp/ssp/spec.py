"""A system spec (TOML): the components of a system, their parameter values and files, the
connections (by identical names, or spelled out with optional transformations), the master's
settings and what is recorded; `compose` turns it into an SSP 1.0 system that `write_ssp` packs
with its FMUs and parameter sets, loaded by the master before it is kept.

    [system]
    name = "my_detumble"
    description = "Our rigid body and thrusters with our own controller"

    [master]
    step_size = 0.015
    stop_time = 20.0
    stop_when = ["controller.done"]

    [components.dynamics]
    fmu = "RigidBody"                          # a shipped FMU by name, or a path to any .fmu
    parameter_files = ["spacecraft"]           # a shipped parameter set by name, or a path to an .ssv
    parameters = { omega0 = [0.17, 0.17, 0.17], integrator = "rk4" }

    [connections]
    auto = true                                # an output feeds the inputs of the same name
    exclude = ["dynamics.omega_dot_BN_B"]      # names (fnmatch patterns) never wired by name
    links = ["controller.torque_cmd_B -> thrusters.torque_cmd_B",
             { from = "a.angle_deg", to = "b.angle", factor = 0.0174533 }]

docs/compose.md describes every key. Errors name the spec, its line, the key and what is
allowed (with close matches), before anything is written.
"""
from dataclasses import dataclass, field
import fnmatch
import math
from pathlib import Path
import re
import sys
from typing import Any, Dict, List, Optional, Tuple

from fmpy import read_model_description

from ..errors import SSPError
from ..limits import read_text_input
from ..master.names import near
from .interface import unit_definitions
from .schedule import Schedule, ScheduleMode, When
from .toml_lines import KeyLines
from .units import BUILTIN, conversion, describe

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10 and older
    import tomli as tomllib

TOP_KEYS = {"extends", "system", "master", "components", "system_parameters", "connections"}
SYSTEM_KEYS = {"name", "description", "ssp_version", "parameter_files"}
MASTER_KEYS = {"step_size", "stop_time", "algorithm", "order", "stop_when", "record", "schedule"}
SCHEDULE_KEYS = {"mode", "events"}
MODE_KEYS = {"name", "step_size", "active", "record_every", "every", "when"}
COMPONENT_KEYS = {"fmu", "parameter_files", "parameters"}
SYSTEM_PARAMETER_KEYS = {"description", "value", "to"}
CONNECTION_KEYS = {"auto", "exclude", "links"}
LINK_KEYS = {"from", "to", "factor", "offset", "suppress_unit_conversion", "from_unit", "to_unit"}
ALGORITHMS = ("gauss-seidel", "jacobi")
SSP_VERSIONS = ("1.0", "2.0")
NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
# a component's name; dots for the components of a nested system as the master names them (outer.inner)
COMPONENT_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$")
STARTABLE = ("parameter", "input")  # what a spec may give a value


@dataclass
class ComponentSpec:
    name: str
    fmu: str  # as the spec gives it
    fmu_path: Path
    parameter_files: List[Tuple[str, Path]]  # (stem in the SSP's parameters/, file)
    parameters: Dict[str, Any]  # variable name (vectors expanded) -> value
    variables: Dict[str, Any] = field(default_factory=dict)  # name -> fmpy ScalarVariable
    unit_defs: Dict[str, Any] = field(default_factory=dict)  # unit name -> units.Unit
    model_identifier: str = ""


@dataclass
class LinkSpec:
    src: str
    src_var: str
    dst: str
    dst_var: str
    factor: Optional[float] = None
    offset: Optional[float] = None
    suppress: bool = False
    how: str = "link"  # "link" (spelled out) or "name" (wired by identical names)


@dataclass
class Composition:
    """What a spec composes to: the SystemWriter spec dict, the files the .ssp holds besides the
    SSD, and the report of what was wired by name and what stays unconnected."""
    name: str
    spec_path: Path
    components: Dict[str, ComponentSpec]
    links: List[LinkSpec]
    writer_spec: Dict[str, Any]
    ssv_files: Dict[str, Any]  # parameters/<stem>.ssv -> source Path, or (description, {name: value})
    ssp_version: str
    unconnected: List[Tuple[str, str, Any, str]]  # (component, variable, start, unit)
    unused: List[Tuple[str, str]]  # outputs that feed nothing

    def report(self) -> str:
        by_name = [lk for lk in self.links if lk.how == "name"]
        out = [f"{self.name}: {len(self.components)} components, {len(self.links)} connections "
               f"({len(by_name)} by identical names)"]
        if by_name:
            out.append("wired by name:")
            out += [f"  {a} -> {b}" for a, b in _grouped([(f"{lk.src}.{lk.src_var}", f"{lk.dst}.{lk.dst_var}")
                                                           for lk in by_name])]
        if self.unconnected:
            out.append(f"inputs left unconnected ({len(self.unconnected)}), at their start values:")
            for comp, var, start, unit in self.unconnected:
                shown = "no start value" if start is None else f"{start}" + (f" {unit}" if unit else "")
                out.append(f"  {comp}.{var} = {shown}")
        if self.unused:
            out.append(f"outputs that feed nothing ({len(self.unused)}):")
            out += [f"  {a}" for a, _ in _grouped([(f"{c}.{v}", "") for c, v in self.unused])]
        return "\n".join(out)


def _grouped(pairs):
    """[(a[1], b[1]), (a[2], b[2]), ...] -> [(a[1..n], b[1..n])]: a vector on one line (b may
    be "" throughout)."""
    index = re.compile(r"^(.*)\[(\d+)\]$")
    groups: List[list] = []  # [a base, first, last, b base, b first] or [a, None, None, b, None]
    for a, b in pairs:
        ma, mb = index.match(a), index.match(b)
        g = groups[-1] if groups else None
        if g and ma and g[1] is not None and g[0] == ma.group(1) and g[2] + 1 == int(ma.group(2)) \
                and ((not b and not g[3]) or (mb and g[3] == mb.group(1))):
            g[2] += 1
            continue
        if ma and (mb or not b):
            groups.append([ma.group(1), int(ma.group(2)), int(ma.group(2)), mb.group(1) if mb else "",
                           int(mb.group(2)) if mb else 0])
        else:
            groups.append([a, None, None, b, None])
    out = []
    for a, first, last, b, bfirst in groups:
        if first is None:
            out.append((a, b))
        elif first == last:
            out.append((f"{a}[{first}]", f"{b}[{bfirst}]" if b else ""))
        else:
            out.append((f"{a}[{first}..{last}]", f"{b}[{bfirst}..{bfirst + last - first}]" if b else ""))
    return out


class SpecReader:
    """Reads one spec file (and the one it extends) and says where a key is."""

    def __init__(self, path: Path):
        self.path = Path(path)
        self.files: List[Tuple[Path, KeyLines]] = []  # this spec, then the ones it extends
        self.doc = self._read(self.path, ())

    def _read(self, path, seen):
        text = read_text_input(path, str(path), "the system spec", "a system spec is TOML, which is UTF-8: save it "
                               "as UTF-8")
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            line = re.search(r"line (\d+)", str(exc))
            raise SSPError(f"{path}{':' + line.group(1) if line else ''}: not valid TOML: {exc}") from None
        lines = KeyLines(text)
        self.files.append((path, lines))
        base = doc.pop("extends", None)
        if base is None:
            return doc
        where = f"{path}:{lines.line('extends')}"
        if not isinstance(base, str) or not base.endswith(".toml"):
            raise SSPError(f"{where}: extends = {base!r}: expected the path of another system spec (.toml)")
        base_path = (path.parent / base) if not Path(base).is_absolute() else Path(base)
        if not base_path.is_file():
            raise SSPError(f"{where}: extends = {base!r}: no such file ({base_path})")
        if base_path.resolve() in seen or base_path.resolve() == path.resolve():
            raise SSPError(f"{where}: extends = {base!r}: the specs extend each other in a cycle")
        base_doc = self._read(base_path, seen + (path.resolve(),))
        return _merged(base_doc, doc)

    def locate(self, *key: str) -> Tuple[Path, Optional[int]]:
        """(file, line) of the longest prefix of `key` a file spells: this spec before the ones
        it extends, so a key is named where the merged value came from."""
        for n in range(len(key), 0, -1):
            for path, lines in self.files:
                if tuple(key[:n]) in lines.lines:
                    return path, lines.lines[tuple(key[:n])]
        return self.path, None

    def where(self, *key: str) -> str:
        path, line = self.locate(*key)
        return f"{path}:{line}" if line else str(path)

    def line_of_text(self, needle: str, *key: str) -> str:
        """file:line of the first line holding `needle` at or after `key`'s (a value in a list)."""
        path, start = self.locate(*key)
        lines = dict(self.files)[path]
        line = lines.line_of_text(needle, start) or start
        return f"{path}:{line}" if line else str(path)

    at_line: Optional[str] = None  # while set, messages name this file:line

    def fail(self, key: Tuple[str, ...], message: str) -> SSPError:
        where = self.at_line or self.where(*key)
        return SSPError(f"{where}: {dotted(key)}: {message}")

    def table(self, key: Tuple[str, ...], value: Any, allowed: set) -> Dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a table (keys: {', '.join(sorted(allowed))})")
        for k in value:
            if k not in allowed:
                raise SSPError(f"{self.where(*key, k)}: {'.'.join(key + (k,))}: unknown key{near(k, allowed)}; "
                               f"allowed: {', '.join(sorted(allowed))}")
        return value

    def strings(self, key: Tuple[str, ...], value: Any) -> List[str]:
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            raise self.fail(key, f"{value!r}: expected a list of strings")
        return list(value)

    def number(self, key: Tuple[str, ...], value: Any, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or (positive and value <= 0):
            raise self.fail(key, f"{value!r}: expected a finite number{' > 0' if positive else ''}")
        return float(value)


def dotted(key: Tuple[str, ...]) -> str:
    """('connections', 'links', '[2]', 'to_unit') -> 'connections.links[2].to_unit'."""
    out = ""
    for k in key:
        out += k if k.startswith("[") or not out else f".{k}"
    return out


def _merged(base, over):
    """`over`'s tables over `base`'s, key by key (values and lists replaced)."""
    out = dict(base)
    for k, v in over.items():
        out[k] = _merged(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def shipped_fmu_names(fmu_dir: Path) -> List[str]:
    return sorted(p.stem for p in Path(fmu_dir).glob("*.fmu"))


def compose(spec_path, fmu_dir: Path, parameters_dir, specs_dir: Path) -> Composition:
    """Read and check the spec at `spec_path`. Shipped FMUs are `fmu_dir/<name>.fmu`, shipped
    parameter sets `parameters_dir/<name>.ssv` (a folder, or a list of folders searched in turn),
    shipped systems' specs `specs_dir/<name>.toml`.
    SSPError (file:line: key: what is allowed) on anything the system could not be written from."""
    return _Composer(Path(spec_path), Path(fmu_dir), parameters_dir, specs_dir).composition()


class _Composer:
    """One spec's composition, table by table."""

    def __init__(self, spec_path: Path, fmu_dir: Path, parameters_dir, specs_dir: Path, within=()):
        self.spec_path, self.fmu_dir, self.specs_dir = spec_path, fmu_dir, Path(specs_dir)
        self.within = tuple(within) + (spec_path.resolve(),)  # the specs this one is a sub-system of
        self.parameters_dirs = [Path(d) for d in (parameters_dir if isinstance(parameters_dir, (list, tuple))
                                                  else [parameters_dir])]
        self.r = r = SpecReader(spec_path)
        for k in r.doc:
            if k not in TOP_KEYS:
                raise SSPError(f"{r.where(k)}: unknown table or key {k!r}{near(k, TOP_KEYS)}; allowed: "
                               f"{', '.join(sorted(TOP_KEYS))}")
        self.ssv_files: Dict[str, Any] = {}
        self.components: Dict[str, ComponentSpec] = {}
        self.links: List[LinkSpec] = []
        self.fed: Dict[Tuple[str, str], str] = {}
        self.exclude: List[str] = []
        self.sealed: set = set()  # (component, variable) of sub-systems that wiring by name leaves alone

    def composition(self) -> Composition:
        r = self.r
        system = r.table(("system",), r.doc.get("system"), SYSTEM_KEYS)
        name = system.get("name")
        if not isinstance(name, str) or not NAME.match(name):
            raise r.fail(("system", "name"), f"{name!r}: expected a name of letters, digits and _ (not starting "
                         "with a digit)")
        description = system.get("description", "")
        if not isinstance(description, str):
            raise r.fail(("system", "description"), "expected a string")
        version = system.get("ssp_version", "1.0")
        if version not in SSP_VERSIONS:
            raise r.fail(("system", "ssp_version"), f"{version!r}: expected one of {', '.join(SSP_VERSIONS)}")
        self.read_components()
        sys_params, sys_values = self.system_parameters()
        system_files = [self.parameter_file(("system", "parameter_files"), e)[0]
                        for e in r.strings(("system", "parameter_files"), system.get("parameter_files", []))]
        self.read_links()
        targets = {t for _, ts in sys_params.values() for t in ts}
        self.auto_links(targets)
        writer_spec = {"description": description, **self.master()}
        for cname, comp in self.components.items():
            if comp.parameters:
                stem = f"{name}.{cname}"
                self.ssv_files[stem] = (f"{cname}'s parameters from {self.spec_path.name}", comp.parameters)
                comp.parameter_files.append((stem, Path(stem + ".ssv")))
        if sys_values:
            self.ssv_files[name] = (f"{name}'s system parameters from {self.spec_path.name}", sys_values)
            system_files = system_files + [name]
        resources = _resource_names(self.components)
        writer_spec["components"] = [(c.name, resources[c.name], [stem for stem, _ in c.parameter_files])
                                     for c in self.components.values()]
        writer_spec["connections"] = [(lk.src, lk.src_var, lk.dst, lk.dst_var, 0)
                                      + ((_transform(lk),) if _transform(lk) else ()) for lk in self.links]
        if sys_params:
            writer_spec["parameters"] = sys_params
        if system_files:
            writer_spec["parameter_bindings"] = system_files
        unconnected, unused = self.loose_ends(targets)
        return Composition(name=name, spec_path=self.spec_path, components=self.components, links=self.links,
                           writer_spec=writer_spec, ssv_files=self.ssv_files, ssp_version=version,
                           unconnected=unconnected, unused=unused)

    def parameter_file(self, key, entry):
        """(stem, path) of a parameter file entry: a path ending in .ssv, or a shipped set's name."""
        r = self.r
        if entry.endswith(".ssv"):
            path = Path(entry) if Path(entry).is_absolute() else self.spec_path.parent / entry
            if not path.is_file():
                raise r.fail(key, f"{entry!r}: no such file ({path})")
            stem = path.stem
        else:
            path = next((d / f"{entry}.ssv" for d in self.parameters_dirs if (d / f"{entry}.ssv").is_file()),
                        self.parameters_dirs[0] / f"{entry}.ssv")
            if not path.is_file():
                known = sorted({p.stem for d in self.parameters_dirs for p in d.glob("*.ssv")})
                raise r.fail(key, f"{entry!r}: no shipped parameter set of that name{near(entry, known)}; give a "
                             "path to an .ssv file (ending in .ssv) or a shipped set's name")
            stem = entry
        previous = self.ssv_files.get(stem)
        if previous is not None and Path(previous).resolve() != path.resolve():
            raise r.fail(key, f"{entry!r}: another parameter file of the spec has the name {stem}.ssv ({previous})")
        self.ssv_files[stem] = path
        return stem, path

    def read_components(self):
        r = self.r
        comps_doc = r.doc.get("components")
        if not isinstance(comps_doc, dict) or not comps_doc:
            raise SSPError(f"{r.where('components')}: a system spec needs [components.<name>] tables (fmu = ...)")
        shipped = shipped_fmu_names(self.fmu_dir)
        for cname, c in comps_doc.items():
            key = ("components", cname)
            if not COMPONENT_NAME.match(cname):
                raise r.fail(key, "a component name is letters, digits and _ (not starting with a digit), parts "
                             "joined by dots for a sub-system's components")
            c = r.table(key, c, COMPONENT_KEYS | {"system"})
            if "system" in c:
                self.add_subsystem(key, cname, c)
                continue
            fmu = c.get("fmu")
            if not isinstance(fmu, str) or not fmu:
                raise r.fail(key + ("fmu",), f"{fmu!r}: expected a shipped FMU's name ({', '.join(shipped)}) or the "
                             "path of an .fmu file")
            if fmu.lower().endswith(".fmu"):
                path = Path(fmu) if Path(fmu).is_absolute() else self.spec_path.parent / fmu
                if not path.is_file():
                    raise r.fail(key + ("fmu",), f"{fmu!r}: no such file ({path})")
            elif fmu in shipped:
                path = self.fmu_dir / f"{fmu}.fmu"
            else:
                raise r.fail(key + ("fmu",), f"{fmu!r}: no shipped FMU of that name{near(fmu, shipped)}; give a path "
                             "ending in .fmu for any other FMU")
            files = [self.parameter_file(key + ("parameter_files",), e)
                     for e in r.strings(key + ("parameter_files",), c.get("parameter_files", []))]
            comp = ComponentSpec(name=cname, fmu=fmu, fmu_path=path, parameter_files=files, parameters={})
            _read_fmu(r, key, comp)
            values = c.get("parameters", {})
            if not isinstance(values, dict):
                raise r.fail(key + ("parameters",), "expected a table of variable = value")
            for var, value in values.items():
                comp.parameters.update(_start_values(r, key + ("parameters", var), comp, var, value))
            self.components[cname] = comp

    def add_subsystem(self, key, cname, c):
        """A system nested as a sub-system (`system = "detumble"`, a shipped system's spec, or the
        path of a spec): its components join this system under dotted names (cname.dynamics, as
        the master names the components of a nested system), with their parameter files, values
        and connections; `parameters = { "dynamics.omega0" = [..] }` changes values inside it.
        Its master settings are not this system's."""
        r = self.r
        if set(c) - {"system", "parameters"}:
            raise r.fail(key, f"a sub-system (system = ...) takes only parameters beside it, not "
                         f"{', '.join(sorted(set(c) - {'system', 'parameters'}))}")
        ref = c["system"]
        if not isinstance(ref, str) or not ref:
            raise r.fail(key + ("system",), f"{ref!r}: expected a shipped system's name or the path of a spec (.toml)")
        if ref.endswith(".toml"):
            path = Path(ref) if Path(ref).is_absolute() else self.spec_path.parent / ref
        else:
            path = self.specs_dir / f"{ref}.toml"
            if not path.is_file():
                known = sorted(p.stem for p in self.specs_dir.glob("*.toml"))
                raise r.fail(key + ("system",), f"{ref!r}: no shipped system of that name{near(ref, known)}; give the "
                             "path of a system spec (ending in .toml)")
        if not path.is_file():
            raise r.fail(key + ("system",), f"{ref!r}: no such file ({path})")
        if path.resolve() in self.within:
            raise r.fail(key + ("system",), f"{ref!r}: the system contains itself")
        sub = _Composer(path, self.fmu_dir, self.parameters_dirs, self.specs_dir, self.within)
        inner = sub.composition()
        if inner.writer_spec.get("parameters") or inner.writer_spec.get("parameter_bindings"):
            raise r.fail(key + ("system",), f"{ref!r} has system parameters or parameter sets bound to the whole "
                         "system, which a sub-system cannot bring yet: give them to its components")
        auto = bool(sub.r.doc.get("connections", {}).get("auto", True))
        for name, comp in inner.components.items():
            # what its spec kept from wiring by name stays so here: its exclusions, and with
            # auto = false the inputs it left unconnected (its outputs feed this system by name)
            self.sealed |= {(f"{cname}.{name}", v.name) for v in comp.variables.values()
                            if (v.causality == "input" and not auto) or
                            (v.causality in ("input", "output") and sub.excluded(name, v.name))}
            comp.name = f"{cname}.{name}"
            files = []
            for stem, source in comp.parameter_files:
                if isinstance(inner.ssv_files.get(stem), tuple):
                    continue  # its values: written again under this system's name
                previous = self.ssv_files.get(stem)
                if previous is not None and Path(previous).resolve() != Path(source).resolve():
                    raise r.fail(key + ("system",), f"{ref!r}: its parameter file {stem}.ssv is another file than "
                                 f"this system's {previous}")
                self.ssv_files[stem] = source
                files.append((stem, source))
            comp.parameter_files = files
            self.components[comp.name] = comp
        for lk in inner.links:
            lk.src, lk.dst = f"{cname}.{lk.src}", f"{cname}.{lk.dst}"
            self.fed[(lk.dst, lk.dst_var)] = f"{lk.src}.{lk.src_var}"
            self.links.append(lk)
        values = c.get("parameters", {})
        if not isinstance(values, dict):
            raise r.fail(key + ("parameters",), "expected a table of \"component.variable\" = value")
        for name, value in values.items():
            comp_name, _, var = name.rpartition(".")
            target = self.components.get(f"{cname}.{comp_name}")
            if target is None or not var:
                raise r.fail(key + ("parameters", name), f"expected \"component.variable\" of a component of {ref!r} "
                             f"({', '.join(inner.components)})")
            target.parameters.update(_start_values(r, key + ("parameters", name), target, var, value))

    def endpoint(self, key, text, causality):
        """'comp.var' -> (component, [variable names]) (a vector name gives its elements); the
        longest component name that prefixes `text` wins (a.b.x: component a.b's x)."""
        r, components = self.r, self.components
        if not isinstance(text, str) or "." not in text:
            raise r.fail(key, f"{text!r}: expected 'component.variable'")
        cname, var = text.split(".", 1)
        for known in sorted(components, key=len, reverse=True):
            if text.startswith(known + "."):
                cname, var = known, text[len(known) + 1:]
                break
        if cname not in components:
            raise r.fail(key, f"{text!r}: unknown component {cname!r}{near(cname, components)} (components: "
                         f"{', '.join(components)})")
        comp = components[cname]
        names = _elements(comp, var)
        if not names:
            candidates = sorted({v.name.split("[", 1)[0] for v in comp.variables.values() if v.causality in causality})
            raise r.fail(key, f"{text!r}: {comp.fmu} has no {' or '.join(causality)} {var!r}{near(var, candidates)}")
        bad = [n for n in names if comp.variables[n].causality not in causality]
        if bad:
            raise r.fail(key, f"{text!r}: {cname}.{bad[0]} is {comp.variables[bad[0]].causality}, expected "
                         f"{' or '.join(causality)}")
        return cname, names

    def system_parameters(self):
        """{name: (description, [(component, parameter)])} and {name: value} of [system_parameters]."""
        r = self.r
        params: Dict[str, Tuple[str, List[Tuple[str, str]]]] = {}
        values: Dict[str, Any] = {}
        doc = r.doc.get("system_parameters") or {}
        if not isinstance(doc, dict):
            raise r.fail(("system_parameters",), "expected [system_parameters.<name>] tables")
        for pname, p in doc.items():
            key = ("system_parameters", pname)
            p = r.table(key, p, SYSTEM_PARAMETER_KEYS)
            targets = []
            for t in r.strings(key + ("to",), p.get("to", [])):
                cname, names = self.endpoint(key + ("to",), t, ("parameter",))
                targets += [(cname, n) for n in names]
            if not targets:
                raise r.fail(key + ("to",), "expected the parameters it sets: to = [\"component.parameter\", ...]")
            params[pname] = (str(p.get("description", pname)), targets)
            if "value" in p:
                cname, var = targets[0]
                values[pname] = _typed(r, key + ("value",), self.components[cname].variables[var], p["value"])
        return params, values

    def read_links(self):
        r = self.r
        conn_doc = r.table(("connections",), r.doc.get("connections", {}), CONNECTION_KEYS)
        raw = conn_doc.get("links", [])
        if not isinstance(raw, list):
            raise r.fail(("connections", "links"), "expected a list of \"a.x -> b.y\" strings or { from, to } tables")
        for k, item in enumerate(raw):
            key = ("connections", "links")
            if isinstance(item, str):
                a, arrow, b = item.partition("->")
                if not arrow:
                    raise r.fail(key, f"{item!r}: expected \"component.output -> component.input\"")
                item = {"from": a.strip(), "to": b.strip()}
            if not isinstance(item, dict):
                raise r.fail(key, f"{item!r}: expected \"a.x -> b.y\" or {{ from = \"a.x\", to = \"b.y\" }}")
            for kk in item:
                if kk not in LINK_KEYS:
                    raise r.fail(key, f"unknown key {kk!r} in a link{near(kk, LINK_KEYS)}; allowed: "
                                 f"{', '.join(sorted(LINK_KEYS))}")
            self.add_link(key + (f"[{k + 1}]",), item, r.line_of_text(str(item.get("from")), *key))

    def add_link(self, where, item, line):
        self.r.at_line = line  # a message about a link names the link's own file:line
        try:
            self._add_link(where, item)
        finally:
            self.r.at_line = None

    def _add_link(self, where, item):
        r = self.r
        src, outs = self.endpoint(where, item.get("from"), ("output",))
        dst, ins = self.endpoint(where, item.get("to"), ("input",))
        if len(outs) != len(ins):
            raise r.fail(where, f"{item['from']} has {len(outs)} element(s), {item['to']} {len(ins)}")
        factor = r.number(where + ("factor",), item["factor"]) if "factor" in item else None
        offset = r.number(where + ("offset",), item["offset"]) if "offset" in item else None
        suppress = item.get("suppress_unit_conversion", False)
        if not isinstance(suppress, bool):
            raise r.fail(where + ("suppress_unit_conversion",), "expected true or false")
        if "from_unit" in item or "to_unit" in item:
            factor, offset = self._unit_conversion(where, item, src, dst, factor, offset)
            suppress = True  # the conversion asked for is the link's whole conversion
        for o, i in zip(outs, ins):
            _check_types(r, where, self.components, src, o, dst, i, factor is not None or offset is not None)
            if (dst, i) in self.fed:
                raise r.fail(where, f"{dst}.{i} is already fed by {self.fed[(dst, i)]}: an input takes one "
                             "connection")
            self.fed[(dst, i)] = f"{src}.{o}"
            self.links.append(LinkSpec(src, o, dst, i, factor, offset, suppress))

    def _unit_conversion(self, where, item, src, dst, factor, offset):
        """(factor, offset) of a link's `from_unit` -> `to_unit` (for FMUs that declare no units,
        or other ones than the values carry): units of our table or of either FMU."""
        r = self.r
        if factor is not None or offset is not None:
            raise r.fail(where, "give from_unit and to_unit, or factor and offset, not both")
        if not isinstance(item.get("from_unit"), str) or not isinstance(item.get("to_unit"), str):
            raise r.fail(where, "from_unit and to_unit go together: the unit the value is in, the unit the input "
                         "takes")
        known = {**BUILTIN, **self.components[dst].unit_defs, **self.components[src].unit_defs}
        units = []
        for key in ("from_unit", "to_unit"):
            if item[key] not in known:
                raise r.fail(where + (key,), f"{item[key]!r}: unknown unit{near(item[key], known)} (units: ours "
                             "and the two FMUs' definitions)")
            units.append(known[item[key]])
        done = conversion(*units)
        if done is None:
            raise r.fail(where, f"{item['from_unit']} ({describe(units[0])}) cannot be converted to {item['to_unit']} "
                         f"({describe(units[1])})")
        return done

    def auto_links(self, targets):
        """Each input not linked, not excluded and not a system parameter's target, fed by the one
        output of another component with its name (several: refused, naming them)."""
        r = self.r
        conn_doc = r.doc.get("connections", {})
        auto = conn_doc.get("auto", True)
        if not isinstance(auto, bool):
            raise r.fail(("connections", "auto"), f"{auto!r}: expected true or false")
        self.exclude = r.strings(("connections", "exclude"), conn_doc.get("exclude", []))
        if not auto:
            return
        excluded = self.excluded

        outputs: Dict[str, List[Tuple[str, Any]]] = {}
        for cname, comp in self.components.items():
            for v in comp.variables.values():
                if v.causality == "output" and not excluded(cname, v.name):
                    outputs.setdefault(v.name, []).append((cname, v))
        for cname, comp in self.components.items():
            for v in comp.variables.values():
                if v.causality != "input" or (cname, v.name) in self.fed or (cname, v.name) in targets \
                        or excluded(cname, v.name):
                    continue
                sources = [s for s, sv in outputs.get(v.name, []) if s != cname and sv.type == v.type]
                if len(sources) > 1:
                    raise SSPError(f"{r.where('connections')}: {cname}.{v.name}: several outputs of that name could "
                                   f"feed it ({', '.join(f'{s}.{v.name}' for s in sources)}); link one in "
                                   "connections.links or exclude the others in connections.exclude")
                if sources:
                    self.fed[(cname, v.name)] = f"{sources[0]}.{v.name}"
                    self.links.append(LinkSpec(sources[0], v.name, cname, v.name, how="name"))

    def excluded(self, cname, var):
        """Whether `cname.var` is left out of wiring by name: this spec's exclusions, and a
        sub-system's inputs and outputs its own spec did not wire (exclusions, auto = false)."""
        if (cname, var) in self.sealed:
            return True
        plain = var.split("[", 1)[0]
        return any(fnmatch.fnmatchcase(f"{cname}.{var}", p) or fnmatch.fnmatchcase(f"{cname}.{plain}", p)
                   for p in self.exclude)

    def master(self):
        """The writer's master settings from [master]."""
        r = self.r
        m = r.table(("master",), r.doc.get("master"), MASTER_KEYS)
        for need in ("step_size", "stop_time"):
            if need not in m:
                raise SSPError(f"{r.where('master')}: [master] needs {need} (seconds)")
        out: Dict[str, Any] = {"step_size": r.number(("master", "step_size"), m["step_size"], positive=True),
                               "stop_time": r.number(("master", "stop_time"), m["stop_time"], positive=True)}
        algorithm = m.get("algorithm", "gauss-seidel")
        if algorithm not in ALGORITHMS:
            raise r.fail(("master", "algorithm"), f"{algorithm!r}: expected one of {', '.join(ALGORITHMS)}"
                         f"{near(str(algorithm), ALGORITHMS)}")
        if algorithm != "gauss-seidel":
            out["algorithm"] = algorithm
        order = r.strings(("master", "order"), m.get("order", []))
        for c in order:
            if c not in self.components:
                raise r.fail(("master", "order"), f"{c!r}: unknown component{near(c, self.components)}")
        missing = [c for c in self.components if c not in order]
        if order and missing:
            raise r.fail(("master", "order"), f"leaves out {', '.join(missing)}: the order lists every component")
        stop_when = []
        for s in r.strings(("master", "stop_when"), m.get("stop_when", [])):
            cname, names = self.endpoint(("master", "stop_when"), s, ("output",))
            if self.components[cname].variables[names[0]].type != "Boolean":
                raise r.fail(("master", "stop_when"), f"{s!r}: a stop condition is a Boolean output")
            stop_when.append((cname, names[0]))
        record = []
        for s in r.strings(("master", "record"), m.get("record", [])):
            cname, names = self.endpoint(("master", "record"), s, ("output", "input", "parameter", "local"))
            record += [f"{cname}.{n}" for n in names]
        for key, value in (("stop", stop_when), ("order", order), ("record", record)):
            if value:
                out[key] = value
        if "schedule" in m:
            out["schedule"] = _schedule(r, m["schedule"], self.components, self.endpoint)
        return out

    def loose_ends(self, targets):
        """(inputs nothing feeds, with their start values; outputs that feed nothing)."""
        unconnected = []
        for cname, comp in self.components.items():
            for v in comp.variables.values():
                if v.causality == "input" and (cname, v.name) not in self.fed and (cname, v.name) not in targets:
                    unit = getattr(v, "unit", None) or ""
                    unconnected.append((cname, v.name, comp.parameters.get(v.name, v.start),
                                        "" if unit == "1" else unit))
        used = {(lk.src, lk.src_var) for lk in self.links}
        unused = [(cname, v.name) for cname, comp in self.components.items() for v in comp.variables.values()
                  if v.causality == "output" and (cname, v.name) not in used]
        return unconnected, unused


def _read_fmu(r, key, comp):
    try:
        md = read_model_description(str(comp.fmu_path), validate=False)
    except Exception as exc:  # fmpy raises several kinds for a file that is not an FMU
        raise r.fail(key + ("fmu",), f"{comp.fmu_path}: not an FMU that can be read ({exc})") from None
    if md.coSimulation is None:
        raise r.fail(key + ("fmu",), f"{comp.fmu_path}: has no co-simulation interface (model exchange only)")
    comp.model_identifier = md.coSimulation.modelIdentifier
    comp.variables = {v.name: v for v in md.modelVariables}
    comp.unit_defs = unit_definitions(md)


def _elements(comp, var):
    """The variable names `var` stands for: itself, or its elements var[1], var[2], ..."""
    if var in comp.variables:
        return [var]
    names = []
    while f"{var}[{len(names) + 1}]" in comp.variables:
        names.append(f"{var}[{len(names) + 1}]")
    return names


def _typed(r, key, v, value):
    """`value` in the type of FMU variable `v` (an int for a Real becomes a float)."""
    t = v.type
    ok = {"Real": lambda x: isinstance(x, (int, float)) and not isinstance(x, bool),
          "Integer": lambda x: isinstance(x, int) and not isinstance(x, bool),
          "Enumeration": lambda x: isinstance(x, int) and not isinstance(x, bool),
          "Boolean": lambda x: isinstance(x, bool),
          "String": lambda x: isinstance(x, str)}.get(t)
    if ok is None or not ok(value):
        raise r.fail(key, f"{value!r}: {v.name} is {t}, expected a value of that type")
    return float(value) if t == "Real" else value


def _start_values(r, key, comp, var, value):
    names = _elements(comp, var)
    if not names:
        candidates = [v.name.split("[", 1)[0] for v in comp.variables.values() if v.causality in STARTABLE]
        raise r.fail(key, f"{comp.fmu} has no parameter or input {var!r}{near(var, sorted(set(candidates)))}")
    values = value if isinstance(value, list) else [value]
    if len(names) != len(values) or (len(names) > 1 and not isinstance(value, list)):
        raise r.fail(key, f"{var} has {len(names)} element(s), the spec gives {len(values)}")
    out = {}
    for n, x in zip(names, values):
        v = comp.variables[n]
        if v.causality not in STARTABLE or v.variability == "constant":
            raise r.fail(key, f"{n} is {v.variability} {v.causality}: only parameters and inputs take a value")
        out[n] = _typed(r, key, v, x)
    return out


def _check_types(r, key, components, src, o, dst, i, transformed):
    a, b = components[src].variables[o], components[dst].variables[i]
    if a.type != b.type and {a.type, b.type} != {"Integer", "Enumeration"}:
        raise r.fail(key, f"{src}.{o} is {a.type}, {dst}.{i} is {b.type}: a connection joins one type")
    if transformed and a.type != "Real":
        raise r.fail(key, f"{src}.{o} is {a.type}: factor and offset apply to Real connections")


def _transform(lk):
    if lk.factor is None and lk.offset is None and not lk.suppress:
        return None
    return {"factor": 1.0 if lk.factor is None else lk.factor, "offset": 0.0 if lk.offset is None else lk.offset,
            "suppress": lk.suppress, "linear": lk.factor is not None or lk.offset is not None}


def _resource_names(components):
    """resources/<name>.fmu for each component: a shipped FMU's own name, another FMU's model
    identifier (made unique when two different files share one)."""
    taken: Dict[str, Path] = {}
    out = {}
    for cname, comp in components.items():
        base = comp.model_identifier if comp.fmu.lower().endswith(".fmu") else comp.fmu
        base = re.sub(r"[^A-Za-z0-9_]", "_", base) or "fmu"
        stem, k = base, 1
        while stem in taken and taken[stem].resolve() != comp.fmu_path.resolve():
            k += 1
            stem = f"{base}_{k}"
        taken[stem] = comp.fmu_path
        out[cname] = stem
    return out


def _schedule(r, s, components, endpoint):
    key = ("master", "schedule")
    s = r.table(key, s, SCHEDULE_KEYS)
    modes_doc = s.get("mode")
    if not isinstance(modes_doc, list) or not modes_doc:
        raise r.fail(key, "expected [[master.schedule.mode]] tables (name, step_size, when, ...)")
    modes = []
    for k, md in enumerate(modes_doc):
        mkey = key + ("mode", str(k))
        md = r.table(mkey, md, MODE_KEYS)
        name = md.get("name")
        if not isinstance(name, str) or not name:
            raise r.fail(mkey + ("name",), "a mode needs a name")
        step = r.number(mkey + ("step_size",), md.get("step_size"), positive=True)
        active = md.get("active")
        if active is not None:
            active = tuple(r.strings(mkey + ("active",), active))
            for c in active:
                if c not in components:
                    raise r.fail(mkey + ("active",), f"{c!r}: unknown component{near(c, components)}")
        every_doc = md.get("every", {})
        if not isinstance(every_doc, dict):
            raise r.fail(mkey + ("every",), "expected a table component = k")
        every = {}
        for c, n in every_doc.items():
            if c not in components:
                raise r.fail(mkey + ("every",), f"{c!r}: unknown component{near(c, components)}")
            if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                raise r.fail(mkey + ("every", c), f"{n!r}: expected an integer >= 1")
            every[c] = n
        record_every = md.get("record_every", 1)
        if isinstance(record_every, bool) or not isinstance(record_every, int) or record_every < 1:
            raise r.fail(mkey + ("record_every",), f"{record_every!r}: expected an integer >= 1")
        when_doc = md.get("when", {})
        if not isinstance(when_doc, dict):
            raise r.fail(mkey + ("when",), "expected a table \"component.signal\" = [values]")
        conditions = []
        for signal, values in when_doc.items():
            cname, names = endpoint(mkey + ("when",), signal, ("output", "parameter", "input", "local"))
            values = values if isinstance(values, list) else [values]
            if not values or not all(isinstance(x, (int, bool)) for x in values):
                raise r.fail(mkey + ("when", signal), f"{values!r}: expected integers or true/false")
            conditions.append(When(cname, names[0], tuple(int(x) for x in values)))
        if not conditions and k != len(modes_doc) - 1:
            raise r.fail(mkey + ("when",), f"mode {name!r} has no condition, so it always matches: only the last "
                         "mode may have none")
        modes.append(ScheduleMode(name, step, active, record_every, tuple(conditions), every))
    events = []
    for e in r.strings(key + ("events",), s.get("events", [])):
        cname, names = endpoint(key + ("events",), e, ("output",))
        events.append((cname, names[0]))
    return Schedule(modes=tuple(modes), events=tuple(events))
