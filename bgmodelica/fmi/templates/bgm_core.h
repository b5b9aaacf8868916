/*
 * bgmodelica FMU runtime: model-independent core shared by the FMI 2.0 and FMI 3.0 wrappers.
 *
 * The core knows nothing about FMI types: it works on an instance (bgm_inst) holding the
 * time, the states x, inputs u, parameters p and cached model evaluations, and calls the
 * CasADi-generated model functions named in bgm_model_data.h.  Statuses are numbered like
 * fmi2Status/fmi3Status (OK, Warning, Discard, Error, Fatal) so wrappers can cast them.
 *
 * Written for bgmodelica from the FMI 2.0.x and 3.0 specifications.
 */
#ifndef BGM_CORE_H
#define BGM_CORE_H

#include <stddef.h>
#include "bgm_model_data.h"

#define BGM_NXA (BGM_NX > 0 ? BGM_NX : 1)
#define BGM_NUA (BGM_NU > 0 ? BGM_NU : 1)
#define BGM_NPA (BGM_NP > 0 ? BGM_NP : 1)
#define BGM_NYA (BGM_NY > 0 ? BGM_NY : 1)

#if BGM_HYBRID
#include "bgm_events.h"
#endif

/* value-reference layout (see bgmodelica/fmi/variables.py) */
#define BGM_VR_TIME 0u
#define BGM_VR_X 1u
#define BGM_VR_DX (BGM_VR_X + BGM_NX)
#define BGM_VR_U (BGM_VR_DX + BGM_NX)
#define BGM_VR_P (BGM_VR_U + BGM_NU)
#define BGM_VR_Y (BGM_VR_P + BGM_NP)
#define BGM_VR_SOLVER (BGM_VR_Y + BGM_NY)
#if BGM_HYBRID
#define BGM_VR_D (BGM_VR_SOLVER + BGM_NSOLVER) /* exported discrete variables */
#define BGM_VR_Z (BGM_VR_D + BGM_NDV)          /* event indicators (FMI 3.0 ME) */
#define BGM_NVR (BGM_VR_Z + BGM_NZV)
#else
#define BGM_NVR (BGM_VR_SOLVER + BGM_NSOLVER)
#endif

typedef enum { BGM_OK = 0, BGM_WARNING = 1, BGM_DISCARD = 2, BGM_ERROR = 3, BGM_FATAL = 4 }
    bgm_status;

/* modes (bit flags so that allowed sets can be or-ed) */
enum {
    BGM_MODE_INSTANTIATED = 1,
    BGM_MODE_INIT = 2,
    BGM_MODE_EVENT = 4,
    BGM_MODE_CONT = 8,
    BGM_MODE_STEP = 16,
    BGM_MODE_TERMINATED = 32
};
#define BGM_MODE_ANY 63

enum { BGM_KIND_ME = 1, BGM_KIND_CS = 2 };

/* variable kinds returned by bgm_classify */
enum {
    BGM_VAR_NONE = 0, BGM_VAR_TIME, BGM_VAR_STATE, BGM_VAR_DERIVATIVE, BGM_VAR_INPUT,
    BGM_VAR_PARAMETER, BGM_VAR_OUTPUT, BGM_VAR_SOLVER, BGM_VAR_DISCRETE, BGM_VAR_INDICATOR
};

/* log categories */
#define BGM_LOG_WARNING 1u
#define BGM_LOG_ERROR 2u
#define BGM_LOG_SOLVER 4u
#define BGM_LOG_EVENTS 8u
#define BGM_LOG_ALL 15u

/* The embedded BDF solver's history between DoStep calls (bgm_solver.c).  Part of the FMU
   state, so that a restored state repeats the same steps. */
#define BGM_BDF_ROWS 8     /* differences 0..order+2 of the highest order, 5 */
typedef struct {
    int valid;             /* the history continues (snap_time, x, p, tolerance) */
    int snap_ok;           /* snap_* hold the end of the last completed step */
    int order;             /* current order 1..5 */
    int n_equal;           /* steps taken with the current order and step size */
    int jac_fresh;         /* jac was evaluated at the current step's predictor */
    double t;              /* time of the newest solution point (may pass the step's end) */
    double h;              /* current step size [s] */
    double snap_time;      /* instance time and tolerance when the history was left */
    double snap_tol;
    double d[BGM_BDF_ROWS * BGM_NXA]; /* backward differences at spacing h, row k = D_k */
    double jac[BGM_NXA * BGM_NXA];    /* d(xdot)/dx of the Newton iterations (column-major) */
    double snap_x[BGM_NXA], snap_u[BGM_NUA], snap_p[BGM_NPA];
} bgm_bdf;

