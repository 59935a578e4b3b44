"""The Gauss-Seidel step loop compiled with numba: many macro steps per call from Python.

The Python loop (algorithms.py) makes, per macro step and component, a Python call that gathers
the inputs from the shared output buffers, compares them with the ones last sent and calls the
FMU; with twenty components that is most of the master's cost. Here the same sequence runs in one
compiled function over flat tables built once per run (`Tables`), calling the FMI functions (and
our runtime's batched `neighborStepIO`) through their addresses in the libraries FMPy loaded:

- a component is stepped exactly as `InstanceTable._batched_stepper` steps it (the same gathers,
  the same "send only when the bytes changed" test, one neighborStepIO call);
- inputs are set and outputs read exactly as `SetOp.run` and `GetOp.run` do;
- `scheduled_span` takes the steps of one nc:Mode as `ScheduledAlgorithm._advance` does and stops
  after the step at which a schedule condition signal changed value, a stop signal is true, the
  run ends or `max_steps` were taken (the recorder's next row): Python then picks the mode,
  records and runs the observers, which see the span's last step;
- `fixed_span` is `FixedStepAlgorithm.run`'s Gauss-Seidel step.

So the FMUs receive the same calls with the same values in the same order; the results are the
same bit for bit (tests run both loops). It serves runs whose components all export
neighborStepIO (our FMUs, FMI 2.0) and whose connections need no Integer/Boolean mapping; every
other run, and runs with the profiler, the caller's observers or FMU debug logging, keep the
Python loop, as do short runs while numba is not loaded (algorithms.compiled_loop imports this
module, numba with it, only for a run it repays). NEIGHBOR_COSIM_COMPILED_LOOP=0 keeps the Python
loop everywhere, =1 takes this one for short runs too.

A failed call returns its status and what failed (ERROR_*: the component's batched step, set
operation, get operation or signal read) and Python raises the StepFailed the Python loop would.
"""
import ctypes
import os
from typing import Any, NamedTuple

from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic
import numpy as np

from .instances import StepFailed

ENABLED = os.environ.get("NEIGHBOR_COSIM_COMPILED_LOOP", "1") != "0"

# what failed, in status_out[1] (status_out[0]: the FMI status, status_out[2]: the index)
ERROR_STEP, ERROR_SET, ERROR_GET, ERROR_SIGNAL, ERROR_EVENT, ERROR_STOP, ERROR_RECORD = 1, 2, 3, 4, 5, 6, 7
# the span's end, in its returned flags
CONDITION_CHANGED, STOP_FIRED, FAILED = 1, 2, 4
# a reader of a refreshed component's outputs in a mode (LazyRefresh.kind): a stepping one that
# steps after it, one that steps before it (or is itself); a refreshed one after it, before it
READER_AFTER, READER_BEFORE, READER_REFRESHED, READER_REFRESHED_BEFORE = 0, 1, 2, 3


@intrinsic
def _call_step_io(typingctx, fn, component, io):
    """int neighborStepIO(void *component, StepIO *io) at address fn."""
    sig = types.int32(types.int64, types.int64, types.int64)

    def codegen(context, builder, signature, args):
        voidp = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.IntType(32), [voidp, voidp])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [builder.inttoptr(args[1], voidp), builder.inttoptr(args[2], voidp)])

    return sig, codegen


@intrinsic
def _call_values(typingctx, fn, component, vr, n, values):
    """fmi2Status fmi2Get*/fmi2Set*(component, const unsigned int vr[], size_t n, values[]) at address fn."""
    sig = types.int32(types.int64, types.int64, types.int64, types.int64, types.int64)

    def codegen(context, builder, signature, args):
        voidp = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.IntType(32), [voidp, voidp, ir.IntType(64), voidp])
        f = builder.inttoptr(args[0], fnty.as_pointer())
        return builder.call(f, [builder.inttoptr(args[1], voidp), builder.inttoptr(args[2], voidp), args[3],
                                builder.inttoptr(args[4], voidp)])

    return sig, codegen


# The loop's functions pass the run's tables (Tables: about seventy arrays) to one another at every
# component and step. With numba's reference counting each such call increfs and decrefs every
# array in them, atomically: 9 % of the default mission's time and most of the master's own cost
# per FMU call. They allocate nothing, and Python holds every array for the run, so they are
# compiled without the runtime's reference counting (numba's own `_nrt` option, which its
# string functions use the same way). The run's results are the same bit for bit.
_LOOP_OPTIONS: dict[str, Any] = {"cache": True, "_nrt": False}  # numba's typing of njit leaves the option out
_loop_function = njit(**_LOOP_OPTIONS)
NO_COMPONENTS = np.empty(0, dtype=np.int64)  # fixed_span's `active` for _row_due (it allocates nothing itself)


