"""Orbit-averaged lifetime model: Gauss equations against Cartesian finite differences, the
analytic circular decay rate, J2 drift, a short retrograde burn against vis-viva, re-entry latch,
state, the `OrbitAveraged` FMU through FMPy, and (when the Cowell model is present) a
cross-check of the mean decay with components.orbit."""
import math

import fmpy
import numpy as np
import pytest

from components.core.jit import njit, objmode
from components.environment import atmosphere, space_weather
from components.orbit import averaged as oa
from components.orbit import elements, propulsion
from fmu_helpers import check_declarations, instantiate

MU, R_EQ, J2 = oa.MU_EARTH, oa.R_EQ, oa.J2
INC = math.radians(51.6)
BC = 2.2 * 0.02 / 12.0  # Cd A / m


@njit
def _constant_kernel(r, jd, data):
    return data[0]


class ConstantDensity:
    """A density model with the components.environment.atmosphere interface and a constant density."""

    def __init__(self, rho):
        self.rho = rho
        self.kernel = _constant_kernel
        self.kernel_data = (float(rho),)

    def density(self, r_N, jd_utc):
        return self.rho


_PYTHON_DENSITY = {}


def _python_density(r, jd):
    return _PYTHON_DENSITY["rho"]


@njit
def _callback_kernel(r, jd, data):
    with objmode(rho="float64"):
        rho = _python_density(r, jd)
    return rho


class PythonOnly(ConstantDensity):
    """The same, with the density computed in Python and called from the kernel (the path msis
    takes)."""

    def __init__(self, rho):
        super().__init__(rho)
        _PYTHON_DENSITY["rho"] = float(rho)
        self.kernel = _callback_kernel
        self.kernel_data = (0.0,)


def elements_vector(r, v):
    """(a, ex, ey, i, raan, lam) of a Cartesian state, through orbit_elements."""
    a, e, i, raan, argp, nu = elements.cartesian_to_kepler(r, v, MU)
    M = elements.mean_from_true(nu, e)
    return np.array([a, e * math.cos(argp), e * math.sin(argp), i, raan, argp + M])


def test_state_reconstruction_matches_orbit_elements():
    for e, argp, ta in ((0.0, 0.0, 0.3), (0.01, 1.0, 2.5), (0.05, 4.0, 5.9)):
        m = oa.OrbitAveraged(None, sma0=7.2e6, ecc0=e, inc0=1.1, raan0=0.4, argp0=argp, ta0=ta)
        r, v = m.state_vectors()
        r_ref, v_ref = elements.kepler_to_cartesian(7.2e6, e, 1.1, 0.4, argp, ta, MU)
        np.testing.assert_allclose(r, r_ref, rtol=0, atol=1e-5)
        np.testing.assert_allclose(v, v_ref, rtol=0, atol=1e-8)


@pytest.mark.parametrize("e", [0.0, 0.02])
def test_gauss_equations_against_cartesian_finite_differences(e):
    """The non-singular Gauss rates per unit acceleration equal the change of the elements
    (from orbit_elements.cartesian_to_kepler) under a small velocity impulse, for all six."""
    m = oa.OrbitAveraged(None, sma0=6.9e6, ecc0=e, inc0=0.9, raan0=0.7, argp0=2.0, ta0=1.3)
    y = m.y.copy()
    r, v = m.state_vectors()
    rng = np.random.default_rng(1)
    for _ in range(3):
        f = rng.normal(size=3)
        f /= np.linalg.norm(f)
        rates = oa._thrust_rates(y, MU, f, 0.0)
        dv = 1e-3
        d = (elements_vector(r, v + dv * f) - elements_vector(r, v - dv * f)) / (2 * dv)
        if e == 0.0:  # at e = 0 only a, i, raan and the rates of (ex, ey) as a vector are defined
            d_e = np.hypot(*(elements_vector(r, v + dv * f)[1:3]))
            assert np.hypot(rates[1], rates[2]) * dv == pytest.approx(d_e, rel=1e-4)
            idx = [0, 3, 4]
        else:
            d[5] = (d[5] + math.pi) % (2 * math.pi) - math.pi
            idx = range(6)
        for k in idx:
            assert rates[k] == pytest.approx(d[k], rel=1e-5, abs=1e-12), k
    # retrograde: |f| along -v
    rr = oa._thrust_rates(y, MU, np.zeros(3), 1.0)
    vhat = v / np.linalg.norm(v)
    np.testing.assert_allclose(rr, oa._thrust_rates(y, MU, -vhat, 0.0), rtol=1e-12, atol=1e-20)


