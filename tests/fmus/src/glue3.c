/*
 * A small FMI 3.0 runtime for the test FMUs of this folder (Model Exchange and
 * Co-Simulation in one binary). A model file defines its variable table VARS, its sizes
 * and the hooks below, then includes this file:
 *
 *   static void model_start(Inst *)                 start values (data is zeroed)
 *   static int  model_setup(Inst *)                 at exitInitializationMode; 0 = ok
 *   static void model_outputs(Inst *)               outputs and locals from inputs/states
 *   static void model_derivatives(Inst *, double *) der(x) (NX entries)
 *   static void model_event(Inst *)                 at an event: discrete updates; may set
 *                                                   inst->next_time / inst->terminate
 *
 * Continuous states live in inst->x[NX]. Co-Simulation integrates them with RK4 at a
 * fixed internal step (H_INT) and stops at time events; a terminate request ends doStep at
 * the event with terminateSimulation and lastSuccessfulTime. FMU states can be saved and
 * restored (a copy of the instance's data).
 */
#include "glue3.h"

typedef struct Inst Inst;

typedef struct {
    unsigned char *data[NVARS];
    size_t bin_size[NVARS];
    double x[NX > 0 ? NX : 1];
    double time;
    double next_time;
    int next_defined;
} Snapshot;

struct Inst {
    char name[128];
    char resource[1024];
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    int cs;
    int initialized;
    int terminate;
    Snapshot s;
    MODEL_STATE model;   /* model-specific fields */
};

#define TIME (inst->s.time)
#define F64(i) ((double *)inst->s.data[i])
#define F32(i) ((float *)inst->s.data[i])
#define I64(i) ((int64_t *)inst->s.data[i])
#define I32(i) ((int32_t *)inst->s.data[i])
#define BOOL(i) ((fmi3Boolean *)inst->s.data[i])
#define STR(i) ((char **)inst->s.data[i])

static void logf3(Inst *inst, fmi3Status status, const char *fmt, const char *arg) {
    char msg[1400];
    if (!inst->log) return;
    snprintf(msg, sizeof msg, fmt, arg);
    inst->log(inst->env, status, status == fmi3OK ? "logEvents" : "logStatusError", msg);
}

static int find(unsigned vr) {
    int i;
    for (i = 0; i < NVARS; i++)
        if (VARS[i].vr == vr) return i;
    return -1;
}

static void model_start(Inst *inst);
static int model_setup(Inst *inst);
static void model_outputs(Inst *inst);
static void model_derivatives(Inst *inst, double *dx);
static void model_event(Inst *inst);

static int snapshot_alloc(Snapshot *s) {
    int i;
    memset(s, 0, sizeof *s);
    for (i = 0; i < NVARS; i++) {
        s->data[i] = calloc(VARS[i].n, TYPE_SIZE[VARS[i].type]);
        if (!s->data[i]) return 0;
    }
    return 1;
}

static void snapshot_free(Snapshot *s) {
    int i;
    size_t k;
    for (i = 0; i < NVARS; i++) {
        if (!s->data[i]) continue;
        if (VARS[i].type == T_STR || VARS[i].type == T_BIN)
            for (k = 0; k < VARS[i].n; k++) free(((void **)s->data[i])[k]);
        free(s->data[i]);
        s->data[i] = NULL;
    }
}

static int snapshot_copy(Snapshot *dst, const Snapshot *src) {
    int i;
    size_t k;
    snapshot_free(dst);
    if (!snapshot_alloc(dst)) return 0;
    for (i = 0; i < NVARS; i++) {
        size_t bytes = VARS[i].n * TYPE_SIZE[VARS[i].type];
        if (VARS[i].type == T_STR) {
            for (k = 0; k < VARS[i].n; k++) {
                const char *from = ((char **)src->data[i])[k];
                ((char **)dst->data[i])[k] = from ? strdup(from) : NULL;
            }
        } else if (VARS[i].type == T_BIN) {
            const void *from = ((void **)src->data[i])[0];
            dst->bin_size[i] = src->bin_size[i];
            if (from) {
                void *to = malloc(src->bin_size[i] ? src->bin_size[i] : 1);
                memcpy(to, from, src->bin_size[i]);
                ((void **)dst->data[i])[0] = to;
            }
        } else {
            memcpy(dst->data[i], src->data[i], bytes);
        }
    }
    memcpy(dst->x, src->x, sizeof src->x);
    dst->time = src->time;
    dst->next_time = src->next_time;
    dst->next_defined = src->next_defined;
    return 1;
}

