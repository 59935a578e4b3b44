"""The CubeSat ADCS sensors (issue 57) against Basilisk's modules on the same inputs, noise off
(the two products draw different random streams): magnetometer (mounting, bias, scale,
saturation), starTracker (the case frame's quaternion), coarseSunSensor (cosine response, field
of view, Sun distance, shadow, bias, scale, saturation) and cssWlsEst (the least-squares Sun
heading from 1 to 8 lit sensors, weighted and not). 25 random cases each; the worst differences
are printed at the end of the run. The noise itself is checked against its stated statistics.

Basilisk is a test extra (pyproject.toml); without it the comparisons skip, saying so."""
import math

import numpy as np
import pytest

from basilisk_oracle import CASES, initialized, random_unit, record_worst, require_basilisk

from components.core import mrp, rotations
from components.sensing import adcs_sensors


def _state_msg(messaging, q, r=(7e6, 0.0, 0.0)):
    state = messaging.SCStatesMsgPayload()
    state.sigma_BN = list(mrp.from_quaternion(tuple(q), short=True))
    state.r_BN_N = list(r)
    return messaging.SCStatesMsg().write(state)


def test_magnetometer_equals_basilisks(record_property):
    require_basilisk()
    from Basilisk.architecture import messaging
    from Basilisk.simulation import magnetometer
    rng = np.random.default_rng(5721)
    worst = 0.0
    for k in range(CASES):
        q, B_N = random_unit(rng, 4), rng.normal(size=3) * 3e-5
        mounting = rng.normal(size=3) * (0.02 if k % 2 else 1.0)  # a misalignment, or any mounting
        bias, scale = rng.normal(size=3) * 1e-6, rng.uniform(0.9, 1.1)
        limit = rng.uniform(2e-5, 6e-5) if k % 3 == 0 else 0.0
        module = magnetometer.Magnetometer()
        module.setBodyToSensorDCM(*mounting)
        module.senBias, module.scaleFactor = bias.tolist(), scale
        if limit:
            module.maxOutput, module.minOutput = limit, -limit
        field = messaging.MagneticFieldMsgPayload()
        field.magField_N = B_N.tolist()
        keep = [messaging.MagneticFieldMsg().write(field), _state_msg(messaging, q)]
        module.magInMsg.subscribeTo(keep[0])
        module.stateInMsg.subscribeTo(keep[1])
        sim = initialized(module)  # noqa: F841 (kept alive)
        module.UpdateState(0)
        theirs = np.array(module.tamDataOutMsg.read().tam_S)
        B_B = np.array(rotations.attitude_matrix(tuple(q))) @ B_N
        ours = adcs_sensors.Magnetometer(mounting, bias, scale, max_field=limit).measure(B_B)
        worst = max(worst, float(np.max(np.abs(ours - theirs)) / np.linalg.norm(B_N)))
    record_worst(record_property, "magnetometer vs Basilisk (relative to |B|)", worst, 1e-14)


def test_star_tracker_attitude_equals_basilisks(record_property):
    """The case frame's attitude q_CN for random mountings and attitudes (noise off)."""
    require_basilisk()
    from Basilisk.architecture import messaging
    from Basilisk.simulation import starTracker
    rng = np.random.default_rng(5722)
    worst = 0.0
    for _ in range(CASES):
        q, mounting = random_unit(rng, 4), rng.normal(size=3)
        module = starTracker.StarTracker()
        module.dcm_CB = adcs_sensors.mounting_dcm(*mounting).tolist()
        keep = _state_msg(messaging, q)
        module.scStateInMsg.subscribeTo(keep)
        sim = initialized(module)  # noqa: F841 (kept alive)
        module.UpdateState(0)
        q_theirs = np.array(module.sensorOutMsg.read().qInrtl2Case)  # scalar first
        theirs = np.array([*q_theirs[1:], q_theirs[0]])
        tracker = adcs_sensors.StarTracker(mounting, sigma_cross=0.0, sigma_roll=0.0)
        ours = np.array(tracker.measured(tuple(q)))
        worst = max(worst, float(min(np.max(np.abs(ours - theirs)), np.max(np.abs(ours + theirs)))))
    record_worst(record_property, "star tracker q_CN vs Basilisk", worst, 1e-14)


BASILISK_AU = 149597870.693e3  # m: its astronomical unit (IAU 1976); ours is IAU 2012's 149597870700 m


