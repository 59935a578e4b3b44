"""The builder: every FMU under fmus/ and every system under system_ssp/systems/, built into the
build folder (system_ssp.locations: build/ in a checkout, else the user's data folder).

    neighbor-cosim build [--clean] [--check] [--compat]   # python build_fmus.py in a checkout

FMUs: each `fmus/neighbor_*.py` wrapper becomes `<build>/fmus/<ClassName>.fmu`:
- modelDescription.xml: pythonfmu's, from the wrapper's declarations, completed here from what
  pythonfmu cannot write (`NeighborSlave.fmu_meta`): `unit` on every Real that has one, with
  `UnitDefinitions` in SI base-unit exponents; `ModelStructure/Outputs` with each output's real
  `dependencies` and `InitialUnknowns`; `canGetAndSetFMUstate` where the wrapper captures the
  model's full state. The GUID is derived from the product version and the code, so the same
  code of the same version gives the same FMU; `version` is the product's.
- binaries/<platform>/<ClassName>.so|.dll: the runtime (fmus/runtime/neighbor_fmi2.c on
  neighbor_core.c), compiled here with gcc (linux64) and, when it is installed, mingw-w64 (win64).
- resources/neighbor_runtime.py and .txt: the loader the binary runs and what it needs to know
  (the model's class, the GUID, the Python the FMU was built with).
- resources/nc_<name>_<digest>/: the model's code, as one package whose name is private to this
  build: the wrapper, the support modules it uses, exactly the modules of components/ it
  imports (computed from the import statements), their PACKAGE_DATA files, and pythonfmu's
  authoring classes. The target needs Python and numpy only (docs/interoperability.md).
A built FMU must pass `fmpy.validation.validate_fmu` or the build fails. Each wrapper is also
built as an FMI 3.0 co-simulation FMU, `<build>/fmus3/<ClassName>.fmu`: its model description
written from the completed FMI 2.0 one (system_ssp.fmi3_description: arrays with dimensions),
the FMI 3.0 binary (neighbor_fmi3.c on the same core, binaries/x86_64-linux|x86_64-windows/),
its own instantiation token and private package (nc3_...).

SSPs: each `system_ssp/systems/<name>.ssd` becomes `<build>/ssp/<name>.ssp` (and, with the FMI
3.0 FMUs, `<build>/ssp3/<name>.ssp`) with the SSD as
SystemStructure.ssd (a component's several parameter bindings merged into one, which libcosim
needs), every .ssv/.ssm it references, the scenario parameter sets named
`parameters/<name>_*.ssv`, and the FMUs its components use under resources/.

Only what changed is rebuilt: an FMU is rebuilt when its wrapper, a support module, the runtime,
anything in components/ or this module changes; an SSP when its SSD, parameter files or FMUs
change. Outputs are written to a temporary file and renamed, so an interrupted build never
leaves a truncated FMU or SSP behind; two processes building into one folder take turns.
"""
import ast
from contextlib import contextmanager
import fcntl
import hashlib
import importlib
import inspect
import json
import os
from pathlib import Path
import re
import shutil
import site
import subprocess
import sys
import sysconfig
import uuid
from xml.etree import ElementTree as ET
import zipfile

import fmpy
from fmpy.validation import validate_fmu
from lxml import etree
import pythonfmu

from .atomic import atomic_write, write_text_atomic
from .errors import SSPError
from . import fmi3_description
from .fmi3_description import fmi3_model_description
from .locations import BUILD, COMPONENTS, FMU_SOURCES, ROOT, SYSTEM_SOURCES as SYSTEMS, system_names
from .ssp.reader import NS_SSD, NS_SSV
from .ssp.units import BUILTIN, base_unit_attributes
from .version import __version__

RUNTIME = FMU_SOURCES / "runtime"
STATE_FILE = BUILD / "build-state.json"


class BuildError(RuntimeError):
    pass


def _shown(path):
    """A path as the digests and messages name it: relative to the sources or the build folder."""
    for base in (ROOT, BUILD):
        if path.is_relative_to(base):
            return path.relative_to(base).as_posix()
    return str(path)


