"""The product's artifacts: `neighbor-cosim build` (every FMU and system into the build folder,
system_ssp.locations) and `neighbor-cosim export` (them as one versioned archive for FMI users
who do not use Python).

    neighbor-cosim build [--clean] [--check] [--compat]
    neighbor-cosim export --out DIR        # DIR/neighbor-cosim-<version>-fmi.zip

The archive holds one folder, neighbor-cosim-<version>-fmi/:
- README.md: what is there, what a target machine needs, how to run an FMU and a system;
- fmus/<Model>/: the FMU with its compatibility information (the FMI cross-check's layout:
  <Model>.fmu, <Model>_ref.csv, <Model>_ref.opt, README.md); fmus3/<Model>/: the same as FMI 3.0;
- systems/<name>.ssp: every packed system (its FMUs, its parameter sets under parameters/);
- reference/: a page per FMU (every variable with unit, start, range, description);
- LICENSE and SHA256SUMS.
"""
import hashlib
from importlib import metadata
import sys
import zipfile

import fmpy
from fmpy.validation import validate_fmu

from .. import builder
from ..atomic import check_output_folder
from ..errors import SSPError
from ..locations import BUILD, COMPAT3_DIR, COMPAT_DIR, ROOT, is_checkout
from ..version import __version__
from . import compat, fmu_reference
from .console import ArgumentParser

BUNDLE_README = """# neighbor-cosim {version}: FMUs and systems

The spacecraft models of neighbor-cosim {version} as FMI 2.0 and FMI 3.0 co-simulation FMUs, and
the systems that wire them as SSP 1.0 files, for any FMI or SSP tool (no neighbor-cosim install
needed). Built on {built_on} with {python}.

- `fmus/<Model>/`: `<Model>.fmu` (FMI 2.0) with its compatibility information in the FMI
  cross-check's layout: `<Model>_ref.csv` (the reference result), `<Model>_ref.opt` (its
  experiment), README.md;
- `fmus3/<Model>/`: the same model as an FMI 3.0 co-simulation FMU (vectors and matrices as
  arrays), with the same reference result (array elements as columns `name[1]` ..);
- `systems/<name>.ssp`: the packed systems: `SystemStructure.ssd`, the FMUs under `resources/`,
  the parameter sets under `parameters/` (scenarios: `parameters/<name>_*.ssv`);
- `reference/`: a page per FMU, every input, output and parameter with unit, start, range and
  description;
- `SHA256SUMS`: the checksum of every file here.

## FMUs

{fmu_table}

Every FMU: model description `version` {version}, a GUID derived from the product version and
the model's code, units and output dependencies declared, `fmpy validate` clean, binaries for
{platforms}.

## What a target machine needs

- **CPython 3.9 to 3.13 with its shared library** (`libpython3.X.so.1.0` on Linux), any of them:
  a host that runs Python already (FMPy, libcosimpy) lends its own; a C or C++ host (fmusim,
  libcosim, ecos, Simulink) makes the FMU look for one: `NEIGHBOR_FMU_LIBPYTHON` (a path), the
  `python3` on `PATH`, `libpython3.X.so.1.0` through the system's library search (Debian/Ubuntu:
  `apt install libpython3.11`).
- **numpy** importable by that Python (its site-packages, `PYTHONPATH` or
  `NEIGHBOR_FMU_PYTHONPATH`).
- Nothing else. When no Python or no numpy can be found, `fmi2Instantiate` (FMI 3.0:
  `fmi3InstantiateCoSimulation`) fails with a message
  in the host's log that lists where it looked; the host is never exited.

## Running

```bash
fmpy simulate fmus/RigidBody/RigidBody.fmu --stop-time 10 --output-file rb.csv
fmusim --interface-type cs --stop-time 10 --output-file rb3.csv fmus3/RigidBody/RigidBody.fmu
pip install neighbor-cosim && neighbor-cosim run systems/slew.ssp --ssv parameters/slew_case1.ssv
```

Hosts these FMUs were run in before release: FMPy, libcosim (libcosimpy), ecos, fmusim (FMI 2.0
and 3.0) and a plain C host with no Python in the process, on the build machine and on simulated user machines with
CPython 3.9 to 3.13 (each FMU's README and `_ref.csv` say what a host should get).

`neighbor-cosim run` applies every parameter binding of a system and its scenario sets (named
inside the .ssp, as above). A host that applies only a component's first binding (libcosim)
finds one merged set per component in these files.
"""


def build_main(argv=None):
    """`neighbor-cosim build` (and `python build_fmus.py` in a checkout)."""
    parser = ArgumentParser(prog="neighbor-cosim build",
                            description=f"Build every FMU and pack every system into {BUILD} "
                                        "(only what changed; NEIGHBOR_COSIM_BUILD chooses another folder).")
    parser.add_argument("--clean", action="store_true", help="rebuild every FMU and SSP")
    parser.add_argument("--check", action="store_true", help="run fmpy validation on every FMU after building")
    parser.add_argument("--compat", action="store_true",
                        help="write each FMU's compatibility information (the FMI cross-check's layout: the FMU, "
                             f"its reference result and options, a README) into {COMPAT_DIR}/<Model>/")
    args = parser.parse_args(argv)
    try:
        fmus, ssps = builder.build_all(clean=args.clean)
    except (builder.BuildError, OSError) as exc:
        print(f"error: build: {builder.build_failure(exc)}", file=sys.stderr)
        return 1
    if args.check:
        checked = fmus + sorted((BUILD / "fmus3").glob("*.fmu"))
        bad = {f"{f.parent.name}/{f.name}": validate_fmu(str(f)) for f in checked}
        bad = {k: v for k, v in bad.items() if v}
        for name, problems in bad.items():
            print(f"{name}: {'; '.join(problems)}", file=sys.stderr)
        if bad:
            return 1
    print(f"{len(fmus)} FMUs in {BUILD / 'fmus'} (FMI 2.0) and {BUILD / 'fmus3'} (FMI 3.0), {len(ssps)} systems "
          f"in {BUILD / 'ssp'} and {BUILD / 'ssp3'}")
    if args.compat:
        for fmu in fmus:
            compat.write_bundle(fmu, COMPAT_DIR)
        for fmu in fmi3_twins(fmus):
            compat.write_bundle(fmu, COMPAT3_DIR)
        print(f"compatibility information for {len(fmus)} FMUs in {COMPAT_DIR} and {COMPAT3_DIR} (FMI 3.0)")
    return 0


