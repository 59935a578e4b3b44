"""Write the NEIGHBOR mission system (.ssd) and its parameter files (.ssv).

    python build_fmus.py && python system_ssp/systems/generate_mission.py

`neighbor_mission` is the product's headline system: one co-simulation from deployment to
re-entry. Components (instance: FMU):
  host: HostSpacecraft (heartbeat)          mission: MissionManager (modes, component power states)
  orbit: Orbit (Cowell, Jacchia-Roberts)    ground: GroundStation (UIUC visibility, confirmation)
  propulsion: Propulsion (de-orbit burn)    dynamics: RigidBody (thesis Euler StateChange)
  detumble / slew / tracking: the three RCS attitude controllers (only the enabled one commands)
  guidance: BurnGuidance (burn attitude and rate from the orbit) -> slew and tracking targets
  selector: TorqueSelector -> thrusters: RcsThrusterSet (the 16 thrusters one by one) -> dynamics;
  the RCS propellant comes out of the propulsion's tank (propulsion.rcs_propellant lowers the mass);
  the rigid body's inertia and the thrusters' centre of mass follow the propellant drawn, and the
  thrusters' force beyond the propulsion's nominal thrust (RCS net force, axial misalignment and
  force error) reaches the orbit as a running total of impulse (closed loop; off in the thesis set)
  power: Power (LG HG2 cell, Table 5 loads)   data: DataStorage (256 kB flash, 9600 baud)
  attitude knowledge (section 3.3.1): sun: SunEphemeris, shadow: EarthShadow, gps: GpsReceiver,
  horizon: HorizonSensor, sun_sensor: SunSensor (the fine one, +x, 60 deg), coarse_sun: SunSensor
  (the coarse sensors on the faces, whole sky), gyro: Gyro -> estimator: AttitudeEstimator (TRIAD,
  then MEKF and the rate filter) -> the three controllers' q_BN, omega_BN_B (and the detumble's
  omega_dot); estimator.attitude_valid ends the attitude determination (mission.attitude_valid)
`neighbor_mission_lifetime` is the same system with orbit = OrbitAveraged (the fidelity swap).

Mode-dependent steps (nc:Schedule, first match wins), events landed exactly on
mission.next_event_time and host.next_event_time:
  detumble, slew, burn   mode 5, phases 2, 3, 4: 15 ms, the attitude loop with the phase's own
                 controller (the other two suspended); orbit, ground, host, power and data every
                 33rd step (0.495 s), in the burn also the manager and the propulsion
  determination  mode 5, phase 1 (at least 10 min of attitude determination, until the estimate is
                 valid): 0.1 s with the tumbling rigid body, the sensors and the estimator (the bus
                 every 10th step); with truth feedback 1 s, no attitude loop (the thesis' timer)
  contact        mode 4 (final-confirmation contact): 1 s
  awaiting       mode 3: 5 s while ground.near_contact, else 240 s (no contact can begin sooner)
  monitoring     mode 6 (GPS beacon during contacts): 10 s while ground.near_contact, else 240 s;
                 without host and propulsion
  decay          mode 7 (battery empty: only the orbit left until re-entry): 1 day
  idle           modes 1-2 (idle, grace period): 6 h, only host, mission, power and orbit
Each maneuver mode comes twice: with truth feedback (estimator.truth_feedback, a parameter the
nc:When tests) without the sensors, and with estimation, the gyro every step, the vector sensors
every 6th (0.09 s, the estimator's update interval: each sample is used the step it is taken) and
the ephemeris, shadow and GPS every 33rd. With
truth feedback the attitude loop (dynamics, controllers, thrusters) is suspended until the
detumble starts, so the host's tumble at takeover is the rigid body's initial state at the
detumble (10 deg/s per axis, Eq. 7); with estimation the host tumbles on, torque-free, through
the determination.

Scenarios (one .ssv each, names component.variable): the thesis' 420, 475 and 525 km cases.
The de-orbit starts, as in the thesis' lifetime study, on 2023-01-01 from the scenario altitude:
the run begins 1855 days earlier (5 years idle + 30 days grace, Appendix I) with the host
deployed at the altitude from which it decays to the scenario altitude by then (found here with
the orbit-averaged model and the same Jacchia-Roberts atmosphere and space weather), and the
heartbeat lost 5 years after deployment. The burn spends the scenario's Eq. 2-3 propellant.

Guidance, navigation and control come in three sets (components.mission.neighbor.GNC_SETS; the mission picks one after
the scenario's parameter set):
  closed-loop  (the system's own bindings) the orbit thrusts along the body's thrust axis, the
               guidance FMU computes the burn attitude and its rate from the orbit's r and v, the
               slew and the tracking take it as their target; flight settle criteria and an
               impulse-bit rate deadband end the maneuvers off the nominal point; RK4 attitude;
               the controllers fly on the estimator (sensor noise on, seeds in the sensor files).
  closed-loop-truth  (parameters/mission_gnc_truth.ssv) the same on the true state: truth feedback.
  thesis       (parameters/mission_gnc_thesis.ssv) the thesis' numbers: truth feedback (the
               estimator passes the rigid body's state through), thrust along -v
               whatever the attitude (orbit.retrograde, the lower-fidelity option), identity slew
               target, tracking at the Eq. 67 rate of Re + 400 km latched from the attitude at the
               burn start, single-sample stop tests, Euler attitude integration.
"""
import datetime as dt
import math


