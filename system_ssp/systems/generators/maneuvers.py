"""The maneuver systems `detumble` and `slew` and the thesis validation cases.

Parameter files, one per concern (docs/conventions.md):
- spacecraft.ssv   host mass and box edges (thesis Appendix A), for `dynamics`;
- thrusters.ssv    RCS thruster force, lever-arm edges, Isp, g0, for `thrusters`;
- detumble_gains.ssv, slew_gains.ssv   controller gains and tolerances (Eq. 32-33, 45);
- <system>_initial_state.ssv   the default initial state and integrator of `dynamics` (the
  values of the system's first thesis case), so the SSP alone runs a thesis case in any SSP
  tool (libcosim reads component-level parameter sets without prefixes only);
- <system>_caseN.ssv   one per thesis validation case: initial state, integrator and the
  case's gains. Names are `component.variable`; a case is applied on top of the SSD's own
  bindings with `simulate(..., parameter_sets=["parameters/detumble_case2.ssv"])` or `--ssv`.
"""
import functools
import math

from components.attitude.detumble import DetumbleController
from components.attitude.rigid_body import RigidBody, box_inertia
from components.attitude.thruster_control import pair_torques
from components.attitude.thrusters import ThrusterPairs
from components.core import rotations
from components.mission.neighbor import SPACECRAFT

from ...ssp.writer import GeneratorError, vec
from .from_spec import write_system

DT = 0.015  # thesis time step (s)
DETUMBLE_LIMIT = 20.0  # s, the Appendix D loop limit

BODY = {"mass": SPACECRAFT.mass, "edge_a": SPACECRAFT.edge_a, "edge_b": SPACECRAFT.edge_b, "edge_c": SPACECRAFT.edge_c,
        "inertia_from_box": True}
THRUSTERS = {"thrust": SPACECRAFT.rcs_thrust, "edge_a": SPACECRAFT.edge_a, "edge_c": SPACECRAFT.edge_c,
             "Isp": SPACECRAFT.isp, "g0": SPACECRAFT.g0}
RATE_TOL = math.radians(0.01)
LEVELS = pair_torques(SPACECRAFT.rcs_thrust, SPACECRAFT.edge_a, SPACECRAFT.edge_c)

DETUMBLE_GAINS = {**vec("Kp", [100.0] * 3), **vec("Kd", [1.0] * 3), **vec("omega_d", [0.0] * 3),
                  **vec("omega_tol", [RATE_TOL] * 3), **vec("torque_level", LEVELS)}
SLEW_GAINS = {**vec("Kp", [10.0] * 3), **vec("Kd", [17.5] * 3), **vec("q_d", [0.0, 0.0, 0.0, 1.0]),
              **vec("omega_d", [0.0] * 3), "q_tol": 0.01, **vec("omega_tol", [RATE_TOL] * 3),
              **vec("torque_level", LEVELS), "accept_antipodal": False}

W0_DETUMBLE = [math.radians(10.0)] * 3  # Eq. 7
# Eq. 36: the thesis' case-2 quaternion, q4 from the unit-norm condition (Eq. 35).
Q0_CASE2 = [0.5597, 0.3484, 0.1653]
Q0_CASE2.append(math.sqrt(1.0 - sum(x * x for x in Q0_CASE2)))


def detumble_end_state(q0):
    """End state of a thesis detumble case (Appendix D loop, explicit Euler, 15 ms).

    The thesis ran each slew case from the full-precision end state of a detumble case, not
    from the four decimals it prints (Eq. 39, 48, 51), and the slews are sensitive to it: from
    the printed values slew case 1 ends one step later with q4 = 1.00021 instead of 1.00060,
    and slew case 2 does not converge within 200 s. The slew case files therefore carry the
    end state computed here with the same component code the FMUs run (a test checks that
    it equals the co-simulated detumble end state)."""
    inertia = box_inertia(SPACECRAFT.mass, *SPACECRAFT.edges)
    body = RigidBody(inertia, q0, W0_DETUMBLE, "euler")
    ctrl = DetumbleController(DETUMBLE_GAINS_KP, DETUMBLE_GAINS_KD, torque_level=LEVELS)
    pairs = ThrusterPairs()
    for _ in range(round(DETUMBLE_LIMIT / DT)):
        if ctrl.done(body.omega):
            return list(body.q), list(body.omega), list(body.euler_integrated)
        cmd, _ = ctrl.command(body.omega, body.omega_dot)
        pairs.step(cmd, DT)
        body.step(pairs.applied_torque(cmd), DT)
    raise GeneratorError(
        f"the thesis detumble (gains Kp {DETUMBLE_GAINS_KP[0]:g}, Kd {DETUMBLE_GAINS_KD[0]:g}) from q0 = {list(q0)} "
        f"does not reach its rate tolerance within the Appendix D limit of {DETUMBLE_LIMIT:g} s for the "
        f"spacecraft of components/mission/neighbor.py (mass {SPACECRAFT.mass:g} kg; it ends at omega = "
        f"{[float(f'{w:.3g}') for w in body.omega]} rad/s): the slew cases start from that end state")


