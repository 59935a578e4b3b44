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

import numpy as np

from ..core.jit import njit
from . import thruster_control as tc

# detumble_into's outputs, in the order of its `outputs` indices, and inputs
PUBLISHED = (("torque_cmd_B", 3), ("thrust_flag", 3), ("done", 1))
READS = (("omega_BN_B", 3), ("omega_dot_BN_B", 3), ("enabled", 1))


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
        # the law's constants as detumble_into reads them
        self.constants = np.array(self.Kp + self.Kd + self.omega_d + self.omega_tol + tuple(self.levels)
                                  + (float(self.signed_stop_test), self.settle.dwell))

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

    def step_into(self, values, inputs, outputs, h, stepping=True):
        """The FMU's step (stepping: advance by h) or publish in one compiled call: omega,
        omega_dot and enabled at values[inputs] (READS), then the gated command and the stop test
        written to values[outputs] (PUBLISHED)."""
        self.settle.time_inside = detumble_into(self.constants, values, inputs, outputs, h, self.settle.time_inside,
                                                stepping)

    def get_state(self):
        return {"time_inside": self.settle.time_inside}  # the command is a function of the inputs

    def set_state(self, state):
        self.settle.time_inside = float(state["time_inside"])


@njit(cache=True, plain_first=True)
def detumble_into(k, values, inputs, outputs, h, time_inside, stepping):
    """DetumbleController on its constants k (Kp, Kd, omega_d, omega_tol, levels, signed test,
    settle time): the stop test on omega = values[inputs[0:3]]; with `stepping` the settle count
    advanced by h (advance); then values[outputs] = the command for omega and omega_dot
    (values[inputs[3:6]]), zero when values[inputs[6]] (enabled) is 0, its flags, and done. The
    same operations as command, done and advance. Returns the settle count."""
    signed = k[15] != 0.0
    inside = True
    for i in range(3):
        d = values[inputs[i]] - k[6 + i]
        if not ((d if signed else abs(d)) <= k[9 + i]):
            inside = False
    enabled = values[inputs[6]] != 0.0
    if stepping:
        time_inside = time_inside + h if (inside and enabled) else 0.0
    for i in range(3):
        torque, flag = 0.0, 0
        if enabled:
            w, level = values[inputs[i]], k[12 + i]
            raw = k[i] * (k[6 + i] - w) - k[3 + i] * values[inputs[3 + i]]
            if raw >= level:
                torque, flag = level, 1
            elif raw <= -level:
                torque, flag = -level, -1
            if abs(w - k[6 + i]) <= k[9 + i]:
                torque, flag = 0.0, 0
        values[outputs[i]] = torque
        values[outputs[3 + i]] = flag
    values[outputs[6]] = 1.0 if (inside and time_inside >= k[16]) else 0.0
    return time_inside