from components.attitude import rigid_body, thruster_control
from components.environment import atmosphere
from components.orbit import averaged, propulsion
from components.core import time_utils
from components.core.constants import DAY, R_EQ, YEAR
from components.mission.modes import DeorbitPhase as Phase, MissionMode as Mode
from components.mission.neighbor import (DEFAULT_SCENARIO, GNC_SETS, MISSION_SYSTEMS, ORBIT as HOST_ORBIT, ORBIT_FMUS,
                                         SCENARIOS, SPACECRAFT, scenario_set)
from components.mission.power_bus import LOAD_NAMES

from ...ssp.schedule import Schedule, ScheduleMode, When
from ...ssp.writer import vec
from . import attitude_determination as ad

KM = 1000.0
IDLE_DAYS = 1825.0  # 5 years (Appendix I: 1855 days of idle + grace)
GRACE_DAYS = 30.0
DEORBIT_EPOCH = HOST_ORBIT.deorbit_epoch  # the thesis' start date for the de-orbit
MISSION_EPOCH = (time_utils.parse_epoch(DEORBIT_EPOCH)
                 - dt.timedelta(days=IDLE_DAYS + GRACE_DAYS)).strftime("%Y-%m-%dT%H:%M:%SZ")
W0_TAKEOVER = [math.radians(10.0)] * 3  # Eq. 7

# During the 15 ms attitude phases the slow components (orbit, ground station, host, power, data)
# step every 33rd step (0.495 s, about the thesis' 0.5 s burn step), ahead with inputs held.
SLOW_EVERY = 33
# Waiting for a contact: 240 s steps while the station's near_contact is false (a contact cannot
# begin within 448 s of that, components/mission/ground_station.py), 5-10 s steps while it is true.
FAR_STEP = 240.0

# The components, in SSD order: instance -> (FMU, parameter files, schedule roles). The roles
# decide where each is stepped (the nc:Schedule below is derived from them):
#   idle     idle and grace period (6 h steps)          bus      awaiting, contact, determination
#   monitor  monitoring (after the burn)                decay    battery empty, until re-entry
#   slow     every SLOW_EVERY-th step of the 15 ms maneuvers; slow_burn: so in the burn only
#   sense    the attitude knowledge (sense_slow: every SLOW_EVERY-th maneuver step, sense_vector:
#            every SENSOR_EVERY-th), truth: also with truth feedback
#   a phase (detumble, slew, burn): the controller of that maneuver only; every other component
#   steps in all three maneuvers.
# Adding a component to the mission is one row here plus its connections in `system()`.
ORBIT = "orbit fidelity"  # Orbit (Cowell) or OrbitAveraged, per system
COMPONENTS = {
    "host": ("HostSpacecraft", ["mission_host"], {"idle", "bus", "slow"}),
    "mission": ("MissionManager", ["mission_manager"], {"idle", "bus", "monitor", "decay", "slow_burn"}),
    "orbit": (ORBIT, ["mission_orbit"], {"idle", "bus", "monitor", "decay", "slow"}),
    "ground": ("GroundStation", ["mission_ground"], {"bus", "monitor", "slow"}),
    "propulsion": ("Propulsion", ["mission_propulsion"], {"bus", "slow_burn"}),
    "dynamics": ("RigidBody", ["mission_takeover", "spacecraft"], set()),
    "guidance": ("BurnGuidance", [], {"slow"}),
    "detumble": ("DetumbleController", ["detumble_gains", "mission_detumble"], {"detumble"}),
    "slew": ("SlewController", ["slew_gains", "mission_slew"], {"slew"}),
    "tracking": ("TrackingController", ["mission_tracking"], {"burn"}),
    "selector": ("TorqueSelector", [], set()),
    "thrusters": ("RcsThrusterSet", ["thrusters", "mission_thrusters"], set()),
    "power": ("Power", ["mission_power"], {"idle", "bus", "monitor", "slow"}),
    "data": ("DataStorage", ["mission_data"], {"bus", "monitor", "slow"}),
    # attitude knowledge: ephemeris, shadow, sensors and the estimator (truth feedback: the estimator only)
    "sun": ("SunEphemeris", ["mission_sun"], {"sense", "sense_slow"}),
    "shadow": ("EarthShadow", [], {"sense", "sense_slow"}),
    "gps": ("GpsReceiver", ["mission_gps"], {"sense", "sense_slow"}),
    "horizon": ("HorizonSensor", ["mission_horizon"], {"sense", "sense_vector"}),
    "sun_sensor": ("SunSensor", ["mission_sun_sensor"], {"sense", "sense_vector"}),
    "coarse_sun": ("SunSensor", ["mission_coarse_sun"], {"sense", "sense_vector"}),
    "gyro": ("Gyro", ["mission_gyro"], {"sense"}),
    "estimator": ("AttitudeEstimator", ["mission_estimator"], {"sense", "truth"}),
}
MANEUVERS = ("detumble", "slew", "burn")
# Gauss-Seidel order. The mission manager decides at a step's start from its inputs there;
# components stepped after it see that decision for the step (the controllers, the burn). Power
# and data integrate the loads and recording over the step, so they step before it and see the
# states held at the step's start; a timed event the manager reaches at the step's end (a
# wake-up) applies from then on, not to the step before. The rest follow the feedthrough edges
# (propulsion -> orbit, orbit -> ground, controllers -> selector -> thrusters -> dynamics).
# The sensors and the estimator come last: they read the rigid body at the step's end, so the
# estimate (or, with truth feedback, the true state) the controllers read at the next step's
# start is the state at that time, as if they read the rigid body itself.
ORDER = ["power", "data", "mission", "host", "propulsion", "orbit", "guidance", "ground", "detumble", "slew",
         "tracking", "selector", "thrusters", "dynamics", "sun", "shadow", "gps", "horizon", "sun_sensor", "coarse_sun",
         "gyro", "estimator"]
