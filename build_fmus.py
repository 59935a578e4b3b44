"""Build every FMU under fmus/ and pack every system under system_ssp/systems/.

    python build_fmus.py            # rebuild what changed
    python build_fmus.py --clean    # rebuild everything
    python build_fmus.py --check    # also run fmpy's validation on every FMU

FMUs: each `fmus/neighbor_*.py` wrapper becomes `build/fmus/<ClassName>.fmu`, built with
pythonfmu and bundling `components/` and `fmus/neighbor_fmu_support.py`, so an FMU needs
only the Python interpreter and the third-party packages (numpy, scipy). pythonfmu writes no
units, no output dependencies and no InitialUnknowns, so the model description is completed
here from what the wrapper declared (`NeighborSlave.fmu_meta`):
- `unit` on every Real that has one, with `UnitDefinitions` in SI base-unit exponents;
- `ModelStructure/Outputs` with each output's real `dependencies` (inputs it reads
  directly; a stateful output depends on none) and `InitialUnknowns` for every output,
  depending on those inputs and on the parameters;
- `canGetAndSetFMUstate` where the wrapper captures the model's full state.
A built FMU must pass `fmpy.validation.validate_fmu` or the build fails.

SSPs: each `system_ssp/systems/<name>.ssd` becomes `build/ssp/<name>.ssp` with the SSD as
SystemStructure.ssd, every .ssv/.ssm it references, the scenario parameter sets named
`parameters/<name>_*.ssv`, and the FMUs its components use under resources/.

Only what changed is rebuilt: an FMU is rebuilt when its wrapper, the support module,
anything in components/ or this script changes; an SSP when its SSD, parameter files or FMUs
change. Outputs are written to a temporary file and renamed, so an interrupted build never
leaves a truncated FMU or SSP behind.
"""
import argparse
import hashlib
import importlib
import inspect
import json
import re
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from system_ssp import __version__
from system_ssp.atomic import atomic_write, write_text_atomic
from system_ssp.ssp.units import BUILTIN, base_unit_attributes

ROOT = Path(__file__).resolve().parent
FMU_SOURCES = ROOT / "fmus"
SUPPORT = FMU_SOURCES / "neighbor_fmu_support.py"
COMPONENTS = ROOT / "components"
SYSTEMS = ROOT / "system_ssp" / "systems"
BUILD = ROOT / "build"
STATE_FILE = BUILD / "build-state.json"


class BuildError(RuntimeError):
    pass


