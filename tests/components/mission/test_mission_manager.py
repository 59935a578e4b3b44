"""NEIGHBOR's mission manager and the host heartbeat: the mode sequence of thesis section 3.4
(Figure 45) driven by a scripted environment, exact timers for any communication step from
15 ms to days, the powered components per mode against Tables 5 and 6, parameter errors, FMU
state, and both FMUs through FMPy."""
import math

import pytest

from components.core.constants import DAY
from components.mission import host as host_model
from components.mission import manager as mm
from components.mission.power_bus import LOAD_NAMES
from fmu_helpers import check_declarations, instantiate

# Table 5 (W). GPS receiver + antenna = 1.366 W, Appendix I's GPS_pwr.
TABLE5 = {"propulsion": 0.5, "horizon_sensor": 0.15, "sun_sensor": 0.115, "gyro": 0.018, "gps_receiver": 1.300,
          "gps_antenna": 0.066, "microprocessor_nominal": 0.0221, "microprocessor_quiescent": 9.24e-8,
          "uhf_rx": 0.1815, "uhf_tx": 2.64}


def power(on):
    return sum(p for name, p in TABLE5.items() if on[name])


class Environment:
    """Scripted surroundings: host heartbeat schedule, ground contacts (start, end, confirms),
    controllers that finish a fixed time after their enable turns on, a battery that empties
    at `battery_empty_at`, re-entry at `reentry_at`. Signals are functions of time and of the
    manager's outputs at that time; `events()` lists the times a master should land on."""

    def __init__(self, loss=2.5 * DAY + 1000.0, returns=(), contacts=(), detumble=9.97, slew=166.26,
                 burn=38.74 * 60.0, battery_empty_at=math.inf, reentry_at=math.inf):
        self.host = host_model.HostSpacecraft(loss, returns)
        self.contacts = list(contacts)
        self.durations = {"detumble_enable": detumble, "slew_enable": slew, "burn_enable": burn}
        self.enabled_since = {}
        self.battery_empty_at, self.reentry_at = battery_empty_at, reentry_at

    def observe(self, t, outputs):
        for name in self.durations:
            if outputs[name]:
                self.enabled_since.setdefault(name, t)
            else:
                self.enabled_since.pop(name, None)

    def done(self, name, t):
        since = self.enabled_since.get(name)
        return since is not None and t >= since + self.durations[name] - 1e-9

    def contact(self, t):
        for start, end, confirms in self.contacts:
            if start <= t < end:
                return True, confirms
        return False, False

    def inputs(self, t):
        contact, confirms = self.contact(t)
        return {"heartbeat": self.host.heartbeat(t), "ground_contact": contact, "ground_command": confirms,
                "detumble_done": self.done("detumble_enable", t), "slew_done": self.done("slew_enable", t),
                "budget_spent": self.done("burn_enable", t),
                "state_of_charge": 0.0 if t >= self.battery_empty_at else 0.8, "reentered": t >= self.reentry_at}

    def events(self, t):
        times = [x for x in self.host.toggles] + [self.battery_empty_at, self.reentry_at]
        times += [x for s, e, _ in self.contacts for x in (s, e)]
        times += [since + self.durations[n] for n, since in self.enabled_since.items()]
        ahead = [x for x in times if x > t + 1e-9]
        return min(ahead) if ahead else math.inf


def run(env, t_stop, h_max, land=True, params=None, t0=0.0, h_deorbit=0.5):
    """Drive a MissionManager like a co-simulation master with mode-dependent steps (h_deorbit
    in the final contact and de-orbit modes, else h_max); returns (manager, transitions, awake) with transitions =
    [(time, mode, phase)] at each change and the microprocessor's awake time in idle/grace."""
    m = mm.MissionManager(params or {}, t0)
    t = t0
    env.observe(t, m.powered())
    trace = [(t, m.mode, m.phase)]
    awake = 0.0
    while t < t_stop - 1e-9:
        h = min(h_deorbit if m.mode in (mm.CONTACT, mm.DEORBIT) else h_max, t_stop - t)
        if land:
            h = min(h, m.next_event_time - t, env.events(t) - t)
        nominal = m.powered()["microprocessor_nominal"]
        m.step(t, h, env.inputs(t))
        t = t + h
        if nominal and m.mode in (mm.IDLE, mm.GRACE):
            awake += h
        env.observe(t, m.powered())
        if (m.mode, m.phase) != trace[-1][1:]:
            trace.append((m.phase_entry, m.mode, m.phase))
    return m, trace, awake


