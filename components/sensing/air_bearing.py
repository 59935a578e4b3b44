"""Attitude thresholding for a spherical air-bearing (SAB) testbed without an IMU (the air-bearing note).

The "kinematics" node of the testbed receives a stream of direction cosine matrices, estimates
the angular velocity from its time derivative, extracts 3-2-1 Euler angles (yaw psi, pitch
theta, roll phi), limits pitch and roll to +-tau so that a half-sphere table stays on its cup,
rebuilds the attitude from the limited angles and publishes it.

Conventions (docs/conventions.md) and how the description maps onto them
-----------------------------------------------------------
- dcm_BN = [BN] maps N-frame components to B-frame components, v_B = [BN] v_N; it is
  components.core.rotations.attitude_matrix(q_BN) (rows: the B axes in N components). Quaternions are
  scalar last, q = [q1, q2, q3, q4].
- The description writes R = R^N_B (B to N), so its R^N_B = [BN]^T: a DCM of the description enters as its
  transpose. The description's explicit 3-2-1 matrix R_321(phi, theta, psi) = R1(phi) R2(theta)
  R3(psi) (frame rotations, first entry c_theta c_psi, (1,3) entry -s_theta) is, entry by entry,
  the matrix that maps N components to B components for the aerospace yaw-pitch-roll sequence
  (psi about n3, theta about the intermediate 2 axis, phi about b1), and the description's extraction
  (theta = asin(-R13), ...) reads the entries of exactly that matrix. In our convention that is
  [BN] = R_321(phi, theta, psi) = attitude_matrix(q_x(phi) (x) q_y(theta) (x) q_z(psi)). Read
  as B-to-N, the same matrix would describe a 1-2-3 rotation with negated angles, not a yaw
  about the table's vertical, so the description's B-to-N label is converted by the transpose and
  R_321 is used as [BN]. Yaw is a rotation about the vertical n3; pitch and roll are the tilt:
  the angle between b3 and n3 satisfies cos(tilt) = cos(theta) cos(phi) >= cos(tau)^2.

3-2-1 angles (`euler321`), atan2-based
--------------------------------------
From the quaternion of the input DCM (Shepperd's method, normalized; this also projects a
slightly non-orthonormal DCM onto the nearest rotation), with A = attitude_matrix(q):

    theta = atan2(-A13, sqrt(A11^2 + A12^2))   in [-pi/2, pi/2]
    phi   = atan2(A23, A33)                     in (-pi, pi]
    psi   = atan2(A12, A11)                     in (-pi, pi]

How this differs from the description: the description takes phi = asin(R23 / cos theta), which covers only
[-pi/2, pi/2] (a roll of 120 deg comes out as 60 deg and the three angles no longer give the
DCM back; upside down cannot be represented) and divides by cos(theta) (undefined at the
singularity, and |R23 / cos theta| can exceed 1 by rounding, a domain error); theta = asin(-R13)
loses accuracy near +-90 deg, where atan2 with sqrt(A11^2 + A12^2) does not; the description states
psi in [0, pi), but atan2 gives (-pi, pi], which is what we output.

Gimbal lock (pitch = +-90 deg): when cos(theta) = sqrt(A11^2 + A12^2) < GIMBAL_LOCK_COS (1e-7,
i.e. pitch within 1e-7 rad of +-90 deg) only psi - phi (theta = +90 deg) or psi + phi (theta =
-90 deg) is defined. We then set phi = 0 and put the combined angle into yaw,
psi = atan2(-A21, A22); theta keeps its atan2 value. With tau < 90 deg the limiter then clamps
pitch to +-tau (so `limited` is true) and the published attitude is far from the singularity.

Limiting and reconstruction
---------------------------
    theta_l = min(max(theta, -tau), tau),  phi_l = min(max(phi, -tau), tau),  psi_l = psi
    [BN]_out = R_321(phi_l, theta_l, psi_l),  q_out = q_x(phi_l) (x) q_y(theta_l) (x) q_z(psi_l)

`limited` is true when |theta| > tau or |phi| > tau (strictly). The published DCM is orthonormal
to rounding (it is built from the angles), also when nothing was limited. q_out is sign
continuous: its sign is chosen so that q_out . q_previous >= 0 (q4 >= 0 for the first sample).

Angular velocity without an IMU
-------------------------------
From [BN]_dot = -[omega x] [BN]:  [omega x] = -[BN]_dot [BN]^T. Two estimates from consecutive
DCMs C_prev (at t_prev) and C (at t, h = t - t_prev):

- "log_map" (default): the rotation between the samples, D = C C_prev^T, which for a constant
  body rate is exactly exp(-[omega x] h); omega = theta_D e_D / h from the quaternion of D taken
  with q4 >= 0 (the shorter rotation). Exact for a constant rate; for a varying rate it is the
  mean rate over the step (the rate at the step's midpoint to O(h^2), at its end to O(h)).
  Valid while |omega| h < pi.
- "finite_difference" (the description's R_dot): W = -(C - C_prev)/h C^T, omega = vee((W - W^T)/2);
  for a constant rate this gives sin(|omega| h)/h along the rate axis (relative error
  (|omega| h)^2 / 6).
Before the first step (no previous sample) omega is zero.

"Re-propagate state vector using new R for R_dot. The previously used R0 remains the same."
Our interpretation: the published state (q_out, omega) is propagated from the thresholded DCM.
The finite-difference history keeps the thresholded DCM of each step as the previous DCM for the
next rate estimate, and the rate is the derivative of the thresholded DCM stream (both samples
thresholded), so it is the rate of the published attitude: while pitch or roll is held at +-tau
their rate is zero and only the yaw rate remains. (Differencing the raw new DCM against the
thresholded previous one would report the whole clamp offset as one step's rotation, a spike of
offset / h.) The reference R0 (the attitude the testbed was powered on in, N aligned with B) is
never changed. `rate_from_thresholded=False` keeps the raw (projected) input DCMs as history
instead, so omega is the measured body rate even while the attitude is limited.

Sampling: step(dcm, t, h) commits the DCM present at doStep(t, h) (FMI: inputs set before
doStep(t, h) hold at t) as the sample at t, with its rate estimate against the previous
commit. Between steps the outputs follow the input (direct feedthrough): a new DCM set at t + h
gives the rate over [t, t + h] at once (Gauss-Seidel with the kinematics stepping before the
DCM's source advances: no lag). If the input is still the DCM the last step committed (a
Jacobi master, or the source stepped first), omega holds that step's estimate (one step of
lag) instead of reading zero. (Consequence: a DCM that stays bitwise identical right after a
motion shows the last motion's rate until the next step commits it; any change of the input
gives the fresh estimate.) The model works on tuples of floats (once per step, numpy's call
overhead would dominate).
"""
import math

