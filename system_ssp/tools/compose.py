"""`neighbor-cosim compose SPEC.toml --out SYSTEM.ssp`: a system from a system spec (TOML,
system_ssp.ssp.spec), packed with its FMUs and parameter sets, loaded by the master before it is
kept; prints what was wired by name, which inputs stay at their start values and which outputs
feed nothing. `neighbor-cosim compose --from SYSTEM --out SPEC.toml`: the spec of an existing
system (any tool's), its FMUs beside it in SPEC_files/, to start from.
"""
import filecmp
import json
import os
from pathlib import Path
import re
import shutil
import tempfile

from .. import builder
from ..atomic import check_output_place, write_text_atomic
from ..errors import SSPError
from ..locations import FMU_DIR, SYSTEM_SOURCES
from ..master import System
from ..master.planning import step_size_of
from ..ssp.spec import NAME, compose
from ..ssp.writer import GeneratorError, SystemWriter
from .console import ArgumentParser, system_path
from .convert import convert_system
from .replace import _pack

PARAMETERS_DIR = SYSTEM_SOURCES / "parameters"
SPECS_DIR = SYSTEM_SOURCES / "specs"  # the shipped systems' specs: a spec's sub-systems by name


def _shipped_fmus(fmu_dir):
    """The shipped FMUs' folder, built first when the default one is empty (a wheel's first use)."""
    fmu_dir = Path(fmu_dir)
    if fmu_dir == FMU_DIR and not any(fmu_dir.glob("*.fmu")):
        builder.build_on_first_use()
    return fmu_dir


def write_folder(composition, folder, fmu_dir):
    """The composed system as a folder: SystemStructure.ssd, parameters/, resources/."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    writer = SystemWriter(folder, fmu_dir)
    resources = {res: composition.components[c].fmu_path for c, res, _ in composition.writer_spec["components"]}
    writer.fmu_files = dict(resources)
    for stem, source in composition.ssv_files.items():
        if isinstance(source, tuple):
            writer.ssv(stem, *source)
        else:
            (folder / "parameters").mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, folder / "parameters" / f"{stem}.ssv")
    try:
        text = writer.ssd_text(composition.name, composition.writer_spec)
    except GeneratorError as exc:
        raise SSPError(f"{composition.spec_path}: {exc}") from None
    write_text_atomic(folder / "SystemStructure.ssd", text)
    (folder / "resources").mkdir(parents=True, exist_ok=True)
    for res, path in resources.items():
        shutil.copyfile(path, folder / "resources" / f"{res}.fmu")
    return folder / "SystemStructure.ssd"


def _users_names(message, composition, folder):
    """`message` with the composed folder's files named as the user knows them: a parameter file
    by the path the spec gave, the rest relative to the composed system."""
    text = str(message)
    for stem, source in composition.ssv_files.items():
        if not isinstance(source, tuple):
            text = text.replace(str(folder / "parameters" / f"{stem}.ssv"), str(source))
    return text.replace(f"{folder}{os.sep}", "(the composed system) ")


def compose_system(spec_path, out, fmu_dir=FMU_DIR, parameters_dir=PARAMETERS_DIR):
    """Write `out` (.ssp) from the spec at `spec_path`; returns the Composition (its report()).
    Nothing is written unless the spec is sound and the composed system loads in the master."""
    out = check_output_place(out, "--out", (".ssp",))
    composition = compose(Path(spec_path), _shipped_fmus(fmu_dir), Path(parameters_dir), SPECS_DIR)
    with tempfile.TemporaryDirectory(prefix="neighbor_compose_") as tmp:
        folder = Path(tmp) / "system"
        ssd = write_folder(composition, folder, fmu_dir)
        try:
            with System(ssd):
                pass
        except SSPError as exc:
            why = _users_names(exc, composition, folder)
            raise SSPError(f"{spec_path}: the composed system does not load: {why}") from None
        if composition.ssp_version == "2.0":
            convert_system(folder, "2.0", out)
        else:
            _pack(folder, ssd, out)
    return composition


# ---- compose --from: the spec of an existing system -----------------------------------------
def _toml_key(name):
    return name if re.fullmatch(r"[A-Za-z0-9_-]+", name) else json.dumps(name)


def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if value != value:
            return "nan"
        if value in (float("inf"), float("-inf")):
            return "inf" if value > 0 else "-inf"
        return repr(float(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if hasattr(value, "item"):  # a numpy scalar
        return _toml_value(value.item())
    return json.dumps(str(value))


def _grouped_values(values, variables):
    """{'q0[1]': a, 'q0[2]': b, ...} -> {'q0': [a, b, ...]} where the FMU's vector is complete."""
    out = {}
    bases = {}
    for name in values:
        m = re.fullmatch(r"(.*)\[(\d+)\]", name)
        if m:
            bases.setdefault(m.group(1), set()).add(int(m.group(2)))
    for name, value in values.items():
        m = re.fullmatch(r"(.*)\[(\d+)\]", name)
        if m and m.group(1) not in variables:
            base = m.group(1)
            n = len(bases[base])
            if bases[base] == set(range(1, n + 1)) and f"{base}[{n + 1}]" not in variables:
                if base not in out:
                    out[base] = [values[f"{base}[{i}]"] for i in range(1, n + 1)]
                continue
        out[name] = value
    return out


