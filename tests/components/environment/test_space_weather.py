"""CSSI space-weather reader and constant space weather: values against the file's own lines,
section handling (observed, daily and monthly predictions, hold after the end), coverage and
parse errors."""
import math
from pathlib import Path

import numpy as np
import pytest

from components.environment import space_weather as sw_mod
from components.environment.space_weather import ConstantSpaceWeather, SpaceWeather
from paths import SHARED

# the team's shared reference data, beside the repository (as in CI)
SHARED_FILE = SHARED / "data" / "space_weather" / "SW-All_CSSI_2026-08-22.txt"


def jd(y, m, d, hour=0.0):
    return sw_mod._jd_of_date(y, m, d) + hour / 24.0


@pytest.fixture(scope="module")
def sw():
    return SpaceWeather.from_file()


def test_observed_values_from_the_file_lines(sw):
    # 2011 08 07 ... Ap 7, adj 108.4, adj ctr81 104.9, obs 105.4, obs ctr81 102.3
    # 2011 08 08 2429  5 20 23 13 23 23 10 10 20 143   7   9   5   9   9   4   4   7   7 ... 104.3 0 105.6
    #            99.4 101.5 103.0 96.4
    t = jd(2011, 8, 8, 12.5)
    assert sw.f107(t) == 101.5 and sw.f107(t, "adjusted") == 104.3
    assert sw.f107_previous_day(t) == 105.4 and sw.f107_previous_day(t, "adjusted") == 108.4
    assert sw.f107a(t) == 103.0 and sw.f107a(t, "adjusted") == 105.6
    assert sw.ap_daily(t) == 7.0
    assert sw.kp_3h(t) == 2.3            # 12:00-15:00 slot: "23"
    assert sw.kp_3h(jd(2011, 8, 8, 23.9)) == 2.0
    assert sw.ap_3h(t) == 9.0 and sw.ap_3h(t, 3.0) == 9.0 and sw.ap_3h(t, 6.0) == 5.0
    # the 7 NRLMSIS ap values: daily, now, -3 h, -6 h, -9 h, mean(-12..-33 h), mean(-36..-57 h)
    ap_0808 = [7, 9, 5, 9, 9, 4, 4, 7]
    ap_0807 = [22, 6, 6, 3, 4, 3, 6, 7]
    ap_0806 = [94, 48, 22, 27, 22, 18, 5, 15]
    seq = ap_0808[:5][::-1] + ap_0807[::-1] + ap_0806[::-1]  # 3-h values going back from 12:30
    expected = [7.0, seq[0], seq[1], seq[2], seq[3], np.mean(seq[4:12]), np.mean(seq[12:20])]
    assert sw.msis_ap(t) == pytest.approx(expected, abs=1e-12)
    with pytest.raises(ValueError, match="kind"):
        sw.f107(t, "smoothed")


def test_bundled_copy_is_the_shared_file_trimmed(sw):
    """The bundled file equals the shared CelesTrak file from 2000-01-01 on."""
    if not SHARED_FILE.is_file():
        pytest.skip(f"the shared reference file {SHARED_FILE} is not beside the repository")
    full = SpaceWeather.from_file(SHARED_FILE)
    assert full.first_jd == jd(1957, 10, 1) and sw.first_jd == jd(2000, 1, 1)
    off = int(sw.first_jd - full.first_jd)
    np.testing.assert_array_equal(full.daily[off + 1:], sw.daily[1:])  # row 0: no previous day in the copy
    np.testing.assert_array_equal(full.ap3h[8 * off:], sw.ap3h)
    header = Path(sw_mod.BUNDLED_FILE).read_text().splitlines()[:15]
    assert header == SHARED_FILE.read_text().splitlines()[:15]


def test_predictions_and_hold_after_the_end(sw):
    # daily prediction 2026-09-13: F10.7 adj 130.0, obs 128.4, Ap 5
    assert sw.f107(jd(2026, 9, 13, 6)) == 128.4 and sw.f107(jd(2026, 9, 13), "adjusted") == 130.0
    # gap between the last daily prediction (2026-10-05) and the first monthly one (2026-11-01)
    assert sw.f107(jd(2026, 10, 20)) == 95.0 and sw.ap_daily(jd(2026, 10, 20)) == 5.0
    # monthly prediction 2027-01: adj 115.5, obs 119.5, ctr81 obs 120.0; Kp/Ap held from the last daily line
    assert sw.f107(jd(2027, 1, 15), "adjusted") == 115.5 and sw.f107(jd(2027, 1, 31)) == 119.5
    assert sw.f107a(jd(2027, 1, 15)) == 120.0
    assert sw.ap_daily(jd(2030, 6, 1)) == 5.0 and sw.kp_3h(jd(2030, 6, 1)) == 1.3
    # last entry 2041-10-01 (adjusted F10.7 = 70.0, the thesis' solar-minimum value) held after the end
    last = jd(2041, 10, 1)
    assert sw.last_jd == last
    assert not sw.past_end(last + 0.99) and sw.past_end(last + 1.0)
    for t in (last, last + 1.0, last + 3650.0):
        assert sw.f107(t, "adjusted") == 70.0 and sw.f107(t) == 69.8 and sw.f107a(t) == 68.8
        if t > last:
            assert sw.f107_previous_day(t) == 69.8  # the held entry is also "the previous day"
    assert not sw.past_end(jd(2023, 1, 1))


