/* The FMI 3.0 co-simulation binary of every neighbor-cosim FMU: the same runtime as the FMI 2.0
 * binary (neighbor_core.c, with its guarantees: any CPython 3.9-3.13 on the target, errors as a
 * status with a message, never a crash or an exit of the host), behind the FMI 3.0 entry points.
 *
 * The model is the same pythonfmu slave as in the FMI 2.0 FMU. Its variables are scalars there
 * (q_BN[1] .. q_BN[4]); the FMI 3.0 model description declares each such run of elements as one
 * array variable whose value reference is the first element's, and the loader
 * (neighbor_runtime.py: get_values/set_values) expands an array's value reference into its
 * elements, in row-major order as FMI 3.0 serializes arrays. Types: Float64 (the model's Real),
 * Int32 (Integer), Boolean, String; the FMU declares no other type, and a get or set of another
 * type with value references is an error naming the type.
 *
 * Not provided, and said so in the model description: event mode and clocks (hasEventMode is
 * false: the models' mode changes happen inside doStep, see docs/interoperability.md), early
 * return, intermediate update, serialized state, directional and adjoint derivatives,
 * configuration mode (no structural parameters), model exchange and scheduled execution
 * (instantiating those returns NULL with the reason). */
#ifndef _WIN32
#define _GNU_SOURCE  /* dladdr */
#endif
#include <stdarg.h>
#include <stdio.h>

#include "fmi3Functions.h"

typedef struct {
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
} HostCallbacks;
static void host_log(HostCallbacks *cb, const char *instance, int status, const char *category, const char *text) {
    (void)instance;  /* FMI 3.0's logger knows the instance by its environment */
    if (cb && cb->log) cb->log(cb->env, (fmi3Status)status, category, text);
}

#include "neighbor_core.c"

static const char *GET_CALLS[] = {"fmi3GetFloat64", "fmi3GetInt32", "fmi3GetBoolean", "fmi3GetString"};
static const char *SET_CALLS[] = {"fmi3SetFloat64", "fmi3SetInt32", "fmi3SetBoolean", "fmi3SetString"};

static Status no_variables_of_type(void *c, const char *what, size_t nvr) {
    Instance *inst = (Instance *)c;
    Status refused = admit(inst, strncmp(what, "fmi3Get", 7) == 0 ? MASK_GET : MASK_SET, what);
    if (refused) return refused;
    if (nvr == 0) return ST_OK;
    char text[256];
    snprintf(text, sizeof text, "%s: this FMU has no variable of that type (it declares Float64, Int32, Boolean and "
             "String variables only)", what);
    host_log(&inst->cb, inst->name, ST_ERROR, "logStatusError", text);
    return ST_ERROR;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)nCategories;
    (void)categories;
    if (!instance) return fmi3Error;
    ((Instance *)instance)->logging_on = loggingOn ? 1 : 0;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    /* event mode, early return and intermediate update are not offered (hasEventMode,
       canReturnEarlyAfterIntermediateUpdate and providesIntermediateUpdate are false): the FMU
       never asks for them, whatever the host allows */
    (void)eventModeUsed; (void)earlyReturnAllowed; (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
    const char *name = instanceName ? instanceName : "";
    HostCallbacks cb = {instanceEnvironment, logMessage};
    if (!resourcePath) {
        host_log(&cb, name, ST_ERROR, "logStatusError", "fmi3InstantiateCoSimulation needs the resourcePath");
        return NULL;
    }
    char resources[4096];
    uri_to_path(resourcePath, resources, sizeof resources);  /* a path; a file: URI from a lenient host too */
    return new_instance("fmi3InstantiateCoSimulation", name, instantiationToken, resources, visible, loggingOn, cb);
}

static fmi3Instance refuse_interface(fmi3String instanceName, fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
                                     const char *what) {
    HostCallbacks cb = {env, log};
    char text[256];
    snprintf(text, sizeof text, "%s: this FMU supports co-simulation only", what);
    host_log(&cb, instanceName ? instanceName : "", ST_ERROR, "logStatusError", text);
    return NULL;
}
fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    return refuse_interface(instanceName, instanceEnvironment, logMessage, "fmi3InstantiateModelExchange");
}
fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn; (void)clockUpdate;
    (void)lockPreemption; (void)unlockPreemption;
    return refuse_interface(instanceName, instanceEnvironment, logMessage, "fmi3InstantiateScheduledExecution");
}

