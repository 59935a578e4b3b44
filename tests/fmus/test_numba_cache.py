"""An FMU's numba kernels compile once per machine, not once per run: a host extracts the FMU to
a new folder for every run, where numba's own cache (beside the source) would go with the
folder. components.core.jit keeps the compiled code of our FMUs' private packages in the user's
cache under the package's name (its digest is of the package's code)."""
import json
import os
import shutil
import subprocess
import sys

import fmpy
import numpy as np
import pytest

pytest.importorskip("numba")

from components.core import jit  # noqa: E402
from components.orbit import averaged  # noqa: E402

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
# is cached with the Jacchia-Roberts kernel bound in by a module's function; numba cannot cache it
# with the kernel as an argument (the type is the identity of a dispatcher object), and while it
# tried, every run added an entry to the user's cache.
CASES = {
    "RigidBody": ({"stop": 0.3, "interval": 0.015, "outputs": ["omega_BN_B[1]", "q_BN[4]"],
                   "starts": {"omega0[1]": 0.2, "omega0[2]": -0.1, "torque_B[3]": 1e-3}},
                  "rigid_body.rk4_steps", "nc_rigidbody_"),
    "Orbit": ({"stop": 20.0, "interval": 10.0, "outputs": ["r_BN_N[1]", "density"],
               "starts": {"density_model": "jacchia_roberts"}},
              "cowell._advance_jacchia_roberts", "nc_orbit_"),
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


@pytest.mark.skipif(not jit.ENABLED, reason="numba's cache")
def test_a_cached_kernel_outside_an_fmu_is_stamped_with_the_whole_package(tmp_path):
    """numba checks only the cached function's own file, but the orbit's integration holds the
    atmosphere's code: outside an FMU every cache entry of the components package is stamped with
    the digest of all its sources, so an edited atmosphere compiles the orbit again (before, the
    orbit kept the old density)."""
    locator = averaged._advance_jacchia_roberts._cache._impl.locator
    root = jit.components_root_of(averaged.__file__)
    assert type(locator).__name__ == "ComponentsCacheLocator"
    assert locator.get_source_stamp() == jit.components_digest(root)
    copy = tmp_path / "components"
    shutil.copytree(root, copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = jit.components_digest(str(copy))
    assert before == jit.components_digest(root)  # the names and contents, not where they are
    kernel = copy / "environment" / "atmosphere" / "jacchia_roberts.py"
    kernel.write_text(kernel.read_text().replace("return rho * 1.0e3", "return rho * 2.0e3"))
    jit.components_digest.cache_clear()
    assert jit.components_digest(str(copy)) != before
