/*
 * Test driver for tests/fmi/test_valgrind.py: dlopens a Co-Simulation FMU binary and runs
 * instantiate / initialize / steps / FMU state / error paths / free several times.
 * Build: cc -g -DFMI_VERSION=2|3 -I<fmu sources> valgrind_driver.c -ldl -o driver
 * Usage: driver <library.so> <token> <vr_param> <vr_output> [<communication step, 0.01>]
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

static int n_errors_logged = 0;
static double dt = 0.01; /* communication step */
static long vr_input = -1;  /* an input to change before every step (-1: none) */

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

static int run(void *lib, const char *token, unsigned vr_param, unsigned vr_out) {
    LOAD(fmi2Instantiate)
    LOAD(fmi2FreeInstance)
    LOAD(fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode)
    LOAD(fmi2SetReal)
    LOAD(fmi2GetReal)
    LOAD(fmi2DoStep)
    LOAD(fmi2Terminate)
    LOAD(fmi2Reset)
    LOAD(fmi2GetFMUstate)
    LOAD(fmi2SetFMUstate)
    LOAD(fmi2FreeFMUstate)
    LOAD(fmi2SerializedFMUstateSize)
    LOAD(fmi2SerializeFMUstate)
    LOAD(fmi2DeSerializeFMUstate)
    LOAD(fmi2GetDirectionalDerivative)
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c;
    fmi2Real value, nan = NAN, y, dd, seed = 1.0;
    fmi2FMUstate state = NULL, copy = NULL;
    size_t size = 0;
    char *blob;
    int k;

    CHECK(fmi2Instantiate("bad", fmi2CoSimulation, "{wrong}", "", &cb, 0, 0) == NULL);
    c = fmi2Instantiate("drv", fmi2CoSimulation, token, "", &cb, 0, 0);
    CHECK(c != NULL);
    CHECK(fmi2DoStep(c, 0.0, 0.1, 1) == fmi2Error);
    CHECK(fmi2SetReal(c, &vr_param, 1, &nan) == fmi2Error);
    value = 1.5;
    CHECK(fmi2SetReal(c, &vr_param, 1, &value) == fmi2OK);
    CHECK(fmi2SetupExperiment(c, 1, 1e-6, 0.0, 0, 0.0) == fmi2OK);
    CHECK(fmi2EnterInitializationMode(c) == fmi2OK);
    CHECK(fmi2ExitInitializationMode(c) == fmi2OK);
    for (k = 0; k < 20; k++) CHECK(fmi2DoStep(c, dt * k, dt, 1) == fmi2OK);
    CHECK(fmi2GetFMUstate(c, &state) == fmi2OK);
    CHECK(fmi2SerializedFMUstateSize(c, state, &size) == fmi2OK);
    blob = (char *)malloc(size);
    CHECK(fmi2SerializeFMUstate(c, state, blob, size) == fmi2OK);
    CHECK(fmi2DeSerializeFMUstate(c, blob, size, &copy) == fmi2OK);
    free(blob);
    for (k = 20; k < 30; k++) {
        if (vr_input >= 0) { /* new inputs at every step: the solver's one-step path */
            fmi2ValueReference vr_in = (fmi2ValueReference)vr_input;
            value = 10.0 + k;
            CHECK(fmi2SetReal(c, &vr_in, 1, &value) == fmi2OK);
        }
        CHECK(fmi2DoStep(c, dt * k, dt, 1) == fmi2OK);
    }
    CHECK(fmi2GetReal(c, &vr_out, 1, &y) == fmi2OK);
    CHECK(fmi2SetFMUstate(c, copy) == fmi2OK);
    CHECK(fmi2GetDirectionalDerivative(c, &vr_out, 1, &vr_param, 1, &seed, &dd) == fmi2OK);
    CHECK(fmi2FreeFMUstate(c, &state) == fmi2OK);
    CHECK(fmi2FreeFMUstate(c, &copy) == fmi2OK);
    CHECK(fmi2Terminate(c) == fmi2OK);
    CHECK(fmi2Reset(c) == fmi2OK);
    fmi2FreeInstance(c);
    return isfinite(y) && isfinite(dd) ? 0 : 4;
}
#else
static void logger(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category,
                   fmi3String message) {
    (void)env;
    (void)category;
    if (status >= fmi3Error) n_errors_logged++;
    printf("%s\n", message);
}

