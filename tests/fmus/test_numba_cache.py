"""An FMU's numba kernels compile once per machine, not once per run: a host extracts the FMU to
a new folder for every run, where numba's own cache (beside the source) would go with the
folder. components.core.jit keeps the compiled code of our FMUs' private packages in the user's
cache under the package's name (its digest is of the package's code)."""
import os
import subprocess
import sys

import fmpy
import numpy as np
import pytest

pytest.importorskip("numba")

RUN = r"""
import sys
import fmpy
import numpy as np
r = fmpy.simulate_fmu(sys.argv[1], stop_time=0.3, output_interval=0.015, output=["omega_BN_B[1]", "q_BN[4]"],
                      start_values={"omega0[1]": 0.2, "omega0[2]": -0.1, "torque_B[3]": 1e-3})
np.save(sys.argv[2], np.array([r[name] for name in ("omega_BN_B[1]", "q_BN[4]")]))
"""


def _stamps(folder):
    return {p.relative_to(folder): p.stat().st_mtime_ns for p in folder.rglob("*") if p.suffix in (".nbi", ".nbc")}


def test_a_second_run_from_a_new_folder_loads_the_kernels_compiled_by_the_first(fmu_paths, tmp_path):
    cache = tmp_path / "user-cache"
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), NEIGHBOR_COSIM_NUMBA="1")
    stamps, results = [], []
    for run in ("first", "second"):
        folder = tmp_path / run
        fmpy.extract(str(fmu_paths["RigidBody"]), unzipdir=str(folder))
        out = tmp_path / f"{run}.npy"
        proc = subprocess.run([sys.executable, "-c", RUN, str(folder), str(out)], env=env, capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr
        assert not list(folder.rglob("*.nbi")), "compiled code left in the run's own folder"
        stamps.append(_stamps(cache))
        results.append(np.load(out))
    kernels = [p for p in stamps[0] if p.name.startswith("rigid_body.rk4_steps")]
    assert kernels and all(p.parts[:2] == ("numba", "neighbor-cosim-fmus") for p in kernels), stamps[0]
    assert kernels[0].parts[2].startswith("nc_rigidbody_")  # under the FMU build's own package name
    assert stamps[1] == stamps[0]  # the second run wrote nothing: it loaded, it did not compile
    np.testing.assert_array_equal(results[1], results[0])
    assert np.ptp(results[0][0]) > 0.0  # the body turned: the kernel ran
