/* Feedthrough: every FMI 3.0 type fed from an input to an output, and a Float64 output
 * that adds a fixed and a tunable parameter. No states. */
#define TOKEN "{bgm-test-feedthrough}"
#define NX 0
#define H_INT 1.0
#define NVARS 34
#define MODEL_STATE int

#include "glue3.h"

static const Var VARS[NVARS] = {
    {0, T_F64, 1},
    {1, T_F32, 1}, {2, T_F32, 1},      /* Float32 continuous in -> out */
    {3, T_F64, 1}, {4, T_F64, 1},      /* Float64 continuous */
    {5, T_F64, 1}, {6, T_F64, 1},      /* Float64 discrete */
    {7, T_I8, 1}, {8, T_I8, 1},
    {9, T_U8, 1}, {10, T_U8, 1},
    {11, T_I16, 1}, {12, T_I16, 1},
    {13, T_U16, 1}, {14, T_U16, 1},
    {15, T_I32, 1}, {16, T_I32, 1},
    {17, T_U32, 1}, {18, T_U32, 1},
    {19, T_I64, 1}, {20, T_I64, 1},
    {21, T_U64, 1}, {22, T_U64, 1},
    {23, T_BOOL, 1}, {24, T_BOOL, 1},
    {25, T_STR, 1}, {26, T_STR, 1},
    {27, T_BIN, 1}, {28, T_BIN, 1},
    {29, T_I64, 1}, {30, T_I64, 1},    /* Enumeration in -> out */
    {31, T_F64, 1}, {32, T_F64, 1}, {33, T_F64, 1}   /* fixed, tunable, their sum */
};

#include "glue3.c"

static void model_start(Inst *inst) {
    STR(25)[0] = strdup("Set me!");
    STR(26)[0] = strdup("Set me!");
    I64(29)[0] = 1;
    ((void **)inst->s.data[27])[0] = memcpy(malloc(3), "foo", 3);
    inst->s.bin_size[27] = 3;
    I64(30)[0] = 1;
    F64(31)[0] = 1.0;
    F64(32)[0] = 2.0;
}

static int model_setup(Inst *inst) {
    (void)inst;
    return 0;
}

static void model_outputs(Inst *inst) {
    int i;
    for (i = 1; i <= 29; i += 2) {
        if (VARS[i].type == T_STR) {
            free(STR(i + 1)[0]);
            STR(i + 1)[0] = strdup(STR(i)[0] ? STR(i)[0] : "");
        } else if (VARS[i].type == T_BIN) {
            void *src = ((void **)inst->s.data[i])[0];
            free(((void **)inst->s.data[i + 1])[0]);
            ((void **)inst->s.data[i + 1])[0] = NULL;
            inst->s.bin_size[i + 1] = inst->s.bin_size[i];
            if (src) {
                void *copy = malloc(inst->s.bin_size[i] ? inst->s.bin_size[i] : 1);
                memcpy(copy, src, inst->s.bin_size[i]);
                ((void **)inst->s.data[i + 1])[0] = copy;
            }
        } else {
            memcpy(inst->s.data[i + 1], inst->s.data[i], TYPE_SIZE[VARS[i].type]);
        }
    }
    F64(33)[0] = F64(31)[0] + F64(32)[0];
}

static void model_derivatives(Inst *inst, double *dx) {
    (void)inst; (void)dx;
}

static void model_event(Inst *inst) {
    (void)inst;
}
