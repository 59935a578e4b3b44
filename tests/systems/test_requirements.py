"""Requirements with verdicts (issue 58): the file and its refusals, the checks' language, the
exact binomial bounds (against scipy), the verdicts of one run (`run --requirements`) and of a
campaign (`campaign --requirements`: an inconclusive probability says how many more runs decide
it), in the table, the summary JSON, the report (headless Chromium) and JUnit XML (parsed). The
mission's: tests/systems/test_mission_system.py (the shipped NEIGHBOR file)."""
import json
import math
from pathlib import Path
import xml.etree.ElementTree as ET

import pytest
from scipy import stats

from browser import open_page
from system_ssp import SSPError
from system_ssp.cli import main
from system_ssp.neighbor import mission
from system_ssp.tools import requirements as req
from system_ssp.tools.campaign import load_spec

from test_campaign import SETTLING  # noqa: E402  (the detumble campaign whose runs settle or not)

RUN_FILE = """
[values]
rate_limit = 0.2618           # rad/s: 15 deg/s

[[requirement]]
id = "DET-1"
text = "The detumble settles within 10 s."
source = "thesis section 3.3.3"
check = "detumble.done and stop_time < 10 s"

[[requirement]]
id = "DET-2"
text = "The x rate stays within 15 deg/s."
source = "ours"
check = "max(dynamics.omega_BN_B[1]) <= 15 deg and abs(min(dynamics.omega_BN_B[1])) <= rate_limit"

[[requirement]]
id = "DET-3"
text = "The detumble settles within 5 s."
source = "ours"
check = "stop_time <= 5 s"

[[requirement]]
id = "DET-4"
text = "Judged by campaigns only."
source = "ours"
probability = "P(done) >= 0.9 at 90 %"
"""


def _file(tmp_path, text, name="req.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, pattern", [
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\n", r"req.toml:1: requirement 'A' has neither a check"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\ncheck = 'x <'\n",
     r"req.toml:5: requirement 'A': check: 'x <' is not an expression"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\ncheck = \"__import__('os')\"\n",
     r"unknown function __import__\(\)"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\ncheck = 'x.y if a else b'\n", r"is not allowed"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\nprobability = 'P(x) >= 1.5'\n",
     r"req.toml:5: requirement 'A': probability: .* must be between 0 and 1"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\nprobability = 'x >= 0.5'\n", r"expected 'P\(<check>\)"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = ''\ncheck = 'x'\n", r"source must be a non-empty text"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\ncheck = 'x'\n[[requirement]]\nid = 'A'\ntext = 't'\n"
     "source = 's'\ncheck = 'y'\n", r"req.toml:6: requirement id 'A' is also the id at line 1"),
    ("[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\ncheck = 'x'\nlevel = 3\n", r"level unknown"),
    ("[values]\nx = 'big'\n[[requirement]]\nid = 'A'\ntext = 't'\nsource = 's'\ncheck = 'x'\n",
     r"values.x = 'big': expected a finite number"),
    ("[requirement]\nid = 'A'\n", r"no \[\[requirement\]\]"),
])
def test_a_bad_file_is_one_line_naming_the_line(tmp_path, text, pattern):
    with pytest.raises(SSPError, match=pattern):
        req.load(_file(tmp_path, text))


def test_checks_read_names_signals_and_numbers_with_units():
    c = req.parse_check("reentered and end_s - burn_start_s < 5 y and max(a.b[2]) <= 0.5 deg and 100 kB > x")
    assert c.names == ("reentered", "end_s", "burn_start_s", "x") and c.signals == (("max", "a.b[2]"),)
    values = {"reentered": True, "end_s": 3.0 * 365.25 * 86400.0, "burn_start_s": 0.0, "x": 99e3}.get
    holds, compared = req.evaluate(c, values, lambda fn, name: math.radians(0.4))
    assert holds and [round(x["margin"], 6) for x in compared] == [round(2 * 365.25 * 86400.0, 6),
                                                                   round(math.radians(0.1), 6), 1000.0]
    # short-circuit: a run that never re-entered has no end time, and fails without it
    holds, _ = req.evaluate(c, {"reentered": False}.get, lambda fn, name: None)
    assert holds is False
    with pytest.raises(req.Missing, match="end_s"):
        req.evaluate(c, {"reentered": True, "burn_start_s": 0.0}.get, lambda fn, name: None)
    assert req.evaluate(req.parse_check("1 < x <= 3"), {"x": 3.0}.get, None)[0]
    assert not req.evaluate(req.parse_check("1 < x <= 3"), {"x": 4.0}.get, None)[0]
    assert req.evaluate(req.parse_check("soc >= 50 %"), {"soc": 0.5}.get, None)[0]


