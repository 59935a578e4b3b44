"""Each FMU on its own through FMPy: a valid model description, standalone simulation,
get/set of the full state, and the incremental build."""
import ast
import math
import re
import zipfile

import fmpy
import numpy as np
import pytest

import build_fmus
from build_fmus import wrapper_scripts
from components.attitude import mass_properties, rigid_body
from fmu_helpers import check_declarations, instantiate

EXPECTED = {"RigidBody", "DetumbleController", "SlewController", "RcsThrusters"}


def test_every_fmu_is_built_valid_and_fully_declared(fmu_paths):
    assert EXPECTED <= set(fmu_paths)
    for path in fmu_paths.values():
        check_declarations(path)


def wrapper_module(fmu_name):
    """The one naming rule for wrappers: fmus/neighbor_<the FMU name in snake case>.py."""
    return "neighbor_" + re.sub(r"(?<!^)(?=[A-Z])", "_", fmu_name).lower()


def test_wrapper_files_are_named_after_their_fmus():
    for script in wrapper_scripts():
        classes = re.findall(r"^class (\w+)\(\w*Slave\)", script.read_text(), re.M)  # NeighborSlave or a shared base
        assert len(classes) == 1, f"{script.name}: one FMU class per wrapper, found {classes}"
        assert script.stem == wrapper_module(classes[0]), f"{script.name} builds {classes[0]}"


def test_module_names_are_unique(fmu_paths):
    """Every FMU's code lives in one package named for the FMU and its build: no two FMUs (or two
    builds of one) can load each other's modules in one process."""
    packages = []
    for name, path in fmu_paths.items():
        with zipfile.ZipFile(path) as zf:
            text = zf.read("resources/neighbor_runtime.txt").decode()
            config = dict(line.split("=", 1) for line in text.splitlines())
            package, module, cls = config["slave"].split()
            assert cls == name and module == wrapper_module(name)
            assert package.startswith(f"nc_{name.lower()}_") and f"resources/{package}/{module}.py" in zf.namelist()
            assert not any(n.startswith(("resources/components", "resources/pythonfmu")) for n in zf.namelist())
        packages.append(package)
    assert len(set(packages)) == len(packages)


def _deps(path):
    md = fmpy.read_model_description(str(path))
    return {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}


def test_output_dependencies_are_real(fmu_paths):
    body = _deps(fmu_paths["RigidBody"])
    assert body and all(d == [] for d in body.values())  # states: no direct feedthrough
    det = _deps(fmu_paths["DetumbleController"])
    assert det["torque_cmd_B[1]"] == sorted([f"omega_BN_B[{i}]" for i in (1, 2, 3)]
                                            + [f"omega_dot_BN_B[{i}]" for i in (1, 2, 3)] + ["enabled"])
    assert det["done"] == [f"omega_BN_B[{i}]" for i in (1, 2, 3)]
    thr = _deps(fmu_paths["RcsThrusters"])
    assert thr["torque_B[2]"] == [f"torque_cmd_B[{i}]" for i in (1, 2, 3)]
    assert thr["propellant_mass"] == [] and thr["fire_time[1]"] == []
    slew = _deps(fmu_paths["SlewController"])
    assert "q_BN[4]" in slew["torque_cmd_B[3]"] and "omega_BN_B[1]" in slew["done"]


def test_each_fmu_simulates_alone(fmu_paths):
    r = fmpy.simulate_fmu(str(fmu_paths["RigidBody"]), stop_time=2.0, output_interval=0.01,
                          start_values={"omega0[3]": 0.2, "integrator": "rk4"})
    assert r["time"][-1] == pytest.approx(2.0)
    # torque-free spin about z: the quaternion rotates at 0.2 rad/s
    assert r["q_BN[3]"][-1] == pytest.approx(math.sin(0.2), abs=1e-9)
    r = fmpy.simulate_fmu(str(fmu_paths["RcsThrusters"]), stop_time=1.0, output_interval=0.01,
                          start_values={"torque_cmd_B[1]": 0.0025})
    assert r["fire_time[1]"][-1] == pytest.approx(1.0, abs=1e-9)
    assert r["propellant_mass"][-1] == pytest.approx(2 * 0.025 * 1.0 / (42 * 9.81), rel=1e-9)
    r = fmpy.simulate_fmu(str(fmu_paths["DetumbleController"]), stop_time=0.1, output_interval=0.01,
                          start_values={"omega_BN_B[2]": 0.1})
    assert list(r["thrust_flag[2]"][:3]) == [-1, -1, -1] and not r["done"][-1]
    r = fmpy.simulate_fmu(str(fmu_paths["SlewController"]), stop_time=0.1, output_interval=0.01)
    assert r["done"][-1] and r["attitude_error"][-1] == 0.0


