"""NEIGHBOR data storage and downlink (NEIGHBOR thesis section 3.6, Table 7, Figure 47, Appendix I):
the Table 7 rate, exact stepping with net rates and clamps, the thesis' de-orbit data profile
(below 0.1 MB, downlinked within two contacts), overflow counting, errors, and the
`DataStorage` FMU through FMPy."""
import math

import fmpy
import pytest

from components.mission import data_storage as ds
from fmu_helpers import check_declarations, instantiate

# De-orbit mode phases that record (Appendix I: attitude determination, control, burn), s
AD_TIME, CONTROL_TIME, BURN_TIME = 600.0, 9.97 + 166.26, 38.74 * 60.0
RECORD_TIME = AD_TIME + CONTROL_TIME + BURN_TIME  # 3100.63 s


def test_table7_rate():
    """Table 7: 28 B/s at 1 s, 12 B per 10 s, 65 B per 60 s = 1817 B/min = 30.2833 B/s ("30 bytes
    per second" in the text); 8 bytes once per maneuver. Appendix I's 29.503 B/s is 2.6 % lower."""
    assert ds.table7_rate() == pytest.approx(1817.0 / 60.0, rel=1e-12)
    assert ds.RECORDING_RATE == pytest.approx(30.2833, abs=1e-4)
    assert round(ds.RECORDING_RATE) == 30
    assert ds.table7_once_bytes() == 8
    assert len(ds.TABLE7) == 18
    assert (ds.RECORDING_RATE - ds.APPENDIX_I_RATE) / ds.RECORDING_RATE == pytest.approx(0.0258, abs=5e-4)
    assert ds.DOWNLINK_RATE == 1200.0 and ds.CAPACITY == 256000.0
    # a store that never fills: the rate is the Table 7 rate
    s = ds.DataStorage()
    s.step(True, False, False, 60.0)
    assert s.storage_used == pytest.approx(1817.0, rel=1e-12) and s.storage_free == pytest.approx(256000.0 - 1817.0)


def test_thesis_deorbit_profile_below_0_1_MB_and_downlinked_within_two_contacts():
    """Section 3.6: storage never exceeds 0.1 MB (Appendix I plots bytes / 1e6) over the
    de-orbit phase, and two contacts after the maneuver suffice to downlink it. Recording for
    3100.63 s (10 min attitude determination, 176.23 s detumble + slew, 38.74 min burn) stores
    93 897 B at the Table 7 rate (91 478 B at Appendix I's rate); at 1200 B/s that takes 78.2 s
    of contact, well inside one 5-min pass. Representative passes: 5 and 10 min, an orbit apart."""
    for rate, expected in ((ds.RECORDING_RATE, 93897.4), (ds.APPENDIX_I_RATE, 91477.9)):
        s = ds.DataStorage(recording_rate=rate)
        peak = 0.0
        for dt in (AD_TIME, CONTROL_TIME, BURN_TIME):
            s.step(True, True, False, dt)  # downlink commanded but no contact during the burn
            peak = max(peak, s.storage_used)
        assert s.storage_used == pytest.approx(expected, abs=0.1)
        assert peak < 0.1e6 and not s.overflow and s.bytes_lost == 0.0
        stored = s.storage_used
        assert stored / ds.DOWNLINK_RATE == pytest.approx(expected / 1200.0)
        contacts = 0
        for pass_time in (5 * 60.0, 10 * 60.0):
            if s.storage_used == 0.0:
                break
            s.step(False, False, False, 92.8 * 60.0 - pass_time)
            s.step(False, True, True, pass_time)
            contacts += 1
        assert contacts <= 2 and s.storage_used == 0.0
        assert contacts == 1  # 78 s of a 5-min pass already empties it
        assert s.downlinked == pytest.approx(stored, rel=1e-12)
    # the same with a 1-s master step (as Appendix I) ends at the same bytes
    s = ds.DataStorage()
    for _ in range(3100):
        s.step(True, False, False, 1.0)
    s.step(True, False, False, 0.63)
    assert s.storage_used == pytest.approx(RECORD_TIME * ds.RECORDING_RATE, abs=1e-6)
    for _ in range(79):
        s.step(False, True, True, 1.0)
    assert s.storage_used == 0.0 and s.downlinked == pytest.approx(RECORD_TIME * ds.RECORDING_RATE, abs=1e-6)


