// solver_internal.h: the solver's private state, shared by solver.c, lu.c and
// the method files (krus.c, rk4.c, rosenbrock.c). Not installed, not public.
#ifndef HYD_SOLVER_INTERNAL_H
#define HYD_SOLVER_INTERNAL_H

#include "hyd_solver.h"

#include <stdint.h>

/// A linearly implicit method in the "original" form
///   (I - h gamma J) k_i = h f(t + c_i h, y + sum_j a_ij k_j) + h J sum_j g_ij k_j
///                         + gs_i h^2 df/dt
/// with y_new = y + sum b_i k_i and error estimate sum (b_i - bh_i) k_i.
typedef struct hyd_tableau {
    int stages;       ///< number of stages (<= 4)
    double gamma;     ///< diagonal gamma
    double a[4][4];   ///< alpha_ij, strictly lower
    double g[4][4];   ///< gamma_ij, strictly lower
    double c[4];      ///< c_i = sum_j a_ij (stage time fraction)
    double gs[4];     ///< gamma + sum_j g_ij (weight of the df/dt term)
    double b[4];      ///< solution weights
    double e[4];      ///< b - bh, error weights
    int needs_dfdt;   ///< 1 for classical Rosenbrock methods (not W-methods)
} hyd_tableau;

struct hyd_solver {
    const hyd_problem* p;
    hyd_method method;
    hyd_solver_opts o;
    int n;
    hyd_tableau tab; ///< Rosenbrock tableau (adaptive methods), else zero

    // Block structure of the iteration matrix: one block of size n when dense.
    int nblock;
    int* boff;   ///< (nblock + 1) first state index of each block
    int* moff;   ///< (nblock) offset of each block's matrix in jb / w
    int* bblk;   ///< (n) block of each state (finite differences)
    int msize;   ///< sum of block_size^2

    // Jacobian and iteration matrix W = I - gamma h J, per block, row-major.
    double* jfull; ///< (n x n) dense scratch for the analytic callback
    double* jb;    ///< (msize) diagonal blocks of J
    double* w;     ///< (msize) LU factors of W
    int* piv;      ///< (n) pivots, block-local
    double* widiag; ///< (n) 1 / U_ii of blocks larger than 2 (lu.c)
    int* wswap;    ///< (nblock) the block's LU exchanged rows
    // Blocks grouped by size class, so the solve runs one tight loop per class
    // instead of a size switch per block: first the nb1 blocks of size 1, then
    // the nb2 of size 2, then the rest (block indices).
    int nb1, nb2;
    int* border;   ///< (nblock)
    // The nb1 blocks of size 1 flat: their state index and 1/W, copied out of
    // boff/w at each factorisation, so their solve is one load pair and a
    // multiply per state instead of three dependent index loads.
    int* b1x;      ///< (nblock) state index of the t-th size-1 block
    double* b1w;   ///< (nblock) its 1 / W [-]
    double* ft;    ///< (n) df/dt at the Jacobian point (RODAS3)
    int j_valid;   ///< jb holds a usable Jacobian
    int j_force;   ///< re-evaluate J at the next step (after a rejection or reset)
    long j_steps;  ///< accepted steps since J was evaluated
    double j_t;    ///< time J was evaluated at [s]
    unsigned long j_events; ///< hyd_problem.events at the last J
    unsigned long ev_now;   ///< its value at the current step (jacobian_due)
    int w_valid;   ///< w holds LU(I - w_gh J)
    double w_gh;   ///< gamma * h that w was factored with [s]