def test_rigid_body_with_its_inertia_off_the_nominal_one(fmu_paths, capsys):
    """inertia_error (issue 28's dispersions): the body's momentum at the start is J' omega0 with
    J' the box's second moments scaled; none given, the box's; out of range, refused and said."""
    from fmpy.fmi1 import FMICallException

    box = rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3)
    spin = {"omega0[1]": 0.1, "omega0[2]": -0.2, "omega0[3]": 0.3}
    errors = {"inertia_error[1]": 0.1, "inertia_error[2]": -0.1, "inertia_error[3]": 0.05}
    for start, J in (({}, box), (errors, mass_properties.with_moment_errors(box, (0.1, -0.1, 0.05)))):
        r = fmpy.simulate_fmu(str(fmu_paths["RigidBody"]), stop_time=0.03, output_interval=0.015,
                              start_values={**spin, **start})
        H = np.array(J) @ np.array([0.1, -0.2, 0.3])
        assert [r[f"H_B[{i}]"][0] for i in (1, 2, 3)] == pytest.approx(H, rel=1e-12)
    with pytest.raises(FMICallException):
        fmpy.simulate_fmu(str(fmu_paths["RigidBody"]), stop_time=0.03, start_values={"inertia_error[2]": 0.7})
    assert "inertia errors [0.0, 0.7, 0.0] must be 3 fractions in [-0.5, 0.5]" in capsys.readouterr().out


def _instance(path, tmp_path, name):
    return instantiate(path, tmp_path, name)


def test_get_and_set_state_restores_hidden_state(fmu_paths, tmp_path):
    # Rigid body: omega_dot (the last step's acceleration) is hidden state beyond the outputs'
    # own values; thrusters: the accumulated firing times.
    body, bv = _instance(fmu_paths["RigidBody"], tmp_path, "body")
    thr, tv = _instance(fmu_paths["RcsThrusters"], tmp_path, "thr")
    try:
        body.setString([bv["integrator"]], ["euler"])
        body.setReal([bv["omega0[1]"], bv["omega0[2]"]], [0.2, -0.1])
        for f in (body, thr):
            f.enterInitializationMode()
            f.exitInitializationMode()
        out = [bv[f"q_BN[{i}]"] for i in range(1, 5)] + [bv[f"omega_dot_BN_B[{i}]"] for i in range(1, 4)]
        t = 0.0

        def advance(n, torque):
            nonlocal t
            for _ in range(n):
                thr.setReal([tv["torque_cmd_B[1]"], tv["torque_cmd_B[2]"]], torque)
                thr.doStep(t, 0.015)
                body.setReal([bv["torque_B[1]"], bv["torque_B[2]"]],
                             thr.getReal([tv["torque_B[1]"], tv["torque_B[2]"]]))
                body.doStep(t, 0.015)
                t += 0.015
            return body.getReal(out) + thr.getReal([tv["fire_time_total"], tv["propellant_mass"]])

        advance(10, [0.0025, 0.0])
        s_body, s_thr, t_saved = body.getFMUstate(), thr.getFMUstate(), t
        first = advance(20, [0.0, -0.0025])
        advance(5, [0.0025, 0.0025])  # wander off
        body.setFMUstate(s_body)
        thr.setFMUstate(s_thr)
        t = t_saved
        second = advance(20, [0.0, -0.0025])
        assert first == second
        body.freeFMUstate(s_body)
        thr.freeFMUstate(s_thr)
    finally:
        for f in (body, thr):
            f.terminate()
            f.freeInstance()


def test_build_is_incremental(tmp_path, monkeypatch, capsys):
    import build_fmus

    build_fmus.build_all(verbose=True)  # brings everything up to date
    capsys.readouterr()
    build_fmus.build_all(verbose=True)
    assert "building" not in capsys.readouterr().out


