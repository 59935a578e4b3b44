"""ACS mode manager of the ACS mode specification (components/acs/modes.py) and its FMU (AcsModeManager)."""
import itertools
import math

import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
import pytest

from components.acs import modes as am
from paths import REPO

P = am.PARAMETER_DEFAULTS
W, DT, SU, RE, DW, AC, DP, OD, ON, GC = range(10)
ALL = tuple(range(10))

# Hand-written from the specification (not from RULES): per table (= target mode), the current modes
# each column applies from, in column order. GC col 2/3 are our added columns (A6, A4).
EXPECTED_FROM = {
    W: [("startup",), ALL, (W,)],
    DT: [(W,), (DT,), (DT,), (SU,), (SU,), (GC,)],
    SU: [(DT,), (SU,), (SU,), (SU,), (RE,), (RE,), (AC,), (OD,), (ON,)],
    RE: [(SU,), (SU,), (RE,), (RE,), (AC,)],
    DW: [(RE,), (DW,)],
    AC: [(RE,), (AC,), (AC,), (DW,), (DP,), (DP,), (OD,), (OD,)],
    DP: [(AC,), (DP,)],
    OD: [(AC,), (ON,), (ON,), (ON,), (OD,), (OD,)],
    ON: [(SU,), (OD,), (OD,), (ON,)],
    GC: [tuple(m for m in ALL if m != W), (W,), (GC,)],
}
CASES = [(target, col + 1, m) for target, cols in EXPECTED_FROM.items() for col, froms in enumerate(cols)
         for m in froms]


def rule(target, column):
    return next(r for r in am.RULES if (r.target, r.column) == (target, column))


def test_rule_tables_have_the_seed_shape():
    shape = {t: len(c) for t, c in EXPECTED_FROM.items()}
    assert shape == {0: 3, 1: 6, 2: 9, 3: 5, 4: 2, 5: 8, 6: 2, 7: 6, 8: 4, 9: 3}
    assert [(r.target, r.column) for r in am.RULES] == [(t, c + 1) for t, cols in EXPECTED_FROM.items()
                                                        for c in range(len(cols))]
    for target, cols in EXPECTED_FROM.items():
        for c, froms in enumerate(cols, 1):
            expected = (am.STARTUP,) if froms == ("startup",) else froms
            assert rule(target, c).from_modes == expected
    assert {r.name for r in am.RULES if r.added} == {"Ground Command col 2", "Ground Command col 3"}
    amended = {r.name for r in am.RULES if r.seed_conditions is not None}
    assert amended == {"Deploy Wheel col 1", "Orbit Day col 5", "Orbit Night col 1", "Orbit Night col 2"}


# ---- driving each column alone ------------------------------------------------------------
def _levels(quantity):
    fine, coarse = P["fine_elevation_error"], P["coarse_elevation_error"]
    return {
        "xz_momentum_error": [0.5e-3, 2e-3],
        "momentum_error": [0.5e-3, 2e-3],
        "|wheel_rate|": [200.0, 500.0],
        "|sin_sun_elevation|": [0.5 * fine, 0.5 * (fine + coarse), 0.5],
        "|sin_sun_azimuth|": [0.5 * fine, 0.5 * (fine + coarse), 0.5],
        "body_rate": [0.005, 0.05],
    }[quantity]


INPUT_OF = {"|wheel_rate|": "wheel_rate", "|sin_sun_elevation|": "sin_sun_elevation",
            "|sin_sun_azimuth|": "sin_sun_azimuth"}


def _quantities(from_mode):
    qs = set()
    for r in am.RULES:
        if from_mode in r.from_modes:
            for c in r.conditions:
                qs.add(c if c in am.BOOLEAN_INPUTS else c.split(" ")[0])
    return sorted(qs)


def _delay_of(from_mode):
    return next((d for d, m in am.DELAY_MODE.items() if m == from_mode), None)


