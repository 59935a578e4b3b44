/* The FMI 2.0 co-simulation binary of every neighbor-cosim FMU.
 *
 * The models are Python (pythonfmu's authoring API, the classes in fmus/); this library is the
 * bridge any FMI host loads, with or without a Python of its own:
 *
 * - The Python C API is resolved at run time (dlsym), never linked: in a host that already runs
 *   Python (FMPy) its interpreter is used; otherwise a CPython 3.9+ shared library is found on the
 *   target (see find_python: NEIGHBOR_FMU_LIBPYTHON, the python3 on PATH, the linker's
 *   libpython3.X newest first, the build's library last) with its own standard library, and an
 *   interpreter is started. Only functions of the stable ABI are called, through pointers, so one
 *   binary serves every CPython 3.9 to 3.13.
 * - Nothing here exits the host: a Python that could not start (Python's initialization would
 *   exit the process) is refused before it starts, and fmi2Instantiate returns NULL with the
 *   reason in the host's logger; every later fmi2Instantiate gives the same answer.
 * - An interpreter this library started is never finalized (extension modules such as numpy or
 *   numba cannot be re-initialized, and a host may load other FMUs later); Python holds no
 *   pointer into this library, so the host may unload it at any time.
 * - Every entry point takes the GIL with PyGILState_Ensure and gives it back, so hosts may call
 *   from any thread.
 * - Messages the model logs are passed to the host's logger as data ("%s"), never as a format.
 * - A Python exception becomes fmi2Error (a bad parameter or input: this instance is refused,
 *   others are not touched); fmi2Fatal only for errors that leave the interpreter unusable
 *   (out of memory, an internal error).
 *
 * The part shared with the FMI 3.0 binary is neighbor_core.c (included below). The Python side
 * lives in the FMU's resources: neighbor_runtime.py (the loader, executed from its path into a
 * module private to the FMU build, never imported) and one private package with the model's code
 * (see system_ssp/builder.py).
 */
#ifndef _WIN32
#define _GNU_SOURCE  /* dladdr */
#endif
#include <stdarg.h>
#include <stdio.h>

#include "fmi2Functions.h"

typedef fmi2CallbackFunctions HostCallbacks;
static void host_log(HostCallbacks *cb, const char *instance, int status, const char *category, const char *text) {
    if (cb && cb->logger) cb->logger(cb->componentEnvironment, instance, (fmi2Status)status, category, "%s", text);
}

#include "neighbor_core.c"

static const char *GET_CALLS[] = {"fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString"};
static const char *SET_CALLS[] = {"fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean", "fmi2SetString"};

/* ---- the batched step of system_ssp's master (not an FMI call) -------------------------------
 * Our master steps a component with its inputs set before and its outputs read after; through the
 * standard calls that is up to seven entries into Python per step. `step_io` makes the same calls
 * (set_values, do_step, get_values: the same values, statuses and messages) under one hold of the
 * GIL, for the Real, Integer and Boolean blocks the master prepared once. Hosts that do not know
 * it use the standard calls; the master uses it only when the library exports it. */
typedef struct {
    double t, h;                       /* the doStep's communication point and step size */
    size_t n_in[3], n_out[3];          /* per kind (Real, Integer, Boolean): inputs set, outputs read */
    const unsigned int *in_vr[3];
    const void *in_val[3];             /* double or int values */
    const unsigned int *out_vr[3];
    void *out_val[3];
    int send[3];                       /* set this kind's inputs in this call (they changed) */
    int failed;                        /* out: 0 none, 1 + kind a set, 4 the doStep, 5 + kind a get */
} StepIO;

static Status step_io(void *c, StepIO *io, const char *const set_calls[], const char *const get_calls[],
                      const char *step_call, size_t bool_size) {
    Instance *inst = (Instance *)c;
    if (!inst || !io) return ST_ERROR;
    if (inst->broken) return ST_FATAL;
    int gil = py.GILStateEnsure();  /* held across the calls below: theirs nest inside it */
    Status worst = ST_OK, s;
    io->failed = 0;
    for (int k = 0; k < 3; k++) {
        if (!io->send[k] || !io->n_in[k]) continue;
        s = set_values(c, k, io->in_vr[k], io->n_in[k], io->in_val[k], io->n_in[k], 0, bool_size, set_calls[k]);
        if (s > worst) worst = s;
        if (s > ST_WARNING) {
            io->failed = 1 + k;
            goto done;
        }
    }
    s = do_step(c, io->t, io->h, step_call);
    if (s > worst) worst = s;
    if (s > ST_WARNING) {
        io->failed = 4;
        goto done;
    }
    for (int k = 0; k < 3; k++) {
        if (!io->n_out[k]) continue;
        s = get_values(c, k, io->out_vr[k], io->n_out[k], io->out_val[k], io->n_out[k], 0, bool_size, get_calls[k]);
        if (s > worst) worst = s;
        if (s > ST_WARNING) {
            io->failed = 5 + k;
            goto done;
        }
    }
done:
    py.GILStateRelease(gil);
    return worst;
}

