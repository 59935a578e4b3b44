"""The acs_modes system (ACS mode specification) run through the master: the shortened scenario reaches every
nominal mode in order and then alternates Orbit Day / Orbit Night with the eclipses; a ground
command takes it to Ground Command (9) and, GCMD after the command, back to Detumble (1)."""
import numpy as np
import pytest

import system_ssp
from system_ssp.systems.generators.acs_modes import SHORT_STEP, SHORT_STOP

SHORT = "parameters/acs_modes_shortened.ssv"
GROUND = "parameters/acs_modes_ground_command.ssv"
STOP, STEP = SHORT_STOP, SHORT_STEP
OUTPUTS = ["modes.mode", "modes.uncertain", "shadow.orbit_day"]


def _run(ssp_paths, parameter_set):
    r = system_ssp.simulate(ssp_paths["acs_modes"], stop_time=STOP, step_size=STEP,
                            parameter_sets=[parameter_set], outputs=OUTPUTS)
    d = r.data
    return (np.asarray(d["time"], float), np.asarray(d["modes.mode"]).astype(int),
            np.asarray(d["modes.uncertain"]).astype(bool), np.asarray(d["shadow.orbit_day"]).astype(bool))


def _entries(t, mode):
    """[(mode, entry time)] at every change of mode."""
    idx = [0] + [i for i in range(1, len(mode)) if mode[i] != mode[i - 1]]
    return [(int(mode[i]), float(t[i])) for i in idx]


@pytest.fixture(scope="module")
def shortened(ssp_paths):
    return _run(ssp_paths, SHORT)


def test_shortened_reaches_every_nominal_mode_in_order(shortened):
    t, mode, uncertain, day = shortened
    first = {}
    for m, te in _entries(t, mode):
        first.setdefault(m, te)
    for m in range(8):
        assert m in first, f"mode {m} never reached"
    order = [first[m] for m in range(7)]
    assert order == sorted(order), first
    assert first[7] > first[6] and first[8] > first[7]
    assert 9 not in first


def test_shortened_alternates_orbit_day_night_with_the_eclipses(shortened):
    t, mode, uncertain, day = shortened
    i7 = int(np.argmax(mode == 7))
    assert mode[i7] == 7
    m, u, d = mode[i7:], uncertain[i7:], day[i7:]
    assert set(np.unique(m)) <= {7, 8}, "left Orbit Day/Night after Orbit Day was first reached"
    assert not u.any(), "uncertain decision after Orbit Day was first reached"
    seq = [e for e, _ in _entries(t[i7:], m)]
    assert seq[:4] == [7, 8, 7, 8], seq  # at least two nights and the day between them
    # in step with the shadow: mode 8 exactly at night, 7 in daylight, except the decision lag of
    # one communication point (the manager decides on orbit_day at t) and Orbit Day's ODMD dwell
    mismatch = (m == 8) != ~d
    assert mismatch.sum() <= 4 * len(seq), np.flatnonzero(mismatch)
    for k in np.flatnonzero(np.diff(d.astype(int)) != 0):
        after = m[k + 1:k + 4]
        assert (after == (7 if d[k + 1] else 8)).any(), (t[i7 + k], after)


def test_ground_command_goes_to_mode_9_and_back_to_detumble(ssp_paths):
    t, mode, uncertain, day = _run(ssp_paths, GROUND)
    start, end, gcmd = 12000.0, 12030.0, 20.0  # generate_acs_modes.GROUND, SHORT_DELAYS["GCMD"]
    i = int(np.searchsorted(t, start))
    assert mode[i - 1] != 9 and mode[i] == 9
    in9 = t[mode == 9]
    assert in9.min() == start and in9.max() < end + gcmd + STEP
    j = int(np.flatnonzero(mode == 9).max()) + 1
    last_command = t[t < end].max()  # the window is [start, end) at communication points
    assert mode[j] == 1 and abs(t[j] - (last_command + gcmd)) < 1e-6, (t[j], last_command)