@pytest.mark.parametrize("model", [ConstantDensity, PythonOnly])
def test_circular_decay_rate_is_analytic(model):
    """da/dt = -sqrt(mu a) rho Cd A / m for a circular orbit in a constant density (no
    atmospheric rotation), within 0.5 % (here 1e-9)."""
    rho = 3e-12
    for h0 in (350e3, 420e3):
        a = R_EQ + h0
        m = oa.OrbitAveraged(model(rho), sma0=a, inc0=INC, omega_atm=0.0)
        d = m.drag_rates(m.y, 0.0, 12.0)
        expected = -math.sqrt(MU * a) * rho * BC
        assert d[0] == pytest.approx(expected, rel=0.005)
        assert d[0] == pytest.approx(expected, rel=1e-9)
        assert abs(d[1]) + abs(d[2]) < 1e-12 * abs(d[0]) / a  # circular stays circular
        assert d[3] == 0.0 or abs(d[3]) < 1e-20


def test_decay_with_rotating_atmosphere_against_independent_average():
    """With the co-rotating atmosphere: da/dt = 2 a^2/h <F_S>, F_S = -1/2 rho B |v_rel| (v -
    w a cos i), |v_rel|^2 = (v - w a cos i)^2 + (w a sin i cos u)^2, averaged over u here with
    2000 points; and di/dt = <r cos u F_W> / h with F_W = -1/2 rho B |v_rel| w a sin i cos u."""
    rho, a, w = 3e-12, R_EQ + 400e3, oa.OMEGA_EARTH
    m = oa.OrbitAveraged(ConstantDensity(rho), sma0=a, inc0=INC)
    d = m.drag_rates(m.y, 0.0, 12.0)
    v = math.sqrt(MU / a)
    u = np.linspace(0.0, 2 * math.pi, 2000, endpoint=False)
    s = v - w * a * math.cos(INC)
    vrel = np.sqrt(s ** 2 + (w * a * math.sin(INC) * np.cos(u)) ** 2)
    h = math.sqrt(MU * a)
    assert d[0] == pytest.approx(2 * a * a / h * np.mean(-0.5 * rho * BC * vrel * s), rel=1e-6)
    fw = -0.5 * rho * BC * vrel * w * a * math.sin(INC) * np.cos(u)
    assert d[3] == pytest.approx(np.mean(a * np.cos(u) * fw) / h, rel=1e-6)
    assert d[3] < 0.0  # drag in a co-rotating atmosphere lowers a prograde inclination
    # about 8 % slower decay than the non-rotating formula at 51.6 deg
    assert d[0] / (-math.sqrt(MU * a) * rho * BC) == pytest.approx((1 - w * a * math.cos(INC) / v) ** 2, rel=0.005)


def test_integrated_decay_in_constant_density():
    """sqrt(a) = sqrt(a0) - k t / 2 with k = sqrt(mu) rho B (circular, constant density)."""
    rho, a0, days = 5e-12, R_EQ + 350e3, 60.0
    m = oa.OrbitAveraged(ConstantDensity(rho), sma0=a0, inc0=INC, omega_atm=0.0, j2=0.0)
    m.advance_to(days * 86400.0)
    k = math.sqrt(MU) * rho * BC
    a_exact = (math.sqrt(a0) - 0.5 * k * days * 86400.0) ** 2
    assert m.sma - a0 == pytest.approx(a_exact - a0, rel=1e-6)
    assert m.ecc < 1e-12


