"""FMI 3.0 co-simulation FMUs in the master, beside FMI 2.0 ones.

The master moves scalars along connections, as SSP 1.0 connectors are scalars. An FMI 3.0 FMU is
seen through its element view (system_ssp.ssp.fmi3_view): each scalar variable as itself, each
array variable as its elements `name[i]` (a matrix `name[i,j]`, row-major), so a system connects
an array element by element under the names an FMI 2.0 export of the same model uses (ours:
`q_BN[1]` .. `q_BN[4]`), and a connection between two arrays of the same shape, named without
indices, is expanded into its elements (system_ssp.master.connections). Types map onto the
master's four: Float64 and Float32 -> Real; Int8 .. Int64, UInt8 .. UInt64 -> Integer (values
must fit 32 bits); Enumeration -> Enumeration; Boolean; String. Binary and Clock variables, the
independent variable and structural parameters are not in the view (a connector naming one is
refused with the reason).

`Fmi3Calls` gives the instance table what FMPy's FMU2Slave gives it for FMI 2.0: the calls by
their FMI 2.0 names with FMI 2.0 signatures over the element view (prepared once per value
reference block, then one FMI 3.0 call per type per block), and the life-cycle methods. An array
is always set whole: the elements a call does not set keep the value last set (the start value
at first).
"""
import ctypes
from ctypes import byref, c_bool, c_char_p, c_double, c_float, c_int, c_size_t, c_uint32, c_void_p

from fmpy.fmi3 import FMU3Slave
import numpy as np

from .list_calls import MASTER_C, ListCalls

# the C type and the call's type name of each FMI 3.0 type (an Enumeration is an Int64)
C_TYPE = {"Float64": c_double, "Float32": c_float, "Int8": ctypes.c_int8, "UInt8": ctypes.c_uint8,
          "Int16": ctypes.c_int16, "UInt16": ctypes.c_uint16, "Int32": ctypes.c_int32, "UInt32": ctypes.c_uint32,
          "Int64": ctypes.c_int64, "UInt64": ctypes.c_uint64, "Boolean": c_bool, "String": c_char_p,
          "Enumeration": ctypes.c_int64}
CALL_TYPE = {t: ("Int64" if t == "Enumeration" else t) for t in C_TYPE}


class _Plan:
    """One element block's FMI 3.0 calls: per FMI 3.0 type, the value references, a buffer of
    all their values, and where each element of the block is in it."""

    def __init__(self, calls, evrs):
        groups = {}
        for i, ev in enumerate(evrs):
            e = calls.elements[ev]
            groups.setdefault(e.type, []).append((i, e))
        self.parts = []
        for type_, items in groups.items():
            vrs = list(dict.fromkeys(e.vr for _, e in items))
            start = {}
            total = 0
            for vr in vrs:
                start[vr] = total
                total += calls.sizes[vr]
            buf = (C_TYPE[type_] * total)()
            positions = np.array([start[e.vr] + e.offset for _, e in items], dtype=np.intp)
            targets = np.array([i for i, _ in items], dtype=np.intp)
            self.parts.append((type_, (c_uint32 * len(vrs))(*vrs), len(vrs), buf, total, positions, targets, vrs))


