"""The 3U CubeSat's first day after separation end to end (the shipped system cubesat_3u_mission):
B-dot detumble from 10 deg/s with the magnetometer, Sun-safe on the coarse Sun sensors, then nadir
pointing on the attitude estimator (gyro, horizon sensor, coarse Sun sensors) with the four
wheels and the magnetic momentum dumping under the disturbance torques, its battery through the
eclipses.

    python build_fmus.py            # builds build/ssp/cubesat_3u_*.ssp
    python examples/cubesat_3u_day.py [figure.png] [--stop SECONDS]

Prints the numbers docs/models/cubesat_3u.md quotes and writes the figure (default
results/cubesat_3u_day.png): the body rate and the mode, the true nadir pointing error (the body's
-z against the nadir) and the estimator's attitude error, the wheel speeds and momentum, the
battery's state of charge with the solar power. About half an hour for the day (86400 steps of
23 FMUs).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import system_ssp  # noqa: E402
from components.acs import mode_sequence  # noqa: E402
from components.acs.reaction_wheel_array import RPM  # noqa: E402
from components.attitude.pointing import nadir_axis_error  # noqa: E402
from components.mission import cubesat_3u  # noqa: E402

SSP = ROOT / "build" / "ssp" / "cubesat_3u_mission.ssp"
VECTOR = lambda name, n: [f"{name}[{i}]" for i in range(1, n + 1)]  # noqa: E731
OUTPUTS = (["modes.mode", "estimator.attitude_error", "power.state_of_charge", "solar_arrays.solar_power",
            "shadow.sunlit_fraction", "power.load_power"]
           + VECTOR("dynamics.omega_BN_B", 3) + VECTOR("dynamics.q_BN", 4) + VECTOR("orbit.r_BN_N", 3)
           + VECTOR("wheels.wheel_speed", 4) + VECTOR("dumping.wheel_momentum_B", 3) + VECTOR("coils.dipole_B", 3))


def columns(data, name, n):
    return np.column_stack([np.asarray(data[f"{name}[{i}]"], float) for i in range(1, n + 1)])


def summary(d):
    """The numbers of the day (printed, and quoted by the docs)."""
    t, mode = d["time"], d["modes.mode"]
    rate = np.degrees(np.linalg.norm(columns(d, "dynamics.omega_BN_B", 3), axis=1))
    error = np.degrees(nadir_axis_error(columns(d, "dynamics.q_BN", 4), columns(d, "orbit.r_BN_N", 3)))
    estimate = np.degrees(d["estimator.attitude_error"])
    entered = {int(m): float(t[np.argmax(mode == m)]) for m in np.unique(mode)}
    lines = ["modes entered: " + ", ".join(f"{mode_sequence.MODE_NAMES[m]} at {s:.0f} s" for m, s in entered.items())]
    if mode_sequence.POINTING in entered:
        settled = (mode == mode_sequence.POINTING) & (t >= entered[mode_sequence.POINTING] + 600.0)
        lines.append(f"nadir pointing from 600 s after entry ({settled.sum()} s): true error max "
                     f"{error[settled].max():.3f} deg, rms {np.sqrt(np.mean(error[settled] ** 2)):.3f} deg, "
                     f"99th percentile "
                     f"{np.percentile(error[settled], 99):.3f} deg; estimator attitude error (all axes) max "
                     f"{estimate[settled].max():.2f} deg, rms {np.sqrt(np.mean(estimate[settled] ** 2)):.2f} deg")
    h = np.linalg.norm(columns(d, "dumping.wheel_momentum_B", 3), axis=1) * 1e3
    speed = np.abs(columns(d, "wheels.wheel_speed", 4)) / RPM
    soc, dark = d["power.state_of_charge"], d["shadow.sunlit_fraction"] == 0.0
    lines.append(f"detumble: 10 deg/s -> {rate[int(entered.get(mode_sequence.SUN_SAFE, t[-1]))]:.2f} deg/s at its end; "
                 f"wheels: speed max {speed.max():.0f} rpm (limit {cubesat_3u.WHEELS.max_speed / RPM:.0f}), momentum "
                 f"max {h.max():.2f} mN.m.s, at the end {h[-1]:.2f}; rods |m| max "
                 f"{np.abs(columns(d, 'coils.dipole_B', 3)).max():.3f} A.m2")
    lines.append(f"power: eclipse {dark.sum() / 60:.0f} min in {t[-1] / 3600:.1f} h; solar mean "
                 f"{d['solar_arrays.solar_power'].mean():.2f} W, load mean {d['power.load_power'].mean():.2f} W; "
                 f"state of charge min {soc.min():.3f}, end {soc[-1]:.3f}")
    return lines, rate, error, estimate


def figure(d, rate, error, estimate, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t_h = d["time"] / 3600
    fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True, constrained_layout=True)
    ax[0].semilogy(t_h, rate, lw=0.8)
    ax[0].set(ylabel="body rate (deg/s)", title="cubesat_3u_mission: detumble, Sun-safe, nadir")
    modes = ax[0].twinx()
    modes.step(t_h, d["modes.mode"], color="tab:red", where="post")
    modes.set_yticks(range(3), mode_sequence.MODE_NAMES)
    ax[1].semilogy(t_h, np.maximum(error, 1e-3), lw=0.6, label="true nadir error (body -z)")
    ax[1].semilogy(t_h, np.maximum(estimate, 1e-3), lw=0.6, alpha=0.6, label="estimator attitude error")
    ax[1].set(ylabel="angle (deg)", ylim=(1e-3, 200))
    ax[1].legend(loc="upper right")
    ax[2].plot(t_h, columns(d, "wheels.wheel_speed", 4) / RPM, lw=0.8)
    ax[2].set(ylabel="wheel speeds (rpm)")
    ax[3].plot(t_h, d["power.state_of_charge"])
    ax[3].set(ylabel="state of charge", xlabel="time (h)")
    twin = ax[3].twinx()
    twin.plot(t_h, d["solar_arrays.solar_power"], color="tab:orange", alpha=0.5, lw=0.6)
    twin.set_ylabel("solar power (W)", color="tab:orange")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("figure", nargs="?", type=Path, default=ROOT / "results" / "cubesat_3u_day.png")
    parser.add_argument("--stop", type=float, default=None, help="stop time, s (default: the system's, one day)")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    settings = {} if args.stop is None else {"stop_time": args.stop}
    data = system_ssp.simulate(SSP, outputs=OUTPUTS, **settings).data
    d = {k: np.asarray(data[k], float) for k in data.dtype.names}
    print(f"cubesat_3u_mission: {time.perf_counter() - t0:.0f} s of wall time for {d['time'][-1]:.0f} s")
    lines, rate, error, estimate = summary(d)
    print("\n".join(lines))
    figure(d, rate, error, estimate, args.figure)


if __name__ == "__main__":
    main()
