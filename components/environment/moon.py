"""Moon position relative to Earth's centre: the low-precision series of Montenbruck and Gill,
Satellite Orbits (2000), section 3.3.2, Eq. 3.47-3.48 (after Brown's lunar theory as truncated in
the Astronomical Almanac), which the authors give as good to a few arcminutes in longitude and
latitude and about 500 km in distance: enough for the Moon's third-body acceleration on a LEO
spacecraft (about 1e-6 m/s^2 in all; a 0.1 deg direction error changes it by some 1e-9 m/s^2).

    T  = Julian centuries since J2000 (UTC for TT, as components.environment.sun)
    L0 = 218.31617 + 481267.88088 T - 1.3972 T deg      mean longitude (referred to J2000's equinox)
    l  = 134.96292 + 477198.86753 T deg                  Moon's mean anomaly
    l' = 357.52543 + 35999.04944 T deg                   Sun's mean anomaly
    F  = 93.27283 + 483202.01873 T deg                   mean distance from the ascending node
    D  = 297.85027 + 445267.11135 T deg                  difference of the Sun's and Moon's longitudes

ecliptic longitude, latitude and distance by the series in `moon_position`, then rotated from the
ecliptic to the equator by the J2000 obliquity 23.43929111 deg. The result is referred to the
J2000 equator and equinox, the product's N frame. Output in m.
"""
import math

from ..core.jit import njit

ARCSEC = math.pi / (180.0 * 3600.0)
DEG = math.pi / 180.0
OBLIQUITY_J2000 = 23.43929111 * DEG


@njit(cache=True)
def moon_position(T):
    """(x, y, z) of the Moon relative to the Earth in m, T in Julian centuries since J2000."""
    L0 = (218.31617 + 481267.88088 * T - 1.3972 * T) * DEG
    l = (134.96292 + 477198.86753 * T) * DEG  # noqa: E741 - the series' own name
    lp = (357.52543 + 35999.04944 * T) * DEG
    F = (93.27283 + 483202.01873 * T) * DEG
    D = (297.85027 + 445267.11135 * T) * DEG
    lam = L0 + ARCSEC * (22640.0 * math.sin(l) + 769.0 * math.sin(2 * l) - 4586.0 * math.sin(l - 2 * D)
                         + 2370.0 * math.sin(2 * D) - 668.0 * math.sin(lp) - 412.0 * math.sin(2 * F)
                         - 212.0 * math.sin(2 * l - 2 * D) - 206.0 * math.sin(l + lp - 2 * D)
                         + 192.0 * math.sin(l + 2 * D) - 165.0 * math.sin(lp - 2 * D) + 148.0 * math.sin(l - lp)
                         - 125.0 * math.sin(D) - 110.0 * math.sin(l + lp) - 55.0 * math.sin(2 * F - 2 * D))
    beta = ARCSEC * (18520.0 * math.sin(F + lam - L0 + ARCSEC * (412.0 * math.sin(2 * F) + 541.0 * math.sin(lp)))
                     - 526.0 * math.sin(F - 2 * D) + 44.0 * math.sin(l + F - 2 * D) - 31.0 * math.sin(-l + F - 2 * D)
                     - 25.0 * math.sin(-2 * l + F) - 23.0 * math.sin(lp + F - 2 * D) + 21.0 * math.sin(-l + F)
                     + 11.0 * math.sin(-lp + F - 2 * D))
    r = 1e3 * (385000.0 - 20905.0 * math.cos(l) - 3699.0 * math.cos(2 * D - l) - 2956.0 * math.cos(2 * D)
               - 570.0 * math.cos(2 * l) + 246.0 * math.cos(2 * l - 2 * D) - 205.0 * math.cos(lp - 2 * D)
               - 171.0 * math.cos(l + 2 * D) - 152.0 * math.cos(l + lp - 2 * D))
    xe = r * math.cos(lam) * math.cos(beta)
    ye = r * math.sin(lam) * math.cos(beta)
    ze = r * math.sin(beta)
    ce, se = math.cos(OBLIQUITY_J2000), math.sin(OBLIQUITY_J2000)
    return xe, ce * ye - se * ze, se * ye + ce * ze
