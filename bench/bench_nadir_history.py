"""The fix without the Sun over many flights: components/sensing/nadir_history.py on the flight of
its tests (tests/components/sensing/test_nadir_history.py: the mission's rigid body, BMG160 gyro
with a 1 mrad/s bias per axis, 0.25 deg horizon sensor, 20 minutes at 420 km), per tumble rate
and seed: the error at the last sample, the largest 1-sigma, the NEES (chi-square with 3 degrees
of freedom when the covariance is right: mean 3, above 7.81 one time in twenty), or no fix (two
attitudes fit alike) and the solve's time. docs/models/sensing.md quotes the default run.

    python bench/bench_nadir_history.py [--rates 13.5 10 5 0] [--seeds 100 112]
"""
import argparse
import importlib.util
import math
import statistics
import time
from pathlib import Path

from components.sensing import triad
from components.sensing.mekf import AttitudeMEKF

NEES_BOUND_95 = 7.815


def _flights():
    """The tests' flight (one definition for both)."""
    path = Path(__file__).resolve().parents[1] / "tests" / "components" / "sensing" / "test_nadir_history.py"
    spec = importlib.util.spec_from_file_location("nadir_history_flights", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rates", type=float, nargs="+", default=[13.5, 10.0, 5.0, 0.0],
                        help="tumble rates, deg/s (0: turning only at minus the gyro's bias)")
    parser.add_argument("--seeds", type=int, nargs=2, default=[100, 112], metavar=("FIRST", "END"))
    args = parser.parse_args(argv)
    flights = _flights()
    for rate in args.rates:
        nees, errors, missing, times = [], [], 0, []
        for seed in range(*args.seeds):
            q_true, _, history = flights._fly(seed, rate)
            start = time.perf_counter()
            f = history.solve(AttitudeMEKF(flights.GYRO_SIGMA * math.sqrt(flights.GYRO_SAMPLE_TIME), 1e-6))
            times.append(time.perf_counter() - start)
            if f is None:
                missing += 1
                print(f"{rate:5.1f} deg/s seed {seed}: no fix (two attitudes fit alike)", flush=True)
                continue
            errors.append(math.degrees(triad.error_angle(f.q, q_true)))
            nees.append(f.attitude_nees(q_true))
            print(f"{rate:5.1f} deg/s seed {seed}: error {errors[-1]:.3f} deg, largest sigma "
                  f"{math.degrees(max(f.attitude_sigma())):.3f} deg, NEES {nees[-1]:.2f}, solve {times[-1]:.1f} s",
                  flush=True)
        if nees:
            print(f"{rate:5.1f} deg/s: {len(nees)} fixed, {missing} without; error {min(errors):.2f}-{max(errors):.2f} "
                  f"deg; NEES mean {statistics.mean(nees):.2f}, {sum(n > NEES_BOUND_95 for n in nees)} above "
                  f"{NEES_BOUND_95}; solve {statistics.mean(times):.1f} s mean\n", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