def test_net_rate_and_clamps_are_exact_at_any_step():
    # recording and downlink together: net -1169.7 B/s empties the store inside the step, then
    # new data stream straight out at the recording rate
    s = ds.DataStorage(initial_storage_used=10000.0)
    s.step(True, True, True, 100.0)
    t0 = 10000.0 / (1200.0 - ds.RECORDING_RATE)
    assert s.storage_used == 0.0
    assert s.downlinked == pytest.approx(1200.0 * t0 + ds.RECORDING_RATE * (100.0 - t0), rel=1e-12)
    assert s.downlinked == pytest.approx(10000.0 + 100.0 * ds.RECORDING_RATE, rel=1e-12)  # conservation
    # downlink needs both switches
    for enable, contact in ((True, False), (False, True), (False, False)):
        s = ds.DataStorage(initial_storage_used=5000.0)
        s.step(False, enable, contact, 10.0)
        assert s.storage_used == 5000.0 and s.downlinked == 0.0
    # empty store, downlink only: nothing sent
    s = ds.DataStorage()
    s.step(False, True, True, 10.0)
    assert s.downlinked == 0.0 and s.storage_used == 0.0
    # recording faster than the downlink into a small store: fills inside the step, the rest lost
    s = ds.DataStorage(capacity=1000.0, recording_rate=1500.0, downlink_rate=1200.0)
    s.step(True, True, True, 10.0)
    assert s.storage_used == 1000.0 and s.storage_free == 0.0
    assert s.bytes_lost == pytest.approx(300.0 * 10.0 - 1000.0) and s.overflow
    assert s.downlinked == pytest.approx(12000.0)
    # one step vs many: identical results through the fill instant
    a = ds.DataStorage(capacity=5000.0)
    b = ds.DataStorage(capacity=5000.0)
    a.step(True, False, False, 200.0)
    for _ in range(2000):
        b.step(True, False, False, 0.1)
    assert a.storage_used == b.storage_used == 5000.0
    assert b.bytes_lost == pytest.approx(a.bytes_lost, abs=1e-6)
    assert a.bytes_lost == pytest.approx(200.0 * ds.RECORDING_RATE - 5000.0, rel=1e-12)
    # bytes are conserved: recorded = stored + downlinked + lost
    c = ds.DataStorage(capacity=3000.0)
    pattern = [(True, False, False, 70.0), (True, True, True, 2.0), (True, False, False, 200.0),
               (False, True, True, 1.0), (True, True, False, 33.3)]
    recorded = 0.0
    for rec, en, con, dt in pattern * 3:
        c.step(rec, en, con, dt)
        recorded += ds.RECORDING_RATE * dt if rec else 0.0
    assert c.storage_used + c.downlinked + c.bytes_lost == pytest.approx(recorded, rel=1e-12)
    assert c.overflow and c.bytes_lost > 0.0


def test_overflow_counted_and_latched():
    """256 000 B fill after 8453.4 s of recording at 30.2833 B/s (2.35 h, three de-orbit
    recordings' worth); from then on every recorded byte is lost and counted; the flag latches
    even after the store is downlinked."""
    s = ds.DataStorage()
    t_full = 256000.0 / ds.RECORDING_RATE
    assert t_full == pytest.approx(8453.4, abs=0.1)
    s.step(True, False, False, t_full - 1.0)
    assert not s.overflow and s.bytes_lost == 0.0
    s.step(True, False, False, 101.0)
    assert s.storage_used == 256000.0 and s.overflow
    assert s.bytes_lost == pytest.approx(100.0 * ds.RECORDING_RATE, rel=1e-9)
    s.step(False, True, True, 600.0)
    assert s.storage_used == 0.0 and s.overflow and s.downlinked == pytest.approx(256000.0)
    # filling exactly to capacity loses nothing and does not flag
    s = ds.DataStorage(capacity=100.0, recording_rate=10.0)
    s.step(True, False, False, 10.0)
    assert s.storage_used == 100.0 and not s.overflow and s.bytes_lost == 0.0