# The estimator takes one vector sample per sensor every UPDATE_INTERVAL (0.09 s), each with its
# own noise, and uses a sample the step it arrives or never. In the 15 ms maneuvers the gyro and
# the estimator step every step, the vector sensors (horizon, fine and coarse Sun: "sense_vector")
# every SENSOR_EVERY-th step, i.e. exactly at the estimator's rate: a sensor samples the rigid
# body at the end of the step it is stepped in, the estimator stepping after it uses that sample
# in the same step (its interval has just elapsed), and between two samples the sensor's output
# is held (a refresh for a recorded row recomputes it from the current geometry; the estimator
# drops it, its interval not elapsed). Stepped every 7th step, a rate the interval does not
# divide, the sensors had made the estimator overconfident (held samples used up to 6 steps
# late, 1.5 deg at 17 deg/s; the attitude NEES in the detumble reached 250-700, issue 28). Every
# step cost 26 s of a mission for samples the estimator dropped (issue 27). Determination runs
# at the gyro's 0.1 s, every sample used.
UPDATE_INTERVAL = 0.09
# The estimator's fault detection watches the mean normalized innovation squared over this many
# vector updates (components.sensing.mekf.InnovationMonitor: 1e-6 false alarms per window at 3.64)
FAULT_WINDOW = 100
# Without a valid attitude this long into the determination (an orbit and its 10 minutes: an
# eclipse is over and the Sun seen by then; the nominal fix takes about 25 min) no Sun sensor is
# left: the detumble runs on rates, then the mission manager's safe state.
DETERMINATION_TIMEOUT = 6000.0
MANEUVER_STEP = 0.015
SENSOR_EVERY = round(UPDATE_INTERVAL / MANEUVER_STEP)
assert abs(SENSOR_EVERY * MANEUVER_STEP - UPDATE_INTERVAL) < 1e-12
DETERMINATION_STEP = 0.1
DETERMINATION_EVERY = 10


# Flight tolerances sized from the impulse bit: the rate change of one 15 ms firing (the attitude
# loop's step, the shortest pulse) at the nominal 12 kg, 0.017-0.043 deg/s per axis. They hold for
# any mass down to 8 kg (the bit grows as the mass falls: 1.5x at 8 kg).
MIN_ON_TIME = MANEUVER_STEP
INERTIA = rigid_body.box_inertia(SPACECRAFT.mass, *SPACECRAFT.edges)
BITS = thruster_control.impulse_bit_rates(thruster_control.pair_torques(), [INERTIA[i, i] for i in range(3)],
                                          MIN_ON_TIME)
DETUMBLE_FLIGHT = {**vec("omega_tol", [0.75 * b for b in BITS]), "settle_time": 1.0}
SLEW_FLIGHT = {"target_from_input": True, **vec("omega_tol", [2.0 * b for b in BITS]),
               **vec("rate_deadband", [1.5 * b for b in BITS]), "settle_time": 3.0, "settle_angle": math.radians(1.0)}
