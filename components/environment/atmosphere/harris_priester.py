"""Harris-Priester atmosphere: Montenbruck and Gill, Satellite Orbits, section 3.5.2 and
Table 3.8 (mean solar activity; as in Orekit HarrisPriester). See the package docstring for the
bulge, the exponent n and the extrapolation outside 100-1000 km."""
import math

import numpy as np

from ...core.jit import njit
from ...core.time_utils import DAYS_PER_CENTURY, J2000_JD
from .base import DensityModel, geodetic, sun_position_au_nb

# ---- Harris-Priester (Montenbruck and Gill Table 3.8) -----------------------------------------
# altitude km, minimum density, maximum density (kg/m^3), mean solar activity
HARRIS_PRIESTER_TABLE = (
    (100, 4.974e-07, 4.974e-07), (120, 2.490e-08, 2.490e-08), (130, 8.377e-09, 8.710e-09),
    (140, 3.899e-09, 4.059e-09), (150, 2.122e-09, 2.215e-09), (160, 1.263e-09, 1.344e-09),
    (170, 8.008e-10, 8.758e-10), (180, 5.283e-10, 6.010e-10), (190, 3.617e-10, 4.297e-10),
    (200, 2.557e-10, 3.162e-10), (210, 1.839e-10, 2.396e-10), (220, 1.341e-10, 1.853e-10),
    (230, 9.949e-11, 1.455e-10), (240, 7.488e-11, 1.157e-10), (250, 5.709e-11, 9.308e-11),
    (260, 4.403e-11, 7.555e-11), (270, 3.430e-11, 6.182e-11), (280, 2.697e-11, 5.095e-11),
    (290, 2.139e-11, 4.226e-11), (300, 1.708e-11, 3.526e-11), (320, 1.099e-11, 2.511e-11),
    (340, 7.214e-12, 1.819e-11), (360, 4.824e-12, 1.337e-11), (380, 3.274e-12, 9.955e-12),
    (400, 2.249e-12, 7.492e-12), (420, 1.558e-12, 5.684e-12), (440, 1.091e-12, 4.355e-12),
    (460, 7.701e-13, 3.362e-12), (480, 5.474e-13, 2.612e-12), (500, 3.916e-13, 2.042e-12),
    (520, 2.819e-13, 1.605e-12), (540, 2.042e-13, 1.267e-12), (560, 1.488e-13, 1.005e-12),
    (580, 1.092e-13, 7.997e-13), (600, 8.070e-14, 6.390e-13), (620, 6.012e-14, 5.123e-13),
    (640, 4.519e-14, 4.121e-13), (660, 3.430e-14, 3.325e-13), (680, 2.632e-14, 2.691e-13),
    (700, 2.043e-14, 2.185e-13), (720, 1.607e-14, 1.779e-13), (740, 1.281e-14, 1.452e-13),
    (760, 1.036e-14, 1.190e-13), (780, 8.496e-15, 9.776e-14), (800, 7.069e-15, 8.059e-14),
    (840, 4.680e-15, 5.741e-14), (880, 3.200e-15, 4.210e-14), (920, 2.210e-15, 3.130e-14),
    (960, 1.560e-15, 2.360e-14), (1000, 1.150e-15, 1.810e-14),
)
HP_LAG = math.radians(30.0)  # the bulge apex leads the Sun by 30 deg in right ascension (about 2 h local time)
HP_EXPONENT_RANGE = (2.0, 6.0)


def hp_exponent_from_inclination(inclination):
    """n = 2 + 4 i'/90 deg with i' = min(i, 180 deg - i): 2 equatorial, 6 polar."""
    i = float(inclination)
    if not (0.0 <= i <= math.pi):
        raise ValueError(f"inclination = {inclination!r} rad must be in [0, pi]")
    i = min(i, math.pi - i)
    return 2.0 + 4.0 * i / (math.pi / 2.0)


@njit(cache=True)
def harris_priester_kernel(r, jd, data):
    h_tab, rho_min, rho_max, n, lag = data
    h = geodetic(r, jd)[2]
    m = h_tab.shape[0]
    i = np.searchsorted(h_tab, h, side="right") - 1
    if i < 0:
        i = 0
    if i > m - 2:
        i = m - 2
    dh = h_tab[i] - h
    hm = (h_tab[i] - h_tab[i + 1]) / math.log(rho_min[i + 1] / rho_min[i])
    hx = (h_tab[i] - h_tab[i + 1]) / math.log(rho_max[i + 1] / rho_max[i])
    dmin = rho_min[i] * math.exp(dh / hm)
    dmax = rho_max[i] * math.exp(dh / hx)
    s = sun_position_au_nb((jd - J2000_JD) / DAYS_PER_CENTURY)
    ra = math.atan2(s[1], s[0])
    dec = math.atan2(s[2], math.sqrt(s[0] * s[0] + s[1] * s[1]))
    cd = math.cos(dec)
    ex, ey, ez = cd * math.cos(ra + lag), cd * math.sin(ra + lag), math.sin(dec)
    rr = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    c_psi = (ex * r[0] + ey * r[1] + ez * r[2]) / rr
    c2 = 0.5 * (1.0 + c_psi)  # cos^2(psi/2)
    if c2 < 0.0:
        c2 = 0.0
    return dmin + (dmax - dmin) * c2 ** (0.5 * n)


class HarrisPriesterModel(DensityModel):
    name = "harris_priester"

    def __init__(self, inclination=None, hp_exponent=None):
        if hp_exponent is not None:
            n = float(hp_exponent)
            lo, hi = HP_EXPONENT_RANGE
            if not (lo <= n <= hi):
                raise ValueError(f"hp_exponent = {hp_exponent!r} must be in [{lo:g}, {hi:g}]")
        elif inclination is not None:
            n = hp_exponent_from_inclination(inclination)
        else:
            n = 4.0
        self.exponent = n
        t = np.array(HARRIS_PRIESTER_TABLE, dtype=np.float64)
        self.kernel = harris_priester_kernel
        self.kernel_data = (t[:, 0] * 1e3, t[:, 1].copy(), t[:, 2].copy(), n, HP_LAG)
