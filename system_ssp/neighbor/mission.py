"""The NEIGHBOR mission from deployment to re-entry, run through the master, with the thesis'
figures and a summary beside the published numbers.

    neighbor-cosim mission [--scenario 420km] [--orbit averaged|cowell]
                           [--gnc closed-loop|closed-loop-truth|thesis]
                           [--out results/mission] [--ssv FILE] [--set COMP.VAR=VALUE]

Runs build/ssp/neighbor_mission_lifetime.ssp (orbit-averaged orbit, the default; about a
two minutes) or neighbor_mission.ssp (Cowell orbit, `--orbit cowell`) with the scenario's parameter
set (system_ssp/systems/parameters/neighbor_mission_<scenario>.ssv). `--gnc closed-loop` (the
default) flies the coupled loop: the burn attitude from the orbit, thrust along the body axis,
flight settle criteria, the controllers on the attitude estimator (sensors with noise);
`--gnc closed-loop-truth` the same on the true state (parameters/mission_gnc_truth.ssv); `--gnc
thesis` applies parameters/mission_gnc_thesis.ssv, the thesis' guidance and control on the true
state, which gives its published numbers (system_ssp/systems/generators/mission.py).
It writes into --out:
- timeseries.parquet  the recorded signals (RECORD below; rows per nc:Schedule mode) with their
                   units (--timeseries csv: timeseries.csv and timeseries.units.json);
- summary.json     every computed figure beside the thesis' (also printed as a table);
- altitude.png (Fig. 11), detumble.png (Fig. 20-22), slew.png (Fig. 27-29), tracking.png
  (Fig. 43-44), battery.png (Fig. 46), data.png (Fig. 47); estimation.png (the estimator's
  attitude error against its 3-sigma, and its rate error; not with truth feedback).
`--profile` adds the wall time per component and of the master to the summary. The folder is
written as one unit (replacing an earlier one only when complete); a failed or interrupted run
leaves <out>.partial with the rows so far and PARTIAL.txt saying why.
"""
import json
from pathlib import Path
import sys
from typing import Dict

import numpy as np

from components.core.constants import DAY, MU_EARTH, R_EQ, YEAR
from components.attitude.thruster_set import thesis_layout
from components.mission.power import CELL_CAPACITY
from components.mission.modes import DeorbitPhase, MissionMode
from components.mission.neighbor import (DATA_STORAGE_LIMIT_B, DEFAULT_GNC, DEFAULT_SCENARIO, GNC_SETS,
                                         MISSION_RECORD, MISSION_SYSTEMS, SCENARIOS as DEFINED_SCENARIOS, SPACECRAFT,
                                         scenario_set)

from ..atomic import atomic_write, check_output_place, write_text_atomic
from ..builder import resolve_system
from ..errors import SSPError
from ..limits import read_text_input
from ..master import System, report, write_result
from ..master.observers import profile_table
from ..systems import PARAMETERS_DIR
from ..tools.console import (ArgumentParser, DEFAULT_SSP_DIR, add_console_arguments, console_settings, parse_sets,
                             positive_float, staged_results)
from ..tools import requirements as req
from . import budgets, deorbit_study, propulsion_report, thesis

# the RCS thrusters' names, bit by bit of the thruster set's disabled_mask
NAMES_RCS = [name for name, *_, role in thesis_layout() if role != "axial"]

SYSTEMS = MISSION_SYSTEMS
# the parameter set each applies: the closed loop on the estimator (the system's own values), on
# the true state (truth feedback), and the thesis' guidance and control (its numbers)
GNC = GNC_SETS
SCENARIOS = tuple(DEFINED_SCENARIOS)
WH = 3600.0
# Thesis figures per scenario. Every scenario: the attitude validation cases the mission's
# detumble and slew are (section 3.3.5-3.3.6) and the section 3.2 burn and lifetime; 420 km also the
# tracking, propellant sizing, power and data budgets (sections 3.3.9, 3.5, 3.6).
# Each published value is taken from where its case is defined: the attitude cases (thesis
# runner), the burn and lifetime (de-orbit study), the sizing (propulsion report).
_ATTITUDE: Dict[str, float] = {"detumble_time_s": thesis.THESIS["detumble_case1"]["duration"],
             "slew_time_s": thesis.THESIS["slew_case1"]["duration"],
             "detumble_propellant_g": thesis.THESIS["detumble_case1"]["propellant"],
             "slew_propellant_g": thesis.THESIS["slew_case1"]["propellant"]}
THESIS = {name: {**_ATTITUDE, "burn_time_min": ref["burn_min"], "burn_propellant_kg": ref["propellant"],
                 "lifetime_with_burn_years": ref["life_burn"]} for name, ref in deorbit_study.THESIS.items()}
# section 3.3.9 (sized for 420 km), 3.5 and 3.6
THESIS[DEFAULT_SCENARIO].update(tracking_propellant_g=propulsion_report.THESIS["tracking_propellant_g"],
                       total_propellant_kg=propulsion_report.THESIS["total_propellant_kg"],
                       soc_after_burn_percent=79.65, energy_used_Wh=2.2, energy_left_Wh=8.6,
                       battery_empty_days_after_burn=14.0, max_storage_MB=0.1, contacts_to_downlink=2)
RECORD = list(MISSION_RECORD)  # components.mission.neighbor


TIMESERIES_FORMATS = ("parquet", "csv")
JUNIT = "requirements.junit.xml"  # --requirements: the verdicts for CI systems
REQUIREMENTS = Path(__file__).with_name("requirements.toml")  # NEIGHBOR's, from the thesis
# The names a requirement's check may read of a mission (summarize's figures; a figure a run did
# not reach is missing there, and the requirement INCONCLUSIVE), with requirement_values' own
SUMMARY_FIGURES = (
    "steps", "wall_time_s", "simulated_years", "reentered", "safe_state", "bias_resets", "fixed_without_sun",
    "thruster_fault_after_deorbit_start_s", "deorbit_start_days", "altitude_at_deorbit_km",
    "attitude_determination_s", "detumble_time_s", "slew_time_s", "burn_time_min", "detumble_propellant_g",
    "slew_propellant_g", "tracking_propellant_g", "axial_off_percent", "burn_pointing_error_deg",
    "burn_thrust_axis_error_deg", "burn_thrust_axis_error_rms_deg", "burn_knowledge_error_deg",
    "burn_knowledge_error_rms_deg", "burn_rate_error_rms_deg_s", "nees_mean", "nees_over_fraction_percent",
    "disturbance_torque_max_Nm", "burn_propellant_kg", "total_propellant_kg", "soc_after_burn_percent",
    "energy_used_Wh", "energy_left_Wh", "battery_empty_days_after_burn", "max_storage_MB", "bytes_lost",
    "contacts_to_downlink", "lifetime_with_burn_years")
