"""Ground station at UIUC: look angles against independent computations (a point overhead, the
meridian-plane geometry of a geostationary satellite, Vallado's SEZ rotation matrices), Earth
rotation over a sidereal day, contact statistics of the 420 km, 51.6 deg orbit over a day, the
final-confirmation signal, and the FMU through FMPy."""
import math

import numpy as np
import pytest

from components.core import constants
from components.environment import geodesy
from components.mission import ground_station as gsm
from components.orbit import circular
from fmu_helpers import check_declarations, instantiate

SIDEREAL_DAY = 86164.0905  # s


def n_position(station, r_E, t):
    """N position of an Earth-fixed point r_E at time t."""
    return geodesy.earth_fixed_to_inertial(r_E, station.gmst(t))


def test_station_position_round_trip():
    gs = gsm.GroundStation()
    lat, lon, h = geodesy.geodetic_from_earth_fixed(gs.r_site_E)
    assert math.degrees(lat) == pytest.approx(40.1020, abs=1e-9)
    assert math.degrees(lon) == pytest.approx(-88.2272, abs=1e-9)
    assert h == pytest.approx(190.0, abs=1e-6)
    # spherical radius of a 40 deg N site: between the polar and equatorial radii
    assert 6356752.0 < math.dist(gs.r_site_E, (0, 0, 0)) - 190.0 < 6378137.0


@pytest.mark.parametrize("t", [0.0, 3 * 3600.0, 1e6])
def test_point_directly_overhead(t):
    """500 km along the ellipsoid normal: elevation 90 deg, range 500 km, at any time."""
    gs = gsm.GroundStation()
    up = gs.axes[2]
    r_E = [gs.r_site_E[k] + 500e3 * up[k] for k in range(3)]
    el, az, rng = gs.look(n_position(gs, r_E, t), t)
    assert math.degrees(el) == pytest.approx(90.0, abs=1e-6)
    assert rng == pytest.approx(500e3, abs=1e-6)
    assert gs.visible(n_position(gs, r_E, t), t)


def test_geostationary_satellite_in_the_station_meridian():
    """A satellite over the equator at the station's longitude, geostationary radius: due south
    (azimuth 180 deg), elevation from the 2-D meridian-plane geometry with the ellipsoid normal."""
    gs = gsm.GroundStation()
    r_geo = 42164.17e3
    lat, lon = gs.latitude, gs.longitude
    a, e2, h = geodesy.WGS84_A, geodesy.WGS84_E2, gs.height
    n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
    p, z = (n + h) * math.cos(lat), (n * (1 - e2) + h) * math.sin(lat)  # station in the meridian plane
    rho = (r_geo - p, -z)
    up, north = (math.cos(lat), math.sin(lat)), (-math.sin(lat), math.cos(lat))
    el_ref = math.atan2(rho[0] * up[0] + rho[1] * up[1], abs(rho[0] * north[0] + rho[1] * north[1]))
    r_E = (r_geo * math.cos(lon), r_geo * math.sin(lon), 0.0)
    for t in (0.0, 5000.0):
        el, az, rng = gs.look(n_position(gs, r_E, t), t)
        assert math.degrees(az) == pytest.approx(180.0, abs=1e-9)
        assert el == pytest.approx(el_ref, abs=1e-12)
        assert rng == pytest.approx(math.hypot(*rho), rel=1e-12)
    assert math.degrees(el_ref) == pytest.approx(43.5, abs=0.5)  # textbook value for 40 deg N


