"""FMI 1.0 co-simulation FMUs in the master, beside FMI 2.0 and 3.0 ones.

Legacy supplier FMUs and the Open Simulation Platform's demo FMUs are FMI 1.0; libcosim and FMPy
import them. `Fmi1Calls` gives the instance table what FMPy's FMU2Slave gives it for FMI 2.0
(the calls by their FMI 2.0 names and signatures, and the life-cycle methods), over FMPy's FMI
1.0 binding (`fmpy.fmi1.FMU1Slave` loads the library and makes the life-cycle calls; the value
calls go to the library's `<modelIdentifier>_fmiGet*`/`_fmiSet*` functions directly, as the
FMI 2.0 ones go to FMPy's loaded functions).

What differs from FMI 2.0, and what the master does about it:

- Initialization: FMI 1.0 has no initialization mode. Parameters and start values are set after
  fmiInstantiateSlave; in the master's exchange in dependency order, fmiInitializeSlave(tStart,
  tStop) is called once the FMU's inputs have been set (system_ssp.master.instances), and its
  outputs are read after it. Before that an FMI 1.0 FMU is not asked for values (the standard
  allows fmiGet* only after fmiInitializeSlave): its outputs read as their start values (0, false,
  "" or an Enumeration's first item without one).
- fmiBoolean is a char: Booleans are converted from and to the master's int buffers.
- No fmiTerminated status: an FMU that returns fmiDiscard from fmiDoStep has failed the step
  (this master does not retry); no FMU state, no output dependencies in a ModelStructure (the
  DirectDependency elements are read: system_ssp.master.components).
"""
import ctypes
from ctypes import POINTER, c_double, c_int, c_size_t, c_ubyte, c_uint, c_void_p

from fmpy import calloc, free
from fmpy.fmi1 import (FMU1Slave, fmi1CallbackAllocateMemoryTYPE, fmi1CallbackFreeMemoryTYPE, fmi1CallbackFunctions,
                       fmi1CallbackLoggerTYPE)
from fmpy.logging import addLoggerProxy

from .connections import KIND
from .list_calls import ListCalls

_KINDS = ("Real", "Integer", "Boolean", "String")  # the value calls: FMI 1.0's fmiBoolean is a char
_ALLOCATE = fmi1CallbackAllocateMemoryTYPE(calloc)
_FREE = fmi1CallbackFreeMemoryTYPE(free)


class Fmi1Calls(ListCalls):
    """An FMI 1.0 co-simulation FMU instance behind the calls the instance table makes on FMPy's
    FMU2Slave (see the module's text)."""

    def __init__(self, info, instance_name):
        md = info.md
        self.slave = FMU1Slave(guid=md.guid, unzipDirectory=info.unzipdir,
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=instance_name)
        prefix = f"{md.coSimulation.modelIdentifier}_fmi"
        dll = self.slave.dll
        self._raw = {}
        for kind in _KINDS:
            for verb in ("Get", "Set"):
                fn = getattr(dll, f"{prefix}{verb}{kind}")
                fn.argtypes = [c_void_p, POINTER(c_uint), c_size_t, c_void_p]
                fn.restype = c_int
                self._raw[(verb, kind)] = fn
        step = getattr(dll, f"{prefix}DoStep")
        step.argtypes = [c_void_p, c_double, c_double, c_ubyte]
        step.restype = c_int
        # the start values an output reads as before fmiInitializeSlave, by (kind, value reference):
        # FMI 1.0 variables of different types may share a value reference
        self._starts = {}
        for v in md.modelVariables:
            if v.type in KIND:
                # an Enumeration without a start: its first item (FMI 1.0 numbers the items from 1)
                start = v.start if v.start is not None or v.type != "Enumeration" else "1"
                self._starts.setdefault((KIND[v.type], v.valueReference), _start(KIND[v.type], start))
        self.initialized = False
        self.component = None
        self.fn = {f"fmi2{verb}{kind}": self._value_call(verb, kind) for kind in _KINDS for verb in ("Get", "Set")}
        self.fn["fmi2DoStep"] = lambda c, t, h, no_set_prior: step(c, t, h, 1)

    # ---- values ------------------------------------------------------------------------
    def specialized(self, name, vr, n):
        """The FMI 2.0-style call `name` (fmi2GetReal ...) for a value-reference block."""
        return self.fn[name]

    def _value_call(self, verb, kind):
        raw = self._raw[(verb, kind)]
        calls, starts = self, self._starts
        if verb == "Get":
            def get(c, vr, n, buf):
                if not calls.initialized:  # no fmiGet* before fmiInitializeSlave: the start values
                    for i in range(n):
                        buf[i] = starts.get((kind, vr[i]), _start(kind, None))
                    return 0
                if kind != "Boolean":
                    return raw(c, vr, n, buf)
                chars = (c_ubyte * n)()
                s = raw(c, vr, n, chars)
                for i in range(n):
                    buf[i] = 1 if chars[i] else 0
                return s

            return get
        if kind != "Boolean":
            return raw

        def set_boolean(c, vr, n, buf):
            chars = (c_ubyte * n)(*[1 if buf[i] else 0 for i in range(n)])
            return raw(c, vr, n, chars)

        return set_boolean

    # ---- FMPy's FMU2Slave interface, as the instance table uses it ----------------------
    def instantiate(self, visible, callbacks, logging_on):
        messages, env = callbacks

        def log(component, instance_name, status, category, message):
            messages.log(env, instance_name, status, category, message)

        cb = fmi1CallbackFunctions()
        self._logger = fmi1CallbackLoggerTYPE(log)  # the proxy below keeps a C pointer to it
        cb.logger = self._logger
        cb.allocateMemory = _ALLOCATE
        cb.freeMemory = _FREE
        cb.stepFinished = None
        addLoggerProxy(ctypes.byref(cb))  # formats printf-style messages of C FMUs
        self._callbacks = cb  # kept alive with the instance: the FMU calls its logger at any time
        self.slave.instantiate(functions=cb, loggingOn=logging_on)
        if not self.slave.component:
            raise RuntimeError("fmiInstantiateSlave returned NULL")
        self.component = self.slave.component
        self.bind_list_calls()

    def setupExperiment(self, tolerance, start, stop):
        self._experiment = (start, stop)

    def enterInitializationMode(self):
        pass  # FMI 1.0 has none: values are set between fmiInstantiateSlave and fmiInitializeSlave

    def exitInitializationMode(self):
        start, stop = self._experiment
        self.slave.initialize(tStart=start, stopTime=stop)
        self.initialized = True

    def terminate(self):
        self.slave.terminate()

    def free_instance(self):
        self.slave.fmi1FreeSlaveInstance(self.component)

    def freeLibrary(self):
        self.slave.freeLibrary()


def _start(kind, text):
    """A start value's text (None: no start) as the master's value of its kind."""
    if kind == "Real":
        return float(text) if text is not None else 0.0
    if kind == "Boolean":
        return 1 if text in ("true", "1") else 0
    if kind == "String":
        return (text or "").encode("utf-8")
    return int(text) if text is not None else 0
