/*
 * bgmodelica FMU runtime: the one-step solver of Co-Simulation steps that start without a
 * usable history (bgm_solver.c decides): the 5-stage, order-4, L-stable and stiffly accurate
 * SDIRK method of Hairer & Wanner ("SDIRK4", Solving ODEs II, Table IV.6.5, gamma = 1/4) with
 * its embedded order-3 solution for the local error estimate.  After new inputs (held over
 * the communication step, a jump in the right-hand side) a multistep method must restart at
 * order 1 with small steps; one SDIRK4 step of the communication step's length usually does.
 * All stages share the diagonal coefficient, so one LU factorisation (bgm_lu.c) of
 * M = I - h*gamma*J per step serves every Newton iteration of every stage; J = d(xdot)/dx
 * comes from the CasADi-generated Jacobian once per step attempt (simplified Newton).  The
 * error estimate is filtered through M^{-1} (Shampine's trick) so that stiff components do not
 * inflate it.  Step-size control: h_new = h * clamp(0.9 * err^(-1/4), 0.2, 5), limited by
 * solver.max_step and the end of the communication step; the proposal is kept in v.h_next.
 */
#include <math.h>
#include <string.h>

#include "bgm_core.h"

#define NS 5
static const double G = 0.25;
static const double C[NS] = {0.25, 0.75, 11.0 / 20.0, 0.5, 1.0};
static const double A[NS][NS] = {
    {0.25, 0, 0, 0, 0},
    {0.5, 0.25, 0, 0, 0},
    {17.0 / 50.0, -1.0 / 25.0, 0.25, 0, 0},
    {371.0 / 1360.0, -137.0 / 2720.0, 15.0 / 544.0, 0.25, 0},
    {25.0 / 24.0, -49.0 / 48.0, 125.0 / 16.0, -85.0 / 12.0, 0.25}};
/* b - bhat: b is the last row of A (stiffly accurate), bhat the embedded order-3 weights */
static const double E[NS] = {25.0 / 24.0 - 59.0 / 48.0, -49.0 / 48.0 + 17.0 / 96.0,
                             125.0 / 16.0 - 225.0 / 32.0, 0.0, 0.25};

#define MAX_NEWTON 10
#define MAX_SUBSTEPS 1000000L

