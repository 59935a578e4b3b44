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

Flight options (defaults give the thesis law):
- `rate_deadband` (rad/s per axis): a pair fires only when |L_i| >= max(pair torque,
  Kd_i rate_deadband_i), i.e. when the switching function L_i / Kd_i is beyond the deadband.
  The thesis threshold (pair torque / Kd = 0.008 deg/s) is narrower than the rate change of
  one 15 ms pulse (0.017-0.043 deg/s), so near the target every pulse overshoots and the next
  fires back: the law limit-cycles and meets a 0.01 deg/s window only by chance. A
  deadband of one impulse bit (thruster_control.impulse_bit_rates) lets a pulse end inside it.
- `settle_time` (s) > 0: done once the attitude error angle is within `settle_angle` and every
  rate error within omega_tol, held for settle_time (the single-sample element test otherwise).
- set_target(q_d, omega_d): a moving target (the burn attitude from the guidance) replaces the
  fixed one; the tests use the rotation angle 2 acos|dq4|, which the target's sign cannot change.
"""
import math

from ..core import rotations
from . import thruster_control as tc


class SlewController:
    def __init__(self, Kp, Kd, q_d=(0.0, 0.0, 0.0, 1.0), omega_d=(0.0, 0.0, 0.0), q_tol=0.01,
                 omega_tol=(math.radians(0.01),) * 3, torque_level=None, accept_antipodal=False,
                 rate_deadband=(0.0, 0.0, 0.0), settle_time=0.0, settle_angle=math.radians(1.0)):
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
        self.rate_deadband = tc.check_gains("rate_deadband", rate_deadband)
        self.thresholds = tuple(max(lvl, kd * db) for lvl, kd, db in zip(self.levels, self.Kd, self.rate_deadband))
        self.settle = tc.SettleTimer(settle_time)
        if not (math.isfinite(settle_angle) and 0 < settle_angle <= math.pi):
            raise ValueError(f"settle_angle = {settle_angle!r} rad must be in (0, pi]")
        self.settle_angle = float(settle_angle)

    def set_target(self, q_d, omega_d):
        """Track a moving target: desired attitude q_d (unit, scalar last) and rate omega_d (rad/s, B)."""
        self.q_d = rotations.normalized(tuple(float(x) for x in q_d), "q_target_BN")
        omega_d = tuple(float(x) for x in omega_d)
        if not all(math.isfinite(x) for x in omega_d):
            raise ValueError(f"omega_target_B {list(omega_d)} must be finite")
        self.omega_d = omega_d

    def error_quaternion(self, q):
        return rotations.error_quaternion(q, self.q_d)

    def command(self, q, omega):
        dq = self.error_quaternion(q)
        s = rotations.sign(dq[3])
        raw = [-self.Kp[i] * s * dq[i] + self.Kd[i] * (self.omega_d[i] - omega[i]) for i in range(3)]
        return tc.quantize(raw, self.levels, self.thresholds)

    def attitude_error(self, q):
        """Rotation angle (rad) from the target to q, 2 acos|dq4| of the normalized error."""
        dq = rotations.normalized(self.error_quaternion(q), "q_BN")
        return 2.0 * math.acos(min(1.0, abs(dq[3])))

    def done(self, q, omega):
        return self.settle.done(self.inside(q, omega))

    def advance(self, q, omega, h, enabled=True):
        """End of a step of h seconds whose stop test was evaluated on (q, omega)."""
        self.settle.advance(self.inside(q, omega), h, enabled)

    def inside(self, q, omega):
        """The single-sample stop test: Appendix E/G's element test, or with a settle time the
        error angle and rates."""
        rates_ok = all(abs(omega[i] - self.omega_d[i]) <= self.omega_tol[i] for i in range(3))
        if self.settle.dwell > 0:
            return rates_ok and self.attitude_error(q) <= self.settle_angle
        tol, qd = self.q_tol, self.q_d
        if self.accept_antipodal:
            q_ok = all(abs(qd[i] - q[i]) <= tol or abs(-qd[i] - q[i]) <= tol for i in range(4))
        else:
            q_ok = all(abs(qd[i] - q[i]) <= tol for i in range(4))
        return q_ok and rates_ok

    def get_state(self):
        return {"time_inside": self.settle.time_inside, "q_d": list(self.q_d), "omega_d": list(self.omega_d)}

    def set_state(self, state):
        self.settle.time_inside = float(state["time_inside"])
        self.q_d, self.omega_d = tuple(state["q_d"]), tuple(state["omega_d"])
