"""Write the Sun-avoidance slew system (sun_avoidance_slew.ssd) and its parameter files.

    python -c "import build_fmus, pathlib; [build_fmus.build_fmu(pathlib.Path(f'fmus/{m}.py'), 'build/fmus') \
        for m in ('neighbor_sas_guidance', 'neighbor_reference_tracking', 'neighbor_rigid_body')]"
    python system_ssp/systems/generate_sas.py

Components: `guidance` (SunAvoidanceGuidance) -> `tracker` (ReferenceTrackingController) ->
`dynamics` (RigidBody). The tracker's continuous torque goes straight into dynamics.torque_B:
an ideal continuous actuator (e.g. reaction wheels, or a throttled RCS averaged over a step),
because the thesis' on/off thruster pairs cannot follow a smooth reference. Gauss-Seidel order
tracker, dynamics, guidance: at each step the tracker sees the guidance reference and the
dynamics state at the same time t (stepping the guidance first would hand the tracker the
reference at t + h against the state at t).

Parameter files (parameters/):
- sun_avoidance_slew_guidance.ssv, _tracker.ssv, _initial_state.ssv: bound to the components
  in the SSD (the near-Sun scenario's geometry is the default);
- sun_avoidance_slew_near_sun.ssv: the Sun 10 deg off the direct path (three segments);
- sun_avoidance_slew_far_sun.ssv: the Sun far from the path (one eigenaxis segment).
"""
import math


from components.core import rotations
from components.attitude import reference_tracking as rt
from components.attitude import sun_avoidance as sa
from components.mission.neighbor import SPACECRAFT

from ...ssp.writer import vec
from .from_spec import write_system

NAME = "sun_avoidance_slew"
BORESIGHT = (0.0, 0.0, 1.0)
Q0 = (0.0, 0.0, 0.0, 1.0)
# Final attitude: 120 deg about x, then 40 deg about the body z (a roll about the boresight).
Q_F = rotations.circle_cross(rotations.from_axis_angle((0.0, 0.0, 1.0), math.radians(40.0)),
                            rotations.from_axis_angle((1.0, 0.0, 0.0), math.radians(120.0)))
EPSILON = math.radians(30.0)
MARGIN = math.radians(5.0)
W_MAX, A_MAX = 0.05, 0.01


def direct_midpoint_boresight():
    """Boresight direction (N) half-way along the direct eigenaxis slew q0 -> q_f."""
    axis, phi = sa.eigenaxis(Q0, Q_F)
    return sa.boresight_N(rotations.circle_cross(rotations.from_axis_angle(axis, phi / 2), Q0), BORESIGHT)


def sun_near():
    """The Sun 10 deg off the direct path's midpoint boresight (inside the 30 deg cone)."""
    mid = direct_midpoint_boresight()
    axis, _ = sa.eigenaxis(Q0, Q_F)
    e_N = sa.mat_t_vec(rotations.attitude_matrix(Q0), axis)
    side = sa._unit(rotations.cross(e_N, mid), "side")
    # Rotating about the direction of motion moves the point off the path.
    return list(sa.rotate(mid, side, math.radians(10.0)))


def sun_far():
    """The Sun on the far side: opposite the direct path's midpoint boresight."""
    return [-x for x in direct_midpoint_boresight()]


def guidance_params(sun):
    return {**vec("boresight_B", list(BORESIGHT)), **vec("sun_N", sun), "epsilon": EPSILON, "margin": MARGIN,
            **vec("q0", list(Q0)), **vec("q_f", list(Q_F)), "w_max": W_MAX, "a_max": A_MAX, "t_start": 0.0,
            "mass": SPACECRAFT.mass, "edge_a": SPACECRAFT.edge_a, "edge_b": SPACECRAFT.edge_b,
            "edge_c": SPACECRAFT.edge_c}


TRACKER = {**vec("Kp", list(rt.DEFAULT_KP)), **vec("Kd", list(rt.DEFAULT_KD)), **vec("max_torque", [0.0025] * 3),
           "quantize": False, "angle_tol": math.radians(0.1), "rate_tol": math.radians(0.01)}
INITIAL = {**vec("q0", list(Q0)), **vec("omega0", [0.0] * 3), "integrator": "rk4"}


def scenario(sun):
    g = {f"guidance.{k}": v for k, v in vec("sun_N", sun).items()}
    g.update({f"guidance.{k}": v for k, v in vec("q_f", list(Q_F)).items()})
    g.update(vec("initial_attitude", list(Q0)))
    g.update({f"dynamics.{k}": v for k, v in INITIAL.items() if not k.startswith("q0")})
    return g


def generate(writer):
    writer.ssv(f"{NAME}_guidance",
               "SAS guidance: boresight, Sun, keep-out cone, attitudes, rate limits, inertia (near-Sun geometry)",
               guidance_params(sun_near()))
    writer.ssv(f"{NAME}_tracker",
               "Reference-tracking gains (wn = 1 rad/s, zeta = 0.9 on the NEIGHBOR box inertia), limits, tolerances",
               TRACKER)
    writer.ssv(f"{NAME}_initial_state",
               "Initial state of the Sun-avoidance slew: at rest at the guidance's q0, rk4", INITIAL)
    writer.ssv(f"{NAME}_near_sun",
               "Sun 10 deg off the direct eigenaxis path (keep-out 30 deg): three-segment detour", scenario(sun_near()))
    writer.ssv(f"{NAME}_far_sun",
               "Sun opposite the direct path's midpoint: single eigenaxis slew", scenario(sun_far()))
    writer.ssv(f"{NAME}_initial_attitude", "Initial attitude q_BN of the guidance and the rigid body, given once",
               vec("initial_attitude", list(Q0)))
    write_system(writer, NAME)
