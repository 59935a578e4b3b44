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


from components.attitude import disturbances, rigid_body, thruster_control
from components.environment import atmosphere
from components.orbit import averaged, propulsion
from components.core import time_utils
from components.core.constants import DAY, R_EQ
from components.mission.neighbor import (DEFAULT_SCENARIO, FACETS, GNC_SETS, MISSION_SYSTEMS, ORBIT as HOST_ORBIT,
                                         RESIDUAL_DIPOLE_B, SCENARIOS, SPACECRAFT, scenario_set)

from ...ssp.writer import vec
from . import attitude_determination as ad
from .from_spec import write_system

KM = 1000.0
IDLE_DAYS = 1825.0  # 5 years (Appendix I: 1855 days of idle + grace)
GRACE_DAYS = 30.0
DEORBIT_EPOCH = HOST_ORBIT.deorbit_epoch  # the thesis' start date for the de-orbit
MISSION_EPOCH = (time_utils.parse_epoch(DEORBIT_EPOCH)
                 - dt.timedelta(days=IDLE_DAYS + GRACE_DAYS)).strftime("%Y-%m-%dT%H:%M:%SZ")
W0_TAKEOVER = [math.radians(10.0)] * 3  # Eq. 7

# The system itself (components, connections, order and the nc:Schedule with its reasons) is
# specs/neighbor_mission.toml; what follows are the values of its parameter files.
# The estimator takes one vector sample per sensor every UPDATE_INTERVAL (0.09 s); the spec steps
# the vector sensors every 6th 15 ms step, exactly at that rate (its comments say why).
UPDATE_INTERVAL = 0.09
# The estimator's fault detection watches the mean normalized innovation squared over this many
# vector updates (components.sensing.mekf.InnovationMonitor: 1e-6 false alarms per window at 3.64)
FAULT_WINDOW = 100
# Without a valid attitude this long into the determination (an orbit and its 10 minutes: an
# eclipse is over and the Sun seen by then; the nominal fix takes about 25 min) no Sun sensor is
# left: the detumble runs on rates, then the mission manager's safe state.
DETERMINATION_TIMEOUT = 6000.0
MANEUVER_STEP = 0.015  # the attitude loop's step (specs/neighbor_mission.toml)



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
# The environment's torques, switched off: the thesis set has none (its published numbers), and
# parameters/mission_disturbances_off.ssv flies any other set without them, for comparison.
DISTURBANCES_OFF = {f"disturbances.{source}": False for source in disturbances.SOURCES}
GNC_THESIS = {"estimator.truth_feedback": True, "orbit.retrograde": True, "dynamics.integrator": "euler",
              "tracking.target_from_input": False, "tracking.knowledge_sigmas": 0.0, "tracking.impulse_bits": 0.0,
              "thrusters.off_pulsing": False, "thrusters.fault_detection": False, "estimator.fault_window": 0,
              "estimator.nadir_history_time": 0.0,
              "dynamics.propellant_mass_properties": False, "thrusters.propellant_mass_properties": False,
              "mission.attitude_determination_timeout": 0.0, "mission.safe_without_attitude": False,
              "detumble.settle_time": 0.0, **vec("detumble.omega_tol", [math.radians(0.01)] * 3),
              "slew.target_from_input": False, **vec("slew.omega_tol", [math.radians(0.01)] * 3),
              **vec("slew.rate_deadband", [0.0] * 3), "slew.settle_time": 0.0,
              **DISTURBANCES_OFF}


# The spacecraft's physical values, each given once (system parameters of the SSD, in
# parameters/mission_spacecraft.ssv; the spec's [system_parameters] say which components take
# them): `--set spacecraft_mass=14` changes the rigid body, the tracking law's inertia and the
# propulsion's initial mass together.
SPACECRAFT_VALUES = {"spacecraft_mass": SPACECRAFT.mass, "spacecraft_edge_a": SPACECRAFT.edge_a,
                     "spacecraft_edge_b": SPACECRAFT.edge_b, "spacecraft_edge_c": SPACECRAFT.edge_c,
                     "spacecraft_Cd": SPACECRAFT.Cd, "spacecraft_drag_area": SPACECRAFT.drag_area,
                     "rcs_thrust": SPACECRAFT.rcs_thrust}


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


def facet_values():
    """The DisturbanceTorques parameters of the mission definition's facets and dipole (its unused
    slots at area 0)."""
    values = {source: True for source in disturbances.SOURCES}
    values.update(vec("residual_dipole_B", list(RESIDUAL_DIPOLE_B)))
    for i in range(1, disturbances.MAX_FACETS + 1):
        f = FACETS[i - 1] if i <= len(FACETS) else None
        values[f"facet_area[{i}]"] = f.area if f else 0.0
        for j in range(3):
            values[f"facet_normal_B[{i},{j + 1}]"] = f.normal_B[j] if f else (1.0 if j == 0 else 0.0)
            values[f"facet_centre_B[{i},{j + 1}]"] = f.centre_B[j] if f else 0.0
        values[f"facet_Cd[{i}]"] = f.Cd if f else SPACECRAFT.Cd
        values[f"facet_specular[{i}]"] = f.specular if f else 0.0
        values[f"facet_diffuse[{i}]"] = f.diffuse if f else 0.0
    return values


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
               SPACECRAFT_VALUES)
    writer.ssv(GNC_SETS["thesis"],
               "The thesis' guidance and control (its published numbers): thrust along -v whatever the attitude, "
               "identity slew target, tracking at the Eq. 67 rate latched at the burn start, single-sample stop "
               "tests, Euler attitude integration", GNC_THESIS)
    writer.ssv("mission_sun", "Sun ephemeris from the mission epoch", {"epoch": MISSION_EPOCH})
    writer.ssv("mission_field", "IGRF-14 magnetic field to degree 13 from the mission epoch, secular variation on",
               {"epoch": MISSION_EPOCH, "secular_variation": True, "degree": 13})
    writer.ssv("mission_disturbances",
               f"Disturbance torques of the 6U stack: its {len(FACETS)} outer faces (the host's with body-mounted "
               "cells, the 2U NEIGHBOR module's bare aluminium; components.mission.neighbor.FACETS), Cd "
               f"{SPACECRAFT.Cd:g}, residual dipole {list(RESIDUAL_DIPOLE_B)} A.m2 (assumed), all four sources on",
               facet_values())
    writer.ssv("mission_disturbances_off", "The mission without the environment's torques (the thesis set's "
               "choice), to compare with the default (neighbor-cosim mission, option ssv)", DISTURBANCES_OFF)
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
    for name in MISSION_SYSTEMS.values():
        write_system(writer, name)
    for name in SCENARIOS:
        writer.ssv_copy(scenario_set(cowell, name), scenario_set(averaged, name))
