"""The thesis' de-orbit lifetime study (Section 3.2, Figures 11-13), run through the master.

    python -m system_ssp deorbit-study [--model averaged|cowell] [--density jacchia_roberts]
                                       [--out results/deorbit_study] [--scenarios 420km,475km,525km]

For each thesis scenario (420 -> 350 km, 475 -> 350 km, 525 -> 300 km perigee; 12 kg, Cd 2.2,
0.02 m^2, i 51.6 deg, start 2023-01-01) the packed system runs twice: with the NEIGHBOR burn
(retrograde from t = 0 until the Eq. 2-3 propellant is spent) and without (host alone). A run
ends at re-entry (orbit.reentered: 250 km). Lifetimes count from the start of the burn, as the
thesis' "de-orbit times" do.

Systems: `deorbit_lifetime` (OrbitAveraged, the default: the 97-year case takes seconds) or
`deorbit` (Cowell; about a minute of wall time per simulated year with Jacchia-Roberts, so the
century-long no-burn cases take long: pick scenarios with --scenarios or cap with --max-years).
Writes into --out: summary.json, table.md (also printed), <scenario>[_no_burn].csv time series,
and altitude_<scenario>.png (semi-major-axis altitude a - R_eq vs time, like the thesis' plots of
"NEIGHBOR.A - Earth.Radius", with perigee altitude shaded).
"""
import json
import math
from pathlib import Path
import sys
import tempfile

import numpy as np

from components.environment import atmosphere, space_weather
from components.orbit import propulsion
from components.core import constants
from components.core.constants import YEAR
from components.mission.neighbor import DEORBIT_RECORD, DEORBIT_SYSTEMS, SCENARIOS, scenario_set

from ..atomic import atomic_write, write_text_atomic
from ..builder import resolve_system
from ..errors import RunInterrupted, RunTimedOut, SimulationError, SSPError
from ..master import System, report, write_result
from ..master.plotting import read_result
from ..systems import PARAMETERS_DIR
from ..tools.console import (ArgumentParser, DEFAULT_SSP_DIR, add_console_arguments, console_settings, positive_float,
                             staged_results)

KM = 1000.0
SYSTEMS = DEORBIT_SYSTEMS
# Section 3.2 per scenario, from the mission definition: initial altitude and target perigee (km),
# delta-V (m/s), propellant (kg), burn (min), lifetime without / with NEIGHBOR (years), figure
THESIS = {name: dict(h0=s.altitude_km, target=s.target_perigee_km, **s.thesis) for name, s in SCENARIOS.items()
          if s.thesis}  # the study compares with the thesis: the scenarios it published
# `--space-weather thesis`: a stand-in for the thesis' space-weather file (docs/models/orbit.md,
# "Lifetimes"): the bundled history to the scenarios' start, then the solar-cycle-25 maximum at the
# level the predictions of the time gave (130 sfu, ap 9) and, from 2030, the solar-minimum entry a
# file of that time ended with and FreeFlyer held for ever after (75 sfu, ap 7).
THESIS_SPACE_WEATHER = (("2023-01-01", 130.0, 9), ("2030-01-01", 75.0, 7))
THESIS_SPACE_WEATHER_FILE = "space_weather_thesis.txt"
RECORD = list(DEORBIT_RECORD)


def run_study(model="averaged", density="jacchia_roberts", scenarios=None, ssp_dir=DEFAULT_SSP_DIR, out=None,
              max_years=150.0, space_weather_file="", progress=False):
    """Run the study; returns {run name: summary dict}. Writes files into `out` if given."""
    if model not in SYSTEMS:
        raise SSPError(f"unknown model {model!r} (expected one of: {', '.join(SYSTEMS)})")
    scenarios = list(scenarios or THESIS)
    unknown = [s for s in scenarios if s not in THESIS]
    if unknown:
        raise SSPError(f"unknown scenario(s) {', '.join(unknown)} (expected: {', '.join(THESIS)})")
    if not (isinstance(max_years, (int, float)) and max_years > 0 and math.isfinite(max_years)):
        raise SSPError(f"max_years must be a positive number, got {max_years!r}")
    if density not in atmosphere.MODELS:  # the FMU would say so only when the first run starts
        raise SSPError(f"--density {density!r}: expected one of {', '.join(atmosphere.MODELS)}")
    if space_weather_file not in ("", "thesis") and not Path(space_weather_file).is_file():
        raise SSPError(f"--space-weather {space_weather_file}: no such file (a CSSI space-weather file, or thesis)")
    ssp = resolve_system(str(Path(ssp_dir) / f"{SYSTEMS[model]}.ssp"))  # built first if it is a missing default
    with staged_results(out, lambda err: f"{err.run}.partial.csv") as staged, \
            tempfile.TemporaryDirectory(prefix="neighbor_sw_") as tmp:
        if space_weather_file == "thesis":  # written beside the results, so the run can be repeated
            space_weather_file = str((staged.path if staged else Path(tmp)) / THESIS_SPACE_WEATHER_FILE)
            space_weather.held_copy(space_weather_file, THESIS_SPACE_WEATHER)
        overrides = {"orbit.density_model": density, "orbit.space_weather_file": space_weather_file}
        summary = _run_all(ssp, scenarios, model, density, overrides, max_years, progress,
                           staged.path if staged else None)
        if staged is not None:
            write_text_atomic(staged.path / "summary.json", json.dumps(summary, indent=1))
            write_text_atomic(staged.path / "table.md", table(summary))
            plot(summary, staged.path)
            write_text_atomic(staged.path / "report.html", report_html(summary, staged.path))
            staged.commit()
    return summary


