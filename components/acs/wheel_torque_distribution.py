"""Reaction-wheel torque distribution: the motor torques that give a body torque, and the
null-space motion that manages the wheel speeds (Basilisk's rwMotorTorque and rwNullSpace).

Minimum-norm distribution over the available wheels (rows g_i of [Gs], spin axes in B):

    u = -[Gs]^T ([Gs] [Gs]^T)^-1 torque_cmd_B

(the body feels -sum g_i u_i = torque_cmd_B); with fewer than three available wheels, or axes
that do not span the body, no torque is commanded. Null-space speed management adds

    u += [tau] (-K_Omega (Omega - Omega_desired)),   [tau] = I - [Gs]^T ([Gs] [Gs]^T)^-1 [Gs],

motor torques that change no body torque (they sum to zero along the body axes) but drive the
wheels toward the desired speeds (spread the momentum, keep them off zero speed): Schaub and
Junkins, Analytical Mechanics of Space Systems, sec. 4.5.3. [tau] is of the configured wheels
(Basilisk's; a failed wheel's null-space torque is not redistributed).
"""
import numpy as np

from ..core.checks import finite_vector
from .reaction_wheel_array import _unit_axes


class WheelTorqueDistribution:
    def __init__(self, axes, null_space_gain=0.0, desired_speeds=None):
        self.G = _unit_axes(axes)
        self.count = len(self.G)
        if not 1 <= self.count <= 6:
            raise ValueError(f"wheel_count = {self.count} must be in 1..6")
        self.null_space_gain = float(null_space_gain)
        if not self.null_space_gain >= 0.0:
            raise ValueError(f"null_space_gain = {null_space_gain!r} N.m.s must be >= 0 (0: no speed management)")
        self.desired = np.array(finite_vector([0.0] * self.count if desired_speeds is None else desired_speeds,
                                              self.count, "Omega_desired", "rad/s"))
        Gs = self.G.T  # 3 x N
        M = Gs @ Gs.T
        self.tau = None
        if self.count >= 3 and np.linalg.matrix_rank(M) == 3:
            self.tau = np.eye(self.count) - Gs.T @ np.linalg.inv(M) @ Gs

    def motor_torques(self, torque_cmd_B, speeds, available=None):
        """(minimum-norm torques, plus null-space torques) for this body torque and wheel speeds."""
        Lr = -np.array(finite_vector(torque_cmd_B, 3, "torque_cmd_B", "N.m"))
        ok = np.ones(self.count, bool) if available is None else np.asarray(available, bool)
        us = np.zeros(self.count)
        Gs = self.G[ok].T
        if ok.sum() >= 3:
            M = Gs @ Gs.T
            if abs(np.linalg.det(M)) > 1e-12:
                us[ok] = Gs.T @ np.linalg.solve(M, Lr)
        if self.tau is not None and self.null_space_gain > 0.0:
            d = -self.null_space_gain * (np.asarray(speeds, float) - self.desired)
            return us, us + self.tau @ d
        return us, us

    def get_state(self):
        return {}  # stateless

    def set_state(self, state):
        pass
