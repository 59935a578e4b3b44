"""The FMU instances of one run and the operations the algorithms call on them.

`InstanceTable` owns the instances (instantiation, initialization, freeing) and, per component,
the prepared FMI calls that move values along the connections: connected outputs of all
components live in one numpy buffer per type, so setting a component's inputs is one `np.take`
(plus the affine map when a connection has one) and one fmi2Set* call, and reading its outputs
is one fmi2Get* call per type straight into that buffer. The calls go to FMPy's loaded ctypes
functions with value-reference arrays and value buffers built once per run. A component of ours
(a library that exports our runtime's `neighborStepIO`) is stepped with one call that makes its
sets, doStep and gets inside the FMU (`StepIO`); every other FMU with the standard calls.
"""
import ctypes
import itertools
import logging
import os
import weakref

from fmpy import calloc, free
from fmpy.fmi2 import (FMU2Slave, fmi2Boolean, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2False, fmi2LastSuccessfulTime, fmi2Real,
                       fmi2Terminated)
from fmpy.logging import addLoggerProxy
import numpy as np

from ..errors import SimulationError, SSPError
from .connections import KIND
from .fmi1 import Fmi1Calls
from .fmi3 import Fmi3Calls
from .graph import toposort

CTYPE = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int, "String": ctypes.c_char_p}
NPTYPE = {"Real": np.float64, "Integer": np.int32, "Boolean": np.int32}
GET = {"Real": "fmi2GetReal", "Integer": "fmi2GetInteger", "Boolean": "fmi2GetBoolean", "String": "fmi2GetString"}
SET = {"Real": "fmi2SetReal", "Integer": "fmi2SetInteger", "Boolean": "fmi2SetBoolean", "String": "fmi2SetString"}
FMI3_CALLS = {"fmi2GetReal": "fmi3GetFloat64", "fmi2SetReal": "fmi3SetFloat64", "fmi2GetInteger": "fmi3GetInt32",
              "fmi2SetInteger": "fmi3SetInt32", "fmi2Instantiate": "fmi3InstantiateCoSimulation",
              "fmi2SetupExperiment": "fmi3EnterInitializationMode"}
FMI1_CALLS = {"fmi2Instantiate": "fmiInstantiateSlave", "fmi2ExitInitializationMode": "fmiInitializeSlave",
              "fmi2Terminate": "fmiTerminateSlave"}
STATUS = ["ok", "warning", "discard", "error", "fatal", "pending"]
# FMU messages also go to Python logging ("system_ssp.fmu"), at these levels per FMI status; with
# INFO enabled there, the FMUs are instantiated with logging on.
FMU_LOG = logging.getLogger("system_ssp.fmu")
LOG_LEVEL = [logging.INFO, logging.WARNING, logging.WARNING, logging.ERROR, logging.CRITICAL, logging.INFO]


class StepFailed(Exception):
    """An FMI call returned error or fatal (turned into a SimulationError with the FMU's messages)."""

    def __init__(self, ci, call, status, names=()):
        super().__init__(ci, call, status)
        self.ci, self.call, self.status, self.names = ci, call, status, names


