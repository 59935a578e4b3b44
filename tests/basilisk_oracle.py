"""What the comparisons with Basilisk share (tests/components/*/test_*_vs_basilisk.py): importing
it or skipping in one line, running its modules in an initialized simulation, and recording each
comparison's worst difference (conftest prints them at the end of the run) against its bound."""
import numpy as np
import pytest

CASES = 25  # random cases per comparison


def require_basilisk():
    return pytest.importorskip("Basilisk", reason="Basilisk is not installed (pip install bsk, a test extra): "
                                                  "the comparisons with its modules are skipped")


def record_worst(record_property, what, worst, bound, cases=CASES):
    record_property("worst difference", f"{what}: {worst:.2e} (bound {bound:.0e})")
    assert worst < bound, f"{what}: worst difference {worst:.3e} over {cases} cases, bound {bound:.0e}"


def initialized(*modules):
    """A Basilisk simulation holding the modules, initialized (their SelfInit and Reset at t = 0),
    the first given running first: a module's UpdateState crashes the process outside one. Keep
    it alive while they are used."""
    from Basilisk.utilities import SimulationBaseClass, macros
    sim = SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("p").addTask(sim.CreateNewTask("t", macros.sec2nano(1.0)))
    for priority, module in enumerate(reversed(modules)):
        sim.AddModelToTask("t", module, priority)
    sim.InitializeSimulation()
    return sim


def random_unit(rng, n=3):
    """A unit vector drawn uniformly on the sphere (n = 4: a random attitude quaternion)."""
    v = rng.normal(size=n)
    return v / np.linalg.norm(v)
