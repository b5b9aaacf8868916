/*
 * bgmodelica FMU runtime: events of hybrid models.  See bgm_events.h.
 *
 * A port of the native event loop (bgmodelica/events/loop.py, HybridSimulator), function by
 * function, so that an FMU and `bgmodelica.simulate` take the same decisions:
 *
 *   ev_initialize      <- HybridSimulator._initialize
 *   ev_begin           <- HybridSimulator._event (before the iteration) and _note
 *   ev_pass/ev_finish  <- one pass of HybridSimulator._iterate / its end
 *   ev_relation_values <- HybridSimulator._relation_values
 *   ev_schedule        <- HybridSimulator._schedule_time_relations
 *   ev_next_time       <- HybridSimulator._next_time_event
 *   ev_locate          <- HybridSimulator._locate (Illinois on re-integrations)
 *   next_sample, is_sample_instant, table_coefficients <- bgmodelica/events/schedule.py
 *
 * Model Exchange: EnterEventMode starts an event at the current time, every
 * NewDiscreteStates/UpdateDiscreteStates call runs one pass of the event iteration
 * (discreteStatesNeedUpdate while something changed), and the last one returns the next time
 * event.  The event indicators are the indicators of the relations located as state events
 * (z > 0 <=> the relation is true; never exactly 0, see ev_fmi_sign).
 * Co-Simulation: DoStep integrates with the embedded solver, checks the indicators after
 * every accepted step, locates a crossing by the Illinois method on re-integrations from the
 * start of that step (to 1e-13 s relative), stops exactly at time events, and iterates the
 * event itself (or, FMI 3.0 with eventModeUsed, returns eventHandlingNeeded; with
 * earlyReturnAllowed it returns at the event time).
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bgm_core.h"

#if BGM_HYBRID

#define EV_INF HUGE_VAL

static double dmax(double a, double b) { return a > b ? a : b; }
static double dmin(double a, double b) { return a < b ? a : b; }

/* ------------------------------------------------------------------ model functions */

static int ev_step(bgm_inst *c, double t, const double *x) {
    bgm_hyb_work *w = &c->hw;
    double *outs[7];
    outs[0] = w->g;
    outs[1] = w->dgdt;
    outs[2] = w->cond;
    outs[3] = w->assign;
    outs[4] = w->reinit;
    outs[5] = w->pre;
    outs[6] = w->dv;
    return bgm_call_event(c, 0, t, x, outs, 7);
}

static int ev_ind(bgm_inst *c, double t, const double *x, double *z) {
    double *outs[1];
    outs[0] = z;
    return bgm_call_event(c, 1, t, x, outs, 1);
}

static int rel_value(int k, double g) { return bgm_rel_strict[k] ? g > 0.0 : g >= 0.0; }

/* FMI sign convention for the state relations' indicators: z > 0 exactly when the relation is
   true, and z is never 0 (an indicator at exactly 0 counts as a root for integrators such as
   CVODE although the relation keeps its value there; then the crossing that follows would be
   missed: a strict relation at 0 is false, -DBL_MIN, a non-strict one true, DBL_MIN) */
static void ev_fmi_sign(double *z) {
    int k;
    for (k = 0; k < BGM_NZ; k++)
        if (z[k] == 0.0) z[k] = bgm_rel_strict[bgm_state_rel[k]] ? -DBL_MIN : DBL_MIN;
}

/* whether a state relation has left its frozen value at indicators z */
static int ev_changed(const bgm_inst *c, const double *z) {
    int k;
    for (k = 0; k < BGM_NZ; k++) {
        int r = bgm_state_rel[k];
        if ((double)rel_value(r, z[k]) != c->v.h.d[bgm_rel_slot[r]]) return 1;
    }
    return 0;
}

static void ev_note_change(bgm_inst *c, const char *what, int *n) {
    char *buf = c->hw.changing;
    size_t len = strlen(buf);
    if (*n < 4 && len + strlen(what) + 3 < sizeof(c->hw.changing))
        snprintf(buf + len, sizeof(c->hw.changing) - len, "%s%s", len ? ", " : "", what);
    (*n)++;
}

static bgm_status ev_failed(bgm_inst *c, const char *fn, const char *what, double t) {
    bgm_error(c, "%s: evaluation of the %s failed at t=%.17g (check parameters and inputs)",
              fn, what, t);
    c->cache_valid = 0;
    return BGM_ERROR;
}

/* ------------------------------------------------------------- time events (schedule.py) */

static double next_sample(double start, double interval, double t) {
    double k, out, prev;
    if (t < start) return start;
    k = floor((t - start) / interval) + 1.0;
    out = start + k * interval;
    while (out <= t) {
        k += 1.0;
        out = start + k * interval;
    }
    prev = start + (k - 1.0) * interval;
    return prev > t ? prev : out;
}

static double instant_index(double start, double interval, double t) {
    return nearbyint((t - start) / interval);
}

static int is_sample_instant(double start, double interval, double t) {
    double k;
    if (t < start - 1e-12 * dmax(1.0, fabs(t))) return 0;
    k = instant_index(start, interval, t);
    return k >= 0.0 &&
           fabs(start + k * interval - t) <= 1e-12 * dmax(dmax(1.0, fabs(t)), interval);
}

static void segment(const double *times, const double *values, int a, int b, double *c0,
                    double *c1) {
    double dt = times[b] - times[a];
    if (dt <= 0.0) {
        *c0 = values[b];
        *c1 = 0.0;
        return;
    }
    *c1 = (values[b] - values[a]) / dt;
    *c0 = values[a] - *c1 * times[a];
}

