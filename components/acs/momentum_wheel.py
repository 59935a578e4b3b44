"""A momentum (reaction) wheel on a fixed body axis: motor torque in, wheel rate and momentum out.

State: the wheel rate Omega (rad/s) relative to the body. Over a communication step the motor
torque tau (N.m, on the wheel, about axis_B) is held constant and

    J_w dOmega/dt = tau,      h_w = J_w Omega axis_B  (N.m.s, B frame),

integrated exactly (Omega += tau h / J_w). The body feels the reaction -tau axis_B; the rigid
body (components.attitude.rigid_body) takes wheel_torque_B = tau axis_B and wheel_momentum_B = h_w and
solves J omega_dot = L - wheel_torque_B - omega x (J omega + h_w), which conserves the total
angular momentum J omega + h_w. With h_w the momentum relative to the body and J the inertia of
the whole spacecraft, wheel included, this is the usual gyrostat form (Hughes, Spacecraft
Attitude Dynamics, 1986, ch. 3; Markley and Crassidis, 2014, sec. 3.3); the wheel equation
here neglects the J_w axis . omega_dot coupling term (the wheel's reaction to the body's own
angular acceleration about the axis), an error of order J_w / J_body (1e-4 for the defaults).

Limits:
- torque: the command is saturated to +-max_torque; `enabled` false gives zero torque;
- speed: at |Omega| >= max_speed no torque is applied that would speed the wheel up further,
  and a step that would cross max_speed ends at +-max_speed (the last step's torque then
  delivered less momentum than tau h: the body and wheel momenta differ by that excess for
  that one step).

Defaults: a small CubeSat wheel, J_w = 2.0e-5 kg.m2, 1 mN.m, 6000 rpm (628.3 rad/s), i.e.
12.6 mN.m.s of storage: the 10-20 mN.m.s class of commercial 1U-3U wheels, enough to take the
0.011 N.m.s of the 12 kg host box (Iy = 0.13 kg.m2) spinning 5 deg/s about Y, the specification's
spin-up rate.
"""
import math

from ..core import rotations
from ..core.checks import positive

RPM = 2.0 * math.pi / 60.0
DEFAULT_INERTIA = 2.0e-5  # kg.m2
DEFAULT_MAX_TORQUE = 1.0e-3  # N.m
DEFAULT_MAX_SPEED = 6000.0 * RPM  # rad/s


class MomentumWheel:
    def __init__(self, axis=(0.0, 1.0, 0.0), inertia=DEFAULT_INERTIA, max_torque=DEFAULT_MAX_TORQUE,
                 max_speed=DEFAULT_MAX_SPEED, omega0=0.0):
        axis = tuple(float(x) for x in axis)
        if len(axis) != 3 or not all(math.isfinite(x) for x in axis) or rotations.norm(axis) < 1e-12:
            raise ValueError(f"axis_B {list(axis)} must be a finite, non-zero 3-vector (it is normalized)")
        n = rotations.norm(axis)
        self.axis = (axis[0] / n, axis[1] / n, axis[2] / n)
        self.inertia = positive("J_w", inertia, "kg.m2")
        self.max_torque = positive("max_torque", max_torque, "N.m")
        self.max_speed = positive("max_speed", max_speed, "rad/s")
        omega0 = float(omega0)
        if not (math.isfinite(omega0) and abs(omega0) <= self.max_speed):
            raise ValueError(f"Omega0 = {omega0!r} must be a finite wheel rate in [-max_speed, max_speed] "
                             f"= [{-self.max_speed}, {self.max_speed}] rad/s")
        self.rate = omega0

    def applied_torque(self, torque_cmd, enabled=True):
        """Motor torque on the wheel about the axis (N.m) for the command and the current rate."""
        if not enabled:
            return 0.0
        tau = float(torque_cmd)
        if math.isnan(tau):
            raise ValueError("torque_cmd = nan must be a number (N.m)")
        m = self.max_torque
        tau = m if tau > m else (-m if tau < -m else tau)
        if (self.rate >= self.max_speed and tau > 0.0) or (self.rate <= -self.max_speed and tau < 0.0):
            return 0.0
        return tau

    def torque_B(self, torque_cmd, enabled=True):
        """Motor torque on the wheel in B (the body feels the opposite), N.m."""
        tau = self.applied_torque(torque_cmd, enabled)
        a = self.axis
        return (tau * a[0], tau * a[1], tau * a[2])

    def momentum_B(self):
        """h_w = J_w Omega axis_B, N.m.s (relative to the body)."""
        h = self.inertia * self.rate
        a = self.axis
        return (h * a[0], h * a[1], h * a[2])

    def step(self, torque_cmd, enabled, h):
        """Advance by h seconds with the command held constant."""
        tau = self.applied_torque(torque_cmd, enabled)
        w = self.rate + tau / self.inertia * h
        m = self.max_speed
        self.rate = m if w > m else (-m if w < -m else w)

    def get_state(self):
        return {"rate": self.rate}

    def set_state(self, state):
        self.rate = float(state["rate"])
