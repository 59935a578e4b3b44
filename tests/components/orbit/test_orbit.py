"""Cowell orbit propagator: Keplerian elements, EGM96 zonal gravity, CowellOrbit against analytic
two-body motion, J2 node regression, drag and thrust, re-entry, state and errors; the Orbit FMU
through FMPy."""
import math

import numpy as np
import pytest

from components.core import constants, jit, rotations
from components.environment import atmosphere, geodesy, gravity, space_weather
from components.orbit import averaged, cowell
from components.orbit import elements as oe
from fmu_helpers import check_declarations, instantiate

R = oe.R_EQ
MU = oe.MU_EARTH
DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def exponential():
    return atmosphere.make_density_model("exponential")


def run(model, duration, h=300.0):
    """Advance by `duration` in communication steps of h."""
    start = model.t
    for k in range(1, int(round(duration / h)) + 1):
        model.advance_to(start + k * h)
    return model


# ---- elements ---------------------------------------------------------------------------------
def test_elements_round_trip_including_circular_and_equatorial():
    rng = np.random.default_rng(7)
    for _ in range(400):
        a = rng.uniform(6.6e6, 4.2e7)
        e = [0.0, 1e-9, rng.uniform(0.0, 0.9)][rng.integers(3)]
        i = [0.0, math.pi, 1e-6, rng.uniform(0.0, math.pi)][rng.integers(4)]
        el = (a, e, i, rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi))
        r, v = oe.kepler_to_cartesian(*el)
        back = oe.cartesian_to_kepler(r, v)
        assert all(math.isfinite(x) for x in back)
        r2, v2 = oe.kepler_to_cartesian(*back)
        assert np.linalg.norm(r2 - r) < 1e-8 * a and np.linalg.norm(v2 - v) < 1e-8 * np.linalg.norm(v)
        assert back[0] == pytest.approx(a, rel=1e-12) and back[1] == pytest.approx(e, abs=1e-11)
        assert back[2] == pytest.approx(i, abs=1e-12)
    # Table 3 orbit: circular, argument of latitude 0 -> on the x axis at the node
    r, v = oe.kepler_to_cartesian(R + 420e3, 0.0, 51.6 * DEG, 0.0, 0.0, 0.0)
    np.testing.assert_allclose(r, [R + 420e3, 0.0, 0.0], atol=1e-6)
    assert oe.cartesian_to_kepler(r, v)[2] == pytest.approx(51.6 * DEG, abs=1e-14)
    # circular: argp 0, nu = argument of latitude; equatorial: raan 0, argp = longitude of perigee
    a, e, i, raan, argp, nu = oe.cartesian_to_kepler(*oe.kepler_to_cartesian(7e6, 0.0, 0.3, 1.0, 0.7, 0.5))
    assert (argp, raan) == (0.0, pytest.approx(1.0)) and nu == pytest.approx(1.2)
    a, e, i, raan, argp, nu = oe.cartesian_to_kepler(*oe.kepler_to_cartesian(7e6, 0.1, 0.0, 0.0, 0.7, 0.5))
    assert raan == 0.0 and argp == pytest.approx(0.7) and nu == pytest.approx(0.5)


def test_kepler_equation_and_two_body_propagation():
    for e in (0.0, 0.1, 0.7, 0.95):
        for M in (-7.0, 0.0, 0.3, 3.1, 10.0):
            E = oe.solve_kepler(M, e)
            assert E - e * math.sin(E) == pytest.approx(M, abs=1e-13)
    # Vallado Example 2-1: M = 235.4 deg, e = 0.4 -> E = 220.512074767522 deg
    assert math.degrees(oe.solve_kepler(235.4 * DEG, 0.4)) == pytest.approx(220.512074767522, abs=1e-9)
    el = (7.2e6, 0.05, 0.9, 0.4, 1.1, 2.0)
    r, v = oe.kepler_to_cartesian(*el)
    n = oe.mean_motion(el[0])
    for dt in (-5000.0, 100.0, 86400.0):
        nu = oe.true_from_mean(oe.mean_from_true(el[5], el[1]) + n * dt, el[1])
        r_ref, v_ref = oe.kepler_to_cartesian(*el[:5], nu)
        r_p, v_p = oe.kepler_propagate(r, v, dt)
        assert np.linalg.norm(r_p - r_ref) < 1e-5 and np.linalg.norm(v_p - v_ref) < 1e-8
    rp, ra = oe.perigee_apogee_radii(r, v)
    assert rp == pytest.approx(7.2e6 * 0.95) and ra == pytest.approx(7.2e6 * 1.05)


