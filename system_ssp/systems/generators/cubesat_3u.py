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
from components.core.names import matrix_names
from components.mission import cubesat_3u as mission

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
