"""FMU `AttitudeToDcm` (instance `to_dcm`): quaternion to direction cosine matrix.

Wraps components.sensing.air_bearing.AttitudeToDcm: dcm_BN = A(q_BN / |q_BN|) (thesis Eq. 22), [BN]
maps N components to B components. Direct feedthrough, stateless; lets the air-bearing
system drive the DCM-input kinematics FMU from the RigidBody FMU.
"""
from neighbor_fmu_support import NeighborSlave

from components.core.names import matrix_names
from components.sensing import air_bearing


class AttitudeToDcm(NeighborSlave):
    description = ("Attitude quaternion q_BN (scalar last) to DCM [BN] = A(q) (NEIGHBOR thesis Eq. 22), "
                   "normalized first; direct feedthrough")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        quaternion = self.input_array(
            "q_BN", [0.0, 0.0, 0.0, 1.0], "1",
            "Attitude quaternion of B relative to N, scalar last (normalized; zero is an error)")
        for i, row in enumerate(matrix_names("dcm_BN", 3, 3), 1):
            for j, element in enumerate(row, 1):
                self.output(element, lambda i=i, j=j: self.feedthrough(self._dcm)[i - 1][j - 1], "1",
                            f"DCM [BN] = A(q) element ({i},{j}): maps N components to B components",
                            depends_on=quaternion)

    def build_model(self):
        return air_bearing.AttitudeToDcm()

    def _dcm(self):
        return self.model.dcm(self.vector("q_BN", 4))

    def do_step(self, current_time, step_size):
        return True