/* (c0, c1, next breakpoint): table i equals c0 + c1*time from t (right limit) up to the next
   breakpoint after t; a time within a few ulps of a breakpoint is the breakpoint itself */
static void table_coefficients(const bgm_inst *c, int i, double t, double *c0, double *c1,
                               double *nxt) {
    const int n = c->tab_n[i];
    const double *times = c->tab_t[i], *values = c->tab_v[i];
    const int extrap = bgm_tab_extrap[i], hold = bgm_tab_hold[i];
    double t0 = times[0], t1 = times[n - 1];
    double eps = 1e-12 * dmax(dmax(1.0, fabs(t)), fabs(t1 - t0));
    double shift = 0.0, local = t, a0, a1;
    int j = 0;
    if (extrap == BGM_TAB_PERIODIC && t1 > t0 && (t < t0 - eps || t >= t1 - eps)) {
        double period = t1 - t0;
        double np_ = floor((t - t0) / period + eps / period);
        shift = np_ * period;
        local = t - shift;
    }
    while (j < n && times[j] <= local + eps) j++; /* times[j-1] <= local */
    if (j == 0) {
        *nxt = t0 + shift;
        if (extrap == BGM_TAB_LINEAR && n > 1 && !hold) segment(times, values, 0, 1, &a0, &a1);
        else {
            a0 = values[0];
            a1 = 0.0;
        }
    } else if (j >= n) {
        *nxt = EV_INF;
        if (extrap == BGM_TAB_LINEAR && n > 1 && !hold)
            segment(times, values, n - 2, n - 1, &a0, &a1);
        else {
            a0 = values[n - 1];
            a1 = 0.0;
        }
    } else {
        *nxt = times[j] + shift;
        if (hold) {
            a0 = values[j - 1];
            a1 = 0.0;
        } else
            segment(times, values, j - 1, j, &a0, &a1);
    }
    if (extrap == BGM_TAB_PERIODIC && *nxt == EV_INF) *nxt = t0 + shift + (t1 - t0);
    *c0 = a0 - a1 * shift;
    *c1 = a1;
}

static void ev_update_tables(bgm_inst *c, double t) {
    int i;
    double c0, c1, nxt;
    for (i = 0; i < BGM_NTAB; i++) {
        table_coefficients(c, i, t, &c0, &c1, &nxt);
        c->v.h.d[bgm_tab_c0[i]] = c0;
        c->v.h.d[bgm_tab_c1[i]] = c1;
    }
}

/* next time event strictly after t (samples, tables, relations on time alone) */
static double ev_next_time(bgm_inst *c, double t) {
    bgm_hyb_vars *h = &c->v.h;
    double best = EV_INF, ts, c0, c1;
    int i;
    for (i = 0; i < BGM_NSAMP; i++) {
        double start = h->samp[2 * i], interval = h->samp[2 * i + 1];
        /* an instant within rounding of t that was not handled yet is due now (a master's
           communication point k*H may differ by an ulp from the accumulated time) */
        ts = next_sample(start, interval, t - 1e-12 * dmax(dmax(1.0, fabs(t)), interval));
        /* an instant within rounding of the one just handled is that one */
        if (h->samp_set[i] && instant_index(start, interval, ts) == h->samp_last[i])
            ts = next_sample(start, interval, ts);
        best = dmin(best, dmax(ts, t));
    }
    for (i = 0; i < BGM_NTAB; i++) {
        table_coefficients(c, i, t, &c0, &c1, &ts);
        best = dmin(best, ts);
    }
    return dmin(best, h->time_next);
}

/* ------------------------------------------------------------------- event iteration */

/* relation values at an event instant: the sign of the indicator; for relations on time
   alone at their crossing, the right limit (the sign of the slope) */
static void ev_relation_values(bgm_inst *c, double t) {
    bgm_hyb_work *w = &c->hw;
    int k, j;
    for (k = 0; k < BGM_NREL; k++) w->vals[k] = rel_value(k, w->g[k]) ? 1.0 : 0.0;
    for (j = 0; j < BGM_NTREL; j++) {
        double a;
        k = bgm_time_rel[j];
        a = w->dgdt[k];
        if (a != 0.0 && fabs(w->g[k]) <= 1e-12 * fabs(a) * dmax(1.0, fabs(t)))
            w->vals[k] = a > 0.0 ? 1.0 : 0.0;
    }
}

static void ev_set_pre(bgm_inst *c) {
    int k;
    for (k = 0; k < BGM_NPRE; k++) c->v.h.d[bgm_pre_slot[k]] = c->hw.pre[k];
}

static void ev_schedule(bgm_inst *c, double t) {
    bgm_hyb_vars *h = &c->v.h;
    int j;
    h->time_next = EV_INF;
    for (j = 0; j < BGM_NTREL; j++) {
        int k = bgm_time_rel[j];
        double a = c->hw.dgdt[k], ts;
        int value;
        if (a == 0.0 || !isfinite(a)) continue;
        value = h->d[bgm_rel_slot[k]] != 0.0;
        if (value == (a > 0.0)) continue;
        ts = t - c->hw.g[k] / a;
        if (ts > t) h->time_next = dmin(h->time_next, ts);
    }
}

/* raise the clocks that tick at t (once per instant) */
static void ev_raise_clocks(bgm_inst *c, double t) {
    bgm_hyb_vars *h = &c->v.h;
    int i;
    for (i = 0; i < BGM_NSAMP; i++) {
        double start = h->samp[2 * i], interval = h->samp[2 * i + 1], k;
        if (!is_sample_instant(start, interval, t)) continue;
        k = instant_index(start, interval, t);
        if (h->samp_set[i] && h->samp_last[i] == k) continue;
        h->d[bgm_sample_slot[i]] = 1.0;
        h->samp_last[i] = k;
        h->samp_set[i] = 1;
        h->flags = 1;
    }
}

