"""The three-axis B-dot detumble and the momentum dumping law (components.acs.magnetic_control):
the 3U detumbled from 10 deg/s in the tilted-dipole field along its orbit, with the body rate
and with the field difference (magnetometer only), its kinetic energy never rising with the
rate; the dumping law's geometry and its refusals. Their Basilisk comparisons are in
test_magnetic_control_vs_basilisk.py."""
import numpy as np
import pytest

from components.acs import magnetic_control, magnetorquer
from components.attitude.rigid_body import RigidBody
from components.core import rotations
from components.environment.magnetic_field import MagneticField
from components.mission import cubesat_3u
from components.orbit.circular import CircularOrbit

TUMBLE = np.radians(10.0) * np.array([0.6, -0.5, 0.62]) / np.linalg.norm([0.6, -0.5, 0.62])


def _detumble(use_field_difference, duration=6000.0, h=2.0):
    orbit, field = CircularOrbit(**cubesat_3u.ORBIT), MagneticField()
    J = np.array(cubesat_3u.SPACECRAFT.inertia_B)
    body = RigidBody(J, cubesat_3u.INITIAL_ATTITUDE, tuple(TUMBLE), max_substep=0.5)
    law = magnetic_control.BdotDetumble(cubesat_3u.COILS.detumble_gain, use_field_difference)
    coils = magnetorquer.TorqueCoils([cubesat_3u.COILS.max_dipole] * 3)
    energy = []
    for k in range(int(duration / h)):
        t = k * h
        B_B = np.array(rotations.attitude_matrix(tuple(body.q))) @ np.array(field.field_N(orbit.position(t), t))
        law.step(B_B, h)  # sample, then command (the field difference's cycle)
        _, torque = coils.torque(law.dipole(B_B, body.omega), B_B)
        w = np.array(body.omega)
        energy.append(0.5 * w @ J @ w)
        body.step(tuple(torque), h)
    return np.degrees(np.linalg.norm(body.omega)), np.array(energy)


@pytest.mark.parametrize("use_field_difference", [False, True], ids=["body rate", "field difference"])
def test_bdot_detumbles_the_3u_from_10_deg_per_s(use_field_difference):
    """10 deg/s to under 1.2 deg/s in 6000 s (just over an orbit; ~0.2 deg/s after three) with the
    0.2 A.m2 rods saturated most of the way; with the body rate the kinetic energy never rises."""
    rate, energy = _detumble(use_field_difference)
    assert rate < 1.2, rate
    if not use_field_difference:
        assert np.all(np.diff(energy) <= 1e-12 * energy[0]), float(np.max(np.diff(energy)))


def test_bdot_law_opposes_the_field_rate_and_starts_from_zero_with_the_difference():
    B = np.array([2e-5, -1e-5, 3e-5])
    omega = np.array([0.05, -0.02, 0.01])
    law = magnetic_control.BdotDetumble(2e-3)
    m = law.dipole(B, omega)
    np.testing.assert_allclose(m, 2e-3 * np.cross(omega, B) / (B @ B), rtol=1e-15)
    assert law.dipole(B, omega, enabled=False).tolist() == [0.0, 0.0, 0.0]
    assert law.dipole([0.0, 0.0, 1e-10], omega).tolist() == [0.0, 0.0, 0.0]  # no field: no command
    difference = magnetic_control.BdotDetumble(2e-3, use_field_difference=True)
    difference.step(B, 0.5)
    assert difference.dipole(B).tolist() == [0.0, 0.0, 0.0]  # one sample: no rate yet
    B2 = B + np.array([1e-7, 0.0, -2e-7])
    difference.step(B2, 0.5)
    np.testing.assert_allclose(difference.dipole(B2), -2e-3 * (B2 - B) / 0.5 / (B2 @ B2), rtol=1e-15)
    state = difference.get_state()
    other = magnetic_control.BdotDetumble(2e-3, use_field_difference=True)
    other.set_state(state)
    np.testing.assert_array_equal(other.dipole(B2), difference.dipole(B2))


def test_dumping_takes_momentum_out_of_the_wheels_and_feeds_the_coil_torque_forward():
    """The coils' torque opposes the wheels' momentum (less its part along B), the wheels are asked
    for the controller's torque less the coils', and the rods clip."""
    axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    dumping = magnetic_control.MomentumDumping(axes, [1e-5] * 3, gain=1e-3, max_dipole=[0.2] * 3)
    B = np.array([1e-5, 2e-5, -2.5e-5])
    speeds = np.array([300.0, -200.0, 100.0])
    torque = np.array([1e-5, 0.0, -2e-5])
    m, coil, wheels, h_w = dumping.evaluate(speeds, B, torque)
    np.testing.assert_allclose(h_w, 1e-5 * speeds)
    assert coil @ h_w < 0.0 and abs(coil @ B) < 1e-15 * np.linalg.norm(coil) * np.linalg.norm(B)
    b = B / np.linalg.norm(B)
    wanted = -1e-3 * h_w
    np.testing.assert_allclose(coil, wanted - (wanted @ b) * b, rtol=1e-12)
    np.testing.assert_allclose(wheels, torque - coil, rtol=1e-15)
    strong = magnetic_control.MomentumDumping(axes, [1e-5] * 3, gain=1.0, max_dipole=[0.2] * 3)
    assert np.max(np.abs(strong.evaluate(speeds, B)[0])) == 0.2
    m_off, coil_off, wheels_off, _ = dumping.evaluate(speeds, B, torque, enabled=False)
    assert m_off.tolist() == [0.0] * 3 and wheels_off.tolist() == torque.tolist()


@pytest.mark.parametrize("kwargs, message", [
    (dict(gain=-1.0), "gain = -1.0 1/s must be a finite number >= 0"),
    (dict(J_s=[1e-5, 0.0, 1e-5]), "J_s [1e-05, 0.0, 1e-05] must be > 0 kg.m2 for every wheel"),
    (dict(max_dipole=[0.2, -0.1, 0.2]), "max_dipole [0.2, -0.1, 0.2] must be >= 0 A.m2 on every axis"),
])
def test_dumping_refuses_bad_parameters_in_one_line(kwargs, message):
    args = dict(axes=[[1, 0, 0], [0, 1, 0], [0, 0, 1]], J_s=[1e-5] * 3, **{"gain": 1e-3, "max_dipole": [0.2] * 3})
    args.update(kwargs)
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        magnetic_control.MomentumDumping(**args)