def test_errors_name_the_parameter():
    for kwargs, name in (({"capacity": 0.0}, "capacity"), ({"capacity": -256e3}, "capacity"),
                         ({"recording_rate": -1.0}, "recording_rate"), ({"downlink_rate": math.nan}, "downlink_rate"),
                         ({"initial_storage_used": 300e3}, "initial_storage_used"),
                         ({"initial_storage_used": -1.0}, "initial_storage_used")):
        with pytest.raises(ValueError, match=name):
            ds.DataStorage(**kwargs)
    with pytest.raises(ValueError, match=r"initial_storage_used.*\[0.0, 256000.0\] byte"):
        ds.DataStorage(initial_storage_used=1e6)
    with pytest.raises(ValueError, match="step size"):
        ds.DataStorage().step(True, False, False, -1.0)


def test_state_round_trip():
    s = ds.DataStorage(capacity=2000.0)
    s.step(True, False, False, 50.0)
    saved = s.get_state()
    s.step(True, False, False, 100.0)
    after = s.get_state()
    assert after["overflow"]
    s.set_state(saved)
    assert not s.overflow
    s.step(True, False, False, 100.0)
    assert s.get_state() == after


# ---- FMU ------------------------------------------------------------------------------------
def test_data_storage_fmu(build_one, tmp_path):
    path = build_one("neighbor_data_storage.py")
    deps = check_declarations(path)
    assert deps == {"storage_used": [], "storage_free": [], "bytes_lost": [], "overflow": [], "downlinked": []}
    md = fmpy.read_model_description(str(path))
    var = {v.name: v for v in md.modelVariables}
    assert md.coSimulation.modelIdentifier == "DataStorage"
    assert float(var["recording_rate"].start) == ds.RECORDING_RATE and var["recording_rate"].unit == "byte/s"
    assert var["capacity"].unit == "byte" and float(var["capacity"].start) == 256000.0
    assert all(var[n].type == "Boolean" and var[n].causality == "input"
               for n in ("data_recording", "downlink_enable", "ground_contact"))

    fmu, vr = instantiate(path, tmp_path, "data", initialize=True)
    reals = [vr[n] for n in ("storage_used", "storage_free", "bytes_lost", "downlinked")]
    try:
        assert fmu.getReal(reals) == [0.0, 256000.0, 0.0, 0.0]
        fmu.setBoolean([vr["data_recording"]], [True])
        fmu.doStep(0.0, RECORD_TIME)
        used = fmu.getReal(reals)[0]
        assert used == pytest.approx(93897.41, abs=0.01)
        saved = fmu.getFMUstate()
        fmu.doStep(RECORD_TIME, 10000.0)  # overflows
        assert fmu.getBoolean([vr["overflow"]]) == [True]
        assert fmu.getReal([vr["bytes_lost"]])[0] == pytest.approx(used + 10000.0 * ds.RECORDING_RATE - 256000.0)
        fmu.setFMUstate(saved)
        assert fmu.getReal(reals)[0] == used and fmu.getBoolean([vr["overflow"]]) == [False]
        fmu.setBoolean([vr[n] for n in ("data_recording", "downlink_enable", "ground_contact")], [False, True, True])
        fmu.doStep(RECORD_TIME, 300.0)
        assert fmu.getReal(reals) == [0.0, 256000.0, 0.0, pytest.approx(used)]
        fmu.freeFMUstate(saved)
    finally:
        fmu.terminate()
        fmu.freeInstance()
    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(path), stop_time=1.0, start_values={"capacity": -1.0})
