"""Attitude sensors with seeded noise and TRIAD attitude determination (thesis section 3.3.1):
components directly, each FMU through FMPy, and the attitude_determination system through
the master."""
import json
import math

import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
import numpy as np
import pytest

import build_fmus
from components.attitude import rigid_body
from components.core import jit, rotations
from components.sensing import sensors, triad
from paths import REPO
import system_ssp

WRAPPERS = {"HorizonSensor": "neighbor_horizon_sensor", "SunSensor": "neighbor_sun_sensor", "Gyro": "neighbor_gyro",
            "GpsReceiver": "neighbor_gps_receiver", "AttitudeDetermination": "neighbor_attitude_determination"}
SSD = REPO / "system_ssp" / "systems" / "attitude_determination.ssd"
DEG = math.pi / 180.0
R_LEO = (6798137.0, 0.0, 0.0)


def random_quaternion(rng):
    return rotations.normalized(tuple(rng.standard_normal(4)))


def rot(q, v):
    return sensors.rotate_vector(rotations.attitude_matrix(q), v)


# ---- components: TRIAD and Shepperd ------------------------------------------------------
def test_shepperd_inverts_the_attitude_matrix_on_every_branch():
    rng = np.random.default_rng(11)
    qs = [random_quaternion(rng) for _ in range(500)]
    # near-180 deg rotations about each axis exercise the q1, q2, q3 branches
    qs += [rotations.from_axis_angle(axis, math.pi - 1e-3) for axis in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    qs += [(0.0, 0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0)]
    branches = set()
    for q in qs:
        A = rotations.attitude_matrix(q)
        p = triad.dcm_to_quaternion(A)
        tr = A[0][0] + A[1][1] + A[2][2]
        cand = (A[0][0], A[1][1], A[2][2], tr)
        branches.add(cand.index(max(cand)))
        assert p[3] >= 0.0
        assert np.allclose(rotations.attitude_matrix(p), A, rtol=0, atol=1e-12)
        assert min(np.abs(np.subtract(p, q)).max(), np.abs(np.add(p, q)).max()) < 1e-12
    assert branches == {0, 1, 2, 3}


def test_triad_recovers_the_attitude_exactly_from_noise_free_vectors():
    rng = np.random.default_rng(12)
    for _ in range(300):
        q = random_quaternion(rng)
        r1, r2 = rng.standard_normal(3) * 1e7, rng.standard_normal(3)
        A = rotations.attitude_matrix(q)
        b1, b2 = sensors.rotate_vector(A, r1), sensors.rotate_vector(A, r2)
        At = triad.triad(b1, b2, r1, r2)
        assert np.allclose(At, A, rtol=0, atol=1e-12)
        qt = triad.triad_quaternion(b1, b2, r1, r2)
        assert np.allclose(rotations.attitude_matrix(qt), At, rtol=0, atol=1e-12)
        assert triad.error_angle(qt, q) < 1e-9
        # TRIAD reproduces b1 exactly, whatever b2 is (here b2 perturbed)
        b2n = np.add(b2, 0.05 * rng.standard_normal(3))
        Ab = triad.triad(b1, b2n, r1, r2)
        assert np.allclose(sensors.rotate_vector(Ab, sensors.unit_vector(r1, "r1")),
                           sensors.unit_vector(b1, "b1"), atol=1e-12)


def test_triad_refuses_parallel_and_zero_vectors():
    with pytest.raises(ValueError, match="parallel"):
        triad.triad((1, 0, 0), (2, 0, 0), (0, 1, 0), (0, 0, 1))
    with pytest.raises(ValueError, match="reference vectors are parallel"):
        triad.triad((1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, -3))
    with pytest.raises(ValueError, match="b1"):
        triad.triad((0, 0, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0))
    with pytest.raises(ValueError, match="finite"):
        triad.dcm_to_quaternion([[1, 0, 0], [0, 1, 0], [0, 0, math.nan]])


# ---- components: sensors -------------------------------------------------------------------
def test_noise_free_sensors_measure_the_truth():
    rng = np.random.default_rng(13)
    q = random_quaternion(rng)
    r_sun = (1.0e11, -1.2e11, -5e10)
    h = sensors.HorizonSensor(sigma=0.0, seed=5)
    nadir, ok = h.measure(R_LEO, q)
    assert ok and np.allclose(nadir, rot(q, (-1.0, 0.0, 0.0)), atol=1e-15)
    sun_B_true = rot(q, sensors.unit_vector(np.subtract(r_sun, R_LEO), "s"))
    s = sensors.SunSensor(boresight_B=sun_B_true, half_fov=10 * DEG, sigma=0.0, seed=5)
    sun, ok = s.measure(r_sun, R_LEO, q, True)
    assert ok and np.allclose(sun, sun_B_true, atol=1e-15)
    assert s.measure(r_sun, R_LEO, q, False) == ((0.0, 0.0, 0.0), False)  # eclipse
    off = sensors.SunSensor(boresight_B=[-x for x in sun_B_true], half_fov=60 * DEG, sigma=0.0)
    assert off.measure(r_sun, R_LEO, q, True) == ((0.0, 0.0, 0.0), False)  # outside the FOV
    # field of view edge: the Sun 59.9 / 60.1 deg off a boresight
    for angle, inside in ((59.9, True), (60.1, False)):
        bs = sensors.perturb(sun_B_true, angle * DEG, 0.3)
        assert sensors.SunSensor(boresight_B=bs, sigma=0.0).measure(r_sun, R_LEO, q)[1] is inside
    g = sensors.Gyro(bias=(1e-3, -2e-3, 3e-3), sigma=0.0)
    assert g.measure((0.1, 0.2, 0.3)) == pytest.approx((0.101, 0.198, 0.303), abs=1e-15)
    gps = sensors.GpsReceiver(sigma=0.0, start_time=5.0)
    assert gps.measure(R_LEO) == (R_LEO, True) and gps.time == 5.0
    gps.step(0.1, 5.1)
    assert gps.time == 5.1
    assert sensors.GpsReceiver(available=False).measure(R_LEO) == ((0.0, 0.0, 0.0), False)


def test_sensor_noise_statistics_match_sigma():
    n = 3000
    q = (0.1, -0.2, 0.3, 0.9)
    q = rotations.normalized(q)
    sigma = 0.25 * DEG
    h = sensors.HorizonSensor(sigma=sigma, seed=21)
    true = rot(q, (-1.0, 0.0, 0.0))
    angles, perp = [], []
    for _ in range(n):
        b, _ = h.measure(R_LEO, q)
        assert abs(rotations.norm(b) - 1.0) < 1e-14
        angles.append(math.atan2(rotations.norm(rotations.cross(true, b)), rotations.dot(true, b)))
        d = np.subtract(b, true)
        perp.append(d / np.linalg.norm(d))
        h.step()
    rms = math.sqrt(np.mean(np.square(angles)))
    assert rms == pytest.approx(sigma, rel=0.05)  # sampling error of the RMS ~ 1.1 %
    # the error directions are spread around the vector (uniform azimuth): mean direction ~ 0
    assert np.linalg.norm(np.mean(perp, axis=0)) < 0.05
    g = sensors.Gyro(bias=(1e-3, 0.0, -1e-3), sigma=5e-4, seed=22)
    w = []
    for _ in range(n):
        w.append(g.measure((0.01, 0.02, 0.03)))
        g.step(0.1)
    w = np.array(w)
    assert np.allclose(w.mean(axis=0), (0.011, 0.02, 0.029), atol=4 * 5e-4 / math.sqrt(n))
    assert np.allclose(w.std(axis=0), 5e-4, rtol=0.05)
    gps = sensors.GpsReceiver(sigma=1.5, seed=23)
    r = []
    for _ in range(n):
        r.append(gps.measure(R_LEO)[0])
        gps.step(1.0)
    assert np.allclose(np.std(r, axis=0), 1.5, rtol=0.05)


def _outputs(sensor, n, *args):
    out = []
    for _ in range(n):
        out.append(sensor.measure(*args))
        sensor.step(0.1)
    return out


def test_noise_is_reproducible_and_state_restores_the_generator():
    q = rotations.normalized((0.3, 0.1, -0.2, 0.9))
    for make, args in ((lambda s: sensors.HorizonSensor(seed=s), (R_LEO, q)),
                       (lambda s: sensors.Gyro(sigma=1e-3, seed=s), ((0.1, 0.0, 0.0),)),
                       (lambda s: sensors.GpsReceiver(seed=s), (R_LEO,))):
        assert _outputs(make(7), 20, *args) == _outputs(make(7), 20, *args)
        assert _outputs(make(7), 20, *args) != _outputs(make(8), 20, *args)
        sensor = make(7)
        _outputs(sensor, 5, *args)
        state = json.loads(json.dumps(sensor.get_state()))  # JSON-able
        first = _outputs(sensor, 10, *args)
        sensor.set_state(state)
        assert _outputs(sensor, 10, *args) == first
        other = make(99)
        other.set_state(state)
        assert _outputs(other, 10, *args) == first


def _one_draw_a_step(seed, n):
    """The gyro's noise as one standard_normal(3) a step would draw it (before the block)."""
    rng = np.random.default_rng(seed)
    return [tuple(rng.standard_normal(3).tolist()) for _ in range(n)], rng


@pytest.mark.parametrize("compiled", [False, True], ids=["plain", "numba"])
def test_gyro_noise_block_and_native_kernel_give_one_draw_a_steps_bits(compiled):
    """The gyro draws its noise sensors.NOISE_BLOCK samples at a time: the same samples as one draw a
    step, across refills, and get_state gives the generator's state of one draw a step (a state
    restored there draws on). gyro_into, the FMU's native step (plain and compiled), takes the
    Python step's bits: the sampling step's scale, the bias jump, the next block's first row, a
    rate that is not finite (stepped, nothing written)."""
    n = 2 * sensors.NOISE_BLOCK + 10
    draws, rng = _one_draw_a_step(5, n + 1)
    gyro = sensors.Gyro((1e-3, 0.0, -1e-3), 5.5e-4, seed=5, sigma_sample_time=0.1, bias_jump=(0.0, 2e-3, 0.0),
                        jump_time=3.0)
    assert gyro.sample == draws[0]
    for k in range(1, sensors.NOISE_BLOCK + 5):
        gyro.step(0.015)
        assert gyro.sample == draws[k], k
    state = gyro.get_state()
    assert state["rng"] == _one_draw_a_step(5, sensors.NOISE_BLOCK + 5)[1].bit_generator.state
    restored = sensors.Gyro(seed=9)
    restored.set_state(json.loads(json.dumps(state)))
    restored.step(0.015)
    assert restored.sample == draws[sensors.NOISE_BLOCK + 5]
    # the kernel against the methods
    if compiled and not jit.ENABLED:
        pytest.skip("numba is not used here (NEIGHBOR_COSIM_NUMBA=0 or not installed)")
    law = sensors.gyro_into if compiled else jit.function_of(sensors.gyro_into)
    python = sensors.Gyro((1e-3, 0.0, -1e-3), 5.5e-4, seed=5, sigma_sample_time=0.1, bias_jump=(0.0, 2e-3, 0.0),
                          jump_time=3.0)
    native = sensors.Gyro((1e-3, 0.0, -1e-3), 5.5e-4, seed=5, sigma_sample_time=0.1, bias_jump=(0.0, 2e-3, 0.0),
                          jump_time=3.0)
    values, inputs, outputs = np.zeros(6), np.arange(3), np.arange(3, 6)
    refills = 0
    for k in range(n):
        values[:3] = (0.1 * math.sin(k), -0.05, 0.02 * math.cos(k)) if k != 50 else (math.nan, 0.0, 0.0)
        python.step(0.015)
        status = law(native.constants, native.x, native.block.ravel(), values, inputs, outputs, 0.015, True)
        if status == 1:  # the block used up: the Python step draws the next
            refills += 1
            native.step(0.015)
            status = law(native.constants, native.x, native.block.ravel(), values, inputs, outputs, 0.0, False)
        assert native.x.tolist() == python.x.tolist(), k
        if k == 50:
            assert status == 2
            continue
        assert status == 0 and values[3:].tolist() == list(python.measure(values[:3])), k
    assert refills == 2 and python.jumped and python.bias == (1e-3, 2e-3, -1e-3)


def test_bad_parameters_name_the_parameter():
    with pytest.raises(ValueError, match="sigma"):
        sensors.HorizonSensor(sigma=-1.0)
    with pytest.raises(ValueError, match="seed"):
        sensors.Gyro(seed=-3)
    with pytest.raises(ValueError, match="half_fov"):
        sensors.SunSensor(half_fov=0.0)
    with pytest.raises(ValueError, match="boresight_B"):
        sensors.SunSensor(boresight_B=(0, 0, 0))
    with pytest.raises(ValueError, match="bias"):
        sensors.Gyro(bias=(0.0, math.inf, 0.0))
    with pytest.raises(ValueError, match="min_separation"):
        triad.AttitudeDetermination(min_separation=2.0)
    with pytest.raises(ValueError, match="sun_sigma"):
        triad.AttitudeDetermination(sun_sigma=math.nan)
    with pytest.raises(ValueError, match="q0"):
        triad.AttitudeDetermination(q0=(0, 0, 0, 0))


# ---- components: TRIAD error statistics ----------------------------------------------------
def _triad_rms(nadir_sigma, sun_sigma, theta, n, seed, ad_sigmas=None):
    """Monte Carlo RMS attitude error of AttitudeDetermination with sensor noise; ad_sigmas:
    the (nadir, sun) sigmas AttitudeDetermination is told, if not the sensors' own."""
    rng = np.random.default_rng(seed)
    r_sun = 1.5e11 * np.array([math.cos(math.pi - theta), math.sin(math.pi - theta), 0.0]) + R_LEO
    horizon = sensors.HorizonSensor(sigma=nadir_sigma, seed=seed + 1)
    sun = sensors.SunSensor(sigma=sun_sigma, half_fov=math.pi, seed=seed + 2)
    ad = triad.AttitudeDetermination(*(ad_sigmas or (nadir_sigma, sun_sigma)))
    err = []
    for _ in range(n):
        q = random_quaternion(rng)
        nb, nv = horizon.measure(R_LEO, q)
        sb, sv = sun.measure(r_sun, R_LEO, q)
        q_est, fix, _ = ad.estimate(nb, nv, sb, sv, R_LEO, r_sun)
        assert fix
        err.append(triad.error_angle(q_est, q))
        horizon.step()
        sun.step()
    return math.sqrt(np.mean(np.square(err)))


@pytest.mark.parametrize("theta_deg, nadir_deg, sun_deg", [(100.0, 0.25, 0.5 / 3), (40.0, 0.25, 0.5 / 3),
                                                           (90.0, 1.0, 0.1)])
def test_triad_error_rms_matches_the_first_order_prediction(theta_deg, nadir_deg, sun_deg):
    """Criterion: over 1500 independent draws the RMS error angle is within 10 % of the
    first-order TRIAD prediction sqrt(s1^2 + (s2^2 + cos^2 s1^2)/(2 sin^2)) (s1 of the
    trusted vector, theta the angle between the vectors); the sampling error of the RMS is
    about 2 %."""
    theta, s_h, s_s = theta_deg * DEG, nadir_deg * DEG, sun_deg * DEG
    rms = _triad_rms(s_h, s_s, theta, 1500, 31)
    predicted = triad.triad_error_rms(s_s, s_h, theta)  # the Sun is more accurate: it goes first
    assert 0.9 < rms / predicted < 1.1
    if nadir_deg == 1.0:
        # the other order: same sensors and draws, `ad` told the sigmas the wrong way round
        swapped = _triad_rms(s_h, s_s, theta, 1500, 31, ad_sigmas=(s_s, s_h))
        assert 0.9 < swapped / triad.triad_error_rms(s_h, s_s, theta) < 1.1
        assert swapped > 1.25 * rms  # trusting the better sensor pays


def test_attitude_determination_orders_by_sigma():
    # Exact nadir, Sun 10 deg off: nadir-first keeps the nadir exact, Sun-first does not.
    q = rotations.normalized((0.2, -0.1, 0.4, 0.8))
    r_sun = (0.0, 1.5e11, 0.0)
    nadir_B = rot(q, (-1.0, 0.0, 0.0))
    sun_B = sensors.perturb(rot(q, sensors.unit_vector(np.subtract(r_sun, R_LEO), "s")), 10 * DEG, 0.7)
    meas = (nadir_B, True, sun_B, True, R_LEO, r_sun)
    q_n, fix, _ = triad.AttitudeDetermination(nadir_sigma=0.1, sun_sigma=0.2).estimate(*meas)
    assert fix and np.allclose(rot(q_n, (-1.0, 0.0, 0.0)), nadir_B, atol=1e-12)
    q_s, _, _ = triad.AttitudeDetermination(nadir_sigma=0.2, sun_sigma=0.1).estimate(*meas)
    assert np.allclose(rot(q_s, sensors.unit_vector(np.subtract(r_sun, R_LEO), "s")), sun_B, atol=1e-12)
    assert triad.error_angle(q_s, q) > 5 * DEG
    # no fix without both vectors or with nearly parallel ones
    ad = triad.AttitudeDetermination(q0=(0, 0, 1, 0))
    assert ad.estimate(nadir_B, True, sun_B, False, R_LEO, r_sun) == ((0.0, 0.0, 1.0, 0.0), False, 0.0)
    assert not ad.estimate(nadir_B, True, nadir_B, True, R_LEO, (-1e11, 0.0, 0.0))[1]


def test_propagation_is_exact_for_a_constant_rate_and_follows_the_bias():
    w = (0.02, -0.01, 0.03)
    q0 = rotations.normalized((0.1, 0.2, 0.3, 0.9))
    # reference: RK4 on q_dot = 1/2 Xi(q) w in 5 ms steps
    q = np.array(q0)
    for _ in range(2000):
        k1 = np.array(rotations.quaternion_rate(q, w))
        k2 = np.array(rotations.quaternion_rate(q + 0.0025 * k1, w))
        k3 = np.array(rotations.quaternion_rate(q + 0.0025 * k2, w))
        k4 = np.array(rotations.quaternion_rate(q + 0.005 * k3, w))
        q = q + 0.005 / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    ad = triad.AttitudeDetermination(q0=q0)
    none = ((0, 0, 0), False, (0, 0, 0), False, R_LEO, (0, 1e11, 0))
    for _ in range(100):
        ad.step(none, w, 0.1)
    assert triad.error_angle(ad.q, q) < 1e-10
    assert ad.estimate(*none)[1:] == (False, pytest.approx(10.0))
    # eclipse at component level: a rigid tumble measured by a biased, noisy gyro
    J = rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3)
    body = rigid_body.RigidBody(J, q0, (0.01, 0.005, -0.02))
    bias = (1e-3, -1e-3, 1e-3)
    gyro = sensors.Gyro(bias=bias, sigma=5.5e-4, seed=3)
    ad = triad.AttitudeDetermination(q0=q0)
    b = rotations.norm(bias)
    for k in range(1, 601):
        ad.step(none, gyro.measure(body.omega), 0.1)
        body.step((0, 0, 0), 0.1)
        gyro.step(0.1)
        if k % 100 == 0:
            t = 0.1 * k
            e = triad.error_angle(ad.q, body.q)
            # |d err/dt| <= |bias| + noise; the tumble turns the body-fixed bias, so a bit less
            assert 0.7 * b * t < e < b * t + 5 * 5.5e-4 * math.sqrt(0.1 * t) + 1e-3, (t, e)