class Tables(NamedTuple):
    """The run's transfers as flat arrays (built by `build_tables`); addresses as int64."""
    component: np.ndarray        # [n] fmi2Component
    step_fn: np.ndarray          # [n] neighborStepIO
    io_address: np.ndarray       # [n] the component's StepIO block
    io_f64: np.ndarray           # the StepIO blocks as doubles (t, h) ...
    io_i32: np.ndarray           # ... and as ints (send, failed)
    io_layout: np.ndarray        # [doubles per block, ints per block, t, h, send, failed] offsets
    set_kind: np.ndarray         # [m] per set operation: 0 Real, 1 Integer, 2 Boolean
    set_start: np.ndarray        # [m] its first position in the kind's input buffer
    set_len: np.ndarray
    set_affine: np.ndarray       # [m] bool: factor/offset apply
    set_valid: np.ndarray        # [m] bool: the input buffer holds the values last sent
    set_fn: np.ndarray           # [m] fmi2Set*
    set_vr: np.ndarray
    set_buf: np.ndarray
    set_ptr: np.ndarray          # [n + 1] component ci's set operations: set_list[set_ptr[ci]:set_ptr[ci + 1]]
    set_list: np.ndarray
    set_by_kind: np.ndarray      # [n, 3] the batched step's set operation per kind, or -1
    get_ptr: np.ndarray          # [n + 1] component ci's get operations
    get_fn: np.ndarray
    get_vr: np.ndarray
    get_len: np.ndarray
    get_buf: np.ndarray
    idx_real: np.ndarray         # per input position: the connected output's position in G
    idx_int: np.ndarray
    idx_bool: np.ndarray
    factor: np.ndarray           # per Real input position
    offset: np.ndarray
    g_real: np.ndarray           # the shared output buffers (InstanceTable.G)
    g_real_bits: np.ndarray
    g_int: np.ndarray
    g_bool: np.ndarray
    in_real: np.ndarray          # the input buffers (InstanceTable.IN)
    in_real_bits: np.ndarray
    in_int: np.ndarray
    in_bool: np.ndarray
    prod_ptr: np.ndarray         # [n + 1] component ci's producers: prod_list[prod_ptr[ci]:prod_ptr[ci + 1]]
    prod_list: np.ndarray
    has_ft: np.ndarray           # [n] bool
    sig_ci: np.ndarray           # schedule condition signals (Integer/Boolean, one value each)
    sig_fn: np.ndarray
    sig_vr: np.ndarray
    sig_buf: np.ndarray          # int32 scratch, one per signal
    sig_values: np.ndarray       # int64: the values the mode was picked with
    ev_ci: np.ndarray            # nc:NextEvent signals (Real)
    ev_fn: np.ndarray
    ev_vr: np.ndarray
    ev_buf: np.ndarray           # float64: the values read (ScheduledAlgorithm.ev_values)
    stop_ci: np.ndarray          # stop condition blocks (Boolean)
    stop_fn: np.ndarray
    stop_vr: np.ndarray
    stop_len: np.ndarray
    stop_start: np.ndarray
    stop_buf: np.ndarray         # int32 scratch
    rec_ci: np.ndarray           # the recorder's reads (Real straight into its row, Integer/Boolean via rec_int)
    rec_fn: np.ndarray
    rec_vr: np.ndarray
    rec_len: np.ndarray
    rec_real: np.ndarray         # bool: a Real block
    rec_col: np.ndarray          # its first column in the row
    rec_int: np.ndarray          # int32 scratch
    scratch: np.ndarray          # float64[1] and its bits
    scratch_bits: np.ndarray


@_loop_function
def _gather(T, m):
    """SetOp.gather of set operation m into its input buffer; True when the values differ from
    the ones last sent (or those are unknown)."""
    kind, s, L = T.set_kind[m], T.set_start[m], T.set_len[m]
    differ = not T.set_valid[m]
    if kind == 0:
        if T.set_affine[m]:
            for j in range(s, s + L):
                x = T.g_real[T.idx_real[j]] * T.factor[j]
                x = x + T.offset[j]
                T.scratch[0] = x
                if T.scratch_bits[0] != T.in_real_bits[j]:
                    differ = True
                    T.in_real[j] = x
        elif _take_changed(T.g_real_bits, T.idx_real, T.in_real_bits, s, L):  # the bits: "the same bytes"
            differ = True
    elif kind == 1:
        if _take_changed(T.g_int, T.idx_int, T.in_int, s, L):
            differ = True
    elif _take_changed(T.g_bool, T.idx_bool, T.in_bool, s, L):
        differ = True
    T.set_valid[m] = True
    return differ


