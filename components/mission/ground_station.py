"""Ground station contact model: the representative station at the University of Illinois at
Urbana-Champaign (thesis section 3.6, Appendix I: FreeFlyer's VisibilityCalculator between the
UIUC GroundStation and the spacecraft).

Geometry. The station is a point at geodetic latitude/longitude/height on the WGS-84
ellipsoid, fixed in the Earth-fixed frame E; E is N rotated by GMST (components.environment.geodesy). The
line of sight rho = r_E(spacecraft) - r_E(station) is resolved in the station's local
East-North-Up frame (Up = the ellipsoid normal):
    elevation = asin(rho . U / |rho|),  azimuth = atan2(rho . E, rho . N) in [0, 2 pi)
    (from north, positive toward east),  range = |rho|.
`visible` = elevation >= elevation_mask. No refraction, no terrain.

Default elevation mask: 0 rad, the geometric horizon. Appendix I's script sets no mask on its
UIUC GroundStation, and a FreeFlyer GroundStation without a mask sees down to the horizon;
so the thesis' contact periods are horizon-to-horizon (at 420 km up to about 10.5 min). Set
e.g. 10 deg for a realistic UHF link margin.

Default height 190 m above the ellipsoid: Urbana lies about 222 m above sea level and the geoid
there is about 33 m below the ellipsoid; 100 m either way changes no contact by a second.

Final confirmation (`ground_command`): the ground's confirmation to de-orbit can only reach the
spacecraft during a contact, so it is true while the spacecraft is visible and the time is at
or after `confirm_after` (s, simulation time): the operators confirm at the first contact from
then on (default 0: at any contact; a large value: the operators never confirm). NEIGHBOR asks
for the confirmation at the end of its grace period and only listens after that, so the
default lets the first contact after the grace period confirm, as in Appendix I.
"""
import math

from ..environment import geodesy
from ..core import time_utils
from ..core.constants import DAY, WGS84_A

UIUC_LATITUDE = math.radians(40.1020)  # N
UIUC_LONGITUDE = math.radians(-88.2272)  # 88.2272 W
UIUC_HEIGHT = 190.0  # m above WGS-84


def earth_fixed_from_geodetic(lat, lon, h):
    """WGS-84 Earth-fixed position (m) of geodetic latitude, longitude (rad), height (m)."""
    sl, cl = math.sin(lat), math.cos(lat)
    n = WGS84_A / math.sqrt(1.0 - geodesy.WGS84_E2 * sl * sl)
    return ((n + h) * cl * math.cos(lon), (n + h) * cl * math.sin(lon), (n * (1.0 - geodesy.WGS84_E2) + h) * sl)


def enu_axes(lat, lon):
    """East, North, Up unit vectors (Earth-fixed components) at geodetic latitude/longitude."""
    sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    return (-so, co, 0.0), (-sl * co, -sl * so, cl), (cl * co, cl * so, sl)


# A spacecraft below elevation_mask - 20 deg needs at least 448 s to reach the mask: the shortest
# rise from -20 deg to 0 deg over 3 days of a 420 km, 51.6 deg circular orbit at 2 s resolution
# (five RAANs), 450 s for a 300 km orbit. A master stepping at most 240 s while near_contact is
# false therefore cannot miss the start of a contact in such orbits.
APPROACH_MARGIN = math.radians(20.0)


class GroundStation(time_utils.Clock):
    def __init__(self, latitude=UIUC_LATITUDE, longitude=UIUC_LONGITUDE, height=UIUC_HEIGHT, elevation_mask=0.0,
                 confirm_after=0.0, epoch=time_utils.DEFAULT_EPOCH, t0=0.0, approach_margin=APPROACH_MARGIN):
        checks = (("latitude", latitude, -math.pi / 2, math.pi / 2, "[-pi/2, pi/2] rad"),
                  ("longitude", longitude, -2 * math.pi, 2 * math.pi, "[-2 pi, 2 pi] rad"),
                  ("height", height, -500.0, 10000.0, "[-500, 10000] m"),
                  ("elevation_mask", elevation_mask, -math.pi / 2, math.pi / 2, "[-pi/2, pi/2) rad"),
                  ("confirm_after", confirm_after, -math.inf, math.inf, "finite s"),
                  ("approach_margin", approach_margin, 0.0, math.pi, "[0, pi] rad"))
        for name, value, lo, hi, text in checks:
            value = float(value)
            if not (math.isfinite(value) and lo <= value <= hi) or (name == "elevation_mask" and value == hi):
                raise ValueError(f"{name} = {value!r} must be in {text}")
        self.latitude, self.longitude, self.height = float(latitude), float(longitude), float(height)
        self.elevation_mask, self.confirm_after = float(elevation_mask), float(confirm_after)
        self.approach_margin = float(approach_margin)
        self.jd0 = time_utils.julian_date(epoch)  # ValueError naming "epoch" if it does not parse
        self.r_site_E = earth_fixed_from_geodetic(self.latitude, self.longitude, self.height)
        self.axes = enu_axes(self.latitude, self.longitude)
        self.t = time_utils.check_time(t0, "start time")
        self._cache = (None, None)

    def gmst(self, t=None):
        return geodesy.gmst_of_jd(self.jd0 + (self.t if t is None else float(t)) / DAY)

    def look(self, r_N, t=None):
        """(elevation rad, azimuth rad in [0, 2 pi), range m) of the N position r_N (m) at time t."""
        t = self.t if t is None else float(t)
        key = (t, tuple(float(x) for x in r_N))
        if self._cache[0] == key:
            return self._cache[1]
        if not all(math.isfinite(x) for x in key[1]):
            raise ValueError(f"r_BN_N = {list(key[1])!r} m must be finite")
        r_E = geodesy.inertial_to_earth_fixed(key[1], self.gmst(t))
        rho = [r_E[k] - self.r_site_E[k] for k in range(3)]
        rng = math.sqrt(rho[0] ** 2 + rho[1] ** 2 + rho[2] ** 2)
        e, n, u = (sum(a[k] * rho[k] for k in range(3)) for a in self.axes)
        if rng == 0.0:
            result = (math.pi / 2, 0.0, 0.0)
        else:
            result = (math.asin(max(-1.0, min(1.0, u / rng))), math.atan2(e, n) % (2 * math.pi), rng)
        self._cache = (key, result)
        return result

    def visible(self, r_N, t=None):
        return self.look(r_N, t)[0] >= self.elevation_mask

    def near_contact(self, r_N, t=None):
        """Elevation above elevation_mask - approach_margin: a contact may begin soon. A master
        can step coarsely while this is false (see APPROACH_MARGIN)."""
        return self.look(r_N, t)[0] > self.elevation_mask - self.approach_margin

    def ground_command(self, r_N, t=None):
        t = self.t if t is None else float(t)
        return self.visible(r_N, t) and t >= self.confirm_after - 1e-6
