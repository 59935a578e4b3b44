"""Tilted-dipole geomagnetic field, magnetic torque coils, momentum wheel and the rigid body's
wheel terms: the components against closed forms and published values, each FMU through FMPy
(validation, standalone simulation, state get/set), and wheel + body co-simulated through FMPy."""
import math

import fmpy
import numpy as np
import pytest

from components.acs import magnetorquer, momentum_wheel
from components.attitude.rigid_body import RigidBody, box_inertia
from components.core import rotations, time_utils
from components.environment import magnetic_field as mf
from fmu_helpers import check_declarations, instantiate
from paths import REPO

WRAPPERS = {"MagneticField": "neighbor_magnetic_field.py", "TorqueCoils": "neighbor_torque_coils.py",
            "MomentumWheel": "neighbor_momentum_wheel.py", "RigidBody": "neighbor_rigid_body.py"}
DEG = math.pi / 180.0
B0_NT = math.sqrt(mf.G10 ** 2 + mf.G11 ** 2 + mf.H11 ** 2)
G_VEC = np.array([mf.G11, mf.H11, mf.G10])  # n = 1 Gauss coefficients as an ECEF vector (nT)


def ecef(r, lat_deg, lon_deg):
    la, lo = lat_deg * DEG, lon_deg * DEG
    return np.array([r * math.cos(la) * math.cos(lo), r * math.cos(la) * math.sin(lo), r * math.sin(la)])


