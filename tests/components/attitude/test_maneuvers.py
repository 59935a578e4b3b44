"""Direct tests of the attitude models in components/ (no FMI), against the thesis."""
import math

import numpy as np
import pytest

from components.attitude.detumble import DetumbleController
from components.attitude.rigid_body import RigidBody, box_inertia, check_inertia, rk4_steps
from components.attitude.slew import SlewController
from components.attitude.thruster_control import pair_torques, quantize
from components.attitude.thrusters import ThrusterPairs
from components.core import jit
from components.core import rotations as att

DT = 0.015
J = box_inertia(12.0, 0.1, 0.2, 0.3)


def test_box_inertia_matches_eq5():
    # Eq. 5 prints 0.05, 0.13, 0.10 kg m^2 (two decimals).
    np.testing.assert_allclose(np.diag(J), [0.05, 0.13, 0.10], atol=0.005)
    np.testing.assert_allclose(np.diag(J), [0.05, 0.13, 0.1], rtol=1e-12)
    assert np.count_nonzero(J - np.diag(np.diag(J))) == 0


def test_pair_torques_match_eq16():
    np.testing.assert_allclose(pair_torques(0.025, 0.1, 0.3), [0.0025] * 3, rtol=1e-12)


@pytest.mark.parametrize("bad", [dict(mass=0.0), dict(mass=-1.0), dict(a=float("nan")), dict(c=0.0)])
def test_box_inertia_rejects_bad_values(bad):
    args = dict(mass=12.0, a=0.1, b=0.2, c=0.3) | bad
    with pytest.raises(ValueError, match="must be a finite positive number"):
        box_inertia(**args)


@pytest.mark.parametrize("J_bad, match", [
    ([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], "symmetric"),
    ([[1, 0, 0], [0, -1, 0], [0, 0, 1]], "positive definite"),
    ([[1, 0, 0], [0, 1, 0], [0, 0, 3]], "triangle inequality"),
])
def test_inertia_tensor_checks(J_bad, match):
    with pytest.raises(ValueError, match=match):
        check_inertia(J_bad)


def test_circle_cross_reproduces_eq60_targets():
    q0 = (0.1460, 0.4400, 0.2256, 0.8573)  # Eq. 51
    targets = []
    t = q0
    for axis in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
        t = att.circle_cross(att.from_axis_angle(axis, math.pi), t)
        targets.append(t)
    expected = [(0.8573, 0.2256, -0.4400, -0.1460), (0.4400, -0.1460, 0.8573, -0.2256),
                (-0.1460, -0.4400, -0.2256, -0.8573)]  # Eq. 60
    np.testing.assert_allclose(targets, expected, atol=5e-5)


def test_attitude_matrix_is_a_rotation_and_composes_like_the_product():
    rng = np.random.default_rng(1)
    for _ in range(20):
        p = att.normalized(rng.normal(size=4))
        q = att.normalized(rng.normal(size=4))
        A = np.array(att.attitude_matrix(p))
        np.testing.assert_allclose(A @ A.T, np.eye(3), atol=1e-14)
        assert np.linalg.det(A) == pytest.approx(1.0, abs=1e-14)
        np.testing.assert_allclose(att.attitude_matrix(att.circle_cross(p, q)),
                                   A @ np.array(att.attitude_matrix(q)), atol=1e-14)


def test_attitude_matrix_maps_n_to_b():
    # 90 deg about z: the N x axis is -y in B (A maps N components to B components).
    q = att.from_axis_angle((0, 0, 1), math.pi / 2)
    np.testing.assert_allclose(np.array(att.attitude_matrix(q)) @ [1, 0, 0], [0, -1, 0], atol=1e-15)


def test_euler123_matches_eq37_and_round_trips():
    q = [0.5597, 0.3484, 0.1653]
    q.append(math.sqrt(1 - sum(x * x for x in q)))  # Eq. 36
    np.testing.assert_allclose(np.degrees(att.euler123(q)), [79.51, 44.12, -11.86], atol=0.005)  # Eq. 37
    for angles in [(0.3, -0.2, 1.1), (-2.5, 1.2, 3.0), (0.0, 0.0, 0.0)]:
        np.testing.assert_allclose(att.euler123(att.from_euler123(*angles)), angles, atol=1e-12)


def test_euler123_matches_eq26_matrix():
    phi, theta, psi = 0.4, -0.7, 2.2
    c, s = math.cos, math.sin
    D = np.array([[c(theta) * c(psi), s(phi) * s(theta) * c(psi) + c(phi) * s(psi),
                   s(phi) * s(psi) - c(phi) * s(theta) * c(psi)],
                  [-c(theta) * s(psi), c(phi) * c(psi) - s(phi) * s(theta) * s(psi),
                   c(phi) * s(theta) * s(psi) + s(phi) * c(psi)],
                  [s(theta), -s(phi) * c(theta), c(phi) * c(theta)]])
    np.testing.assert_allclose(att.attitude_matrix(att.from_euler123(phi, theta, psi)), D, atol=1e-14)


