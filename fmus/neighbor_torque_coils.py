"""FMU `TorqueCoils` (instance `coils`): three magnetic torque coils along the body axes.

Wraps components.acs.magnetorquer.TorqueCoils: the commanded dipole saturated per axis (zero when
disabled) and the torque dipole x field. Both outputs are direct feedthrough of the inputs.
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import magnetorquer

class TorqueCoils(NeighborSlave):
    description = ("Magnetic torque coils on the body axes: commanded dipole saturated per axis, torque = "
                   "dipole x field")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("max_dipole", [0.2, 0.2, 0.2], "A.m2",
                             "Largest dipole magnitude of the coil on each body axis, >= 0 (CubeSat torque "
                             "rod/coil class)")
        dipole_cmd = self.input_array("dipole_cmd_B", [0.0, 0.0, 0.0], "A.m2", "Commanded magnetic dipole in B")
        field = self.input_array("B_B", [0.0, 0.0, 0.0], "T", "Geomagnetic field at the spacecraft in B")
        enabled = self.input("enabled", True, None, "Coils enabled; when false the dipole and torque are zero", bool)
        self.output_array("dipole_B", 3, self._dipole, "A.m2",
                          "Dipole produced: the command saturated per axis to +-max_dipole, 0 when disabled",
                          depends_on=dipole_cmd + (enabled,))
        self.output_array("torque_B", 3, lambda: self._torque()[1], "N.m",
                          "Magnetic torque on the body in B, dipole_B x B_B",
                          depends_on=dipole_cmd + (enabled,) + field)

    def _dipole(self):
        return self.model.dipole(self.vector("dipole_cmd_B", 3), self.values["enabled"])

    def _torque(self):
        return self.model.torque(self.vector("dipole_cmd_B", 3), self.vector("B_B", 3), self.values["enabled"])

    def build_model(self):
        return magnetorquer.TorqueCoils(self.vector("max_dipole", 3))

    def do_step(self, current_time, step_size):
        return True