# Sensors: the gyro's bias left after a ground calibration (about 0.06 deg/s; the estimator
# learns it); the rate filter's unmodelled acceleration, 2 % of one pair's about the x axis (the
# thruster force and direction errors of the dispersion are of that order).
GYRO_BIAS = [1e-3, -5e-4, 2e-4]
# The thesis' one fine Sun sensor (+x, 60 deg half field) may never see the Sun from a tumbling host
# (with the Eq. 7 tumble at the 420 km epoch it did not in 6 h): coarse sun sensors on the faces
# (as the sunline module's CSS) give a 2 deg Sun vector whenever the fine one has none.
COARSE_SUN_SIGMA = math.radians(2.0)
# The detumble waits (after the 10 minutes of determination) until the estimator's largest
# 1-sigma attitude error is below this: a TRIAD fix right at the end would start it at 1-2 deg.
VALID_SIGMA = math.radians(0.25)
# Without any Sun sensor: the first fix from the horizon sensor's and the gyro's history once it
# spans 20 minutes (a fifth of an orbit: the nadir has turned 78 deg) and the spacecraft has been
# sunlit 5 minutes with no Sun vector; valid at 1 deg 1-sigma, since no Sun vector narrows the
# rotation about the nadir further (a 3 deg thrust axis error costs 0.14 % of the burn's delta-V).
# The fix itself waits for 0.5 deg: with the body's spin axis near the orbit plane (the 475 km
# campaign's run 70) 20 minutes of history leave 1.3 deg per axis (4.5 deg off in one of six noise
# draws), 30 minutes 0.6 deg.
NADIR_HISTORY = {"nadir_history_time": 1200.0, "sun_missing_time": 300.0, "valid_sigma_without_sun": math.radians(1.0),
                 "history_fix_sigma": math.radians(0.5)}
ACCEL_SIGMA = 0.02 * thruster_control.pair_torques()[0] / INERTIA[0, 0]
# The tracking law's boundary layer sized for estimates (deorbit_tracking.boundary_layer): its
# deadband in s at least 3 sigmas of the estimate's noise and one impulse bit; the rate estimate's
# 1-sigma per axis as the rate filter holds it in the burn (0.0106 deg/s RMS over three axes).
TRACKING_LAYER = {"knowledge_sigmas": 3.0, "impulse_bits": 1.0, "rate_sigma": 1e-4, "min_on_time": MIN_ON_TIME}
# What the thesis parameter set restores (names component.variable); every value the closed loop
# changes appears here.
GNC_THESIS = {"estimator.truth_feedback": True, "orbit.retrograde": True, "dynamics.integrator": "euler",
              "tracking.target_from_input": False, "tracking.knowledge_sigmas": 0.0, "tracking.impulse_bits": 0.0,
              "thrusters.off_pulsing": False, "thrusters.fault_detection": False, "estimator.fault_window": 0,
              "estimator.nadir_history_time": 0.0,
              "dynamics.propellant_mass_properties": False, "thrusters.propellant_mass_properties": False,
              "mission.attitude_determination_timeout": 0.0, "mission.safe_without_attitude": False,
              "detumble.settle_time": 0.0, **vec("detumble.omega_tol", [math.radians(0.01)] * 3),
              "slew.target_from_input": False, **vec("slew.omega_tol", [math.radians(0.01)] * 3),
              **vec("slew.rate_deadband", [0.0] * 3), "slew.settle_time": 0.0}


# The spacecraft's physical values, each given once (system parameters of the SSD, in
# parameters/mission_spacecraft.ssv) and handed by parameter connections to every component that
# uses it: `--set spacecraft_mass=14` changes the rigid body, the tracking law's inertia and the
# propulsion's initial mass together.
SPACECRAFT_PARAMETERS = {
    "spacecraft_mass": ("Host spacecraft total mass at takeover, kg (Table 2: 12 kg)", SPACECRAFT.mass,
                        [("dynamics", "mass"), ("tracking", "mass"), ("estimator", "mass"), ("propulsion", "mass0"),
                         ("thrusters", "mass")]),
    "spacecraft_edge_a": ("Box edge a along body y, m (Appendix A: 0.1 m); also the x thruster pairs' spacing",
                          SPACECRAFT.edge_a, [("dynamics", "edge_a"), ("tracking", "edge_a"), ("estimator", "edge_a"),
                                ("thrusters", "edge_a")]),
    "spacecraft_edge_b": ("Box edge b along body z, m (Appendix A: 0.2 m)", SPACECRAFT.edge_b,
                          [("dynamics", "edge_b"), ("tracking", "edge_b"), ("estimator", "edge_b"),
                           ("thrusters", "edge_b")]),
    "spacecraft_edge_c": ("Box edge c along body x, m (Appendix A: 0.3 m); also the y and z thruster pairs' arms",
                          SPACECRAFT.edge_c, [("dynamics", "edge_c"), ("tracking", "edge_c"), ("estimator", "edge_c"),
                                ("thrusters", "edge_c")]),
    "spacecraft_Cd": ("Drag coefficient (Table 2: 2.2)", SPACECRAFT.Cd, [("orbit", "Cd")]),
    "spacecraft_drag_area": ("Drag area facing the flow, m2 (Table 2: 0.02 m2)", SPACECRAFT.drag_area,
                             [("orbit", "area")]),
    "rcs_thrust": ("Force of one RCS thruster, N (Appendix A: 25 mN)", SPACECRAFT.rcs_thrust,
                   [("thrusters", "thrust")]),
}