def r3(angle):
    """Rotation matrix R3(angle): components in a frame rotated by `angle` about z."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


# ---- geomagnetic field ------------------------------------------------------------------------
def test_gmst_iau1982_published_values():
    # Vallado, Fundamentals of Astrodynamics and Applications, Example 3-5: 1992 Aug 20,
    # 12:14 UT1 -> GMST = 152.578787886 deg (UTC taken for UT1 here, as the product does;
    # 1e-6 deg = 0.004 arcsec: the seconds-of-day term is 2e8 s, so doubles carry ~1e-7 deg).
    T = time_utils.julian_centuries("1992-08-20T12:14:00Z")
    assert math.degrees(mf.gmst(T)) == pytest.approx(152.578787886, abs=1e-6)
    # At J2000.0 (2000-01-01 12:00 UT1) GMST = 18h 41m 50.54841s = 280.46061837 deg.
    assert math.degrees(mf.gmst(0.0)) == pytest.approx(280.46061837, abs=1e-6)
    # The model's clock: epoch + simulation time gives the same sidereal angle.
    f = mf.MagneticField("1992-08-20T12:00:00Z")
    assert math.degrees(f.gmst(840.0)) == pytest.approx(152.578787886, abs=1e-6)


def test_dipole_axis_tilt_and_pole_from_the_coefficients():
    assert B0_NT == pytest.approx(29805.924, abs=1e-3)
    # Tilt acos(-g10 / B0); the brief's "about 9.7 deg" does not follow from the 2020.0 numbers.
    assert mf.tilt_deg() == pytest.approx(9.4105, abs=1e-4)
    lat, lon = mf.boreal_pole_deg()
    # Centred-dipole north geomagnetic pole 2020: 80.59 deg N (WHOI centred-dipole pole table),
    # longitude -72.68 deg (atan2(-h11, -g11)).
    assert lat == pytest.approx(80.59, abs=0.005)
    assert lon == pytest.approx(-72.68, abs=0.005)
    # The field at the boreal pole's surface point is vertical, downward, 2 B0.
    pole = ecef(mf.R_REF, lat, lon)
    b = np.array(mf.MagneticField().field_ecef(pole))
    up = pole / np.linalg.norm(pole)
    np.testing.assert_allclose(b, -2.0 * B0_NT * 1e-9 * up, rtol=0, atol=1e-9 * 2 * B0_NT * 1e-12)


def test_field_magnitude_and_direction_on_the_surface():
    f = mf.MagneticField()
    for lon in range(0, 360, 15):
        r = ecef(mf.R_REF, 0.0, lon)
        b = np.array(f.field_ecef(r))
        assert 2.9e-5 < np.linalg.norm(b) < 3.2e-5, lon  # about B0 = 2.98e-5 T on the equator
        assert b[2] > 0.94 * np.linalg.norm(b), lon  # points (mostly) north
    for lat, lon in ((80.59, -72.68), (-80.59, 107.32)):  # the two geomagnetic poles
        assert np.linalg.norm(f.field_ecef(ecef(mf.R_REF, lat, lon))) == pytest.approx(5.9612e-5, rel=1e-4)
    for lon in range(0, 360, 30):
        for lat in (60.0, 75.0, 90.0):
            r = ecef(mf.R_REF, lat, lon)
            b = np.array(f.field_ecef(r))
            assert b @ r < -0.8 * np.linalg.norm(b) * np.linalg.norm(r), (lat, lon)  # down into the Earth
            b = np.array(f.field_ecef(ecef(mf.R_REF, -lat, lon)))
            assert b @ ecef(mf.R_REF, -lat, lon) > 0, (lat, lon)  # up out of the Earth in the south
    # inverse-cube fall-off
    r = ecef(mf.R_REF, 30.0, 40.0)
    np.testing.assert_allclose(np.array(f.field_ecef(2 * r)) * 8, f.field_ecef(r), rtol=1e-14)


def test_cartesian_dipole_matches_the_spherical_gauss_potential_gradient():
    # Published form: X, Y, Z (north, east, down) from the n = 1 IGRF potential.
    # On the equator at 0 deg longitude: X = -g10, Y = -h11, Z = -2 g11 (nT).
    x, y, z = mf.dipole_field_spherical(mf.G10, mf.G11, mf.H11, mf.R_REF, 90 * DEG, 0.0)
    assert (x, y, z) == pytest.approx((29404.8, -4652.5, 2901.8), abs=1e-9)
    f = mf.MagneticField()
    rng = np.random.default_rng(7)
    for _ in range(40):
        r = mf.R_REF + rng.uniform(0.0, 3.0e7)
        colat, lon = math.acos(rng.uniform(-1, 1)), rng.uniform(-math.pi, math.pi)
        X, Y, Z = mf.dipole_field_spherical(mf.G10, mf.G11, mf.H11, r, colat, lon)
        st, ct, sp, cp = math.sin(colat), math.cos(colat), math.sin(lon), math.cos(lon)
        up = np.array([st * cp, st * sp, ct])
        north = np.array([-ct * cp, -ct * sp, st])
        east = np.array([-sp, cp, 0.0])
        expected = (X * north + Y * east - Z * up) * 1e-9
        got = np.array(f.field_ecef(r * up))
        assert np.linalg.norm(got - expected) <= 1e-9 * np.linalg.norm(expected)


def _div_curl(field, r, d):
    J = np.zeros((3, 3))  # J[i, j] = dB_i / dx_j
    for j in range(3):
        e = np.zeros(3)
        e[j] = d
        J[:, j] = (np.array(field(r + e)) - np.array(field(r - e))) / (2 * d)
    return np.trace(J), np.array([J[2, 1] - J[1, 2], J[0, 2] - J[2, 0], J[1, 0] - J[0, 1]])


def test_dipole_field_is_divergence_and_curl_free():
    def field(r):
        return mf.dipole_field(tuple(G_VEC), r)

    def wrong(r):  # a sign slip in the formula: 3 (g.r)r + g is neither
        b = mf.dipole_field(tuple(G_VEC), r)
        k = (mf.R_REF / np.linalg.norm(r)) ** 3
        return np.array(b) + 2 * k * G_VEC

    rng = np.random.default_rng(3)
    for _ in range(20):
        r = rng.normal(size=3)
        r *= rng.uniform(6.6e6, 4.2e7) / np.linalg.norm(r)
        scale = np.linalg.norm(field(r)) / np.linalg.norm(r)
        div, curl = _div_curl(field, r, 1.0e3)
        assert abs(div) < 1e-6 * scale and np.linalg.norm(curl) < 1e-6 * scale
        div_w, curl_w = _div_curl(wrong, r, 1.0e3)
        assert abs(div_w) > 1e-2 * scale or np.linalg.norm(curl_w) > 1e-2 * scale


def test_field_in_N_follows_the_earth_rotation_and_attitude():
    f = mf.MagneticField("2023-03-20T00:00:00Z", t0=100.0)
    r_N = (7.0e6, 0.0, 0.0)
    # N -> ECEF by R3(GMST): the field at r_N is the Earth-fixed field at R3(GMST) r_N, rotated back.
    th = f.gmst()
    expected = r3(th).T @ np.array(f.field_ecef(r3(th) @ np.array(r_N)))
    np.testing.assert_allclose(f.field_N(r_N), expected, rtol=1e-14, atol=1e-20)
    # Right ascension = GMST + east longitude: over the boreal geomagnetic pole the field in N is
    # vertical, downward, 2 B0 (a sign slip in the N <-> ECEF rotation breaks this).
    lat, lon = mf.boreal_pole_deg()
    for t in (0.0, 5000.0, 40000.0):
        ra = f.gmst(t) / DEG + lon
        p = ecef(mf.R_REF, lat, ra)
        np.testing.assert_allclose(f.field_N(p, t), -2 * B0_NT * 1e-9 * p / mf.R_REF, rtol=0, atol=1e-15)
    # One sidereal day later (86164.0905 s) the same inertial point sees the same field;
    # six hours later it does not.
    b0 = np.array(f.field_N(r_N))
    np.testing.assert_allclose(f.field_N(r_N, 100.0 + 86164.0905), b0, rtol=2e-6)
    assert np.linalg.norm(np.array(f.field_N(r_N, 100.0 + 21600.0)) - b0) > 0.1 * np.linalg.norm(b0)
    # North in N is north in ECEF (R3 keeps z): over the equator the field points to +z in N.
    for t in np.linspace(0, 86400, 13):
        b = f.field_N((0.0, -7.0e6, 0.0), t)
        assert b[2] > 0.9 * math.sqrt(b[0] ** 2 + b[1] ** 2 + b[2] ** 2)
    # B_B = A(q) B_N: a 90 deg turn of B about z gives [By, -Bx, Bz].
    q = rotations.from_axis_angle((0, 0, 1), math.pi / 2)
    bB = f.field_B(r_N, q)
    bN = f.field_N(r_N)
    np.testing.assert_allclose(bB, [bN[1], -bN[0], bN[2]], rtol=0, atol=1e-18)
    # the model keeps time
    f.advance_to(3600.0)
    assert f.get_state() == {"t": 3600.0}
    np.testing.assert_allclose(f.field_N(r_N), f.field_N(r_N, 3600.0), rtol=0)


def test_secular_variation_switch_and_bad_values():
    f = mf.MagneticField("2023-01-01T00:00:00Z", secular_variation=True)
    years = 1096.0 / 365.25  # 2020-01-01 to 2023-01-01 (2020 is a leap year)
    assert f.decimal_year() == pytest.approx(2020.0 + years, abs=1e-12)
    np.testing.assert_allclose(f.coefficients(), (mf.G10 + 5.7 * years, mf.G11 + 7.4 * years,
                                                  mf.H11 - 25.9 * years), rtol=1e-12)
    assert mf.MagneticField("2023-01-01T00:00:00Z").coefficients() == (-29404.8, -1450.9, 4652.5)
    r = (6.9e6, 1.0e6, 2.0e6)
    b_sv, b_2020 = np.array(f.field_N(r)), np.array(mf.MagneticField().field_N(r))
    assert 1e-4 < np.linalg.norm(b_sv - b_2020) / np.linalg.norm(b_2020) < 5e-3
    with pytest.raises(ValueError, match="epoch"):
        mf.MagneticField("2023-01-01")
    with pytest.raises(ValueError, match="r_BN_N"):
        mf.MagneticField().field_N((0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="r_BN_N"):
        mf.MagneticField().field_N((math.nan, 7e6, 0.0))
    with pytest.raises(ValueError, match="q_BN"):
        mf.MagneticField().field_B(r, (0, 0, 0, 0))


# ---- torque coils ----------------------------------------------------------------------------
def test_torque_coils_saturation_torque_and_disable():
    c = magnetorquer.TorqueCoils((0.2, 0.1, 0.3))
    assert c.dipole((0.5, -0.5, 0.25)) == (0.2, -0.1, 0.25)
    assert c.dipole((-0.05, 0.05, -1.0)) == (-0.05, 0.05, -0.3)
    B = (2.0e-5, -1.0e-5, 3.5e-5)
    m, tau = c.torque((0.15, 0.4, -0.2), B)
    assert m == (0.15, 0.1, -0.2)
    np.testing.assert_allclose(tau, np.cross(m, B), rtol=1e-15)
    # tau = m x B: a dipole along x in a field along y gives a torque along +z
    assert c.torque((0.1, 0, 0), (0, 1e-5, 0))[1] == pytest.approx((0.0, 0.0, 1e-6))
    assert c.torque((0.15, 0.4, -0.2), B, enabled=False) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    for bad in ((0.2, -0.1, 0.2), (0.2, math.inf, 0.2)):
        with pytest.raises(ValueError, match="max_dipole"):
            magnetorquer.TorqueCoils(bad)
    with pytest.raises(ValueError, match="dipole_cmd_B"):
        c.dipole((math.nan, 0, 0))


# ---- momentum wheel --------------------------------------------------------------------------
def test_wheel_integrates_the_saturated_torque_and_respects_the_speed_limit():
    w = momentum_wheel.MomentumWheel()  # Y axis, 2e-5 kg.m2, 1 mN.m, 6000 rpm
    assert w.max_speed == pytest.approx(628.3185307, abs=1e-6)
    for _ in range(10):
        w.step(5e-4, True, 0.1)
    assert w.rate == pytest.approx(5e-4 / 2e-5 * 1.0, rel=1e-12)  # 25 rad/s after 1 s
    assert w.momentum_B() == pytest.approx((0.0, 2e-5 * 25.0, 0.0), rel=1e-12)
    assert w.torque_B(5.0) == (0.0, 1e-3, 0.0)  # saturated
    assert w.torque_B(-5.0) == (0.0, -1e-3, 0.0)
    assert w.torque_B(5.0, enabled=False) == (0.0, 0.0, 0.0)
    w.step(1.0, False, 1.0)
    assert w.rate == pytest.approx(25.0, rel=1e-12)  # disabled: coasts
    state = w.get_state()
    for _ in range(20):  # 1 mN.m for 20 s would reach 1025 rad/s: stops at 628.3
        w.step(1.0, True, 1.0)
    assert w.rate == w.max_speed
    assert w.torque_B(1.0) == (0.0, 0.0, 0.0) and w.applied_torque(-1.0) == -1e-3  # only slowing down
    w.step(-1.0, True, 1.0)
    assert w.rate == pytest.approx(w.max_speed - 50.0, rel=1e-12)
    w.set_state(state)
    assert w.rate == 25.0
    skew = momentum_wheel.MomentumWheel(axis=(1.0, 1.0, 0.0), omega0=-100.0)
    assert skew.momentum_B() == pytest.approx((-2e-3 / math.sqrt(2), -2e-3 / math.sqrt(2), 0.0), rel=1e-12)
    for kwargs, name in (({"axis": (0, 0, 0)}, "axis_B"), ({"inertia": 0.0}, "J_w"),
                         ({"max_torque": -1e-3}, "max_torque"), ({"max_speed": math.nan}, "max_speed"),
                         ({"omega0": 1000.0}, "Omega0")):
        with pytest.raises(ValueError, match=name):
            momentum_wheel.MomentumWheel(**kwargs)


# ---- rigid body with wheels ---------------------------------------------------------------------
def inertial_momentum(body, h_w):
    A = np.array(rotations.attitude_matrix(body.q))
    return A.T @ np.array(body.total_angular_momentum(h_w))


def test_zero_wheel_inputs_are_bit_identical_to_the_wheelless_body():
    J = box_inertia(12.0, 0.1, 0.2, 0.3)
    for integrator in ("euler", "rk4"):
        a = RigidBody(J, rotations.normalized((0.1, -0.2, 0.3, 0.9)), (0.2, -0.1, 0.05), integrator)
        b = RigidBody(J, rotations.normalized((0.1, -0.2, 0.3, 0.9)), (0.2, -0.1, 0.05), integrator)
        for k in range(200):
            torque = (0.0025 * (k % 3 - 1), -0.0025 * (k % 2), 0.0)
            a.step(torque, 0.015)
            b.step(torque, 0.015, (0.0, 0.0, 0.0), (0.0, -0.0, 0.0))
        assert a.get_state() == b.get_state()


def test_spinning_wheel_conserves_total_momentum():
    J = box_inertia(12.0, 0.1, 0.2, 0.3)
    body = RigidBody(J, rotations.normalized((0.3, 0.1, -0.2, 0.9)), (0.05, 0.1, -0.03), "rk4")
    h_w = (0.0, 0.008, 0.0)  # a wheel spinning at 400 rad/s, no motor torque, no external torque
    H0 = inertial_momentum(body, h_w)
    for _ in range(600):
        body.step((0.0, 0.0, 0.0), 0.1, (0.0, 0.0, 0.0), h_w)
    H1 = inertial_momentum(body, h_w)
    assert np.linalg.norm(H1 - H0) < 1e-10 * np.linalg.norm(H0)
    # the gyroscopic term matters: without it the body would move differently
    free = RigidBody(J, rotations.normalized((0.3, 0.1, -0.2, 0.9)), (0.05, 0.1, -0.03), "rk4")
    for _ in range(600):
        free.step((0.0, 0.0, 0.0), 0.1)
    assert np.linalg.norm(np.subtract(free.omega, body.omega)) > 1e-3


def test_wheel_spin_up_transfers_body_momentum_to_the_wheel():
    """Seed mode 4: spin the wheel up to take the body's Y momentum; total momentum constant."""
    J = box_inertia(12.0, 0.1, 0.2, 0.3)
    w0 = (0.002, 5.0 * DEG, -0.001)  # 5 deg/s about Y with a little nutation
    body = RigidBody(J, (0.0, 0.0, 0.0, 1.0), w0, "rk4")
    wheel = momentum_wheel.MomentumWheel()
    H0 = inertial_momentum(body, wheel.momentum_B())
    for _ in range(100):  # 10 s at 1 mN.m: 0.01 N.m.s into the wheel
        body.step((0.0, 0.0, 0.0), 0.1, wheel.torque_B(1e-3), wheel.momentum_B())
        wheel.step(1e-3, True, 0.1)
    H1 = inertial_momentum(body, wheel.momentum_B())
    assert np.linalg.norm(H1 - H0) < 1e-10 * np.linalg.norm(H0)
    assert wheel.rate == pytest.approx(500.0, rel=1e-12)
    # the body's Y rate dropped by about h_w / Iy (0.01 / 0.13 rad/s): most of its spin went
    # into the wheel
    assert body.omega[1] == pytest.approx(w0[1] - 0.01 / J[1, 1], abs=2e-3)
    assert abs(body.omega[1]) < 0.2 * w0[1]