def test_attitude_determination_state_round_trip():
    ad = triad.AttitudeDetermination()
    none = ((0, 0, 0), False, (0, 0, 0), False, R_LEO, (0, 1e11, 0))
    for _ in range(3):
        ad.step(none, (0.1, 0.0, 0.0), 0.5)
    state = json.loads(json.dumps(ad.get_state()))
    other = triad.AttitudeDetermination()
    other.set_state(state)
    assert other.estimate(*none) == ad.estimate(*none) and other.estimate(*none)[2] == 1.5


# ---- FMUs ----------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def ad_fmus(tmp_path_factory):
    """Our five FMUs and RigidBody, built into a tmp dir, and each extracted once (the
    extracted directories stay for the session)."""
    d = tmp_path_factory.mktemp("ad_fmus")
    paths = {name: build_fmus.build_fmu(REPO / "fmus" / f"{mod}.py", d) for name, mod in WRAPPERS.items()}
    paths["RigidBody"] = build_fmus.build_fmu(REPO / "fmus" / "neighbor_rigid_body.py", d)
    unzipped = {name: fmpy.extract(str(p), unzipdir=str(d / f"x_{name}")) for name, p in paths.items()}
    return paths, unzipped


def test_fmus_validate_and_declare_dependencies(ad_fmus):
    paths, _ = ad_fmus
    for name in WRAPPERS:
        assert validate_fmu(str(paths[name])) == [], name
        md = fmpy.read_model_description(str(paths[name]))
        assert md.coSimulation.canGetAndSetFMUstate
        deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
        if name == "Gyro":
            assert deps["omega_meas_B[1]"] == [f"omega_BN_B[{i}]" for i in (1, 2, 3)]
        if name == "HorizonSensor":
            expected = [f"r_BN_N[{i}]" for i in (1, 2, 3)] + [f"q_BN[{i}]" for i in range(1, 5)]
            assert deps["nadir_B[2]"] == sorted(expected)
        if name == "GpsReceiver":
            assert deps["gps_time"] == [] and deps["r_meas_N[3]"] == [f"r_BN_N[{i}]" for i in (1, 2, 3)]
        if name == "SunSensor":
            assert "sunlit" in deps["valid"] and "q_BN[4]" in deps["sun_B[1]"]
        if name == "AttitudeDetermination":
            assert deps["omega_est_B[1]"] == [f"omega_meas_B[{i}]" for i in (1, 2, 3)]
            assert "sun_valid" in deps["q_est_BN[4]"] and "omega_meas_B[1]" not in deps["q_est_BN[4]"]


