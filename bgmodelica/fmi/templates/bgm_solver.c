/*
 * bgmodelica FMU runtime: the implicit solver embedded in Co-Simulation FMUs.
 *
 * Method: variable-order (1..5), variable-step backward differentiation formulas in the
 * quasi-constant step-size form of Shampine & Reichelt (the numerical differentiation
 * formulas, NDF, of "The MATLAB ODE Suite", SIAM J. Sci. Comput. 18, 1997, with Klopfenstein's
 * kappa coefficients): the solution history is a table D of backward differences at spacing
 * h, re-expressed exactly for a new step size when h changes.  Each step predicts from D,
 * corrects with a simplified Newton iteration on (I - c J) with c = h / alpha[order] (one
 * LU inside the Jacobian's band, bgm_lu.c, reused over steps while it converges;
 * J = d(xdot)/dx from the CasADi-generated Jacobian, re-evaluated only when Newton stalls),
 * and estimates the local error from the corrector's update.  After order+1 steps at the
 * same size the order and size change to whichever of order-1, order, order+1 allows the
 * largest step.
 *
 * Between DoStep calls the history is kept when nothing changed (time, states, inputs up to
 * rounding, parameters, tolerance): a step may then run past the communication point and the
 * state there is interpolated from D, so communication points do not cut the solver's steps.
 * New inputs are a jump of the right-hand side (they are held over each communication step)
 * that the history must not straddle: that step is taken by the one-step SDIRK4 of
 * bgm_sdirk.c instead, which needs no history (a restart at order 1 would need many small
 * steps, every step, in a co-simulation).  New parameters, set states, an event or a Reset
 * restart the BDF at order 1.  The history is part of the FMU state: a restored state repeats the same
 * steps.  Hybrid models stop every step at the event or communication time instead (their
 * relations are checked over each step).
 */
#include <math.h>
#include <string.h>

#include "bgm_core.h"

#define MAX_ORDER 5
#define NEWTON_MAXITER 4
#define MIN_FACTOR 0.2
#define MAX_FACTOR 10.0
#define MAX_SUBSTEPS 1000000L
#define EPS 2.220446049250313e-16

/* NDF coefficients: kappa, gamma_k = sum_{j<=k} 1/j, alpha = (1 - kappa) gamma, and the
   error constants kappa gamma + 1/(k+1) */
static const double KAPPA[MAX_ORDER + 1] = {0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0};
static double GAMMA[MAX_ORDER + 2], ALPHA[MAX_ORDER + 1], ERRC[MAX_ORDER + 2];
static int coefficients_ready = 0;

static void init_coefficients(void) {
    int k;
    GAMMA[0] = 0.0;
    for (k = 1; k <= MAX_ORDER + 1; k++) GAMMA[k] = GAMMA[k - 1] + 1.0 / k;
    for (k = 0; k <= MAX_ORDER; k++) {
        ALPHA[k] = (1.0 - KAPPA[k]) * GAMMA[k];
        ERRC[k] = KAPPA[k] * GAMMA[k] + 1.0 / (k + 1);
    }
    ERRC[MAX_ORDER + 1] = 1.0 / (MAX_ORDER + 2);
    coefficients_ready = 1;
}

/* workspace: the BDF's LU and 9 vectors (its history is FMU state, bgm_core.h), or
   SDIRK4's 13 vectors and two matrices (bgm_sdirk.c); the two never run at once */
size_t bgm_solver_workspace(void) {
    size_t n = BGM_NXA;
    return 13 * n + 2 * n * n;
}

/* root mean square of v ./ sc */
double bgm_wnorm(const double *v, const double *sc, int n) {
    double s = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        double q = v[i] / sc[i];
        s += q * q;
    }
    return n > 0 ? sqrt(s / n) : 0.0;
}

/* D[0..order] <- the same interpolating polynomial as differences at spacing factor * h:
   D <- (R U)^T D with R = R(order, factor), U = R(order, 1) (Shampine & Reichelt, eq. 2.3) */
