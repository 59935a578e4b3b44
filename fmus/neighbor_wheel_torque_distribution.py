"""FMU `WheelTorqueDistribution` (instance `distribution`): the reaction-wheel motor torques that
give a commanded body torque (minimum norm over the available wheels), plus null-space motor
torques that drive the wheel speeds toward desired ones without changing the body torque
(Basilisk's rwMotorTorque and rwNullSpace).

Wraps components.acs.wheel_torque_distribution.WheelTorqueDistribution. The spin axes are the
ReactionWheelArray's (same parameter names and defaults: a four-wheel pyramid about +z); slots
above wheel_count are zero. Stateless: the outputs depend directly on the inputs.
"""
from neighbor_fmu_support import NeighborSlave
from neighbor_wheel_support import SLOTS as N, padded, wheel_axes, wheel_geometry_parameters

from components.acs import wheel_torque_distribution
from components.core.names import element_names


class WheelTorqueDistribution(NeighborSlave):
    description = ("Reaction-wheel torque distribution: minimum-norm motor torques for a body torque command, "
                   "plus null-space wheel-speed management")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        wheel_geometry_parameters(self, "Number of wheels")
        self.parameter("null_space_gain", 0.0, "N.m.s",
                       "Null-space speed gain K_Omega (N.m per rad/s of speed error), >= 0 (0: off)")
        self.parameter_array("Omega_desired", [0.0] * N, "rad/s", "Wheel speeds the null-space motion drives toward")
        torque = self.input_array("torque_cmd_B", [0.0] * 3, "N.m", "Torque the body is to feel, in B (MrpFeedback)")
        speeds = self.input_array("wheel_speed", [0.0] * N, "rad/s", "Wheel speeds relative to the body "
                                  "(ReactionWheelArray)")
        available = self.input_array("wheel_available", [True] * N, None, "Wheel available for the distribution",
                                     bool)
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        self.output_array("wheel_torque_cmd", N, lambda: padded(out()[1]), "N.m",
                          "Motor torque command per wheel (minimum norm plus null space; ReactionWheelArray's "
                          "torque_cmd)", depends_on=torque + speeds + available)
        self.output_array("minimum_norm_torque", N, lambda: padded(out()[0]), "N.m",
                          "The minimum-norm part of the command", depends_on=torque + available)

    def build_model(self):
        v = self.values
        count, axes = wheel_axes(v)
        desired = [v[e] for e in element_names("Omega_desired", N)][:count]
        return wheel_torque_distribution.WheelTorqueDistribution(axes, v["null_space_gain"], desired)

    def _evaluate(self):
        count = self.model.count
        return self.model.motor_torques(self.vector("torque_cmd_B", 3), self.vector("wheel_speed", N)[:count],
                                        self.vector("wheel_available", N)[:count])

    def do_step(self, current_time, step_size):
        return True