class _Messages:
    """One logger for every FMU instance the master creates, kept for the life of the process.

    An FMU may call the logger it was given after the instance is gone (pythonfmu keeps the logger
    of the instance created last; FMPy's logger proxy keeps one global logger for all instances),
    so the callback itself must never be freed; it routes each message by the instance's
    componentEnvironment, a number, to the instance that is still alive (messages for an instance
    already freed are dropped). Nothing of a run is kept alive by it."""

    def __init__(self):
        self.live = weakref.WeakValueDictionary()  # componentEnvironment number -> FmuInstance
        self.numbers = itertools.count(1)
        self.c_logger = fmi2CallbackLoggerTYPE(self.log)

    def log(self, env, instance_name, status, category, message):
        try:
            inst = self.live.get(env or 0)
            name = instance_name.decode("utf-8", "replace") if instance_name else ""
            if inst is not None and name and name != inst.name:
                # a binary that keeps the callbacks of the instance created last (stock pythonfmu):
                # the instance name it passes says whose message it is
                inst = next((i for i in self.live.values() if i.name == name), inst)
            if inst is None or (status < 1 and not inst.debug):
                return
            text = message.decode("utf-8", "replace") if message else ""
            cat = category.decode("utf-8", "replace") if category else ""
            label = STATUS[status] if 0 <= status < len(STATUS) else str(status)
            inst.messages.append((label, cat, text))
            if len(inst.messages) > 200:
                del inst.messages[:100]
            FMU_LOG.log(LOG_LEVEL[status] if 0 <= status < len(LOG_LEVEL) else logging.WARNING, "%s: %s",
                        inst.name, text.strip())
        except Exception:  # never let a logging problem propagate into C
            pass

    def register(self, inst):
        """A new instance's number (its componentEnvironment / instanceEnvironment)."""
        number = next(self.numbers)
        self.live[number] = inst
        return number

    def callbacks(self, inst):
        """The fmi2CallbackFunctions for one new instance, its componentEnvironment registered."""
        number = self.register(inst)
        cb = fmi2CallbackFunctions()
        cb.logger = self.c_logger
        cb.allocateMemory = _ALLOCATE
        cb.freeMemory = _FREE
        cb.componentEnvironment = number
        try:
            addLoggerProxy(ctypes.byref(cb))  # formats printf-style messages of C FMUs
        except Exception:
            pass
        return cb


def _unloadable(unzipdir):
    """Whether an FMU's library may be unloaded after its instances are freed: yes for our runtime
    (it never finalizes the interpreter and leaves no code of its own referenced from Python), no
    for a stock pythonfmu binary (resources/slavemodule.txt), whose unloading while the interpreter
    holds objects it created crashes the process at exit."""
    return not os.path.exists(os.path.join(unzipdir, "resources", "slavemodule.txt"))


_ALLOCATE = fmi2CallbackAllocateMemoryTYPE(calloc)
_FREE = fmi2CallbackFreeMemoryTYPE(free)
_MESSAGES = _Messages()


class FmuInstance:
    """One FMU instance (its FMPy object, library loaded) and the messages it logged."""

    def __init__(self, info, debug=False):
        self.info = info
        self.name = info.name
        self.messages = []  # (status label, category, message)
        self.debug = debug
        self.instantiated = False
        self.initialized = False
        self.failed_status = None  # the FMI status of a failed call (3 error, 4 fatal), once one failed
        md = info.md
        self.fmi3 = info.fmi3_md is not None
        self.fmi1 = info.fmi1
        if self.fmi3 or self.fmi1:  # behind the FMI 2.0 calls the table makes (system_ssp.master.fmi3, .fmi1)
            self.callbacks = (_MESSAGES, _MESSAGES.register(self))
            self.fmu = (Fmi3Calls if self.fmi3 else Fmi1Calls)(info, info.name)
            self.fn = self.fmu.fn
            return
        self.callbacks = _MESSAGES.callbacks(self)
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=info.unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=info.name)
        self.fn = self.fmu._functions

    def free(self):
        """fmi2Terminate (when initialized and healthy), fmi2FreeInstance (unless the FMU reported
        fatal: FMI 2.0 allows no further call then), and the library unloaded."""
        fmu, self.fn = self.fmu, None
        if fmu is None:
            return
        self.fmu = None
        healthy = self.failed_status is None
        if self.initialized and healthy:
            try:
                fmu.terminate()
            except Exception:
                pass
        if self.instantiated and self.failed_status != 4:
            try:
                fmu.free_instance() if self.fmi3 or self.fmi1 else fmu.fmi2FreeInstance(fmu.component)
            except Exception:
                pass
        if self.failed_status != 4 and _unloadable(self.info.unzipdir):
            try:
                fmu.freeLibrary()
            except Exception:
                pass

    def function(self, name, vr, n):
        """The FMI call `name` (by its FMI 2.0 name) for the value reference block `vr[:n]`, which
        the caller keeps: FMPy's loaded function, or for FMI 3.0 one prepared for the block."""
        return self.fmu.specialized(name, vr, n) if self.fmi3 or self.fmi1 else self.fn[name]

    def take_messages(self):
        msgs = self.messages
        self.messages = []
        return msgs


