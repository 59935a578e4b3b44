"""Real-time pacing: communication points held to wall time, for a flight computer or hardware
in the loop that follows the master's clock.

With a factor F, the communication point at simulated time t is not passed before
`wall0 + (t - t0) / F` (wall0: the first step's start, t0: the start time): 1 is real time, 100
a hundred times faster, 0.5 half as fast. A point reached later than that is late; it is an
*overrun* when it is late by more than the step just taken lasts at the factor (the master fell a
whole communication step behind, where a following device would miss a sample). Late points
are not made up by skipping: the master goes on as fast as it can until it is on time again."""
import time

from ..errors import RealTimeOverrun
from .observers import Observer

SLICE = 0.1  # s: the longest single sleep, so that Ctrl-C ends a run paced with long steps at once


class RealTimePacer(Observer):
    """Holds each communication point to wall time at `factor` (> 0, checked by System.run);
    counts overruns and the worst lateness; `stop_on_overrun` ends the run at the first overrun
    with RealTimeOverrun (rows so far in err.result). `watch` (a SignalWatch) cuts a sleep short when a signal came."""

    def __init__(self, factor: float, stop_on_overrun: bool = False, watch=None):
        self.factor = float(factor)
        self.stop_on_overrun = stop_on_overrun
        self.watch = watch
        self.wall0 = 0.0
        self.t0 = self.last_t = 0.0
        self.overruns = 0
        self.points = 0
        self.late_points = 0
        self.worst = 0.0  # s: the worst lateness of any point
        self.worst_at = None  # simulated time of that point
        self.slept = 0.0
        self.wall = 0.0  # s: from the start to the last point

    def start(self, info):
        self.wall0 = time.perf_counter()
        self.t0 = self.last_t = info.t

    def step(self, info):
        t = info.t
        step = (t - self.last_t) / self.factor  # wall seconds the step just taken is worth
        self.last_t = t
        self.points += 1
        due = self.wall0 + (t - self.t0) / self.factor
        now = time.perf_counter()
        late = now - due
        if late <= 0.0:
            self._sleep_until(due)
            self.wall = due - self.wall0
            return
        self.wall = now - self.wall0
        self.late_points += 1
        if late > self.worst:
            self.worst, self.worst_at = late, t
        if late > step:
            self.overruns += 1
            if self.stop_on_overrun:
                raise RealTimeOverrun(f"real-time overrun at t = {t:g} s: {late * 1e3:.3g} ms behind wall time at "
                                      f"x{self.factor:g}, more than the step of {step * 1e3:.3g} ms")

    def _sleep_until(self, due):
        while True:
            left = due - time.perf_counter()
            if left <= 0.0 or (self.watch is not None and self.watch.received is not None):
                return
            pause = min(left, SLICE)
            time.sleep(pause)
            self.slept += pause

    def report(self):
        """What `Result.pacing` holds."""
        return {"factor": self.factor, "points": self.points, "late_points": self.late_points,
                "overruns": self.overruns, "worst_lateness_s": self.worst, "worst_at_s": self.worst_at,
                "slept_s": self.slept, "wall_s": self.wall}
