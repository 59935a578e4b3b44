"""Rigid-body attitude dynamics: Euler's equation and quaternion kinematics.

Thesis Eq. 4-5 (inertia of a uniform box), Eq. 17-21 (Euler's equation, q_dot = 1/2 Xi(q) w,
explicit Euler update) and Appendix C `StateChange`.

Two integrators:
- "euler": one explicit Euler step per communication step, no normalization: exactly the
  thesis scripts' `StateChange` (the published numbers depend on it, including the drift of
  the quaternion norm, e.g. q4 = 1.00060 at the end of slew case 1).
- "rk4": classical Runge-Kutta on (q, omega) with sub-steps of at most `max_substep`,
  and the quaternion normalized at the end of each communication step. The default.
The applied torque is held constant over a communication step (zero-order hold).

Integrated Euler angles (Eq. 30-31): the thesis scripts print "Euler angles" that are not the
1-2-3 angles of q but the body rates integrated, angles += omega dt, from the 1-2-3 angles of
the start attitude (Eq. 27-29: zero for the identity, Eq. 30). `euler_integrated` carries them
with the same integrator as the attitude: "euler" adds the new omega times the step after the
state update, as Appendix C-D do; "rk4" integrates d(angles)/dt = omega within its sub-steps.
They are not an attitude representation (body rates are not Euler-angle rates); they match
the thesis' printed triples, e.g. Eq. 34: 22.32, 53.52, 21.71 deg.

Momentum wheels (optional): with wheel_torque_B (the torque the wheel motors apply to the wheels,
N.m, B) and wheel_momentum_B (h_w, the wheels' angular momentum relative to the body, N.m.s, B)
Euler's equation becomes the gyrostat equation (Hughes, Spacecraft Attitude Dynamics, 1986,
ch. 3; Markley and Crassidis, 2014, sec. 3.3)

    J omega_dot = L - wheel_torque_B - omega x (J omega + h_w),

with J the inertia of the whole spacecraft. It conserves the total angular momentum
J omega + h_w (in N) when L = 0. Within a step the wheel torque is held and h_w follows it,
h_w(t_k + s) = h_w(t_k) + wheel_torque_B s, as the wheel's own exact integration of a held
torque gives (components.acs.momentum_wheel). With both wheel inputs zero the step runs the
same arithmetic plus exact zeros, so results are bit-identical to the wheel-less model.
`angular_momentum()` (the H_B output) stays the body's own J omega; the total is
`total_angular_momentum(h_w)`.
"""
import math

import numpy as np

from ..core import rotations, state_views
from ..core.jit import njit
from . import mass_properties

INTEGRATORS = ("euler", "rk4")
ZERO3 = (0.0, 0.0, 0.0)


def box_inertia(mass, a, b, c):
    """Principal inertia of a uniform box (Eq. 4, Appendix A): Ix uses a and b, Iy uses b and
    c, Iz uses a and c (x runs along the c edge, y along a, z along b)."""
    for name, value in (("mass", mass), ("edge a", a), ("edge b", b), ("edge c", c)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r} must be a finite positive number")
    return np.diag([mass * (a * a + b * b) / 12.0, mass * (b * b + c * c) / 12.0, mass * (a * a + c * c) / 12.0])


def check_inertia(inertia):
    J = np.asarray(inertia, dtype=float).reshape(3, 3)
    if not np.all(np.isfinite(J)):
        raise ValueError(f"inertia tensor {J.tolist()} has non-finite entries")
    if not np.allclose(J, J.T, rtol=1e-12, atol=1e-15):
        raise ValueError(f"inertia tensor {J.tolist()} must be symmetric")
    eig = np.linalg.eigvalsh(J)
    if eig[0] <= 0:
        raise ValueError(f"inertia tensor must be positive definite (eigenvalues {eig.tolist()})")
    # Any physical body satisfies the triangle inequality on its principal moments.
    if eig[2] > eig[0] + eig[1] * (1 + 1e-12):
        raise ValueError(f"principal moments {eig.tolist()} violate the triangle inequality I3 <= I1 + I2")
    return J


