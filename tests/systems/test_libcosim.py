"""libcosim (the Open Simulation Platform's master) runs every product system at its fixed step,
with the parameter bindings merged per component at packing (libcosim applies only a
component's first binding), and its trajectories equal our Jacobi runs to 1e-9."""
import json
import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from paths import MASTER_FIXTURES
import system_ssp
from system_ssp.tools.flatten import flatten_system_parameters

SYSTEMS = ["detumble", "slew", "air_bearing", "acs_modes", "attitude_determination", "deorbit", "deorbit_lifetime",
           "sun_avoidance_slew", "sun_eclipse", "sunline", "neighbor_mission", "neighbor_mission_lifetime"]
STEPS = 40


def system_parameters(ssp):
    with system_ssp.System(ssp) as system:
        return [name for name, targets in system.parameter_links.items() if targets]


def osp_step(ssp):
    with zipfile.ZipFile(ssp) as z:
        text = z.read("SystemStructure.ssd").decode()
    return float(re.search(r'FixedStepAlgorithm baseStepSize="([^"]+)"', text).group(1))


@pytest.mark.parametrize("name", SYSTEMS)
def test_libcosim_equals_our_jacobi(name, ssp_paths, tmp_path):
    pytest.importorskip("libcosimpy")
    ssp = ssp_paths[name]
    h = osp_step(ssp)
    with system_ssp.System(ssp) as system:
        names = [f"{c.name}.{v.name}" for c in system.comps for v in c.md.modelVariables
                 if v.causality == "output" and v.type == "Real"]
        ours = system.run(algorithm="jacobi", schedule=False, step_size=h, stop_time=STEPS * h, stop_when=[],
                          outputs=names)
    if system_parameters(ssp):  # libcosim reads no connection from a system connector: the flattened copy
        flat = tmp_path / "flat.ssp"
        flatten_system_parameters(ssp, flat)
        ssp = flat
    out = tmp_path / "libcosim.json"
    # libcosim in its own process: a process that ran both libcosim and FMPy once aborted at exit
    proc = subprocess.run([sys.executable, str(MASTER_FIXTURES / "libcosim_run.py"), str(ssp), repr(h), str(STEPS),
                           str(out), *names], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    ref = np.array(json.loads(out.read_text()))
    got = np.column_stack([ours.data[k][1:] for k in names])
    assert got.shape == ref.shape == (STEPS, len(names))
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-9)
    assert np.ptp(ref, axis=0).max() > 0.0  # something moves


def test_packed_systems_bind_one_parameter_set_per_component(ssp_paths):
    """air_bearing's dynamics binds its initial state and the testbed's inertia in the source SSD;
    the packed one binds one merged set with both."""
    with zipfile.ZipFile(ssp_paths["air_bearing"]) as z:
        ssd = z.read("SystemStructure.ssd").decode()
        merged = z.read("parameters/merged/air_bearing.dynamics.ssv").decode()
    block = ssd[ssd.index('<ssd:Component name="dynamics"'):]
    block = block[:block.index("</ssd:Component>")]
    assert block.count("<ssd:ParameterBinding ") == 1
    assert 'name="inertia_from_box"' in merged and 'name="q0[1]"' in merged