/* ---- instantiation ----------------------------------------------------------------- */

static Inst *make(fmi3String name, fmi3String token, fmi3String resourcePath, int cs,
                  fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    Inst *inst;
    if (!token || strcmp(token, TOKEN) != 0) {
        if (log) log(env, fmi3Error, "logStatusError", "wrong instantiation token");
        return NULL;
    }
    inst = calloc(1, sizeof *inst);
    if (!inst || !snapshot_alloc(&inst->s)) {
        free(inst);
        return NULL;
    }
    snprintf(inst->name, sizeof inst->name, "%s", name ? name : "");
    snprintf(inst->resource, sizeof inst->resource, "%s", resourcePath ? resourcePath : "");
    inst->env = env;
    inst->log = log;
    inst->cs = cs;
    model_start(inst);
    return inst;
}

FMI3_Export fmi3Instance fmi3InstantiateModelExchange(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage) {
    (void)visible; (void)loggingOn;
    return make(instanceName, instantiationToken, resourcePath, 0, instanceEnvironment,
                logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
    fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)visible; (void)loggingOn; (void)eventModeUsed; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    return make(instanceName, instantiationToken, resourcePath, 1, instanceEnvironment,
                logMessage);
}

FMI3_Export fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
    fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
    fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
    fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible;
    (void)loggingOn; (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "Scheduled Execution is not provided");
    return NULL;
}

FMI3_Export void fmi3FreeInstance(fmi3Instance instance) {
    Inst *inst = (Inst *)instance;
    if (!inst) return;
    snapshot_free(&inst->s);
    free(inst);
}

FMI3_Export const char *fmi3GetVersion(void) { return fmi3Version; }

FMI3_Export fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn,
                                           size_t nCategories, const fmi3String categories[]) {
    (void)instance; (void)loggingOn; (void)nCategories; (void)categories;
    return fmi3OK;
}

/* ---- modes --------------------------------------------------------------------------- */