# The nominal mission: heartbeat lost at day 2.5 (+1000 s), found missing at the day-3 check,
# grace period 3 days, a first contact without confirmation, a confirming contact, the de-orbit
# phases with the thesis' durations (10 min attitude determination, 9.97 s detumble, 166.26 s
# slew, 38.74 min burn), monitoring with a contact, then the battery runs empty. A completion
# flag acts one de-orbit step (0.5 s) after its phase began: the controller sees its enable only
# from the end of the step that decided the phase (state outputs, no feedthrough).
GRACE = 3 * DAY
C1 = (6 * DAY + 3000.0, 6 * DAY + 3400.0, False)
C2 = (6 * DAY + 9000.0, 6 * DAY + 9550.0, True)
C3 = (6 * DAY + 20000.0, 6 * DAY + 20500.0, False)
EMPTY = 6 * DAY + 30000.0
EXPECTED = [
    (0.0, mm.IDLE, 0), (3 * DAY, mm.GRACE, 0), (6 * DAY, mm.AWAITING, 0), (C1[0], mm.CONTACT, 0),
    (C1[1], mm.AWAITING, 0), (C2[0], mm.CONTACT, 0), (C2[1], mm.DEORBIT, mm.ATTITUDE_DETERMINATION),
    (C2[1] + 600.0, mm.DEORBIT, mm.DETUMBLE), (C2[1] + 609.97, mm.DEORBIT, mm.SLEW),
    (C2[1] + 609.97 + 0.5 + 166.26, mm.DEORBIT, mm.BURN), (C2[1] + 609.97 + 166.26 + 2324.4 + 1.0, mm.MONITORING, 0),
    (EMPTY, mm.END, 0)]


def nominal_env():
    return Environment(contacts=[C1, C2, C3], battery_empty_at=EMPTY)


@pytest.mark.parametrize("h_max", [60.0, 3600.0, 5 * 3600.0, 2 * DAY])
def test_nominal_sequence_exact_for_any_step_when_landing_on_events(h_max):
    m, trace, awake = run(nominal_env(), 6 * DAY + 40000.0, h_max, params={"grace_period": GRACE})
    assert [(mode, phase) for _, mode, phase in trace] == [(mode, phase) for _, mode, phase in EXPECTED]
    for (t, _, _), (t_ref, _, _) in zip(trace, EXPECTED):
        assert t == pytest.approx(t_ref, abs=1e-6)
    assert m.end_reason == mm.END_BATTERY
    assert m.heartbeat_lost_at == 3 * DAY
    # the microprocessor was awake for 5 s at each daily check in idle and grace (days 0..5),
    # exactly when the master lands on the wake start and end (it does not land inside
    # windows that a long step covers, so count only with steps that resolve them)
    if h_max <= 3600.0:
        assert awake == pytest.approx(6 * 5.0, abs=1e-6)