SCENARIO_LIMITS = ("tank_kg", "rcs_allowance_kg", "battery_capacity_Wh", "data_storage_limit_MB")
REQUIREMENT_NAMES = SUMMARY_FIGURES + ("rcs_propellant_kg", "stop_time") + SCENARIO_LIMITS


def requirement_values(s):
    """{name: value} a requirement's check reads of a mission summary: its figures (None where
    the run did not reach them), the RCS propellant, the stop time, and the
    scenario's limits (its tank and RCS allowance, section 3.3.9's rule; the cell, 3.5; the
    storage, 3.6), which replace a requirements file's [values] of the same names."""
    a = budgets.allowance(s["scenario"])
    out = {name: s.get(name) for name in SUMMARY_FIGURES}
    total, burn = s.get("total_propellant_kg"), s.get("burn_propellant_kg")
    out["rcs_propellant_kg"] = None if total is None or burn is None else total - burn
    out["stop_time"] = s["simulated_years"] * YEAR
    out.update(tank_kg=a.tank_kg, rcs_allowance_kg=a.rcs_g / 1e3, battery_capacity_Wh=CELL_CAPACITY / WH,
               data_storage_limit_MB=DATA_STORAGE_LIMIT_B / 1e6)
    return out


def _recorded_signal(fn, name):
    """Why a requirement cannot read signal `name` of a mission (None: it can)."""
    if name not in RECORD:
        return f"not one of the mission's {len(RECORD)} recorded signals (components.mission.neighbor.MISSION_RECORD)"
    return None


def _signal_value(r, fn, name):
    return req.signal_statistic(fn, np.asarray(r.data[name], dtype=float).tolist())


def run_mission(scenario=DEFAULT_SCENARIO, orbit="averaged", ssp_dir=DEFAULT_SSP_DIR, out=None, max_years=40.0,
                parameters=None, profile=False, progress=False, parameter_sets=(), gnc=DEFAULT_GNC,
                timeseries="parquet", requirements=None, events=None):
    """Run the mission; returns (summary dict, Result). Writes the results folder if `out`.
    `requirements` (a requirements file or its loaded Requirements, checked before the run):
    each judged on the run, in the summary ("requirements"), report.html and
    requirements.junit.xml. `events`: scenario events (a scenario file or a list of event tables,
    system_ssp.master.events), what they did in the summary ("events").
    `gnc` (GNC) picks the guidance and control parameter set, applied after the scenario's;
    `parameter_sets` (files, names component.variable) apply after it and `parameters`
    ({component.variable: value}) after them. `timeseries`: the recorded signals' format, "parquet"
    (units in the file) or "csv" (units in timeseries.units.json)."""
    if timeseries not in TIMESERIES_FORMATS:
        raise SSPError(f"--timeseries {timeseries!r}: expected one of {', '.join(TIMESERIES_FORMATS)}")
    series = f"timeseries.{timeseries}"
    if orbit not in SYSTEMS:
        raise SSPError(f"unknown orbit model {orbit!r} (expected one of: {', '.join(SYSTEMS)})")
    if scenario not in SCENARIOS:
        raise SSPError(f"unknown scenario {scenario!r} (expected one of: {', '.join(SCENARIOS)})")
    ssp = resolve_system(str(Path(ssp_dir) / f"{SYSTEMS[orbit]}.ssp"))  # built first if it is a missing default
    if not (max_years > 0 and np.isfinite(max_years)):
        raise SSPError(f"--max-years {max_years:g}: must be a positive number of years (the longest the mission "
                       "may run before re-entry)")
    if gnc not in GNC:
        raise SSPError(f"unknown guidance and control set {gnc!r} (expected one of: {', '.join(GNC)})")
    ssv = [PARAMETERS_DIR / f"{scenario_set(SYSTEMS['cowell'], scenario)}.ssv"] + (
        [PARAMETERS_DIR / f"{GNC[gnc]}.ssv"] if GNC[gnc] else [])
    if requirements is not None and not isinstance(requirements, req.Requirements):
        requirements = req.load(requirements)
    if requirements is not None:  # before the run: a name the mission has not is the file's mistake
        req.check_names(requirements, False, REQUIREMENT_NAMES, _recorded_signal)
    with staged_results(out, lambda err: series) as staged:
        with System(ssp) as system:
            r = system.run(stop_time=max_years * YEAR, parameter_sets=[*map(str, ssv), *parameter_sets],
                           parameters=parameters or {},
                           outputs=RECORD, profile=profile, progress=progress, events=events)
        s = summarize(r, scenario, orbit, gnc)
        s["gnc"] = gnc
        if r.events:
            s["events"] = r.events
        if requirements is not None:
            s["requirements"] = req.summary(requirements, req.judge_run(
                requirements, requirement_values(s), lambda fn, name: _signal_value(r, fn, name)), False)
        if staged is not None:
            if requirements is not None:
                write_text_atomic(staged.path / JUNIT, req.junit(s["requirements"], f"mission {scenario} {gnc}"))
            write_result(r.data, staged.path / series, r.units)
            settings = {"scenario": scenario, "orbit": orbit, "gnc": gnc, "system": ssp.name,
                        "parameter sets": ", ".join(map(str, [*ssv, *parameter_sets])),
                        "parameters": ", ".join(f"{k}={v}" for k, v in (parameters or {}).items()) or "-"}
            write_text_atomic(staged.path / "report.html", report_html(r, s, settings))
            write_text_atomic(staged.path / "summary.json", json.dumps(s, indent=1))
            plot(r.data, s, staged.path)
            staged.commit()
    return s, r



