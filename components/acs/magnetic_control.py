"""Magnetic-torquer laws of a wheel-and-coil CubeSat: a three-axis B-dot detumble and reaction-wheel
momentum dumping (the cross-product law with the coils' torque fed forward to the wheels).

Coils: three, along the body axes (components.acs.magnetorquer.TorqueCoils), each saturating at
+-max_dipole; a dipole m (A.m2) in the field B (T) gives the torque m x B (N.m). A desired torque
tau_d is produced as well as coils can by the cross-product law

    m = B x tau_d / |B|^2,   so   m x B = tau_d - (tau_d . b) b   (b = B / |B|)

(the component along the field cannot be made), no command when |B| < 1 nT.

B-dot detumble (BdotDetumble): m = -k Bdot_B / |B|^2 on all three axes, with the field's rate in
B either from the body rate, Bdot_B = -omega x B (the field's own inertial change over a step is
small against a tumble's), or from successive field samples (magnetometer only, no gyro):
Bdot_B = (B_k - B_k-1) / h from the samples at the last two communication points, zero until
the second. With the body rate the kinetic energy
T = 1/2 omega . J omega obeys dT/dt = omega . (m x B) = -k |omega x B|^2 / |B|^2 <= 0 with the
unsaturated dipole and stays <= 0 when the coils clip each axis (each component keeps its sign).
The law removes the rate across the field; the field turning over an orbit reaches the rest.
The ACS seed's detumble is this law restricted to the Y coil (components.acs.control).

Momentum dumping (MomentumDumping): the wheels' momentum in B from their speeds (what a flight
computer knows, Basilisk's mtbMomentumManagementSimple), h_w = sum g_i J_s,i Omega_i, asks the
coils for tau_d = -k_dump h_w, the cross-product law gives the dipole, clipped per axis to
max_dipole (Basilisk's torque2Dipole and dipoleMapping with the rods on the body axes), and the
torque the clipped dipole makes, m x B, is subtracted from the attitude controller's torque
command before the wheel distribution (Basilisk's mtbFeedforward): the wheels then absorb the
coils' torque, so the attitude holds while the coils change the wheels' momentum at -k_dump h_w
(less the part along B). The field is the magnetometer's (or the field model's) B in B.
"""

import numpy as np

from ..core.checks import finite_vector, non_negative
from .reaction_wheel_array import _unit_axes

B_MIN = 1.0e-9  # T: below it the field is taken as absent (no coil command)


def _max_dipole(max_dipole):
    md = np.array(finite_vector(max_dipole, 3, "max_dipole", "A.m2"))
    if np.any(md < 0.0):
        raise ValueError(f"max_dipole {md.tolist()} must be >= 0 A.m2 on every axis")
    return md


def cross_product_dipole(torque_B, field_B):
    """The dipole m = B x tau / |B|^2 (A.m2) whose torque m x B is tau less its part along B;
    zero when |B| < B_MIN."""
    B = np.asarray(field_B, float)
    b2 = float(B @ B)
    if not b2 > B_MIN * B_MIN:
        return np.zeros(3)
    return np.cross(B, np.asarray(torque_B, float)) / b2


class BdotDetumble:
    """BdotDetumble(gain N.m.s, use_field_difference=False): the dipole command (A.m2) of the
    three-axis B-dot law; the coils saturate it.

    A flight computer's cycle with the field difference: `step(B, h)` takes the sample at the
    start of a step of h seconds (the field rate becomes (this sample - the last) / the last
    interval), then `dipole(B)` commands with it, held over the step. The FMU runs the same
    cycle: its do_step takes the sample, and a consumer stepped after it reads the command that
    uses it (Gauss-Seidel)."""

    def __init__(self, gain=2.0e-3, use_field_difference=False):
        self.gain = non_negative("gain", gain, "N.m.s")
        self.use_field_difference = bool(use_field_difference)
        self.previous_field = None  # the last sample (field-difference mode)
        self.interval = 0.0  # s, from that sample to the next
        self.field_rate = np.zeros(3)  # T/s, from the last two samples

    def dipole(self, field_B, omega_BN_B=(0.0, 0.0, 0.0), enabled=True):
        B = np.array(finite_vector(field_B, 3, "B_B", "T"))
        if self.use_field_difference:
            rate = self.field_rate
        else:
            rate = -np.cross(np.array(finite_vector(omega_BN_B, 3, "omega_BN_B", "rad/s")), B)
        b2 = float(B @ B)
        if not enabled or not b2 > B_MIN * B_MIN:
            return np.zeros(3)
        return -self.gain * rate / b2

    def step(self, field_B, h):
        """The sample at the start of a step of h seconds (field-difference mode): the field rate
        from it and the last one."""
        if not self.use_field_difference:
            return
        B = np.array(finite_vector(field_B, 3, "B_B", "T"))
        if self.previous_field is not None and self.interval > 0.0:
            self.field_rate = (B - self.previous_field) / self.interval
        self.previous_field, self.interval = B, float(h)

    def get_state(self):
        return {"previous_field": None if self.previous_field is None else self.previous_field.tolist(),
                "interval": self.interval, "field_rate": self.field_rate.tolist()}

    def set_state(self, state):
        p = state["previous_field"]
        self.previous_field = None if p is None else np.array(p, float)
        self.interval = float(state["interval"])
        self.field_rate = np.array(state["field_rate"], float)


class MomentumDumping:
    """MomentumDumping(axes, J_s, gain 1/s, max_dipole A.m2): the coils' dipole command and the
    wheels' torque command with the coils' torque fed forward (see the module)."""

    def __init__(self, axes, J_s, gain=1.0e-3, max_dipole=(0.2, 0.2, 0.2)):
        self.G = _unit_axes(axes)
        self.count = len(self.G)
        self.J_s = np.array(finite_vector(J_s, self.count, "J_s", "kg.m2"))
        if np.any(self.J_s <= 0.0):
            raise ValueError(f"J_s {self.J_s.tolist()} must be > 0 kg.m2 for every wheel")
        self.gain = non_negative("gain", gain, "1/s")
        self.max_dipole = _max_dipole(max_dipole)

    def wheel_momentum(self, speeds):
        """h_w = sum g_i J_s,i Omega_i (N.m.s, B) from the wheel speeds relative to the body."""
        return self.G.T @ (self.J_s * np.array(finite_vector(speeds, self.count, "wheel_speed", "rad/s")))

    def evaluate(self, speeds, field_B, torque_cmd_B=(0.0, 0.0, 0.0), enabled=True):
        """(dipole_cmd_B, coil torque m x B, torque command for the wheels, h_w) at these inputs."""
        B = np.array(finite_vector(field_B, 3, "B_B", "T"))
        torque = np.array(finite_vector(torque_cmd_B, 3, "torque_cmd_B", "N.m"))
        h_w = self.wheel_momentum(speeds)
        m = np.zeros(3)
        if enabled:
            m = np.clip(cross_product_dipole(-self.gain * h_w, B), -self.max_dipole, self.max_dipole)
        coil_torque = np.cross(m, B)
        return m, coil_torque, torque - coil_torque, h_w

    def get_state(self):
        return {}  # stateless

    def set_state(self, state):
        pass
