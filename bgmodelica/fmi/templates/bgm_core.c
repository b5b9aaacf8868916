/*
 * bgmodelica FMU runtime: instance management, variable access, model evaluation,
 * directional derivatives and FMU-state handling.  See bgm_core.h.
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bgm_core.h"

#define BGM_INST_MAGIC 0x42474d49u  /* "BGMI" */
#define BGM_STATE_MAGIC 0x42474d53u /* "BGMS" */

/* ------------------------------------------------------------------ CasADi functions */

typedef int (*bgm_cfun)(const casadi_real **arg, casadi_real **res, casadi_int *iw,
                        casadi_real *w, int mem);
typedef struct {
    bgm_cfun eval;
    int (*work)(casadi_int *, casadi_int *, casadi_int *, casadi_int *);
    int (*checkout)(void);
    void (*release)(int);
    void (*incref)(void);
    void (*decref)(void);
} bgm_function;

#define BGM_CAT_(a, b) a##b
#define BGM_CAT(a, b) BGM_CAT_(a, b)
#define BGM_FUNCTION(F)                                                            \
    {                                                                              \
        F, BGM_CAT(F, _work), BGM_CAT(F, _checkout), BGM_CAT(F, _release),         \
            BGM_CAT(F, _incref), BGM_CAT(F, _decref)                               \
    }

enum { F_ODE = 0, F_FWD, F_JACX, F_XDOT, F_INIT, F_INITFWD };

static const bgm_function bgm_functions[] = {
    BGM_FUNCTION(BGM_CASADI_ODE), BGM_FUNCTION(BGM_CASADI_FWD), BGM_FUNCTION(BGM_CASADI_JACX),
    BGM_FUNCTION(BGM_CASADI_XDOT),
#if BGM_HAS_INIT
    BGM_FUNCTION(BGM_CASADI_INIT), BGM_FUNCTION(BGM_CASADI_INITFWD),
#endif
#if BGM_HYBRID
    BGM_FUNCTION(BGM_CASADI_EVSTEP), BGM_FUNCTION(BGM_CASADI_EVIND),
    BGM_FUNCTION(BGM_CASADI_EVSAMP),
#endif
};
#define BGM_NFUN ((int)(sizeof(bgm_functions) / sizeof(bgm_functions[0])))

static int bgm_call(bgm_inst *c, int f, const double **args, int nargs, double **outs,
                    int nouts) {
    int i;
    for (i = 0; i < nargs; i++) c->arg[i] = args[i];
    for (i = 0; i < nouts; i++) c->res[i] = outs[i];
#if BGM_HYBRID
    c->arg[nargs] = c->v.h.d; /* the discrete slots are the last argument of every function */
#endif
    return bgm_functions[f].eval(c->arg, c->res, c->iw, c->w, c->mem[f]);
}

#if BGM_HYBRID
int bgm_call_event(bgm_inst *c, int which, double t, const double *x, double **outs, int nouts) {
    const double *args[4];
    args[0] = &t;
    args[1] = x;
    args[2] = c->v.u;
    args[3] = c->v.p;
    return bgm_call(c, 4 + 2 * BGM_HAS_INIT + which, args, 4, outs, nouts);
}
#endif

