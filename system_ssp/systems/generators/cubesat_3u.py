"""Write the 3U CubeSat's pointing system (cubesat_3u_pointing.ssd) and its parameter files from the
second mission definition (components.mission.cubesat_3u).

System: four reaction wheels in a pyramid (`wheels`, ReactionWheelArray) on the rigid body
(`dynamics`), flown by the pointing guidance (`guidance`, PointingGuidance: inertial by default),
Schaub's MRP feedback law (`control`, MrpFeedback) and the minimum-norm wheel torque distribution
(`distribution`, WheelTorqueDistribution), in a circular 500 km Sun-synchronous orbit (`orbit`).
The truth attitude feeds the guidance (no sensors yet). Step 0.1 s (the wheels' 1 mN.m moves the
body 1.4 deg/s per 100 s; the loop settles in ~20 s), stop 300 s.

Gauss-Seidel order: guidance, control, distribution, dynamics, wheels, orbit. The laws act on the
state at t; the rigid body then flies [t, t + h] with the wheels' torque and momentum at t (as it
holds them: components.attitude.rigid_body); the wheels step last, after the body. That is
Basilisk's order of the same chain (tests/components/acs/test_wheels_vs_basilisk.py), and with
the wheels before the body the body would take their momentum at t + h.

Parameter files:
- cubesat_3u_spacecraft.ssv      dynamics: the body's inertia, the spacecraft's without the
  wheels' spin-axis inertia (components.acs.reaction_wheel_array.body_inertia), rk4 at one
  sub-step per step;
- cubesat_3u_initial_state.ssv   dynamics: 1.6 deg/s tumble 144 deg from the reference;
- cubesat_3u_wheels.ssv          wheels and distribution: count, spin axes, inertia, limits, speeds;
- cubesat_3u_control.ssv         control: K, P and the spacecraft's inertia (wheels included);
- cubesat_3u_guidance.ssv        guidance: the inertial reference sigma_R0N;
- cubesat_3u_orbit.ssv           orbit: 500 km, 97.4 deg;
- cubesat_3u_pointing_nadir.ssv           scenario: nadir pointing (guidance.mode = 1) with body -z to
  nadir (the offset sigma_R0R turns the Hill frame's -x onto -z).
"""
import math

from components.acs import reaction_wheel_array as rwa
from components.attitude import disturbances
from components.core.names import matrix_names
from components.mission import cubesat_3u as mission
from components.mission import solar_arrays

from ...ssp.writer import vec
from .from_spec import write_system

SLOTS = rwa.MAX_WHEELS
WHEEL_AXES = rwa.pyramid_axes(mission.WHEELS.elevation, mission.WHEELS.count, mission.WHEELS.azimuth0)


def _matrix(name, M):
    return {element: float(M[i][j]) for i, row in enumerate(matrix_names(name, 3, 3)) for j, element in enumerate(row)}


def _axes():
    axes = WHEEL_AXES + rwa.default_axes()[mission.WHEELS.count:]
    return {element: float(axes[i][j]) for i, row in enumerate(matrix_names("spin_axis_B", SLOTS, 3))
            for j, element in enumerate(row)}


def _per_wheel(name, value):
    values = list(value) if isinstance(value, (tuple, list)) else [value] * mission.WHEELS.count
    return vec(name, values + [0.0 if name == "Omega0" else values[-1]] * (SLOTS - len(values)))


def body_inertia():
    w = mission.WHEELS
    return rwa.body_inertia(mission.SPACECRAFT.inertia_B, WHEEL_AXES, [w.J_s] * w.count)


SPACECRAFT = {"mass": mission.SPACECRAFT.mass, "inertia_from_box": False, **_matrix("inertia_B", body_inertia()),
              "integrator": "rk4", "max_substep": mission.POINTING.step}
INITIAL = {**vec("q0", list(mission.INITIAL_ATTITUDE)), **vec("omega0", list(mission.INITIAL_RATE)),
           "euler0_from_q0": True}
WHEELS = {"wheel_count": mission.WHEELS.count, **_axes(), **_per_wheel("J_s", mission.WHEELS.J_s),
          **_per_wheel("max_torque", mission.WHEELS.max_torque), **_per_wheel("max_speed", mission.WHEELS.max_speed),
          **_per_wheel("Omega0", mission.WHEELS.speed0)}
DISTRIBUTION = {"wheel_count": mission.WHEELS.count, **_axes()}
CONTROL = {"K": mission.POINTING.K, "P": mission.POINTING.P, "mass": mission.SPACECRAFT.mass,
           "inertia_from_box": False, **_matrix("inertia_B", mission.SPACECRAFT.inertia_B)}
GUIDANCE = vec("sigma_R0N", list(mission.POINTING.sigma_R0N))
# the Hill frame's x is the zenith: R = R0 turned +90 deg about its y has its z on R0's x, so the
# body's +z is on the zenith and -z at nadir (sigma_R0R, the MRP of R0 relative to R, is -90 deg about y)
NADIR = {"guidance.mode": 1, **vec("guidance.sigma_R0R", [0.0, -math.tan(math.radians(90.0) / 4.0), 0.0])}


