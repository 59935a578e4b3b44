"""FMU `HostSpacecraft` (instance `host`): the host spacecraft's heartbeat from a schedule.

Wraps components.mission.host.HostSpacecraft. No inputs; the outputs are functions of time: the
heartbeat is present before heartbeat_loss_time, lost from it on, and toggled again at each
time of heartbeat_return_times. `next_event_time` is the next toggle so that a master can end a
step on it. The model keeps the time: the start time at initialization, t + h after do_step.
"""
from neighbor_fmu_support import NeighborSlave

from components.mission import host


class HostSpacecraft(NeighborSlave):
    description = ("Host spacecraft heartbeat (watchdog signal) from a schedule: lost at heartbeat_loss_time, "
                   "toggled again at each of heartbeat_return_times")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("heartbeat_loss_time", host.DEFAULT_LOSS_TIME, "s",
                       "Time the host fails or its operators stop the heartbeat (>= 0); default 1825 days")
        self.parameter("heartbeat_return_times", "", None,
                       "Later toggle times in s, strictly increasing after heartbeat_loss_time, separated by "
                       "commas or blanks: the first returns the heartbeat, the second loses it again, ... "
                       "(empty: it never returns)", str)
        self.output("heartbeat", lambda: self.model.heartbeat(), None, "Host heartbeat signal present", bool)
        self.output("next_event_time", lambda: self.model.next_event_time(), "s",
                    "Time of the next heartbeat toggle; 1e300 if none")

    def build_model(self):
        return host.HostSpacecraft(self.values["heartbeat_loss_time"], self.values["heartbeat_return_times"],
                                   self.start_time)

    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True
