"""The attitude MEKF (thesis section 3.3.1): from a TRIAD-sized initial error it converges on
noisy nadir and Sun vectors with a biased, noisy gyro, estimates the bias, its covariance is
consistent with its errors, and in eclipse (nadir only) the error about the nadir grows while
the filter says so."""
import math

import numpy as np
import pytest

from components.attitude import rigid_body
from components.core import rotations
from components.sensing import mekf, triad
from components.sensing.mekf import EXACT_ANGLE, AttitudeMEKF, NeesMonitor, _inverse_quadratic_form, \
    _propagated_covariance

H = 0.1
GYRO_SIGMA = 5.5e-4  # rad/s per 10 Hz sample (the attitude-determination system's gyro)
BIAS = np.array([1e-3, -5e-4, 2e-4])
NADIR_SIGMA = math.radians(0.25) / math.sqrt(2.0)  # per axis
SUN_SIGMA = math.radians(0.5) / 3.0 / math.sqrt(2.0)


def _noisy(v, sigma, rng):
    return v + rng.normal(0.0, sigma, 3)


def _run(seconds, sun=True, seed=1, filt=None, q_true=None, rng=None, update_bias=True):
    """(filter, true q, per-step true errors (rad, about the body axes), per-step 1-sigma)."""
    rng = rng or np.random.default_rng(seed)
    n = 0.00113
    omega = np.array([0.0, n, 0.0])  # the burn attitude's rate
    q_true = q_true or rotations.from_axis_angle((0.3, -0.2, 0.9), 0.7)
    nadir_N, sun_N = np.array([0.0, 0.0, -1.0]), np.array([0.6, 0.8, 0.0])
    if filt is None:
        filt = AttitudeMEKF(sigma_v=GYRO_SIGMA * math.sqrt(H), sigma_u=1e-7)
        q0 = rotations.circle_cross(rotations.from_axis_angle((1.0, 1.0, 0.0), math.radians(5.0)), q_true)
        filt.initialize(q0, math.radians(5.0), sigma_bias=2e-3)
    errors, sigmas = [], []
    for _ in range(int(round(seconds / H))):
        A = np.array(rotations.attitude_matrix(q_true))
        filt.update(_noisy(A @ nadir_N, NADIR_SIGMA, rng), nadir_N, NADIR_SIGMA, update_bias)
        if sun:
            filt.update(_noisy(A @ sun_N, SUN_SIGMA, rng), sun_N, SUN_SIGMA)
        dq = rotations.circle_cross(q_true, rotations.conjugate(filt.q))  # true = dq (x) estimate
        errors.append(2.0 * np.array(dq[:3]) * (1.0 if dq[3] >= 0 else -1.0))
        sigmas.append(filt.attitude_sigma())
        filt.propagate(omega + BIAS + rng.normal(0.0, GYRO_SIGMA, 3), H)
        q_true = triad.propagate(q_true, omega, H)
    return filt, q_true, np.array(errors), np.array(sigmas)


