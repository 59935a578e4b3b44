"""Orbital lifetime with the orbit-averaged model (components.orbit.averaged), no FMUs.

    python bench/bench_lifetime.py [--models exponential jacchia_roberts ...] [--skip-timing]
                                   [--skip-scenarios] [--msis-days 5]

Prints
1. wall time per simulated year of the averaged model with each density model (525 km circular,
   one simulated year; msis: --msis-days simulated days, scaled to a year, since every drag
   average is 16 pymsis calls);
2. the three thesis scenarios (Sec. 3.2: 420 -> 350, 475 -> 350, 525 -> 300 km, 51.6 deg, 12 kg,
   Cd 2.2, 0.02 m2, epoch 2023-01-01, re-entry at a mean perigee altitude of 250 km) without and
   with the de-orbit burn, for each model in --models: the burn is a finite retrograde burn of the
   4 x 25 mN thrusters (Isp 42 s) starting at t = 0 with the library's propellant for the Eq. 2
   delta-V (components.orbit.propulsion.deorbit_scenario), the mass falling as the propellant is used,
   then a coast to re-entry at the final mass. Lifetimes count from the start of the burn, as in
   the thesis, and are printed beside the thesis' values.

Space weather for msis / jacchia_roberts: the bundled CSSI file (observed to 2026-08, predicted to
2041-10, then the last entry held; see components/environment/space_weather.py), not the 2023-era data the
thesis' FreeFlyer runs used.
"""
import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from components.environment import atmosphere  # noqa: E402
from components.orbit import propulsion  # noqa: E402
from components.orbit import averaged as oa  # noqa: E402
from components.core.constants import DAY, YEAR  # noqa: E402

THESIS = {420: (4.38, 2.20), 475: (25.04, 3.44), 525: (97.41, 3.19)}  # years without / with NEIGHBOR
TARGET = {420: 350, 475: 350, 525: 300}


def make(name):
    return atmosphere.make_density_model(name, inclination=math.radians(51.6))


def timing(name, msis_days):
    model = make(name)
    warm = oa.OrbitAveraged(model, sma0=oa.R_EQ + 525e3)
    warm.advance_to(2 * DAY)  # compile the kernel path
    span = msis_days * DAY if name == "msis" else YEAR
    m = oa.OrbitAveraged(model, sma0=oa.R_EQ + 525e3)
    t0 = time.perf_counter()
    m.advance_to(span)
    wall = time.perf_counter() - t0
    per_year = wall * YEAR / span
    print(f"  {name:16s} {per_year:9.3f} s per simulated year   ({m.evaluations} drag averages over "
          f"{span / DAY:.0f} days, {1e6 * wall / m.evaluations:.1f} us each)")


def lifetime(model, h0, burn, cap_years=250.0):
    """(lifetime in years or None past the cap, wall s, dict of burn results)."""
    m = oa.OrbitAveraged(model, sma0=oa.R_EQ + h0 * 1e3, inc0=math.radians(51.6))
    info = {}
    t0 = time.perf_counter()
    mass = propulsion.MASS0
    if burn:
        s = propulsion.deorbit_scenario(h0 * 1e3, TARGET[h0] * 1e3)
        thr = propulsion.MainThrusters(mass0=propulsion.MASS0, propellant_budget=s["propellant"])
        t, h = 0.0, 5.0
        while not thr.spent:
            force = thr.force_B(True)
            mass = thr.mass
            thr.step(True, h)
            m.advance_to(t + h, force, retrograde=True, mass=mass)
            t += h
        mass = thr.mass
        info = {"dv": s["delta_v"], "mp": s["propellant"], "burn_min": thr.burn_time / 60.0,
                "perigee_km": m.perigee_altitude / 1e3, "apogee_km": m.apogee_altitude / 1e3}
    t = m.t
    while not m.reentered and t < cap_years * YEAR:
        t += 30 * DAY
        m.advance_to(t, mass=mass)
    wall = time.perf_counter() - t0
    return (m.reentry_time / YEAR if m.reentered else None), wall, info


def scenarios(names):
    for name in names:
        model = make(name)
        print(f"\n  density model: {name}")
        print("  initial  burn  lifetime [y]  thesis [y]  wall [s]   burn: dV [m/s]  mp [kg]  time [min]  "
              "perigee x apogee [km]")
        for h0 in (420, 475, 525):
            for burn in (False, True):
                life, wall, info = lifetime(model, h0, burn)
                life_txt = f"{life:10.2f}" if life is not None else "   > 250  "
                ref = THESIS[h0][1 if burn else 0]
                line = f"  {h0} km  {'yes' if burn else ' no'}  {life_txt}    {ref:8.2f}   {wall:7.2f}"
                if burn:
                    line += (f"    {info['dv']:6.2f}       {info['mp']:.3f}    {info['burn_min']:7.2f}     "
                             f"{info['perigee_km']:.1f} x {info['apogee_km']:.1f}")
                print(line, flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", nargs="+", default=["jacchia_roberts", "exponential"],
                    help="density models for the scenario table (default: jacchia_roberts exponential)")
    ap.add_argument("--timing-models", nargs="+", default=list(atmosphere.MODELS))
    ap.add_argument("--msis-days", type=float, default=5.0)
    ap.add_argument("--skip-timing", action="store_true")
    ap.add_argument("--skip-scenarios", action="store_true")
    args = ap.parse_args()
    if not args.skip_timing:
        print("Wall time per simulated year, orbit-averaged model, 525 km circular:")
        for name in args.timing_models:
            try:
                timing(name, args.msis_days)
            except (ImportError, ValueError) as exc:
                print(f"  {name:16s} not available: {exc}")
    if not args.skip_scenarios:
        print("\nThesis de-orbit scenarios (lifetime from the start of the burn to a 250 km mean perigee):")
        scenarios(args.models)


if __name__ == "__main__":
    main()
