"""Campaigns (issue 13): the spec and its errors, per-run draws that depend on the seed and the
run index only, identical results with 1 and 2 Dask workers, resume, and a failing run kept as
a row (timeouts and crashed workers: tests/master/test_master_campaign.py)."""
import json
import tomllib

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from browser import open_page
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


def test_a_spec_extends_another_key_by_key(ssp_paths, tmp_path):
    """campaign.extends: the base's tables with the extending spec's entries over them (campaign
    keys, a dispersion and a probability replaced, a metric added); errors name the file and key."""
    _spec(tmp_path, DETUMBLE.format(system=ssp_paths["detumble"], runs=2), "base.toml")
    child = _spec(tmp_path, """
[campaign]
extends = "base.toml"
runs = 3
seed = 11
[dispersions."dynamics.omega0[1]"]
distribution = "uniform"
low = 0.0
high = 0.2
[metrics]
wy = "final:dynamics.omega_BN_B[2]"
[probabilities]
slow_x = "wmax > 0.2"
""", "child.toml")
    base = load_spec(tmp_path / "base.toml")
    assert (child.runs, child.seed, child.system, child.parameter_sets, child.stop_time) == (
        3, 11, base.system, base.parameter_sets, base.stop_time)
    assert child.parameters == base.parameters == {"dynamics.integrator": "rk4"}
    by_name = {d.name: d for d in child.dispersions}
    replaced = by_name["dynamics.omega0[1]"]
    assert (replaced.kind, replaced.args) == ("uniform", {"low": 0.0, "high": 0.2})
    assert by_name["detumble.Kp[1]"] == {d.name: d for d in base.dispersions}["detumble.Kp[1]"]
    assert [m.name for m in child.metrics] == [m.name for m in base.metrics] + ["wy"]
    assert child.probabilities == [("slow_x", "wmax", ">", 0.2)]
    assert child.text.startswith("\n[campaign]\nextends") and "# ---- campaign.extends: base.toml" in child.text
    assert tomllib.loads(child.text) == tomllib.loads((tmp_path / "child.toml").read_text())  # the base as comments
    for extends, pattern in (('"../base.toml"', r"child2.toml: campaign.extends = '../base.toml': expected the file "
                                                r"name of a campaign spec"),
                             ('"gone.toml"', r"campaign.extends = 'gone.toml': no such file"),
                             ('"child2.toml"', r"extend each other in a cycle")):
        with pytest.raises(SSPError, match=pattern):
            _spec(tmp_path, f"[campaign]\nextends = {extends}\n[metrics]\nend_s = \"stop_time\"\n", "child2.toml")


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
    # 1 s is too short for the detumble to settle: incomplete, without an end time
    assert all(r["status"] == "incomplete" and r["end_s"] is None for r in rows if r["detumble.Kp[1]"] != -1.0)
    assert s1["failed"] == s2["failed"] == len(failed) and s1["metrics"] == s2["metrics"]
    probability = json.loads((tmp_path / "one" / "summary.json").read_text())["probabilities"]["slow_x"]
    assert probability["n"] == s1["incomplete"]
    assert (tmp_path / "one" / "figures" / "scatter.png").stat().st_size > 5000
    dom, console = open_page(tmp_path / "one" / "report.html")  # one file, drawn by a real browser
    assert console == [] and dom.count('class="main-svg"') >= 2 and "success rate" in dom
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