def test_element_errors():
    with pytest.raises(ValueError, match="eccentricity"):
        oe.kepler_to_cartesian(7e6, 1.0, 0.1, 0, 0, 0)
    with pytest.raises(ValueError, match="semi-major axis"):
        oe.kepler_to_cartesian(-7e6, 0.1, 0.1, 0, 0, 0)
    with pytest.raises(ValueError, match="inclination"):
        oe.kepler_to_cartesian(7e6, 0.1, 4.0, 0, 0, 0)
    with pytest.raises(ValueError, match="closed orbit"):
        oe.cartesian_to_kepler([7e6, 0, 0], [0, 11e3, 0])  # escape speed
    with pytest.raises(ValueError, match="mu"):
        oe.mean_motion(7e6, mu=0.0)


# ---- gravity ----------------------------------------------------------------------------------
def test_zonal_gravity_is_the_gradient_of_the_potential():
    J = gravity.zonal_coefficients(6)
    assert J[2] == pytest.approx(1.0826266835531513e-3, rel=1e-12)
    assert J[3] == pytest.approx(-2.5326564853e-6, rel=1e-8)
    for r in ([5e6, 2e6, 4.3e6], [-1e6, 6.5e6, -2.5e6], [0.0, 0.0, 7e6]):
        r = np.array(r)
        a = gravity.acceleration(r)
        h = 1.0
        grad = [(gravity.potential_zonal(*(r + h * e), MU, R, J, 6)
                 - gravity.potential_zonal(*(r - h * e), MU, R, J, 6))
                / (2 * h) for e in np.eye(3)]
        np.testing.assert_allclose(a, grad, atol=5e-8)
    # J2 closed form
    r = np.array([5e6, 2e6, 4.3e6])
    x, y, z = r
    rm = np.linalg.norm(r)
    k = 1.5 * J[2] * MU * R ** 2 / rm ** 5
    a2 = -MU * r / rm ** 3 - k * np.array([x * (1 - 5 * z * z / rm ** 2), y * (1 - 5 * z * z / rm ** 2),
                                          z * (3 - 5 * z * z / rm ** 2)])
    np.testing.assert_allclose(gravity.acceleration(r, 2), a2, rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match="zonal_degree"):
        gravity.zonal_coefficients(7)


# ---- Cowell propagation -----------------------------------------------------------------------
@pytest.mark.parametrize("ecc, inc", [(0.0, 51.6 * DEG), (0.02, 98.0 * DEG), (0.0, 0.0)])
def test_two_body_matches_kepler_within_1_m_after_one_day(ecc, inc):
    m = cowell.CowellOrbit(sma0=R + 500e3, ecc0=ecc, inc0=inc, raan0=0.3, argp0=0.5, ta0=1.0,
                          zonal_degree=0, drag=False)
    r0, v0 = m.position(), m.velocity()
    run(m, 86400.0, 300.0)
    r_ref, v_ref = oe.kepler_propagate(r0, v0, 86400.0)
    assert np.linalg.norm(m.position() - r_ref) < 1.0
    assert np.linalg.norm(m.velocity() - v_ref) < 1e-3


def test_j2_node_regression_matches_secular_rate_within_1_percent():
    a0, i0 = R + 420e3, 51.6 * DEG
    m = cowell.CowellOrbit(sma0=a0, inc0=i0, zonal_degree=2, drag=False)
    t, raan = [], []
    for k in range(1, 10 * 144 + 1):  # 10 days, 600 s steps
        m.advance_to(600.0 * k)
        t.append(m.t)
        raan.append(oe.cartesian_to_kepler(m.position(), m.velocity())[3])
    raan = np.unwrap(raan)
    rate = np.polyfit(t, raan, 1)[0]
    expected = oe.j2_secular_rates(a0, 0.0, i0)[0]
    assert expected == pytest.approx(-5.0 * DEG / 86400, rel=0.05)  # the ISS orbit regresses ~5 deg/day
    assert rate == pytest.approx(expected, rel=0.01)