def test_look_angles_against_sez_rotation_matrices():
    """Random LEO points: Vallado's topocentric SEZ frame, rho_SEZ = R2(90 deg - lat) R3(lon)
    rho_E, gives azimuth atan2(E, -S) and elevation asin(Z / |rho|)."""
    gs = gsm.GroundStation()

    def r2(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])

    def r3(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])

    rng_ = np.random.default_rng(3)
    for _ in range(200):
        t = rng_.uniform(0, 86400)
        r_N = rng_.normal(size=3)
        r_N *= rng_.uniform(6.6e6, 7.5e6) / np.linalg.norm(r_N)
        r_E = r3(gs.gmst(t)) @ r_N
        s, e, z = r2(math.pi / 2 - gs.latitude) @ r3(gs.longitude) @ (r_E - np.array(gs.r_site_E))
        el, az, rng = gs.look(r_N, t)
        assert el == pytest.approx(math.asin(z / math.sqrt(s * s + e * e + z * z)), abs=1e-12)
        assert abs((az - math.atan2(e, -s)) % (2 * math.pi)) < 1e-12 or \
            abs((az - math.atan2(e, -s)) % (2 * math.pi) - 2 * math.pi) < 1e-12
        assert 0.0 <= az < 2 * math.pi


def test_earth_rotation_over_a_sidereal_day():
    """A fixed N position has the same look angles one sidereal day later and different ones
    a quarter of a day later (the station has turned 90 deg)."""
    gs = gsm.GroundStation()
    r_N = (4.0e6, -5.0e6, 4.5e6)
    a = gs.look(r_N, 1000.0)
    b = gs.look(r_N, 1000.0 + SIDEREAL_DAY)
    np.testing.assert_allclose(b[:2], a[:2], rtol=0, atol=1e-8)  # rad
    assert b[2] == pytest.approx(a[2], abs=0.1)  # m
    c = gs.look(r_N, 1000.0 + SIDEREAL_DAY / 4)
    assert abs(c[2] - a[2]) > 1e5


def passes(gs, orbit, t_end, dt):
    """[(rise, set)] with the edges located to dt; passes cut by the span are dropped."""
    ts = np.arange(0.0, t_end + dt, dt)
    vis = [gs.visible(orbit.position(t), t) for t in ts]
    out, rise = [], None
    for k in range(1, len(ts)):
        if vis[k] and not vis[k - 1]:
            rise = ts[k]
        elif vis[k - 1] and not vis[k] and rise is not None:
            out.append((rise, ts[k]))
            rise = None
    return out


@pytest.mark.parametrize("raan_deg", [0.0, 120.0, 240.0])
def test_contact_statistics_420_km_51_6_deg(raan_deg):
    """Over a day, a 420 km, 51.6 deg circular orbit passes over Urbana (40.1 N, just below the
    inclination) 5-9 times (visible passes come in groups on consecutive orbits); horizon-to-
    horizon passes last typically 8-11 min, with a 10 deg mask 3-7 min. Upper bound: the
    visibility cone's central angle 2 acos(|r_site| / |r|) (41 deg) swept at no less than the
    relative rate n - omega_earth."""
    orbit = circular.CircularOrbit(420e3, math.radians(51.6), raan=math.radians(raan_deg))
    gs0 = gsm.GroundStation()
    found = passes(gs0, orbit, 86400.0, 5.0)
    durations = np.array([b - a for a, b in found]) / 60.0
    assert 5 <= len(found) <= 9
    lam = math.acos(math.dist(gs0.r_site_E, (0, 0, 0)) / orbit.a)
    bound = 2 * lam / (orbit.n - constants.OMEGA_EARTH) / 60.0
    assert 11.0 < bound < 11.5
    assert durations.max() <= bound + 5.0 / 60.0
    assert 8.0 <= np.median(durations) <= 11.0
    gs10 = gsm.GroundStation(elevation_mask=math.radians(10.0))
    found10 = passes(gs10, orbit, 86400.0, 5.0)
    d10 = np.array([b - a for a, b in found10]) / 60.0
    assert 3 <= len(found10) <= len(found) and d10.max() < 7.5 and 3.0 <= np.median(d10) <= 7.0
    for a, b in found10:  # every 10 deg pass lies inside a horizon pass
        assert any(a0 <= a and b <= b0 for a0, b0 in found)