def having(role):
    """The components with a schedule role, in SSD order."""
    return tuple(c for c, (_, _, roles) in COMPONENTS.items() if role in roles)


def maneuver_active(phase, truth=False):
    """Every component but the other maneuvers' controllers, in Gauss-Seidel order; with truth
    feedback no sensors (the estimator passes the rigid body's state through)."""
    others = {c for c, (_, _, roles) in COMPONENTS.items() if roles & set(MANEUVERS) - {phase}}
    if truth:
        others |= set(having("sense")) - set(having("truth"))
    return tuple(c for c in ORDER if c not in others)


def maneuver_every(phase, truth=False):
    slow = having("slow") + (having("slow_burn") if phase == "burn" else ())
    every = {c: SLOW_EVERY for c in slow}
    if not truth:
        every.update({c: SLOW_EVERY for c in having("sense_slow")})
        every.update({c: SENSOR_EVERY for c in having("sense_vector")})
    return every


def determination_active():
    """Estimation: the bus, the tumbling rigid body, the sensors and the estimator."""
    return tuple(c for c in ORDER if c in set(having("bus")) | set(having("sense")) | {"dynamics"})


def determination_every():
    """In the 0.1 s determination steps the bus (but the manager, whose timers land exactly), the
    ephemeris, the shadow and the GPS step every second."""
    slow = (set(having("bus")) - {"mission"}) | set(having("sense_slow"))
    return {c: DETERMINATION_EVERY for c in determination_active() if c in slow}


def deployment_altitude(target_km, density=HOST_ORBIT.density_model):
    """Mean altitude (km) at MISSION_EPOCH from which the host decays to `target_km` at the
    de-orbit epoch (1855 days later), found by bisection with the orbit-averaged model."""
    model = atmosphere.make_density_model(density, inclination=HOST_ORBIT.inclination)
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


TRUTH = When("estimator", "truth_feedback", (1,))


def in_mode(mode, **also):
    """Conditions: the mission in `mode` and each further output of the manager at its value."""
    return (When("mission", "mode", (mode,)),) + tuple(When("mission", k, (v,)) for k, v in also.items())


def maneuver_modes():
    """The 15 ms attitude phases, each twice: with truth feedback (no sensors) and with estimation."""
    modes = []
    for name, phase in (("detumble", Phase.DETUMBLE), ("slew", Phase.SLEW), ("burn", Phase.BURN)):
        when = in_mode(Mode.DEORBIT, phase=phase)
        modes.append(ScheduleMode(f"{name}_truth", MANEUVER_STEP, maneuver_active(name, truth=True), 20,
                                  when + (TRUTH,), maneuver_every(name, truth=True)))
        modes.append(ScheduleMode(name, MANEUVER_STEP, maneuver_active(name), 20, when, maneuver_every(name)))
    return modes