/* _note: chattering (Zeno) check */
static bgm_status ev_note(bgm_inst *c, const char *fn, double t) {
    bgm_hyb_vars *h = &c->v.h;
    h->recent[h->i_recent] = t;
    h->i_recent = (h->i_recent + 1) % BGM_EV_ZENO;
    if (h->n_recent < BGM_EV_ZENO) h->n_recent++;
    if (h->n_recent == BGM_EV_ZENO) {
        double span = t - h->recent[h->i_recent];
        if (span <= BGM_EV_ZENO_DT * dmax(1.0, fabs(t))) {
            bgm_error(c, "%s: chattering at t = %.12g s: %d events within %.3g s; the model "
                      "switches back and forth without time passing (Zeno behaviour). Add "
                      "hysteresis or a stuck/rest mode", fn, t, BGM_EV_ZENO, span);
            return BGM_ERROR;
        }
    }
    bgm_log(c, BGM_OK, "logEvents", "%s: event at t=%.17g", fn, t);
    return BGM_OK;
}

/* _event before the iteration: pre() takes the left limits, tables and clocks switch */
static bgm_status ev_begin(bgm_inst *c, const char *fn, int terminal) {
    bgm_hyb_vars *h = &c->v.h;
    double t = c->v.time;
    if (ev_note(c, fn, t) != BGM_OK) return BGM_ERROR;
    if (ev_step(c, t, c->v.x)) return ev_failed(c, fn, "event functions", t);
    ev_set_pre(c);
    ev_update_tables(c, t);
    ev_raise_clocks(c, t);
#if BGM_TERMINAL_SLOT >= 0
    if (terminal) h->d[BGM_TERMINAL_SLOT] = 1.0;
#else
    (void)terminal;
#endif
    h->phase = 1;
    h->iter = 0;
    c->cache_valid = 0;
    return BGM_OK;
}

/* one pass of _iterate; *again: something changed, another pass is needed */
static bgm_status ev_pass(bgm_inst *c, const char *fn, int *again) {
    bgm_hyb_vars *h = &c->v.h;
    bgm_hyb_work *w = &c->hw;
    double t = c->v.time;
    int fired[BGM_NCONDA];
    int k, j, b, moved = 0, fired_any = 0, n_changing = 0;
    w->changing[0] = '\0';
    *again = 0;
    if (ev_step(c, t, c->v.x)) return ev_failed(c, fn, "event functions", t);
    c->cache_valid = 0;
    ev_relation_values(c, t);
    for (k = 0; k < BGM_NREL; k++)
        if (w->vals[k] != h->d[bgm_rel_slot[k]]) {
            ev_note_change(c, bgm_rel_text[k], &n_changing);
            moved = 1;
        }
    if (moved) {
        for (k = 0; k < BGM_NREL; k++) h->d[bgm_rel_slot[k]] = w->vals[k];
        *again = 1;
        return BGM_OK;
    }
    /* rising edges: in each when-clause the first branch whose condition became true */
    memset(fired, 0, sizeof(fired));
    for (k = 0; k < BGM_NWHEN; k++)
        for (j = bgm_when_first[k]; j < bgm_when_first[k + 1]; j++) {
            b = bgm_when_branch[j];
            if (w->cond[b] != 0.0 && h->cond_pre[b] == 0.0) {
                fired[b] = 1;
                fired_any = 1;
                break;
            }
        }
    for (b = 0; b < BGM_NCOND; b++) h->cond_pre[b] = w->cond[b];
    if (BGM_NX > 0) memcpy(w->xnew, c->v.x, BGM_NX * sizeof(double));
    for (b = 0; b < BGM_NCOND; b++) {
        if (!fired[b]) continue;
        for (j = bgm_assign_first[b]; j < bgm_assign_first[b + 1]; j++) {
            int slot = bgm_assign_slot[j];
            double value = w->assign[bgm_assign_pos[j]];
            if (h->d[slot] != value) ev_note_change(c, bgm_d_names[slot], &n_changing);
            h->d[slot] = value;
        }
        for (j = bgm_reinit_first[b]; j < bgm_reinit_first[b + 1]; j++) {
            int s = bgm_reinit_state[j];
            w->xnew[s] = bgm_reinit_sign[j] * w->reinit[bgm_reinit_pos[j]];
            ev_note_change(c, bgm_var_names[BGM_VR_X + s], &n_changing);
            w->x_changed = 1;
        }
    }
    /* discrete variables defined by equations: pre() catches up with them */
    for (k = 0; k < BGM_NPRE; k++) {
        if (!bgm_pre_discrete[k]) continue;
        if (w->pre[k] != h->d[bgm_pre_slot[k]]) {
            ev_note_change(c, bgm_pre_names[k], &n_changing);
            h->d[bgm_pre_slot[k]] = w->pre[k];
        }
    }
    if (fired_any && BGM_NX > 0) memcpy(c->v.x, w->xnew, BGM_NX * sizeof(double));
    *again = n_changing > 0;
    return BGM_OK;
}