# ---- the detumble and the day ---------------------------------------------------------------
COILS = vec("max_dipole", [mission.COILS.max_dipole] * 3)
BDOT = {"gain": mission.COILS.detumble_gain, "use_field_difference": True}
# the detumble flies the whole spacecraft (wheels at rest and not modelled: their spin inertia is
# the body's), rk4 at 0.5 s sub-steps (10 deg/s turns 5 deg per sub-step)
DETUMBLE_SPACECRAFT = {"mass": mission.SPACECRAFT.mass, "inertia_from_box": False,
                       **_matrix("inertia_B", mission.SPACECRAFT.inertia_B), "integrator": "rk4", "max_substep": 0.5}
TUMBLE = {**vec("q0", list(mission.INITIAL_ATTITUDE)), **vec("omega0", list(mission.DETUMBLE_RATE)),
          "euler0_from_q0": True}
DAY_SPACECRAFT = {**SPACECRAFT, "max_substep": mission.DAY.step}
DAY_GAINS = {"K": mission.DAY.K, "P": mission.DAY.P}
NADIR_GUIDANCE = {name.split(".", 1)[1]: value for name, value in NADIR.items()}
DUMPING = {**_per_wheel("J_s", mission.WHEELS.J_s), "gain": mission.COILS.dumping_gain, **COILS}
WHEEL_POWER = {**_per_wheel("base_power", mission.POWER.wheel_base_power),
               "motor_efficiency": mission.POWER.wheel_motor_efficiency}
BATTERY = {"capacity": mission.POWER.capacity, "initial_state_of_charge": mission.POWER.initial_state_of_charge,
           "base_load": mission.POWER.base_load}


# ---- the first day: detumble, Sun-safe, nadir on the estimator ----------------------------------
# rk4 at 0.5 s sub-steps of the 1 s step (10 deg/s turns 5 deg per sub-step), the wheels at rest
MISSION_SPACECRAFT = {**SPACECRAFT, "max_substep": 0.5}
WHEELS_AT_REST = _per_wheel("Omega0", 0.0)
GYRO = {**vec("bias", list(mission.SENSORS.gyro_bias)), "sigma": mission.SENSORS.gyro_sigma, "seed": 11}
HORIZON = {"sigma": mission.SENSORS.horizon_sigma, "seed": 12}
COARSE_SUN = {"seed": 13}
ESTIMATOR = {"nadir_sigma": mission.SENSORS.horizon_sigma, "gyro_sigma": mission.SENSORS.gyro_sigma,
             "gyro_sample_time": mission.DAY.step, "use_coarse_sun": True,
             "coarse_sun_sigma": mission.SENSORS.coarse_sun_sigma, "valid_sigma": mission.SENSORS.attitude_valid_sigma,
             "mass": mission.SPACECRAFT.mass, "inertia_from_box": False,
             **_matrix("inertia_B", mission.SPACECRAFT.inertia_B)}
MODES = {"detumble_exit_rate": mission.MODES.detumble_exit_rate,
         "detumble_entry_rate": mission.MODES.detumble_entry_rate,
         "sun_safe_exit_angle": mission.MODES.sun_safe_exit_angle, "hold_time": mission.MODES.hold_time,
         **vec("sun_axis_B", list(mission.MODES.sun_axis_B)), "pointing_mode": 1}
# the guidance's parameters there: its mode is the mode sequence's output
GUIDANCE_MODES = {**vec("sun_axis_B", list(mission.MODES.sun_axis_B)),
                  **{name: value for name, value in NADIR_GUIDANCE.items() if name != "mode"}}


def disturbance_values():
    """DisturbanceTorques' parameters: the 3U's facets, residual dipole and inertia (unused facet
    slots at area 0)."""
    values = {source: True for source in disturbances.SOURCES}
    values.update({"mass": mission.SPACECRAFT.mass, "inertia_from_box": False,
                   **_matrix("inertia_B", mission.SPACECRAFT.inertia_B)})
    values.update(vec("residual_dipole_B", list(mission.RESIDUAL_DIPOLE_B)))
    for i in range(1, disturbances.MAX_FACETS + 1):
        f = mission.FACETS[i - 1] if i <= len(mission.FACETS) else None
        values[f"facet_area[{i}]"] = f.area if f else 0.0
        for j in range(3):
            values[f"facet_normal_B[{i},{j + 1}]"] = f.normal_B[j] if f else (1.0 if j == 0 else 0.0)
            values[f"facet_centre_B[{i},{j + 1}]"] = f.centre_B[j] if f else 0.0
        values[f"facet_specular[{i}]"] = f.specular if f else 0.0
        values[f"facet_diffuse[{i}]"] = f.diffuse if f else 0.0
    return values