def system(orbit_fmu):
    comps = [(name, orbit_fmu if fmu == ORBIT else fmu, files) for name, (fmu, files, _) in COMPONENTS.items()]
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
             ("dynamics", "q_BN", "orbit", "q_BN", 4),
             ("orbit", "r_BN_N", "guidance", "r_BN_N", 3),
             ("orbit", "v_BN_N", "guidance", "v_BN_N", 3),
             ("guidance", "q_target_BN", "slew", "q_target_BN", 4),
             ("guidance", "omega_target_B", "slew", "omega_target_B", 3),
             ("guidance", "q_target_BN", "tracking", "q_target_BN", 4),
             ("guidance", "omega_target_B", "tracking", "omega_target_B", 3),
             ("estimator", "omega_est_B", "detumble", "omega_BN_B", 3),
             ("estimator", "omega_dot_est_B", "detumble", "omega_dot_BN_B", 3),
             ("estimator", "q_est_BN", "slew", "q_BN", 4),
             ("estimator", "omega_est_B", "slew", "omega_BN_B", 3),
             ("estimator", "q_est_BN", "tracking", "q_BN", 4),
             ("estimator", "omega_est_B", "tracking", "omega_BN_B", 3),
             ("estimator", "sigma_attitude", "tracking", "sigma_attitude_B", 3),
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
             ("thrusters", "propellant_mass", "propulsion", "rcs_propellant", 0),
             ("propulsion", "burning", "thrusters", "axial_firing", 0),
             ("thrusters", "axial_off_time", "propulsion", "axial_off_time", 0),
             ("thrusters", "torque_B", "dynamics", "torque_B", 3),
             # mass properties that follow the tank, the thrusters' force on the orbit (issue 28)
             ("propulsion", "propellant_used", "dynamics", "propellant_used", 0),
             ("thrusters", "propellant_mass", "dynamics", "rcs_propellant", 0),
             ("propulsion", "propellant_used", "thrusters", "propellant_used", 0),
             ("thrusters", "impulse_B", "orbit", "impulse_B", 3),
             ("mission", "data_recording", "data", "data_recording", 0),
             ("mission", "downlink_enable", "data", "downlink_enable", 0),
             ("ground", "visible", "data", "ground_contact", 0),
             # attitude knowledge
             ("orbit", "r_BN_N", "shadow", "r_BN_N", 3),
             ("sun", "r_SN_N", "shadow", "r_SN_N", 3),
             ("orbit", "r_BN_N", "gps", "r_BN_N", 3),
             ("orbit", "r_BN_N", "horizon", "r_BN_N", 3),
             ("dynamics", "q_BN", "horizon", "q_BN", 4),
             ("sun", "r_SN_N", "sun_sensor", "r_SN_N", 3),
             ("orbit", "r_BN_N", "sun_sensor", "r_BN_N", 3),
             ("dynamics", "q_BN", "sun_sensor", "q_BN", 4),
             ("shadow", "orbit_day", "sun_sensor", "sunlit", 0),
             ("sun", "r_SN_N", "coarse_sun", "r_SN_N", 3),
             ("orbit", "r_BN_N", "coarse_sun", "r_BN_N", 3),
             ("dynamics", "q_BN", "coarse_sun", "q_BN", 4),
             ("shadow", "orbit_day", "coarse_sun", "sunlit", 0),
             ("coarse_sun", "sun_B", "estimator", "coarse_sun_B", 3),
             ("coarse_sun", "valid", "estimator", "coarse_sun_valid", 0),
             ("dynamics", "omega_BN_B", "gyro", "omega_BN_B", 3),
             ("gyro", "omega_meas_B", "thrusters", "omega_meas_B", 3),
             ("horizon", "nadir_B", "estimator", "nadir_B", 3),
             ("horizon", "valid", "estimator", "nadir_valid", 0),
             ("sun_sensor", "sun_B", "estimator", "sun_B", 3),
             ("sun_sensor", "valid", "estimator", "sun_valid", 0),
             ("gyro", "omega_meas_B", "estimator", "omega_meas_B", 3),
             ("gps", "r_meas_N", "estimator", "r_BN_N", 3),
             ("sun", "r_SN_N", "estimator", "r_SN_N", 3),
             ("selector", "torque_cmd_B", "estimator", "torque_cmd_B", 3),
             ("dynamics", "q_BN", "estimator", "q_true_BN", 4),
             ("dynamics", "omega_BN_B", "estimator", "omega_true_B", 3),
             ("dynamics", "omega_dot_BN_B", "estimator", "omega_dot_true_B", 3),
             ("estimator", "attitude_valid", "mission", "attitude_valid", 0)]
    conns += [("mission", name, "power", name, 0) for name in LOAD_NAMES]
    return {
        "description": f"NEIGHBOR mission from deployment to re-entry ({orbit_fmu} orbit): operating modes, "
                       "heartbeat, ground contact, de-orbit attitude control and burn, power, data. Correct at the "
                       "fixed 15 ms step; years of coasting need the mode-dependent steps of the "
                       "org.neighbor-cosim.master annotation (nc:Schedule)",
        "components": comps,
        "connections": conns,
        "parameters": {name: (about, targets) for name, (about, _, targets) in SPACECRAFT_PARAMETERS.items()},
        "parameter_bindings": ["mission_spacecraft"],
        "stop": [("orbit", "reentered")],
        "order": ORDER,
        "stop_time": 40.0 * YEAR,
        # The fixed step a master without our nc:Schedule runs at (and `--no-schedule`): the 15 ms of
        # the attitude loop, which every phase is correct at. The schedule only saves the steps.
        "step_size": MANEUVER_STEP,
        "schedule": Schedule(modes=(
            *maneuver_modes(),
            ScheduleMode("determination_truth", 1.0, having("bus"), 10, in_mode(Mode.DEORBIT) + (TRUTH,)),
            ScheduleMode("determination", DETERMINATION_STEP, determination_active(), 10, in_mode(Mode.DEORBIT),
                         determination_every()),
            ScheduleMode("contact", 1.0, having("bus"), 10, in_mode(Mode.CONTACT)),
            ScheduleMode("awaiting_near", 5.0, having("bus"), 12,
                         in_mode(Mode.AWAITING) + (When("ground", "near_contact", (1,)),)),
            ScheduleMode("awaiting", FAR_STEP, having("bus"), 1, in_mode(Mode.AWAITING)),
            ScheduleMode("monitoring_near", 10.0, having("monitor"), 6,
                         in_mode(Mode.MONITORING) + (When("ground", "near_contact", (1,)),)),
            ScheduleMode("monitoring", FAR_STEP, having("monitor"), 1, in_mode(Mode.MONITORING)),
            ScheduleMode("decay", DAY, having("decay"), 1, in_mode(Mode.END)),
            ScheduleMode("idle", 6 * 3600.0, having("idle"), 4)),
            events=(("mission", "next_event_time"), ("host", "next_event_time"))),
    }