@pytest.mark.parametrize("change, pattern", [
    (('"dynamics.integrator" = "rk4"', '"dynamics.integrater" = "rk4"'),
     r"spec.toml: parameters.dynamics.integrater: parameter 'dynamics.integrater': component 'dynamics' has no "
     r"variable 'integrater' \(did you mean 'integrator'"),
    (('wz = "final:dynamics.omega_BN_B[3]"', 'wz = "final:dynamics.omega_BN[3]"'),
     r"spec.toml: metrics.wz: output 'dynamics.omega_BN\[3\]': component 'dynamics' has no variable"),
    (('[sweep."dynamics.omega0[2]"]', '[sweep."dynamic.omega0[2]"]'),
     r"sweep.dynamic.omega0\[2\]: .*unknown component"),
    (('parameter_sets = ["parameters/detumble_case1.ssv"]', 'parameter_sets = ["parameters/detumble_case9.ssv"]'),
     r"spec.toml: parameter set 'parameters/detumble_case9.ssv': file not found"),
])
def test_names_are_checked_against_the_system_before_any_run(ssp_paths, tmp_path, change, pattern):
    """A misspelled name in the spec stops the campaign before its folder is made or a run starts,
    with the file, the key and the closest names (it used to run every run and exit 0)."""
    spec = _spec(tmp_path, DETUMBLE.format(system=ssp_paths["detumble"], runs=2).replace(*change))
    with pytest.raises(SSPError, match=pattern):
        run_campaign(spec, tmp_path / "out", workers=1)
    assert not (tmp_path / "out").exists()


def test_cli_exit_codes_say_how_the_campaign_went(ssp_paths, tmp_path, capsys):
    """exit 2 for a bad spec (before any run); exit 1 when no run succeeds, with the commonest
    error; exit 1 below campaign.min_success; resuming says what it kept."""
    from system_ssp.cli import main

    bad = tmp_path / "bad.toml"
    bad.write_text(DETUMBLE.format(system=ssp_paths["detumble"], runs=1).replace('"dynamics.integrator"',
                                                                                 '"dynamics.integrater"'))
    assert main(["campaign", str(bad), "--out", str(tmp_path / "bad"), "--workers", "1"]) == 2
    assert "did you mean 'integrator'" in capsys.readouterr().err
    failing = tmp_path / "failing.toml"
    failing.write_text(DETUMBLE.format(system=ssp_paths["detumble"], runs=1).replace("values = [100.0, 80.0, -1.0]",
                                                                                     "values = [-1.0]"))
    assert main(["campaign", str(failing), "--out", str(tmp_path / "failing"), "--workers", "1"]) == 1
    out = capsys.readouterr()
    assert "campaign failed: no run succeeded" in out.err and "2 run(s) failed with:" in out.out
    strict = tmp_path / "strict.toml"
    strict.write_text(DETUMBLE.format(system=ssp_paths["detumble"], runs=3).replace(
        "stop_time = 1.0", "stop_time = 1.0\nmin_success = 0.99"))
    assert main(["campaign", str(strict), "--out", str(tmp_path / "strict"), "--workers", "1"]) == 1
    assert "below campaign.min_success 0.99" in capsys.readouterr().err
    assert main(["campaign", str(strict), "--out", str(tmp_path / "strict"), "--workers", "1"]) == 1
    assert "6 of 6 runs already recorded there are kept, 0 to run" in capsys.readouterr().err


SETTLING = """
[campaign]
system = "{system}"
parameter_sets = ["parameters/detumble_case1.ssv"]
runs = 8
seed = 3
min_success = 0.8
[dispersions."dynamics.omega0[1]"]
distribution = "uniform"
low = -0.17
high = 0.17
[dispersions."dynamics.omega0[2]"]
distribution = "uniform"
low = -0.17
high = 0.17
[dispersions."dynamics.omega0[3]"]
distribution = "uniform"
low = -0.17
high = 0.17
[metrics]
t_done = "stop_time"
done = "final:detumble.done"
reason = "stop_reason"
[probabilities]
done_in_10s = "t_done <= 10"
"""


