"""The host spacecraft as NEIGHBOR sees it: a heartbeat signal (thesis section 3.7: the host's
watchdog timer hardware) that stops when the host fails or its operators end the mission.

The heartbeat follows a schedule of toggle times (s, simulation time): it is present before
`heartbeat_loss_time`, lost from it on, and every later time in `return_times` toggles it again
(the first returns it, the second loses it again, ...). At a toggle time itself the new value
holds (a master that ends a step on `next_event_time` sees the new value after that step).

Default loss time 1825 days (5 years): the thesis' power analysis keeps the idle mode and
the 30-day grace period running for 1855 days together (section 3.5, Appendix I).
"""
import math
import re

from ..core import time_utils
from ..core.constants import DAY

NO_EVENT = 1e300
DEFAULT_LOSS_TIME = 1825 * DAY


def parse_times(text, name="heartbeat_return_times"):
    """Floats (s) from a string of numbers separated by commas and/or blanks ("" -> [])."""
    if not isinstance(text, str):
        raise ValueError(f"{name} = {text!r} must be a string of times in s separated by commas or blanks")
    items = [s for s in re.split(r"[,\s;]+", text.strip()) if s]
    times = []
    for s in items:
        try:
            value = float(s)
        except ValueError:
            raise ValueError(f"{name}: {s!r} is not a number (expected times in s separated by commas or "
                             f"blanks, e.g. '3.0e6, 4.0e6')") from None
        if not math.isfinite(value):
            raise ValueError(f"{name}: {s!r} must be a finite time in s")
        times.append(value)
    return times


class HostSpacecraft(time_utils.Clock):
    def __init__(self, heartbeat_loss_time=DEFAULT_LOSS_TIME, return_times=(), t0=0.0):
        loss = float(heartbeat_loss_time)
        if not (math.isfinite(loss) and loss >= 0):
            raise ValueError(f"heartbeat_loss_time = {heartbeat_loss_time!r} s must be a finite time >= 0")
        if isinstance(return_times, str):
            return_times = parse_times(return_times)
        toggles = [loss] + [float(x) for x in return_times]
        for i in range(1, len(toggles)):
            if not toggles[i] > toggles[i - 1]:
                what = "heartbeat_loss_time" if i == 1 else f"the previous time {toggles[i - 1]!r} s"
                raise ValueError(f"heartbeat_return_times must increase strictly and start after "
                                 f"heartbeat_loss_time: {toggles[i]!r} s is not after {what} "
                                 f"(schedule {toggles[1:]!r})")
        self.toggles = tuple(toggles)
        self.t = time_utils.check_time(t0, "start time")

    def _count(self, t):
        """Number of toggles at or before t (a toggle within 1 us + 1e-14 |t| counts as reached)."""
        tol = 1e-6 + 1e-14 * abs(t)
        return sum(1 for x in self.toggles if x <= t + tol)

    def heartbeat(self, t=None):
        return self._count(self.t if t is None else float(t)) % 2 == 0

    def next_event_time(self, t=None):
        n = self._count(self.t if t is None else float(t))
        return self.toggles[n] if n < len(self.toggles) else NO_EVENT