@_loop_function
def _take_changed(source, idx, sent, s, L):
    """sent[s:s+L] = source[idx[s:s+L]]; True when a value changed."""
    changed = False
    for j in range(s, s + L):
        v = source[idx[j]]
        if v != sent[j]:
            changed = True
            sent[j] = v
    return changed


@_loop_function
def _set_inputs(T, ci, status_out):
    """InstanceTable.setters[ci]: each set operation gathered and sent when changed."""
    for p in range(T.set_ptr[ci], T.set_ptr[ci + 1]):
        m = T.set_list[p]
        if _gather(T, m):
            s = _call_values(T.set_fn[m], T.component[ci], T.set_vr[m], T.set_len[m], T.set_buf[m])
            if s > 1:
                T.set_valid[m] = False
                status_out[0], status_out[1], status_out[2] = s, ERROR_SET, m
                return False
    return True


@_loop_function
def _get_outputs(T, ci, status_out):
    """InstanceTable.getters[ci]: the connected outputs read into the shared buffers."""
    for g in range(T.get_ptr[ci], T.get_ptr[ci + 1]):
        s = _call_values(T.get_fn[g], T.component[ci], T.get_vr[g], T.get_len[g], T.get_buf[g])
        if s > 1:
            status_out[0], status_out[1], status_out[2] = s, ERROR_GET, g
            return False
    return True


@_loop_function
def _step(T, ci, t, dt, status_out):
    """The batched step of component ci (InstanceTable._batched_stepper's step)."""
    _gather_step(T, ci)
    return _call_step(T, ci, t, dt, status_out)


@_loop_function
def _gather_step(T, ci):
    """The first part of a batched step: ci's inputs gathered into its StepIO block's input
    buffers, each kind marked to be sent when it changed."""
    lay = T.io_layout
    ii = ci * lay[1]
    for k in range(3):
        m = T.set_by_kind[ci, k]
        if m >= 0:
            T.io_i32[ii + lay[4] + k] = 1 if _gather(T, m) else 0


@_loop_function
def _send_nothing(T, ci):
    """ci's next batched step sends no input."""
    base = ci * T.io_layout[1] + T.io_layout[4]
    for k in range(3):
        T.io_i32[base + k] = 0


@_loop_function
def _call_step(T, ci, t, dt, status_out):
    """The rest of a batched step: neighborStepIO sends the gathered inputs, steps and reads the
    outputs into the shared buffers."""
    lay = T.io_layout
    fi, ii = ci * lay[0], ci * lay[1]
    T.io_f64[fi + lay[2]] = t
    T.io_f64[fi + lay[3]] = dt
    s = _call_step_io(T.step_fn[ci], T.component[ci], T.io_address[ci])
    if s > 1:
        where = T.io_i32[ii + lay[5]]  # 1 + kind: its set failed; those after it were not sent
        if 1 <= where <= 3:
            for k in range(where - 1, 3):
                m = T.set_by_kind[ci, k]
                if m >= 0:
                    T.set_valid[m] = False
        status_out[0], status_out[1], status_out[2] = s, ERROR_STEP, ci
        return False
    return True


@_loop_function
def _stop_fired(T, changed, status_out):
    """Reads the stop signals of the components that changed; 1 when one is true, -1 on error."""
    for j in range(len(T.stop_ci)):
        ci = T.stop_ci[j]
        if not changed[ci]:
            continue
        st = T.stop_start[j]
        s = _call_values(T.stop_fn[j], T.component[ci], T.stop_vr[j], T.stop_len[j],
                         T.stop_buf.ctypes.data + 4 * st)
        if s > 1:
            status_out[0], status_out[1], status_out[2] = s, ERROR_STOP, j
            return -1
        for q in range(st, st + T.stop_len[j]):
            if T.stop_buf[q] != 0:
                return 1
    return 0


@_loop_function
def _record(T, rows, times, rec, t, active, status_out):
    """Recorder.record: the active components' inputs set and feedthrough outputs read
    (ScheduledAlgorithm.refresh_for_record; `active` is empty for a fixed-step run), then the
    recorded variables read into row rec[0]."""
    for ci in active:
        if not _set_inputs(T, ci, status_out):
            return False
        if T.has_ft[ci] and not _get_outputs(T, ci, status_out):
            return False
    row = rec[0]
    base = rows.ctypes.data + row * rows.shape[1] * 8
    for j in range(len(T.rec_ci)):
        ci, L, col = T.rec_ci[j], T.rec_len[j], T.rec_col[j]
        if T.rec_real[j]:
            s = _call_values(T.rec_fn[j], T.component[ci], T.rec_vr[j], L, base + 8 * col)
        else:
            s = _call_values(T.rec_fn[j], T.component[ci], T.rec_vr[j], L, T.rec_int.ctypes.data)
            for q in range(L):
                rows[row, col + q] = T.rec_int[q]
        if s > 1:
            status_out[0], status_out[1], status_out[2] = s, ERROR_RECORD, j
            return False
    times[row] = t
    rec[0] = row + 1
    rec[1] = 0
    return True