void fmi3FreeInstance(fmi3Instance instance) { free_instance((Instance *)instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Instance *inst = (Instance *)instance;
    Status refused = admit(inst, MASK_ENTER_INIT, "fmi3EnterInitializationMode");
    if (refused) return (fmi3Status)refused;
    Setup s = {toleranceDefined, stopTimeDefined, tolerance, startTime, stopTime};
    Status status = call_method(instance, "fmi3EnterInitializationMode", "setup_experiment", setup_args, &s);
    if (status <= ST_WARNING) {
        Status entered = call_method(instance, "fmi3EnterInitializationMode", "enter_initialization_mode", NULL,
                                     NULL);
        if (entered > status) status = entered;
    }
    enter_state(inst, status, S_INITIALIZATION);
    if (status <= ST_WARNING) start_time(instance, startTime);
    return (fmi3Status)status;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    return (fmi3Status)lifecycle(instance, "fmi3ExitInitializationMode", "exit_initialization_mode", NULL, NULL,
                                 MASK_EXIT_INIT, S_STEPPING);
}
fmi3Status fmi3Terminate(fmi3Instance instance) {
    return (fmi3Status)lifecycle(instance, "fmi3Terminate", "terminate", NULL, NULL, MASK_TERMINATE, S_TERMINATED);
}
fmi3Status fmi3Reset(fmi3Instance instance) { return (fmi3Status)reset_instance(instance, "fmi3Reset"); }

/* ---- values: arrays expanded by the loader --------------------------------------------------- */
#define GET3(kind, v) (fmi3Status)get_values(instance, kind, valueReferences, nValueReferences, v, nValues, 1, \
                                             sizeof(fmi3Boolean), GET_CALLS[kind])
#define SET3(kind, v) (fmi3Status)set_values(instance, kind, valueReferences, nValueReferences, v, nValues, 1, \
                                             sizeof(fmi3Boolean), SET_CALLS[kind])
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues) {
    return GET3(KIND_REAL, values);
}
fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int32 values[], size_t nValues) {
    return GET3(KIND_INTEGER, values);
}
fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Boolean values[], size_t nValues) {
    return GET3(KIND_BOOLEAN, values);
}
fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         fmi3String values[], size_t nValues) {
    return GET3(KIND_STRING, (void *)values);
}
fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues) {
    return SET3(KIND_REAL, values);
}
fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int32 values[], size_t nValues) {
    return SET3(KIND_INTEGER, values);
}
fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Boolean values[], size_t nValues) {
    return SET3(KIND_BOOLEAN, values);
}
fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const fmi3String values[], size_t nValues) {
    return SET3(KIND_STRING, values);
}

/* ---- state ---------------------------------------------------------------------------------- */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    return (fmi3Status)get_state(instance, FMUState, "fmi3GetFMUState");
}
fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    return (fmi3Status)set_state(instance, FMUState, "fmi3SetFMUState");
}
fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    return (fmi3Status)free_state(instance, FMUState);
}

/* ---- co-simulation -------------------------------------------------------------------------- */
fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Status status = do_step(instance, currentCommunicationPoint, communicationStepSize, "fmi3DoStep");
    if (eventHandlingNeeded) *eventHandlingNeeded = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (earlyReturn) *earlyReturn = fmi3False;
    if (lastSuccessfulTime)
        *lastSuccessfulTime = currentCommunicationPoint + (status <= ST_WARNING ? communicationStepSize : 0.0);
    return (fmi3Status)status;
}