def _drive(r, from_mode):
    """Inputs and time in mode under which `r` fires from `from_mode` with as few other rules
    as possible (none into another mode). Returns (inputs, t_in_mode, decision)."""
    qs = _quantities(from_mode)
    choices = []
    for q in qs:
        if q in am.BOOLEAN_INPUTS:
            choices.append([False, True])
        elif q == "t_in_mode":
            d = P[_delay_of(from_mode)]
            choices.append([0.5 * d, d])
        else:
            choices.append(_levels(q))
    best = None
    for combo in itertools.product(*choices):
        inputs, tm = {}, 1.0
        for q, v in zip(qs, combo):
            if q == "t_in_mode":
                tm = v
            else:
                inputs[INPUT_OF.get(q, q)] = v
        inputs = am.check_inputs(inputs)
        if not r.fires(from_mode, inputs, tm, P):
            continue
        fired = [x for x in am.RULES if x.fires(from_mode, inputs, tm, P)]
        score = (sum(x.target != r.target for x in fired), len(fired))
        if best is None or score < best[0]:
            best = (score, inputs, tm)
    assert best is not None, f"{r.name} cannot fire from {from_mode}"
    return best[1], best[2]


@pytest.mark.parametrize("target,column,from_mode", [c for c in CASES if c[2] != "startup"],
                         ids=lambda v: str(v))
def test_each_column_drives_its_mode(target, column, from_mode):
    r = rule(target, column)
    inputs, tm = _drive(r, from_mode)
    m = am.AcsModeManager()
    m.set_state({"mode": from_mode, "t": 1000.0, "t_entered": 1000.0 - tm})
    d = m.step(1000.0, 1.0, inputs)
    # reset / ground-command columns override the normal rules that fire with them (priority)
    # and a transition out overrides the holds of the current mode
    lower = (lambda x: x.kind == "normal") if r.kind != "normal" else (lambda x: x.target == from_mode != target)
    others = [x.name for x in d.fired if x.target != target and not lower(x)]
    assert others == [], f"{r.name} co-fires with {others}"
    assert r in d.fired and m.mode == target and not m.uncertain
    assert m.rule == (target, column) or any(x.target == target for x in d.fired)
    # a hold keeps the timer, a transition (or reset/command re-entry) restarts it
    restarts = target != from_mode or r.kind in ("reset", "ground")
    assert m.t_entered == (1000.0 if restarts else 1000.0 - tm)
    assert m.time_in_mode == pytest.approx(1.0 if restarts else tm + 1.0)


def test_startup_column_enters_wait():
    m = am.AcsModeManager(t0=5.0)
    assert (m.mode, m.t_entered, m.time_in_mode, m.rule, m.uncertain) == (W, 5.0, 0.0, (W, 1), False)
    assert m.permissions == (False, False, False)


def test_amendment_a1_literal_deploy_wheel_is_unreachable():
    """Literally, Deploy Wheel col 1 implies Spinup col 6 (same from-mode, a subset of its
    conditions), so every time it fires there is a conflict and Deploy Wheel is never entered."""
    lit = {(r.target, r.column): r for r in am.literal_rules()}
    dw, su6 = lit[(DW, 1)], lit[(SU, 6)]
    assert dw.from_modes == su6.from_modes
    assert all(dw.conditions.get(c) == v for c, v in su6.conditions.items())
    inputs = am.check_inputs({"orbit_day": True, "momentum_error": 2e-3, "sin_sun_elevation": 0.5,
                              "wheel_rate": 0.0})
    d = am.decide(RE, P["RMD"], inputs, P, am.literal_rules())
    assert dw in d.fired and d.uncertain and d.mode == SU
    d = am.decide(RE, P["RMD"], am.check_inputs({"orbit_day": True, "sin_sun_elevation": 0.05}), P)
    assert d.mode == DW and not d.uncertain


