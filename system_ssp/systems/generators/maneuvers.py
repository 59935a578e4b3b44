"""Write the maneuver systems' .ssd and .ssv files from the short descriptions below.

    python build_fmus.py && python system_ssp/systems/generate.py

The generated files are committed; this script keeps them consistent with the FMUs: every
component lists all its inputs, outputs and parameters as SSD connectors with the FMU's
types and units (read from build/fmus/*.fmu), connections are checked against those
connectors, and numbers are written with full precision.

Parameter files, one per concern (CONVENTIONS.md):
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
import math
import sys
from pathlib import Path
from xml.sax.saxutils import quoteattr

from fmpy import read_model_description

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT))

from components.core import rotations  # noqa: E402
from components.attitude.detumble import DetumbleController  # noqa: E402
from components.attitude.rigid_body import RigidBody, box_inertia  # noqa: E402
from components.attitude.thruster_control import pair_torques  # noqa: E402
from components.attitude.thrusters import ThrusterPairs  # noqa: E402

FMU_DIR = ROOT / "build" / "fmus"
MASTER_NS = "https://neighbor-cosim.org/ssp/master"
DT = 0.015  # thesis time step (s)

SPACECRAFT = {"mass": 12.0, "edge_a": 0.1, "edge_b": 0.2, "edge_c": 0.3, "inertia_from_box": True}
THRUSTERS = {"thrust": 0.025, "edge_a": 0.1, "edge_c": 0.3, "Isp": 42.0, "g0": 9.81}
RATE_TOL = math.radians(0.01)
LEVELS = pair_torques(0.025, 0.1, 0.3)


def vec(name, values):
    return {f"{name}[{i}]": v for i, v in enumerate(values, 1)}


DETUMBLE_GAINS = {**vec("Kp", [100.0] * 3), **vec("Kd", [1.0] * 3), **vec("omega_d", [0.0] * 3),
                  **vec("omega_tol", [RATE_TOL] * 3), **vec("torque_level", LEVELS), "signed_stop_test": True}
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
    inertia = box_inertia(SPACECRAFT["mass"], SPACECRAFT["edge_a"], SPACECRAFT["edge_b"], SPACECRAFT["edge_c"])
    body = RigidBody(inertia, q0, W0_DETUMBLE, "euler")
    ctrl = DetumbleController(DETUMBLE_GAINS_KP, DETUMBLE_GAINS_KD, torque_level=LEVELS)
    pairs = ThrusterPairs()
    while not ctrl.done(body.omega):
        cmd, _ = ctrl.command(body.omega, body.omega_dot)
        pairs.step(cmd, DT)
        body.step(pairs.applied_torque(cmd), DT)
    return list(body.q), list(body.omega)


DETUMBLE_GAINS_KP, DETUMBLE_GAINS_KD = [100.0] * 3, [1.0] * 3
Q_END_1, W_END_1 = detumble_end_state([0.0, 0.0, 0.0, 1.0])
Q_END_2, W_END_2 = detumble_end_state(Q0_CASE2)

CASES = {
    "detumble_case1": {"description": "Thesis detumble validation case 1 (Eq. 6-7, 32-34)",
                       "dynamics": {**vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("omega0", W0_DETUMBLE),
                                    "integrator": "euler"}},
    "detumble_case2": {"description": "Thesis detumble validation case 2 (Eq. 35-38)",
                       "dynamics": {**vec("q0", Q0_CASE2), **vec("omega0", W0_DETUMBLE), "integrator": "euler"}},
    "slew_case1": {"description": "Thesis slew validation case 1 (Eq. 39-47): from the end state of detumble "
                                  "case 1 (full precision; Eq. 39 prints it to 4 decimals)",
                   "dynamics": {**vec("q0", Q_END_1), **vec("omega0", W_END_1), "integrator": "euler"},
                   "slew": {**vec("Kd", [17.5] * 3)}},
    "slew_case2": {"description": "Thesis slew validation case 2 (Eq. 48-50): from the end state of detumble "
                                  "case 2 (full precision; Eq. 48 prints it to 4 decimals)",
                   "dynamics": {**vec("q0", Q_END_2), **vec("omega0", W_END_2), "integrator": "euler"},
                   "slew": {**vec("Kd", [22.5] * 3)}},
}
# Slew case 3 (Eq. 51-66, Appendix G): three 180 deg rotations from the end state of
# detumble case 1, targets q_x (x) q0, q_y (x) q_d,x, q_z (x) q_d,y (Eq. 57-59), each with its
# own gains and the Appendix G stop test. The y and z rotations start where the previous one
# ended, so their files carry no initial state: system_ssp.thesis chains them.
_target = tuple(Q_END_1)
for axis, (kp, kd) in {"x": (10.0, 20.0), "y": (1.0, 5.0), "z": (10.0, 30.0)}.items():
    _rot = rotations.from_axis_angle({"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}[axis],
                                    math.pi)
    _target = rotations.circle_cross(_rot, _target)
    CASES[f"slew_case3_{axis}"] = {
        "description": f"Thesis slew validation case 3, 180 deg about {axis} (Eq. 57-66, Appendix G)",
        "dynamics": ({**vec("q0", Q_END_1), **vec("omega0", W_END_1)} if axis == "x" else {}) | {"integrator": "euler"},
        "slew": {**vec("Kp", [kp] * 3), **vec("Kd", [kd] * 3), **vec("q_d", list(_target)),
                 "accept_antipodal": True}}

SYSTEMS = {
    "detumble": {
        "description": "NEIGHBOR detumble maneuver: PD rate controller, RCS thruster pairs, rigid body",
        "components": [("detumble", "DetumbleController", ["detumble_gains"]),
                       ("thrusters", "RcsThrusters", ["thrusters"]),
                       ("dynamics", "RigidBody", ["detumble_initial_state", "spacecraft"])],
        "connections": [("dynamics", "omega_BN_B", "detumble", "omega_BN_B", 3),
                        ("dynamics", "omega_dot_BN_B", "detumble", "omega_dot_BN_B", 3),
                        ("detumble", "torque_cmd_B", "thrusters", "torque_cmd_B", 3),
                        ("thrusters", "torque_B", "dynamics", "torque_B", 3)],
        "default_case": "detumble_case1",
        "stop": [("detumble", "done")],
        "order": ["detumble", "thrusters", "dynamics"],
        "stop_time": 20.0,  # the Appendix D loop limit
    },
    "slew": {
        "description": "NEIGHBOR slew maneuver: quaternion PD controller, RCS thruster pairs, rigid body",
        "components": [("slew", "SlewController", ["slew_gains"]),
                       ("thrusters", "RcsThrusters", ["thrusters"]),
                       ("dynamics", "RigidBody", ["slew_initial_state", "spacecraft"])],
        "connections": [("dynamics", "q_BN", "slew", "q_BN", 4),
                        ("dynamics", "omega_BN_B", "slew", "omega_BN_B", 3),
                        ("slew", "torque_cmd_B", "thrusters", "torque_cmd_B", 3),
                        ("thrusters", "torque_B", "dynamics", "torque_B", 3)],
        "default_case": "slew_case1",
        "stop": [("slew", "done")],
        "order": ["slew", "thrusters", "dynamics"],
        "stop_time": 1500.0,  # the Appendix G loop limit
    },
}

CONCERNS = {"spacecraft": ("Host spacecraft mass and box edges (thesis Appendix A)", SPACECRAFT),
            "thrusters": ("RCS thruster force, lever-arm edges, Isp and g0 (Appendix A, Eq. 16, 74)", THRUSTERS),
            "detumble_gains": ("Detumble PD gains and tolerances (Eq. 8, 32-33, Appendix D)", DETUMBLE_GAINS),
            "slew_gains": ("Slew PD gains, target and tolerances (Eq. 40, 45, Appendix E)", SLEW_GAINS)}

NS = ('xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
      'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
      'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"')
OSP_NS = 'xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations"'


def fmu_variables(fmu_name):
    md = read_model_description(str(FMU_DIR / f"{fmu_name}.fmu"))
    units = {u.name: u.baseUnit for u in md.unitDefinitions}
    return md.modelVariables, units


def typed_value(value):
    if isinstance(value, bool):
        return f'<ssv:Boolean value="{str(value).lower()}"/>'
    if isinstance(value, int):
        return f'<ssv:Integer value="{value}"/>'
    if isinstance(value, float):
        return f'<ssv:Real value="{value!r}"/>'
    return f"<ssv:String value={quoteattr(value)}/>"


def write_ssv(path, name, description, params):
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<!-- {description} -->',
             f'<ssv:ParameterSet {NS.split(" ")[2]} version="1.0" name={quoteattr(name)}>',
             "  <ssv:Parameters>"]
    for key, value in params.items():
        lines.append(f'    <ssv:Parameter name={quoteattr(key)}>{typed_value(value)}</ssv:Parameter>')
    lines += ["  </ssv:Parameters>", "</ssv:ParameterSet>", ""]
    path.write_text("\n".join(lines))


def case_parameters(case):
    return {f"{comp}.{k}": v for comp, params in CASES[case].items() if comp != "description"
            for k, v in params.items()}


def connector_xml(var):
    kind = var.causality
    if var.type == "Real":
        t = f'<ssc:Real unit="{var.unit}"/>' if var.unit else "<ssc:Real/>"
    else:
        t = f"<ssc:{var.type}/>"
    return f'        <ssd:Connector name={quoteattr(var.name)} kind="{kind}">{t}</ssd:Connector>'


def write_ssd(name, spec, directory=HERE):
    """Write <directory>/<name>.ssd from a spec (see SYSTEMS): components as (instance, FMU
    model identifier, [parameter files in parameters/, without .ssv]), connections as
    (source, output, destination, input, n) with n > 0 for structured names out[1]..out[n] or
    n = 0 for a scalar, optional "stop" Boolean outputs, "order", "stop_time", "step_size", and
    "schedule": {"modes": [(name, step, active components or None, recordEvery,
    [(component, connector, [values])][, {component: k}])], "events": [(component, connector)]} for an
    nc:Schedule (the optional dict: components stepped every k-th step of the mode).
    libcosim applies only a component's first ParameterBinding: put the one that matters first."""
    all_units = {}
    comp_vars = {}
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           # Namespace on the root: libcosim's parser takes xmlns attributes on inner
           # elements for child elements.
           f'<ssd:SystemStructureDescription {NS} {OSP_NS} version="1.0" name="{name}">',
           f'  <ssd:System name="{name}" description={quoteattr(spec["description"])}>',
           "    <ssd:Elements>"]
    for inst, fmu, concerns in spec["components"]:
        variables, units = fmu_variables(fmu)
        all_units.update(units)
        comp_vars[inst] = {v.name: v for v in variables}
        out.append(f'      <ssd:Component name="{inst}" type="application/x-fmu-sharedlibrary" '
                   f'source="resources/{fmu}.fmu">')
        out.append("        <ssd:Connectors>")
        out += ["  " + connector_xml(v) for v in variables if v.causality in ("input", "output", "parameter")]
        out.append("        </ssd:Connectors>")
        bindings = [f'<ssd:ParameterBinding source="parameters/{c}.ssv"/>' for c in concerns]
        if bindings:  # the schema refuses an empty ParameterBindings element
            out.append("        <ssd:ParameterBindings>")
            out += [f"          {b}" for b in bindings]
            out.append("        </ssd:ParameterBindings>")
        out.append("      </ssd:Component>")
    out.append("    </ssd:Elements>")
    out.append("    <ssd:Connections>")
    for src, sname, dst, dname, n in spec["connections"]:
        pairs = [(f"{sname}[{i}]", f"{dname}[{i}]") for i in range(1, n + 1)] if n else [(sname, dname)]
        for a, b in pairs:
            if comp_vars[src][a].causality != "output" or comp_vars[dst][b].causality != "input":
                raise SystemExit(f"{name}: {src}.{a} -> {dst}.{b} is not output -> input")
            out.append(f'      <ssd:Connection startElement="{src}" startConnector="{a}" '
                       f'endElement="{dst}" endConnector="{b}"/>')
    out.append("    </ssd:Connections>")
    dt = spec.get("step_size", DT)
    for comp, var in spec.get("stop", []):
        if comp_vars[comp][var].type != "Boolean" or comp_vars[comp][var].causality != "output":
            raise SystemExit(f"{name}: stop signal {comp}.{var} must be a Boolean output")
    out += ["    <ssd:Annotations>",
            '      <ssc:Annotation type="org.neighbor-cosim.master">',
            f'        <nc:Master xmlns:nc="{MASTER_NS}" stepSize="{dt!r}" algorithm="gauss-seidel">',
            *([f'          <nc:Order>{" ".join(spec["order"])}</nc:Order>'] if spec.get("order") else [])]
    out += [f'          <nc:StopCondition component="{c}" connector="{v}"/>' for c, v in spec.get("stop", [])]
    if spec.get("schedule"):
        out += _schedule_xml(name, spec["schedule"], comp_vars)
    out += ["        </nc:Master>", "      </ssc:Annotation>", "    </ssd:Annotations>", "  </ssd:System>"]
    out.append("  <ssd:Units>")
    for uname in sorted(all_units):
        bu = all_units[uname]
        attrs = " ".join(f'{k}="{getattr(bu, k)}"' for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
                         if bu is not None and getattr(bu, k))
        out.append(f'    <ssc:Unit name="{uname}"><ssc:BaseUnit {attrs}/></ssc:Unit>')
    out.append("  </ssd:Units>")
    # libcosim takes its fixed step from this OSP annotation (our master reads its own).
    out += [f'  <ssd:DefaultExperiment startTime="0.0" stopTime="{spec["stop_time"]!r}">',
            "    <ssd:Annotations>",
            '      <ssc:Annotation type="com.opensimulationplatform">',
            '        <osp:Algorithm>',
            f'          <osp:FixedStepAlgorithm baseStepSize="{dt!r}"/>',
            "        </osp:Algorithm>",
            "      </ssc:Annotation>",
            "    </ssd:Annotations>",
            "  </ssd:DefaultExperiment>"]
    out += ["</ssd:SystemStructureDescription>", ""]
    (directory / f"{name}.ssd").write_text("\n".join(out))