from ..core import rotations

RATE_METHODS = ("log_map", "finite_difference")
GIMBAL_LOCK_COS = 1e-7
IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


# ---- DCM / quaternion / 3-2-1 helpers ---------------------------------------------------
def matmul_t(a, b):
    """a b^T for 3x3 nested sequences."""
    return tuple(tuple(a[i][0] * b[j][0] + a[i][1] * b[j][1] + a[i][2] * b[j][2] for j in range(3))
                 for i in range(3))


def orthonormality_error(c):
    """max |C C^T - I| over the entries."""
    p = matmul_t(c, c)
    return max(abs(p[i][j] - (1.0 if i == j else 0.0)) for i in range(3) for j in range(3))


def determinant(c):
    return (c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
            - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
            + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]))


def quaternion_from_dcm(c):
    """Unit q (scalar last, q4 >= 0) with attitude_matrix(q) = C (Shepperd's method).

    For a C that is only nearly orthonormal the result is normalized, i.e. the quaternion of
    a nearby rotation."""
    return rotations.dcm_to_quaternion(c)


def euler321_from_quaternion(q):
    """(psi, theta, phi) = (yaw, pitch, roll) in rad of [BN] = attitude_matrix(q) =
    R_321(phi, theta, psi); atan2-based, with the gimbal-lock rule of the module docstring."""
    q1, q2, q3, q4 = q
    a11 = q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4
    a12 = 2.0 * (q1 * q2 + q3 * q4)
    a13 = 2.0 * (q1 * q3 - q2 * q4)
    a23 = 2.0 * (q2 * q3 + q1 * q4)
    a33 = -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4
    c_theta = math.hypot(a11, a12)
    theta = math.atan2(-a13, c_theta)
    if c_theta < GIMBAL_LOCK_COS:
        a21 = 2.0 * (q1 * q2 - q3 * q4)
        a22 = -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4
        return (math.atan2(-a21, a22), theta, 0.0)
    return (math.atan2(a12, a11), theta, math.atan2(a23, a33))


def dcm_from_euler321(psi, theta, phi):
    """The description's R_321(phi, theta, psi) = R1(phi) R2(theta) R3(psi): [BN] (N to B)."""
    sf, cf = math.sin(phi), math.cos(phi)
    st, ct = math.sin(theta), math.cos(theta)
    sp, cp = math.sin(psi), math.cos(psi)
    return ((ct * cp, ct * sp, -st),
            (-cf * sp + sf * st * cp, cf * cp + sf * st * sp, sf * ct),
            (sf * sp + cf * st * cp, -sf * cp + cf * st * sp, cf * ct))


