"""Pointing guidance: the reference attitude of a pointing mode and the attitude tracking error
the feedback laws take (Basilisk's attitude guidance chain, one function per module).

Modes (the `mode` input of the PointingGuidance FMU):
  0 INERTIAL  a fixed reference attitude sigma_R0N, at rest in N (Basilisk inertial3D);
  1 NADIR     the Hill frame (Basilisk hillPoint): x along the position (zenith; -x points at
              nadir), z along the orbit normal r x v, y completing it (along track for a
              circular orbit); rate h / r^2 about z and its derivative -2 (v . r_hat) / r times it;
  2 VELOCITY  the velocity frame (Basilisk velocityPoint): y along v, z along r x v, x = y x z;
              rate and acceleration of the flight-path frame of a Kepler orbit with mu;
  3 SUN_SAFE  point the body axis sun_axis_B at the measured Sun heading (Basilisk sunSafePoint),
              spinning about it at sun_spin_rate; with no valid Sun heading the attitude error is
              zero and the body is driven to the search rate search_rate_B;
  4 TARGET    point the body axis boresight_B at a ground target (Basilisk locationPointing,
              target given by geodetic latitude, longitude and height, rotating with the Earth):
              the error rate is the MRP error's finite difference over the last step.

For modes 0-2 the tracking error is Basilisk's attTrackingError: an optional body offset sigma_R0R
(the corrected reference R = R0 rotated by -sigma_R0R, e.g. to point -z rather than -x at nadir),
sigma_BR = sigma_BN - sigma_RN (as rotations, short set), omega_RN_B = [BN] omega_RN_N,
omega_BR_B = omega_BN_B - omega_RN_B, domega_RN_B = [BN] domega_RN_N. Modes 3 and 4 compute the
error directly, as their Basilisk modules do (the offset does not apply).

Everything is N-frame vectors and scalar-last quaternions q_BN in, MRPs out (components.core.mrp).
"""
import math

import numpy as np

from ..core import mrp
from ..core.checks import finite_vector, positive
from ..core.constants import MU_EARTH, WGS84_A, WGS84_F
from ..core.time_utils import julian_date
from ..environment import geodesy

INERTIAL, NADIR, VELOCITY, SUN_SAFE, TARGET = range(5)
MODE_NAMES = ("inertial", "nadir", "velocity", "sun-safe", "target")
DEFAULT_SMALL_ANGLE = math.radians(0.1)  # below it the pointing error is taken as zero (Basilisk's use)
DEFAULT_MIN_SUN_NORM = 0.1  # a measured Sun heading shorter than this is "Sun not seen"


def _dcm(sigma):
    return np.array(mrp.to_dcm(sigma))


def sigma_of_dcm(C):
    return mrp.from_dcm(C.tolist(), tol=1e-6)


def subtract(sigma_BN, sigma_RN):
    """sigma_BR (short set) of [BR] = [BN] [RN]^T."""
    return sigma_of_dcm(_dcm(sigma_BN) @ _dcm(sigma_RN).T)


def _orthogonal_axis(axis):
    """Basilisk's eHat180_B: axis x x_hat, or axis x y_hat when axis is near x."""
    e = np.cross(axis, (1.0, 0.0, 0.0))
    if np.linalg.norm(e) < 0.1:
        e = np.cross(axis, (0.0, 1.0, 0.0))
    return e / np.linalg.norm(e)


def _unit(v, what):
    v = np.array(finite_vector(v, 3, what))
    n = np.linalg.norm(v)
    if n < 1e-12:
        raise ValueError(f"{what} {v.tolist()} must be a non-zero 3-vector (it is normalized)")
    return v / n


def hill_frame(r_N, v_N):
    """([RN], omega_RN_N, domega_RN_N) of the Hill frame (hillPoint)."""
    r, v = np.asarray(r_N, float), np.asarray(v_N, float)
    h = np.cross(r, v)
    x = r / np.linalg.norm(r)
    z = h / np.linalg.norm(h)
    C = np.array([x, np.cross(z, x), z])
    rm, hm = np.linalg.norm(r), np.linalg.norm(h)
    dfdt = hm / (rm * rm) if rm > 1.0 else 0.0
    ddfdt2 = -2.0 * np.dot(v, x) / rm * dfdt if rm > 1.0 else 0.0
    return C, C.T @ np.array([0.0, 0.0, dfdt]), C.T @ np.array([0.0, 0.0, ddfdt2])