def test_zero_quaternion_is_rejected():
    with pytest.raises(ValueError, match="q0 .* zero or non-finite norm"):
        RigidBody(J, q0=(0, 0, 0, 0))
    with pytest.raises(ValueError, match="integrator 'rk5' must be one of euler, rk4"):
        RigidBody(J, integrator="rk5")


def test_euler_step_is_the_thesis_statechange():
    q, w, L = (0.1, 0.2, 0.3, 0.927), (0.1, -0.2, 0.3), (0.001, -0.002, 0.0025)
    body = RigidBody(J, q, w, "euler")
    body.step(L, DT)
    Jm = np.array(J)
    w_dot = np.linalg.inv(Jm) @ (np.array(L) - np.cross(w, Jm @ w))  # Eq. 17
    xi = np.array(att.xi(q))
    np.testing.assert_allclose(body.q, np.array(q) + 0.5 * xi @ w * DT, rtol=0, atol=1e-16)  # Eq. 19-21
    np.testing.assert_allclose(body.omega, np.array(w) + w_dot * DT, rtol=0, atol=1e-16)  # Eq. 18
    np.testing.assert_allclose(body.omega_dot, w_dot, rtol=1e-15)
    assert body.q[:] != att.normalized(body.q)  # no normalization under euler


def test_rk4_conserves_energy_and_inertial_momentum_torque_free():
    body = RigidBody(J, att.normalized((0.2, -0.1, 0.4, 0.9)), (0.3, 0.05, -0.2), "rk4")
    energy0 = body.kinetic_energy()
    H_N0 = np.array(att.attitude_matrix(body.q)).T @ body.angular_momentum()
    for _ in range(2000):  # 30 s
        body.step((0.0, 0.0, 0.0), DT)
    H_N = np.array(att.attitude_matrix(body.q)).T @ body.angular_momentum()
    assert body.kinetic_energy() == pytest.approx(energy0, rel=1e-10)
    np.testing.assert_allclose(H_N, H_N0, rtol=0, atol=1e-11)
    assert att.norm(body.q) == pytest.approx(1.0, abs=1e-15)


def test_rk4_spin_about_principal_axis_is_exact():
    w = 0.2
    body = RigidBody(J, (0, 0, 0, 1), (0, 0, w), "rk4")
    for _ in range(100):
        body.step((0, 0, 0), DT)
    np.testing.assert_allclose(body.q, att.from_axis_angle((0, 0, 1), w * 100 * DT), atol=1e-13)


def test_rigid_body_state_round_trip():
    a = RigidBody(J, (0, 0, 0, 1), (0.1, 0.2, 0.3), "rk4")
    a.step((0.001, 0, 0), DT)
    saved = a.get_state()
    b = RigidBody(J, (0, 0, 0, 1), (0, 0, 0), "rk4")
    b.set_state(saved)
    for body in (a, b):
        body.step((0, 0.002, 0), DT)
    assert a.get_state() == b.get_state()


def run_detumble(q0):
    """Appendix D loop on the components: control, thrusters, state change, stop test."""
    body = RigidBody(J, q0, [math.radians(10.0)] * 3, "euler")
    ctrl = DetumbleController([100.0] * 3, [1.0] * 3)
    pairs = ThrusterPairs()
    n = 0
    while not ctrl.done(body.omega):
        cmd, _ = ctrl.command(body.omega, body.omega_dot)
        pairs.step(cmd, DT)
        body.step(pairs.applied_torque(cmd), DT)
        n += 1
    return body, pairs, n


def test_detumble_components_reproduce_case1():
    body, pairs, n = run_detumble((0.0, 0.0, 0.0, 1.0))
    np.testing.assert_allclose(body.q, [0.1460, 0.4400, 0.2256, 0.8573], atol=5e-5)  # Eq. 34
    np.testing.assert_allclose(np.degrees(body.omega), [0.0019, 0.0013, -0.0003], atol=5e-5)
    assert n == 664  # 9.96 s of 15 ms steps ("about 9.97 s")
    assert pairs.propellant_mass() * 1e3 == pytest.approx(2.36, abs=0.005)  # section 3.3.9