def test_drag_lowers_sma_by_the_eq_1_amount(exponential):
    """Difference in a after one day, with and without drag, against the integral of
    da/dt = -rho Cd A/m sqrt(mu a) (|v_rel|/|v|)^2-ish: evaluated with the model's own density
    output along the orbit, trapezoid rule over 300 s (2 %). Point-mass gravity: with J2 the
    osculating a of the two runs carries short-periodic terms of different phase."""
    kw = dict(sma0=R + 300e3, Cd=2.2, area=0.02, mass=12.0, reentry_altitude=100e3, zonal_degree=0)
    m = cowell.CowellOrbit(density_model=exponential, **kw)
    ref = cowell.CowellOrbit(drag=False, **kw)
    expected = 0.0
    for k in range(1, 289):
        o0 = m.outputs()
        v = np.array(o0["v_BN_N"])
        r = np.array(o0["r_BN_N"])
        v_rel = v - np.cross([0, 0, constants.OMEGA_EARTH_WGS84], r)
        # da/dt = 2 a^2 / mu (v . a_drag)
        drag = -0.5 * o0["density"] * 2.2 * 0.02 / 12.0 * np.linalg.norm(v_rel) * v_rel
        adot = 2 * o0["sma"] ** 2 / MU * (v @ drag)
        m.advance_to(300.0 * k)
        ref.advance_to(300.0 * k)
        o1 = m.outputs()
        v = np.array(o1["v_BN_N"])
        r = np.array(o1["r_BN_N"])
        v_rel = v - np.cross([0, 0, constants.OMEGA_EARTH_WGS84], r)
        drag1 = -0.5 * o1["density"] * 2.2 * 0.02 / 12.0 * np.linalg.norm(v_rel) * v_rel
        adot1 = 2 * o1["sma"] ** 2 / MU * (v @ drag1)
        expected += 0.5 * (adot + adot1) * 300.0
    da = m.outputs()["sma"] - ref.outputs()["sma"]
    assert expected < -100.0  # about -0.3 km/day at 300 km
    assert da == pytest.approx(expected, rel=0.02)


def test_retrograde_burn_lowers_a_by_the_rocket_equation_delta_v():
    """0.1 N, Isp 42 s (thesis Sec. 3.2), 600 s in 0.5 s steps with the mass falling as the
    propulsion FMU would feed it: the energy change matches -dv * mean speed with dv from Eq. 3."""
    F, isp, g0, m0 = 0.1, 42.0, 9.81, 12.0
    mdot = F / (isp * g0)
    m = cowell.CowellOrbit(zonal_degree=0, drag=False, mass=m0)
    r0, v0 = m.position(), m.velocity()
    e0 = 0.5 * v0 @ v0 - MU / np.linalg.norm(r0)
    h = 0.5
    for k in range(1200):
        mass_mid = m0 - mdot * (k + 0.5) * h  # held over the step: the mean mass of the step
        m.set_inputs(F_thrust_B=(F, 0.0, 0.0), retrograde=True, mass=mass_mid)
        m.advance_to((k + 1) * h)
    mf = m0 - mdot * 600.0
    dv = isp * g0 * math.log(m0 / mf)
    assert dv == pytest.approx(5.03, abs=0.01)
    r1, v1 = m.position(), m.velocity()
    e1 = 0.5 * v1 @ v1 - MU / np.linalg.norm(r1)
    vbar = 0.5 * (np.linalg.norm(v0) + np.linalg.norm(v1))
    assert e1 - e0 == pytest.approx(-dv * vbar, rel=2e-4)
    a1 = oe.osculating_sma(r1, v1)
    assert (R + 420e3) - a1 == pytest.approx(2 * dv * math.sqrt((R + 420e3) ** 3 / MU), rel=2e-3)  # ~8.9 km