# The state array (RigidBody.x), which the compiled step and publish read and write in place
# (RAW_Q: the unnormalized quaternion of a step that could not normalize it, for its error)
Q, OMEGA, OMEGA_DOT, ANGLES, CENTER, J_ROWS, JINV_ROWS, RAW_Q, STATE_SIZE = 0, 4, 7, 10, 13, 16, 25, 34, 38
# publish_into's outputs, in the order of its `outputs` indices
PUBLISHED = (("q_BN", 4), ("omega_BN_B", 3), ("omega_dot_BN_B", 3), ("euler123", 3), ("H_B", 3),
             ("euler_integrated", 3), ("center_of_mass_B", 3))
_INPUT_NAMES = ("torque_B", "wheel_torque_B", "wheel_momentum_B", "disturbance_torque_B")
NINE = np.arange(9)  # step()'s inputs: the whole of its own array


class RigidBody:
    """Attitude state (q_BN, omega_BN_B) of a rigid body under a body-frame torque.

    The state lives in one float array `x` (q, omega, omega_dot, the integrated angles, the
    centre of mass, J and its inverse) so that the compiled RK4 step and publish_into work on it
    in place; the attributes are views of it."""

    q = state_views.view(Q, 4)
    omega = state_views.view(OMEGA, 3)
    omega_dot = state_views.view(OMEGA_DOT, 3)
    euler_integrated = state_views.view(ANGLES, 3)
    center_of_mass = state_views.view(CENTER, 3)

    def __init__(self, inertia, q0=(0.0, 0.0, 0.0, 1.0), omega0=(0.0, 0.0, 0.0), integrator="rk4",
                 max_substep=0.005, euler0=None):
        J = check_inertia(inertia)
        if integrator not in INTEGRATORS:
            raise ValueError(f"integrator {integrator!r} must be one of {', '.join(INTEGRATORS)}")
        if not (math.isfinite(max_substep) and max_substep > 0):
            raise ValueError(f"max_substep = {max_substep!r} must be a positive number of seconds")
        omega0 = tuple(float(x) for x in omega0)
        if not all(math.isfinite(x) for x in omega0):
            raise ValueError(f"omega0 {list(omega0)} must be finite")
        self.integrator = integrator
        self.max_substep = float(max_substep)
        self.x = np.zeros(STATE_SIZE)
        self._inputs = np.zeros(9)  # step()'s torques in the compiled step's form
        self.set_inertia(tuple(map(tuple, J.tolist())), tuple(map(tuple, np.linalg.inv(J).tolist())))
        self.J0 = self.J  # the inertia at takeover, before any propellant is drawn
        self.drawn_cell = np.zeros(1)  # the FMU's native step reads it where the binary calls it
        self.drawn = 0.0  # kg of propellant the inertia has followed (follow_propellant)
        self.center_of_mass = (0.0, 0.0, 0.0)  # m in B, from the takeover centre of mass
        q0 = tuple(float(x) for x in q0)
        unit_q0 = rotations.normalized(q0, "q0")  # also rejects a zero or non-finite q0
        # The thesis scripts carry q from one maneuver to the next without normalizing it
        # (the slews start from a detumble end state of norm 1.0008), so "euler" keeps q0 as
        # given; "rk4" normalizes.
        self.q = q0 if integrator == "euler" else unit_q0
        self.omega = omega0
        self.omega_dot = (0.0, 0.0, 0.0)  # no step taken yet (thesis: w_dot = [0; 0; 0])
        if euler0 is None:  # the start attitude's 1-2-3 angles (Eq. 27-29), as the scripts begin
            euler0 = rotations.euler123(unit_q0)
        euler0 = tuple(float(x) for x in euler0)
        if len(euler0) != 3 or not all(math.isfinite(x) for x in euler0):
            raise ValueError(f"euler0 {list(euler0)} must be three finite angles in rad")
        self.euler_integrated = euler0

    @property
    def drawn(self):
        """kg of propellant the inertia has followed (follow_propellant), kept in drawn_cell."""
        return float(self.drawn_cell[0])

    @drawn.setter
    def drawn(self, value):
        self.drawn_cell[0] = value

    def set_inertia(self, J, Jinv):
        """Hold the inertia J (and its inverse) from now on: the mass properties as the tank empties
        (components.attitude.mass_properties), applied between steps."""
        self.J, self.Jinv = J, Jinv
        self.x[J_ROWS:J_ROWS + 9] = [x for row in J for x in row]
        self.x[JINV_ROWS:JINV_ROWS + 9] = [x for row in Jinv for x in row]

    def follow_propellant(self, drawn, mass0, tank):
        """The inertia about the centre of mass once `drawn` kg left the tank at `tank` (m, B) of a
        body of `mass0` kg (components.attitude.mass_properties); recomputed once it changed by
        mass_properties.RESOLUTION."""
        if abs(drawn - self.drawn) < mass_properties.RESOLUTION:
            return
        J, c = mass_properties.drawn(self.J0, mass0, drawn, tank)
        self.set_inertia(J, mass_properties.inverse(J))
        self.drawn, self.center_of_mass = drawn, c

    # ---- dynamics --------------------------------------------------------------------
    def step(self, torque, h, wheel_torque=ZERO3, wheel_momentum=ZERO3):
        """Advance by h seconds with the body torque held constant (N.m, B frame).

        wheel_torque / wheel_momentum (B frame): the wheel motors' torque on the wheels (N.m,
        held over the step) and the wheels' momentum h_w at the step start (N.m.s); see the
        module docstring. Left at zero: the wheel-less model, bit for bit."""
        u = self._inputs
        for k, (name, v) in enumerate(zip(_INPUT_NAMES, (torque, wheel_torque, wheel_momentum))):
            if len(v) != 3:
                raise ValueError(f"{name} {list(v)} must have 3 elements")
            u[3 * k:3 * k + 3] = v
        self.step_from(u, NINE, h)

    def step_from(self, values, inputs, h):
        """step() with the torque, wheel torque and wheel momentum at values[inputs[0:9]] (the
        FMU passes the array it shares with the runtime): one compiled call."""
        if self.integrator == "euler":
            error = euler_step_into(self.x, values, inputs, h)
        else:
            error = rk4_step_into(self.x, values, inputs, h, self._substeps(h))
        self._refuse(error, values, inputs)

    def step_and_publish(self, values, inputs, outputs, h):
        """step_from(values, inputs, h) then publish_into(values, outputs) in one compiled call (the
        FMU's step: one call from Python where there were two). False when the step was taken but
        the outputs were not written (publish_into would raise the quaternion's error)."""
        error = step_publish_into(self.x, values, inputs, outputs, h, self._substeps(h), self.integrator == "euler")
        self._refuse(max(error, 0), values, inputs)
        return error == 0

    def _substeps(self, h):
        return 1 if self.integrator == "euler" else max(1, math.ceil(h / self.max_substep - 1e-9))

    def _refuse(self, error, values, inputs):
        """Raise the error a step kernel's code stands for (0: none)."""
        if error:
            if error <= 4:
                name = _INPUT_NAMES[error - 1]
                raise ValueError(f"{name} {values[inputs[3 * error - 3:3 * error]].tolist()} must be finite")
            rotations.normalized(tuple(self.x[RAW_Q:RAW_Q + 4].tolist()))  # raises its error

    def publish_into(self, values, outputs):
        """Write q, omega, omega_dot, the 1-2-3 angles, H_B, the integrated angles and the centre
        of mass (PUBLISHED) to values[outputs] in one compiled call."""
        if not publish_into(self.x, values, outputs):
            rotations.euler123(self.q)  # raises the quaternion's error

    # ---- derived quantities ------------------------------------------------------------
    def euler123(self):
        return rotations.euler123(self.q)

    def angular_momentum(self):
        """H_B = I omega (N.m.s, B frame): the body's own angular momentum, without the
        wheels' relative momentum h_w (see total_angular_momentum)."""
        J, w = self.J, self.omega
        return tuple(J[i][0] * w[0] + J[i][1] * w[1] + J[i][2] * w[2] for i in range(3))

    def total_angular_momentum(self, wheel_momentum=(0.0, 0.0, 0.0)):
        """J omega + h_w (N.m.s, B frame): body plus wheels (h_w relative to the body)."""
        H = self.angular_momentum()
        return tuple(H[i] + float(wheel_momentum[i]) for i in range(3))

    def kinetic_energy(self):
        return 0.5 * rotations.dot(self.omega, self.angular_momentum())

    # ---- full state for FMU get/set state ------------------------------------------------
    def get_state(self):
        return {"q": list(self.q), "omega": list(self.omega), "omega_dot": list(self.omega_dot),
                "euler_integrated": list(self.euler_integrated), "J": [list(r) for r in self.J],
                "Jinv": [list(r) for r in self.Jinv], "drawn": self.drawn, "center_of_mass": list(self.center_of_mass)}

    def set_state(self, state):
        self.q = tuple(state["q"])
        self.omega = tuple(state["omega"])
        self.omega_dot = tuple(state["omega_dot"])
        self.euler_integrated = tuple(state["euler_integrated"])
        if "J" in state:  # states saved before the inertia could change carry none
            self.set_inertia(tuple(map(tuple, state["J"])), tuple(map(tuple, state["Jinv"])))
            self.drawn, self.center_of_mass = float(state["drawn"]), tuple(state["center_of_mass"])


