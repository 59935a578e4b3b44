"""Test fixture: gain block y = k*u + b (direct feedthrough), with a parameter check."""
from neighbor_fmu_support import NeighborSlave


class _GainModel:
    def __init__(self, k, b):
        self.k = k
        self.b = b

    def get_state(self):
        return None

    def set_state(self, state):
        pass


class MfGain(NeighborSlave):
    description = "Test gain y = k*u + b"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("k", 1.0, "1", "Gain")
        self.parameter("b", 0.0, "m", "Bias")
        self.parameter("k_max", 1.0e6, "1", "Largest allowed |k|")
        self.parameter("label", "gain", None, "A label", kind=str)
        self.input("u", 0.0, "m", "Input")
        self.output("y", lambda: self.values["k"] * self.values["u"] + self.values["b"], "m",
                    "Output", depends_on=["u"])

    def build_model(self):
        if abs(self.values["k"]) > self.values["k_max"]:
            raise ValueError(f"k = {self.values['k']} exceeds k_max = {self.values['k_max']}")
        return _GainModel(self.values["k"], self.values["b"])

    def do_step(self, current_time, step_size):
        self.model  # noqa: B018
        return True