def test_fixed_steps_without_landing_detect_events_at_step_boundaries():
    """A master that ignores next_event_time: the heartbeat check of a wake window that starts
    inside a step still happens at the window's start (held input), so the grace period starts
    at the day-3 check exactly even with 7 s steps that never hit it; attitude determination
    ends at its exact time; input-driven changes happen at the first step start after the
    input changed."""
    h = 7.0
    env = Environment(contacts=[C1, C2], burn=100.0)
    m, trace, _ = run(env, 6 * DAY + 12000.0, h, land=False, params={"grace_period": GRACE}, h_deorbit=h)
    times = {}
    for t, mode, phase in trace:
        times.setdefault((mode, phase), t)  # first entry
    assert times[(mm.GRACE, 0)] == pytest.approx(3 * DAY, abs=1e-6)
    assert times[(mm.AWAITING, 0)] == pytest.approx(6 * DAY, abs=1e-6)
    deorbit = times[(mm.DEORBIT, mm.ATTITUDE_DETERMINATION)]
    assert C2[1] <= deorbit < C2[1] + h  # first step start after the contact ended
    assert deorbit == pytest.approx(math.ceil(C2[1] / h) * h, abs=1e-6)
    assert times[(mm.DEORBIT, mm.DETUMBLE)] == pytest.approx(deorbit + 600.0, abs=1e-6)
    assert times[(mm.DEORBIT, mm.SLEW)] - times[(mm.DEORBIT, mm.DETUMBLE)] < 9.97 + 2 * h
    assert m.mode == mm.MONITORING


def test_wake_windows_with_15_ms_steps():
    """Around a daily check with 15 ms steps (not landing): the microprocessor is nominal for
    5 s within one step, and the heartbeat lost 2 s into the window is found at the first step
    start after the loss, inside the window."""
    t0 = 3 * DAY - 1.0
    h = 0.015
    env = Environment(loss=3 * DAY + 2.0)
    m = mm.MissionManager({}, t0)
    t, awake, n = t0, 0.0, 0
    while t < 3 * DAY + 7.0:
        nominal = m.powered()["microprocessor_nominal"]
        m.step(t, h, env.inputs(t))
        t = t0 + (n := n + 1) * h
        awake += h if nominal else 0.0
    assert awake == pytest.approx(5.0, abs=2 * h)
    assert m.mode == mm.GRACE
    assert 3 * DAY + 2.0 <= m.heartbeat_lost_at < 3 * DAY + 2.0 + h + 1e-9
    assert m.next_event_time == pytest.approx(4 * DAY, abs=1e-6)  # next wake start
    assert m.grace_end == pytest.approx(m.heartbeat_lost_at + 30 * DAY)


def test_attitude_determination_with_15_ms_steps_landing():
    m = mm.MissionManager({"initial_mode": mm.DEORBIT}, 100.0)
    assert m.next_event_time == 700.0
    t, h = 100.0, 0.015
    while m.phase == mm.ATTITUDE_DETERMINATION:
        step = min(h, m.next_event_time - t)
        m.step(t, step, {})
        t += step
    assert t == pytest.approx(700.0, abs=1e-9)
    assert m.phase_entry == 700.0 and m.phase == mm.DETUMBLE and m.powered()["detumble_enable"]


def test_next_event_time_sequence_in_idle_and_grace():
    m = mm.MissionManager({"grace_period": 1.5 * DAY}, 0.0)
    assert m.powered()["microprocessor_nominal"] and m.next_event_time == 5.0
    m.step(0.0, 5.0, {})
    assert not m.powered()["microprocessor_nominal"] and m.next_event_time == DAY
    m.step(5.0, DAY - 5.0, {})
    assert m.powered()["microprocessor_nominal"] and m.mode == mm.IDLE and m.next_event_time == DAY + 5.0
    m.step(DAY, 5.0, {"heartbeat": False})  # the check at the window start finds it missing
    assert m.mode == mm.GRACE and m.mode_entry == DAY and m.next_event_time == 2 * DAY
    m.step(DAY + 5.0, DAY - 5.0, {"heartbeat": False})
    m.step(2 * DAY, 5.0, {"heartbeat": False})
    assert m.next_event_time == 2.5 * DAY  # grace end before the next wake start
    m.step(2 * DAY + 5.0, 0.5 * DAY - 5.0, {"heartbeat": False})
    assert m.mode == mm.AWAITING and m.time_in_mode == 0.0 and m.next_event_time == mm.NO_EVENT