static int run(void *lib, const char *token, unsigned vr_param, unsigned vr_out) {
    LOAD(fmi3InstantiateCoSimulation)
    LOAD(fmi3FreeInstance)
    LOAD(fmi3EnterInitializationMode)
    LOAD(fmi3ExitInitializationMode)
    LOAD(fmi3SetFloat64)
    LOAD(fmi3GetFloat64)
    LOAD(fmi3DoStep)
    LOAD(fmi3Terminate)
    LOAD(fmi3Reset)
    LOAD(fmi3GetFMUState)
    LOAD(fmi3SetFMUState)
    LOAD(fmi3FreeFMUState)
    LOAD(fmi3SerializedFMUStateSize)
    LOAD(fmi3SerializeFMUState)
    LOAD(fmi3DeserializeFMUState)
    LOAD(fmi3GetDirectionalDerivative)
    fmi3Instance c;
    fmi3Float64 value, nan = NAN, y, dd, seed = 1.0, last;
    fmi3Boolean ev, term, early;
    fmi3FMUState state = NULL, copy = NULL;
    size_t size = 0;
    fmi3Byte *blob;
    int k;

    CHECK(fmi3InstantiateCoSimulation("bad", "{wrong}", "", 0, 0, 0, 0, NULL, 0, NULL, logger,
                                      NULL) == NULL);
    c = fmi3InstantiateCoSimulation("drv", token, "", 0, 0, 0, 0, NULL, 0, NULL, logger, NULL);
    CHECK(c != NULL);
    CHECK(fmi3DoStep(c, 0.0, 0.1, 1, &ev, &term, &early, &last) == fmi3Error);
    CHECK(fmi3SetFloat64(c, &vr_param, 1, &nan, 1) == fmi3Error);
    value = 1.5;
    CHECK(fmi3SetFloat64(c, &vr_param, 1, &value, 1) == fmi3OK);
    CHECK(fmi3EnterInitializationMode(c, 1, 1e-6, 0.0, 0, 0.0) == fmi3OK);
    CHECK(fmi3ExitInitializationMode(c) == fmi3OK);
    for (k = 0; k < 20; k++)
        CHECK(fmi3DoStep(c, dt * k, dt, 1, &ev, &term, &early, &last) == fmi3OK);
    CHECK(fmi3GetFMUState(c, &state) == fmi3OK);
    CHECK(fmi3SerializedFMUStateSize(c, state, &size) == fmi3OK);
    blob = (fmi3Byte *)malloc(size);
    CHECK(fmi3SerializeFMUState(c, state, blob, size) == fmi3OK);
    CHECK(fmi3DeserializeFMUState(c, blob, size, &copy) == fmi3OK);
    free(blob);
    for (k = 20; k < 30; k++) {
        if (vr_input >= 0) { /* new inputs at every step: the solver's one-step path */
            fmi3ValueReference vr_in = (fmi3ValueReference)vr_input;
            value = 10.0 + k;
            CHECK(fmi3SetFloat64(c, &vr_in, 1, &value, 1) == fmi3OK);
        }
        CHECK(fmi3DoStep(c, dt * k, dt, 1, &ev, &term, &early, &last) == fmi3OK);
    }
    CHECK(fmi3GetFloat64(c, &vr_out, 1, &y, 1) == fmi3OK);
    CHECK(fmi3SetFMUState(c, copy) == fmi3OK);
    CHECK(fmi3GetDirectionalDerivative(c, &vr_out, 1, &vr_param, 1, &seed, 1, &dd, 1) ==
          fmi3OK);
    CHECK(fmi3FreeFMUState(c, &state) == fmi3OK);
    CHECK(fmi3FreeFMUState(c, &copy) == fmi3OK);
    CHECK(fmi3Terminate(c) == fmi3OK);
    CHECK(fmi3Reset(c) == fmi3OK);
    fmi3FreeInstance(c);
    return isfinite(y) && isfinite(dd) ? 0 : 4;
}
#endif

int main(int argc, char **argv) {
    void *lib;
    int round, rc = 0;
    const char *input = getenv("BGM_DRIVER_INPUT_VR"); /* an input set before every step */
    if (input) vr_input = atol(input);
    if (argc != 5 && argc != 6) {
        fprintf(stderr, "usage: %s lib.so token vr_param vr_output [step]\n", argv[0]);
        return 2;
    }
    if (argc == 6) dt = atof(argv[5]);
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 2;
    }
    for (round = 0; round < 3 && rc == 0; round++)
        rc = run(lib, argv[2], (unsigned)atoi(argv[3]), (unsigned)atoi(argv[4]));
    dlclose(lib);
    if (rc == 0 && n_errors_logged < 3 * 3) {
        fprintf(stderr, "expected logged errors, got %d\n", n_errors_logged);
        rc = 5;
    }
    printf("driver done rc=%d errors_logged=%d\n", rc, n_errors_logged);
    return rc;
}