def _master_lines(s):
    """The [master] table (and its schedule) of a loaded system."""
    desc, m = s.desc, s.desc.master
    lines = []
    try:
        step = step_size_of(s)[0]
    except SSPError:  # the system has none: the user gives one
        step = None
    stop = desc.stop_time
    lines += ["", "[master]", f"step_size = {_toml_value(float(step))}" if step is not None else
              "# step_size = ...  (the system has none: give one)"]
    if stop is not None:
        lines.append(f"stop_time = {_toml_value(float(stop))}")
    else:
        lines.append("# stop_time = ...  (the system has none: give one)")
    algorithm = m.algorithm or m.osp_algorithm
    if algorithm and algorithm != "gauss-seidel":
        lines.append(f"algorithm = {json.dumps(algorithm)}")
    if m.order:
        lines.append(f"order = {_toml_value(list(m.order))}")
    if m.stop_conditions:
        lines.append(f"stop_when = {_toml_value(list(m.stop_conditions))}")
    if m.record:
        lines.append(f"record = {_toml_value(list(m.record))}")
    if m.schedule is not None:
        if m.schedule.events:
            lines += ["", "[master.schedule]",
                      f"events = {_toml_value([f'{c}.{v}' for c, v in m.schedule.events])}"]
        for mode in m.schedule.modes:
            lines += ["", "[[master.schedule.mode]]", f"name = {json.dumps(mode.name)}",
                      f"step_size = {_toml_value(float(mode.step_size))}"]
            if mode.active is not None:
                lines.append(f"active = {_toml_value(list(mode.active))}")
            if mode.record_every != 1:
                lines.append(f"record_every = {mode.record_every}")
            if mode.every:
                lines.append("every = { " + ", ".join(f"{_toml_key(c)} = {k}" for c, k in mode.every.items())
                             + " }")
            if mode.conditions:
                lines.append("when = { " + ", ".join(f"{json.dumps(f'{w.component}.{w.connector}')} = "
                                                     f"{_toml_value(list(w.values))}" for w in mode.conditions)
                             + " }")
    return lines


