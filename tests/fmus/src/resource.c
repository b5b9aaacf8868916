/* Resource: at initialization reads resources/y.txt; output y = the code of its first
 * character. A missing file is an error naming it. */
#define TOKEN "{bgm-test-resource}"
#define NX 0
#define H_INT 1.0
#define NVARS 2
#define MODEL_STATE int

#include "glue3.h"

static const Var VARS[NVARS] = {{0, T_F64, 1}, {1, T_I32, 1}};

#include "glue3.c"

static void model_start(Inst *inst) {
    (void)inst;
}

static int model_setup(Inst *inst) {
    char path[1200];
    FILE *f;
    int c;
    snprintf(path, sizeof path, "%s%sy.txt", inst->resource,
             (inst->resource[0] && inst->resource[strlen(inst->resource) - 1] != '/') ? "/" : "");
    f = fopen(path, "rb");
    if (!f) {
        logf3(inst, fmi3Error, "cannot open the resource file %s", path);
        return 1;
    }
    c = fgetc(f);
    fclose(f);
    I32(1)[0] = c == EOF ? 0 : c;
    return 0;
}

static void model_outputs(Inst *inst) {
    (void)inst;
}

static void model_derivatives(Inst *inst, double *dx) {
    (void)inst; (void)dx;
}

static void model_event(Inst *inst) {
    (void)inst;
}