DETUMBLE_GAINS_KP, DETUMBLE_GAINS_KD = [100.0] * 3, [1.0] * 3
# Appendix D's stop test as printed (omega - omega_d <= tol, no absolute value): the thesis cases
# use it; everything else the controller's default, |omega - omega_d| <= tol (same end here).
THESIS_STOP_TEST = {"signed_stop_test": True}


def continued_angles(euler):
    """The slews carry on integrating the detumble's Eq. 31 angles (Eq. 39 = Eq. 34)."""
    return {"euler0_from_q0": False, **vec("euler0", euler)}


@functools.lru_cache(maxsize=None)
def thesis_cases():
    """The thesis' validation cases as parameter sets (computed when first asked for: the slews
    start from the detumbles' end states, which take a simulation)."""
    q_end_1, w_end_1, e_end_1 = detumble_end_state([0.0, 0.0, 0.0, 1.0])
    q_end_2, w_end_2, e_end_2 = detumble_end_state(Q0_CASE2)
    cases = {
        "detumble_case1": {"description": "Thesis detumble validation case 1 (Eq. 6-7, 32-34)",
                           "dynamics": {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", W0_DETUMBLE),
                                        "integrator": "euler"},
                           "detumble": THESIS_STOP_TEST},
        "detumble_case2": {"description": "Thesis detumble validation case 2 (Eq. 35-38)",
                           "dynamics": {**vec("q0", Q0_CASE2), **vec("omega0", W0_DETUMBLE), "integrator": "euler"},
                           "detumble": THESIS_STOP_TEST},
        "slew_case1": {"description": "Thesis slew validation case 1 (Eq. 39-47): from the end state of detumble "
                                      "case 1 (full precision; Eq. 39 prints it to 4 decimals)",
                       "dynamics": {**vec("q0", q_end_1), **vec("omega0", w_end_1), "integrator": "euler",
                                    **continued_angles(e_end_1)},
                       "slew": {**vec("Kd", [17.5] * 3)}},
        "slew_case2": {"description": "Thesis slew validation case 2 (Eq. 48-50): from the end state of detumble "
                                      "case 2 (full precision; Eq. 48 prints it to 4 decimals)",
                       "dynamics": {**vec("q0", q_end_2), **vec("omega0", w_end_2), "integrator": "euler",
                                    **continued_angles(e_end_2)},
                       "slew": {**vec("Kd", [22.5] * 3)}},
    }
    # Slew case 3 (Eq. 51-66, Appendix G): three 180 deg rotations from the end state of
    # detumble case 1, targets q_x (x) q0, q_y (x) q_d,x, q_z (x) q_d,y (Eq. 57-59), each with its
    # own gains and the Appendix G stop test. The y and z rotations start where the previous one
    # ended, so their files carry no initial state: system_ssp.thesis chains them.
    target = tuple(q_end_1)
    for axis, (kp, kd) in {"x": (10.0, 20.0), "y": (1.0, 5.0), "z": (10.0, 30.0)}.items():
        rot = rotations.from_axis_angle({"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}[axis],
                                       math.pi)
        target = rotations.circle_cross(rot, target)
        cases[f"slew_case3_{axis}"] = {
            "description": f"Thesis slew validation case 3, 180 deg about {axis} (Eq. 57-66, Appendix G)",
            "dynamics": ({**vec("q0", q_end_1), **vec("omega0", w_end_1), **continued_angles(e_end_1)}
                         if axis == "x" else {}) | {"integrator": "euler"},
            "slew": {**vec("Kp", [kp] * 3), **vec("Kd", [kd] * 3), **vec("q_d", list(target)),
                     "accept_antipodal": True}}
    return cases


# The systems and the thesis case each one binds by default (specs/<name>.toml describe them)
DEFAULT_CASES = {"detumble": "detumble_case1", "slew": "slew_case1"}

CONCERNS = {"spacecraft": ("Host spacecraft mass and box edges (thesis Appendix A)", BODY),
            "thrusters": ("RCS thruster force, lever-arm edges, Isp and g0 (Appendix A, Eq. 16, 74)", THRUSTERS),
            "detumble_gains": ("Detumble PD gains and tolerances (Eq. 8, 32-33, Appendix D)", DETUMBLE_GAINS),
            "slew_gains": ("Slew PD gains, target and tolerances (Eq. 40, 45, Appendix E)", SLEW_GAINS)}


def case_parameters(case):
    return {f"{comp}.{k}": v for comp, params in thesis_cases()[case].items() if comp != "description"
            for k, v in params.items()}


def generate(writer):
    for concern, (description, values) in CONCERNS.items():
        writer.ssv(concern, description, values)
    cases = thesis_cases()
    for case, spec in cases.items():
        writer.ssv(case, spec["description"], case_parameters(case))
    for name, case in DEFAULT_CASES.items():
        writer.ssv(f"{name}_initial_state", f"Default initial state of {name}: {cases[case]['description']}",
                   cases[case]["dynamics"])
        write_system(writer, name)