/* ---- FMI 2.0 -------------------------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)nCategories;
    (void)categories;
    if (!c) return fmi2Error;
    ((Instance *)c)->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    const char *name = instanceName ? instanceName : "";
    fmi2CallbackFunctions cb;
    memset(&cb, 0, sizeof cb);
    if (functions) cb = *functions;
    if (fmuType != fmi2CoSimulation) {
        host_log(&cb, name, fmi2Error, "logStatusError", "this FMU supports co-simulation only");
        return NULL;
    }
    if (!fmuResourceLocation) {
        host_log(&cb, name, fmi2Error, "logStatusError", "fmi2Instantiate needs the fmuResourceLocation");
        return NULL;
    }
    char resources[4096];
    uri_to_path(fmuResourceLocation, resources, sizeof resources);
    return new_instance("fmi2Instantiate", name, fmuGUID, resources, visible, loggingOn, cb);
}

void fmi2FreeInstance(fmi2Component c) { free_instance((Instance *)c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Setup s = {toleranceDefined, stopTimeDefined, tolerance, startTime, stopTime};
    Status status = lifecycle(c, "fmi2SetupExperiment", "setup_experiment", setup_args, &s, MASK_SETUP,
                              S_INSTANTIATED);
    if (status <= ST_WARNING) start_time(c, startTime);
    return (fmi2Status)status;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    return (fmi2Status)lifecycle(c, "fmi2EnterInitializationMode", "enter_initialization_mode", NULL, NULL,
                                 MASK_ENTER_INIT, S_INITIALIZATION);
}
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    return (fmi2Status)lifecycle(c, "fmi2ExitInitializationMode", "exit_initialization_mode", NULL, NULL,
                                 MASK_EXIT_INIT, S_STEPPING);
}
fmi2Status fmi2Terminate(fmi2Component c) {
    return (fmi2Status)lifecycle(c, "fmi2Terminate", "terminate", NULL, NULL, MASK_TERMINATE, S_TERMINATED);
}
fmi2Status fmi2Reset(fmi2Component c) { return (fmi2Status)reset_instance(c, "fmi2Reset"); }

/* ---- values -------------------------------------------------------------------------------- */
#define GET2(kind, v) (fmi2Status)get_values(c, kind, vr, nvr, v, nvr, 0, sizeof(fmi2Boolean), GET_CALLS[kind])
#define SET2(kind, v) (fmi2Status)set_values(c, kind, vr, nvr, v, nvr, 0, sizeof(fmi2Boolean), SET_CALLS[kind])
fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    return GET2(KIND_REAL, value);
}
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    return GET2(KIND_INTEGER, value);
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    return GET2(KIND_BOOLEAN, value);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    return GET2(KIND_STRING, (void *)value);
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    return SET2(KIND_REAL, value);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    return SET2(KIND_INTEGER, value);
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    return SET2(KIND_BOOLEAN, value);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    return SET2(KIND_STRING, value);
}

/* ---- state ---------------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    return (fmi2Status)get_state(c, state, "fmi2GetFMUstate");
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    return (fmi2Status)set_state(c, state, "fmi2SetFMUstate");
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    return (fmi2Status)free_state(c, state);
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)s; (void)n;
    return (fmi2Status)unsupported(c, "fmi2SerializedFMUstateSize");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)s; (void)b; (void)n;
    return (fmi2Status)unsupported(c, "fmi2SerializeFMUstate");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)b; (void)n; (void)s;
    return (fmi2Status)unsupported(c, "fmi2DeSerializeFMUstate");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                        fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return (fmi2Status)unsupported(c, "fmi2GetDirectionalDerivative");
}

/* ---- co-simulation -------------------------------------------------------------------------- */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return (fmi2Status)unsupported(c, "fmi2SetRealInputDerivatives");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return (fmi2Status)unsupported(c, "fmi2GetRealOutputDerivatives");
}

/* system_ssp's master: a suspended component's clock jumps to t (skip_to in neighbor_core.c) */
FMI2_Export fmi2Status neighborSkipTo(fmi2Component c, fmi2Real t) { return (fmi2Status)skip_to(c, t); }

/* system_ssp's master: set, doStep and get of one component in one call (step_io above) */
FMI2_Export fmi2Status neighborStepIO(fmi2Component c, void *io) {
    return (fmi2Status)step_io(c, (StepIO *)io, SET_CALLS, GET_CALLS, "fmi2DoStep", sizeof(fmi2Boolean));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    return (fmi2Status)do_step(c, t, h, "fmi2DoStep");
}
fmi2Status fmi2CancelStep(fmi2Component c) { return (fmi2Status)unsupported(c, "fmi2CancelStep"); }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value;
    return (fmi2Status)unsupported(c, "fmi2GetStatus");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    (void)s; (void)value;
    return (fmi2Status)unsupported(c, "fmi2GetRealStatus");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s; (void)value;
    return (fmi2Status)unsupported(c, "fmi2GetIntegerStatus");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)s; (void)value;
    return (fmi2Status)unsupported(c, "fmi2GetBooleanStatus");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s; (void)value;
    return (fmi2Status)unsupported(c, "fmi2GetStringStatus");
}