def test_heartbeat_return_during_grace_and_while_awaiting():
    # returns at day 4.3, found at the day-5 check
    env = Environment(loss=2.5 * DAY, returns=[4.3 * DAY])
    m, trace, _ = run(env, 6 * DAY, 3600.0)
    assert [(t, mode) for t, mode, _ in trace] == [(0.0, mm.IDLE), (3 * DAY, mm.GRACE), (5 * DAY, mm.IDLE)]
    # no confirmation at the contact -> awaiting again; the heartbeat comes back -> idle
    env = Environment(loss=0.5 * DAY, returns=[3 * DAY], contacts=[(2 * DAY, 2 * DAY + 500.0, False)])
    m, trace, _ = run(env, 4 * DAY, 3600.0, params={"grace_period": 0.5 * DAY})
    assert [(t, mode) for t, mode, _ in trace] == [
        (0.0, mm.IDLE), (DAY, mm.GRACE), (1.5 * DAY, mm.AWAITING), (2 * DAY, mm.CONTACT),
        (2 * DAY + 500.0, mm.AWAITING), (3 * DAY, mm.IDLE)]


def test_stale_completion_flags_do_not_skip_phases():
    """Completion inputs true all the time: each phase is decided at the second step start
    after it began (its controller has had one whole step with its enable on)."""
    m = mm.MissionManager({"initial_mode": mm.DEORBIT, "attitude_determination_duration": 1.0}, 0.0)
    flags = {"detumble_done": True, "slew_done": True, "budget_spent": True}
    phases = []
    for k in range(8):
        m.step(k * 1.0, 1.0, flags)
        phases.append((m.mode, m.phase))
    assert phases == [(mm.DEORBIT, mm.DETUMBLE)] * 2 + [(mm.DEORBIT, mm.SLEW)] * 2 + [(mm.DEORBIT, mm.BURN)] * 2 + [
        (mm.MONITORING, 0)] * 2


def test_powered_components_against_tables_5_and_6():
    """Sums of Table 5 over the components each state powers reproduce Table 6, whose last
    seven values are printed one row off (see components.mission.manager): to 0.005 W."""
    def state(mode, phase=mm.PHASE_NONE, awake=False, contact=False):
        m = mm.MissionManager({"initial_mode": mode if mode != mm.END else mm.IDLE}, 10.0)
        m.mode, m.phase, m.awake, m.in_contact = mode, phase, awake, contact
        return m.powered()

    table6 = [
        (state(mm.IDLE, awake=True), 0.0221), (state(mm.IDLE), 9.24e-8),
        (state(mm.GRACE, awake=True), 0.0221), (state(mm.GRACE), 9.24e-8),
        (state(mm.AWAITING), 0.0221), (state(mm.CONTACT), 2.84),
        (state(mm.DEORBIT, mm.ATTITUDE_DETERMINATION), 1.67),
        (state(mm.DEORBIT, mm.DETUMBLE), 2.17), (state(mm.DEORBIT, mm.SLEW), 2.17),
        (state(mm.DEORBIT, mm.BURN), 2.17),
        (state(mm.MONITORING), 9.24e-8), (state(mm.MONITORING, contact=True), 4.21),
    ]
    for on, watts in table6:
        assert power(on) == pytest.approx(watts, abs=0.005, rel=0.01)
    assert power(state(mm.END)) == 0.0
    burn = state(mm.DEORBIT, mm.BURN)
    assert burn["tracking_enable"] and burn["burn_enable"] and burn["data_recording"]
    assert not burn["slew_enable"] and not burn["detumble_enable"] and not burn["downlink_enable"]
    assert state(mm.DEORBIT, mm.ATTITUDE_DETERMINATION)["data_recording"]
    assert not state(mm.MONITORING, contact=True)["data_recording"]  # Table 7: none in monitoring
    assert state(mm.MONITORING, contact=True)["downlink_enable"] and state(mm.CONTACT)["downlink_enable"]
    m = mm.MissionManager({"initial_mode": mm.AWAITING, "listen_while_awaiting": True})
    assert m.powered()["uhf_rx"] and not m.powered()["uhf_tx"]