/* end of _iterate: clocks fall, initial() ends, conditions re-armed; time relations */
static bgm_status ev_finish(bgm_inst *c, const char *fn) {
    bgm_hyb_vars *h = &c->v.h;
    double t = c->v.time;
    int i;
    if (h->flags) {
        for (i = 0; i < BGM_NSAMP; i++) h->d[bgm_sample_slot[i]] = 0.0;
#if BGM_INITIAL_SLOT >= 0
        h->d[BGM_INITIAL_SLOT] = 0.0;
#endif
        if (ev_step(c, t, c->v.x)) return ev_failed(c, fn, "event functions", t);
        for (i = 0; i < BGM_NCOND; i++) h->cond_pre[i] = c->hw.cond[i];
        ev_set_pre(c);
        h->flags = 0;
    }
    ev_schedule(c, t);
    h->phase = 2;
    h->iter = 0;
    c->cache_valid = 0;
    return BGM_OK;
}

static bgm_status ev_no_convergence(bgm_inst *c, const char *fn) {
    bgm_error(c, "%s: event iteration at t = %g s did not converge after %d iterations: %s "
              "keep changing (a discrete equation without pre() feeding back on itself?)",
              fn, c->v.time, BGM_EV_MAX_ITER, c->hw.changing);
    return BGM_ERROR;
}

/* the whole iteration (initialization, Co-Simulation, terminal event) */
static bgm_status ev_converge(bgm_inst *c, const char *fn) {
    int again = 1;
    while (again) {
        if (ev_pass(c, fn, &again) != BGM_OK) return BGM_ERROR;
        if (again && ++c->v.h.iter >= BGM_EV_MAX_ITER) return ev_no_convergence(c, fn);
    }
    return ev_finish(c, fn);
}

/* ------------------------------------------------------------------------- public */

void bgm_hyb_defaults(bgm_inst *c) {
    bgm_hyb_vars *h = &c->v.h;
    memset(h, 0, sizeof(*h));
    memcpy(h->d, bgm_d_start, sizeof(h->d));
    h->time_next = EV_INF;
}

/* _initialize at ExitInitializationMode: relations from the start values, conditions true
   at the start do not fire, initial() and clocks ticking at the start time do */
bgm_status bgm_hyb_initialize(bgm_inst *c, const char *fn) {
    bgm_hyb_vars *h = &c->v.h;
    bgm_hyb_work *w = &c->hw;
    double t0 = c->v.time;
    int i, k, it;
    if (BGM_NSAMP > 0) {
        double *outs[1];
        outs[0] = w->samp;
        if (bgm_call_event(c, 2, t0, c->v.x, outs, 1))
            return ev_failed(c, fn, "sample intervals", t0);
        for (i = 0; i < BGM_NSAMP; i++) {
            double start = w->samp[2 * i], interval = w->samp[2 * i + 1];
            if (!(isfinite(start) && isfinite(interval) && interval > 0.0)) {
                bgm_error(c, "%s: sample(start=%g, interval=%g): the interval must be a "
                          "positive finite number", fn, start, interval);
                return BGM_ERROR;
            }
            h->samp[2 * i] = start;
            h->samp[2 * i + 1] = interval;
        }
    }
    h->time_next = EV_INF;
    h->n_recent = h->i_recent = 0;
    for (i = 0; i < BGM_NSAMP; i++) h->samp_set[i] = 0;
    ev_update_tables(c, t0);
    if (bgm_update_x0(c, fn) != BGM_OK) return BGM_ERROR;
    for (it = 0; it < BGM_EV_MAX_ITER; it++) {
        int same = 1;
        if (ev_step(c, t0, c->v.x)) return ev_failed(c, fn, "event functions", t0);
        ev_relation_values(c, t0);
        for (k = 0; k < BGM_NREL; k++)
            if (w->vals[k] != h->d[bgm_rel_slot[k]]) same = 0;
        if (same) break;
        for (k = 0; k < BGM_NREL; k++) h->d[bgm_rel_slot[k]] = w->vals[k];
#if BGM_HAS_INIT
        /* the consistent initial state for the new relation values */
        c->v.x0_done = 0;
        if (bgm_update_x0(c, fn) != BGM_OK) return BGM_ERROR;
#endif
    }
    if (ev_step(c, t0, c->v.x)) return ev_failed(c, fn, "event functions", t0);
    for (i = 0; i < BGM_NCOND; i++) h->cond_pre[i] = w->cond[i];
    ev_set_pre(c);
    h->flags = 0;
    ev_raise_clocks(c, t0);
#if BGM_INITIAL_SLOT >= 0
    h->d[BGM_INITIAL_SLOT] = 1.0;
    h->flags = 1;
#endif
    h->iter = 0;
    h->phase = 1;
    w->x_changed = 0;
    if (ev_converge(c, fn) != BGM_OK) return BGM_ERROR;
    h->initialized = 1;
    c->cache_valid = 0;
    return BGM_OK;
}

bgm_status bgm_hyb_enter_event(bgm_inst *c, const char *fn) {
    c->v.h.pending = 0;
    c->v.h_next = 0.0; /* Co-Simulation: restart the embedded solver after the event */
    if (!c->v.h.initialized) return BGM_OK;
    return ev_begin(c, fn, 0);
}

bgm_status bgm_hyb_update(bgm_inst *c, const char *fn, int *need_update, int *x_changed,
                          int *next_defined, double *next_time) {
    bgm_hyb_vars *h = &c->v.h;
    int again = 0;
    *need_update = 0;
    *x_changed = 0;
    *next_defined = 0;
    *next_time = 0.0;
    if (h->phase == 0) h->phase = 2;  /* no event started: a pass that changes nothing */
    c->hw.x_changed = 0;
    if (ev_pass(c, fn, &again) != BGM_OK) return BGM_ERROR;
    *x_changed = c->hw.x_changed;
    if (again) {
        if (++h->iter >= BGM_EV_MAX_ITER) return ev_no_convergence(c, fn);
        *need_update = 1;
        return BGM_OK;
    }
    if (ev_finish(c, fn) != BGM_OK) return BGM_ERROR;
    *next_time = ev_next_time(c, c->v.time);
    if (isfinite(*next_time)) *next_defined = 1;
    else *next_time = 0.0;
    return BGM_OK;
}

