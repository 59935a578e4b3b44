"""Property-based hardening of the command line (issue 30): every command driven with options and
files drawn from what a careless user or an attacker passes (missing, empty, binary, Latin-1,
damaged or wrong-kind files, folders, devices, names too long, /proc paths, numbers that are NaN,
huge, negative or not numbers, unknown names and choices). Each command either works (exit 0 or 1)
or refuses in one line (exit 2, "error: ..." and never "error: unexpected", exit 3); it leaves
nothing in $TMPDIR and changes none of the files it was given. The long applications (thesis,
de-orbit study, mission, propulsion, validation) and the campaign always get at least one bad
argument here, and must refuse it before their work starts: reaching a run's first step is a failure.
Runs in this process (about 0.1-0.5 s an example)."""
import hashlib
import os
import random
from pathlib import Path
import shutil
import stat
import tempfile
import zipfile

from hypothesis import HealthCheck, event, given, settings, strategies as st
import pytest

from system_ssp import cli
from system_ssp.master import system as system_module
from system_ssp.tools.campaign import runner


RANDOM = random.Random(30)  # the same "garbage" every run


class WorkStarted(BaseException):
    """Raised where a long command's work begins (a simulation run, a cluster)."""


@pytest.fixture(scope="module")
def files(ssp_paths, fmu_paths, tmp_path_factory):
    """Inputs of every kind in one folder (read-only to the commands: their hashes are checked)."""
    root = tmp_path_factory.mktemp("fuzz_inputs")
    f = {"ssp": ssp_paths["detumble"], "slew_ssp": ssp_paths["slew"], "fmu": fmu_paths["Gyro"],
         "fmu2": fmu_paths["RigidBody"], "missing": root / "missing.ssp", "folder": root / "folder",
         "proc": Path("/proc/self/status"), "null": root / "null",
         "by_name": Path("detumble"), "unknown_name": Path("nosuch")}  # built systems by name
    f["folder"].mkdir()
    os.mknod(f["null"], stat.S_IFCHR | 0o666, os.makedev(1, 3))
    for name, data in {"empty.ssp": b"", "garbage.ssp": RANDOM.randbytes(2000), "garbage.fmu": RANDOM.randbytes(2000),
                       "garbage.toml": RANDOM.randbytes(500),
                       "latin1.toml": "[campaign]\nx = 'caf\xe9'\n".encode("latin-1"),
                       "list.json": b"[1, 2]", "nan.json": b"NaN", "text.csv": "a,b\n1,x\n".encode(),
                       "garbage.ssd": b"<ssd:SystemStructureDescription", "garbage.ssv": b"<x/>",
                       "summary.json": b'{"scenario": "420km", "burn_propellant_kg": 0.5, "detumble_propellant_g": '
                                       b'1e400, "slew_propellant_g": 1, "tracking_propellant_g": 1}',
                       "spec.toml": f'[campaign]\nsystem = "{ssp_paths["detumble"]}"\nruns = 2\nseed = 1\n'
                                    'stop_time = 0.1\n[metrics]\nt = "stop_time"\n'.encode(),
                       "bad_spec.toml": b'[campaign]\nsystem = "detumble"\nruns = -2\nseed = 1\n[metrics]\n'
                                        b't = "stop_time"\n'}.items():
        (root / name).write_bytes(data)
        f[name] = root / name
    shutil.copy(ssp_paths["detumble"], root / "damaged.ssp")
    with zipfile.ZipFile(root / "damaged.ssp") as z:
        info = z.getinfo("SystemStructure.ssd")
    data = bytearray((root / "damaged.ssp").read_bytes())
    data[info.header_offset + 30 + len(info.filename) + len(info.extra) + 10] ^= 0xFF
    (root / "damaged.ssp").write_bytes(bytes(data))
    f["damaged.ssp"] = root / "damaged.ssp"
    assert cli.main(["run", str(ssp_paths["detumble"]), "--stop-time", "0.3", "--output", str(root / "r.csv"),
                     "--no-progress"]) == 0
    f["result"] = root / "r.csv"
    return f


def _hashes(paths):
    out = {}
    for p in paths:
        if isinstance(p, Path) and p.is_file() and not str(p).startswith("/proc"):
            out[p] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


NUMBERS = ["0.1", "0", "-1", "nan", "inf", "1e308", "-1e308", "abc", "", "1,5", "0x10"]
COUNTS = ["1", "2", "0", "-3", "1e12", "x", "99999999999999999999"]
NAMES = ["dynamics.omega0[1]", "dynamics.q_BN[1]", "detumble.enabled", "ghost.x", "dynamics", "", "a.b.c",
         "dynamics.omega0[99]", "thrusters.propellant_mass"]
SETS = ["dynamics.omega0[1]=0.1", "dynamics.omega0[1]=nan", "dynamics.omega0[1]=abc", "ghost.x=1", "nonsense",
        "dynamics.integrator=rk4", "dynamics.integrator=bogus", "=1"]


