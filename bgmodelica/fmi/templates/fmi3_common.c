/*
 * bgmodelica FMU runtime: FMI 3.0 functions common to all interface types.
 * Only Float64 variables exist; the getters/setters of every other type accept empty
 * requests and report an error for any value reference.  Scheduled Execution, clocks,
 * configuration mode, adjoint derivatives and per-element dependencies are not provided
 * (declared as such in modelDescription.xml) and return fmi3Error with a log message.
 * Written for bgmodelica from the FMI 3.0 specification.
 */
#include <stdio.h>
#include <string.h>

#include "fmi3Functions.h"
#include "bgm_core.h"

#define INST ((bgm_inst *)instance)
#define VALID_OR_ERROR(instance)                           \
    do {                                                   \
        if (!bgm_valid(INST)) return fmi3Error;            \
    } while (0)

static void fmi3_emit(bgm_inst *inst, int status, const char *category, const char *message) {
    fmi3LogMessageCallback logger = (fmi3LogMessageCallback)inst->logger_fn;
    if (logger)
        logger((fmi3InstanceEnvironment)inst->logger_env, (fmi3Status)status, category, message);
}

static bgm_inst *fmi3_new(const char *fn, int kind, fmi3String instanceName,
                          fmi3String instantiationToken, fmi3String resourcePath,
                          fmi3Boolean loggingOn, fmi3InstanceEnvironment env,
                          fmi3LogMessageCallback logMessage) {
    char msg[512];
    bgm_inst *inst;
    if (!instanceName || !instanceName[0]) {
        if (logMessage) {
            snprintf(msg, sizeof(msg), "%s: missing instance name", fn);
            logMessage(env, fmi3Error, "logStatusError", msg);
        }
        return NULL;
    }
    if ((kind == BGM_KIND_ME && !BGM_HAS_ME) || (kind == BGM_KIND_CS && !BGM_HAS_CS)) {
        if (logMessage) {
            snprintf(msg, sizeof(msg), "%s: this FMU does not provide the %s interface", fn,
                     kind == BGM_KIND_ME ? "Model Exchange" : "Co-Simulation");
            logMessage(env, fmi3Error, "logStatusError", msg);
        }
        return NULL;
    }
    if (!instantiationToken || strcmp(instantiationToken, BGM_TOKEN) != 0) {
        if (logMessage) {
            snprintf(msg, sizeof(msg), "%s: wrong instantiationToken \"%.200s\", expected \"%s\"",
                     fn, instantiationToken ? instantiationToken : "(null)", BGM_TOKEN);
            logMessage(env, fmi3Error, "logStatusError", msg);
        }
        return NULL;
    }
    inst = bgm_new(3, kind, instanceName, loggingOn, fmi3_emit, (bgm_any_fn)logMessage, env);
    if (!inst && logMessage) logMessage(env, fmi3Fatal, "logStatusError", "out of memory");
#if BGM_HYBRID
    if (inst && bgm_tables_load(inst, resourcePath)) {     /* tables from resource files */
        bgm_free(inst);
        return NULL;
    }
#else
    (void)resourcePath;
#endif
    return inst;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_set_debug_logging(INST, loggingOn, nCategories, categories);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName,
                                          fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)visible;
    return (fmi3Instance)fmi3_new("fmi3InstantiateModelExchange", BGM_KIND_ME, instanceName,
                                  instantiationToken, resourcePath, loggingOn,
                                  instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    bgm_inst *inst;
    (void)visible;
#if !BGM_HYBRID
    (void)earlyReturnAllowed;
#endif
    (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    inst = fmi3_new("fmi3InstantiateCoSimulation", BGM_KIND_CS, instanceName,
                    instantiationToken, resourcePath, loggingOn, instanceEnvironment,
                    logMessage);
    if (inst) {
        inst->event_mode_used = eventModeUsed ? 1 : 0;
#if BGM_HYBRID
        inst->early_return_allowed = earlyReturnAllowed ? 1 : 0;
#endif
        if (nRequiredIntermediateVariables > 0)
            bgm_log(inst, BGM_WARNING, "logStatusWarning",
                    "fmi3InstantiateCoSimulation: intermediate update is not provided, "
                    "%lu required intermediate variables ignored",
                    (unsigned long)nRequiredIntermediateVariables);
    }
    return (fmi3Instance)inst;
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName;
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    (void)clockUpdate;
    (void)lockPreemption;
    (void)unlockPreemption;
    if (logMessage)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "fmi3InstantiateScheduledExecution: Scheduled Execution is not supported");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    if (bgm_valid(INST)) bgm_free(INST);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    bgm_status s;
    VALID_OR_ERROR(instance);
    s = bgm_setup_experiment(INST, "fmi3EnterInitializationMode", toleranceDefined, tolerance,
                             startTime, stopTimeDefined, stopTime);
    if (s != BGM_OK) return (fmi3Status)s;
    return (fmi3Status)bgm_enter_init(INST, "fmi3EnterInitializationMode");
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_exit_init(INST, "fmi3ExitInitializationMode");
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    VALID_OR_ERROR(instance);
    if (INST->v.kind == BGM_KIND_ME) {
        if (!bgm_check(INST, "fmi3EnterEventMode", BGM_MODE_CONT | BGM_MODE_EVENT))
            return fmi3Error;
    } else {
        if (!INST->event_mode_used) {
            bgm_error(INST, "fmi3EnterEventMode: instantiated with eventModeUsed=false");
            return fmi3Error;
        }
        if (!bgm_check(INST, "fmi3EnterEventMode", BGM_MODE_STEP | BGM_MODE_EVENT))
            return fmi3Error;
    }
    INST->v.mode = BGM_MODE_EVENT;
#if BGM_HYBRID
    return (fmi3Status)bgm_hyb_enter_event(INST, "fmi3EnterEventMode");
#else
    return fmi3OK;
#endif
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_terminate(INST, "fmi3Terminate");
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    VALID_OR_ERROR(instance);
    bgm_reset(INST);
    return fmi3OK;
}

