"""Campaigns (issue 13): the spec and its errors, per-run draws that depend on the seed and the
run index only, identical results with 1 and 2 Dask workers, resume, and a failing run kept as
a row (timeouts and crashed workers: tests/master/test_master_campaign.py)."""
import json

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from system_ssp import SSPError
from system_ssp.tools.campaign import load_spec, run_campaign
from system_ssp.tools.campaign.runner import wilson

DETUMBLE = """
[campaign]
system = "{system}"
parameter_sets = ["parameters/detumble_case1.ssv"]
runs = {runs}
seed = 7
stop_time = 1.0
[parameters]
"dynamics.integrator" = "rk4"
[dispersions."dynamics.omega0[1]"]
distribution = "normal"
mean = 0.1
std = 0.02
[dispersions."detumble.Kp[1]"]
distribution = "choice"
values = [100.0, 80.0, -1.0]
[sweep."dynamics.omega0[2]"]
values = [0.05, 0.1]
[metrics]
end_s = "stop_time"
wz = "final:dynamics.omega_BN_B[3]"
wmax = "max:dynamics.omega_BN_B[1]"
[probabilities]
slow_x = "wmax > 0.1"
"""


def _spec(tmp_path, text, name="spec.toml"):
    path = tmp_path / name
    path.write_text(text)
    return load_spec(path)


def _rows(folder):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in pq.read_table(folder / "runs.parquet").to_pylist()]


@pytest.mark.parametrize("change, pattern", [
    (("runs = {runs}", "runs = 0"), r"spec.toml: campaign.runs = 0: expected an integer > 0"),
    (('distribution = "normal"', 'distribution = "gauss"'),
     r"dispersions.'dynamics.omega0\[1\]'.distribution = 'gauss': expected one of uniform, normal"),
    (("std = 0.02", "sigma = 0.02"), r"\(normal\) needs mean, std; missing std; unknown sigma"),
    (('slow_x = "wmax > 0.1"', 'slow_x = "vmax > 0.1"'), r"probabilities.slow_x = 'vmax > 0.1': expected"),
    (("[metrics]", "[metric]"), r"unknown table\(s\) metric"),
    (('end_s = "stop_time"', 'end_s = "last:orbit.sma"'), r"metrics.end_s = 'last:orbit.sma': expected"),
    (("[metrics]", '[dispersions."dynamics.omega0[3]"]\ndistribution = "integers"\nlow = 0\nhigh = 2.5\n[metrics]'),
     r"omega0\[3\]'.high = 2.5: expected an integer"),
])
def test_spec_errors_name_file_key_and_allowed(ssp_paths, tmp_path, change, pattern):
    text = DETUMBLE.replace(*change).format(system=ssp_paths["detumble"], runs=2)
    with pytest.raises(SSPError, match=pattern):
        _spec(tmp_path, text)
    with pytest.raises(SSPError, match=r"campaign.system = 'nope': no such file"):
        _spec(tmp_path, DETUMBLE.format(system="nope", runs=2))


def test_draws_depend_on_seed_and_index_only(ssp_paths, tmp_path):
    spec = _spec(tmp_path, DETUMBLE.format(system="detumble", runs=3))
    assert spec.total_runs == 6 and spec.system == ssp_paths["detumble"].resolve()
    forward = [spec.inputs(i) for i in range(6)]
    assert [spec.inputs(i) for i in reversed(range(6))] == forward[::-1]
    assert [v["dynamics.omega0[2]"] for _, v in forward] == [0.05] * 3 + [0.1] * 3  # sweep point = index // runs
    assert len({s for s, _ in forward}) == 6
    seed_table = '[dispersions."gyro.seed"]\ndistribution = "integers"\nlow = 1\nhigh = 3\n[metrics]'
    seeded = _spec(tmp_path, DETUMBLE.replace("[metrics]", seed_table).format(system="detumble", runs=60), "s.toml")
    seeds = [seeded.inputs(i)[1]["gyro.seed"] for i in range(60)]
    assert set(seeds) == {1, 2, 3} and all(type(x) is int for x in seeds)  # both ends, integers
    assert wilson(0, 10)[0] == 0.0 and wilson(10, 10)[1] == pytest.approx(1.0)
    assert wilson(5, 10)[0] < 0.5 < wilson(5, 10)[1]


def test_one_and_two_workers_give_the_same_rows_and_resume_skips(ssp_paths, tmp_path):
    spec = _spec(tmp_path, DETUMBLE.format(system=ssp_paths["detumble"], runs=3))
    s1 = run_campaign(spec, tmp_path / "one", workers=1)
    s2 = run_campaign(spec, tmp_path / "two", workers=2, batch=2)  # two runs per task: the same rows
    assert _rows(tmp_path / "one") == _rows(tmp_path / "two")
    rows = _rows(tmp_path / "one")
    assert [r["run"] for r in rows] == list(range(6))
    failed = [r for r in rows if r["detumble.Kp[1]"] == -1.0]
    assert failed and all(r["status"] == "failed" and "component 'detumble'" in r["error"] for r in failed)
    assert all(r["status"] == "ok" and r["end_s"] == 1.0 for r in rows if r["detumble.Kp[1]"] != -1.0)
    assert s1["failed"] == s2["failed"] == len(failed) and s1["metrics"] == s2["metrics"]
    assert json.loads((tmp_path / "one" / "summary.json").read_text())["probabilities"]["slow_x"]["n"] == s1["ok"]
    assert (tmp_path / "one" / "figures" / "scatter.png").stat().st_size > 5000
    # an interrupted campaign: only the first 2 runs were recorded; the same spec resumes
    parts = sorted((tmp_path / "two" / "runs").glob("part-*.parquet"))
    table = pa.concat_tables([pq.read_table(p) for p in parts])
    first = table.filter(pc.less(table["run"], pa.scalar(2, table.schema.field("run").type)))
    for p in parts:
        p.unlink()
    pq.write_table(first, tmp_path / "two" / "runs" / "part-0000000-0.parquet")
    s3 = run_campaign(spec, tmp_path / "two", workers=2)
    assert s3["resumed_from"] == 2 and s3["runs"] == 6
    assert _rows(tmp_path / "two") == rows
    # a different spec is not mixed into these results
    other = _spec(tmp_path, DETUMBLE.format(system=ssp_paths["detumble"], runs=4), "other.toml")
    with pytest.raises(SSPError, match="holds the results of another campaign spec"):
        run_campaign(other, tmp_path / "two", workers=1)