class Fmi3Calls(ListCalls):
    """An FMI 3.0 co-simulation FMU instance behind the calls the instance table makes on FMPy's
    FMU2Slave (see the module's text)."""

    CALL_PREFIX = "fmi3"

    def __init__(self, info, instance_name):
        md = info.fmi3_md
        self.info = info
        self.elements = info.fmi3_elements
        self.sizes = {e.vr: e.size for e in self.elements.values()}
        self.slave = FMU3Slave(guid=md.guid, unzipDirectory=info.unzipdir,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=instance_name)
        dll = self.slave.dll
        self._c = {}
        for type_ in set(CALL_TYPE.values()):
            for verb in ("Get", "Set"):
                fn = getattr(dll, f"fmi3{verb}{type_}")
                fn.argtypes = [c_void_p, ctypes.POINTER(c_uint32), c_size_t, c_void_p, c_size_t]
                fn.restype = c_int
                self._c[(verb, type_)] = fn
        step = dll.fmi3DoStep
        step.argtypes = [c_void_p, c_double, c_double, c_bool, ctypes.POINTER(c_bool), ctypes.POINTER(c_bool),
                         ctypes.POINTER(c_bool), ctypes.POINTER(c_double)]
        step.restype = c_int
        self._step = step
        # the values last set of every array (an array is set whole), from the start values
        self.shadow = {}
        for ev, e in self.elements.items():
            if e.size > 1:
                values = self.shadow.setdefault(e.vr, (C_TYPE[e.type] * e.size)())
                start = info.md_view_vars[ev].start
                if start is not None:
                    values[e.offset] = _c_value(e.type, start)
        self.terminated = None  # lastSuccessfulTime when the FMU asked to end the simulation
        self.fn = {}
        for kind in ("Real", "Integer", "Boolean", "String"):
            self.fn[f"fmi2Get{kind}"] = self._cached(f"fmi2Get{kind}")
            self.fn[f"fmi2Set{kind}"] = self._cached(f"fmi2Set{kind}")
        self.fn["fmi2DoStep"] = self._do_step
        self.component = None

    # ---- values ------------------------------------------------------------------------
    def specialized(self, name, vr, n):
        """The FMI 2.0-style call `name` (fmi2GetReal ...) for the element block `vr[:n]`, prepared
        once: a block that is whole variables of the master's own C type in order (a Float64
        array, Int32s, Strings) goes straight to the FMI 3.0 call with the caller's buffer;
        anything else through a per-type buffer."""
        verb = name[4:7]
        kind = name[7:]
        plan = _Plan(self, list(vr[:n]))
        if len(plan.parts) == 1:
            type_, vrs, nvr, tbuf, total, positions, targets, plain = plan.parts[0]
            direct = (total == n and np.array_equal(positions, np.arange(n)) and np.array_equal(targets, np.arange(n))
                      and C_TYPE[type_] is MASTER_C[kind])  # Boolean never: 1-byte bool vs int
            if direct:
                fn3 = self._c[(verb, CALL_TYPE[type_])]
                arrays = [v for v in plain if self.sizes[v] > 1] if verb == "Set" else []
                if not arrays:
                    return lambda c, vr, n, buf: fn3(c, vrs, nvr, buf, total)
                return self._direct_set(fn3, vrs, nvr, total, plain, type_)
        return self._general(verb, plan)

    def _direct_set(self, fn3, vrs, nvr, total, plain, type_):
        """A whole-variable set that also keeps the arrays' values last set."""
        size = ctypes.sizeof(C_TYPE[type_])
        copies = []
        offset = 0
        for v in plain:
            if self.sizes[v] > 1:
                copies.append((self.shadow[v], offset * size, self.sizes[v] * size))
            offset += self.sizes[v]
        memmove, addressof = ctypes.memmove, ctypes.addressof

        def set_(c, vr, n, buf):
            s = fn3(c, vrs, nvr, buf, total)
            if s <= 1:
                base = addressof(buf)
                for shadow, at, nbytes in copies:
                    memmove(shadow, base + at, nbytes)
            return s

        return set_

    def _general(self, verb, plan):
        calls = self
        parts = [(calls._c[(verb, CALL_TYPE[type_])], type_, vrs, nvr, tbuf, total, positions.tolist(),
                  targets.tolist(), plain, ctypes.sizeof(C_TYPE[type_]))
                 for type_, vrs, nvr, tbuf, total, positions, targets, plain in plan.parts]
        if verb == "Get":
            def get(c, vr, n, buf):
                for fn3, _, vrs, nvr, tbuf, total, positions, targets, _, _ in parts:
                    s = fn3(c, vrs, nvr, tbuf, total)
                    if s > 1:
                        return s
                    for p, t in zip(positions, targets):
                        buf[t] = tbuf[p]
                return 0

            return get

        def set_(c, vr, n, buf):
            for fn3, type_, vrs, nvr, tbuf, total, positions, targets, plain, size in parts:
                offset = 0
                for v in plain:  # the elements not set keep the values last set
                    if calls.sizes[v] > 1:
                        ctypes.memmove(ctypes.addressof(tbuf) + offset * size, calls.shadow[v], calls.sizes[v] * size)
                    offset += calls.sizes[v]
                for p, t in zip(positions, targets):
                    tbuf[p] = _convert(type_, buf[t])
                s = fn3(c, vrs, nvr, tbuf, total)
                if s > 1:
                    return s
                offset = 0
                for v in plain:
                    if calls.sizes[v] > 1:
                        ctypes.memmove(calls.shadow[v], ctypes.addressof(tbuf) + offset * size, calls.sizes[v] * size)
                    offset += calls.sizes[v]
            return 0

        return set_

    def _cached(self, name):
        """`name` for any block (the blocks are prepared on first use): the calls outside the
        step loop (parameters, final values)."""
        plans = {}

        def call(c, vr, n, buf):
            key = bytes(vr)[:4 * n]
            fn = plans.get(key)
            if fn is None:
                fn = plans[key] = self.specialized(name, vr, n)
            return fn(c, vr, n, buf)

        return call

    def _do_step(self, c, t, h, no_set_prior):
        event, terminate, early, reached = c_bool(False), c_bool(False), c_bool(False), c_double(t)
        s = self._step(c, t, h, bool(no_set_prior), byref(event), byref(terminate), byref(early), byref(reached))
        if s <= 1 and terminate.value:
            # FMI 3.0 asks the importer to end here: as FMI 2.0's fmi2Discard + fmi2Terminated
            self.terminated = reached.value
            return 2
        if s == 2:
            self.terminated = None
        return s

    # ---- FMPy's FMU2Slave interface, as the instance table uses it ----------------------
    def instantiate(self, visible, callbacks, logging_on):
        messages, env = callbacks

        def log(instance_env, status, category, message):
            messages.log(env, self.slave.instanceName.encode(), status, category, message)

        self.slave.instantiate(visible=visible, loggingOn=logging_on, eventModeUsed=False, earlyReturnAllowed=False,
                               logMessage=log)
        self._log = self.slave.logMessage  # kept alive with the instance
        self.component = self.slave.component
        self.bind_list_calls()

    def setupExperiment(self, tolerance, start, stop):
        self._experiment = (tolerance, start, stop)

    def enterInitializationMode(self):
        tolerance, start, stop = self._experiment
        self.slave.enterInitializationMode(tolerance=tolerance, startTime=start, stopTime=stop)

    def exitInitializationMode(self):
        self.slave.exitInitializationMode()

    def terminate(self):
        self.slave.terminate()

    def free_instance(self):
        self.slave.fmi3FreeInstance(self.component)

    def freeLibrary(self):
        self.slave.freeLibrary()


def _convert(type_, value):
    """A master value (double, int, int as Boolean, bytes) as the FMI 3.0 type's C value."""
    if type_ == "Boolean":
        return bool(value)
    return value


def _c_value(type_, text):
    """A start value's text as the C value of FMI 3.0 type `type_`."""
    if type_ in ("Float64", "Float32"):
        return float(text)
    if type_ == "Boolean":
        return text in ("true", "1")
    if type_ == "String":
        return text.encode("utf-8")
    return int(text)

