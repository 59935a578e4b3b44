"""FMU `AttitudeToDcm` (instance `to_dcm`): quaternion to direction cosine matrix.

Wraps components.sensing.air_bearing.AttitudeToDcm: dcm_BN = A(q_BN / |q_BN|) (thesis Eq. 22), [BN]
maps N components to B components. Direct feedthrough, stateless; lets the air-bearing
system drive the DCM-input kinematics FMU from the RigidBody FMU.
"""
from neighbor_fmu_support import NeighborSlave

from components.sensing import air_bearing

Q_INPUTS = [f"q_BN[{i}]" for i in (1, 2, 3, 4)]


class AttitudeToDcm(NeighborSlave):
    description = ("Attitude quaternion q_BN (scalar last) to DCM [BN] = A(q) (NEIGHBOR thesis Eq. 22), "
                   "normalized first; direct feedthrough")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                         "Attitude quaternion of B relative to N, scalar last (normalized; zero is an error)")
        for i in range(1, 4):
            for j in range(1, 4):
                self.output(f"dcm_BN[{i},{j}]", lambda i=i, j=j: self.feedthrough(self._dcm)[i - 1][j - 1], "1",
                            f"DCM [BN] = A(q) element ({i},{j}): maps N components to B components",
                            depends_on=Q_INPUTS)

    def build_model(self):
        return air_bearing.AttitudeToDcm()

    def _dcm(self):
        return self.model.dcm(self.vector("q_BN", 4))

    def do_step(self, current_time, step_size):
        return True