def _schedule_xml(name, schedule, comp_vars):
    """nc:Schedule lines, checked against the FMUs' variables."""
    def check(comp, var, types):
        v = comp_vars.get(comp, {}).get(var)
        if v is None or v.causality != "output" or v.type not in types:
            raise SystemExit(f"{name}: schedule signal {comp}.{var} must be an output of type {' or '.join(types)}")

    out = ["          <nc:Schedule>"]
    for mode, step, active, every, when, *multiples in schedule["modes"]:
        multiples = multiples[0] if multiples else {}
        for comp in list(active or []) + list(multiples):
            if comp not in comp_vars:
                raise SystemExit(f"{name}: schedule mode {mode} lists unknown component {comp}")
        attrs = f'name="{mode}" stepSize="{step!r}"'
        if active is not None:
            attrs += f' active="{" ".join(active)}"'
        if every != 1:
            attrs += f' recordEvery="{every}"'
        if multiples:
            attrs += f' every="{" ".join(f"{c}:{k}" for c, k in multiples.items())}"'
        if not when:
            out.append(f"            <nc:Mode {attrs}/>")
            continue
        out.append(f"            <nc:Mode {attrs}>")
        for comp, var, values in when:
            check(comp, var, ("Integer", "Enumeration", "Boolean"))
            out.append(f'              <nc:When component="{comp}" connector="{var}" '
                       f'values="{" ".join(str(int(v)) for v in values)}"/>')
        out.append("            </nc:Mode>")
    for comp, var in schedule.get("events", []):
        check(comp, var, ("Real",))
        out.append(f'            <nc:NextEvent component="{comp}" connector="{var}"/>')
    out.append("          </nc:Schedule>")
    return out


def main():
    params_dir = HERE / "parameters"
    params_dir.mkdir(exist_ok=True)
    for concern, (description, values) in CONCERNS.items():
        write_ssv(params_dir / f"{concern}.ssv", concern, description, values)
    for case, spec in CASES.items():
        write_ssv(params_dir / f"{case}.ssv", case, spec["description"], case_parameters(case))
    for name, spec in SYSTEMS.items():
        initial = CASES[spec["default_case"]]["dynamics"]
        write_ssv(params_dir / f"{name}_initial_state.ssv", f"{name}_initial_state",
                  f"Default initial state of {name}: {CASES[spec['default_case']]['description']}", initial)
        write_ssd(name, spec)
    print(f"wrote {len(SYSTEMS)} systems and {len(CONCERNS) + len(CASES)} parameter sets in {HERE}")


if __name__ == "__main__":
    main()
