/*
 * bgmodelica FMU runtime: events of hybrid models (relations, when-clauses, pre(), reinit,
 * sample clocks, time tables).  Included by bgm_core.h when the generated model data define
 * BGM_HYBRID.
 *
 * The runtime is a port of the native event loop (bgmodelica/events/loop.py,
 * HybridSimulator) onto the CasADi functions of bgmodelica/events/functions.py, generated
 * into the FMU's C code with the algebraic variables eliminated (fast_newton, as in the
 * model function):
 *
 *   evstep(t, x, u, p, d) -> g (every relation indicator), dgdt, cond (when-branch
 *                            conditions), assign, reinit, pre (pre() sources), dv (exported
 *                            discrete variables)
 *   evind(t, x, u, p, d)  -> indicators of the relations located as state events
 *   evsamp(t, x, u, p, d) -> start, interval of every sample clock
 *
 * d holds the discrete slots (relation values, discrete variables, pre() values, clock
 * flags, table coefficients, initial()/terminal()); it is passed as the last argument of
 * every generated function.  Relations are frozen between events (their values live in d).
 */
#ifndef BGM_EVENTS_H
#define BGM_EVENTS_H

#define BGM_NDA (BGM_ND > 0 ? BGM_ND : 1)
#define BGM_NRELA (BGM_NREL > 0 ? BGM_NREL : 1)
#define BGM_NZA (BGM_NZ > 0 ? BGM_NZ : 1)
#define BGM_NTRELA (BGM_NTREL > 0 ? BGM_NTREL : 1)
#define BGM_NWHENA (BGM_NWHEN > 0 ? BGM_NWHEN : 1)
#define BGM_NCONDA (BGM_NCOND > 0 ? BGM_NCOND : 1)
#define BGM_NASSIGNA (BGM_NASSIGN > 0 ? BGM_NASSIGN : 1)
#define BGM_NASSIGNVA (BGM_NASSIGNV > 0 ? BGM_NASSIGNV : 1) /* values: evstep's assign */
#define BGM_NREINITVA (BGM_NREINITV > 0 ? BGM_NREINITV : 1) /* values: evstep's reinit */
#define BGM_NREINITA (BGM_NREINIT > 0 ? BGM_NREINIT : 1)
#define BGM_NPREA (BGM_NPRE > 0 ? BGM_NPRE : 1)
#define BGM_NSAMPA (BGM_NSAMP > 0 ? BGM_NSAMP : 1)
#define BGM_NTABA (BGM_NTAB > 0 ? BGM_NTAB : 1)
#define BGM_NTABPTSA (BGM_NTABPTS > 0 ? BGM_NTABPTS : 1)
#define BGM_NDVA (BGM_NDV > 0 ? BGM_NDV : 1)

/* EventOptions of the native loop */
#define BGM_EV_MAX_ITER 100   /* event-iteration bound */
#define BGM_EV_TOL 1e-13      /* state-event location, relative to max(1, |t|) */
#define BGM_EV_ZENO 50        /* events within BGM_EV_ZENO_DT*max(1,|t|) s: chattering */
#define BGM_EV_ZENO_DT 1e-10

/* types of exported discrete variables */
enum { BGM_DV_REAL = 0, BGM_DV_INTEGER = 1, BGM_DV_BOOLEAN = 2 };

/* Event state: part of the FMU state (copied by Get/SetFMUState). */
typedef struct {
    double d[BGM_NDA];            /* discrete slots */
    double cond_pre[BGM_NCONDA];  /* when-conditions after the last event iteration */
    double samp[2 * BGM_NSAMPA];  /* start, interval of each clock */
    double samp_last[BGM_NSAMPA]; /* index k of the instant at which each clock last ticked */
    double time_next;             /* next change of a relation on time alone */
    double recent[BGM_EV_ZENO];   /* times of the last events (chattering check) */
    int n_recent, i_recent;
    int samp_set[BGM_NSAMPA];     /* samp_last is defined */
    int phase;                    /* 0 none, 1 event iteration under way, 2 converged */
    int iter;                     /* passes of the current event iteration */
    int flags;                    /* clocks or initial() raised at this instant */
    int initialized;              /* the initial event iteration is done */
    int pending;                  /* CS: an event at the current time awaits Event Mode */
} bgm_hyb_vars;

/* Scratch memory of the event functions (not part of the FMU state). */
typedef struct {
    double g[BGM_NRELA], dgdt[BGM_NRELA], cond[BGM_NCONDA], assign[BGM_NASSIGNVA];
    double reinit[BGM_NREINITVA], pre[BGM_NPREA], dv[BGM_NDVA];
    double z[BGM_NZA], vals[BGM_NRELA], samp[2 * BGM_NSAMPA];
    double xnew[BGM_NXA], xc[BGM_NXA], zc[BGM_NZA];
    /* Co-Simulation: bracket of a state event found by the solver */
    double lo_t, hi_t, lo_x[BGM_NXA], hi_x[BGM_NXA], lo_g[BGM_NZA], hi_g[BGM_NZA];
    int check;          /* the solver checks the indicators after each accepted step */
    int crossed;        /* ... and found a crossing (bracket above) */
    int event_needed;   /* FMI 3.0 CS with event mode: eventHandlingNeeded */
    int x_changed;      /* a reinit changed the states in the last update call */
    char changing[256]; /* what changed in the last pass (error messages) */
} bgm_hyb_work;

/* model data (bgm_hybrid_data.c, generated) */
extern const double bgm_d_start[BGM_NDA];
extern const char *const bgm_d_names[BGM_NDA];
extern const int bgm_rel_slot[BGM_NRELA], bgm_rel_strict[BGM_NRELA];
extern const char *const bgm_rel_text[BGM_NRELA];
extern const int bgm_state_rel[BGM_NZA], bgm_time_rel[BGM_NTRELA];
extern const int bgm_when_first[BGM_NWHENA + 1], bgm_when_branch[BGM_NCONDA];
extern const int bgm_assign_first[BGM_NCONDA + 1], bgm_assign_slot[BGM_NASSIGNA];
extern const int bgm_assign_pos[BGM_NASSIGNA];
extern const int bgm_reinit_first[BGM_NCONDA + 1], bgm_reinit_state[BGM_NREINITA];
extern const int bgm_reinit_pos[BGM_NREINITA];
extern const double bgm_reinit_sign[BGM_NREINITA];
extern const int bgm_pre_slot[BGM_NPREA], bgm_pre_discrete[BGM_NPREA];
extern const char *const bgm_pre_names[BGM_NPREA];
extern const int bgm_sample_slot[BGM_NSAMPA];
extern const int bgm_tab_c0[BGM_NTABA], bgm_tab_c1[BGM_NTABA], bgm_tab_first[BGM_NTABA + 1];
extern const int bgm_tab_hold[BGM_NTABA], bgm_tab_extrap[BGM_NTABA];
extern const double bgm_tab_times[BGM_NTABPTSA], bgm_tab_values[BGM_NTABPTSA];
extern const char *const bgm_tab_file[BGM_NTABA], *const bgm_tab_column[BGM_NTABA];
extern const int bgm_dv_type[BGM_NDVA], bgm_dv_slot[BGM_NDVA];

/* table extrapolation codes */
enum { BGM_TAB_HOLD = 0, BGM_TAB_PERIODIC = 1, BGM_TAB_LINEAR = 2 };

#endif
