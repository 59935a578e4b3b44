"""Analytic circular Keplerian orbit: a simple position source.

    a = R_earth + altitude,  n = sqrt(mu / a^3),  period P = 2 pi / n = 2 pi sqrt(a^3 / mu)
    u(t) = u0 + n t                          argument of latitude
    r_BN_N = a [cos O cos u - sin O cos i sin u,  sin O cos u + cos O cos i sin u,  sin i sin u]
    v_BN_N = sqrt(mu / a) [-cos O sin u - sin O cos i cos u,  -sin O sin u + cos O cos i cos u,
                           sin i cos u]

with O the right ascension of the ascending node (RAAN) and i the inclination, in N. Two-body
motion only: no J2, drag or third bodies. At 400 km, P = 92.56 min (thesis Eq. 67).
State: the simulation time t only.
"""
import math

from ..core import time_utils
from ..core.constants import MU_EARTH_WGS84, WGS84_A



class CircularOrbit(time_utils.Clock):
    def __init__(self, altitude=420e3, inclination=math.radians(51.6), raan=0.0, arg_latitude0=0.0,
                 mu=MU_EARTH_WGS84, earth_radius=WGS84_A, t0=0.0):
        for name, value in (("mu", mu), ("earth_radius", earth_radius)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r} must be a finite positive number")
        if not (math.isfinite(altitude) and altitude > 0):
            raise ValueError(f"altitude = {altitude!r} must be a finite positive number of metres above "
                             "earth_radius")
        if not (math.isfinite(inclination) and 0.0 <= inclination <= math.pi):
            raise ValueError(f"inclination = {inclination!r} rad must be in [0, pi]")
        for name, value in (("raan", raan), ("arg_latitude0", arg_latitude0)):
            if not math.isfinite(value):
                raise ValueError(f"{name} = {value!r} rad must be finite")
        self.mu, self.earth_radius = float(mu), float(earth_radius)
        self.altitude, self.inclination = float(altitude), float(inclination)
        self.raan, self.arg_latitude0 = float(raan), float(arg_latitude0)
        self.a = self.earth_radius + self.altitude
        self.n = math.sqrt(self.mu / self.a ** 3)
        self.period = 2.0 * math.pi / self.n
        self.speed = math.sqrt(self.mu / self.a)
        cO, sO, ci, si = math.cos(raan), math.sin(raan), math.cos(inclination), math.sin(inclination)
        # In-plane unit vectors: P toward the ascending node, Q 90 deg ahead in the orbit plane.
        self._P = (cO, sO, 0.0)
        self._Q = (-sO * ci, cO * ci, si)
        self.t = time_utils.check_time(t0, "start time")
        self._cache = (None, None)

    def _state(self, t):
        if self._cache[0] == t:
            return self._cache[1]
        u = self.arg_latitude0 + self.n * t
        cu, su = math.cos(u), math.sin(u)
        P, Q, a, s = self._P, self._Q, self.a, self.speed
        r = tuple(a * (P[k] * cu + Q[k] * su) for k in range(3))
        v = tuple(s * (-P[k] * su + Q[k] * cu) for k in range(3))
        self._cache = (t, (r, v))
        return r, v

    def position(self, t=None):
        return self._state(self.t if t is None else float(t))[0]

    def velocity(self, t=None):
        return self._state(self.t if t is None else float(t))[1]

    def normal(self):
        """Unit orbit normal h_hat = P x Q."""
        cO, sO, ci, si = (math.cos(self.raan), math.sin(self.raan), math.cos(self.inclination),
                          math.sin(self.inclination))
        return (sO * si, -cO * si, ci)
