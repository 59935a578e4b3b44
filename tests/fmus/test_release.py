"""The product outside the checkout (issue 31): where the built FMUs and systems live, systems by
name (built on first use), the FMUs' GUID and version from the product version, and the release
bundle (`neighbor-cosim export`). The wheel itself is installed and run outside the checkout by
.ci/wheel."""
import fcntl
import hashlib
import os
from pathlib import Path
import shutil
import subprocess
import sys
import time
import zipfile

import fmpy
from fmpy.validation import validate_fmu
import pytest

from paths import REPO
import system_ssp
from system_ssp import SSPError, builder, cli, locations
from system_ssp.tools import release

from test_hosts import CLEAN_ENV, extract, fmpy_values, plan, run_host


def command(*args, env=None, cwd=None):
    return subprocess.run([sys.executable, "-m", "system_ssp", *args], capture_output=True, text=True, timeout=300,
                          env={**os.environ, **(env or {})}, cwd=cwd)


def test_build_folder_is_the_checkouts_or_the_one_named():
    """build/ in a checkout; NEIGHBOR_COSIM_BUILD wins everywhere."""
    chosen = os.environ.get("NEIGHBOR_COSIM_BUILD")
    assert locations.is_checkout() and locations.BUILD == (Path(chosen).resolve() if chosen else REPO / "build")
    probe = "from system_ssp import locations; print(locations.BUILD)"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         env={**os.environ, "NEIGHBOR_COSIM_BUILD": "/tmp/somewhere/else"}).stdout
    assert out.strip() == "/tmp/somewhere/else"


def test_systems_by_name_in_the_api(ssp_paths):
    """system_ssp.simulate("detumble") from the API, as the README's snippet does; names that are
    no shipped system are refused with the list; a missing file is named."""
    r = system_ssp.simulate("detumble", stop_time=0.03)
    assert r.steps == 2
    with pytest.raises(SSPError, match=r"detumbl: no such file, and no system of that name \(systems: acs_modes, "):
        system_ssp.System("detumbl")
    with pytest.raises(SSPError, match=r"nowhere/slew.ssp: file not found"):
        builder.resolve_system("nowhere/slew.ssp")


def _fmus_built_systems_not(tmp_path):
    """A build folder with this session's FMUs (and build state) but no packed systems."""
    folder = tmp_path / "build"
    folder.mkdir()
    for part in ("fmus", "runtime"):
        shutil.copytree(locations.BUILD / part, folder / part)
    shutil.copy(locations.BUILD / "build-state.json", folder)
    return folder