bgm_status bgm_hyb_terminate(bgm_inst *c, const char *fn) {
#if BGM_TERMINAL_SLOT >= 0
    if (!c->v.h.initialized) return BGM_OK;
    if (ev_begin(c, fn, 1) != BGM_OK) return BGM_ERROR;
    return ev_converge(c, fn);
#else
    (void)c;
    (void)fn;
    return BGM_OK;
#endif
}

bgm_status bgm_hyb_event_indicators(bgm_inst *c, const char *fn, double z[], size_t ni) {
    if (!bgm_check_kind(c, fn, BGM_KIND_ME)) return BGM_ERROR;
    if (!bgm_check(c, fn, BGM_MODE_INIT | BGM_MODE_EVENT | BGM_MODE_CONT | BGM_MODE_TERMINATED))
        return BGM_ERROR;
    if (ni != (size_t)BGM_NZ) {
        bgm_error(c, "%s: the model has %d event indicators, %lu requested", fn, BGM_NZ,
                  (unsigned long)ni);
        return BGM_ERROR;
    }
    if (ni == 0) return BGM_OK;
    if (!z) {
        bgm_error(c, "%s: NULL array argument", fn);
        return BGM_ERROR;
    }
    if (ev_ind(c, c->v.time, c->v.x, z)) return ev_failed(c, fn, "event indicators", c->v.time);
    ev_fmi_sign(z);
    return BGM_OK;
}

/* ------------------------------------------------------------------- Co-Simulation */

/* after a completed integrator step: the pre() slots that follow their sources between
   events (BGM_PRE_TRACKS: the Newton guesses of dynamic state selection) take their values */
void bgm_hyb_track(bgm_inst *c, double t, const double *x) {
#if BGM_PRE_TRACKS
    if (!c->v.h.initialized || ev_step(c, t, x)) return;
    ev_set_pre(c);
    c->cache_valid = 0;
#else
    (void)c;
    (void)t;
    (void)x;
#endif
}

/* called by the solver after each accepted step (before it is committed) */
int bgm_hyb_step_check(bgm_inst *c, double t0, const double *x0, double t1, const double *x1) {
    bgm_hyb_work *w = &c->hw;
    if (!w->check || BGM_NZ == 0) return 0;
    bgm_hyb_track(c, t1, x1);
    if (ev_ind(c, t1, x1, w->hi_g) || !ev_changed(c, w->hi_g)) return 0;
    if (ev_ind(c, t0, x0, w->lo_g)) return 0;
    w->lo_t = t0;
    w->hi_t = t1;
    if (BGM_NX > 0) {
        memcpy(w->lo_x, x0, BGM_NX * sizeof(double));
        memcpy(w->hi_x, x1, BGM_NX * sizeof(double));
    }
    w->crossed = 1;
    return 1;
}

/* an interval of a few ulps of t: the states do not move (the solver cannot step it) */
static int ev_negligible(double t0, double t1) {
    return t1 - t0 <= 1e-14 * dmax(1.0, fabs(t0));
}

/* states at t1 from (t0, x0): the embedded solver, starting with one step */
static bgm_status ev_integrate_one(bgm_inst *c, const char *fn, double t0, const double *x0,
                                   double t1, double *x1) {
    bgm_hyb_work *w = &c->hw;
    double h_save = c->v.h_next;
    int check = w->check;
    bgm_status st = BGM_OK;
    c->v.time = t0;
    if (BGM_NX > 0) memcpy(c->v.x, x0, BGM_NX * sizeof(double));
    c->v.h_next = t1 - t0;
    w->check = 0;
    if (ev_negligible(t0, t1)) c->v.time = t1;
    else st = bgm_integrate(c, fn, t1);
    w->check = check;
    if (BGM_NX > 0) memcpy(x1, c->v.x, BGM_NX * sizeof(double));
    c->v.h_next = h_save;
    return st;
}