def test_detumble_thresholds():
    ctrl = DetumbleController([100.0] * 3, [1.0] * 3)
    tol = math.radians(0.01)
    torque, flags = ctrl.command((0.1, -0.1, 0.9 * tol), (0, 0, 0))
    levels = pair_torques()
    assert flags == [-1, 1, 0] and torque == [-levels[0], levels[1], 0.0]
    # below one pair torque: no firing even outside the rate tolerance
    torque, flags = ctrl.command((2e-5, 0, 0), (0, 0, 0))
    assert 100 * 2e-5 < 0.0025 and flags == [0, 0, 0]
    assert not ctrl.done((1.1 * tol, 0, 0)) and ctrl.done((tol, tol, tol)) and ctrl.done((-tol, 0, tol))


def test_detumble_stop_test_is_two_sided_by_default():
    """A spacecraft tumbling at -0.5 rad/s (or 1e6 rad/s the other way) on every axis is not
    detumbled (before: the default was Appendix D's one-sided test, done at t = 0); the thesis'
    literal test stays available and is what the thesis cases use."""
    ctrl = DetumbleController([100.0] * 3, [1.0] * 3)
    assert not ctrl.done((-0.5, -0.5, -0.5)) and not ctrl.done((-1e6, -1e6, -1e6))
    assert not ctrl.done((0.0, 0.0, -1.0))
    literal = DetumbleController([100.0] * 3, [1.0] * 3, signed_stop_test=True)
    assert literal.done((-0.5, -0.5, -0.5)) and not literal.done((0.0, 0.0, 1.0))


def test_slew_sign_of_zero_and_antipodal_stop_test():
    ctrl = SlewController([10.0] * 3, [20.0] * 3, q_d=(1.0, 0.0, 0.0, 0.0), accept_antipodal=True)
    # Exactly 180 deg away at rest: delta_q4 = 0, sign(0) = 0, so no proportional torque.
    torque, flags = ctrl.command((0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0))
    assert ctrl.error_quaternion((0.0, 0.0, 0.0, 1.0))[3] == 0.0 and flags == [0, 0, 0]
    # A hair off the singularity the full proportional term acts, in the direction of delta_q4's sign.
    q_off = att.normalized((1e-9, 0.0, 0.0, 1.0))
    _, flags = ctrl.command(q_off, (0.0, 0.0, 0.0))
    assert flags[0] != 0
    assert ctrl.done((-1.0, 0.0, 0.0, 0.0), (0, 0, 0))  # -q_d accepted (Appendix G)
    strict = SlewController([10.0] * 3, [20.0] * 3, q_d=(1.0, 0.0, 0.0, 0.0))
    assert not strict.done((-1.0, 0.0, 0.0, 0.0), (0, 0, 0)) and strict.done((1.0, 0.0, 0.0, 0.0), (0, 0, 0))


def test_quantize_and_thruster_rounding():
    assert quantize([0.003, -0.0025, 0.0024], (0.0025,) * 3) == ([0.0025, -0.0025, 0.0], [1, -1, 0])
    pairs = ThrusterPairs()
    assert pairs.flags([0.0013, -0.0013, 0.0012]) == [1, -1, 0]  # nearest level
    pairs.step([0.0025, 0.0, -0.0025], DT)
    pairs.step([0.0025, 0.0, 0.0], DT)
    assert pairs.fire_time == [2 * DT, 0.0, DT]
    assert pairs.propellant_mass() == pytest.approx(2 * 0.025 * 3 * DT / (42 * 9.81), rel=1e-15)  # Eq. 74
    with pytest.raises(ValueError, match=r"torque_cmd_B\[2\] = nan must be finite"):
        pairs.flags([0.0, float("nan"), 0.0])


def test_integrated_euler_angles_are_eq31():
    """Eq. 31: angles += omega_new dt after each StateChange (Appendix D), starting from the
    1-2-3 angles of q0 (Eq. 30 for the identity, Eq. 37 for detumble case 2's q0)."""
    assert RigidBody(J).euler_integrated == (0.0, 0.0, 0.0)
    q2 = (0.5597, 0.3484, 0.1653, math.sqrt(1 - 0.5597 ** 2 - 0.3484 ** 2 - 0.1653 ** 2))  # Eq. 36
    np.testing.assert_allclose(np.degrees(RigidBody(J, q2).euler_integrated), (79.51, 44.12, -11.86), atol=0.005)
    body = RigidBody(J, (0, 0, 0, 1), (0.1, -0.2, 0.3), "euler", euler0=(1.0, 2.0, 3.0))
    angles = np.array([1.0, 2.0, 3.0])
    for _ in range(50):
        body.step((0.001, -0.002, 0.0025), DT)
        angles += np.array(body.omega) * DT
    np.testing.assert_allclose(body.euler_integrated, angles, rtol=0, atol=1e-14)


