"""Mode-dependent communication steps (nc:Schedule) on small fixture FMUs."""

import numpy as np
import pytest

from master_fixtures import helpers as h
import system_ssp
from system_ssp import SSPError

USES = {"integ.fmu": "integrator", "gain.fmu": "gain", "timer.fmu": "timer"}
X0 = ('<ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="p"><ssv:Parameters>'
      '<ssv:Parameter name="x0"><ssv:Real value="1"/></ssv:Parameter></ssv:Parameters></ssv:ParameterSet>'
      '</ssd:ParameterValues></ssd:ParameterBinding>')
SCHEDULE = """<nc:Schedule>
  <nc:Mode name="before" stepSize="0.1"><nc:When component="timer" connector="expired" values="0"/></nc:Mode>
  <nc:Mode name="after" stepSize="0.25" active="integ timer" recordEvery="{every}"/>
  <nc:NextEvent component="timer" connector="next_event_time"/>
</nc:Schedule>"""


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))


EVERY_STEP = SCHEDULE.format(every=1)


def scheduled_system(folder, fmus, schedule=EVERY_STEP, expiry=0.35):
    """integ.x -> gain.u -> gain.y -> integ.u (x' = x), and a timer that expires at `expiry`."""
    ann = ('<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master">'
           f'<nc:Master xmlns:nc="https://neighbor-cosim.org/ssp/master" stepSize="0.1">{schedule}</nc:Master>'
           '</ssc:Annotation></ssd:Annotations>')
    timer_bind = ('<ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="t">'
                  f'<ssv:Parameters><ssv:Parameter name="expiry"><ssv:Real value="{expiry}"/></ssv:Parameter>'
                  '</ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding>')
    el = (h.component("integ", "integ.fmu", bindings=X0) + h.component("gain", "gain.fmu")
          + h.component("timer", "timer.fmu", bindings=timer_bind))
    co = h.connection("integ.x", "gain.u") + h.connection("gain.y", "integ.u")
    return h.write_system(folder, fmus, USES, h.ssd_text(el, co, system_extra=ann,
                                                         experiment='<ssd:DefaultExperiment stopTime="1"/>'))


def test_steps_follow_the_mode_and_land_on_events(fmus, tmp_path):
    r = system_ssp.simulate(scheduled_system(tmp_path, fmus), profile=True)
    # 0.1 steps until the timer's announced expiry at 0.35 (last one shortened to 0.05), then
    # 0.25 steps, the last one shortened to end at the stop time.
    np.testing.assert_allclose(r.data["time"], [0, 0.1, 0.2, 0.3, 0.35, 0.6, 0.85, 1.0], atol=1e-12)
    assert r.steps == 7 and r.stop_time == 1.0
    assert r.modes["before"]["steps"] == 4 and r.modes["after"]["steps"] == 3
    assert r.modes["after"]["simulated_time"] == pytest.approx(0.65)
    assert r.final["timer.steps"] == 7 and r.final["timer.last_step"] == pytest.approx(0.15)
    # gain is suspended after the expiry: its output holds x(0.35), so x grows linearly from there
    x35 = 1.1 * 1.1 * 1.1 * 1.05
    assert r.data["integ.x"][4] == pytest.approx(x35, rel=1e-12)
    assert r.final["integ.x"] == pytest.approx(x35 + 0.65 * x35, rel=1e-12)
    assert r.final["gain.y"] == pytest.approx(x35, rel=1e-12)
    assert set(r.profile["components"]) == {"integ", "gain", "timer"} and r.profile["master"] >= 0.0


def test_record_every_and_fixed_step_fallback(fmus, tmp_path):
    ssd = scheduled_system(tmp_path, fmus, schedule=SCHEDULE.format(every=2))
    r = system_ssp.simulate(ssd)
    # in "after": 0.6 skipped (every 2nd step), 0.85 recorded, 1.0 recorded as the end
    np.testing.assert_allclose(r.data["time"], [0, 0.1, 0.2, 0.3, 0.35, 0.85, 1.0], atol=1e-12)
    fixed = system_ssp.simulate(ssd, schedule=False)
    assert fixed.steps == 10 and fixed.modes is None
    assert fixed.final["integ.x"] == pytest.approx(1.1 ** 10)