def test_end_state_reasons():
    m = mm.MissionManager({"initial_mode": mm.MONITORING})
    m.step(0.0, 10.0, {"ground_contact": True})
    assert m.powered()["gps_receiver"] and m.powered()["uhf_tx"]
    m.step(10.0, 10.0, {"reentered": True})
    assert (m.mode, m.end_reason) == (mm.END, mm.END_REENTERED) and m.mode_entry == 10.0
    m.step(20.0, 10.0, {"state_of_charge": 0.5})
    assert m.mode == mm.END and not any(m.powered().values())
    m = mm.MissionManager({"battery_empty_soc": 0.05})
    m.step(0.0, 1.0, {"state_of_charge": 0.049})
    assert (m.mode, m.end_reason) == (mm.END, mm.END_BATTERY)


def test_beacon_interval_skips_contacts():
    """beacon_interval = 1 day: only the first contact starting a day or more after the last
    beacon is used; 0 (Appendix I) beacons in every contact."""
    def beacons(interval):
        m = mm.MissionManager({"initial_mode": mm.MONITORING, "beacon_interval": interval})
        used, t = [], 0.0
        # contacts of 600 s starting every 6 h (4 a day) for 3 days, 60 s steps
        while t < 3 * DAY:
            contact = (t % (6 * 3600.0)) < 600.0
            m.step(t, 60.0, {"ground_contact": contact})
            if m.powered()["gps_receiver"] and (not used or t - used[-1] > 700.0):
                used.append(t)
            t += 60.0
        return used
    assert beacons(0.0) == [6 * 3600.0 * k for k in range(12)]
    assert beacons(DAY) == [0.0, DAY, 2 * DAY]
    with pytest.raises(ValueError, match="beacon_interval"):
        mm.MissionManager({"beacon_interval": -1.0})


def test_state_round_trip():
    env = nominal_env()
    m, _, _ = run(env, 6 * DAY + 3200.0, 600.0, params={"grace_period": GRACE})
    saved = m.get_state()
    m.step(m.t, 7 * 3600.0, {"heartbeat": False})
    after = m.get_state()
    m.set_state(saved)
    m.step(saved["t"], 7 * 3600.0, {"heartbeat": False})
    assert m.get_state() == after and m.mode == mm.AWAITING


@pytest.mark.parametrize("params, match", [
    ({"grace_period": -1.0}, "grace_period"), ({"wake_period": 0.0}, "wake_period"),
    ({"wake_duration": DAY}, "wake_duration"), ({"wake_offset": -1.0}, "wake_offset"),
    ({"attitude_determination_duration": -600.0}, "attitude_determination_duration"),
    ({"battery_empty_soc": 1.0}, "battery_empty_soc"), ({"initial_mode": 7}, "initial_mode"),
    ({"initial_phase": 0}, "initial_phase"), ({"grace": 1.0}, "unknown"), ({"grace_period": math.nan}, "grace_period"),
])
def test_parameter_errors(params, match):
    with pytest.raises(ValueError, match=match):
        mm.MissionManager(params)


def test_step_errors():
    m = mm.MissionManager()
    with pytest.raises(ValueError, match="unknown"):
        m.step(0.0, 1.0, {"hartbeat": True})
    with pytest.raises(ValueError, match="state_of_charge"):
        m.step(0.0, 1.0, {"state_of_charge": math.nan})
    m.step(0.0, 10.0, {})
    with pytest.raises(ValueError, match="before"):
        m.step(5.0, 1.0, {})


# ---- host -----------------------------------------------------------------------------------
def test_host_schedule():
    h = host_model.HostSpacecraft(100.0, "200, 300 400")
    assert [h.heartbeat(t) for t in (0.0, 99.9, 100.0, 150.0, 200.0, 299.0, 300.0, 399.0, 400.0, 1e9)] == [
        True, True, False, False, True, True, False, False, True, True]
    assert [h.next_event_time(t) for t in (0.0, 100.0, 250.0, 400.0)] == [100.0, 200.0, 300.0, host_model.NO_EVENT]
    assert host_model.HostSpacecraft().next_event_time() == 1825 * DAY
    for bad, match in ((dict(heartbeat_loss_time=-1.0), "heartbeat_loss_time"),
                       (dict(return_times="50"), "heartbeat_return_times"),
                       (dict(heartbeat_loss_time=10.0, return_times="20, 20"), "heartbeat_return_times"),
                       (dict(heartbeat_loss_time=10.0, return_times="30 20"), "heartbeat_return_times"),
                       (dict(return_times="1e9, soon"), "heartbeat_return_times.*soon")):
        with pytest.raises(ValueError, match=match):
            host_model.HostSpacecraft(**bad)