/* ---- what this FMU does not offer (see the head of this file) ------------------------------- */
fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    return (fmi3Status)unsupported(instance, "fmi3EnterEventMode");
}
fmi3Status fmi3GetFloat32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float32 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetFloat32", nValueReferences);
}
fmi3Status fmi3GetInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int8 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetInt8", nValueReferences);
}
fmi3Status fmi3GetUInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt8 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetUInt8", nValueReferences);
}
fmi3Status fmi3GetInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int16 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetInt16", nValueReferences);
}
fmi3Status fmi3GetUInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt16 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetUInt16", nValueReferences);
}
fmi3Status fmi3GetUInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt32 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetUInt32", nValueReferences);
}
fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Int64 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetInt64", nValueReferences);
}
fmi3Status fmi3GetUInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetUInt64", nValueReferences);
}
fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)valueSizes; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetBinary", nValueReferences);
}
fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Clock values[]) {
    (void)valueReferences; (void)nValueReferences; (void)values;
    return (fmi3Status)no_variables_of_type(instance, "fmi3GetClock", nValueReferences);
}
fmi3Status fmi3SetFloat32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float32 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetFloat32", nValueReferences);
}
fmi3Status fmi3SetInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int8 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetInt8", nValueReferences);
}
fmi3Status fmi3SetUInt8(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt8 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetUInt8", nValueReferences);
}
fmi3Status fmi3SetInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int16 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetInt16", nValueReferences);
}
fmi3Status fmi3SetUInt16(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt16 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetUInt16", nValueReferences);
}
fmi3Status fmi3SetUInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt32 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetUInt32", nValueReferences);
}
fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int64 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetInt64", nValueReferences);
}
fmi3Status fmi3SetUInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetUInt64", nValueReferences);
}
fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)valueSizes; (void)values; (void)nValues;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetBinary", nValueReferences);
}
fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Clock values[]) {
    (void)valueReferences; (void)nValueReferences; (void)values;
    return (fmi3Status)no_variables_of_type(instance, "fmi3SetClock", nValueReferences);
}
fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference, size_t* nDependencies) {
    (void)valueReference; (void)nDependencies;
    return (fmi3Status)unsupported(instance, "fmi3GetNumberOfVariableDependencies");
}
fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent, size_t elementIndicesOfDependent[], fmi3ValueReference independents[], size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[], size_t nDependencies) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents; (void)dependencyKinds; (void)nDependencies;
    return (fmi3Status)unsupported(instance, "fmi3GetVariableDependencies");
}
fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t* size) {
    (void)FMUState; (void)size;
    return (fmi3Status)unsupported(instance, "fmi3SerializedFMUStateSize");
}
fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size) {
    (void)FMUState; (void)serializedState; (void)size;
    return (fmi3Status)unsupported(instance, "fmi3SerializeFMUState");
}
fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size, fmi3FMUState* FMUState) {
    (void)serializedState; (void)size; (void)FMUState;
    return (fmi3Status)unsupported(instance, "fmi3DeserializeFMUState");
}
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity; (void)nSensitivity;
    return (fmi3Status)unsupported(instance, "fmi3GetDirectionalDerivative");
}
fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity; (void)nSensitivity;
    return (fmi3Status)unsupported(instance, "fmi3GetAdjointDerivative");
}
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return (fmi3Status)unsupported(instance, "fmi3EnterConfigurationMode");
}
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return (fmi3Status)unsupported(instance, "fmi3ExitConfigurationMode");
}
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    return (fmi3Status)unsupported(instance, "fmi3GetIntervalDecimal");
}
fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    return (fmi3Status)unsupported(instance, "fmi3GetIntervalFraction");
}
fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return (fmi3Status)unsupported(instance, "fmi3GetShiftDecimal");
}
fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return (fmi3Status)unsupported(instance, "fmi3GetShiftFraction");
}
fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 intervals[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    return (fmi3Status)unsupported(instance, "fmi3SetIntervalDecimal");
}
fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return (fmi3Status)unsupported(instance, "fmi3SetIntervalFraction");
}
fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return (fmi3Status)unsupported(instance, "fmi3SetShiftDecimal");
}
fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return (fmi3Status)unsupported(instance, "fmi3SetShiftFraction");
}
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    return (fmi3Status)unsupported(instance, "fmi3EvaluateDiscreteStates");
}
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean* discreteStatesNeedUpdate, fmi3Boolean* terminateSimulation, fmi3Boolean* nominalsOfContinuousStatesChanged, fmi3Boolean* valuesOfContinuousStatesChanged, fmi3Boolean* nextEventTimeDefined, fmi3Float64* nextEventTime) {
    (void)discreteStatesNeedUpdate; (void)terminateSimulation; (void)nominalsOfContinuousStatesChanged; (void)valuesOfContinuousStatesChanged; (void)nextEventTimeDefined; (void)nextEventTime;
    return (fmi3Status)unsupported(instance, "fmi3UpdateDiscreteStates");
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    return (fmi3Status)unsupported(instance, "fmi3EnterContinuousTimeMode");
}
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* enterEventMode, fmi3Boolean* terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    return (fmi3Status)unsupported(instance, "fmi3CompletedIntegratorStep");
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    (void)time;
    return (fmi3Status)unsupported(instance, "fmi3SetTime");
}
fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[], size_t nContinuousStates) {
    (void)continuousStates; (void)nContinuousStates;
    return (fmi3Status)unsupported(instance, "fmi3SetContinuousStates");
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t nContinuousStates) {
    (void)derivatives; (void)nContinuousStates;
    return (fmi3Status)unsupported(instance, "fmi3GetContinuousStateDerivatives");
}
fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
    (void)eventIndicators; (void)nEventIndicators;
    return (fmi3Status)unsupported(instance, "fmi3GetEventIndicators");
}
fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates) {
    (void)continuousStates; (void)nContinuousStates;
    return (fmi3Status)unsupported(instance, "fmi3GetContinuousStates");
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates) {
    (void)nominals; (void)nContinuousStates;
    return (fmi3Status)unsupported(instance, "fmi3GetNominalsOfContinuousStates");
}
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t* nEventIndicators) {
    (void)nEventIndicators;
    return (fmi3Status)unsupported(instance, "fmi3GetNumberOfEventIndicators");
}
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t* nContinuousStates) {
    (void)nContinuousStates;
    return (fmi3Status)unsupported(instance, "fmi3GetNumberOfContinuousStates");
}
fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    return (fmi3Status)unsupported(instance, "fmi3EnterStepMode");
}
fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
    (void)valueReferences; (void)nValueReferences; (void)orders; (void)values; (void)nValues;
    return (fmi3Status)unsupported(instance, "fmi3GetOutputDerivatives");
}
fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference, fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    return (fmi3Status)unsupported(instance, "fmi3ActivateModelPartition");
}

/* system_ssp's master: a suspended component's clock jumps to t (skip_to in neighbor_core.c) */
FMI3_Export fmi3Status neighborSkipTo(fmi3Instance instance, fmi3Float64 t) {
    return (fmi3Status)skip_to(instance, t);
}
