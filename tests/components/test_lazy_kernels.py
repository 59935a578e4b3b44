"""numba is loaded when a kernel first needs it (components.core.jit): a run that calls only the
attitude models' plain_first kernels, for fewer than jit.PLAIN_CALLS calls, never imports numba
and gives numba's bits; past that budget numba is loaded and the kernels run compiled; a kernel
that is not plain_first loads numba at its first call; and a module's name for a kernel is
rebound to numba's dispatcher once it is loaded (identity-keyed tables use jit.function_of)."""
import json
import os
import subprocess
import sys

import pytest

pytest.importorskip("numba")

RUN = r"""
import json, sys
import numpy as np
from components.core import jit
from components.attitude import detumble, rigid_body, thrusters

out = {"numba_at_import": "numba" in sys.modules, "budget": jit.PLAIN_CALLS}
J = [[0.1, 0.002, 0.0], [0.002, 0.12, 0.0], [0.0, 0.0, 0.15]]
body = rigid_body.RigidBody(J, (0.1, 0.2, 0.3, 0.9), (0.17, -0.1, 0.05), "rk4")
pairs, law = thrusters.ThrusterPairs(), detumble.DetumbleController([100.0] * 3, [1.0] * 3, settle_time=0.03)
values, history = np.zeros(90), []
for k in range(int(sys.argv[1])):
    values[20:26] = body.omega + body.omega_dot
    values[26] = 1.0
    law.step_into(values, np.arange(20, 27), np.arange(30, 37), 0.015)
    values[40:43] = values[30:33]
    pairs.step_into(values, np.arange(40, 43), np.arange(44, 58), 0.015)
    values[0:3] = values[44:47]
    body.step_from(values, np.arange(9), 0.015)
    body.publish_into(values, np.arange(60, 82))
    history.append(values.tolist())
out["numba_after_steps"] = "numba" in sys.modules
out["rebound"] = not isinstance(rigid_body.rk4_step_into, jit.Kernel)
out["values"] = history[-1]
if sys.argv[2] == "orbit":  # a kernel that is not plain_first: numba at its first call
    from components.orbit import averaged
    averaged.OrbitAveraged(None, sma0=6378136.3 + 400e3).advance_to(600.0)
    out["numba_after_orbit"] = "numba" in sys.modules
print(json.dumps(out))
"""


def run(steps, then="", **env):
    environment = {k: v for k, v in os.environ.items() if k != "NEIGHBOR_COSIM_NUMBA"}
    proc = subprocess.run([sys.executable, "-c", RUN, str(steps), then], capture_output=True, text=True,
                          env=dict(environment, **env), timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_a_short_run_of_plain_first_kernels_never_imports_numba_and_gives_its_bits():
    plain, compiled = run(300, "orbit"), run(300, NEIGHBOR_COSIM_NUMBA="1")
    assert not plain["numba_at_import"] and not compiled["numba_at_import"]  # importing declares only
    assert not plain["numba_after_steps"] and not plain["rebound"]
    assert compiled["numba_after_steps"] and compiled["rebound"]
    assert plain["values"] == compiled["values"]  # bit for bit
    assert plain["numba_after_orbit"]  # the orbit's kernels are not plain_first


def test_past_the_budget_numba_is_loaded_and_the_results_stay_the_same():
    steps = run(1, "")["budget"] // 20  # 30 plain_first calls a step: the budget is spent
    lazy, compiled = run(steps), run(steps, NEIGHBOR_COSIM_NUMBA="1")
    assert lazy["numba_after_steps"] and lazy["rebound"]
    assert lazy["values"] == compiled["values"]


def test_a_kernel_pickles_as_numbas_dispatcher():
    import pickle

    from components.environment.atmosphere import base

    kernel = base.gmst_nb  # bound under another name than its function's: pickled by value
    again = pickle.loads(pickle.dumps(kernel))
    assert again(2460000.5) == kernel(2460000.5) == base.magnetic_field.gmst(2460000.5)