def test_j2_drift_equals_analytic_rates():
    a, e = R_EQ + 500e3, 0.01
    m = oa.OrbitAveraged(None, sma0=a, ecc0=e, inc0=INC, raan0=1.0, argp0=0.5)
    days = 10.0
    m.advance_to(days * 86400.0)
    n = math.sqrt(MU / a ** 3)
    p = a * (1 - e * e)
    k = n * J2 * (R_EQ / p) ** 2
    raan_rate = -1.5 * k * math.cos(INC)
    argp_rate = 0.75 * k * (4 - 5 * math.sin(INC) ** 2)
    m_rate = n + 0.75 * k * math.sqrt(1 - e * e) * (2 - 3 * math.sin(INC) ** 2)
    assert math.degrees(raan_rate) * 86400 == pytest.approx(-4.8, abs=0.3)  # ~ -5 deg/day in LEO at 51.6 deg
    t = days * 86400.0
    assert (m.raan - 1.0) == pytest.approx(raan_rate * t, rel=1e-9)
    # (ex, ey) rotate under RK4 with one-day steps of 0.06 rad: phase error ~1e-7
    assert (m.argp - 0.5) == pytest.approx(argp_rate * t, rel=1e-6)
    assert m.ecc == pytest.approx(e, rel=1e-7) and m.sma == a  # RK4 amplitude error of the rotation
    lam_expected = (0.5 + elements.mean_from_true(0.0, e) + (argp_rate + m_rate) * t) % (2 * math.pi)
    assert m.mean_arg_latitude == pytest.approx(lam_expected, abs=1e-6)


def test_short_retrograde_burn_matches_vis_viva():
    """60 s at 0.1 N on 12 kg along -v from a 420 km circular orbit (dv = 0.5 m/s): the change
    of a and e equals the impulsive vis-viva values (the finite arc of 3.9 deg changes e by
    the factor sinc(1.9 deg) = 0.99981), and the perigee lies opposite the burn."""
    a0 = R_EQ + 420e3
    m = oa.OrbitAveraged(None, sma0=a0, inc0=INC)
    thr = propulsion.MainThrusters(mass0=12.0, propellant_budget=0.5)
    t = 0.0
    while t < 60.0 - 1e-9:
        m.advance_to(t + 0.5, thr.force_B(True), retrograde=True, mass=thr.mass)
        thr.step(True, 0.5)
        t += 0.5
    dv = propulsion.delta_v_of_propellant(thr.used, 12.0)
    assert dv == pytest.approx(0.5, rel=1e-3)
    v0 = math.sqrt(MU / a0)
    a1 = 1.0 / (2.0 / a0 - (v0 - dv) ** 2 / MU)
    e1 = a0 / a1 - 1.0  # the burn point becomes the apogee
    assert m.sma - a0 == pytest.approx(a1 - a0, rel=1e-3)
    assert m.ecc == pytest.approx(e1, rel=1e-3)
    u_mid = 30.0 * math.sqrt(MU / a0 ** 3)
    assert abs((m.argp - (u_mid + math.pi) + math.pi) % (2 * math.pi) - math.pi) < 0.01
    # the same with the thrust given in B and an attitude: identity q, force fixed along -v0
    m2 = oa.OrbitAveraged(None, sma0=a0, inc0=INC)
    r, v = m2.state_vectors()
    F_B = -0.1 * v / np.linalg.norm(v)
    m2.advance_to(4.0, F_B, (0.0, 0.0, 0.0, 1.0), False, 12.0)
    m3 = oa.OrbitAveraged(None, sma0=a0, inc0=INC)
    m3.advance_to(4.0, (0.1, 0.0, 0.0), retrograde=True, mass=12.0)
    assert m2.sma - a0 == pytest.approx(m3.sma - a0, rel=1e-5)
    # and with a rotated attitude: B = N rotated 90 deg about z, so F_N = A^T F_B
    q = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    A = oa.quaternion_to_dcm(q)
    np.testing.assert_allclose(A @ [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], atol=1e-15)
    m4 = oa.OrbitAveraged(None, sma0=a0, inc0=INC)
    m4.advance_to(4.0, A @ F_B, q, False, 12.0)
    np.testing.assert_allclose(m4.y, m2.y, rtol=1e-12)