/* Everything that makes up the FMU state (copied verbatim by Get/SetFMUState). */
typedef struct {
    unsigned magic;
    unsigned size;
    unsigned token_hash;
    int kind;
    int mode;
    int x0_done;           /* x holds init(t,u,p) for the current u,p (spec with init) */
    double time;
    double x[BGM_NXA];
    double u[BGM_NUA];
    double p[BGM_NPA];
    double solver_tol;     /* parameter solver.tolerance */
    double solver_hmax;    /* parameter solver.max_step */
    double h_next;         /* step-size proposal of the embedded solver (0: restart it) */
    bgm_bdf bdf;           /* the embedded solver's history (Co-Simulation) */
#if BGM_HYBRID
    bgm_hyb_vars h;        /* discrete slots and event state (bgm_events.c) */
#endif
} bgm_vars;

struct bgm_inst;
typedef void (*bgm_emit_fn)(struct bgm_inst *c, int status, const char *category,
                            const char *message);
typedef void (*bgm_any_fn)(void);

typedef struct bgm_inst {
    unsigned magic;
    int fmi_version;
    bgm_vars v;
    /* cached evaluation of ode(t, x, u, p) */
    double xdot[BGM_NXA];
    double y[BGM_NYA];
    int cache_valid;
    /* experiment */
    double start_time;
    int exp_tol_defined;
    double exp_tol;
    int stop_defined;
    double stop_time;
    int event_mode_used;   /* FMI 3.0 Co-Simulation */
    /* logging */
    char *name;
    int logging_on;
    unsigned log_mask;
    bgm_emit_fn emit;
    bgm_any_fn logger_fn;  /* the importer's callback, cast back by the wrapper's emit */
    void *logger_env;
    /* CasADi work memory */
    const double **arg;
    double **res;
    casadi_int *iw;
    double *w;
    int mem[16];
    /* solver work memory */
    double *ws;
    int *piv;
    long stat_steps, stat_rejected, stat_newton_fail, stat_f, stat_jac;
    int lu_ok;                /* ws holds the LU of I - lu_c * v.bdf.jac */
    double lu_c;
#if BGM_HYBRID
    int early_return_allowed; /* FMI 3.0 Co-Simulation */
    bgm_hyb_work hw;          /* scratch of the event functions */
    /* time tables: the compiled-in data, or a file of the FMU's resources (not FMU state) */
    const double *tab_t[BGM_NTABA], *tab_v[BGM_NTABA];
    int tab_n[BGM_NTABA];
    double *tab_buf[BGM_NTABA];
#endif
} bgm_inst;

/* model data (bgm_model_data.c, generated) */
extern const double bgm_x_start[BGM_NXA], bgm_x_nominal[BGM_NXA];
extern const double bgm_x_min[BGM_NXA], bgm_x_max[BGM_NXA];
extern const double bgm_u_start[BGM_NUA], bgm_u_min[BGM_NUA], bgm_u_max[BGM_NUA];
extern const double bgm_p_start[BGM_NPA], bgm_p_min[BGM_NPA], bgm_p_max[BGM_NPA];
extern const char *const bgm_var_names[BGM_NVR];

/* lifecycle */
bgm_inst *bgm_new(int fmi_version, int kind, const char *name, int logging_on,
                  bgm_emit_fn emit, bgm_any_fn logger_fn, void *logger_env);
void bgm_free(bgm_inst *c);
void bgm_reset(bgm_inst *c);
int bgm_valid(const bgm_inst *c);
int bgm_check(bgm_inst *c, const char *fn, int modes);
int bgm_check_kind(bgm_inst *c, const char *fn, int kind);
const char *bgm_mode_name(int mode);
unsigned bgm_hash(const char *s);