def test_amendment_a2_literal_orbit_night_col2_kills_orbit_day_hold():
    lit = {(r.target, r.column): r for r in am.literal_rules()}
    inputs = am.check_inputs({"orbit_day": True, "sin_sun_elevation": 0.05, "sin_sun_azimuth": 0.05})
    assert am.decide(OD, 20.0, inputs, P, am.literal_rules()).mode == ON
    assert lit[(OD, 6)] in am.decide(OD, 20.0, inputs, P, am.literal_rules()).fired
    d = am.decide(OD, 20.0, inputs, P)
    assert d.mode == OD and d.rule == rule(OD, 6)


def test_amendments_a3_a4_a5_against_the_literal_draft():
    lit = am.literal_rules()
    # A3: literal Spinup -> Orbit Night at once; amended after SMD only (before: fallback, stays)
    inputs = am.check_inputs({"paddles_deployed": True, "optical_tracking": True})
    assert am.decide(SU, 1.0, inputs, P, lit).mode == ON
    d = am.decide(SU, 1.0, inputs, P)
    assert d.mode == SU and d.uncertain and not d.enter
    assert am.decide(SU, P["SMD"], inputs, P).mode == ON
    # A4: literal Ground Command has no hold
    assert am.decide(GC, 1.0, am.check_inputs(), P, lit).uncertain
    assert am.decide(GC, 1.0, am.check_inputs(), P).mode == GC
    # A5: Orbit Day entered in daylight without tracking
    inputs = am.check_inputs({"orbit_day": True})
    assert am.decide(OD, 1.0, inputs, P, lit).uncertain
    assert am.decide(OD, 1.0, inputs, P).mode == OD


# ---- conflict resolution -----------------------------------------------------------------
def test_priority_reset_then_ground_command_then_transitions_then_holds():
    base = {"orbit_day": True, "sin_sun_elevation": 0.5}
    # reset beats ground command and everything else
    d = am.decide(AC, 50.0, am.check_inputs({**base, "reset": True, "ground_command": True}), P)
    assert d.mode == W and d.rule == rule(W, 2) and d.enter
    # ground command beats a transition out (Acquire -> Reorient fires too)
    d = am.decide(AC, 50.0, am.check_inputs({**base, "ground_command": True}), P)
    assert d.mode == GC and rule(RE, 5) in d.fired
    # transition out beats a hold: Reorient col 3 (hold) and Deploy Wheel col 1 both fire
    d = am.decide(RE, P["RMD"], am.check_inputs({"orbit_day": True, "sin_sun_elevation": 0.05}), P)
    assert d.mode == DW and rule(RE, 3) in d.fired
    # two transitions into different modes: conflict -> Spinup, uncertain (Orbit Night col 2 and
    # Spinup col 8: tracking lost at night after ODMD)
    d = am.decide(OD, 20.0, am.check_inputs({"orbit_day": False}), P)
    assert {r.name for r in d.fired} == {"Orbit Night col 2", "Spinup col 8"}
    assert d.mode == SU and d.uncertain and d.rule is None and d.enter
    # no rule -> Spinup, uncertain (Reorient reaching the coarse elevation before RMD)
    d = am.decide(RE, 10.0, am.check_inputs({"orbit_day": True, "sin_sun_elevation": 0.05}), P)
    assert d.fired == [] and d.mode == SU and d.uncertain


def test_uncertain_flag_in_the_model_and_spinup_timer_kept():
    m = am.AcsModeManager()
    m.set_state({"mode": RE, "t": 100.0, "t_entered": 50.0})
    m.step(100.0, 1.0, {"orbit_day": True, "sin_sun_elevation": 0.05})
    assert (m.mode, m.uncertain, m.t_entered, m.rule) == (SU, True, 100.0, None)
    m.step(101.0, 1.0, {"paddles_deployed": True})  # Spinup, no rule: stays, timer kept
    assert (m.mode, m.uncertain, m.t_entered) == (SU, True, 100.0)
    m.step(102.0, 1.0, {})  # Spinup col 2 hold
    assert (m.mode, m.uncertain, m.rule) == (SU, False, (SU, 2))