def test_reentry_latch_and_hold():
    m = oa.OrbitAveraged(atmosphere.make_density_model("exponential"), sma0=R_EQ + 262e3, inc0=INC)
    t = 0.0
    while not m.reentered and t < 30 * 86400:
        t += 3600.0
        m.advance_to(t)
    assert m.reentered and 0.0 < m.reentry_time <= t
    assert m.perigee_altitude == pytest.approx(250e3, abs=100.0)
    frozen, r_frozen = m.y.copy(), m.state_vectors()[0].copy()
    m.advance_to(t + 86400.0)
    assert m.t == t + 86400.0 and np.array_equal(m.y, frozen) and m.reentered
    np.testing.assert_array_equal(m.state_vectors()[0], r_frozen)
    with pytest.raises(ValueError, match="reentry_altitude"):
        oa.OrbitAveraged(None, sma0=R_EQ + 300e3, ecc0=0.01)  # perigee 228 km


def _numpy_advance(m, t_end, thrust, mass):
    """OrbitAveraged.advance_to's integration as it was written in numpy before it was compiled into
    one call: the same operations in the same order, through the model's public pieces."""
    def rates(y, t):
        d = m.drag_rates(y, t, mass)
        e = math.hypot(y[1], y[2])
        draan, dargp = elements.j2_secular_rates(y[0], e, y[3], m.mu, m.j2, m.r_eq)
        dM = oa.j2_mean_anomaly_rate(y[0], e, y[3], m.mu, m.j2, m.r_eq)
        d[1] -= y[2] * dargp
        d[2] += y[1] * dargp
        d[4] += draan
        d[5] += math.sqrt(m.mu / y[0] ** 3) + dargp + dM
        if thrust is not None:
            d += oa._thrust_rates(y, m.mu, thrust[0], thrust[1])
        return d

    def rk4(y, t, h, k1):
        k2 = rates(y + 0.5 * h * k1, t + 0.5 * h)
        k3 = rates(y + 0.5 * h * k2, t + 0.5 * h)
        k4 = rates(y + h * k3, t + h)
        return y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)

    def margin(y):
        return y[0] * (1.0 - math.hypot(y[1], y[2])) - R_EQ - m.reentry_altitude

    t, y = m.t, m.y
    while t_end - t > 64.0 * math.ulp(max(1.0, abs(t_end))):
        h = min(t_end - t, m.max_step)
        to_midnight = 86400.0 - (m._day_offset + t) % 86400.0
        if to_midnight > 1e-3:
            h = min(h, to_midnight)
        if thrust is not None:
            h = min(h, m.thrust_step)
        k1 = rates(y, t)
        if k1[0] != 0.0:
            h = min(h, m.max_da_step / abs(k1[0]))
        y1 = rk4(y, t, h, k1)
        if margin(y1) < 0.0:
            lo, glo, hi, ghi = 0.0, margin(y), h, margin(y1)
            for _ in range(40):
                tau = lo + (hi - lo) * glo / (glo - ghi)
                tau = min(max(tau, lo + 1e-3 * (hi - lo)), hi - 1e-3 * (hi - lo))
                yt = rk4(y, t, tau, k1)
                g = margin(yt)
                if g < 0.0:
                    hi, ghi = tau, g
                else:
                    lo, glo = tau, g
                if hi - lo < 1.0 or abs(g) < 1.0:
                    break
            yt[4] %= 2.0 * math.pi
            yt[5] %= 2.0 * math.pi
            return yt, t + tau
        t, y = t + h, y1
        y[4] %= 2.0 * math.pi
        y[5] %= 2.0 * math.pi
    return y, None


