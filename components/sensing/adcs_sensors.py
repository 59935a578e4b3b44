"""The CubeSat ADCS sensors with seeded, reproducible errors: a three-axis magnetometer, a star
tracker and an array of coarse Sun sensors with its least-squares Sun heading (the models of
Basilisk's magnetometer, starTracker, coarseSunSensor and cssWlsEst, which they equal without
noise: tests/components/sensing/test_adcs_sensors_vs_basilisk.py).

Mounting: each sensor frame S is the body frame turned by the 3-2-1 Euler angles (yaw, pitch,
roll) of its mounting, [SB] = M1(roll) M2(pitch) M3(yaw) (Basilisk's setBodyToSensorDCM); small
angles are a misalignment.

- Magnetometer: B_S = scale ([SB] B_B + bias + noise), each axis clipped to +-max_field
  (0: no limit). Noise: N(0, sigma^2) per axis per sample.
- StarTracker: the attitude of its case frame C, q_CN = [CB] [BN], turned by a noise rotation
  (N(0, sigma_cross^2) about each of the two axes across the boresight, N(0, sigma_roll^2) about
  it; the boresight is the case's +z). Invalid (the output held at its last valid value, the
  `valid` flag false) when the Sun, the Earth's disc or the Moon is within its exclusion angle
  of the boresight, or when the body rate exceeds max_rate; a new measurement every
  update_period seconds of its steps (0: at every communication point), held between them.
- CoarseSunSensorArray: up to 8 cosine sensors with normals n_i in B: signal_i = scale
  (n_i . s_B if that is >= cos(fov) else 0) x (1 AU / |r_S - r_B|)^2 x shadow_factor + bias +
  noise, clipped to [0, max_signal]; albedo is not modelled. The Sun heading is Basilisk's
  cssWlsEst: over the sensors whose signal exceeds `threshold`, the least-squares s of
  signal = [N] s with weights = the signals (three or more), the minimum-norm one (two), the
  normal itself (one), then normalized; none, or normals that do not span B: not valid.
  use_weights false: unit weights.

Noise comes from numpy.random.default_rng(seed) as in components.sensing.sensors: the sample in
use is drawn at construction and once per step, as standard normals scaled afterwards (sigma = 0
gives the exact measurement, and the stream does not depend on sigma).
"""
import math

import numpy as np

from ..core import rotations
from ..core.checks import finite_vector, positive
from ..core.constants import ASTRONOMICAL_UNIT
from .sensors import _Seeded, check_sigma

AU = ASTRONOMICAL_UNIT  # m
MAX_CSS = 8


def mounting_dcm(yaw, pitch, roll):
    """[SB] = M1(roll) M2(pitch) M3(yaw): a sensor frame turned from B by 3-2-1 Euler angles."""
    def m1(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])

    def m2(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])

    def m3(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])

    return m1(roll) @ m2(pitch) @ m3(yaw)


def _mounting(angles, what):
    return mounting_dcm(*finite_vector(angles, 3, what, "rad (3-2-1 Euler angles)"))


class Magnetometer(_Seeded):
    def __init__(self, mounting=(0.0, 0.0, 0.0), bias=(0.0, 0.0, 0.0), scale=1.0, sigma=0.0, max_field=0.0, seed=0):
        self.dcm_SB = _mounting(mounting, "mounting")
        self.bias = np.array(finite_vector(bias, 3, "bias", "T"))
        self.scale = float(scale)
        if not math.isfinite(self.scale) or self.scale == 0.0:
            raise ValueError(f"scale = {scale!r} must be a finite non-zero factor")
        self.sigma = check_sigma("sigma", sigma, "T")
        self.max_field = check_sigma("max_field", max_field, "T (0: no saturation)")
        super().__init__(seed)

    def _draw(self):
        return tuple(float(x) for x in self.rng.standard_normal(3))

    def measure(self, B_B):
        """The measured field in the sensor frame (T)."""
        B_S = self.dcm_SB @ np.asarray(finite_vector(B_B, 3, "B_B", "T"), float)
        out = self.scale * (B_S + self.bias + self.sigma * np.array(self.sample))
        if self.max_field > 0.0:
            out = np.clip(out, -self.max_field, self.max_field)
        return out


def _angle(a, b):
    return math.acos(max(-1.0, min(1.0, float(np.dot(a, b)) / (np.linalg.norm(a) * np.linalg.norm(b)))))


