"""The master's life cycle under stress: memory over many runs, failures, interruptions and
output locations (issue 15)."""
import argparse
import csv
import gc
import json
import logging
import os
from pathlib import Path
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import REPO
import system_ssp
from system_ssp import SimulationError, SSPError
from system_ssp.tools.console import add_console_arguments, console_settings
from system_ssp.atomic import StagedFolder, atomic_write
from system_ssp.master import instances
from system_ssp.master.observers import ProgressBar, StepInfo
from system_ssp.master.plan import RunOptions
from system_ssp.master.planning import make_plan
from test_master_core import loop_system


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))


def _rss_kb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    pytest.skip("no /proc/self/status")


def _mapped(folder):
    with open("/proc/self/maps") as f:
        return sum(1 for line in f if str(folder) in line)


def _alive_instances():
    gc.collect()
    return sum(isinstance(o, instances.FmuInstance) for o in gc.get_objects())


def test_memory_flat_over_150_runs(fmus, tmp_path):
    """Every run frees its instances and unloads their libraries: no instance stays alive, memory
    stays flat (before: +23.8 MB and 453 live instances after 150 runs), nothing of a closed
    system stays mapped (before: 15 libraries per System)."""
    ssd = loop_system(tmp_path, fmus)
    with system_ssp.System(ssd) as system:
        for _ in range(10):  # warm-up: the first loads import the models
            system.run(step_size=0.01, stop_time=1)
        gc.collect()
        before = _rss_kb()
        for _ in range(150):
            system.run(step_size=0.01, stop_time=1)
        with pytest.raises(SimulationError):  # a failed run frees its instances too
            system.run(step_size=0.01, stop_time=1, parameters={"gain.k": 5.0, "gain.k_max": 2.0})
        gc.collect()
        growth = _rss_kb() - before
        folder = system._tmp
        assert _mapped(folder) == 0
    assert _alive_instances() == 0
    assert growth < 6000, f"RSS grew by {growth} kB over 150 runs"
    assert _mapped(folder) == 0


# ---- a failed run keeps what it computed (defect 4) -------------------------------------------
def test_failed_run_keeps_its_rows(fmus, tmp_path):
    """An FMU raising in its step from t = 0.5 s: the error carries the rows to 0.5 s (the last
    communication point reached) and the run's output file
    gets them as <name>.partial.csv (before: nothing, the 0.5 s computed were lost)."""
    ssd = loop_system(tmp_path, fmus)
    out = tmp_path / "res.csv"
    with pytest.raises(SimulationError, match=r"component 'integ'.*fixture failure at t=0.5 s") as err:
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1.0, outputs=["integ.x"], output_file=out,
                            parameters={"integ.fail_at": 0.5})
    r = err.value.result
    assert r is not None and r.partial and "failed at t=0.5 s" in r.stop_reason
    np.testing.assert_allclose(r.data["time"], np.arange(6) * 0.1, atol=1e-12)
    np.testing.assert_allclose(r.data["integ.x"], 1.1 ** np.arange(6), rtol=1e-12)
    assert err.value.partial_file == tmp_path / "res.partial.csv"
    assert not out.exists()
    lines = (tmp_path / "res.partial.csv").read_text().splitlines()
    assert lines[0] == "time,integ.x" and len(lines) == 7
    assert json.loads((tmp_path / "res.partial.units.json").read_text()) == {"time": "s", "integ.x": None}


def test_partial_results_place_is_checked_before_the_run(fmus, tmp_path):
    """Issue 54: a folder where x.partial.csv goes was found only when the run failed, and its
    refusal replaced the run's own failure (which component failed). Now refused before any step."""
    ssd = loop_system(tmp_path, fmus)
    (tmp_path / "res.partial.csv").mkdir()
    with pytest.raises(SSPError, match=r"partial-results file .*res\.partial\.csv: is a folder"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1.0, outputs=["integ.x"], output_file=tmp_path / "res.csv")


