"""Attitude and navigation sensors with seeded, reproducible noise (thesis section 3.3.1).

NEIGHBOR determines the host's attitude from a horizon sensor (nadir vector) and a digital sun
sensor, propagates it with a 3-axis gyro, and takes position and time from a GPS receiver.
Each sensor here is the ideal measurement of the true state plus random errors:

- HorizonSensor: nadir_B = A(q_BN) (-r_BN_N / |r_BN_N|), rotated by a small random angle
  theta ~ N(0, sigma) about a random axis perpendicular to it (uniform azimuth), so the error
  angle has RMS sigma.
- SunSensor: sun_B = A(q_BN) (r_SN_N - r_BN_N) / |r_SN_N - r_BN_N| with the same error model;
  valid only when sunlit and the true Sun direction is within the half field of view of the
  boresight; zeros when invalid.
- Gyro: omega_meas_B = omega_BN_B + bias + sigma n, n ~ N(0, I3) per sample.
- GpsReceiver: r_meas_N = r_BN_N + sigma n, n ~ N(0, I3) per sample, plus the time.

Noise comes from numpy.random.default_rng(seed). The sample in use is drawn when the model is
built (the sample for the start time) and then once per step (`step`), so the outputs at a
communication point are f(current inputs, current sample). Samples are drawn as standard
normals and uniforms and scaled by sigma afterwards, so the random stream does not depend on
sigma (sigma = 0 gives the exact measurement). get_state/set_state capture the generator
state (rng.bit_generator.state, a JSON-able dict) and the current sample. The gyro draws its
samples a block at a time (the same samples, see Gyro).
"""
import math

import numpy as np

from ..core import rotations, state_views
from ..core.checks import finite_vector
from ..core.jit import njit

TWO_PI = 2.0 * math.pi


def check_sigma(name, value, unit):
    value = float(value)
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError(f"{name} = {value!r} must be a finite number >= 0 ({unit})")
    return value


def check_seed(seed):
    if isinstance(seed, bool) or int(seed) != seed or not (0 <= int(seed) < 2 ** 63):
        raise ValueError(f"seed = {seed!r} must be an integer in [0, 2**63)")
    return int(seed)


def unit_vector(v, what):
    n = rotations.norm(v)
    if not math.isfinite(n) or n == 0.0:
        raise ValueError(f"{what} {list(v)} has zero or non-finite norm")
    return (v[0] / n, v[1] / n, v[2] / n)


def rotate_vector(A, v):
    """A v for a 3x3 nested tuple A."""
    return (A[0][0] * v[0] + A[0][1] * v[1] + A[0][2] * v[2],
            A[1][0] * v[0] + A[1][1] * v[1] + A[1][2] * v[2],
            A[2][0] * v[0] + A[2][1] * v[1] + A[2][2] * v[2])


def perpendicular_basis(b):
    """Two unit vectors e1, e2 with (e1, e2, b) right-handed and orthonormal (b a unit vector)."""
    ax = [abs(x) for x in b]
    k = ax.index(min(ax))  # the coordinate axis least aligned with b
    axis = [0.0, 0.0, 0.0]
    axis[k] = 1.0
    e1 = unit_vector(rotations.cross(b, axis), "perpendicular")
    return e1, rotations.cross(b, e1)


def perturb(b, angle, azimuth):
    """Rotate unit vector b by `angle` (rad) about the axis perpendicular to b at `azimuth`
    (rad) in the plane perpendicular to b: b' = b cos(angle) + (a x b) sin(angle)."""
    if angle == 0.0:
        return tuple(b)
    e1, e2 = perpendicular_basis(b)
    ca, sa = math.cos(azimuth), math.sin(azimuth)
    a = (ca * e1[0] + sa * e2[0], ca * e1[1] + sa * e2[1], ca * e1[2] + sa * e2[2])
    axb = rotations.cross(a, b)
    c, s = math.cos(angle), math.sin(angle)
    return (b[0] * c + axb[0] * s, b[1] * c + axb[1] * s, b[2] * c + axb[2] * s)


