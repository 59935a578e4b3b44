"""Write the NEIGHBOR mission system (.ssd) and its parameter files (.ssv).

    python build_fmus.py && python system_ssp/systems/generate_mission.py

`neighbor_mission` is the product's headline system: one co-simulation from deployment to
re-entry. Components (instance: FMU):
  host: HostSpacecraft (heartbeat)          mission: MissionManager (modes, component power states)
  orbit: Orbit (Cowell, Jacchia-Roberts)    ground: GroundStation (UIUC visibility, confirmation)
  propulsion: Propulsion (de-orbit burn)    dynamics: RigidBody (thesis Euler StateChange)
  detumble / slew / tracking: the three RCS attitude controllers (only the enabled one commands)
  selector: TorqueSelector -> thrusters: RcsThrusters -> dynamics
  power: Power (LG HG2 cell, Table 5 loads)   data: DataStorage (256 kB flash, 9600 baud)
`neighbor_mission_lifetime` is the same system with orbit = OrbitAveraged (the fidelity swap).

Mode-dependent steps (nc:Schedule, first match wins), events landed exactly on
mission.next_event_time and host.next_event_time:
  detumble, slew, burn   mode 5, phases 2, 3, 4: 15 ms, the attitude loop with the phase's own
                 controller (the other two suspended); orbit, ground, host, power and data every
                 33rd step (0.495 s), in the burn also the manager and the propulsion
  determination  mode 5, phase 1 (10 min of attitude determination): 1 s, no attitude loop
  contact        mode 4 (final-confirmation contact): 1 s
  awaiting       mode 3: 5 s while ground.near_contact, else 240 s (no contact can begin sooner)
  monitoring     mode 6 (GPS beacon during contacts): 10 s while ground.near_contact, else 240 s;
                 without host and propulsion
  decay          mode 7 (battery empty: only the orbit left until re-entry): 1 day
  idle           modes 1-2 (idle, grace period): 6 h, only host, mission, power and orbit
The attitude loop (dynamics, controllers, thrusters) is suspended until the detumble starts, so
the host's tumble at takeover is the rigid body's initial state (10 deg/s per axis, Eq. 7).

Scenarios (one .ssv each, names component.variable): the thesis' 420, 475 and 525 km cases.
The de-orbit starts, as in the thesis' lifetime study, on 2023-01-01 from the scenario altitude:
the run begins 1855 days earlier (5 years idle + 30 days grace, Appendix I) with the host
deployed at the altitude from which it decays to the scenario altitude by then (found here with
the orbit-averaged model and the same Jacchia-Roberts atmosphere and space weather), and the
heartbeat lost 5 years after deployment. The burn spends the scenario's Eq. 2-3 propellant.
The orbit FMU applies the thrust along -v (retrograde): the attitude loop holds the thesis'
burn attitude in its own reference (identity target, tracked at the orbital rate), which is not
tied to the orbit's velocity direction here (documented in the README).
"""
import datetime as dt
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[1]))

from generate import vec, write_ssd, write_ssv  # noqa: E402

from components.environment import atmosphere  # noqa: E402
from components.orbit import averaged, propulsion  # noqa: E402
from components.core import time_utils  # noqa: E402
from components.core.constants import DAY, R_EQ, YEAR  # noqa: E402
from components.mission.modes import DeorbitPhase as Phase, MissionMode as Mode  # noqa: E402
from components.mission.power_bus import LOAD_NAMES  # noqa: E402

KM = 1000.0
IDLE_DAYS = 1825.0  # 5 years (Appendix I: 1855 days of idle + grace)
GRACE_DAYS = 30.0
DEORBIT_EPOCH = time_utils.DEFAULT_EPOCH  # the thesis' start date for the de-orbit
MISSION_EPOCH = (time_utils.parse_epoch(DEORBIT_EPOCH)
                 - dt.timedelta(days=IDLE_DAYS + GRACE_DAYS)).strftime("%Y-%m-%dT%H:%M:%SZ")
SCENARIOS = {"420km": (420.0, 350.0), "475km": (475.0, 350.0), "525km": (525.0, 300.0)}
W0_TAKEOVER = [math.radians(10.0)] * 3  # Eq. 7