class StarTracker(_Seeded):
    def __init__(self, mounting=(0.0, 0.0, 0.0), sigma_cross=math.radians(10.0 / 3600.0),
                 sigma_roll=math.radians(60.0 / 3600.0), sun_exclusion=math.radians(45.0),
                 earth_exclusion=math.radians(20.0), moon_exclusion=math.radians(10.0), max_rate=math.radians(1.0),
                 update_period=0.0, earth_radius=6378137.0, seed=0):
        self.dcm_CB = _mounting(mounting, "mounting")
        self.sigma_cross = check_sigma("sigma_cross", sigma_cross, "rad")
        self.sigma_roll = check_sigma("sigma_roll", sigma_roll, "rad")
        self.exclusions = tuple(check_sigma(name, value, "rad") for name, value in (
            ("sun_exclusion", sun_exclusion), ("earth_exclusion", earth_exclusion), ("moon_exclusion", moon_exclusion)))
        self.max_rate = positive("max_rate", max_rate, "rad/s")
        self.update_period = check_sigma("update_period", update_period, "s (0: every step)")
        self.earth_radius = positive("earth_radius", earth_radius, "m")
        self.since_update = 0.0
        self.held = None  # (q_CN, valid, reasons) of the last update
        self.last_valid = (0.0, 0.0, 0.0, 1.0)  # what an invalid output holds (identity before any)
        super().__init__(seed)

    def _draw(self):
        return tuple(float(x) for x in self.rng.standard_normal(3))

    def true_attitude(self, q_BN):
        """q_CN (scalar last) of the case frame."""
        return rotations.dcm_to_quaternion(tuple(map(tuple, self.dcm_CB @ np.array(rotations.attitude_matrix(q_BN)))))

    def boresight_N(self, q_BN):
        return (self.dcm_CB @ np.array(rotations.attitude_matrix(q_BN))).T @ np.array([0.0, 0.0, 1.0])

    def blinded(self, q_BN, omega_BN_B, r_BN_N, r_SN_N, r_MN_N=None):
        """The reasons the tracker has no solution now: 'rate', 'sun', 'earth', 'moon' (empty: valid)."""
        reasons = []
        if np.linalg.norm(omega_BN_B) > self.max_rate:
            reasons.append("rate")
        z = self.boresight_N(q_BN)
        r = np.asarray(r_BN_N, float)
        if self.exclusions[0] > 0.0 and _angle(z, np.asarray(r_SN_N, float) - r) < self.exclusions[0]:
            reasons.append("sun")
        # the Earth's limb: the boresight within the exclusion angle of the Earth's disc
        rn = float(np.linalg.norm(r))
        if rn > self.earth_radius and self.exclusions[1] > 0.0:
            half_disc = math.asin(self.earth_radius / rn)
            if _angle(z, -r) < half_disc + self.exclusions[1]:
                reasons.append("earth")
        if r_MN_N is not None and self.exclusions[2] > 0.0 and np.any(r_MN_N) and \
                _angle(z, np.asarray(r_MN_N, float) - r) < self.exclusions[2]:
            reasons.append("moon")
        return reasons

    def measured(self, q_BN):
        """q_CN turned by the current noise sample (about the case's x, y: cross-boresight; z: roll)."""
        e = np.array([self.sigma_cross * self.sample[0], self.sigma_cross * self.sample[1],
                      self.sigma_roll * self.sample[2]])
        angle = float(np.linalg.norm(e))
        C = self.dcm_CB @ np.array(rotations.attitude_matrix(q_BN))
        if angle > 0.0:
            C = np.array(rotations.attitude_matrix(rotations.from_axis_angle(tuple(e / angle), angle))) @ C
        return rotations.dcm_to_quaternion(tuple(map(tuple, C)))

    def output(self, q_BN, omega_BN_B, r_BN_N, r_SN_N, r_MN_N=None):
        """(q_CN measured, valid, the reasons it is not) now: without an update period, the
        measurement at these inputs (invalid: the last valid attitude); with one, the last update's."""
        if self.update_period > 0.0 and self.held is not None:
            return self.held
        return self._update(q_BN, omega_BN_B, r_BN_N, r_SN_N, r_MN_N)

    def _update(self, q_BN, omega_BN_B, r_BN_N, r_SN_N, r_MN_N=None):
        reasons = tuple(self.blinded(q_BN, omega_BN_B, r_BN_N, r_SN_N, r_MN_N))
        if reasons:
            return self.last_valid, False, reasons
        return self.measured(q_BN), True, ()

    def step(self, h, inputs):
        """Advance h seconds from the communication point whose inputs (output()'s arguments)
        are given: an update (with a period, when it has elapsed) keeps its measurement, then a
        new noise sample is drawn."""
        if self.update_period == 0.0 or self.held is None or self.since_update >= self.update_period - 1e-9:
            self.held = self._update(*inputs)
            if self.held[1]:
                self.last_valid = self.held[0]
            self.since_update = 0.0
        self.since_update += float(h)
        super().step(h)

    def get_state(self):
        state = super().get_state()
        state.update(since_update=self.since_update, last_valid=list(self.last_valid),
                     held=None if self.held is None else [list(self.held[0]), self.held[1], list(self.held[2])])
        return state

    def set_state(self, state):
        super().set_state(state)
        self.since_update = float(state["since_update"])
        self.last_valid = tuple(state["last_valid"])
        held = state["held"]
        self.held = None if held is None else (tuple(held[0]), bool(held[1]), tuple(held[2]))