def velocity_frame(r_N, v_N, mu=MU_EARTH):
    """([RN], omega_RN_N, domega_RN_N) of the velocity frame (velocityPoint), the flight-path
    angle's rate from the osculating Kepler orbit: e cos f = h^2/(mu r) - 1, e sin f = (r.v) h/(mu r)."""
    r, v = np.asarray(r_N, float), np.asarray(v_N, float)
    h = np.cross(r, v)
    y = v / np.linalg.norm(v)
    z = h / np.linalg.norm(h)
    C = np.array([np.cross(y, z), y, z])
    rm, hm = np.linalg.norm(r), np.linalg.norm(h)
    w = dw = 0.0
    if rm > 1.0:
        dfdt = hm / (rm * rm)
        ddfdt2 = -2.0 * (np.dot(v, r) / (rm * rm)) * dfdt
        ecosf = hm * hm / (mu * rm) - 1.0
        esinf = np.dot(r, v) * hm / (mu * rm)
        e2 = ecosf * ecosf + esinf * esinf
        denom = 1.0 + e2 + 2.0 * ecosf
        w = dfdt * (1.0 + ecosf) / denom
        dw = ddfdt2 * (1.0 + ecosf) / denom - dfdt * dfdt * esinf * (e2 - 1.0) / (denom * denom)
    return C, C.T @ np.array([0.0, 0.0, w]), C.T @ np.array([0.0, 0.0, dw])


def tracking_error(sigma_BN, omega_BN_B, C_RN, omega_RN_N, domega_RN_N, sigma_R0R=(0.0, 0.0, 0.0)):
    """attTrackingError: (sigma_BR, omega_BR_B, omega_RN_B, domega_RN_B, sigma_RN) for the
    reference [R0N] = C_RN corrected by the offset sigma_R0R."""
    C_RN = _dcm(tuple(-s for s in sigma_R0R)) @ np.asarray(C_RN, float)
    sigma_RN = sigma_of_dcm(C_RN)
    BN = _dcm(sigma_BN)
    sigma_BR = sigma_of_dcm(BN @ C_RN.T)
    omega_RN_B = BN @ np.asarray(omega_RN_N, float)
    return (np.array(sigma_BR), np.asarray(omega_BN_B, float) - omega_RN_B, omega_RN_B,
            BN @ np.asarray(domega_RN_N, float), np.array(sigma_RN))


def sun_safe(sun_B, sun_valid, omega_BN_B, sun_axis_B, sun_spin_rate, search_rate_B, small_angle=DEFAULT_SMALL_ANGLE,
             min_sun_norm=DEFAULT_MIN_SUN_NORM):
    """sunSafePoint: (sigma_BR, omega_BR_B, omega_RN_B, domega_RN_B)."""
    s = np.asarray(sun_B, float)
    omega = np.asarray(omega_BN_B, float)
    axis = np.asarray(sun_axis_B, float)
    n = np.linalg.norm(s)
    if not sun_valid or not n > min_sun_norm:
        w_RN = np.asarray(search_rate_B, float)
        return np.zeros(3), omega - w_RN, w_RN.copy(), np.zeros(3)
    angle = math.acos(max(-1.0, min(1.0, float(np.dot(axis, s)) / n)))
    sigma = np.zeros(3)
    if angle >= small_angle:
        e = _orthogonal_axis(axis) if math.pi - angle < small_angle else np.cross(s, axis)
        sigma = math.tan(angle / 4.0) * e / np.linalg.norm(e)
        sigma = np.array(mrp.short(sigma))
    w_RN = sun_spin_rate / n * s
    return sigma, omega - w_RN, w_RN, np.zeros(3)


def target_position_N(latitude, longitude, height, epoch, t):
    """r_TN_N (m) of a point on the rotating WGS-84 Earth (geodetic latitude, longitude rad, height m)."""
    sl, cl = math.sin(latitude), math.cos(latitude)
    e2 = WGS84_F * (2.0 - WGS84_F)
    n = WGS84_A / math.sqrt(1.0 - e2 * sl * sl)
    r_E = ((n + height) * cl * math.cos(longitude), (n + height) * cl * math.sin(longitude),
           (n * (1.0 - e2) + height) * sl)
    return np.array(geodesy.earth_fixed_to_inertial(r_E, geodesy.gmst_of_jd(julian_date(epoch, t))))