@pytest.mark.parametrize("k, n, confidence", [(10, 10, 0.95), (0, 10, 0.95), (5, 10, 0.9), (298, 300, 0.95),
                                              (99, 100, 0.99), (1, 2000, 0.95), (1999, 2000, 0.999)])
def test_clopper_pearson_bounds_are_scipys(k, n, confidence):
    lo, hi = req.clopper_pearson(k, n, confidence)
    assert lo == pytest.approx(0.0 if k == 0 else stats.beta.ppf(1 - confidence, k, n - k + 1), abs=1e-12)
    assert hi == pytest.approx(1.0 if k == n else stats.beta.ppf(confidence, k + 1, n - k), abs=1e-12)


def test_runs_to_decide():
    # the success-run rule: 299 runs without a failure show 0.99 at 95 % (ln 0.05 / ln 0.99 = 298.07)
    assert req.runs_to_decide(10, 10, ">=", 0.99, 0.95) == 289
    assert req.clopper_pearson(299, 299, 0.95)[0] >= 0.99 > req.clopper_pearson(298, 298, 0.95)[0]
    more = req.runs_to_decide(9, 10, ">=", 0.99, 0.95)  # 90 %: the upper bound falls below 0.99
    assert req.clopper_pearson(round(0.9 * (10 + more)), 10 + more, 0.95)[1] < 0.99
    assert req.runs_to_decide(9, 10, ">=", 0.9, 0.95) is None  # the rate is the required one


def test_campaign_rows_that_failed_or_lack_a_value_count_against_it():
    reqs = req.Requirements(Path("r.toml"), [req.Requirement("A", "t", "s", probability=req.parse_probability(
        "P(x < 1) >= 0.5 at 90 %"))])
    rows = [{"status": "ok", "x": 0.5}] * 6 + [{"status": "incomplete", "x": None}, {"status": "failed", "x": None},
                                                {"status": "timeout", "x": None}, {"status": "ok", "x": 2.0}]
    (v,) = req.judge_campaign(reqs, rows)
    assert (v["k"], v["n"]) == (6, 10)
    assert "(2 failed or timed out and 1 without a value it needs: counted as not meeting it)" in v["evidence"]
    assert req.judge_campaign(reqs, [])[0]["verdict"] == "ERROR"
    (v,) = req.judge_run(req.Requirements(Path("r.toml"), [req.Requirement("B", "t", "s", check=req.parse_check(
        "x < 1"))]), {"x": 0.5}, None, error="component 'a' failed at t = 3 s")
    assert v["verdict"] == "ERROR" and v["evidence"] == "the run failed: component 'a' failed at t = 3 s"


def test_run_verdicts_table_junit_and_report(ssp_paths, tmp_path, capsys):
    path = _file(tmp_path, RUN_FILE)
    system = str(ssp_paths["detumble"])
    junit, report = tmp_path / "run.xml", tmp_path / "run.html"
    args = ["run", system, "--requirements", str(path), "--junit", str(junit), "--report", str(report),
            "--outputs", "dynamics.q_BN[4]"]  # the signals the checks read are recorded besides
    assert main(args) == 1  # DET-3 fails
    out = capsys.readouterr()
    assert "requirements (" in out.out and ": 2 PASS, 1 FAIL" in out.out
    assert "DET-3  FAIL          stop_time <= 5 s" in out.out
    assert "stop_time = 9.96 is not <= 5 (margin -4.96)" in out.out
    assert "DET-4  not judged    no check: judged by campaigns" in out.out
    assert "requirements not met: 1 FAIL" in out.err
    suite = ET.parse(junit).getroot().find("testsuite")
    assert [suite.get(k) for k in ("tests", "failures", "errors", "skipped")] == ["3", "1", "0", "0"]
    cases = {c.get("name").split(":")[0]: c for c in suite.findall("testcase")}
    assert cases["DET-3"].find("failure").get("message").startswith("FAIL: stop_time = 9.96 is not <= 5")
    assert cases["DET-1"].find("failure") is None and "stop_time = 9.96 < 10" in cases["DET-1"].find("system-out").text
    dom, console = open_page(report)
    assert console == [] and "DET-2" in dom and "FAIL" in dom and "thesis section 3.3.3" in dom
    # names the run has not: refused before the run, naming the file and line
    bad = _file(tmp_path, RUN_FILE.replace("stop_time < 10 s", "stop_tme < 10 s"), "bad.toml")
    assert main(["run", system, "--requirements", str(bad)]) == 2
    assert "bad.toml:9: requirement 'DET-1': check: unknown name 'stop_tme' (the closest" in capsys.readouterr().err
    bad.write_text(RUN_FILE.replace("max(dynamics.omega_BN_B[1])", "max(dynamics.omega[1])"))
    assert main(["run", system, "--requirements", str(bad)]) == 2
    assert "bad.toml:15: requirement 'DET-2': check: dynamics.omega[1]:" in capsys.readouterr().err
    assert main(["run", system, "--junit", str(junit)]) == 2
    assert "--junit writes the verdicts of --requirements FILE" in capsys.readouterr().err