def test_a_partial_place_that_fails_late_keeps_the_runs_own_failure(fmus, tmp_path, monkeypatch):
    """The partial place turned into a folder during the run (after the check): the error is still
    the component's failure, and says the rows could not be kept."""
    import system_ssp.master.system as system_module

    ssd = loop_system(tmp_path, fmus)
    monkeypatch.setattr(system_module, "check_output_file", lambda path: path)  # as if it changed after
    (tmp_path / "res.partial.csv").mkdir()
    with pytest.raises(SimulationError, match=r"component 'integ'.*fixture failure at t=0.5 s") as err:
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1.0, outputs=["integ.x"], output_file=tmp_path / "res.csv",
                            parameters={"integ.fail_at": 0.5})
    assert err.value.partial_file is None
    assert "its rows could not be kept" in err.value.partial_note and "res.partial.csv" in err.value.partial_note


# ---- Ctrl-C and SIGTERM (defect 2) ------------------------------------------------------------
def _cli_env(tmpdir):
    return dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""), TMPDIR=str(tmpdir))


@pytest.mark.parametrize("signum, code, name", [(signal.SIGINT, 130, "SIGINT"), (signal.SIGTERM, 143, "SIGTERM"),
                                               (signal.SIGHUP, 129, "SIGHUP")])
def test_signal_stops_at_a_communication_point(fmus, tmp_path, signum, code, name):
    """A signal in the middle of a run (while a model's Python code runs) stops it at the next
    communication point: exit 128 + signal, 'interrupted at t = ...', the rows so far in
    .partial.csv, no output file, no temporary folder or file left (before: 'component ...
    fmi2GetReal returned status fatal', exit 2, 41 MB left in $TMPDIR)."""
    ssd = loop_system(tmp_path / "sys", fmus)
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    started = tmp_path / "started"
    out = tmp_path / "res.csv"
    proc = subprocess.Popen([sys.executable, "-m", "system_ssp", "run", str(ssd), "--step-size", "0.01",
                             "--stop-time", "1000", "--output", str(out), "--quiet",
                             "--set", "integ.step_delay=0.002", "--set", f"integ.touch_file={started}"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_cli_env(tmpdir))
    try:
        deadline = time.monotonic() + 60
        while not started.exists() and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        time.sleep(0.2)
        proc.send_signal(signum)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == code, stderr
    m = re.search(rf"interrupted \({name}\) at t = ([0-9.e+-]+) s", stderr)
    assert m and "Traceback" not in stderr and "fmi2" not in stderr, stderr
    partial = tmp_path / "res.partial.csv"
    assert "partial results" in stderr and str(partial) in stderr
    rows = partial.read_text().splitlines()
    assert len(rows) > 2 and float(rows[-1].split(",")[0]) == pytest.approx(float(m.group(1)))
    assert not out.exists()
    assert list(tmpdir.iterdir()) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res.partial.csv", "res.partial.units.json", "started",
                                                          "sys", "tmp"]


# ---- output locations are checked before the run (defect 1) -----------------------------------
def test_unwritable_output_refused_before_the_run(fmus, tmp_path):
    """Missing folder, a folder as the file, a file as the folder, an unwritable folder: one line,
    exit 2, before the first step (before: after the whole run, 'unexpected PermissionError')."""
    ssd = loop_system(tmp_path / "sys", fmus)
    (tmp_path / "afile").write_text("x")
    (tmp_path / "adir").mkdir()
    cases = [(tmp_path / "missing" / "r.csv", "folder .*missing does not exist"),
             (tmp_path / "adir", "is a folder"),
             (tmp_path / "afile" / "r.csv", "afile is not a folder"),
             (Path("/proc/r.csv"), "cannot write in /proc"),
             (tmp_path / "r.xlsx", "unknown format '.xlsx'")]
    for out, pattern in cases:
        with pytest.raises(SSPError, match=pattern):
            # a stop time whose run would take minutes: the refusal comes first
            system_ssp.simulate(ssd, step_size=0.01, stop_time=1e5, output_file=out,
                                parameters={"integ.step_delay": 0.01})
    p = subprocess.run([sys.executable, "-m", "system_ssp", "run", str(ssd), "--step-size", "0.01", "--output",
                        str(tmp_path / "missing" / "r.csv")], capture_output=True, text=True,
                       env=_cli_env(tmp_path), timeout=60)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "does not exist" in p.stderr


