"""The compatibility information in the FMI cross-check's layout (system_ssp.tools.compat), checked
the way a user would: every bundled FMU `fmpy validate`-clean; its reference reproduced by ecos
(a C++ co-simulation engine from PyPI with no Python in it) on a simulated user machine (see
user_machine.py) and by FMPy in a Python with only fmpy and numpy. The table of importing tools in
docs/interoperability.md is rendered from these runs; set NEIGHBOR_WRITE_DOCS=1 to write it."""
from concurrent.futures import ThreadPoolExecutor
import filecmp
import importlib.metadata
import importlib.util
import json
import os
from pathlib import Path
import shutil
import subprocess

from fmpy.validation import validate_fmu
import pytest

from paths import REPO
from system_ssp.tools import compat
from user_machine import TARGETS, numpy_for, on_user_machine

DOCS = REPO / "docs" / "interoperability.md"
ECOS_TOLERANCE = (1e-6, 1e-9)  # ecos writes its CSV with 6 decimals: atol, rtol
FMPY_TOLERANCE = (0.0, 1e-12)
RUNS = {}  # tool -> the record the docs' table is rendered from
USER_PYTHONS = {"debian": "Debian's CPython", "pyenv": "CPython (pyenv)"}


def minor_version(target_id):
    return "3." + target_id.rsplit(".", 1)[1]


@pytest.fixture(scope="module")
def bundle(fmu_paths, tmp_path_factory):
    """build/compat/<Model>/ where `build_fmus.py --compat` wrote it for the FMU built now (CI
    does), else a fresh bundle."""
    out = tmp_path_factory.mktemp("compat")

    def folder(model):
        built = REPO / "build" / "compat" / model
        if filecmp.cmp(built / f"{model}.fmu", fmu_paths[model], shallow=False) if (
                built / f"{model}.fmu").is_file() else False:
            return built
        return compat.write_bundle(fmu_paths[model], out)

    # one at a time: write_bundle runs FMPy in this process, and FMPy's FMU loading changes the
    # working directory to the binary's folder and back; two threads interleaving that left the
    # worker in a deleted extraction folder (os.getcwd() failing in every later test of it: the
    # 254 failures of two CI runs)
    folders = [folder(model) for model in sorted(fmu_paths)]
    return {f.name: f for f in folders}


def test_every_fmu_has_its_compatibility_information(bundle, fmu_paths):
    assert sorted(bundle) == sorted(fmu_paths)
    for model, folder in bundle.items():
        assert sorted(p.name for p in folder.iterdir()) == sorted(
            [f"{model}.fmu", f"{model}_ref.csv", f"{model}_ref.opt", "README.md"]), model
        options = compat.Options.read(folder / f"{model}_ref.opt")
        ref = compat.read_csv(folder / f"{model}_ref.csv")
        n = round((options.stop_time - options.start_time) / options.output_interval) + 1
        assert list(ref)[0] == "time" and len(ref["time"]) == n, model
        assert validate_fmu(str(folder / f"{model}.fmu")) == [], model
        assert f"`{model}_ref.opt`" in (folder / "README.md").read_text()


def test_options_file_names_a_bad_line(tmp_path):
    bad = tmp_path / "M_ref.opt"
    bad.write_text("StartTime, 0\nStopTme, 1\n")
    with pytest.raises(ValueError, match=r"M_ref.opt:2: unknown option 'StopTme'"):
        compat.Options.read(bad)


@pytest.fixture(scope="module")
def ecos(tmp_path_factory):
    """The ecos command-line engine of the ecospy wheel, copied out of the checkout (hidden on the
    user machine); it needs Debian's libtbb12."""
    spec = importlib.util.find_spec("ecospy")
    if spec is None:
        pytest.skip("ecospy is not installed (pip install ecospy)")
    source = Path(spec.origin).parent / "binaries" / "ecos"
    target = tmp_path_factory.mktemp("ecos") / "ecos"
    shutil.copyfile(source, target)
    target.chmod(0o755)
    proc = subprocess.run([str(target), "--version"], capture_output=True, text=True)
    if proc.returncode != 0:
        pytest.skip(f"the ecos command does not start ({proc.stderr.strip()[-200:]}): apt install libtbb12")
    return target, importlib.metadata.version("ecospy")


def _user_python():
    """Debian's Python 3.11 when present, else the newest other CPython of the machine."""
    present = [t for t in TARGETS if t[1] is not None]
    debian = [t for t in present if t[0].startswith("debian")]
    if not (debian or present):
        pytest.skip("no CPython with its shared library on this machine")
    return (debian or present[::-1])[0]