@_loop_function
def _row_due(T, rows, times, rec, t, active, status_out):
    """After a step that does not end the span: the recorder's count (rec[1]) goes on, and a
    row due (rec[2] steps since the last) is recorded here; False when it cannot be (the rows
    are full: the span ends there and Python records) or failed (status_out[0] > 1)."""
    rec[1] += 1
    if rec[1] < rec[2]:
        return True
    if rec[0] >= rows.shape[0]:
        rec[1] -= 1  # Python's recorder counts the step again
        return False
    return _record(T, rows, times, rec, t, active, status_out)


@_loop_function
def _refresh_one(T, ci, status_out):
    """A refreshed component's inputs sent (where changed) and its connected outputs read."""
    return _set_inputs(T, ci, status_out) and _get_outputs(T, ci, status_out)


@_loop_function
def _needed(L, refresh, tc, t1, tol):
    """L.needed[ci] for the refreshed components after a step ending at t1. A lazily refreshed
    one (L.lazy) is refreshed now only when one of its readers would otherwise read an output
    the Python loop's refresh at every step gives another value: a stepping reader due at the
    next step that steps before it (or any due one when it is not due itself), a reader refreshed
    after it in this step, or one refreshed before it at the next step while it does not step
    (each refreshed reader is also a stepping one)."""
    for r in range(len(refresh) - 1, -1, -1):
        ci = refresh[r]
        need = not L.lazy[ci]
        if not need:
            ci_next = tc[ci] <= t1 + tol
            for p in range(L.ptr[ci], L.ptr[ci + 1]):
                cj, kind = L.reader[p], L.kind[p]
                cj_next = tc[cj] <= t1 + tol
                if kind == READER_AFTER:
                    need = cj_next and not ci_next
                elif kind == READER_BEFORE:
                    need = cj_next
                elif kind == READER_REFRESHED:
                    need = L.needed[cj] or (cj_next and not ci_next)
                else:  # READER_REFRESHED_BEFORE
                    need = cj_next or not ci_next
                if need:
                    break
        L.needed[ci] = need


@_loop_function
def _catch_up(T, L, refresh, status_out):
    """The refreshes the steps left out (L.stale), in the refresh order: before a recorded row
    and at a span's end (the next step may be another mode's), the outputs are then those the
    refresh at every step would have given."""
    for ci in refresh:
        if L.stale[ci]:
            if not _refresh_one(T, ci, status_out):
                return False
            L.stale[ci] = False
    return True


@_loop_function
def _step_mode(T, L, order, mult, refresh, h_mode, t, t1, stop, tol, tc, changed, status_out):
    """One macro step's components (ScheduledAlgorithm._advance): each due one stepped from its
    own time (multiples run ahead), then the refreshed feedthrough ones whose inputs changed:
    now where a reader needs them before the next update (_needed), else marked stale (the Python
    loop refreshes each at every such step; the values any component reads are the same)."""
    for ci in range(len(changed)):
        changed[ci] = False
    for ci in order:
        t_c = tc[ci]
        if t_c > t + tol:
            continue  # ahead of the master (stepped with a multiple)
        k = mult[ci]
        end = t1 if k == 1 else min(t + k * h_mode, stop)
        if end - t_c <= tol:
            continue
        if not _step(T, ci, t_c, end - t_c, status_out):
            return False
        tc[ci] = end
        changed[ci] = True
    if len(refresh) > 0:
        _needed(L, refresh, tc, t1, tol)
    for ci in refresh:
        due = changed[ci] or L.stale[ci]
        if not due:
            for p in range(T.prod_ptr[ci], T.prod_ptr[ci + 1]):
                cp = T.prod_list[p]
                if changed[cp] or L.stale[cp]:
                    due = True
                    break
        if due:
            if L.needed[ci]:
                if not _refresh_one(T, ci, status_out):
                    return False
                changed[ci] = True
                L.stale[ci] = False
            else:
                L.stale[ci] = True
                L.left_out[0] += 1
    return True