# ---- delays on both sides -----------------------------------------------------------------
DAY = {"orbit_day": True}
LOW = {"sin_sun_elevation": 0.05, "sin_sun_azimuth": 0.05}
# (delay, source, inputs, gated target, mode just before the delay); before_mode Spinup from a
# source without a hold for these inputs is an uncertain fallback (FALLBACK_BEFORE)
DELAY_CASES = [
    ("WMD", W, {}, DT, W),
    ("DMD", DT, {"xz_momentum_error": 0.5e-3}, SU, DT),
    ("SMD", SU, {**DAY}, RE, SU),
    ("SMD", SU, {"xz_momentum_error": 2e-3}, DT, SU),
    ("SMD", SU, {"paddles_deployed": True, "optical_tracking": True}, ON, SU),  # A3; before: fallback
    ("RMD", RE, {**DAY, **LOW, "wheel_rate": 500.0}, AC, SU),  # before RMD no Reorient hold (draft gap)
    ("RMD", RE, {**DAY, **LOW, "wheel_rate": 0.0}, DW, SU),
    ("DWMD", DW, {}, AC, DW),
    ("AMD", AC, {**DAY, **LOW}, DP, AC),
    ("AMD", AC, {**DAY, **LOW, "paddles_deployed": True}, OD, AC),
    ("AMD", AC, {**DAY, "sin_sun_elevation": 0.5}, RE, AC),
    ("DPMD", DP, {}, AC, DP),
    ("ODMD", OD, {**DAY, "sin_sun_elevation": 0.05, "sin_sun_azimuth": 0.5}, AC, OD),
    ("ODMD", OD, {**DAY, **LOW, "optical_tracking": True}, ON, OD),
    ("ODMD", OD, {**LOW, "optical_tracking": True}, ON, SU),  # night within ODMD: no rule
    ("GCMD", GC, {}, DT, GC),
]


@pytest.mark.parametrize("delay,source,inputs,target,before_mode", DELAY_CASES, ids=lambda v: str(v))
def test_delay_both_sides(delay, source, inputs, target, before_mode):
    """Just before the delay the gated transition does not happen (the source holds, or where the
    draft has no hold there, the decision falls back to Spinup); at and after it, it does."""
    d = P[delay]
    for dt, expected in ((-1e-6, before_mode), (-0.5, before_mode), (0.0, target), (1.0, target)):
        m = am.AcsModeManager()
        m.set_state({"mode": source, "t": 500.0, "t_entered": 500.0})
        m.step(500.0 + d + dt, 1.0, inputs)
        assert m.mode == expected, (delay, dt)
        fallback = before_mode == SU and (source != SU or "paddles_deployed" in inputs)
        assert m.uncertain == (dt < 0 and fallback)  # fallback only where the draft has no hold


def test_accumulated_steps_reach_the_delay_exactly():
    m = am.AcsModeManager()
    t, k = 0.0, 0
    while m.mode == W:
        m.step(t, 0.1)
        t += 0.1
        k += 1
    assert k == 101 and m.t_entered == pytest.approx(10.0)  # decided at the 101st point, t = 10


# ---- startup, reset, ground command -------------------------------------------------------
@pytest.mark.parametrize("mode", ALL)
def test_reset_from_any_mode_goes_to_wait_and_waits_wmd(mode):
    m = am.AcsModeManager()
    m.set_state({"mode": mode, "t": 300.0, "t_entered": 100.0})
    m.step(300.0, 1.0, {"reset": True, "ground_command": True})
    assert (m.mode, m.t_entered, m.permissions) == (W, 300.0, (False, False, False))
    t = 301.0
    while t < 310.0:
        m.step(t, 1.0, {"ground_command": True})  # a command in Wait waits for WMD (A6)
        assert m.mode == W
        t += 1.0
    m.step(310.0, 1.0, {})
    assert m.mode == DT


