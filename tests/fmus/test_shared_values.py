"""Values shared with the runtime (issue 27, item 1): the wrappers that call share_values() keep
their inputs and outputs in an array the binary reads and writes without entering Python.

- A wrapper's own publish (a compiled call or one write) writes exactly what its getters define,
  after steps and after inputs changed without a step, over every option of the model.
- Through the binary (FMPy loading the built FMU): an output that depends on an input follows it
  without a step; a parameter set in initialization changes the outputs; a reset gives the
  initial outputs again in new arrays; a value reference of the wrong type is still an error; the
  values equal the Python object's bit for bit; FMI 3.0's arrays cross the same way.
"""
import math

import fmpy
from fmpy.fmi3 import FMU3Slave
import numpy as np
import pytest

import build_fmus
from build_fmus import wrapper_scripts
from components.attitude import thruster_control
from fmu_helpers import instantiate
from system_ssp import builder

LEVELS = thruster_control.pair_torques()  # x, y, z pair torques (they differ in the last bit)
LEVEL = LEVELS[0]
SETTERS = {float: "set_real", bool: "set_boolean", int: "set_integer", str: "set_string"}


def _slave(name, parameters):
    """A wrapper object of FMU `name` (the class inside the FMU), initialized with `parameters`."""
    cls = builder._import_wrapper(build_fmus.FMU_SOURCES / f"neighbor_{_snake(name)}.py")
    slave = cls(instance_name=name, resources=str(builder.FMU_SOURCES))
    slave.setup_experiment(0.0, 100.0)
    slave.enter_initialization_mode()
    _set(slave, parameters)
    slave.exit_initialization_mode()
    return slave


def _snake(name):
    return "".join("_" + c.lower() if c.isupper() else c for c in name).lstrip("_")


def _set(slave, values):
    vr = {var.name: r for r, var in slave.vars.items()}
    for name, value in values.items():
        getattr(slave, SETTERS[type(value)])([vr[name]], [value])


def _rigid_body_inputs(rng, k):
    v = {f"torque_B[{i}]": float(rng.choice([-1.0, 0.0, 1.0]) * LEVEL) for i in (1, 2, 3)}
    v.update({f"wheel_torque_B[{i}]": float(rng.uniform(-1e-4, 1e-4)) for i in (1, 2, 3)})
    v.update({f"wheel_momentum_B[{i}]": float(rng.uniform(-1e-3, 1e-3)) for i in (1, 2, 3)})
    v.update(propellant_used=2e-4 * k, rcs_propellant=5e-5 * k)
    return v


def _detumble_inputs(rng, k):
    scale = 0.2 if k < 100 else 1e-4  # tumbling, then inside the tolerance so the settle count runs
    v = {f"omega_BN_B[{i}]": float(rng.uniform(-scale, scale)) for i in (1, 2, 3)}
    v.update({f"omega_dot_BN_B[{i}]": float(rng.uniform(-0.01, 0.01)) for i in (1, 2, 3)})
    v["enabled"] = bool(k % 37 != 5)
    return v


def _thruster_inputs(rng, k):
    return {f"torque_cmd_B[{i}]": float(rng.choice([-1.0, 0.0, 1.0]) * LEVEL + rng.uniform(-0.6, 0.6) * LEVEL)
            for i in (1, 2, 3)}


def _unit(rng, n):
    v = rng.normal(size=n)
    return (v / np.linalg.norm(v)).tolist()


def _gyro_inputs(rng, k):
    return {f"omega_BN_B[{i}]": float(x) for i, x in enumerate(rng.uniform(-0.3, 0.3, 3), 1)}


def _attitude_and_position(rng, k):
    v = {f"q_BN[{i}]": x for i, x in enumerate(_unit(rng, 4), 1)}
    r = [0.0, 0.0, 0.0] if k % 23 == 11 else (6.8e6 * np.array(_unit(rng, 3))).tolist()  # a zero position: invalid
    v.update({f"r_BN_N[{i}]": x for i, x in enumerate(r, 1)})
    return v