    // Sparse path for a dense W (nblock == 1; lu.c). J's non-zeros seen so
    // far (their union, plus the diagonal) are kept in sp_jmask. From that
    // pattern a pivot order is chosen (Markowitz on the diagonal: least fill),
    // and W is factored in that order without row exchanges over the
    // pattern and its fill (sp_mask) only, accepting a diagonal pivot when it
    // is at least HYD_SP_THRESH times the largest entry below it in its
    // column (threshold partial pivoting). Otherwise that W falls back to the
    // dense LU with partial pivoting. The factors stay in W's dense storage,
    // in the states' own order; only the lists below follow the pivot order.
    int sp_on;             ///< the sparse path is available (dense W, n >= 3)
    int w_sparse;          ///< w holds a sparse, unpivoted factorisation
    unsigned char* sp_mask;///< (n x n) pattern of W's factors (J's, the diagonal and the fill)
    unsigned char* sp_jmask;///< (n x n) union of J's non-zeros and the diagonal
    int* sp_perm;          ///< (n) pivot order: the state eliminated k-th
    int* sp_pos;           ///< (n) its inverse: the step at which state i is eliminated
    // Lists per elimination step k (pivot sp_perm[k]); indices are states.
    int* sp_lptr;          ///< (n + 1) column k of L: rows sp_lrow[sp_lptr[k] ..]
    int* sp_lrow;
    int* sp_uptr;          ///< (n + 1) row sp_perm[k] of U, the states eliminated after it: sp_ucol[...]
    int* sp_ucol;
    int* sp_upos;          ///< position sp_perm[k]*n + j of each sp_ucol entry
    int* sp_fptr;          ///< (n + 1) row sp_perm[k] of L, the states eliminated before it: sp_fpos/sp_fcol
    int* sp_fpos;
    int* sp_fcol;
    double* sp_scale;      ///< (n) 1 / (atol + rtol |y_i|) at the Jacobian point: the
                           ///< threshold test runs on D^-1 W D (state units differ)
    uint64_t* sp_zmask;    ///< (n x n) magnitude-bit mask of the positions off the pattern
    int* sp_ppos;          ///< (n x n) positions on the pattern, sp_np of them
    int sp_np;
    long sp_fallbacks;     ///< factorisations that needed the dense pivoting path
    int w_custom;          ///< W is factored by the problem's wfactor (solve with wsolve)

    // Stage work vectors, n each.
    double* k[4];
    double* hjk[4]; ///< h J k_i, recovered from the stage equations (no J product)
    double* ys;     ///< stage argument
    double* fs;     ///< stage f
    double* r;      ///< stage right-hand side
    double* ynew;
    double* err;
    double* fdy;    ///< perturbed y for finite differences
    double* fdf;    ///< f at the perturbed y
    double* yout;   ///< interpolated output state
    double* hc[3];  ///< Hermite coefficients of the current step (see hermite_prepare)

    // Cache of f at the current point, so an adaptive step reuses f(y_{n+1})
    // (already needed for Hermite output) as the next step's first stage.
    int fc_valid;
    double fc_t;
    double* fc_y;
    double* fc_f;
    double* fnew;

    // Step-size controller (adaptive methods).
    double h_next;   ///< proposed next step [s]; 0: estimate one
    double h_acc;    ///< previous accepted step [s] (Gustafsson)
    double err_acc;  ///< previous accepted error norm (Gustafsson)
    int have_acc;    ///< h_acc/err_acc are meaningful
    int last_rejected;
    double last_h;   ///< last accepted step [s]
    int last_wstep;  ///< the last step was the problem's wstep (hyd_solver_step_quadrature)
    int last_split;  ///< the last fixed step was retried in sub-steps (its stages are not one step's)

    hyd_solver_stats st;
    int bad_i;
    double bad_t;
};

// lu.c: build and factor W = I - gh J block by block, solve W x = b in place.
int hydFactorW(hyd_solver* s, double gh);
/// Symbolic set-up of the sparse path from sp_mask (the diagonal at create).
void hydSparseInit(hyd_solver* s);
void hydSolveW(const hyd_solver* s, double* x);

// solver.c: make J and LU(W) current for a step of gamma*h = gh from (t, y),
// whose f is f0. Returns HYD_OK, HYD_ERR_RHS or HYD_ERR_SINGULAR.
int hydPrepareW(hyd_solver* s, double t, const double* y, const double* f0, double gh);
/// Evaluate f, counting it; maps a callback failure to HYD_ERR_RHS.
int hydEvalF(hyd_solver* s, double t, const double* y, double* dydt);

/// gamma of the two-stage W-methods: 1/2 for Krus, 1 + 1/sqrt(2) for ROS2.
static inline double hydKrusGamma(hyd_method m) { return m == HYD_KRUS ? 0.5 : 1.0 + 0.70710678118654752440; }

// Method steps: one trial step of size h from (t, y) with f0 = f(t, y) into
// ynew; rosenbrock also writes the error estimate to err (when non-NULL).
int hydKrusStep(hyd_solver* s, double t, const double* y, const double* f0, double h,
                double* ynew);
int hydRk4Step(hyd_solver* s, double t, const double* y, const double* f0, double h,
               double* ynew);
int hydRosenbrockStep(hyd_solver* s, double t, const double* y, const double* f0, double h,
                      double* ynew, double* err);
/// Fill the tableau of an adaptive method; -1 for other methods.
int hydRosenbrockTableau(hyd_method m, hyd_tableau* out);

#endif