@pytest.mark.parametrize("model", ["jacchia_roberts", "exponential", None])
def test_compiled_integration_gives_the_numpy_bits(model):
    """The integration is one compiled call (the mission's orbit costs a third less): its states,
    with and without drag and thrust, through midnights and a re-entry, are the numpy version's
    bit for bit."""
    density = None if model is None else atmosphere.make_density_model(
        model, space_weather=space_weather.SpaceWeather.from_file(), inclination=INC)
    m = oa.OrbitAveraged(density, epoch="2023-01-01T00:00:00Z", sma0=R_EQ + 420e3, ecc0=1e-3, inc0=INC, argp0=0.3)
    q = (0.1, -0.2, 0.3, 0.92)
    steps = [(0.495, (0.0, 0.0, 0.0)), (0.495, (0.1, 0.02, -0.01)), (30.0, (0.1, 0.0, 0.0)), (240.0, (0.0, 0.0, 0.0)),
             (86400.0 * 3, (0.0, 0.0, 0.0)), (600.0, (0.0, 0.0, 0.5))]
    for dt, F in steps:
        expected, _ = _numpy_advance(m, m.t + dt, m.thrust_acceleration(F, q, False, 12.0), 12.0)
        m.advance_to(m.t + dt, F, q, False, 12.0)
        assert m.y.tolist() == expected.tolist()
    if model is None:
        return
    m.set_state(dict(m.get_state(), y=[R_EQ + 255e3, 1e-4, 0.0, INC, 0.2, 0.1]))  # days from re-entry
    expected, reentry = _numpy_advance(m, m.t + 30 * 86400.0, None, 12.0)
    m.advance_to(m.t + 30 * 86400.0, mass=12.0)
    assert reentry is not None and m.reentered and m.reentry_time == reentry
    assert m.y.tolist() == expected.tolist()


def test_elements_leaving_the_closed_orbit_domain_are_named():
    m = oa.OrbitAveraged(None, sma0=R_EQ + 420e3, inc0=INC)
    m.set_state(dict(m.get_state(), y=[R_EQ + 420e3, 0.8, 0.7, INC, 0.0, 0.0]))
    with pytest.raises(ValueError, match=r"closed-orbit domain \(a = 6798136.3 m, e = 1.06\d+\) at t = 0.0 s"):
        m.advance_to(10.0)
    assert m.t == 0.0 and m.y[1] == 0.8  # nothing advanced


def test_get_set_state_and_exact_landing():
    m = oa.OrbitAveraged(atmosphere.make_density_model("exponential"), sma0=R_EQ + 400e3, t0=100.0)
    m.advance_to(100.0 + 5 * 86400.0 + 0.37)
    assert m.t == 100.0 + 5 * 86400.0 + 0.37
    s = m.get_state()
    m.advance_to(m.t + 7 * 86400.0)
    after = m.y.copy()
    m.set_state(s)
    m.advance_to(m.t + 7 * 86400.0)
    np.testing.assert_array_equal(m.y, after)
    with pytest.raises(ValueError, match="mass"):
        m.advance_to(m.t + 1.0, mass=0.0)
    with pytest.raises(ValueError, match="before"):
        m.advance_to(0.0)


def test_short_steps_years_after_the_epoch_are_integrated():
    """0.1 s steps five years after the epoch (the mission's attitude determination) move the
    orbit as one 1 s step does; a tolerance relative to the time once dropped them."""
    a, b = oa.OrbitAveraged(None, sma0=6798137.0), oa.OrbitAveraged(None, sma0=6798137.0)
    t0 = 1.6e8
    a.advance_to(t0)
    b.advance_to(t0)
    u0 = a.mean_arg_latitude
    for k in range(1, 11):
        a.advance_to(t0 + 0.1 * k)
    b.advance_to(t0 + 1.0)
    assert a.mean_arg_latitude - u0 == pytest.approx(math.sqrt(3.986004418e14 / 6798137.0 ** 3), rel=0.01)
    assert a.mean_arg_latitude - b.mean_arg_latitude == pytest.approx(0.0, abs=1e-9)