def test_body_frame_thrust_rotated_with_the_attitude():
    m = cowell.CowellOrbit(zonal_degree=0, drag=False)
    r, v = m.position(), m.velocity()
    x_b = -v / np.linalg.norm(v)                  # body x along -v
    z_b = np.cross(r, v) / np.linalg.norm(np.cross(r, v))
    y_b = np.cross(z_b, x_b)
    q = rotations.dcm_to_quaternion([list(x_b), list(y_b), list(z_b)])
    m.set_inputs(F_thrust_B=(0.1, 0.0, 0.0), q_BN=q, mass=12.0)
    np.testing.assert_allclose(m.thrust_acceleration_N(), x_b * 0.1 / 12.0, atol=1e-15)
    m.set_inputs(F_thrust_B=(0.0, 0.0, 0.2))
    np.testing.assert_allclose(m.thrust_acceleration_N(), z_b * 0.2 / 12.0, atol=1e-15)
    # a 10 s body-x burn along -v does what the retrograde burn does, except that the retrograde
    # direction follows v, which turns at the mean motion n: they part by (F/m) n t^3 / 6 = 1.57 mm
    m.set_inputs(F_thrust_B=(0.1, 0.0, 0.0))
    retro = cowell.CowellOrbit(zonal_degree=0, drag=False)
    retro.set_inputs(F_thrust_B=(0.0, 0.1, 0.0), retrograde=True)
    m.advance_to(10.0)
    retro.advance_to(10.0)
    expected = 0.1 / 12.0 * oe.mean_motion(R + 420e3) * 10.0 ** 3 / 6.0
    assert np.linalg.norm(m.position() - retro.position()) == pytest.approx(expected, rel=0.02)
    # a normal (orbit-plane) burn changes the inclination, not a
    n = cowell.CowellOrbit(zonal_degree=0, drag=False)
    n.set_inputs(F_thrust_B=(0.0, 0.0, 0.1), q_BN=q)
    n.advance_to(60.0)
    a, e, i, *_ = oe.cartesian_to_kepler(n.position(), n.velocity())
    assert a == pytest.approx(R + 420e3, abs=0.1)  # second order only: a^2 dv^2 / mu = 0.03 m
    assert i - 51.6 * DEG == pytest.approx(0.1 / 12.0 * 60.0 / np.linalg.norm(v), rel=0.01)


def test_outputs_geodetic_altitude_and_elements(exponential):
    m = cowell.CowellOrbit(density_model=exponential)
    run(m, 3000.0, 300.0)
    o = m.outputs()
    r = o["r_BN_N"]
    lat, lon, alt = geodesy.geodetic_from_inertial(r, m.jd_state())
    assert (o["latitude"], o["longitude"], o["altitude"]) == (lat, lon, alt)
    assert cowell.geodetic_altitude_nb(*r) == pytest.approx(alt, abs=1e-6)
    assert o["altitude_spherical"] == pytest.approx(np.linalg.norm(r) - R, abs=1e-6)
    assert o["perigee_altitude"] <= o["sma"] - R <= o["apogee_altitude"]
    assert o["density"] == exponential.density(np.array(r), m.jd_state())
    # on the equator and at the pole
    assert cowell.geodetic_altitude_nb(geodesy.WGS84_A + 400e3, 0.0, 0.0) == pytest.approx(400e3, abs=1e-6)
    assert cowell.geodetic_altitude_nb(0.0, 0.0, geodesy.WGS84_B + 400e3) == pytest.approx(400e3, abs=1e-6)


def test_reentry_latches_and_holds_the_state(exponential):
    m = cowell.CowellOrbit(density_model=exponential)
    m.set_inputs(F_thrust_B=(20.0, 0.0, 0.0), retrograde=True)  # drops the perigee below the ground
    m.advance_to(120.0)
    m.set_inputs(F_thrust_B=(0.0, 0.0, 0.0))
    k = 0
    while not m.reentered and k < 40:
        k += 1
        m.advance_to(120.0 + 300.0 * k)
    assert m.reentered and 120.0 < m.reentry_time <= m.t
    o = m.outputs()
    assert 200e3 < o["altitude"] < 250e3 and o["reentered"]
    held = m.get_state()
    m.advance_to(m.t + 3600.0)
    assert m.position().tolist() == held["y"][:3] and m.t == held["t"] + 3600.0


