"""The master's entry point: RunOptions, keyword settings as its shorthand, and the caller's
observers (libcosim's add_observer): they see every step, read values and may stop the run."""
import dataclasses

import numpy as np
import pytest

import system_ssp
from system_ssp import Observer, RunOptions, SSPError

OMEGA = "dynamics.omega_BN_B[1]"


class Watch(Observer):
    """Reads one variable after every step; stops the run once it falls below `below`."""

    def __init__(self, below=None):
        self.below = below
        self.times, self.values, self.calls = [], [], []

    def attach(self, run):
        self.run = run
        self.calls.append("attach")

    def start(self, info):
        self.calls.append("start")

    def step(self, info):
        value = self.run.read([OMEGA])[OMEGA]
        self.times.append(info.t)
        self.values.append(value)
        if self.below is not None and value < self.below:
            info.fired = f"{OMEGA} below {self.below}"

    def finish(self, info):
        self.calls.append("finish")


def test_options_and_keywords_are_the_same_run(ssp_paths):
    options = RunOptions(stop_time=0.6, outputs=[OMEGA], stop_when=[])
    with system_ssp.System(ssp_paths["detumble"]) as system:
        a = system.run(options)
        b = system.run(stop_time=0.6, outputs=[OMEGA], stop_when=[])
        c = system.run(dataclasses.replace(options, stop_time=0.3))
        d = system.run(options, stop_time=0.3)  # a keyword replaces the field
    np.testing.assert_array_equal(a.data, b.data)
    np.testing.assert_array_equal(c.data, d.data)
    assert c.stop_time == pytest.approx(0.3) and a.stop_time == pytest.approx(0.6)


def test_an_unknown_setting_is_refused_with_the_fields(ssp_paths):
    with pytest.raises(TypeError, match="unknown run setting.*stop_tme.*RunOptions fields: stop_time"):
        system_ssp.simulate(ssp_paths["detumble"], stop_tme=1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        RunOptions().stop_time = 1.0  # type: ignore[misc]


def test_observers_see_every_step_and_read_what_is_recorded(ssp_paths):
    watch = Watch()
    r = system_ssp.simulate(ssp_paths["detumble"], stop_time=0.6, outputs=[OMEGA], stop_when=[], observers=[watch])
    assert watch.calls == ["attach", "start", "finish"]
    assert len(watch.times) == r.steps == 40
    np.testing.assert_allclose(watch.times, r.data["time"][1:], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(watch.values, r.data[OMEGA][1:])


def test_an_observer_stops_the_run(ssp_paths):
    full = system_ssp.simulate(ssp_paths["detumble"], stop_time=5.0, outputs=[OMEGA], stop_when=[])
    threshold = float(np.median(full.data[OMEGA]))
    watch = Watch(below=threshold)
    r = system_ssp.simulate(ssp_paths["detumble"], stop_time=5.0, outputs=[OMEGA], stop_when=[], observers=[watch])
    first = int(np.flatnonzero(full.data[OMEGA] < threshold)[0])
    assert r.stop_time == pytest.approx(full.data["time"][first])
    assert r.stop_reason.startswith(f"stop condition {OMEGA} below")
    assert r.data[OMEGA][-1] < threshold <= r.data[OMEGA][-2]


def test_an_observer_reading_an_unknown_variable_gets_the_masters_message(ssp_paths):
    class Bad(Observer):
        def attach(self, run):
            self.run = run

        def step(self, info):
            self.run.read(["dynamics.omega_BN_B[9]"])

    with pytest.raises(SSPError, match=r"omega_BN_B\[9\]"):
        system_ssp.simulate(ssp_paths["detumble"], stop_time=0.1, observers=[Bad()])
