"""Air-bearing testbed kinematics (the air-bearing note): the component, the AirBearingKinematics and
AttitudeToDcm FMUs through FMPy, and the air_bearing system through the master."""
import json
import math

import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from scipy.linalg import expm

from components.core import rotations
from components.sensing import air_bearing as ab
from paths import REPO

TAU = math.radians(40.0)
DCM_NAMES = [f"dcm_BN[{i},{j}]" for i in (1, 2, 3) for j in (1, 2, 3)]


def skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def const_rate_dcm(c0, w, t):
    """[BN](t) for a constant body rate w: [BN]_dot = -[w x][BN]."""
    return expm(-skew(w) * t) @ np.asarray(c0)


def R321(psi, theta, phi):
    return np.array(ab.dcm_from_euler321(psi, theta, phi))


def assert_rotation(c, tol=1e-12):
    c = np.asarray(c)
    np.testing.assert_allclose(c @ c.T, np.eye(3), rtol=0, atol=tol)
    assert abs(np.linalg.det(c) - 1.0) < tol


# ---- conventions and extraction ------------------------------------------------------------
def test_conventions_yaw_pitch_roll_and_quaternions():
    # A yaw about n3 is the attitude matrix of from_axis_angle(e3, psi): [BN] = R3(psi).
    q = rotations.from_axis_angle((0.0, 0.0, 1.0), 0.7)
    np.testing.assert_allclose(ab.euler321_from_quaternion(q), (0.7, 0.0, 0.0), atol=1e-15)
    # [BN] = R_321 = R1(phi) R2(theta) R3(psi) = A(q_x (x) q_y (x) q_z)
    rng = np.random.default_rng(7)
    for _ in range(200):
        psi, theta, phi = rng.uniform(-math.pi, math.pi), rng.uniform(-1.5, 1.5), rng.uniform(-math.pi, math.pi)
        c = R321(psi, theta, phi)
        r1 = np.array(rotations.attitude_matrix(rotations.from_axis_angle((1.0, 0.0, 0.0), phi)))
        r2 = np.array(rotations.attitude_matrix(rotations.from_axis_angle((0.0, 1.0, 0.0), theta)))
        r3 = np.array(rotations.attitude_matrix(rotations.from_axis_angle((0.0, 0.0, 1.0), psi)))
        np.testing.assert_allclose(c, r1 @ r2 @ r3, atol=1e-14)
        np.testing.assert_allclose(rotations.attitude_matrix(ab.quaternion_from_euler321(psi, theta, phi)), c,
                                   atol=1e-14)
        q = ab.quaternion_from_dcm(c)
        assert q[3] >= 0 and abs(math.fsum(x * x for x in q) - 1) < 1e-15
        np.testing.assert_allclose(rotations.attitude_matrix(q), c, atol=1e-14)
        np.testing.assert_allclose(ab.euler321_from_quaternion(q), (psi, theta, phi), atol=1e-12)
        # the tilt of b3 from n3: cos = cos(theta) cos(phi)
        assert c[2, 2] == pytest.approx(math.cos(theta) * math.cos(phi), abs=1e-14)