class _Seeded:
    """Random generator plus the current sample; subclasses define _draw(). `operating_time`:
    the sum of the steps taken (a host that steps a sensor only while it is powered counts its
    powered time), which the sensors' faults are timed by."""

    def __init__(self, seed):
        self.seed = check_seed(seed)
        self.rng = np.random.default_rng(self.seed)
        self.operating_time = 0.0
        self.sample = self._draw()

    def step(self, h=None):
        """Advance to the next communication point, h seconds of operation after the last: draw
        a new noise sample."""
        if h is not None:
            self.operating_time += h
        self.sample = self._draw()

    def get_state(self):
        return {"rng": self.rng.bit_generator.state, "sample": list(self.sample), "operating_time": self.operating_time}

    def set_state(self, state):
        self.rng.bit_generator.state = state["rng"]
        self.sample = tuple(float(x) for x in state["sample"])
        self.operating_time = float(state["operating_time"])


class _VectorSensor(_Seeded):
    """Direction sensor: error rotation angle ~ N(0, sigma) about a random perpendicular axis."""

    def __init__(self, sigma, seed):
        self.sigma = check_sigma("sigma", sigma, "rad")
        super().__init__(seed)

    def _draw(self):
        return (float(self.rng.standard_normal()), float(self.rng.uniform(0.0, TWO_PI)))

    def _measure(self, true_B):
        return perturb(true_B, self.sigma * self.sample[0], self.sample[1])


class HorizonSensor(_VectorSensor):
    """Nadir vector in B from a horizon sensor (thesis 3.3.1, CubeSpace CubeIR [40])."""

    def __init__(self, sigma=math.radians(0.25), seed=0):
        super().__init__(sigma, seed)

    def true_nadir(self, r_BN_N, q_BN):
        r = finite_vector(r_BN_N, 3, "r_BN_N")
        n = rotations.norm(r)
        if n == 0.0:
            return None
        q = rotations.normalized(finite_vector(q_BN, 4, "q_BN"), "q_BN")
        return rotate_vector(rotations.attitude_matrix(q), (-r[0] / n, -r[1] / n, -r[2] / n))

    def measure(self, r_BN_N, q_BN):
        """(nadir_B, valid); invalid (zeros) only for a zero position."""
        true_B = self.true_nadir(r_BN_N, q_BN)
        if true_B is None:
            return (0.0, 0.0, 0.0), False
        return self._measure(true_B), True


class SunSensor(_VectorSensor):
    """Sun vector in B from a digital sun sensor (thesis 3.3.1, Solar MEMS nanoSSOC-D60 [43]:
    +-60 deg field of view, accuracy < 0.5 deg 3 sigma).

    A fault: once the sensor has operated `fail_time` seconds (the sum of its steps; None: never),
    no valid sample (a dead sensor, or one blinded for good, e.g. a degraded detector)."""

    def __init__(self, boresight_B=(1.0, 0.0, 0.0), half_fov=math.radians(60.0), sigma=math.radians(0.5) / 3.0,
                 seed=0, fail_time=None):
        b = finite_vector(boresight_B, 3, "boresight_B")
        if rotations.norm(b) == 0.0:
            raise ValueError("boresight_B must be a non-zero vector")
        self.boresight = unit_vector(b, "boresight_B")
        half_fov = float(half_fov)
        if not (math.isfinite(half_fov) and 0.0 < half_fov <= math.pi):
            raise ValueError(f"half_fov = {half_fov!r} must be in (0, pi] rad")
        self.half_fov = half_fov
        self.cos_half_fov = math.cos(half_fov)
        self.fail_time = None if fail_time is None else check_sigma("fail_time", fail_time, "s")
        super().__init__(sigma, seed)

    @property
    def failed(self):
        return self.fail_time is not None and self.operating_time >= self.fail_time - 1e-9

    def true_sun(self, r_SN_N, r_BN_N, q_BN):
        s = finite_vector(r_SN_N, 3, "r_SN_N")
        r = finite_vector(r_BN_N, 3, "r_BN_N")
        d = (s[0] - r[0], s[1] - r[1], s[2] - r[2])
        n = rotations.norm(d)
        if n == 0.0:
            return None
        q = rotations.normalized(finite_vector(q_BN, 4, "q_BN"), "q_BN")
        return rotate_vector(rotations.attitude_matrix(q), (d[0] / n, d[1] / n, d[2] / n))

    def in_fov(self, sun_B):
        return rotations.dot(sun_B, self.boresight) >= self.cos_half_fov

    def measure(self, r_SN_N, r_BN_N, q_BN, sunlit=True):
        """(sun_B, valid): valid when sunlit, the true Sun is inside the field of view and the
        sensor has not failed."""
        true_B = self.true_sun(r_SN_N, r_BN_N, q_BN)
        if not sunlit or true_B is None or self.failed or not self.in_fov(true_B):
            return (0.0, 0.0, 0.0), False
        return self._measure(true_B), True