def test_fmus_simulate_alone(ad_fmus):
    _, x = ad_fmus
    q = rotations.normalized((0.2, -0.1, 0.4, 0.8))
    qv = {f"q_BN[{i}]": v for i, v in enumerate(q, 1)}
    r = fmpy.simulate_fmu(x["HorizonSensor"], stop_time=1.0, output_interval=0.1, start_values={"sigma": 0.0, **qv})
    assert np.allclose([r[f"nadir_B[{i}]"][-1] for i in (1, 2, 3)], rot(q, (-1, 0, 0)), atol=1e-15)
    r = fmpy.simulate_fmu(x["Gyro"], stop_time=1.0, output_interval=0.1,
                          start_values={"bias[2]": 0.01, "sigma": 1e-3, "seed": 4, "omega_BN_B[1]": 0.1})
    assert len(set(r["omega_meas_B[1]"])) == len(r)  # a new draw each step
    assert np.all(np.abs(r["omega_meas_B[2]"] - 0.01) < 5e-3) and np.all(np.abs(r["omega_meas_B[1]"] - 0.1) < 5e-3)
    r = fmpy.simulate_fmu(x["GpsReceiver"], start_time=2.0, stop_time=3.0, output_interval=0.1)
    assert np.allclose(r["gps_time"], np.linspace(2.0, 3.0, 11), atol=1e-12)
    assert np.all(np.abs(r["r_meas_N[1]"] - R_LEO[0]) < 8.0) and r["valid"].all()
    r_sun = (0.0, 1.5e11, 0.0)
    sun_N = sensors.unit_vector(np.subtract(r_sun, R_LEO), "s")
    inputs = {**{f"nadir_B[{i}]": v for i, v in enumerate(rot(q, (-1, 0, 0)), 1)},
              **{f"sun_B[{i}]": v for i, v in enumerate(rot(q, sun_N), 1)},
              "nadir_valid": True, "sun_valid": True, **{f"r_SN_N[{i}]": v for i, v in enumerate(r_sun, 1)}}
    r = fmpy.simulate_fmu(x["AttitudeDetermination"], stop_time=0.5, output_interval=0.1, start_values=inputs)
    q_est = [r[f"q_est_BN[{i}]"][-1] for i in range(1, 5)]
    assert r["fix"].all() and triad.error_angle(q_est, q) < 1e-9 and r["time_since_fix"][-1] == 0.0
    r = fmpy.simulate_fmu(x["SunSensor"], stop_time=0.3, output_interval=0.1,
                          start_values={**qv, **{f"r_SN_N[{i}]": v for i, v in enumerate(r_sun, 1)},
                                        **{f"boresight_B[{i}]": v for i, v in enumerate(rot(q, sun_N), 1)},
                                        "sigma": 0.0})
    assert r["valid"].all() and np.allclose([r[f"sun_B[{i}]"][-1] for i in (1, 2, 3)], rot(q, sun_N), atol=1e-15)
    # faults: the Sun sensor dead from 0.2 s on, the gyro's bias jumping at 0.5 s
    r = fmpy.simulate_fmu(x["SunSensor"], stop_time=0.4, output_interval=0.1,
                          start_values={**qv, **{f"r_SN_N[{i}]": v for i, v in enumerate(r_sun, 1)},
                                        **{f"boresight_B[{i}]": v for i, v in enumerate(rot(q, sun_N), 1)},
                                        "failed": True, "fail_time": 0.2})
    assert list(r["valid"]) == [True, True, False, False, False] and r["sun_B[1]"][-1] == 0.0
    r = fmpy.simulate_fmu(x["Gyro"], stop_time=1.0, output_interval=0.1,
                          start_values={"sigma": 0.0, "bias_jump[3]": 0.002, "jump_time": 0.5})
    assert list(r["omega_meas_B[3]"]) == [0.0] * 5 + [0.002] * 6