def six_face_normals():
    """The default array: a sensor on each body face, +x, -x, +y, -y, +z, -z."""
    return [(1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)]


class CoarseSunSensorArray(_Seeded):
    def __init__(self, normals=None, fov=math.radians(80.0), scale=1.0, bias=0.0, sigma=0.0, max_signal=0.0,
                 threshold=0.1, use_weights=True, seed=0):
        normals = six_face_normals() if normals is None else normals
        if not 1 <= len(normals) <= MAX_CSS:
            raise ValueError(f"css_count = {len(normals)} must be in 1..{MAX_CSS}")
        N = np.array([finite_vector(n, 3, f"normal of sensor {i + 1}", "B frame") for i, n in enumerate(normals)])
        norms = np.linalg.norm(N, axis=1)
        if np.any(norms < 1e-12):
            raise ValueError(f"normal of sensor {int(np.argmin(norms)) + 1} is zero: each must be a non-zero 3-vector")
        self.N = N / norms[:, None]
        self.count = len(self.N)
        if not 0.0 < fov <= math.pi:
            raise ValueError(f"fov = {fov!r} rad (half angle) must be in (0, pi]")
        self.fov = float(fov)
        self.scale = positive("scale", scale)
        self.bias = float(bias)
        self.sigma = check_sigma("sigma", sigma, "1")
        self.max_signal = check_sigma("max_signal", max_signal, "1 (0: no saturation)")
        self.threshold = check_sigma("threshold", threshold, "1")
        self.use_weights = bool(use_weights)
        super().__init__(seed)

    def _draw(self):
        return tuple(float(x) for x in self.rng.standard_normal(MAX_CSS))

    def sun_B(self, q_BN, r_BN_N, r_SN_N):
        """(unit Sun direction in B, Sun distance in m)."""
        d = np.asarray(r_SN_N, float) - np.asarray(r_BN_N, float)
        dist = float(np.linalg.norm(d))
        return np.array(rotations.attitude_matrix(q_BN)) @ (d / dist), dist

    def signals(self, q_BN, r_BN_N, r_SN_N, shadow_factor=1.0):
        s, dist = self.sun_B(q_BN, r_BN_N, r_SN_N)
        cosine = self.N @ s
        true = np.where(cosine >= math.cos(self.fov), cosine, 0.0) * (AU / dist) ** 2 * float(shadow_factor)
        out = self.scale * (true + self.bias + self.sigma * np.array(self.sample[:self.count]))
        out = np.maximum(out, 0.0)
        if self.max_signal > 0.0:
            out = np.minimum(out, self.max_signal)
        return out

    def heading(self, signals):
        """(unit Sun heading in B, valid, sensors used) from the signals (cssWlsEst)."""
        y = np.asarray(signals, float)
        used = y > self.threshold
        k = int(used.sum())
        if k == 0:
            return np.zeros(3), False, 0
        H, y = self.N[used], y[used]
        if k == 1:
            s = H[0].copy()
        elif k == 2:
            s = H.T @ np.linalg.solve(H @ H.T, y)  # minimum norm
        else:
            W = np.diag(y) if self.use_weights else np.eye(k)
            M = H.T @ W @ H
            if abs(np.linalg.det(M)) < 1e-12:  # the used normals do not span B
                return np.zeros(3), False, k
            s = np.linalg.solve(M, H.T @ W @ y)
        n = float(np.linalg.norm(s))
        if n < 1e-12:
            return np.zeros(3), False, k
        return s / n, True, k