def location_error(r_TN_N, r_BN_N, sigma_BN, boresight_B, small_angle=DEFAULT_SMALL_ANGLE):
    """locationPointing's MRP error sigma_BR putting boresight_B on the target, and the unit
    line of sight in B."""
    BN = _dcm(sigma_BN)
    los = BN @ (np.asarray(r_TN_N, float) - np.asarray(r_BN_N, float))
    los = los / np.linalg.norm(los)
    p = np.asarray(boresight_B, float)
    phi = math.acos(max(-1.0, min(1.0, float(np.dot(p, los)))))
    if phi < small_angle:
        return np.zeros(3), los
    e = _orthogonal_axis(p) if math.pi - phi < small_angle else np.cross(p, los)
    return -math.tan(phi / 4.0) * e / np.linalg.norm(e), los


def nadir_axis_error(q_BN, r_BN_N, axis_B=(0.0, 0.0, -1.0)):
    """The angle (rad) between the body axis axis_B and the nadir, -r_BN_N / |r_BN_N|: the true
    pointing error of a nadir-pointing spacecraft whatever its rotation about the nadir. Takes one
    attitude and position or arrays of them (rows, quaternions scalar last)."""
    q = np.atleast_2d(np.asarray(q_BN, float))
    r = np.atleast_2d(np.asarray(r_BN_N, float))
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    a = _unit(axis_B, "axis_B")
    # the axis in N: [NB] a = [BN]^T a, [BN] = (q4^2 - |v|^2) I + 2 v v^T - 2 q4 [v x]
    v, s = q[:, :3], q[:, 3:]
    axis_N = (s * s - np.sum(v * v, axis=1, keepdims=True)) * a + 2.0 * v * (v @ a)[:, None] \
        + 2.0 * s * np.cross(v, a)
    nadir = -r / np.linalg.norm(r, axis=1, keepdims=True)
    angle = np.arctan2(np.linalg.norm(np.cross(axis_N, nadir), axis=1), np.sum(axis_N * nadir, axis=1))
    return angle if np.ndim(q_BN) > 1 else float(angle[0])


