"""Test fixture: integrator x' = u (explicit Euler), stateful output x.

For the failure and interruption tests: `fail_at` (a doStep at t >= fail_at raises; negative: never),
`step_delay` (seconds each doStep sleeps, a run that lasts long enough to be interrupted),
`touch_file` (created at the first doStep: the run has started) and `crash_at` (a doStep at
t >= crash_at ends the process at once, as a crashing native model would; negative: never).
"""
import os
import time

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
        self.parameter("fail_at", -1.0, "s", "Time from which doStep raises (negative: never)")
        self.parameter("step_delay", 0.0, "s", "Seconds each doStep sleeps")
        self.parameter("crash_at", -1.0, "s", "Time from which doStep ends the process (negative: never)")
        self.parameter("touch_file", "", None, "File created at the first doStep (empty: none)", kind=str)
        self.output("steps", lambda: self.values["n_steps"], None, "Steps taken", kind=int)
        self.values["n_steps"] = 0

    def build_model(self):
        return _IntModel(self.values["x0"])

    def do_step(self, current_time, step_size):
        if 0.0 <= self.values["fail_at"] <= current_time:
            raise ValueError(f"fixture failure at t={current_time:g} s")
        if 0.0 <= self.values["crash_at"] <= current_time:
            os._exit(70)
        if self.values["touch_file"] and self.values["n_steps"] == 0:
            with open(self.values["touch_file"], "w"):
                pass
        if self.values["step_delay"] > 0.0:
            time.sleep(self.values["step_delay"])
        self.model.x += step_size * self.values["u"]
        self.values["n_steps"] += 1
        return True