def test_before_the_first_entry_is_an_error(sw):
    with pytest.raises(ValueError, match=r"1999-12-31T12:00:00Z.*before the first entry.*2000-01-01"):
        sw.f107(jd(1999, 12, 31, 12))
    with pytest.raises(ValueError, match="finite"):
        sw.f107(math.nan)


def test_kernel_arrays_index_by_day(sw):
    jd0, daily, ap3h = sw.kernel_arrays()
    assert daily.dtype == np.float64 and daily.shape == (int(sw.last_jd - jd0) + 1, sw_mod.NCOL)
    assert ap3h.shape == (8 * daily.shape[0],)
    t = jd(2011, 8, 8, 12.5)
    i = sw_mod.day_index(t, jd0, daily.shape[0])
    assert daily[i, sw_mod.COL_F107_OBS] == 101.5 and daily[i, sw_mod.COL_KP + 4] == 2.3
    assert sw_mod.day_index(jd0 - 0.1, jd0, daily.shape[0]) == -1
    assert sw_mod.day_index(jd0 + 1e5, jd0, daily.shape[0]) == daily.shape[0] - 1


def test_constant_space_weather():
    c = ConstantSpaceWeather(120.0, 110.0, 15.0)
    t = jd(2023, 1, 1)
    for kind in ("observed", "adjusted"):
        assert c.f107(t, kind) == 120.0 and c.f107_previous_day(t, kind) == 120.0 and c.f107a(t, kind) == 110.0
    assert c.ap_daily(t) == 15.0 and c.ap_3h(t, 30.0) == 15.0 and c.msis_ap(t) == [15.0] * 7
    assert c.kp_3h(t) == pytest.approx(3.0)  # ap 15 <-> Kp 3o (Bartels table)
    assert c.f107(jd(1960, 1, 1)) == 120.0 and not c.past_end(jd(2100, 1, 1))
    for args, name in (((40.0, 110.0, 15.0), "f107"), ((120.0, 500.0, 15.0), "f107a"),
                       ((120.0, 110.0, -1.0), "ap"), ((math.nan, 110.0, 15.0), "f107")):
        with pytest.raises(ValueError, match=name):
            ConstantSpaceWeather(*args)
    assert sw_mod.kp_from_ap(0.0) == 0.0 and sw_mod.kp_from_ap(400.0) == 9.0
    assert sw_mod.kp_from_ap(48.0) == pytest.approx(5.0)


def _write(tmp_path, lines):
    p = tmp_path / "sw.txt"
    p.write_text("\n".join(lines) + "\n")
    return p


def test_parse_errors_name_file_and_line(tmp_path):
    good = Path(sw_mod.BUNDLED_FILE).read_text().splitlines()
    begin = good.index("BEGIN OBSERVED")
    with pytest.raises(ValueError, match=r"nope\.txt.*cannot be read"):
        SpaceWeather.from_file(tmp_path / "nope.txt")
    with pytest.raises(ValueError, match=r"sw\.txt', line 1: expected 'DATATYPE CssiSpaceWeather'"):
        SpaceWeather.from_file(_write(tmp_path, ["hello"] + good[1:]))
    with pytest.raises(ValueError, match="line 2: format version '1.1'"):
        SpaceWeather.from_file(_write(tmp_path, [good[0], "VERSION 1.1"] + good[2:]))
    bad = list(good)
    bad[begin + 3] = bad[begin + 3][:92] + "  abc.d" + bad[begin + 3][98:]
    with pytest.raises(ValueError, match=f"line {begin + 4}: "):
        SpaceWeather.from_file(_write(tmp_path, bad))
    bad = list(good)
    bad[begin + 3], bad[begin + 4] = bad[begin + 4], bad[begin + 3]
    with pytest.raises(ValueError, match=f"line {begin + 5}: date .* is not after"):
        SpaceWeather.from_file(_write(tmp_path, bad))
    bad = list(good)
    del bad[begin + 10]
    with pytest.raises(ValueError, match="NUM_OBSERVED_POINTS says 9730 but the section has 9729"):
        SpaceWeather.from_file(_write(tmp_path, bad))
    # a small valid file: three observed days
    small = (good[:begin - 1] + ["NUM_OBSERVED_POINTS 3", "BEGIN OBSERVED"] + good[begin + 1:begin + 4]
             + ["END OBSERVED"])
    s = SpaceWeather.from_file(_write(tmp_path, small))
    assert s.first_jd == jd(2000, 1, 1) and s.last_jd == jd(2000, 1, 3)
    assert s.f107(jd(2000, 1, 9)) == 133.1 and s.past_end(jd(2000, 1, 9))
