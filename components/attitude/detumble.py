"""Detumble controller: PD on body rates with thruster threshold logic.

Thesis Eq. 9-16 and Appendix C `Detumble`, stop test of Appendix D:

    L_i = Kp_i (omega_d,i - omega_i) - Kd_i omega_dot_i            (Eq. 12)
    saturate to +-pair torque, zero below it, zero if |omega_i - omega_d,i| <= tol_i
    done when  omega_i - omega_d,i <= tol_i  for every axis          (Appendix D)

The Appendix D test is one-sided (no absolute value): an axis whose rate overshoots below
the target counts as converged, so a spacecraft tumbling at -0.5 rad/s on every axis would be
"done" at once. The default is the two-sided test |omega_i - omega_d,i| <= tol_i;
`signed_stop_test=True` is the thesis' literal test (its validation-case parameter sets set it;
both end the thesis cases at the same step).
Settle criterion (flight option): with `settle_time` > 0 the controller is done once the stop
test has held for that long (thruster_control.SettleTimer); 0 is the thesis' single sample.
For a window the RCS can meet, omega_tol must exceed half the rate change of one minimum
firing (thruster_control.impulse_bit_rates): a pulse from just outside the window then lands
inside it instead of across it.
omega_dot is the angular acceleration of the last integration step (the scripts keep the
w_dot of the previous `StateChange`; zero before the first step).
"""
import math

from . import thruster_control as tc


class DetumbleController:
    def __init__(self, Kp, Kd, omega_d=(0.0, 0.0, 0.0), omega_tol=(math.radians(0.01),) * 3,
                 torque_level=None, signed_stop_test=False, settle_time=0.0):
        self.Kp = tc.check_gains("Kp", Kp)
        self.Kd = tc.check_gains("Kd", Kd)
        self.omega_d = tuple(float(x) for x in omega_d)
        if not all(math.isfinite(x) for x in self.omega_d):
            raise ValueError(f"omega_d {list(self.omega_d)} must be finite")
        self.omega_tol = tc.check_gains("omega_tol", omega_tol)
        self.levels = tc.check_levels(torque_level if torque_level is not None else tc.pair_torques())
        self.signed_stop_test = bool(signed_stop_test)
        self.settle = tc.SettleTimer(settle_time)

    def command(self, omega, omega_dot):
        """Quantized torque command (N.m) and thrust flags (-1/0/1) for the current rates."""
        raw = [self.Kp[i] * (self.omega_d[i] - omega[i]) - self.Kd[i] * omega_dot[i] for i in range(3)]
        torque, flags = tc.quantize(raw, self.levels)
        for i in range(3):
            if abs(omega[i] - self.omega_d[i]) <= self.omega_tol[i]:
                torque[i], flags[i] = 0.0, 0
        return torque, flags

    def done(self, omega):
        return self.settle.done(self.inside(omega))

    def advance(self, omega, h, enabled=True):
        """End of a step of h seconds whose stop test was evaluated on `omega`."""
        self.settle.advance(self.inside(omega), h, enabled)

    def inside(self, omega):
        """The single-sample stop test (Appendix D, or its two-sided form)."""
        if self.signed_stop_test:
            return all(omega[i] - self.omega_d[i] <= self.omega_tol[i] for i in range(3))
        return all(abs(omega[i] - self.omega_d[i]) <= self.omega_tol[i] for i in range(3))

    def get_state(self):
        return {"time_inside": self.settle.time_inside}  # the command is a function of the inputs

    def set_state(self, state):
        self.settle.time_inside = float(state["time_inside"])
