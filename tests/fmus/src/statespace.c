/* StateSpace: der(x) = A x + B u, y = C x + D u with array variables (n = m = r = 3),
 * x(0) = x0. */
#define TOKEN "{bgm-test-statespace}"
#define NX 3
#define H_INT 1e-3
#define NVARS 13
#define MODEL_STATE int

#include "glue3.h"

enum { M = 1, N = 2, R = 3, A_ = 4, B_ = 5, C_ = 6, D_ = 7, X0 = 8, U = 9, Y = 10, X = 11,
       DX = 12 };

static const Var VARS[NVARS] = {
    {0, T_F64, 1}, {M, T_U64, 1}, {N, T_U64, 1}, {R, T_U64, 1},
    {A_, T_F64, 9}, {B_, T_F64, 9}, {C_, T_F64, 9}, {D_, T_F64, 9}, {X0, T_F64, 3},
    {U, T_F64, 3}, {Y, T_F64, 3}, {X, T_F64, 3}, {DX, T_F64, 3}};

#include "glue3.c"

/* the variable table is indexed like the value references */
#define V(vr) ((double *)inst->s.data[vr])

static const double A0[9] = {0, 1, 0, -2, -0.5, 0, 0, 0, -3};
static const double B0[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
static const double C0[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
static const double D0[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
static const double XS[3] = {1, 0, 0.5};

static void model_start(Inst *inst) {
    ((uint64_t *)inst->s.data[M])[0] = 3;
    ((uint64_t *)inst->s.data[N])[0] = 3;
    ((uint64_t *)inst->s.data[R])[0] = 3;
    memcpy(V(A_), A0, sizeof A0);
    memcpy(V(B_), B0, sizeof B0);
    memcpy(V(C_), C0, sizeof C0);
    memcpy(V(D_), D0, sizeof D0);
    memcpy(V(X0), XS, sizeof XS);
}

static int model_setup(Inst *inst) {
    memcpy(inst->s.x, V(X0), 3 * sizeof(double));
    return 0;
}

static void model_derivatives(Inst *inst, double *dx) {
    int i, j;
    for (i = 0; i < 3; i++) {
        dx[i] = 0;
        for (j = 0; j < 3; j++) dx[i] += V(A_)[3 * i + j] * inst->s.x[j] + V(B_)[3 * i + j] * V(U)[j];
    }
}

static void model_outputs(Inst *inst) {
    int i, j;
    memcpy(V(X), inst->s.x, 3 * sizeof(double));
    model_derivatives(inst, V(DX));
    for (i = 0; i < 3; i++) {
        V(Y)[i] = 0;
        for (j = 0; j < 3; j++) V(Y)[i] += V(C_)[3 * i + j] * inst->s.x[j] + V(D_)[3 * i + j] * V(U)[j];
    }
}

static void model_event(Inst *inst) {
    (void)inst;
}
