"""Slew controller: quaternion-error PD with thruster threshold logic.

Thesis Eq. 41-46 and Appendix C `Slew`; stop test of Appendix E (and G):

    delta_q = q (x) q_d^-1                                           (Eq. 41)
    L = -Kp sign(delta_q4) delta_q_1:3 + Kd (omega_d - omega)         (Eq. 46)
    saturate to +-pair torque, zero below it (no rate dead band, unlike detumble)
    done when |q_d,i - q_i| <= q_tol for i = 1..4 and |omega_i - omega_d,i| <= omega_tol_i

sign(0) = 0, as in FreeFlyer and numpy: exactly at the singularity (a 180 deg error, delta_q4
= 0) the proportional term vanishes and only the rate term acts until the attitude moves off
it. Appendix G (slew case 3) also accepts the antipodal target: `accept_antipodal=True` tests
each element against q_d,i or -q_d,i as the script does (element by element).
"""
import math

from ..core import rotations
from . import thruster_control as tc


class SlewController:
    def __init__(self, Kp, Kd, q_d=(0.0, 0.0, 0.0, 1.0), omega_d=(0.0, 0.0, 0.0), q_tol=0.01,
                 omega_tol=(math.radians(0.01),) * 3, torque_level=None, accept_antipodal=False):
        self.Kp = tc.check_gains("Kp", Kp)
        self.Kd = tc.check_gains("Kd", Kd)
        self.q_d = rotations.normalized(tuple(float(x) for x in q_d), "q_d")
        self.omega_d = tuple(float(x) for x in omega_d)
        if not all(math.isfinite(x) for x in self.omega_d):
            raise ValueError(f"omega_d {list(self.omega_d)} must be finite")
        if not (math.isfinite(q_tol) and q_tol > 0):
            raise ValueError(f"q_tol = {q_tol!r} must be a positive number")
        self.q_tol = float(q_tol)
        self.omega_tol = tc.check_gains("omega_tol", omega_tol)
        self.levels = tc.check_levels(torque_level if torque_level is not None else tc.pair_torques())
        self.accept_antipodal = bool(accept_antipodal)

    def error_quaternion(self, q):
        return rotations.error_quaternion(q, self.q_d)

    def command(self, q, omega):
        dq = self.error_quaternion(q)
        s = rotations.sign(dq[3])
        raw = [-self.Kp[i] * s * dq[i] + self.Kd[i] * (self.omega_d[i] - omega[i]) for i in range(3)]
        return tc.quantize(raw, self.levels)

    def done(self, q, omega):
        tol, qd = self.q_tol, self.q_d
        if self.accept_antipodal:
            q_ok = all(abs(qd[i] - q[i]) <= tol or abs(-qd[i] - q[i]) <= tol for i in range(4))
        else:
            q_ok = all(abs(qd[i] - q[i]) <= tol for i in range(4))
        return q_ok and all(abs(omega[i] - self.omega_d[i]) <= self.omega_tol[i] for i in range(3))

    def get_state(self):
        return {}

    def set_state(self, state):
        pass