def _run_all(ssp, scenarios, model, density, overrides, max_years, progress, out):
    """The runs of the study, each run's CSV written into `out` (if given) as it finishes; a
    failed or interrupted run's error says which run it was (err.run)."""
    summary = {}
    with System(ssp) as system:
        for name in scenarios:
            for burn in (True, False):
                run = name + ("" if burn else "_no_burn")
                ssv = PARAMETERS_DIR / f"{scenario_set(DEORBIT_SYSTEMS['cowell'], name, burn)}.ssv"
                try:
                    r = system.run(stop_time=max_years * YEAR, parameter_sets=[str(ssv)], parameters=overrides,
                                   outputs=RECORD, progress=progress)
                except (SimulationError, RunInterrupted, RunTimedOut) as err:
                    err.run = run
                    raise
                reentered = bool(r.final["orbit.reentered"])
                ref = THESIS[name]
                s = {"scenario": name, "burn": burn, "model": model, "density_model": density,
                     "space_weather": Path(overrides["orbit.space_weather_file"]).name or "bundled",
                     "reentered": reentered, "lifetime_years": r.stop_time / YEAR,
                     "thesis_lifetime_years": ref["life_burn" if burn else "life_no_burn"],
                     "steps": r.steps, "wall_time_s": r.wall_time,
                     "propellant_used_kg": r.final["propulsion.propellant_used"],
                     "burn_time_min": r.final["propulsion.burn_time"] / 60.0}
                if burn:
                    lib = propulsion.mission_scenario(name)
                    s.update(delta_v_m_s=lib["delta_v"], propellant_kg=lib["propellant"],
                             burn_time_library_min=lib["burn_time"] / 60.0,
                             thesis_delta_v_m_s=ref["delta_v"], thesis_propellant_kg=ref["propellant"],
                             thesis_burn_min=ref["burn_min"])
                    burning = r.data["propulsion.burning"]
                    i_end = int(burning.nonzero()[0].max()) + 1 if burning.any() else 0
                    s["perigee_after_burn_km"] = float(r.data["orbit.perigee_altitude"][i_end]) / KM
                summary[run] = s
                if out is not None:
                    write_result(r.data, out / f"{run}.csv", r.units)
    return summary



def table(summary):
    lines = ["| scenario | dV m/s (thesis) | propellant kg (thesis) | burn min (thesis) | lifetime no burn y (thesis) "
             "| lifetime with burn y (thesis) | model |",
             "|---|---|---|---|---|---|---|"]
    for name in THESIS:
        b, n = summary.get(name), summary.get(name + "_no_burn")
        if b is None or n is None:
            continue

        def life(s):
            mark = "" if s["reentered"] else "> "
            diff = 100.0 * (s["lifetime_years"] - s["thesis_lifetime_years"]) / s["thesis_lifetime_years"]
            return f"{mark}{s['lifetime_years']:.2f} ({s['thesis_lifetime_years']:.2f}; {diff:+.0f} %)"

        lines.append(f"| {name} | {b['delta_v_m_s']:.2f} ({b['thesis_delta_v_m_s']:.2f}) | "
                     f"{b['propellant_used_kg']:.3f} ({b['thesis_propellant_kg']:.3f}) | "
                     f"{b['burn_time_min']:.2f} ({b['thesis_burn_min']:.2f}) | {life(n)} | {life(b)} | "
                     f"{b['model']}, {b['density_model']}, {b.get('space_weather', 'bundled')} space weather |")
    return "\n".join(lines) + "\n"


REQUIREMENT_YEARS = 5.0  # the mission's goal: re-entry within five years of the burn