# ---- the RK4 kernel (numba where installed; the same arithmetic, operation for operation, as
# the plain-Python path, so both give the same bits) ------------------------------------------
@njit(cache=True, plain_first=True)
def _acceleration(w0, w1, w2, J, Ji, t, tw, h0, h1, h2):
    """Eq. 17 in gyrostat form: omega_dot = I^-1 [L - wheel_torque - omega x (I omega + h_w)]. With
    zero wheel terms this is exactly Eq. 17 (adding or subtracting 0.0 changes no non-zero float,
    so the thesis' numbers are reproduced bit for bit)."""
    a0 = J[0] * w0 + J[1] * w1 + J[2] * w2 + h0
    a1 = J[3] * w0 + J[4] * w1 + J[5] * w2 + h1
    a2 = J[6] * w0 + J[7] * w1 + J[8] * w2 + h2
    r0 = t[0] - tw[0] - (w1 * a2 - w2 * a1)
    r1 = t[1] - tw[1] - (w2 * a0 - w0 * a2)
    r2 = t[2] - tw[2] - (w0 * a1 - w1 * a0)
    return (Ji[0] * r0 + Ji[1] * r1 + Ji[2] * r2,
            Ji[3] * r0 + Ji[4] * r1 + Ji[5] * r2,
            Ji[6] * r0 + Ji[7] * r1 + Ji[8] * r2)


