/*
 * A small FMI 2.0 runtime for the test FMUs of this folder (Model Exchange and
 * Co-Simulation in one binary). A model file defines TOKEN, NVARS, NX, H_INT, its variable
 * table VARS (value reference = index) and the hooks, then includes this file:
 *
 *   static void model_start(Inst *)                 start values
 *   static int  model_setup(Inst *)                 at exitInitializationMode; 0 = ok
 *   static void model_outputs(Inst *)               outputs from inputs and states
 *   static void model_derivatives(Inst *, double *) der(x)
 *
 * Variables are fmi2Real, fmi2Integer (also enumerations), fmi2Boolean or fmi2String.
 * Co-Simulation integrates the states with RK4 at the fixed internal step H_INT.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

enum { T_REAL, T_INT, T_BOOL, T_STR };

typedef struct {
    int type;
} Var;

static const Var VARS[NVARS];

typedef struct {
    double r[NVARS];
    int i[NVARS];
    char *s[NVARS];
    double x[NX > 0 ? NX : 1];
    double time;
} State;

typedef struct {
    char name[128];
    fmi2CallbackFunctions cb;
    int cs;
    State st;
} Inst;

#define TIME (inst->st.time)

static void model_start(Inst *inst);
static int model_setup(Inst *inst);
static void model_outputs(Inst *inst);
static void model_derivatives(Inst *inst, double *dx);

static void state_free(State *s) {
    int k;
    for (k = 0; k < NVARS; k++) {
        free(s->s[k]);
        s->s[k] = NULL;
    }
}

static void state_copy(State *dst, const State *src) {
    int k;
    state_free(dst);
    *dst = *src;
    for (k = 0; k < NVARS; k++) dst->s[k] = src->s[k] ? strdup(src->s[k]) : NULL;
}

static int bad(Inst *inst, const char *fn, fmi2ValueReference vr) {
    if (inst->cb.logger)
        inst->cb.logger(inst->cb.componentEnvironment, inst->name, fmi2Error, "logStatusError",
                        "%s: value reference %u is unknown or of another type", fn, vr);
    return 1;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)c; (void)loggingOn; (void)nCategories; (void)categories;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    Inst *inst;
    (void)fmuResourceLocation; (void)visible; (void)loggingOn;
    if (!fmuGUID || strcmp(fmuGUID, TOKEN) != 0) return NULL;
    inst = calloc(1, sizeof *inst);
    if (!inst) return NULL;
    snprintf(inst->name, sizeof inst->name, "%s", instanceName ? instanceName : "");
    if (functions) inst->cb = *functions;
    inst->cs = fmuType == fmi2CoSimulation;
    model_start(inst);
    return inst;
}

void fmi2FreeInstance(fmi2Component c) {
    Inst *inst = (Inst *)c;
    if (!inst) return;
    state_free(&inst->st);
    free(inst);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    ((Inst *)c)->st.time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Inst *inst = (Inst *)c;
    if (model_setup(inst)) return fmi2Error;
    model_outputs(inst);
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    Inst *inst = (Inst *)c;
    state_free(&inst->st);
    memset(&inst->st, 0, sizeof inst->st);
    model_start(inst);
    return fmi2OK;
}

#define CHECK(fn, TCODE)                                                                     \
    if (vr[k] >= NVARS || VARS[vr[k]].type != TCODE) {                                        \
        bad(inst, fn, vr[k]);                                                                 \
        return fmi2Error;                                                                     \
    }

#define GETTER(Name, ctype, TCODE, field)                                                     \
    fmi2Status fmi2Get##Name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,      \
                             ctype value[]) {                                                 \
        Inst *inst = (Inst *)c;                                                               \
        size_t k;                                                                             \
        model_outputs(inst);                                                                  \
        for (k = 0; k < nvr; k++) {                                                           \
            CHECK("fmi2Get" #Name, TCODE)                                                     \
            value[k] = (ctype)inst->st.field[vr[k]];                                          \
        }                                                                                     \
        return fmi2OK;                                                                        \
    }

#define SETTER(Name, ctype, TCODE, field, convert)                                            \
    fmi2Status fmi2Set##Name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,      \
                             const ctype value[]) {                                           \
        Inst *inst = (Inst *)c;                                                               \
        size_t k;                                                                             \
        for (k = 0; k < nvr; k++) {                                                           \
            CHECK("fmi2Set" #Name, TCODE)                                                     \
            inst->st.field[vr[k]] = convert(value[k]);                                        \
        }                                                                                     \
        return fmi2OK;                                                                        \
    }

#define AS_IS(v) (v)
#define AS_BOOL(v) ((v) ? 1 : 0)

GETTER(Real, fmi2Real, T_REAL, r)
SETTER(Real, fmi2Real, T_REAL, r, AS_IS)
GETTER(Integer, fmi2Integer, T_INT, i)
SETTER(Integer, fmi2Integer, T_INT, i, AS_IS)
GETTER(Boolean, fmi2Boolean, T_BOOL, i)
SETTER(Boolean, fmi2Boolean, T_BOOL, i, AS_BOOL)

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    Inst *inst = (Inst *)c;
    size_t k;
    model_outputs(inst);
    for (k = 0; k < nvr; k++) {
        if (vr[k] >= NVARS || VARS[vr[k]].type != T_STR) {
            bad(inst, "fmi2GetString", vr[k]);
            return fmi2Error;
        }
        value[k] = inst->st.s[vr[k]] ? inst->st.s[vr[k]] : "";
    }
    return fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    Inst *inst = (Inst *)c;
    size_t k;
    for (k = 0; k < nvr; k++) {
        if (vr[k] >= NVARS || VARS[vr[k]].type != T_STR) {
            bad(inst, "fmi2SetString", vr[k]);
            return fmi2Error;
        }
        free(inst->st.s[vr[k]]);
        inst->st.s[vr[k]] = strdup(value[k] ? value[k] : "");
    }
    return fmi2OK;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    Inst *inst = (Inst *)c;
    State *s = *FMUstate ? (State *)*FMUstate : calloc(1, sizeof(State));
    if (!s) return fmi2Error;
    state_copy(s, &inst->st);
    *FMUstate = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    if (!FMUstate) return fmi2Error;
    state_copy(&((Inst *)c)->st, (const State *)FMUstate);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    (void)c;
    if (FMUstate && *FMUstate) {
        state_free((State *)*FMUstate);
        free(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

/* ---- Model Exchange -------------------------------------------------------------------- */