def test_wheel_terms_with_the_euler_integrator():
    J = box_inertia(12.0, 0.1, 0.2, 0.3)
    body = RigidBody(J, (0.0, 0.0, 0.0, 1.0), (0.1, 0.2, 0.3), "euler")
    tw, hw = (0.0, 1e-3, 0.0), (0.0, 0.01, 0.0)
    body.step((1e-3, 0.0, 0.0), 0.5, tw, hw)
    w = np.array([0.1, 0.2, 0.3])
    expected = np.linalg.solve(J, np.array([1e-3, 0, 0]) - tw - np.cross(w, J @ w + hw))
    np.testing.assert_allclose(body.omega_dot, expected, rtol=1e-13)
    np.testing.assert_allclose(body.omega, w + 0.5 * expected, rtol=1e-13)
    with pytest.raises(ValueError, match="wheel_momentum_B"):
        body.step((0.0, 0.0, 0.0), 0.1, tw, (math.nan, 0.0, 0.0))


# ---- FMUs ------------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def ma_fmus(tmp_path_factory):
    import build_fmus

    dest = tmp_path_factory.mktemp("magnetic_actuator_fmus")
    return {name: build_fmus.build_fmu(REPO / "fmus" / script, dest) for name, script in WRAPPERS.items()}


def test_fmus_are_valid_with_units_descriptions_and_dependencies(ma_fmus):
    R = [f"r_BN_N[{i}]" for i in (1, 2, 3)]
    Q = [f"q_BN[{i}]" for i in (1, 2, 3, 4)]
    CMD = [f"dipole_cmd_B[{i}]" for i in (1, 2, 3)] + ["enabled"]
    BB = [f"B_B[{i}]" for i in (1, 2, 3)]
    for name, path in ma_fmus.items():
        deps = check_declarations(path)
        md = fmpy.read_model_description(str(path))
        if name == "MagneticField":
            assert all(deps[f"B_N[{i}]"] == sorted(R) for i in (1, 2, 3))
            assert all(deps[f"B_B[{i}]"] == sorted(R + Q) for i in (1, 2, 3))
            assert {v.name: v.unit for v in md.modelVariables if v.name.startswith("B_")}["B_B[2]"] == "T"
        elif name == "TorqueCoils":
            assert all(deps[f"dipole_B[{i}]"] == sorted(CMD) for i in (1, 2, 3))
            assert all(deps[f"torque_B[{i}]"] == sorted(CMD + BB) for i in (1, 2, 3))
        elif name == "MomentumWheel":
            assert deps["wheel_rate"] == [] and all(deps[f"wheel_momentum_B[{i}]"] == [] for i in (1, 2, 3))
            assert all(deps[f"wheel_torque_B[{i}]"] == ["enabled", "torque_cmd"] for i in (1, 2, 3))
        else:  # RigidBody: states only; the wheel inputs are appended after every other variable
            assert all(d == [] for d in deps.values())
            names = [v.name for v in md.modelVariables]
            vr = {v.name: v.valueReference for v in md.modelVariables}
            new = [f"wheel_torque_B[{i}]" for i in (1, 2, 3)] + [f"wheel_momentum_B[{i}]" for i in (1, 2, 3)]
            # then the thesis' Eq. 31 angles, appended after the wheel inputs
            later = ([f"euler_integrated[{i}]" for i in (1, 2, 3)] + ["euler0_from_q0"]
                     + [f"euler0[{i}]" for i in (1, 2, 3)])
            # then the mass properties that follow the tank (issue 28)
            tank = (["propellant_mass_properties", "propellant_used", "rcs_propellant"]
                    + [f"center_of_mass_B[{i}]" for i in (1, 2, 3)])
            # then the body's own inertia off the nominal one (issue 28's dispersions)
            dispersion = [f"inertia_error[{i}]" for i in (1, 2, 3)]
            # then the environment's torque (issue 56)
            last = [f"disturbance_torque_B[{i}]" for i in (1, 2, 3)]
            assert names[-25:-19] == new and names[-26] == "H_B[3]" and names[-19:-12] == later
            assert names[-12:-6] == tank and names[-6:-3] == dispersion and names[-3:] == last
            assert min(vr[n] for n in new) > max(vr[n] for n in names[:-25])
            assert min(vr[n] for n in later) > max(vr[n] for n in new)
            assert min(vr[n] for n in tank) > max(vr[n] for n in later)
            assert min(vr[n] for n in dispersion) > max(vr[n] for n in tank)
            assert min(vr[n] for n in last) > max(vr[n] for n in dispersion)
            assert names.index("torque_B[1]") < names.index("q_BN[1]")


