"""An FMU's numba kernels compile once per machine, not once per run: a host extracts the FMU to
a new folder for every run, where numba's own cache (beside the source) would go with the
folder. components.core.jit keeps the compiled code of our FMUs' private packages in the user's
cache under the package's name (its digest is of the package's code)."""
import json
import os
import subprocess
import sys

import fmpy
import numpy as np
import pytest

pytest.importorskip("numba")

RUN = r"""
import json, sys
import fmpy
import numpy as np
case = json.loads(sys.argv[3])
r = fmpy.simulate_fmu(sys.argv[1], stop_time=case["stop"], output_interval=case["interval"], output=case["outputs"],
                      start_values=case["starts"])
np.save(sys.argv[2], np.array([r[name] for name in case["outputs"]]))
"""

# Per FMU: its run, the kernel whose cache file is checked and the package prefix. Orbit's DOP853
# takes the atmosphere's kernel as an argument; numba cannot cache that (the type is the identity
# of a dispatcher object), and while it tried, every run added an entry to the user's cache.
CASES = {
    "RigidBody": ({"stop": 0.3, "interval": 0.015, "outputs": ["omega_BN_B[1]", "q_BN[4]"],
                   "starts": {"omega0[1]": 0.2, "omega0[2]": -0.1, "torque_B[3]": 1e-3}},
                  "rigid_body.rk4_steps", "nc_rigidbody_"),
    "Orbit": ({"stop": 20.0, "interval": 10.0, "outputs": ["r_BN_N[1]", "density"],
               "starts": {"density_model": "jacchia_roberts"}},
              "jacchia_roberts.jacchia_roberts_kernel", "nc_orbit_"),
}


def _stamps(folder):
    return {p.relative_to(folder): p.stat().st_mtime_ns for p in folder.rglob("*") if p.suffix in (".nbi", ".nbc")}


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_second_run_from_a_new_folder_loads_the_kernels_compiled_by_the_first(fmu_paths, tmp_path, name):
    case, kernel, package = CASES[name]
    cache = tmp_path / "user-cache"
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), NEIGHBOR_COSIM_NUMBA="1")
    stamps, results = [], []
    for run in ("first", "second"):
        folder = tmp_path / run
        fmpy.extract(str(fmu_paths[name]), unzipdir=str(folder))
        out = tmp_path / f"{run}.npy"
        proc = subprocess.run([sys.executable, "-c", RUN, str(folder), str(out), json.dumps(case)], env=env,
                              capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr
        assert not list(folder.rglob("*.nbi")), "compiled code left in the run's own folder"
        stamps.append(_stamps(cache))
        results.append(np.load(out))
    kernels = [p for p in stamps[0] if p.name.startswith(kernel)]
    assert kernels and all(p.parts[:2] == ("numba", "neighbor-cosim-fmus") for p in kernels), stamps[0]
    assert kernels[0].parts[2].startswith(package)  # under the FMU build's own package name
    # the second run wrote nothing: it loaded what it could and left no entry it cannot use
    assert stamps[1] == stamps[0], sorted(set(stamps[1]) ^ set(stamps[0]))
    np.testing.assert_array_equal(results[1], results[0])
    assert np.ptp(results[0][0]) > 0.0  # the body turned, the spacecraft moved: the kernels ran
