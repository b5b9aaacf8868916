/*
 * bgmodelica FMU runtime: FMI 2.0 functions common to Model Exchange and Co-Simulation.
 * Written for bgmodelica from the FMI 2.0.x specification.
 */
#include <string.h>

#include "fmi2Functions.h"
#include "bgm_core.h"

#define INST ((bgm_inst *)c)
#define VALID_OR_ERROR(c) \
    do {                  \
        if (!bgm_valid(INST)) return fmi2Error; \
    } while (0)

static void fmi2_emit(bgm_inst *inst, int status, const char *category, const char *message) {
    fmi2CallbackLogger logger = (fmi2CallbackLogger)inst->logger_fn;
    if (logger)
        logger((fmi2ComponentEnvironment)inst->logger_env, inst->name, (fmi2Status)status,
               category, "%s", message);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_set_debug_logging(INST, loggingOn, nCategories, categories);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    fmi2ComponentEnvironment env = functions ? functions->componentEnvironment : NULL;
    const char *name = instanceName ? instanceName : "(null)";
    int kind;
    bgm_inst *inst;
    (void)visible;
    if (!instanceName || !instanceName[0]) {
        if (logger)
            logger(env, name, fmi2Error, "logStatusError",
                   "fmi2Instantiate: missing instance name");
        return NULL;
    }
    if (fmuType == fmi2ModelExchange && BGM_HAS_ME) kind = BGM_KIND_ME;
    else if (fmuType == fmi2CoSimulation && BGM_HAS_CS) kind = BGM_KIND_CS;
    else {
        if (logger)
            logger(env, name, fmi2Error, "logStatusError",
                   "fmi2Instantiate: this FMU does not support interface type %d",
                   (int)fmuType);
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, BGM_TOKEN) != 0) {
        if (logger)
            logger(env, name, fmi2Error, "logStatusError",
                   "fmi2Instantiate: wrong GUID \"%s\", expected \"%s\"",
                   fmuGUID ? fmuGUID : "(null)", BGM_TOKEN);
        return NULL;
    }
    inst = bgm_new(2, kind, instanceName, loggingOn, fmi2_emit, (bgm_any_fn)logger, env);
    if (!inst && logger)
        logger(env, name, fmi2Fatal, "logStatusError", "fmi2Instantiate: out of memory");
#if BGM_HYBRID
    if (inst) {                                   /* tables from resource files */
        char dir[4096];
        bgm_resource_dir(fmuResourceLocation, dir, sizeof dir);
        if (bgm_tables_load(inst, dir)) {
            bgm_free(inst);
            return NULL;
        }
    }
#else
    (void)fmuResourceLocation;
#endif
    return (fmi2Component)inst;
}

void fmi2FreeInstance(fmi2Component c) {
    if (bgm_valid(INST)) bgm_free(INST);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_setup_experiment(INST, "fmi2SetupExperiment", toleranceDefined,
                                            tolerance, startTime, stopTimeDefined, stopTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_enter_init(INST, "fmi2EnterInitializationMode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_exit_init(INST, "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component c) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_terminate(INST, "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component c) {
    VALID_OR_ERROR(c);
    bgm_reset(INST);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_get_real(INST, "fmi2GetReal", vr, nvr, value);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    VALID_OR_ERROR(c);
#if BGM_HYBRID
    return (fmi2Status)bgm_hyb_get_typed(INST, "fmi2GetInteger", vr, nvr, BGM_DV_INTEGER, 0,
                                         value);
#endif
    (void)value;
    return (fmi2Status)bgm_no_variables(INST, "fmi2GetInteger", "Integer", vr, nvr);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    VALID_OR_ERROR(c);
#if BGM_HYBRID
    return (fmi2Status)bgm_hyb_get_typed(INST, "fmi2GetBoolean", vr, nvr, BGM_DV_BOOLEAN, 0,
                                         value);
#endif
    (void)value;
    return (fmi2Status)bgm_no_variables(INST, "fmi2GetBoolean", "Boolean", vr, nvr);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    (void)value;
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_no_variables(INST, "fmi2GetString", "String", vr, nvr);
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_set_real(INST, "fmi2SetReal", vr, nvr, value);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    VALID_OR_ERROR(c);
#if BGM_HYBRID
    return (fmi2Status)bgm_hyb_set_typed(INST, "fmi2SetInteger", vr, nvr, BGM_DV_INTEGER, 0,
                                         value);
#endif
    (void)value;
    return (fmi2Status)bgm_no_variables(INST, "fmi2SetInteger", "Integer", vr, nvr);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    VALID_OR_ERROR(c);
#if BGM_HYBRID
    return (fmi2Status)bgm_hyb_set_typed(INST, "fmi2SetBoolean", vr, nvr, BGM_DV_BOOLEAN, 0,
                                         value);
#endif
    (void)value;
    return (fmi2Status)bgm_no_variables(INST, "fmi2SetBoolean", "Boolean", vr, nvr);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    (void)value;
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_no_variables(INST, "fmi2SetString", "String", vr, nvr);
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_get_state(INST, "fmi2GetFMUstate", (void **)FMUstate);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_set_state(INST, "fmi2SetFMUstate", FMUstate);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_free_state(INST, "fmi2FreeFMUstate", (void **)FMUstate);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_serialized_size(INST, "fmi2SerializedFMUstateSize", FMUstate, size);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[],
                                 size_t size) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_serialize(INST, "fmi2SerializeFMUstate", FMUstate, serializedState,
                                     size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_deserialize(INST, "fmi2DeSerializeFMUstate", serializedState, size,
                                       (void **)FMUstate);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    VALID_OR_ERROR(c);
    return (fmi2Status)bgm_directional_derivative(INST, "fmi2GetDirectionalDerivative",
                                                  vUnknown_ref, nUnknown, vKnown_ref, nKnown,
                                                  dvKnown, dvUnknown);
}