def test_atan2_extraction_covers_roll_beyond_90_deg_unlike_the_seed():
    psi, theta, phi = 0.4, 0.3, math.radians(120.0)
    c = R321(psi, theta, phi)
    # the description: phi = asin(R23 / cos(theta)) gives 60 deg, and the angles no longer give C back
    seed_phi = math.asin(c[1, 2] / math.cos(math.asin(-c[0, 2])))
    assert math.degrees(seed_phi) == pytest.approx(60.0, abs=1e-9)
    assert np.abs(R321(psi, theta, seed_phi) - c).max() > 0.5
    got = ab.euler321_from_quaternion(ab.quaternion_from_dcm(c))
    np.testing.assert_allclose(got, (psi, theta, phi), atol=1e-13)
    np.testing.assert_allclose(R321(*got), c, atol=1e-14)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_gimbal_lock_puts_the_combined_angle_into_yaw(sign):
    psi, phi = 0.3, 0.5
    c = R321(psi, sign * math.pi / 2, phi)
    got = ab.euler321_from_quaternion(ab.quaternion_from_dcm(c))
    # theta = +90 deg: only psi - phi is defined; theta = -90 deg: psi + phi. roll = 0.
    assert got[2] == 0.0
    assert got[0] == pytest.approx(psi - phi if sign > 0 else psi + phi, abs=1e-12)
    assert got[1] == pytest.approx(sign * math.pi / 2, abs=1e-12)
    np.testing.assert_allclose(R321(*got), c, atol=1e-12)
    # inside the lock band (1e-9 rad from 90 deg) the same rule; the DCM back to ~1e-9
    c = R321(psi, sign * (math.pi / 2 - 1e-9), phi)
    got = ab.euler321_from_quaternion(ab.quaternion_from_dcm(c))
    assert got[2] == 0.0
    np.testing.assert_allclose(R321(*got), c, atol=1e-8)
    # outside it (1e-5 rad) the regular extraction still resolves roll and yaw
    c = R321(psi, sign * (math.pi / 2 - 1e-5), phi)
    np.testing.assert_allclose(ab.euler321_from_quaternion(ab.quaternion_from_dcm(c)),
                               (psi, sign * (math.pi / 2 - 1e-5), phi), atol=1e-8)
    # through the limiter: pitch clamped to +-tau, roll 0, combined yaw kept
    out = ab.AirBearingKinematics(TAU).evaluate(R321(psi, sign * math.pi / 2, phi))
    assert out["limited"]
    np.testing.assert_allclose(out["euler321"], (psi - sign * phi, sign * TAU, 0.0), atol=1e-12)
    assert_rotation(out["dcm_out_BN"])


# ---- limiting ------------------------------------------------------------------------------
@pytest.mark.parametrize("angles, expected, limited", [
    ((100.0, 50.0, -60.0), (100.0, 40.0, -40.0), True),
    ((-170.0, -45.0, 10.0), (-170.0, -40.0, 10.0), True),
    ((20.0, 5.0, 170.0), (20.0, 5.0, 40.0), True),   # upside down: the description's asin would read 10 deg
    ((30.0, 30.0, -20.0), (30.0, 30.0, -20.0), False),
    ((-60.0, 40.0, -40.0), (-60.0, 40.0, -40.0), False),  # exactly at tau: not limited
])
def test_pitch_and_roll_are_clamped_yaw_kept_dcm_orthonormal(angles, expected, limited):
    psi, theta, phi = (math.radians(a) for a in angles)
    c_in = R321(psi, theta, phi)
    if angles[1:] == (40.0, -40.0):
        c_in = R321(psi, TAU, -TAU)
    model = ab.AirBearingKinematics(TAU)
    out = model.evaluate(c_in)
    assert out["limited"] is limited
    np.testing.assert_allclose(out["euler321"], [math.radians(a) for a in expected], atol=1e-12)
    c = np.array(out["dcm_out_BN"])
    assert_rotation(c)
    np.testing.assert_allclose(c, R321(*out["euler321"]), atol=1e-15)
    np.testing.assert_allclose(rotations.attitude_matrix(out["q_BN"]), c, atol=1e-14)
    assert c[2, 2] >= math.cos(TAU) ** 2 - 1e-15  # the tilt stays within the table's limit
    if not limited:
        np.testing.assert_allclose(c, c_in, atol=1e-14)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4).filter(lambda v: sum(x * x for x in v) > 1e-3),
       st.floats(0.05, 1.5))
def test_limiter_properties_for_any_attitude(qv, tau):
    c = rotations.attitude_matrix(rotations.normalized(qv))
    psi, theta, phi = ab.euler321_from_quaternion(ab.quaternion_from_dcm(c))
    out = ab.AirBearingKinematics(tau).evaluate(c)
    y, p, r = out["euler321"]
    assert abs(p) <= tau and abs(r) <= tau
    assert y == psi  # yaw preserved
    assert out["limited"] == (abs(theta) > tau or abs(phi) > tau)
    assert_rotation(out["dcm_out_BN"])