@njit(cache=True, plain_first=True)
def rk4_steps(q, w, angles, J, Ji, torque, tw, hw, dt, n):
    """n classical RK4 sub-steps of dt on (q, omega) with the torque held, h_w following the held
    wheel torque, h_w(s) = h_w + tw s (the wheel's own exact integration); `angles` (Eq. 31) gain
    the integral of omega. J, Ji: the inertia and its inverse, row-major 9-tuples. Returns
    (q, omega, angles), q not normalized."""
    qa, qb, qc, qd = q[0], q[1], q[2], q[3]
    wa, wb, wc = w[0], w[1], w[2]
    ea, eb, ec = angles[0], angles[1], angles[2]
    for k in range(n):
        s0 = k * dt
        sm, s1 = s0 + 0.5 * dt, s0 + dt
        k1q = rotations.quaternion_rate_kernel(qa, qb, qc, qd, wa, wb, wc)
        k1w = _acceleration(wa, wb, wc, J, Ji, torque, tw, hw[0] + tw[0] * s0, hw[1] + tw[1] * s0, hw[2] + tw[2] * s0)
        q2 = (qa + 0.5 * dt * k1q[0], qb + 0.5 * dt * k1q[1], qc + 0.5 * dt * k1q[2], qd + 0.5 * dt * k1q[3])
        w2 = (wa + 0.5 * dt * k1w[0], wb + 0.5 * dt * k1w[1], wc + 0.5 * dt * k1w[2])
        k2q = rotations.quaternion_rate_kernel(q2[0], q2[1], q2[2], q2[3], w2[0], w2[1], w2[2])
        k2w = _acceleration(w2[0], w2[1], w2[2], J, Ji, torque, tw,
                            hw[0] + tw[0] * sm, hw[1] + tw[1] * sm, hw[2] + tw[2] * sm)
        q3 = (qa + 0.5 * dt * k2q[0], qb + 0.5 * dt * k2q[1], qc + 0.5 * dt * k2q[2], qd + 0.5 * dt * k2q[3])
        w3 = (wa + 0.5 * dt * k2w[0], wb + 0.5 * dt * k2w[1], wc + 0.5 * dt * k2w[2])
        k3q = rotations.quaternion_rate_kernel(q3[0], q3[1], q3[2], q3[3], w3[0], w3[1], w3[2])
        k3w = _acceleration(w3[0], w3[1], w3[2], J, Ji, torque, tw,
                            hw[0] + tw[0] * sm, hw[1] + tw[1] * sm, hw[2] + tw[2] * sm)
        q4 = (qa + dt * k3q[0], qb + dt * k3q[1], qc + dt * k3q[2], qd + dt * k3q[3])
        w4 = (wa + dt * k3w[0], wb + dt * k3w[1], wc + dt * k3w[2])
        k4q = rotations.quaternion_rate_kernel(q4[0], q4[1], q4[2], q4[3], w4[0], w4[1], w4[2])
        k4w = _acceleration(w4[0], w4[1], w4[2], J, Ji, torque, tw,
                            hw[0] + tw[0] * s1, hw[1] + tw[1] * s1, hw[2] + tw[2] * s1)
        c = dt / 6.0
        qa = qa + c * (k1q[0] + 2 * k2q[0] + 2 * k3q[0] + k4q[0])
        qb = qb + c * (k1q[1] + 2 * k2q[1] + 2 * k3q[1] + k4q[1])
        qc = qc + c * (k1q[2] + 2 * k2q[2] + 2 * k3q[2] + k4q[2])
        qd = qd + c * (k1q[3] + 2 * k2q[3] + 2 * k3q[3] + k4q[3])
        ea = ea + c * (wa + 2 * w2[0] + 2 * w3[0] + w4[0])
        eb = eb + c * (wb + 2 * w2[1] + 2 * w3[1] + w4[1])
        ec = ec + c * (wc + 2 * w2[2] + 2 * w3[2] + w4[2])
        wa, wb, wc = (wa + c * (k1w[0] + 2 * k2w[0] + 2 * k3w[0] + k4w[0]),
                      wb + c * (k1w[1] + 2 * k2w[1] + 2 * k3w[1] + k4w[1]),
                      wc + c * (k1w[2] + 2 * k2w[2] + 2 * k3w[2] + k4w[2]))
    return (qa, qb, qc, qd), (wa, wb, wc), (ea, eb, ec)


