"""The CubeSat ADCS sensors on their own (their Basilisk comparisons, noise off, are in
test_adcs_sensors_vs_basilisk.py): the noise they state, the exclusions and the update rate of
the star tracker, the shadow and the heading of the Sun sensors, and the errors of bad values."""
import math

import numpy as np
import pytest

from components.core import rotations
from components.sensing import adcs_sensors

AU = adcs_sensors.AU


def test_mounting_turns_the_sensor_frame_by_its_3_2_1_angles():
    C = adcs_sensors.mounting_dcm(math.radians(90.0), 0.0, 0.0)  # yaw 90 deg: sensor x on body y
    assert np.allclose(C @ [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
    C = adcs_sensors.mounting_dcm(0.1, -0.2, 0.3)
    assert np.allclose(C @ C.T, np.eye(3)) and np.linalg.det(C) == pytest.approx(1.0)


def test_magnetometer_noise_and_bias_are_what_it_states():
    sensor = adcs_sensors.Magnetometer(bias=(1e-6, -2e-6, 0.0), sigma=5e-8, seed=3)
    samples = []
    for _ in range(4000):
        samples.append(sensor.measure((2e-5, 0.0, -3e-5)))
        sensor.step(0.1)
    error = np.array(samples) - [2e-5 + 1e-6, -2e-6, -3e-5]
    assert np.allclose(error.mean(axis=0), 0.0, atol=4 * 5e-8 / math.sqrt(4000))
    assert np.allclose(error.std(axis=0), 5e-8, rtol=0.05)
    assert np.all(adcs_sensors.Magnetometer(max_field=1e-5).measure((2e-5, -3e-5, 5e-6)) == [1e-5, -1e-5, 5e-6])


def _tracker(**kwargs):
    return adcs_sensors.StarTracker(**kwargs)


R_B = np.array([6878137.0, 0.0, 0.0])
SUN_FAR = np.array([0.0, -AU, 0.0])  # the Sun along -y, away from a +z boresight


def test_star_tracker_noise_about_and_across_the_boresight():
    """The error rotation of 3000 samples in the case frame: its x and y parts have sigma_cross,
    its z part (about the boresight) sigma_roll."""
    tracker = _tracker(mounting=(0.3, -0.4, 1.2), sigma_cross=2e-5, sigma_roll=1e-4, seed=11)
    q = rotations.normalized((0.1, 0.7, -0.2, 0.6))
    true_C = np.array(rotations.attitude_matrix(tracker.true_attitude(q)))
    errors = []
    for _ in range(3000):
        C = np.array(rotations.attitude_matrix(tracker.measured(q)))
        E = C @ true_C.T  # the noise rotation, in the case frame
        errors.append([E[1, 2], E[2, 0], E[0, 1]])
        tracker.step(0.1, (q, (0, 0, 0), R_B, SUN_FAR))
    errors = np.array(errors)
    assert errors[:, 0].std() == pytest.approx(2e-5, rel=0.06) and errors[:, 1].std() == pytest.approx(2e-5, rel=0.06)
    assert errors[:, 2].std() == pytest.approx(1e-4, rel=0.06)


def test_star_tracker_is_blinded_by_the_sun_the_earth_the_moon_and_a_fast_rate():
    tracker = _tracker(sigma_cross=0.0, sigma_roll=0.0)
    q = (0.0, 0.0, 0.0, 1.0)  # boresight (case +z = body +z) along N's z
    assert tracker.output(q, (0, 0, 0), R_B, SUN_FAR)[1:] == (True, ())
    assert tracker.output(q, (0, 0, 0), R_B, (0.0, 0.3 * AU, AU))[2] == ("sun",)  # 17 deg from the Sun
    assert tracker.output(q, (0.0, 0.02, 0.0), R_B, SUN_FAR)[2] == ("rate",)  # 1.15 deg/s
    moon = R_B + [0.0, 0.0, 3.8e8]
    assert tracker.output(q, (0, 0, 0), R_B, SUN_FAR, moon)[2] == ("moon",)
    # the Earth's disc is 73 deg in radius from 500 km: a boresight 80 deg from nadir is within 20 deg of it
    down = rotations.from_axis_angle((0.0, 1.0, 0.0), math.radians(-170.0))
    q_BN, valid, reasons = tracker.output(down, (0, 0, 0), R_B, SUN_FAR)
    assert not valid and reasons == ("earth",) and q_BN == (0.0, 0.0, 0.0, 1.0)


def test_star_tracker_holds_its_measurement_between_updates():
    tracker = _tracker(update_period=1.0, sigma_cross=1e-4, seed=2)
    q = (0.0, 0.0, 0.0, 1.0)
    seen = []
    for _ in range(25):
        tracker.step(0.2, (q, (0, 0, 0), R_B, SUN_FAR))
        seen.append(tracker.output(q, (0, 0, 0), R_B, SUN_FAR)[0])
    distinct = [seen[0]] + [b for a, b in zip(seen, seen[1:]) if a != b]
    assert len(distinct) == 5  # a new measurement every 5 steps of 0.2 s
    assert all(seen[i] == seen[i + 1] for i in range(0, 25 - 1) if (i + 1) % 5)


def test_coarse_sun_sensors_in_shadow_and_in_the_sun():
    array = adcs_sensors.CoarseSunSensorArray(sigma=0.005, seed=1)
    q = rotations.normalized((0.2, -0.1, 0.4, 0.9))
    r_S = np.array(rotations.attitude_matrix(q)).T @ np.array([0.6, -0.6, 0.53]) * AU  # three faces lit
    signals = array.signals(q, R_B, r_S, sunlit_fraction := 0.0)
    assert sunlit_fraction == 0.0 and np.all(signals <= 3 * 0.005)
    assert not array.heading(signals)[1]
    truth = array.sun_B(q, R_B, r_S)[0]
    errors = []
    for _ in range(200):
        heading, valid, used = array.heading(array.signals(q, R_B, r_S, 1.0))
        assert valid and used == 3
        errors.append(math.degrees(math.acos(min(1.0, float(heading @ truth)))))
        array.step(0.1)
    assert max(errors) < 2.0  # 0.005 noise on six face sensors: about a degree


@pytest.mark.parametrize("kwargs, message", [
    (dict(normals=[(1, 0, 0)] * 9), "css_count = 9 must be in 1..8"),
    (dict(normals=[(1, 0, 0), (0, 0, 0)]), "normal of sensor 2 is zero"),
    (dict(fov=0.0), "fov = 0.0 rad"),
])
def test_bad_sun_sensor_values_say_what_is_allowed(kwargs, message):
    with pytest.raises(ValueError, match=message):
        adcs_sensors.CoarseSunSensorArray(**kwargs)


def test_bad_magnetometer_and_tracker_values_say_what_is_allowed():
    with pytest.raises(ValueError, match="scale = 0.0 must be a finite non-zero factor"):
        adcs_sensors.Magnetometer(scale=0.0)
    with pytest.raises(ValueError, match="max_rate"):
        adcs_sensors.StarTracker(max_rate=0.0)