def report_html(r, s, settings):
    """report.html of a mission: the summary beside the thesis (rows 10 % or more away shaded), the
    whole mission and the de-orbit maneuver as interactive figures with their modes and phases
    shaded, the settings and versions; one file that opens without network access."""
    data = r.data
    columns = {n: data[n] for n in data.dtype.names}
    t = data["time"]
    modes = {int(m): m.name.lower() for m in MissionMode}
    phases = {int(p): p.name.lower().replace("_", " ") for p in DeorbitPhase}
    whole = ["orbit.altitude", "orbit.perigee_altitude", "power.state_of_charge", "data.storage_used",
             "propulsion.propellant_used"]
    sections = [("Requirements", req.html(s["requirements"]))] if s.get("requirements") else []
    if s.get("events"):
        sections.append(("Events", report.table(("time (s)", "event", "action", "description"), [
            (f"{e['t']:g}", e["event"], e["action"], e["description"]) for e in s["events"]])))
    sections += [("Summary", report.markdown(table(s), far_beyond=10.0)),
                ("The mission", report.figure(
                    columns, r.units, [n for n in whole if n in columns],
                    bands=report.bands(t, data["mission.mode"], modes, (t[-1] - t[0]) / 300)))]
    deorbit = np.flatnonzero(data["mission.mode"] == MissionMode.DEORBIT)
    if deorbit.size:
        window = slice(deorbit[0], deorbit[-1] + 2)
        part = {n: col[window] for n, col in columns.items()}
        maneuver = [*(n for n in columns if n.startswith("dynamics.omega_BN_B")), "tracking.pointing_error",
                    "thrusters.propellant_mass", "propulsion.propellant_used"]
        sections.append(("The de-orbit maneuver", report.figure(
            part, r.units, [n for n in maneuver if n in part],
            bands=report.bands(part["time"], part["mission.phase"], phases))))
    sections += [("Settings", report.table(("setting", "value"), list(settings.items()))),
                 ("Versions", report.table(("software", "version"), list(report.versions().items())))]
    return report.page(f"NEIGHBOR mission, {s.get('scenario')} scenario", sections)


def _first(mask):
    idx = np.flatnonzero(mask)
    return int(idx[0]) if idx.size else None


def _altitude_at(d, i, orbit):
    """a - R_eq at row i (km) and what kind of a it is. The averaged orbit's a is a mean element;
    Cowell's is osculating (a 15-20 km band at 420 km), so there the mean over the orbit before
    row i is taken when the record holds it (at least 20 rows in the last period)."""
    a = d["orbit.sma"]
    if orbit == "averaged":
        return float(a[i] - R_EQ) / 1e3, "mean"
    t = d["time"]
    period = 2.0 * np.pi * np.sqrt(float(a[i]) ** 3 / MU_EARTH)
    window = (t > t[i] - period) & (t <= t[i])
    if np.count_nonzero(window) >= 20:
        return float(np.mean(a[window]) - R_EQ) / 1e3, "mean over the last orbit"
    return float(a[i] - R_EQ) / 1e3, "osculating"


def _x_axis_in_n(d, q, rows):
    """The body x axis in N on `rows` (a mask) from the recorded quaternion `q` (q_BN, scalar last):
    the first row of A(q), which maps N to B."""
    q1, q2, q3, q4 = (np.asarray(d[f"{q}[{i}]"])[rows] for i in (1, 2, 3, 4))
    x = np.array([q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4, 2.0 * (q1 * q2 + q3 * q4), 2.0 * (q1 * q3 - q2 * q4)])
    return x / np.linalg.norm(x, axis=0)


