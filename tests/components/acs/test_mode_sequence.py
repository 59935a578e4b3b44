"""The wheel-and-coil CubeSat's mode sequence (components.acs.mode_sequence): each transition once
its condition has held for hold_time, the rate alarm at once, the coil command of the active law,
bad parameters refused with their names."""
import math

import numpy as np
import pytest

from components.acs import mode_sequence as ms
from components.attitude import pointing

DEG = math.radians(1.0)
SUN_ON_AXIS = (0.0, 0.0, 1.0)


def _run(seq, seconds, rate=0.0, sun=SUN_ON_AXIS, sun_valid=True, valid=True, h=1.0):
    modes = []
    for _ in range(int(round(seconds / h))):
        modes.append(seq.step(h, (rate, 0.0, 0.0), sun, sun_valid, valid))
    return modes


def test_detumble_sun_safe_pointing_each_after_its_hold():
    seq = ms.ModeSequence(detumble_exit_rate=1.5 * DEG, detumble_entry_rate=5.0 * DEG, hold_time=60.0)
    assert seq.mode == ms.DETUMBLE and seq.enables() == (True, False) and seq.guidance_mode == pointing.SUN_SAFE
    assert set(_run(seq, 600.0, rate=2.0 * DEG)) == {ms.DETUMBLE}  # above the exit rate: stays
    modes = _run(seq, 60.0, rate=1.0 * DEG)
    assert modes[:59] == [ms.DETUMBLE] * 59 and modes[59] == ms.SUN_SAFE  # the 60th second of the hold
    assert seq.enables() == (False, True) and seq.guidance_mode == pointing.SUN_SAFE
    off_axis = (math.sin(20 * DEG), 0.0, math.cos(20 * DEG))
    assert set(_run(seq, 300.0, sun=off_axis)) == {ms.SUN_SAFE}  # the Sun 20 deg off: not acquired
    assert set(_run(seq, 300.0, valid=False)) == {ms.SUN_SAFE}  # no valid estimate: stays
    assert set(_run(seq, 300.0, sun_valid=False)) == {ms.SUN_SAFE}  # eclipse: stays
    assert _run(seq, 60.0)[-1] == ms.POINTING and seq.guidance_mode == pointing.NADIR
    assert seq.transitions == 2


def test_a_broken_hold_starts_again_and_the_rate_alarm_is_immediate():
    seq = ms.ModeSequence(hold_time=60.0)
    _run(seq, 59.0, rate=0.1 * DEG)
    _run(seq, 1.0, rate=1.0 * DEG)  # one gyro sample above 0.5 deg/s
    assert set(_run(seq, 59.0, rate=0.1 * DEG)) == {ms.DETUMBLE}
    assert _run(seq, 1.0, rate=0.1 * DEG) == [ms.SUN_SAFE]
    assert _run(seq, 60.0)[-1] == ms.POINTING
    assert _run(seq, 59.0, valid=False)[-1] == ms.POINTING  # the estimate lost: back to Sun-safe after the hold
    assert _run(seq, 1.0, valid=False) == [ms.SUN_SAFE]
    assert _run(seq, 1.0, rate=6.0 * DEG) == [ms.DETUMBLE]  # above 5 deg/s: at once
    assert seq.time_in_mode == 0.0 and seq.transitions == 4


def test_the_coils_get_the_active_laws_dipole():
    seq = ms.ModeSequence(hold_time=0.0)
    bdot, dump = (0.1, -0.2, 0.05), (0.01, 0.0, -0.02)
    np.testing.assert_array_equal(seq.select_dipole(bdot, dump), bdot)
    _run(seq, 1.0)
    np.testing.assert_array_equal(seq.select_dipole(bdot, dump), dump)


def test_state_round_trip():
    seq = ms.ModeSequence()
    _run(seq, 30.0)
    copy = ms.ModeSequence()
    copy.set_state(seq.get_state())
    assert _run(copy, 40.0) == _run(seq, 40.0)


@pytest.mark.parametrize("kwargs, message", [
    (dict(detumble_exit_rate=-1.0), "detumble_exit_rate = -1.0 rad/s must be a finite number >= 0"),
    (dict(detumble_exit_rate=0.1, detumble_entry_rate=0.05), "detumble_entry_rate = 0.05 rad/s must be 0"),
    (dict(sun_safe_exit_angle=0.0), r"sun_safe_exit_angle = 0.0 rad must be in \(0, pi\]"),
    (dict(hold_time=float("nan")), "hold_time = nan s must be a finite number >= 0"),
    (dict(sun_axis_B=(0.0, 0.0, 0.0)), "sun_axis_B must not be zero"),
    (dict(pointing_mode=3), "pointing_mode = 3 must be a PointingGuidance mode"),
    (dict(initial_mode=5), "initial_mode = 5 must be 0 detumble, 1 sun-safe or 2 pointing"),
])
def test_bad_parameters_are_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ms.ModeSequence(**kwargs)


def test_nadir_axis_error_against_the_attitude_matrix():
    from components.core import rotations
    rng = np.random.default_rng(5)
    q = rng.normal(size=(25, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    r = rng.normal(size=(25, 3)) * 7e6
    expected = [math.acos(np.clip(np.array(rotations.attitude_matrix(qi))[2] @ (ri / np.linalg.norm(ri)), -1, 1))
                for qi, ri in zip(q, r)]  # -z . (-r_hat) = z_N . r_hat
    np.testing.assert_allclose(pointing.nadir_axis_error(q, r), expected, atol=1e-12)
    assert pointing.nadir_axis_error((0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 7e6)) == 0.0  # -z at nadir


@pytest.mark.parametrize("enabled", [True, False])
def test_mrp_feedback_fmu_switched_off_commands_nothing_and_keeps_no_integral(build_one, enabled):
    """MrpFeedback's `enabled` (the mode sequence's pointing_enabled): off, zero torque and the
    integral at zero; on, the law."""
    import fmpy
    fmu = build_one("neighbor_mrp_feedback.py")
    start = {"enabled": enabled, "Ki": 0.01, "integral_limit": 1e-3, "sigma_BR[1]": 0.1, "sigma_BR[2]": -0.05,
             "omega_BR_B[3]": 0.01}
    out = fmpy.simulate_fmu(str(fmu), stop_time=5.0, output_interval=1.0, start_values=start,
                            output=["torque_cmd_B[1]", "torque_cmd_B[3]", "integral_torque_B[1]"])
    torque, integral = np.abs(out["torque_cmd_B[1]"]), np.abs(out["integral_torque_B[1]"])
    if enabled:
        assert torque.min() > 1e-5 and integral[-1] > 0.0  # K sigma = 5e-5 N.m
    else:
        assert torque.max() == 0.0 and np.abs(out["torque_cmd_B[3]"]).max() == 0.0 and integral.max() == 0.0