def test_coarse_sun_sensors_equal_basilisks(record_property, monkeypatch):
    """Each of 6-8 random sensors of random arrays: Basilisk's coarseSunSensor (Kelly factor off,
    no albedo) at random attitudes, Sun distances (0.98-1.02 AU, and Mars' 1.5), shadow factors,
    fields of view, biases, scales and saturations. With Basilisk's astronomical unit (ours, 7 m
    longer, makes the signals 9.4e-11 smaller)."""
    require_basilisk()
    monkeypatch.setattr(adcs_sensors, "AU", BASILISK_AU)
    from Basilisk.architecture import messaging
    from Basilisk.simulation import coarseSunSensor
    rng = np.random.default_rng(5723)
    worst, lit = 0.0, 0
    for k in range(CASES):
        q, n = random_unit(rng, 4), int(rng.integers(6, adcs_sensors.MAX_CSS + 1))
        normals = [random_unit(rng) for _ in range(n)]
        fov, scale, bias = rng.uniform(0.5, 1.5), rng.uniform(0.5, 2.0), rng.normal() * 0.01
        limit = rng.uniform(0.6, 1.5) if k % 3 == 0 else 0.0
        shadow = 1.0 if k % 4 else rng.uniform(0.0, 1.0)
        r_B = random_unit(rng) * 7e6
        r_S = random_unit(rng) * adcs_sensors.AU * (1.5 if k == 7 else rng.uniform(0.98, 1.02))
        array = adcs_sensors.CoarseSunSensorArray(normals, fov, scale, bias, max_signal=limit)
        ours = array.signals(tuple(q), r_B, r_S, shadow)
        sun = messaging.SpicePlanetStateMsgPayload()
        sun.PositionVector = r_S.tolist()
        eclipse = messaging.EclipseMsgPayload()
        eclipse.illuminationFactor = shadow  # 1 fully sunlit (its shadowFactor, deprecated)
        keep = [messaging.SpicePlanetStateMsg().write(sun), _state_msg(messaging, q, r_B),
                messaging.EclipseMsg().write(eclipse)]
        for i, normal in enumerate(normals):
            module = coarseSunSensor.CoarseSunSensor()
            module.nHat_B, module.fov, module.scaleFactor = normal.tolist(), fov, scale
            module.kellyFactor, module.senBias = 0.0, bias
            module.maxOutput, module.minOutput = (limit if limit else 1e200), 0.0
            module.sunInMsg.subscribeTo(keep[0])
            module.stateInMsg.subscribeTo(keep[1])
            module.sunEclipseInMsg.subscribeTo(keep[2])
            sim = initialized(module)  # noqa: F841 (kept alive)
            module.UpdateState(0)
            theirs = module.sensedValue  # its output message is written only within a simulation step
            worst = max(worst, abs(float(ours[i]) - theirs))
            lit += theirs > 0.05
    assert lit > CASES, f"only {lit} lit sensors: the cases do not exercise the response"
    record_worst(record_property, "coarse Sun sensor signals vs Basilisk", worst, 1e-14)


@pytest.mark.parametrize("weights", [True, False])
def test_coarse_sun_heading_equals_basilisks_least_squares(weights, record_property):
    """cssWlsEst on random arrays of 3-8 sensors at random Sun directions, so that 0 to all of
    them are lit (its 1-, 2- and many-sensor branches)."""
    require_basilisk()
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import cssWlsEst
    rng = np.random.default_rng(5724 + weights)
    worst, branches = 0.0, set()
    for k in range(CASES * 2):
        n = int(rng.integers(3, adcs_sensors.MAX_CSS + 1))
        normals = [random_unit(rng) for _ in range(n)]
        array = adcs_sensors.CoarseSunSensorArray(normals, math.radians(rng.uniform(30.0, 90.0)), threshold=0.1,
                                                  use_weights=weights)
        q, r_B, r_S = random_unit(rng, 4), np.array([7e6, 0.0, 0.0]), random_unit(rng) * adcs_sensors.AU
        signals = array.signals(tuple(q), r_B, r_S) + rng.normal(size=n) * 0.02
        ours, valid, used = array.heading(signals)
        branches.add(min(used, 3))
        config = messaging.CSSConfigMsgPayload()
        config.nCSS = n
        units = []
        for normal in normals:
            unit = messaging.CSSUnitConfigMsgPayload()
            unit.nHat_B, unit.CBias = normal.tolist(), 1.0
            units.append(unit)
        config.cssVals = units
        data = messaging.CSSArraySensorMsgPayload()
        data.CosValue = signals.tolist() + [0.0] * (32 - n)
        module = cssWlsEst.cssWlsEst()
        module.sensorUseThresh, module.useWeights = 0.1, int(weights)
        keep = [messaging.CSSConfigMsg().write(config), messaging.CSSArraySensorMsg().write(data)]
        module.cssConfigInMsg.subscribeTo(keep[0])
        module.cssDataInMsg.subscribeTo(keep[1])
        sim = initialized(module)  # noqa: F841 (kept alive)
        module.UpdateState(0)
        theirs = np.array(module.navStateOutMsg.read().vehSunPntBdy)
        assert valid == bool(np.any(theirs)), (k, used, ours, theirs)
        worst = max(worst, float(np.max(np.abs(ours - theirs))))
    assert branches == {0, 1, 2, 3}, branches
    record_worst(record_property, f"coarse Sun heading ({'weighted' if weights else 'unweighted'}) vs Basilisk", worst,
           1e-12)