ATTITUDE = ["dynamics", "detumble", "slew", "tracking", "selector", "thrusters"]
BUS = ["host", "mission", "orbit", "ground", "propulsion", "power", "data"]
MONITOR = ["mission", "orbit", "ground", "power", "data"]  # after the burn: no host, no thrust
# During the 15 ms attitude phases the orbit, ground station, host, power and data step every
# 33rd step (0.495 s, about the thesis' 0.5 s burn step), ahead with inputs held.
SLOW_EVERY = 33
# Waiting for a contact: 240 s steps while the station's near_contact is false (a contact cannot
# begin within 448 s of that, components/mission/ground_station.py), 5-10 s steps while it is true.
FAR_STEP = 240.0
SLOW = {c: SLOW_EVERY for c in ("host", "orbit", "ground", "power", "data")}
ALL = ["power", "data", "mission", "host", "propulsion", "orbit", "ground", "detumble", "slew", "tracking", "selector",
       "thrusters", "dynamics"]


def ALL_BUT(*names):
    return [c for c in ALL if c not in names]


def deployment_altitude(target_km, density="jacchia_roberts"):
    """Mean altitude (km) at MISSION_EPOCH from which the host decays to `target_km` at the
    de-orbit epoch (1855 days later), found by bisection with the orbit-averaged model."""
    model = atmosphere.make_density_model(density, inclination=math.radians(51.6))
    span = (IDLE_DAYS + GRACE_DAYS) * DAY

    def end_altitude(h0_km):
        orb = averaged.OrbitAveraged(model, epoch=MISSION_EPOCH, sma0=R_EQ + h0_km * KM)
        orb.advance_to(span)
        return (orb.sma - R_EQ) / KM

    lo, hi = target_km, target_km + 150.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if end_altitude(mid) < target_km:
            lo = mid
        else:
            hi = mid
        if hi - lo < 0.01:
            break
    return 0.5 * (lo + hi)