def test_fmus_simulate_alone(ma_fmus):
    epoch = "2023-06-01T00:00:00Z"
    r_N = (4.0e6, -3.0e6, 4.5e6)
    q = rotations.normalized((0.2, -0.4, 0.1, 0.8))
    start = {"epoch": epoch, **{f"r_BN_N[{i + 1}]": r_N[i] for i in range(3)},
             **{f"q_BN[{i + 1}]": q[i] for i in range(4)}}
    res = fmpy.simulate_fmu(str(ma_fmus["MagneticField"]), start_time=60.0, stop_time=3660.0, output_interval=600.0,
                            start_values=start)
    model = mf.MagneticField(epoch)
    assert res["time"][0] == 60.0 and res["time"][-1] == pytest.approx(3660.0)
    for row in res:
        np.testing.assert_allclose([row[f"B_N[{i}]"] for i in (1, 2, 3)], model.field_N(r_N, row["time"]),
                                   rtol=1e-12, atol=1e-20)
        np.testing.assert_allclose([row[f"B_B[{i}]"] for i in (1, 2, 3)], model.field_B(r_N, q, row["time"]),
                                   rtol=1e-12, atol=1e-20)
    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(ma_fmus["MagneticField"]), stop_time=1.0, start_values={"r_BN_N[1]": 0.0})

    res = fmpy.simulate_fmu(str(ma_fmus["TorqueCoils"]), stop_time=1.0, output_interval=0.5,
                            start_values={"dipole_cmd_B[1]": 0.5, "dipole_cmd_B[3]": -0.1, "B_B[2]": 3e-5})
    assert res["dipole_B[1]"][-1] == 0.2 and res["dipole_B[3]"][-1] == -0.1
    assert res["torque_B[1]"][-1] == pytest.approx(0.1 * 3e-5) and res["torque_B[3]"][-1] == pytest.approx(0.2 * 3e-5)
    res = fmpy.simulate_fmu(str(ma_fmus["TorqueCoils"]), stop_time=1.0, output_interval=0.5,
                            start_values={"dipole_cmd_B[1]": 0.5, "B_B[2]": 3e-5, "enabled": False})
    assert res["dipole_B[1]"][-1] == 0.0 and res["torque_B[3]"][-1] == 0.0

    res = fmpy.simulate_fmu(str(ma_fmus["MomentumWheel"]), stop_time=2.0, output_interval=0.1,
                            start_values={"torque_cmd": 5e-4, "Omega0": 10.0})
    assert res["wheel_rate"][-1] == pytest.approx(10.0 + 25.0 * 2.0, rel=1e-12)
    assert res["wheel_momentum_B[2]"][-1] == pytest.approx(2e-5 * 60.0, rel=1e-12)
    assert res["wheel_torque_B[2]"][-1] == 5e-4 and res["wheel_momentum_B[1]"][-1] == 0.0


