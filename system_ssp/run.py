"""One simulation run: FMU instances, initialization, stepping loops, recording.

Built by `System.run`; not meant to be used directly.
"""
import ctypes
import math
import sys

import numpy as np

from .errors import SimulationError, SSPError

_CT = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int}
_NP = {"Real": np.float64, "Integer": np.int32, "Boolean": np.int32}
_GET = {"Real": "fmi2GetReal", "Integer": "fmi2GetInteger", "Boolean": "fmi2GetBoolean"}
_SET = {"Real": "fmi2SetReal", "Integer": "fmi2SetInteger", "Boolean": "fmi2SetBoolean"}
_KIND = {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean"}
_STATUS = ["ok", "warning", "discard", "error", "fatal", "pending"]
_RESULT_DTYPE = {"Real": np.float64, "Integer": np.int64, "Boolean": np.bool_}


class _Failed(Exception):
    def __init__(self, ci, call, status):
        self.ci, self.call, self.status = ci, call, status


_CALLBACKS_KEPT = []


class _Instance:
    """One FMU instance plus the logger that collects its messages."""

    def __init__(self, info, run):
        from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
        from fmpy import calloc, free

        self.info = info
        self.name = info.name
        self.messages = []  # (status label, category, message)
        self.instantiated = False
        self.initialized = False
        self.failed = False
        md = info.md

        def logger(env, instance_name, status, category, message):
            try:
                text = message.decode("utf-8", "replace") if message else ""
                cat = category.decode("utf-8", "replace") if category else ""
                label = _STATUS[status] if 0 <= status < len(_STATUS) else str(status)
                if status >= 1 or run.debug:
                    # pythonfmu reports through the logger of the most recently instantiated
                    # instance, so route by the instance name the FMU passes.
                    name = instance_name.decode("utf-8", "replace") if instance_name else ""
                    target = run.by_name.get(name, self)
                    target.messages.append((label, cat, text))
                    if len(target.messages) > 200:
                        del target.messages[:100]
            except Exception:  # never let a logging problem propagate into C
                pass

        self._logger = fmi2CallbackLoggerTYPE(logger)
        cb = fmi2CallbackFunctions()
        cb.logger = self._logger
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        try:
            from fmpy.logging import addLoggerProxy
            addLoggerProxy(ctypes.byref(cb))
        except Exception:
            pass
        self.callbacks = cb
        # pythonfmu keeps the logger of the instance created last and may call it after that
        # instance is gone (messages of other instances, teardown at exit): the callbacks
        # must outlive every instance, so they are kept for the life of the process.
        _CALLBACKS_KEPT.append((self._logger, cb))
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=info.unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=info.name)
        self.fn = self.fmu._functions

    def take_messages(self):
        msgs = self.messages
        self.messages = []
        return msgs