def test_a_missing_system_is_built_on_first_use(built, tmp_path):
    """A build folder whose FMUs are there but whose systems are not: the first command that
    needs one builds what is missing, says so in one line, and runs; the next says nothing."""
    folder = _fmus_built_systems_not(tmp_path)
    env = {"NEIGHBOR_COSIM_BUILD": str(folder)}
    first = command("run", "detumble", "--stop-time", "0.03", "--quiet", env=env, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert first.stderr.strip() == (f"neighbor-cosim: the FMUs and systems are not built yet; building them into "
                                    f"{folder} (once per version, under a minute; `neighbor-cosim build` does it "
                                    "ahead)")
    assert "steps:       2" in first.stdout
    assert sorted(p.stem for p in (folder / "ssp").glob("*.ssp")) == locations.system_names()
    again = command("info", "slew", env=env, cwd=tmp_path)
    assert again.returncode == 0 and again.stderr == ""


def test_a_command_that_finds_a_build_under_way_waits_for_it(built, tmp_path):
    """Two commands that find the systems missing at once (two terminals, two campaign clients)
    take turns on the build folder's lock: while another holds it, nothing is packed; once it is
    released the waiting command builds, runs, and every packed system is whole."""
    folder = _fmus_built_systems_not(tmp_path)
    env = {**os.environ, "NEIGHBOR_COSIM_BUILD": str(folder)}
    with open(folder / ".build.lock", "a+") as lock:
        fcntl.flock(lock.fileno(), fcntl.LOCK_EX)  # another build under way
        proc = subprocess.Popen([sys.executable, "-m", "system_ssp", "info", "slew"], stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
        assert "not built yet" in proc.stderr.readline()  # it is about to build
        time.sleep(5.0)  # unlocked, it would have packed systems by now (about one a second here)
        assert proc.poll() is None and not list(folder.glob("ssp/*.ssp"))
    assert proc.wait(timeout=300) == 0, proc.stderr.read()
    assert sorted(p.name for p in (folder / "ssp").iterdir()) == [f"{n}.ssp" for n in locations.system_names()]
    for ssp in folder.glob("ssp/*.ssp"):
        with zipfile.ZipFile(ssp) as z:
            assert z.testzip() is None and "SystemStructure.ssd" in z.namelist()


def test_a_build_folder_that_cannot_be_written_is_one_line(tmp_path):
    """The build folder under a file: the command that would build says so in one line (exit 2;
    `build` exits 1 like a failed build) and names the way out."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    env = {"NEIGHBOR_COSIM_BUILD": str(blocker / "build")}
    for args, code in ((("run", "detumble"), 2), (("build",), 1)):
        proc = command(*args, env=env, cwd=tmp_path)
        last = proc.stderr.strip().splitlines()[-1]
        assert proc.returncode == code, proc.stderr
        assert str(blocker / "build") in last and "NEIGHBOR_COSIM_BUILD=DIR builds into another folder" in last
    assert blocker.read_text() == ""


def test_guid_and_version_carry_the_product_version(build_one, tmp_path, monkeypatch):
    """The same code built as another product version: model description version and GUID both change."""
    current = build_one("neighbor_gyro.py")
    monkeypatch.setattr(builder, "__version__", "9.8.7")
    other = builder.build_fmu(builder.FMU_SOURCES / "neighbor_gyro.py", tmp_path)
    a, b = fmpy.read_model_description(str(current)), fmpy.read_model_description(str(other))
    assert a.version == system_ssp.__version__ and b.version == "9.8.7"
    assert a.guid != b.guid


def test_export_bundle(built, c_host, tmp_path, capsys):
    """`neighbor-cosim export`: one versioned archive with every FMU (and its compatibility
    information), every system, the reference pages, the licence, a README naming each FMU's
    GUID, and checksums; its FMUs validate and run in the C host with no Python in its
    environment; a second export writes the same bytes."""
    fmu_paths, ssp_paths = built
    assert cli.main(["export", "--out", str(tmp_path / "release")]) == 0
    target = tmp_path / "release" / f"neighbor-cosim-{system_ssp.__version__}-fmi.zip"
    assert f"{target}: 52 FMUs (and 52 as FMI 3.0), 17 systems" in capsys.readouterr().out
    top = f"neighbor-cosim-{system_ssp.__version__}-fmi/"
    with zipfile.ZipFile(target) as z:
        files = {name[len(top):]: z.read(name) for name in z.namelist()}
        assert all(name.startswith(top) for name in z.namelist())
    assert len(fmu_paths) == 52
    for name, path in fmu_paths.items():
        assert files[f"fmus/{name}/{name}.fmu"] == path.read_bytes(), name
        assert {f"fmus/{name}/{name}_ref.csv", f"fmus/{name}/{name}_ref.opt", f"fmus/{name}/README.md",
                f"reference/{name}.md"} <= set(files), name
        guid = fmpy.read_model_description(str(path)).guid
        assert f"| `{name}` | `{guid}` |" in files["README.md"].decode()
        fmu3 = path.parent.parent / "fmus3" / path.name  # its FMI 3.0 twin, with the same reference columns
        assert files[f"fmus3/{name}/{name}.fmu"] == fmu3.read_bytes(), name
        assert files[f"fmus3/{name}/{name}_ref.csv"].split(b"\n")[0] == files[f"fmus/{name}/{name}_ref.csv"].split(
            b"\n")[0], name
    for name, path in ssp_paths.items():
        assert files[f"systems/{name}.ssp"] == path.read_bytes(), name
    assert files["LICENSE"] == (REPO / "LICENSE").read_bytes()
    sums = dict(reversed(line.split("  ", 1)) for line in files["SHA256SUMS"].decode().splitlines())
    assert set(sums) == set(files) - {"SHA256SUMS"}
    assert all(hashlib.sha256(files[name]).hexdigest() == digest for name, digest in sums.items())

    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(target) as z:
        z.extractall(folder)
    for name in ("RigidBody", "Orbit", "MissionManager"):  # every FMU runs in the C host in test_hosts
        fmu = folder / top / "fmus" / name / f"{name}.fmu"
        assert validate_fmu(str(fmu)) == []
        unzipped = extract(fmu, tmp_path / f"x_{name}")
        guid, model, opts, outputs = plan(fmu)
        proc = run_host(c_host, unzipped, model, guid, opts, env=CLEAN_ENV)
        assert proc.returncode == 0 and "DONE failures=0" in proc.stdout, proc.stdout[-2000:]
        got = [float(line.split()[2]) for line in proc.stdout.splitlines() if line.startswith("GET ")]
        expected = fmpy_values(fmu, unzipped, outputs, opts[:3] if opts[:1] == ["--set-real"] else [])
        assert got == pytest.approx(list(expected) * 2, rel=1e-12, abs=0), name

    first = target.read_bytes()
    assert release.export(tmp_path / "release") == target
    assert target.read_bytes() == first


def test_export_refuses_an_output_it_cannot_write(tmp_path, capsys):
    """--out a file: one line, exit 2, nothing replaced."""
    occupied = tmp_path / "occupied"
    occupied.write_text("keep")
    assert cli.main(["export", "--out", str(occupied)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out" in err and "not a folder" in err
    assert occupied.read_text() == "keep"