def _sun_sensor_inputs(rng, k):
    v = _attitude_and_position(rng, k)
    v.update({f"r_SN_N[{i}]": x for i, x in enumerate((1.496e11 * np.array(_unit(rng, 3))).tolist(), 1)})
    v["sunlit"] = bool(k % 17 != 3)
    return v


def _selector_inputs(rng, k):
    active = ("detumble", "slew", "tracking", None)[k % 4]
    v = {}
    for name in ("detumble", "slew", "tracking"):
        v.update({f"torque_cmd_{name}_B[{i}]": float(rng.uniform(-LEVEL, LEVEL)) for i in (1, 2, 3)})
        v[f"{name}_enable"] = name == active
    return v


def _disturbance_inputs(rng, k):
    v = _sun_sensor_inputs(rng, k)
    del v["sunlit"]
    v.update({f"r_BN_N[{i}]": x for i, x in enumerate((6.8e6 * np.array(_unit(rng, 3))).tolist(), 1)})
    v["sunlit_fraction"] = float(rng.choice([0.0, 1.0, rng.uniform(0.0, 1.0)]))
    v["density"] = float(10 ** rng.uniform(-14, -10))
    v.update({f"v_BN_N[{i}]": 7600.0 * x for i, x in enumerate(_unit(rng, 3), 1)})
    v.update({f"B_N[{i}]": 3e-5 * x for i, x in enumerate(_unit(rng, 3), 1)})
    v.update({f"center_of_mass_B[{i}]": float(x) for i, x in enumerate(rng.uniform(-0.01, 0.01, 3), 1)})
    return v


def _tracking_inputs(rng, k):
    v = {f"q_BN[{i}]": x for i, x in enumerate(_unit(rng, 4), 1)}
    v.update({f"omega_BN_B[{i}]": float(x) for i, x in enumerate(rng.uniform(-0.01, 0.01, 3), 1)})
    v["enabled"] = bool(k % 41 < 30)  # disabled for a while: the latched q_d released
    if k % 7 == 0:  # the guidance's target moves every few steps (and is held in between)
        v.update({f"q_target_BN[{i}]": x for i, x in enumerate(_unit(rng, 4), 1)})
        v.update({f"omega_target_B[{i}]": float(x) for i, x in enumerate(rng.uniform(-2e-3, 2e-3, 3), 1)})
    v.update({f"sigma_attitude_B[{i}]": float(x) for i, x in enumerate(rng.uniform(0.0, 3e-3, 3), 1)})
    return v


