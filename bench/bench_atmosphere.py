"""Cost of the density models: numba compile time of each kernel (first call) and time per
call from numba code (a loop inside an njit function, as the orbit right-hand side calls it),
plus the cost of one NRLMSIS call through pymsis and of the Python `density` method.

    python bench/bench_atmosphere.py
"""
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from components.environment import atmosphere  # noqa: E402

JD = 2459945.5  # 2023-01-01


@njit(cache=False)
def _loop(kernel, data, rs, jd, n):
    s = 0.0
    for k in range(n):
        r = rs[k % rs.shape[0]]
        s += kernel(r, jd + k * 1e-5, data)
    return s


def main():
    rng = np.random.default_rng(1)
    u = rng.normal(size=(64, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    rs = u * (6378137.0 + rng.uniform(200e3, 600e3, size=(64, 1)))
    for name in atmosphere.MODELS:
        t0 = time.perf_counter()
        model = atmosphere.make_density_model(name)
        t_build = time.perf_counter() - t0
        if model.kernel is None:
            model.density(rs[0], JD)
            t0 = time.perf_counter()
            n = 200
            for k in range(n):
                model.density(rs[k % 64], JD + k * 1e-5)
            per = (time.perf_counter() - t0) / n
            print(f"{name:16s} build {t_build:6.2f} s   Python density (pymsis) {per * 1e6:9.1f} us/call   (no kernel)")
            continue
        t0 = time.perf_counter()
        model.kernel(rs[0], JD, model.kernel_data)
        t_compile = time.perf_counter() - t0
        _loop(model.kernel, model.kernel_data, rs, JD, 10)  # compile the loop for this kernel
        n = 200_000
        t0 = time.perf_counter()
        _loop(model.kernel, model.kernel_data, rs, JD, n)
        per = (time.perf_counter() - t0) / n
        t0 = time.perf_counter()
        for k in range(2000):
            model.density(rs[k % 64], JD)
        py = (time.perf_counter() - t0) / 2000
        print(f"{name:16s} build {t_build:6.2f} s   kernel compile {t_compile:6.2f} s   "
              f"{per * 1e9:8.0f} ns/call in numba   Python density {py * 1e6:6.1f} us/call")


if __name__ == "__main__":
    main()