def system(orbit_fmu):
    comps = [("host", "HostSpacecraft", ["mission_host"]),
             ("mission", "MissionManager", ["mission_manager"]),
             ("orbit", orbit_fmu, ["mission_orbit"]),
             ("ground", "GroundStation", ["mission_ground"]),
             ("propulsion", "Propulsion", ["mission_propulsion"]),
             ("dynamics", "RigidBody", ["mission_takeover", "spacecraft"]),
             ("detumble", "DetumbleController", ["detumble_gains"]),
             ("slew", "SlewController", ["slew_gains"]),
             ("tracking", "TrackingController", ["mission_tracking"]),
             ("selector", "TorqueSelector", []),
             ("thrusters", "RcsThrusters", ["thrusters"]),
             ("power", "Power", ["mission_power"]),
             ("data", "DataStorage", ["mission_data"])]
    conns = [("host", "heartbeat", "mission", "heartbeat", 0),
             ("ground", "visible", "mission", "ground_contact", 0),
             ("ground", "ground_command", "mission", "ground_command", 0),
             ("detumble", "done", "mission", "detumble_done", 0),
             ("slew", "done", "mission", "slew_done", 0),
             ("propulsion", "budget_spent", "mission", "budget_spent", 0),
             ("power", "state_of_charge", "mission", "state_of_charge", 0),
             ("orbit", "reentered", "mission", "reentered", 0),
             ("orbit", "r_BN_N", "ground", "r_BN_N", 3),
             ("mission", "burn_enable", "propulsion", "burn_enable", 0),
             ("propulsion", "F_thrust_B", "orbit", "F_thrust_B", 3),
             ("propulsion", "mass", "orbit", "mass", 0),
             ("dynamics", "omega_BN_B", "detumble", "omega_BN_B", 3),
             ("dynamics", "omega_dot_BN_B", "detumble", "omega_dot_BN_B", 3),
             ("dynamics", "q_BN", "slew", "q_BN", 4),
             ("dynamics", "omega_BN_B", "slew", "omega_BN_B", 3),
             ("dynamics", "q_BN", "tracking", "q_BN", 4),
             ("dynamics", "omega_BN_B", "tracking", "omega_BN_B", 3),
             ("mission", "detumble_enable", "detumble", "enabled", 0),
             ("mission", "slew_enable", "slew", "enabled", 0),
             ("mission", "tracking_enable", "tracking", "enabled", 0),
             ("mission", "detumble_enable", "selector", "detumble_enable", 0),
             ("mission", "slew_enable", "selector", "slew_enable", 0),
             ("mission", "tracking_enable", "selector", "tracking_enable", 0),
             ("detumble", "torque_cmd_B", "selector", "torque_cmd_detumble_B", 3),
             ("slew", "torque_cmd_B", "selector", "torque_cmd_slew_B", 3),
             ("tracking", "torque_cmd_B", "selector", "torque_cmd_tracking_B", 3),
             ("selector", "torque_cmd_B", "thrusters", "torque_cmd_B", 3),
             ("thrusters", "torque_B", "dynamics", "torque_B", 3),
             ("mission", "data_recording", "data", "data_recording", 0),
             ("mission", "downlink_enable", "data", "downlink_enable", 0),
             ("ground", "visible", "data", "ground_contact", 0)]
    conns += [("mission", name, "power", name, 0) for name in LOAD_NAMES]
    quiet = [c for c in BUS if c != "ground" and c != "data" and c != "propulsion"]
    return {
        "description": f"NEIGHBOR mission from deployment to re-entry ({orbit_fmu} orbit): operating modes, "
                       "heartbeat, ground contact, de-orbit attitude control and burn, power, data",
        "components": comps,
        "connections": conns,
        "stop": [("orbit", "reentered")],
        # Gauss-Seidel order. The mission manager decides at a step's start from its inputs
        # there; components stepped after it see that decision for the step (the controllers,
        # the burn). Power and data integrate the loads and recording over the step, so they
        # step before it and see the states held at the step's start; a timed event the manager
        # reaches at the step's end (a wake-up) applies from then on, not to the step before.
        # The rest follow the feedthrough edges (propulsion -> orbit, orbit -> ground,
        # controllers -> selector -> thrusters -> dynamics).
        "order": ALL,
        "stop_time": 40.0 * YEAR,
        "step_size": 3600.0,
        "schedule": {"modes": [
            ("detumble", 0.015, ALL_BUT("slew", "tracking"), 20,
             [("mission", "mode", [Mode.DEORBIT]), ("mission", "phase", [Phase.DETUMBLE])], SLOW),
            ("slew", 0.015, ALL_BUT("detumble", "tracking"), 20,
             [("mission", "mode", [Mode.DEORBIT]), ("mission", "phase", [Phase.SLEW])], SLOW),
            ("burn", 0.015, ALL_BUT("detumble", "slew"), 20,
             [("mission", "mode", [Mode.DEORBIT]), ("mission", "phase", [Phase.BURN])],
             dict(SLOW, mission=SLOW_EVERY, propulsion=SLOW_EVERY)),
            ("determination", 1.0, BUS, 10, [("mission", "mode", [Mode.DEORBIT])]),
            ("contact", 1.0, BUS, 10, [("mission", "mode", [Mode.CONTACT])]),
            ("awaiting_near", 5.0, BUS, 12, [("mission", "mode", [Mode.AWAITING]), ("ground", "near_contact", [1])]),
            ("awaiting", FAR_STEP, BUS, 1, [("mission", "mode", [Mode.AWAITING])]),
            ("monitoring_near", 10.0, MONITOR, 6, [("mission", "mode", [Mode.MONITORING]), ("ground", "near_contact", [1])]),
            ("monitoring", FAR_STEP, MONITOR, 1, [("mission", "mode", [Mode.MONITORING])]),
            ("decay", DAY, ["mission", "orbit"], 1, [("mission", "mode", [Mode.END])]),
            ("idle", 6 * 3600.0, quiet, 4, [])],
            "events": [("mission", "next_event_time"), ("host", "next_event_time")]},
    }