class GetOp:
    """fmi2Get* of a block of one component's connected outputs of one type, into the shared
    buffer. `run()` makes the call (a closure over these fields: the hot loop's fast path)."""
    __slots__ = ("fn", "c", "vr", "n", "buf", "ci", "call", "names", "run")

    def __init__(self, fn, c, vr, n, buf, ci, call, names):
        self.fn, self.c, self.vr, self.n, self.buf, self.ci, self.call = fn, c, vr, n, buf, ci, call
        self.names = names

        def run():
            s = fn(c, vr, n, buf)
            if s > 1:
                raise StepFailed(ci, call, s, names)

        self.run = run


class SetOp:
    """fmi2Set* of one component's connected inputs of one type, gathered from the shared buffer
    `G` at `idx`, mapped (affine `factor`/`offset`, or `post` for Integer/Boolean mappings); not
    sent again when the bytes equal the ones last sent (FMU inputs keep their values, and a call
    into a pythonfmu FMU costs about 10 us, which a byte comparison saves). `run()` does it."""
    __slots__ = ("fn", "c", "vr", "n", "buf", "view", "G", "idx", "factor", "offset", "post", "ci", "call", "names",
                 "last", "gather", "run")

    def __init__(self, fn, c, vr, n, buf, view, G, idx, factor, offset, post, ci, call, names):
        self.fn, self.c, self.vr, self.n, self.buf, self.view = fn, c, vr, n, buf, view
        self.G, self.idx, self.factor, self.offset, self.post = G, idx, factor, offset, post
        self.ci, self.call, self.names = ci, call, names
        take, multiply, add = G.take, np.multiply, np.add  # the bound method: np.take's wrappers cost ~1 us
        last = self.last = [None]  # the bytes last sent

        def gather():
            """The values to send into `buf`; False when they equal the ones last sent."""
            take(idx, out=view)
            if factor is not None:
                multiply(view, factor, out=view)
                add(view, offset, out=view)
            if post is not None:
                post(view)
            sent = view.tobytes()
            if sent == last[0]:
                return False
            last[0] = sent
            return True

        def run():
            if gather():
                s = fn(c, vr, n, buf)
                if s > 1:
                    last[0] = None
                    raise StepFailed(ci, call, s, names)

        self.gather, self.run = gather, run


class StringGetOp:
    """fmi2GetString of a block of one component's connected String outputs, copied at once into
    the shared list `G` at `pos` (the FMU's char pointers are valid only until its next call)."""
    __slots__ = ("ci", "call", "names", "run")

    def __init__(self, fn, c, vr, n, G, pos, ci, names):
        self.ci, self.call, self.names = ci, "fmi2GetString", names
        buf = (ctypes.c_char_p * n)()

        def run():
            s = fn(c, vr, n, buf)
            if s > 1:
                raise StepFailed(ci, "fmi2GetString", s, names)
            G[pos:pos + n] = buf[:n]

        self.run = run


class StringSetOp:
    """fmi2SetString of one component's connected String inputs from the shared list `G` at
    `idx`; not sent again when the texts equal the ones last sent."""
    __slots__ = ("ci", "call", "names", "run")

    def __init__(self, fn, c, vr, n, G, idx, ci, names):
        self.ci, self.call, self.names = ci, "fmi2SetString", names
        buf = (ctypes.c_char_p * n)()
        last = [None]

        def run():
            texts = [G[i] for i in idx]
            if texts == last[0]:
                return
            buf[:] = texts
            s = fn(c, vr, n, buf)
            if s > 1:
                raise StepFailed(ci, "fmi2SetString", s, names)
            last[0] = texts

        self.run = run


class StepIO(ctypes.Structure):
    """The block descriptions of our runtime's batched step (fmus/runtime/neighbor_fmi2.c, StepIO):
    per kind (Real, Integer, Boolean) the inputs to set and the outputs to read."""
    _fields_ = [("t", ctypes.c_double), ("h", ctypes.c_double),
                ("n_in", ctypes.c_size_t * 3), ("n_out", ctypes.c_size_t * 3),
                ("in_vr", ctypes.c_void_p * 3), ("in_val", ctypes.c_void_p * 3),
                ("out_vr", ctypes.c_void_p * 3), ("out_val", ctypes.c_void_p * 3),
                ("send", ctypes.c_int * 3), ("failed", ctypes.c_int)]


STEP_IO_KIND = {"Real": 0, "Integer": 1, "Boolean": 2}