# ---- FMUs -----------------------------------------------------------------------------------
def test_host_fmu(build_one, tmp_path):
    path = build_one("neighbor_host_spacecraft.py")
    assert check_declarations(path) == {"heartbeat": [], "next_event_time": []}
    fmu, vr = instantiate(path, tmp_path, "host")
    fmu.setReal([vr["heartbeat_loss_time"]], [50.0])
    fmu.setString([vr["heartbeat_return_times"]], ["80"])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    seen = []
    for t, h in ((0.0, 50.0), (50.0, 30.0), (80.0, 20.0)):
        seen.append((fmu.getBoolean([vr["heartbeat"]])[0], fmu.getReal([vr["next_event_time"]])[0]))
        fmu.doStep(t, h)
    seen.append((fmu.getBoolean([vr["heartbeat"]])[0], fmu.getReal([vr["next_event_time"]])[0]))
    assert seen == [(True, 50.0), (False, 80.0), (True, 1e300), (True, 1e300)]
    fmu.terminate()
    fmu.freeInstance()
    fmu, vr = instantiate(path, tmp_path, "host_bad")
    fmu.setString([vr["heartbeat_return_times"]], ["10, 5"])
    fmu.enterInitializationMode()
    with pytest.raises(Exception):
        fmu.exitInitializationMode()


def test_mission_fmu(build_one, tmp_path):
    path = build_one("neighbor_mission_manager.py")
    deps = check_declarations(path)
    assert set(deps) == {"mode", "phase", "end_reason", "next_event_time", "time_in_mode", "time_in_phase",
                         "detumble_timeouts", "slew_timeouts", "determination_timeouts", "safe_reason", *LOAD_NAMES,
                         *mm.COMMANDS}
    assert all(d == [] for d in deps.values())  # state outputs: no direct feedthrough
    fmu, vr = instantiate(path, tmp_path, "mission", start_time=1000.0)
    fmu.setReal([vr["grace_period"]], [100.0])
    fmu.setInteger([vr["initial_mode"]], [mm.GRACE])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()

    def read():
        return (fmu.getInteger([vr["mode"]])[0], fmu.getInteger([vr["phase"]])[0],
                fmu.getReal([vr["next_event_time"]])[0])

    assert read() == (mm.GRACE, 0, 1100.0)
    fmu.setBoolean([vr["heartbeat"]], [False])
    fmu.doStep(1000.0, 100.0)
    assert read() == (mm.AWAITING, 0, 1e300)
    fmu.setBoolean([vr["ground_contact"], vr["ground_command"]], [True, True])
    fmu.doStep(1100.0, 10.0)
    assert read()[0] == mm.CONTACT and fmu.getBoolean([vr["uhf_tx"]])[0]
    state = fmu.getFMUstate()
    fmu.setBoolean([vr["ground_contact"], vr["ground_command"]], [False, False])
    fmu.doStep(1110.0, 10.0)
    assert read() == (mm.DEORBIT, mm.ATTITUDE_DETERMINATION, 1710.0)
    assert fmu.getBoolean([vr["gyro"], vr["propulsion"], vr["data_recording"]]) == [True, False, True]
    fmu.setFMUstate(state)  # restores the inputs of that moment too
    assert read()[0] == mm.CONTACT and fmu.getBoolean([vr["ground_contact"]]) == [True]
    fmu.setBoolean([vr["ground_contact"], vr["ground_command"]], [False, False])
    fmu.doStep(1110.0, 10.0)
    assert read() == (mm.DEORBIT, mm.ATTITUDE_DETERMINATION, 1710.0)
    fmu.doStep(1120.0, 590.0)
    assert read()[:2] == (mm.DEORBIT, mm.DETUMBLE) and fmu.getReal([vr["time_in_phase"]])[0] == 0.0
    assert fmu.getBoolean([vr["detumble_enable"], vr["propulsion"]]) == [True, True]
    fmu.freeFMUstate(state)
    fmu.terminate()
    fmu.freeInstance()
    fmu, vr = instantiate(path, tmp_path, "mission_bad")
    fmu.setReal([vr["grace_period"]], [-1.0])
    fmu.enterInitializationMode()
    with pytest.raises(Exception):
        fmu.exitInitializationMode()


