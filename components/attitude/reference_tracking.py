"""Reference-tracking attitude controller: PD on the quaternion error to a moving reference,
plus the reference's feed-forward torque.

    dq = q (x) q_ref^-1                      (thesis Eq. 41 with the moving reference q_ref)
    L  = torque_ff - Kp sign(dq4) dq_1:3 + Kd (omega_ref - omega)

sign(dq4) makes the controller take the short way to q_ref or -q_ref (sign(0) = 0, as in
components/attitude/slew.py). omega_ref is the reference rate in the reference body frame; near the
reference it equals its components in the actual body frame to first order in the error.

Torque modes:
- quantize = False (continuous, to track a smooth profile): each axis clipped to +-max_torque;
  thrust_flag is the sign of the torque (1, -1, 0).
- quantize = True: the thesis' thruster threshold logic (components/thruster_control.quantize)
  with max_torque as the pair torque: +-max_torque when |L| >= max_torque, else 0.

done: the guidance reports its profile ended, the rotation angle of dq, 2 acos|dq4|, is at most
angle_tol and every |omega_i - omega_ref,i| at most rate_tol.

Gains (defaults): per axis a second-order error loop J theta'' + Kd theta' + Kp/2 theta = 0
(dq_1:3 ~ theta/2) with natural frequency 1 rad/s and damping 0.9 on the NEIGHBOR box inertia
(12 kg, 0.1 x 0.2 x 0.3 m: J = diag(0.05, 0.13, 0.10) kg.m2): Kp = 2 J wn^2, Kd = 2 zeta wn J.
"""
import math

from ..core import rotations
from . import thruster_control as tc

NEIGHBOR_J = (0.05, 0.13, 0.10)
DEFAULT_KP = tuple(2.0 * j * 1.0 ** 2 for j in NEIGHBOR_J)
DEFAULT_KD = tuple(2.0 * 0.9 * 1.0 * j for j in NEIGHBOR_J)
DEFAULT_MAX_TORQUE = tuple(tc.pair_torques())  # the thesis' thruster-pair torques


class ReferenceTrackingController:
    def __init__(self, Kp=DEFAULT_KP, Kd=DEFAULT_KD, max_torque=DEFAULT_MAX_TORQUE, quantize=False,
                 angle_tol=math.radians(0.1), rate_tol=math.radians(0.01)):
        self.Kp = tc.check_gains("Kp", Kp)
        self.Kd = tc.check_gains("Kd", Kd)
        mt = tuple(float(x) for x in max_torque)
        if len(mt) != 3 or not all(math.isfinite(x) and x > 0 for x in mt):
            raise ValueError(f"max_torque {list(mt)} must be three finite positive torques (N.m)")
        self.max_torque = mt
        self.quantize = bool(quantize)
        for name, v in (("angle_tol", angle_tol), ("rate_tol", rate_tol)):
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} = {v!r} must be a positive number (rad or rad/s)")
        if angle_tol >= math.pi:
            raise ValueError(f"angle_tol = {angle_tol!r} rad must be in (0, pi)")
        self.angle_tol = float(angle_tol)
        self.rate_tol = float(rate_tol)

    @staticmethod
    def error_quaternion(q, q_ref):
        q = rotations.normalized(q, "q_BN")
        q_ref = rotations.normalized(q_ref, "q_ref_BN")
        return rotations.error_quaternion(q, q_ref)

    def error_angle(self, q, q_ref):
        dq = self.error_quaternion(q, q_ref)
        return 2.0 * math.acos(min(1.0, abs(dq[3])))

    def raw_torque(self, q, omega, q_ref, omega_ref, torque_ff):
        dq = self.error_quaternion(q, q_ref)
        s = rotations.sign(dq[3])
        return [torque_ff[i] - self.Kp[i] * s * dq[i] + self.Kd[i] * (omega_ref[i] - omega[i]) for i in range(3)]

    def command(self, q, omega, q_ref, omega_ref, torque_ff):
        """(torque_cmd_B, thrust_flag) for the current measurement and reference."""
        raw = self.raw_torque(q, omega, q_ref, omega_ref, torque_ff)
        if self.quantize:
            return tc.quantize(raw, self.max_torque)
        torque = [min(self.max_torque[i], max(-self.max_torque[i], raw[i])) for i in range(3)]
        return torque, [rotations.sign(x) for x in torque]

    def done(self, q, omega, q_ref, omega_ref, guidance_done):
        return (bool(guidance_done) and self.error_angle(q, q_ref) <= self.angle_tol
                and all(abs(omega[i] - omega_ref[i]) <= self.rate_tol for i in range(3)))

    def get_state(self):
        return {}

    def set_state(self, state):
        pass