NOISE_BLOCK = 1024  # gyro samples drawn at once: the generator gives the numbers of one draw a step
# Gyro.x, the state its FMU's native step reads and writes (gyro_into): the noise scale, the
# operating time, the jump flag, the bias (3), the sample (3), the next row of the noise block
_SCALE, _TIME, _JUMPED, _BIAS, _SAMPLE, _ROW = 0, 1, 2, 3, 6, 9


class Gyro(_Seeded):
    """3-axis rate gyro (thesis 3.3.1, Bosch BMG160 [44]): omega + bias + white noise.

    `sigma` is the noise of one sample. With `sigma_sample_time` > 0 it is the noise at that
    sampling step, and a sample at the communication step h has sigma sqrt(sigma_sample_time / h)
    (white rate noise of a fixed density over the Nyquist band): the same gyro sampled at 15 ms
    or 0.1 s has the same angle random walk, sigma sqrt(sigma_sample_time) in rad/s^0.5. Until
    the first step (h unknown) the sample has sigma.

    A fault: `bias_jump` (rad/s) is added to the bias once the gyro has operated `jump_time`
    seconds (the sum of its steps: a host that steps it only while it is powered counts its
    powered time), a sudden bias shift such as a shock or a temperature step gives a MEMS gyro.
    Zero (the default) is no fault.

    The samples are drawn NOISE_BLOCK at a time into `block` (numpy's standard normals come one
    after the other from the generator: the same numbers as one draw a step), and the state lives
    in the array `x` (the attributes are properties over it), so that the FMU's native step can
    take a sample without Python; get_state gives the generator's state at the sample in use."""

    def __init__(self, bias=(0.0, 0.0, 0.0), sigma=5.5e-4, seed=0, sigma_sample_time=0.0, bias_jump=(0.0, 0.0, 0.0),
                 jump_time=0.0):
        self.x = np.zeros(10)
        self.x[_ROW] = NOISE_BLOCK  # no block drawn yet
        self.block = np.zeros((NOISE_BLOCK, 3))
        self._block_state = None  # the generator's state before the block was drawn
        self.bias = finite_vector(bias, 3, "bias")
        self.sigma = check_sigma("sigma", sigma, "rad/s")
        self.sigma_sample_time = check_sigma("sigma_sample_time", sigma_sample_time, "s")
        self.bias_jump = finite_vector(bias_jump, 3, "bias_jump")
        self.jump_time = check_sigma("jump_time", jump_time, "s")
        self.constants = np.array([self.sigma, self.sigma_sample_time, self.jump_time, *self.bias_jump])
        self.scale = self.sigma
        self.jumped = False
        super().__init__(seed)

    scale = state_views.view(_SCALE)
    operating_time = state_views.view(_TIME)
    jumped = state_views.flag(_JUMPED)
    bias = state_views.view(_BIAS, 3)
    sample = state_views.view(_SAMPLE, 3)

    def _draw(self):
        row = int(self.x[_ROW])
        if row >= NOISE_BLOCK:
            self._block_state = self.rng.bit_generator.state
            self.block[:] = self.rng.standard_normal(3 * NOISE_BLOCK).reshape(NOISE_BLOCK, 3)
            row = 0
        self.x[_ROW] = row + 1
        return tuple(self.block[row].tolist())

    def step(self, h=None):
        """The next sample, h seconds of operation after the last."""
        if self.sigma_sample_time > 0.0 and h is not None and h > 0.0:
            self.scale = self.sigma * math.sqrt(self.sigma_sample_time / h)
        super().step(h)
        if not self.jumped and any(self.bias_jump) and self.operating_time >= self.jump_time - 1e-9:
            self.jumped = True
            self.bias = tuple(b + j for b, j in zip(self.bias, self.bias_jump))

    def measure(self, omega_BN_B):
        w = finite_vector(omega_BN_B, 3, "omega_BN_B")
        b, n, s = self.bias, self.sample, self.scale
        return (w[0] + b[0] + s * n[0], w[1] + b[1] + s * n[1], w[2] + b[2] + s * n[2])

    def _generator_state(self):
        """The generator's state after the sample in use (as if it had been drawn alone)."""
        row = int(self.x[_ROW])
        if self._block_state is None or row >= NOISE_BLOCK:
            return self.rng.bit_generator.state
        replay = np.random.Generator(type(self.rng.bit_generator)())
        replay.bit_generator.state = self._block_state
        replay.standard_normal(3 * row)
        return replay.bit_generator.state

    def get_state(self):
        return {**super().get_state(), "rng": self._generator_state(), "scale": self.scale, "jumped": self.jumped,
                "bias": list(self.bias)}

    def set_state(self, state):
        super().set_state(state)
        self.x[_ROW], self._block_state = NOISE_BLOCK, None  # the next sample from the restored generator
        self.scale = float(state["scale"])
        self.jumped = bool(state["jumped"])
        self.bias = tuple(float(x) for x in state["bias"])