@pytest.mark.parametrize("schedule, pattern", [
    ('<nc:Schedule><nc:Mode name="a" stepSize="0.1"/><nc:Mode name="b" stepSize="1"/></nc:Schedule>',
     "only the last mode may be unconditional"),
    ('<nc:Schedule><nc:Mode name="a" stepSize="0"/></nc:Schedule>', "stepSize must be a positive number"),
    ('<nc:Schedule><nc:Mode name="a" stepSize="1" active="integ nosuch"/></nc:Schedule>',
     "active lists unknown component"),
    ('<nc:Schedule><nc:Mode name="a" stepSize="1"><nc:When component="integ" connector="x" values="1"/>'
     '</nc:Mode><nc:Mode name="b" stepSize="1"/></nc:Schedule>', "must be output or parameter of type Integer"),
    ('<nc:Schedule><nc:Mode name="a" stepSize="1"/><nc:NextEvent component="timer" connector="expired"/>'
     '</nc:Schedule>', "must be output of type Real"),
    ('<nc:Schedule><nc:Mode name="a" stepSize="1"><nc:When component="timer" connector="expired" values="1"/>'
     '</nc:Mode></nc:Schedule>', "no nc:Mode matches"),
])
def test_bad_schedules(fmus, tmp_path, schedule, pattern):
    with pytest.raises(SSPError, match=pattern):
        system_ssp.simulate(scheduled_system(tmp_path, fmus, schedule=schedule))


def test_schedule_needs_gauss_seidel(fmus, tmp_path):
    with pytest.raises(SSPError, match="gauss-seidel only"):
        system_ssp.simulate(scheduled_system(tmp_path, fmus), algorithm="jacobi")


def test_every_k_steps_ahead_with_contiguous_points(fmus, tmp_path):
    schedule = SCHEDULE.format(every=1).replace('active="integ timer"', 'active="integ timer" every="integ:2"')
    r = system_ssp.simulate(scheduled_system(tmp_path, fmus, schedule=schedule))
    # after 0.35 integ steps 0.35 -> 0.85 (2 x 0.25 ahead), skips the master step at 0.6, then
    # 0.85 -> 1.0 (cut at the stop time); the timer steps every macro step
    assert r.final["integ.steps"] == 4 + 2 and r.final["timer.steps"] == 7
    x35 = 1.1 * 1.1 * 1.1 * 1.05
    assert r.final["integ.x"] == pytest.approx(x35 * 1.65, rel=1e-12)
    i06 = int(np.argmin(abs(r.data["time"] - 0.6)))
    assert r.data["integ.x"][i06] == pytest.approx(x35 * 1.5, rel=1e-12)  # already at its own t = 0.85
    bad = SCHEDULE.format(every=1).replace('active="integ timer"', 'active="integ timer" every="gain:2"')
    with pytest.raises(SSPError, match="not active in that mode"):
        system_ssp.simulate(scheduled_system(tmp_path / "bad", fmus, schedule=bad))


def test_component_suspended_from_the_start_joins_at_the_current_time(fmus, tmp_path):
    """A component inactive in the first mode starts its clock when it is first stepped."""
    schedule = ('<nc:Schedule><nc:Mode name="late" stepSize="0.25"><nc:When component="timer" connector="expired" '
                'values="1"/></nc:Mode><nc:Mode name="early" stepSize="0.1" active="timer gain"/>'
                '<nc:NextEvent component="timer" connector="next_event_time"/></nc:Schedule>')
    r = system_ssp.simulate(scheduled_system(tmp_path, fmus, schedule=schedule, expiry=0.5))
    # integ is suspended until 0.5 (x = x0 = 1), then steps 0.5 -> 0.75 -> 1.0 with u = gain.y:
    # x = 1 + 0.25 * 1 = 1.25, then 1.25 + 0.25 * 1.25 (not a 0.5 s step from t = 0)
    assert r.final["integ.steps"] == 2 and r.final["integ.x"] == pytest.approx(1.5625, rel=1e-12)


def test_info_lists_the_schedule(fmus, tmp_path):
    with system_ssp.System(scheduled_system(tmp_path, fmus)) as s:
        text = s.info()
    assert "mode before: when timer.expired in {0}: step 0.1 s, active all" in text
    assert "mode after: when always: step 0.25 s, active integ timer" in text
    assert "steps land on timer.next_event_time" in text