# ---- CSV a spreadsheet reads, units, Parquet (defect 7) ---------------------------------------
def test_csv_quoted_with_units_and_parquet(fmus, tmp_path):
    """Names with commas are quoted (RFC 4180: every row has as many fields as the header); the
    units go to a sidecar JSON and, for Parquet, into the schema metadata."""
    ssd = loop_system(tmp_path / "sys", fmus, units='<ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit>',
                      gain_conn='<ssd:Connector name="u" kind="input"><ssc:Real unit="m"/></ssd:Connector>'
                                '<ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector>')
    with system_ssp.System(ssd) as system:
        r = system.run(step_size=0.1, outputs=["integ.x", "gain.u", "thr.done"])
    renamed = r.data.copy()
    renamed.dtype.names = ("time", "dcm_BN[1,1]", 'say "hi"', "thr.done")
    units = {"time": "s", "dcm_BN[1,1]": None, 'say "hi"': "m", "thr.done": None}
    csv_file = tmp_path / "r.csv"
    system_ssp.write_result(renamed, csv_file, units)
    with open(csv_file, newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time", "dcm_BN[1,1]", 'say "hi"', "thr.done"]
    assert all(len(row) == 4 for row in rows) and len(rows) == 12
    assert csv_file.read_bytes().startswith(b'time,"dcm_BN[1,1]","say ""hi""",thr.done\r\n')
    assert json.loads((tmp_path / "r.units.json").read_text()) == units
    assert r.units["gain.u"] == "m" and r.units["time"] == "s"
    pq = pytest.importorskip("pyarrow.parquet")
    pq_file = tmp_path / "r.parquet"
    with system_ssp.System(ssd) as system:
        r = system.run(step_size=0.1, outputs=["integ.x", "gain.u", "thr.done"], output_file=pq_file)
    table = pq.read_table(pq_file)
    assert table.column_names == ["time", "integ.x", "gain.u", "thr.done"]
    np.testing.assert_array_equal(table.column("integ.x").to_numpy(), r.data["integ.x"])
    assert str(table.schema.field("thr.done").type) == "bool"
    assert table.schema.field("gain.u").metadata == {b"unit": b"m"}
    assert json.loads(table.schema.metadata[b"neighbor-cosim.units"])["gain.u"] == "m"


# ---- results folders as one unit (defect 6) ---------------------------------------------------
def test_staged_folder_replaces_as_one_unit(tmp_path):
    """A results folder appears complete or not at all; an earlier folder stays until the new one
    is complete; a stopped run's folder goes to <target>.partial, marked; modes follow the umask."""
    target = tmp_path / "results"
    target.mkdir()
    (target / "summary.json").write_text("old")
    (target / "old_only.png").write_text("old")
    staged = StagedFolder(target)
    with atomic_write(staged.path / "timeseries.csv") as f:
        f.write("new")
    assert (target / "summary.json").read_text() == "old"  # untouched while the new one is written
    staged.commit()
    assert sorted(p.name for p in target.iterdir()) == ["timeseries.csv"]
    old_umask = os.umask(0o022)
    try:
        staged = StagedFolder(target)
        with atomic_write(staged.path / "timeseries.csv") as f:
            f.write("part")
        partial = staged.commit_partial("interrupted (SIGINT) at t = 5 s")
    finally:
        os.umask(old_umask)
    assert partial == tmp_path / "results.partial"
    assert "interrupted (SIGINT) at t = 5 s" in (partial / "PARTIAL.txt").read_text()
    assert (partial / "timeseries.csv").stat().st_mode & 0o777 == 0o644
    assert partial.stat().st_mode & 0o777 == 0o755
    assert (target / "timeseries.csv").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results", "results.partial"]
    with pytest.raises(SSPError, match=r"results folder /proc/x: cannot write in /proc"):
        StagedFolder("/proc/x")
    (tmp_path / "afile").write_text("")
    with pytest.raises(SSPError, match="exists and is not a folder"):
        StagedFolder(tmp_path / "afile")


# ---- the progress bar speaks the user's units (defect 9) --------------------------------------
def test_progress_bar_units_and_totals(fmus, tmp_path):
    """Simulated time in s, days or years by the span; a total (and so a percentage and an ETA)
    only when the run will reach its stop time; the ETA from the average rate (smoothing 0)."""
    ssd = loop_system(tmp_path, fmus)
    with system_ssp.System(ssd) as system:
        for stop, step, unit in ((100.0, 0.1, "s"), (10 * 86400.0, 3600.0, "d"), (5 * 3.15576e7, 86400.0, "yr")):
            bar = ProgressBar(make_plan(system, RunOptions(stop_time=stop, step_size=step)))
            bar.start(StepInfo(0.0, 1))
            try:
                assert bar.unit == unit and bar.bar.total == pytest.approx(stop / bar.scale)
                assert bar.bar.smoothing == 0
                info = StepInfo(stop / 2, 1)
                info.steps = bar.chunk
                bar.step(info)
                assert bar.bar.n == pytest.approx(stop / 2 / bar.scale)
            finally:
                bar.close()
        bar = ProgressBar(make_plan(system, RunOptions(stop_time=100.0, step_size=0.1, stop_when=["thr.done"])))
        bar.start(StepInfo(0.0, 1))
        try:
            assert bar.bar.total is None  # may stop before 100 s: no percentage, no ETA
        finally:
            bar.close()


def test_progress_default_follows_the_terminal(monkeypatch):
    ap = argparse.ArgumentParser()
    add_console_arguments(ap)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert console_settings(ap.parse_args([])) is True
    assert console_settings(ap.parse_args(["--quiet"])) is False
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False, raising=False)
    assert console_settings(ap.parse_args([])) is False
    assert console_settings(ap.parse_args(["--progress"])) is True
    assert console_settings(ap.parse_args(["--log-level", "info"])) is False
    assert logging.getLogger("system_ssp").level == logging.INFO
    console_settings(ap.parse_args([]))
    assert logging.getLogger("system_ssp").level == logging.WARNING