def test_get_set_state_reproduces_steps_exactly(exponential):
    m = cowell.CowellOrbit(density_model=exponential)
    run(m, 1800.0)
    s = m.get_state()
    m.set_inputs(F_thrust_B=(0.1, 0.0, 0.0), retrograde=True, mass=11.9)
    m.advance_to(2400.0)
    first = (m.position().tolist(), m.velocity().tolist(), m.outputs()["sma"])
    m.set_state(s)
    m.set_inputs(F_thrust_B=(0.1, 0.0, 0.0), retrograde=True, mass=11.9)
    m.advance_to(2400.0)
    assert (m.position().tolist(), m.velocity().tolist(), m.outputs()["sma"]) == first


def test_errors(exponential):
    with pytest.raises(ValueError, match="perigee altitude"):
        cowell.CowellOrbit(sma0=R + 240e3, density_model=exponential)
    with pytest.raises(ValueError, match="perigee altitude"):
        cowell.CowellOrbit(sma0=R + 420e3, ecc0=0.03, density_model=exponential)
    for kw, what in ((dict(mass=0.0), "mass"), (dict(area=-1.0), "area"), (dict(Cd=0.0), "Cd"),
                     (dict(ecc0=1.2), "ecc0"), (dict(inc0=4.0), "inc0"), (dict(zonal_degree=7), "zonal_degree"),
                     (dict(epoch="2023-01-01"), "epoch"), (dict(mu=-1.0), "mu")):
        with pytest.raises(ValueError, match=what):
            cowell.CowellOrbit(density_model=exponential, **kw)
    with pytest.raises(ValueError, match="unknown"):
        cowell.CowellOrbit(density_model="jacchia_robert")
    with pytest.raises(ValueError, match="density_model"):
        cowell.CowellOrbit(density_model=None)
    m = cowell.CowellOrbit(density_model=exponential)
    with pytest.raises(ValueError, match="mass"):
        m.set_inputs(mass=-1.0)
    with pytest.raises(ValueError, match="q_BN"):
        m.set_inputs(q_BN=(0.0, 0.0, 0.0, 0.0))
    m.advance_to(60.0)
    with pytest.raises(ValueError, match="before"):
        m.advance_to(30.0)


# ---- FMU -------------------------------------------------------------------------------------
def test_orbit_fmu(build_one, tmp_path, exponential):
    path = build_one("neighbor_orbit.py")
    deps = check_declarations(path)
    assert all(d == [] for d in deps.values())  # state outputs only
    expected_outputs = {f"r_BN_N[{i}]" for i in (1, 2, 3)} | {f"v_BN_N[{i}]" for i in (1, 2, 3)} | {
        "altitude", "altitude_spherical", "latitude", "longitude", "sma", "ecc", "perigee_altitude",
        "apogee_altitude", "density", "reentered"}
    assert set(deps) == expected_outputs
    fmu, vr = instantiate(path, tmp_path, "orbit")
    for name in ("F_thrust_B[1]", "q_BN[4]", "retrograde", "mass", "epoch", "sma0", "ecc0", "inc0", "raan0",
                 "argp0", "ta0", "Cd", "area", "reentry_altitude", "density_model", "space_weather_file",
                 "use_constant_space_weather", "f107", "f107a", "ap", "mu"):
        assert name in vr, name
    fmu.setString([vr["density_model"]], ["exponential"])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    names = sorted(expected_outputs - {"reentered"})
    refs = [vr[n] for n in names]
    t = 0.0
    for _ in range(6):
        fmu.doStep(t, 300.0)
        t += 300.0
    state = fmu.getFMUstate()
    fmu.setReal([vr["F_thrust_B[1]"]], [0.1])
    fmu.setBoolean([vr["retrograde"]], [True])
    fmu.doStep(t, 0.5)
    fmu.doStep(t + 0.5, 299.5)
    first = fmu.getReal(refs)
    fmu.setFMUstate(state)
    fmu.setReal([vr["F_thrust_B[1]"]], [0.1])
    fmu.setBoolean([vr["retrograde"]], [True])
    fmu.doStep(t, 0.5)
    fmu.doStep(t + 0.5, 299.5)
    assert fmu.getReal(refs) == first
    fmu.freeFMUstate(state)
    # the same run through the component
    m = cowell.CowellOrbit(density_model=exponential)
    run(m, 1800.0)
    m.set_inputs(F_thrust_B=(0.1, 0.0, 0.0), retrograde=True)
    m.advance_to(1800.5)
    m.advance_to(2100.0)
    out = dict(zip(names, first))
    np.testing.assert_array_equal([out[f"r_BN_N[{i}]"] for i in (1, 2, 3)], m.position())
    assert out["sma"] == m.outputs()["sma"] and out["density"] == m.outputs()["density"]
    assert fmu.getBoolean([vr["reentered"]]) == [False]
    fmu.terminate()
    fmu.freeInstance()


