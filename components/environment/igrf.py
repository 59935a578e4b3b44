"""Earth's main magnetic field from the International Geomagnetic Reference Field, 14th generation
(IGRF-14, IAGA Working Group V-MOD, released December 2024), to degree 13.

Coefficients: data/IGRF14.shc, the IAGA release file (https://doi.org/10.5281/zenodo.14012302),
copied from the ppigrf package (MIT licence), see data/README.md. Schmidt semi-normalized Gauss
coefficients g_n^m, h_n^m (nT) at the 5-year epochs 1900.0 ... 2025.0 plus the 2030.0 column
that the 2025-2030 predicted secular variation gives.

Time: the coefficients are linear in time between the epochs (1 January 00:00 UTC of each epoch
year, as ppigrf interpolates), so between 2025 and 2030 the predicted secular variation applies;
after 2030 the last interval's rate is extrapolated (IGRF-14 is defined to 2030.0). Dates before
1900 are refused.

Synthesis (IGRF-14 description, Eq. 1): geocentric spherical coordinates (r, colatitude theta,
east longitude phi) of the Earth-fixed position, reference radius a = 6371.2 km,

    V = a sum_n (a/r)^(n+1) sum_m [g_n^m cos(m phi) + h_n^m sin(m phi)] P_n^m(cos theta)
    B_r = -dV/dr, B_theta = -(1/r) dV/dtheta, B_phi = -1/(r sin theta) dV/dphi

with P_n^m the Schmidt semi-normalized associated Legendre functions (recursions in
`legendre`), then rotated to the Earth-fixed Cartesian frame with the local unit vectors. The
position is Cartesian, so the geocentric coordinates are exact: no geodetic latitude enters
(ppigrf's `igrf_gc` is the same geocentric form; its `igrf` first converts geodetic input).
The Earth-fixed frame is N rotated by GMST, as for the tilted dipole
(components.environment.magnetic_field), which this model replaces with the same connectors.
"""
import bisect
import datetime as _dt
import math
import os

import numpy as np

from ..core import time_utils
from ..core.jit import njit
from . import magnetic_field

PACKAGE_DATA = ("data/IGRF14.shc",)  # what an FMU that imports this bundles
COEFFICIENT_FILE = os.path.join(os.path.dirname(__file__), "data", "IGRF14.shc")
MAX_DEGREE = 13
R_REF = magnetic_field.R_REF  # 6371.2 km, the IGRF reference radius


def read_shc(path=COEFFICIENT_FILE):
    """(years, g, h) of an IGRF .shc file: the epoch years (k) and arrays g[k, n, m], h[k, n, m]
    in nT (n, m up to the file's degree). ValueError naming the file and line for a malformed one."""
    rows, years, degree = [], None, None
    with open(path) as f:
        for number, line in enumerate(f, 1):
            text = line.strip()
            if not text or text.startswith("#"):
                continue
            fields = text.split()
            try:
                values = [float(x) for x in fields]
            except ValueError:
                raise ValueError(f"{path}:{number}: not numbers: {text[:60]!r}") from None
            if degree is None:
                degree = int(values[1])
                continue
            if years is None:
                years = values
                continue
            if len(values) != len(years) + 2:
                raise ValueError(f"{path}:{number}: {len(values)} numbers, expected n, m and {len(years)} values")
            rows.append(values)
    if years is None or not rows:
        raise ValueError(f"{path}: no coefficients")
    g = np.zeros((len(years), degree + 1, degree + 1))
    h = np.zeros_like(g)
    for values in rows:
        n, m = int(values[0]), int(values[1])
        if not (1 <= n <= degree and abs(m) <= n):
            raise ValueError(f"{path}: degree {n}, order {m} outside 1..{degree}")
        (g if m >= 0 else h)[:, n, abs(m)] = values[2:]
    return years, g, h


@njit(cache=True)
def legendre(theta, nmax, P, dP):
    """Schmidt semi-normalized P_n^m(cos theta) and dP_n^m/dtheta into P[n, m], dP[n, m]."""
    c, s = math.cos(theta), math.sin(theta)
    P[0, 0], dP[0, 0] = 1.0, 0.0
    if nmax >= 1:
        P[1, 0], dP[1, 0] = c, -s
        P[1, 1], dP[1, 1] = s, c
    for n in range(2, nmax + 1):
        k = math.sqrt((2.0 * n - 1.0) / (2.0 * n))
        P[n, n] = k * s * P[n - 1, n - 1]
        dP[n, n] = k * (s * dP[n - 1, n - 1] + c * P[n - 1, n - 1])
        for m in range(n):
            a = math.sqrt(n * n - m * m)
            b = math.sqrt((n - 1.0) * (n - 1.0) - m * m) if n - 1 > m else 0.0
            p2 = P[n - 2, m] if n - 2 >= m else 0.0
            dp2 = dP[n - 2, m] if n - 2 >= m else 0.0
            P[n, m] = ((2.0 * n - 1.0) * c * P[n - 1, m] - b * p2) / a
            dP[n, m] = ((2.0 * n - 1.0) * (c * dP[n - 1, m] - s * P[n - 1, m]) - b * dp2) / a