FMI3_Export fmi3Status fmi3EnterInitializationMode(fmi3Instance instance,
                                                   fmi3Boolean toleranceDefined,
                                                   fmi3Float64 tolerance,
                                                   fmi3Float64 startTime,
                                                   fmi3Boolean stopTimeDefined,
                                                   fmi3Float64 stopTime) {
    Inst *inst = (Inst *)instance;
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    inst->s.time = startTime;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Inst *inst = (Inst *)instance;
    if (model_setup(inst) != 0) return fmi3Error;
    inst->initialized = 1;
    model_outputs(inst);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Terminate(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3Reset(fmi3Instance instance) {
    Inst *inst = (Inst *)instance;
    snapshot_free(&inst->s);
    if (!snapshot_alloc(&inst->s)) return fmi3Fatal;
    inst->initialized = 0;
    inst->terminate = 0;
    model_start(inst);
    return fmi3OK;
}

/* ---- getters and setters ------------------------------------------------------------ */

#define ACCESS(Name, ctype, TCODE, GET)                                                       \
    FMI3_Export fmi3Status fmi3##GET##Name(fmi3Instance instance,                             \
                                           const fmi3ValueReference valueReferences[],       \
                                           size_t nValueReferences, ctype values[],          \
                                           size_t nValues) {                                 \
        Inst *inst = (Inst *)instance;                                                        \
        size_t k, pos = 0;                                                                    \
        if (GET_IS_##GET) model_outputs(inst);                                                \
        for (k = 0; k < nValueReferences; k++) {                                              \
            int i = find(valueReferences[k]);                                                 \
            if (i < 0 || VARS[i].type != TCODE || pos + VARS[i].n > nValues) {               \
                logf3(inst, fmi3Error, "%s: unknown value reference, wrong type or too few "  \
                      "values", #GET #Name);                                                  \
                return fmi3Error;                                                             \
            }                                                                                 \
            if (GET_IS_##GET)                                                                 \
                memcpy((void *)&values[pos], inst->s.data[i], VARS[i].n * sizeof(ctype));    \
            else                                                                              \
                memcpy(inst->s.data[i], (const void *)&values[pos], VARS[i].n * sizeof(ctype)); \
            pos += VARS[i].n;                                                                 \
        }                                                                                     \
        return fmi3OK;                                                                        \
    }

#define GET_IS_Get 1
#define GET_IS_Set 0
#define BOTH(Name, ctype, TCODE) ACCESS(Name, ctype, TCODE, Get) ACCESS(Name, const ctype, TCODE, Set)

BOTH(Float32, fmi3Float32, T_F32)
BOTH(Float64, fmi3Float64, T_F64)
BOTH(Int8, fmi3Int8, T_I8)
BOTH(UInt8, fmi3UInt8, T_U8)
BOTH(Int16, fmi3Int16, T_I16)
BOTH(UInt16, fmi3UInt16, T_U16)
BOTH(Int32, fmi3Int32, T_I32)
BOTH(UInt32, fmi3UInt32, T_U32)
BOTH(Int64, fmi3Int64, T_I64)
BOTH(UInt64, fmi3UInt64, T_U64)
BOTH(Boolean, fmi3Boolean, T_BOOL)

FMI3_Export fmi3Status fmi3GetString(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, fmi3String values[],
                                     size_t nValues) {
    Inst *inst = (Inst *)instance;
    size_t k;
    model_outputs(inst);
    for (k = 0; k < nValueReferences; k++) {
        int i = find(valueReferences[k]);
        if (i < 0 || VARS[i].type != T_STR || k >= nValues) return fmi3Error;
        values[k] = STR(i)[0] ? STR(i)[0] : "";
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetString(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const fmi3String values[],
                                     size_t nValues) {
    Inst *inst = (Inst *)instance;
    size_t k;
    for (k = 0; k < nValueReferences; k++) {
        int i = find(valueReferences[k]);
        if (i < 0 || VARS[i].type != T_STR || k >= nValues) return fmi3Error;
        free(STR(i)[0]);
        STR(i)[0] = strdup(values[k] ? values[k] : "");
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetBinary(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, size_t valueSizes[],
                                     fmi3Binary values[], size_t nValues) {
    Inst *inst = (Inst *)instance;
    size_t k;
    model_outputs(inst);
    for (k = 0; k < nValueReferences; k++) {
        int i = find(valueReferences[k]);
        if (i < 0 || VARS[i].type != T_BIN || k >= nValues) return fmi3Error;
        values[k] = ((fmi3Binary *)inst->s.data[i])[0];
        valueSizes[k] = inst->s.bin_size[i];
    }
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetBinary(fmi3Instance instance,
                                     const fmi3ValueReference valueReferences[],
                                     size_t nValueReferences, const size_t valueSizes[],
                                     const fmi3Binary values[], size_t nValues) {
    Inst *inst = (Inst *)instance;
    size_t k;
    for (k = 0; k < nValueReferences; k++) {
        int i = find(valueReferences[k]);
        void *copy;
        if (i < 0 || VARS[i].type != T_BIN || k >= nValues) return fmi3Error;
        copy = malloc(valueSizes[k] ? valueSizes[k] : 1);
        memcpy(copy, values[k], valueSizes[k]);
        free(((void **)inst->s.data[i])[0]);
        ((void **)inst->s.data[i])[0] = copy;
        inst->s.bin_size[i] = valueSizes[k];
    }
    return fmi3OK;
}

/* ---- FMU state ------------------------------------------------------------------------ */

FMI3_Export fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    Inst *inst = (Inst *)instance;
    Snapshot *s = *FMUState ? (Snapshot *)*FMUState : calloc(1, sizeof(Snapshot));
    if (!s || !snapshot_copy(s, &inst->s)) return fmi3Error;
    *FMUState = s;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    Inst *inst = (Inst *)instance;
    if (!FMUState || !snapshot_copy(&inst->s, (Snapshot *)FMUState)) return fmi3Error;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    (void)instance;
    if (FMUState && *FMUState) {
        snapshot_free((Snapshot *)*FMUState);
        free(*FMUState);
        *FMUState = NULL;
    }
    return fmi3OK;
}

/* ---- Model Exchange ----------------------------------------------------------------- */

FMI3_Export fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    (void)instance;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                                   fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi3Boolean *enterEventMode,
                                                   fmi3Boolean *terminateSimulation) {
    (void)instance; (void)noSetFMUStatePriorToCurrentPoint;
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Inst *)instance)->s.time = time;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3SetContinuousStates(fmi3Instance instance,
                                               const fmi3Float64 continuousStates[],
                                               size_t nContinuousStates) {
    Inst *inst = (Inst *)instance;
    if (nContinuousStates != NX) return fmi3Error;
    if (NX) memcpy(inst->s.x, continuousStates, NX * sizeof(double));
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetContinuousStates(fmi3Instance instance,
                                               fmi3Float64 continuousStates[],
                                               size_t nContinuousStates) {
    Inst *inst = (Inst *)instance;
    if (nContinuousStates != NX) return fmi3Error;
    if (NX) memcpy(continuousStates, inst->s.x, NX * sizeof(double));
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance,
                                                         fmi3Float64 derivatives[],
                                                         size_t nContinuousStates) {
    Inst *inst = (Inst *)instance;
    if (nContinuousStates != NX) return fmi3Error;
    if (NX) model_derivatives(inst, derivatives);
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetEventIndicators(fmi3Instance instance,
                                              fmi3Float64 eventIndicators[],
                                              size_t nEventIndicators) {
    (void)instance; (void)eventIndicators;
    return nEventIndicators == 0 ? fmi3OK : fmi3Error;
}

FMI3_Export fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance,
                                                         fmi3Float64 nominals[],
                                                         size_t nContinuousStates) {
    size_t k;
    (void)instance;
    for (k = 0; k < nContinuousStates; k++) nominals[k] = 1.0;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance,
                                                      size_t *nEventIndicators) {
    (void)instance;
    *nEventIndicators = 0;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance,
                                                       size_t *nContinuousStates) {
    (void)instance;
    *nContinuousStates = NX;
    return fmi3OK;
}

FMI3_Export fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance,
                                                fmi3Boolean *discreteStatesNeedUpdate,
                                                fmi3Boolean *terminateSimulation,
                                                fmi3Boolean *nominalsOfContinuousStatesChanged,
                                                fmi3Boolean *valuesOfContinuousStatesChanged,
                                                fmi3Boolean *nextEventTimeDefined,
                                                fmi3Float64 *nextEventTime) {
    Inst *inst = (Inst *)instance;
    if (inst->s.next_defined && inst->s.time >= inst->s.next_time - 1e-12)
        model_event(inst);
    model_outputs(inst);
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = inst->terminate ? fmi3True : fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = inst->s.next_defined ? fmi3True : fmi3False;
    *nextEventTime = inst->s.next_time;
    return fmi3OK;
}

/* ---- Co-Simulation ------------------------------------------------------------------- */

static void rk4(Inst *inst, double h) {
    double k1[NX > 0 ? NX : 1], k2[NX > 0 ? NX : 1], k3[NX > 0 ? NX : 1], k4[NX > 0 ? NX : 1];
    double x0[NX > 0 ? NX : 1], t0 = inst->s.time;
    int i;
    if (NX == 0) {
        inst->s.time = t0 + h;
        return;
    }
    memcpy(x0, inst->s.x, sizeof x0);
    model_derivatives(inst, k1);
    for (i = 0; i < NX; i++) inst->s.x[i] = x0[i] + 0.5 * h * k1[i];
    inst->s.time = t0 + 0.5 * h;
    model_derivatives(inst, k2);
    for (i = 0; i < NX; i++) inst->s.x[i] = x0[i] + 0.5 * h * k2[i];
    model_derivatives(inst, k3);
    for (i = 0; i < NX; i++) inst->s.x[i] = x0[i] + h * k3[i];
    inst->s.time = t0 + h;
    model_derivatives(inst, k4);
    for (i = 0; i < NX; i++)
        inst->s.x[i] = x0[i] + h / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}

FMI3_Export fmi3Status fmi3DoStep(fmi3Instance instance,
                                  fmi3Float64 currentCommunicationPoint,
                                  fmi3Float64 communicationStepSize,
                                  fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                  fmi3Boolean *eventHandlingNeeded,
                                  fmi3Boolean *terminateSimulation,
                                  fmi3Boolean *earlyReturn,
                                  fmi3Float64 *lastSuccessfulTime) {
    Inst *inst = (Inst *)instance;
    double t_end = currentCommunicationPoint + communicationStepSize;
    (void)noSetFMUStatePriorToCurrentPoint;
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    inst->s.time = currentCommunicationPoint;
    while (inst->s.time < t_end - 1e-13 * (1.0 + t_end)) {
        double stop = t_end, h;
        if (inst->s.next_defined && inst->s.next_time < stop) stop = inst->s.next_time;
        h = stop - inst->s.time;
        if (h > H_INT) h = H_INT;
        rk4(inst, h);
        if (inst->s.next_defined && inst->s.time >= inst->s.next_time - 1e-12) {
            inst->s.time = inst->s.next_time;
            model_event(inst);
            if (inst->terminate) {
                *terminateSimulation = fmi3True;
                *earlyReturn = inst->s.time < t_end ? fmi3True : fmi3False;
                *lastSuccessfulTime = inst->s.time;
                model_outputs(inst);
                return fmi3OK;
            }
        }
    }
    inst->s.time = t_end;
    *lastSuccessfulTime = t_end;
    model_outputs(inst);
    return fmi3OK;
}

/* ---- not provided ------------------------------------------------------------------- */

#define NOT_PROVIDED(call, ...)                                                              \
    FMI3_Export fmi3Status call(fmi3Instance instance, __VA_ARGS__) {                         \
        logf3((Inst *)instance, fmi3Error, "%s is not provided by this FMU", #call);         \
        return fmi3Error;                                                                     \
    }

NOT_PROVIDED(fmi3GetClock, const fmi3ValueReference v[], size_t n, fmi3Clock c[])
NOT_PROVIDED(fmi3SetClock, const fmi3ValueReference v[], size_t n, const fmi3Clock c[])
NOT_PROVIDED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference v, size_t *n)
NOT_PROVIDED(fmi3GetVariableDependencies, fmi3ValueReference d, size_t e[],
             fmi3ValueReference i[], size_t ei[], fmi3DependencyKind k[], size_t n)
NOT_PROVIDED(fmi3SerializedFMUStateSize, fmi3FMUState s, size_t *size)
NOT_PROVIDED(fmi3SerializeFMUState, fmi3FMUState s, fmi3Byte b[], size_t size)
NOT_PROVIDED(fmi3DeserializeFMUState, const fmi3Byte b[], size_t size, fmi3FMUState *s)
NOT_PROVIDED(fmi3GetDirectionalDerivative, const fmi3ValueReference u[], size_t nu,
             const fmi3ValueReference k[], size_t nk, const fmi3Float64 s[], size_t ns,
             fmi3Float64 r[], size_t nr)
NOT_PROVIDED(fmi3GetAdjointDerivative, const fmi3ValueReference u[], size_t nu,
             const fmi3ValueReference k[], size_t nk, const fmi3Float64 s[], size_t ns,
             fmi3Float64 r[], size_t nr)
NOT_PROVIDED(fmi3GetIntervalDecimal, const fmi3ValueReference v[], size_t n, fmi3Float64 i[],
             fmi3IntervalQualifier q[])
NOT_PROVIDED(fmi3GetIntervalFraction, const fmi3ValueReference v[], size_t n,
             fmi3UInt64 c[], fmi3UInt64 r[], fmi3IntervalQualifier q[])
NOT_PROVIDED(fmi3GetShiftDecimal, const fmi3ValueReference v[], size_t n, fmi3Float64 s[])
NOT_PROVIDED(fmi3GetShiftFraction, const fmi3ValueReference v[], size_t n, fmi3UInt64 c[],
             fmi3UInt64 r[])
NOT_PROVIDED(fmi3SetIntervalDecimal, const fmi3ValueReference v[], size_t n,
             const fmi3Float64 i[])
NOT_PROVIDED(fmi3SetIntervalFraction, const fmi3ValueReference v[], size_t n,
             const fmi3UInt64 c[], const fmi3UInt64 r[])
NOT_PROVIDED(fmi3SetShiftDecimal, const fmi3ValueReference v[], size_t n, const fmi3Float64 s[])
NOT_PROVIDED(fmi3SetShiftFraction, const fmi3ValueReference v[], size_t n,
             const fmi3UInt64 c[], const fmi3UInt64 r[])
NOT_PROVIDED(fmi3GetOutputDerivatives, const fmi3ValueReference v[], size_t n,
             const fmi3Int32 o[], fmi3Float64 values[], size_t nv)
NOT_PROVIDED(fmi3ActivateModelPartition, fmi3ValueReference c, fmi3Float64 t)

#define NOT_PROVIDED0(call)                                                                  \
    FMI3_Export fmi3Status call(fmi3Instance instance) {                                      \
        logf3((Inst *)instance, fmi3Error, "%s is not provided by this FMU", #call);         \
        return fmi3Error;                                                                     \
    }

NOT_PROVIDED0(fmi3EvaluateDiscreteStates)
NOT_PROVIDED0(fmi3EnterStepMode)
NOT_PROVIDED0(fmi3EnterConfigurationMode)
NOT_PROVIDED0(fmi3ExitConfigurationMode)