def _step_io_kind(op):
    """StepIO's index of a GetOp's or SetOp's type (None for String, which StepIO does not carry)."""
    return STEP_IO_KIND.get(op.call[len("fmi2Get"):])  # fmi2GetReal, fmi2SetBoolean, ...


# Step our runtime's FMUs with its batched call (set inputs, doStep, get outputs in one entry into
# the FMU) when the library exports it; False: the standard calls only (the tests compare both).
BATCHED_STEPS = os.environ.get("NEIGHBOR_COSIM_BATCHED_STEPS", "1") != "0"


def _step_io_function(inst):
    """The runtime's `neighborStepIO` of an FMI 2.0 instance's library, or None (another FMU)."""
    if inst.fmi3 or not BATCHED_STEPS:
        return None
    fn = getattr(getattr(inst.fmu, "dll", None), "neighborStepIO", None)
    if fn is not None:
        fn.argtypes = [ctypes.c_void_p, ctypes.POINTER(StepIO)]
        fn.restype = ctypes.c_int
    return fn


def _skip_function(inst):
    """The runtime's `neighborSkipTo(component, t)` of an instance's library (FMI 2.0 or 3.0), or
    None (another tool's FMU, which takes a jump of its communication point as it is)."""
    dll = getattr(inst.fmu.slave if inst.fmi3 else inst.fmu, "dll", None)
    fn = getattr(dll, "neighborSkipTo", None)
    if fn is not None:
        fn.argtypes = [ctypes.c_void_p, ctypes.c_double]
        fn.restype = ctypes.c_int
    return fn


def _slot_blocks(slots):
    """([(component, [variables], first position)], total): each component's connected outputs of
    one type as one block of the type's shared buffer, in component order; fills `slots`
    ((component, variable) -> position)."""
    by_comp = {}
    for (ci, var) in slots:
        by_comp.setdefault(ci, []).append(var)
    blocks, pos = [], 0
    for ci in sorted(by_comp):
        vars_ = by_comp[ci]
        for j, var in enumerate(vars_):
            slots[(ci, var)] = pos + j
        blocks.append((ci, vars_, pos))
        pos += len(vars_)
    return blocks, pos


def _sequence(runs):
    """One function running `runs` in order (the common single-call case is the call itself)."""
    if len(runs) == 1:
        return runs[0]
    if not runs:
        return _nothing

    def run_all():
        for run in runs:
            run()

    return run_all


def _nothing():
    pass


class ReadOp:
    """fmi2Get* of a block of variables of one component and type (recording, stop conditions)."""
    __slots__ = ("fn", "c", "vr", "n", "buf", "view", "ci", "call", "names", "vars")

    def __init__(self, instance, ci, kind, variables, vrefs, names):
        m = len(vrefs)
        self.c = instance.fmu.component
        self.vr = (ctypes.c_uint * m)(*vrefs)
        self.fn = instance.function(GET[kind], self.vr, m)
        self.n = m
        self.buf = (CTYPE[kind] * m)()
        # Strings: the texts, decoded (a list, copied at each read: the FMU owns the char pointers)
        self.view = np.ctypeslib.as_array(self.buf) if kind != "String" else None
        self.ci = ci
        self.call = GET[kind]
        self.names = names  # "component.variable", the result's columns
        self.vars = tuple(variables)

    def read(self):
        """Read the block into self.view; StepFailed on error."""
        s = self.fn(self.c, self.vr, self.n, self.buf)
        if s > 1:
            raise StepFailed(self.ci, self.call, s, self.vars)
        if self.view is None:
            return [b.decode("utf-8", "replace") if b is not None else "" for b in self.buf]
        return self.view


def read_ops(table, variables):
    """ReadOps for [(component, variable)], grouped per component and type in sorted order;
    returns (ops, [(name, kind)] in the ops' column order)."""
    comps = table.system.comps
    groups = {}
    for ci, var in variables:
        kind = KIND[comps[ci].vars[var].type]
        groups.setdefault((ci, kind), []).append(var)
    ops, columns = [], []
    for (ci, kind), vars_ in sorted(groups.items()):
        names = [f"{comps[ci].name}.{v}" for v in vars_]
        ops.append(ReadOp(table.instances[ci], ci, kind, vars_, [comps[ci].vars[v].valueReference for v in vars_],
                          names))
        columns += [(name, kind) for name in names]
    return ops, columns