static int bgm_all_finite(const double *v, size_t n) {
    size_t i;
    for (i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* Call model function f at (t, x, u, p); 0 ok, 1 evaluation failed, 2 non-finite output. */
static int bgm_call_model(bgm_inst *c, int f, double t, const double *x, double **outs,
                          const size_t *sizes, int nouts) {
    const double *args[4];
    int i;
    args[0] = &t;
    args[1] = x;
    args[2] = c->v.u;
    args[3] = c->v.p;
    if (bgm_call(c, f, args, 4, outs, nouts)) return 1;
    for (i = 0; i < nouts; i++)
        if (outs[i] && !bgm_all_finite(outs[i], sizes[i])) return 2;
    return 0;
}

int bgm_call_ode(bgm_inst *c, double t, const double *x, double *xdot, double *y) {
    double *outs[2] = {xdot, y};
    const size_t sizes[2] = {BGM_NX, BGM_NY};
    c->stat_f++;
    return bgm_call_model(c, F_ODE, t, x, outs, sizes, 2);
}

int bgm_call_xdot(bgm_inst *c, double t, const double *x, double *xdot) {
    double *outs[1] = {xdot};
    const size_t sizes[1] = {BGM_NX};
    c->stat_f++;
    return bgm_call_model(c, F_XDOT, t, x, outs, sizes, 1);
}

/* d(xdot)/dx as a dense column-major nx x nx matrix. The generated function writes the
   structural nonzeros (column-major order) to the front of jac; they are scattered in place
   from the last one down: nonzero k goes to a position >= k, so none is overwritten before it
   is read. CasADi's compressed pattern is {nrow, ncol, colind[ncol + 1], row[nnz]}, or
   {nrow, ncol, 1} for a dense one (colind[0] is 0 otherwise). */
int bgm_call_jacx(bgm_inst *c, double t, const double *x, double *jac) {
    const casadi_int *sp = BGM_CAT(BGM_CASADI_JACX, _sparsity_out)(0);
    const casadi_int nrow = sp[0], ncol = sp[1], *colind = sp + 2, *row = sp + 3 + ncol;
    const int dense = nrow * ncol > 0 && sp[2] == 1;
    double *outs[1] = {jac};
    size_t sizes[1];
    size_t next = (size_t)nrow * (size_t)ncol, pos, q;
    casadi_int j, k;
    int rc;
    sizes[0] = dense ? next : (size_t)colind[ncol];
    c->stat_jac++;
    rc = bgm_call_model(c, F_JACX, t, x, outs, sizes, 1);
    if (rc || dense) return rc;
    for (j = ncol - 1; j >= 0; j--) {
        for (k = colind[j + 1] - 1; k >= colind[j]; k--) {
            double v = jac[k];
            pos = (size_t)j * (size_t)nrow + (size_t)row[k];
            for (q = pos + 1; q < next; q++) jac[q] = 0.0;
            jac[pos] = v;
            next = pos;
        }
    }
    for (q = 0; q < next; q++) jac[q] = 0.0;
    return 0;
}

/* ------------------------------------------------------------------------- logging */

unsigned bgm_hash(const char *s) {
    unsigned h = 2166136261u; /* FNV-1a */
    while (s && *s) {
        h ^= (unsigned char)*s++;
        h *= 16777619u;
    }
    return h;
}

void bgm_log(bgm_inst *c, int status, const char *category, const char *fmt, ...) {
    char buf[1024];
    va_list ap;
    if (!c || !c->emit) return;
    if (status == BGM_OK) {
        unsigned bit = strcmp(category, "logSolver") == 0   ? BGM_LOG_SOLVER
                       : strcmp(category, "logEvents") == 0 ? BGM_LOG_EVENTS
                                                            : 0u;
        if (!c->logging_on || !(c->log_mask & bit)) return;
    }
    va_start(ap, fmt);
    vsnprintf(buf, sizeof(buf), fmt, ap);
    va_end(ap);
    c->emit(c, status, category, buf);
}

bgm_status bgm_set_debug_logging(bgm_inst *c, int on, size_t n, const char *const cats[]) {
    size_t i;
    unsigned mask = 0;
    if (n > 0 && !cats) {
        bgm_error(c, "SetDebugLogging: categories is NULL");
        return BGM_ERROR;
    }
    for (i = 0; i < n; i++) {
        const char *cat = cats[i];
        if (cat && strcmp(cat, "logStatusWarning") == 0) mask |= BGM_LOG_WARNING;
        else if (cat && strcmp(cat, "logStatusError") == 0) mask |= BGM_LOG_ERROR;
        else if (cat && strcmp(cat, "logSolver") == 0) mask |= BGM_LOG_SOLVER;
        else if (cat && strcmp(cat, "logEvents") == 0) mask |= BGM_LOG_EVENTS;
        else {
            bgm_error(c, "SetDebugLogging: unknown log category \"%s\"", cat ? cat : "(null)");
            return BGM_ERROR;
        }
    }
    c->logging_on = on ? 1 : 0;
    if (n == 0) c->log_mask = on ? BGM_LOG_ALL : 0u;
    else if (on) c->log_mask |= mask;
    else c->log_mask &= ~mask;
    return BGM_OK;
}

/* ------------------------------------------------------------------------ lifecycle */

const char *bgm_mode_name(int mode) {
    switch (mode) {
    case BGM_MODE_INSTANTIATED: return "Instantiated";
    case BGM_MODE_INIT: return "Initialization Mode";
    case BGM_MODE_EVENT: return "Event Mode";
    case BGM_MODE_CONT: return "Continuous-Time Mode";
    case BGM_MODE_STEP: return "Step Mode";
    case BGM_MODE_TERMINATED: return "Terminated";
    default: return "an unknown mode";
    }
}

int bgm_valid(const bgm_inst *c) { return c != NULL && c->magic == BGM_INST_MAGIC; }

int bgm_check(bgm_inst *c, const char *fn, int modes) {
    if (!bgm_valid(c)) return 0;
    if (!(c->v.mode & modes)) {
        bgm_error(c, "%s: not allowed in %s", fn, bgm_mode_name(c->v.mode));
        return 0;
    }
    return 1;
}

int bgm_check_kind(bgm_inst *c, const char *fn, int kind) {
    if (!bgm_valid(c)) return 0;
    if (c->v.kind != kind) {
        bgm_error(c, "%s: only available for %s instances", fn,
                  kind == BGM_KIND_ME ? "Model Exchange" : "Co-Simulation");
        return 0;
    }
    return 1;
}

static void bgm_defaults(bgm_inst *c) {
    int kind = c->v.kind;
    memset(&c->v, 0, sizeof(c->v));
    c->v.magic = BGM_STATE_MAGIC;
    c->v.size = (unsigned)sizeof(bgm_vars);
    c->v.token_hash = bgm_hash(BGM_TOKEN);
    c->v.kind = kind;
    c->v.mode = BGM_MODE_INSTANTIATED;
    c->v.time = BGM_DEFAULT_START_TIME;
    memcpy(c->v.x, bgm_x_start, sizeof(c->v.x));
    memcpy(c->v.u, bgm_u_start, sizeof(c->v.u));
    memcpy(c->v.p, bgm_p_start, sizeof(c->v.p));
    c->v.solver_tol = BGM_DEFAULT_TOLERANCE;
    c->v.solver_hmax = BGM_DEFAULT_MAX_STEP;
    c->v.h_next = 0.0;
    c->cache_valid = 0;
    c->start_time = BGM_DEFAULT_START_TIME;
    c->exp_tol_defined = 0;
    c->exp_tol = 0.0;
    c->stop_defined = 0;
    c->stop_time = 0.0;
#if BGM_HYBRID
    bgm_hyb_defaults(c);
#endif
}

bgm_inst *bgm_new(int fmi_version, int kind, const char *name, int logging_on,
                  bgm_emit_fn emit, bgm_any_fn logger_fn, void *logger_env) {
    bgm_inst *c = (bgm_inst *)calloc(1, sizeof(bgm_inst));
    casadi_int sz_arg = 0, sz_res = 0, sz_iw = 0, sz_w = 0;
    int f;
    if (!c) return NULL;
    c->magic = BGM_INST_MAGIC;
    c->fmi_version = fmi_version;
    c->v.kind = kind;
    c->emit = emit;
    c->logger_fn = logger_fn;
    c->logger_env = logger_env;
    c->logging_on = logging_on ? 1 : 0;
    c->log_mask = logging_on ? BGM_LOG_ALL : 0u;
    c->name = (char *)malloc(strlen(name) + 1);
    if (!c->name) {
        free(c);
        return NULL;
    }
    strcpy(c->name, name);
    for (f = 0; f < BGM_NFUN; f++) {
        casadi_int a = 0, r = 0, i = 0, w = 0;
        bgm_functions[f].incref();
        c->mem[f] = bgm_functions[f].checkout();
        bgm_functions[f].work(&a, &r, &i, &w);
        if (a > sz_arg) sz_arg = a;
        if (r > sz_res) sz_res = r;
        if (i > sz_iw) sz_iw = i;
        if (w > sz_w) sz_w = w;
    }
    if (sz_arg < 8) sz_arg = 8;
    if (sz_res < 4) sz_res = 4;
    c->arg = (const double **)calloc((size_t)sz_arg, sizeof(double *));
    c->res = (double **)calloc((size_t)sz_res, sizeof(double *));
    c->iw = (casadi_int *)calloc((size_t)(sz_iw > 0 ? sz_iw : 1), sizeof(casadi_int));
    c->w = (double *)calloc((size_t)(sz_w > 0 ? sz_w : 1), sizeof(double));
    c->ws = (double *)calloc(bgm_solver_workspace(), sizeof(double));
    c->piv = (int *)calloc(BGM_NXA, sizeof(int));
    if (!c->arg || !c->res || !c->iw || !c->w || !c->ws || !c->piv) {
        bgm_free(c);
        return NULL;
    }
#if BGM_HYBRID
    bgm_tables_init(c);
#endif
    bgm_defaults(c);
    return c;
}

void bgm_free(bgm_inst *c) {
    int f;
    if (!c) return;
    for (f = 0; f < BGM_NFUN; f++) {
        bgm_functions[f].release(c->mem[f]);
        bgm_functions[f].decref();
    }
    free(c->arg);
    free(c->res);
    free(c->iw);
    free(c->w);
    free(c->ws);
    free(c->piv);
    free(c->name);
#if BGM_HYBRID
    bgm_tables_free(c);
#endif
    c->magic = 0;
    free(c);
}

void bgm_reset(bgm_inst *c) { bgm_defaults(c); }

/* ------------------------------------------------------- experiment and initialization */

bgm_status bgm_setup_experiment(bgm_inst *c, const char *fn, int tol_defined, double tol,
                                double start, int stop_defined, double stop) {
    if (!bgm_check(c, fn, BGM_MODE_INSTANTIATED)) return BGM_ERROR;
    if (!isfinite(start)) {
        bgm_error(c, "%s: start time %g is not finite", fn, start);
        return BGM_ERROR;
    }
    if (stop_defined && !(isfinite(stop) && stop >= start)) {
        bgm_error(c, "%s: stop time %g is not finite or before the start time %g", fn, stop,
                  start);
        return BGM_ERROR;
    }
    if (tol_defined && !(isfinite(tol) && tol > 0.0)) {
        bgm_error(c, "%s: tolerance %g must be finite and > 0", fn, tol);
        return BGM_ERROR;
    }
    c->start_time = start;
    c->v.time = start;
    c->exp_tol_defined = tol_defined ? 1 : 0;
    c->exp_tol = tol_defined ? tol : 0.0;
    c->stop_defined = stop_defined ? 1 : 0;
    c->stop_time = stop_defined ? stop : 0.0;
    c->cache_valid = 0;
    c->v.x0_done = 0;
    return BGM_OK;
}

bgm_status bgm_enter_init(bgm_inst *c, const char *fn) {
    if (!bgm_check(c, fn, BGM_MODE_INSTANTIATED)) return BGM_ERROR;
    c->v.mode = BGM_MODE_INIT;
    c->v.x0_done = 0;
    c->cache_valid = 0;
    return BGM_OK;
}

bgm_status bgm_update_x0(bgm_inst *c, const char *fn) {
#if BGM_HAS_INIT
    if (!c->v.x0_done && (c->v.mode & (BGM_MODE_INSTANTIATED | BGM_MODE_INIT))) {
        const double *args[3];
        double *outs[1];
        double x0[BGM_NXA];
        size_t i;
        args[0] = &c->v.time;
        args[1] = c->v.u;
        args[2] = c->v.p;
        outs[0] = x0;
        if (bgm_call(c, F_INIT, args, 3, outs, 1)) {
            bgm_error(c, "%s: evaluation of the initial states failed at t=%g", fn, c->v.time);
            return BGM_ERROR;
        }
        for (i = 0; i < BGM_NX; i++) {
            if (!isfinite(x0[i])) {
                bgm_error(c, "%s: initial value of state %s is %g (check parameters and inputs)",
                          fn, bgm_var_names[BGM_VR_X + i], x0[i]);
                return BGM_ERROR;
            }
        }
        memcpy(c->v.x, x0, sizeof(c->v.x));
        c->v.x0_done = 1;
        c->cache_valid = 0;
    }
#else
    (void)c;
    (void)fn;
#endif
    return BGM_OK;
}

/* cache_valid: 0 nothing, 1 derivatives, 2 derivatives and outputs. The solver and
   GetDerivatives need only xdot (level 1); outputs are computed when read (level 2). */
static bgm_status bgm_evaluate(bgm_inst *c, const char *fn, int level) {
    int rc;
    size_t i;
    if (c->cache_valid >= level) return BGM_OK;
    if (bgm_update_x0(c, fn) != BGM_OK) return BGM_ERROR;
    if (level == 2)
        rc = bgm_call_ode(c, c->v.time, c->v.x, c->xdot, c->y);
    else
        rc = BGM_NX ? bgm_call_xdot(c, c->v.time, c->v.x, c->xdot) : 0;
    if (rc == 1) {
        bgm_error(c, "%s: model evaluation failed at t=%g", fn, c->v.time);
        return BGM_ERROR;
    }
    if (rc == 2) {
        for (i = 0; i < BGM_NX; i++)
            if (!isfinite(c->xdot[i])) {
                bgm_error(c, "%s: model evaluation returned %g for %s at t=%g", fn, c->xdot[i],
                          bgm_var_names[BGM_VR_DX + i], c->v.time);
                return BGM_ERROR;
            }
        for (i = 0; level == 2 && i < BGM_NY; i++)
            if (!isfinite(c->y[i])) {
                bgm_error(c, "%s: model evaluation returned %g for %s at t=%g", fn, c->y[i],
                          bgm_var_names[BGM_VR_Y + i], c->v.time);
                return BGM_ERROR;
            }
        return BGM_ERROR;
    }
    c->cache_valid = level;
    return BGM_OK;
}

bgm_status bgm_eval(bgm_inst *c, const char *fn) { return bgm_evaluate(c, fn, 1); }

bgm_status bgm_eval_y(bgm_inst *c, const char *fn) { return bgm_evaluate(c, fn, 2); }

bgm_status bgm_exit_init(bgm_inst *c, const char *fn) {
    if (!bgm_check(c, fn, BGM_MODE_INIT)) return BGM_ERROR;
    c->cache_valid = 0;
#if BGM_HYBRID
    if (bgm_hyb_initialize(c, fn) != BGM_OK) return BGM_ERROR;
#endif
    if (bgm_eval(c, fn) != BGM_OK) return BGM_ERROR;
    c->v.x0_done = 1;
    c->v.h_next = 0.0;
    if (c->v.kind == BGM_KIND_ME || c->event_mode_used) c->v.mode = BGM_MODE_EVENT;
    else c->v.mode = BGM_MODE_STEP;
    return BGM_OK;
}

bgm_status bgm_terminate(bgm_inst *c, const char *fn) {
    if (!bgm_check(c, fn, BGM_MODE_INIT | BGM_MODE_EVENT | BGM_MODE_CONT | BGM_MODE_STEP))
        return BGM_ERROR;
#if BGM_HYBRID
    if (c->v.mode != BGM_MODE_INIT && bgm_hyb_terminate(c, fn) != BGM_OK) return BGM_ERROR;
#endif
    c->v.mode = BGM_MODE_TERMINATED;
    if (c->v.kind == BGM_KIND_CS)
        bgm_log(c, BGM_OK, "logSolver",
                "solver statistics: %ld steps, %ld rejected, %ld Newton failures, "
                "%ld model and %ld Jacobian evaluations",
                c->stat_steps, c->stat_rejected, c->stat_newton_fail, c->stat_f, c->stat_jac);
    return BGM_OK;
}

/* ------------------------------------------------------------------------ variables */

int bgm_classify(unsigned vr, size_t *index) {
    *index = 0;
    if (vr == BGM_VR_TIME) return BGM_VAR_TIME;
    if (vr >= BGM_VR_X && vr < BGM_VR_DX) {
        *index = vr - BGM_VR_X;
        return BGM_VAR_STATE;
    }
    if (vr >= BGM_VR_DX && vr < BGM_VR_U) {
        *index = vr - BGM_VR_DX;
        return BGM_VAR_DERIVATIVE;
    }
    if (vr >= BGM_VR_U && vr < BGM_VR_P) {
        *index = vr - BGM_VR_U;
        return BGM_VAR_INPUT;
    }
    if (vr >= BGM_VR_P && vr < BGM_VR_Y) {
        *index = vr - BGM_VR_P;
        return BGM_VAR_PARAMETER;
    }
    if (vr >= BGM_VR_Y && vr < BGM_VR_SOLVER) {
        *index = vr - BGM_VR_Y;
        return BGM_VAR_OUTPUT;
    }
    if (vr >= BGM_VR_SOLVER && vr < BGM_VR_SOLVER + BGM_NSOLVER) {
        *index = vr - BGM_VR_SOLVER;
        return BGM_VAR_SOLVER;
    }
#if BGM_HYBRID
    if (vr >= BGM_VR_D && vr < BGM_VR_Z) {
        *index = vr - BGM_VR_D;
        return BGM_VAR_DISCRETE;
    }
    if (vr >= BGM_VR_Z && vr < BGM_NVR) {
        *index = vr - BGM_VR_Z;
        return BGM_VAR_INDICATOR;
    }
#endif
    return BGM_VAR_NONE;
}

bgm_status bgm_get_real(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                        double values[]) {
    size_t k, i;
#if BGM_HYBRID
    int evaluated = 0;
#endif
    if (!bgm_check(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (n == 0) return BGM_OK;
    if (!vr || !values) {
        bgm_error(c, "%s: NULL array argument", fn);
        return BGM_ERROR;
    }
    for (k = 0; k < n; k++) {
        switch (bgm_classify(vr[k], &i)) {
        case BGM_VAR_TIME: values[k] = c->v.time; break;
        case BGM_VAR_STATE:
            if (bgm_update_x0(c, fn) != BGM_OK) return BGM_ERROR;
            values[k] = c->v.x[i];
            break;
        case BGM_VAR_DERIVATIVE:
            if (bgm_eval(c, fn) != BGM_OK) return BGM_ERROR;
            values[k] = c->xdot[i];
            break;
        case BGM_VAR_INPUT: values[k] = c->v.u[i]; break;
        case BGM_VAR_PARAMETER: values[k] = c->v.p[i]; break;
        case BGM_VAR_OUTPUT:
            if (bgm_eval_y(c, fn) != BGM_OK) return BGM_ERROR;
            values[k] = c->y[i];
            break;
        case BGM_VAR_SOLVER: values[k] = i == 0 ? c->v.solver_tol : c->v.solver_hmax; break;
#if BGM_HYBRID
        case BGM_VAR_DISCRETE:
        case BGM_VAR_INDICATOR:
            if (bgm_hyb_value(c, fn, bgm_classify(vr[k], &i), i, BGM_DV_REAL, &evaluated,
                              &values[k]) != BGM_OK)
                return BGM_ERROR;
            break;
#endif
        default:
            bgm_error(c, "%s: unknown value reference %u", fn, vr[k]);
            return BGM_ERROR;
        }
    }
    return BGM_OK;
}

static int bgm_check_set(bgm_inst *c, const char *fn, unsigned vr, double value) {
    size_t i;
    int kind = bgm_classify(vr, &i);
    int mode = c->v.mode;
    double lo = -DBL_MAX, hi = DBL_MAX;
    int allowed = 0;
    const char *what = "";
    switch (kind) {
#if BGM_HYBRID
    case BGM_VAR_DISCRETE: return bgm_hyb_check_set(c, fn, i, BGM_DV_REAL, value);
#endif
    case BGM_VAR_STATE:
        what = "a state";
#if BGM_HAS_INIT
        bgm_error(c, "%s: state %s is calculated from the parameters (initial=\"calculated\") "
                  "and cannot be set", fn, bgm_var_names[vr]);
        return 0;
#else
        allowed = mode & (BGM_MODE_INSTANTIATED | BGM_MODE_INIT);
        lo = bgm_x_min[i];
        hi = bgm_x_max[i];
        break;
#endif
    case BGM_VAR_INPUT:
        what = "an input";
        allowed = mode & (BGM_MODE_INSTANTIATED | BGM_MODE_INIT | BGM_MODE_EVENT |
                          BGM_MODE_CONT | BGM_MODE_STEP);
        lo = bgm_u_min[i];
        hi = bgm_u_max[i];
        break;
    case BGM_VAR_PARAMETER:
    case BGM_VAR_SOLVER:
        what = "a tunable parameter";
        allowed = mode & (BGM_MODE_INSTANTIATED | BGM_MODE_INIT | BGM_MODE_EVENT |
                          BGM_MODE_STEP);
        if (kind == BGM_VAR_PARAMETER) {
            lo = bgm_p_min[i];
            hi = bgm_p_max[i];
        } else if (i == 0) {
            lo = BGM_SOLVER_TOL_MIN;
            hi = BGM_SOLVER_TOL_MAX;
        } else {
            lo = BGM_SOLVER_HMAX_MIN;
        }
        break;
    case BGM_VAR_NONE:
        bgm_error(c, "%s: unknown value reference %u", fn, vr);
        return 0;
    default:
        bgm_error(c, "%s: variable %s (value reference %u) is calculated and cannot be set",
                  fn, bgm_var_names[vr], vr);
        return 0;
    }
    if (!allowed) {
        bgm_error(c, "%s: %s is %s and cannot be set in %s", fn, bgm_var_names[vr], what,
                  bgm_mode_name(mode));
        return 0;
    }
    if (!isfinite(value)) {
        bgm_error(c, "%s: value %g for %s is not finite; the value is not set", fn, value,
                  bgm_var_names[vr]);
        return 0;
    }
    if (value < lo || value > hi) {
        char los[32], his[32];
        if (lo <= -DBL_MAX) snprintf(los, sizeof(los), "-inf");
        else snprintf(los, sizeof(los), "%.17g", lo);
        if (hi >= DBL_MAX) snprintf(his, sizeof(his), "inf");
        else snprintf(his, sizeof(his), "%.17g", hi);
        bgm_error(c, "%s: value %.17g for %s is outside its range [%s, %s] (min, max); "
                  "the value is not set", fn, value, bgm_var_names[vr], los, his);
        return 0;
    }
    return 1;
}

bgm_status bgm_set_real(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                        const double values[]) {
    size_t k, i;
    if (!bgm_check(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (n == 0) return BGM_OK;
    if (!vr || !values) {
        bgm_error(c, "%s: NULL array argument", fn);
        return BGM_ERROR;
    }
    /* validate everything first so that a failing call changes nothing */
    for (k = 0; k < n; k++)
        if (!bgm_check_set(c, fn, vr[k], values[k])) return BGM_ERROR;
    for (k = 0; k < n; k++) {
        switch (bgm_classify(vr[k], &i)) {
        case BGM_VAR_STATE: c->v.x[i] = values[k]; break;
        case BGM_VAR_INPUT: c->v.u[i] = values[k]; c->v.x0_done = 0; break;
        case BGM_VAR_PARAMETER: c->v.p[i] = values[k]; c->v.x0_done = 0; break;
        case BGM_VAR_SOLVER:
            if (i == 0) c->v.solver_tol = values[k];
            else c->v.solver_hmax = values[k];
            break;
#if BGM_HYBRID
        case BGM_VAR_DISCRETE: bgm_hyb_set(c, i, values[k]); break;
#endif
        default: break;
        }
    }
    c->cache_valid = 0;
    return BGM_OK;
}

bgm_status bgm_no_variables(bgm_inst *c, const char *fn, const char *type,
                            const unsigned vr[], size_t n) {
    if (!bgm_valid(c)) return BGM_ERROR;
    if (n == 0) return BGM_OK;
    bgm_error(c, "%s: the model has no %s variables (value reference %u)", fn, type,
              vr ? vr[0] : 0u);
    return BGM_ERROR;
}

/* ------------------------------------------------------------ directional derivatives */

bgm_status bgm_directional_derivative(bgm_inst *c, const char *fn, const unsigned unknowns[],
                                      size_t nu, const unsigned knowns[], size_t nk,
                                      const double seed[], double sens[]) {
    double dx[BGM_NXA], du[BGM_NUA], dp[BGM_NPA];
    double sx[BGM_NXA], sxdot[BGM_NXA], sy[BGM_NYA];
    size_t k, i;
    int through_init = 0;
    if (!bgm_check(c, fn, BGM_MODE_INIT | BGM_MODE_EVENT | BGM_MODE_CONT | BGM_MODE_STEP |
                              BGM_MODE_TERMINATED))
        return BGM_ERROR;
    if ((nu > 0 && (!unknowns || !sens)) || (nk > 0 && (!knowns || !seed))) {
        bgm_error(c, "%s: NULL array argument", fn);
        return BGM_ERROR;
    }
#if BGM_HAS_INIT
    through_init = c->v.mode == BGM_MODE_INIT;
#endif
    memset(dx, 0, sizeof(dx));
    memset(du, 0, sizeof(du));
    memset(dp, 0, sizeof(dp));
    for (k = 0; k < nk; k++) {
        int kind = bgm_classify(knowns[k], &i);
        if (!isfinite(seed[k])) {
            bgm_error(c, "%s: seed %g is not finite", fn, seed[k]);
            return BGM_ERROR;
        }
        if (kind == BGM_VAR_STATE && !through_init) dx[i] += seed[k];
        else if (kind == BGM_VAR_INPUT) du[i] += seed[k];
        else if (kind == BGM_VAR_PARAMETER) dp[i] += seed[k];
        else {
            bgm_error(c, "%s: value reference %u is not a known (state, input or parameter) "
                      "in %s", fn, knowns[k], bgm_mode_name(c->v.mode));
            return BGM_ERROR;
        }
    }
    for (k = 0; k < nu; k++) {
        int kind = bgm_classify(unknowns[k], &i);
        if (!(kind == BGM_VAR_DERIVATIVE || kind == BGM_VAR_OUTPUT ||
              (kind == BGM_VAR_STATE && through_init))) {
            bgm_error(c, "%s: value reference %u is not an unknown (state derivative or "
                      "output) in %s", fn, unknowns[k], bgm_mode_name(c->v.mode));
            return BGM_ERROR;
        }
    }
    if (bgm_eval(c, fn) != BGM_OK) return BGM_ERROR;
    memset(sx, 0, sizeof(sx));
    if (through_init) {
#if BGM_HAS_INIT
        const double *args[5];
        double *outs[3];
        args[0] = &c->v.time;
        args[1] = c->v.u;
        args[2] = c->v.p;
        args[3] = du;
        args[4] = dp;
        outs[0] = sx;
        outs[1] = sxdot;
        outs[2] = sy;
        if (bgm_call(c, F_INITFWD, args, 5, outs, 3)) {
            bgm_error(c, "%s: evaluation of the directional derivative failed", fn);
            return BGM_ERROR;
        }
#endif
    } else {
        const double *args[7];
        double *outs[2];
        args[0] = &c->v.time;
        args[1] = c->v.x;
        args[2] = c->v.u;
        args[3] = c->v.p;
        args[4] = dx;
        args[5] = du;
        args[6] = dp;
        outs[0] = sxdot;
        outs[1] = sy;
        if (bgm_call(c, F_FWD, args, 7, outs, 2)) {
            bgm_error(c, "%s: evaluation of the directional derivative failed", fn);
            return BGM_ERROR;
        }
    }
    for (k = 0; k < nu; k++) {
        int kind = bgm_classify(unknowns[k], &i);
        double value = kind == BGM_VAR_STATE ? sx[i]
                       : kind == BGM_VAR_DERIVATIVE ? sxdot[i] : sy[i];
        if (!isfinite(value)) {
            bgm_error(c, "%s: directional derivative of %s is %g", fn,
                      bgm_var_names[unknowns[k]], value);
            return BGM_ERROR;
        }
        sens[k] = value;
    }
    return BGM_OK;
}

/* ------------------------------------------------------------------- Model Exchange */

#define BGM_ME_CHECK(c, fn, modes) \
    (bgm_check_kind((c), (fn), BGM_KIND_ME) && bgm_check((c), (fn), (modes)))

static int bgm_check_n(bgm_inst *c, const char *fn, const void *ptr, size_t n, size_t want,
                       const char *what) {
    if (n != want) {
        bgm_error(c, "%s: expected %lu %s, got %lu", fn, (unsigned long)want, what,
                  (unsigned long)n);
        return 0;
    }
    if (n > 0 && !ptr) {
        bgm_error(c, "%s: NULL array argument", fn);
        return 0;
    }
    return 1;
}

bgm_status bgm_set_time(bgm_inst *c, const char *fn, double t) {
    if (!BGM_ME_CHECK(c, fn, BGM_MODE_EVENT | BGM_MODE_CONT)) return BGM_ERROR;
    if (!isfinite(t)) {
        bgm_error(c, "%s: time %g is not finite", fn, t);
        return BGM_ERROR;
    }
    c->v.time = t;
    c->cache_valid = 0;
    return BGM_OK;
}

bgm_status bgm_set_states(bgm_inst *c, const char *fn, const double x[], size_t nx) {
    size_t i;
    if (!BGM_ME_CHECK(c, fn, BGM_MODE_EVENT | BGM_MODE_CONT)) return BGM_ERROR;
    if (!bgm_check_n(c, fn, x, nx, BGM_NX, "continuous states")) return BGM_ERROR;
    for (i = 0; i < nx; i++)
        if (!isfinite(x[i])) {
            bgm_error(c, "%s: value %g for state %s is not finite", fn, x[i],
                      bgm_var_names[BGM_VR_X + i]);
            return BGM_ERROR;
        }
    if (nx > 0) memcpy(c->v.x, x, nx * sizeof(double));
    c->cache_valid = 0;
    return BGM_OK;
}

bgm_status bgm_get_states(bgm_inst *c, const char *fn, double x[], size_t nx) {
    if (!BGM_ME_CHECK(c, fn, BGM_MODE_INIT | BGM_MODE_EVENT | BGM_MODE_CONT |
                                 BGM_MODE_TERMINATED))
        return BGM_ERROR;
    if (!bgm_check_n(c, fn, x, nx, BGM_NX, "continuous states")) return BGM_ERROR;
    if (bgm_update_x0(c, fn) != BGM_OK) return BGM_ERROR;
    if (nx > 0) memcpy(x, c->v.x, nx * sizeof(double));
    return BGM_OK;
}

bgm_status bgm_get_derivatives(bgm_inst *c, const char *fn, double dx[], size_t nx) {
    if (!BGM_ME_CHECK(c, fn, BGM_MODE_INIT | BGM_MODE_EVENT | BGM_MODE_CONT |
                                 BGM_MODE_TERMINATED))
        return BGM_ERROR;
    if (!bgm_check_n(c, fn, dx, nx, BGM_NX, "state derivatives")) return BGM_ERROR;
    if (bgm_eval(c, fn) != BGM_OK) return BGM_ERROR;
    if (nx > 0) memcpy(dx, c->xdot, nx * sizeof(double));
    return BGM_OK;
}

bgm_status bgm_get_nominals(bgm_inst *c, const char *fn, double nominal[], size_t nx) {
    if (!BGM_ME_CHECK(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (!bgm_check_n(c, fn, nominal, nx, BGM_NX, "nominals")) return BGM_ERROR;
    if (nx > 0) memcpy(nominal, bgm_x_nominal, nx * sizeof(double));
    return BGM_OK;
}

bgm_status bgm_event_indicators(bgm_inst *c, const char *fn, size_t ni) {
    if (!BGM_ME_CHECK(c, fn, BGM_MODE_INIT | BGM_MODE_EVENT | BGM_MODE_CONT |
                                 BGM_MODE_TERMINATED))
        return BGM_ERROR;
    if (ni != 0) {
        bgm_error(c, "%s: the model has no event indicators, %lu requested", fn,
                  (unsigned long)ni);
        return BGM_ERROR;
    }
    return BGM_OK;
}

/* -------------------------------------------------------------------- Co-Simulation */

bgm_status bgm_do_step(bgm_inst *c, const char *fn, double t, double h) {
    double tol_t;
    if (!bgm_check_kind(c, fn, BGM_KIND_CS)) return BGM_ERROR;
    if (!bgm_check(c, fn, BGM_MODE_STEP)) return BGM_ERROR;
    if (!isfinite(t) || !isfinite(h) || h < 0.0) {
        bgm_error(c, "%s: invalid communication point %g or step size %g", fn, t, h);
        return BGM_ERROR;
    }
    tol_t = 1e-9 * (fabs(t) > 1.0 ? fabs(t) : 1.0) + 1e-9 * h;
    if (fabs(t - c->v.time) > tol_t) {
        bgm_error(c, "%s: communication point %.17g does not match the FMU time %.17g", fn, t,
                  c->v.time);
        return BGM_ERROR;
    }
    if (c->stop_defined) {
        /* the step may end at the stop time up to rounding (t_k = t0 + k h, importers
           comparing with a relative tolerance of 1e-9), not beyond */
        double end = t + h;
        double slack = 1e-8 * (fabs(c->stop_time) > 1.0 ? fabs(c->stop_time) : 1.0);
        if (end > c->stop_time + slack) {
            bgm_error(c, "%s: the step from t=%.17g by %.17g ends at %.17g, past the stop "
                      "time %.17g given at initialization (stopTimeDefined); the step is "
                      "not taken", fn, t, h, end, c->stop_time);
            return BGM_ERROR;
        }
    }
    c->v.time = t;
    c->cache_valid = 0;
#if BGM_HYBRID
    if (h > 0.0 && bgm_hyb_integrate(c, fn, t + h) != BGM_OK) {
#else
    if (h > 0.0 && bgm_integrate(c, fn, t + h) != BGM_OK) {
#endif
        c->cache_valid = 0;
        return BGM_ERROR;
    }
    return bgm_eval(c, fn);
}

/* ------------------------------------------------------------------------ FMU state */

bgm_status bgm_get_state(bgm_inst *c, const char *fn, void **state) {
    bgm_vars *s;
    if (!bgm_check(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (!state) {
        bgm_error(c, "%s: NULL state pointer", fn);
        return BGM_ERROR;
    }
    s = (bgm_vars *)*state;
    if (s && s->magic != BGM_STATE_MAGIC) {
        bgm_error(c, "%s: the given FMU state was not created by this FMU", fn);
        return BGM_ERROR;
    }
    if (!s) {
        s = (bgm_vars *)malloc(sizeof(bgm_vars));
        if (!s) {
            bgm_error(c, "%s: out of memory", fn);
            return BGM_ERROR;
        }
    }
    memcpy(s, &c->v, sizeof(bgm_vars));
    *state = s;
    return BGM_OK;
}

static int bgm_state_ok(bgm_inst *c, const char *fn, const bgm_vars *s) {
    if (!s) {
        bgm_error(c, "%s: NULL FMU state", fn);
        return 0;
    }
    if (s->magic != BGM_STATE_MAGIC || s->size != sizeof(bgm_vars) ||
        s->token_hash != bgm_hash(BGM_TOKEN) || s->kind != c->v.kind) {
        bgm_error(c, "%s: the FMU state does not belong to this FMU and interface type", fn);
        return 0;
    }
    return 1;
}

bgm_status bgm_set_state(bgm_inst *c, const char *fn, const void *state) {
    if (!bgm_check(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (!bgm_state_ok(c, fn, (const bgm_vars *)state)) return BGM_ERROR;
    memcpy(&c->v, state, sizeof(bgm_vars));
    c->lu_ok = 0;
    c->cache_valid = 0;
    return BGM_OK;
}

bgm_status bgm_free_state(bgm_inst *c, const char *fn, void **state) {
    if (!bgm_valid(c)) return BGM_ERROR;
    if (!state || !*state) return BGM_OK;
    if (((bgm_vars *)*state)->magic != BGM_STATE_MAGIC) {
        bgm_error(c, "%s: the given FMU state was not created by this FMU", fn);
        return BGM_ERROR;
    }
    ((bgm_vars *)*state)->magic = 0;
    free(*state);
    *state = NULL;
    return BGM_OK;
}

bgm_status bgm_serialized_size(bgm_inst *c, const char *fn, const void *state, size_t *size) {
    if (!bgm_valid(c)) return BGM_ERROR;
    if (!size || !bgm_state_ok(c, fn, (const bgm_vars *)state)) return BGM_ERROR;
    *size = sizeof(bgm_vars);
    return BGM_OK;
}

bgm_status bgm_serialize(bgm_inst *c, const char *fn, const void *state, void *bytes,
                         size_t size) {
    if (!bgm_valid(c)) return BGM_ERROR;
    if (!bgm_state_ok(c, fn, (const bgm_vars *)state)) return BGM_ERROR;
    if (!bytes || size != sizeof(bgm_vars)) {
        bgm_error(c, "%s: buffer of %lu bytes, %lu needed", fn, (unsigned long)size,
                  (unsigned long)sizeof(bgm_vars));
        return BGM_ERROR;
    }
    memcpy(bytes, state, sizeof(bgm_vars));
    return BGM_OK;
}

bgm_status bgm_deserialize(bgm_inst *c, const char *fn, const void *bytes, size_t size,
                           void **state) {
    bgm_vars tmp;
    if (!bgm_valid(c)) return BGM_ERROR;
    if (!bytes || !state || size != sizeof(bgm_vars)) {
        bgm_error(c, "%s: serialized FMU state has %lu bytes, %lu expected", fn,
                  (unsigned long)size, (unsigned long)sizeof(bgm_vars));
        return BGM_ERROR;
    }
    memcpy(&tmp, bytes, sizeof(bgm_vars));
    if (!bgm_state_ok(c, fn, &tmp)) return BGM_ERROR;
    if (*state && ((bgm_vars *)*state)->magic != BGM_STATE_MAGIC) {
        bgm_error(c, "%s: the given FMU state was not created by this FMU", fn);
        return BGM_ERROR;
    }
    if (!*state) {
        *state = malloc(sizeof(bgm_vars));
        if (!*state) {
            bgm_error(c, "%s: out of memory", fn);
            return BGM_ERROR;
        }
    }
    memcpy(*state, &tmp, sizeof(bgm_vars));
    return BGM_OK;
}