def spec_from_system(source, out, fmu_dir=FMU_DIR):
    """Write the spec of the system at `source` to `out` (.toml) and its FMUs that are not the
    shipped ones into <out stem>_files/ beside it. Parameter values are written as the master
    applies them (every binding, mapping and system parameter resolved), connections as it
    resolved them (unit conversions and transformations as one factor and offset). Returns
    the spec's text."""
    out = check_output_place(out, "--out", (".toml",))
    files_dir = out.parent / f"{out.stem}_files"
    if files_dir.exists() and (not files_dir.is_dir() or any(files_dir.iterdir())):
        raise SSPError(f"{files_dir}: already there (the spec's FMUs go into it): remove it or choose another --out")
    with System(source) as s:
        for lk in s.links:
            if lk.mapping:
                raise SSPError(f"{lk.label}: an Integer/Boolean mapping transformation, which a system spec cannot "
                               "say yet")
        desc = s.desc
        name = re.sub(r"[^A-Za-z0-9_]", "_", desc.name or desc.system_name or "system")
        if not NAME.match(name):
            name = f"system_{name}"
        lines = [f"# The spec of {source}, written by neighbor-cosim compose --from: the values as the master",
                 "# applies them, connections as it resolved them. compose it with",
                 f"#   neighbor-cosim compose {out.name} --out {out.stem}.ssp",
                 "", "[system]", f"name = {json.dumps(name)}"]
        lines.append(f"description = {json.dumps(f'{desc.system_name} (from {Path(str(source)).name})')}")
        lines += _master_lines(s)
        values = {}  # component index -> {variable: the value the master applies}
        for (ci, var), v in s.collect_parameters().items():
            values.setdefault(ci, {})[var] = v
        shipped = {p.stem: p for p in Path(fmu_dir).glob("*.fmu")}
        copied = {}
        for comp in s.comps:
            fmu = comp.decl.fmu_path
            stem = Path(comp.decl.source).stem
            if stem in shipped and filecmp.cmp(fmu, shipped[stem], shallow=False):
                given = stem
            else:
                files_dir.mkdir(exist_ok=True)
                target = files_dir / Path(fmu).name
                k = 1
                while target.name in copied and not filecmp.cmp(copied[target.name], fmu, shallow=False):
                    k += 1
                    target = files_dir / f"{Path(fmu).stem}_{k}.fmu"
                if target.name not in copied:
                    shutil.copyfile(fmu, target)
                    copied[target.name] = fmu
                given = f"{files_dir.name}/{target.name}"
            lines += ["", f"[components.{_toml_key(comp.name)}]", f"fmu = {json.dumps(given)}"]
            grouped = _grouped_values(values.get(comp.index, {}), comp.vars)
            if grouped:
                lines.append(f"[components.{_toml_key(comp.name)}.parameters]")
                lines += [f"{_toml_key(k)} = {_toml_value(v)}" for k, v in grouped.items()]
        params = {n: targets for n, targets in s.parameter_links.items()
                  if desc.system_connectors[n].kind == "parameter"
                  and all(c.vars[v].causality == "parameter" for c, v, _ in targets)}
        for pname, targets in params.items():
            lines += ["", f"[system_parameters.{_toml_key(pname)}]",
                      f"to = {_toml_value([f'{c.name}.{v}' for c, v, _ in targets])}"]
        lines += ["", "[connections]", "auto = false", "links = ["]
        for lk in s.links:
            a, b = f"{s.comps[lk.src].name}.{lk.src_var}", f"{s.comps[lk.dst].name}.{lk.dst_var}"
            if lk.factor != 1.0 or lk.offset != 0.0:
                lines.append(f"  {{ from = {json.dumps(a)}, to = {json.dumps(b)}, factor = {_toml_value(lk.factor)}, "
                             f"offset = {_toml_value(lk.offset)}, suppress_unit_conversion = true }},")
            else:
                lines.append(f"  {json.dumps(f'{a} -> {b}')},")
        lines += ["]", ""]
    text = "\n".join(lines)
    write_text_atomic(out, text)
    return text


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim compose", description=__doc__.split("\n\n")[0])
    ap.add_argument("spec", nargs="?", help="the system spec (.toml)")
    ap.add_argument("--from", dest="source", metavar="SYSTEM",
                    help="write the spec of this system (.ssp, .ssd, a folder, or a shipped system's name) instead")
    ap.add_argument("--out", required=True, help="the system to write (.ssp); with --from, the spec (.toml)")
    ap.add_argument("--fmu-dir", type=Path, default=FMU_DIR, help="the shipped FMUs (default: %(default)s)")
    args = ap.parse_args(argv)
    if (args.spec is None) == (args.source is None):
        raise SSPError("compose: give a spec (compose SPEC.toml --out X.ssp) or --from SYSTEM (--out SPEC.toml)")
    if args.source is not None:
        spec_from_system(system_path(args.source), args.out, args.fmu_dir)
        print(f"wrote {args.out}")
        return 0
    composition = compose_system(args.spec, args.out, args.fmu_dir)
    print(composition.report())
    print(f"wrote {args.out}")
    return 0