static void change_d(double *D, int order, double factor, int n) {
    double R[MAX_ORDER + 1][MAX_ORDER + 1], U[MAX_ORDER + 1][MAX_ORDER + 1];
    double tmp[MAX_ORDER + 1];
    double RU[MAX_ORDER + 1][MAX_ORDER + 1];
    int i, j, k, q = order + 1;
    for (k = 0; k < 2; k++) {
        double (*M)[MAX_ORDER + 1] = k == 0 ? R : U;
        double f = k == 0 ? factor : 1.0;
        for (j = 0; j < q; j++) M[0][j] = 1.0;
        for (i = 1; i < q; i++) {
            M[i][0] = 0.0;
            for (j = 1; j < q; j++) M[i][j] = M[i - 1][j] * (i - 1 - f * j) / i;
        }
    }
    for (i = 0; i < q; i++)
        for (j = 0; j < q; j++) {
            double acc = 0.0;
            for (k = 0; k < q; k++) acc += R[i][k] * U[k][j];
            RU[i][j] = acc;
        }
    for (k = 0; k < n; k++) {
        for (j = 0; j < q; j++) {
            double acc = 0.0;
            for (i = 0; i < q; i++) acc += RU[i][j] * D[i * n + k];
            tmp[j] = acc;
        }
        for (j = 0; j < q; j++) D[j * n + k] = tmp[j];
    }
}

/* y(t) from the difference table (newest point t_new, spacing h, current order) */
static void interpolate(const double *D, int order, double t_new, double h, double t, int n,
                        double *y) {
    double p[MAX_ORDER];
    int i, j;
    double acc = 1.0;
    for (j = 0; j < order; j++) {
        acc *= (t - (t_new - h * j)) / (h * (j + 1));
        p[j] = acc;
    }
    for (i = 0; i < n; i++) {
        double v = D[i];
        for (j = 1; j <= order; j++) v += D[j * n + i] * p[j - 1];
        y[i] = v;
    }
}

static int same(const double *a, const double *b, size_t n) {
    return n == 0 || memcmp(a, b, n * sizeof(double)) == 0;
}

/* equal up to rounding (an importer's interpolation of a constant signal) */
static int nearly_same(const double *a, const double *b, size_t n) {
    size_t i;
    for (i = 0; i < n; i++)
        if (fabs(a[i] - b[i]) > 4.0 * EPS * (fabs(a[i]) > 1.0 ? fabs(a[i]) : 1.0)) return 0;
    return 1;
}

/* first step size at order 1 from (t0, y0) with y0' = f (Hairer, Norsett & Wanner I, II.4):
   h0 from |y| / |y'|, h1 from an estimate of y''; the proposal (if any) caps it; -1 when the
   model cannot be evaluated */
static double initial_step(bgm_inst *c, double t0, const double *y0, const double *f,
                           double rtol, double hmax, double *sc, double *tmp, double *dy) {
    const int n = BGM_NX;
    double h0, h1, h, d0, d1, d2;
    int i;
    for (i = 0; i < n; i++) sc[i] = rtol * bgm_x_nominal[i] + rtol * fabs(y0[i]);
    d0 = bgm_wnorm(y0, sc, n);
    d1 = bgm_wnorm(f, sc, n);
    h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (h0 > hmax) h0 = hmax;
    for (i = 0; i < n; i++) tmp[i] = y0[i] + h0 * f[i];
    if (bgm_call_xdot(c, t0 + h0, tmp, dy)) return -1.0;
    for (i = 0; i < n; i++) dy[i] = (dy[i] - f[i]) / h0;
    d2 = bgm_wnorm(dy, sc, n);
    h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? (h0 * 1e-3 > 1e-6 ? h0 * 1e-3 : 1e-6)
                                      : sqrt(0.01 / (d1 > d2 ? d1 : d2));
    h = 100.0 * h0 < h1 ? 100.0 * h0 : h1;
    if (c->v.h_next > 0.0 && c->v.h_next < h) h = c->v.h_next;
    return h;
}

/* remember where this step ended: the next one continues from here unless things changed */
static void keep_snapshot(bgm_inst *c, double rtol) {
    bgm_bdf *b = &c->v.bdf;
    b->snap_ok = 1;
    b->snap_time = c->v.time;
    b->snap_tol = rtol;
    memcpy(b->snap_x, c->v.x, BGM_NX * sizeof(double));
    if (BGM_NU > 0) memcpy(b->snap_u, c->v.u, BGM_NU * sizeof(double));
    if (BGM_NP > 0) memcpy(b->snap_p, c->v.p, BGM_NP * sizeof(double));
}