class PointingGuidance:
    """The guidance of every mode with one set of parameters; the target mode's finite difference
    keeps the error at the start of the last step (step())."""

    def __init__(self, sigma_R0N=(0.0, 0.0, 0.0), sigma_R0R=(0.0, 0.0, 0.0), mu=MU_EARTH,
                 sun_axis_B=(0.0, 0.0, 1.0), sun_spin_rate=0.0, search_rate_B=(0.0, 0.0, 0.0),
                 boresight_B=(0.0, 0.0, 1.0), target_latitude=0.0, target_longitude=0.0, target_height=0.0,
                 epoch="2023-01-01T00:00:00Z", boresight_rate_damping=False, small_angle=DEFAULT_SMALL_ANGLE,
                 min_sun_norm=DEFAULT_MIN_SUN_NORM, t0=0.0):
        self.C_R0N = _dcm(finite_vector(sigma_R0N, 3, "sigma_R0N"))
        self.sigma_R0R = finite_vector(sigma_R0R, 3, "sigma_R0R")
        self.mu = positive("mu", mu, "m3/s2")
        self.sun_axis_B = _unit(sun_axis_B, "sun_axis_B")
        self.sun_spin_rate = float(sun_spin_rate)
        self.search_rate_B = np.array(finite_vector(search_rate_B, 3, "search_rate_B", "rad/s"))
        self.boresight_B = _unit(boresight_B, "boresight_B")
        if not -math.pi / 2.0 <= target_latitude <= math.pi / 2.0:
            raise ValueError(f"target_latitude = {target_latitude!r} rad must be in [-pi/2, pi/2]")
        self.target = (float(target_latitude), float(target_longitude), float(target_height))
        julian_date(epoch)  # checks the epoch
        self.epoch = epoch
        self.boresight_rate_damping = bool(boresight_rate_damping)
        self.small_angle = positive("small_angle", small_angle, "rad")
        self.min_sun_norm = positive("min_sun_norm", min_sun_norm)
        self.previous = None  # (t, sigma_BR) of the target mode's last step
        self.time = float(t0)  # simulation time (s from the epoch): the target's Earth rotation

    def reference(self, mode, r_N, v_N):
        """([R0N], omega_RN_N, domega_RN_N) of modes 0-2."""
        if mode == INERTIAL:
            return self.C_R0N, np.zeros(3), np.zeros(3)
        if mode == NADIR:
            return hill_frame(r_N, v_N)
        return velocity_frame(r_N, v_N, self.mu)

    def guidance(self, mode, q_BN, omega_BN_B, r_BN_N, v_BN_N, sun_B, sun_valid, t=None):
        """(sigma_BR, omega_BR_B, omega_RN_B, domega_RN_B, sigma_RN) in the given mode at time t
        (default: the model's time)."""
        t = self.time if t is None else t
        if mode not in range(5):
            raise ValueError(f"mode = {mode!r} must be one of 0..4 ({', '.join(MODE_NAMES)})")
        sigma_BN = mrp.from_quaternion(q_BN, short=True)
        omega = np.asarray(omega_BN_B, float)
        if mode in (INERTIAL, NADIR, VELOCITY):
            if mode != INERTIAL and (np.linalg.norm(np.cross(r_BN_N, v_BN_N)) < 1e-9):
                raise ValueError(f"the {MODE_NAMES[mode]} frame needs r_BN_N and v_BN_N that are not parallel, got "
                                 f"{list(r_BN_N)} and {list(v_BN_N)}")
            return tracking_error(sigma_BN, omega, *self.reference(mode, r_BN_N, v_BN_N), self.sigma_R0R)
        if mode == SUN_SAFE:
            out = sun_safe(sun_B, sun_valid, omega, self.sun_axis_B, self.sun_spin_rate, self.search_rate_B,
                           self.small_angle, self.min_sun_norm)
        else:
            out = self._target(sigma_BN, omega, r_BN_N, t)
        # the reference the error implies: [RN] = [RB][BN]
        sigma_RN = sigma_of_dcm(_dcm(tuple(-s for s in out[0])) @ _dcm(sigma_BN))
        return (*out, np.array(sigma_RN))

    def _target(self, sigma_BN, omega, r_BN_N, t):
        sigma_BR, los = location_error(target_position_N(*self.target, self.epoch, t), r_BN_N, sigma_BN,
                                       self.boresight_B, self.small_angle)
        omega_BR = np.zeros(3)
        if self.previous is not None and t > self.previous[0]:
            sigma_dot = (sigma_BR - self.previous[1]) / (t - self.previous[0])
            omega_BR = np.linalg.inv(_b_matrix(sigma_BR)) @ (4.0 * sigma_dot)
        if self.boresight_rate_damping:
            omega_BR = omega_BR + float(omega @ los) * los
        omega_RN = omega - omega_BR
        return sigma_BR, omega_BR, omega_RN, np.zeros(3)

    def step(self, mode, q_BN, r_BN_N, h):
        """A step of h seconds from the model's time: the target mode keeps the error at its
        start for the next finite difference."""
        t = self.time
        self.time = t + float(h)
        if mode == TARGET:
            sigma_BN = mrp.from_quaternion(q_BN, short=True)
            self.previous = (t, location_error(target_position_N(*self.target, self.epoch, t), r_BN_N, sigma_BN,
                                               self.boresight_B, self.small_angle)[0])
        else:
            self.previous = None

    def get_state(self):
        return {"time": self.time,
                "previous": None if self.previous is None else (self.previous[0], self.previous[1].tolist())}

    def set_state(self, state):
        self.time = float(state["time"])
        p = state["previous"]
        self.previous = None if p is None else (p[0], np.array(p[1]))


def _b_matrix(sigma):
    """[B(sigma)] of sigma_dot = 1/4 [B] omega (Schaub and Junkins)."""
    s = np.asarray(sigma, float)
    ss = float(s @ s)
    tilde = np.array([[0.0, -s[2], s[1]], [s[2], 0.0, -s[0]], [-s[1], s[0], 0.0]])
    return (1.0 - ss) * np.eye(3) + 2.0 * tilde + 2.0 * np.outer(s, s)