def quaternion_from_euler321(psi, theta, phi):
    """q with attitude_matrix(q) = R_321(phi, theta, psi): q_x(phi) (x) q_y(theta) (x) q_z(psi)."""
    qz = rotations.from_axis_angle((0.0, 0.0, 1.0), psi)
    qy = rotations.from_axis_angle((0.0, 1.0, 0.0), theta)
    qx = rotations.from_axis_angle((1.0, 0.0, 0.0), phi)
    return rotations.circle_cross(qx, rotations.circle_cross(qy, qz))


def rotation_vector(q):
    """theta e of the unit quaternion q taken with q4 >= 0 (the rotation by at most pi), so
    that attitude_matrix(q) = exp(-[(theta e) x])."""
    if q[3] < 0.0:
        q = tuple(-x for x in q)
    s = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2])
    f = 2.0 * math.atan2(s, q[3]) / s if s > 1e-300 else 2.0 / q[3]
    return (f * q[0], f * q[1], f * q[2])


def rate_log_map(c, c_prev, h):
    """omega (rad/s, B) from D = C C_prev^T = exp(-[omega x] h); exact for a constant rate."""
    v = rotation_vector(quaternion_from_dcm(matmul_t(c, c_prev)))
    return (v[0] / h, v[1] / h, v[2] / h)


def rate_finite_difference(c, c_prev, h):
    """omega from the description's R_dot: W = -(C - C_prev)/h C^T, omega = vee(skew part of W)."""
    d = tuple(tuple((c[i][j] - c_prev[i][j]) / h for j in range(3)) for i in range(3))
    w = matmul_t(d, c)
    w = tuple(tuple(-x for x in row) for row in w)
    return (0.5 * (w[2][1] - w[1][2]), 0.5 * (w[0][2] - w[2][0]), 0.5 * (w[1][0] - w[0][1]))


def as_dcm(values, what="dcm_BN"):
    """3x3 tuple from 9 row-major values or a nested 3x3 sequence; rejects non-finite entries."""
    flat = [float(x) for row in values for x in row] if len(values) == 3 else [float(x) for x in values]
    if len(flat) != 9:
        raise ValueError(f"{what} must have 9 elements ({what}[1,1]..{what}[3,3]), got {len(flat)}")
    if not all(math.isfinite(x) for x in flat):
        raise ValueError(f"input {what} {flat} has non-finite elements")
    return (tuple(flat[0:3]), tuple(flat[3:6]), tuple(flat[6:9]))


class AttitudeToDcm:
    """dcm_BN = attitude_matrix(q_BN / |q_BN|) (Eq. 22). Stateless."""

    def dcm(self, q):
        q = tuple(float(x) for x in q)
        if not all(math.isfinite(x) for x in q):
            raise ValueError(f"input q_BN {list(q)} has non-finite elements")
        return rotations.attitude_matrix(rotations.normalized(q, "input q_BN"))

    def get_state(self):
        return {}

    def set_state(self, state):
        pass