def plot(summary, out):
    """altitude_<scenario>.png: a - R_eq (km) vs years since the burn, with and without NEIGHBOR."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r_eq = constants.R_EQ
    for name, ref in THESIS.items():
        if name not in summary:
            continue
        runs = ((name + "_no_burn", "without NEIGHBOR", "tab:red"), (name, "with NEIGHBOR", "tab:blue"))
        with_burn = summary[name]["lifetime_years"]
        # a host that stays up for decades squashes the de-orbit into the axis' first percent: zoom too
        zoom = summary[name + "_no_burn"]["lifetime_years"] > 4.0 * max(with_burn, REQUIREMENT_YEARS)
        fig, axes = plt.subplots(1, 2 if zoom else 1, figsize=(12 if zoom else 8, 4.5), squeeze=False)
        for k, ax in enumerate(axes[0]):
            for run, label, color in runs:
                data = np.genfromtxt(out / f"{run}.csv", delimiter=",", names=True, deletechars="")
                years = data["time"] / YEAR
                ax.plot(years, (data["orbit.sma"] - r_eq) / KM, color=color,
                        label=f"{label}: {summary[run]['lifetime_years']:.2f} y "
                              f"(thesis {summary[run]['thesis_lifetime_years']:.2f} y)")
                ax.fill_between(years, data["orbit.perigee_altitude"] / KM, (data["orbit.sma"] - r_eq) / KM,
                                color=color, alpha=0.15, linewidth=0)
            ax.axhline(250.0, color="k", linestyle=":", linewidth=1, label="re-entry, 250 km")
            ax.axvline(REQUIREMENT_YEARS, color="tab:green", linestyle="--", linewidth=1,
                       label=f"requirement: re-entry within {REQUIREMENT_YEARS:g} years")
            ax.set_xlabel("years since the start of the burn")
            ax.grid(alpha=0.3)
            if k == 1:
                ax.set_xlim(0.0, 1.5 * max(with_burn, REQUIREMENT_YEARS))
                ax.set_title("zoom: the de-orbit with NEIGHBOR", fontsize=9)
        ax = axes[0][0]
        s = summary[name]
        ax.set_title(f"Orbital lifetime from {ref['h0']:g} km (thesis Fig. {ref['figure']}); {s['model']} orbit, "
                     f"{s['density_model']}", fontsize=9 if zoom else 10)
        ax.set_ylabel("a - R_eq (km); shaded down to perigee")
        ax.legend(loc="upper right", fontsize=8)
        fig.tight_layout()
        with atomic_write(out / f"altitude_{name}.png", "wb") as f:
            fig.savefig(f, dpi=110, format="png")
        plt.close(fig)


def report_html(summary, folder):
    """report.html of the study: its table beside the thesis, and per scenario the altitude with and
    without NEIGHBOR as an interactive figure (the five-year requirement shaded), versions."""
    sections = [("Lifetimes beside the thesis", report.markdown(table(summary), far_beyond=None))]
    for name in THESIS:
        if name not in summary:
            continue
        columns, units = {}, {}
        runs = [(name, "with NEIGHBOR"), (name + "_no_burn", "without NEIGHBOR")]
        for run, label in runs:
            data, data_units = read_result(folder / f"{run}.csv")
            columns[f"time {label}"] = data["time"]
            columns[f"a - R_eq, {label}"] = (data["orbit.sma"] - constants.R_EQ) / KM
            units[f"a - R_eq, {label}"] = "km"
        # one time axis: each run on the longer run's times (NaN past its re-entry)
        t = max((columns[f"time {label}"] for _, label in runs), key=len)
        figure_columns = {"time": t}
        for _, label in runs:
            own = columns[f"time {label}"]
            y = np.interp(t, own, columns[f"a - R_eq, {label}"], right=np.nan)
            figure_columns[f"a - R_eq, {label}"] = y
        sections.append((f"{name}: orbital lifetime (thesis Fig. {THESIS[name]['figure']})", report.figure(
            figure_columns, units, [n for n in figure_columns if n != "time"],
            bands=[(0.0, REQUIREMENT_YEARS * YEAR, f"re-entry required within {REQUIREMENT_YEARS:g} years")])))
    sections.append(("Versions", report.table(("software", "version"), list(report.versions().items()))))
    return report.page("NEIGHBOR de-orbit lifetime study", sections)


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim deorbit-study", description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", choices=list(SYSTEMS), default="averaged",
                    help="orbit fidelity: averaged (default; seconds for a century) or cowell (the full orbit)")
    ap.add_argument("--density", default="jacchia_roberts",
                    help="exponential | harris_priester | msis | jacchia_roberts (default)")
    ap.add_argument("--space-weather", default="", metavar="FILE|thesis",
                    help="CSSI space-weather file (default: the bundled copy), or `thesis`: the stand-in for the "
                    "thesis' file (history to 2023, 130 sfu to 2030, then 75 sfu held; docs/models/orbit.md)")
    ap.add_argument("--scenarios", default=",".join(THESIS), help="comma-separated, e.g. 420km,475km")
    ap.add_argument("--max-years", type=positive_float, default=150.0,
                    help="the longest a run may last before re-entry (default: %(default)s years)")
    ap.add_argument("--out", default="results/deorbit_study", help="results folder (default: %(default)s)")
    ap.add_argument("--ssp-dir", default=str(DEFAULT_SSP_DIR),
                    help="folder of the built systems (default: %(default)s)")
    add_console_arguments(ap)
    args = ap.parse_args(argv)
    progress = console_settings(args)
    summary = run_study(args.model, args.density, [s for s in args.scenarios.split(",") if s], args.ssp_dir,
                        args.out, args.max_years, args.space_weather, progress)
    print(table(summary), end="")
    total = sum(s["wall_time_s"] for s in summary.values())
    print(f"wall time: {total:.1f} s for {len(summary)} runs; results in {args.out}")
    ok = all(s["reentered"] for s in summary.values())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