def test_fmu_seed_reproducibility(ad_fmus):
    _, x = ad_fmus

    def run(seed):
        r = fmpy.simulate_fmu(x["HorizonSensor"], stop_time=1.0, output_interval=0.1, start_values={"seed": seed})
        return r["nadir_B[2]"].tolist() + r["nadir_B[3]"].tolist()

    assert run(3) == run(3) and run(3) != run(4)


def _instance(path, md, name):
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=path, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=name)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


@pytest.mark.parametrize("name, inputs, outputs", [
    ("Gyro", {"omega_BN_B[1]": 0.1}, [f"omega_meas_B[{i}]" for i in (1, 2, 3)]),
    ("SunSensor", {"boresight_B[1]": 0.0, "boresight_B[2]": -1.0}, [f"sun_B[{i}]" for i in (1, 2, 3)]),
    ("GpsReceiver", {}, ["r_meas_N[1]", "r_meas_N[2]", "gps_time"]),
    ("AttitudeDetermination", {"omega_meas_B[2]": 0.05}, ["q_est_BN[1]", "q_est_BN[2]", "time_since_fix"]),
])
def test_fmu_get_set_state_restores_the_generator(ad_fmus, name, inputs, outputs):
    paths, x = ad_fmus
    md = fmpy.read_model_description(str(paths[name]))
    fmu, vr = _instance(x[name], md, name)
    try:
        bools = {k: v for k, v in inputs.items() if isinstance(v, bool)}
        reals = {k: v for k, v in inputs.items() if k not in bools}
        if reals:
            fmu.setReal([vr[k] for k in reals], list(reals.values()))
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        t = 0.0

        def advance(n):
            nonlocal t
            out = []
            for _ in range(n):
                fmu.doStep(t, 0.1)
                t += 0.1
                out.append(fmu.getReal([vr[o] for o in outputs]))
            return out

        advance(5)
        state, t_saved = fmu.getFMUstate(), t
        try:
            first = advance(10)
            advance(7)
            fmu.setFMUstate(state)
            t = t_saved
            second = advance(10)
        finally:
            fmu.freeFMUstate(state)
        assert first == second
        assert len({tuple(o) for o in first}) == 10  # the outputs do change from step to step
    finally:
        fmu.terminate()
        fmu.freeInstance()