class AirBearingKinematics:
    """Rate estimation, 3-2-1 extraction and pitch/roll limiting of a DCM stream (see module)."""

    def __init__(self, tau=math.radians(40.0), dcm_tol=1e-6, rate_method="log_map", rate_from_thresholded=True):
        tau = float(tau)
        if not (math.isfinite(tau) and 0.0 < tau < 0.5 * math.pi):
            raise ValueError(f"tau = {tau!r} rad must be in (0, pi/2) (0 to 90 deg, both excluded)")
        dcm_tol = float(dcm_tol)
        if not (math.isfinite(dcm_tol) and 0.0 < dcm_tol <= 0.1):
            raise ValueError(f"dcm_tol = {dcm_tol!r} must be in (0, 0.1]")
        if rate_method not in RATE_METHODS:
            raise ValueError(f"rate_method {rate_method!r} must be one of {', '.join(RATE_METHODS)}")
        self.tau = tau
        self.dcm_tol = dcm_tol
        self.rate_method = rate_method
        self.rate_from_thresholded = bool(rate_from_thresholded)
        self._rate = rate_log_map if rate_method == "log_map" else rate_finite_difference
        self.reset()

    def reset(self):
        self.has_prev = False           # first-sample flag: no previous DCM yet
        self.prev_dcm = IDENTITY        # previous DCM of the rate history (R0 until the first step)
        self.prev_q = (0.0, 0.0, 0.0, 1.0)  # previous published quaternion (sign continuity)
        self.prev_input = None          # the input DCM last committed (as given, 3x3 tuple)
        self.last_rate = (0.0, 0.0, 0.0)  # rate estimate of the last committed sample (rad/s)
        self.t_prev = 0.0               # time of prev_dcm (s)
        self.time = 0.0                 # current time: end of the last step (s)

    # ---- per sample ---------------------------------------------------------------------
    def check_dcm(self, dcm):
        c = as_dcm(dcm)
        err = orthonormality_error(c)
        if not err <= self.dcm_tol:
            raise ValueError(f"input dcm_BN is not orthonormal: max |C C^T - I| = {err:.3g} exceeds dcm_tol = "
                             f"{self.dcm_tol:g}")
        if determinant(c) <= 0.0:
            raise ValueError(f"input dcm_BN has determinant {determinant(c):.6g}: a reflection, not a rotation "
                             "(det must be +1)")
        return c

    def threshold(self, dcm):
        """(q_in, (psi, theta, phi) limited, limited flag, dcm_out, q_out) of one input DCM."""
        return self._threshold(self.check_dcm(dcm))

    def _threshold(self, c):
        q_in = quaternion_from_dcm(c)
        psi, theta, phi = euler321_from_quaternion(q_in)
        tau = self.tau
        theta_l = min(max(theta, -tau), tau)
        phi_l = min(max(phi, -tau), tau)
        limited = theta_l != theta or phi_l != phi
        dcm_out = dcm_from_euler321(psi, theta_l, phi_l)
        q_out = quaternion_from_euler321(psi, theta_l, phi_l)
        return q_in, (psi, theta_l, phi_l), limited, dcm_out, q_out

    def evaluate(self, dcm):
        """Outputs for the DCM at the current time (the end of the last step): dict with q_BN,
        omega_BN_B, euler321 (yaw, pitch, roll), dcm_out_BN (3x3), limited; and "history",
        the DCM that step() keeps as the previous sample.

        If the input is still the DCM the last step committed (no new sample since, as under a
        Jacobi master or when the source stepped first), omega is the estimate of that step."""
        return self._evaluate(dcm, self.time, hold=True)

    def _evaluate(self, dcm, now, hold):
        c = self.check_dcm(dcm)
        q_in, angles, limited, dcm_out, q_out = self._threshold(c)
        current = dcm_out if self.rate_from_thresholded else rotations.attitude_matrix(q_in)
        p = self.prev_q if self.has_prev else (0.0, 0.0, 0.0, 1.0)
        if q_out[0] * p[0] + q_out[1] * p[1] + q_out[2] * p[2] + q_out[3] * p[3] < 0.0:
            q_out = tuple(-x for x in q_out)
        h = now - self.t_prev
        if hold and self.has_prev and c == self.prev_input:
            omega = self.last_rate
        elif self.has_prev and h > 0.0:
            omega = self._rate(current, self.prev_dcm, h)
        else:
            omega = (0.0, 0.0, 0.0)
        return {"q_BN": q_out, "omega_BN_B": omega, "euler321": angles, "dcm_out_BN": dcm_out,
                "limited": limited, "history": current, "input": c}

    def step(self, dcm, t, h):
        """Commit the DCM present at the start of the step [t, t + h] as the sample at t; the
        rate estimate of this sample is against the previous commit, over t - t_prev."""
        t, h = float(t), float(h)
        if not (math.isfinite(t) and math.isfinite(h) and h > 0.0):
            raise ValueError(f"step from t = {t!r} by h = {h!r} s: h must be a positive finite number")
        out = self._evaluate(dcm, t, hold=False)
        self.prev_dcm = out["history"]
        self.prev_input = out["input"]
        self.prev_q = tuple(out["q_BN"])
        self.last_rate = tuple(out["omega_BN_B"])
        self.t_prev = t
        self.time = t + h
        self.has_prev = True
        return out

    # ---- full state ---------------------------------------------------------------------
    def get_state(self):
        return {"has_prev": self.has_prev, "prev_dcm": [list(r) for r in self.prev_dcm],
                "prev_input": None if self.prev_input is None else [list(r) for r in self.prev_input],
                "prev_q": list(self.prev_q), "last_rate": list(self.last_rate), "t_prev": self.t_prev,
                "time": self.time}

    def set_state(self, state):
        self.has_prev = bool(state["has_prev"])
        self.prev_dcm = tuple(tuple(float(x) for x in r) for r in state["prev_dcm"])
        self.prev_input = (None if state["prev_input"] is None
                           else tuple(tuple(float(x) for x in r) for r in state["prev_input"]))
        self.prev_q = tuple(float(x) for x in state["prev_q"])
        self.last_rate = tuple(float(x) for x in state["last_rate"])
        self.t_prev = float(state["t_prev"])
        self.time = float(state["time"])
