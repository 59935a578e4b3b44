"""What the magnetic-field FMUs share (MagneticField, MagneticFieldIgrf): their connector contract,
so that `neighbor-cosim replace` swaps one for the other, and the stepping of a model that keeps
the simulation time."""
from neighbor_fmu_support import NeighborSlave

from components.core import time_utils
from components.environment import magnetic_field


class FieldSlave(NeighborSlave):
    """Declares `epoch`, `secular_variation` (its description: `secular_text`, its start:
    `secular_start`), the inputs r_BN_N and q_BN and the outputs B_N and B_B; the subclass builds
    the model (field_N, field_B, advance_to) from self.values and self._start_time."""

    def __init__(self, epoch_text, secular_text, secular_start, **kwargs):
        super().__init__(**kwargs)
        self._start_time = 0.0
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None, epoch_text, str)
        self.parameter("secular_variation", secular_start, None, secular_text, bool)
        position = self.input_array("r_BN_N", [magnetic_field.R_REF + 500e3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N (must be non-zero)")
        quaternion = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                                      "Attitude quaternion of B relative to N, scalar last (normalized before use)")
        self.output_array("B_N", 3, self._field_N, "T",
                          "Geomagnetic field at the spacecraft in N", depends_on=position)
        self.output_array("B_B", 3, self._field_B, "T",
                          "Geomagnetic field at the spacecraft in B, A(q_BN) B_N", depends_on=position + quaternion)

    def _field_N(self):
        return self.model.field_N(self.vector("r_BN_N", 3))

    def _field_B(self):
        return self.model.field_B(self.vector("r_BN_N", 3), self.vector("q_BN", 4))

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._start_time = float(start_time)
        self._model = None

    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True