@njit(cache=True, plain_first=True)
def gyro_into(c, x, block, values, inputs, outputs, h, stepping):
    """Gyro's FMU step on its constants c (sigma, sigma_sample_time, jump_time, bias_jump), state x
    and noise block (flat, 3 a row): with `stepping`, step(h) with the block's next row; then
    values[outputs] = measure(values[inputs]). The same operations as those methods. Returns 0;
    1 when the block is used up (nothing changed: the Python step draws the next); 2 when the rate
    is not finite (stepped, nothing written: the Python publish raises the error)."""
    if stepping:
        row = int(x[_ROW])
        if 3 * row >= block.size:
            return 1
        if c[1] > 0.0 and h > 0.0:
            x[_SCALE] = c[0] * math.sqrt(c[1] / h)
        x[_TIME] += h
        for i in range(3):
            x[_SAMPLE + i] = block[3 * row + i]
        x[_ROW] = row + 1
        if x[_JUMPED] == 0.0 and (c[3] != 0.0 or c[4] != 0.0 or c[5] != 0.0) and x[_TIME] >= c[2] - 1e-9:
            x[_JUMPED] = 1.0
            for i in range(3):
                x[_BIAS + i] = x[_BIAS + i] + c[3 + i]
    for i in range(3):
        if not math.isfinite(values[inputs[i]]):
            return 2
    for i in range(3):
        values[outputs[i]] = values[inputs[i]] + x[_BIAS + i] + x[_SCALE] * x[_SAMPLE + i]
    return 0


class GpsReceiver(_Seeded):
    """GPS position and time (thesis 3.3.1, NovAtel OEM7700 [45]: 1.5 m RMS single point)."""

    def __init__(self, sigma=1.5, seed=0, available=True, start_time=0.0):
        self.sigma = check_sigma("sigma", sigma, "m")
        self.available = bool(available)
        start_time = float(start_time)
        if not math.isfinite(start_time):
            raise ValueError(f"start_time = {start_time!r} must be finite (s)")
        self.time = start_time
        super().__init__(seed)

    def _draw(self):
        return tuple(self.rng.standard_normal(3).tolist())

    def step(self, h, new_time=None):
        self.time = float(new_time) if new_time is not None else self.time + h
        super().step(h)

    def measure(self, r_BN_N):
        """(r_meas_N, valid): zeros when the receiver is unavailable."""
        r = finite_vector(r_BN_N, 3, "r_BN_N")
        if not self.available:
            return (0.0, 0.0, 0.0), False
        n, s = self.sample, self.sigma
        return (r[0] + s * n[0], r[1] + s * n[1], r[2] + s * n[2]), True

    def get_state(self):
        return {**super().get_state(), "time": self.time}

    def set_state(self, state):
        super().set_state(state)
        self.time = float(state["time"])
