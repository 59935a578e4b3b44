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

from ..core import rotations

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


class RigidBody:
    """Attitude state (q_BN, omega_BN_B) of a rigid body under a body-frame torque."""

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
        self.J = tuple(tuple(row) for row in J.tolist())
        self.Jinv = tuple(tuple(row) for row in np.linalg.inv(J).tolist())
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

    # ---- dynamics --------------------------------------------------------------------
    def angular_acceleration(self, omega, torque, wheel_torque=ZERO3, h_w=ZERO3):
        """Eq. 17, in gyrostat form: omega_dot = I^-1 [L - wheel_torque - omega x (I omega + h_w)].

        With zero wheel terms this is exactly Eq. 17 (adding or subtracting 0.0 changes no
        non-zero float, so the thesis' numbers are reproduced bit for bit)."""
        J, Ji = self.J, self.Jinv
        h = (J[0][0] * omega[0] + J[0][1] * omega[1] + J[0][2] * omega[2] + h_w[0],
             J[1][0] * omega[0] + J[1][1] * omega[1] + J[1][2] * omega[2] + h_w[1],
             J[2][0] * omega[0] + J[2][1] * omega[1] + J[2][2] * omega[2] + h_w[2])
        c = rotations.cross(omega, h)
        r = (torque[0] - wheel_torque[0] - c[0], torque[1] - wheel_torque[1] - c[1],
             torque[2] - wheel_torque[2] - c[2])
        return (Ji[0][0] * r[0] + Ji[0][1] * r[1] + Ji[0][2] * r[2],
                Ji[1][0] * r[0] + Ji[1][1] * r[1] + Ji[1][2] * r[2],
                Ji[2][0] * r[0] + Ji[2][1] * r[1] + Ji[2][2] * r[2])

    def step(self, torque, h, wheel_torque=ZERO3, wheel_momentum=ZERO3):
        """Advance by h seconds with the body torque held constant (N.m, B frame).

        wheel_torque / wheel_momentum (B frame): the wheel motors' torque on the wheels (N.m,
        held over the step) and the wheels' momentum h_w at the step start (N.m.s); see the
        module docstring. Left at zero: the wheel-less model, bit for bit."""
        for name, v in (("torque_B", torque), ("wheel_torque_B", wheel_torque), ("wheel_momentum_B", wheel_momentum)):
            if not all(math.isfinite(x) for x in v):
                raise ValueError(f"{name} {list(v)} must be finite")
        tw, hw = tuple(wheel_torque), tuple(wheel_momentum)
        if self.integrator == "euler":
            q, w = self.q, self.omega
            q_dot = rotations.quaternion_rate(q, w)
            w_dot = self.angular_acceleration(w, torque, tw, hw)
            self.q = tuple(q[i] + q_dot[i] * h for i in range(4))
            self.omega = tuple(w[i] + w_dot[i] * h for i in range(3))
            self.omega_dot = w_dot
            # Eq. 31 after StateChange, with the new rates (Appendix C-D)
            self.euler_integrated = tuple(self.euler_integrated[i] + self.omega[i] * h for i in range(3))
            return
        n = max(1, math.ceil(h / self.max_substep - 1e-9))
        dt = h / n
        q, w = self.q, self.omega
        w_start = w
        angles = self.euler_integrated
        for k in range(n):
            q, w, turned = self._rk4(q, w, torque, dt, tw, hw, k * dt)
            angles = tuple(angles[i] + turned[i] for i in range(3))
        self.euler_integrated = angles
        self.q = rotations.normalized(q)
        self.omega = w
        self.omega_dot = tuple((w[i] - w_start[i]) / h for i in range(3))

    def _rk4(self, q, w, torque, dt, tw, hw, s0):
        """One RK4 sub-step from s0 (s after the step start); h_w follows the held wheel
        torque within the step, h_w(s) = h_w + tw s, as the wheel's own exact integration.
        Returns q, omega and the integral of omega over the sub-step (Eq. 31's increment)."""
        f_q, f_w = rotations.quaternion_rate, self.angular_acceleration
        h0, hm, h1 = (tuple(hw[i] + tw[i] * s for i in range(3)) for s in (s0, s0 + 0.5 * dt, s0 + dt))
        k1q, k1w = f_q(q, w), f_w(w, torque, tw, h0)
        q2 = tuple(q[i] + 0.5 * dt * k1q[i] for i in range(4))
        w2 = tuple(w[i] + 0.5 * dt * k1w[i] for i in range(3))
        k2q, k2w = f_q(q2, w2), f_w(w2, torque, tw, hm)
        q3 = tuple(q[i] + 0.5 * dt * k2q[i] for i in range(4))
        w3 = tuple(w[i] + 0.5 * dt * k2w[i] for i in range(3))
        k3q, k3w = f_q(q3, w3), f_w(w3, torque, tw, hm)
        q4 = tuple(q[i] + dt * k3q[i] for i in range(4))
        w4 = tuple(w[i] + dt * k3w[i] for i in range(3))
        k4q, k4w = f_q(q4, w4), f_w(w4, torque, tw, h1)
        q = tuple(q[i] + dt / 6.0 * (k1q[i] + 2 * k2q[i] + 2 * k3q[i] + k4q[i]) for i in range(4))
        turned = tuple(dt / 6.0 * (w[i] + 2 * w2[i] + 2 * w3[i] + w4[i]) for i in range(3))
        w = tuple(w[i] + dt / 6.0 * (k1w[i] + 2 * k2w[i] + 2 * k3w[i] + k4w[i]) for i in range(3))
        return q, w, turned

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
                "euler_integrated": list(self.euler_integrated)}

    def set_state(self, state):
        self.q = tuple(state["q"])
        self.omega = tuple(state["omega"])
        self.omega_dot = tuple(state["omega_dot"])
        self.euler_integrated = tuple(state["euler_integrated"])