def test_bad_parameters_are_named():
    for kwargs, name in (({"inc0": 0.0}, "inc0"), ({"ecc0": 1.0}, "ecc0"), ({"sma0": -1.0}, "sma0"),
                         ({"Cd": -1.0}, "Cd"), ({"quadrature_nodes": 4}, "quadrature_nodes"),
                         ({"epoch": "2023-01-01"}, "epoch"), ({"mu": 0.0}, "mu")):
        with pytest.raises(ValueError, match=name):
            oa.OrbitAveraged(None, **kwargs)


# ---- FMU ---------------------------------------------------------------------------------------
CONTRACT_INPUTS = {"F_thrust_B[1]", "F_thrust_B[2]", "F_thrust_B[3]", "q_BN[1]", "q_BN[2]", "q_BN[3]", "q_BN[4]",
                   "retrograde", "mass", "impulse_B[1]", "impulse_B[2]", "impulse_B[3]"}
CONTRACT_OUTPUTS = {"r_BN_N[1]", "r_BN_N[2]", "r_BN_N[3]", "v_BN_N[1]", "v_BN_N[2]", "v_BN_N[3]", "altitude",
                    "altitude_spherical", "latitude", "longitude", "sma", "ecc", "perigee_altitude",
                    "apogee_altitude", "density", "reentered"}
SHARED_PARAMETERS = {"epoch", "sma0", "ecc0", "inc0", "raan0", "argp0", "ta0", "Cd", "area", "reentry_altitude",
                     "density_model", "space_weather_file", "use_constant_space_weather", "f107", "f107a", "ap",
                     "mu"}


@pytest.fixture(scope="module")
def fmu_path(build_one):
    return build_one("neighbor_orbit_averaged.py")


def test_fmu_connectors_are_the_contract(fmu_path):
    deps = check_declarations(fmu_path)
    assert set(deps) == CONTRACT_OUTPUTS and all(d == [] for d in deps.values())
    md = fmpy.read_model_description(str(fmu_path))
    by = {v.name: v for v in md.modelVariables}
    assert {n for n, v in by.items() if v.causality == "input"} == CONTRACT_INPUTS
    assert SHARED_PARAMETERS <= {n for n, v in by.items() if v.causality == "parameter"}
    assert by["mass"].start == "12.0" or float(by["mass"].start) == 12.0
    assert by["epoch"].start == "2023-01-01T00:00:00Z"


def test_fmu_through_fmpy_matches_component(fmu_path, tmp_path):
    start = {"density_model": "exponential", "sma0": R_EQ + 380e3}
    r = fmpy.simulate_fmu(str(fmu_path), start_time=0.0, stop_time=3 * 86400.0, output_interval=6 * 3600.0,
                          start_values=start)
    comp = oa.OrbitAveraged(atmosphere.make_density_model("exponential"), sma0=R_EQ + 380e3)
    for row in r:
        comp.advance_to(row["time"])
        assert row["sma"] == pytest.approx(comp.sma, rel=1e-12)
        np.testing.assert_allclose([row[f"r_BN_N[{i}]"] for i in (1, 2, 3)], comp.state_vectors()[0], atol=1e-3)
        lat, lon, alt = comp.geodetic()
        assert row["altitude"] == pytest.approx(alt, abs=1e-3) and row["density"] == pytest.approx(comp.density())
    assert r["sma"][-1] < r["sma"][0] and not r["reentered"][-1]
    # state save/restore through FMI, a burn through the inputs
    fmu, vr = instantiate(fmu_path, tmp_path, "orbit_avg")
    try:
        fmu.setString([vr["density_model"]], ["exponential"])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 1200.0)
        saved = fmu.getFMUstate()
        sma = lambda: fmu.getReal([vr["sma"]])[0]  # noqa: E731
        s0 = sma()
        fmu.setBoolean([vr["retrograde"]], [True])
        fmu.setReal([vr["F_thrust_B[1]"]], [0.1])
        for k in range(20):
            fmu.doStep(1200.0 + 0.5 * k, 0.5)
        dv = 0.1 * 10.0 / 12.0
        assert sma() - s0 == pytest.approx(-2 * (R_EQ + 420e3) * dv / math.sqrt(MU / (R_EQ + 420e3)), rel=0.01)
        fmu.setFMUstate(saved)
        assert sma() == s0
        fmu.freeFMUstate(saved)
    finally:
        fmu.terminate()
        fmu.freeInstance()
    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(fmu_path), stop_time=10.0, start_values={"sma0": R_EQ + 200e3})