@_loop_function
def _read_signals(T, changed, status_out):
    """After a step: the event times and condition signals of the components that changed read
    (as _advance and _pick do), then the stop signals; returns the span's flags, FAILED on error."""
    flags = 0
    for j in range(len(T.ev_ci)):
        ci = T.ev_ci[j]
        if changed[ci]:
            s = _call_values(T.ev_fn[j], T.component[ci], T.ev_vr[j], 1, T.ev_buf.ctypes.data + 8 * j)
            if s > 1:
                status_out[0], status_out[1], status_out[2] = s, ERROR_EVENT, j
                return FAILED
    for j in range(len(T.sig_ci)):
        ci = T.sig_ci[j]
        if changed[ci]:
            s = _call_values(T.sig_fn[j], T.component[ci], T.sig_vr[j], 1, T.sig_buf.ctypes.data + 4 * j)
            if s > 1:
                status_out[0], status_out[1], status_out[2] = s, ERROR_SIGNAL, j
                return FAILED
            if T.sig_buf[j] != T.sig_values[j]:
                T.sig_values[j] = T.sig_buf[j]
                flags |= CONDITION_CHANGED
    fired = _stop_fired(T, changed, status_out)
    if fired < 0:
        return FAILED
    return flags | (STOP_FIRED if fired > 0 else 0)


@_loop_function
def scheduled_span(T, L, order, mult, refresh, h_mode, t, stop, tol, max_steps, spent, tc, changed, status_out, rows,
                   times, rec):
    """Up to max_steps macro steps of one mode from t (ScheduledAlgorithm._advance, the schedule's
    signals and the stop signals read as there, the recorder's rows due on the way recorded into
    rows/times; rec: [rows recorded, steps since the last, the mode's recordEvery]; L: the mode's
    LazyRefresh). Returns (steps, t reached, `spent` plus the steps' sizes, added one by one as
    the Python loop does, flags); `changed` is the last step's, which the observers see in Python."""
    steps, flags = 0, 0
    status_out[0] = 0
    end_time = stop - tol
    while max_steps > 0:  # 0: nothing (Loop.load)
        h = h_mode
        for j in range(len(T.ev_buf)):
            te = T.ev_buf[j]
            if te > t + tol and te - t < h:
                h = te - t
        if stop - t < h + tol:
            h = stop - t
        t1 = t + h if stop - (t + h) > tol else stop
        if not _step_mode(T, L, order, mult, refresh, h_mode, t, t1, stop, tol, tc, changed, status_out):
            return steps, t, spent, FAILED
        t = t1
        spent += h
        steps += 1
        flags = _read_signals(T, changed, status_out)
        if flags != 0 or t >= end_time or steps >= max_steps:
            break
        if rec[1] + 1 >= rec[2] and not _catch_up(T, L, refresh, status_out):  # a row is due
            return steps, t, spent, FAILED
        if not _row_due(T, rows, times, rec, t, order, status_out):
            if status_out[0] > 1:
                return steps, t, spent, FAILED
            break
    if flags & FAILED or not _catch_up(T, L, refresh, status_out):
        return steps, t, spent, FAILED
    return steps, t, spent, flags


@_loop_function
def _end_of_fixed_step(T, changed, status_out, rows, times, rec, t, last):
    """After a fixed step to t: the stop signals read, then the row due recorded unless the step
    ends the span (`last`). Returns FAILED or STOP_FIRED to end the span with, 0 to go on, -1 to
    end it here (Python records the last row)."""
    fired = _stop_fired(T, changed, status_out)
    if fired < 0:
        return FAILED
    if fired > 0:
        return STOP_FIRED
    if last:
        return -1
    if not _row_due(T, rows, times, rec, t, NO_COMPONENTS, status_out):
        return FAILED if status_out[0] > 1 else -1
    return 0


@_loop_function
def fixed_span(T, order, mult, all_one, start, stop, h, n_steps, k, max_steps, changed, status_out, rows, times, rec):
    """Up to max_steps Gauss-Seidel steps from step k (FixedStepAlgorithm.run): the components
    stepped in order (multiples), then every component's inputs set and its feedthrough outputs
    read in order; rows due recorded as in scheduled_span. Returns (steps taken, flags); stops
    after a step whose stop signal is true and at the last step (Python records it)."""
    steps = 0
    status_out[0] = 0
    for ci in range(len(changed)):
        changed[ci] = True  # a fixed-step run reads the stop signals at every step
    while steps < max_steps and k < n_steps:
        t = start + k * h
        for ci in order:
            mk = mult[ci]
            if all_one or k % mk == 0:
                if not _step(T, ci, t, mk * h if k + mk < n_steps else stop - t, status_out):
                    return steps, FAILED
        for ci in order:
            if not _set_inputs(T, ci, status_out):
                return steps, FAILED
            if T.has_ft[ci] and not _get_outputs(T, ci, status_out):
                return steps, FAILED
        k += 1
        steps += 1
        end = _end_of_fixed_step(T, changed, status_out, rows, times, rec, start + k * h,
                                 k >= n_steps or steps >= max_steps)
        if end > 0:
            return steps, end
        if end < 0:
            break
    return steps, 0