bgm_status bgm_sdirk_integrate(bgm_inst *c, const char *fn, double t_end) {
    const int n = BGM_NX;
    double *ws = c->ws;
    double *x0 = ws, *Y = x0 + BGM_NXA, *s = Y + BGM_NXA, *F = s + BGM_NXA;
    double *err = F + BGM_NXA, *sc = err + BGM_NXA, *f0 = sc + BGM_NXA, *tmp = f0 + BGM_NXA;
    double *K = tmp + BGM_NXA, *J = K + NS * BGM_NXA, *M = J + BGM_NXA * BGM_NXA;
    double rtol = c->v.solver_tol, hmax = c->v.solver_hmax;
    double t = c->v.time, h;
    long substeps = 0;
    int have_f0 = 0, last_rejected = 0, i, j, st, rc;
    const char *why = "";

    if (c->exp_tol_defined && c->exp_tol > 0.0 && c->exp_tol < rtol) rtol = c->exp_tol;
    if (n == 0) {
        c->v.time = t_end;
        c->cache_valid = 0;
        return BGM_OK;
    }
    memcpy(x0, c->v.x, n * sizeof(double));

    h = c->v.h_next;
    if (!(h > 0.0)) {
        /* initial step guess from the size of x and xdot */
        double d0, d1;
        if (bgm_call_xdot(c, t, x0, f0)) goto eval_failed;
        have_f0 = 1;
        for (i = 0; i < n; i++) sc[i] = rtol * bgm_x_nominal[i] + rtol * fabs(x0[i]);
        d0 = bgm_wnorm(x0, sc, n);
        d1 = bgm_wnorm(f0, sc, n);
        h = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
        if (h > 0.1 * (t_end - t)) h = 0.1 * (t_end - t);
        if (h < 1e-10 * (t_end - t)) h = 1e-10 * (t_end - t);
    }

    while (t < t_end) {
        double hs = h, hmin, en, fac;
        int clipped = 0, newton_ok = 1;
        if (hs > hmax) hs = hmax;
        if (t + hs >= t_end || t + 1.01 * hs >= t_end) {
            hs = t_end - t;
            clipped = 1;
        }
        hmin = 1e-14 * (fabs(t) > 1.0 ? fabs(t) : 1.0);
        if (hs < hmin && !clipped) {
            bgm_error(c, "%s: step size %g too small at t=%.17g (%s); the model may be "
                      "singular or need a looser solver.tolerance", fn, hs, t, why);
            return BGM_ERROR;
        }
        if (++substeps > MAX_SUBSTEPS) {
            bgm_error(c, "%s: more than %ld internal steps in one communication step at t=%g",
                      fn, MAX_SUBSTEPS, t);
            return BGM_ERROR;
        }
        if (!have_f0) {
            if (bgm_call_xdot(c, t, x0, f0)) goto eval_failed;
            have_f0 = 1;
        }
        rc = bgm_call_jacx(c, t, x0, J);
        if (rc) goto eval_failed;
        /* M = I - hs*G*J ; J is column-major from CasADi, M row-major */
        bgm_iteration_matrix(M, J, hs * G, n);
        if (bgm_lu_factor(M, c->piv, n)) {
            why = "singular iteration matrix";
            c->stat_newton_fail++;
            h = 0.25 * hs;
            last_rejected = 1;
            if (h < hmin) {
                bgm_error(c, "%s: singular iteration matrix at t=%.17g", fn, t);
                return BGM_ERROR;
            }
            continue;
        }
        for (i = 0; i < n; i++) sc[i] = rtol * bgm_x_nominal[i] + rtol * fabs(x0[i]);

        for (st = 0; st < NS && newton_ok; st++) {
            double ts = t + C[st] * hs, nrm_old = 0.0;
            const double *kprev = st == 0 ? f0 : K + (st - 1) * n;
            int it, converged = 0;
            for (i = 0; i < n; i++) {
                double acc = 0.0;
                for (j = 0; j < st; j++) acc += A[st][j] * K[j * n + i];
                s[i] = x0[i] + hs * acc;
                Y[i] = s[i] + hs * G * kprev[i];
            }
            for (it = 0; it < MAX_NEWTON; it++) {
                double nrm;
                rc = bgm_call_xdot(c, ts, Y, F);
                if (rc == 1) goto eval_failed;
                if (rc == 2) {
                    why = "non-finite model evaluation during Newton iteration";
                    break;
                }
                for (i = 0; i < n; i++) tmp[i] = -(Y[i] - s[i] - hs * G * F[i]);
                bgm_lu_solve(M, c->piv, n, tmp);
                for (i = 0; i < n; i++) Y[i] += tmp[i];
                nrm = bgm_wnorm(tmp, sc, n);
                if (!isfinite(nrm)) {
                    why = "Newton iteration diverged";
                    break;
                }
                if (it == 0) {
                    if (nrm <= 1e-3) {
                        converged = 1;
                        break;
                    }
                } else {
                    double theta = nrm / nrm_old;
                    if (theta >= 0.99) {
                        why = "Newton iteration diverged";
                        break;
                    }
                    if (theta / (1.0 - theta) * nrm <= 0.03) {
                        converged = 1;
                        break;
                    }
                }
                nrm_old = nrm;
            }
            if (!converged) {
                if (it == MAX_NEWTON) why = "Newton iteration did not converge";
                newton_ok = 0;
                break;
            }
            for (i = 0; i < n; i++) K[st * n + i] = (Y[i] - s[i]) / (hs * G);
        }
        if (!newton_ok) {
            c->stat_newton_fail++;
            h = 0.25 * hs;
            last_rejected = 1;
            if (h < hmin) {
                bgm_error(c, "%s: step size %g too small at t=%.17g (%s)", fn, h, t, why);
                return BGM_ERROR;
            }
            continue;
        }
        /* Y holds the new solution (stiffly accurate); local error estimate */
        for (i = 0; i < n; i++) {
            double acc = 0.0;
            for (st = 0; st < NS; st++) acc += E[st] * K[st * n + i];
            err[i] = hs * acc;
        }
        bgm_lu_solve(M, c->piv, n, err);
        for (i = 0; i < n; i++) {
            double ref = fabs(x0[i]) > fabs(Y[i]) ? fabs(x0[i]) : fabs(Y[i]);
            sc[i] = rtol * bgm_x_nominal[i] + rtol * ref;
        }
        en = bgm_wnorm(err, sc, n);
        if (!isfinite(en)) en = 1e10;
        fac = en > 0.0 ? 0.9 * pow(en, -0.25) : 5.0;
        if (fac > 5.0) fac = 5.0;
        if (fac < 0.2) fac = 0.2;
        if (en <= 1.0) {
#if BGM_HYBRID
            /* a relation left its frozen value during this step: stop, the caller locates it */
            int crossed = bgm_hyb_step_check(c, t, x0, clipped ? t_end : t + hs, Y);
#endif
            c->stat_steps++;
            t = clipped ? t_end : t + hs;
            memcpy(x0, Y, n * sizeof(double));
            memcpy(f0, K + (NS - 1) * n, n * sizeof(double)); /* FSAL: f(t+h, Y5) */
            if (last_rejected && fac > 1.0) fac = 1.0;
            last_rejected = 0;
            /* a step shortened to hit t_end does not shrink a good proposal */
            if (clipped && hs < h && fac >= 1.0) {
                if (hs * fac > h) h = hs * fac;
            } else {
                h = hs * fac;
            }
            /* commit the accepted step: DoStep failures later keep a consistent state */
            memcpy(c->v.x, x0, n * sizeof(double));
            c->v.time = t;
#if BGM_HYBRID
            if (crossed) {
                c->v.h_next = h;
                c->cache_valid = 0;
                return BGM_OK;
            }
#endif
        } else {
            c->stat_rejected++;
            last_rejected = 1;
            h = hs * (fac < 1.0 ? fac : 0.5);
            why = "error test failed repeatedly";
        }
    }
    c->v.time = t_end;
    c->v.h_next = h;
    c->cache_valid = 0;
    bgm_log(c, BGM_OK, "logSolver", "%s: reached t=%g, next step %g, %ld steps so far", fn,
            t_end, h, c->stat_steps);
    return BGM_OK;

eval_failed:
    bgm_error(c, "%s: model evaluation failed or returned NaN/Inf at t=%.17g (state or "
              "Jacobian); check inputs and parameters", fn, t);
    c->cache_valid = 0;
    return BGM_ERROR;
}