def test_fmu_connectors_equal_the_cowell_orbit_fmu(fmu_path, build_one):
    """Both FMUs have exactly the same inputs and outputs (names, types, units), so a system
    swaps them by replacing one component."""
    cowell = fmpy.read_model_description(str(build_one("neighbor_orbit.py")))
    mine = fmpy.read_model_description(str(fmu_path))

    def connectors(md):
        return {v.name: (v.causality, v.type, v.unit) for v in md.modelVariables if v.causality in ("input", "output")}

    assert connectors(mine) == connectors(cowell)
    params = lambda md: {v.name: (v.type, v.unit) for v in md.modelVariables if v.causality == "parameter"}  # noqa: E731
    shared = SHARED_PARAMETERS | {"drag", "hp_exponent"}
    assert {k: v for k, v in params(mine).items() if k in shared} == {k: v for k, v in params(cowell).items()
                                                                       if k in shared}


# ---- cross-check with the Cowell model -----------------------------------------------------------
def _orbit_mean(model, t_start, value, period, n=48):
    vals = []
    for k in range(n):
        model.advance_to(t_start + k * period / n)
        vals.append(value(model))
    return float(np.mean(vals))


@pytest.mark.parametrize("zonal_degree, tolerance", [(0, 0.005), (6, 0.05)])
def test_mean_decay_agrees_with_cowell(zonal_degree, tolerance):
    """350 km circular, exponential density, 30 days: the decay of the orbit-mean semi-major
    axis of the Cowell model (components.orbit.cowell, osculating a averaged over one orbit at the
    start and the end) and of the averaged model started from the same mean a.

    Point mass only (zonal_degree 0, j2 0): within 0.5 % (measured 0.1 %). With J2..J6 in
    Cowell and J2 here: within 5 % (measured 2.6 %: the averaged model rebuilds the orbit by
    two-body formulae, so its mean geodetic altitude is 0.8 km above the Cowell orbit's at the
    same mean a, the first-order J2 short-period offset of the radius, and the density there
    is 1.5 % lower; J3..J6 add their own long-period eccentricity)."""
    from components.orbit import cowell

    dens = atmosphere.make_density_model("exponential")
    a0, days = R_EQ + 350e3, 30.0
    period = elements.period(a0)
    c = cowell.CowellOrbit(sma0=a0, density_model=dens, zonal_degree=zonal_degree)
    sma = lambda mdl: mdl.outputs()["sma"]  # noqa: E731
    s0 = _orbit_mean(c, 0.0, sma, period)
    c.advance_to(days * 86400.0)
    s1 = _orbit_mean(c, days * 86400.0, sma, period)
    av = oa.OrbitAveraged(dens, sma0=s0, j2=J2 if zonal_degree else 0.0)
    av.advance_to(days * 86400.0)
    a1 = _orbit_mean(av, days * 86400.0, lambda mdl: mdl.sma, period)
    assert s1 - s0 < -3000.0  # a few km in a month at 350 km
    assert (a1 - s0) == pytest.approx(s1 - s0, rel=tolerance)