def main():
    params = HERE / "parameters"
    takeover_altitudes = {name: deployment_altitude(h0) for name, (h0, _) in SCENARIOS.items()}
    write_ssv(params / "mission_host.ssv", "mission_host",
              "Host heartbeat: lost 5 years after deployment (Appendix I: 1825 days of idle)",
              {"heartbeat_loss_time": IDLE_DAYS * DAY, "heartbeat_return_times": ""})
    write_ssv(params / "mission_manager.ssv", "mission_manager",
              "Operating modes (Section 3.4): 30-day grace period, 5 s daily wake, 10 min attitude determination; "
              "in monitoring one GPS beacon contact a day (operators choose the frequency, Section 3.6)",
              {"grace_period": GRACE_DAYS * DAY, "wake_period": DAY, "wake_duration": 5.0,
               "attitude_determination_duration": 600.0, "beacon_interval": DAY})
    h420 = takeover_altitudes["420km"]
    write_ssv(params / "mission_orbit.ssv", "mission_orbit",
              f"Host orbit at deployment ({MISSION_EPOCH}, 51.6 deg; {h420:.2f} km decays to 420 km by "
              f"{DEORBIT_EPOCH}), Cd 2.2, 0.02 m^2, Jacchia-Roberts with the bundled space weather, retrograde burn",
              {"epoch": MISSION_EPOCH, "sma0": R_EQ + h420 * KM, "ecc0": 0.0, "inc0": math.radians(51.6),
               "raan0": 0.0, "argp0": 0.0, "ta0": 0.0, "Cd": 2.2, "area": 0.02, "reentry_altitude": 250.0 * KM,
               "density_model": "jacchia_roberts", "space_weather_file": "", "use_constant_space_weather": False,
               "retrograde": True})
    write_ssv(params / "mission_ground.ssv", "mission_ground",
              "UIUC ground station (40.1020 N, 88.2272 W), horizon mask (Appendix I sets none)",
              {"epoch": MISSION_EPOCH})
    budget = {name: propulsion.deorbit_scenario(h0 * KM, target * KM)["propellant"]
              for name, (h0, target) in SCENARIOS.items()}
    write_ssv(params / "mission_propulsion.ssv", "mission_propulsion",
              "Main de-orbit thrusters, 12 kg, the 420 km -> 350 km budget (Eq. 2-3: 0.564 kg)",
              {"mass0": propulsion.MASS0, "propellant_budget": budget["420km"]})
    write_ssv(params / "mission_takeover.ssv", "mission_takeover",
              "Host tumble when NEIGHBOR takes over (Eq. 6-7: 10 deg/s per axis), thesis Euler integration",
              {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", W0_TAKEOVER), "integrator": "euler"})
    write_ssv(params / "mission_tracking.ssv", "mission_tracking",
              "De-orbit tracking (Appendix F): k 1, G 0.1 I, e 0.001, desired attitude from the measured one at "
              "the start of the burn", {"k": 1.0, **vec("G", [0.1] * 3), **vec("e", [0.001] * 3),
                                        "q_d_from_measured": True})
    write_ssv(params / "mission_power.ssv", "mission_power", "LG HG2 cell: 3.0 Ah x 3.6 V = 10.8 Wh, full",
              {"capacity": 10.8 * 3600.0, "initial_state_of_charge": 1.0})
    write_ssv(params / "mission_data.ssv", "mission_data", "256 kB flash, Table 7 rate, 9600 baud downlink",
              {"capacity": 256e3, "downlink_rate": 1200.0})
    for name, (h0, target) in SCENARIOS.items():
        write_ssv(params / f"neighbor_mission_{name}.ssv", f"neighbor_mission_{name}",
                  f"Thesis scenario {h0:g} km -> {target:g} km: deployed at {takeover_altitudes[name]:.2f} km on "
                  f"{MISSION_EPOCH}, at {h0:g} km when the de-orbit starts ({DEORBIT_EPOCH})",
                  {"orbit.sma0": R_EQ + takeover_altitudes[name] * KM,
                   "propulsion.propellant_budget": budget[name]})
    write_ssd("neighbor_mission", system("Orbit"))
    write_ssd("neighbor_mission_lifetime", system("OrbitAveraged"))
    for name in SCENARIOS:
        src = params / f"neighbor_mission_{name}.ssv"
        (params / f"neighbor_mission_lifetime_{name}.ssv").write_text(src.read_text())
    print("deployment altitudes:", {k: round(v, 2) for k, v in takeover_altitudes.items()})
    print(f"wrote neighbor_mission.ssd, neighbor_mission_lifetime.ssd and their parameter sets in {HERE}")


if __name__ == "__main__":
    main()