@njit(cache=True)
def field_spherical(r, theta, phi, g, h, nmax):
    """(B_r, B_theta, B_phi) in the unit of g, h at geocentric radius r (m), colatitude theta and
    east longitude phi (rad). At the poles B_phi is the limit (theta held 1e-9 rad off)."""
    if math.sin(theta) < 1e-9:
        theta = 1e-9 if theta < 1.0 else math.pi - 1e-9
    P = np.zeros((nmax + 1, nmax + 1))
    dP = np.zeros((nmax + 1, nmax + 1))
    legendre(theta, nmax, P, dP)
    s = math.sin(theta)
    ratio = R_REF / r
    rn = ratio * ratio
    br = bt = bp = 0.0
    for n in range(1, nmax + 1):
        rn *= ratio  # (a/r)^(n+2)
        for m in range(n + 1):
            cm, sm = math.cos(m * phi), math.sin(m * phi)
            e = g[n, m] * cm + h[n, m] * sm
            br += (n + 1.0) * rn * e * P[n, m]
            bt -= rn * e * dP[n, m]
            bp += rn * m * (g[n, m] * sm - h[n, m] * cm) * P[n, m]
    return br, bt, bp / s


@njit(cache=True)
def field_cartesian(x, y, z, g, h, nmax):
    """B in the Earth-fixed Cartesian frame (unit of g, h) at the Earth-fixed position (m)."""
    rho = math.sqrt(x * x + y * y)
    r = math.sqrt(rho * rho + z * z)
    theta = math.atan2(rho, z)
    phi = math.atan2(y, x)
    br, bt, bp = field_spherical(r, theta, phi, g, h, nmax)
    st, ct, sp, cp = math.sin(theta), math.cos(theta), math.sin(phi), math.cos(phi)
    return (br * st * cp + bt * ct * cp - bp * sp,
            br * st * sp + bt * ct * sp + bp * cp,
            br * ct - bt * st)


class IgrfField(magnetic_field.MagneticField):
    """IGRF-14 to `degree` (1..13) in N and B at `t` seconds after `epoch`; the tilted dipole's
    interface (field_N, field_B, advance_to, get_state, set_state). `secular_variation` false
    holds the coefficients of the epoch's date for the whole run."""

    _tables = {}

    def __init__(self, epoch=time_utils.DEFAULT_EPOCH, t0=0.0, secular_variation=True, degree=MAX_DEGREE,
                 coefficient_file=COEFFICIENT_FILE):
        super().__init__(epoch, t0, secular_variation)
        if isinstance(degree, bool) or int(degree) != degree or not 1 <= int(degree) <= MAX_DEGREE:
            raise ValueError(f"degree = {degree!r} must be an integer in [1, {MAX_DEGREE}]")
        self.degree = int(degree)
        if coefficient_file not in self._tables:
            years, g, h = read_shc(coefficient_file)
            seconds = [time_utils.seconds_since_j2000(_dt.datetime(int(y), 1, 1, tzinfo=_dt.timezone.utc))
                       for y in years]
            self._tables[coefficient_file] = (seconds, g, h)
        self._seconds, self._g, self._h = self._tables[coefficient_file]
        if self._s_j2000 + self.t < self._seconds[0]:
            raise ValueError(f"epoch = {epoch!r}: IGRF-14 starts in 1900")
        self._igrf_cache = (None, None)

    def gauss_coefficients(self, t=None):
        """(g, h) arrays [n, m] in nT at time t (linear between the file's epochs)."""
        t = self.t if t is None else t
        if not self.secular_variation:
            t = 0.0
        if self._igrf_cache[0] == t:
            return self._igrf_cache[1]
        s = self._s_j2000 + t
        if s < self._seconds[0]:
            raise ValueError(f"time {t} s is before 1900, where IGRF-14 starts")
        k = min(max(bisect.bisect_right(self._seconds, s) - 1, 0), len(self._seconds) - 2)
        w = (s - self._seconds[k]) / (self._seconds[k + 1] - self._seconds[k])  # > 1 after 2030: extrapolated
        g = self._g[k] + w * (self._g[k + 1] - self._g[k])
        h = self._h[k] + w * (self._h[k + 1] - self._h[k])
        self._igrf_cache = (t, (g, h))
        return g, h

    def coefficients(self, t=None):
        """(g10, g11, h11) in nT at time t: the dipole part, for comparison with the tilted dipole."""
        g, h = self.gauss_coefficients(t)
        return (float(g[1, 0]), float(g[1, 1]), float(h[1, 1]))

    def field_ecef(self, r_ecef, t=None):
        x, y, z = (float(c) for c in r_ecef)
        if not (x * x + y * y + z * z > 0.0) or not all(math.isfinite(c) for c in (x, y, z)):
            raise ValueError(f"r_BN_N {[x, y, z]} must be a finite, non-zero position")
        g, h = self.gauss_coefficients(t)
        b = field_cartesian(x, y, z, g, h, self.degree)
        nt = magnetic_field.NT
        return (b[0] * nt, b[1] * nt, b[2] * nt)

    def set_state(self, state):
        super().set_state(state)
        self._igrf_cache = (None, None)