def test_fmus_load_their_bundled_components_after_another_fmu_is_gone(fmu_paths, tmp_path):
    """In a fresh process, fmpy.simulate_fmu runs one FMU and deletes its extracted folder;
    a second FMU that needs a `components` module nobody imported yet must still load it
    (from its own bundled copy)."""
    import subprocess
    import sys

    script = (
        "import fmpy, sys\n"
        "fmpy.simulate_fmu(sys.argv[1], stop_time=1.0)\n"
        "r = fmpy.simulate_fmu(sys.argv[2], stop_time=1.0, start_values={'torque_cmd_B[1]': 0.0025})\n"
        "print(r['fire_time[1]'][-1])\n")
    p = subprocess.run([sys.executable, "-c", script, str(fmu_paths["SunEphemeris"]), str(fmu_paths["RcsThrusters"])],
                       capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    assert float(p.stdout.strip().splitlines()[-1]) == pytest.approx(1.0)


def test_feedthrough_cache_follows_parameters_and_restored_state():
    """Outputs computed once per set of inputs must be recomputed after a parameter change
    (a rebuilt model) and after a restored FMU state, however the memory is reused."""
    import sys

    from build_fmus import FMU_SOURCES

    sys.path.insert(0, str(FMU_SOURCES))
    from neighbor_detumble_controller import DetumbleController

    d = DetumbleController(instance_name="d")
    vr = {v.name: v.value_reference for v in d.vars.values()}
    w1, kp1, out = vr["omega_BN_B[1]"], vr["Kp[1]"], vr["torque_cmd_B[1]"]
    d.set_real([w1], [0.1])
    assert d.get_real([out])[0] < 0
    for _ in range(3):  # parameter changes rebuild the model
        d.set_real([kp1], [0.0])
        assert d.get_real([out])[0] == 0.0
        d.set_real([kp1], [100.0])
        assert d.get_real([out])[0] < 0
    saved = d._get_fmu_state()
    d.set_real([w1], [-0.1])
    assert d.get_real([out])[0] > 0
    d._set_fmu_state(saved)
    assert d.get_real([out])[0] < 0


def test_get_and_set_plans_give_what_each_value_reference_asks():
    """The wrappers' get and set plans (neighbor_fmu_support): array elements in any order and
    repeated, a parameter among them, a list asked for again (the plan is kept), a Boolean asked
    for as Real (pythonfmu's error), inputs with a parameter in one set (the checking path), and an
    empty set that changes nothing."""
    import sys

    from build_fmus import FMU_SOURCES

    sys.path.insert(0, str(FMU_SOURCES))
    from neighbor_rigid_body import RigidBody
    from pythonfmu.variables import Real

    body = RigidBody(instance_name="b")
    vr = {v.name: v.value_reference for v in body.vars.values()}
    body.set_real([vr["q0[1]"], vr["q0[4]"]], [0.6, 0.8])
    body.set_real([vr["omega0[3]"]], [0.25])
    ask = [vr["q_BN[4]"], vr["omega_BN_B[3]"], vr["q_BN[1]"], vr["q_BN[4]"], vr["max_substep"], vr["q_BN[2]"]]
    for _ in range(2):
        assert body.get_real(ask) == [0.8, 0.25, 0.6, 0.8, 0.005, 0.0]
        assert body.get_real(tuple(ask)) == [0.8, 0.25, 0.6, 0.8, 0.005, 0.0]
    assert all(type(x) is float for x in body.get_real(ask))
    # each array whole and in order, a scalar between them: each getter called once (the usual plan)
    ordered = tuple([vr[f"q_BN[{i}]"] for i in (1, 2, 3, 4)] + [vr["max_substep"]]
                    + [vr[f"omega_BN_B[{i}]"] for i in (1, 2, 3)])
    for _ in range(2):
        assert body.get_real(ordered) == [0.6, 0.0, 0.0, 0.8, 0.005, 0.0, 0.0, 0.25]
    assert body._get_plans[Real][ordered][1] is None and body._get_plans[Real][tuple(ask)][1] is not None
    body.set_real([vr["torque_B[2]"], vr["max_substep"], vr["torque_B[1]"]], [0.5, 0.001, -0.5])
    assert body.values["max_substep"] == 0.001 and body.get_real([vr["torque_B[1]"], vr["torque_B[2]"]]) == [-0.5, 0.5]
    with pytest.raises(TypeError, match="is not of type Real"):  # a Boolean asked for as Real: pythonfmu says so
        body.get_real([vr["euler0_from_q0"]])
    version = body._input_version
    body.set_real([], [])
    assert body._input_version == version


def _retyped_element_names(script):
    """Lines where a wrapper spells FMI element names itself (f"x[{i}]" or "x[1]") instead of
    taking them from the declaration that made them (input_array etc. return their names)."""
    tree = ast.parse(script.read_text(), str(script))
    lines = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.JoinedStr):
            parts = node.values
            if any(isinstance(a, ast.Constant) and str(a.value).endswith("[") and isinstance(b, ast.FormattedValue)
                   for a, b in zip(parts, parts[1:])):
                lines.add(node.lineno)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and re.fullmatch(
                r"\w+\[\d+(,\d+)?\]", node.value):
            lines.add(node.lineno)
    return sorted(lines)


