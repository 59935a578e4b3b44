"""Test fixture: integrator x' = u (explicit Euler), stateful output x."""
from neighbor_fmu_support import NeighborSlave


class _IntModel:
    def __init__(self, x0):
        self.x = x0

    def get_state(self):
        return self.x

    def set_state(self, state):
        self.x = state


class MfIntegrator(NeighborSlave):
    description = "Test integrator x' = u"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("x0", 0.0, None, "Initial state")
        self.input("u", 0.0, None, "Rate")
        self.output("x", lambda: self.model.x, None, "State")
        self.output("steps", lambda: self.values["n_steps"], None, "Steps taken", kind=int)
        self.values["n_steps"] = 0

    def build_model(self):
        return _IntModel(self.values["x0"])

    def do_step(self, current_time, step_size):
        self.model.x += step_size * self.values["u"]
        self.values["n_steps"] += 1
        return True
