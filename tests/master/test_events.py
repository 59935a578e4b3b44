"""Scenario events (issue 58): at a time or when a condition holds, the master sets an input or
faults an output (stuck, bias, scale, noise, dropout) as the inputs it feeds see it, and releases
it; refused before the run in one line naming the event; listed in the result and the report; a
campaign disperses an event's time. The mission's dead Sun sensors as events against the models'
own fault parameters: tests/systems/test_mission_system.py."""
import numpy as np
import pytest

from browser import open_page
from system_ssp import SSPError, System
from system_ssp.cli import main
from system_ssp.master.events import read_events
from system_ssp.tools.campaign import load_spec
from system_ssp.tools.campaign.runner import check_against_system
from system_ssp.tools.campaign.worker import run_one

OUT, IN = "dynamics.omega_BN_B[1]", "detumble.omega_BN_B[1]"  # the rate, and the controller's input of it


@pytest.fixture(scope="module")
def detumble(ssp_paths):
    with System(ssp_paths["detumble"]) as system:
        yield system


def _run(system, events=None, **kw):
    return system.run(outputs=[OUT, IN, "detumble.q_BN[4]", "detumble.torque_cmd_B[1]"], events=events, **kw)


def _at(r, t):
    return int(np.searchsorted(r.data["time"], t - 1e-9))


def test_a_bias_from_2_s_released_at_4_s(detumble):
    free = _run(detumble)
    r = _run(detumble, [{"at": 2.0, "fault": OUT, "kind": "bias", "value": -0.2},
                        {"at": 4.0, "release": OUT, "description": "the gyro recovers"}])
    assert r.events == [{"t": 2.01, "event": 1, "action": f"fault {OUT}: bias -0.2", "description": ""},
                        {"t": 4.005, "event": 2, "action": f"release {OUT}", "description": "the gyro recovers"}]
    d, f = r.data, free.data
    before, during, after = _at(r, 2.01), _at(r, 3.0), _at(r, 4.005)
    assert np.array_equal(d[IN][:before], f[IN][:before]) and np.array_equal(d[OUT][:before], f[OUT][:before])
    # what the controller sees from the step after the fault's point: the rate (the FMU's own
    # output, recorded) plus the bias; its input at the point itself was sent before the fault
    assert d[IN][before] == d[OUT][before]
    assert np.allclose(d[IN][before + 1:after + 1] - d[OUT][before + 1:after + 1], -0.2, rtol=0, atol=1e-15)
    assert np.array_equal(d[IN][after + 1:], d[OUT][after + 1:])  # released
    # the controller, seeing the rate's sign turned, torques the other way
    assert np.all(np.sign(d["detumble.torque_cmd_B[1]"][before + 1:during]) == -np.sign(
        f["detumble.torque_cmd_B[1]"][before + 1:during]))


def test_faults_stuck_dropout_noise_scale(detumble):
    free = _run(detumble)
    same = _run(detumble, [{"at": 0.0, "fault": OUT, "kind": "scale", "value": 1.0}])
    for name in free.data.dtype.names:  # the Python loop with a neutral fault: the compiled loop's bits
        assert np.array_equal(same.data[name], free.data[name]), name
    stuck = _run(detumble, [{"at": 1.5, "fault": OUT, "kind": "stuck"}])
    i = _at(stuck, 1.5)
    assert np.all(stuck.data[IN][i + 1:] == stuck.data[OUT][i])  # held at its value when the fault began
    dead = _run(detumble, [{"at": 1.5, "fault": OUT, "kind": "dropout"}], stop_time=3.0)
    assert np.all(dead.data[IN][i + 1:] == 0.0) and dead.data[IN][i] != 0.0
    noisy = [_run(detumble, [{"at": 0.0, "fault": OUT, "kind": "noise", "value": 1e-3, "seed": s}], stop_time=5.0)
             for s in (1, 1, 2)]
    errors = [n.data[IN] - n.data[OUT] for n in noisy]
    assert np.array_equal(errors[0], errors[1]) and not np.array_equal(errors[0], errors[2])
    assert np.std(errors[0][1:]) == pytest.approx(1e-3, rel=0.1) and abs(np.mean(errors[0][1:])) < 2e-4


def test_a_condition_and_a_set(detumble):
    r = _run(detumble, [{"when": f"{OUT} < 0.1 and t > 1", "set": {"detumble.q_BN[4]": 0.5}}])
    (e,) = r.events
    i = _at(r, e["t"])
    assert r.data[OUT][i] < 0.1 <= r.data[OUT][i - 1] and e["action"] == "set detumble.q_BN[4] = 0.5"
    assert np.all(r.data["detumble.q_BN[4]"][:i] == 1.0) and np.all(r.data["detumble.q_BN[4]"][i:] == 0.5)
    # set at its point: the FMU holds it from there (no connection resends it)