fmi2Status fmi2EnterEventMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    (void)c;
    memset(info, 0, sizeof *info);
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
    (void)c;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noPrior,
                                       fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    (void)c; (void)noPrior;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    ((Inst *)c)->st.time = time;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    if (nx != NX) return fmi2Error;
    if (NX) memcpy(((Inst *)c)->st.x, x, NX * sizeof(double));
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    if (nx != NX) return fmi2Error;
    if (NX) memcpy(x, ((Inst *)c)->st.x, NX * sizeof(double));
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t nx) {
    if (nx != NX) return fmi2Error;
    if (NX) model_derivatives((Inst *)c, dx);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t nz) {
    (void)c; (void)z;
    return nz == 0 ? fmi2OK : fmi2Error;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real n[], size_t nx) {
    size_t k;
    (void)c;
    for (k = 0; k < nx; k++) n[k] = 1.0;
    return fmi2OK;
}

/* ---- Co-Simulation ------------------------------------------------------------------- */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noPrior) {
    Inst *inst = (Inst *)c;
    double t_end = t + h;
    (void)noPrior;
    inst->st.time = t;
    while (inst->st.time < t_end - 1e-13 * (1.0 + t_end)) {
        double step = t_end - inst->st.time, k1[NX > 0 ? NX : 1], k2[NX > 0 ? NX : 1];
        double k3[NX > 0 ? NX : 1], k4[NX > 0 ? NX : 1], x0[NX > 0 ? NX : 1], t0;
        int i;
        if (step > H_INT) step = H_INT;
        if (NX == 0) {
            inst->st.time += step;
            continue;
        }
        t0 = inst->st.time;
        memcpy(x0, inst->st.x, sizeof x0);
        model_derivatives(inst, k1);
        for (i = 0; i < NX; i++) inst->st.x[i] = x0[i] + 0.5 * step * k1[i];
        inst->st.time = t0 + 0.5 * step;
        model_derivatives(inst, k2);
        for (i = 0; i < NX; i++) inst->st.x[i] = x0[i] + 0.5 * step * k2[i];
        model_derivatives(inst, k3);
        for (i = 0; i < NX; i++) inst->st.x[i] = x0[i] + step * k3[i];
        inst->st.time = t0 + step;
        model_derivatives(inst, k4);
        for (i = 0; i < NX; i++)
            inst->st.x[i] = x0[i] + step / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
    inst->st.time = t_end;
    model_outputs(inst);
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    (void)c;
    return fmi2Error;
}

/* ---- not provided ------------------------------------------------------------------- */

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    (void)c; (void)s; (void)size;
    return fmi2Error;
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)c; (void)s; (void)b; (void)n;
    return fmi2Error;
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n,
                                   fmi2FMUstate *s) {
    (void)c; (void)b; (void)n; (void)s;
    return fmi2Error;
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
                                        size_t nu, const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real dv[], fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return fmi2Error;
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value;
    return fmi2Error;
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value;
    return fmi2Error;
}
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