# ---- rate estimate -------------------------------------------------------------------------
@pytest.mark.parametrize("w, h", [((0.3, -0.2, 0.5), 0.02), ((0.0, 0.0, 1.0), 0.1), ((2.0, -1.0, 1.5), 0.5),
                                  ((1e-4, 2e-4, -1e-4), 0.015)])
def test_log_map_rate_is_exact_for_a_constant_rate(w, h):
    c0 = R321(0.2, -0.3, 0.25)  # inside tau; the rotation keeps it inside over these steps
    model = ab.AirBearingKinematics(math.radians(89.0), rate_from_thresholded=False)
    assert model.evaluate(c0)["omega_BN_B"] == (0.0, 0.0, 0.0)  # no previous sample yet
    for k in range(5):
        model.step(const_rate_dcm(c0, w, k * h), k * h, h)
        est = model.evaluate(const_rate_dcm(c0, w, (k + 1) * h))["omega_BN_B"]
        np.testing.assert_allclose(est, w, rtol=0, atol=1e-9)
    # the description's finite difference gives sin(|w| h)/h along the axis
    fd = ab.rate_finite_difference(const_rate_dcm(c0, w, h), c0, h)
    n = np.linalg.norm(w)
    np.testing.assert_allclose(fd, np.asarray(w) / n * math.sin(n * h) / h, atol=1e-12)


def test_rate_is_held_until_a_new_sample_arrives():
    """After step() committed C_k, outputs read with C_k still on the input (Jacobi master)
    give that step's estimate, not zero; a new input gives the fresh estimate."""
    w, h = (0.1, -0.3, 0.2), 0.05
    model = ab.AirBearingKinematics(TAU)
    model.step(const_rate_dcm(np.eye(3), w, 0.0), 0.0, h)
    assert model.evaluate(const_rate_dcm(np.eye(3), w, 0.0))["omega_BN_B"] == (0.0, 0.0, 0.0)  # first sample
    for k in range(1, 4):
        c = const_rate_dcm(np.eye(3), w, k * h)
        np.testing.assert_allclose(model.evaluate(c)["omega_BN_B"], w, atol=1e-9)  # fresh
        model.step(c, k * h, h)
        np.testing.assert_allclose(model.evaluate(c)["omega_BN_B"], w, atol=1e-9)  # held
    c = const_rate_dcm(np.eye(3), w, 3 * h)  # the body stops: the next commit reads zero
    model.step(c, 4 * h, h)
    assert model.evaluate(c)["omega_BN_B"] == (0.0, 0.0, 0.0)


def _euler_motion(t):
    """3-2-1 angles and their rates for a smooth varying motion, and the body rate."""
    psi, dpsi = 0.3 * math.sin(t), 0.3 * math.cos(t)
    theta, dtheta = 0.2 * math.sin(1.3 * t), 0.26 * math.cos(1.3 * t)
    phi, dphi = 0.25 * math.cos(0.7 * t), -0.175 * math.sin(0.7 * t)
    st_, ct = math.sin(theta), math.cos(theta)
    sf, cf = math.sin(phi), math.cos(phi)
    w = (dphi - dpsi * st_, dtheta * cf + dpsi * ct * sf, -dtheta * sf + dpsi * ct * cf)
    return R321(psi, theta, phi), np.array(w)


@pytest.mark.parametrize("method, order_mid", [("log_map", 2), ("finite_difference", 1)])
def test_rate_estimate_converges_for_a_varying_rate(method, order_mid):
    t = 1.0
    end_err, mid_err = [], []
    for h in (0.02, 0.01, 0.005):
        model = ab.AirBearingKinematics(TAU, rate_method=method)
        model.step(_euler_motion(t - h)[0], t - h, h)
        est = np.array(model.evaluate(_euler_motion(t)[0])["omega_BN_B"])
        end_err.append(np.linalg.norm(est - _euler_motion(t)[1]))
        mid_err.append(np.linalg.norm(est - _euler_motion(t - h / 2)[1]))
    # first order towards the rate at the sample time, second order (log map) at the midpoint
    assert end_err[-1] < 2e-3
    for a, b in zip(end_err, end_err[1:]):
        assert 1.8 < a / b < 2.2
    if order_mid == 2:
        assert mid_err[-1] < 1e-5
        for a, b in zip(mid_err, mid_err[1:]):
            assert 3.6 < a / b < 4.4


