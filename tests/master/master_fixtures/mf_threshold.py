"""Test fixture: Boolean flag done = (x >= threshold), direct feedthrough; Integer output."""
from neighbor_fmu_support import NeighborSlave


class _ThrModel:
    def get_state(self):
        return None

    def set_state(self, state):
        pass


class MfThreshold(NeighborSlave):
    description = "Test threshold flag"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("threshold", 1.0, "m", "Threshold")
        self.parameter("n", 3, None, "An integer parameter", kind=int)
        self.parameter("enabled", True, None, "A Boolean parameter", kind=bool)
        self.input("x", 0.0, "m", "Signal")
        self.output("done", lambda: self.values["enabled"] and self.values["x"] >= self.values["threshold"],
                    None, "Flag", kind=bool, depends_on=["x"])
        self.output("n_out", lambda: self.values["n"], None, "Echo of n", kind=int)

    def build_model(self):
        return _ThrModel()

    def do_step(self, current_time, step_size):
        return True