def fmi3_twins(fmus):
    """The FMI 3.0 builds (build/fmus3) of the FMI 2.0 FMUs `fmus`."""
    return [fmu.parent.parent / "fmus3" / fmu.name for fmu in fmus]


def _compat_is_current(fmu, compat_dir=COMPAT_DIR):
    """True when compat_dir/<Model>/ was written for exactly this FMU (`build --compat` or an
    earlier export did it)."""
    folder = compat_dir / fmu.stem
    names = [f"{fmu.stem}.fmu", f"{fmu.stem}_ref.csv", f"{fmu.stem}_ref.opt", "README.md"]
    return (all((folder / name).is_file() for name in names)
            and (folder / f"{fmu.stem}.fmu").read_bytes() == fmu.read_bytes())


def _fmu_table(fmus):
    rows = ["| FMU | GUID | description |", "|---|---|---|"]
    for fmu in fmus:
        md = fmpy.read_model_description(str(fmu), validate=False)
        rows.append(f"| `{fmu.stem}` | `{md.guid}` | {fmu_reference.table_cell(md.description or '')} |")
    return "\n".join(rows)


def bundle_name():
    return f"neighbor-cosim-{__version__}-fmi"


def export(out_dir, progress=None):
    """Build what is missing, then write out_dir/neighbor-cosim-<version>-fmi.zip (see the module
    docstring); returns its path. The archive is written to a temporary file and renamed."""
    out_dir = check_output_folder(out_dir, "--out")
    fmus, ssps = builder.build_all(verbose=False)
    top = bundle_name()
    files = {}
    platforms = set()
    for top_folder, compat_dir, version_fmus in (("fmus", COMPAT_DIR, fmus), ("fmus3", COMPAT3_DIR, fmi3_twins(fmus))):
        stale = [fmu for fmu in version_fmus if not _compat_is_current(fmu, compat_dir)]
        if stale and progress:
            progress(f"writing the compatibility information of {len(stale)} FMUs into {compat_dir} (a reference "
                     "run each)")
        for fmu in version_fmus:
            folder = compat.write_bundle(fmu, compat_dir) if fmu in stale else compat_dir / fmu.stem
            for path in sorted(folder.iterdir()):
                files[f"{top_folder}/{fmu.stem}/{path.name}"] = path.read_bytes()
            with zipfile.ZipFile(fmu) as z:
                platforms |= {n.split("/")[1] for n in z.namelist()
                              if n.startswith("binaries/") and n.count("/") == 2}
    for ssp in ssps:
        files[f"systems/{ssp.name}"] = ssp.read_bytes()
    for name, text in fmu_reference.generate(BUILD / "fmus").items():
        files[f"reference/{name}"] = text.encode("utf-8")
    files["LICENSE"] = licence_text()
    files["README.md"] = BUNDLE_README.format(
        version=__version__, built_on=f"{sys.platform}", python=f"Python {sys.version.split()[0]}",
        fmu_table=_fmu_table(fmus), platforms=", ".join(sorted(platforms))).encode("utf-8")
    files["SHA256SUMS"] = "".join(f"{hashlib.sha256(data).hexdigest()}  {name}\n"
                                  for name, data in sorted(files.items())).encode()
    target = out_dir / f"{top}.zip"
    builder.write_zip(target, {f"{top}/{name}": data for name, data in files.items()})
    return target


def export_main(argv=None):
    """`neighbor-cosim export --out DIR`."""
    parser = ArgumentParser(prog="neighbor-cosim export",
                            description="Write every FMU (with its compatibility information), every packed system, "
                                        "the FMU reference pages and a README as one versioned archive, "
                                        f"OUT/{bundle_name()}.zip.")
    parser.add_argument("--out", required=True, metavar="DIR", help="the folder to write the archive into")
    args = parser.parse_args(argv)
    try:
        target = export(args.out, progress=lambda text: print(text, file=sys.stderr, flush=True))
    except (builder.BuildError, OSError) as exc:
        raise SSPError(f"building the FMUs and systems failed: {builder.build_failure(exc)}") from None
    with zipfile.ZipFile(target) as z:
        count = sum(1 for n in z.namelist() if n.endswith(".fmu") and "/fmus/" in n)
        count3 = sum(1 for n in z.namelist() if n.endswith(".fmu") and "/fmus3/" in n)
        systems = sum(1 for n in z.namelist() if n.endswith(".ssp"))
    print(f"{target}: {count} FMUs (and {count3} as FMI 3.0), {systems} systems, reference pages, README")
    return 0


def licence_text():
    """The product's LICENSE: the checkout's, or the one the wheel carries in its metadata."""
    if is_checkout():
        return (ROOT / "LICENSE").read_bytes()
    for path in metadata.distribution("neighbor-cosim").files or ():
        if path.name == "LICENSE":
            return path.read_binary()
    raise SSPError("the installed package carries no LICENSE file; reinstall neighbor-cosim")
