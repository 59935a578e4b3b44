"""Write the air-bearing testbed system (the air-bearing note) and its parameter files.

    python system_ssp/systems/generate_air_bearing.py

It reads the connectors from build/fmus/{RigidBody,AttitudeToDcm,AirBearingKinematics}.fmu.

System `air_bearing`: dynamics (RigidBody, rk4) -> to_dcm (AttitudeToDcm) -> kinematics
(AirBearingKinematics). Gauss-Seidel order to_dcm, kinematics, dynamics: the kinematics
commits the DCM of time t before the dynamics advances to t + h, and after the step the master
refreshes to_dcm and kinematics with the attitude at t + h, so the rate over [t, t + h] is
published at t + h. (Other orders and Jacobi also work, with the rate one step late.)

Parameter files (parameters/, one per concern):
- air_bearing_initial_state.ssv  default initial state of `dynamics` (the slow-rotation case);
- air_bearing_testbed.ssv        testbed inertia and integrator for `dynamics`. The description gives no
  inertia; this is an illustrative table with its largest moment about the vertical b3
  (diag(0.08, 0.09, 0.12) kg m^2), so a spin about b3 is stable;
- air_bearing_kinematics.ssv     tau = 40 deg (the description's threshold), dcm_tol, rate options;
- scenarios (names `component.variable`, applied with parameter_sets=[...]):
  air_bearing_slow_rotation.ssv   spin 0.1 rad/s about b3 with small transverse rates; the tilt
                                  stays below 19 deg, inside tau;
  air_bearing_tilt_beyond_tau.ssv roll at 0.08 rad/s about the principal axis b1: the roll
                                  passes tau = 40 deg at t = 8.73 s and is limited after that.
"""
import math

from ...ssp.writer import vec
from .from_spec import write_system


STEP = 0.02
TAU = math.radians(40.0)
TESTBED = {"inertia_from_box": False, "integrator": "rk4", "max_substep": 0.005,
           **{f"inertia_B[{i},{j}]": (v if i == j else 0.0) for i, v in zip((1, 2, 3), (0.08, 0.09, 0.12))
              for j in (1, 2, 3)}}
KINEMATICS = {"tau": TAU, "dcm_tol": 1e-6, "rate_method": "log_map", "rate_from_thresholded": True}
SLOW = {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", [0.02, -0.015, 0.1])}
TILT = {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", [0.08, 0.0, 0.0])}

SCENARIOS = {
    "air_bearing_slow_rotation": ("Slow rotation inside tau: spin 0.1 rad/s about b3, transverse rates 0.02 and "
                                  "-0.015 rad/s (tilt below 19 deg)", SLOW),
    "air_bearing_tilt_beyond_tau": ("Tilt beyond tau: roll at 0.08 rad/s about b1 from rest attitude; roll passes "
                                    "tau = 40 deg at 8.73 s", TILT),
}

DCM = [(i, j) for i in (1, 2, 3) for j in (1, 2, 3)]


def generate(writer):
    writer.ssv("air_bearing_initial_state",
               "Default initial state of the air-bearing dynamics: " + SCENARIOS["air_bearing_slow_rotation"][0], SLOW)
    writer.ssv("air_bearing_testbed",
               "Air-bearing testbed inertia (illustrative, largest moment about b3; the description gives none) and "
               "integrator", TESTBED)
    writer.ssv("air_bearing_kinematics",
               "Kinematics node: pitch/roll limit tau = 40 deg (the air-bearing note), DCM tolerance, rate estimate",
               KINEMATICS)
    for name, (description, values) in SCENARIOS.items():
        writer.ssv(name, description, {f"dynamics.{k}": v for k, v in values.items()})
    write_system(writer, "air_bearing")