def _instance(path, tmp_path, name):
    return instantiate(path, tmp_path, name)


def test_wheel_and_body_fmus_cosimulate_and_restore_state(ma_fmus, tmp_path):
    """Wheel -> body through FMPy (Jacobi-style exchange at the communication points): the total
    momentum is conserved; getFMUstate/setFMUstate on wheel, body and field reproduce a run."""
    body, bv = _instance(ma_fmus["RigidBody"], tmp_path, "body")
    wheel, wv = _instance(ma_fmus["MomentumWheel"], tmp_path, "wheel")
    field, fv = _instance(ma_fmus["MagneticField"], tmp_path, "field")
    try:
        body.setReal([bv["omega0[1]"], bv["omega0[2]"], bv["omega0[3]"]], [0.002, 5.0 * DEG, -0.001])
        field.setReal([fv["r_BN_N[1]"], fv["r_BN_N[3]"]], [5.0e6, 5.0e6])
        for f in (body, wheel, field):
            f.enterInitializationMode()
            f.exitInitializationMode()
        h_out = [wv[f"wheel_momentum_B[{i}]"] for i in (1, 2, 3)]
        t_out = [wv[f"wheel_torque_B[{i}]"] for i in (1, 2, 3)]
        h_in = [bv[f"wheel_momentum_B[{i}]"] for i in (1, 2, 3)]
        t_in = [bv[f"wheel_torque_B[{i}]"] for i in (1, 2, 3)]
        q_out = [bv[f"q_BN[{i}]"] for i in (1, 2, 3, 4)]
        H_out = [bv[f"H_B[{i}]"] for i in (1, 2, 3)]
        t = 0.0

        def total():
            A = np.array(rotations.attitude_matrix(body.getReal(q_out)))
            return A.T @ (np.array(body.getReal(H_out)) + wheel.getReal(h_out))

        def advance(n, cmd):
            nonlocal t
            for _ in range(n):
                wheel.setReal([wv["torque_cmd"]], [cmd])
                body.setReal(h_in + t_in, wheel.getReal(h_out) + wheel.getReal(t_out))
                field.setReal([fv[f"q_BN[{i}]"] for i in (1, 2, 3, 4)], body.getReal(q_out))
                for f in (body, wheel, field):
                    f.doStep(t, 0.1)
                t += 0.1
            return body.getReal(q_out + H_out) + wheel.getReal(h_out + [wv["wheel_rate"]]) + \
                field.getReal([fv[f"B_B[{i}]"] for i in (1, 2, 3)])

        H0 = total()
        advance(20, 1e-3)
        saved = [f.getFMUstate() for f in (body, wheel, field)]
        t_saved = t
        first = advance(30, 1e-3)
        H1 = total()
        assert np.linalg.norm(H1 - H0) < 1e-10 * np.linalg.norm(H0)
        assert first[-4] == pytest.approx(250.0, rel=1e-12)  # wheel rate after 5 s at 1 mN.m
        advance(7, -1e-3)  # wander off
        for f, s in zip((body, wheel, field), saved):
            f.setFMUstate(s)
        t = t_saved
        assert advance(30, 1e-3) == first
        for f, s in zip((body, wheel, field), saved):
            f.freeFMUstate(s)
    finally:
        for f in (body, wheel, field):
            f.terminate()
            f.freeInstance()