def test_orbit_fmu_rejects_bad_parameters(build_one, tmp_path):
    path = build_one("neighbor_orbit.py")
    fmu, vr = instantiate(path, tmp_path, "orbit_bad")
    fmu.setReal([vr["sma0"]], [R + 200e3])
    fmu.enterInitializationMode()
    with pytest.raises(Exception):
        fmu.exitInitializationMode()


def test_orbit_fmu_cartesian_start_equals_the_elements(build_one, tmp_path):
    """cartesian0 with the state of the Table 3 elements gives the same trajectory."""
    path = build_one("neighbor_orbit.py")
    r0, v0 = oe.kepler_to_cartesian(R + 420e3, 0.001, math.radians(51.6), 0.3, 0.2, 0.1)
    finals = []
    for name, cartesian in (("orbit_elements", False), ("orbit_cartesian", True)):
        fmu, vr = instantiate(path, tmp_path, name)
        fmu.setString([vr["density_model"]], ["exponential"])
        if cartesian:
            fmu.setBoolean([vr["cartesian0"]], [True])
            fmu.setReal([vr[f"r0_N[{k}]"] for k in (1, 2, 3)] + [vr[f"v0_N[{k}]"] for k in (1, 2, 3)],
                        list(r0) + list(v0))
        else:
            fmu.setReal([vr[n] for n in ("ecc0", "raan0", "argp0", "ta0")], [0.001, 0.3, 0.2, 0.1])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 600.0)
        finals.append(fmu.getReal([vr[f"r_BN_N[{k}]"] for k in (1, 2, 3)]))
        fmu.terminate()
    np.testing.assert_allclose(finals[0], finals[1], rtol=0, atol=1e-3)
    assert oe.initial_elements({"cartesian0": True, **{f"r0_N[{k}]": x for k, x in zip((1, 2, 3), r0)},
                                **{f"v0_N[{k}]": x for k, x in zip((1, 2, 3), v0)}})[0] == pytest.approx(R + 420e3)
    with pytest.raises(ValueError, match="r0_N"):
        oe.initial_elements({"cartesian0": True, **{f"r0_N[{k}]": 0.0 for k in (1, 2, 3)},
                             **{f"v0_N[{k}]": 0.0 for k in (1, 2, 3)}})


@pytest.mark.skipif(not jit.ENABLED, reason="numba's cache")
def test_the_product_atmospheres_are_bound_in_by_cached_functions():
    """Both integrators bind the product's atmosphere kernels in through functions numba caches
    across processes: a kernel passed as an argument is compiled again in every process (the Cowell
    integration 4-6 s, the averaged one 2-4 s). NRLMSIS (pymsis from compiled code) and a user's
    kernel take that path."""
    sw = space_weather.SpaceWeather.from_file()
    for name in atmosphere.MODELS:
        if name == "msis":
            continue
        kernel = atmosphere.make_density_model(name, space_weather=sw, inclination=0.9).kernel
        for integration in (averaged._advance_function(kernel), cowell._CACHED_ADVANCE[jit.function_of(kernel)]):
            assert type(integration._cache).__name__ == "FunctionCache", (name, integration)
