"""Campaign failure isolation on the fixture FMUs: a run past its timeout and a run whose FMU
ends its worker process are rows with their status; the campaign goes on."""
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from master_fixtures import helpers as h
from system_ssp.tools.campaign import load_spec, run_campaign
from test_master_core import loop_system


def _spec(tmp_path, text):
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return load_spec(path)


def _rows(folder):
    return pq.read_table(folder / "runs.parquet").to_pylist()


def test_timeout_and_a_crashed_worker_are_rows(tmp_path, tmp_path_factory):
    """A run past timeout_s is 'timeout'; a run whose FMU ends its process is 'failed' (its worker
    is replaced) and the campaign goes on."""
    fmus = h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))
    ssd = loop_system(tmp_path / "sys", fmus)
    spec = _spec(tmp_path, f"""
[campaign]
system = "{ssd}"
runs = 4
seed = 1
stop_time = 2.0
step_size = 0.1
timeout_s = 0.5
[parameters]
"gain.k" = 0.5
[dispersions."integ.crash_at"]
distribution = "choice"
values = [-1.0, 0.3]
[dispersions."integ.step_delay"]
distribution = "choice"
values = [0.0, 0.05]
[metrics]
x = "final:integ.x"
""")
    # two runs per task: a crash takes its task-mate down, which is then run alone and gets through
    s = run_campaign(spec, tmp_path / "out", workers=2, batch=2)
    rows = _rows(tmp_path / "out")
    assert len(rows) == 4 and s["runs"] == 4
    for r in rows:
        if r["integ.crash_at"] >= 0:
            assert r["status"] == "failed" and "worker running it died" in r["error"]
        elif r["integ.step_delay"] > 0:
            assert r["status"] == "timeout" and "wall-clock limit of 0.5 s" in r["error"]
        else:
            assert r["status"] == "ok" and r["x"] == pytest.approx(1.05 ** 20, rel=1e-12)
    assert {r["status"] for r in rows} == {"ok", "failed", "timeout"}
    assert Path(tmp_path / "out" / "environment.json").is_file()