/* logging */
void bgm_log(bgm_inst *c, int status, const char *category, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
#define bgm_error(c, ...) bgm_log((c), BGM_ERROR, "logStatusError", __VA_ARGS__)
bgm_status bgm_set_debug_logging(bgm_inst *c, int on, size_t n, const char *const cats[]);

/* experiment and initialization */
bgm_status bgm_setup_experiment(bgm_inst *c, const char *fn, int tol_defined, double tol,
                                double start, int stop_defined, double stop);
bgm_status bgm_enter_init(bgm_inst *c, const char *fn);
bgm_status bgm_exit_init(bgm_inst *c, const char *fn);
bgm_status bgm_terminate(bgm_inst *c, const char *fn);

/* variables */
int bgm_classify(unsigned vr, size_t *index);
bgm_status bgm_get_real(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                        double values[]);
bgm_status bgm_set_real(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                        const double values[]);
bgm_status bgm_no_variables(bgm_inst *c, const char *fn, const char *type,
                            const unsigned vr[], size_t n);
bgm_status bgm_eval(bgm_inst *c, const char *fn);
bgm_status bgm_eval_y(bgm_inst *c, const char *fn);
bgm_status bgm_update_x0(bgm_inst *c, const char *fn);
bgm_status bgm_directional_derivative(bgm_inst *c, const char *fn, const unsigned unknowns[],
                                      size_t nu, const unsigned knowns[], size_t nk,
                                      const double seed[], double sens[]);

/* Model Exchange helpers */
bgm_status bgm_set_time(bgm_inst *c, const char *fn, double t);
bgm_status bgm_set_states(bgm_inst *c, const char *fn, const double x[], size_t nx);
bgm_status bgm_get_states(bgm_inst *c, const char *fn, double x[], size_t nx);
bgm_status bgm_get_derivatives(bgm_inst *c, const char *fn, double dx[], size_t nx);
bgm_status bgm_get_nominals(bgm_inst *c, const char *fn, double nominal[], size_t nx);
bgm_status bgm_event_indicators(bgm_inst *c, const char *fn, size_t ni);

/* Co-Simulation */
bgm_status bgm_do_step(bgm_inst *c, const char *fn, double t, double h);
bgm_status bgm_integrate(bgm_inst *c, const char *fn, double t_end);  /* bgm_solver.c */
bgm_status bgm_sdirk_integrate(bgm_inst *c, const char *fn, double t_end); /* bgm_sdirk.c */
void bgm_iteration_matrix(double *m, const double *J, double coef, int n); /* I - coef*J */
int bgm_lu_factor(double *a, int *piv, int n);        /* row-major, partial pivoting */
void bgm_lu_solve(const double *a, const int *piv, int n, double *b);
double bgm_wnorm(const double *v, const double *sc, int n); /* RMS of v ./ sc */
size_t bgm_solver_workspace(void);                                     /* doubles */

/* FMU state */
bgm_status bgm_get_state(bgm_inst *c, const char *fn, void **state);
bgm_status bgm_set_state(bgm_inst *c, const char *fn, const void *state);
bgm_status bgm_free_state(bgm_inst *c, const char *fn, void **state);
bgm_status bgm_serialized_size(bgm_inst *c, const char *fn, const void *state, size_t *size);
bgm_status bgm_serialize(bgm_inst *c, const char *fn, const void *state, void *bytes,
                         size_t size);
bgm_status bgm_deserialize(bgm_inst *c, const char *fn, const void *bytes, size_t size,
                           void **state);

/* raw model calls (0 on success); used by the solver */
int bgm_call_ode(bgm_inst *c, double t, const double *x, double *xdot, double *y);
int bgm_call_xdot(bgm_inst *c, double t, const double *x, double *xdot);
int bgm_call_jacx(bgm_inst *c, double t, const double *x, double *jac);

#if BGM_HYBRID
/* events (bgm_events.c); bgm_call_event: which = 0 evstep, 1 evind, 2 evsamp */
int bgm_call_event(bgm_inst *c, int which, double t, const double *x, double **outs, int nouts);
void bgm_hyb_defaults(bgm_inst *c);
void bgm_tables_init(bgm_inst *c);
void bgm_tables_free(bgm_inst *c);
int bgm_tables_load(bgm_inst *c, const char *dir);
void bgm_resource_dir(const char *uri, char *out, size_t size);
bgm_status bgm_hyb_initialize(bgm_inst *c, const char *fn);
bgm_status bgm_hyb_enter_event(bgm_inst *c, const char *fn);
bgm_status bgm_hyb_update(bgm_inst *c, const char *fn, int *need_update, int *x_changed,
                          int *next_defined, double *next_time);
bgm_status bgm_hyb_terminate(bgm_inst *c, const char *fn);
bgm_status bgm_hyb_event_indicators(bgm_inst *c, const char *fn, double z[], size_t ni);
bgm_status bgm_hyb_integrate(bgm_inst *c, const char *fn, double t_end);
void bgm_hyb_track(bgm_inst *c, double t, const double *x);
int bgm_hyb_step_check(bgm_inst *c, double t0, const double *x0, double t1, const double *x1);
bgm_status bgm_hyb_value(bgm_inst *c, const char *fn, int kind, size_t i, int type,
                         int *evaluated, double *value);
int bgm_hyb_check_set(bgm_inst *c, const char *fn, size_t i, int type, double value);
void bgm_hyb_set(bgm_inst *c, size_t i, double value);
bgm_status bgm_hyb_get_typed(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                             int type, int bool_byte, void *values);
bgm_status bgm_hyb_set_typed(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                             int type, int bool_byte, const void *values);
#endif

#endif