def _in_phase(phase, **params):
    return mm.MissionManager(dict({"initial_mode": mm.DEORBIT, "initial_phase": phase}, **params))


def test_a_phase_that_never_finishes_times_out_retries_and_moves_on():
    """A slew that never reports done (the thesis PD law limit-cycling off-nominal): retried once
    after slew_timeout, then the burn follows; the mission never waits for an empty battery."""
    m = _in_phase(mm.SLEW, slew_timeout=100.0)
    assert m.next_event_time == 100.0
    m.step(0.0, 100.0, {})
    assert (m.phase, m.slew_timeouts, m.attempt) == (mm.SLEW, 1, 1) and m.phase_entry == 100.0
    assert m.next_event_time == 200.0
    m.step(100.0, 50.0, {})
    m.step(150.0, 60.0, {})  # the second timeout inside the step, at its exact time
    assert (m.phase, m.slew_timeouts, m.phase_entry) == (mm.BURN, 2, 200.0)
    assert m.powered()["tracking_enable"] and m.powered()["burn_enable"]
    # detumble: no retry with phase_retries = 0, then the slew
    m = _in_phase(mm.DETUMBLE, detumble_timeout=30.0, phase_retries=0)
    m.step(0.0, 30.0, {})
    assert (m.phase, m.detumble_timeouts) == (mm.SLEW, 1)
    # a phase that finishes in time is not touched; 0 switches the timeout off
    m = _in_phase(mm.SLEW, slew_timeout=100.0)
    m.step(0.0, 10.0, {})
    m.step(10.0, 10.0, {"slew_done": True})
    assert (m.phase, m.slew_timeouts) == (mm.BURN, 0) and m.next_event_time == 1e300
    m = _in_phase(mm.SLEW, slew_timeout=0.0)
    m.step(0.0, 1e6, {})
    assert m.phase == mm.SLEW and m.next_event_time == 1e300
    with pytest.raises(ValueError, match=r"slew_timeout = -1.0 s must be >= 0"):
        _in_phase(mm.SLEW, slew_timeout=-1.0)
    with pytest.raises(ValueError, match=r"phase_retries = 1.5 must be an integer >= 0"):
        _in_phase(mm.SLEW, phase_retries=1.5)


def test_attitude_determination_waits_for_a_valid_attitude_then_times_out():
    """Without a fix at the end of the 600 s (no Sun in eclipse) the determination goes on until
    attitude_valid holds; with attitude_determination_timeout > 0 the detumble starts then anyway."""
    m = _in_phase(mm.ATTITUDE_DETERMINATION)
    m.step(0.0, 600.0, {"attitude_valid": False})
    assert m.phase == mm.ATTITUDE_DETERMINATION and m.att_det_waiting and m.next_event_time == 1e300
    m.step(600.0, 900.0, {"attitude_valid": False})
    assert m.phase == mm.ATTITUDE_DETERMINATION
    m.step(1500.0, 1.0, {"attitude_valid": True})  # the fix, seen at the step start
    assert (m.phase, m.phase_entry, m.determination_timeouts) == (mm.DETUMBLE, 1500.0, 0)
    # valid already at the end of the duration: on time, as before
    m = _in_phase(mm.ATTITUDE_DETERMINATION)
    m.step(0.0, 700.0, {"attitude_valid": True})
    assert (m.phase, m.phase_entry) == (mm.DETUMBLE, 600.0)
    # the timeout counts from the phase start and is announced as the next event
    m = _in_phase(mm.ATTITUDE_DETERMINATION, attitude_determination_timeout=3000.0)
    m.step(0.0, 600.0, {"attitude_valid": False})
    assert m.next_event_time == 3000.0
    m.step(600.0, 2500.0, {"attitude_valid": False})
    assert (m.phase, m.phase_entry, m.determination_timeouts) == (mm.DETUMBLE, 3000.0, 1)
    state = m.get_state()
    m.set_state(state)
    assert m.get_state() == state
    with pytest.raises(ValueError, match=r"attitude_determination_timeout = -5.0 s must be >= 0"):
        _in_phase(mm.ATTITUDE_DETERMINATION, attitude_determination_timeout=-5.0)