def _x_axis_angle(d, q_a, q_b, rows):
    """Angle (rad) between the body x axes of two recorded attitudes on `rows`."""
    cos = np.sum(_x_axis_in_n(d, q_a, rows) * _x_axis_in_n(d, q_b, rows), axis=0)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def summarize(r, scenario, orbit, gnc=DEFAULT_GNC):
    d = r.data
    t = d["time"]
    mode, phase = d["mission.mode"], d["mission.phase"]
    s = {"scenario": scenario, "orbit": orbit, "stop_reason": r.stop_reason, "steps": r.steps,
         "wall_time_s": r.wall_time, "simulated_years": r.stop_time / YEAR, "modes": r.modes,
         "reentered": bool(r.final["orbit.reentered"])}
    if r.profile:
        s["profile_s"] = r.profile
    timeouts = {"detumble": int(d["mission.detumble_timeouts"][-1]), "slew": int(d["mission.slew_timeouts"][-1])}
    s["phase_timeouts"] = timeouts
    safe = int(d["mission.safe_reason"][-1])
    s["safe_state"] = bool(safe)  # the de-orbit abandoned without a valid attitude
    then = "the safe state (no valid attitude)" if safe else "the mission went on with the next phase"
    faults = [f"the {name} timed out {n} time(s): retried, then {then}" for name, n in timeouts.items() if n]
    if int(d["mission.determination_timeouts"][-1]):
        faults.insert(0, "the attitude determination timed out without a valid attitude: the detumble started "
                         "anyway (it needs rates only)")
    s["fixed_without_sun"] = bool(d["estimator.fixed_without_sun"][-1])
    if s["fixed_without_sun"]:
        began, fixed = _first(mode == MissionMode.DEORBIT), _first(d["estimator.initialized"] > 0)
        when = "" if began is None or fixed is None else f" {float(t[fixed] - t[began]):.0f} s after the de-orbit began"
        faults.insert(0, "no Sun vector from any Sun sensor: the first attitude fix from the horizon sensor's and "
                         f"the gyro's history{when}, flown on without the Sun (valid at a wider sigma)")
    resets = int(d["estimator.bias_resets"][-1])
    s["bias_resets"] = resets
    if resets:
        faults.append(f"the estimator's innovations contradicted it {resets} time(s) (a gyro bias jump): the bias "
                      "was reopened and learned again")
    disabled = int(d["thrusters.disabled_mask"][-1])
    s["thrusters_disabled"] = [NAMES_RCS[i] for i in range(len(NAMES_RCS)) if disabled >> i & 1]
    if disabled:
        declared = float(d["thrusters.fault_time"][-1])
        began = _first(mode == MissionMode.DEORBIT)
        after = None if began is None else declared - float(t[began])
        s["thruster_fault_after_deorbit_start_s"] = after
        when = "" if after is None else f" {after:.1f} s after the de-orbit began"
        faults.append(f"a stuck thruster declared from the rate response{when}: the valve of "
                      f"{' and '.join(s['thrusters_disabled'])} closed, its axis taken by the others")
    if safe:
        faults.append("no valid attitude for the slew or the burn: the de-orbit was abandoned for the safe state "
                      "(monitoring: no thrust, the position beaconed in ground contacts)")
    s["fault_management"] = "; ".join(faults) or "none needed"
    if safe:
        s["error"] = "the de-orbit was abandoned for the safe state: no valid attitude (no Sun sensor left?)"
        return s

    def phase_start(p):
        i = _first((mode == MissionMode.DEORBIT) & (phase == p))
        return None if i is None else (i, float(t[i]))

    i_deorbit = _first(mode == MissionMode.DEORBIT)
    i_mon = _first(mode == MissionMode.MONITORING)
    if i_deorbit is None or i_mon is None:
        where = ("it never started" if i_deorbit is None else
                 f"it was in phase {DeorbitPhase(int(phase[-1])).name.lower()} when the run ended"
                 if int(mode[-1]) == MissionMode.DEORBIT else f"the mission ended in mode "
                 f"{MissionMode(int(mode[-1])).name.lower()}")
        s["error"] = f"the de-orbit did not complete (no monitoring mode reached): {where}"
        return s
    t0 = float(t[i_deorbit])
    starts = {p: phase_start(p) for p in DeorbitPhase if p != DeorbitPhase.NONE}
    t_mon = float(t[i_mon])
    s["deorbit_start_days"] = t0 / DAY
    s["altitude_at_deorbit_km"], s["altitude_at_deorbit_kind"] = _altitude_at(d, i_deorbit, orbit)
    s["attitude_determination_s"] = starts[DeorbitPhase.DETUMBLE][1] - starts[DeorbitPhase.ATTITUDE_DETERMINATION][1]
    s["detumble_time_s"] = starts[DeorbitPhase.SLEW][1] - starts[DeorbitPhase.DETUMBLE][1]
    s["slew_time_s"] = starts[DeorbitPhase.BURN][1] - starts[DeorbitPhase.SLEW][1]
    s["burn_time_min"] = (t_mon - starts[DeorbitPhase.BURN][1]) / 60.0
    rcs = d["thrusters.propellant_mass"]
    s["detumble_propellant_g"] = 1e3 * float(rcs[starts[DeorbitPhase.SLEW][0]] - rcs[starts[DeorbitPhase.DETUMBLE][0]])
    s["slew_propellant_g"] = 1e3 * float(rcs[starts[DeorbitPhase.BURN][0]] - rcs[starts[DeorbitPhase.SLEW][0]])
    s["tracking_propellant_g"] = 1e3 * float(rcs[i_mon] - rcs[starts[DeorbitPhase.BURN][0]])
    # y and z torques in the burn from switching axial thrusters off: the share of their thrust given up
    off = float(d["thrusters.axial_off_time"][i_mon])
    s["axial_off_percent"] = 100.0 * off / (SPACECRAFT.n_deorbit_thrusters * 60.0 * s["burn_time_min"])
    # the thrust axis against the tracked burn attitude, after the first 10 s of the burn (the
    # tracking's own transient from the slew's end state)
    burning = (t >= starts[DeorbitPhase.BURN][1] + 10.0) & (t < t_mon)
    pointing = np.degrees(d["tracking.pointing_error"][burning])
    s["burn_pointing_error_deg"] = float(pointing.max()) if pointing.size else None
    # the true thrust axis (the rigid body's x) against the burn guidance's (x along -v): what the
    # burn gets, knowledge error included; the thesis set thrusts along -v whatever the attitude
    if gnc != "thesis":
        axis = np.degrees(_x_axis_angle(d, "dynamics.q_BN", "guidance.q_target_BN", burning))
        s["burn_thrust_axis_error_deg"] = float(axis.max()) if axis.size else None
        s["burn_thrust_axis_error_rms_deg"] = float(np.sqrt(np.mean(axis ** 2))) if axis.size else None
    # attitude knowledge: the estimator against the rigid body (zero with truth feedback)
    knowledge = np.degrees(d["estimator.attitude_error"][burning])
    s["burn_knowledge_error_deg"] = float(knowledge.max()) if knowledge.size else None
    s["burn_knowledge_error_rms_deg"] = float(np.sqrt(np.mean(knowledge ** 2))) if knowledge.size else None
    s["burn_rate_error_rms_deg_s"] = float(np.degrees(np.sqrt(np.mean(d["estimator.rate_error"][burning] ** 2)))) \
        if knowledge.size else None
    # the estimator's consistency against the truth, over every step since its first fix (none
    # with truth feedback): mean NEES 3 and 5 % of the steps above the 95 % bound when consistent
    nees_mean, nees_over = float(r.final["estimator.nees_mean"]), float(r.final["estimator.nees_over_fraction"])
    ran = nees_mean > 0.0
    s["nees_mean"] = nees_mean if ran else None
    s["nees_over_fraction_percent"] = 100.0 * nees_over if ran else None
    # the environment's torque on the stack from the takeover to the end of the burn (0: switched off)
    maneuver = (t >= t0) & (t <= t_mon)
    torque = np.linalg.norm(np.column_stack([d[f"disturbances.torque_B[{i}]"][maneuver] for i in (1, 2, 3)]), axis=1)
    s["disturbance_torque_max_Nm"] = float(torque.max()) if torque.size else 0.0
    s["burn_propellant_kg"] = float(d["propulsion.propellant_used"][i_mon])
    s["total_propellant_kg"] = s["burn_propellant_kg"] + float(rcs[i_mon])
    soc, energy = d["power.state_of_charge"], d["power.energy"]
    s["soc_after_burn_percent"] = 100.0 * float(soc[i_mon])
    s["energy_used_Wh"] = float(energy[0] - energy[i_mon]) / WH
    s["energy_left_Wh"] = float(energy[i_mon]) / WH
    i_empty = _first((t > t_mon) & (soc <= 0.0))
    s["battery_empty_days_after_burn"] = None if i_empty is None else (float(t[i_empty]) - t_mon) / DAY
    store = d["data.storage_used"]
    s["max_storage_MB"] = float(store.max()) / 1e6
    s["bytes_lost"] = float(d["data.bytes_lost"][-1])
    # contacts after the burn until the store is empty: rising edges of ground.visible
    vis = d["ground.visible"].astype(bool)
    after = t >= t_mon
    rises = np.flatnonzero(after[1:] & vis[1:] & ~vis[:-1]) + 1
    i_clear = _first(after & (store <= 0.5))
    s["contacts_to_downlink"] = None if i_clear is None else int(np.sum(rises <= i_clear))
    s["lifetime_with_burn_years"] = (r.stop_time - starts[DeorbitPhase.BURN][1]) / YEAR if s["reentered"] else None
    s["thesis"] = THESIS.get(scenario, {})  # a scenario the thesis did not publish: no column
    s["propulsion"] = propulsion_report.of_mission(s)
    s["allowance"] = budgets.allowance(scenario).describe()
    s["budgets"] = [b.as_dict() for b in budgets.of_summary(s)]
    return s