def test_history_uses_the_thresholded_dcm():
    """Roll at a constant rate through tau: with the description's re-propagation the rate is that of
    the thresholded attitude (zero roll rate once clamped) and the stored previous DCM is the
    thresholded one; with rate_from_thresholded=False it is the measured rate throughout."""
    w, h = (0.08, 0.0, 0.0), 0.05
    seed, raw = ab.AirBearingKinematics(TAU), ab.AirBearingKinematics(TAU, rate_from_thresholded=False)
    crossing = 0
    for k in range(200):
        c = R321(0.0, 0.0, 0.08 * k * h)  # = exp(-[w x] k h): roll about b1 = n1
        out_s, out_r = seed.evaluate(c), raw.evaluate(c)
        if k >= 1:
            assert max(abs(a - b) for a, b in zip(out_r["omega_BN_B"], w)) < 1e-9
            roll_prev = 0.08 * (k - 1) * h
            if 0.08 * k * h <= TAU:
                expected = w
            elif roll_prev >= TAU:
                expected = (0.0, 0.0, 0.0)
            else:  # the step that crosses tau: only the part up to tau
                expected = ((TAU - roll_prev) / h, 0.0, 0.0)
                crossing += 1
            assert max(abs(a - b) for a, b in zip(out_s["omega_BN_B"], expected)) < 1e-9
        seed.step(c, k * h, h)
        raw.step(c, k * h, h)
        assert seed.get_state()["prev_dcm"] == [list(row) for row in out_s["dcm_out_BN"]]
        assert raw.get_state()["prev_dcm"] != seed.get_state()["prev_dcm"] or not out_s["limited"]
    assert crossing == 1
    assert out_s["limited"] and out_s["euler321"][2] == pytest.approx(TAU, abs=1e-15)


def test_quaternion_output_is_sign_continuous():
    model = ab.AirBearingKinematics(TAU)
    q_prev, q4_min = None, 1.0
    for k in range(400):  # 1.6 turns of yaw: q4 reaches -1 when continuous (q4 >= 0 would jump)
        out = model.step(R321(0.025 * k, 0.1, -0.2), 0.1 * k, 0.1)
        if q_prev is not None:
            assert sum(a * b for a, b in zip(out["q_BN"], q_prev)) > 0.99
        q_prev = out["q_BN"]
        q4_min = min(q4_min, q_prev[3])
    assert q4_min < -0.99


# ---- errors and state ----------------------------------------------------------------------
@pytest.mark.parametrize("kwargs, words", [
    ({"tau": 0.0}, ["tau", "(0, pi/2)"]), ({"tau": math.pi / 2}, ["tau", "(0, pi/2)"]),
    ({"tau": -0.3}, ["tau"]), ({"tau": float("nan")}, ["tau"]), ({"tau": 2.0}, ["tau"]),
    ({"dcm_tol": 0.0}, ["dcm_tol", "(0, 0.1]"]), ({"dcm_tol": 0.5}, ["dcm_tol"]),
    ({"rate_method": "euler"}, ["rate_method", "log_map"]),
])
def test_bad_parameters_raise_clear_errors(kwargs, words):
    with pytest.raises(ValueError) as exc:
        ab.AirBearingKinematics(**kwargs)
    assert all(w in str(exc.value) for w in words)


def test_bad_input_dcm_raises_clear_errors():
    model = ab.AirBearingKinematics(TAU, dcm_tol=1e-6)
    c = R321(0.1, 0.2, 0.3)
    ok = model.evaluate(c + 1e-8)  # within the tolerance: projected onto a rotation
    assert_rotation(ok["dcm_out_BN"])
    with pytest.raises(ValueError, match=r"input dcm_BN is not orthonormal.*dcm_tol"):
        model.evaluate(1.01 * c)
    with pytest.raises(ValueError, match=r"input dcm_BN is not orthonormal"):
        model.step(c + 1e-4, 0.0, 0.1)
    with pytest.raises(ValueError, match=r"input dcm_BN has determinant -1"):
        model.evaluate(-c)
    with pytest.raises(ValueError, match=r"input dcm_BN .* non-finite"):
        model.evaluate(np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match="h must be a positive"):
        model.step(c, 0.0, 0.0)
    with pytest.raises(ValueError, match="q_BN"):
        ab.AttitudeToDcm().dcm((0.0, 0.0, 0.0, 0.0))