# FMU -> [(parameters, inputs(rng, step))]: every model option a wrapper's publish must follow
SCENARIOS = {
    "TrackingController": [
        ({}, _tracking_inputs),
        ({"target_from_input": True, "knowledge_sigmas": 3.0, "impulse_bits": 1.0, "rate_sigma": 1e-4},
         _tracking_inputs),
        ({"q_d_from_measured": False, "q_d0[1]": 0.1, "q_d0[4]": 0.99, "target_from_input": True, "k": 0.7,
          "G[2]": 0.2, "e[3]": 0.002, "omega_dot_d[1]": 1e-5}, _tracking_inputs),
    ],
    "DisturbanceTorques": [({}, _disturbance_inputs),
                           ({"aerodynamic": False, "residual_dipole": False, "inertia_from_box": False,
                             "inertia_B[1,1]": 0.1, "inertia_B[2,2]": 0.2, "inertia_B[3,3]": 0.25,
                             "facet_area[12]": 0.05, "facet_normal_B[12,1]": 0.0, "facet_normal_B[12,3]": 1.0,
                             "facet_centre_B[12,3]": 0.3, "facet_specular[12]": 0.5}, _disturbance_inputs)],
    "RigidBody": [
        ({"integrator": "euler", "omega0[1]": 0.17, "omega0[2]": -0.1}, _rigid_body_inputs),
        ({"integrator": "rk4", "q0[1]": 0.3, "q0[4]": 0.9, "omega0[3]": 0.2, "inertia_error[1]": 0.1,
          "inertia_error[3]": -0.05, "propellant_mass_properties": True}, _rigid_body_inputs),
        ({"integrator": "rk4", "max_substep": 0.004, "inertia_from_box": False, "inertia_B[1,1]": 0.1,
          "inertia_B[2,2]": 0.12, "inertia_B[3,3]": 0.15, "inertia_B[1,2]": 0.002, "inertia_B[2,1]": 0.002,
          "euler0_from_q0": False, "euler0[2]": 0.4}, _rigid_body_inputs),
    ],
    "DetumbleController": [
        ({}, _detumble_inputs),
        ({"signed_stop_test": True, "settle_time": 0.045, "omega_d[2]": 1e-4}, _detumble_inputs),
    ],
    "RcsThrusters": [({}, _thruster_inputs), ({"edge_a": 0.2, "thrust": 0.03, "Isp": 60.0}, _thruster_inputs)],
    "Gyro": [({"seed": 3, "bias[2]": 1e-3}, _gyro_inputs),
             ({"seed": 4, "sigma_sample_time": 0.1, "bias_jump[1]": 2e-3, "jump_time": 1.0}, _gyro_inputs)],
    "HorizonSensor": [({"seed": 5, "sigma": 0.01}, _attitude_and_position)],
    "SunSensor": [({"seed": 6}, _sun_sensor_inputs),
                  ({"seed": 7, "boresight_B[3]": 1.0, "boresight_B[1]": 0.0, "half_fov": 1.2, "failed": True,
                    "fail_time": 2.0}, _sun_sensor_inputs)],
    "TorqueSelector": [({}, _selector_inputs)],
}