def _places(out):
    """Output places: new files of several formats, and places no command can write."""
    return [str(out / n) for n in ("r.csv", "r.parquet", "p.png", "p.html", "x.ssp", "x.json", "x.md", "d")] + \
        ["/proc/x/y.csv", "/proc/y.ssp", str(out / "missing" / "r.csv"), str(out / ("a" * 300 + ".csv")),
         str(out / "bad\nname.csv"), str(out), "relative_nowhere/x.csv"]


def _input(files, *kinds):
    return st.sampled_from([str(files[k]) for k in kinds])


def _options(data, table, label):
    """Draw a subset of `table` {option: strategy or None (a flag)} as an argument list."""
    argv = []
    for option, values in table.items():
        if data.draw(st.booleans(), label=f"{label} {option}?"):
            argv += [option] if values is None else [option, data.draw(values, label=option)]
    return argv


SYSTEMS = ("ssp", "slew_ssp", "by_name", "unknown_name", "fmu", "missing", "folder", "empty.ssp", "garbage.ssp",
           "garbage.ssd", "damaged.ssp", "proc", "null", "text.csv")


def command_line(data, files, out):
    """(argv, long): a command and its arguments; `long` for the commands whose work must not start."""
    places = st.sampled_from(_places(out))
    num, count = st.sampled_from(NUMBERS), st.sampled_from(COUNTS)
    command = data.draw(st.sampled_from(["run", "info", "replace", "compare", "flatten", "convert", "plot", "campaign",
                                         "thesis", "deorbit-study", "mission", "propulsion", "validation"]),
                        label="command")
    console = {"--quiet": None, "--log-level": st.sampled_from(["error", "debug", "loud"])}
    if command == "run":
        argv = [data.draw(_input(files, *SYSTEMS), label="system"), "--stop-time",
                data.draw(st.sampled_from(["0.05", "0.1", "0", "-1", "nan", "1e308", "abc"]), label="stop")]
        argv += _options(data, {
            "--step-size": st.sampled_from(["0.015", "0.05", "0", "-1", "nan", "1e308", "abc"]),
            "--start-time": num, "--set": st.sampled_from(SETS), "--ssv": _input(files, "garbage.ssv", "missing",
                                                                                  "folder", "list.json"),
            "--algorithm": st.sampled_from(["jacobi", "gauss-seidel", "newton"]),
            "--order": st.sampled_from(["dynamics,detumble,thrusters", "ghost", ",,", ""]),
            "--step-multiple": st.sampled_from(["dynamics=2", "dynamics=0", "ghost=2", "dynamics=x", "x"]),
            "--stop-when": st.sampled_from(NAMES), "--output": places,
            "--outputs": st.sampled_from(NAMES + ["dynamics.q_BN*", ",", "dynamics.omega_BN_B[1],ghost.y"]),
            "--record-every": count, "--print-final": None, "--plot": places, "--report": places,
            "--no-validate": None, "--no-schedule": None, "--profile": None, **console}, "run")
        return ["run"] + argv, False
    if command == "info":
        return ["info", data.draw(_input(files, *SYSTEMS), label="system")] + _options(
            data, {"--json": None, "--no-validate": None}, "info"), False
    if command == "replace":
        return ["replace", data.draw(_input(files, *SYSTEMS), label="system"),
                data.draw(st.sampled_from(["dynamics", "ghost", "", "detumble"]), label="component"),
                data.draw(_input(files, "fmu", "fmu2", "garbage.fmu", "missing", "ssp"), label="new"),
                "--out", data.draw(places, label="out")] + _options(data, {"--drop-unmatched": None}, "replace"), False
    if command == "compare":
        return ["compare", data.draw(_input(files, "fmu", "fmu2", "garbage.fmu", "missing", "ssp", "folder"),
                                     label="a"),
                data.draw(_input(files, "fmu", "fmu2", "garbage.fmu", "missing", "null"), label="b")] + _options(
            data, {"--json": None}, "compare"), False
    if command == "flatten":
        return ["flatten", data.draw(_input(files, *SYSTEMS), label="system"), "--out",
                data.draw(places, label="out")], False
    if command == "convert":
        return ["convert", data.draw(_input(files, *SYSTEMS), label="system"), "--ssp-version",
                data.draw(st.sampled_from(["2.0", "1.0", "3.0", ""]), label="version"), "--out",
                data.draw(places, label="out")], False
    if command == "plot":
        argv = ["plot", data.draw(_input(files, "result", "text.csv", "garbage.ssp", "missing", "folder", "null",
                                         "empty.ssp"), label="result")]
        argv += data.draw(st.lists(st.sampled_from(NAMES + ["time", "*", "["]), max_size=2), label="signals")
        return argv + _options(data, {"--out": places, "--title": st.sampled_from(["t", "", "\x00"])}, "plot"), False
    # the long ones: one argument at least is bad
    bad_place = st.sampled_from(["/proc/x/y", "/proc/y", str(out / "missing" / "x"), str(out / ("a" * 300)),
                                 str(files["proc"])])
    if command == "campaign":
        spec = data.draw(_input(files, "spec.toml", "bad_spec.toml", "garbage.toml", "latin1.toml", "missing",
                                "folder", "null"), label="spec")
        argv = ["campaign", spec, "--out", data.draw(st.sampled_from([str(out / "c")]) if spec.endswith("/spec.toml")
                                                     else places, label="out")]
        argv += _options(data, {"--workers": count, "--batch": count, "--rerun": count, "--quiet": None}, "campaign")
        if spec.endswith("/spec.toml"):  # a good spec: a bad option or place must stop it
            argv += data.draw(st.sampled_from([["--workers", "0"], ["--batch", "-1"], ["--scheduler", "no where"],
                                               ["--workers", "x"], ["--out", "/proc/x/c"], ["--rerun", "-5"],
                                               ["--rerun", "99"]]), label="bad")
        return argv, True
    tables = {
        "thesis": {"--integrator": st.sampled_from(["euler", "rk4", "rk45"]), "--slew-stop-time": num,
                   "--ssp-dir": _input(files, "folder", "missing", "ssp")},
        "deorbit-study": {"--model": st.sampled_from(["averaged", "cowell", "sgp4"]),
                          "--density": st.sampled_from(["msis", "exponential", "nonsense"]),
                          "--space-weather": st.sampled_from(["thesis", str(files["garbage.ssv"]),
                                                              str(files["missing"])]),
                          "--scenarios": st.sampled_from(["420km", "420km,999km", "", ","]),
                          "--max-years": num, "--out": bad_place, "--ssp-dir": _input(files, "folder", "missing")},
        "mission": {"--scenario": st.sampled_from(["420km", "999km"]), "--orbit": st.sampled_from(["averaged", "j2"]),
                    "--gnc": st.sampled_from(["thesis", "none"]), "--out": bad_place, "--max-years": num,
                    "--timeseries": st.sampled_from(["csv", "hdf5"]), "--ssv": _input(files, "garbage.ssv", "missing"),
                    "--set": st.sampled_from(SETS), "--ssp-dir": _input(files, "folder", "missing"), "--profile": None},
        "propulsion": {"--scenario": st.sampled_from(["420km", "999km"]),
                       "--mission": _input(files, "list.json", "nan.json", "summary.json", "missing", "folder",
                                           "latin1.toml"),
                       "--gnc": st.sampled_from(["thesis", "none"]), "--json": bad_place,
                       "--ssp-dir": _input(files, "folder", "missing")},
        "validation": {"--markdown": bad_place, "--json": bad_place, "--ssp-dir": _input(files, "folder", "missing")},
    }
    table = tables[command]
    argv = [command] + _options(data, {**table, **console}, command)
    forced = data.draw(st.sampled_from(sorted(o for o, v in table.items() if v is not None)), label="bad option")
    bad = {"--integrator": "rk45", "--slew-stop-time": "nan", "--ssp-dir": str(files["missing"]),
           "--model": "sgp4", "--density": "nonsense", "--space-weather": str(files["missing"]),
           "--scenarios": "420km,999km", "--max-years": "-1", "--out": "/proc/x/y", "--scenario": "999km",
           "--orbit": "j2", "--gnc": "none", "--timeseries": "hdf5", "--ssv": str(files["missing"]),
           "--set": "ghost.x=1", "--mission": str(files["list.json"]), "--json": "/proc/x/y.json",
           "--markdown": str(out / "missing" / "x.md")}[forced]
    return argv + [forced, bad], True