def test_get_and_set_state_restores_everything():
    model = ab.AirBearingKinematics(TAU)
    w = (0.05, 0.6, -0.1)  # pitches through tau
    seq = [const_rate_dcm(np.eye(3), w, 0.05 * k) for k in range(40)]
    for k in range(15):
        model.step(seq[k], 0.05 * k, 0.05)
    state = json.loads(json.dumps(model.get_state()))
    first = [model.step(seq[k], 0.05 * k, 0.05) for k in range(15, 40)]
    other = ab.AirBearingKinematics(TAU)
    other.set_state(state)
    second = [other.step(seq[k], 0.05 * k, 0.05) for k in range(15, 40)]
    assert first == second and any(o["limited"] for o in first) and not all(o["limited"] for o in first)


def test_attitude_to_dcm_normalizes():
    q = (1.0, 2.0, 3.0, 4.0)
    np.testing.assert_allclose(ab.AttitudeToDcm().dcm(q), rotations.attitude_matrix(rotations.normalized(q)),
                               atol=1e-15)


# ---- FMUs ----------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def ab_fmus(tmp_path_factory):
    import build_fmus

    d = tmp_path_factory.mktemp("air_bearing_fmus")
    for script in ("neighbor_air_bearing_kinematics.py", "neighbor_attitude_to_dcm.py", "neighbor_rigid_body.py"):
        build_fmus.build_fmu(REPO / "fmus" / script, d)
    return d


@pytest.fixture(scope="session")
def ab_ssp(ab_fmus, tmp_path_factory):
    import build_fmus

    return build_fmus.pack_ssp(REPO / "system_ssp" / "systems" / "air_bearing.ssd", ab_fmus,
                               tmp_path_factory.mktemp("air_bearing_ssp"))


def test_fmus_are_valid_and_declare_units_and_dependencies(ab_fmus):
    kin, to_dcm = ab_fmus / "AirBearingKinematics.fmu", ab_fmus / "AttitudeToDcm.fmu"
    for path in (kin, to_dcm):
        assert validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(kin))
    assert md.coSimulation.canGetAndSetFMUstate
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["omega_BN_B[1]"] == "rad/s" and units["euler321[2]"] == "rad" and units["tau"] == "rad"
    assert units["dcm_BN[2,3]"] == "1" and units["dcm_out_BN[3,1]"] == "1" and units["q_BN[4]"] == "1"
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    assert len(deps) == 4 + 3 + 3 + 9 + 1
    assert all(d == sorted(DCM_NAMES) for d in deps.values())
    md = fmpy.read_model_description(str(to_dcm))
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    assert set(deps) == set(DCM_NAMES) and all(d == [f"q_BN[{i}]" for i in (1, 2, 3, 4)] for d in deps.values())


def test_fmus_simulate_alone(ab_fmus):
    psi, theta, phi = 0.5, 0.9, 0.1  # pitch 51.6 deg > tau
    c = R321(psi, theta, phi)
    r = fmpy.simulate_fmu(str(ab_fmus / "AirBearingKinematics.fmu"), stop_time=0.5, output_interval=0.1,
                          start_values={n: float(v) for n, v in zip(DCM_NAMES, c.ravel())})
    assert r["time"][-1] == pytest.approx(0.5)
    assert all(r["limited"])
    np.testing.assert_allclose(r["euler321[1]"], psi, atol=1e-12)
    np.testing.assert_allclose(r["euler321[2]"], TAU, atol=1e-12)
    np.testing.assert_allclose(r["euler321[3]"], phi, atol=1e-12)
    np.testing.assert_allclose(r["omega_BN_B[2]"], 0.0, atol=1e-12)  # constant input: no rate
    q = (0.1, -0.2, 0.3, 0.5)
    r = fmpy.simulate_fmu(str(ab_fmus / "AttitudeToDcm.fmu"), stop_time=0.1, output_interval=0.1,
                          start_values={f"q_BN[{i}]": v for i, v in enumerate(q, 1)})
    a = rotations.attitude_matrix(rotations.normalized(q))
    for i in range(3):
        for j in range(3):
            assert r[f"dcm_BN[{i + 1},{j + 1}]"][-1] == pytest.approx(a[i][j], abs=1e-15)