@pytest.mark.parametrize("mode", ALL)
def test_ground_command_from_any_mode_and_back_to_detumble(mode):
    m = am.AcsModeManager()
    m.set_state({"mode": mode, "t": 300.0, "t_entered": 200.0})  # Wait: WMD elapsed
    m.step(300.0, 1.0, {"ground_command": True})
    assert (m.mode, m.t_entered) == (GC, 300.0)
    m.step(305.0, 1.0, {"ground_command": True})  # a new command restarts GCMD
    assert (m.mode, m.t_entered) == (GC, 305.0)
    m.step(314.9, 1.0, {})
    assert m.mode == GC
    m.step(315.0, 1.0, {})
    assert m.mode == DT and m.rule == (DT, 6)


# ---- random sequences -----------------------------------------------------------------------
GATED = {(W, DT): "WMD", (DT, SU): "DMD", (SU, DT): "SMD", (SU, RE): "SMD", (SU, ON): "SMD",
         (RE, DW): "RMD", (RE, AC): "RMD", (DW, AC): "DWMD", (AC, RE): "AMD", (AC, DP): "AMD",
         (AC, OD): "AMD", (OD, ON): "ODMD", (GC, DT): "GCMD"}
UNGATED = {(RE, SU), (AC, SU), (DP, AC), (OD, SU), (OD, AC), (ON, SU), (ON, OD)}

_num = st.sampled_from
inputs_st = st.fixed_dictionaries({
    "xz_momentum_error": _num([0.0, 0.5e-3, 1e-3, 2e-3]),
    "momentum_error": _num([0.0, 0.5e-3, 1e-3, 2e-3]),
    "wheel_rate": _num([0.0, -450.0, 400.0, 500.0]),
    "sin_sun_elevation": _num([0.0, 0.02, -0.05, 0.1, 0.5, -1.0]),
    "sin_sun_azimuth": _num([0.0, 0.02, 0.05, -0.1, 0.5, 1.0]),
    "body_rate": _num([0.0, 0.01, 0.05]),
    "orbit_day": st.booleans(), "paddles_deployed": st.booleans(), "optical_tracking": st.booleans(),
    "ground_command": st.sampled_from([False] * 15 + [True]),
    "reset": st.sampled_from([False] * 20 + [True]),
})
steps_st = st.lists(st.tuples(st.sampled_from([0.1, 1.0, 3.0, 9.99, 10.0, 60.0, 100.0, 2000.0]), inputs_st),
                    min_size=1, max_size=60)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(start=st.one_of(st.just(None), st.tuples(st.sampled_from(ALL), st.floats(0.0, 7000.0))),
       steps=steps_st)
def test_random_sequences_respect_modes_and_delays(start, steps):
    m = am.AcsModeManager()
    t = 1.0e4
    if start is None:
        m = am.AcsModeManager(t0=t)
        wait_since = t
    else:
        m.set_state({"mode": start[0], "t": t, "t_entered": t - start[1]})
        wait_since = t - start[1] if start[0] == W else None
    for h, inputs in steps:
        before, tm = m.mode, t - m.t_entered
        d = m.step(t, h, inputs)
        assert m.mode in ALL and isinstance(m.mode, int)
        if inputs["reset"]:
            assert m.mode == W
            wait_since = t
        elif before == W and m.mode != W and wait_since is not None:
            assert t - wait_since >= P["WMD"] - am.TIME_TOL  # never leaves Wait before WMD
        if d.rule is not None and d.rule.kind == "normal" and m.mode != before:
            assert (before, m.mode) in set(GATED) | UNGATED
            if (before, m.mode) in GATED:
                assert tm >= P[GATED[(before, m.mode)]] - am.TIME_TOL
        if d.uncertain:
            assert m.mode == SU and d.rule is None
        if m.mode == W and before != W:
            wait_since = t
        assert m.time_in_mode >= 0.0
        t += h