class Run:
    def __init__(self, system, plan):
        self.system = system
        self.plan = plan
        self.debug = False
        self.instances = []
        self.by_name = {}
        self.t = plan["start"]

    # ---- errors -------------------------------------------------------------------------
    def _error(self, ci, call, exc=None, status=None):
        inst = self.instances[ci]
        inst.failed = True
        msgs = inst.take_messages()
        texts = []
        for _, _, m in msgs:
            if "PyObject_CallMethod\n" in m:  # pythonfmu: keep the Python exception text
                m = m.split("PyObject_CallMethod\n", 1)[1]
            if m and m not in texts:
                texts.append(m.strip())
        text = "; ".join(texts)
        if status is not None:
            what = f"returned status {_STATUS[status] if 0 <= status < len(_STATUS) else status}"
        elif exc is not None and not texts:
            what = f"failed ({exc})"
        else:
            what = "failed"
        detail = f": {text}" if text else ""
        return SimulationError(f"component {inst.name!r}: {call} {what} at t={self.t:g} s{detail}")

    def _call(self, ci, call, fn, *args):
        """Call an fmpy method; wrap failures with the component's logged messages."""
        try:
            return fn(*args)
        except SSPError:
            raise
        except Exception as exc:
            raise self._error(ci, call, exc) from None

    # ---- main -------------------------------------------------------------------------
    def execute(self, progress=False):
        try:
            self._instantiate()
            self._prepare()
            self._initialize()
            if self.plan.get("schedule"):
                return self._loop_scheduled(progress)
            return self._loop(progress)
        except _Failed as f:
            raise self._error(f.ci, f.call, status=f.status) from None
        finally:
            self._free()

    def _instantiate(self):
        p = self.plan
        for info in self.system.comps:
            try:
                inst = _Instance(info, self)
            except Exception as exc:
                raise SimulationError(f"component {info.name!r}: cannot load the FMU binary "
                                      f"({self.system.namer(info.decl.fmu_path)}): {exc}") from None
            self.instances.append(inst)
            self.by_name[inst.name] = inst
            ci = len(self.instances) - 1
            self._call(ci, "fmi2Instantiate", inst.fmu.instantiate, False, inst.callbacks, True)
            inst.instantiated = True
        for ci, inst in enumerate(self.instances):
            self._call(ci, "fmi2SetupExperiment", inst.fmu.setupExperiment, None, p["start"], p["stop"])
            self._call(ci, "fmi2EnterInitializationMode", inst.fmu.enterInitializationMode)
            inst.initialized = True
        # parameters and start values, batched per component and type
        per = {}
        for (ci, var), value in p["params"].items():
            v = self.system.comps[ci].vars[var]
            per.setdefault((ci, v.type), ([], []))
            per[(ci, v.type)][0].append(v.valueReference)
            per[(ci, v.type)][1].append(value)
        for (ci, vtype), (vrs, values) in sorted(per.items()):
            fmu = self.instances[ci].fmu
            setter = {"Real": fmu.setReal, "Integer": fmu.setInteger, "Enumeration": fmu.setInteger,
                      "Boolean": fmu.setBoolean, "String": fmu.setString}[vtype]
            self._call(ci, f"setting parameters/start values ({vtype})", setter, vrs, values)

    def _free(self):
        for inst in self.instances:
            if inst.failed:
                # FMI 2.0: after an error/fatal status only fmi2FreeInstance may be called; a
                # pythonfmu instance that raised is left alone (freeing it can crash at exit).
                continue
            try:
                if inst.initialized:
                    inst.fmu.terminate()
            except Exception:
                pass
            try:
                # fmi2FreeInstance only: unloading a pythonfmu library (dlclose) while the
                # interpreter still holds objects created by it crashes the process at exit,
                # so the library stays loaded (dlopen of the same file reuses it next run).
                if inst.instantiated:
                    inst.fmu.fmi2FreeInstance(inst.fmu.component)
            except Exception:
                pass
        self.instances = []

    # ---- buffers and op lists -------------------------------------------------------------
    def _prepare(self):
        sysm = self.system
        comps = sysm.comps
        n = len(comps)
        # connected outputs: per type, one global buffer; each (comp, var) a slot
        slots = {"Real": {}, "Integer": {}, "Boolean": {}}
        for lk in sysm.links:
            key = (lk.src, lk.src_var)
            d = slots[lk.vtype]
            if key not in d:
                d[key] = None
        self.G = {}
        self.gets = [[] for _ in range(n)]
        for kind, d in slots.items():
            by_comp = {}
            for (ci, var) in d:
                by_comp.setdefault(ci, []).append(var)
            size = sum(len(v) for v in by_comp.values())
            G = np.zeros(max(size, 1), dtype=_NP[kind])
            self.G[kind] = G
            pos = 0
            for ci in sorted(by_comp):
                vars_ = by_comp[ci]
                m = len(vars_)
                for j, var in enumerate(vars_):
                    d[(ci, var)] = pos + j
                vr = (ctypes.c_uint * m)(*[comps[ci].vars[v].valueReference for v in vars_])
                buf = (_CT[kind] * m).from_address(G.ctypes.data + pos * G.itemsize)
                self.gets[ci].append((self.instances[ci].fn[_GET[kind]], self.instances[ci].fmu.component,
                                      vr, m, buf, _GET[kind]))
                pos += m
        self.slots = slots
        # inputs: per consumer and type
        self.sets = [[] for _ in range(n)]
        by_dst = {}
        for lk in sysm.links:
            by_dst.setdefault((lk.dst, lk.vtype), []).append(lk)
        for (ci, kind), lks in sorted(by_dst.items()):
            m = len(lks)
            vr = (ctypes.c_uint * m)(*[comps[ci].vars[lk.dst_var].valueReference for lk in lks])
            buf = (_CT[kind] * m)()
            view = np.ctypeslib.as_array(buf)
            idx = np.array([slots[kind][(lk.src, lk.src_var)] for lk in lks], dtype=np.intp)
            fac = np.array([lk.factor for lk in lks])
            off = np.array([lk.offset for lk in lks])
            affine = kind == "Real" and (np.any(fac != 1.0) or np.any(off != 0.0))
            post = None
            maps = [(j, lk.mapping) for j, lk in enumerate(lks) if lk.mapping]
            if maps:
                if kind == "Boolean":
                    def post(view, maps=maps):
                        for j, mp in maps:
                            view[j] = int(mp.get(bool(view[j]), bool(view[j])))
                else:
                    def post(view, maps=maps):
                        for j, mp in maps:
                            view[j] = mp.get(int(view[j]), int(view[j]))
            self.sets[ci].append((self.instances[ci].fn[_SET[kind]], self.instances[ci].fmu.component, vr, m, buf,
                                  view, self.G[kind], idx, fac if affine else None, off if affine else None, post,
                                  _SET[kind], [None]))
        # recording
        p = self.plan
        rec_by = {}
        self.rec_names = []
        self.rec_kinds = []
        for ci, var in p["record"]:
            kind = _KIND[comps[ci].vars[var].type]
            rec_by.setdefault((ci, kind), []).append(var)
        self.recs = []
        col = 0
        for (ci, kind), vars_ in sorted(rec_by.items()):
            m = len(vars_)
            vr = (ctypes.c_uint * m)(*[comps[ci].vars[v].valueReference for v in vars_])
            buf = (_CT[kind] * m)()
            self.recs.append((self.instances[ci].fn[_GET[kind]], self.instances[ci].fmu.component, vr, m, buf,
                              np.ctypeslib.as_array(buf), col, col + m, ci, _GET[kind]))
            for v in vars_:
                self.rec_names.append(f"{comps[ci].name}.{v}")
                self.rec_kinds.append(kind)
            col += m
        self.ncols = col
        # stop conditions
        st_by = {}
        for ci, var in p["stops"]:
            st_by.setdefault(ci, []).append(var)
        self.stop_ops = []
        for ci, vars_ in sorted(st_by.items()):
            m = len(vars_)
            vr = (ctypes.c_uint * m)(*[comps[ci].vars[v].valueReference for v in vars_])
            buf = (ctypes.c_int * m)()
            self.stop_ops.append((self.instances[ci].fn["fmi2GetBoolean"], self.instances[ci].fmu.component, vr, m,
                                  buf, ci, [f"{comps[ci].name}.{v}" for v in vars_]))
        self.step_fns = [(inst.fn["fmi2DoStep"], inst.fmu.component) for inst in self.instances]
        # components whose connected outputs change when their inputs are set
        self.has_ft = [bool(sysm.feedthrough_outputs[ci]) and bool(self.gets[ci]) for ci in range(n)]

    # ---- primitive phases -----------------------------------------------------------------
    def _get(self, ci):
        for fn, c, vr, m, buf, name in self.gets[ci]:
            s = fn(c, vr, m, buf)
            if s > 1:
                raise _Failed(ci, name, s)

    def _set(self, ci):
        """Set ci's connected inputs from the output buffers. A batch whose values are the ones
        last set is not sent again: inputs keep their values in FMI, and a call into a
        pythonfmu FMU costs about 10 us, which a byte comparison saves."""
        take = np.take
        for fn, c, vr, m, buf, view, G, idx, fac, off, post, name, last in self.sets[ci]:
            take(G, idx, out=view)
            if fac is not None:
                view *= fac
                view += off
            if post is not None:
                post(view)
            sent = view.tobytes()
            if sent == last[0]:
                continue
            s = fn(c, vr, m, buf)
            if s > 1:
                raise _Failed(ci, name, s)
            last[0] = sent

    def _check_stop(self):
        """Name of the first stop signal that is true, or None."""
        for fn, c, vr, m, buf, ci, names in self.stop_ops:
            s = fn(c, vr, m, buf)
            if s > 1:
                raise _Failed(ci, "fmi2GetBoolean", s)
            for j in range(m):
                if buf[j]:
                    return names[j]
        return None

    def _read_row(self, r):
        """Read every recorded variable into the row array r."""
        for fn, c, vr, m, buf, view, a, b, ci, name in self.recs:
            s = fn(c, vr, m, buf)
            if s > 1:
                raise _Failed(ci, name, s)
            r[a:b] = view

    def _initialize(self):
        sysm = self.system
        n = len(sysm.comps)
        for ci in range(n):
            self._get(ci)
        from .master import _toposort
        order, cycle = _toposort(n, sysm.edges)
        passes = 1
        if cycle:  # only reachable with Jacobi: iterate like a fixed-point exchange
            order, passes = list(range(n)), n
        for _ in range(passes):
            for ci in order:
                self._set(ci)
                self._get(ci)
        for ci, inst in enumerate(self.instances):
            self._call(ci, "fmi2ExitInitializationMode", inst.fmu.exitInitializationMode)
        for _ in range(passes):
            for ci in order:
                self._get(ci)
                self._set(ci)
        for ci in range(n):
            self._get(ci)
        self.init_order = order

    # ---- stepping -------------------------------------------------------------------------
    def _loop(self, progress):
        p = self.plan
        start, stop, h, N = p["start"], p["stop"], p["h"], p["n_steps"]
        every = p["record_every"]
        n_rows = N // every + 2
        rec = np.zeros((n_rows, self.ncols), dtype=np.float64)
        times = np.zeros(n_rows, dtype=np.float64)
        stop_ops = self.stop_ops
        row = 0

        def record(t):
            nonlocal row
            self._read_row(rec[row])
            times[row] = t
            row += 1

        self.t = start
        record(start)
        fired = self._check_stop() if stop_ops else None
        steps = 0
        bar = None
        if progress and N >= 2000:
            try:
                from tqdm import tqdm
                bar = tqdm(total=N, file=sys.stderr, unit="step", leave=False, mininterval=0.5)
            except ImportError:
                bar = None
        chunk = max(1, N // 200)
        order = p["order"]
        mult = p["mult"]
        all_one = all(k == 1 for k in mult)
        jacobi = p["algorithm"] == "jacobi"
        step_fns = self.step_fns
        get, set_ = self._get, self._set
        n = len(self.instances)
        has_ft = self.has_ft
        t_last = start
        try:
            while fired is None and steps < N:
                k = steps
                t = start + k * h
                self.t = t
                if jacobi:
                    for ci in range(n):
                        mk = mult[ci]
                        if all_one or k % mk == 0:
                            nxt = k + mk
                            # The nominal step, not a difference of rounded times: models
                            # that integrate with the step (the thesis' Euler scripts) must
                            # see exactly h every step.
                            dt = mk * h if nxt < N else stop - t
                            fn, c = step_fns[ci]
                            s = fn(c, t, dt, 1)
                            if s > 1:
                                raise _Failed(ci, "fmi2DoStep", s)
                    for ci in range(n):
                        get(ci)
                    k1 = k + 1
                    # Record like libcosim's observers: outputs right after the step, inputs as
                    # used during it; then transfer for the next step.
                    t1 = start + k1 * h if k1 < N else stop
                    self.t = t1
                    if k1 % every == 0 or k1 == N:
                        record(t1)
                    if stop_ops:
                        fired = self._check_stop()
                    for ci in range(n):
                        if all_one or k1 % mult[ci] == 0 or k1 >= N:
                            set_(ci)
                else:
                    for ci in order:
                        mk = mult[ci]
                        if all_one or k % mk == 0:
                            nxt = k + mk
                            dt = mk * h if nxt < N else stop - t
                            set_(ci)
                            fn, c = step_fns[ci]
                            s = fn(c, t, dt, 1)
                            if s > 1:
                                raise _Failed(ci, "fmi2DoStep", s)
                            get(ci)
                    for ci in order:
                        set_(ci)
                        if has_ft[ci]:
                            get(ci)
                steps = k + 1
                t_last = start + steps * h if steps < N else stop
                self.t = t_last
                if not jacobi:
                    if steps % every == 0 or steps == N:
                        record(t_last)
                    if stop_ops:
                        fired = self._check_stop()
                if fired is not None and times[row - 1] != t_last:
                    record(t_last)
                if bar is not None and steps % chunk == 0:
                    bar.update(steps - bar.n)
        finally:
            if bar is not None:
                bar.close()
        if fired is not None:
            reason = f"stop condition {fired} at t={t_last:g} s"
        else:
            reason = "reached stop time"
        data = self._result_array(times[:row], rec[:row])
        final = self._final()
        from .master import Result
        return Result(data=data, stop_time=t_last, stop_reason=reason, steps=steps, final=final, wall_time=0.0,
                      start_time=start, step_size=h, algorithm=p["algorithm"],
                      order=[self.system.comps[i].name for i in order],
                      messages={inst.name: list(inst.messages) for inst in self.instances if inst.messages})

    def _loop_scheduled(self, progress):
        """Gauss-Seidel with mode-dependent communication steps (nc:Schedule).

        After initialization and after every macro step the master reads the schedule's
        condition signals and takes the first nc:Mode whose conditions all hold. The next macro
        step [t, t + h] is that mode's stepSize, shortened so that it ends exactly on the
        earliest nc:NextEvent time ahead (an FMU announcing e.g. a timer expiry) and on the stop
        time. Each component keeps its own time t_c:
        - active, every = 1: stepped from t_c to t + h (t_c = t, or a little before when it
          ran ahead in an earlier mode; communication points stay contiguous);
        - active, every = k > 1 (nc:Mode every="comp:k"): stepped when due (t_c <= t) from t_c
          to t + k stepSize, i.e. ahead of the master with its inputs held from t (like fixed-
          step multiples); until the master reaches t_c it is not stepped again;
        - not active in the mode: suspended, not stepped, outputs held, inputs not set. When it
          becomes active again its clock jumps to the current time: its next doStep starts
          there, and the suspended span is skipped, not integrated (FMI 2.0 does not require
          contiguous communication points; every component must declare
          canHandleVariableCommunicationStepSize).
        After the steps, direct-feedthrough components whose outputs the schedule or a stop
        condition watches, or that feed a component stepping before them, get their inputs again
        and their outputs are read (so conditions, stop signals and the next steps see values at
        t + h); the rest is brought up to date on recorded rows (every active component), and
        inputs are always set right before a doStep. Rows are
        recorded every `recordEvery` macro steps of a mode, at every mode change, at a stop
        condition and at the end."""
        import time as _time

        p = self.plan
        sch = p["schedule"]
        start, stop = p["start"], p["stop"]
        n = len(self.instances)
        comps = self.system.comps
        for ci in range(n):
            if comps[ci].md.coSimulation is not None and not comps[ci].md.coSimulation.canHandleVariableCommunicationStepSize:
                raise SimulationError(f"{sch['origin']}: component {comps[ci].name!r} cannot handle a variable "
                                      "communication step size, which nc:Schedule needs")

        def reader(ci, var, kind):  # straight through the FMI functions, like stop conditions
            vr = (ctypes.c_uint * 1)(comps[ci].vars[var].valueReference)
            buf = (_CT[kind] * 1)()
            return (self.instances[ci].fn[_GET[kind]], self.instances[ci].fmu.component, vr, buf, ci,
                    f"{comps[ci].name}.{var}")

        consumers = [set() for _ in range(n)]
        producers = [set() for _ in range(n)]
        for lk in self.system.links:
            consumers[lk.src].add(lk.dst)
            producers[lk.dst].add(lk.src)
        watched = {ci for ci, _ in p["stops"]} | {ci for ci, _ in sch["events"]}
        watched |= {ci for m in sch["modes"] for ci, _, _ in m["conds"]}

        def refreshed(order):
            """Feedthrough components whose outputs must be brought to t + h after the steps:
            those watched by the schedule or a stop condition, those read by a component that
            steps before them, and (transitively) their feedthrough producers. The others are
            read fresh in the next step pass anyway."""
            pos = {ci: k for k, ci in enumerate(order)}
            need = {ci for ci in order if self.has_ft[ci]
                    and (ci in watched or any(cj in pos and pos[cj] < pos[ci] for cj in consumers[ci]))}
            grow = list(need)
            while grow:
                for cj in producers[grow.pop()]:
                    if cj in pos and self.has_ft[cj] and cj not in need:
                        need.add(cj)
                        grow.append(cj)
            return [ci for ci in order if ci in need]

        modes = []
        for m in sch["modes"]:
            conds = [(reader(ci, var, _KIND[comps[ci].vars[var].type]), vals) for ci, var, vals in m["conds"]]
            order = [ci for ci in p["order"] if m["active"][ci]]
            modes.append((m["name"], m["h"], order, m["every"], conds, m["mult"], refreshed(order)))
        events = [reader(ci, var, "Real") for ci, var in sch["events"]]

        def read(op):
            fn, c, vr, buf, ci, name = op
            s = fn(c, vr, 1, buf)
            if s > 1:
                raise _Failed(ci, name, s)
            return buf[0]

        def pick():
            for mode in modes:
                if all(int(read(op)) in vals for op, vals in mode[4]):
                    return mode
            raise SimulationError(f"{sch['origin']}: no nc:Mode matches at t={self.t:g} s ("
                                  + ", ".join(f"{op[5]}={int(read(op))}" for mode in modes for op, _ in mode[4])
                                  + "); end the schedule with an unconditional nc:Mode")

        stop_ops = self.stop_ops
        rows, times = [], []
        set_, get = self._set, self._get

        has_ft = self.has_ft

        def record(t):
            # every active component's inputs and feedthrough outputs as they stand at t (the
            # step loop refreshes only what the next steps need); rows are also recorded at each
            # mode change, so a component suspended by the change holds its outputs at t
            for ci in active_order:
                set_(ci)
                if has_ft[ci]:
                    get(ci)
            r = np.empty(self.ncols, dtype=np.float64)
            self._read_row(r)
            rows.append(r)
            times.append(t)

        profile = p.get("profile")
        spent = [0.0] * n
        mode_time = {m[0]: 0.0 for m in modes}
        mode_steps = {m[0]: 0 for m in modes}
        perf = _time.perf_counter
        wall0 = perf()
        t = start
        self.t = t
        tc = [start] * n  # each component's own time
        mode = pick()
        active_order = mode[2]
        suspended = [ci not in active_order for ci in range(n)]
        record(t)
        fired = self._check_stop() if stop_ops else None
        steps = 0
        since_record = 0
        # Times closer than this are the same instant: a few ulps of the largest time in the run
        # (1.5e-5 s at 40 years), far below any step, so that t + (t_event - t) lands on t_event.
        tol = 64.0 * math.ulp(max(1.0, abs(start), abs(stop)))
        step_fns = self.step_fns
        bar = None
        if progress:
            try:
                from tqdm import tqdm
                bar = tqdm(total=stop - start, file=sys.stderr, unit="s", leave=False, mininterval=0.5)
            except ImportError:
                bar = None
        try:
            # Signals are re-read only when the component that outputs them was stepped or
            # refreshed in the macro step (a held output cannot change).
            ev_comps = [op[4] for op in events]
            ev_values = [read(op) for op in events]
            cond_comps = sorted({op[4] for m in modes for op, _ in m[4]})
            stop_comps = [op[5] for op in stop_ops]
            prod = [sorted(producers[ci]) for ci in range(n)]
            while fired is None and t < stop - tol:
                name, h_mode, order, every, _, mult, ft_order = mode
                active_order = order
                h = h_mode
                for j, te in enumerate(ev_values):
                    if te > t + tol and te - t < h:
                        h = te - t
                if stop - t < h + tol:
                    h = stop - t
                t1 = t + h if stop - (t + h) > tol else stop
                changed = [False] * n
                for ci in order:
                    if suspended[ci]:
                        tc[ci] = t  # back from suspension: the clock jumps to now
                        suspended[ci] = False
                    t_c = tc[ci]
                    if t_c > t + tol:
                        continue  # ahead of the master (stepped with a multiple)
                    k = mult[ci]
                    end = t1 if k == 1 else min(t + k * h_mode, stop)
                    if end - t_c <= tol:
                        continue  # already at the end of this step (it ran ahead)
                    if profile:
                        w0 = perf()
                    set_(ci)
                    fn, c = step_fns[ci]
                    s = fn(c, t_c, end - t_c, 1)
                    if s > 1:
                        raise _Failed(ci, "fmi2DoStep", s)
                    get(ci)
                    tc[ci] = end
                    changed[ci] = True
                    if profile:
                        spent[ci] += perf() - w0
                for ci in ft_order:
                    if changed[ci] or any(changed[cp] for cp in prod[ci]):
                        set_(ci)
                        get(ci)
                        changed[ci] = True
                t = t1
                self.t = t
                steps += 1
                since_record += 1
                mode_time[name] += h
                mode_steps[name] += 1
                if stop_ops and any(changed[ci] for ci in stop_comps):
                    fired = self._check_stop()
                for j, ci in enumerate(ev_comps):
                    if changed[ci]:
                        ev_values[j] = read(events[j])
                nxt = pick() if any(changed[ci] for ci in cond_comps) else mode
                if nxt is not mode:
                    active_now = set(nxt[2])
                    for ci in range(n):
                        if ci not in active_now:
                            suspended[ci] = True
                if since_record >= every or nxt is not mode or fired is not None or t >= stop:
                    record(t)
                    since_record = 0
                mode = nxt
                if bar is not None:
                    bar.update(t - start - bar.n)
        finally:
            if bar is not None:
                bar.close()
        if times[-1] != t:
            record(t)
        for ci in mode[2]:
            set_(ci)
        total = perf() - wall0
        reason = f"stop condition {fired} at t={t:g} s" if fired is not None else "reached stop time"
        data = self._result_array(np.array(times), np.array(rows).reshape(len(rows), self.ncols))
        final = self._final()
        from .master import Result
        res = Result(data=data, stop_time=t, stop_reason=reason, steps=steps, final=final, wall_time=0.0,
                     start_time=start, step_size=None, algorithm="gauss-seidel",
                     order=[comps[i].name for i in p["order"]],
                     messages={inst.name: list(inst.messages) for inst in self.instances if inst.messages})
        res.modes = {m: {"steps": mode_steps[m], "simulated_time": mode_time[m]} for m in mode_steps}
        if profile:
            res.profile = {"components": {comps[ci].name: spent[ci] for ci in range(n)},
                           "loop": total, "master": total - sum(spent)}
        return res

    def _result_array(self, times, rec):
        col_of = {name: j for j, name in enumerate(self.rec_names)}
        wanted = [f"{self.system.comps[ci].name}.{var}" for ci, var in self.plan["record"]]
        kind_of = dict(zip(self.rec_names, self.rec_kinds))
        dtype = [("time", np.float64)] + [(name, _RESULT_DTYPE[kind_of[name]]) for name in wanted]
        data = np.zeros(len(times), dtype=dtype)
        data["time"] = times
        for name in wanted:
            j, k = col_of[name], kind_of[name]
            col = rec[:, j]
            data[name] = col.astype(_RESULT_DTYPE[k]) if k != "Boolean" else (col != 0)
        return data

    def _final(self):
        final = {}
        for ci, inst in enumerate(self.instances):
            info = inst.info
            groups = {}
            for v in info.md.modelVariables:
                if v.causality in ("input", "output") and v.type in _KIND:
                    groups.setdefault(_KIND[v.type], []).append(v)
            for kind, vs in groups.items():
                getter = {"Real": inst.fmu.getReal, "Integer": inst.fmu.getInteger,
                          "Boolean": inst.fmu.getBoolean}[kind]
                vals = self._call(ci, _GET[kind], getter, [v.valueReference for v in vs])
                for v, x in zip(vs, vals):
                    final[f"{info.name}.{v.name}"] = bool(x) if kind == "Boolean" else (
                        int(x) if kind == "Integer" else float(x))
        return final
