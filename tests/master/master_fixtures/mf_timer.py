"""Test fixture: a timer that announces its expiry. `expired` turns true once the time reaches
`expiry`; `next_event_time` is the expiry while it lies ahead (1e300 afterwards); `steps` counts
doStep calls and `last_step` is the last communication step size."""
from neighbor_fmu_support import NeighborSlave


class _TimerModel:
    def __init__(self, start):
        self.t = start

    def get_state(self):
        return self.t

    def set_state(self, state):
        self.t = state


class MfTimer(NeighborSlave):
    description = "Test timer with a next-event output"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("expiry", 1.0, "s", "Expiry time")
        self.output("expired", lambda: self.model.t >= self.values["expiry"] - 1e-12, None, "Timer expired",
                    kind=bool)
        self.output("next_event_time", lambda: self.values["expiry"] if self.model.t < self.values["expiry"] - 1e-12
                    else 1e300, "s", "Time of the next event")
        self.output("steps", lambda: self.values["n_steps"], None, "doStep calls", kind=int)
        self.output("last_step", lambda: self.values["h_last"], "s", "Last communication step size")
        self.values["n_steps"] = 0
        self.values["h_last"] = 0.0

    def build_model(self):
        return _TimerModel(self.start_time)

    def do_step(self, current_time, step_size):
        self.model.t = current_time + step_size
        self.values["n_steps"] += 1
        self.values["h_last"] = step_size
        return True
