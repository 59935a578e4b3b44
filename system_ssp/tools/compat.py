"""Compatibility information for FMUs in the layout of the FMI standard's cross-check: per FMU a
folder `<Model>/` with `<Model>.fmu`, `<Model>_ref.csv` (the reference result), `<Model>_ref.opt`
(start, stop, step, tolerance, output interval) and a README. The reference is computed here with
FMPy; importing tools are checked against it (tests/fmus/test_compat.py runs ecos on a simulated
user machine and writes what it found; `importers_table` renders the docs' table from that).

    python -m system_ssp.tools.compat build/fmus/*.fmu --out build/compat

No input file is written: every input is held at its start value (the README says so).
"""
from __future__ import annotations

import argparse
import csv
import itertools
from dataclasses import dataclass
import os
from pathlib import Path
import platform
import shutil
import sys
import tempfile
import zipfile
from typing import Any, Dict, List, Mapping, Optional, Sequence

import fmpy

from .. import __version__
from ..atomic import write_text_atomic


@dataclass(frozen=True)
class Options:
    """What `<Model>_ref.opt` holds: the experiment every importing tool repeats."""
    start_time: float = 0.0
    stop_time: float = 10.0
    step_size: float = 0.1
    rel_tol: float = 1e-6
    output_interval: float = 0.1

    def text(self) -> str:
        return (f"StartTime, {self.start_time!r}\nStopTime, {self.stop_time!r}\nStepSize, {self.step_size!r}\n"
                f"RelTol, {self.rel_tol!r}\nOutputInterval, {self.output_interval!r}\n")

    @classmethod
    def read(cls, path: Path) -> "Options":
        keys = {"StartTime": "start_time", "StopTime": "stop_time", "StepSize": "step_size", "RelTol": "rel_tol",
                "OutputInterval": "output_interval"}
        values: Dict[str, float] = {}
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if not line.strip():
                continue
            key, _, value = (part.strip() for part in line.partition(","))
            if key not in keys:
                raise ValueError(f"{path}:{number}: unknown option {key!r} (allowed: {', '.join(keys)})")
            values[keys[key]] = float(value)
        return cls(**values)


NUMERIC = ("Real", "Integer", "Boolean", "Float64", "Float32", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32",
           "Int64", "UInt64")


def outputs(md: Any) -> List[str]:
    """The numeric and Boolean outputs, in model-description order: the variables FMPy records (an
    FMI 3.0 array whole)."""
    return [v.name for v in md.modelVariables if v.causality == "output" and v.type in NUMERIC]


def reference(fmu: Path, options: Options) -> Dict[str, List[float]]:
    """{"time": [...], output: [...]}: FMPy's result of the experiment, inputs at their starts. An
    FMI 3.0 array is written as its elements `name[1]` .. (`name[1,1]` .. row-major), the columns
    its FMI 2.0 twin has."""
    md = fmpy.read_model_description(str(fmu))
    names = outputs(md)
    result = fmpy.simulate_fmu(str(fmu), start_time=options.start_time, stop_time=options.stop_time,
                               step_size=options.step_size, output_interval=options.output_interval,
                               output=names, relative_tolerance=options.rel_tol)
    columns: Dict[str, List[float]] = {"time": [float(x) for x in result["time"]]}
    for name in names:
        values = result[name]
        shape = values.shape[1:]
        if not shape:
            columns[name] = [float(x) for x in values]
            continue
        for index in itertools.product(*(range(n) for n in shape)):
            element = f"{name}[{','.join(str(i + 1) for i in index)}]"
            columns[element] = [float(x) for x in values[(slice(None),) + tuple(index)]]
    return columns


def write_csv(path: Path, columns: Mapping[str, Sequence[float]]) -> None:
    """The cross-check's CSV: a header of quoted names, then one row per time, full precision."""
    names = list(columns)
    rows = zip(*(columns[n] for n in names))
    lines = [",".join(f'"{n}"' for n in names)] + [",".join(repr(float(x)) for x in row) for row in rows]
    write_text_atomic(path, "\n".join(lines) + "\n")


def read_csv(path: Path, separator: Optional[str] = None) -> Dict[str, List[float]]:
    """{column: values} of a result file: the cross-check's CSV, or with `separator` a file split
    on exactly that text (ecos writes ", " and names such as dcm_BN[1,1] unquoted)."""
    with open(path, newline="") as f:
        if separator is None:
            rows = list(csv.reader(f, skipinitialspace=True))
        else:
            rows = [line.rstrip("\r\n").split(separator) for line in f if line.strip()]
    header = rows[0]
    out = {}
    for i, name in enumerate(header):
        try:
            out[name] = [_number(row[i]) for row in rows[1:] if row]
        except ValueError:  # a String variable (a tool may log parameters too): not compared
            continue
    return out


def _number(text: str) -> float:
    """A CSV cell: a number, or a Boolean as 1/0 (some tools write true/false)."""
    word = text.strip().lower()
    return 1.0 if word == "true" else 0.0 if word == "false" else float(word)