@pytest.mark.parametrize("events, pattern", [
    ([{"at": 1, "set": {"dynamics.omega0[1]": 1.0}}], r"events\[1\]: event 1: set dynamics.omega0\[1\]: a fixed "
                                                      r"parameter cannot change during a run"),
    ([{"at": 1, "set": {IN: 1.0}}], r"a connection feeds it \(every step overwrites it\); fault the output"),
    ([{"at": 1, "fault": "detumble.Kp[1]", "kind": "dropout"}], r"is a parameter; a fault acts on an output"),
    ([{"at": 1, "fault": "detumble.done", "kind": "dropout"}], r"feeds no input: a fault there would change nothing"),
    ([{"at": 1, "release": OUT}], r"release dynamics.omega_BN_B\[1\]: no event before it faults it"),
    ([{"at": 1, "fault": OUT, "kind": "bias"}], r"a bias fault needs value \(the offset\)"),
    ([{"at": 1, "fault": OUT, "kind": "melt"}], r"kind = 'melt': expected one of stuck, bias, scale, noise, dropout"),
    ([{"at": 1, "when": "t > 1", "fault": OUT, "kind": "dropout"}], r"needs `at` \(s\) or `when` \(a condition\), one"),
    ([{"when": "max(dynamics.q_BN[1]) > 1", "fault": OUT, "kind": "dropout"}], r"reads max\(dynamics.q_BN\[1\]\)"),
    ([{"at": 1, "fault": "dynamics.omegaa[1]", "kind": "dropout"}], r"has no variable 'omegaa\[1\]' \(did you mean"),
    ([{"at": 1, "fault": "dynamics.done", "kind": "bias", "value": 1}], r"has no variable"),
    ([{"at": 1, "set": {"detumble.q_BN[4]": True}}], r"expected a finite number \(it is a Real\)"),
    ("nowhere.toml", r"nowhere.toml: cannot read the scenario file"),
])
def test_bad_events_are_refused_before_the_run(detumble, events, pattern):
    with pytest.raises(SSPError, match=pattern):
        _run(detumble, events)


def test_command_line_scenario_file_and_report(ssp_paths, tmp_path, capsys):
    scenario = tmp_path / "gyro.toml"
    scenario.write_text(f'[[event]]\nat = 2.0\nfault = "{OUT}"\nkind = "bias"\nvalue = 0.01\ndescription = "a jump"\n'
                        f'\n[[event]]\nat = 4.0\nrelease = "{OUT}"\n')
    report = tmp_path / "r.html"
    assert main(["run", str(ssp_paths["detumble"]), "--events", str(scenario), "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert f"event 1:     t = 2.01 s: fault {OUT}: bias 0.01 (a jump)" in out
    assert f"event 2:     t = 4.005 s: release {OUT}" in out
    dom, console = open_page(report)
    assert console == [] and "Events" in dom and "a jump" in dom
    assert [(e.number, e.origin) for e in read_events(scenario)] == [(1, f"{scenario}:1"), (2, f"{scenario}:8")]
    scenario.write_text(f'[[event]]\nat = 2.0\nfault = "{OUT}"\nkind = "bias"\n')
    assert main(["run", str(ssp_paths["detumble"]), "--events", str(scenario)]) == 2
    assert f"{scenario}:1: a bias fault needs value" in capsys.readouterr().err


CAMPAIGN = """
[campaign]
system = "{system}"
parameter_sets = ["parameters/detumble_case1.ssv"]
runs = 4
seed = 5
[[events]]
at = 3.0
fault = "dynamics.omega_BN_B[1]"
kind = "stuck"
value = 0.0
[dispersions."events[1].at"]
distribution = "uniform"
low = 1.0
high = 5.0
[metrics]
wx = "final:dynamics.omega_BN_B[1]"
"""


def test_a_campaign_disperses_an_events_time(ssp_paths, tmp_path):
    """The controller's x rate stuck at zero from a drawn time: the later, the more of the x tumble
    it has damped (the final x rate falls with the fault's time)."""
    path = tmp_path / "c.toml"
    path.write_text(CAMPAIGN.format(system=ssp_paths["detumble"]))
    spec = load_spec(path)
    check_against_system(spec)
    rows = [run_one(spec, i) for i in range(4)]
    assert all(r["status"] == "ok" for r in rows)
    times = [r["events[1].at"] for r in rows]
    assert len(set(times)) == 4 and all(1.0 <= t <= 5.0 for t in times)
    by_time = sorted(rows, key=lambda r: r["events[1].at"])
    assert [r["wx"] for r in by_time] == sorted((r["wx"] for r in rows), reverse=True)
    path.write_text(CAMPAIGN.format(system=ssp_paths["detumble"]).replace('[dispersions."events[1].at"]',
                                                                          '[dispersions."events[2].at"]'))
    with pytest.raises(SSPError, match=r"events\[2\].at: an event's field is events\[i\].at or events\[i\].value, "
                                       r"i from 1 to 1"):
        load_spec(path)
    path.write_text(CAMPAIGN.format(system=ssp_paths["detumble"]).replace('fault = "dynamics.omega_BN_B[1]"',
                                                                          'fault = "dynamics.omega[1]"'))
    with pytest.raises(SSPError, match=r"c.toml: events\[1\]: event 1: event's output 'dynamics.omega\[1\]'"):
        check_against_system(load_spec(path))