def solar_array_values():
    """SolarArrays' parameters: the facets that carry cells (unused slots at area 0)."""
    panels = [f for f in mission.FACETS if f.cell_area > 0.0]
    n = solar_arrays.MAX_PANELS
    values = {"panel_count": len(panels)}
    for i in range(1, n + 1):
        f = panels[i - 1] if i <= len(panels) else None
        for j in range(3):
            values[f"normal_B[{i},{j + 1}]"] = f.normal_B[j] if f else (1.0 if j == 0 else 0.0)
        values[f"area[{i}]"] = f.cell_area if f else 0.0
        values[f"efficiency[{i}]"] = f.cell_efficiency if f else 0.0
    return values


def generate(writer):
    writer.ssv("cubesat_3u_spacecraft", "3U body without the wheels' spin-axis inertia (kg.m2), rk4 at one "
               "sub-step per 0.1 s step", SPACECRAFT)
    writer.ssv("cubesat_3u_initial_state", "1.6 deg/s tumble, 144 deg from the inertial reference", INITIAL)
    writer.ssv("cubesat_3u_wheels", "Four 10 mN.m.s wheels in a pyramid about +z (35.26 deg), 1 mN.m, 6000 rpm",
               WHEELS)
    writer.ssv("cubesat_3u_distribution", "The four pyramid wheels' spin axes", DISTRIBUTION)
    writer.ssv("cubesat_3u_control", "MRP feedback gains and the 3U's inertia (wheels included)", CONTROL)
    writer.ssv("cubesat_3u_guidance", "Inertial reference attitude (MRP)", GUIDANCE)
    writer.ssv("cubesat_3u_orbit", "Circular orbit 500 km, 97.4 deg (SI units)", dict(mission.ORBIT))
    writer.ssv("cubesat_3u_pointing_nadir", "Scenario: nadir pointing with body -z to nadir", NADIR)
    write_system(writer, "cubesat_3u_pointing")
    writer.ssv("cubesat_3u_coils", "Three 0.2 A.m2 torque rods on the body axes", COILS)
    writer.ssv("cubesat_3u_bdot", "Three-axis B-dot from the magnetometer alone (field difference)", BDOT)
    writer.ssv("cubesat_3u_detumble_spacecraft", "The whole 3U's inertia (kg.m2), rk4 at 0.5 s sub-steps",
               DETUMBLE_SPACECRAFT)
    writer.ssv("cubesat_3u_tumble", "10 deg/s after the deployer", TUMBLE)
    write_system(writer, "cubesat_3u_detumble")
    writer.ssv("cubesat_3u_sunline", "The Sun heading from the quaternion attitude", {"attitude_input": "quaternion"})
    writer.ssv("cubesat_3u_disturbances", "The 3U's facets, residual dipole and inertia", disturbance_values())
    writer.ssv("cubesat_3u_nadir", "Nadir pointing with body -z to nadir", NADIR_GUIDANCE)
    writer.ssv("cubesat_3u_day_gains", "MRP gains at 1 Hz", DAY_GAINS)
    writer.ssv("cubesat_3u_dumping", "Momentum dumping through the rods: gain, rods, wheel inertias", DUMPING)
    writer.ssv("cubesat_3u_wheel_power", "The wheels' electronics and motor efficiency", WHEEL_POWER)
    writer.ssv("cubesat_3u_day_spacecraft", "3U body without the wheels' spin-axis inertia (kg.m2), rk4 at one "
               "sub-step per 1 s step", DAY_SPACECRAFT)
    writer.ssv("cubesat_3u_solar_arrays", "Cells on the four long faces and two deployed wings facing +z",
               solar_array_values())
    writer.ssv("cubesat_3u_battery", "Two 18650 cells (21.6 Wh), 80 % charged, 2 W always on", BATTERY)
    write_system(writer, "cubesat_3u_nadir_day")
    writer.ssv("cubesat_3u_mission_spacecraft", "3U body without the wheels' spin-axis inertia (kg.m2), rk4 at 0.5 s "
               "sub-steps", MISSION_SPACECRAFT)
    writer.ssv("cubesat_3u_wheels_at_rest", "The wheels at rest after separation", WHEELS_AT_REST)
    writer.ssv("cubesat_3u_gyro", "MEMS gyro at 1 Hz: 1e-4 rad/s noise, 10 deg/h bias", GYRO)
    writer.ssv("cubesat_3u_horizon", "Horizon sensor, 0.25 deg", HORIZON)
    writer.ssv("cubesat_3u_coarse_sun", "Six coarse Sun sensors on the faces (the FMU's defaults), own seed",
               COARSE_SUN)
    writer.ssv("cubesat_3u_estimator", "MEKF on the gyro with the horizon sensor and the coarse Sun heading; valid "
               "within 5 deg", ESTIMATOR)
    writer.ssv("cubesat_3u_modes", "Detumble below 1.5 deg/s, Sun-safe to 10 deg, then nadir (holds of 60 s)", MODES)
    writer.ssv("cubesat_3u_guidance_modes", "Sun-safe points +z (the wings) at the Sun; nadir with body -z to nadir",
               GUIDANCE_MODES)
    write_system(writer, "cubesat_3u_mission")