README = """# {model}

{description}

- FMI {fmi_version} co-simulation, model identifier `{model}`, built by neighbor-cosim {version} (model
  description by {tool}).
- Platforms: {linux} (run); {win64}.
- Needs on the target: CPython 3.9 to 3.13 with its shared library, and numpy (the FMU finds a
  Python by itself; see the project's docs/interoperability.md).

## Reference result

`{model}_ref.csv`: FMPy {fmpy_version} on {system} {machine}, Python {python}: the experiment of
`{model}_ref.opt` (start {o.start_time:g} s, stop {o.stop_time:g} s, communication step {o.step_size:g} s,
a row every {o.output_interval:g} s), every input held at its start value (so no `{model}_in.csv`),
every parameter at its start value. Columns: time and the {n} outputs (Real, Integer, Boolean as
0/1; an FMI 3.0 array as its elements, name[1] .., a matrix row-major).
"""


def write_bundle(fmu: Path, out_dir: Path, options: Options = Options()) -> Path:
    """`out_dir/<Model>/` for one FMU; returns that folder. Written to a temporary folder and
    renamed, so an interrupted run leaves no half bundle."""
    md = fmpy.read_model_description(str(fmu))
    model = md.coSimulation.modelIdentifier
    target = out_dir / model
    out_dir.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{model}.", dir=out_dir))
    try:
        shutil.copyfile(fmu, tmp / f"{model}.fmu")
        write_csv(tmp / f"{model}_ref.csv", reference(fmu, options))
        write_text_atomic(tmp / f"{model}_ref.opt", options.text())
        with zipfile.ZipFile(fmu) as z:
            win64 = any(n.startswith(("binaries/win64/", "binaries/x86_64-windows/")) for n in z.namelist())
        write_text_atomic(tmp / "README.md", README.format(
            model=model, fmi_version=md.fmiVersion, description=md.description or "", version=__version__,
            tool=md.generationTool or "?",
            linux="x86_64-linux" if md.fmiVersion.startswith("3.") else "linux64",
            win64=("x86_64-windows" if md.fmiVersion.startswith("3.") else "win64")
            + (" (compiled, not yet run on Windows)" if win64 else ": no binary in this build"),
            fmpy_version=fmpy.__version__, system=platform.system(), machine=platform.machine(),
            python=platform.python_version(), o=options, n=len(outputs(md))))  # variables (arrays whole)
        if target.exists():
            shutil.rmtree(target)
        os.replace(tmp, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return target


def compare(reference_columns: Mapping[str, Sequence[float]], got: Mapping[str, Sequence[float]],
            atol: float, rtol: float) -> Dict[str, Any]:
    """How a tool's result departs from the reference, at the reference's times: the largest
    deviation and the columns beyond atol + rtol |ref| (both must have every column)."""
    times = {round(t, 9): i for i, t in enumerate(got["time"])}
    missing = [n for n in reference_columns if n not in got]
    worst, failing = 0.0, []
    for name, ref in reference_columns.items():
        if name == "time" or name in missing:
            continue
        for t, r in zip(reference_columns["time"], ref):
            i = times.get(round(t, 9))
            if i is None:
                missing.append(f"time {t:g}")
                break
            deviation = abs(got[name][i] - r)
            worst = max(worst, deviation)
            if not deviation <= atol + rtol * abs(r):
                failing.append(name)
                break
    return {"missing": missing, "failing": failing, "max_deviation": worst}


def importers_table(runs: Sequence[Mapping[str, Any]]) -> str:
    """The docs' table of importing tools, from the records the compatibility tests write."""
    lines = ["| importing tool | version | where it ran | what was run | FMUs equal to the reference |",
             "|---|---|---|---|---|"]
    for r in runs:  # no deviations: they depend on the CPU (numba's kernels), the table must not
        lines.append(f"| {r['tool']} | {r['version']} | {r['setup']} | {r['what']} | {r['passed']} of {r['total']} "
                     f"(within {r['tolerance']}) |")
    return "\n".join(lines)


TABLE_BEGIN = "<!-- importers: written by tests/fmus/test_compat.py from its runs; do not edit -->"
TABLE_END = "<!-- end importers -->"


def docs_table(docs_text: str) -> Optional[str]:
    """The generated table between the markers of docs/interoperability.md (None if absent)."""
    if TABLE_BEGIN not in docs_text or TABLE_END not in docs_text:
        return None
    return docs_text.split(TABLE_BEGIN, 1)[1].split(TABLE_END, 1)[0].strip()


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m system_ssp.tools.compat", description=__doc__.split("\n\n")[0])
    parser.add_argument("fmus", nargs="+", type=Path, help="FMU files")
    parser.add_argument("--out", type=Path, required=True, help="folder for the <Model>/ bundles")
    args = parser.parse_args(argv)
    for fmu in args.fmus:
        if not fmu.is_file():
            print(f"compat: error: {fmu}: no such FMU file", file=sys.stderr)
            return 2
    for fmu in args.fmus:
        print(write_bundle(fmu, args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