def test_ground_command_and_parameters():
    gs = gsm.GroundStation(confirm_after=1000.0)
    up = gs.axes[2]
    r_E = [gs.r_site_E[k] + 500e3 * up[k] for k in range(3)]
    below = [-x for x in r_E]  # antipode: not visible
    assert not gs.ground_command(n_position(gs, r_E, 999.0), 999.0)
    assert gs.ground_command(n_position(gs, r_E, 1000.0), 1000.0)
    assert not gs.ground_command(n_position(gs, below, 2000.0), 2000.0)
    for bad, match in ((dict(latitude=2.0), "latitude"), (dict(elevation_mask=math.pi / 2), "elevation_mask"),
                       (dict(height=-1e4), "height"), (dict(confirm_after=math.inf), "confirm_after"),
                       (dict(epoch="2023-01-01"), "epoch")):
        with pytest.raises(ValueError, match=match):
            gsm.GroundStation(**bad)
    with pytest.raises(ValueError, match="r_BN_N"):
        gs.look((math.nan, 0.0, 7e6))


def test_ground_station_fmu(build_one, tmp_path):
    path = build_one("neighbor_ground_station.py")
    deps = check_declarations(path)
    r = ["r_BN_N[1]", "r_BN_N[2]", "r_BN_N[3]"]
    assert deps == {name: r for name in ("visible", "elevation", "azimuth", "range", "near_contact", "ground_command")}
    fmu, vr = instantiate(path, tmp_path, "ground", start_time=0.0)
    fmu.setReal([vr["confirm_after"]], [50.0])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    gs = gsm.GroundStation(confirm_after=50.0)
    up = gs.axes[2]
    r_E = [gs.r_site_E[k] + 420e3 * up[k] for k in range(3)]
    rv = [vr[n] for n in r]
    out = [vr[n] for n in ("elevation", "azimuth", "range")]
    flags = [vr["visible"], vr["ground_command"]]
    for t in (0.0, 100.0):
        r_N = n_position(gs, r_E, t)
        fmu.setReal(rv, list(r_N))  # direct feedthrough: read without a step
        el, _, rng = fmu.getReal(out)
        assert math.degrees(el) == pytest.approx(90.0, abs=1e-6) and rng == pytest.approx(420e3, abs=1e-6)
        assert fmu.getBoolean(flags) == [True, t >= 50.0]
        fmu.setReal(rv, [-x for x in r_N])
        assert fmu.getBoolean(flags) == [False, False]
        fmu.doStep(t, 100.0 - t if t == 0.0 else 10.0)
    fmu.terminate()
    fmu.freeInstance()


def test_near_contact_gives_warning_before_every_contact():
    """near_contact (elevation above mask - 20 deg) turns true at least 240 s before each
    contact of a 420 km, 51.6 deg orbit over a day (the coarse step a master may take outside)."""
    from components.orbit import elements as oe

    station = gsm.GroundStation(epoch="2023-01-01T00:00:00Z")
    r0, v0 = oe.kepler_to_cartesian(oe.R_EQ + 420e3, 0.0, math.radians(51.6), 0.0, 0.0, 0.0)
    ts = np.arange(0.0, 86400.0, 4.0)
    near, vis = [], []
    for t in ts:
        r = oe.kepler_propagate(r0, v0, t)[0]
        near.append(station.near_contact(r, t))
        vis.append(station.visible(r, t))
    near, vis = np.array(near), np.array(vis)
    rises = np.flatnonzero(vis[1:] & ~vis[:-1]) + 1
    assert len(rises) >= 4
    for i in rises:
        j = i
        while j > 0 and near[j - 1]:
            j -= 1
        assert ts[i] - ts[j] >= 240.0
    assert (near | ~vis).all()  # visible implies near
    with pytest.raises(ValueError, match="approach_margin"):
        gsm.GroundStation(approach_margin=-0.1)
