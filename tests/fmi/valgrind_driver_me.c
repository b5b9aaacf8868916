/*
 * Test driver for tests/fmi/test_hybrid_fmus.py: dlopens a Model Exchange FMU with events
 * (the bouncing ball) and runs the FMI event loop of the standard (forward Euler, event
 * indicators, time events, event iteration, state changes at events), FMU state get/set and
 * error paths, several times.
 * Build: cc -g -DFMI_VERSION=2|3 -I<fmu sources> valgrind_driver_me.c -ldl -lm -o driver
 * Usage: driver <library.so> <token> <vr_param> <vr_state> <vr_boolean>
 *   (vr_boolean "-": the model has no Boolean to read)
 *   sets the parameter to 1.5, simulates 2.5 s, prints the number of events and the final
 *   state; exits 0 when everything behaved.
 */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#if FMI_VERSION == 2
#include "fmi2Functions.h"
#else
#include "fmi3Functions.h"
#endif

#define NX_MAX 16
#define NZ_MAX 16

static int n_errors_logged = 0;
static int use_boolean = 1;

#define LOAD(name)                                                             \
    name##TYPE *name = (name##TYPE *)dlsym(lib, #name);                        \
    if (!name) {                                                               \
        fprintf(stderr, "missing symbol %s\n", #name);                         \
        return 2;                                                              \
    }
#define CHECK(cond)                                                            \
    do {                                                                       \
        if (!(cond)) {                                                         \
            fprintf(stderr, "check failed line %d: %s\n", __LINE__, #cond);    \
            return 3;                                                          \
        }                                                                      \
    } while (0)

#if FMI_VERSION == 2
static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    (void)name;
    (void)category;
    if (status >= fmi2Error) n_errors_logged++;
    va_start(ap, message);
    vfprintf(stdout, message, ap);
    va_end(ap);
    fputc('\n', stdout);
}

static int run(void *lib, const char *token, unsigned vr_param, unsigned vr_state,
               unsigned vr_bool, int *n_events, double *final) {
    LOAD(fmi2Instantiate)
    LOAD(fmi2FreeInstance)
    LOAD(fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode)
    LOAD(fmi2SetReal)
    LOAD(fmi2GetReal)
    LOAD(fmi2GetBoolean)
    LOAD(fmi2SetBoolean)
    LOAD(fmi2GetInteger)
    LOAD(fmi2Terminate)
    LOAD(fmi2Reset)
    LOAD(fmi2GetFMUstate)
    LOAD(fmi2SetFMUstate)
    LOAD(fmi2FreeFMUstate)
    LOAD(fmi2SetTime)
    LOAD(fmi2SetContinuousStates)
    LOAD(fmi2GetContinuousStates)
    LOAD(fmi2GetDerivatives)
    LOAD(fmi2GetEventIndicators)
    LOAD(fmi2EnterEventMode)
    LOAD(fmi2NewDiscreteStates)
    LOAD(fmi2EnterContinuousTimeMode)
    LOAD(fmi2CompletedIntegratorStep)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c;
    fmi2EventInfo info;
    fmi2Real value = 1.5, x[NX_MAX], dx[NX_MAX], z[NZ_MAX], zpre[NZ_MAX], t = 0.0, h = 1e-3;
    fmi2Boolean flying = fmi2False, enter, term;
    fmi2Integer bad;
    fmi2FMUstate state = NULL;
    const size_t nx = 2, nz = 1;
    size_t i;
    int k;

    c = fmi2Instantiate("drv", fmi2ModelExchange, token, "", &cb, 0, 0);
    CHECK(c != NULL);
    CHECK(fmi2SetReal(c, &vr_param, 1, &value) == fmi2OK);
    if (use_boolean) {
        CHECK(fmi2SetBoolean(c, &vr_bool, 1, &flying) == fmi2OK);  /* start value, set back */
        flying = fmi2True;
        CHECK(fmi2SetBoolean(c, &vr_bool, 1, &flying) == fmi2OK);
        CHECK(fmi2GetInteger(c, &vr_bool, 1, &bad) == fmi2Error);  /* wrong type */
    }
    CHECK(fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 2.5) == fmi2OK);
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK);
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK);
    if (use_boolean) CHECK(fmi2SetBoolean(c, &vr_bool, 1, &flying) == fmi2Error);  /* not after init */
    info.newDiscreteStatesNeeded = fmi2True;
    while (info.newDiscreteStatesNeeded) CHECK(fmi2NewDiscreteStates(c, &info) == fmi2OK);
    CHECK(fmi2EnterContinuousTimeMode(c) == fmi2OK);
    CHECK(fmi2GetContinuousStates(c, x, nx) == fmi2OK);
    CHECK(fmi2GetEventIndicators(c, zpre, nz) == fmi2OK);
    CHECK(fmi2GetEventIndicators(c, zpre, nz + 1) == fmi2Error);
    for (k = 0; t < 2.5; k++) {
        int event = 0;
        CHECK(fmi2GetDerivatives(c, dx, nx) == fmi2OK);
        t += h;
        for (i = 0; i < nx; i++) x[i] += h * dx[i];
        CHECK(fmi2SetTime(c, t) == fmi2OK);
        CHECK(fmi2SetContinuousStates(c, x, nx) == fmi2OK);
        CHECK(fmi2GetEventIndicators(c, z, nz) == fmi2OK);
        for (i = 0; i < nz; i++) event |= (zpre[i] > 0) != (z[i] > 0);
        if (info.nextEventTimeDefined && t >= info.nextEventTime) event = 1;
        CHECK(fmi2CompletedIntegratorStep(c, fmi2True, &enter, &term) == fmi2OK);
        if (event) {
            (*n_events)++;
            CHECK(fmi2EnterEventMode(c) == fmi2OK);
            info.newDiscreteStatesNeeded = fmi2True;
            while (info.newDiscreteStatesNeeded) CHECK(fmi2NewDiscreteStates(c, &info) == fmi2OK);
            CHECK(fmi2EnterContinuousTimeMode(c) == fmi2OK);
            CHECK(fmi2GetContinuousStates(c, x, nx) == fmi2OK);
            CHECK(fmi2GetEventIndicators(c, z, nz) == fmi2OK);
        }
        for (i = 0; i < nz; i++) zpre[i] = z[i];
        if (k == 500) CHECK(fmi2GetFMUstate(c, &state) == fmi2OK);
    }
    CHECK(fmi2GetReal(c, &vr_state, 1, final) == fmi2OK);
    if (use_boolean) CHECK(fmi2GetBoolean(c, &vr_bool, 1, &flying) == fmi2OK);
    CHECK(fmi2SetFMUstate(c, state) == fmi2OK);
    CHECK(fmi2FreeFMUstate(c, &state) == fmi2OK);
    CHECK(fmi2Terminate(c) == fmi2OK);
    CHECK(fmi2Reset(c) == fmi2OK);
    fmi2FreeInstance(c);
    return isfinite(*final) ? 0 : 4;
}
#else
static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                   fmi3String message) {
    (void)env;
    (void)category;
    if (status >= fmi3Error) n_errors_logged++;
    printf("%s\n", message);
}

