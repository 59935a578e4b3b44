"""What the FMI 1.0 and FMI 3.0 adapters (system_ssp.master.fmi1, .fmi3) share: FMPy's list-based
calls (getReal(vrs), setReal(vrs, values), ... for parameters and final values) over the FMI
2.0-named value functions each adapter gives the instance table (`fn`, `component`)."""
from ctypes import c_char_p, c_double, c_int, c_uint32

# the C type of each of the master's kinds in its buffers (Booleans as int, as FMI 2.0 has them)
MASTER_C = {"Real": c_double, "Integer": c_int, "Boolean": c_int, "String": c_char_p}


class ListCalls:
    """Mixed into an adapter: `bind_list_calls()` once the instance exists gives it getReal,
    setReal, getInteger, ... as FMPy's FMU2Slave has them; a failed call raises naming the
    standard's call (`CALL_PREFIX` + Get/Set + kind)."""
    CALL_PREFIX = "fmi"

    def bind_list_calls(self):
        for kind in MASTER_C:
            get, set_ = self._list_calls(kind)
            setattr(self, f"get{kind}", get)
            setattr(self, f"set{kind}", set_)

    def _list_calls(self, kind):
        ctype, prefix = MASTER_C[kind], self.CALL_PREFIX

        def get(vrs):
            vrs = list(vrs)
            buf = (ctype * len(vrs))()
            s = self.fn[f"fmi2Get{kind}"](self.component, (c_uint32 * len(vrs))(*vrs), len(vrs), buf)
            if s > 1:
                raise RuntimeError(f"{prefix}Get{kind} returned status {s}")
            return list(buf)

        def set_(vrs, values):
            vrs = list(vrs)
            buf = (ctype * len(vrs))(*[v.encode("utf-8") if isinstance(v, str) else v for v in values])
            s = self.fn[f"fmi2Set{kind}"](self.component, (c_uint32 * len(vrs))(*vrs), len(vrs), buf)
            if s > 1:
                raise RuntimeError(f"{prefix}Set{kind} returned status {s}")

        return get, set_