/* _locate: Illinois iteration on the earliest crossing indicator of the bracket */
static bgm_status ev_locate(bgm_inst *c, const char *fn) {
    bgm_hyb_work *w = &c->hw;
    double lo = w->lo_t, hi = w->hi_t;
    double tol = BGM_EV_TOL * dmax(1.0, fabs(hi));
    double widths[402];
    int nw = 0, side = 0, it, k;
    widths[nw++] = hi - lo;
    for (it = 0; it < 400; it++) {
        double cand = hi, margin;
        if (hi - lo <= tol) break;
        for (k = 0; k < BGM_NZ; k++) {
            int r = bgm_state_rel[k];
            if ((double)rel_value(r, w->hi_g[k]) != c->v.h.d[bgm_rel_slot[r]]) {
                double a = w->lo_g[k], b = w->hi_g[k];
                if (a != b) cand = dmin(cand, lo + (hi - lo) * a / (a - b));
            }
        }
        margin = 0.1 * tol;
        cand = dmin(dmax(cand, lo + margin), hi - margin);
        /* bisect when the bracket did not halve over the last three steps */
        if (!(lo < cand && cand < hi) || (nw > 3 && widths[nw - 1] > 0.5 * widths[nw - 4]))
            cand = 0.5 * (lo + hi);
        if (ev_integrate_one(c, fn, lo, w->lo_x, cand, w->xc) != BGM_OK) return BGM_ERROR;
        if (ev_ind(c, cand, w->xc, w->zc)) return ev_failed(c, fn, "event indicators", cand);
        if (ev_changed(c, w->zc)) {
            hi = cand;
            if (BGM_NX > 0) memcpy(w->hi_x, w->xc, BGM_NX * sizeof(double));
            memcpy(w->hi_g, w->zc, sizeof(w->hi_g));
            if (side == 1)
                for (k = 0; k < BGM_NZ; k++) w->lo_g[k] *= 0.5;
            side = 1;
        } else {
            lo = cand;
            if (BGM_NX > 0) memcpy(w->lo_x, w->xc, BGM_NX * sizeof(double));
            memcpy(w->lo_g, w->zc, sizeof(w->lo_g));
            if (side == -1)
                for (k = 0; k < BGM_NZ; k++) w->hi_g[k] *= 0.5;
            side = -1;
        }
        widths[nw++] = hi - lo;
    }
    c->v.time = hi;
    if (BGM_NX > 0) memcpy(c->v.x, w->hi_x, BGM_NX * sizeof(double));
    c->cache_valid = 0;
    return BGM_OK;
}

/* DoStep's integration from c->v.time to t_end with events (see the file comment). */
bgm_status bgm_hyb_integrate(bgm_inst *c, const char *fn, double t_end) {
    bgm_hyb_work *w = &c->hw;
    w->event_needed = 0;
    if (c->v.h.pending) {
        /* the importer did not enter Event Mode for the last event: handle it here */
        c->v.h.pending = 0;
        if (ev_begin(c, fn, 0) != BGM_OK || ev_converge(c, fn) != BGM_OK) return BGM_ERROR;
        c->v.h_next = 0.0;
    }
    if (BGM_NZ > 0 && t_end > c->v.time) {
        /* inputs (or parameters) set since the last step moved a relation: an event now */
        if (ev_ind(c, c->v.time, c->v.x, w->zc))
            return ev_failed(c, fn, "event indicators", c->v.time);
        if (ev_changed(c, w->zc)) {
            if (ev_begin(c, fn, 0) != BGM_OK || ev_converge(c, fn) != BGM_OK) return BGM_ERROR;
            c->v.h_next = 0.0;
        }
    }
    while (c->v.time < t_end) {
        double t = c->v.time, t_ev = ev_next_time(c, t), target = t_end;
        int time_event = 0;
        bgm_status st;
        if (t_ev <= t_end) {
            target = t_ev;
            time_event = 1;
        }
        w->crossed = 0;
        w->check = BGM_NZ > 0;
        if (ev_negligible(t, target)) {
            c->v.time = target;
            st = BGM_OK;
        } else {
            st = bgm_integrate(c, fn, target);
        }
        if (st == BGM_OK && BGM_NX == 0 && BGM_NZ > 0 && !w->crossed)
            bgm_hyb_step_check(c, t, c->v.x, target, c->v.x);
        w->check = 0;
        if (st != BGM_OK) return st;
        if (w->crossed) {
            if (ev_locate(c, fn) != BGM_OK) return BGM_ERROR;
        } else if (time_event) {
            c->v.time = t_ev;
        } else {
            break;
        }
        /* an event at c->v.time */
        if (c->event_mode_used && (c->early_return_allowed || c->v.time >= t_end)) {
            w->event_needed = 1;   /* handled by the importer in Event Mode */
            c->v.h.pending = 1;
            return BGM_OK;
        }
        if (ev_begin(c, fn, 0) != BGM_OK || ev_converge(c, fn) != BGM_OK) return BGM_ERROR;
        c->v.h_next = 0.0;         /* restart the solver after the event */
        if (c->early_return_allowed && c->v.time < t_end) return BGM_OK;
    }
    return BGM_OK;
}

/* ------------------------------------------------------------- discrete variables */

static const char *const dv_type_names[3] = {"Real", "Integer", "Boolean"};

bgm_status bgm_hyb_value(bgm_inst *c, const char *fn, int kind, size_t i, int type,
                         int *evaluated, double *value) {
    if (kind == BGM_VAR_DISCRETE) {
        if (bgm_dv_type[i] != type) {
            bgm_error(c, "%s: %s is a%s %s variable, not %s", fn,
                      bgm_var_names[BGM_VR_D + i], bgm_dv_type[i] == BGM_DV_INTEGER ? "n" : "",
                      dv_type_names[bgm_dv_type[i]], dv_type_names[type]);
            return BGM_ERROR;
        }
        if (bgm_dv_slot[i] >= 0) {
            *value = c->v.h.d[bgm_dv_slot[i]];
            return BGM_OK;
        }
        if (!(*evaluated & 1)) {
            if (ev_step(c, c->v.time, c->v.x))
                return ev_failed(c, fn, "discrete variables", c->v.time);
            *evaluated |= 1;
        }
        *value = c->hw.dv[i];
        return BGM_OK;
    }
    if (kind == BGM_VAR_INDICATOR && type == BGM_DV_REAL) {
        if (!(*evaluated & 2)) {
            if (ev_ind(c, c->v.time, c->v.x, c->hw.z))
                return ev_failed(c, fn, "event indicators", c->v.time);
            ev_fmi_sign(c->hw.z);
            *evaluated |= 2;
        }
        *value = c->hw.z[i];
        return BGM_OK;
    }
    bgm_error(c, "%s: value reference is not a %s variable", fn, dv_type_names[type]);
    return BGM_ERROR;
}