def test_fmu_rejects_bad_input_and_parameter_with_messages(ab_fmus):
    msgs = []

    def logger(env, inst, status, cat, msg):
        msgs.append(msg.decode() if isinstance(msg, bytes) else str(msg))

    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(ab_fmus / "AirBearingKinematics.fmu"), stop_time=0.1,
                          start_values={"dcm_BN[1,1]": 1.1}, logger=logger, debug_logging=True)
    assert any("input dcm_BN is not orthonormal" in m for m in msgs)
    msgs.clear()
    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(ab_fmus / "AirBearingKinematics.fmu"), stop_time=0.1,
                          start_values={"tau": 1.6}, logger=logger, debug_logging=True)
    assert any("tau" in m and "(0, pi/2)" in m for m in msgs)


def test_fmu_rate_and_get_set_state(ab_fmus, tmp_path):
    path = ab_fmus / "AirBearingKinematics.fmu"
    md = fmpy.read_model_description(str(path))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(path), unzipdir=str(tmp_path / "k")),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="kinematics")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    ins = [vr[n] for n in DCM_NAMES]
    outs = ([vr[f"omega_BN_B[{i}]"] for i in (1, 2, 3)] + [vr[f"q_BN[{i}]"] for i in (1, 2, 3, 4)]
            + [vr[f"euler321[{i}]"] for i in (1, 2, 3)])
    w, h = (0.05, 0.6, -0.1), 0.05
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()

        def run(k0, k1):
            rows = []
            for k in range(k0, k1):
                fmu.setReal(ins, list(const_rate_dcm(np.eye(3), w, k * h).ravel()))
                rows.append(fmu.getReal(outs) + fmu.getBoolean([vr["limited"]]))
                fmu.doStep(k * h, h)
            return rows

        rows = run(0, 10)
        assert rows[0][:3] == [0.0, 0.0, 0.0]
        np.testing.assert_allclose([r[:3] for r in rows[1:]], [w] * 9, atol=1e-9)  # inside tau
        state = fmu.getFMUstate()
        first = run(10, 30)
        run(30, 35)
        fmu.setFMUstate(state)
        second = run(10, 30)
        assert first == second and first[-1][-1] and not first[0][-1]
        fmu.freeFMUstate(state)
    finally:
        fmu.terminate()
        fmu.freeInstance()


# ---- the system through the master ---------------------------------------------------------
def _col(r, name):
    return np.asarray(r.data[name])


def test_system_tilt_beyond_tau(ab_ssp):
    import system_ssp

    r = system_ssp.simulate(ab_ssp, parameter_sets=["parameters/air_bearing_tilt_beyond_tau.ssv"])
    assert r.stop_reason == "reached stop time" and r.order == ["to_dcm", "kinematics", "dynamics"]
    t = _col(r, "time")
    assert t[-1] == pytest.approx(20.0) and len(t) == 1001
    roll, lim = _col(r, "kinematics.euler321[3]"), _col(r, "kinematics.limited")
    inside = 0.08 * t <= TAU
    np.testing.assert_allclose(roll[inside], 0.08 * t[inside], atol=1e-9)
    np.testing.assert_allclose(roll[~inside], TAU, atol=1e-15)
    assert not lim[inside].any() and lim[~inside].all()
    assert t[~inside][0] == pytest.approx(8.74)
    for name in ("kinematics.euler321[1]", "kinematics.euler321[2]"):
        np.testing.assert_allclose(_col(r, name), 0.0, atol=1e-12)
    wx = _col(r, "kinematics.omega_BN_B[1]")
    assert wx[0] == 0.0  # first sample: no rate yet
    np.testing.assert_allclose(wx[1:][inside[1:]], 0.08, atol=1e-9)
    np.testing.assert_allclose(wx[t >= 8.76 - 1e-9], 0.0, atol=1e-12)  # thresholded stream: held
    dcm = np.stack([_col(r, f"kinematics.dcm_out_{n[4:]}") for n in DCM_NAMES], axis=1).reshape(-1, 3, 3)
    np.testing.assert_allclose(np.einsum("kij,klj->kil", dcm, dcm), np.broadcast_to(np.eye(3), dcm.shape),
                               atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(dcm), 1.0, atol=1e-12)
    # measured rate of the raw stream instead: the body rate throughout
    r = system_ssp.simulate(ab_ssp, parameter_sets=["parameters/air_bearing_tilt_beyond_tau.ssv"],
                            parameters={"kinematics.rate_from_thresholded": False}, stop_time=12.0,
                            outputs=["kinematics.omega_BN_B[1]", "kinematics.limited"])
    np.testing.assert_allclose(_col(r, "kinematics.omega_BN_B[1]")[1:], 0.08, atol=1e-9)
    assert _col(r, "kinematics.limited")[-1]