# ---- the system through the master --------------------------------------------------------
@pytest.fixture(scope="session")
def ad_ssp(ad_fmus, tmp_path_factory):
    paths, _ = ad_fmus
    return build_fmus.pack_ssp(SSD, paths["RigidBody"].parent, tmp_path_factory.mktemp("ad_ssp"))


Q = [f"dynamics.q_BN[{i}]" for i in range(1, 5)]
QE = [f"ad.q_est_BN[{i}]" for i in range(1, 5)]
REC = Q + QE + ["ad.fix", "ad.time_since_fix", "sun_sensor.valid", "horizon.valid"]


def _ssv_values(name):
    from lxml import etree  # noqa: PLC0415
    root = etree.parse(str(SSD.parent / "parameters" / f"{name}.ssv")).getroot()
    ns = {"ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues"}
    return {p.get("name"): float(p[0].get("value")) for p in root.iterfind(".//ssv:Parameter", ns)
            if p[0].tag.endswith("Real")}


def _errors(r):
    d = r.data
    return np.array([triad.error_angle([d[e][k] for e in QE], [d[q][k] for q in Q]) for k in range(len(d))])


def test_system_noise_free_recovers_the_attitude(ad_ssp):
    r = system_ssp.simulate(ad_ssp, parameter_sets=["parameters/attitude_determination_noise_free.ssv"],
                            outputs=REC)
    d, err = r.data, _errors(r)
    fix = d["ad.fix"].astype(bool)
    assert d["time"][-1] == pytest.approx(60.0)
    assert fix[0] and fix.sum() > 200  # the Sun is in view for the first ~34 s
    assert err[fix].max() < 1e-9
    # then it leaves the field of view: propagation with the (exact) gyro, zero-order hold
    assert not d["sun_sensor.valid"][-1] and not fix[-1] and d["horizon.valid"].all()
    assert d["ad.time_since_fix"][-1] == pytest.approx(60.0 - d["time"][fix][-1], abs=1e-9)
    assert 0.0 < err[~fix].max() < 1e-3