int bgm_hyb_check_set(bgm_inst *c, const char *fn, size_t i, int type, double value) {
    unsigned vr = (unsigned)(BGM_VR_D + i);
    if (bgm_dv_type[i] != type) {
        bgm_error(c, "%s: %s is a%s %s variable, not %s", fn, bgm_var_names[vr],
                  bgm_dv_type[i] == BGM_DV_INTEGER ? "n" : "", dv_type_names[bgm_dv_type[i]],
                  dv_type_names[type]);
        return 0;
    }
    if (bgm_dv_slot[i] < 0) {
        bgm_error(c, "%s: discrete variable %s (value reference %u) is calculated and cannot "
                  "be set", fn, bgm_var_names[vr], vr);
        return 0;
    }
    if (!(c->v.mode & (BGM_MODE_INSTANTIATED | BGM_MODE_INIT))) {
        bgm_error(c, "%s: the start value of discrete variable %s can only be set before the "
                  "end of initialization, not in %s", fn, bgm_var_names[vr],
                  bgm_mode_name(c->v.mode));
        return 0;
    }
    if (!isfinite(value)) {
        bgm_error(c, "%s: value %g for %s is not finite; the value is not set", fn, value,
                  bgm_var_names[vr]);
        return 0;
    }
    return 1;
}

void bgm_hyb_set(bgm_inst *c, size_t i, double value) {
    c->v.h.d[bgm_dv_slot[i]] = value;
    c->cache_valid = 0;
}