def test_rk4_integrated_angles_follow_a_spin_exactly():
    """Under rk4 the angles integrate omega with the same stages: a torque-free spin about a
    principal axis turns by w t exactly, and a constant torque about it gives w0 t + a t^2 / 2."""
    body = RigidBody(J, (0, 0, 0, 1), (0, 0, 0.2), "rk4")
    for _ in range(100):
        body.step((0, 0, 0), DT)
    np.testing.assert_allclose(body.euler_integrated, (0, 0, 0.2 * 100 * DT), atol=1e-13)
    body = RigidBody(J, (0, 0, 0, 1), (0, 0, 0.2), "rk4")
    L = 1e-3
    for _ in range(100):
        body.step((0, 0, L), DT)
    t = 100 * DT
    assert body.euler_integrated[2] == pytest.approx(0.2 * t + 0.5 * L / J[2][2] * t * t, rel=1e-12)
    with pytest.raises(ValueError, match="euler0"):
        RigidBody(J, euler0=(0.0, math.nan, 0.0))


def _rk4_reference(q, w, angles, J, Ji, torque, tw, hw, dt, n):
    """The RK4 sub-steps as the rigid body computed them before the kernel (tuples, Eq. 17 and 19
    through rotations' functions), kept here as the kernel's reference."""
    def accel(w, hs):
        h = tuple(J[3 * i] * w[0] + J[3 * i + 1] * w[1] + J[3 * i + 2] * w[2] + hs[i] for i in range(3))
        c = att.cross(w, h)
        r = tuple(torque[i] - tw[i] - c[i] for i in range(3))
        return tuple(Ji[3 * i] * r[0] + Ji[3 * i + 1] * r[1] + Ji[3 * i + 2] * r[2] for i in range(3))

    for k in range(n):
        s0 = k * dt
        h0, hm, h1 = (tuple(hw[i] + tw[i] * s for i in range(3)) for s in (s0, s0 + 0.5 * dt, s0 + dt))
        k1q, k1w = att.quaternion_rate(q, w), accel(w, h0)
        q2 = tuple(q[i] + 0.5 * dt * k1q[i] for i in range(4))
        w2 = tuple(w[i] + 0.5 * dt * k1w[i] for i in range(3))
        k2q, k2w = att.quaternion_rate(q2, w2), accel(w2, hm)
        q3 = tuple(q[i] + 0.5 * dt * k2q[i] for i in range(4))
        w3 = tuple(w[i] + 0.5 * dt * k2w[i] for i in range(3))
        k3q, k3w = att.quaternion_rate(q3, w3), accel(w3, hm)
        q4 = tuple(q[i] + dt * k3q[i] for i in range(4))
        w4 = tuple(w[i] + dt * k3w[i] for i in range(3))
        k4q, k4w = att.quaternion_rate(q4, w4), accel(w4, h1)
        q = tuple(q[i] + dt / 6.0 * (k1q[i] + 2 * k2q[i] + 2 * k3q[i] + k4q[i]) for i in range(4))
        angles = tuple(angles[i] + dt / 6.0 * (w[i] + 2 * w2[i] + 2 * w3[i] + w4[i]) for i in range(3))
        w = tuple(w[i] + dt / 6.0 * (k1w[i] + 2 * k2w[i] + 2 * k3w[i] + k4w[i]) for i in range(3))
    return q, w, angles


def test_rk4_kernel_gives_the_reference_bits_compiled_and_plain():
    """The rigid body's RK4 kernel (issue 27: 64 -> 6 us a 15 ms step with numba) equals the
    tuple-by-tuple reference bit for bit, compiled and as plain Python, over random states,
    inertias with products, torques and wheel terms."""
    rng = np.random.default_rng(27)
    kernels = [rk4_steps] + ([rk4_steps.py_func] if jit.ENABLED else [])
    for _ in range(200):
        J = np.diag(rng.uniform(0.1, 0.15, 3))
        J[0, 1] = J[1, 0] = rng.uniform(-0.01, 0.01)
        Ji = np.linalg.inv(J)
        args = (tuple(rng.normal(size=4)), tuple(rng.uniform(-0.5, 0.5, 3)), tuple(rng.uniform(-1, 1, 3)),
                tuple(J.ravel().tolist()), tuple(Ji.ravel().tolist()), tuple(rng.uniform(-1e-3, 1e-3, 3)),
                tuple(rng.uniform(-1e-4, 1e-4, 3)), tuple(rng.uniform(-1e-3, 1e-3, 3)),
                float(rng.choice([0.005, 0.0041, 0.1])), int(rng.integers(1, 5)))
        args = tuple(tuple(float(x) for x in a) if isinstance(a, tuple) else a for a in args)
        expected = _rk4_reference(*args)
        for kernel in kernels:
            assert kernel(*args) == expected
