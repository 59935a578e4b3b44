"""Long run of the ACS of the mode specification modes system with the specification's mode delays (RMD 6000 s, ...).

    python build_fmus.py            # builds build/ssp/acs_modes.ssp
    python examples/acs_modes_long_run.py [stop_time] [step]

Scenario: acs_modes_sun_facing.ssv, a 420 km orbit at 98 deg inclination whose node is 90 deg
east of the Sun at the epoch (the Sun 75 deg from the orbit plane): no eclipse. Why: with the
specification's RMD = 6000 s longer than the 5577 s period of a 420 km orbit, Reorient always meets a
night before RMD and the tables send it back to Spinup (Spinup col 5), so the deployment never
completes in an orbit with eclipses. Without eclipses there is no Orbit Night either: the run
ends holding Orbit Day (7). The default 0.2 A.m2 coils and a 2 s step (the 1 s of the system's
default halves the run time; the fastest loop, the azimuth loop at 0.05 rad/s, has omega_n h =
0.1). Span 36000 s (6.5 orbits): the sequence reaches Orbit Day at about 20800 s (Reorient
holds the elevation at 15 deg until RMD, then takes ~12500 s to bring it inside the coarse 10
deg with the 0.2 A.m2 coils) and the rest shows the Orbit Day hold (15000 s, no drift).

Writes results/acs_modes_long_run.png (mode, body rates, wheel speed, Sun angles versus time)
and prints the first entry time of each mode.
"""
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import system_ssp  # noqa: E402
from components.acs.modes import MODE_NAMES  # noqa: E402

SSP = ROOT / "build" / "ssp" / "acs_modes.ssp"
SCENARIO = "parameters/acs_modes_sun_facing.ssv"
OUTPUTS = ["modes.mode", "modes.uncertain", "shadow.orbit_day", "signals.sin_sun_elevation",
           "signals.sin_sun_azimuth", "wheel.wheel_rate", "signals.body_rate",
           *[f"dynamics.omega_BN_B[{i}]" for i in (1, 2, 3)]]


def main(stop=36000.0, step=2.0):
    r = system_ssp.simulate(SSP, stop_time=stop, step_size=step, parameter_sets=[SCENARIO], outputs=OUTPUTS)
    d = r.data
    t = np.asarray(d["time"], float)
    mode = np.asarray(d["modes.mode"]).astype(int)
    print(f"{SCENARIO}: {stop:.0f} s, step {step:g} s; day fraction {np.mean(d['shadow.orbit_day']):.2f}")
    for m in range(10):
        hit = np.flatnonzero(mode == m)
        print(f"  mode {m} {MODE_NAMES[m]:<15} " + (f"first entered at {t[hit[0]]:8.0f} s" if len(hit) else "never"))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(4, 1, sharex=True, figsize=(11, 10))
    ax[0].step(t, mode, where="post")
    ax[0].set_yticks(range(10), [f"{i} {n}" for i, n in enumerate(MODE_NAMES)], fontsize=7)
    ax[0].set_ylabel("mode")
    for i, c in zip((1, 2, 3), "XYZ"):
        ax[1].plot(t, np.degrees(d[f"dynamics.omega_BN_B[{i}]"]), label=f"omega_{c}")
    ax[1].set_ylabel("body rate (deg/s)")
    ax[1].legend(loc="upper right")
    ax[2].plot(t, d["wheel.wheel_rate"])
    ax[2].set_ylabel("wheel rate (rad/s)")
    ax[3].plot(t, np.degrees(np.arcsin(np.clip(d["signals.sin_sun_elevation"], -1, 1))), label="elevation")
    ax[3].plot(t, np.degrees(np.arcsin(np.clip(d["signals.sin_sun_azimuth"], -1, 1))), label="asin(sin azimuth)")
    ax[3].set_ylabel("Sun angle (deg)")
    ax[3].set_xlabel("time (s)")
    ax[3].legend(loc="upper right")
    for a in ax:
        a.grid(True, alpha=0.3)
    fig.suptitle("ACS of the mode specification modes, seed delays, eclipse-free (sun-facing) orbit")
    fig.tight_layout()
    out = ROOT / "results" / "acs_modes_long_run.png"
    out.parent.mkdir(exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*(float(a) for a in sys.argv[1:3]))
