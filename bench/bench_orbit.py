"""Cowell orbit propagator: wall time per simulated day and per simulated year for each density
model (420 km, 51.6 deg, thesis Table 3 orbit; J2..J6 + drag; communication step 300 s), with the
per-call numbers behind it, and the tolerance convergence check (position difference after one day
against a run with rtol 1e-13).

    python bench/bench_orbit.py [days]   (default 3 simulated days; msis: 0.25 day)

Speed target: Cowell with Jacchia-Roberts <= 60 s of wall time per simulated year.
Compilation (numba, first step of each model) is reported separately and excluded from the rates.
"""
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from components.environment import atmosphere  # noqa: E402
from components.orbit import cowell  # noqa: E402
from components.core.constants import DAY  # noqa: E402

STEP = 300.0


def timed_run(model, days):
    n = int(round(days * DAY / STEP))
    start = model.t
    t0 = time.perf_counter()
    for k in range(1, n + 1):
        model.advance_to(start + STEP * k)
    return time.perf_counter() - t0, n


def density_call_cost(dm, n=2000):
    r = np.array([cowell.R_EQ + 420e3, 0.0, 0.0])
    jd = 2459945.5
    dm.density(r, jd)
    t0 = time.perf_counter()
    for i in range(n):
        dm.density(r, jd + i * 1e-4)
    py = (time.perf_counter() - t0) / n
    nb = float("nan")
    if dm.kernel is not None:
        data = dm.kernel_data
        t0 = time.perf_counter()
        for i in range(n):
            dm.kernel(r, jd + i * 1e-4, data)
        nb = (time.perf_counter() - t0) / n  # includes the numba dispatch from Python (~upper bound)
    return py, nb


def main():
    days = float(sys.argv[1]) if len(sys.argv) > 1 else 3.0
    print(f"Cowell, 420 km / 51.6 deg, J2..J6 + drag, communication step {STEP:.0f} s, "
          f"rtol {cowell.RTOL:g}, atol {cowell.ATOL_POSITION:g} m / {cowell.ATOL_VELOCITY:g} m/s")
    print(f"{'model':16s} {'compile s':>9s} {'days':>5s} {'s/day':>8s} {'s/year':>8s} {'steps/day':>9s} "
          f"{'us/step':>8s} {'rho py us':>9s} {'rho nb us':>9s}")
    for name in atmosphere.MODELS:
        dm = atmosphere.make_density_model(name, inclination=math.radians(51.6))
        m = cowell.CowellOrbit(density_model=dm)
        t0 = time.perf_counter()
        m.advance_to(STEP)  # first step: numba compilation of the integrator for this kernel
        compile_s = time.perf_counter() - t0
        d = min(days, 0.25) if dm.kernel is None else days
        s0 = m.steps
        wall, _ = timed_run(m, d)
        steps_day = (m.steps - s0) / d
        py, nb = density_call_cost(dm)
        print(f"{name:16s} {compile_s:9.2f} {d:5.2f} {wall / d:8.3f} {wall / d * 365.25:8.1f} {steps_day:9.0f} "
              f"{wall / (m.steps - s0) * 1e6:8.1f} {py * 1e6:9.1f} {nb * 1e6:9.2f}")
    print("\nconvergence (exponential, 1 day): position difference vs rtol 1e-13 / atol 1e-6 m, 1e-9 m/s")
    dm = atmosphere.make_density_model("exponential")
    ref = cowell.CowellOrbit(density_model=dm, rtol=1e-13, atol_position=1e-6, atol_velocity=1e-9)
    timed_run(ref, 1.0)
    for rtol, atr, atv in ((1e-9, 1e-2, 1e-5), (1e-10, 1e-3, 1e-6), (cowell.RTOL, cowell.ATOL_POSITION,
                                                                     cowell.ATOL_VELOCITY), (1e-12, 1e-5, 1e-8)):
        m = cowell.CowellOrbit(density_model=dm, rtol=rtol, atol_position=atr, atol_velocity=atv)
        wall, _ = timed_run(m, 1.0)
        dr = np.linalg.norm(m.position() - ref.position())
        print(f"  rtol {rtol:g} atol {atr:g} m {atv:g} m/s: |dr| = {dr:.2e} m, "
              f"{m.steps} steps, {wall:.3f} s")


if __name__ == "__main__":
    main()