def test_a_run_whose_stop_condition_never_held_is_incomplete(ssp_paths, tmp_path, capsys):
    """Random tumbles up to 10 deg/s per axis with the shipped detumble law over its 20 s: the runs
    whose rates limit-cycle outside the band never raise detumble.done and reach the stop time.
    They are "incomplete", counted apart, without an end time, not successes for min_success, and
    in the probabilities as runs that did not detumble (not left out)."""
    from system_ssp.cli import main

    spec_path = tmp_path / "settling.toml"
    spec_path.write_text(SETTLING.format(system=ssp_paths["detumble"]))
    assert main(["campaign", str(spec_path), "--out", str(tmp_path / "out"), "--workers", "1"]) == 1
    out = capsys.readouterr()
    assert "6 ok, 2 incomplete (stop time reached before a stop condition held), 0 failed" in out.out
    assert "success rate 75.0 % is below campaign.min_success 0.8" in out.err
    rows = _rows(tmp_path / "out")
    incomplete = [r for r in rows if r["status"] == "incomplete"]
    assert [r["run"] for r in incomplete] == [2, 7]
    for r in incomplete:
        assert r["t_done"] is None and r["done"] is False and r["reason"] == "reached stop time" and r["error"] == ""
    for r in rows:
        if r["status"] == "ok":
            assert r["done"] is True and 0.0 <= r["t_done"] < 20.0 and r["reason"].startswith("stop condition")
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert (s["ok"], s["incomplete"], s["failed"], s["timeout"], s["success_rate"]) == (6, 2, 0, 0, 0.75)
    assert s["metrics"]["t_done"]["n"] == 6  # the end times there are
    p = s["probabilities"]["done_in_10s"]
    assert (p["k"], p["n"]) == (6, 8)  # the two that never settled count against it
    dom, console = open_page(tmp_path / "out" / "report.html")
    assert console == [] and "2 incomplete (stop time reached before a stop condition held)" in dom


DEORBIT = """
[campaign]
system = "{system}"
parameter_sets = ["parameters/deorbit_lifetime_420km.ssv"]
runs = 3
seed = 11
stop_time = 2592000.0
keep_timeseries = ["orbit.altitude"]
[dispersions."orbit.Cd"]
distribution = "uniform"
low = 2.0
high = 2.4
[metrics]
burn_s = "duration:burn"
coast_s = "duration:coast"
burning_s = "time_in:propulsion.burning"
sma = "final:orbit.sma"
"""


def test_durations_units_kept_series_and_rerun(ssp_paths, tmp_path, capsys):
    """Metrics of time spent (in a schedule mode, or with a signal true) with their units; each
    run's series kept and drawn as envelopes in the report; `--rerun N` gives run N again."""
    from system_ssp.cli import main

    spec = _spec(tmp_path, DEORBIT.format(system=ssp_paths["deorbit_lifetime"]))
    s = run_campaign(spec, tmp_path / "out", workers=1)
    assert s["incomplete"] == 3  # 30 days of a 420 km orbit: no re-entry (the system's stop condition)
    rows = _rows(tmp_path / "out")
    for r in rows:
        assert r["burn_s"] == pytest.approx(38.74 * 60.0, abs=60.0)  # the thesis' 38.74 min burn
        assert r["burn_s"] + r["coast_s"] == pytest.approx(2592000.0)
        assert abs(r["burning_s"] - r["burn_s"]) <= 30.0  # rows every 30 s in the burn
    assert s["metrics"]["sma"]["unit"] == "m" and s["metrics"]["burn_s"]["unit"] == "s"
    kept = sorted(p.name for p in (tmp_path / "out" / "series").iterdir())
    assert kept == [f"run-{i:06d}.parquet" for i in range(3)]
    report = (tmp_path / "out" / "report.html").read_text()
    assert "Envelopes over the runs" in report and "orbit.altitude p95" in report
    capsys.readouterr()
    assert main(["campaign", str(spec.path), "--out", str(tmp_path / "out"), "--rerun", "1"]) == 0
    out = capsys.readouterr().out
    assert f"sma = {rows[1]['sma']!r}" in out and f"burn_s = {rows[1]['burn_s']!r}" in out
    assert (tmp_path / "out" / "rerun" / "run-000001.parquet").is_file()
    bad = tmp_path / "bad.toml"
    bad.write_text(DEORBIT.format(system=ssp_paths["deorbit_lifetime"]).replace("duration:burn", "duration:burnn"))
    assert main(["campaign", str(bad), "--out", str(tmp_path / "bad")]) == 2
    assert "metrics.burn_s: duration:burnn: the system has no nc:Schedule mode 'burnn' (did you mean 'burn'" in \
        capsys.readouterr().err