def test_progress_bar_never_looks_hung(fmus, tmp_path, capsys):
    """The bar's clock moves every second even while one step takes seconds (it used to freeze for
    45 s in the mission's de-orbit), and a scheduled run shows its mode, the time in it and the
    steps per second."""
    import time

    ssd = loop_system(tmp_path, fmus)
    with system_ssp.System(ssd) as system:
        bar = ProgressBar(make_plan(system, RunOptions(stop_time=5 * 3.15576e7, step_size=86400.0)))
    bar.chunk = 1  # every step, as in a scheduled run
    info = StepInfo(0.0, 1)
    info.mode = "coast"
    bar.start(info)
    try:
        time.sleep(3.3)  # a step that takes seconds: no update() call at all
        frames = [f for f in capsys.readouterr().err.split("\r") if "yr" in f]
        assert {"00:01", "00:02", "00:03"} <= {re.search(r"(\d\d:\d\d)", f).group(1) for f in frames}, frames
        for k, (mode, t) in enumerate((("coast", 86400.0), ("detumble", 86400.0 + 0.015), ("detumble", 86400.03))):
            info = StepInfo(t, 1)
            info.steps, info.mode, info.mode_changed = k + 1, mode, k == 1
            bar.step(info)
            time.sleep(0.6)
        assert "detumble for 0.015 s" in bar.bar.postfix and "steps/s" in bar.bar.postfix
    finally:
        bar.close()
