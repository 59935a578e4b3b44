"""Schaub's MRP feedback law (Basilisk's mrpFeedback): the body torque that tracks a reference
given the attitude tracking error, with an optional integral term, for a spacecraft with
reaction wheels.

    z  = K int(sigma_BR dt) + [I] omega_BR_B            (integral term, Ki > 0 only; each
                                                          component of the sum clipped to
                                                          +-integral_limit)
    Lr = K sigma_BR + P omega_BR_B + P Ki z
         - (omega_RN_B + Ki z) x ([I] omega_BN_B + h_s)   (control_law 0; 1 uses omega_BN_B)
         + [I] (omega_BN_B x omega_RN_B - domega_RN_B) + L_known
    torque_cmd_B = -Lr                                    (the torque the body is to feel)

with omega_BN_B = omega_BR_B + omega_RN_B, [I] the spacecraft's inertia (wheels included) and
h_s the wheels' absolute spin momentum in B (the ReactionWheelArray's wheel_momentum_B). The
closed loop is globally asymptotically stable for K, P > 0 (Schaub and Junkins, Analytical
Mechanics of Space Systems, sec. 8.4 and 8.5). The integral is a running sum: at each update
the attitude error times the time since the last update is added (Basilisk's, which the first
update skips).
"""
import numpy as np

from ..core.checks import finite_vector, positive


class MrpFeedback:
    def __init__(self, inertia, K, P, Ki=0.0, integral_limit=0.0, control_law=0, known_torque_B=(0.0, 0.0, 0.0)):
        self.inertia = np.asarray(inertia, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(self.inertia)):
            raise ValueError("inertia_B must be 9 finite numbers (kg.m2)")
        self.K = positive("K", K, "N.m")
        self.P = positive("P", P, "N.m.s")
        self.Ki = float(Ki)
        if not self.Ki >= 0.0:
            raise ValueError(f"Ki = {Ki!r} 1/s must be >= 0 (0: no integral term)")
        self.integral_limit = float(integral_limit)
        if self.Ki > 0.0 and not self.integral_limit > 0.0:
            raise ValueError(f"integral_limit = {integral_limit!r} must be > 0 with the integral term on (Ki > 0)")
        if control_law not in (0, 1):
            raise ValueError(f"control_law = {control_law!r} must be 0 (gyroscopic term with omega_RN) or 1 "
                             "(with omega_BN)")
        self.control_law = control_law
        self.known_torque_B = np.array(finite_vector(known_torque_B, 3, "known_torque_B", "N.m"))
        self.int_sigma = np.zeros(3)
        self.dt = 0.0  # time since the last update (Basilisk: 0 at the first)

    def _integral(self, sigma_BR):
        s = self.int_sigma + self.K * self.dt * sigma_BR
        big = np.abs(s) > self.integral_limit
        s[big] *= self.integral_limit / np.abs(s[big])
        return s

    def torque(self, sigma_BR, omega_BR_B, omega_RN_B, domega_RN_B, wheel_momentum_B=(0.0, 0.0, 0.0)):
        """(torque_cmd_B = -Lr, the integral feedback part -P Ki z) at the current error."""
        sigma, w_BR, w_RN, dw_RN = (np.asarray(x, dtype=float) for x in (sigma_BR, omega_BR_B, omega_RN_B,
                                                                           domega_RN_B))
        inertia = self.inertia
        omega = w_BR + w_RN
        z = np.zeros(3)
        if self.Ki > 0.0:
            z = self._integral(sigma) + inertia @ w_BR
        Lr = self.K * sigma + self.P * w_BR + self.P * self.Ki * z
        H = inertia @ omega + np.asarray(wheel_momentum_B, dtype=float)
        Lr = Lr - np.cross(w_RN + self.Ki * z if self.control_law == 0 else omega, H)
        Lr = Lr + inertia @ (np.cross(omega, w_RN) - dw_RN) + self.known_torque_B
        return -Lr, -self.P * self.Ki * z

    def step(self, sigma_BR, h):
        """The update at the end of a step: the integral takes this error, then h passes."""
        if self.Ki > 0.0:
            self.int_sigma = self._integral(np.asarray(sigma_BR, dtype=float))
        self.dt = float(h)

    def reset(self):
        """The law off: the integral restarts from zero (Basilisk's Reset), the next update's dt is 0."""
        self.int_sigma = np.zeros(3)
        self.dt = 0.0

    def get_state(self):
        return {"int_sigma": self.int_sigma.tolist(), "dt": self.dt}

    def set_state(self, state):
        self.int_sigma = np.array(state["int_sigma"], dtype=float)
        self.dt = float(state["dt"])