def _digest(paths):
    h = hashlib.sha256()
    for p in sorted(paths):
        h.update(_shown(p).encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def _component_files():
    """Everything bundled from components/ (code and package data such as space-weather tables)."""
    return [p for p in COMPONENTS.rglob("*") if p.is_file() and "__pycache__" not in p.parts]


def wrapper_scripts():
    """fmus/neighbor_*.py, but the support modules (neighbor_*_support.py)."""
    return sorted(p for p in FMU_SOURCES.glob("neighbor_*.py") if not p.stem.endswith("_support"))


def _import_wrapper(script):
    for path in (str(ROOT), str(script.parent)):
        if path not in sys.path:
            sys.path.insert(0, path)
    module = sys.modules.get(script.stem)
    # a process that builds again (a test session) must declare what the file says now, not
    # what it said at the first import: the bundled code is read from disk
    module = importlib.import_module(script.stem) if module is None else importlib.reload(module)
    from neighbor_fmu_support import NeighborSlave

    NeighborSlave.version = __version__  # the modelDescription's version: the product's
    classes = [c for _, c in inspect.getmembers(module, inspect.isclass)
               if issubclass(c, NeighborSlave) and c is not NeighborSlave and c.__module__ == module.__name__]
    if len(classes) != 1:
        raise BuildError(f"{script}: expected exactly one NeighborSlave subclass, found {len(classes)}")
    return classes[0]


def _unit_definitions(units_used):
    defs = ET.Element("UnitDefinitions")
    for name in sorted(units_used):
        if name not in BUILTIN:
            raise BuildError(f"unit {name!r} has no SI definition in system_ssp.ssp.units.BUILTIN")
        unit = ET.SubElement(defs, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", {k: str(v) for k, v in base_unit_attributes(BUILTIN[name]).items()})
    return defs


def complete_model_description(xml_bytes, meta, can_get_set_state, starts):
    """Add units, UnitDefinitions, output dependencies and InitialUnknowns; write Real start
    values with full precision (pythonfmu rounds them to 15 digits)."""
    root = ET.fromstring(xml_bytes)
    cosim = root.find("CoSimulation")
    cosim.set("canGetAndSetFMUstate", "true" if can_get_set_state else "false")
    variables = root.find("ModelVariables").findall("ScalarVariable")
    index = {v.get("name"): i + 1 for i, v in enumerate(variables)}
    if set(index) != set(meta):
        raise BuildError(f"declared variables and model description differ: {sorted(set(index) ^ set(meta))}")
    units_used = set()
    parameters = []
    for v in variables:
        info = meta[v.get("name")]
        if v.get("causality") == "parameter":
            parameters.append(index[v.get("name")])
        real = v.find("Real")
        if real is not None and real.get("start") is not None:
            real.set("start", repr(float(starts[v.get("name")])))
        if real is not None and info["unit"]:
            real.set("unit", info["unit"])
            units_used.add(info["unit"])
    if units_used:
        pos = list(root).index(cosim) + 1
        root.insert(pos, _unit_definitions(units_used))

    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    outputs = [v for v in variables if v.get("causality") == "output"]
    if outputs:
        out_el = ET.SubElement(structure, "Outputs")
        init_el = ET.SubElement(structure, "InitialUnknowns")
        for v in outputs:
            deps = []
            for name in meta[v.get("name")]["depends_on"]:
                if name not in index or meta[name]["causality"] != "input":
                    raise BuildError(f"output {v.get('name')} depends on {name!r}, which is not an input")
                deps.append(index[name])
            deps = sorted(deps)
            ET.SubElement(out_el, "Unknown", index=str(index[v.get("name")]),
                          dependencies=" ".join(map(str, deps)))
            ET.SubElement(init_el, "Unknown", index=str(index[v.get("name")]),
                          dependencies=" ".join(map(str, sorted(deps + parameters))))
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8")


def write_zip(dest, entries):
    """Write {archive name: bytes} as a zip through a temporary file. Fixed dates, so that the same
    inputs give the same archive, and normal permissions: 0644, 0755 for binaries."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(dest, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as zf:
        for name in sorted(entries):
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = (0o755 if name.startswith("binaries/") else 0o644) << 16
            zf.writestr(info, entries[name])


# ---- the FMU runtime: one C binary for every FMU, the Python loader, the model's own package -----
RUNTIME_C = {2: RUNTIME / "neighbor_fmi2.c", 3: RUNTIME / "neighbor_fmi3.c"}  # the entry points per standard
RUNTIME_CORE = RUNTIME / "neighbor_core.c"  # what both share (included by each)
RUNTIME_LOADER = RUNTIME / "neighbor_runtime.py"
PLATFORMS = {  # FMI platform folder: (compiler, file suffix, extra flags)
    "linux64": ("gcc", ".so", ["-fPIC", "-fvisibility=hidden", "-pthread", "-ldl"]),
    "win64": ("x86_64-w64-mingw32-gcc", ".dll", ["-static-libgcc"]),
}
FMI3_PLATFORMS = {"linux64": "x86_64-linux", "win64": "x86_64-windows"}  # FMI 3.0's platform tuples
_compiled: dict = {}  # {runtime digest: {platform: binary path}}


def compile_runtime(out_dir=None, fmi_version=2):
    """{platform: path} of the runtime binary of FMI `fmi_version` (2 or 3) compiled for every
    platform whose compiler is on this machine (linux64 always: gcc is required; win64 with
    mingw-w64). Compiled once per source version (build/runtime/<digest>/)."""
    source = RUNTIME_C[fmi_version]
    digest = _digest([source, RUNTIME_CORE])[:16]
    if digest in _compiled:
        return _compiled[digest]
    out_dir = Path(out_dir or BUILD / "runtime" / digest)
    headers = Path(fmpy.__file__).parent / "c-code"  # the FMI 2.0 and 3.0 headers FMPy ships (BSD-2)
    out = {}
    for platform, (cc, suffix, flags) in PLATFORMS.items():
        target = out_dir / f"{source.stem}{suffix}"
        if not target.is_file():
            if shutil.which(cc) is None:
                if platform == "linux64":
                    raise BuildError(f"the FMU runtime needs a C compiler: {cc} not found")
                continue
            out_dir.mkdir(parents=True, exist_ok=True)
            # a name of this process's own: two processes (pytest-xdist's workers, two commands) may
            # compile the same runtime at once, and each replaces the target whole
            tmp = target.with_name(f"{target.name}.{os.getpid()}.tmp")
            cmd = [cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-shared", f"-I{headers}", str(source),
                   "-o", str(tmp), *flags]
            proc = subprocess.run(cmd, capture_output=True, text=True)
            if proc.returncode != 0:
                raise BuildError(f"compiling the FMU runtime for {platform} failed:\n{' '.join(cmd)}\n{proc.stderr}")
            os.replace(tmp, target)
        out[platform] = target
    _compiled[digest] = out
    return out


_ROOTS = {"components": ROOT, "pythonfmu": Path(pythonfmu.__file__).parents[1]}


def _root_of(top):
    """Where the top-level name `top` is found for bundling: components, pythonfmu, or a module of
    fmus/ (the support modules); None for everything else (numpy and the standard library come
    from the target's Python)."""
    if top in _ROOTS:
        return _ROOTS[top]
    return FMU_SOURCES if top.startswith("neighbor_") and (FMU_SOURCES / f"{top}.py").is_file() else None


def _source_of(dotted):
    """The file of a module or package to bundle, or None."""
    root = _root_of(dotted.split(".")[0])
    if root is None:
        return None
    base = root.joinpath(*dotted.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _imports(path, dotted, is_package):
    """Absolute names of the modules `path` imports (anywhere, functions included)."""
    tree = ast.parse(path.read_bytes(), str(path))
    package = dotted if is_package else dotted.rpartition(".")[0]
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module
            names.append(module)
            names += [f"{module}.{a.name}" for a in node.names]
    return names


def bundle(script):
    """The modules the wrapper `script` imports (computed from the import statements, transitively,
    parent packages included) and the data files they declare (`PACKAGE_DATA`, paths relative to
    the module), as {path inside the private package: bytes}; pythonfmu's __init__ (which imports
    its builder) is replaced by an empty one. The wrapper's and the support module's absolute
    imports become relative: the bundle is importable under any package name."""
    wrapper = script.stem
    found = {wrapper: script}
    todo = [wrapper]
    while todo:
        name = todo.pop()
        path = found[name]
        parts = name.split(".")
        for i in range(1, len(parts)):  # importing a.b.c runs a/__init__ and a/b/__init__ first
            parent = ".".join(parts[:i])
            if parent not in found and _source_of(parent) is not None:
                found[parent] = _source_of(parent)
                todo.append(parent)
        if name == "pythonfmu":
            continue  # replaced below: its own __init__ would pull in the builder
        for imported in _imports(path, name, path.name == "__init__.py"):
            if imported not in found and _source_of(imported) is not None:
                found[imported] = _source_of(imported)
                todo.append(imported)
    files = {}
    for name, path in found.items():
        rel = Path(*name.split("."))
        rel = rel / "__init__.py" if path.name == "__init__.py" else rel.with_suffix(".py")
        text = path.read_text(encoding="utf-8")
        if name == "pythonfmu":
            text = '"""pythonfmu\'s authoring API (fmi2slave, enums, variables), bundled."""\n'
        elif "." not in name:  # the wrapper and the support modules: top level of the package
            text = _relative_imports(text, path)
        elif _absolute_project_imports(text, path):
            raise BuildError(f"{path}: bundled modules import each other relatively; found "
                             + ", ".join(_absolute_project_imports(text, path)))
        files[rel.as_posix()] = text.encode("utf-8")
        module_dir = path.parent
        for data in _package_data(path):
            source = module_dir / data
            if not source.is_file():
                raise BuildError(f"{path}: PACKAGE_DATA names {data!r}, which does not exist")
            files[(rel.parent / data).as_posix()] = source.read_bytes()
    return files


def _absolute_project_imports(text, path):
    tree = ast.parse(text, str(path))
    return [node.module for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module
            and _root_of(node.module.split(".")[0]) is not None]


def _relative_imports(text, path):
    """`from components...`, `from neighbor_fmu_support ...`, `from pythonfmu...` -> `from .X`."""
    lines = text.splitlines(keepends=True)
    tree = ast.parse(text, str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(_root_of(a.name.split(".")[0]) for a in node.names):
            raise BuildError(f"{path}:{node.lineno}: use `from X import ...` for the project's modules")
        if isinstance(node, ast.ImportFrom) and node.level == 0 and _root_of(node.module.split(".")[0]):
            line = lines[node.lineno - 1]
            start = node.col_offset
            if not line[start:].startswith(f"from {node.module}"):
                raise BuildError(f"{path}:{node.lineno}: cannot rewrite this import")
            lines[node.lineno - 1] = line[:start] + "from ." + line[start + 5:]
    return "".join(lines)


def _package_data(path):
    """The module's PACKAGE_DATA tuple of relative file names, read without importing it."""
    tree = ast.parse(path.read_bytes(), str(path))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "PACKAGE_DATA"
                                                 for t in node.targets):
            return list(ast.literal_eval(node.value))
    return []


def _runtime_config(package, wrapper, cls, guid, fmi3=None):
    """resources/neighbor_runtime.txt: the model's class, its GUID, where the Python the FMU
    was built with lives (a Python-less host starts that one when it exists; see docs), and for
    FMI 3.0 the arrays (value reference:elements) the loader expands and time's value reference."""
    libdir, soname = sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("INSTSONAME")
    libpython = Path(libdir or "", soname or "")
    lines = [f"slave={package} {wrapper} {cls.__name__}", f"guid={guid}",
             f"python_version={sys.version_info[0]}.{sys.version_info[1]}"]
    if libpython.is_file():
        lines += [f"libpython={libpython}", f"python_home={sys.base_prefix}"]
    for folder in dict.fromkeys(site.getsitepackages() + [site.getusersitepackages()]):
        if Path(folder).is_dir():
            lines.append(f"site_packages={folder}")
    if fmi3 is not None:
        arrays, time_vr = fmi3
        lines += ["arrays=" + " ".join(f"{vr}:{n}" for vr, n in sorted(arrays.items())), f"time={time_vr}"]
    return ("\n".join(lines) + "\n").encode("utf-8")


def build_fmu(script, dest_dir, fmi_version=2):
    """Build one wrapper script into `<dest_dir>/<ClassName>.fmu` as an FMI `fmi_version` (2 or 3)
    co-simulation FMU: the model description from pythonfmu's declarations, completed (for 3.0
    written from the completed 2.0 one: system_ssp.fmi3_description); the runtime binary per
    platform; the loader; the model's own modules under a package name private to this build
    (the two standards' builds of one wrapper have different names and tokens: they share
    nothing in a process). Returns the FMU path; raises BuildError if fmpy finds a problem."""
    script = Path(script).resolve()
    dest_dir = Path(dest_dir)
    cls = _import_wrapper(script)
    instance = cls(instance_name="build", resources=str(script.parent))
    files = bundle(script)
    code_digest = hashlib.sha256(b"".join(name.encode() + b"\0" + data for name, data in sorted(files.items())))
    code_digest.update(RUNTIME_LOADER.read_bytes())
    prefix = "nc" if fmi_version == 2 else "nc3"
    package = f"{prefix}_{cls.__name__.lower()}_{code_digest.hexdigest()[:12]}"
    files["__init__.py"] = f'"""{cls.__name__}: this FMU build\'s private package."""\n'.encode()
    guid = str(uuid.uuid5(uuid.NAMESPACE_URL, f"https://neighbor-cosim.org/fmu/{__version__}/{package}"))
    instance.guid = guid
    options = {"needsExecutionTool": "false", "canGetAndSetFMUstate": cls.can_get_and_set_state}
    xml = ET.tostring(instance.to_xml(options), encoding="utf-8")
    description = complete_model_description(xml, instance.fmu_meta, cls.can_get_and_set_state,
                                              instance.variable_values())
    fmi3 = None
    if fmi_version == 3:
        guid = "{" + guid + "}"
        description, arrays, time_vr = fmi3_model_description(description, guid, cls.can_get_and_set_state)
        fmi3 = (arrays, time_vr)
    entries = {"modelDescription.xml": description,
               "resources/neighbor_runtime.py": RUNTIME_LOADER.read_bytes(),
               "resources/neighbor_runtime.txt": _runtime_config(package, script.stem, cls, guid, fmi3)}
    for name, data in files.items():
        entries[f"resources/{package}/{name}"] = data
    for platform, binary in compile_runtime(fmi_version=fmi_version).items():
        entries[f"binaries/{FMI3_PLATFORMS[platform] if fmi_version == 3 else platform}/"
                f"{cls.__name__}{binary.suffix}"] = binary.read_bytes()
    dest = dest_dir / f"{cls.__name__}.fmu"
    write_zip(dest, entries)
    problems = validate_fmu(str(dest))
    if problems:
        dest.unlink()
        raise BuildError(f"{dest.name} fails fmpy validation: " + "; ".join(problems))
    return dest


def _system_files(ssd):
    """Files an SSD brings into its .ssp: referenced .ssv/.ssm and parameters/<name>_*.ssv."""
    tree = ET.parse(ssd)
    refs = set()
    fmus = []
    for el in tree.iter():
        tag = el.tag.split("}")[-1]
        if tag == "Component":
            source = el.get("source", "")
            m = re.fullmatch(r"resources/([A-Za-z0-9_]+\.fmu)", source)
            if not m:
                raise BuildError(f"{ssd.name}: component {el.get('name')} source {source!r} must be "
                                 "resources/<Name>.fmu")
            fmus.append(m.group(1))
        elif tag in ("ParameterBinding", "ParameterMapping") and el.get("source"):
            refs.add(el.get("source"))
    for p in (ssd.parent / "parameters").glob(f"{ssd.stem}_*.ssv"):
        refs.add(str(p.relative_to(ssd.parent)))
    missing = [r for r in refs if not (ssd.parent / r).is_file()]
    if missing:
        raise BuildError(f"{ssd.name} references missing files: {', '.join(sorted(missing))}")
    return sorted(refs), sorted(set(fmus))


def merged_bindings(ssd_bytes, base_dir):
    """libcosim (and other readers) apply only a component's first ParameterBinding. A component
    that binds several parameter sets (one per concern) gets one set instead, their values merged
    in binding order (a later file wins, as the SSP standard and our master apply them), under
    parameters/merged/<system>.<component>.ssv. Returns (SSD bytes, {archive name: bytes})."""
    tree = etree.fromstring(ssd_bytes)
    ns = {"ssd": NS_SSD, "ssv": NS_SSV}
    system = tree.get("name")
    extra = {}
    for comp in tree.iterfind(".//ssd:Component", ns):
        bindings = comp.find("ssd:ParameterBindings", ns)
        items = [] if bindings is None else bindings.findall("ssd:ParameterBinding", ns)
        if len(items) < 2:
            continue
        if any(b.get("source") is None or b.get("prefix") or len(b) for b in items):
            raise BuildError(f"{system}: component {comp.get('name')}: only plain file bindings can be merged")
        merged, units = {}, {}
        for b in items:
            ssv = etree.parse(str(base_dir / b.get("source"))).getroot()
            for unit in ssv.iterfind("ssv:Units/*", ns):
                units[unit.get("name")] = unit
            for par in ssv.iterfind("ssv:Parameters/ssv:Parameter", ns):
                merged[par.get("name")] = par
        root = etree.Element(f"{{{NS_SSV}}}ParameterSet", nsmap={"ssv": NS_SSV}, version="1.0",
                             name=f"{system}.{comp.get('name')}")
        root.append(etree.Comment(" merged from " + ", ".join(b.get("source") for b in items)
                                  + " (later files win) "))
        if units:
            holder = etree.SubElement(root, f"{{{NS_SSV}}}Units")
            holder.extend(units.values())
        params = etree.SubElement(root, f"{{{NS_SSV}}}Parameters")
        params.extend(merged.values())
        name = f"parameters/merged/{system}.{comp.get('name')}.ssv"
        extra[name] = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
        for b in items[1:]:
            bindings.remove(b)
        items[0].set("source", name)
    return etree.tostring(tree, xml_declaration=True, encoding="UTF-8"), extra


def pack_ssp(ssd, fmu_dir, dest_dir):
    """build/ssp/<name>.ssp: the SSD as SystemStructure.ssd (bindings merged per component), the
    parameter files it and its scenarios use, and its FMUs under resources/."""
    refs, fmus = _system_files(ssd)
    missing = [f for f in fmus if not (fmu_dir / f).is_file()]
    if missing:
        raise BuildError(f"{ssd.name} uses FMUs that were not built: {', '.join(missing)}")
    dest = Path(dest_dir) / f"{ssd.stem}.ssp"
    text, merged = merged_bindings(ssd.read_bytes(), ssd.parent)
    entries = {"SystemStructure.ssd": text, **merged}
    for ref in refs:
        entries[ref] = (ssd.parent / ref).read_bytes()
    for f in fmus:
        entries[f"resources/{f}"] = (fmu_dir / f).read_bytes()
    write_zip(dest, entries)
    return dest


def _load_state():
    try:
        return json.loads(STATE_FILE.read_text())
    except (OSError, ValueError):
        return {}


def _save_state(state):
    STATE_FILE.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(STATE_FILE, json.dumps(state, indent=1, sort_keys=True))


def build_all(clean=False, verbose=True):
    """Build what changed; returns (fmu paths, ssp paths). Two processes building at once (two
    commands that each found the systems missing) take turns on a lock in the build folder."""
    BUILD.mkdir(parents=True, exist_ok=True)
    with _build_lock():
        return _build_all(clean, verbose)


@contextmanager
def _build_lock():
    with open(BUILD / ".build.lock", "a+") as lock:
        fcntl.flock(lock.fileno(), fcntl.LOCK_EX)
        yield


def _build_all(clean, verbose):
    state = {} if clean else _load_state()

    def refresh(key, digest, target, make, verb):
        """`target` if its inputs' digest is unchanged, else the result of `make()`."""
        if state.get(key) == digest and target.is_file():
            return target
        if verbose:
            print(f"{verb} {_shown(target)}", flush=True)
        made = make()
        state[key] = digest
        _save_state(state)
        return made

    shared = _component_files() + sorted(FMU_SOURCES.glob("neighbor_*_support.py")) + [
        *RUNTIME_C.values(), RUNTIME_CORE, RUNTIME_LOADER, Path(__file__).resolve()]
    fmi3_inputs = [Path(fmi3_description.__file__)]
    scripts = []
    names = {}
    for script in wrapper_scripts():
        cls = _import_wrapper(script)
        if cls.__name__ in names:
            raise BuildError(f"{script.name} and {names[cls.__name__]} both define FMU {cls.__name__}")
        names[cls.__name__] = script.name
        scripts.append((script, cls.__name__))
    built = {}
    # FMI 2.0 in fmus/ and ssp/ (the product's systems), the same FMUs as FMI 3.0 in fmus3/ and
    # the same systems packed with them in ssp3/
    for version, fmu_dir, ssp_dir, key in ((2, BUILD / "fmus", BUILD / "ssp", ""),
                                           (3, BUILD / "fmus3", BUILD / "ssp3", "3")):
        inputs_of_version = shared + (fmi3_inputs if version == 3 else [])
        fmus = [refresh(f"fmu{key}:{name}", _digest(inputs_of_version + [script]), fmu_dir / f"{name}.fmu",
                        lambda script=script, fmu_dir=fmu_dir, version=version: build_fmu(script, fmu_dir, version),
                        "building") for script, name in scripts]
        ssps = []
        for ssd in sorted(SYSTEMS.glob("*.ssd")):
            refs, used = _system_files(ssd)
            inputs = [ssd] + [ssd.parent / r for r in refs] + [fmu_dir / f for f in used if (fmu_dir / f).is_file()]
            ssps.append(refresh(f"ssp{key}:{ssd.stem}", _digest(inputs), ssp_dir / f"{ssd.stem}.ssp",
                                lambda ssd=ssd, fmu_dir=fmu_dir, ssp_dir=ssp_dir: pack_ssp(ssd, fmu_dir, ssp_dir),
                                "packing"))
        built[version] = (fmus, ssps)
    return built[2]


def resolve_system(name):
    """The file of a system named by the user: the path as given when it exists; a bare name (no
    folder, no suffix) of a shipped system, <build>/ssp/<name>.ssp. A shipped system's packed file
    in the build folder that is missing is built first, with one line on stderr: a wheel
    installed without a build builds them on the first command that needs them, once per version.
    Anything else missing: SSPError (for a bare name, listing the systems there are)."""
    path = Path(name)
    if path.exists():
        return path
    bare = bool(name) and not path.suffix and "/" not in str(name) and os.sep not in str(name)
    if bare:
        if str(name) not in system_names():
            raise SSPError(f"{name}: no such file, and no system of that name (systems: {', '.join(system_names())})")
        path = BUILD / "ssp" / f"{name}.ssp"
        if path.is_file():
            return path
    elif (path.suffix != ".ssp" or path.stem not in system_names()
          or path.parent.resolve() not in ((BUILD / "ssp").resolve(), (BUILD / "ssp3").resolve())):
        raise SSPError(f"{path}: file not found")
    build_on_first_use()
    return path


def build_on_first_use():
    """Build every FMU and system into the build folder, with one line on stderr: what the first
    command that needs them does on an installed wheel. SSPError when the build fails."""
    print(f"neighbor-cosim: the FMUs and systems are not built yet; building them into {BUILD} "
          "(once per version, under a minute; `neighbor-cosim build` does it ahead)", file=sys.stderr, flush=True)
    try:
        build_all(verbose=False)
    except (BuildError, OSError) as exc:
        raise SSPError(f"building the systems into {BUILD} failed: {build_failure(exc)}") from None


def build_failure(exc):
    """A build failure in words; a folder it cannot write says how to choose another."""
    if isinstance(exc, OSError):
        return (f"{exc.filename or BUILD}: {exc.strerror or exc} (NEIGHBOR_COSIM_BUILD=DIR builds into another "
                "folder)")
    return str(exc)