@_loop_function
def jacobi_span(T, order, mult, all_one, start, stop, h, n_steps, k, max_steps, changed, status_out, rows, times, rec):
    """Up to max_steps Jacobi steps from step k (FixedStepAlgorithm.run's Jacobi step): every
    component due gathers its inputs from the outputs of the last communication point first, then
    each is stepped (its batched step sends those inputs, steps and reads its outputs). Each FMU
    gets the calls, with the values, of the Python loop's Jacobi step (its inputs set for the
    step, doStep, its outputs read); only the interleaving between FMUs differs. Rows, stop
    signals and the returned (steps taken, flags) as fixed_span."""
    steps = 0
    status_out[0] = 0
    for ci in range(len(changed)):
        changed[ci] = True
    while steps < max_steps and k < n_steps:
        t = start + k * h
        for ci in order:
            if all_one or k % mult[ci] == 0:
                if k > 0:
                    _gather_step(T, ci)
                else:  # the first step's inputs are those the initialization set (as in Python)
                    _send_nothing(T, ci)
        for ci in order:
            mk = mult[ci]
            if all_one or k % mk == 0:
                if not _call_step(T, ci, t, mk * h if k + mk < n_steps else stop - t, status_out):
                    return steps, FAILED
        k += 1
        steps += 1
        end = _end_of_fixed_step(T, changed, status_out, rows, times, rec, start + k * h,
                                 k >= n_steps or steps >= max_steps)
        if end > 0:
            return steps, end
        if end < 0:
            break
    return steps, 0


class LazyRefresh(NamedTuple):
    """One mode's refresh, lazily (_step_mode): which refreshed components may wait (`lazy`:
    those the schedule's and stop conditions' signals do not read), their readers in the mode
    (`reader`/`kind` from ptr[ci] to ptr[ci + 1]), and the state the steps keep: `needed` (this
    step's), `stale` (a refresh left out) and `left_out` (how many were)."""
    lazy: np.ndarray     # [n] bool
    ptr: np.ndarray      # [n + 1]
    reader: np.ndarray
    kind: np.ndarray     # READER_*
    needed: np.ndarray   # [n] bool
    stale: np.ndarray    # [n] bool
    left_out: np.ndarray  # [1] refreshes left out so far


def lazy_refresh(n, order, refresh, consumers, watched):
    """The LazyRefresh of a mode stepping `order` and refreshing `refresh` (component indices),
    from each component's consumers and the components whose outputs the schedule or a stop
    condition reads."""
    pos = {ci: k for k, ci in enumerate(order)}
    refreshed = set(refresh)
    lazy = np.zeros(n, dtype=np.bool_)
    ptr, reader, kind = [0], [], []
    for ci in range(n):
        if ci in refreshed:
            lazy[ci] = ci not in watched
            for cj in sorted(cj for cj in consumers[ci] if cj in pos):
                before = pos[cj] <= pos[ci]
                reader.append(cj)
                if cj in refreshed:
                    kind.append(READER_REFRESHED_BEFORE if before else READER_REFRESHED)
                else:
                    kind.append(READER_BEFORE if before else READER_AFTER)
        ptr.append(len(reader))
    return LazyRefresh(lazy, _i64(ptr), _i64(reader), _i64(kind), np.zeros(n, dtype=np.bool_),
                       np.zeros(n, dtype=np.bool_), np.zeros(1, dtype=np.int64))


def _i64(values):
    return np.array(list(values), dtype=np.int64)


def _address(fn):
    return 0 if fn is None else ctypes.cast(fn, ctypes.c_void_p).value