def table(s):
    """The summary beside the thesis' values (every scenario: what the thesis publishes for it),
    with the relative difference, then the propulsion budget of the run's propellant."""
    kind = s.get("altitude_at_deorbit_kind", "mean")
    rows = [("de-orbit starts (days after deployment)", "deorbit_start_days", "{:.2f}"),
            (f"altitude at de-orbit start (km, a - R_eq, {kind})", "altitude_at_deorbit_km", "{:.1f}"),
            ("attitude determination (s)", "attitude_determination_s", "{:.1f}"),
            ("detumble time (s)", "detumble_time_s", "{:.2f}"),
            ("slew time (s)", "slew_time_s", "{:.2f}"),
            ("burn time (min)", "burn_time_min", "{:.2f}"),
            ("burn propellant (kg)", "burn_propellant_kg", "{:.4f}"),
            ("detumble propellant (g)", "detumble_propellant_g", "{:.3f}"),
            ("slew propellant (g)", "slew_propellant_g", "{:.3f}"),
            ("tracking propellant during the burn (g)", "tracking_propellant_g", "{:.3f}"),
            ("axial thrust given up to off-pulsing for y/z torques in the burn (%)", "axial_off_percent", "{:.2f}"),
            ("largest thrust-axis pointing error in the burn (deg, after 10 s; the tracking law's, on its estimate)",
             "burn_pointing_error_deg", "{:.3f}"),
            ("true thrust axis against the guidance's in the burn, largest (deg, after 10 s)",
             "burn_thrust_axis_error_deg", "{:.3f}"),
            ("true thrust axis against the guidance's in the burn, RMS (deg)", "burn_thrust_axis_error_rms_deg",
             "{:.3f}"),
            ("attitude-knowledge error in the burn, RMS (deg, estimator vs truth; 0: truth feedback)",
             "burn_knowledge_error_rms_deg", "{:.3f}"),
            ("attitude-knowledge error in the burn, largest (deg, after 10 s)", "burn_knowledge_error_deg", "{:.3f}"),
            ("estimator consistency: mean attitude NEES since the first fix (3 when consistent)", "nees_mean",
             "{:.2f}"),
            ("estimator consistency: steps with the NEES above its 95 % bound (%; 5 when consistent)",
             "nees_over_fraction_percent", "{:.1f}"),
            ("largest disturbance torque in the de-orbit maneuver (N.m; gravity gradient, drag, solar pressure, "
             "residual dipole; 0: off)", "disturbance_torque_max_Nm", "{:.3g}"),
            ("total propellant (kg; thesis: sized for the worst-case slew)", "total_propellant_kg", "{:.4f}"),
            ("battery after the de-orbit maneuver (%)", "soc_after_burn_percent", "{:.2f}"),
            ("energy used to the end of the burn (Wh)", "energy_used_Wh", "{:.3f}"),
            ("energy left after the burn (Wh)", "energy_left_Wh", "{:.3f}"),
            ("battery empty after the burn (days)", "battery_empty_days_after_burn", "{:.2f}"),
            ("largest data storage (MB; thesis: below)", "max_storage_MB", "{:.4f}"),
            ("contacts after the burn to downlink", "contacts_to_downlink", "{}"),
            ("re-entry after the burn (years)", "lifetime_with_burn_years", "{:.2f}")]
    thesis = dict(s.get("thesis", {}))
    thesis.setdefault("attitude_determination_s", 600.0)  # section 3.4: ten minutes
    lines = [f"NEIGHBOR mission, {s.get('scenario')} scenario ({s.get('orbit')} orbit, "
             f"{s.get('gnc', 'closed-loop')} guidance and control)",
             "| quantity | this run | thesis | difference |", "|---|---|---|---|"]
    for label, key, fmt in rows:
        value, ref = s.get(key), thesis.get(key)
        ours = "-" if value is None else fmt.format(value)
        diff = "-" if value is None or not ref else f"{100.0 * (value - ref) / ref:+.1f} %"
        lines.append(f"| {label} | {ours} | {'-' if ref is None else ref} | {diff} |")
    lines.append(f"\nfault management: {s.get('fault_management', '-')}")
    if s.get("budgets"):
        lines += ["", *budgets.lines(s["budgets"], f"budgets, {s.get('scenario')} scenario:"), s.get("allowance", "")]
    if "propulsion" in s:
        lines.append("\npropulsion budget for this run's propellant "
                     "(`neighbor-cosim propulsion` sizes the worst case):")
        p = s["propulsion"]
        shown = ("delta_v_m_s", "total_propellant_kg", "volume_cm3", "inner_radius_cm", "shell_mass_g", "assembly_g")
        lines += [f"  {label}: {fmt.format(p[key])}" for key, label, fmt in propulsion_report.ROWS if key in shown]
    return "\n".join(lines) + "\n"


def _envelope(ax, x, y, color, label, max_points=600, **kw):
    """Plot y(x); a series longer than max_points is drawn as its min/max envelope per bin
    with the bin mean, so a 15 ms limit cycle over 40 min reads as a band, not a solid block."""
    if x.size <= max_points:
        ax.plot(x, y, color=color, label=label, **kw)
        return
    edges = np.linspace(0, x.size, max_points + 1).astype(int)
    xs = x[edges[:-1]]
    lo = np.minimum.reduceat(y, edges[:-1])
    hi = np.maximum.reduceat(y, edges[:-1])
    mean = np.add.reduceat(y, edges[:-1]) / np.diff(edges)
    ax.fill_between(xs, lo, hi, color=color, alpha=0.25, linewidth=0)
    ax.plot(xs, mean, color=color, label=f"{label} (bin mean; band: min-max)", **kw)


