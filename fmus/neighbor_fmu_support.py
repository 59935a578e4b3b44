"""Shared base class for the product's pythonfmu wrappers.

Bundled into every FMU next to the wrapper script (its module name is product-specific so
that it cannot collide with another vendor's helper in the same process).

A wrapper declares its variables with `parameter`, `input`, `output` (or the `*_array`
forms, which give FMI structured names `name[1]`..`name[n]`), each with a unit and a
description. The declarations also record what pythonfmu cannot write itself: the unit, the
direct dependencies of each output on inputs, and whether the FMU restores its full state.
`build_fmus.py` reads that record (`fmu_meta`) to complete modelDescription.xml.

Values live in `self.values` (name -> value). Parameters rebuild the model lazily: setting
one drops the current model, and the next access of `self.model` builds a fresh one from
the parameter values through `build_model()`, which the wrapper implements. Outputs are
getters, so an output that depends directly on inputs is recomputed from the inputs as they
are when it is read (true direct feedthrough, as FMI co-simulation masters expect).

A wrapper may share its inputs and outputs with the FMU's binary instead (`share_values`): they
then live in one array the binary reads and writes without entering Python, and the wrapper
publishes its outputs into it (see the section "values shared with the runtime" below).
"""
import copy
import math
import os
import sys
from collections import OrderedDict
from operator import itemgetter
from typing import Any, Callable, Iterable, NamedTuple, Optional, Sequence, Union

import numpy as np
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Variability
from pythonfmu.fmi2slave import Fmi2Slave
from pythonfmu.variables import Boolean, Integer, Real, String

from components.core import jit
from components.core.names import Names, element_names, matrix_names
from components.mission.neighbor import SPACECRAFT

_TYPES = {float: Real, int: Integer, bool: Boolean, str: String}
_KINDS = {cls: kind for kind, cls in _TYPES.items()}
Scalar = Union[float, int, bool, str]
# Values shared with the runtime (share_values): a variable's code is its role | its kind << 4
# (kinds 0 Real, 1 Integer, 2 Boolean, the runtime's numbers); the flags say which outputs in the
# array are current. neighbor_core.c carries the same numbers.
SHARED_INPUT, SHARED_STATE_OUTPUT, SHARED_FEEDTHROUGH_OUTPUT = 1, 2, 3
FRESH_STATE, FRESH_FEEDTHROUGH = 0, 1
_SHARED_KINDS = {Real: 0, Integer: 1, Boolean: 2}
# "0": never a native step (arm_native), every step through Python (the tests and benchmarks compare)
NATIVE = os.environ.get("NEIGHBOR_COSIM_NATIVE", "") != "0"
# The moving-target inputs of the RCS controller family (declared by `target_inputs`), named here
# once because a controller's outputs depend on them before they are declared.
TARGET_INPUTS = element_names("q_target_BN", 4) + element_names("omega_target_B", 3)


class ControllerSignals(NamedTuple):
    """What `thruster_controller_interface` declares, by connector."""
    q_BN: Names
    omega_BN_B: Names
    omega_dot_BN_B: Names
    enabled: str
    torque_cmd_B: Names
    thrust_flag: Names
    done: str


class AttitudeMeasurementSignals(NamedTuple):
    """What `attitude_measurement_inputs` declares: the vector measurements with their validity
    and reference positions (what a TRIAD fix reads), and the gyro rate."""
    vectors: Names
    rate: Names


def _picker(indices):
    """f(vector) -> the elements at `indices`, as a sequence."""
    if len(indices) == 1:
        i = indices[0]
        return lambda vector: (vector[i],)
    return itemgetter(*indices)


_SHARED = object()  # marks a get or set plan served by the shared array


def in_this_extraction(path, module, resources):
    """`path`, a file of the FMU's bundled `module`, in this instance's extraction of the FMU:
    every instance gets its own `resources` folder, while the module may have been imported from
    an earlier extraction of the same build that is gone by now. Unchanged outside an FMU."""
    parts = module.__name__.split(".")
    if not resources or not __package__ or parts[0] != __package__.split(".")[0]:
        return path
    relative = os.path.relpath(path, os.path.dirname(os.path.abspath(module.__file__)))
    return os.path.join(resources, *parts[:-1], relative)