def test_system_noisy_fix_errors_match_the_sensor_accuracies(ad_ssp):
    """Criterion: the RMS error over the ~340 fixes is within 25 % of the first-order TRIAD
    prediction for each step's geometry (Sun first: 0.167 deg; nadir 0.25 deg); sampling
    error about 4 %."""
    r = system_ssp.simulate(ad_ssp, outputs=REC)
    d, err = r.data, _errors(r)
    fix = d["ad.fix"].astype(bool)
    ssv = _ssv_values("attitude_determination_ad") | _ssv_values("attitude_determination_gps")
    r_sc = [ssv[f"r_BN_N[{i}]"] for i in (1, 2, 3)]
    sun_N = sensors.unit_vector(np.subtract([ssv[f"r_SN_N[{i}]"] for i in (1, 2, 3)], r_sc), "sun")
    theta = math.acos(rotations.dot(sun_N, sensors.unit_vector([-x for x in r_sc], "nadir")))
    # fixed positions: the angle between the two vectors, and so the prediction, is constant
    predicted = [triad.triad_error_rms(ssv["sun_sigma"], ssv["nadir_sigma"], theta)]
    assert ssv["sun_sigma"] < ssv["nadir_sigma"]
    rms, pred = math.sqrt(np.mean(err[fix] ** 2)), math.sqrt(np.mean(np.square(predicted)))
    assert 0.75 < rms / pred < 1.25, (rms, pred)
    # reproducible through the master; other seeds give other estimates (first 3 s)
    again = system_ssp.simulate(ad_ssp, outputs=REC, stop_time=3.0)
    assert np.array_equal(again.data, d[:len(again.data)])
    other = system_ssp.simulate(ad_ssp, outputs=REC, stop_time=3.0, parameters={"horizon.seed": 78})
    assert not np.array_equal(other.data["ad.q_est_BN[1]"], again.data["ad.q_est_BN[1]"])
    assert np.array_equal(other.data["dynamics.q_BN[1]"], again.data["dynamics.q_BN[1]"])


def test_system_eclipse_degrades_to_gyro_propagation(ad_ssp):
    r = system_ssp.simulate(ad_ssp, parameter_sets=["parameters/attitude_determination_eclipse.ssv"], outputs=REC)
    d, err = r.data, _errors(r)
    assert not d["ad.fix"].any() and not d["sun_sensor.valid"].any()
    assert d["ad.time_since_fix"][-1] == pytest.approx(60.0)
    b = math.sqrt(3) * 1e-3
    assert err[0] < 1e-12
    for k in range(100, len(d), 100):
        t = d["time"][k]
        assert 0.7 * b * t < err[k] < b * t + 5 * 5.5e-4 * math.sqrt(0.1 * t) + 1e-3, (t, err[k])
