/* Feedthrough (FMI 2.0): Real (continuous and discrete), Integer, Boolean, String and
 * Enumeration inputs fed to outputs, a Real output adding a fixed and a tunable parameter,
 * and a String output writing the Integer input in decimal. No states. */
#define TOKEN "{bgm-test-feedthrough2}"
#define NX 0
#define H_INT 1.0
#define NVARS 17

#include "glue2.c"

static const Var VARS[NVARS] = {
    {T_REAL}, {T_REAL}, {T_REAL}, {T_REAL}, {T_REAL}, {T_INT}, {T_INT}, {T_BOOL}, {T_BOOL},
    {T_STR}, {T_STR}, {T_INT}, {T_INT}, {T_REAL}, {T_REAL}, {T_REAL}, {T_STR}};

static void model_start(Inst *inst) {
    inst->st.s[9] = strdup("Set me!");
    inst->st.s[10] = strdup("Set me!");
    inst->st.i[11] = 1;
    inst->st.i[12] = 1;
    inst->st.r[13] = 1.0;
    inst->st.r[14] = 2.0;
}

static int model_setup(Inst *inst) {
    (void)inst;
    return 0;
}

static void model_outputs(Inst *inst) {
    inst->st.r[2] = inst->st.r[1];
    inst->st.r[4] = inst->st.r[3];
    inst->st.i[6] = inst->st.i[5];
    inst->st.i[8] = inst->st.i[7];
    free(inst->st.s[10]);
    inst->st.s[10] = strdup(inst->st.s[9] ? inst->st.s[9] : "");
    inst->st.i[12] = inst->st.i[11];
    inst->st.r[15] = inst->st.r[13] + inst->st.r[14];
    {
        char text[16];
        snprintf(text, sizeof text, "%d", inst->st.i[5]);
        free(inst->st.s[16]);
        inst->st.s[16] = strdup(text);
    }
}

static void model_derivatives(Inst *inst, double *dx) {
    (void)inst; (void)dx;
}
