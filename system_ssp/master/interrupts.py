"""Ctrl-C, SIGTERM and SIGHUP stop a run at the next communication point.

Python runs signal handlers between bytecodes, which, with FMUs that run Python in this
interpreter, can be inside a model's doStep: a KeyboardInterrupt raised there would come back as
that component's fmi2Error. While a run executes, SIGINT, SIGTERM and SIGHUP only set a flag, which the
`Interruption` observer reads after every macro step (only in the main thread: elsewhere signals
cannot be caught and the run is not interruptible this way)."""
import signal
import threading
import time

from .observers import Observer

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class SignalWatch:
    """`with SignalWatch() as watch:` SIGINT/SIGTERM/SIGHUP set `watch.received` (the first signal's
    number) instead of their usual action; the earlier handlers come back on exit."""

    def __init__(self):
        self.received = None
        self.saved = {}

    def _handler(self, signum, frame):
        if self.received is None:
            self.received = signum

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            for sig in SIGNALS:
                try:
                    self.saved[sig] = signal.signal(sig, self._handler)
                except (ValueError, OSError):  # not allowed here (embedded interpreter)
                    pass
        return self

    def __exit__(self, *exc):
        for sig, old in self.saved.items():
            signal.signal(sig, old)
        self.saved = {}


class Interrupted(Exception):
    """Raised by the Interruption observer; the execution turns it into RunInterrupted."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


class Interruption(Observer):
    """Ends the run at the communication point after a signal arrived (last observer: the
    others have seen the step)."""

    def __init__(self, watch):
        self.watch = watch

    def start(self, info):
        self.step(info)

    def step(self, info):
        if self.watch.received is not None:
            raise Interrupted(self.watch.received)


class TimedOut(Exception):
    """Raised by the WallClockLimit observer; the execution turns it into RunTimedOut."""


class WallClockLimit(Observer):
    """Ends the run at the first communication point after `seconds` of wall time (checked
    every few steps: reading the clock costs about as much as a cheap FMU call)."""

    def __init__(self, seconds):
        self.deadline = time.perf_counter() + seconds
        self.seconds = seconds
        self.check_at = 16

    def step(self, info):
        if info.steps >= self.check_at:  # every 16 steps (the compiled loop reports several at once)
            self.check_at = info.steps + 16
            if time.perf_counter() > self.deadline:
                raise TimedOut()