def test_converges_estimates_the_bias_and_is_consistent():
    filt, _, err, sig = _run(600.0)
    late = slice(len(err) // 2, None)
    rms = np.degrees(np.sqrt(np.mean(np.sum(err[late] ** 2, axis=1))))
    assert rms < 0.1  # from 5 deg; the sensors alone (TRIAD) give about 0.2 deg
    assert np.abs(filt.bias - BIAS).max() < 5e-5
    inside = np.mean(np.abs(err[late]) <= 3.0 * sig[late])
    assert inside > 0.97  # the covariance tells the truth about the error


def test_nees_is_the_error_against_the_filters_own_covariance():
    """NEES = dtheta^T P_aa^-1 dtheta with dtheta about the body axes (q_true = dq (x) q):
    an error about body x is weighed by P's x entry, whatever the attitude; over a converged
    run its mean is near 3 (chi-square, 3 degrees of freedom) and about 5 % of the steps exceed
    the 95 % bound."""
    filt = AttitudeMEKF()
    q = rotations.from_axis_angle((0.3, -0.2, 0.9), 0.7)
    filt.initialize(q, 1e-3)
    filt.P[:3, :3] = np.diag([1e-6, 4e-6, 9e-6])  # sigmas 1, 2, 3 mrad
    for axis, sigma in (((1.0, 0.0, 0.0), 1e-3), ((0.0, 1.0, 0.0), 2e-3), ((0.0, 0.0, 1.0), 3e-3)):
        q_true = rotations.circle_cross(rotations.from_axis_angle(axis, 2e-3), q)
        assert filt.attitude_nees(q_true) == pytest.approx((2e-3 / sigma) ** 2, rel=1e-5)
    assert filt.attitude_nees(q) == 0.0 and filt.attitude_nees(tuple(-x for x in q)) == 0.0
    # the converged run of the test above: consistent
    filt, _, err, sig = _run(600.0)
    late = slice(len(err) // 2, None)
    nees = np.sum((err[late] / sig[late]) ** 2, axis=1)  # P nearly diagonal once converged
    monitor = NeesMonitor()
    for x in nees:
        monitor.add(float(x))
    assert 2.0 < monitor.mean < 4.0 and monitor.over_fraction < 0.12
    assert monitor.count == len(nees) and monitor.mean == pytest.approx(np.mean(nees))
    restored = NeesMonitor()
    restored.set_state(monitor.get_state())
    assert (restored.mean, restored.over_fraction) == (monitor.mean, monitor.over_fraction)


def test_eclipse_nadir_only_error_about_nadir_grows_and_the_filter_knows():
    rng = np.random.default_rng(7)
    filt, q_true, _, _ = _run(600.0, rng=rng)
    sigma_before = np.array(filt.attitude_sigma())
    filt, _, err, sig = _run(1800.0, sun=False, filt=filt, q_true=q_true, rng=rng)
    assert np.array(filt.attitude_sigma()).max() > 2.0 * sigma_before.max()
    assert np.degrees(np.abs(err).max()) < 2.0  # the estimated bias keeps the drift small
    assert np.mean(np.abs(err) <= 3.0 * sig) > 0.97


def test_a_held_bias_is_a_consider_state_whose_covariance_stays_honest():
    """Nadir only with the bias held: the updates correct the attitude alone, the bias estimate
    does not move, its covariance only grows by the random walk the filter assumes, and the
    covariance still bounds the attitude error."""
    rng = np.random.default_rng(11)
    filt, q_true, _, _ = _run(600.0, rng=rng)
    bias, P_bias = filt.bias.copy(), filt.P[3:, 3:].copy()
    seconds = 3600.0
    filt, _, err, sig = _run(seconds, sun=False, filt=filt, q_true=q_true, rng=rng, update_bias=False)
    assert np.array_equal(filt.bias, bias)
    # the updates leave the bias block alone; each propagation adds sigma_u^2 h
    assert filt.P[3:, 3:] == pytest.approx(P_bias + np.eye(3) * filt.sigma_u ** 2 * seconds, rel=1e-9, abs=1e-18)
    assert np.allclose(filt.P, filt.P.T) and np.all(np.linalg.eigvalsh(filt.P) > 0.0)
    assert np.mean(np.abs(err) <= 3.0 * sig) > 0.97
    assert np.degrees(np.abs(err).max()) < 2.0  # the held bias was learned with the Sun: a small drift


def test_the_covariance_transition_is_first_order_below_its_angle_and_exact_above():
    """Up to EXACT_ANGLE per step Phi = I + F h (the mission's nominal runs, unchanged); above it
    exp(F h), so that a body spun up to hundreds of deg/s (a thruster stuck open) keeps a finite
    covariance (the first order grew it by (1 + angle^2) per step and overflowed)."""
    from scipy.linalg import expm

    rng = np.random.default_rng(3)
    L = rng.normal(size=(6, 6))
    P = L @ L.T * 1e-6 + np.eye(6) * 1e-8
    qv, qu = 1e-9, 1e-12

    def transition(w, h, exact):
        W = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
        F = np.zeros((6, 6))
        F[:3, :3], F[:3, 3:] = -W, -np.eye(3)
        return expm(F * h) if exact else np.eye(6) + F * h

    Q = np.diag([qv] * 3 + [qu] * 3)
    for w, h in (((0.2, -0.3, 0.25), 0.115), ((0.0, 0.0, 0.8), 0.125)):  # 0.05 and exactly 0.1 rad
        assert np.linalg.norm(w) * h <= EXACT_ANGLE + 1e-12
        phi = transition(w, h, exact=False)
        assert np.allclose(_propagated_covariance(P, *w, h, qv, qu), phi @ P @ phi.T + Q * h, rtol=1e-13, atol=0.0)
    for w, h in (((0.3, -5.0, 2.0), 0.1), ((16.0, 1.0, -0.5), 0.1), ((0.0, 1.2, 0.0), 0.1)):
        phi = transition(w, h, exact=True)
        assert np.allclose(_propagated_covariance(P, *w, h, qv, qu), phi @ P @ phi.T + Q * h, rtol=1e-12, atol=0.0)
    spun = P.copy()
    for _ in range(20000):  # 2000 s at 16 rad/s (920 deg/s)
        spun = _propagated_covariance(spun, 16.0, 1.0, -0.5, 0.1, qv, qu)
    # finite, and the attitude's sigma no more than its start plus what the bias' sigma integrates
    # to over the 2000 s (a rotation only turns it; the first order grew P by about 1 + 1.6^2 a step)
    drift = np.sqrt(np.max(np.diag(P)[3:])) * 2000.0 * math.sqrt(3.0)
    assert np.all(np.isfinite(spun)) and np.sqrt(np.max(np.diag(spun)[:3])) < np.sqrt(np.max(np.diag(P)[:3])) + drift


def test_bad_use_is_refused():
    filt = AttitudeMEKF()
    with pytest.raises(ValueError, match="not initialized"):
        filt.propagate((0.0, 0.0, 0.0), 0.1)
    with pytest.raises(ValueError, match="sigma_v"):
        AttitudeMEKF(sigma_v=-1.0)
    filt.initialize((0.0, 0.0, 0.0, 1.0), 0.01)
    with pytest.raises(ValueError, match="measurement sigma"):
        filt.update((1.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.0)
    state = filt.get_state()
    filt.propagate((0.01, 0.0, 0.0), 1.0)
    filt.set_state(state)
    assert filt.q == (0.0, 0.0, 0.0, 1.0)


def test_fmu_equals_the_component_and_declares_its_dependencies(build_one, tmp_path):
    """AttitudeEstimator through FMPy: TRIAD start, MEKF updates, gyro propagation and the rate
    filter give the component's estimate bit for bit; no output is direct feedthrough (all are
    computed in do_step); truth feedback passes the true state through."""
    from fmu_helpers import check_declarations, instantiate
    from components.sensing.mekf import AttitudeEstimator

    path = build_one("neighbor_attitude_estimator.py")
    deps = check_declarations(path)
    assert all(d == [] for d in deps.values())
    fmu, vr = instantiate(path, tmp_path, "estimator", initialize=True)
    model = AttitudeEstimator(inertia=rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3))  # the FMU default
    rng = np.random.default_rng(5)
    q_true = rotations.from_axis_angle((0.2, 0.9, -0.1), 1.1)
    omega = np.array([0.001, 0.00113, -0.002])
    r_BN, r_SN = [6798137.0, 0.0, 0.0], [0.0, -1.496e11, 0.0]
    torque = [2.5e-3, 0.0, -2.5e-3]
    names = ([f"nadir_B[{i}]" for i in (1, 2, 3)] + [f"sun_B[{i}]" for i in (1, 2, 3)]
             + [f"omega_meas_B[{i}]" for i in (1, 2, 3)] + [f"r_BN_N[{i}]" for i in (1, 2, 3)]
             + [f"r_SN_N[{i}]" for i in (1, 2, 3)] + [f"torque_cmd_B[{i}]" for i in (1, 2, 3)]
             + [f"q_true_BN[{i}]" for i in (1, 2, 3, 4)])
    try:
        fmu.setReal([vr[f"r_BN_N[{i}]"] for i in (1, 2, 3)], r_BN)
        for k in range(300):
            q_true = triad.propagate(q_true, omega, H)  # the truth at the step's end: the measurements' time
            A = np.array(rotations.attitude_matrix(q_true))
            nadir = _noisy(A @ -np.array(r_BN) / r_BN[0], NADIR_SIGMA, rng)
            sun = _noisy(A @ (np.array(r_SN) - r_BN) / np.linalg.norm(np.array(r_SN) - r_BN), SUN_SIGMA, rng)
            w = omega + BIAS + rng.normal(0.0, GYRO_SIGMA, 3)
            sunlit = k < 200  # then eclipse
            fmu.setReal([vr[n] for n in names], [*nadir, *sun, *w, *r_BN, *r_SN, *torque, *q_true])
            fmu.setBoolean([vr["nadir_valid"], vr["sun_valid"]], [True, sunlit])
            fmu.doStep(k * H, H)
            model.step((tuple(nadir), True, tuple(sun), sunlit, r_BN, r_SN), tuple(w), H, torque)
        got = fmu.getReal([vr[f"q_est_BN[{i}]"] for i in (1, 2, 3, 4)])
        assert got == list(model.filter.q)
        assert fmu.getReal([vr[f"omega_est_B[{i}]"] for i in (1, 2, 3)]) == list(model.rate)
        assert fmu.getBoolean([vr["initialized"]]) == [True]
        error = fmu.getReal([vr["attitude_error"]])[0]
        assert error == pytest.approx(triad.error_angle(got, q_true), abs=1e-15) and error < math.radians(0.3)
        bias = fmu.getReal([vr[f"bias_est_B[{i}]"] for i in (1, 2, 3)])
        assert np.abs(np.array(bias) - BIAS).max() < 2e-4
    finally:
        fmu.terminate()
        fmu.freeInstance()
    # truth feedback: the outputs are the truth inputs of the step
    fmu, vr = instantiate(path, tmp_path, "truth")
    try:
        fmu.setBoolean([vr["truth_feedback"]], [True])
        fmu.enterInitializationMode()
        truth = {"q_true_BN": [0.1, 0.2, 0.3, math.sqrt(0.86)], "omega_true_B": [0.01, -0.02, 0.03],
                 "omega_dot_true_B": [1e-3, 2e-3, -3e-3]}
        for name, values in truth.items():
            fmu.setReal([vr[f"{name}[{i}]"] for i in range(1, len(values) + 1)], values)
        fmu.exitInitializationMode()
        assert fmu.getReal([vr[f"q_est_BN[{i}]"] for i in (1, 2, 3, 4)]) == truth["q_true_BN"]
        fmu.setReal([vr["omega_true_B[1]"]], [0.5])
        assert fmu.getReal([vr["omega_est_B[1]"]]) == [0.01]  # a state output: changes in do_step
        fmu.doStep(0.0, 0.015)
        assert fmu.getReal([vr[f"omega_est_B[{i}]"] for i in (1, 2, 3)]) == [0.5, -0.02, 0.03]
        assert fmu.getReal([vr[f"omega_dot_est_B[{i}]"] for i in (1, 2, 3)]) == truth["omega_dot_true_B"]
        assert fmu.getBoolean([vr["initialized"]]) == [True]
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_nees_through_the_cholesky_factor_equals_the_lu_solve_and_refuses_an_indefinite_block():
    rng = np.random.default_rng(5)
    for _ in range(50):
        M = rng.normal(size=(3, 3))
        A = M @ M.T + np.diag(rng.uniform(1e-8, 1e-2, 3))
        d = rng.normal(size=3) * 1e-3
        assert _inverse_quadratic_form(A.tolist(), tuple(d)) == pytest.approx(d @ np.linalg.solve(A, d), rel=1e-9)
    assert _inverse_quadratic_form([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]], (1.0, 1.0, 1.0)) is None
    # a filter whose attitude block went indefinite still answers (LU), it does not raise
    filt = AttitudeMEKF()
    filt.initialize((0.0, 0.0, 0.0, 1.0), 0.01)
    filt.P[1, 1] = -1e-4
    q = rotations.normalized((0.001, 0.002, 0.0, 1.0))
    assert math.isfinite(filt.attitude_nees(q))


def _reference_step(state, u, h, J, J_inv, accel_sigma, sigma_v, qv, qu):
    """One step of the estimator between vector updates in plain Python floats, as the Python
    code wrote it before the step was compiled: the attitude over the step with the mean gyro
    rate (triad.propagate), the rate filter's prediction and update, the covariance gathered,
    the NEES and the outputs. `state` (get_state's) is changed in place; returns (outputs, nees)."""
    f, r = state["filter"], state["rates"]
    m, torque, q_true, w_true = u[14:17], u[17:20], u[24:28], u[28:31]
    state["time"] += h
    mean = [0.5 * (a + b) for a, b in zip(state["held_rate"], m)]
    w = [mean[i] - f["bias"][i] for i in range(3)]
    f["q"] = list(triad.propagate(tuple(f["q"]), w, h))
    state["cov_pending"] += h
    state["cov_rate"] = w
    o = r["omega"]
    Jw = [sum(J[i][j] * o[j] for j in range(3)) for i in range(3)]  # the same three terms, left to right
    gyroscopic = rotations.cross(o, Jw)
    v = [torque[i] - gyroscopic[i] for i in range(3)]
    a = [J_inv[i][0] * v[0] + J_inv[i][1] * v[1] + J_inv[i][2] * v[2] for i in range(3)]
    r["omega_dot"] = a
    o = [o[i] + a[i] * h for i in range(3)]
    P = [p + (accel_sigma * h) ** 2 for p in r["P"]]
    if state["cov_pending"] >= 0.1 - 1e-9:
        w = state["cov_rate"]
        f["P"] = _propagated_covariance(np.array(f["P"]), w[0], w[1], w[2], state["cov_pending"], qv, qu).tolist()
        state["cov_pending"] = 0.0
    state["held_rate"] = list(m)
    z = [m[i] - f["bias"][i] for i in range(3)]
    R = sigma_v ** 2 / h
    for i in range(3):
        gain = P[i] / (P[i] + R)
        o[i] += gain * (z[i] - o[i])
        P[i] *= 1.0 - gain
    r["omega"], r["P"] = o, P
    e = rotations.circle_cross(rotations.normalized(q_true), rotations.conjugate(f["q"]))
    k = 2.0 if e[3] >= 0.0 else -2.0
    nees = _inverse_quadratic_form([row[:3] for row in f["P"][:3]], [e[0] * k, e[1] * k, e[2] * k])
    error = triad.error_angle(f["q"], q_true)
    rate_error = math.sqrt(sum((a - b) ** 2 for a, b in zip(o, w_true)))
    return [*f["q"], *o, *a, error, rate_error], nees


def test_compiled_step_between_updates_gives_the_python_bits():
    """AttitudeEstimator.step_packed between vector updates (two compiled calls) against the
    plain-Python step: a tumbling body, a torque, a biased and noisy gyro, the covariance gathered
    over 0.1 s; every output and the NEES the same bits at every step (fails if the compiled code
    regroups a sum or numba turns a power of two into a product)."""
    J = rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3)
    est = mekf.AttitudeEstimator(inertia=J, accel_sigma=5e-4)
    rng = np.random.default_rng(11)
    est.filter.initialize(rotations.normalized((0.2, -0.4, 0.1, 0.8)), 0.01, bias=(1e-3, -2e-3, 5e-4))
    u, y, h = np.zeros(mekf.U_SIZE), np.zeros(mekf.Y_SIZE), 0.015
    u[mekf.U_Q_TRUE:mekf.U_Q_TRUE + 4] = rotations.normalized((0.21, -0.39, 0.12, 0.79))
    u[mekf.U_RATE:mekf.U_RATE + 3] = (0.3, -0.2, 0.25)
    est.step_packed(u, h)  # the first gyro sample held and the rate filter started
    J_inv = np.linalg.inv(np.array(J)).tolist()
    for step in range(400):
        u[mekf.U_RATE:mekf.U_RATE + 3] = np.array([0.3, -0.2, 0.25]) + rng.normal(0.0, 5e-4, 3)
        u[mekf.U_TORQUE:mekf.U_TORQUE + 3] = rng.normal(0.0, 2e-3, 3)
        u[mekf.U_RATE_TRUE:mekf.U_RATE_TRUE + 3] = (0.301, -0.199, 0.251)
        state = est.get_state()
        expected, nees = _reference_step(state, u.tolist(), h, J, J_inv, 5e-4, est.rates.sigma_v,
                                         est.filter.sigma_v ** 2, est.filter.sigma_u ** 2)
        assert est.step_packed(u, h, True, y) == 0
        assert y.tolist() == expected, step
        assert est.consistency.last == nees, step
        assert est.filter.P.tolist() == state["filter"]["P"], step
    assert est.consistency.count == 400
