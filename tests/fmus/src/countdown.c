/* Countdown: an Int32 counter starts at `start` and goes down by one at t = 1, 2, ... s;
 * when it reaches 0 the FMU asks to terminate the simulation. A state x, der(x) = 1, keeps
 * time within the FMU. The counter is also a String output "left <n>" and a Binary output
 * of two bytes: n, then 0xA5. */
#define TOKEN "{bgm-test-countdown}"
#define NX 1
#define H_INT 1e-2
#define NVARS 7
#define MODEL_STATE int

#include "glue3.h"

static const Var VARS[NVARS] = {{0, T_F64, 1}, {1, T_I32, 1}, {2, T_I32, 1}, {3, T_F64, 1},
                                 {4, T_F64, 1}, {5, T_STR, 1}, {6, T_BIN, 1}};

#include "glue3.c"

static void model_start(Inst *inst) {
    I32(1)[0] = 3;      /* start (parameter) */
}

static int model_setup(Inst *inst) {
    I32(2)[0] = I32(1)[0];
    inst->s.x[0] = 0.0;
    inst->s.next_defined = 1;
    inst->s.next_time = inst->s.time + 1.0;
    return 0;
}

static void model_outputs(Inst *inst) {
    char label[32];
    unsigned char *code = malloc(2);
    F64(3)[0] = inst->s.x[0];
    F64(4)[0] = 1.0;
    snprintf(label, sizeof label, "left %d", (int)I32(2)[0]);
    free(STR(5)[0]);
    STR(5)[0] = strdup(label);
    code[0] = (unsigned char)I32(2)[0];
    code[1] = 0xA5;
    free(((void **)inst->s.data[6])[0]);
    ((void **)inst->s.data[6])[0] = code;
    inst->s.bin_size[6] = 2;
}

static void model_derivatives(Inst *inst, double *dx) {
    (void)inst;
    dx[0] = 1.0;
}

static void model_event(Inst *inst) {
    I32(2)[0] -= 1;
    inst->s.next_time += 1.0;
    if (I32(2)[0] <= 0) {
        inst->terminate = 1;
        inst->s.next_defined = 0;
    }
}