def test_wrappers_take_declared_names_from_their_declarations():
    found = {s.stem: _retyped_element_names(s) for s in wrapper_scripts()}
    support = build_fmus.FMU_SOURCES / "neighbor_fmu_support.py"
    assert _retyped_element_names(support) == [], "the support module takes element names from components.core.names"
    offenders = {name: lines for name, lines in found.items() if lines}
    assert offenders == {}, f"wrappers that retype declared names (file: lines): {offenders}"


def test_every_real_parameter_of_every_fmu_refuses_nan_and_inf(fmu_paths, tmp_path, capsys):
    """Issue 30: a NaN or infinite parameter (q0, valid_sigma, ...) was taken and turned the
    outputs to NaN. Every Real parameter of every FMU now refuses it with fmi2Error and a message
    naming the parameter, keeps its value, and the FMU then initializes and steps with finite
    outputs. (FMPy raises FMICallException on fmi2Error and prints the FMU's messages.)"""
    from fmpy.fmi1 import FMICallException

    tried = 0
    for name, path in sorted(fmu_paths.items()):
        md = fmpy.read_model_description(str(path))
        params = [v for v in md.modelVariables if v.causality == "parameter" and v.type == "Real"]
        outputs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        fmu, _ = instantiate(path, tmp_path, name)
        try:
            fmu.enterInitializationMode()  # a get is allowed from initialization mode on (FMI 2.0 4.2.4)
            for v in params:
                before = fmu.getReal([v.valueReference])
                for bad in (math.nan, math.inf, -math.inf):
                    with pytest.raises(FMICallException):
                        fmu.setReal([v.valueReference], [bad])
                    assert f"parameter {v.name} = {bad!r}: expected a finite number" in capsys.readouterr().out
                    tried += 1
                assert fmu.getReal([v.valueReference]) == before, f"{name}.{v.name} changed"
            fmu.exitInitializationMode()
            fmu.doStep(0.0, 0.01)
            assert all(math.isfinite(x) for x in fmu.getReal(outputs)), name
        finally:
            fmu.terminate()
            fmu.freeInstance()
    assert tried > 300, tried


@pytest.mark.parametrize("name, bad", [("mass", -12.0), ("edge_b", -0.1), ("gyro_sigma", -5.5e-4),
                                       ("gyro_sample_time", -0.1), ("gyro_sample_time", 0.0)])
def test_rcs_thruster_set_refuses_values_no_detection_can_use(fmu_paths, tmp_path, capsys, name, bad):
    """Issue 54: a negative mass, box edge, gyro noise or sample time was taken silently while the
    fault detection was off (and failed only once it was on). Refused at initialization, naming
    the parameter, whatever the options."""
    from fmpy.fmi1 import FMICallException

    fmu, refs = instantiate(fmu_paths["RcsThrusterSet"], tmp_path, "thrusters")
    vr = refs[name]
    try:
        fmu.enterInitializationMode()
        fmu.setReal([vr], [bad])
        with pytest.raises(FMICallException):
            fmu.exitInitializationMode()
        assert f"{name} = {bad!r}" in capsys.readouterr().out
    finally:
        fmu.freeInstance()


def test_processes_compiling_the_runtime_at_once_all_get_it(tmp_path):
    """Issue 54: two pytest-xdist workers of a fresh clone compiled the runtime into the same
    build/runtime/<digest>/ with one temporary name, and one failed ('No such file or directory:
    neighbor_fmi2.so.tmp'). Each process now compiles to a name of its own and replaces the target
    whole."""
    import subprocess
    import sys

    code = "import sys; from system_ssp import builder; print(builder.compile_runtime(sys.argv[1], 2)['linux64'])"
    procs = [subprocess.Popen([sys.executable, "-c", code, str(tmp_path)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(4)]
    results = [p.communicate(timeout=300) + (p.returncode,) for p in procs]
    assert all(rc == 0 for _, _, rc in results), [err[-500:] for _, err, _ in results]
    assert (tmp_path / "neighbor_fmi2.so").is_file()
    assert not list(tmp_path.glob("*.tmp"))