bgm_status bgm_integrate(bgm_inst *c, const char *fn, double t_end) {
    const int n = BGM_NX;
    bgm_bdf *b = &c->v.bdf;
    double *D = b->d, *J = b->jac, *LU = c->ws, *ypred = LU + BGM_NXA * BGM_NXA;
    double *psi = ypred + BGM_NXA, *d = psi + BGM_NXA, *ynew = d + BGM_NXA, *f = ynew + BGM_NXA;
    double *dy = f + BGM_NXA, *sc = dy + BGM_NXA, *tmp = sc + BGM_NXA, *y0 = tmp + BGM_NXA;
    double rtol = c->v.solver_tol, hmax = c->v.solver_hmax, newton_tol, newton_floor, t_bound;
    long substeps = 0;
#if BGM_HYBRID
    const int overshoot = 0;
#else
    const int overshoot = 1;
#endif
    int i, j;
    const char *why = "";

    if (!coefficients_ready) init_coefficients();
    if (c->exp_tol_defined && c->exp_tol > 0.0 && c->exp_tol < rtol) rtol = c->exp_tol;
    if (n == 0) {
        c->v.time = t_end;
        c->cache_valid = 0;
        return BGM_OK;
    }
    newton_tol = sqrt(rtol) < 0.03 ? sqrt(rtol) : 0.03;
    if (newton_tol < 10.0 * EPS / rtol) newton_tol = 10.0 * EPS / rtol;
    newton_floor = 100.0 * EPS / rtol < 1e-3 * newton_tol ? 100.0 * EPS / rtol
                                                          : 1e-3 * newton_tol;
    /* steps may pass t_end (not in hybrid models), whatever the importer's stop time */
    t_bound = overshoot ? INFINITY : t_end;

    /* continue the history (a step may already have passed the communication point); after
       new inputs take this step with SDIRK4 (bgm_sdirk.c); otherwise restart at order 1 */
    {
        double tscale = fabs(c->v.time) > 1.0 ? fabs(c->v.time) : 1.0;
        int at_snap = b->snap_ok && c->v.h_next > 0.0 && b->snap_tol == rtol &&
                      fabs(b->snap_time - c->v.time) <= 1e-11 * tscale &&
                      same(b->snap_x, c->v.x, n) && same(b->snap_p, c->v.p, BGM_NP);
        int new_inputs = at_snap && !nearly_same(b->snap_u, c->v.u, BGM_NU);
        if (new_inputs) {
            bgm_status st = bgm_sdirk_integrate(c, fn, t_end);
            b->valid = 0;
            c->lu_ok = 0;  /* SDIRK4 used the workspace */
            b->snap_ok = st == BGM_OK && c->v.time == t_end;
            if (b->snap_ok) keep_snapshot(c, rtol);
            return st;
        }
        if (!(at_snap && b->valid && b->t >= b->snap_time && b->t <= t_bound)) {
            double t0 = c->v.time;
            b->valid = 0;
            b->snap_ok = 0;
            memcpy(y0, c->v.x, n * sizeof(double));
            if (bgm_call_xdot(c, t0, y0, f)) goto eval_failed;
            b->h = initial_step(c, t0, y0, f, rtol, hmax, sc, tmp, dy);
            if (b->h < 0.0) goto eval_failed;
            if (b->h > hmax) b->h = hmax;
            if (bgm_call_jacx(c, t0, y0, J)) goto eval_failed;
            b->jac_fresh = 1;
            memcpy(D, y0, n * sizeof(double));
            for (i = 0; i < n; i++) D[n + i] = f[i] * b->h;
            for (i = 2 * n; i < BGM_BDF_ROWS * n; i++) D[i] = 0.0;
            b->t = t0;
            b->order = 1;
            b->n_equal = 0;
            c->lu_ok = 0;
            b->valid = 1;
        }
    }

    /* (a remainder of a few ulps of t_end is interpolated, not stepped) */
    while (t_end - b->t > 10.0 * EPS * (fabs(t_end) > 1.0 ? fabs(t_end) : 1.0)) {
        double h, t_new, c_coef, err_norm, safety, hmin;
        int order = b->order, converged = 0, n_iter = 0, clipped = 0;
        double h_natural = b->h;

        if (++substeps > MAX_SUBSTEPS) {
            bgm_error(c, "%s: more than %ld internal steps in one communication step at t=%g",
                      fn, MAX_SUBSTEPS, b->t);
            goto fail;
        }
        if (b->h > hmax) {
            change_d(D, order, hmax / b->h, n);
            b->h = hmax;
            b->n_equal = 0;
            c->lu_ok = 0;
            h_natural = hmax;
        }
        hmin = 10.0 * EPS * (fabs(b->t) > 1.0 ? fabs(b->t) : 1.0);
        if (b->t + b->h > t_bound || (!overshoot && b->t + 1.01 * b->h >= t_bound)) {
            double hb = t_bound - b->t;
            change_d(D, order, hb / b->h, n);
            b->h = hb;
            c->lu_ok = 0;
            clipped = 1;
        }
        if (b->h < hmin) {
            bgm_error(c, "%s: step size %g too small at t=%.17g (%s); the model may be "
                      "singular or need a looser solver.tolerance", fn, b->h, b->t, why);
            goto fail;
        }
        h = b->h;
        t_new = clipped ? t_bound : b->t + h;

        /* predictor, and psi = sum gamma_k D_k / alpha */
        for (i = 0; i < n; i++) {
            double yp = 0.0, ps = 0.0;
            for (j = 0; j <= order; j++) yp += D[j * n + i];
            for (j = 1; j <= order; j++) ps += GAMMA[j] * D[j * n + i];
            ypred[i] = yp;
            psi[i] = ps / ALPHA[order];
            sc[i] = rtol * bgm_x_nominal[i] + rtol * fabs(yp);
        }
        c_coef = h / ALPHA[order];

        /* simplified Newton on y - c f(t_new, y) = ypred - psi, in the increment d */
        for (;;) {
            double dy_old = 0.0;
            int k, fresh = b->jac_fresh;
            if (!c->lu_ok || c->lu_c != c_coef) {
                bgm_iteration_matrix(LU, J, c_coef, n);
                if (bgm_lu_factor(LU, c->piv, n)) {
                    c->lu_ok = 0;
                    why = "singular iteration matrix";
                    if (fresh) break;
                    if (bgm_call_jacx(c, t_new, ypred, J)) goto eval_failed;
                    b->jac_fresh = 1;
                    continue;
                }
                c->lu_ok = 1;
                c->lu_c = c_coef;
            }
            memcpy(ynew, ypred, n * sizeof(double));
            memset(d, 0, n * sizeof(double));
            converged = 0;
            for (k = 0; k < NEWTON_MAXITER; k++) {
                double dy_norm, rate = -1.0;
                int rc = bgm_call_xdot(c, t_new, ynew, f);
                if (rc == 1) goto eval_failed;
                if (rc == 2) {
                    why = "non-finite model evaluation during Newton iteration";
                    break;
                }
                for (i = 0; i < n; i++) dy[i] = c_coef * f[i] - psi[i] - d[i];
                bgm_lu_solve(LU, c->piv, n, dy);
                dy_norm = bgm_wnorm(dy, sc, n);
                if (!isfinite(dy_norm)) {
                    why = "Newton iteration diverged";
                    break;
                }
                if (dy_norm <= newton_floor) {
                    /* an update at the level of rounding (a steady state): its ratio to the
                       previous one is noise, not a rate of convergence */
                    for (i = 0; i < n; i++) {
                        ynew[i] += dy[i];
                        d[i] += dy[i];
                    }
                    n_iter = k + 1;
                    converged = 1;
                    break;
                }
                if (k > 0) {
                    rate = dy_norm / dy_old;
                    if (rate >= 1.0 ||
                        pow(rate, NEWTON_MAXITER - k) / (1.0 - rate) * dy_norm > newton_tol) {
                        why = "Newton iteration did not converge";
                        break;
                    }
                }
                for (i = 0; i < n; i++) {
                    ynew[i] += dy[i];
                    d[i] += dy[i];
                }
                n_iter = k + 1;
                if (dy_norm == 0.0 || (rate >= 0.0 && rate / (1.0 - rate) * dy_norm < newton_tol)) {
                    converged = 1;
                    break;
                }
                dy_old = dy_norm;
            }
            if (converged || fresh) break;
            /* a stale Jacobian: refresh it at the predictor and try again */
            if (bgm_call_jacx(c, t_new, ypred, J)) goto eval_failed;
            b->jac_fresh = 1;
            c->lu_ok = 0;
        }
        if (!converged) {
            c->stat_newton_fail++;
            change_d(D, order, 0.5, n);
            b->h = 0.5 * h;
            b->n_equal = 0;
            c->lu_ok = 0;
            continue;
        }

        /* local error estimate */
        for (i = 0; i < n; i++) sc[i] = rtol * bgm_x_nominal[i] + rtol * fabs(ynew[i]);
        for (i = 0; i < n; i++) tmp[i] = ERRC[order] * d[i];
        err_norm = bgm_wnorm(tmp, sc, n);
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter);
        if (!(err_norm <= 1.0)) {
            double factor = isfinite(err_norm) ? safety * pow(err_norm, -1.0 / (order + 1))
                                               : MIN_FACTOR;
            if (factor < MIN_FACTOR) factor = MIN_FACTOR;
            c->stat_rejected++;
            why = "error test failed repeatedly";
            change_d(D, order, factor, n);
            b->h = h * factor;
            b->n_equal = 0;
            c->lu_ok = 0;
            continue;
        }

        /* accepted: update the differences */
        c->stat_steps++;
        {
            double t_old = b->t;
            memcpy(y0, D, n * sizeof(double)); /* y at t_old */
            for (i = 0; i < n; i++) {
                D[(order + 2) * n + i] = d[i] - D[(order + 1) * n + i];
                D[(order + 1) * n + i] = d[i];
            }
            for (j = order; j >= 0; j--)
                for (i = 0; i < n; i++) D[j * n + i] += D[(j + 1) * n + i];
            b->t = t_new;
            b->jac_fresh = 0;
            b->n_equal++;
#if BGM_HYBRID
            /* a relation left its frozen value during this step: stop, the caller locates it */
            if (bgm_hyb_step_check(c, t_old, y0, t_new, D)) {
                c->v.time = t_new;
                memcpy(c->v.x, D, n * sizeof(double));
                c->v.h_next = b->h;
                b->valid = 0;
                b->snap_ok = 0;
                c->cache_valid = 0;
                return BGM_OK;
            }
#else
            (void)t_old;
#endif
        }
        if (clipped && h < h_natural) {
            /* a step shortened to land on the bound: keep the natural step size */
            change_d(D, order, h_natural / h, n);
            b->h = h_natural;
            b->n_equal = 0;
            c->lu_ok = 0;
        } else if (b->n_equal >= order + 1) {
            /* order and step-size selection among order-1, order, order+1 */
            double em = INFINITY, ep = INFINITY, fm, f0, fp, factor;
            if (order > 1) {
                for (i = 0; i < n; i++) tmp[i] = ERRC[order - 1] * D[order * n + i];
                em = bgm_wnorm(tmp, sc, n);
            }
            if (order < MAX_ORDER) {
                for (i = 0; i < n; i++) tmp[i] = ERRC[order + 1] * D[(order + 2) * n + i];
                ep = bgm_wnorm(tmp, sc, n);
            }
            fm = em > 0.0 ? pow(em, -1.0 / order) : INFINITY;
            f0 = err_norm > 0.0 ? pow(err_norm, -1.0 / (order + 1)) : INFINITY;
            fp = ep > 0.0 ? pow(ep, -1.0 / (order + 2)) : INFINITY;
            if (order <= 1) fm = 0.0;
            if (order >= MAX_ORDER) fp = 0.0;
            factor = f0;
            if (fm > factor) {
                factor = fm;
                order--;
            }
            if (fp > factor) {
                factor = fp;
                order = b->order + 1;
            }
            factor *= safety;
            if (factor > MAX_FACTOR) factor = MAX_FACTOR;
            b->order = order;
            change_d(D, order, factor, n);
            b->h *= factor;
            b->n_equal = 0;
            c->lu_ok = 0;
        }
    }

    /* the state at t_end: the newest point, or interpolated when a step ran past it */
    if (b->t != t_end) interpolate(D, b->order, b->t, b->h, t_end, n, c->v.x);
    else memcpy(c->v.x, D, n * sizeof(double));
    c->v.time = t_end;
    c->v.h_next = b->h;
    c->cache_valid = 0;
    keep_snapshot(c, rtol);
    bgm_log(c, BGM_OK, "logSolver", "%s: reached t=%g (solver at t=%g, order %d, step %g), "
            "%ld steps so far", fn, t_end, b->t, b->order, b->h, c->stat_steps);
    return BGM_OK;

eval_failed:
    bgm_error(c, "%s: model evaluation failed or returned NaN/Inf at t=%.17g (state or "
              "Jacobian); check inputs and parameters", fn, b->t);
fail:
    b->valid = 0;
    b->snap_ok = 0;
    c->cache_valid = 0;
    return BGM_ERROR;
}