def _digest(paths):
    h = hashlib.sha256()
    for p in sorted(paths):
        h.update(str(p.relative_to(ROOT)).encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def _component_files():
    """Everything bundled from components/ (code and package data such as space-weather tables)."""
    return [p for p in COMPONENTS.rglob("*") if p.is_file() and "__pycache__" not in p.parts]


def wrapper_scripts():
    return sorted(p for p in FMU_SOURCES.glob("neighbor_*.py") if p != SUPPORT)


def _import_wrapper(script):
    for path in (str(ROOT), str(script.parent)):
        if path not in sys.path:
            sys.path.insert(0, path)
    module = importlib.import_module(script.stem)
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


def _atomic_zip(dest, write_entries):
    dest.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(dest, "wb") as f, zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as zf:
        write_entries(zf)


def build_fmu(script, dest_dir):
    """Build one wrapper script into `<dest_dir>/<ClassName>.fmu` with a complete model
    description; returns the FMU path. Raises BuildError if fmpy finds a problem."""
    from fmpy.validation import validate_fmu
    from pythonfmu.builder import FmuBuilder

    script = Path(script).resolve()
    dest_dir = Path(dest_dir)
    cls = _import_wrapper(script)
    instance = cls(instance_name="build", resources=str(script.parent))
    with tempfile.TemporaryDirectory(prefix="neighbor_fmu_") as tmp:
        raw = FmuBuilder.build_FMU(script, dest=tmp, project_files=[SUPPORT, COMPONENTS],
                                   canGetAndSetFMUstate=cls.can_get_and_set_state)
        with zipfile.ZipFile(raw) as src:
            entries = {info.filename: src.read(info.filename) for info in src.infolist()}
    if not any(name.startswith("binaries/") for name in entries):
        import pythonfmu

        raise BuildError(f"{script.name}: pythonfmu wrote no binaries/; the pythonfmu package in use "
                         f"({Path(pythonfmu.__file__).parent}) lacks its resources/binaries, e.g. the copy "
                         "inside an extracted FMU. Import build_fmus before running FMUs in-process.")
    entries["modelDescription.xml"] = complete_model_description(
        entries["modelDescription.xml"], instance.fmu_meta, cls.can_get_and_set_state, instance.values)
    dest = dest_dir / f"{cls.__name__}.fmu"

    def write(zf):
        for name, data in entries.items():
            zf.writestr(name, data)

    _atomic_zip(dest, write)
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


def pack_ssp(ssd, fmu_dir, dest_dir):
    refs, fmus = _system_files(ssd)
    missing = [f for f in fmus if not (fmu_dir / f).is_file()]
    if missing:
        raise BuildError(f"{ssd.name} uses FMUs that were not built: {', '.join(missing)}")
    dest = Path(dest_dir) / f"{ssd.stem}.ssp"

    def write(zf):
        zf.write(ssd, "SystemStructure.ssd")
        for ref in refs:
            zf.write(ssd.parent / ref, ref)
        for f in fmus:
            zf.write(fmu_dir / f, f"resources/{f}")

    _atomic_zip(dest, write)
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
    """Build what changed; returns (fmu paths, ssp paths)."""
    state = {} if clean else _load_state()

    def refresh(key, digest, target, make, verb):
        """`target` if its inputs' digest is unchanged, else the result of `make()`."""
        if state.get(key) == digest and target.is_file():
            return target
        if verbose:
            print(f"{verb} {target.relative_to(ROOT)}", flush=True)
        made = make()
        state[key] = digest
        _save_state(state)
        return made

    fmu_dir, ssp_dir = BUILD / "fmus", BUILD / "ssp"
    shared = _component_files() + [SUPPORT, Path(__file__).resolve()]
    fmus = []
    names = {}
    for script in wrapper_scripts():
        cls = _import_wrapper(script)
        if cls.__name__ in names:
            raise BuildError(f"{script.name} and {names[cls.__name__]} both define FMU {cls.__name__}")
        names[cls.__name__] = script.name
        target = fmu_dir / f"{cls.__name__}.fmu"
        fmus.append(refresh(f"fmu:{cls.__name__}", _digest(shared + [script]), target,
                            lambda script=script: build_fmu(script, fmu_dir), "building"))
    ssps = []
    for ssd in sorted(SYSTEMS.glob("*.ssd")):
        refs, used = _system_files(ssd)
        inputs = [ssd] + [ssd.parent / r for r in refs] + [fmu_dir / f for f in used if (fmu_dir / f).is_file()]
        digest = _digest(inputs)
        ssps.append(refresh(f"ssp:{ssd.stem}", digest, ssp_dir / f"{ssd.stem}.ssp",
                            lambda ssd=ssd: pack_ssp(ssd, fmu_dir, ssp_dir), "packing"))
    return fmus, ssps


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--clean", action="store_true", help="rebuild every FMU and SSP")
    parser.add_argument("--check", action="store_true", help="run fmpy validation on every FMU after building")
    args = parser.parse_args(argv)
    try:
        fmus, ssps = build_all(clean=args.clean)
    except BuildError as exc:
        print(f"build_fmus: error: {exc}", file=sys.stderr)
        return 1
    if args.check:
        from fmpy.validation import validate_fmu

        bad = {f.name: validate_fmu(str(f)) for f in fmus}
        bad = {k: v for k, v in bad.items() if v}
        for name, problems in bad.items():
            print(f"{name}: {'; '.join(problems)}", file=sys.stderr)
        if bad:
            return 1
    print(f"{len(fmus)} FMUs in {BUILD / 'fmus'}, {len(ssps)} systems in {BUILD / 'ssp'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