def build_tables(table, set_ops, get_ops, signals=(), events=(), stop_ops=(), record_ops=(), producers=None):
    """The Tables of an InstanceTable whose every component has a batched step and no mapped
    or String input (`eligible`): its prepared operations (`set_ops` and `get_ops`: every
    component's, in component order), the schedule's signals (`_Signal`s), the stop conditions'
    and the recorder's ReadOps and the components' producers (ScheduledAlgorithm.prod; a
    fixed-step run refreshes without them)."""
    n = len(table.instances)
    prod = producers if producers is not None else [[] for _ in range(n)]
    kinds = {"Real": 0, "Integer": 1, "Boolean": 2}
    index = {id(op): m for m, op in enumerate(set_ops)}
    set_ptr, set_list, by_kind = [0], [], np.full((n, 3), -1, dtype=np.int64)
    for ci in range(n):
        for op in table.sets[ci]:
            set_list.append(index[id(op)])
            by_kind[ci, kinds[op.call[len("fmi2Set"):]]] = index[id(op)]
        set_ptr.append(len(set_list))
    IN, G = table.IN, table.G
    idx = {kind: np.zeros(len(IN[kind]), dtype=np.int64) for kind in kinds}
    factor, offset = np.ones(len(IN["Real"])), np.zeros(len(IN["Real"]))
    for op in set_ops:
        kind, s = op.call[len("fmi2Set"):], table.in_start[op]
        idx[kind][s:s + op.n] = op.idx
        if op.factor is not None:
            factor[s:s + op.n], offset[s:s + op.n] = op.factor, op.offset
    get_ptr = np.cumsum([0] + [len(table.gets[ci]) for ci in range(n)]).astype(np.int64)
    size = ctypes.sizeof(table.step_ios) // max(n, 1)
    io_type = type(table.step_ios[0]) if n else None
    layout = _i64([size // 8, size // 4, io_type.t.offset // 8, io_type.h.offset // 8, io_type.send.offset // 4,
                   io_type.failed.offset // 4])
    io_base = ctypes.addressof(table.step_ios)
    stop_lens = [op.n for op in stop_ops]
    scratch = np.zeros(1)
    rec_cols = np.cumsum([0] + [op.n for op in record_ops]).astype(np.int64)
    return Tables(
        component=_i64(inst.fmu.component for inst in table.instances),
        step_fn=_i64(_address(fn) for fn in table.step_io_functions),
        io_address=_i64(io_base + ci * size for ci in range(n)),
        io_f64=np.frombuffer(table.step_ios, dtype=np.float64), io_i32=np.frombuffer(table.step_ios, dtype=np.int32),
        io_layout=layout,
        set_kind=_i64(kinds[op.call[len("fmi2Set"):]] for op in set_ops),
        set_start=_i64(table.in_start[op] for op in set_ops), set_len=_i64(op.n for op in set_ops),
        set_affine=np.array([op.factor is not None for op in set_ops], dtype=np.bool_),
        set_valid=np.zeros(len(set_ops), dtype=np.bool_),
        set_fn=_i64(_address(op.fn) for op in set_ops), set_vr=_i64(ctypes.addressof(op.vr) for op in set_ops),
        set_buf=_i64(ctypes.addressof(op.buf) for op in set_ops),
        set_ptr=_i64(set_ptr), set_list=_i64(set_list), set_by_kind=by_kind,
        get_ptr=get_ptr, get_fn=_i64(_address(op.fn) for op in get_ops),
        get_vr=_i64(ctypes.addressof(op.vr) for op in get_ops), get_len=_i64(op.n for op in get_ops),
        get_buf=_i64(ctypes.addressof(op.buf) for op in get_ops),
        idx_real=idx["Real"], idx_int=idx["Integer"], idx_bool=idx["Boolean"], factor=factor, offset=offset,
        g_real=G["Real"], g_real_bits=G["Real"].view(np.int64), g_int=G["Integer"], g_bool=G["Boolean"],
        in_real=IN["Real"], in_real_bits=IN["Real"].view(np.int64), in_int=IN["Integer"], in_bool=IN["Boolean"],
        prod_ptr=np.cumsum([0] + [len(p) for p in prod]).astype(np.int64), prod_list=_i64(c for p in prod for c in p),
        has_ft=np.array(table.has_ft, dtype=np.bool_),
        sig_ci=_i64(sig.ci for sig in signals), sig_fn=_i64(_address(sig.fn) for sig in signals),
        sig_vr=_i64(ctypes.addressof(sig.vr) for sig in signals), sig_buf=np.zeros(len(signals), dtype=np.int32),
        sig_values=np.zeros(len(signals), dtype=np.int64),
        ev_ci=_i64(sig.ci for sig in events), ev_fn=_i64(_address(sig.fn) for sig in events),
        ev_vr=_i64(ctypes.addressof(sig.vr) for sig in events), ev_buf=np.zeros(len(events)),
        stop_ci=_i64(op.ci for op in stop_ops), stop_fn=_i64(_address(op.fn) for op in stop_ops),
        stop_vr=_i64(ctypes.addressof(op.vr) for op in stop_ops), stop_len=_i64(stop_lens),
        stop_start=np.cumsum([0] + stop_lens[:-1]).astype(np.int64) if stop_lens else _i64([]),
        stop_buf=np.zeros(max(sum(stop_lens), 1), dtype=np.int32),
        rec_ci=_i64(op.ci for op in record_ops), rec_fn=_i64(_address(op.fn) for op in record_ops),
        rec_vr=_i64(ctypes.addressof(op.vr) for op in record_ops), rec_len=_i64(op.n for op in record_ops),
        rec_real=np.array([op.call == "fmi2GetReal" for op in record_ops], dtype=np.bool_), rec_col=rec_cols[:-1],
        rec_int=np.zeros(max([op.n for op in record_ops] + [1]), dtype=np.int32),
        scratch=scratch, scratch_bits=scratch.view(np.int64))


def eligible(table, components, rows):
    """Whether the compiled loop can step these components of the table: each has our runtime's
    batched step (FMI 2.0) and no input that needs a mapping or is a String; and whether it can
    record the recorder's rows (no String recorded)."""
    if not ENABLED or table.debug or rows.text_ops:
        return False
    for ci in components:
        if table.step_io_functions[ci] is None or table.instances[ci].fmi3:
            return False
        if any(op.call == "fmi2SetString" or op.post is not None for op in table.sets[ci]):
            return False
        if any(op.call == "fmi2GetString" for op in table.gets[ci]):
            return False
    return True


class Loop:
    """The compiled loop of one run: its tables and the Python side's bookkeeping around a span
    (the set operations' "last sent" kept in step with the Python loop's)."""

    def __init__(self, table, rows, signals=(), events=(), stop_ops=(), producers=None):
        self.table = table
        self.rows = rows  # the Recorder (its numeric ops only: eligible() refuses recorded Strings)
        self.signals, self.events, self.stop_ops = signals, events, stop_ops
        n = len(table.instances)
        self.set_ops = [op for ci in range(n) for op in table.sets[ci]]  # the tables' order
        self.get_ops = [op for ci in range(n) for op in table.gets[ci]]
        self.T = build_tables(table, self.set_ops, self.get_ops, signals, events, stop_ops, rows.ops, producers)
        self.rec = np.zeros(3, dtype=np.int64)
        self.status = np.zeros(3, dtype=np.int64)
        self.changed = np.zeros(len(table.instances), dtype=np.bool_)

    def load(self, mode_arrays=None, fixed=None, span=fixed_span):
        """Call the span function once without a step, so that numba loads (or compiles) it now,
        before the run's clock starts: `mode_arrays` (order, mult, refresh, LazyRefresh) of a scheduled run,
        or `fixed` (order, mult) of a fixed-step one, whose `span` is fixed_span or jacobi_span."""
        rows, times = self.rows.rows, self.rows.times
        if fixed is not None:
            span(self.T, fixed[0], fixed[1], False, 0.0, 1.0, 1.0, 1, 0, 0, self.changed, self.status, rows, times,
                 self.rec)
        else:
            order, mult, refresh, lazy = mode_arrays
            scheduled_span(self.T, lazy, order, mult, refresh, 1.0, 0.0, 1.0, 0.0, 0, 0.0, np.zeros(len(self.changed)),
                           self.changed, self.status, rows, times, self.rec)

    def enter(self, record_every):
        """Before a span: which inputs the Python loop has sent (its SetOp.last), the recorder's
        state; returns the rows and times arrays to record into."""
        valid = self.T.set_valid
        for m, op in enumerate(self.set_ops):
            valid[m] = op.last[0] is not None
        rows = self.rows
        self.rec[:] = rows.count, rows.since, record_every
        return rows.rows, rows.times

    def leave(self):
        """After a span: the Python SetOps' last sent bytes are the input buffers' (where known),
        the recorder's rows and count since its last row (the observers then see the span's
        last step: the recorder counts it)."""
        valid = self.T.set_valid
        for m, op in enumerate(self.set_ops):
            op.last[0] = op.view.tobytes() if valid[m] else None
        self.rows.count, self.rows.since = int(self.rec[0]), int(self.rec[1])

    def failure(self):
        """The StepFailed the Python loop would have raised for the span's failed call."""
        s, what, i = (int(x) for x in self.status)
        if what == ERROR_STEP:
            return self.table.step_failures[i](s)
        if what in (ERROR_SET, ERROR_GET):
            op = (self.set_ops if what == ERROR_SET else self.get_ops)[i]
            return StepFailed(op.ci, op.call, s, op.names)
        sig = {ERROR_SIGNAL: self.signals, ERROR_EVENT: self.events}.get(what)
        if sig is not None:
            return StepFailed(sig[i].ci, sig[i].call, s, (sig[i].var,))
        op = self.stop_ops[i] if what == ERROR_STOP else self.rows.ops[i]
        return StepFailed(op.ci, op.call, s, op.vars)
