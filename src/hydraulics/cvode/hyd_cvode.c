// hyd_cvode.c: the CVODE adapter (SUNDIALS 6.x API: SUNContext, SUNMatrix,
// SUNLinearSolver), through CVODES for its quadratures. Everything is created
// and freed inside one call; this is a reference solver, not a real-time path.
#include "hyd_cvode.h"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct cv_ctx {
    const hyd_problem* p;
    double* jrow; ///< (n x n) row-major scratch for the hyd_jac_fn layout
    const hyd_cvode_opts* o; ///< its quadrature
} cv_ctx;

hyd_cvode_opts hyd_cvode_default_opts(void) {
    hyd_cvode_opts o;
    o.rtol = 1e-8;
    o.atol = 1e-10;
    o.h_max = 0.0;
    o.max_steps = 10000000;
    o.max_order = 0;
    o.nq = 0;
    o.qfn = NULL;
    o.quser = NULL;
    o.q = NULL;
    return o;
}

static int cv_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* data) {
    const cv_ctx* c = data;
    // CVODE treats a positive return as recoverable (retry with smaller h).
    return c->p->f(c->p->user, t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)) == 0 ? 0 : 1;
}

static int cv_quad(sunrealtype t, N_Vector y, N_Vector qdot, void* data) {
    const cv_ctx* c = data;
    return c->o->qfn(c->o->quser, t, N_VGetArrayPointer(y), N_VGetArrayPointer(qdot)) == 0 ? 0 : 1;
}

// hyd_jac_fn is row-major; SUNDIALS' dense matrix is column-major.
static int cv_jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void* data, N_Vector t1,
                  N_Vector t2, N_Vector t3) {
    (void)fy, (void)t1, (void)t2, (void)t3;
    const cv_ctx* c = data;
    const int n = c->p->n;
    memset(c->jrow, 0, (size_t)n * (size_t)n * sizeof *c->jrow);
    if (c->p->jac(c->p->user, t, N_VGetArrayPointer(y), c->jrow) != 0) return 1;
    for (int j = 0; j < n; ++j) {
        sunrealtype* col = SUNDenseMatrix_Column(J, j);
        for (int i = 0; i < n; ++i) col[i] = c->jrow[i * n + j];
    }
    return 0;
}

int hyd_cvode_integrate(const hyd_problem* p, const hyd_cvode_opts* o, double t0, double* y,
                        double t_end, double dt_out, hyd_output_fn out, void* user,
                        hyd_solver_stats* stats) {
    if (!p || !p->f || p->n <= 0 || !y || !(dt_out > 0.0) || !(t_end >= t0)) return HYD_ERR_RHS;
    const hyd_cvode_opts opts = o ? *o : hyd_cvode_default_opts();
    if (opts.nq < 0 || (opts.nq > 0 && (!opts.qfn || !opts.q))) return HYD_ERR_RHS;
    const int n = p->n, nq = opts.nq;
    int result = HYD_OK;
    cv_ctx c = {p, NULL, &opts};
    SUNContext sctx = NULL;
    N_Vector v = NULL, vq = NULL;
    SUNMatrix A = NULL;
    SUNLinearSolver LS = NULL;
    void* mem = NULL;

    if (SUNContext_Create(NULL, &sctx) != 0) return HYD_ERR_RHS;
    v = N_VNew_Serial(n, sctx);
    A = SUNDenseMatrix(n, n, sctx);
    c.jrow = p->jac ? malloc((size_t)n * (size_t)n * sizeof *c.jrow) : NULL;
    mem = CVodeCreate(CV_BDF, sctx);
    if (!v || !A || !mem || (p->jac && !c.jrow)) {
        result = HYD_ERR_RHS;
        goto done;
    }
    memcpy(N_VGetArrayPointer(v), y, (size_t)n * sizeof *y);
    LS = SUNLinSol_Dense(v, A, sctx);
    if (!LS || CVodeInit(mem, cv_rhs, t0, v) != CV_SUCCESS ||
        CVodeSStolerances(mem, opts.rtol, opts.atol) != CV_SUCCESS ||
        CVodeSetUserData(mem, &c) != CV_SUCCESS ||
        CVodeSetLinearSolver(mem, LS, A) != CV_SUCCESS ||
        (p->jac && CVodeSetJacFn(mem, cv_jac) != CV_SUCCESS) ||
        CVodeSetMaxNumSteps(mem, opts.max_steps) != CV_SUCCESS ||
        CVodeSetStopTime(mem, t_end) != CV_SUCCESS) {
        result = HYD_ERR_RHS;
        goto done;
    }
    if (nq) {
        vq = N_VNew_Serial(nq, sctx);
        if (!vq) {
            result = HYD_ERR_RHS;
            goto done;
        }
        memcpy(N_VGetArrayPointer(vq), opts.q, (size_t)nq * sizeof *opts.q);
        // Out of the error test (CVODES' default): the steps stay those of
        // the state alone.
        if (CVodeQuadInit(mem, cv_quad, vq) != CV_SUCCESS || CVodeSetQuadErrCon(mem, SUNFALSE) != CV_SUCCESS) {
            result = HYD_ERR_RHS;
            goto done;
        }
    }
    if (opts.h_max > 0.0) CVodeSetMaxStep(mem, opts.h_max);
    if (opts.max_order > 0) CVodeSetMaxOrd(mem, opts.max_order);

    if (out && out(user, t0, y) != 0) goto done;
    const long nseg = (long)ceil((t_end - t0) / dt_out - 1e-9);
    for (long k = 1; k <= nseg && t_end > t0; ++k) {
        const double tk = k >= nseg ? t_end : t0 + (double)k * dt_out;
        sunrealtype tr = t0;
        int flag = CVode(mem, tk, v, &tr, CV_NORMAL);
        if (flag < 0) {
            result = flag == CV_TOO_MUCH_WORK                             ? HYD_ERR_STEPS
                     : (flag == CV_RHSFUNC_FAIL || flag == CV_FIRST_RHSFUNC_ERR ||
                        flag == CV_REPTD_RHSFUNC_ERR || flag == CV_UNREC_RHSFUNC_ERR)
                         ? HYD_ERR_RHS
                         : HYD_ERR_HMIN;
            break;
        }
        memcpy(y, N_VGetArrayPointer(v), (size_t)n * sizeof *y);
        if (nq) {
            if (CVodeGetQuad(mem, &tr, vq) != CV_SUCCESS) {
                result = HYD_ERR_RHS;
                break;
            }
            memcpy(opts.q, N_VGetArrayPointer(vq), (size_t)nq * sizeof *opts.q);
        }
        if (out && out(user, tk, y) != 0) break;
    }

done:
    if (stats && mem) {
        long nst = 0, netf = 0, nfe = 0, nje = 0, nfeLS = 0, nsetups = 0;
        CVodeGetNumSteps(mem, &nst);
        CVodeGetNumErrTestFails(mem, &netf);
        CVodeGetNumRhsEvals(mem, &nfe);
        CVodeGetNumJacEvals(mem, &nje);
        CVodeGetNumLinRhsEvals(mem, &nfeLS);
        CVodeGetNumLinSolvSetups(mem, &nsetups);
        stats->steps = nst;
        stats->rejected = netf;
        stats->fevals = nfe + nfeLS;
        stats->jevals = nje;
        stats->lus = nsetups;
    }
    if (mem) CVodeFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (v) N_VDestroy(v);
    if (vq) N_VDestroy(vq);
    free(c.jrow);
    if (sctx) SUNContext_Free(&sctx);
    return result;
}