def generate(writer):
    takeover_altitudes = {name: deployment_altitude(s.altitude_km) for name, s in SCENARIOS.items()}
    base = SCENARIOS[DEFAULT_SCENARIO]  # the component-level files start from it
    writer.ssv("mission_host",
               "Host heartbeat: lost 5 years after deployment (Appendix I: 1825 days of idle)",
               {"heartbeat_loss_time": IDLE_DAYS * DAY, "heartbeat_return_times": ""})
    writer.ssv("mission_manager",
               "Operating modes (Section 3.4): 30-day grace period, 5 s daily wake, 10 min attitude determination; "
               "in monitoring one GPS beacon contact a day (operators choose the frequency, Section 3.6); without a "
               "valid attitude after one orbit (no Sun sensor left and no fix from the horizon sensor's history) the "
               "detumble on rates, then the safe state instead of a slew or burn",
               {"grace_period": GRACE_DAYS * DAY, "wake_period": DAY, "wake_duration": 5.0,
               "attitude_determination_duration": 600.0, "beacon_interval": DAY,
                "attitude_determination_timeout": DETERMINATION_TIMEOUT, "safe_without_attitude": True})
    h_base = takeover_altitudes[base.name]
    writer.ssv("mission_orbit",
               f"Host orbit at deployment ({MISSION_EPOCH}, {HOST_ORBIT.inclination_deg:g} deg; {h_base:.2f} km decays "
               f"to {base.altitude_km:g} km by {DEORBIT_EPOCH}), Cd {SPACECRAFT.Cd:g}, {SPACECRAFT.drag_area:g} m^2, "
               "Jacchia-Roberts with the bundled space weather, thrust along the body's thrust axis (q_BN from the "
               "rigid body)",
               {"epoch": MISSION_EPOCH, "sma0": R_EQ + h_base * KM, "ecc0": 0.0, "inc0": HOST_ORBIT.inclination,
               "raan0": 0.0, "argp0": 0.0, "ta0": 0.0, "Cd": SPACECRAFT.Cd, "area": SPACECRAFT.drag_area,
               "reentry_altitude": HOST_ORBIT.reentry_altitude_km * KM, "density_model": HOST_ORBIT.density_model,
               "space_weather_file": "", "use_constant_space_weather": False, "retrograde": False})
    writer.ssv("mission_ground",
               "UIUC ground station (40.1020 N, 88.2272 W), horizon mask (Appendix I sets none)",
               {"epoch": MISSION_EPOCH})
    budget = {name: propulsion.mission_scenario(name)["propellant"] for name in SCENARIOS}
    writer.ssv("mission_propulsion",
               f"Main de-orbit thrusters, {SPACECRAFT.mass:g} kg, the {base.altitude_km:g} km -> "
               f"{base.target_perigee_km:g} km budget (Eq. 2-3: {base.thesis['propellant']:g} kg)",
               {"mass0": SPACECRAFT.mass, "propellant_budget": budget[base.name]})
    writer.ssv("mission_takeover",
               "Host tumble when NEIGHBOR takes over (Eq. 6-7: 10 deg/s per axis), RK4 attitude integration, the "
               "inertia following the propellant drawn from the tank",
               {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", W0_TAKEOVER), "integrator": "rk4",
                "propellant_mass_properties": True})
    writer.ssv("mission_tracking",
               "De-orbit tracking (Appendix F): k 1, G 0.1 I, e 0.001 widened to 3 sigmas of the estimate's noise and "
               "one impulse bit, desired attitude and rate from the burn guidance",
               {"k": 1.0, **vec("G", [0.1] * 3), **vec("e", [0.001] * 3), "q_d_from_measured": True,
                "target_from_input": True, **TRACKING_LAYER})
    writer.ssv("mission_thrusters",
               "In the burn, y and z torques by switching axial thrusters off (off-pulsing): no RCS propellant "
               "for the thrust axis' misalignment torque; a stuck thruster detected from the gyro's rates, its valve "
               "closed and its axis taken by the others; torques about the centre of mass as the tank empties",
               {"off_pulsing": True, "fault_detection": True, "gyro_sigma": ad.GYRO_SIGMA, "gyro_sample_time": ad.STEP,
                "propellant_mass_properties": True})
    writer.ssv("mission_detumble",
               "Detumble flight settle criterion: rate window 0.75 impulse bit per axis held for 1 s", DETUMBLE_FLIGHT)
    writer.ssv("mission_slew",
               "Slew to the burn attitude from the guidance; flight rate deadband 1.5 impulse bits, settle within "
               "1 deg and 2 impulse bits for 3 s", SLEW_FLIGHT)
    writer.ssv("mission_spacecraft",
               "The spacecraft's physical values, each once: system parameters handed to every component that uses "
               "them (the system's parameter connections)",
               {name: value for name, (_, value, _) in SPACECRAFT_PARAMETERS.items()})
    writer.ssv(GNC_SETS["thesis"],
               "The thesis' guidance and control (its published numbers): thrust along -v whatever the attitude, "
               "identity slew target, tracking at the Eq. 67 rate latched at the burn start, single-sample stop "
               "tests, Euler attitude integration", GNC_THESIS)
    writer.ssv("mission_sun", "Sun ephemeris from the mission epoch", {"epoch": MISSION_EPOCH})
    writer.ssv("mission_gps", "GPS receiver (OEM7700): 1.5 m per axis, seed", {"sigma": ad.GPS_SIGMA, "seed": 14})
    writer.ssv("mission_horizon", "Horizon sensor (CubeIR class): 0.25 deg RMS, seed", {"sigma": ad.HORIZON_SIGMA,
                                                                                         "seed": 11})
    writer.ssv("mission_sun_sensor", "Sun sensor (nanoSSOC-D60) on +x: 60 deg half field of view, 0.5 deg 3 sigma, "
               "seed", {**vec("boresight_B", [1.0, 0.0, 0.0]), "half_fov": math.radians(60.0), "sigma": ad.SUN_SIGMA,
                        "seed": 12})
    writer.ssv("mission_coarse_sun", "Coarse sun sensors on the six faces, taken together: the Sun anywhere in the "
               f"sky when sunlit, {math.degrees(COARSE_SUN_SIGMA):g} deg RMS (Earth albedo not modelled), seed",
               {"half_fov": math.pi, "sigma": COARSE_SUN_SIGMA, "seed": 15})
    writer.ssv("mission_gyro", "Gyro (BMG160): 0.032 deg/s per 0.1 s sample (0.014 deg/s/sqrt(Hz)) at any sampling "
               "step, a calibration residual bias of 0.06 deg/s, seed",
               {**vec("bias", GYRO_BIAS), "sigma": ad.GYRO_SIGMA, "sigma_sample_time": ad.STEP, "seed": 13})
    writer.ssv("mission_estimator", "Attitude estimator: the sensors' accuracies, each vector sample used once "
               "(vector sensors at about 10 Hz), rate filter trusting the torque model to 2 % of one pair's "
               "acceleration, coarse Sun vectors when the fine sensor has none, attitude valid at 0.25 deg 1-sigma, "
               "a gyro bias jump detected from the innovations over 100 updates (9 s) and the bias learned again; "
               "with every Sun sensor failed the first fix from 20 minutes of the horizon sensor and the gyro, valid "
               "at 1 deg",
               {"nadir_sigma": ad.HORIZON_SIGMA, "sun_sigma": ad.SUN_SIGMA, "gyro_sigma": ad.GYRO_SIGMA,
                "gyro_sample_time": ad.STEP, "sigma_bias0": 1e-3, "update_interval": UPDATE_INTERVAL,
                "accel_sigma": ACCEL_SIGMA,
                "use_coarse_sun": True, "coarse_sun_sigma": COARSE_SUN_SIGMA, "valid_sigma": VALID_SIGMA,
                "fault_window": FAULT_WINDOW, **NADIR_HISTORY})
    writer.ssv(GNC_SETS["closed-loop-truth"],
               "Closed-loop guidance and control on the true state (a fidelity choice): the estimator passes the "
               "rigid body's attitude, rate and acceleration through; the sensors are not stepped",
               {"estimator.truth_feedback": True})
    writer.ssv("mission_power", "LG HG2 cell: 3.0 Ah x 3.6 V = 10.8 Wh, full",
               {"capacity": 10.8 * 3600.0, "initial_state_of_charge": 1.0})
    writer.ssv("mission_data", "256 kB flash, Table 7 rate, 9600 baud downlink",
               {"capacity": 256e3, "downlink_rate": 1200.0})
    cowell, averaged = MISSION_SYSTEMS["cowell"], MISSION_SYSTEMS["averaged"]
    for name, s in SCENARIOS.items():
        h0, target = s.altitude_km, s.target_perigee_km
        writer.ssv(scenario_set(cowell, name),
                   f"Thesis scenario {h0:g} km -> {target:g} km: deployed at {takeover_altitudes[name]:.2f} km on "
                   f"{MISSION_EPOCH}, at {h0:g} km when the de-orbit starts ({DEORBIT_EPOCH})",
                   {"orbit.sma0": R_EQ + takeover_altitudes[name] * KM,
                   "propulsion.propellant_budget": budget[name]})
    for orbit, name in MISSION_SYSTEMS.items():
        writer.ssd(name, system(ORBIT_FMUS[orbit]))
    for name in SCENARIOS:
        writer.ssv_copy(scenario_set(cowell, name), scenario_set(averaged, name))
