"""Benchmark what a short run pays before its first step (issue 60, part 3).

    python bench/bench_startup.py [--repeat 5]

Each command runs in fresh processes, `--repeat` times (the best and the median printed), and is
printed as a ratio against baselines measured in the same run: the bare interpreter
(`python -c pass`), numba's own start (numba imported and one function loaded from its cache:
numba initializes its CPU target there, which imports scipy when scipy is installed; what a run
paid before the kernels and the compiled loop were loaded only where they repay it), and the
issue's target.

- `neighbor-cosim --version` and `--help` (target 0.2 s);
- `neighbor-cosim run detumble` (664 steps; target 0.7 s), with its import chain (-X importtime's
  largest cumulative imports) and the run's own wall time as the command prints it;
- the same with numba loaded as before (NEIGHBOR_COSIM_NUMBA=1: every kernel compiled at its first
  call; NEIGHBOR_COSIM_COMPILED_LOOP=1: the compiled loop for a short run too);
- the same with the FMUs' bytecode cache off (NEIGHBOR_FMU_BYTECODE_CACHE=0: their private
  packages compiled from source in every process, as before it);
- fmusim (the Reference-FMUs' C simulator, no Python in its environment) stepping RigidBody once
  (target 0.4 s), when fmusim can be compiled here (tests/fmus/fmusim_host.py), and the same with
  NEIGHBOR_COSIM_NUMBA=1.
Build first: python build_fmus.py
"""
import argparse
import os
from pathlib import Path
import statistics
import subprocess
import sys
import time

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "fmus"))

import fmusim_host  # noqa: E402

COMMAND = [sys.executable, "-m", "system_ssp"]
# the numba floor: numpy and numba imported and one function loaded from numba's cache (numba
# initializes its CPU target at the first function it compiles or loads)
FLOOR_MODULE = ("import numba\n\n\n@numba.njit(cache=True)\ndef plus_one(x):\n    return x + 1\n")
# numba loaded as before this round: every kernel compiled at its first call, the compiled loop for
# every run it can serve
EAGER = {"NEIGHBOR_COSIM_NUMBA": "1", "NEIGHBOR_COSIM_COMPILED_LOOP": "1"}
FLOOR = "import sys; sys.path.insert(0, sys.argv[1]); import startup_floor; startup_floor.plus_one(1)"


def timed(argv, repeat, env=None):
    """(best, median) wall seconds of `argv` in fresh processes; the last run's stdout."""
    walls, out = [], ""
    for _ in range(repeat):
        t0 = time.perf_counter()
        proc = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT)
        walls.append(time.perf_counter() - t0)
        if proc.returncode != 0:
            raise RuntimeError(f"{' '.join(argv)} failed: {proc.stderr[-2000:]}")
        out = proc.stdout
    return min(walls), statistics.median(walls), out


def import_chain(argv, top=8):
    """The largest cumulative imports of one run of `argv` (python -X importtime)."""
    proc = subprocess.run([sys.executable, "-X", "importtime", *argv[1:]], capture_output=True, text=True, cwd=ROOT)
    rows = []
    for line in proc.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            _, cumulative, name = line.split("|")
            if cumulative.strip().isdigit():
                rows.append((int(cumulative) / 1e6, name.strip()))
    return sorted(rows, reverse=True)[:top]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    n = args.repeat
    bare, _, _ = timed([sys.executable, "-c", "pass"], n)
    folder = ROOT / "build" / "bench_startup"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "startup_floor.py").write_text(FLOOR_MODULE)
    timed([sys.executable, "-c", FLOOR, str(folder)], 1)  # numba's cache written
    floor, _, _ = timed([sys.executable, "-c", FLOOR, str(folder)], n)
    print(f"baselines (best of {n}): python -c pass {bare:.3f} s; numba imported and one function loaded from its "
          f"cache {floor:.3f} s (what every run of our FMUs paid before numba was loaded only where it repays)")
    for what, argv, target in (("neighbor-cosim --version", [*COMMAND, "--version"], 0.2),
                               ("neighbor-cosim --help", [*COMMAND, "--help"], 0.2)):
        best, median, _ = timed(argv, n)
        print(f"{what:<34} {best:6.3f} s (median {median:.3f}): {best / bare:5.2f}x the bare interpreter, "
              f"{best / target:.2f}x the target {target} s")
    run = [*COMMAND, "run", "detumble", "--quiet"]
    timed(run, 1)  # the build folder checked, the caches written
    best, median, out = timed(run, n)
    inside = next((line.split()[2] for line in out.splitlines() if line.startswith("wall time:")), "?")
    print(f"{'neighbor-cosim run detumble':<34} {best:6.3f} s (median {median:.3f}; the run itself {inside} s): "
          f"{best / floor:.2f}x the numba floor, {best / 0.7:.2f}x the target 0.7 s")
    eager = dict(os.environ, **EAGER)
    best_eager, median_eager, _ = timed(run, n, env=eager)
    print(f"{'  numba loaded as before':<34} {best_eager:6.3f} s (median {median_eager:.3f}): loading it only where "
          f"it repays saves {best_eager - best:.3f} s ({best_eager / best:.2f}x)")
    off = dict(os.environ, NEIGHBOR_FMU_BYTECODE_CACHE="0")
    best_off, median_off, _ = timed(run, n, env=off)
    print(f"{'  the FMUs bytecode cache off':<34} {best_off:6.3f} s (median {median_off:.3f}): the cache saves "
          f"{best_off - best:.3f} s ({best_off / best:.2f}x)")
    print("  largest imports of that command (cumulative s):")
    for seconds, name in import_chain(run):
        print(f"    {seconds:6.3f}  {name}")
    missing = fmusim_host.missing_packages()
    if missing:
        print(f"fmusim: not compiled here (apt install {' '.join(missing)})")
        return
    exe = fmusim_host.build(ROOT / "build" / "fmusim")
    fmu = ROOT / "build" / "fmus" / "RigidBody.fmu"
    argv = [str(exe), "--interface-type", "cs", "--stop-time", "0.015", "--output-interval", "0.015",
            "--output-file", os.devnull, str(fmu)]
    timed(argv, 1, env=dict(fmusim_host.CLEAN_ENV))
    best, median, _ = timed(argv, n, env=dict(fmusim_host.CLEAN_ENV))
    print(f"{'fmusim, RigidBody, one step':<34} {best:6.3f} s (median {median:.3f}): {best / floor:.2f}x the numba "
          f"floor, {best / 0.4:.2f}x the target 0.4 s")
    best_eager, median_eager, _ = timed(argv, n, env=dict(fmusim_host.CLEAN_ENV, NEIGHBOR_COSIM_NUMBA="1"))
    print(f"{'  numba loaded as before':<34} {best_eager:6.3f} s (median {median_eager:.3f}): the plain-Python first "
          f"steps save {best_eager - best:.3f} s ({best_eager / best:.2f}x)")


if __name__ == "__main__":
    main()