class ParameterError(ValueError):
    """A parameter or input value outside its allowed range (message names the variable)."""


class _Variables(OrderedDict):
    """pythonfmu's value reference -> variable table, with a clear error for a value reference
    the code does not declare (a model description from another build)."""

    def __missing__(self, vr):
        raise ValueError(f"value reference {vr} is not a variable of this FMU's code (it declares 0..{len(self) - 1}): "
                         "the modelDescription.xml does not come from the same build as the code")


class NeighborSlave(Fmi2Slave):
    author = "neighbor-cosim"
    license = "MIT"
    version = "0.2.0"  # build_fmus.py sets the product version (system_ssp.__version__)
    # A wrapper whose get_state/set_state capture the whole model sets this True.
    can_get_and_set_state = True

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.vars = _Variables(self.vars)
        self.values = {}
        self.fmu_meta = {}
        self._model = None
        self._input_version = 0
        self._model_generation = 0  # counts model builds: a cache key that is never reused
        self._vector_keys = {}
        self._feedthrough_cache = {}  # compute's name -> (input version and model generation, its value)
        self.start_time = 0.0  # from fmi2SetupExperiment; models that keep time start there
        self._accessors = {}  # (type, "getter" or "setter") -> {value reference: function}
        self._input_names = {}  # type -> {value reference: name} of the inputs
        self._input_vrs = {}  # input name -> value reference
        self._array_elements = {}  # value reference of an array output's element -> (vector getter, index)
        self._get_plans = {cls: {} for cls in _KINDS}  # type -> {value references: plan (_get_plan)}
        self._set_plans = {cls: {} for cls in _KINDS}  # type -> {value references: input names or None}
        self.shared = None  # share_values: every Real/Integer/Boolean input and output by value reference
        self.shares_outputs = False
        self.share_native = None  # share_values: the native step's two slots (arm_native)
        self._native_arrays = self._native_context = None

    # ---- the FMI get and set calls ----------------------------------------------------------
    # pythonfmu's own look up each variable and check its type on every call. Ours follow a plan
    # made at the first call with a given list of value references (a master asks for the same
    # list at every step; our runtime passes it as the same tuple): a get calls each array
    # output's vector getter once and picks its elements, a set of inputs stores them in one
    # update. Anything a plan cannot serve falls back to pythonfmu's, so its errors stay the same.
    def _accessor_table(self, cls, what):
        table = self._accessors.get((cls, what))
        if table is None:
            table = self._accessors[(cls, what)] = {
                vr: getattr(var, what) for vr, var in self.vars.items()
                if isinstance(var, cls) and getattr(var, what) is not None}
        return table

    def _get_plan(self, cls, key):
        """The plan of a get of the value references `key`, or None when one of them has no getter
        of type cls: ([(getter, picker of its elements or None for a scalar)], None) when each
        getter is read in one run of elements (the usual list: each array in order), else
        (vector getters, [(index into them, picker or None)])."""
        getters = self._accessor_table(cls, "getter")
        sources, slots, runs = [], {}, []
        for vr in key:
            element = self._array_elements.get(vr)
            if element is None:
                getter = getters.get(vr)
                if getter is None:
                    return None
                slots[getter] = len(sources)
                sources.append(getter)
                runs.append([len(sources) - 1, None])
                continue
            if vr not in getters:
                return None
            vector_getter, i = element
            s = slots.get(vector_getter)
            if s is None:
                s = slots[vector_getter] = len(sources)
                sources.append(vector_getter)
            if runs and runs[-1][0] == s and runs[-1][1] is not None:
                runs[-1][1].append(i)  # the next element of the same vector
            else:
                runs.append([s, [i]])
        picked = [(s, None if idx is None else _picker(idx)) for s, idx in runs]
        if len(runs) == len(sources):  # then the runs are in the order of their getters
            return [(sources[s], pick) for s, pick in picked], None
        return sources, picked

    def _get(self, cls, kind, vrs, fallback):
        key = vrs if type(vrs) is tuple else tuple(vrs)
        plans = self._get_plans[cls]
        plan = plans.get(key, False)
        if plan is False:
            plan = plans[key] = self._shared_plan(cls, key) or self._get_plan(cls, key)
        if plan is None:
            return fallback(self, vrs)
        if plan[0] is _SHARED:  # the values the runtime reads too, published when stale
            _, index, needs = plan
            flags = self.share_flags
            if not all(flags[f] for f in needs):
                self.publish()
            return list(map(kind, self.shared[index].tolist()))
        if self.shared is not None:
            self.count_shared_inputs()
        return self._values_of_plan(plan, kind)

    def _values_of_plan(self, plan, kind):
        """The values of a get plan (_get_plan) from the variables' getters."""
        sources, runs = plan
        out: list = []
        if runs is None:  # each getter called once, in order, and its elements taken
            for get, pick in sources:
                if pick is None:
                    out.append(get())
                else:
                    out.extend(pick(get()))
            return list(map(kind, out))
        vectors = [get() for get in sources]
        for s, pick in runs:
            if pick is None:
                out.append(vectors[s])
            else:
                out.extend(pick(vectors[s]))
        return list(map(kind, out))

    def _set(self, cls, vrs, values, fallback):
        # inputs are stored in place in one update (no setter call per value: the mission sets
        # millions); a parameter goes through its setter, which checks it and drops the model
        key = vrs if type(vrs) is tuple else tuple(vrs)
        plans = self._set_plans[cls]
        names = plans.get(key, False)
        if names is False:
            inputs = self._input_names.get(cls, {})
            names = plans[key] = [inputs[vr] for vr in key] if all(vr in inputs for vr in key) else None
            if names and self.shared is not None:
                names = plans[key] = (_SHARED, list(key))
        if names and names[0] is _SHARED and len(values) == len(names[1]):
            self.shared[names[1]] = list(map(_KINDS[cls], values))
            self.share_flags[FRESH_FEEDTHROUGH] = 0
            return
        if names and names[0] is _SHARED:
            names = None  # a count mismatch: pythonfmu's error
        if names and len(values) == len(names):
            self.values.update(zip(names, map(_KINDS[cls], values)))
            self._input_version += 1
            return
        setters = self._accessor_table(cls, "setter")
        inputs = self._input_names.get(cls, {})
        store, kind, changed = self.values, _KINDS[cls], False
        try:
            for vr, value in zip(vrs, values):
                name = inputs.get(vr)
                if name is None:
                    setters[vr](value)
                elif self.shared is not None:
                    self.shared[vr] = kind(value)
                    self.share_flags[FRESH_FEEDTHROUGH] = 0
                else:
                    store[name] = kind(value)
                    changed = True
        except KeyError:
            fallback(self, vrs, values)
        finally:  # also when the fallback raises after some inputs were stored
            if changed:
                self._input_version += 1

    def get_real(self, vrs):
        return self._get(Real, float, vrs, Fmi2Slave.get_real)

    def get_integer(self, vrs):
        return self._get(Integer, int, vrs, Fmi2Slave.get_integer)

    def get_boolean(self, vrs):
        return self._get(Boolean, bool, vrs, Fmi2Slave.get_boolean)

    def set_real(self, vrs, values):
        self._set(Real, vrs, values, Fmi2Slave.set_real)

    def set_integer(self, vrs, values):
        self._set(Integer, vrs, values, Fmi2Slave.set_integer)

    def set_boolean(self, vrs, values):
        self._set(Boolean, vrs, values, Fmi2Slave.set_boolean)

    # ---- declarations -------------------------------------------------------------------
    def _register(self, name, kind, causality, variability, unit, description, start=None,
                  getter=None, setter=None, initial=None, depends_on=None):
        if not description:
            raise ValueError(f"variable {name!r} needs a description")
        cls = _TYPES[kind]
        kwargs = dict(causality=causality, variability=variability, description=description)
        if initial is not None:
            kwargs["initial"] = initial
        if getter is None:
            getter = lambda: self.values[name]  # noqa: E731
        var = cls(name, getter=getter, setter=setter, **kwargs)
        self.register_variable(var, nested=False)
        self.fmu_meta[name] = {
            "unit": unit if kind is float else None,
            "causality": causality.name,
            "depends_on": list(depends_on or []),
        }
        return var

    def add_dependencies(self, outputs: Iterable[str], inputs: Iterable[str]) -> None:
        """Outputs (scalars or arrays by name) declared earlier also depend directly on `inputs`
        (an input appended after them, so that the earlier value references stay)."""
        inputs = list(inputs)
        for out in outputs:
            names = [n for n in self.fmu_meta if n == out or n.startswith(out + "[")]
            if not names or any(self.fmu_meta[n]["causality"] != "output" for n in names):
                raise ValueError(f"add_dependencies: {out!r} is not a declared output")
            for n in names:
                self.fmu_meta[n]["depends_on"].extend(inputs)

    def parameter(self, name: str, start: Scalar, unit: Optional[str], description: str, kind: type = float) -> str:
        self.values[name] = kind(start)

        def setter(value, name=name):
            if kind is float and not math.isfinite(value):  # no model of ours can use a NaN or inf parameter
                raise ParameterError(f"{type(self).__name__} instance '{self.instance_name}': parameter {name} = "
                                     f"{value!r}: expected a finite number")
            self.values[name] = kind(value)
            self._drop_model()  # rebuilt from the new parameter values on next use
            self._outputs_stale()

        self._register(name, kind, Fmi2Causality.parameter, Fmi2Variability.fixed, unit, description,
                       setter=setter, initial=Fmi2Initial.exact)
        return name

    def parameter_array(self, name: str, starts: Sequence[Scalar], unit: Optional[str], description: str,
                        kind: type = float) -> Names:
        names = element_names(name, len(starts))
        for i, (element, start) in enumerate(zip(names, starts), 1):
            self.parameter(element, start, unit, f"{description} (component {i})", kind)
        return names

    def input(self, name: str, start: Scalar, unit: Optional[str], description: str, kind: type = float) -> str:
        self.values[name] = kind(start)

        def setter(value, name=name):  # pythonfmu's own calls; ours store in place (_set)
            if self.shared is not None:
                self.shared[self._input_vrs[name]] = kind(value)
                self.share_flags[FRESH_FEEDTHROUGH] = 0
                return
            self.values[name] = kind(value)
            self._input_version += 1

        variability = Fmi2Variability.continuous if kind is float else Fmi2Variability.discrete
        var = self._register(name, kind, Fmi2Causality.input, variability, unit, description,
                             getter=lambda: self.input_value(name), setter=setter)
        self._input_names.setdefault(_TYPES[kind], {})[var.value_reference] = name
        self._input_vrs[name] = var.value_reference
        return name

    def input_array(self, name: str, starts: Sequence[Scalar], unit: Optional[str], description: str,
                    kind: type = float) -> Names:
        names = element_names(name, len(starts))
        for i, (element, start) in enumerate(zip(names, starts), 1):
            self.input(element, start, unit, f"{description} (component {i})", kind)
        return names

    def output(self, name: str, getter: Callable[[], Scalar], unit: Optional[str], description: str,
               kind: type = float, depends_on: Iterable[str] = ()) -> str:
        """`depends_on`: input names this output depends on directly (feedthrough)."""
        variability = Fmi2Variability.continuous if kind is float else Fmi2Variability.discrete
        self._register(name, kind, Fmi2Causality.output, variability, unit, description,
                       getter=getter, initial=Fmi2Initial.calculated,  # _get converts to kind
                       depends_on=depends_on)
        return name

    def output_array(self, name: str, n: int, getter: Callable[[], Sequence[Scalar]], unit: Optional[str],
                     description: str, kind: type = float, depends_on: Iterable[str] = ()) -> Names:
        """`getter()` returns the whole vector; element i is output as `name[i+1]`."""
        names = element_names(name, n)

        def element(i):
            return lambda: getter()[i]

        for i, element_name in enumerate(names):
            self.output(element_name, element(i), unit, f"{description} (component {i + 1})", kind, depends_on)
            var = self.vars[len(self.vars) - 1]  # the one just registered (pythonfmu numbers them in order)
            assert var.name == element_name, (var.name, element_name)
            self._array_elements[var.value_reference] = (getter, i)
        return names

    def thruster_controller_interface(self, command: Callable[[], Any], done: Callable[[], bool],
                                      reads: Callable[[ControllerSignals], Iterable[str]],
                                      done_reads: Callable[[ControllerSignals], Iterable[str]],
                                      done_description: str) -> ControllerSignals:
        """The connectors every RCS attitude controller shares (the controller interface family:
        detumble, slew, tracking), so that a system swaps one controller for another by
        replacing a component: the attitude knowledge `q_BN[4]`, `omega_BN_B[3]`,
        `omega_dot_BN_B[3]` (each controller reads the ones its law needs), an `enabled` input
        (false: zero command), the quantized `torque_cmd_B[3]`, the pair signals `thrust_flag[3]`
        and `done`.

        `command()` returns (torque, flags) from the current inputs, `done()` the stop test;
        `reads` / `done_reads` give, from the declared connectors, the input names they read
        (their output dependencies). Returns every connector's names."""
        q = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1", "Measured attitude quaternion q_BN, scalar last")
        w = self.input_array("omega_BN_B", [0.0] * 3, "rad/s", "Measured angular velocity of B relative to N, in B")
        w_dot = self.input_array("omega_dot_BN_B", [0.0] * 3, "rad/s2",
                                 "Angular acceleration of the last step (read by laws with a derivative term)")
        enabled = self.input("enabled", True, None, "Controller enabled; when false it commands zero torque", bool)
        declared = ControllerSignals(q, w, w_dot, enabled, (), (), "")

        def gated():
            return command() if self.input_value(enabled) else ([0.0, 0.0, 0.0], [0, 0, 0])

        deps = list(reads(declared)) + [enabled]
        torque = self.output_array("torque_cmd_B", 3, lambda: self.feedthrough(gated)[0], "N.m",
                                   "Commanded body torque, quantized to +-torque_level or 0", depends_on=deps)
        flags = self.output_array("thrust_flag", 3, lambda: self.feedthrough(gated)[1], None,
                                  "Thruster pair signal per axis: 1 positive torque, -1 negative, 0 off", int,
                                  depends_on=deps)
        finished = self.output("done", lambda: self.feedthrough(done), None, done_description, bool,
                               depends_on=list(done_reads(declared)))
        return declared._replace(torque_cmd_B=torque, thrust_flag=flags, done=finished)

    def target_inputs(self, used_when: str) -> Names:
        """The moving-target inputs of the RCS controller family, `q_target_BN[4]` and
        `omega_target_B[3]` (the burn guidance's attitude and rate), declared after a controller's
        other variables so that their value references stay as they were. `used_when` says when
        this law reads them. Their names are TARGET_INPUTS."""
        q = self.input_array("q_target_BN", [0.0, 0.0, 0.0, 1.0], "1",
                             f"Target attitude quaternion q_BN, scalar last, from the guidance; {used_when}")
        w = self.input_array("omega_target_B", [0.0] * 3, "rad/s",
                             f"Target angular velocity in B, from the guidance; {used_when}")
        assert q + w == TARGET_INPUTS  # the names outputs declared earlier depend on
        return q + w

    def attitude_measurement_inputs(self) -> AttitudeMeasurementSignals:
        """The inputs of the attitude-knowledge family (AttitudeDetermination, AttitudeEstimator):
        the nadir and Sun vectors with their validity, the gyro rate, and the positions that give
        the vectors' reference directions, in this order."""
        nadir = self.input_array("nadir_B", [0.0, 0.0, 0.0], "1", "Measured nadir unit vector in B")
        nadir_valid = self.input("nadir_valid", False, None, "Nadir measurement valid", bool)
        sun = self.input_array("sun_B", [0.0, 0.0, 0.0], "1", "Measured Sun unit vector in B")
        sun_valid = self.input("sun_valid", False, None, "Sun measurement valid", bool)
        rate = self.input_array("omega_meas_B", [0.0, 0.0, 0.0], "rad/s", "Measured angular velocity in B (gyro)")
        position = self.input_array("r_BN_N", [6798137.0, 0.0, 0.0], "m", "Spacecraft position in N (e.g. GPS)")
        sun_position = self.input_array("r_SN_N", [0.0, -1.496e11, 0.0], "m", "Sun position in N (ephemeris)")
        return AttitudeMeasurementSignals(nadir + (nadir_valid,) + sun + (sun_valid,) + position + sun_position,
                                          rate)

    def inertia_parameters(self, mass_description):
        """The spacecraft inertia parameters shared by RigidBody and the controllers that use
        the inertia: mass and box edges (Eq. 4) or a full tensor inertia_B[i,j]."""
        self.parameter("mass", SPACECRAFT.mass, "kg", mass_description)
        self.parameter("edge_a", SPACECRAFT.edge_a, "m", "Box edge a along body y (Appendix A a = 0.1 m)")
        self.parameter("edge_b", SPACECRAFT.edge_b, "m", "Box edge b along body z (Appendix A b = 0.2 m)")
        self.parameter("edge_c", SPACECRAFT.edge_c, "m", "Box edge c along body x (Appendix A c = 0.3 m)")
        self.parameter("inertia_from_box", True, None,
                       "True: inertia of a uniform box from mass and edges (Eq. 4); false: use inertia_B", bool)
        for i, row in enumerate(matrix_names("inertia_B", 3, 3), 1):
            for j, element in enumerate(row, 1):
                self.parameter(element, 0.0, "kg.m2",
                               f"Inertia tensor element ({i},{j}) in B, used when inertia_from_box is false")

    def inertia(self, box_inertia):
        """The 3x3 inertia from the inertia_parameters values (box_inertia: the Eq. 4 function)."""
        v = self.values
        if v["inertia_from_box"]:
            return box_inertia(v["mass"], v["edge_a"], v["edge_b"], v["edge_c"])
        return [[v[element] for element in row] for row in matrix_names("inertia_B", 3, 3)]

    # ---- values shared with the runtime ----------------------------------------------------
    # A wrapper that calls share_values() at the end of its __init__ keeps every Real, Integer and
    # Boolean input and output in one float64 array by value reference, which the binary reads and
    # writes in memory (neighbor_core.c): fmi2Set* of inputs and fmi2Get* of fresh outputs do not
    # enter Python. The wrapper then reads its inputs with vector() or input_value() (not
    # self.values) and ends each do_step with publish_after_step(), which writes every output; an output
    # read while stale (after a parameter, a state or, for one that depends on inputs, an input
    # changed) is published first. The getters stay the outputs' definition: the generic publish
    # evaluates them, and a wrapper's faster publish must write the same values.
    def share_values(self, outputs: bool = True) -> None:
        """Keep the inputs and outputs in the shared array from now on (call it last in __init__,
        after every declaration). With `outputs` false only the inputs: the outputs stay getters
        that each get evaluates, for a model whose many outputs cost more to publish at every step
        than the few a master reads (the binary's sets still do not enter Python)."""
        n = len(self.vars)
        self.shares_outputs = outputs
        self.shared = np.zeros(n)
        self.share_codes = np.zeros(n, np.int32)
        self.share_flags = np.zeros(2, np.int32)  # FRESH_STATE, FRESH_FEEDTHROUGH
        self.share_native = np.zeros(3, np.int64)  # the step's address (0: none), its context's, a publish's
        published = {cls: [] for cls in _SHARED_KINDS}
        self._shared_inputs = {}  # input name -> (value reference, its Python type)
        for vr, var in self.vars.items():
            code = _SHARED_KINDS.get(type(var))
            if code is None:
                continue
            meta = self.fmu_meta[var.name]
            if meta["causality"] == "input":
                role = SHARED_INPUT
                # the input lives in the array only: a wrapper that still read it from self.values
                # would fail loudly rather than read its start value for ever
                self.shared[vr] = self.values.pop(var.name)
                self._shared_inputs[var.name] = (vr, _KINDS[type(var)])
            elif meta["causality"] == "output" and outputs:
                role = SHARED_FEEDTHROUGH_OUTPUT if meta["depends_on"] else SHARED_STATE_OUTPUT
                published[type(var)].append(vr)
            else:
                continue
            self.share_codes[vr] = role | code << 4
        self._vr_of = {var.name: vr for vr, var in self.vars.items()}
        self._publish_plans = [(vrs, self._get_plan(cls, tuple(vrs)), _KINDS[cls])
                               for cls, vrs in published.items() if vrs]
        self._vector_keys = {}  # input vectors now read from the array

    def publish(self) -> None:
        """Write every shared output from its getter and mark the outputs fresh (a wrapper may
        override this with a faster one that writes the same values)."""
        shared = self.shared
        self._input_version += 1  # one feedthrough computation per publish, on the inputs as they are
        for vrs, plan, kind in self._publish_plans:
            shared[vrs] = self._values_of_plan(plan, kind)
        self.mark_published()

    def publish_after_step(self) -> None:
        """The end of a sharing wrapper's do_step: publish, or when an output cannot be computed
        from the inputs as they are, leave the outputs stale so that the get that reads them
        raises the error (where it was raised before the values were shared). Nothing to do for a
        wrapper whose values are not shared (its getters compute the outputs when read)."""
        if self.shared is None or not self.shares_outputs:
            return
        try:
            self.publish()
        except Exception:
            self._outputs_stale()

    # A sharing wrapper whose step is one compiled kernel on its model's arrays may also hand the
    # binary a native step (components.core.native): the binary then calls it instead of do_step,
    # without Python. The wrapper arms it after a Python step once numba is loaded (native_ready);
    # a rebuilt model (a parameter, the experiment's setup, an FMU state) disarms it, and the next
    # Python step arms it again on the new model's arrays.
    def native_ready(self) -> bool:
        """True once numba is in the process (it is not started for a native step), unless
        NEIGHBOR_COSIM_NATIVE=0: a wrapper may then import its native steps and arm one. (For FMI
        3.0 the binary advances the loader's clock after a native step, as the loader's step does.)"""
        return NATIVE and jit.ENABLED and "numba" in sys.modules and self.share_native is not None

    def arm_native(self, step: Any, *arrays: np.ndarray, publish: Any = None) -> None:
        """From the next doStep on, the binary calls the cfunc `step` on `arrays` (kept here); and
        the cfunc `publish` (same signature and context, t and h unused), when given, where it would
        call the Python publish for a get of stale outputs."""
        from components.core import native
        self._native_arrays = arrays
        self._native_context = native.context(*arrays)
        self.share_native[1] = self._native_context.ctypes.data
        self.share_native[2] = 0 if publish is None else publish.address
        self.share_native[0] = step.address  # last: the binary reads it first

    def disarm_native(self) -> None:
        if self.share_native is not None:
            self.share_native[0] = 0  # first: the binary reads it before the context
        self._native_arrays = self._native_context = None

    def _drop_model(self) -> None:
        self._model = None
        self.disarm_native()

    def mark_published(self) -> None:
        """A wrapper's publish wrote every shared output: they are fresh."""
        self.share_flags[FRESH_STATE] = self.share_flags[FRESH_FEEDTHROUGH] = 1

    def shared_slice(self, variables: Iterable[tuple]) -> slice:
        """shared_indices(variables) as a slice, for variables declared one after the other."""
        at = self.shared_indices(variables)
        if not (np.diff(at) == 1).all():
            raise ValueError(f"{variables} are not consecutive variables")
        return slice(int(at[0]), int(at[-1]) + 1)

    def _outputs_stale(self) -> None:
        if self.shared is not None:
            self.share_flags[FRESH_STATE] = self.share_flags[FRESH_FEEDTHROUGH] = 0

    def _shared_plan(self, cls, key):
        """A get of shared variables of type cls only: (_SHARED, their indices, the flags that must
        be set), else None."""
        if self.shared is None or not key:
            return None
        code = _SHARED_KINDS.get(cls)
        needs = set()
        for vr in key:
            c = int(self.share_codes[vr]) if 0 <= vr < len(self.share_codes) else 0
            if not c or c >> 4 != code:
                return None
            if c & 15 == SHARED_STATE_OUTPUT:
                needs.add(FRESH_STATE)
            elif c & 15 == SHARED_FEEDTHROUGH_OUTPUT:
                needs.update((FRESH_STATE, FRESH_FEEDTHROUGH))
        return _SHARED, list(key), sorted(needs)

    def shared_indices(self, variables: Iterable[tuple]) -> np.ndarray:
        """The value references, as an index array into the shared array, of `variables`
        ((name, n) pairs: n > 1 an array's elements name[1]..name[n], 1 the scalar `name`), in
        order: what a compiled step reads or writes."""
        names = [e for name, n in variables for e in (element_names(name, n) if n > 1 else (name,))]
        return np.array([self._vr_of[name] for name in names], dtype=np.int64)

    def variable_values(self) -> dict:
        """Every parameter's and input's current value by name (the inputs from the shared array
        when values are shared): the start values a model description declares."""
        return {**self.values, **{name: self.input_value(name) for name in self._input_vrs}}

    def count_shared_inputs(self) -> None:
        """Inputs written in the shared array count no versions (feedthrough's cache key): count
        one now. A wrapper that shares only its inputs counts one only if an input was set since
        the last count (the binary's set clears the flag that no published output uses then), so
        that one set of inputs is one computation, as before its inputs were shared."""
        if self.shared is None:
            return
        if self.shares_outputs:
            self._input_version += 1
        elif not self.share_flags[FRESH_FEEDTHROUGH]:
            self._input_version += 1
            self.share_flags[FRESH_FEEDTHROUGH] = 1

    def input_value(self, name: str) -> Scalar:
        """The current value of input `name` (from the shared array when values are shared)."""
        at = None if self.shared is None else self._shared_inputs.get(name)
        if at is None:  # values not shared, or a String input (never shared)
            return self.values[name]
        return at[1](self.shared.item(at[0]))

    # ---- helpers for wrappers -----------------------------------------------------------
    def feedthrough(self, compute: Callable[[], Any]) -> Any:
        """Value of `compute()` cached until an input or parameter changes.

        Several outputs of a controller come from one computation on the current inputs;
        this runs it once per set of inputs rather than once per output read."""
        if self._model is None:
            self.model  # noqa: B018 - build it first, so that the key carries its generation
        key = (self._input_version, self._model_generation)
        cache = self._feedthrough_cache
        name = compute.__name__
        hit = cache.get(name)
        if hit is None or hit[0] != key:
            hit = cache[name] = (key, compute())
        return hit[1]

    def vector(self, name: str, n: int) -> list:
        """[values of name[1] .. name[n]] (the element names are built once, not per call)."""
        pick = self._vector_keys.get((name, n))
        if pick is None:
            names = list(element_names(name, n))
            if self.shared is not None and all(e in self._input_vrs for e in names):  # shared inputs
                vrs = [self._input_vrs[e] for e in names]
                kind = _KINDS[type(self.vars[vrs[0]])]
                if vrs == list(range(vrs[0], vrs[0] + n)) and kind is float:
                    window = slice(vrs[0], vrs[0] + n)
                    pick = self._vector_keys[(name, n)] = lambda _, s=self.shared: s[window].tolist()
                else:
                    pick = self._vector_keys[(name, n)] = lambda _, s=self.shared: list(map(kind, s[vrs].tolist()))
            else:
                pick = self._vector_keys[(name, n)] = _picker(names)
        return list(pick(self.values))

    @property
    def model(self) -> Any:
        if self._model is None:
            try:
                self._model = self.build_model()
                self._model_generation += 1
            except (ValueError, TypeError) as exc:
                raise ParameterError(f"{type(self).__name__} instance '{self.instance_name}': {exc}") from exc
        return self._model

    def build_model(self) -> Any:  # pragma: no cover - every wrapper implements it
        raise NotImplementedError

    def setup_experiment(self, start_time: float, stop_time: Optional[float] = None,
                         tolerance: Optional[float] = None) -> None:
        self.start_time = float(start_time or 0.0)
        self._drop_model()  # rebuilt so that a model that keeps time starts at start_time
        self._outputs_stale()

    def exit_initialization_mode(self) -> None:
        # Build (and so validate) the model from the final parameter values.
        self.model  # noqa: B018

    # ---- FMU state: every value plus the model's full (hidden) state --------------------
    def _get_fmu_state(self):
        clock = getattr(self, "_neighbor_clock", None)  # FMI 3.0: the time (neighbor_runtime)
        return {
            "values": copy.deepcopy(self.values),
            "model": None if self._model is None else self._model.get_state(),
            "shared": None if self.shared is None else self.shared.copy(),
            "clock": None if clock is None else float(clock[0]),
        }

    def _set_fmu_state(self, state):
        if state.get("clock") is not None:
            self._neighbor_clock[0] = state["clock"]  # in place: the binary holds its address
        self.values = copy.deepcopy(state["values"])
        self._input_version += 1  # never a version an earlier cache entry could carry
        self._drop_model()
        if self.shared is not None:
            self.shared[:] = state["shared"]  # in place: the runtime holds the array's address
            self._outputs_stale()
        if state["model"] is not None:
            self.model.set_state(state["model"])