# ---- nominal sequence ---------------------------------------------------------------------
def test_nominal_sequence_through_all_modes_and_alternating_day_night():
    """0 -> 1 -> 2 -> 3 -> 4 -> 5 -> 6 -> 5 -> 7 -> 8 -> 7 -> 8 with 1 s steps.

    What the tables demand of the inputs: Reorient must keep the Sun elevation beyond the
    coarse error until RMD (col 4), the optical system must still track at dawn (Orbit Day col
    4) and stop tracking within ODMD of entering Orbit Day (else Orbit Night col 3 after ODMD)."""
    period, night = 5800.0, 2100.0
    t_ops = 7000.0

    def inputs(t, mode_now):
        i = {"orbit_day": True, "xz_momentum_error": 5e-3 if t < 150 else 2e-4,
             "momentum_error": 5e-3 if t < 300 else 2e-4,
             "sin_sun_elevation": 0.5 if t < 6300 else 0.02, "sin_sun_azimuth": 0.5 if t < 6500 else 0.02,
             "wheel_rate": 0.0 if t < 6400 else 420.0, "paddles_deployed": t >= 6600, "body_rate": 0.001}
        if t >= t_ops:
            phase = (t - t_ops + 1000.0) % period  # operations start 1000 s after dawn
            i["orbit_day"] = phase < period - night
            i["optical_tracking"] = not i["orbit_day"] or phase < 5.0  # still tracking just after dawn
        return i

    m = am.AcsModeManager()
    t, modes, entries = 0.0, [0], [(0, 0.0)]
    while t < t_ops + 2 * period + 100:
        m.step(t, 1.0, inputs(t, m.mode))
        assert not m.uncertain, (t, m.mode)
        if m.mode != modes[-1]:
            modes.append(m.mode)
            entries.append((m.mode, t))
        t += 1.0
    assert modes == [W, DT, SU, RE, DW, AC, DP, AC, OD, ON, OD, ON, OD]
    times = dict()
    for mode, te in entries:
        times.setdefault(mode, te)
    assert times[DT] == 10.0 and times[SU] == 150.0 and times[RE] == 300.0
    assert times[DW] == 6300.0 and times[AC] == 6480.0 and times[DP] == 6500.0
    night_start = t_ops - 1000.0 + period - night
    on_entries = [te for mode, te in entries if mode == ON]
    assert on_entries == [night_start, night_start + period]


def test_daylight_tracking_cycles_orbit_day_and_night():
    """Literal Orbit Night col 3 (no day condition) with Orbit Day col 4: tracking in daylight
    alternates 7 -> 8 after ODMD and straight back 8 -> 7 (documented draft behaviour)."""
    m = am.AcsModeManager()
    m.set_state({"mode": OD, "t": 0.0, "t_entered": 0.0})
    seen = []
    for k in range(25):
        m.step(float(k), 1.0, {**DAY, **LOW, "optical_tracking": True, "paddles_deployed": True})
        seen.append(m.mode)
    assert seen[:10] == [OD] * 10 and seen[10:12] == [ON, OD] and seen[12:21] == [OD] * 9 and seen[21] == ON
    assert not m.uncertain


# ---- parameters and inputs --------------------------------------------------------------------
@pytest.mark.parametrize("params,match", [
    ({"WMD": -1.0}, r"WMD .* \[0, inf\)"), ({"RMD": math.nan}, "RMD"),
    ({"coarse_azimuth_error": 1.5}, r"coarse_azimuth_error .*\(0, 1\]"),
    ({"fine_elevation_error": 0.5}, r"fine_elevation_error .*coarse_elevation_error"),
    ({"max_tumble_rate": 0.0}, r"max_tumble_rate .*\(0, inf\)"), ({"bogus": 1.0}, "bogus")])
def test_bad_parameters_are_named(params, match):
    with pytest.raises(ValueError, match=match):
        am.AcsModeManager(params)


def test_bad_inputs_are_named():
    m = am.AcsModeManager()
    with pytest.raises(ValueError, match="sin_sun_azimuth"):
        m.step(0.0, 1.0, {"sin_sun_azimuth": 1.5})
    with pytest.raises(ValueError, match="body_rate"):
        m.step(0.0, 1.0, {"body_rate": -0.1})
    with pytest.raises(ValueError, match="xz_momentum_error"):
        m.step(0.0, 1.0, {"xz_momentum_error": math.inf})