def _phase_spans(ax, t_hours, mode, phase):
    """Shade the de-orbit phases and mark the mode changes on a time axis in hours."""
    colors = {DeorbitPhase.ATTITUDE_DETERMINATION: "tab:purple", DeorbitPhase.DETUMBLE: "tab:orange",
              DeorbitPhase.SLEW: "tab:olive", DeorbitPhase.BURN: "tab:red"}
    for p, color in colors.items():
        sel = np.flatnonzero((mode == MissionMode.DEORBIT) & (phase == p))
        if sel.size:
            ax.axvspan(t_hours[sel[0]], t_hours[min(sel[-1] + 1, t_hours.size - 1)], color=color, alpha=0.3,
                       linewidth=0, label=p.name.lower().replace("_", " "))
    changes = np.flatnonzero(np.diff(mode) != 0) + 1
    for i in changes:
        ax.axvline(t_hours[i], color="0.4", linewidth=0.6, linestyle="--")
        ax.annotate(MissionMode(int(mode[i])).name.lower(), (t_hours[i], 1.0), xycoords=("data", "axes fraction"),
                    rotation=90, va="top", ha="right", fontsize=7, color="0.3")


def _contacts(ax, t_hours, visible, label=True):
    ax.fill_between(t_hours, 0, 1, where=visible.astype(bool), step="post", transform=ax.get_xaxis_transform(),
                    color="tab:green", alpha=0.15, linewidth=0, label="ground contact" if label else None)