@njit(cache=True, plain_first=True)
def _body_torque(values, inputs):
    """The external torque: torque_B at values[inputs[0:3]], plus the disturbance torque at
    values[inputs[9:12]] where the caller passes twelve inputs (the FMU) rather than nine."""
    if inputs.shape[0] > 9:
        return (values[inputs[0]] + values[inputs[9]], values[inputs[1]] + values[inputs[10]],
                values[inputs[2]] + values[inputs[11]])
    return (values[inputs[0]], values[inputs[1]], values[inputs[2]])


@njit(cache=True, plain_first=True)
def euler_step_into(x, values, inputs, h):
    """The thesis scripts' StateChange on the state array x in place: one explicit Euler step of h
    with the inputs at values[inputs[0:9]] as in rk4_step_into, q not normalized, then Eq. 31's
    angles += the new omega h (Appendix C-D). Returns 0, or 1-4 when that input vector is not
    finite (nothing changed)."""
    for k in range(inputs.shape[0]):
        if not math.isfinite(values[inputs[k]]):
            return k // 3 + 1
    torque = _body_torque(values, inputs)
    tw = (values[inputs[3]], values[inputs[4]], values[inputs[5]])
    J = (x[16], x[17], x[18], x[19], x[20], x[21], x[22], x[23], x[24])
    Ji = (x[25], x[26], x[27], x[28], x[29], x[30], x[31], x[32], x[33])
    q1, q2, q3, q4, w1, w2, w3 = x[0], x[1], x[2], x[3], x[4], x[5], x[6]
    q_dot = rotations.quaternion_rate_kernel(q1, q2, q3, q4, w1, w2, w3)
    w_dot = _acceleration(w1, w2, w3, J, Ji, torque, tw, values[inputs[6]], values[inputs[7]], values[inputs[8]])
    x[0], x[1], x[2], x[3] = q1 + q_dot[0] * h, q2 + q_dot[1] * h, q3 + q_dot[2] * h, q4 + q_dot[3] * h
    x[4], x[5], x[6] = w1 + w_dot[0] * h, w2 + w_dot[1] * h, w3 + w_dot[2] * h
    x[7], x[8], x[9] = w_dot
    x[10], x[11], x[12] = x[10] + x[4] * h, x[11] + x[5] * h, x[12] + x[6] * h
    return 0