/* ------------------------------------------------------------------- Float64 access */

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Float64 values[], size_t nValues) {
    VALID_OR_ERROR(instance);
    if (nValues != nValueReferences) {
        bgm_error(INST, "fmi3GetFloat64: nValues (%lu) must equal nValueReferences (%lu)",
                  (unsigned long)nValues, (unsigned long)nValueReferences);
        return fmi3Error;
    }
    return (fmi3Status)bgm_get_real(INST, "fmi3GetFloat64", valueReferences, nValueReferences,
                                    values);
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Float64 values[], size_t nValues) {
    VALID_OR_ERROR(instance);
    if (nValues != nValueReferences) {
        bgm_error(INST, "fmi3SetFloat64: nValues (%lu) must equal nValueReferences (%lu)",
                  (unsigned long)nValues, (unsigned long)nValueReferences);
        return fmi3Error;
    }
    return (fmi3Status)bgm_set_real(INST, "fmi3SetFloat64", valueReferences, nValueReferences,
                                    values);
}

/* ------------------------------------------------- types without any variable */

#define BGM_NO_GET(NAME, TYPE)                                                           \
    fmi3Status fmi3Get##NAME(fmi3Instance instance,                                      \
                             const fmi3ValueReference valueReferences[],                 \
                             size_t nValueReferences, TYPE values[], size_t nValues) {   \
        (void)values;                                                                    \
        (void)nValues;                                                                   \
        VALID_OR_ERROR(instance);                                                        \
        return (fmi3Status)bgm_no_variables(INST, "fmi3Get" #NAME, #NAME, valueReferences, \
                                            nValueReferences);                           \
    }
#define BGM_NO_SET(NAME, TYPE)                                                           \
    fmi3Status fmi3Set##NAME(fmi3Instance instance,                                      \
                             const fmi3ValueReference valueReferences[],                 \
                             size_t nValueReferences, const TYPE values[], size_t nValues) { \
        (void)values;                                                                    \
        (void)nValues;                                                                   \
        VALID_OR_ERROR(instance);                                                        \
        return (fmi3Status)bgm_no_variables(INST, "fmi3Set" #NAME, #NAME, valueReferences, \
                                            nValueReferences);                           \
    }
#define BGM_NO_VARS(NAME, TYPE) BGM_NO_GET(NAME, TYPE) BGM_NO_SET(NAME, TYPE)