def test_ecos_on_a_user_machine_reproduces_every_reference(bundle, ecos, user_machine, tmp_path):
    binary, version = ecos
    target_id, python, bin_dir, installer = _user_python()
    minor = int(target_id.rsplit(".", 1)[1])
    numpy_dir = numpy_for(target_id, installer, minor)

    def run(model):
        folder = bundle[model]
        options = compat.Options.read(folder / f"{model}_ref.opt")
        work = tmp_path / model
        work.mkdir()
        shutil.copyfile(folder / f"{model}.fmu", work / f"{model}.fmu")
        proc = on_user_machine(["sh", "-c", f'cd "{work}" && exec "$@"', "sh", str(binary), "simulate", "--path",
                                f"{model}.fmu", "--startTime", repr(options.start_time), "--stopTime",
                                repr(options.stop_time), "--stepSize", repr(options.step_size), "--noParallel"],
                               [bin_dir], str(numpy_dir))
        assert proc.returncode == 0, f"{model}:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
        got = compat.read_csv(work / f"{model}.csv", separator=", ")
        got = {name.split("::", 1)[-1].rsplit("[", 1)[0] if "::" in name else name: values
               for name, values in got.items()}
        return model, compat.compare(compat.read_csv(folder / f"{model}_ref.csv"), got, *ECOS_TOLERANCE)

    with ThreadPoolExecutor(os.cpu_count() or 2) as pool:
        results = dict(pool.map(run, sorted(bundle)))
    bad = {m: r for m, r in results.items() if r["missing"] or r["failing"]}
    assert bad == {}, bad
    user_python = f"{USER_PYTHONS[target_id.split('-')[0]]} {minor_version(target_id)}"
    RUNS["ecos"] = dict(tool="ecos (ecospy's `ecos simulate`, C++, no Python in the process)", version=version,
                        setup=f"simulated user machine: {user_python} found on PATH, numpy only",
                        what="every FMU, the `_ref.opt` experiment", passed=len(results), total=len(bundle),
                        tolerance=f"{ECOS_TOLERANCE[0]:g} + {ECOS_TOLERANCE[1]:g} x value: its CSV has 6 decimals",
                        max_deviation=max(r["max_deviation"] for r in results.values()))


FMPY_RUN = r"""
import json, sys, fmpy
out = {}
for model, fmu, start, stop, step, interval, tol in json.loads(sys.argv[1]):
    r = fmpy.simulate_fmu(fmu, start_time=start, stop_time=stop, step_size=step, output_interval=interval,
                          relative_tolerance=tol)
    out[model] = {name: [float(x) for x in r[name]] for name in r.dtype.names}
print(json.dumps(out))
"""


def test_fmpy_with_only_numpy_reproduces_every_reference(bundle, numpy_only_python):
    """FMPy in a Python that has fmpy and numpy only (the FMUs' plain-Python kernels, no numba)."""
    jobs = []
    for model in sorted(bundle):
        o = compat.Options.read(bundle[model] / f"{model}_ref.opt")
        jobs.append((model, str(bundle[model] / f"{model}.fmu"), o.start_time, o.stop_time, o.step_size,
                     o.output_interval, o.rel_tol))
    proc = subprocess.run([str(numpy_only_python), "-c", FMPY_RUN, json.dumps(jobs)], capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    there = json.loads(proc.stdout.strip().splitlines()[-1])
    results = {m: compat.compare(compat.read_csv(bundle[m] / f"{m}_ref.csv"), there[m], *FMPY_TOLERANCE)
               for m in sorted(bundle)}
    bad = {m: r for m, r in results.items() if r["missing"] or r["failing"]}
    assert bad == {}, bad
    version = subprocess.run([str(numpy_only_python), "-c", "import fmpy; print(fmpy.__version__)"],
                             capture_output=True, text=True).stdout.strip()
    RUNS["fmpy"] = dict(tool="FMPy (`simulate_fmu`)", version=version,
                        setup="a virtual environment with only fmpy and numpy (its Python lent to the FMU)",
                        what="every FMU, the `_ref.opt` experiment", passed=len(results), total=len(bundle),
                        tolerance=f"{FMPY_TOLERANCE[1]:g} x value", max_deviation=max(
                            r["max_deviation"] for r in results.values()))


def test_docs_table_of_importing_tools_is_these_runs():
    if set(RUNS) != {"ecos", "fmpy"}:
        pytest.skip(f"needs the runs above (have: {sorted(RUNS) or 'none'})")
    table = compat.importers_table([RUNS["ecos"], RUNS["fmpy"]])
    text = DOCS.read_text()
    if os.environ.get("NEIGHBOR_WRITE_DOCS") == "1":
        before, rest = text.split(compat.TABLE_BEGIN, 1)
        DOCS.write_text(before + compat.TABLE_BEGIN + "\n" + table + "\n" + compat.TABLE_END
                        + rest.split(compat.TABLE_END, 1)[1])
        text = DOCS.read_text()
    assert compat.docs_table(text) == table, f"docs/interoperability.md's table is not these runs':\n{table}\n" \
        "(NEIGHBOR_WRITE_DOCS=1 writes it)"


def test_ecos_without_python_gets_the_error_and_lives(bundle, ecos, user_machine, tmp_path):
    """No CPython on the machine: ecos gets fmi2Instantiate's fmi2Error with the message and the
    process ends by itself. (ecos 0.7.2 then carries on: it logs the error at debug level only,
    steps nothing and writes zeros; our calls after the failure return fmi2Error.)"""
    binary, _ = ecos
    shutil.copyfile(bundle["Gyro"] / "Gyro.fmu", tmp_path / "Gyro.fmu")
    proc = on_user_machine(["sh", "-c", f'cd "{tmp_path}" && exec "$@"', "sh", str(binary), "simulate", "--path",
                            "Gyro.fmu", "--stopTime", "1", "--stepSize", "0.1", "--noParallel", "-l", "debug"], [],
                           hide_all_python=True)
    assert proc.returncode >= 0, f"ecos died of signal {-proc.returncode}:\n{proc.stdout[-2000:]}"
    assert "fmi2Error" in proc.stdout and "found none it can use" in proc.stdout, proc.stdout[-2000:]