def test_permission_table():
    assert am.PERMISSIONS[W] == (False, False, False)
    assert am.PERMISSIONS[DW] == (False, True, False)
    assert am.PERMISSIONS[DP] == (False, True, True)
    assert [m for m in ALL if am.PERMISSIONS[m][2]] == [DP]
    assert all(am.PERMISSIONS[m] == (True, True, False) for m in (DT, SU, RE, AC, OD, ON, GC))


def test_state_round_trip_is_json():
    import json

    m = am.AcsModeManager()
    for k in range(15):
        m.step(float(k), 1.0, {"xz_momentum_error": 0.01})
    s = json.loads(json.dumps(m.get_state()))
    n = am.AcsModeManager()
    n.set_state(s)
    assert (n.mode, n.t, n.t_entered, n.rule, n.uncertain) == (m.mode, m.t, m.t_entered, m.rule, m.uncertain)


# ---- FMU ----------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def acs_fmu(tmp_path_factory):
    import build_fmus

    return build_fmus.build_fmu(REPO / "fmus" / "neighbor_acs_mode_manager.py", tmp_path_factory.mktemp("acs_fmu"))


def test_fmu_valid_units_and_no_feedthrough(acs_fmu):
    assert validate_fmu(str(acs_fmu)) == []
    md = fmpy.read_model_description(str(acs_fmu))
    assert md.coSimulation.canGetAndSetFMUstate
    v = {x.name: x for x in md.modelVariables}
    assert "0 Wait, 1 Detumble, 2 Spinup" in v["mode"].description and "9 Ground Command" in v["mode"].description
    assert v["mode"].type == "Integer" and v["uncertain"].type == "Boolean" and v["reset"].type == "Boolean"
    assert v["xz_momentum_error"].unit == "N.m.s" and v["wheel_rate"].unit == "rad/s"
    assert v["sin_sun_azimuth"].unit == "1" and v["RMD"].unit == "s" and v["time_in_mode"].unit == "s"
    assert float(v["RMD"].start) == 6000.0 and float(v["GCMD"].start) == 10.0
    assert all(u.dependencies == [] for u in md.outputs)
    assert {u.variable.name for u in md.outputs} == {"mode", "time_in_mode", "coils_enabled", "wheel_enabled",
                                                      "paddle_deploy", "uncertain", "rule_table", "rule_column"}


def test_fmu_simulates_alone_wait_then_detumble(acs_fmu):
    r = fmpy.simulate_fmu(str(acs_fmu), stop_time=15.0, output_interval=1.0,
                          start_values={"xz_momentum_error": 0.01})
    t, mode = list(r["time"]), list(r["mode"])
    assert mode[:11] == [0] * 11 and not any(r["coils_enabled"][:11])
    assert mode[11:] == [1] * 5  # decided at t = 10, visible after that step
    k = t.index(11.0)
    assert t[k] - r["time_in_mode"][k] == pytest.approx(10.0) and r["coils_enabled"][k]


def test_fmu_get_set_state_restores_mode_and_time(acs_fmu, tmp_path):
    md = fmpy.read_model_description(str(acs_fmu))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(acs_fmu), unzipdir=str(tmp_path / "u")),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="modes")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.setReal([vr["xz_momentum_error"]], [0.01])

        def read():
            return fmu.getInteger([vr["mode"]])[0], fmu.getReal([vr["time_in_mode"]])[0]

        for k in range(12):
            fmu.doStep(float(k), 1.0)
        saved, at_save = fmu.getFMUstate(), read()
        assert at_save == (1, 2.0)
        fmu.setBoolean([vr["reset"]], [True])
        fmu.doStep(12.0, 1.0)
        assert read() == (0, 1.0)
        fmu.setFMUstate(saved)
        assert read() == at_save
        fmu.setBoolean([vr["reset"]], [False])
        fmu.doStep(12.0, 1.0)
        assert read() == (1, 3.0)
        fmu.freeFMUstate(saved)
    finally:
        fmu.terminate()
        fmu.freeInstance()