def _propulsion_inputs(rng, k):
    return {"burn_enable": bool(k % 50 < 35), "rcs_propellant": 2e-6 * k, "axial_off_time": 0.004 * (k // 3)}


def _manager_inputs(rng, k):
    v = {name: bool(rng.random() < p) for name, p in (
        ("heartbeat", 0.3), ("ground_contact", 0.5), ("ground_command", 0.5), ("detumble_done", 0.2),
        ("slew_done", 0.2), ("budget_spent", 0.05), ("reentered", 0.005), ("attitude_valid", 0.7))}
    v["state_of_charge"] = float(rng.uniform(0.05, 1.0))
    return v


def _thruster_set_inputs(rng, k):
    v = _thruster_inputs(rng, k)
    v.update({f"omega_meas_B[{i}]": float(x) for i, x in enumerate(rng.uniform(-0.02, 0.02, 3), 1)})
    v["axial_firing"] = bool(k % 60 >= 30)
    v["propellant_used"] = 1e-4 * k
    return v


def _estimator_inputs(rng, k):
    """A body turning slowly, seen by noisy nadir and Sun vectors (now and then invalid), and the gyro."""
    angle = 0.002 * k
    q = [0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)]
    A = np.array([[math.cos(angle), math.sin(angle), 0.0], [-math.sin(angle), math.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    r, sun = np.array([6.8e6, 0.0, 0.0]), np.array([0.3, 0.9, 0.3]) * 1.496e11
    nadir_B = A @ (-r / np.linalg.norm(r)) + rng.normal(0.0, 0.004, 3)
    sun_B = A @ (sun / np.linalg.norm(sun)) + rng.normal(0.0, 0.003, 3)
    v = {f"q_true_BN[{i}]": x for i, x in enumerate(q, 1)}
    v.update({f"omega_true_B[{i}]": x for i, x in enumerate((0.0, 0.0, 0.002 / 0.015), 1)})
    v.update({f"omega_meas_B[{i}]": float(x) for i, x in enumerate(rng.normal((0.0, 0.0, 0.002 / 0.015), 5e-4), 1)})
    v.update({f"nadir_B[{i}]": float(x) for i, x in enumerate(nadir_B / np.linalg.norm(nadir_B), 1)})
    v.update({f"sun_B[{i}]": float(x) for i, x in enumerate(sun_B / np.linalg.norm(sun_B), 1)})
    v.update({f"r_BN_N[{i}]": float(x) for i, x in enumerate(r, 1)})
    v.update({f"r_SN_N[{i}]": float(x) for i, x in enumerate(sun, 1)})
    v["nadir_valid"], v["sun_valid"] = bool(k % 13 != 7), bool(k % 29 < 20)
    v.update({f"torque_cmd_B[{i}]": float(rng.choice([-1.0, 0.0, 1.0]) * LEVEL) for i in (1, 2, 3)})
    return v


# FMU -> ([(parameters, inputs(rng, step))], step size): the wrappers that share only their inputs
# (share_values(outputs=False): their outputs are getters evaluated when read, as a step would
# publish many more than a master reads)
INPUTS_SHARED = {
    "Propulsion": ([({}, _propulsion_inputs), ({"propellant_budget": 5e-3}, _propulsion_inputs)], 1.0),
    "MissionManager": ([({"initial_mode": 5, "attitude_determination_duration": 1.0, "detumble_timeout": 3.0,
                          "slew_timeout": 3.0}, _manager_inputs),
                        ({"grace_period": 86400.0}, _manager_inputs)], 0.25),
    "RcsThrusterSet": ([({}, _thruster_set_inputs),
                        ({"min_on_time": 0.04, "off_pulsing": True, "force_error[3]": 0.1, "misalignment_1[14]": 0.05,
                          "propellant_mass_properties": True}, _thruster_set_inputs),
                        ({"stuck_thruster": 6, "stuck_on": True, "stuck_time": 0.3, "fault_detection": True},
                         _thruster_set_inputs)], 0.015),
    "AttitudeEstimator": ([({}, _estimator_inputs), ({"fault_window": 20, "use_coarse_sun": True}, _estimator_inputs),
                           ({"truth_feedback": True}, _estimator_inputs)], 0.015),
}

# every output depends on inputs, which a master sets after the step: the step leaves them stale
PUBLISHED_WHEN_READ = ("TrackingController",)


def _sharing_wrappers():
    names = []
    for script in wrapper_scripts():
        cls = builder._import_wrapper(script)
        if cls(instance_name="probe", resources=str(builder.FMU_SOURCES)).shared is not None:
            names.append(cls.__name__)
    return sorted(names)


def _generic_publish(slave):
    """The outputs as the getters define them (NeighborSlave.publish), leaving the slave as it was."""
    base = next(klass for klass in type(slave).__mro__ if klass.__name__ == "NeighborSlave")
    assert type(slave).publish is not base.publish  # the wrapper has its own
    fast = slave.shared.copy()
    base.publish(slave)
    generic = slave.shared.copy()
    slave.shared[:] = fast
    return generic


def test_every_sharing_wrapper_has_a_scenario():
    assert _sharing_wrappers() == sorted([*SCENARIOS, *INPUTS_SHARED])
    for name in [*SCENARIOS, *INPUTS_SHARED]:
        cls = builder._import_wrapper(build_fmus.FMU_SOURCES / f"neighbor_{_snake(name)}.py")
        assert cls(instance_name="probe", resources=str(builder.FMU_SOURCES)).shares_outputs == (name in SCENARIOS)


def _outputs(slave):
    """Every output's value, read by type as a master reads them."""
    by_type = {}
    for vr, var in slave.vars.items():
        if slave.fmu_meta[var.name]["causality"] == "output":
            by_type.setdefault(type(var).__name__, []).append(vr)
    getters = {"Real": slave.get_real, "Integer": slave.get_integer, "Boolean": slave.get_boolean}
    return {kind: getters[kind](vrs) for kind, vrs in sorted(by_type.items())}


@pytest.mark.parametrize("name", sorted(INPUTS_SHARED))
def test_shared_inputs_give_the_outputs_of_inputs_kept_in_python(name, monkeypatch):
    """The same wrapper twice: sharing its inputs, and with share_values() doing nothing (every
    input in self.values, as before it shared them). Same inputs, same steps: the same outputs bit
    for bit, read after the inputs changed and after each step."""
    base = next(klass for klass in builder._import_wrapper(
        build_fmus.FMU_SOURCES / f"neighbor_{_snake(name)}.py").__mro__ if klass.__name__ == "NeighborSlave")
    scenarios, h = INPUTS_SHARED[name]
    rng = np.random.default_rng(314)
    for parameters, inputs in scenarios:
        shared = _slave(name, parameters)
        with monkeypatch.context() as m:
            m.setattr(base, "share_values", lambda self, outputs=True: None)
            kept = _slave(name, parameters)
        assert shared.shared is not None and kept.shared is None
        assert repr(_outputs(shared)) == repr(_outputs(kept)), (name, parameters)
        for k in range(200):
            values = inputs(rng, k)
            _set(shared, values)
            _set(kept, values)
            if k % 9 == 4:  # inputs changed, no step: the outputs that depend on them follow
                assert repr(_outputs(shared)) == repr(_outputs(kept)), (name, parameters, k)
            assert shared.do_step(k * h, h) and kept.do_step(k * h, h)
            assert repr(_outputs(shared)) == repr(_outputs(kept)), (name, parameters, k)


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_a_compiled_publish_writes_what_the_getters_define(name):
    rng = np.random.default_rng(271)
    for parameters, inputs in SCENARIOS[name]:
        slave = _slave(name, parameters)
        real_outputs = [vr for vr, var in slave.vars.items()
                        if slave.share_codes[vr] & 15 > 1 and type(var).__name__ == "Real"]
        for k in range(200):
            _set(slave, inputs(rng, k))
            if k % 9 == 4:  # inputs changed, no step: a get publishes (feedthrough outputs follow the inputs)
                slave.get_real(real_outputs)
                assert slave.shared.tobytes() == _generic_publish(slave).tobytes(), (name, parameters, k)
            assert slave.do_step(k * 0.015, 0.015)
            if name in PUBLISHED_WHEN_READ:
                assert not slave.share_flags[1]  # stale: the get publishes them
                slave.get_real(real_outputs)
            assert slave.share_flags[0] and slave.share_flags[1]  # the step published, or the get
            assert slave.shared.tobytes() == _generic_publish(slave).tobytes(), (name, parameters, k)


def test_a_wrapper_sharing_only_inputs_computes_its_outputs_when_read(fmu_paths, tmp_path):
    """Through the binary: the inputs are written in the shared array, and an output that depends
    on one follows it without a step, computed by its getter."""
    fmu, vr = instantiate(fmu_paths["Propulsion"], tmp_path, "propulsion", initialize=True)
    try:
        force, flow = [vr[f"F_thrust_B[{i}]"] for i in (1, 2, 3)], vr["mdot"]
        assert fmu.getReal(force + [flow]) == [0.0] * 4
        fmu.setBoolean([vr["burn_enable"]], [True])
        thrust = fmu.getReal(force + [flow])
        assert thrust[0] > 0.0 and thrust[1:3] == [0.0, 0.0] and thrust[3] > 0.0
        assert fmu.getBoolean([vr["burn_enable"], vr["burning"]]) == [True, True]
        fmu.doStep(0.0, 10.0)
        assert fmu.getReal([vr["burn_time"]]) == [10.0]
        assert fmu.getReal([vr["propellant_used"]])[0] == pytest.approx(10.0 * thrust[3], rel=1e-12)
        mass0, used = fmu.getReal([vr["mass0"], vr["propellant_used"]])
        fmu.setReal([vr["rcs_propellant"]], [0.01])  # the mass depends on it: follows without a step
        assert fmu.getReal([vr["mass"]])[0] == pytest.approx(mass0 - used - 0.01, rel=1e-15)
        fmu.setBoolean([vr["burn_enable"]], [False])
        assert fmu.getReal(force + [flow]) == [0.0] * 4
    finally:
        fmu.terminate()
        fmu.freeInstance()


def _read(fmu, vr, names):
    return fmu.getReal([vr[n] for n in names])


def test_a_feedthrough_output_follows_its_input_without_a_step(fmu_paths, tmp_path):
    fmu, vr = instantiate(fmu_paths["RcsThrusters"], tmp_path, "thr", initialize=True)
    try:
        cmd = [f"torque_cmd_B[{i}]" for i in (1, 2, 3)]
        applied = [f"torque_B[{i}]" for i in (1, 2, 3)]
        flags = [vr[f"thrust_flag[{i}]"] for i in (1, 2, 3)]
        fmu.setReal([vr[n] for n in cmd], [LEVEL, -0.2 * LEVEL, -LEVEL])
        assert _read(fmu, vr, applied) == [LEVELS[0], 0.0, -LEVELS[2]] and fmu.getInteger(flags) == [1, 0, -1]
        fmu.setReal([vr[n] for n in cmd], [0.0, 0.9 * LEVEL, 0.0])
        assert _read(fmu, vr, applied) == [0.0, LEVELS[1], 0.0] and fmu.getInteger(flags) == [0, 1, 0]
        assert _read(fmu, vr, ["fire_time[2]"]) == [0.0]
        fmu.doStep(0.0, 0.015)
        assert _read(fmu, vr, ["fire_time[2]", "fire_time_total"]) == [0.015, 0.015]
        with pytest.raises(Exception, match="fmi2GetReal"):  # an Integer's value reference: an error, as before
            fmu.getReal(flags)
        with pytest.raises(Exception, match="fmi2SetInteger"):
            fmu.setInteger([vr[cmd[0]]], [1])
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_parameters_and_reset_renew_the_shared_outputs(fmu_paths, tmp_path):
    fmu, vr = instantiate(fmu_paths["RigidBody"], tmp_path, "body")
    q = [f"q_BN[{i}]" for i in (1, 2, 3, 4)]
    try:
        fmu.enterInitializationMode()
        assert _read(fmu, vr, q) == [0.0, 0.0, 0.0, 1.0]
        fmu.setReal([vr["q0[1]"], vr["q0[4]"]], [1.0, 1.0])  # a parameter: the outputs are stale
        assert _read(fmu, vr, q) == [1 / math.sqrt(2), 0.0, 0.0, 1 / math.sqrt(2)]
        fmu.exitInitializationMode()
        fmu.setReal([vr["torque_B[3]"]], [LEVEL])
        for k in range(5):
            fmu.doStep(k * 0.015, 0.015)
        assert _read(fmu, vr, ["omega_BN_B[3]"])[0] > 0.0
        fmu.reset()  # a new slave object's arrays: the binary must read those, not the old ones
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        assert _read(fmu, vr, q + ["omega_BN_B[3]", "torque_B[3]"]) == [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]
        fmu.setReal([vr["torque_B[1]"]], [LEVEL])
        fmu.doStep(0.0, 0.015)
        assert _read(fmu, vr, ["omega_BN_B[1]"])[0] > 0.0
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_the_binary_gives_the_python_objects_bits(fmu_paths, tmp_path):
    parameters = SCENARIOS["RigidBody"][1][0]
    slave = _slave("RigidBody", parameters)
    fmu, vr = instantiate(fmu_paths["RigidBody"], tmp_path, "body")
    try:
        fmu.enterInitializationMode()
        for name, value in parameters.items():
            if isinstance(value, str):
                fmu.setString([vr[name]], [value])
            elif isinstance(value, bool):
                fmu.setBoolean([vr[name]], [value])
            else:
                fmu.setReal([vr[name]], [value])
        fmu.exitInitializationMode()
        outputs = [vr for vr, var in slave.vars.items() if slave.fmu_meta[var.name]["causality"] == "output"]
        rng = np.random.default_rng(5)
        for k in range(150):
            inputs = _rigid_body_inputs(rng, k)
            _set(slave, inputs)
            fmu.setReal([vr[n] for n in inputs], list(inputs.values()))
            slave.do_step(k * 0.015, 0.015)
            fmu.doStep(k * 0.015, 0.015)
            assert fmu.getReal(outputs) == slave.get_real(outputs), k
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_fmi3_arrays_cross_through_the_shared_values(fmu3_paths, fmu_paths, tmp_path):
    """FMI 3.0 names an array by its first element's value reference: the binary expands it over
    the shared values as the loader does, and the values are the FMI 2.0 FMU's."""
    md = fmpy.read_model_description(str(fmu3_paths["RcsThrusters"]))
    folder = fmpy.extract(str(fmu3_paths["RcsThrusters"]), str(tmp_path / "thr3"))
    fmu3 = FMU3Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                     instanceName="thr3")
    fmu3.instantiate()
    fmu2, vr2 = instantiate(fmu_paths["RcsThrusters"], tmp_path, "thr2", initialize=True)
    vr3 = {v.name: v.valueReference for v in md.modelVariables}
    try:
        fmu3.enterInitializationMode(startTime=0.0)
        fmu3.exitInitializationMode()
        rng = np.random.default_rng(3)
        for k in range(40):
            cmd = _thruster_inputs(rng, k)
            fmu3.setFloat64([vr3["torque_cmd_B"]], list(cmd.values()))
            fmu2.setReal([vr2[n] for n in cmd], list(cmd.values()))
            applied = fmu3.getFloat64([vr3["torque_B"]], nValues=3)  # before the step: feedthrough
            assert applied == fmu2.getReal([vr2[f"torque_B[{i}]"] for i in (1, 2, 3)])
            assert fmu3.getInt32([vr3["thrust_flag"]], nValues=3) == fmu2.getInteger(
                [vr2[f"thrust_flag[{i}]"] for i in (1, 2, 3)])
            fmu3.doStep(k * 0.015, 0.015)
            fmu2.doStep(k * 0.015, 0.015)
            assert fmu3.getFloat64([vr3["fire_time"], vr3["propellant_mass"]], nValues=4) == fmu2.getReal(
                [vr2[f"fire_time[{i}]"] for i in (1, 2, 3)] + [vr2["propellant_mass"]])
        assert fmu3.getFloat64([vr3["fire_time_total"]])[0] > 0.0
    finally:
        for fmu in (fmu3, fmu2):
            fmu.terminate()
            fmu.freeInstance()


def test_an_output_the_inputs_cannot_give_fails_where_it_is_read(fmu_paths, tmp_path):
    """Two controllers enabled at once: the selector's step goes on and the read of its command is
    the error, as before its values were shared (the step publishes, the failure waits for the get)."""
    fmu, vr = instantiate(fmu_paths["TorqueSelector"], tmp_path, "selector", initialize=True)
    try:
        fmu.setBoolean([vr["detumble_enable"], vr["slew_enable"]], [True, True])
        fmu.doStep(0.0, 0.015)
        with pytest.raises(Exception, match="fmi2GetReal"):
            fmu.getReal([vr["torque_cmd_B[1]"]])
        fmu.setBoolean([vr["slew_enable"]], [False])
        fmu.setReal([vr["torque_cmd_detumble_B[2]"]], [LEVEL])
        assert fmu.getReal([vr[f"torque_cmd_B[{i}]"] for i in (1, 2, 3)]) == [0.0, LEVEL, 0.0]
    finally:
        fmu.terminate()
        fmu.freeInstance()