CAMPAIGN_FILE = """
[[requirement]]
id = "SET-1"
text = "A tumble up to 10 deg/s per axis settles within 10 s, 99 % of the time at 95 % confidence."
source = "ours"
probability = "P(done and t_done <= 10 s) >= 0.99 at 95 %"

[[requirement]]
id = "SET-2"
text = "Half the tumbles settle."
source = "ours"
probability = "P(done) >= 0.4 at 90 %"

[[requirement]]
id = "SET-3"
text = "Seven in ten tumbles settle."
source = "ours"
probability = "P(done) >= 0.7"

[[requirement]]
id = "SET-4"
text = "One run only."
source = "ours"
check = "done"
"""


def test_campaign_verdicts_with_bounds_and_the_runs_that_would_decide(ssp_paths, tmp_path, capsys):
    spec_path = _file(tmp_path, SETTLING.format(system=ssp_paths["detumble"]).replace("min_success = 0.8\n", ""),
                      "settling.toml")
    path = _file(tmp_path, CAMPAIGN_FILE)
    out = tmp_path / "out"
    assert main(["campaign", str(spec_path), "--out", str(out), "--workers", "1", "--requirements", str(path)]) == 1
    text = capsys.readouterr()
    assert "1 PASS, 1 FAIL, 1 INCONCLUSIVE" in text.out and "requirements not met: 1 FAIL, 1 INCONCLUSIVE" in text.err
    s = json.loads((out / "summary.json").read_text())["requirements"]
    v = {x["id"]: x for x in s["verdicts"]}
    # 6 of the 8 settle (the 2 incomplete runs are not done, and have no t_done either)
    assert (v["SET-1"]["k"], v["SET-1"]["n"], v["SET-1"]["verdict"]) == (6, 8, "FAIL")
    assert v["SET-1"]["evidence"] == ("6 of 8 runs meet it: p = 0.75, one-sided 95 % bounds [0.4003, 0.9536] "
                                      "against >= 0.99")
    assert v["SET-2"]["verdict"] == "PASS" and v["SET-2"]["bounds"][0] >= 0.4
    assert v["SET-3"]["verdict"] == "INCONCLUSIVE" and v["SET-3"]["confidence"] == 0.95
    more = v["SET-3"]["more_runs"]
    assert more > 0 and f"about {more} more runs like these would decide it" in v["SET-3"]["evidence"]
    assert req.clopper_pearson(round(0.75 * (8 + more)), 8 + more, 0.95)[0] >= 0.7  # 75 % of them would pass
    assert s["uncovered"] == [{"id": "SET-4", "why": "no probability: judged by single runs"}]
    suite = ET.parse(out / "requirements.junit.xml").getroot().find("testsuite")
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("3", "1", "1")
    dom, console = open_page(out / "report.html")
    assert console == [] and "SET-3" in dom and "INCONCLUSIVE" in dom and "more runs like these" in dom
    # a campaign's checks read its metrics: a signal or an unknown metric is refused before any run
    bad = _file(tmp_path, CAMPAIGN_FILE.replace("P(done)", "P(max(dynamics.omega_BN_B[1]) < 1)", 1), "bad.toml")
    assert main(["campaign", str(spec_path), "--out", str(tmp_path / "bad"), "--requirements", str(bad)]) == 2
    assert "a campaign's checks read its metrics, not signals" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


def test_the_shipped_neighbor_file_reads_what_the_mission_and_its_campaigns_have():
    """Every check names a figure of the mission (or a recorded signal) and every probability a
    metric of each shipped mission campaign, so `--requirements` never stops on them."""
    shipped = req.load(mission.REQUIREMENTS)
    assert [r.id for r in shipped.requirements] == ["NBR-DEO-1", "NBR-DEO-2", "NBR-PRO-1", "NBR-PRO-2",
                                                    "NBR-PWR-1", "NBR-DAT-1", "NBR-ACS-1"]
    assert all("thesis section" in r.source for r in shipped.requirements)
    req.check_names(shipped, False, mission.REQUIREMENT_NAMES, mission._recorded_signal)
    from paths import REPO

    for scenario in ("420km", "475km", "525km"):
        spec = load_spec(REPO / "examples" / "campaigns" / f"mission_dispersion_{scenario}.toml")
        req.check_names(shipped, True, [m.name for m in spec.metrics])
    # its 420 km values are the budgets' own (the mission command gives each scenario's)
    values = mission.requirement_values({"scenario": "420km", "simulated_years": 1.0})
    for name in mission.SCENARIO_LIMITS:
        assert shipped.values[name] == pytest.approx(values[name], rel=1e-4), name