@njit(cache=True, plain_first=True)
def rk4_step_into(x, values, inputs, h, n):
    """RigidBody's RK4 communication step on its state array x in place: the torque, wheel torque
    and wheel momentum at values[inputs[0:9]], n sub-steps of h / n (rk4_steps), the quaternion
    normalized (rotations.normalized) and omega_dot the mean over the step; the same operations
    as the step in Python. Returns 0, or 1-4 when that input vector is not finite (nothing
    changed), or 5 when the quaternion's norm is zero or not finite (the angles are updated, the
    quaternion is left in x[RAW_Q:])."""
    for k in range(inputs.shape[0]):
        if not math.isfinite(values[inputs[k]]):
            return k // 3 + 1
    torque = _body_torque(values, inputs)
    tw = (values[inputs[3]], values[inputs[4]], values[inputs[5]])
    hw = (values[inputs[6]], values[inputs[7]], values[inputs[8]])
    J = (x[16], x[17], x[18], x[19], x[20], x[21], x[22], x[23], x[24])
    Ji = (x[25], x[26], x[27], x[28], x[29], x[30], x[31], x[32], x[33])
    w0 = (x[4], x[5], x[6])
    q, w, angles = rk4_steps((x[0], x[1], x[2], x[3]), w0, (x[10], x[11], x[12]), J, Ji, torque, tw, hw, h / n, n)
    x[10], x[11], x[12] = angles
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if not math.isfinite(norm) or norm < 1e-12:
        x[34], x[35], x[36], x[37] = q
        return 5
    x[0], x[1], x[2], x[3] = q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm
    x[4], x[5], x[6] = w
    x[7], x[8], x[9] = (w[0] - w0[0]) / h, (w[1] - w0[1]) / h, (w[2] - w0[2]) / h
    return 0


@njit(cache=True, plain_first=True)
def publish_into(x, values, outputs):
    """values[outputs] = q, omega, omega_dot, the 1-2-3 angles of q (rotations.euler123), the body's
    J omega (angular_momentum), the integrated angles and the centre of mass from the state x (22
    values, PUBLISHED); the same operations as those methods. False (nothing written) when q has a
    zero or non-finite norm."""
    q1, q2, q3, q4 = x[0], x[1], x[2], x[3]
    norm = math.sqrt(q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4)
    if not math.isfinite(norm) or norm < 1e-12:
        return False
    a, b, c, d = q1 / norm, q2 / norm, q3 / norm, q4 / norm
    a00 = a * a - b * b - c * c + d * d
    a10 = 2 * (a * b - c * d)
    a20 = 2 * (a * c + b * d)
    a21 = 2 * (b * c - a * d)
    a22 = -a * a - b * b + c * c + d * d
    s = max(-1.0, min(1.0, a20))
    for i in range(10):  # q, omega, omega_dot
        values[outputs[i]] = x[i]
    values[outputs[10]] = math.atan2(-a21, a22)
    values[outputs[11]] = math.asin(s)
    values[outputs[12]] = math.atan2(-a10, a00)
    w0, w1, w2 = x[4], x[5], x[6]
    for i in range(3):
        values[outputs[13 + i]] = x[16 + 3 * i] * w0 + x[17 + 3 * i] * w1 + x[18 + 3 * i] * w2
    for i in range(6):  # the integrated angles, the centre of mass
        values[outputs[16 + i]] = x[10 + i]
    return True


@njit(cache=True, plain_first=True)
def step_publish_into(x, values, inputs, outputs, h, n, euler):
    """euler_step_into (euler) or rk4_step_into with n sub-steps, then, when the step was taken,
    publish_into: the step's code (1-5, nothing published), 0 when published, -1 when publish_into
    wrote nothing (the quaternion's norm)."""
    error = euler_step_into(x, values, inputs, h) if euler else rk4_step_into(x, values, inputs, h, n)
    if error:
        return error
    return 0 if publish_into(x, values, outputs) else -1