def plot(d, s, out):
    """The mission's figures (see the module docstring); long series are enveloped, angles are
    the continuous Eq. 31 angles, phases and contacts are marked, short events get a zoom."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = d["time"]
    mode, phase = d["mission.mode"], d["mission.phase"]

    def save(fig, name):
        fig.tight_layout()
        with atomic_write(out / name, "wb") as f:
            fig.savefig(f, dpi=110, format="png")
        plt.close(fig)

    def legend(ax, **kw):
        ax.legend(fontsize=7, framealpha=0.85, **({"loc": "best"} | kw))

    fig, ax = plt.subplots(figsize=(8, 4.5))
    kind = "mean elements" if s["orbit"] == "averaged" else "osculating"
    ax.plot(t / YEAR, (d["orbit.sma"] - R_EQ) / 1e3, label=f"a - R_eq ({kind})")
    ax.plot(t / YEAR, d["orbit.perigee_altitude"] / 1e3, linewidth=0.8, label="perigee altitude")
    if "deorbit_start_days" in s:
        ax.axvline(s["deorbit_start_days"] * DAY / YEAR, color="k", linestyle="--", linewidth=1, label="de-orbit")
    ax.axhline(250.0, color="k", linestyle=":", linewidth=1, label="re-entry, 250 km")
    ax.set_xlabel("years since deployment")
    ax.set_ylabel("altitude (km)")
    ax.set_title(f"NEIGHBOR mission, {s['scenario']} scenario ({s['orbit']} orbit), cf. thesis Fig. 11")
    legend(ax, loc="lower left")
    ax.grid(alpha=0.3)
    save(fig, "altitude.png")

    for name, p, title in (("detumble.png", DeorbitPhase.DETUMBLE, "Detumble (cf. Fig. 20-22)"),
                           ("slew.png", DeorbitPhase.SLEW, "Slew to the burn attitude (cf. Fig. 27-29)"),
                           ("tracking.png", DeorbitPhase.BURN, "Burn-attitude tracking (cf. Fig. 43-44)")):
        sel = (mode == MissionMode.DEORBIT) & (phase == p)
        if not sel.any():
            continue
        tt = t[sel] - t[sel][0]
        burn = p == DeorbitPhase.BURN
        fig, axes = plt.subplots(3 if burn else 2, 1, figsize=(8, 8 if burn else 6), sharex=True)
        for i, color in zip((1, 2, 3), ("tab:blue", "tab:orange", "tab:green")):
            _envelope(axes[0], tt, np.degrees(d[f"dynamics.omega_BN_B[{i}]"][sel]), color, f"omega_{'xyz'[i - 1]}")
        axes[0].set_ylabel("body rate (deg/s)")
        if p == DeorbitPhase.SLEW:
            for i in (1, 2, 3, 4):
                axes[1].plot(tt, d[f"dynamics.q_BN[{i}]"][sel], label=f"q{i}")
            axes[1].set_ylabel("quaternion q_BN (-)")
        else:
            # Eq. 31's angles (rates integrated) from the phase start: continuous, as the thesis plots
            for i, color in zip((1, 2, 3), ("tab:blue", "tab:orange", "tab:green")):
                e = d[f"dynamics.euler_integrated[{i}]"][sel]
                _envelope(axes[1], tt, np.degrees(e - e[0]), color, ("phi", "theta", "psi")[i - 1])
            axes[1].set_ylabel("angle turned, Eq. 31 (deg)")
        if burn:
            err = np.degrees(d["tracking.attitude_error"][sel])
            _envelope(axes[2], tt, err, "k", "angle from the desired attitude (the law's, on its attitude input)",
                      linewidth=0.8)
            axes[2].set_ylabel("tracking error (deg)")
            settled = err[tt >= 10.0]
            if settled.size and err.max() > 3.0 * settled.max() > 0.0:
                # the first seconds (the slew's end state, the first target) would flatten the rest
                axes[2].set_ylim(0.0, 1.5 * settled.max())
                axes[2].annotate(f"first 10 s: up to {err.max():.1f} deg (off the scale)", (0.02, 0.9),
                                 xycoords="axes fraction", fontsize=8)
        axes[-1].set_xlabel("time in phase (s)")
        for a in axes:  # inside the axes: outside, the legends took two thirds of the width
            legend(a, ncol=3 if len(a.get_legend_handles_labels()[1]) > 2 else 1)
            a.grid(alpha=0.3)
        axes[0].set_title(title)
        save(fig, name)

    _plot_estimation(plt, d, s, save, legend)

    # battery and data from the end of the grace period to a few days after the burn
    i3 = _first(mode >= MissionMode.AWAITING)
    if i3 is not None:
        t_end = (s.get("deorbit_start_days", 0) * DAY) + 3 * DAY
        sel = (t >= t[i3] - 3600.0) & (t <= t_end)
        th = (t[sel] - t[i3]) / 3600.0
        m, ph, vis = mode[sel], phase[sel], d["ground.visible"][sel]
        store = d["data.storage_used"][sel] / 1e6
        # the zoom: from just before the de-orbit until the stored data is downlinked
        i_deorbit = np.flatnonzero(m == MissionMode.DEORBIT)
        i_mon = np.flatnonzero(m == MissionMode.MONITORING)
        window = None
        if i_deorbit.size:
            after = np.flatnonzero((np.arange(m.size) > (i_mon[0] if i_mon.size else i_deorbit[-1]))
                                   & (store <= 0.5e-6))
            t_end_zoom = th[after[0]] if after.size else th[i_deorbit[-1]]
            window = (th[i_deorbit[0]] - 0.5, t_end_zoom + 0.5)
        for name, y, ylabel, title in (
                ("battery.png", 100.0 * d["power.state_of_charge"][sel], "battery state of charge (%)",
                 "Battery through the final contact, de-orbit and first contacts (cf. Fig. 46)"),
                ("data.png", store, "data stored (MB)", "Data storage and downlink (cf. Fig. 47)")):
            fig, (ax, zoom) = plt.subplots(2, 1, figsize=(10, 7))
            for a, first in ((ax, True), (zoom, False)):
                a.plot(th, y, color="k" if name == "battery.png" else "tab:blue",
                       label=("state of charge" if name == "battery.png" else "storage used") if first else None)
                _contacts(a, th, vis, first)
                a.set_ylabel(ylabel)
                a.set_xlabel("hours since the end of the grace period")
                a.grid(alpha=0.3)
            ax.set_title(title, fontsize=10)
            legend(ax)
            if window is not None:
                _phase_spans(zoom, th, m, ph)
                zoom.set_xlim(*window)
                zoom.set_title("zoom: final contact, de-orbit phases (shaded) and the downlink", fontsize=9)
                legend(zoom)
            save(fig, name)


def _plot_estimation(plt, d, s, save, legend):
    """estimation.png: the estimator's attitude error against its own 3-sigma (the whole de-orbit,
    then the first minutes after the fix with the phases marked) and its rate error; skipped
    with truth feedback."""
    t, mode, phase = d["time"], d["mission.mode"], d["mission.phase"]
    sel = (mode == MissionMode.DEORBIT) & (d["estimator.initialized"] > 0)
    if not sel.any() or not np.any(d["estimator.attitude_error"][sel] > 0.0):
        return
    t0 = t[_first(mode == MissionMode.DEORBIT)]
    tm = (t[sel] - t0) / 60.0
    err = np.degrees(d["estimator.attitude_error"][sel])
    # the error is an angle about any axis: compare it with the covariance's root-sum-square, not one axis
    sigma3 = 3.0 * np.degrees(np.sqrt(np.sum([d[f"estimator.sigma_attitude[{i}]"][sel] ** 2 for i in (1, 2, 3)],
                                             axis=0)))
    fig, axes = plt.subplots(3, 1, figsize=(9, 9))
    zoom = (tm - tm[0]) * 60.0 <= 180.0
    for ax, x, keep in ((axes[0], tm, slice(None)), (axes[1], (tm - tm[0]) * 60.0, zoom)):
        ax.semilogy(x[keep], err[keep], color="k", linewidth=0.6, label="attitude error (estimate vs truth)")
        ax.semilogy(x[keep], sigma3[keep], color="tab:red", linewidth=0.9,
                    label="3 sigma, root-sum-square of the axes (filter covariance)")
        ax.set_ylabel("attitude knowledge (deg)")
    axes[0].set_xlabel("minutes since the de-orbit start (from the first attitude fix)")
    axes[1].set_xlabel("seconds since the first attitude fix")
    phases = ((DeorbitPhase.DETUMBLE, "detumble"), (DeorbitPhase.SLEW, "slew"), (DeorbitPhase.BURN, "burn"))
    for k, (p, name) in enumerate(phases):
        i = _first(phase[sel] == p)
        if i is not None and zoom[i]:
            x = (tm[i] - tm[0]) * 60.0
            axes[1].axvline(x, color="0.4", linestyle="--", linewidth=0.8)
            # one height per label: the phases can start seconds apart
            axes[1].annotate(f"{name} starts", (x, 0.97 - 0.1 * k), xycoords=("data", "axes fraction"),
                             xytext=(3, 0), textcoords="offset points", fontsize=8, va="top")
    axes[2].semilogy(tm, np.degrees(np.maximum(d["estimator.rate_error"][sel], 1e-9)), color="tab:blue",
                     linewidth=0.6, label="|rate estimate - truth|")
    axes[2].set_ylabel("rate knowledge (deg/s)")
    axes[2].set_xlabel("minutes since the de-orbit start")
    for a in axes:
        legend(a, loc="lower right")
        a.grid(alpha=0.3, which="both")
    axes[0].set_title("Attitude estimator (TRIAD start, MEKF on the gyro with nadir and Sun vectors)")
    save(fig, "estimation.png")


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim mission", description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", choices=SCENARIOS, default=DEFAULT_SCENARIO,
                    help="the thesis' de-orbit case (default: %(default)s)")
    ap.add_argument("--orbit", choices=list(SYSTEMS), default="averaged",
                    help="orbit fidelity: averaged (years in seconds; default) or cowell (the full orbit)")
    ap.add_argument("--gnc", choices=list(GNC), default=DEFAULT_GNC,
                    help="guidance and control: closed-loop (burn attitude from the orbit, thrust along the body "
                         "axis, flight settle criteria, controllers on the attitude estimator; default), "
                         "closed-loop-truth (the same on the true state) or thesis (the thesis' laws on the true "
                         "state, and its numbers)")
    ap.add_argument("--out", default="results/mission", help="results folder (default: %(default)s)")
    ap.add_argument("--ssp-dir", default=str(DEFAULT_SSP_DIR), help="folder of the built systems")
    ap.add_argument("--max-years", type=positive_float, default=40.0,
                    help="the longest the mission may run before re-entry (default: %(default)s years)")
    ap.add_argument("--profile", action="store_true", help="print the wall time per component")
    ap.add_argument("--timeseries", choices=TIMESERIES_FORMATS, default="parquet",
                    help="format of the recorded signals: parquet (default; units in the file; "
                         "`neighbor-cosim plot` reads it) or csv (units in timeseries.units.json)")
    ap.add_argument("--ssv", action="append", default=[], metavar="FILE",
                    help="extra parameter set after the scenario's, names component.variable (repeatable)")
    ap.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE",
                    help="override a parameter or start value, after every parameter set (repeatable)")
    ap.add_argument("--events", metavar="FILE", help="a scenario file (TOML [[event]] tables): values set and "
                    "outputs faulted during the mission (docs/master.md, Scenario events)")
    ap.add_argument("--requirements", metavar="FILE", nargs="?", const=str(REQUIREMENTS),
                    help="a requirements file (TOML; without FILE NEIGHBOR's, system_ssp/neighbor/requirements.toml): "
                    "each check judged PASS/FAIL/INCONCLUSIVE/ERROR on the run, printed, in summary.json, "
                    f"report.html and {JUNIT}; exit 1 unless all pass")
    add_console_arguments(ap)
    args = ap.parse_args(argv)
    progress = console_settings(args)
    requirements = req.load(args.requirements) if args.requirements else None
    s, r = run_mission(args.scenario, args.orbit, args.ssp_dir, args.out, args.max_years,
                       parameters=parse_sets(args.set), profile=args.profile, progress=progress,
                       parameter_sets=args.ssv, gnc=args.gnc, timeseries=args.timeseries, requirements=requirements,
                       events=args.events)
    print(table(s), end="")
    print(f"{r.steps} steps, {s['simulated_years']:.2f} simulated years, {r.wall_time:.1f} s wall; {r.stop_reason}")
    if r.profile:
        print(profile_table(r.profile))
    if requirements is not None:
        print(req.table(s["requirements"]))
    print(f"results in {args.out}")
    if "error" in s:
        print(f"mission incomplete: {s['error']} within --max-years {args.max_years:g}", file=sys.stderr)
        return 1
    if requirements is not None and not s["requirements"]["all_passed"]:
        c = s["requirements"]["counts"]
        print("requirements not met: " + ", ".join(f"{c[v]} {v}" for v in req.VERDICTS[1:] if c[v]), file=sys.stderr)
        return 1
    return 0


PROPELLANT_KEYS = {"burn_propellant_kg": 1.0, "detumble_propellant_g": 1e-3, "slew_propellant_g": 1e-3,
                   "tracking_propellant_g": 1e-3}  # key: kg per unit


def read_mission_summary(path: Path, scenario: str) -> dict:
    """A mission's summary.json, checked: a JSON object of `scenario`, its propellant numbers
    finite, >= 0 and below the spacecraft's mass (SSPError naming the file and key otherwise)."""
    text = read_text_input(path, f"--mission {path}", "the mission summary",
                           "expected the summary.json of a mission run")
    try:
        summary = json.loads(text)
    except ValueError as err:
        raise SSPError(f"--mission {path}: not JSON ({err}): expected the summary.json of a mission run") from None
    if not isinstance(summary, dict):
        raise SSPError(f"--mission {path}: holds a JSON {type(summary).__name__}, expected an object (the "
                       "summary.json of a mission run)")
    if summary.get("scenario") != scenario:
        raise SSPError(f"--mission {path} is a {summary.get('scenario')!r} mission run, not --scenario {scenario}")
    missing = [key for key in PROPELLANT_KEYS if summary.get(key) is None]
    if missing:
        why = str(summary.get("error", "an incomplete run"))[:200]
        raise SSPError(f"--mission {path}: has no {', '.join(missing)} ({why})")
    for key, kg in PROPELLANT_KEYS.items():
        value = summary[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value * kg <= SPACECRAFT.mass:
            raise SSPError(f"--mission {path}: {key} = {value!r}: expected a number from 0 to "
                           f"{SPACECRAFT.mass / kg:g} (the spacecraft's mass)")
    return summary


def main_propulsion(argv=None):
    """`neighbor-cosim propulsion` (system_ssp.neighbor.propulsion_report): the budget of the worst
    case and of a mission run, read from --mission or run here."""
    ap = ArgumentParser(prog="neighbor-cosim propulsion",
                                 description=propulsion_report.__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", choices=SCENARIOS, default=DEFAULT_SCENARIO,
                    help="the thesis' de-orbit case (default: %(default)s)")
    ap.add_argument("--mission", metavar="SUMMARY_JSON",
                    help="summary.json of a mission run of the scenario (default: run the mission now)")
    ap.add_argument("--gnc", choices=list(GNC), default="thesis",
                    help="guidance and control of the mission run here (default: thesis, whose numbers the "
                         "thesis' sizing used)")
    ap.add_argument("--ssp-dir", default=str(DEFAULT_SSP_DIR),
                    help="folder of the built systems (default: %(default)s)")
    ap.add_argument("--json", metavar="FILE", help="also write both budgets as JSON")
    add_console_arguments(ap)
    args = ap.parse_args(argv)
    progress = console_settings(args)
    if args.json:
        check_output_place(args.json, "--json", (".json",))
    if args.mission:
        summary = read_mission_summary(Path(args.mission), args.scenario)
    else:
        summary, _ = run_mission(args.scenario, ssp_dir=args.ssp_dir, progress=progress, gnc=args.gnc)
    budget = propulsion_report.of_mission(summary)
    worst, _ = propulsion_report.worst_case(summary, args.ssp_dir)
    limits = {"worst_case": [b.as_dict() for b in budgets.propellant_budgets(worst, args.scenario)],
              "mission": [b.as_dict() for b in budgets.propellant_budgets(budget, args.scenario)]}
    print(propulsion_report.report(worst, budget, args.scenario))
    print(budgets.allowance(args.scenario).describe())
    for label, rows in (("worst case", limits["worst_case"]), ("this mission", limits["mission"])):
        print("\n".join(["", *budgets.lines(rows, f"budgets, {label}:")]))
    print()
    print(budgets.mass_volume_report(worst, budget, args.scenario), end="")
    if args.json:
        write_text_atomic(Path(args.json), json.dumps(
            {"scenario": args.scenario, "worst_case": worst, "mission": budget, "thesis": propulsion_report.THESIS,
             "allowance": budgets.allowance(args.scenario).describe(), "budgets": limits,
             "mass_g": {"worst_case": budgets.mass_table(worst), "mission": budgets.mass_table(budget),
                        "thesis": budgets.mass_table()},
             "volume_cm3": {"worst_case": budgets.volume_table(worst), "mission": budgets.volume_table(budget),
                            "thesis": budgets.volume_table()}}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
