"""An FMU's Python modules compile once per machine and Python version, not once per extraction
(fmus/runtime/neighbor_runtime.py): the bytecode of the FMU's private package is kept in the
user's cache under the package's name (its digest is of the package's code) as hash-checked .pyc
files, and loaded as compiled from the extraction that runs. Each run here is its own process,
extracting the FMU to a new folder as a host does."""
import json
import os
import subprocess
import sys

import fmpy
import numpy as np

RUN = r"""
import json, sys
import fmpy
import numpy as np
r = fmpy.simulate_fmu(sys.argv[1], stop_time=0.3, output_interval=0.015, output=["omega_BN_B[1]", "q_BN[4]"],
                      start_values={"omega0[1]": 0.2, "omega0[2]": -0.1})
np.save(sys.argv[2], np.array([r["omega_BN_B[1]"], r["q_BN[4]"]]))
module = next(m for name, m in sys.modules.items() if name.startswith("nc_rigidbody_")
              and name.endswith(".components.attitude.rigid_body"))
kernel = module.rk4_step_into
code = getattr(kernel, "py_func", kernel).__code__
print(json.dumps({"loader": type(module.__spec__.loader).__name__, "pyc": getattr(module.__spec__.loader, "pyc", None),
                  "file": module.__file__, "code_file": code.co_filename}))
"""


def _run(fmu, tmp_path, label, env):
    folder = tmp_path / label
    fmpy.extract(str(fmu), unzipdir=str(folder))
    out = tmp_path / f"{label}.npy"
    proc = subprocess.run([sys.executable, "-c", RUN, str(folder), str(out)], env=env, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return folder, np.load(out), json.loads(proc.stdout.strip().splitlines()[-1])


def _kept(cache):
    root = cache / "neighbor-cosim" / "fmu-bytecode"
    return {p.relative_to(root): p.stat().st_mtime_ns for p in root.rglob("*.pyc")} if root.is_dir() else {}


def test_a_second_extraction_loads_the_bytecode_the_first_kept(fmu_paths, tmp_path):
    cache = tmp_path / "user-cache"
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), NEIGHBOR_FMU_BYTECODE_CACHE="1")
    env.pop("NEIGHBOR_FMU_CACHE", None)
    first, values1, info1 = _run(fmu_paths["RigidBody"], tmp_path, "first", env)
    kept = _kept(cache)
    tag = sys.implementation.cache_tag
    assert any(p.parts[0].startswith("nc_rigidbody_") and p.parts[1] == tag for p in kept), sorted(kept)[:5]
    assert any(p.parts[-3:] == ("attitude", "rigid_body.pyc") or p.name == "rigid_body.pyc" for p in kept)
    assert not list(first.rglob("__pycache__")), "bytecode written into the extraction"
    second, values2, info2 = _run(fmu_paths["RigidBody"], tmp_path, "second", env)
    assert _kept(cache) == kept  # loaded, nothing compiled or written again
    np.testing.assert_array_equal(values2, values1)
    assert np.ptp(values1[0]) > 0.0  # the body turned: the model ran
    # the code loaded from the first extraction's bytecode names the second extraction's file
    assert info2["loader"] == "_KeptBytecodeLoader" and os.path.isfile(info2["pyc"])
    assert info2["file"].startswith(str(second)) and info2["code_file"] == info2["file"]


def test_a_damaged_kept_file_is_compiled_again(fmu_paths, tmp_path):
    cache = tmp_path / "user-cache"
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), NEIGHBOR_FMU_BYTECODE_CACHE="1")
    env.pop("NEIGHBOR_FMU_CACHE", None)
    _, values1, info = _run(fmu_paths["RigidBody"], tmp_path, "first", env)
    pyc = info["pyc"]
    with open(pyc, "r+b") as f:  # the source hash kept, the code garbled
        f.seek(16)
        f.write(b"\x00" * 64)
    _, values2, _ = _run(fmu_paths["RigidBody"], tmp_path, "second", env)
    np.testing.assert_array_equal(values2, values1)
    with open(pyc, "rb") as f:
        assert b"\x00" * 64 not in f.read()[16:80]  # written whole again


def test_no_bytecode_kept_when_turned_off_or_where_it_cannot_be_written(fmu_paths, tmp_path):
    off = tmp_path / "off"
    env = dict(os.environ, XDG_CACHE_HOME=str(off), NEIGHBOR_FMU_BYTECODE_CACHE="0")
    env.pop("NEIGHBOR_FMU_CACHE", None)
    _, values, info = _run(fmu_paths["RigidBody"], tmp_path, "off", env)
    assert _kept(off) == {} and info["loader"] == "SourceFileLoader"
    blocked = tmp_path / "a file"
    blocked.write_text("not a folder")
    env = dict(os.environ, XDG_CACHE_HOME=str(blocked), NEIGHBOR_FMU_BYTECODE_CACHE="1")
    env.pop("NEIGHBOR_FMU_CACHE", None)
    _, values2, _ = _run(fmu_paths["RigidBody"], tmp_path, "blocked", env)
    np.testing.assert_array_equal(values2, values)


def test_an_explicit_cache_folder(fmu_paths, tmp_path):
    """NEIGHBOR_FMU_CACHE names the folder (its bytecode/ part), whatever the user's cache is."""
    chosen = tmp_path / "chosen"
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "user-cache"), NEIGHBOR_FMU_CACHE=str(chosen),
               NEIGHBOR_FMU_BYTECODE_CACHE="1")
    _, _, info = _run(fmu_paths["RigidBody"], tmp_path, "run", env)
    assert info["pyc"].startswith(str(chosen / "bytecode")) and os.path.isfile(info["pyc"])
    assert _kept(tmp_path / "user-cache") == {}