static int run(void *lib, const char *token, unsigned vr_param, unsigned vr_state,
               unsigned vr_bool, int *n_events, double *final) {
    LOAD(fmi3InstantiateModelExchange)
    LOAD(fmi3FreeInstance)
    LOAD(fmi3EnterInitializationMode)
    LOAD(fmi3ExitInitializationMode)
    LOAD(fmi3SetFloat64)
    LOAD(fmi3GetFloat64)
    LOAD(fmi3GetBoolean)
    LOAD(fmi3SetBoolean)
    LOAD(fmi3GetInt32)
    LOAD(fmi3Terminate)
    LOAD(fmi3Reset)
    LOAD(fmi3GetFMUState)
    LOAD(fmi3SetFMUState)
    LOAD(fmi3FreeFMUState)
    LOAD(fmi3SetTime)
    LOAD(fmi3SetContinuousStates)
    LOAD(fmi3GetContinuousStates)
    LOAD(fmi3GetContinuousStateDerivatives)
    LOAD(fmi3GetEventIndicators)
    LOAD(fmi3GetNumberOfEventIndicators)
    LOAD(fmi3EnterEventMode)
    LOAD(fmi3UpdateDiscreteStates)
    LOAD(fmi3EnterContinuousTimeMode)
    LOAD(fmi3CompletedIntegratorStep)
    fmi3Instance c;
    fmi3Float64 value = 1.5, x[NX_MAX], dx[NX_MAX], z[NZ_MAX], zpre[NZ_MAX], t = 0.0, h = 1e-3;
    fmi3Float64 next = 0.0;
    fmi3Boolean flying = fmi3False, need = fmi3True, term, nom, changed, defined = fmi3False;
    fmi3Boolean enter;
    fmi3Int32 bad;
    fmi3FMUState state = NULL;
    size_t nx = 2, nz = 0, i;
    int k;

    c = fmi3InstantiateModelExchange("drv", token, "", 0, 0, NULL, logger);
    CHECK(c != NULL);
    CHECK(fmi3SetFloat64(c, &vr_param, 1, &value, 1) == fmi3OK);
    if (use_boolean) {
        CHECK(fmi3SetBoolean(c, &vr_bool, 1, &flying, 1) == fmi3OK);
        flying = fmi3True;
        CHECK(fmi3SetBoolean(c, &vr_bool, 1, &flying, 1) == fmi3OK);
        CHECK(fmi3GetInt32(c, &vr_bool, 1, &bad, 1) == fmi3Error);
    }
    CHECK(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 1, 2.5) == fmi3OK);
    CHECK(fmi3ExitInitializationMode(c) == fmi3OK);
    if (use_boolean) CHECK(fmi3SetBoolean(c, &vr_bool, 1, &flying, 1) == fmi3Error);
    while (need)
        CHECK(fmi3UpdateDiscreteStates(c, &need, &term, &nom, &changed, &defined, &next) ==
              fmi3OK);
    CHECK(fmi3EnterContinuousTimeMode(c) == fmi3OK);
    CHECK(fmi3GetNumberOfEventIndicators(c, &nz) == fmi3OK);
    CHECK(nz == 1);
    CHECK(fmi3GetContinuousStates(c, x, nx) == fmi3OK);
    CHECK(fmi3GetEventIndicators(c, zpre, nz) == fmi3OK);
    CHECK(fmi3GetEventIndicators(c, zpre, nz + 1) == fmi3Error);
    for (k = 0; t < 2.5; k++) {
        int event = 0;
        CHECK(fmi3GetContinuousStateDerivatives(c, dx, nx) == fmi3OK);
        t += h;
        for (i = 0; i < nx; i++) x[i] += h * dx[i];
        CHECK(fmi3SetTime(c, t) == fmi3OK);
        CHECK(fmi3SetContinuousStates(c, x, nx) == fmi3OK);
        CHECK(fmi3GetEventIndicators(c, z, nz) == fmi3OK);
        for (i = 0; i < nz; i++) event |= (zpre[i] > 0) != (z[i] > 0);
        if (defined && t >= next) event = 1;
        CHECK(fmi3CompletedIntegratorStep(c, fmi3True, &enter, &term) == fmi3OK);
        if (event) {
            (*n_events)++;
            CHECK(fmi3EnterEventMode(c) == fmi3OK);
            need = fmi3True;
            while (need)
                CHECK(fmi3UpdateDiscreteStates(c, &need, &term, &nom, &changed, &defined,
                                               &next) == fmi3OK);
            CHECK(fmi3EnterContinuousTimeMode(c) == fmi3OK);
            CHECK(fmi3GetContinuousStates(c, x, nx) == fmi3OK);
            CHECK(fmi3GetEventIndicators(c, z, nz) == fmi3OK);
        }
        for (i = 0; i < nz; i++) zpre[i] = z[i];
        if (k == 500) CHECK(fmi3GetFMUState(c, &state) == fmi3OK);
    }
    CHECK(fmi3GetFloat64(c, &vr_state, 1, final, 1) == fmi3OK);
    if (use_boolean) CHECK(fmi3GetBoolean(c, &vr_bool, 1, &flying, 1) == fmi3OK);
    CHECK(fmi3SetFMUState(c, state) == fmi3OK);
    CHECK(fmi3FreeFMUState(c, &state) == fmi3OK);
    CHECK(fmi3Terminate(c) == fmi3OK);
    CHECK(fmi3Reset(c) == fmi3OK);
    fmi3FreeInstance(c);
    return isfinite(*final) ? 0 : 4;
}
#endif

int main(int argc, char **argv) {
    void *lib;
    int round, rc = 0, n_events = 0;
    double final = NAN;
    if (argc != 6) {
        fprintf(stderr, "usage: %s lib.so token vr_param vr_state vr_boolean\n", argv[0]);
        return 2;
    }
    use_boolean = argv[5][0] != '-';
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    for (round = 0; round < 2 && rc == 0; round++) {
        n_events = 0;
        rc = run(lib, argv[2], (unsigned)atoi(argv[3]), (unsigned)atoi(argv[4]),
                 (unsigned)atoi(argv[5]), &n_events, &final);
    }
    dlclose(lib);
    if (rc == 0 && n_errors_logged < 2 * (use_boolean ? 3 : 1)) {
        fprintf(stderr, "expected logged errors, got %d\n", n_errors_logged);
        rc = 5;
    }
    printf("driver done rc=%d events=%d final=%.9g errors_logged=%d\n", rc, n_events, final,
           n_errors_logged);
    return rc;
}