@pytest.mark.parametrize("algorithm, order, first, angle_lag", [
    ("gauss-seidel", None, 1, 0),                          # the SSD's order: no lag
    ("gauss-seidel", "dynamics to_dcm kinematics", 2, 0),  # the source stepped first: rate held, 1 step late
    ("jacobi", None, 3, 2)])                               # Jacobi: to_dcm adds a step, the rate one more
def test_system_rate_under_other_orders_and_jacobi(ab_ssp, algorithm, order, first, angle_lag):
    import system_ssp

    r = system_ssp.simulate(ab_ssp, parameter_sets=["parameters/air_bearing_tilt_beyond_tau.ssv"], stop_time=1.0,
                            algorithm=algorithm, order=order,
                            outputs=["kinematics.omega_BN_B[1]", "kinematics.euler321[3]"])
    wx = _col(r, "kinematics.omega_BN_B[1]")
    assert (wx[:first] == 0.0).all()
    np.testing.assert_allclose(wx[first:], 0.08, atol=1e-9)
    t = _col(r, "time")
    np.testing.assert_allclose(_col(r, "kinematics.euler321[3]")[angle_lag:], 0.08 * t[:len(t) - angle_lag],
                               atol=1e-12)


def test_system_slow_rotation_stays_inside_tau(ab_ssp):
    import system_ssp

    r = system_ssp.simulate(ab_ssp, parameter_sets=["parameters/air_bearing_slow_rotation.ssv"])
    assert not _col(r, "kinematics.limited").any()
    pitch, roll = _col(r, "kinematics.euler321[2]"), _col(r, "kinematics.euler321[3]")
    assert 0.2 < max(np.abs(pitch).max(), np.abs(roll).max()) < math.radians(19.0)
    q_k = np.stack([_col(r, f"kinematics.q_BN[{i}]") for i in (1, 2, 3, 4)], axis=1)
    q_d = np.stack([_col(r, f"dynamics.q_BN[{i}]") for i in (1, 2, 3, 4)], axis=1)
    np.testing.assert_allclose(np.abs(np.sum(q_k * q_d, axis=1)), 1.0, atol=1e-12)  # same attitude
    w_k = np.stack([_col(r, f"kinematics.omega_BN_B[{i}]") for i in (1, 2, 3)], axis=1)
    w_d = np.stack([_col(r, f"dynamics.omega_BN_B[{i}]") for i in (1, 2, 3)], axis=1)
    # mean rate over the 20 ms step against the rate at its end: O(h) lag, here < 2e-5 rad/s
    assert np.abs(w_k[1:] - w_d[1:]).max() < 2e-5
    # against the mean of the rates at both ends (midpoint to O(h^2)) much closer
    assert np.abs(w_k[1:] - 0.5 * (w_d[1:] + w_d[:-1])).max() < 1e-7


def test_system_rejects_bad_tau(ab_ssp):
    import system_ssp

    with pytest.raises(system_ssp.SSPError, match=r"kinematics.*tau = 1\.6 rad must be in \(0, pi/2\)"):
        system_ssp.simulate(ab_ssp, parameters={"kinematics.tau": 1.6}, stop_time=0.1)