def test_a_vector_dispersion_in_one_table(ssp_paths, tmp_path):
    """`elements = n`: name[1]..name[n] each drawn on its own (a column each), checked against the
    system like any other name."""
    text = DETUMBLE.format(system=ssp_paths["detumble"], runs=2).replace(
        '[dispersions."dynamics.omega0[1]"]', '[dispersions."detumble.Kd"]\nelements = 3')
    spec = _spec(tmp_path, text)
    assert [d.name for d in spec.dispersions][:3] == [f"detumble.Kd[{i}]" for i in (1, 2, 3)]
    _, values = spec.inputs(0)
    assert len({values[f"detumble.Kd[{i}]"] for i in (1, 2, 3)}) == 3  # three draws
    assert run_campaign(spec, tmp_path / "out", workers=1)["runs"] == 4
    bad = _spec(tmp_path, text.replace('[dispersions."detumble.Kd"]', '[dispersions."detumble.Kdd"]'), "bad.toml")
    with pytest.raises(SSPError, match=r"dispersions.detumble.Kdd\[1\]: parameter 'detumble.Kdd\[1\]'"):
        run_campaign(bad, tmp_path / "bad", workers=1)


FAULTS = """
[faults]
probability = 0.5
[faults.cases.weak_x]
"detumble.Kp[1]" = 5.0
[faults.cases.no_damping]
"detumble.Kp[2]" = 0.0
"detumble.Kp[3]" = 0.0
"""


def test_faults_one_case_in_a_share_of_the_runs(ssp_paths, tmp_path):
    """[faults]: with the probability, one case per run (its parameters over the draws), named in
    the `fault` column; the other draws are those of the spec without [faults]; a case's bad name
    is refused before any run, naming the case."""
    plain = _spec(tmp_path, DETUMBLE.format(system=ssp_paths["detumble"], runs=200), "plain.toml")
    spec = _spec(tmp_path, (DETUMBLE + FAULTS).format(system=ssp_paths["detumble"], runs=200))
    draws = [spec.inputs(i) for i in range(spec.total_runs)]
    faults = [v.pop("fault") for _, v in draws]
    assert draws == [plain.inputs(i) for i in range(plain.total_runs)]  # adding faults moves no other draw
    assert set(faults) == {"none", "weak_x", "no_damping"} and 0.4 < faults.count("none") / len(faults) < 0.6
    i = faults.index("no_damping")
    params = spec.overrides(spec.inputs(i)[1])
    assert params["detumble.Kp[2]"] == params["detumble.Kp[3]"] == 0.0 and "fault" not in params
    assert "detumble.Kp[2]" not in spec.overrides(spec.inputs(faults.index("none"))[1])
    small = _spec(tmp_path, (DETUMBLE + FAULTS).format(system=ssp_paths["detumble"], runs=2), "small.toml")
    summary = run_campaign(small, tmp_path / "out", workers=1)
    rows = _rows(tmp_path / "out")
    assert [r["fault"] for r in rows] == [small.inputs(i)[1]["fault"] for i in range(4)]
    assert sum(summary["faults"].values()) == 4
    for change, pattern in ((("probability = 0.5", "probability = 1.5"), r"probability = 1.5: expected a fraction"),
                            (("[faults.cases.weak_x]", "[faults.cases.none]"), r"faults.cases.none: \"none\" names")):
        with pytest.raises(SSPError, match=pattern):
            _spec(tmp_path, (DETUMBLE + FAULTS.replace(*change)).format(system=ssp_paths["detumble"], runs=2), "b.toml")
    misnamed = _spec(tmp_path, (DETUMBLE + FAULTS.replace('"detumble.Kp[1]"', '"detumble.Kq[1]"')).format(
        system=ssp_paths["detumble"], runs=2), "b.toml")
    with pytest.raises(SSPError, match=r"faults.cases.weak_x: .*Kq"):
        run_campaign(misnamed, tmp_path / "bad", workers=1)
    assert not (tmp_path / "bad" / "runs.parquet").exists()