BGM_NO_VARS(Float32, fmi3Float32)
BGM_NO_VARS(Int8, fmi3Int8)
BGM_NO_VARS(UInt8, fmi3UInt8)
BGM_NO_VARS(Int16, fmi3Int16)
BGM_NO_VARS(UInt16, fmi3UInt16)
#if BGM_HYBRID
fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Int32 values[], size_t nValues) {
    VALID_OR_ERROR(instance);
    if (nValues != nValueReferences) {
        bgm_error(INST, "fmi3GetInt32: nValues must equal nValueReferences (scalars only)");
        return fmi3Error;
    }
    return (fmi3Status)bgm_hyb_get_typed(INST, "fmi3GetInt32", valueReferences,
                                         nValueReferences, BGM_DV_INTEGER, 0, values);
}
fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Int32 values[], size_t nValues) {
    VALID_OR_ERROR(instance);
    if (nValues != nValueReferences) {
        bgm_error(INST, "fmi3SetInt32: nValues must equal nValueReferences (scalars only)");
        return fmi3Error;
    }
    return (fmi3Status)bgm_hyb_set_typed(INST, "fmi3SetInt32", valueReferences,
                                         nValueReferences, BGM_DV_INTEGER, 0, values);
}
#else
BGM_NO_VARS(Int32, fmi3Int32)
#endif
BGM_NO_VARS(UInt32, fmi3UInt32)
BGM_NO_VARS(Int64, fmi3Int64)
BGM_NO_VARS(UInt64, fmi3UInt64)
#if BGM_HYBRID
fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, fmi3Boolean values[], size_t nValues) {
    VALID_OR_ERROR(instance);
    if (nValues != nValueReferences) {
        bgm_error(INST, "fmi3GetBoolean: nValues must equal nValueReferences (scalars only)");
        return fmi3Error;
    }
    return (fmi3Status)bgm_hyb_get_typed(INST, "fmi3GetBoolean", valueReferences,
                                         nValueReferences, BGM_DV_BOOLEAN,
                                         sizeof(fmi3Boolean) == 1, values);
}
fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                          size_t nValueReferences, const fmi3Boolean values[], size_t nValues) {
    VALID_OR_ERROR(instance);
    if (nValues != nValueReferences) {
        bgm_error(INST, "fmi3SetBoolean: nValues must equal nValueReferences (scalars only)");
        return fmi3Error;
    }
    return (fmi3Status)bgm_hyb_set_typed(INST, "fmi3SetBoolean", valueReferences,
                                         nValueReferences, BGM_DV_BOOLEAN,
                                         sizeof(fmi3Boolean) == 1, values);
}
#else
BGM_NO_VARS(Boolean, fmi3Boolean)
#endif
BGM_NO_VARS(String, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, size_t valueSizes[], fmi3Binary values[],
                         size_t nValues) {
    (void)valueSizes;
    (void)values;
    (void)nValues;
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_no_variables(INST, "fmi3GetBinary", "Binary", valueReferences,
                                        nValueReferences);
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                         size_t nValueReferences, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues) {
    (void)valueSizes;
    (void)values;
    (void)nValues;
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_no_variables(INST, "fmi3SetBinary", "Binary", valueReferences,
                                        nValueReferences);
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, fmi3Clock values[]) {
    (void)values;
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_no_variables(INST, "fmi3GetClock", "Clock", valueReferences,
                                        nValueReferences);
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                        size_t nValueReferences, const fmi3Clock values[]) {
    (void)values;
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_no_variables(INST, "fmi3SetClock", "Clock", valueReferences,
                                        nValueReferences);
}

/* ----------------------------------------------------------- not provided features */

static fmi3Status fmi3_unsupported(fmi3Instance instance, const char *fn, const char *why) {
    VALID_OR_ERROR(instance);
    bgm_error(INST, "%s: not supported (%s)", fn, why);
    return fmi3Error;
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance,
                                               fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference;
    (void)nDependencies;
    return fmi3_unsupported(instance, "fmi3GetNumberOfVariableDependencies",
                            "providesPerElementDependencies=false");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return fmi3_unsupported(instance, "fmi3GetVariableDependencies",
                            "providesPerElementDependencies=false");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                    size_t nUnknowns, const fmi3ValueReference knowns[],
                                    size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return fmi3_unsupported(instance, "fmi3GetAdjointDerivative",
                            "providesAdjointDerivatives=false");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return fmi3_unsupported(instance, "fmi3EnterConfigurationMode",
                            "the model has no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return fmi3_unsupported(instance, "fmi3ExitConfigurationMode",
                            "the model has no structural parameters");
}

