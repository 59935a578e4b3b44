"""FMU `MomentumDumping` (instance `dumping`): reaction-wheel momentum dumping through the magnetic
torque coils, the cross-product law with the coils' torque fed forward to the wheels.

Wraps components.acs.magnetic_control.MomentumDumping (Basilisk's mtbMomentumManagementSimple,
torque2Dipole, dipoleMapping with the rods on the body axes, and mtbFeedforward): the wheels'
momentum from their speeds asks the coils for -gain h_w, the dipole B x tau / |B|^2 is clipped per
axis, and its torque is taken out of the attitude controller's command. Wire it between the
controller and the distribution: MrpFeedback.torque_cmd_B -> torque_cmd_B,
torque_cmd_wheels_B -> WheelTorqueDistribution.torque_cmd_B, dipole_cmd_B -> TorqueCoils. The
wheel count and spin axes are the wheel FMUs' parameters (same names). Stateless.
"""
from neighbor_fmu_support import NeighborSlave
from neighbor_wheel_support import SLOTS as N, wheel_axes, wheel_geometry_parameters

from components.acs import magnetic_control
from components.acs import reaction_wheel_array as rwa
from components.core.names import element_names


class MomentumDumping(NeighborSlave):
    description = ("Wheel momentum dumping with the magnetic coils: dipole B x (-k h_w) / |B|^2 clipped per axis, "
                   "the coils' torque fed forward out of the wheels' torque command")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        wheel_geometry_parameters(self, "Number of wheels")
        self.parameter_array("J_s", [rwa.DEFAULT_INERTIA] * N, "kg.m2", "Wheel spin-axis inertia, > 0")
        self.parameter("gain", 1.0e-3, "1/s", "Dumping gain k: the coils are asked for -k h_w, >= 0 (0: off)")
        self.parameter_array("max_dipole", [0.2, 0.2, 0.2], "A.m2",
                             "Largest dipole of the coil on each body axis, >= 0 (TorqueCoils' max_dipole)")
        speeds = self.input_array("wheel_speed", [0.0] * N, "rad/s", "Wheel speeds relative to the body "
                                  "(ReactionWheelArray)")
        field = self.input_array("B_B", [0.0, 0.0, 0.0], "T", "Magnetic field in B (magnetometer or field FMU)")
        torque = self.input_array("torque_cmd_B", [0.0, 0.0, 0.0], "N.m",
                                  "Torque the body is to feel from the attitude controller (MrpFeedback)")
        enabled = self.input("enabled", True, None, "Dumping enabled; when false no dipole (the torque command "
                             "passes through)", bool)
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        dipole_inputs = speeds + field + (enabled,)
        self.output_array("dipole_cmd_B", 3, lambda: out()[0], "A.m2",
                          "Coil dipole command in B, clipped to +-max_dipole (TorqueCoils' dipole_cmd_B)",
                          depends_on=dipole_inputs)
        self.output_array("coil_torque_B", 3, lambda: out()[1], "N.m", "Torque the clipped dipole makes, m x B",
                          depends_on=dipole_inputs)
        self.output_array("torque_cmd_wheels_B", 3, lambda: out()[2], "N.m",
                          "Torque the wheels are to give: torque_cmd_B - m x B (WheelTorqueDistribution's "
                          "torque_cmd_B)", depends_on=dipole_inputs + torque)
        self.output_array("wheel_momentum_B", 3, lambda: out()[3], "N.m.s",
                          "Wheel momentum from the speeds, sum g_i J_s,i Omega_i", depends_on=speeds)

    def build_model(self):
        v = self.values
        count, axes = wheel_axes(v)
        J_s = [v[e] for e in element_names("J_s", N)][:count]
        return magnetic_control.MomentumDumping(axes, J_s, v["gain"], self.vector("max_dipole", 3))

    def _evaluate(self):
        m = self.model
        return [x.tolist() for x in m.evaluate(self.vector("wheel_speed", N)[:m.count], self.vector("B_B", 3),
                                               self.vector("torque_cmd_B", 3), self.values["enabled"])]

    def do_step(self, current_time, step_size):
        return True