def test_without_attitude_no_slew_or_burn_starts_the_safe_state_instead():
    """No Sun sensor left: the determination times out, the detumble runs on rates, and then, with
    safe_without_attitude, no slew starts without an attitude: the done detumble goes on until one
    is valid (an estimate settling after a fast detumble), and if the phase times out first the
    de-orbit is abandoned for monitoring (no burn in an unknown direction); the burn likewise."""
    m = _in_phase(mm.ATTITUDE_DETERMINATION, attitude_determination_timeout=3000.0, safe_without_attitude=True,
                  detumble_timeout=100.0, phase_retries=1)
    m.step(0.0, 3000.0, {"attitude_valid": False})
    assert (m.phase, m.determination_timeouts) == (mm.DETUMBLE, 1)
    m.step(3000.0, 10.0, {"attitude_valid": False, "detumble_done": True})
    m.step(3010.0, 10.0, {"attitude_valid": False, "detumble_done": True})
    assert (m.mode, m.phase) == (mm.DEORBIT, mm.DETUMBLE)  # done, waiting for the attitude
    m.step(3020.0, 80.0, {"attitude_valid": False, "detumble_done": True})
    assert (m.phase, m.detumble_timeouts, m.attempt) == (mm.DETUMBLE, 1, 1)  # retried with a fresh timer
    m.step(3100.0, 100.0, {"attitude_valid": False, "detumble_done": True})
    assert (m.mode, m.safe_reason, m.phase, m.detumble_timeouts) == (mm.MONITORING, mm.SAFE_NO_ATTITUDE,
                                                                     mm.PHASE_NONE, 2)
    assert not any(m.powered()[c] for c in ("burn_enable", "slew_enable", "tracking_enable", "propulsion"))
    # the attitude valid a little after the detumble is done: the slew follows, no safe state
    m = _in_phase(mm.DETUMBLE, safe_without_attitude=True)
    m.step(0.0, 1.0, {"detumble_done": True, "attitude_valid": False})
    m.step(1.0, 1.0, {"detumble_done": True, "attitude_valid": False})
    assert m.phase == mm.DETUMBLE
    m.step(2.0, 1.0, {"detumble_done": True, "attitude_valid": True})
    assert (m.mode, m.phase, m.safe_reason) == (mm.DEORBIT, mm.SLEW, mm.SAFE_NONE)
    # the burn needs it as well: a slew that times out without it ends in the safe state
    m = _in_phase(mm.SLEW, safe_without_attitude=True, slew_timeout=50.0, phase_retries=0)
    m.step(0.0, 1.0, {})
    m.step(1.0, 1.0, {"slew_done": True, "attitude_valid": False})
    assert m.phase == mm.SLEW
    m.step(2.0, 48.0, {"slew_done": True, "attitude_valid": False})
    assert (m.mode, m.safe_reason) == (mm.MONITORING, mm.SAFE_NO_ATTITUDE)
    # off (the default, the thesis): the mission goes on as before
    m = _in_phase(mm.SLEW)
    m.step(0.0, 1.0, {})
    m.step(1.0, 1.0, {"slew_done": True, "attitude_valid": False})
    assert (m.mode, m.phase) == (mm.DEORBIT, mm.BURN)
