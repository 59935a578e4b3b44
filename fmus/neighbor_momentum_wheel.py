"""FMU `MomentumWheel` (instance `wheel`): a momentum wheel on a fixed body axis.

Wraps components.acs.momentum_wheel.MomentumWheel: J_w dOmega/dt = tau with the motor torque
saturated (and none beyond the speed limit). wheel_rate and wheel_momentum_B are states (no
direct dependencies); wheel_torque_B depends directly on torque_cmd and enabled. Connect
wheel_torque_B and wheel_momentum_B to the RigidBody inputs of the same names.
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import momentum_wheel


class MomentumWheel(NeighborSlave):
    description = ("Momentum wheel on a body axis: motor torque in (saturated, speed-limited), wheel rate, "
                   "wheel torque and momentum in B out")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("axis_B", [0.0, 1.0, 0.0], "1", "Wheel spin axis in B (normalized; non-zero)")
        self.parameter("J_w", momentum_wheel.DEFAULT_INERTIA, "kg.m2", "Wheel spin-axis inertia, > 0")
        self.parameter("max_torque", momentum_wheel.DEFAULT_MAX_TORQUE, "N.m", "Largest motor torque, > 0")
        self.parameter("max_speed", momentum_wheel.DEFAULT_MAX_SPEED, "rad/s",
                       "Largest wheel rate relative to the body, > 0 (default 6000 rpm)")
        self.parameter("Omega0", 0.0, "rad/s", "Initial wheel rate relative to the body, |Omega0| <= max_speed")
        self.input("torque_cmd", 0.0, "N.m", "Commanded motor torque on the wheel about axis_B")
        self.input("enabled", True, None, "Wheel motor enabled; when false the motor torque is zero", bool)
        m = lambda: self.model  # noqa: E731
        self.output("wheel_rate", lambda: m().rate, "rad/s", "Wheel rate Omega relative to the body")
        self.output_array("wheel_momentum_B", 3, lambda: m().momentum_B(), "N.m.s",
                          "Wheel angular momentum relative to the body in B, J_w Omega axis_B")
        self.output_array("wheel_torque_B", 3, self._torque, "N.m",
                          "Motor torque on the wheel in B (saturated; 0 beyond max_speed or when disabled); "
                          "the body feels the opposite", depends_on=["torque_cmd", "enabled"])

    def _torque(self):
        return self.model.torque_B(self.values["torque_cmd"], self.values["enabled"])

    def build_model(self):
        return momentum_wheel.MomentumWheel(self.vector("axis_B", 3), self.values["J_w"], self.values["max_torque"],
                                            self.values["max_speed"], self.values["Omega0"])

    def do_step(self, current_time, step_size):
        self.model.step(self.values["torque_cmd"], self.values["enabled"], step_size)
        return True
