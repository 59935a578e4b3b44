"""FMU `BdotDetumble` (instance `detumble`): the three-axis B-dot detumble law with the magnetic
torque coils.

Wraps components.acs.magnetic_control.BdotDetumble: m = -k Bdot_B / |B|^2 with the field's rate in
B from the body rate (Bdot_B = -omega x B, a gyro) or from the field samples at the last two
communication points (magnetometer only). Connect dipole_cmd_B to TorqueCoils (which saturates it
per axis). With the body rate the dipole depends directly on B_B and omega_BN_B. With the field
difference the rate is a state: do_step takes the sample B_B at the step's start, so in a
Gauss-Seidel order put the coils after this FMU: they then read the command that uses it (the
flight computer's sample-then-command cycle); the dipole still depends directly on B_B (1/|B|^2).
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import magnetic_control


class BdotDetumble(NeighborSlave):
    description = ("Three-axis B-dot detumble: coil dipole command m = -k dB/dt / |B|^2 from the body rate or "
                   "from successive field samples")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("gain", 2.0e-3, "N.m.s", "B-dot gain k, >= 0 (2e-3: the coils of a CubeSat saturate "
                       "above ~0.2 deg/s)")
        self.parameter("use_field_difference", False, None,
                       "Field rate from successive B_B samples (magnetometer only) instead of -omega x B", bool)
        field = self.input_array("B_B", [0.0, 0.0, 0.0], "T", "Magnetic field in B (field FMU or magnetometer)")
        rate = self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s",
                                "Body angular velocity in B (gyro or rigid body; unused with the field difference)")
        enabled = self.input("enabled", True, None, "Law enabled; when false the command is zero", bool)
        self.output_array("dipole_cmd_B", 3, lambda: self.feedthrough(self._dipole), "A.m2",
                          "Commanded coil dipole in B (TorqueCoils' dipole_cmd_B)",
                          depends_on=field + rate + (enabled,))

    def build_model(self):
        v = self.values
        return magnetic_control.BdotDetumble(v["gain"], v["use_field_difference"])

    def _dipole(self):
        return self.model.dipole(self.vector("B_B", 3), self.vector("omega_BN_B", 3), self.values["enabled"]).tolist()

    def do_step(self, current_time, step_size):
        self.model.step(self.vector("B_B", 3), step_size)
        self._input_version += 1  # the field sample of the next difference
        return True