/* typed access (Integer/Int32: int; Boolean: int, or one byte when bool_byte) */
bgm_status bgm_hyb_get_typed(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                             int type, int bool_byte, void *values) {
    size_t k, i;
    int evaluated = 0;
    double v;
    if (!bgm_check(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (n == 0) return BGM_OK;
    if (!vr || !values) {
        bgm_error(c, "%s: NULL array argument", fn);
        return BGM_ERROR;
    }
    for (k = 0; k < n; k++) {
        int kind = bgm_classify(vr[k], &i);
        if (kind != BGM_VAR_DISCRETE) {
            if (kind == BGM_VAR_NONE) bgm_error(c, "%s: unknown value reference %u", fn, vr[k]);
            else bgm_error(c, "%s: %s (value reference %u) is not a%s %s variable", fn,
                           bgm_var_names[vr[k]], vr[k], type == BGM_DV_INTEGER ? "n" : "",
                           dv_type_names[type]);
            return BGM_ERROR;
        }
        if (bgm_hyb_value(c, fn, kind, i, type, &evaluated, &v) != BGM_OK) return BGM_ERROR;
        if (type == BGM_DV_BOOLEAN && bool_byte) ((unsigned char *)values)[k] = v != 0.0;
        else if (type == BGM_DV_BOOLEAN) ((int *)values)[k] = v != 0.0;
        else ((int *)values)[k] = (int)v;
    }
    return BGM_OK;
}

bgm_status bgm_hyb_set_typed(bgm_inst *c, const char *fn, const unsigned vr[], size_t n,
                             int type, int bool_byte, const void *values) {
    size_t k, i;
    if (!bgm_check(c, fn, BGM_MODE_ANY)) return BGM_ERROR;
    if (n == 0) return BGM_OK;
    if (!vr || !values) {
        bgm_error(c, "%s: NULL array argument", fn);
        return BGM_ERROR;
    }
    for (k = 0; k < n; k++) {
        int kind = bgm_classify(vr[k], &i);
        double v = type == BGM_DV_BOOLEAN
                       ? (bool_byte ? (double)(((const unsigned char *)values)[k] != 0)
                                    : (double)(((const int *)values)[k] != 0))
                       : (double)((const int *)values)[k];
        if (kind != BGM_VAR_DISCRETE) {
            if (kind == BGM_VAR_NONE) bgm_error(c, "%s: unknown value reference %u", fn, vr[k]);
            else bgm_error(c, "%s: %s (value reference %u) is not a%s %s variable", fn,
                           bgm_var_names[vr[k]], vr[k], type == BGM_DV_INTEGER ? "n" : "",
                           dv_type_names[type]);
            return BGM_ERROR;
        }
        if (!bgm_hyb_check_set(c, fn, i, type, v)) return BGM_ERROR;
    }
    for (k = 0; k < n; k++) {
        double v = type == BGM_DV_BOOLEAN
                       ? (bool_byte ? (double)(((const unsigned char *)values)[k] != 0)
                                    : (double)(((const int *)values)[k] != 0))
                       : (double)((const int *)values)[k];
        bgm_classify(vr[k], &i);
        bgm_hyb_set(c, i, v);
    }
    return BGM_OK;
}

#else
typedef int bgm_events_unused; /* ISO C: no empty translation unit */
#endif

/* ------------------------------------------------------------- tables from resources */

/* the compiled-in tables */
void bgm_tables_init(bgm_inst *c) {
    int i;
    for (i = 0; i < BGM_NTAB; i++) {
        c->tab_t[i] = bgm_tab_times + bgm_tab_first[i];
        c->tab_v[i] = bgm_tab_values + bgm_tab_first[i];
        c->tab_n[i] = bgm_tab_first[i + 1] - bgm_tab_first[i];
        c->tab_buf[i] = NULL;
    }
}

void bgm_tables_free(bgm_inst *c) {
    int i;
    for (i = 0; i < BGM_NTAB; i++) {
        free(c->tab_buf[i]);
        c->tab_buf[i] = NULL;
    }
}

/* the next comma-separated field of *s (trimmed, quotes removed) into out */
static int csv_field(const char **s, char *out, size_t size) {
    const char *p = *s, *end;
    size_t n;
    if (*p == '\0' || *p == '\n' || *p == '\r') return 0;
    end = p;
    while (*end && *end != ',' && *end != '\n' && *end != '\r') end++;
    while (p < end && (*p == ' ' || *p == '"')) p++;
    n = (size_t)(end - p);
    while (n > 0 && (p[n - 1] == ' ' || p[n - 1] == '"')) n--;
    if (n >= size) n = size - 1;
    memcpy(out, p, n);
    out[n] = '\0';
    *s = *end == ',' ? end + 1 : end;
    return 1;
}

/* one table from "<resources>/<file>": a header row whose first column is time, then rows */
static int load_table(bgm_inst *c, int i, const char *dir) {
    char path[4096], field[256], line[8192];
    FILE *f;
    int col = -1, k, rows = 0, cap = 64;
    double *buf;
    const char *s;
    snprintf(path, sizeof path, "%s%s%s", dir, (dir[0] && dir[strlen(dir) - 1] != '/') ? "/" : "",
             bgm_tab_file[i]);
    f = fopen(path, "r");
    if (!f) {
        bgm_log(c, BGM_ERROR, "logStatusError", "time table: cannot open the resource file %s",
                path);
        return 1;
    }
    if (!fgets(line, sizeof line, f)) {
        fclose(f);
        bgm_log(c, BGM_ERROR, "logStatusError", "time table: %s is empty", path);
        return 1;
    }
    s = line;
    for (k = 0; csv_field(&s, field, sizeof field); k++) {
        if (k == 0 && strcmp(field, "time") != 0) break;
        if (strcmp(field, bgm_tab_column[i]) == 0) col = k;
    }
    if (col <= 0) {
        fclose(f);
        bgm_log(c, BGM_ERROR, "logStatusError",
                "time table: %s needs a first column 'time' and a column '%s'", path,
                bgm_tab_column[i]);
        return 1;
    }
    buf = (double *)malloc(2 * (size_t)cap * sizeof(double));
    while (buf && fgets(line, sizeof line, f)) {
        double t = 0.0, v = 0.0;
        int got = 0;
        char *end;
        s = line;
        for (k = 0; csv_field(&s, field, sizeof field) && k <= col; k++) {
            if (k != 0 && k != col) continue;
            if (k == 0) t = strtod(field, &end);
            else v = strtod(field, &end);
            if (end == field || *end != '\0' || t != t || v != v) {
                got = -1;
                break;
            }
            got++;
        }
        if (got == 0) continue;              /* a blank line */
        if (got != 2 || (rows > 0 && t < buf[2 * (rows - 1)])) {
            bgm_log(c, BGM_ERROR, "logStatusError", "time table: %s row %d: %s", path,
                    rows + 2, got != 2 ? "not two numbers in time and the column"
                                       : "time decreases");
            free(buf);
            fclose(f);
            return 1;
        }
        if (rows == cap) {
            double *more = (double *)realloc(buf, 4 * (size_t)cap * sizeof(double));
            if (!more) break;
            buf = more;
            cap *= 2;
        }
        buf[2 * rows] = t;
        buf[2 * rows + 1] = v;
        rows++;
    }
    fclose(f);
    if (!buf || rows == 0) {
        free(buf);
        bgm_log(c, BGM_ERROR, "logStatusError", "time table: %s has no data rows", path);
        return 1;
    }
    /* split into times and values */
    c->tab_buf[i] = (double *)malloc(2 * (size_t)rows * sizeof(double));
    if (!c->tab_buf[i]) {
        free(buf);
        return 1;
    }
    for (k = 0; k < rows; k++) {
        c->tab_buf[i][k] = buf[2 * k];
        c->tab_buf[i][rows + k] = buf[2 * k + 1];
    }
    free(buf);
    c->tab_t[i] = c->tab_buf[i];
    c->tab_v[i] = c->tab_buf[i] + rows;
    c->tab_n[i] = rows;
    bgm_log(c, BGM_OK, "logEvents", "time table: %d rows of '%s' from %s", rows,
            bgm_tab_column[i], path);
    return 0;
}

/* Tables declared from files are read from the FMU's resources folder; a failure (logged)
   returns nonzero. ``dir``: the folder (NULL or "": no tables from files can be read). */
int bgm_tables_load(bgm_inst *c, const char *dir) {
    int i;
    for (i = 0; i < BGM_NTAB; i++) {
        if (!bgm_tab_file[i][0]) continue;
        if (!dir || !dir[0]) {
            bgm_log(c, BGM_ERROR, "logStatusError",
                    "time table: the resource location is unknown; cannot read %s",
                    bgm_tab_file[i]);
            return 1;
        }
        if (load_table(c, i, dir)) return 1;
    }
    return 0;
}

/* FMI 2.0 fmuResourceLocation (a URI: file:///C:/x, file:/x, file://host/x) as a path;
   percent-escapes decoded. Anything else is taken as a path. */
void bgm_resource_dir(const char *uri, char *out, size_t size) {
    const char *p = uri ? uri : "";
    size_t n = 0;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (*p != '/') {                       /* file://host/path: skip the host */
            while (*p && *p != '/') p++;
        }
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;
    }
    while (*p && n + 1 < size) {
        if (p[0] == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            out[n++] = (char)strtol(hex, NULL, 16);
            p += 3;
        } else {
            out[n++] = *p++;
        }
    }
    out[n] = '\0';
}