class InstanceTable:
    """The run's FMU instances (SSD order) and the prepared value transfers between them."""

    def __init__(self, system, plan):
        self.system = system
        self.plan = plan
        self.debug = FMU_LOG.isEnabledFor(logging.INFO)  # FMUs instantiated with logging on
        self.instances = []
        self.t = plan.start  # the time error messages name

    # ---- errors -------------------------------------------------------------------------
    def error(self, ci, call, exc=None, status=None, names=()):
        """A SimulationError for a failed call of component ci (of its variables `names`, for a
        get or set), with the messages it logged."""
        inst = self.instances[ci]
        if inst.failed_status is None:
            inst.failed_status = status if status is not None and status > 2 else 3
        texts = []
        for label, _, m in inst.take_messages():
            if label == "ok":
                continue
            if "PyObject_CallMethod\n" in m:  # pythonfmu: keep the Python exception text
                m = m.split("PyObject_CallMethod\n", 1)[1]
            if m and m not in texts:
                texts.append(m.strip())
        text = "; ".join(texts)
        if status is not None:
            what = f"returned status {STATUS[status] if 0 <= status < len(STATUS) else status}"
        elif exc is not None and not texts:
            what = f"failed ({exc})"
        else:
            what = "failed"
        detail = f": {text}" if text else ""
        if inst.fmi3:  # the calls are made under FMI 2.0 names (system_ssp.master.fmi3): say the FMI 3.0 ones
            call = FMI3_CALLS.get(call, call.replace("fmi2", "fmi3"))
        elif inst.fmi1:
            call = FMI1_CALLS.get(call, call.replace("fmi2", "fmi"))
        if names:
            shown = ", ".join(names[:6]) + (f" and {len(names) - 6} more" if len(names) > 6 else "")
            call = f"{call} of {shown}"
        return SimulationError(f"component {inst.name!r}: {call} {what} at t={self.t:g} s{detail}")

    def terminated_at(self, ci):
        """After ci's fmi2DoStep returned fmi2Discard, ask it (FMI 2.0 section 4.2.3) whether it
        ended the simulation (fmi2Terminated): the time it reached (fmi2LastSuccessfulTime, or
        the communication point the step started from when it does not say), else None."""
        fmu = self.instances[ci].fmu
        if self.instances[ci].fmi1:  # FMI 1.0 has no fmiTerminated: a discarded step is a failed one
            return None
        if self.instances[ci].fmi3:  # FMI 3.0 said so in fmi3DoStep (terminateSimulation)
            reached = fmu.terminated
            return None if reached is None else (reached if np.isfinite(reached) and reached >= self.t else self.t)
        ended, reached = fmi2Boolean(fmi2False), fmi2Real(self.t)
        try:
            if fmu.fmi2GetBooleanStatus(fmu.component, fmi2Terminated, ctypes.byref(ended)) > 1 or not ended.value:
                return None
        except Exception:  # FMPy raises for a status it does not accept: not an answer
            return None
        try:
            if fmu.fmi2GetRealStatus(fmu.component, fmi2LastSuccessfulTime, ctypes.byref(reached)) > 1:
                return self.t
        except Exception:
            return self.t
        return float(reached.value) if np.isfinite(reached.value) and reached.value >= self.t else self.t

    def call(self, ci, call, fn, *args, names=()):
        """Call an fmpy method; wrap failures with the component's logged messages."""
        try:
            return fn(*args)
        except SSPError:
            raise
        except Exception as exc:
            raise self.error(ci, call, exc, names=names) from None

    # ---- life cycle ---------------------------------------------------------------------
    def instantiate(self):
        """Instantiate every FMU, set up the experiment, enter initialization mode and set the
        plan's parameters and start values (batched per component and type)."""
        p = self.plan
        for info in self.system.comps:
            try:
                inst = FmuInstance(info, self.debug)
            except Exception as exc:
                raise SimulationError(f"component {info.name!r}: cannot load the FMU binary "
                                      f"({self.system.namer(info.decl.fmu_path)}): {exc}") from None
            self.instances.append(inst)
            ci = len(self.instances) - 1
            self.call(ci, "fmi2Instantiate", inst.fmu.instantiate, False, inst.callbacks, self.debug)
            inst.instantiated = True
        for ci, inst in enumerate(self.instances):
            self.call(ci, "fmi2SetupExperiment", inst.fmu.setupExperiment, None, p.start, p.stop)
            self.call(ci, "fmi2EnterInitializationMode", inst.fmu.enterInitializationMode)
            inst.initialized = True
        per = {}
        for (ci, var), value in p.params.items():
            v = self.system.comps[ci].vars[var]
            per.setdefault((ci, v.type), ([], [], []))
            per[(ci, v.type)][0].append(v.valueReference)
            per[(ci, v.type)][1].append(value)
            per[(ci, v.type)][2].append(var)
        for (ci, vtype), (vrs, values, names) in sorted(per.items()):
            fmu = self.instances[ci].fmu
            setter = {"Real": fmu.setReal, "Integer": fmu.setInteger, "Enumeration": fmu.setInteger,
                      "Boolean": fmu.setBoolean, "String": fmu.setString}[vtype]
            self.call(ci, f"setting parameters/start values ({vtype})", setter, vrs, values, names=tuple(names))

    def free(self):
        """Free every instance and unload the libraries that may be unloaded (see FmuInstance.free)."""
        instances, self.instances = self.instances, []
        for inst in instances:
            inst.free()
        self.G = self.gets = self.sets = self.getters = self.setters = self.do_steps = self.steppers = None

    def messages(self):
        return {inst.name: list(inst.messages) for inst in self.instances if inst.messages}

    # ---- prepared transfers -------------------------------------------------------------
    def prepare(self):
        """Build the shared output buffers, the GetOps and SetOps per component and the doStep
        functions."""
        sysm = self.system
        comps = sysm.comps
        n = len(comps)
        slots = {"Real": {}, "Integer": {}, "Boolean": {}, "String": {}}  # (ci, var) -> position in its buffer
        for lk in sysm.links:
            slots[lk.vtype].setdefault((lk.src, lk.src_var), None)
        self.G = {}
        self.gets = [[] for _ in range(n)]
        for kind, d in slots.items():
            blocks, total = _slot_blocks(d)
            if kind == "String":  # texts: a list, copied at each get (the FMU owns its char pointers)
                G = self.G[kind] = [b""] * total
                for ci, vars_, pos in blocks:
                    vr = (ctypes.c_uint * len(vars_))(*[comps[ci].vars[v].valueReference for v in vars_])
                    inst = self.instances[ci]
                    self.gets[ci].append(StringGetOp(inst.function(GET[kind], vr, len(vars_)), inst.fmu.component, vr,
                                                     len(vars_), G, pos, ci, tuple(vars_)))
                continue
            G = np.zeros(max(total, 1), dtype=NPTYPE[kind])
            self.G[kind] = G
            for ci, vars_, pos in blocks:
                m = len(vars_)
                vr = (ctypes.c_uint * m)(*[comps[ci].vars[v].valueReference for v in vars_])
                buf = (CTYPE[kind] * m).from_address(G.ctypes.data + pos * G.itemsize)
                inst = self.instances[ci]
                self.gets[ci].append(GetOp(inst.function(GET[kind], vr, m), inst.fmu.component, vr, m, buf, ci,
                                           GET[kind], tuple(vars_)))
        self.sets = [[] for _ in range(n)]
        by_dst = {}
        for lk in sysm.links:
            by_dst.setdefault((lk.dst, lk.vtype), []).append(lk)
        # every component's inputs of one type live in one buffer too (the values last sent, which
        # the compiled step loop reads and writes in place: system_ssp.master.compiled)
        sizes = {}
        for (_, kind), lks in by_dst.items():
            sizes[kind] = sizes.get(kind, 0) + len(lks)
        self.IN = {kind: np.zeros(max(sizes.get(kind, 0), 1), dtype=t) for kind, t in NPTYPE.items()}
        self.in_start = {}  # SetOp -> its first position in self.IN[kind]
        filled = dict.fromkeys(NPTYPE, 0)
        for (ci, kind), lks in sorted(by_dst.items()):
            m = len(lks)
            if kind == "String":
                inst = self.instances[ci]
                vr = (ctypes.c_uint * m)(*[comps[ci].vars[lk.dst_var].valueReference for lk in lks])
                self.sets[ci].append(StringSetOp(inst.function(SET[kind], vr, m), inst.fmu.component, vr, m,
                                                 self.G[kind], [slots[kind][(lk.src, lk.src_var)] for lk in lks], ci,
                                                 tuple(lk.dst_var for lk in lks)))
                continue
            vr = (ctypes.c_uint * m)(*[comps[ci].vars[lk.dst_var].valueReference for lk in lks])
            store, first = self.IN[kind], filled[kind]
            filled[kind] += m
            buf = (CTYPE[kind] * m).from_address(store.ctypes.data + first * store.itemsize)
            idx = np.array([slots[kind][(lk.src, lk.src_var)] for lk in lks], dtype=np.intp)
            fac = np.array([lk.factor for lk in lks])
            off = np.array([lk.offset for lk in lks])
            affine = kind == "Real" and (np.any(fac != 1.0) or np.any(off != 0.0))
            inst = self.instances[ci]
            op = SetOp(inst.function(SET[kind], vr, m), inst.fmu.component, vr, m, buf, store[first:first + m],
                       self.G[kind], idx, fac if affine else None, off if affine else None, _mapper(kind, lks), ci,
                       SET[kind], tuple(lk.dst_var for lk in lks))
            self.sets[ci].append(op)
            self.in_start[op] = first
        # the hot loop's calls, one function per component
        self.getters = [_sequence([op.run for op in ops]) for ops in self.gets]
        self.setters = [_sequence([op.run for op in ops]) for ops in self.sets]
        self.do_steps = [self._do_step(ci) for ci in range(n)]
        self.step_ios = (StepIO * n)()  # the batched step's blocks, one per component (read by the compiled loop)
        self.step_io_functions = [None] * n  # per component: its library's neighborStepIO, or None
        self.step_failures = [None] * n  # per component: status -> the StepFailed of a failed batched step
        self.steppers = [self._stepper(ci) for ci in range(n)]
        # components whose connected outputs change when their inputs are set
        self.has_ft = [bool(sysm.graph.feedthrough_outputs[ci]) and bool(self.gets[ci]) for ci in range(n)]

    def resume(self, ci, t):
        """Component ci, suspended by a schedule, goes on at `t`: our runtime's FMUs, which refuse a
        doStep that does not start where the last one ended (the FMI standard's order), are told
        that their clock jumps there."""
        inst = self.instances[ci]
        fn = _skip_function(inst)
        if fn is not None:
            s = fn(inst.fmu.component, t)
            if s > 1:
                raise StepFailed(ci, "neighborSkipTo", s)

    def _do_step(self, ci):
        """do_step(t, dt) of component ci: fmi2DoStep only."""
        inst = self.instances[ci]
        fn, c = inst.fn["fmi2DoStep"], inst.fmu.component

        def do_step(t, dt):
            s = fn(c, t, dt, 1)
            if s > 1:
                raise StepFailed(ci, "fmi2DoStep", s)

        return do_step

    def _stepper(self, ci):
        """step(t, dt) of component ci: set its inputs, doStep, read its outputs (in one call into
        the FMU where our runtime offers it)."""
        inst = self.instances[ci]
        step_io = _step_io_function(inst)
        if step_io is not None and all(_step_io_kind(op) is not None for op in self.sets[ci] + self.gets[ci]):
            return self._batched_stepper(ci, step_io)
        fn, c = inst.fn["fmi2DoStep"], inst.fmu.component
        set_, get = self.setters[ci], self.getters[ci]

        def step(t, dt):
            set_()
            s = fn(c, t, dt, 1)
            if s > 1:
                raise StepFailed(ci, "fmi2DoStep", s)
            get()

        return step

    def _batched_stepper(self, ci, step_io):
        """step(t, dt) of component ci through the runtime's neighborStepIO: the same set, doStep
        and get calls as `_stepper`'s, made inside the FMU; a failure names the call that failed."""
        io = self.step_ios[ci]
        sets = {_step_io_kind(op): op for op in self.sets[ci]}  # one block per type and component
        gets = {_step_io_kind(op): op for op in self.gets[ci]}
        for k, op in sets.items():
            io.n_in[k], io.in_vr[k], io.in_val[k] = op.n, ctypes.addressof(op.vr), ctypes.addressof(op.buf)
        for k, op in gets.items():
            io.n_out[k], io.out_vr[k], io.out_val[k] = op.n, ctypes.addressof(op.vr), ctypes.addressof(op.buf)
        gathers = [(k, op.gather) for k, op in sets.items()]
        c, send, ref = self.instances[ci].fmu.component, io.send, ctypes.byref(io)

        def failed(s):
            where = io.failed  # 1 + type: its set; 4: the doStep; 5 + type: its get
            if where in (1, 2, 3):
                for k, other in sets.items():
                    if k >= where - 1:
                        other.last[0] = None  # this block and the ones after it were not sent
                op = sets[where - 1]
                return StepFailed(ci, op.call, s, op.names)
            if where in (5, 6, 7):
                op = gets[where - 5]
                return StepFailed(ci, op.call, s, op.names)
            return StepFailed(ci, "fmi2DoStep", s)

        self.step_io_functions[ci], self.step_failures[ci] = step_io, failed

        def step(t, dt):
            for k, gather in gathers:
                send[k] = gather()
            io.t = t
            io.h = dt
            s = step_io(c, ref)
            if s > 1:
                raise failed(s)

        return step

    def get(self, ci):
        """Read ci's connected outputs into the shared buffers."""
        self.getters[ci]()

    def set(self, ci):
        """Set ci's connected inputs from the shared buffers (skipped when unchanged)."""
        self.setters[ci]()

    def initialize(self):
        """Exchange values in dependency order inside initialization mode, leave it, exchange
        again (an algebraic loop, possible with Jacobi only, is iterated n times)."""
        n = len(self.instances)
        for ci in range(n):
            self.get(ci)
        order, cycle = toposort(n, self.system.graph.edges)
        passes = 1
        if cycle:  # only reachable with Jacobi: iterate like a fixed-point exchange
            order, passes = list(range(n)), n
        for _ in range(passes):
            for ci in order:
                self.set(ci)
                inst = self.instances[ci]
                if inst.fmi1 and not inst.fmu.initialized:
                    # FMI 1.0 has no initialization mode: fmiInitializeSlave once its inputs have
                    # their values, so that what it gives the components after it is initialized
                    self.call(ci, "fmi2ExitInitializationMode", inst.fmu.exitInitializationMode)
                self.get(ci)
        for ci, inst in enumerate(self.instances):
            if inst.fmi1:
                continue
            self.call(ci, "fmi2ExitInitializationMode", inst.fmu.exitInitializationMode)
        for _ in range(passes):
            for ci in order:
                self.get(ci)
                self.set(ci)
        for ci in range(n):
            self.get(ci)

    def final(self):
        """{'component.variable': value} of every input and output now."""
        final = {}
        for ci, inst in enumerate(self.instances):
            groups = {}
            for v in inst.info.md.modelVariables:
                if v.causality in ("input", "output") and v.type in KIND:
                    groups.setdefault(KIND[v.type], []).append(v)
            for kind, vs in groups.items():
                getter = {"Real": inst.fmu.getReal, "Integer": inst.fmu.getInteger,
                          "Boolean": inst.fmu.getBoolean, "String": inst.fmu.getString}[kind]
                vals = self.call(ci, GET[kind], getter, [v.valueReference for v in vs],
                                 names=tuple(v.name for v in vs))
                for v, x in zip(vs, vals):
                    final[f"{inst.name}.{v.name}"] = _python_value(kind, x)
        return final


def _python_value(kind, x):
    """A value FMPy read, as the Python value results hold (FMPy gives Strings as bytes)."""
    if kind == "Boolean":
        return bool(x)
    if kind == "Integer":
        return int(x)
    if kind == "String":
        return x.decode("utf-8", "replace") if isinstance(x, bytes) else ("" if x is None else str(x))
    return float(x)


def _mapper(kind, links):
    """In-place Integer/Boolean mapping of a SetOp's view, or None when no link maps."""
    maps = [(j, lk.mapping) for j, lk in enumerate(links) if lk.mapping]
    if not maps:
        return None
    if kind == "Boolean":
        def post(view):
            for j, mp in maps:
                view[j] = int(mp.get(bool(view[j]), bool(view[j])))
    else:
        def post(view):
            for j, mp in maps:
                view[j] = mp.get(int(view[j]), int(view[j]))
    return post