/* the clock arrays are never touched: there are no clocks */
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#endif
#define BGM_NO_CLOCK(NAME, ...)                                                     \
    fmi3Status fmi3##NAME(fmi3Instance instance,                                    \
                          const fmi3ValueReference valueReferences[],               \
                          size_t nValueReferences, __VA_ARGS__) {                   \
        VALID_OR_ERROR(instance);                                                   \
        return (fmi3Status)bgm_no_variables(INST, "fmi3" #NAME, "Clock",           \
                                            valueReferences, nValueReferences);     \
    }

BGM_NO_CLOCK(GetIntervalDecimal, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
BGM_NO_CLOCK(GetIntervalFraction, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
             fmi3IntervalQualifier qualifiers[])
BGM_NO_CLOCK(GetShiftDecimal, fmi3Float64 shifts[])
BGM_NO_CLOCK(GetShiftFraction, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
BGM_NO_CLOCK(SetIntervalDecimal, const fmi3Float64 intervals[])
BGM_NO_CLOCK(SetIntervalFraction, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
BGM_NO_CLOCK(SetShiftDecimal, const fmi3Float64 shifts[])
BGM_NO_CLOCK(SetShiftFraction, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference;
    (void)activationTime;
    return fmi3_unsupported(instance, "fmi3ActivateModelPartition",
                            "Scheduled Execution is not provided");
}

/* ----------------------------------------------------------------- discrete states */

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    VALID_OR_ERROR(instance);
    if (!bgm_check(INST, "fmi3EvaluateDiscreteStates", BGM_MODE_EVENT | BGM_MODE_STEP |
                                                            BGM_MODE_CONT))
        return fmi3Error;
    return fmi3OK;
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    VALID_OR_ERROR(instance);
    if (!bgm_check(INST, "fmi3UpdateDiscreteStates", BGM_MODE_EVENT)) return fmi3Error;
#if BGM_HYBRID
    {
        int need, changed, defined;
        double next;
        if (bgm_hyb_update(INST, "fmi3UpdateDiscreteStates", &need, &changed, &defined,
                           &next) != BGM_OK)
            return fmi3Error;
        if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = need ? fmi3True : fmi3False;
        if (terminateSimulation) *terminateSimulation = fmi3False;
        if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = fmi3False;
        if (valuesOfContinuousStatesChanged)
            *valuesOfContinuousStatesChanged = changed ? fmi3True : fmi3False;
        if (nextEventTimeDefined) *nextEventTimeDefined = defined ? fmi3True : fmi3False;
        if (nextEventTime) *nextEventTime = next;
        return fmi3OK;
    }
#endif
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = fmi3False;
    if (valuesOfContinuousStatesChanged) *valuesOfContinuousStatesChanged = fmi3False;
    if (nextEventTimeDefined) *nextEventTimeDefined = fmi3False;
    if (nextEventTime) *nextEventTime = 0.0;
    return fmi3OK;
}

/* ----------------------------------------------------------------------- FMU state */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_get_state(INST, "fmi3GetFMUState", (void **)FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_set_state(INST, "fmi3SetFMUState", FMUState);
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_free_state(INST, "fmi3FreeFMUState", (void **)FMUState);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState,
                                      size_t *size) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_serialized_size(INST, "fmi3SerializedFMUStateSize", FMUState, size);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState,
                                 fmi3Byte serializedState[], size_t size) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_serialize(INST, "fmi3SerializeFMUState", FMUState, serializedState,
                                     size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[],
                                   size_t size, fmi3FMUState *FMUState) {
    VALID_OR_ERROR(instance);
    return (fmi3Status)bgm_deserialize(INST, "fmi3DeserializeFMUState", serializedState, size,
                                       (void **)FMUState);
}

/* ------------------------------------------------------------ directional derivative */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance,
                                        const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns,
                                        const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity) {
    VALID_OR_ERROR(instance);
    if (nSeed != nKnowns || nSensitivity != nUnknowns) {
        bgm_error(INST, "fmi3GetDirectionalDerivative: nSeed must equal nKnowns and "
                  "nSensitivity must equal nUnknowns (all variables are scalars)");
        return fmi3Error;
    }
    return (fmi3Status)bgm_directional_derivative(INST, "fmi3GetDirectionalDerivative",
                                                  unknowns, nUnknowns, knowns, nKnowns, seed,
                                                  sensitivity);
}
