"""The 3U CubeSat's shipped systems end to end: the magnetometer-only B-dot detumble from 10 deg/s
(three orbits) and one day of nadir pointing with the wheels and the magnetic momentum dumping
under the disturbance torques, its battery through the eclipses; and the same day without dumping.

    python build_fmus.py            # builds build/ssp/cubesat_3u_*.ssp
    python examples/cubesat_3u_day.py [figure.png]

Prints the numbers docs/models/cubesat_3u.md quotes and writes the figure (default
results/cubesat_3u_day.png): the detumble's rate, and over the day the pointing error, the
wheels' momentum with and without dumping, the wheel speeds and the battery's state of charge
with the solar power. About 10 minutes (each day is 86400 steps of 17 FMUs).
"""
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import system_ssp  # noqa: E402
from components.acs.reaction_wheel_array import RPM  # noqa: E402

SSP = ROOT / "build" / "ssp"
VECTOR = lambda name, n: [f"{name}[{i}]" for i in range(1, n + 1)]  # noqa: E731
DAY_OUTPUTS = (["guidance.pointing_error", "power.state_of_charge", "solar_arrays.solar_power",
                "shadow.sunlit_fraction", "power.load_power"] + VECTOR("wheels.wheel_speed", 4)
               + VECTOR("dumping.wheel_momentum_B", 3) + VECTOR("coils.dipole_B", 3)
               + VECTOR("disturbances.torque_B", 3))


def columns(data, name, n):
    return np.column_stack([np.asarray(data[f"{name}[{i}]"], float) for i in range(1, n + 1)])


def run(name, outputs, **settings):
    t0 = time.perf_counter()
    data = system_ssp.simulate(SSP / f"{name}.ssp", outputs=outputs, **settings).data
    print(f"{name} {settings or ''}: {time.perf_counter() - t0:.0f} s of wall time")
    return {k: np.asarray(v, float) for k, v in data.items()}


def main(figure):
    detumble = run("cubesat_3u_detumble", VECTOR("dynamics.omega_BN_B", 3))
    rate = np.degrees(np.linalg.norm(columns(detumble, "dynamics.omega_BN_B", 3), axis=1))
    td = detumble["time"]
    print(f"detumble: 10 deg/s -> {rate[td >= 5700].max():.2f} deg/s after one orbit, {rate[-1]:.3f} deg/s at "
          f"{td[-1]:.0f} s (max over the last orbit {rate[td >= td[-1] - 5700].max():.2f} deg/s)")
    days = {"dumping": run("cubesat_3u_nadir_day", DAY_OUTPUTS),
            "no dumping": run("cubesat_3u_nadir_day", DAY_OUTPUTS, parameters={"dumping.gain": 0.0})}
    for label, d in days.items():
        t = d["time"]
        settled = t >= 600.0
        error = np.degrees(d["guidance.pointing_error"])
        h = np.linalg.norm(columns(d, "dumping.wheel_momentum_B", 3), axis=1) * 1e3
        speed = np.abs(columns(d, "wheels.wheel_speed", 4)) / RPM
        torque = np.linalg.norm(columns(d, "disturbances.torque_B", 3), axis=1)
        soc = d["power.state_of_charge"]
        dark = d["shadow.sunlit_fraction"] == 0.0
        print(f"{label}: pointing error after 600 s max {error[settled].max():.4f} deg, rms "
              f"{np.sqrt(np.mean(error[settled] ** 2)):.4f} deg; wheel momentum max {h[settled].max():.2f} mN.m.s, "
              f"at the end {h[-1]:.2f}; wheel speed max {speed.max():.0f} rpm; disturbance torque mean "
              f"{torque.mean():.2e} N.m, max {torque.max():.2e}; eclipse {dark.sum() / 60:.0f} min a day; "
              f"solar power mean {d['solar_arrays.solar_power'].mean():.2f} W, load mean "
              f"{d['power.load_power'].mean():.2f} W; state of charge min {soc.min():.3f}, end {soc[-1]:.3f}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(5, 1, figsize=(9, 12), constrained_layout=True)
    ax[0].semilogy(td / 3600, rate)
    ax[0].set(ylabel="body rate (deg/s)", xlabel="time (h)", title="cubesat_3u_detumble: magnetometer-only B-dot")
    d, t_h = days["dumping"], days["dumping"]["time"] / 3600
    ax[1].semilogy(t_h, np.degrees(d["guidance.pointing_error"]))
    ax[1].set(ylabel="nadir pointing error (deg)", title="cubesat_3u_nadir_day")
    for label, run_data in days.items():
        h = np.linalg.norm(columns(run_data, "dumping.wheel_momentum_B", 3), axis=1) * 1e3
        ax[2].plot(run_data["time"] / 3600, h, label=label)
    ax[2].set(ylabel="wheel momentum (mN.m.s)")
    ax[2].legend()
    ax[3].plot(t_h, columns(d, "wheels.wheel_speed", 4) / RPM)
    ax[3].set(ylabel="wheel speeds (rpm)")
    ax[4].plot(t_h, d["power.state_of_charge"], label="state of charge")
    ax[4].set(ylabel="state of charge", xlabel="time (h)")
    twin = ax[4].twinx()
    twin.plot(t_h, d["solar_arrays.solar_power"], color="tab:orange", alpha=0.5, lw=0.6)
    twin.set_ylabel("solar power (W)", color="tab:orange")
    figure.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure, dpi=80)
    print(f"wrote {figure}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "results" / "cubesat_3u_day.png")