@settings(max_examples=400, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_every_command_works_or_refuses_in_one_line(files, tmp_path_factory, data, capsys, monkeypatch):
    out = tmp_path_factory.mktemp("fuzz_out")
    argv, long = command_line(data, files, out)

    def work(*args, **kwargs):
        raise WorkStarted(f"reached its work despite a bad argument: {argv}")

    before = _hashes(files.values())
    scratch = tempfile.mkdtemp(prefix="fuzz_tmp_")
    saved = tempfile.tempdir
    tempfile.tempdir = scratch
    try:
        with monkeypatch.context() as m:
            if long:
                m.setattr(system_module, "execute", work)  # after the run's plan (its checks), before a step
                m.setattr(runner, "_client", work)
                m.setattr(runner, "run_one", work)
            code = cli.main(argv)
        left = os.listdir(scratch)
    finally:
        tempfile.tempdir = saved
        shutil.rmtree(scratch, ignore_errors=True)
    err = capsys.readouterr().err
    event(f"{argv[0]}: exit {code}")  # --hypothesis-show-statistics shows how the examples ended
    lines = [line for line in err.splitlines() if line.strip()]
    assert code in (0, 1, 2), (argv, code, err)
    if code == 2:
        assert len(lines) == 1 and lines[0].startswith("error: ") and not lines[0].startswith("error: unexpected"), \
            (argv, err)
    assert not (long and code == 0), (argv, "a long command with a bad argument did not refuse it")
    assert left == [], (argv, left)
    assert _hashes(files.values()) == before, argv
    assert stat.S_ISCHR(files["null"].stat().st_mode)
