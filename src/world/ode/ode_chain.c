// ode_chain.c: the ODE world from a crane chain (ode_chain.h).
//
// Bodies: chain_update at the start coordinates gives every body's frame;
// an ODE body sits at the frame's centre of mass (ODE's body origin) with
// the frame's axes, so the chain's inertia tensor (about the centre of mass,
// body axes) is ODE's as it stands, and a point given in the frame is
// org + p in ODE body coordinates (org = -com). Joints are built in that
// pose, so each ODE joint's zero is the start coordinate: q = q0 + angle
// (hinge) or q0 + position (slider). The hinge axis of a revolute joint is
// the frame's -y (a positive q turns x towards z, chain.h), of the slew +z;
// a slider's axis is the child's x. ODE's hinge angle wraps at +-pi: it is
// unwrapped after every step (whole turns counted), and the stops are given
// to ODE per turn, as the two-link world does for its slew.
//
// Coupling (as ode_coupling.c, docs/ode_world.md "Coupling"): at the start
// of each ODE step each actuator's stroke and rate are read from its pins;
// the circuit is advanced over the step in dt_hyd sub-steps with the
// strokes extrapolated linearly; the cylinder force at the end of the
// sub-steps acts at the pins, equal and opposite along them, during the
// ODE step.
#include "ode_chain.h"

#include "ode_common.h"
#include "circuit_fast.h"
#include "circuit_kernel.h"
#include "energy_acc.h"
#include "hyd_cylinder.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct oc_body {
    dBodyID body;      ///< 0: fixed to the ground (a column that does not slew)
    double org[3];     ///< frame origin in ODE body coordinates (-com) [m]
    double R[9], p[3]; ///< body == 0: the frame's fixed pose
    dJointID joint;    ///< to the parent (or the ground); 0 for the fixed column
    int dof;           ///< the chain DOF of its joint, or -1
    int revolute;      ///< the joint is a hinge (a boom or the slew)
    double q0;         ///< joint coordinate at build time (the ODE joint's zero) [rad or m]
    double raw, turns; ///< hinge: angle at the last read and the whole turns counted [rad]
    double lo, hi;     ///< stops relative to the joint's zero, continuous [rad or m] (+-inf: none)
    int seal;          ///< implicit_seal: a cylinder's seal friction acts as this joint's motor
    int motor;         ///< the motor runs this step (apply_seal), else the friction is explicit
    double qd0;        ///< joint rate at the step's start [rad/s or m/s]
    double C, vel;     ///< the motor's damping sum l^2 dF/dv [N m s or N s/m] and target rate
    double steep;      ///< its cylinders' steepest slope sum l^2 (F_c + F_s)/v_sm [N m s or N s/m]
    double fmax;       ///< that motor's force limit this step [N m or N]
} oc_body;

typedef struct oc_act {
    int iA, iB;       ///< chamber pressure states, -1 without a circuit
    double AA, AB;    ///< piston and annulus areas [m^2]
    double x0, v0;    ///< stroke [m] and rate [m/s] at the start of the step
    double F;         ///< force over the step [N], + extends
    int stop_body;    ///< the body whose joint carries this cylinder's stroke ends, or -1
    int seal;         ///< implicit_seal: its seal friction is a motor on the joint of seal_body
    int seal_body;    ///< the body whose joint the cylinder spans (implicit_seal), or -1
    double Fc, Fs, vst, vsm; ///< its seal friction's parameters [N, N, m/s, m/s]
    double Fsc;       ///< the circuit's seal friction at the step's rate v0 [N]
    /// The friction as a line ODE holds (apply_seal): Fs0 + dFs (v - v0)
    /// within +-Fmax [N, N s/m, N].
    double Fs0, dFs, Fmax;
    double lever;     ///< dL/dq of its joint at the step's start [m/rad or -]
    double Fp;        ///< the force at its pins this step [N] (F without the seal friction when the motor holds it)
    /// CRANE_ACT_LINKAGE: the link (A-P) and the rocker (C-P) as bodies, the
    /// loop closed by hinges at A (link-parent), C (rocker-knuckle) and P
    /// (link-rocker); the rod pushes P, the link's end at (l1/2, 0, 0) in its
    /// body frame (origin at its centre, x along A->P). 0 for a pin pair.
    dBodyID link, rocker;
    double Pl[3];     ///< P in the link's body coordinates [m]
} oc_act;

struct ode_chain {
    crane_chain cc; ///< the copy, bound to the circuit
    ode_chain_opts opt;
    chain* mech;    ///< the mechanism with the tip mass merged (start poses, gravity load, stroke ends)
    chain_ws* ws;
    int nbody, ndof, nact, nfn;
    int nlinkage;   ///< actuators through a linkage (two extra bodies each)
    oc_body* b;
    oc_act* a;
    double* tau;    ///< extra joint forces (ndof)
    double* u;      ///< valve commands (nfn)
    double* qstart; ///< start coordinates (ndof)
    double* qs;     ///< scratch (ndof)
    double* dL;     ///< implicit_seal: lever arms (ndof), NULL when no cylinder's friction is held so
    dWorldID world;
    dThreadingImplementationID threading;
    double g;
    double t;
    long nstep;
    int failed, dead, acquired;
    char err[384];
    // Hydraulics.
    hyd_model* hm;
    hyd_data* hd;
    hyd_fast* fk; ///< the sub-steps' kernel (circuit_fast.h), or NULL: the component loops
    hyd_solver* hs;
    hyd_problem hp;
    int nh, nsub, npres;
    double* y;
    double* ydot;
    int* pres;
    double th, step_t0;
    struct sim_energy* energy; ///< ode_chain_follow_energy's balance, or NULL
    // Hosted (opts.host_world): the world is the host's.
    int hosted;
    double Rb[9], pb[3]; ///< base frame to world: rotation (row-major), origin [m]
    // The slew drive (opts.slew_drive): the rack cylinder on body 0's hinge.
    int slew_on;
    int slew_cyl, slew_valve;   ///< the circuit's rack cylinder and its valve
    int slew_iA, slew_iB;       ///< their chamber pressure states
    double slew_AA, slew_AB, slew_stroke; ///< [m^2, m^2, m]
    double slew_x0, slew_v0;    ///< rack stroke [m] and rate [m/s] at the step start
    double slew_F;              ///< rack force over the step [N]
    double slew_u;              ///< the slew command [-1, 1]
};

ode_chain_opts ode_chain_default_opts(void) {
    ode_chain_opts o;
    memset(&o, 0, sizeof o);
    o.dt_ode = 1e-3;
    o.dt_hyd = 1e-4;
    o.solver = HYD_KRUS;
    o.jac_every = 1;
    o.erp = 0.2;
    o.cfm = 1e-10;
    o.stop_limits = 1;
    o.init_hold = 1;
    o.p_low = 2e6;
    o.model_file = "model";
    o.implicit_seal = 1;
    return o;
}

// ---- frames ----

static void frame_point(const ode_chain* w, int i, const double p[3], double out[3]) {
    const oc_body* b = &w->b[i];
    if (b->body) {
        dVector3 r;
        dBodyGetRelPointPos(b->body, b->org[0] + p[0], b->org[1] + p[1], b->org[2] + p[2], r);
        out[0] = r[0], out[1] = r[1], out[2] = r[2];
    } else {
        for (int k = 0; k < 3; ++k) out[k] = b->p[k] + b->R[3 * k] * p[0] + b->R[3 * k + 1] * p[1] + b->R[3 * k + 2] * p[2];
    }
}

static void frame_point_vel(const ode_chain* w, int i, const double p[3], double out[3]) {
    const oc_body* b = &w->b[i];
    if (b->body) {
        dVector3 r;
        dBodyGetRelPointVel(b->body, b->org[0] + p[0], b->org[1] + p[1], b->org[2] + p[2], r);
        out[0] = r[0], out[1] = r[1], out[2] = r[2];
    } else {
        out[0] = out[1] = out[2] = 0.0;
    }
}

// Pin length [m] and rate [m/s] of actuator k, and the unit vector from the
// barrel pin to the rod pin with both pins (any of them may be NULL).
// The rod pin of actuator k and its velocity: on body_b, or (a linkage) the
// common pin P on the link's body.
static void rod_point(const ode_chain* w, int k, double p[3], double v[3]) {
    const crane_act* c = &w->cc.act[k];
    const oc_act* a = &w->a[k];
    if (a->link) {
        dVector3 r;
        if (p) {
            dBodyGetRelPointPos(a->link, a->Pl[0], a->Pl[1], a->Pl[2], r);
            p[0] = r[0], p[1] = r[1], p[2] = r[2];
        }
        if (v) {
            dBodyGetRelPointVel(a->link, a->Pl[0], a->Pl[1], a->Pl[2], r);
            v[0] = r[0], v[1] = r[1], v[2] = r[2];
        }
        return;
    }
    if (p) frame_point(w, c->body_b, c->pb, p);
    if (v) frame_point_vel(w, c->body_b, c->pb, v);
}

static double act_geometry(const ode_chain* w, int k, double* rate, double u[3], double pa[3], double pb[3]) {
    const crane_act* c = &w->cc.act[k];
    double a[3], b[3];
    frame_point(w, c->body_a, c->pa, a);
    rod_point(w, k, b, NULL);
    const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double L = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (rate) {
        double va[3], vb[3];
        frame_point_vel(w, c->body_a, c->pa, va);
        rod_point(w, k, NULL, vb);
        *rate = ((vb[0] - va[0]) * d[0] + (vb[1] - va[1]) * d[1] + (vb[2] - va[2]) * d[2]) / L;
    }
    if (u)
        for (int i = 0; i < 3; ++i) u[i] = d[i] / L;
    if (pa) memcpy(pa, a, sizeof a);
    if (pb) memcpy(pb, b, sizeof b);
    return L;
}

// ---- hinge angles and stops ----

// The turns counted for a hinge whose angle now reads raw (a step turns a
// joint far less than pi, so a jump of more than pi is a wrap).
static double turns_at(const oc_body* b, double raw) {
    const double d = raw - b->raw;
    return b->turns + (d > M_PI ? -2 * M_PI : d < -M_PI ? 2 * M_PI : 0.0);
}

static void set_param(const oc_body* b, int param, double v) {
    if (b->revolute) dJointSetHingeParam(b->joint, param, v);
    else dJointSetSliderParam(b->joint, param, v);
}

// Give ODE the joint's stops. A slider takes them as they are; a hinge's
// are moved into the present turn, and a stop that turn's (-pi, pi] cannot
// reach is left out until the angle has wrapped towards it. With both in
// one turn and lo > hi (a range of more than a turn) only the one on the
// angle's side is reachable before the next wrap. hi is set before lo so
// ODE never sees lo > hi.
static void apply_stops(const oc_body* b) {
    double lo = b->lo, hi = b->hi;
    if (b->revolute) {
        lo -= b->turns, hi -= b->turns;
        if (!(fabs(lo) < M_PI)) lo = -dInfinity;
        if (!(fabs(hi) < M_PI)) hi = dInfinity;
        if (lo > -dInfinity && hi < dInfinity && lo >= hi) {
            if (b->raw >= lo) hi = dInfinity;
            else lo = -dInfinity;
        }
    }
    set_param(b, dParamLoStop, -dInfinity);
    set_param(b, dParamHiStop, hi);
    set_param(b, dParamLoStop, lo);
    set_param(b, dParamBounce, 0.0);
}

// After a step: count the hinges' wraps (and move their stops with them).
static void read_turns(ode_chain* w) {
    for (int i = 0; i < w->nbody; ++i) {
        oc_body* b = &w->b[i];
        if (b->dof < 0 || !b->revolute) continue;
        const double raw = dJointGetHingeAngle(b->joint);
        const double turns = turns_at(b, raw);
        b->raw = raw;
        if (turns != b->turns) {
            b->turns = turns;
            apply_stops(b);
        }
    }
}

// A slider's rate [m/s]: the relative velocity of its two bodies along the
// axis, ax . (v1 - v2), plus the turning of that axis with the bodies,
// (c x ax) . (w1 + w2) / 2 with c = p2 - p1 the line between their centres
// of mass: the rate of dJointGetSliderPosition and the velocity ODE's
// slider motor row holds (its linear torque decoupling). ODE's own
// dJointGetSliderPositionRate leaves out the second term, which on a
// turning boom is its angular rate times the offset of the centres of mass
// across the axis (0.1 rad/s over 0.1 m: 10 mm/s).
static double slider_rate(dJointID j) {
    dVector3 ax;
    dJointGetSliderAxis(j, ax);
    const dBodyID b1 = dJointGetBody(j, 0), b2 = dJointGetBody(j, 1);
    const dReal* v1 = dBodyGetLinearVel(b1);
    if (!b2) return ax[0] * v1[0] + ax[1] * v1[1] + ax[2] * v1[2];
    const dReal* v2 = dBodyGetLinearVel(b2);
    const dReal *w1 = dBodyGetAngularVel(b1), *w2 = dBodyGetAngularVel(b2);
    const dReal *p1 = dBodyGetPosition(b1), *p2 = dBodyGetPosition(b2);
    const double c[3] = {p2[0] - p1[0], p2[1] - p1[1], p2[2] - p1[2]};
    const double cx[3] = {c[1] * ax[2] - c[2] * ax[1], c[2] * ax[0] - c[0] * ax[2], c[0] * ax[1] - c[1] * ax[0]};
    double r = 0.0;
    for (int i = 0; i < 3; ++i) r += ax[i] * (v1[i] - v2[i]) + 0.5 * cx[i] * (w1[i] + w2[i]);
    return r;
}

static double joint_q(const ode_chain* w, const oc_body* b, double* qd) {
    if (b->revolute) {
        const double raw = dJointGetHingeAngle(b->joint);
        if (qd) *qd = dJointGetHingeAngleRate(b->joint);
        return b->q0 + raw + turns_at(b, raw);
    }
    (void)w;
    if (qd) *qd = slider_rate(b->joint);
    return b->q0 + dJointGetSliderPosition(b->joint);
}

static int at_stop(const oc_body* b) {
    if (b->dof < 0) return 0;
    double x, lo, hi;
    if (b->revolute) {
        x = dJointGetHingeAngle(b->joint);
        lo = dJointGetHingeParam(b->joint, dParamLoStop), hi = dJointGetHingeParam(b->joint, dParamHiStop);
    } else {
        x = dJointGetSliderPosition(b->joint);
        lo = dJointGetSliderParam(b->joint, dParamLoStop), hi = dJointGetSliderParam(b->joint, dParamHiStop);
    }
    return (lo > -dInfinity && x <= lo + 1e-6) || (hi < dInfinity && x >= hi - 1e-6);
}

// ---- the stroke ends as joint stops ----

static double stroke_at(ode_chain* w, int k, int dof, double s) {
    const crane_act* c = &w->cc.act[k];
    memcpy(w->qs, w->qstart, (size_t)w->ndof * sizeof *w->qs);
    w->qs[dof] = s;
    chain_update(w->mech, w->ws, w->qs, NULL);
    return crane_act_length(c, w->mech, w->ws, NULL, NULL, NULL) - c->closed_length;
}

// The joint coordinate, walking from the start in direction dir, where the
// stroke of actuator k first leaves [0, stroke]: a march in steps of h up
// to span [rad or m], then bisection to 1e-13 of the step. +-inf when it
// stays inside (a cylinder whose length turns back before its end).
static double stroke_end(ode_chain* w, int k, int dof, double dir, double h, double span) {
    const double S = w->cc.act[k].stroke, q0 = w->qstart[dof];
    double prev = q0;
    const int n = (int)ceil(span / h);
    for (int i = 1; i <= n; ++i) {
        const double q = q0 + dir * h * i;
        const double x = stroke_at(w, k, dof, q);
        if (x >= 0.0 && x <= S) {
            prev = q;
            continue;
        }
        const double target = x < 0.0 ? 0.0 : S;
        double in = prev, out = q;
        for (int it = 0; it < 200 && fabs(out - in) > 1e-13 * h; ++it) {
            const double mid = 0.5 * (in + out);
            const double xm = stroke_at(w, k, dof, mid);
            if ((target == 0.0 && xm >= 0.0) || (target == S && xm <= S)) in = mid;
            else out = mid;
        }
        return 0.5 * (in + out);
    }
    return dir > 0 ? INFINITY : -INFINITY;
}

// ---- hydraulics ----

static void set_inputs(ode_chain* w, double t) {
    const double tau = t - w->step_t0;
    for (int k = 0; k < w->nact; ++k) {
        const int c = w->cc.act[k].cyl;
        w->hd->cyl_x[c] = w->a[k].x0 + w->a[k].v0 * tau;
        w->hd->cyl_v[c] = w->a[k].v0;
    }
    for (int f = 0; f < w->nfn; ++f) w->hd->valve_cmd[w->cc.fn[f].valve_idx] = w->u[f];
    if (w->slew_on) {
        w->hd->cyl_x[w->slew_cyl] = w->slew_x0 + w->slew_v0 * tau;
        w->hd->cyl_v[w->slew_cyl] = w->slew_v0;
        w->hd->valve_cmd[w->slew_valve] = w->slew_u;
    }
}

// The rack's stroke [m] and rate [m/s] from the column's hinge (slew q and
// its rate): r q + s/2 (crane_slew_stroke), r qd.
static double slew_kinematics(const ode_chain* w, double* rate) {
    const oc_body* b = &w->b[0];
    double qd;
    const double q = joint_q(w, b, &qd);
    if (rate) *rate = w->cc.slew.pinion_radius * qd;
    return crane_slew_stroke(&w->cc.slew, q, w->slew_stroke);
}

static int rhs(void* user, double t, const double* y, double* dydt) {
    ode_chain* w = user;
    set_inputs(w, t);
    hyd_eval(w->hm, w->hd, t, y, dydt);
    return 0;
}

static int jac(void* user, double t, const double* y, double* J) {
    ode_chain* w = user;
    set_inputs(w, t);
    hyd_jacobian(w->hm, w->hd, t, y, NULL, J, w->nh, 0, 0);
    return 0;
}

// The sub-steps' f and Jacobian on the fast kernel (circuit_fast.h): the
// same laws in type-sorted loops, equal to the loops' to rounding. It fills
// no comp_q or comp_open, so the evaluation the rows and the balance read
// (after the sub-steps, hyd_step) stays on the loops.
static int rhs_fast(void* user, double t, const double* y, double* dydt) {
    ode_chain* w = user;
    set_inputs(w, t);
    hyd_fast_eval(w->fk, w->hd, y, dydt);
    return 0;
}

static int jac_fast(void* user, double t, const double* y, double* J) {
    ode_chain* w = user;
    set_inputs(w, t);
    hyd_fast_jacobian(w->fk, w->hd, y, NULL, J, w->nh);
    return 0;
}

// A node pressure below absolute zero (the solver retries shorter).
static int outside(void* user, const double* y) {
    const ode_chain* w = user;
    for (int k = 0; k < w->npres; ++k)
        if (!(y[w->pres[k]] >= 0.0)) return w->pres[k] + 1;
    return 0;
}

// More than 0.1 MPa below absolute zero: implausible (as ode_coupling.c).
static int implausible(void* user, const double* y) {
    const ode_chain* w = user;
    for (int k = 0; k < w->npres; ++k)
        if (!(y[w->pres[k]] > -1e5)) return w->pres[k] + 1;
    return 0;
}

// Spools commanded to 0 set to 0 once within HYD_SPOOL_SETTLE of it (they
// would decay into subnormal numbers), and the circuit's other lags towards
// 0 likewise (hyd_model_flush), as ode_coupling.c does.
static int settle(void* user, double t, double* y) {
    (void)t;
    ode_chain* w = user;
    int changed = hyd_model_flush(w->hm, y, NULL) > 0;
    for (int f = 0; f < w->nfn; ++f) {
        double* u = &y[hyd_model_valve_state(w->hm, w->cc.fn[f].valve_idx)];
        if (*u != 0.0 && fabs(*u) < HYD_SPOOL_SETTLE && fabs(w->u[f]) < HYD_SPOOL_SETTLE) {
            *u = 0.0;
            changed = 1;
        }
    }
    if (w->slew_on) {
        double* u = &y[hyd_model_valve_state(w->hm, w->slew_valve)];
        if (*u != 0.0 && fabs(*u) < HYD_SPOOL_SETTLE && fabs(w->slew_u) < HYD_SPOOL_SETTLE) {
            *u = 0.0;
            changed = 1;
        }
    }
    return changed;
}

static int hose_of(const ode_chain* w, int ic) {
    const int hose = hyd_model_feed_hose(w->hm, hyd_model_state_node(w->hm, ic));
    return hose < 0 ? -1 : hyd_model_node_state(w->hm, hyd_model_comp_node(w->hm, hose, 0));
}

// Solves the n x n system A x = b in place (A row-major, destroyed) by
// Gaussian elimination with partial pivoting. -1 when a pivot is below
// 1e-12 of the largest entry (singular for this purpose).
static int solve_dense(int n, double* A, double* b) {
    double amax = 0.0;
    for (int i = 0; i < n * n; ++i) amax = fmax(amax, fabs(A[i]));
    for (int c = 0; c < n; ++c) {
        int p = c;
        for (int r = c + 1; r < n; ++r)
            if (fabs(A[r * n + c]) > fabs(A[p * n + c])) p = r;
        if (!(fabs(A[p * n + c]) > 1e-12 * amax)) return -1;
        if (p != c) {
            for (int j = 0; j < n; ++j) {
                const double t = A[c * n + j];
                A[c * n + j] = A[p * n + j];
                A[p * n + j] = t;
            }
            const double t = b[c];
            b[c] = b[p];
            b[p] = t;
        }
        for (int r = c + 1; r < n; ++r) {
            const double f = A[r * n + c] / A[c * n + c];
            for (int j = c; j < n; ++j) A[r * n + j] -= f * A[c * n + j];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; --c) {
        double s = b[c];
        for (int j = c + 1; j < n; ++j) s -= A[c * n + j] * b[j];
        b[c] = s / A[c * n + c];
    }
    return 0;
}

// The actuator forces F that hold the start pose against gravity: the
// joints' gravity load G(q0) = sum_k F_k dL_k/dq (a cylinder's force F
// gives tau = F dL/dq). With as many actuators as DOFs this is square;
// otherwise the least-squares F (fewer actuators: a DOF no cylinder moves,
// as a free slew on level ground, gets what the others leave) or the
// least-norm one (more: several cylinders share a joint). -1 when the
// cylinders' lever arms are dependent.
static int holding_forces(ode_chain* w, double* F) {
    const int n = w->ndof, m = w->nact, s = n > m ? n : m;
    // A (n x m: column k actuator k's lever arms), G (n), N (s x s), r (s), dL (n)
    double* A = malloc((size_t)(n * m + n + s * s + s + n) * sizeof *A);
    if (!A) return -1;
    double* G = A + n * m;
    double* N = G + n;
    double* r = N + s * s;
    double* dL = r + s;
    chain_update(w->mech, w->ws, w->qstart, NULL);
    chain_inverse_dynamics(w->mech, w->ws, NULL, CHAIN_GRAVITY, G);
    for (int k = 0; k < m; ++k) {
        const crane_act* c = &w->cc.act[k];
        crane_act_length(c, w->mech, w->ws, NULL, dL, NULL);
        for (int j = 0; j < n; ++j) A[j * m + k] = dL[j];
    }
    int rc = 0;
    if (n == m) {
        memcpy(N, A, (size_t)n * n * sizeof *N);
        memcpy(F, G, (size_t)n * sizeof *F);
        rc = solve_dense(n, N, F);
    } else if (m < n) {
        // (A^T A) F = A^T G
        for (int i = 0; i < m; ++i) {
            double t = 0.0;
            for (int j = 0; j < n; ++j) t += A[j * m + i] * G[j];
            F[i] = t;
            for (int k = 0; k < m; ++k) {
                double v = 0.0;
                for (int j = 0; j < n; ++j) v += A[j * m + i] * A[j * m + k];
                N[i * m + k] = v;
            }
        }
        rc = solve_dense(m, N, F);
    } else {
        // F = A^T z, (A A^T) z = G
        for (int i = 0; i < n; ++i) {
            r[i] = G[i];
            for (int j = 0; j < n; ++j) {
                double v = 0.0;
                for (int k = 0; k < m; ++k) v += A[i * m + k] * A[j * m + k];
                N[i * n + j] = v;
            }
        }
        rc = solve_dense(n, N, r);
        for (int k = 0; k < m && !rc; ++k) {
            double v = 0.0;
            for (int i = 0; i < n; ++i) v += A[i * m + k] * r[i];
            F[k] = v;
        }
    }
    free(A);
    return rc;
}

static int hyd_create(ode_chain* w, char* err, size_t errsz) {
    const char* mf = w->opt.model_file;
    char e[256];
    if (crane_chain_bind(&w->cc, w->hm, e, sizeof e)) {
        snprintf(err, errsz, "%s: %s", mf, e);
        return -1;
    }
    for (int k = 0; k < w->nact; ++k)
        for (int j = 0; j < k; ++j)
            if (w->cc.act[j].cyl == w->cc.act[k].cyl) {
                snprintf(err, errsz,
                         "%s: mechanics.actuators[%d].cylinder: '%s' already drives actuators[%d] (%s); one cylinder "
                         "moves one pair of pins",
                         mf, k, w->cc.act[k].cylinder, j, w->cc.act[j].name);
                return -1;
            }
    if (w->opt.slew_drive) {
        const crane_slew* sl = &w->cc.slew;
        w->slew_cyl = hyd_model_cylinder(w->hm, sl->cylinder);
        w->slew_valve = hyd_model_valve(w->hm, sl->valve);
        if (!sl->present) {
            snprintf(err, errsz, "%s: mechanics.slew: missing (the column's slew drive is needed here)", mf);
            return -1;
        }
        if (w->slew_cyl < 0 || w->slew_valve < 0) {
            snprintf(err, errsz, "%s: mechanics.slew.%s: no %s named \"%s\" in the circuit (hydraulics_slew)", mf,
                     w->slew_cyl < 0 ? "cylinder" : "valve", w->slew_cyl < 0 ? "cylinder" : "valve",
                     w->slew_cyl < 0 ? sl->cylinder : sl->valve);
            return -1;
        }
        // One cylinder or valve on two functions would couple them through
        // one set of states: a slew that moves a boom.
        for (int k = 0; k < w->nact; ++k)
            if (w->cc.act[k].cyl == w->slew_cyl || w->cc.fn[w->cc.act[k].function].valve_idx == w->slew_valve) {
                snprintf(err, errsz, "%s: mechanics.slew: \"%s\" already drives actuators[%d] (%s)", mf,
                         w->cc.act[k].cyl == w->slew_cyl ? sl->cylinder : sl->valve, k, w->cc.act[k].name);
                return -1;
            }
        if (!(sl->pinion_radius > 0)) {
            snprintf(err, errsz, "%s: mechanics.slew.pinion_radius: %g m; must be > 0", mf, sl->pinion_radius);
            return -1;
        }
        hyd_model_cylinder_states(w->hm, w->slew_cyl, &w->slew_iA, &w->slew_iB);
        hyd_model_cylinder_geometry(w->hm, w->slew_cyl, &w->slew_AA, &w->slew_AB, &w->slew_stroke);
        w->slew_on = 1;
    }
    if (hyd_method_is_adaptive(w->opt.solver)) {
        snprintf(err, errsz, "ode chain world: the %s solver is adaptive; this world sub-steps a fixed-step one (krus, ros2)",
                 hyd_method_name(w->opt.solver));
        return -1;
    }
    w->nh = hyd_model_nstate(w->hm);
    w->y = calloc((size_t)w->nh, sizeof *w->y);
    w->ydot = calloc((size_t)w->nh, sizeof *w->ydot);
    w->pres = calloc((size_t)(hyd_model_nnode(w->hm) + 1), sizeof *w->pres);
    w->hd = hyd_data_create(w->hm);
    if (!w->y || !w->ydot || !w->pres || !w->hd) {
        snprintf(err, errsz, "ode chain world: out of memory");
        return -1;
    }
    for (int i = 0; i < hyd_model_nnode(w->hm); ++i) {
        const int st = hyd_model_node_state(w->hm, i);
        if (st >= 0) w->pres[w->npres++] = st;
    }
    for (int k = 0; k < w->nact; ++k) {
        oc_act* a = &w->a[k];
        double s;
        hyd_model_cylinder_states(w->hm, w->cc.act[k].cyl, &a->iA, &a->iB);
        hyd_model_cylinder_geometry(w->hm, w->cc.act[k].cyl, &a->AA, &a->AB, &s);
    }
    w->hp.n = w->nh;
    w->hp.user = w;
    w->hp.f = rhs;
    w->hp.jac = jac;
    if (!w->opt.general_circuit) {
        // With fallback: a component type the kernel has no loop for runs
        // its reference loop inside it, so it takes every circuit; NULL
        // only when out of memory (then the loops, still correct).
        char why[160];
        w->fk = hyd_fast_create(w->hm, hyd_fast_types(), 1, why, sizeof why);
        if (w->fk) w->hp.f = rhs_fast, w->hp.jac = jac_fast;
    }
    w->hp.outside = outside;
    w->hp.implausible = implausible;
    w->hp.settle = settle;
    hyd_solver_opts so = hyd_default_solver_opts();
    so.h = w->opt.dt_hyd;
    so.h_max = w->opt.dt_ode;
    so.jac_every = w->opt.jac_every > 0 ? w->opt.jac_every : 1;
    w->hs = hyd_solver_create(&w->hp, w->opt.solver, &so);
    if (!w->hs) {
        snprintf(err, errsz, "ode chain world: cannot create the %s solver", hyd_method_name(w->opt.solver));
        return -1;
    }
    w->nsub = (int)floor(w->opt.dt_ode / w->opt.dt_hyd + 0.5);
    return 0;
}

// The start state: the model's, then (init_hold) every cylinder's chambers
// and the hoses feeding them at the pressures of the forces that hold the
// start pose (the unloaded side at p_low), as the two-link worlds start.
static int hyd_init_state(ode_chain* w, char* err, size_t errsz) {
    hyd_model_initial_state(w->hm, w->y);
    w->th = 0.0;
    for (int k = 0; k < w->nact; ++k) w->a[k].x0 = act_geometry(w, k, &w->a[k].v0, NULL, NULL, NULL) - w->cc.act[k].closed_length;
    if (w->slew_on) w->slew_x0 = slew_kinematics(w, &w->slew_v0);
    if (!w->opt.init_hold) return 0;
    if (w->slew_on) {
        // The rack balanced with both chambers at p_low (no static torque on
        // a level base), as the two-link sandbox starts its slew.
        const double p = w->opt.p_low;
        w->y[w->slew_iA] = p;
        w->y[w->slew_iB] = p * w->slew_AA / w->slew_AB;
        const int hA = hose_of(w, w->slew_iA), hB = hose_of(w, w->slew_iB);
        if (hA >= 0) w->y[hA] = w->y[w->slew_iA];
        if (hB >= 0) w->y[hB] = w->y[w->slew_iB];
    }
    double* F = calloc((size_t)(w->nact + w->ndof), sizeof *F);
    if (!F) {
        snprintf(err, errsz, "ode chain world: out of memory");
        return -1;
    }
    int bad = 0;
    if (w->nact && (w->opt.hold_tip_mass > 0 || w->nlinkage)) {
        // The forces of the pose with the hanging mass at the tip: from a
        // mechanism with it merged (the world's bodies stay without it);
        // and the linkages' links lumped at their pins (the world has them
        // as bodies): their weight is then held, as in the analytic mode.
        char e[320];
        chain* held = crane_chain_mechanism(&w->cc, w->opt.tip_mass + w->opt.hold_tip_mass, w->cc.slew_free,
                                            w->opt.slew0, e, sizeof e);
        chain_ws* hws = held ? chain_ws_create(held) : NULL;
        chain* m0 = w->mech;
        chain_ws* ws0 = w->ws;
        if (hws) {
            w->mech = held, w->ws = hws;
            bad = holding_forces(w, F);
            w->mech = m0, w->ws = ws0;
        } else {
            bad = 1;
        }
        chain_ws_free(hws);
        chain_free(held);
    } else if (w->nact) {
        bad = holding_forces(w, F);
    }
    if (bad) {
        snprintf(err, errsz,
                 "%s: mechanics.actuators: the cylinders' lever arms at the start pose are dependent; no set of "
                 "forces holds it (start with init_hold off)",
                 w->opt.model_file);
        free(F);
        return -1;
    }
    const double p = w->opt.p_low;
    for (int k = 0; k < w->nact; ++k) {
        oc_act* a = &w->a[k];
        double pA = p, pB = p;
        if (F[k] >= 0) pA = (F[k] + p * a->AB) / a->AA;
        else pB = (p * a->AA - F[k]) / a->AB;
        w->y[a->iA] = pA;
        w->y[a->iB] = pB;
        const int hA = hose_of(w, a->iA), hB = hose_of(w, a->iB);
        if (hA >= 0) w->y[hA] = pA;
        if (hB >= 0) w->y[hB] = pB;
        a->F = F[k];
    }
    free(F);
    return 0;
}

// The seal friction's tanh is within 1e-4 of 1 beyond |v| = atanh(1 - 1e-4)
// v_sm = 4.95 v_sm: sliding (hyd_step).
#define SEAL_SLIDING 4.95

static int hyd_step(ode_chain* w, double H) {
    w->step_t0 = w->th;
    // The strokes, rates and commands this step integrates start here (as
    // ode_coupling.c): the balance's next step starts from their powers.
    if (w->energy) sim_energy_follow_inputs(w->energy, w->th, w->y);
    hyd_solver_inputs_changed(w->hs);
    const double h = H / w->nsub;
    for (int i = 0; i < w->nsub; ++i) {
        const int rc = hyd_solver_step(w->hs, &w->th, w->y, h);
        // hyd_solver_step calls no on_step: each sub-step's balance here.
        if (rc == HYD_OK && w->energy) sim_energy_follow_step(w->energy, w->hs, w->th, w->y, NAN);
        if (rc != HYD_OK) {
            double tb = w->th;
            const int bad = rc == HYD_ERR_NONFINITE || rc == HYD_ERR_DOMAIN ? hyd_solver_bad_state(w->hs, &tb) : -1;
            if (bad >= 0)
                snprintf(w->err, sizeof w->err, "hydraulics: state %s %s at t = %.6f s", hyd_model_state_name(w->hm, bad),
                         rc == HYD_ERR_DOMAIN ? "went below absolute zero at every step size tried" : "became non-finite",
                         tb);
            else
                snprintf(w->err, sizeof w->err, "hydraulics: %s solver stopped at t = %.6f s: %s",
                         hyd_method_name(w->opt.solver), w->th, hyd_error_text(rc));
            return -1;
        }
    }
    // The force at the end of the sub-steps (the solver's last f was at a
    // stage point), held over the ODE step.
    rhs(w, w->th, w->y, w->ydot);
    w->th = (double)(w->nstep + 1) * H; // on the step count: no drift from the mechanical clock
    for (int k = 0; k < w->nact; ++k) {
        oc_act* a = &w->a[k];
        a->F = a->Fp = w->hd->cyl_F[w->cc.act[k].cyl];
        if (a->seal) {
            // The circuit subtracted its seal friction at the step's rate
            // v0 (its rate input), Fsc: added back at the pins where
            // apply_seal holds the friction in ODE's solver instead, as the
            // line Fs0 + dFs (v - v0) within +-Fmax.
            double d;
            a->Fsc = hyd_cyl_seal(a->Fc, a->Fs, a->vst, a->vsm, a->v0, &d);
            if (fabs(a->v0) < SEAL_SLIDING * a->vsm) {
                // At rest and through the knee: the law's tangent at v0,
                // its negative part (the Stribeck fall) left out.
                a->Fs0 = a->Fsc, a->dFs = d > 0.0 ? d : 0.0, a->Fmax = a->Fc + a->Fs;
            } else {
                // Sliding: the law is mag(v0) sign(v) to 1e-4. As a damper
                // of its slope at zero, mag(v0)/v_sm, saturating at
                // mag(v0), it stays that while the step keeps sliding and
                // follows the law through zero when the step stops it
                // (the tangent, flat here, would hold +mag past zero).
                const double r = a->v0 / a->vst, mag = a->Fc + a->Fs * exp(-r * r);
                a->dFs = mag / a->vsm, a->Fs0 = a->dFs * a->v0, a->Fmax = mag;
            }
        }
        if (!isfinite(w->a[k].F)) {
            snprintf(w->err, sizeof w->err, "hydraulics: the force of actuator %s became non-finite at t = %.6f s",
                     w->cc.act[k].name, w->th);
            return -1;
        }
    }
    if (w->slew_on) {
        w->slew_F = w->hd->cyl_F[w->slew_cyl];
        if (!isfinite(w->slew_F)) {
            snprintf(w->err, sizeof w->err, "hydraulics: the slew rack's force became non-finite at t = %.6f s", w->th);
            return -1;
        }
    }
    return 0;
}

// ---- build ----

static void to_dmatrix(const double R[9], dMatrix3 M) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M[4 * i + j] = R[3 * i + j];
        M[4 * i + 3] = 0;
    }
}

// A link of the linkage as a body from a to b (world) [m] of mass m [kg]: a
// uniform bar, its centre at the middle, its x along a->b, its y the
// parent's y (rot: the parent's axes, row-major; ang: the bar's angle from
// the parent's x towards its z [rad]); about its centre m l^2/12 about y
// and z (linkage_links' uniform link) and m r^2/2 about x for a bar of
// radius r = 0.05 m (the turn about its own axis, which no joint drives).
static dBodyID link_body(dWorldID world, const double prot[9], double ang, const double a[3], const double b[3],
                         double len, double m) {
    const double ct = cos(ang), st = sin(ang);
    // R = Rparent Ry with Ry's columns x = (c, 0, s), y, z = (-s, 0, c).
    const double Ry[9] = {ct, 0, -st, 0, 1, 0, st, 0, ct};
    double R[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R[3 * r + c] = prot[3 * r] * Ry[c] + prot[3 * r + 1] * Ry[3 + c] + prot[3 * r + 2] * Ry[6 + c];
    dMass ms;
    dMassSetZero(&ms);
    const double Ib = m * len * len / 12.0, Ia = 0.5 * m * 0.05 * 0.05;
    dMassSetParameters(&ms, m, 0, 0, 0, Ia, Ib, Ib, 0, 0, 0);
    dBodyID body = dBodyCreate(world);
    dBodySetPosition(body, 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]));
    dMatrix3 M;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) M[4 * i + j] = R[3 * i + j];
        M[4 * i + 3] = 0;
    }
    dBodySetRotation(body, M);
    dBodySetMass(body, &ms);
    return body;
}

static dJointID loop_hinge(dWorldID world, dBodyID b1, dBodyID b2, const double at[3], const double ax[3]) {
    dJointID j = dJointCreateHinge(world, 0);
    dJointAttach(j, b1, b2);
    dJointSetHingeAnchor(j, at[0], at[1], at[2]);
    dJointSetHingeAxis(j, ax[0], ax[1], ax[2]);
    return j;
}

// Actuator k's linkage as bodies in the start pose (the chain's poses in
// b[]): the loop solved at the knuckle's start angle (linkage_eval), the
// link A-P and the rocker C-P as bars, hinged at A to the parent, at C to
// the knuckle and at P to each other (axes the parent's -y, as the
// knuckle's). ODE holds the loop closed; the formula only places it.
static int build_linkage(ode_chain* w, int k, char* err, size_t errsz) {
    const crane_act* c = &w->cc.act[k];
    oc_act* a = &w->a[k];
    const linkage* lk = &c->lk;
    chain_update(w->mech, w->ws, w->qstart, NULL);
    const double q = chain_joint_q(w->mech, w->ws, c->body_b, NULL);
    linkage_state s;
    if (linkage_eval(lk, q, &s)) {
        snprintf(err, errsz, "%s: mechanics.actuators[%d] (%s).linkage: the loop does not close at the start angle %g rad",
                 w->opt.model_file, k, c->name, q);
        return -1;
    }
    const oc_body* pb = &w->b[c->body_a];
    // A point (x, z) of the parent's plane in the world.
    double A[3], C[3], P[3];
    const double* pts[3] = {lk->d.link_pin, s.C, s.P};
    double* out[3] = {A, C, P};
    for (int i = 0; i < 3; ++i)
        for (int r = 0; r < 3; ++r) out[i][r] = pb->p[r] + pb->R[3 * r] * pts[i][0] + pb->R[3 * r + 2] * pts[i][1];
    a->link = link_body(w->world, pb->R, s.link_angle, A, P, lk->d.link_len, lk->d.link_mass);
    a->rocker = link_body(w->world, pb->R, s.rocker_angle, C, P, lk->d.rocker_len, lk->d.rocker_mass);
    a->Pl[0] = 0.5 * lk->d.link_len, a->Pl[1] = a->Pl[2] = 0.0;
    const double ax[3] = {-pb->R[1], -pb->R[4], -pb->R[7]};
    loop_hinge(w->world, a->link, pb->body, A, ax);
    loop_hinge(w->world, a->rocker, w->b[c->body_b].body, C, ax);
    loop_hinge(w->world, a->link, a->rocker, P, ax);
    return 0;
}

typedef struct build_args {
    ode_chain* w;
    char* err;
    size_t errsz;
} build_args;

static int build(void* arg) {
    build_args* ba = arg;
    ode_chain* w = ba->w;
    const char* mf = w->opt.model_file;
    if (w->hosted) {
        w->world = (dWorldID)w->opt.host_world;
    } else {
        w->world = ow_world_new(w->g, w->opt.erp, w->opt.cfm, &w->threading);
        dWorldSetAutoDisableFlag(w->world, 0);
    }

    chain_update(w->mech, w->ws, w->qstart, NULL);
    for (int i = 0; i < w->nbody; ++i) {
        const chain_body_def* d = chain_body(w->mech, i);
        oc_body* b = &w->b[i];
        b->dof = chain_body_dof(w->mech, i);
        b->revolute = d->joint == CHAIN_REVOLUTE;
        b->lo = -INFINITY, b->hi = INFINITY;
        double Rl[9], pl[3]; // in the base frame
        chain_body_pose(w->mech, w->ws, i, Rl, pl);
        // Into the world: R = Rb Rl, p = pb + Rb pl (the identity unhosted).
        for (int r = 0; r < 3; ++r) {
            b->p[r] = w->pb[r];
            for (int c = 0; c < 3; ++c) {
                b->p[r] += w->Rb[3 * r + c] * pl[c];
                double v = 0.0;
                for (int k = 0; k < 3; ++k) v += w->Rb[3 * r + k] * Rl[3 * k + c];
                b->R[3 * r + c] = v;
            }
        }
        // The column on the ground: a fixed frame (hosted on a body it is a
        // body, so that it moves with its base).
        if (i == 0 && d->fixed && !(w->hosted && w->opt.host_base)) continue;
        if (!(d->mass > 0)) {
            snprintf(ba->err, ba->errsz, "%s: bodies[%d] (%s).mass: %g kg; the ODE world moves only bodies with mass",
                     mf, i, d->name, d->mass);
            return -1;
        }
        dMass m;
        dMassSetZero(&m);
        dMassSetParameters(&m, d->mass, 0, 0, 0, d->inertia[0][0], d->inertia[1][1], d->inertia[2][2], d->inertia[0][1],
                           d->inertia[0][2], d->inertia[1][2]);
        if (!dMassCheck(&m)) {
            snprintf(ba->err, ba->errsz, "%s: bodies[%d] (%s).inertia: not an inertia tensor ODE accepts", mf, i,
                     d->name);
            return -1;
        }
        double c[3];
        for (int k = 0; k < 3; ++k) {
            c[k] = b->p[k] + b->R[3 * k] * d->com[0] + b->R[3 * k + 1] * d->com[1] + b->R[3 * k + 2] * d->com[2];
            b->org[k] = -d->com[k];
        }
        b->body = dBodyCreate(w->world);
        dBodySetPosition(b->body, c[0], c[1], c[2]);
        dMatrix3 M;
        to_dmatrix(b->R, M);
        dBodySetRotation(b->body, M);
        dBodySetMass(b->body, &m);
    }
    for (int i = 0; i < w->nbody; ++i) {
        const chain_body_def* d = chain_body(w->mech, i);
        oc_body* b = &w->b[i];
        if (!b->body) continue;
        dBodyID parent = i == 0 ? (dBodyID)w->opt.host_base : w->b[d->parent].body;
        if (d->fixed) {
            b->joint = dJointCreateFixed(w->world, 0);
            dJointAttach(b->joint, b->body, parent);
            dJointSetFixed(b->joint);
            continue;
        }
        b->q0 = w->qstart[b->dof];
        if (b->revolute) {
            // The slew turns about base z; a boom about its frame's -y.
            const double ax[3] = {i == 0 ? w->Rb[2] : -b->R[1], i == 0 ? w->Rb[5] : -b->R[4],
                                  i == 0 ? w->Rb[8] : -b->R[7]};
            b->joint = dJointCreateHinge(w->world, 0);
            dJointAttach(b->joint, b->body, parent);
            dJointSetHingeAnchor(b->joint, b->p[0], b->p[1], b->p[2]);
            dJointSetHingeAxis(b->joint, ax[0], ax[1], ax[2]);
            b->raw = dJointGetHingeAngle(b->joint);
        } else {
            b->joint = dJointCreateSlider(w->world, 0);
            dJointAttach(b->joint, b->body, parent);
            dJointSetSliderAxis(b->joint, b->R[0], b->R[3], b->R[6]);
        }
        // The chain's limits, relative to the joint's zero.
        const double q = b->q0;
        if (q < d->q_min - 1e-12 || q > d->q_max + 1e-12) {
            snprintf(ba->err, ba->errsz, "%s: q0[%d]: the start %g %s of bodies[%d] (%s) is outside its limits [%g, %g]",
                     mf, b->dof, q, b->revolute ? "rad" : "m", i, d->name, d->q_min, d->q_max);
            return -1;
        }
        b->lo = d->q_min - q;
        b->hi = d->q_max - q;
        if (i == 0 && w->slew_on && w->slew_stroke > 0) {
            // The rack's ends: slew within +-s/(2 r) (crane_slew_stroke).
            const double smax = 0.5 * w->slew_stroke / w->cc.slew.pinion_radius;
            if (q < -smax - 1e-12 || q > smax + 1e-12) {
                snprintf(ba->err, ba->errsz,
                         "initial slew %.1f deg is outside the slew cylinder's range +-%.1f deg", q * 180.0 / M_PI,
                         smax * 180.0 / M_PI);
                return -1;
            }
            if (w->opt.stop_limits) {
                if (-smax - q > b->lo) b->lo = -smax - q;
                if (smax - q < b->hi) b->hi = smax - q;
            }
        }
    }
    for (int k = 0; k < w->nact; ++k)
        if (w->cc.act[k].kind == CRANE_ACT_LINKAGE && build_linkage(w, k, ba->err, ba->errsz)) return -1;
    // The cylinders' stroke ends as stops on the joint between their two
    // bodies (the only joint that changes their length), where one is the
    // other's parent; a cylinder across more joints meets its end stop in
    // the circuit (the cylinder's stop spring) alone.
    for (int k = 0; k < w->nact && w->hm; ++k) {
        const crane_act* c = &w->cc.act[k];
        const double x = act_geometry(w, k, NULL, NULL, NULL, NULL) - c->closed_length;
        if (x < -1e-9 || x > c->stroke + 1e-9) {
            snprintf(ba->err, ba->errsz,
                     "%s: q0: actuators[%d] (%s) starts at a stroke of %.4f m, outside its cylinder's [0, %g] m", mf, k,
                     c->name, x, c->stroke);
            return -1;
        }
        w->a[k].stop_body = -1;
        const int jb = chain_body(w->mech, c->body_b)->parent == c->body_a   ? c->body_b
                       : chain_body(w->mech, c->body_a)->parent == c->body_b ? c->body_a
                                                                            : -1;
        if (jb < 0 || w->b[jb].dof < 0 || !w->opt.stop_limits || !(c->stroke > 0)) continue;
        oc_body* b = &w->b[jb];
        w->a[k].stop_body = jb;
        const double h = b->revolute ? 0.5 * M_PI / 180.0 : c->stroke / 400.0;
        const double span = b->revolute ? M_PI : 20.0 * (c->closed_length + c->stroke);
        const double lo = stroke_end(w, k, b->dof, -1.0, h, span) - b->q0;
        const double hi = stroke_end(w, k, b->dof, 1.0, h, span) - b->q0;
        if (lo > b->lo) b->lo = lo;
        if (hi < b->hi) b->hi = hi;
    }
    for (int i = 0; i < w->nbody; ++i)
        if (w->b[i].dof >= 0) apply_stops(&w->b[i]);
    // implicit_seal: a cylinder across one moving joint with seal friction.
    for (int k = 0; k < w->nact && w->hm && w->opt.implicit_seal; ++k) {
        oc_act* a = &w->a[k];
        const crane_act* c = &w->cc.act[k];
        const int jb = chain_body(w->mech, c->body_b)->parent == c->body_a   ? c->body_b
                       : chain_body(w->mech, c->body_a)->parent == c->body_b ? c->body_a
                                                                            : -1;
        if (jb < 0 || w->b[jb].dof < 0) continue;
        const char* cyl = c->cylinder; // the circuit's component of that name (crane_chain_bind)
        char path[160];
        double v[4] = {0, 0, 0, 0};
        static const char* const par[4] = {"coulomb", "stribeck", "v_stribeck", "v_smooth"};
        int ok = 1;
        for (int j = 0; j < 4; ++j) {
            snprintf(path, sizeof path, "%s.%s", cyl, par[j]);
            ok &= hyd_model_get(w->hm, path, &v[j]) == 0;
        }
        if (!ok || !(v[0] >= 0.0 && v[1] >= 0.0) || !(v[0] + v[1] > 0.0) || !(v[2] > 0.0) || !(v[3] > 0.0))
            continue;
        a->seal = 1, a->seal_body = jb;
        a->Fc = v[0], a->Fs = v[1], a->vst = v[2], a->vsm = v[3];
        w->b[jb].seal = 1;
        // apply_seal's lever arms, one per DOF.
        if (!w->dL && !(w->dL = calloc((size_t)w->ndof, sizeof *w->dL))) {
            snprintf(ba->err, ba->errsz, "ode chain world: out of memory");
            return -1;
        }
    }
    return 0;
}

static void free_world(ode_chain* w);

ode_chain* ode_chain_create(const crane_chain* cc, const ode_chain_opts* o, char* err, size_t errsz) {
    ode_chain_opts opt = o ? *o : ode_chain_default_opts();
    if (!opt.model_file) opt.model_file = "model";
    if (!(opt.dt_ode > 0) || !(opt.dt_hyd > 0) || opt.dt_hyd > opt.dt_ode * (1 + 1e-9) ||
        fabs(opt.dt_ode / opt.dt_hyd - floor(opt.dt_ode / opt.dt_hyd + 0.5)) > 1e-6) {
        snprintf(err, errsz, "ode chain world: need 0 < dt_hyd <= dt_ode, dt_ode a whole multiple of dt_hyd; got %g s, %g s",
                 opt.dt_hyd, opt.dt_ode);
        return NULL;
    }
    if (cc->tip_body < 0 || cc->tip_body >= cc->nbody) {
        snprintf(err, errsz, "%s: mechanics.tip: body %d is not in the chain (%d bodies)", opt.model_file, cc->tip_body,
                 cc->nbody);
        return NULL;
    }
    ode_chain* w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errsz, "ode chain world: out of memory");
        return NULL;
    }
    w->opt = opt;
    if (crane_chain_copy(&w->cc, cc)) {
        free(w);
        snprintf(err, errsz, "ode chain world: out of memory");
        return NULL;
    }
    w->hosted = opt.host_world != NULL;
    {
        int any = 0;
        for (int k = 0; k < 9; ++k) any |= opt.base_rot[k] != 0.0;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) w->Rb[3 * r + c] = any ? opt.base_rot[3 * r + c] : r == c ? 1.0 : 0.0;
        for (int k = 0; k < 3; ++k) w->pb[k] = w->hosted ? opt.base_pos[k] : 0.0;
        if (!w->hosted && any) {
            snprintf(err, errsz, "ode chain world: base_rot is for a hosted world only");
            free_world(w);
            return NULL;
        }
    }
    // A slew drive turns the column: its joint is then a DOF (the copy's
    // slew_free, so everything sized by the chain counts it).
    if (opt.slew_drive) w->cc.slew_free = true;
    if (opt.slew_drive && !opt.circuit) {
        snprintf(err, errsz, "ode chain world: a slew drive needs the circuit");
        free_world(w);
        return NULL;
    }
    char e[320];
    // The booms without the linkages' links: the world makes them bodies.
    w->mech = crane_chain_mechanism_links(&w->cc, opt.tip_mass, w->cc.slew_free, opt.slew0, false, e, sizeof e);
    if (!w->mech) {
        snprintf(err, errsz, "%s: mechanics.%s", opt.model_file, e);
        free_world(w);
        return NULL;
    }
    w->ws = chain_ws_create(w->mech);
    w->nbody = cc->nbody, w->nact = cc->nact, w->nfn = cc->nfn, w->ndof = chain_ndof(w->mech);
    for (int k = 0; k < cc->nact; ++k) w->nlinkage += cc->act[k].kind == CRANE_ACT_LINKAGE;
    const size_t nd = (size_t)(w->ndof > 0 ? w->ndof : 1);
    w->b = calloc((size_t)w->nbody, sizeof *w->b);
    w->a = calloc((size_t)(w->nact > 0 ? w->nact : 1), sizeof *w->a);
    w->tau = calloc(nd, sizeof *w->tau);
    w->u = calloc((size_t)(w->nfn > 0 ? w->nfn : 1), sizeof *w->u);
    w->qstart = calloc(nd, sizeof *w->qstart);
    w->qs = calloc(nd, sizeof *w->qs);
    if (!w->ws || !w->b || !w->a || !w->tau || !w->u || !w->qstart || !w->qs) {
        snprintf(err, errsz, "ode chain world: out of memory");
        free_world(w);
        return NULL;
    }
    if (opt.q0) memcpy(w->qstart, opt.q0, (size_t)w->ndof * sizeof *w->qstart);
    for (int k = 0; k < w->ndof; ++k)
        if (!isfinite(w->qstart[k])) {
            snprintf(err, errsz, "%s: q0[%d]: not a finite number", opt.model_file, k);
            free_world(w);
            return NULL;
        }
    for (int k = 0; k < w->nact; ++k) w->a[k].iA = w->a[k].iB = -1, w->a[k].stop_body = -1;
    w->g = cc->gravity;
    ow_ode_acquire();
    w->acquired = 1;
    w->hm = opt.circuit;
    if (w->hm && hyd_create(w, err, errsz)) {
        free_world(w);
        return NULL;
    }
    build_args ba = {w, err, errsz};
    char fatal[200];
    const int rc = ow_ode_call(build, &ba, fatal, sizeof fatal);
    if (rc == OW_ODE_FAILED) {
        w->dead = 1;
        snprintf(err, errsz, "ode chain world: ODE failed while building the world (%.150s): a mass, size or position "
                             "far outside the physical range",
                 fatal);
    }
    if (rc || (w->hm && hyd_init_state(w, err, errsz))) {
        free_world(w);
        return NULL;
    }
    // The hydraulic data at the start state (pump pressure, spools, relief
    // states), so what ode_chain_circuit_state gives before the first step
    // is the start's, not zeros. The evaluation also sets the circuit's
    // switching memories in hd (relief and check valves) from the start
    // state rather than their zero defaults, as the analytic mode's output
    // at t = 0 does with its own hd; on the 3-boom scenario the booms'
    // stroke RMS against it moves by +0.002 to +0.004 mm.
    if (w->hm) rhs(w, w->th, w->y, w->ydot);
    return w;
}

static int destroy_ode(void* arg) {
    ode_chain* w = arg;
    // Hosted: the bodies and joints are the host's world's, gone with it.
    if (w->world && !w->hosted) {
        dWorldSetStepThreadingImplementation(w->world, NULL, NULL);
        dWorldDestroy(w->world);
    }
    if (w->threading && !w->dead) dThreadingFreeImplementation(w->threading);
    return 0;
}

static void free_world(ode_chain* w) {
    if (w->acquired) {
        char fatal[200];
        ow_ode_call(destroy_ode, w, fatal, sizeof fatal);
        ow_ode_release();
    }
    if (w->hs) hyd_solver_destroy(w->hs);
    if (w->hd) hyd_data_free(w->hd);
    hyd_fast_free(w->fk);
    free(w->y);
    free(w->ydot);
    free(w->pres);
    chain_ws_free(w->ws);
    chain_free(w->mech);
    free(w->b);
    free(w->a);
    free(w->tau);
    free(w->u);
    free(w->qstart);
    free(w->qs);
    free(w->dL);
    crane_chain_free(&w->cc);
    free(w);
}

void ode_chain_destroy(ode_chain* w) {
    if (w) free_world(w);
}

// ---- stepping ----

static void apply_forces(ode_chain* w) {
    for (int k = 0; k < w->nact; ++k) {
        const double F = w->a[k].Fp;
        if (F == 0.0) continue;
        const crane_act* c = &w->cc.act[k];
        double u[3], pa[3], pb[3];
        act_geometry(w, k, NULL, u, pa, pb);
        const dBodyID ba = w->b[c->body_a].body, bb = w->a[k].link ? w->a[k].link : w->b[c->body_b].body;
        if (bb) dBodyAddForceAtPos(bb, F * u[0], F * u[1], F * u[2], pb[0], pb[1], pb[2]);
        if (ba) dBodyAddForceAtPos(ba, -F * u[0], -F * u[1], -F * u[2], pa[0], pa[1], pa[2]);
    }
    for (int i = 0; i < w->nbody; ++i) {
        const oc_body* b = &w->b[i];
        if (b->dof < 0 || w->tau[b->dof] == 0.0) continue;
        if (b->revolute) dJointAddHingeTorque(b->joint, w->tau[b->dof]);
        else dJointAddSliderForce(b->joint, w->tau[b->dof]);
    }
    if (w->slew_on) {
        // The rack's force F r (crane_slew_torque) and the slewing ring's
        // viscous friction [N m s/rad] on the column's hinge.
        dJointAddHingeTorque(w->b[0].joint, crane_slew_torque(&w->cc.slew, w->slew_F) -
                                                w->cc.slew.damping * dJointGetHingeAngleRate(w->b[0].joint));
    }
}

// implicit_seal: the seal friction of each cylinder across one joint, by
// the circuit's own law (hyd_cyl_seal: (F_c + F_s exp(-(v/v_st)^2))
// tanh(v/v_sm), smooth through zero), as a line solved by ODE with the
// step's end velocities: a linearly implicit step of the friction, where
// the analytic mode's implicit solver holds the same law in the cylinder's
// equation of motion. hyd_step gives each cylinder its line F_k(v) = Fs0_k
// + c_k (v - v0_k) within +-Fmax_k: at rest and through the knee the law's
// tangent at the step's rate v0 (c_k >= 0, the Stribeck fall explicit);
// sliding (|v0| >= 4.95 v_sm, the tanh within 1e-4 of 1) a damper of the
// law's slope at zero saturating at the law's magnitude at v0 (the tangent
// is flat there, and a step that stops the cylinder would carry the
// sliding friction past zero: explicit Coulomb friction's chatter). On
// joint j with cylinders k of lever arm l_k = dL_k/dq (m/rad on a hinge, -
// on a slider) the friction's generalized force is
//   tau(qd) = -sum_k l_k [Fs0_k + c_k l_k (qd - qd0)]
// [N m or N]. A joint motor with target rate vel and constraint force
// mixing CFM gives ODE's row lambda = (vel - qd_new)/CFM within +-fmax, a
// damper implicit in the new rate: C = sum l_k^2 c_k = 1/CFM and vel = qd0
// - sum l_k Fs0_k / C reproduce tau, fmax = sum |l_k| Fmax_k its
// saturation. Kept explicit (the circuit's friction at v0, in the force at
// the pins): a joint at one of its ODE stops (ODE then applies a powered
// motor as a fixed force, not a damper), and a joint whose C is below 1e-9
// of its cylinders' steepest slope (l^2 (F_c + F_s) / v_sm), where the
// implicit part is nothing and vel would overflow.
static int stop_active(const oc_body* b) {
    double x, lo, hi;
    if (b->revolute) {
        x = dJointGetHingeAngle(b->joint);
        lo = dJointGetHingeParam(b->joint, dParamLoStop), hi = dJointGetHingeParam(b->joint, dParamHiStop);
    } else {
        x = dJointGetSliderPosition(b->joint);
        lo = dJointGetSliderParam(b->joint, dParamLoStop), hi = dJointGetSliderParam(b->joint, dParamHiStop);
    }
    // As ODE's own test (dxJointLimitMotor::testRotationalLimit and the
    // slider's): at or beyond a stop the limit row replaces the motor's.
    return x <= lo || x >= hi;
}

static void apply_seal(ode_chain* w) {
    if (!w->dL) return; // no cylinder's friction held this way
    for (int i = 0; i < w->nbody; ++i) {
        oc_body* b = &w->b[i];
        b->motor = 0, b->C = b->vel = b->fmax = b->steep = 0.0;
    }
    ode_chain_q(w, w->qs, NULL);
    chain_update(w->mech, w->ws, w->qs, NULL);
    // Per joint: C, sum l F0 (in vel until the end), the force limit, and
    // the steepest slope.
    for (int k = 0; k < w->nact; ++k) {
        oc_act* a = &w->a[k];
        if (!a->seal) continue;
        oc_body* b = &w->b[a->seal_body];
        const crane_act* c = &w->cc.act[k];
        crane_act_length(c, w->mech, w->ws, NULL, w->dL, NULL);
        const double l = w->dL[b->dof];
        a->lever = l;
        b->C += l * l * a->dFs;
        b->vel += l * a->Fs0;
        b->fmax += fabs(l) * a->Fmax;
        b->steep += l * l * (a->Fc + a->Fs) / a->vsm;
    }
    for (int i = 0; i < w->nbody; ++i) {
        oc_body* b = &w->b[i];
        if (b->dof < 0 || !b->seal) continue;
        const double lF0 = b->vel;
        b->motor = b->C > 1e-9 * b->steep && !stop_active(b);
        if (b->motor) {
            double qd;
            joint_q(w, b, &qd);
            b->qd0 = qd;
            b->vel = qd - lF0 / b->C;
            set_param(b, dParamCFM, 1.0 / b->C);
            set_param(b, dParamVel, b->vel);
        }
        // fmax 0 switches the motor off (ODE adds no row).
        set_param(b, dParamFMax, b->motor ? b->fmax : 0.0);
    }
    // The force at the pins: without the seal friction where the motor
    // holds it.
    for (int k = 0; k < w->nact; ++k) {
        oc_act* a = &w->a[k];
        a->Fp = a->seal && w->b[a->seal_body].motor ? a->F + a->Fsc : a->F;
    }
}

// After the step: the seal friction the motor applied, shared out to its
// cylinders by their linearised laws (scaled where the force limit cut the
// sum), so each cylinder's F is its force over the step, friction included,
// as the analytic mode reports it.
static void seal_applied(ode_chain* w) {
    if (!w->dL) return;
    for (int k = 0; k < w->nact; ++k) {
        oc_act* a = &w->a[k];
        if (!a->seal || !w->b[a->seal_body].motor) continue;
        const oc_body* b = &w->b[a->seal_body];
        double qd;
        joint_q(w, b, &qd);
        // ODE's row: lambda = C (vel - qd), within +-fmax.
        const double lin = b->C * (b->vel - qd);
        const double lam = lin > b->fmax ? b->fmax : lin < -b->fmax ? -b->fmax : lin;
        const double scale = lin != 0.0 ? lam / lin : 1.0;
        a->F = a->Fp - scale * (a->Fs0 + a->dFs * a->lever * (qd - b->qd0));
    }
}

static int body_finite(dBodyID b) {
    const dReal* p = dBodyGetPosition(b);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* a = dBodyGetAngularVel(b);
    for (int i = 0; i < 3; ++i)
        if (!isfinite(p[i]) || !isfinite(v[i]) || !isfinite(a[i])) return 0;
    return 1;
}

typedef struct step_args {
    ode_chain* w;
    long n;
} step_args;

// One step's work before ODE's step: the strokes read, the hydraulic
// sub-steps, the forces on the bodies.
static int pre_step(ode_chain* w) {
    for (int k = 0; k < w->nact; ++k)
        w->a[k].x0 = act_geometry(w, k, &w->a[k].v0, NULL, NULL, NULL) - w->cc.act[k].closed_length;
    if (w->slew_on) w->slew_x0 = slew_kinematics(w, &w->slew_v0);
    if (w->hm && hyd_step(w, w->opt.dt_ode)) return -1;
    // The seal's motor first: apply_forces applies the part of the
    // cylinder force ODE's solver does not hold (apply_seal splits it).
    apply_seal(w);
    apply_forces(w);
    return 0;
}

// And after it: the clock, the hinges' turns, the bodies' check.
static int post_step(ode_chain* w) {
    seal_applied(w);
    ++w->nstep;
    w->t = (double)w->nstep * w->opt.dt_ode;
    read_turns(w);
    for (int i = 0; i < w->nbody; ++i)
        if (w->b[i].body && !body_finite(w->b[i].body)) {
            snprintf(w->err, sizeof w->err, "ode chain world: body %s became non-finite at t = %.6f s",
                     w->cc.body[i].def.name, w->t);
            return -1;
        }
    for (int k = 0; k < w->nact; ++k)
        if (w->a[k].link && !(body_finite(w->a[k].link) && body_finite(w->a[k].rocker))) {
            snprintf(w->err, sizeof w->err, "ode chain world: the linkage of %s became non-finite at t = %.6f s",
                     w->cc.act[k].name, w->t);
            return -1;
        }
    return 0;
}

static int step_n(void* arg) {
    step_args* sa = arg;
    ode_chain* w = sa->w;
    for (long s = 0; s < sa->n; ++s) {
        if (pre_step(w)) return -1;
        dWorldStep(w->world, w->opt.dt_ode);
        if (post_step(w)) return -1;
    }
    return 0;
}

int ode_chain_host_pre(ode_chain* w) {
    if (w->failed) return -1;
    if (pre_step(w)) w->failed = 1;
    return w->failed ? -1 : 0;
}

int ode_chain_host_post(ode_chain* w) {
    if (w->failed) return -1;
    if (post_step(w)) w->failed = 1;
    return w->failed ? -1 : 0;
}

void ode_chain_host_failed(ode_chain* w) {
    w->dead = w->failed = 1;
    if (!w->err[0]) snprintf(w->err, sizeof w->err, "ode chain world: its host's world failed in ODE");
}

struct dxBody* ode_chain_body_id(const ode_chain* w, int i, double org[3]) {
    if (i < 0 || i >= w->nbody) return NULL;
    if (org) memcpy(org, w->b[i].org, sizeof w->b[i].org);
    return w->b[i].body;
}

struct dxBody* ode_chain_link_body(const ode_chain* w, int k, int which, double* len) {
    if (k < 0 || k >= w->nact || !w->a[k].link) return NULL;
    if (len) len[0] = which ? w->cc.act[k].lk.d.rocker_len : w->cc.act[k].lk.d.link_len;
    return which ? w->a[k].rocker : w->a[k].link;
}

const crane_chain* ode_chain_chain(const ode_chain* w) { return &w->cc; }

void ode_chain_act_pins(const ode_chain* w, int k, double pa[3], double pb[3]) {
    if (w->dead || k < 0 || k >= w->nact) {
        for (int i = 0; i < 3; ++i) pa[i] = pb[i] = NAN;
        return;
    }
    act_geometry(w, k, NULL, NULL, pa, pb);
}

void ode_chain_set_slew_command(ode_chain* w, double u) { w->slew_u = u > 1 ? 1 : u < -1 ? -1 : (u == u ? u : 0); }

int ode_chain_slew_state(const ode_chain* w, double* x, double* v, double* F, double* pA, double* pB, int* at_stop_) {
    if (!w->slew_on) return -1;
    double xx = NAN, vv = NAN;
    if (!w->dead) xx = slew_kinematics(w, &vv);
    if (x) *x = xx;
    if (v) *v = vv;
    if (F) *F = w->slew_F;
    if (pA) *pA = w->y[w->slew_iA];
    if (pB) *pB = w->y[w->slew_iB];
    if (at_stop_) *at_stop_ = !w->dead && (at_stop(&w->b[0]) || w->hd->cyl_stop[w->slew_cyl] != 0);
    return 0;
}

int ode_chain_step(ode_chain* w, double dt) {
    if (w->failed) return -1;
    const double steps = floor(dt / w->opt.dt_ode + 0.5);
    step_args sa = {w, steps > 1e12 ? (long)1e12 : steps < 1 ? 1 : (long)steps};
    if (w->hosted) {
        snprintf(w->err, sizeof w->err, "ode chain world: hosted; its host steps it (ode_chain_host_pre, _post)");
        w->failed = 1;
        return -1;
    }
    char fatal[200];
    const int rc = ow_ode_call(step_n, &sa, fatal, sizeof fatal);
    if (rc == OW_ODE_FAILED) {
        w->dead = 1;
        snprintf(w->err, sizeof w->err, "ode chain world: ODE failed in a step at t = %.6f s (%.150s)", w->t, fatal);
    }
    if (rc) w->failed = 1;
    return rc ? -1 : 0;
}

const char* ode_chain_error(const ode_chain* w) { return w->err; }
double ode_chain_time(const ode_chain* w) { return w->t; }
int ode_chain_ndof(const ode_chain* w) { return w->ndof; }
int ode_chain_nact(const ode_chain* w) { return w->nact; }
int ode_chain_nfn(const ode_chain* w) { return w->nfn; }

void ode_chain_set_commands(ode_chain* w, const double* u) {
    for (int f = 0; f < w->nfn; ++f) {
        const double v = u[f];
        w->u[f] = v > 1 ? 1 : v < -1 ? -1 : (v == v ? v : 0);
    }
}

void ode_chain_set_forces(ode_chain* w, const double* F) {
    if (w->hm) return; // the circuit's forces
    for (int k = 0; k < w->nact; ++k) w->a[k].F = w->a[k].Fp = isfinite(F[k]) ? F[k] : 0.0;
}

void ode_chain_set_joint_forces(ode_chain* w, const double* tau) {
    for (int k = 0; k < w->ndof; ++k) w->tau[k] = isfinite(tau[k]) ? tau[k] : 0.0;
}

// Reads after ODE failed in the world would ask ODE again: they give NaN.
void ode_chain_q(const ode_chain* w, double* q, double* qd) {
    for (int i = 0; i < w->nbody; ++i) {
        const oc_body* b = &w->b[i];
        if (b->dof < 0) continue;
        double r = NAN, x = NAN;
        if (!w->dead) x = joint_q(w, b, &r);
        if (q) q[b->dof] = x;
        if (qd) qd[b->dof] = r;
    }
}

double ode_chain_act_length(const ode_chain* w, int k, double* rate) {
    if (w->dead || k < 0 || k >= w->nact) {
        if (rate) *rate = NAN;
        return NAN;
    }
    return act_geometry(w, k, rate, NULL, NULL, NULL);
}

double ode_chain_act_force(const ode_chain* w, int k, double* pA, double* pB) {
    if (k < 0 || k >= w->nact) return NAN;
    const oc_act* a = &w->a[k];
    if (pA) *pA = w->hm ? w->y[a->iA] : 0.0;
    if (pB) *pB = w->hm ? w->y[a->iB] : 0.0;
    return a->F;
}

void ode_chain_tip(const ode_chain* w, double p[3], double v[3]) {
    if (w->dead) {
        p[0] = p[1] = p[2] = NAN;
        if (v) v[0] = v[1] = v[2] = NAN;
        return;
    }
    frame_point(w, w->cc.tip_body, w->cc.tip, p);
    if (v) frame_point_vel(w, w->cc.tip_body, w->cc.tip, v);
}

void ode_chain_body_pose(const ode_chain* w, int i, double R[9], double p[3]) {
    const oc_body* b = &w->b[i];
    if (R) {
        if (b->body && !w->dead) {
            const dReal* M = dBodyGetRotation(b->body);
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) R[3 * r + c] = M[4 * r + c];
        } else {
            memcpy(R, b->R, sizeof b->R);
        }
    }
    if (p) {
        const double zero[3] = {0, 0, 0};
        if (w->dead && b->body) p[0] = p[1] = p[2] = NAN;
        else frame_point(w, i, zero, p);
    }
}

int ode_chain_act_at_stop(const ode_chain* w, int k) {
    if (w->dead || k < 0 || k >= w->nact) return 0;
    const oc_act* a = &w->a[k];
    if (a->stop_body >= 0 && at_stop(&w->b[a->stop_body])) return 1;
    return w->hm && w->hd->cyl_stop[w->cc.act[k].cyl] != 0;
}

void ode_chain_circuit_state(const ode_chain* w, const double** y, const hyd_data** hd) {
    if (y) *y = w->hm ? w->y : NULL;
    if (hd) *hd = w->hm ? w->hd : NULL;
}

// sim_energy_eval_fn: the circuit at (t, y) with the inputs the sub-steps
// integrate there (set_inputs' extrapolated strokes), into the balance's
// own data, so the world's hd is left as the last step had it.
static const hyd_data* energy_eval(void* user, double t, const double* y) {
    ode_chain* w = user;
    hyd_data* d = sim_energy_data(w->energy);
    const double tau = t - w->step_t0;
    for (int k = 0; k < w->nact; ++k) {
        const int c = w->cc.act[k].cyl;
        d->cyl_x[c] = w->a[k].x0 + w->a[k].v0 * tau;
        d->cyl_v[c] = w->a[k].v0;
    }
    for (int f = 0; f < w->nfn; ++f) d->valve_cmd[w->cc.fn[f].valve_idx] = w->u[f];
    if (w->slew_on) {
        d->cyl_x[w->slew_cyl] = w->slew_x0 + w->slew_v0 * tau;
        d->cyl_v[w->slew_cyl] = w->slew_v0;
        d->valve_cmd[w->slew_valve] = w->slew_u;
    }
    hyd_eval(w->hm, d, t, y, w->ydot);
    return d;
}

int ode_chain_follow_energy(ode_chain* w, struct sim_energy* e) {
    if (!w->hm || !e) return -1;
    w->energy = e;
    if (sim_energy_follow(e, w->nh, energy_eval, w) || sim_energy_follow_sample(e, w->th, w->y, NAN)) {
        w->energy = NULL;
        return -1;
    }
    return 0;
}

// Kinetic energy of an ODE body (translation of its centre of mass and
// rotation about it, the inertia turned into the world frame) plus its
// height's potential energy, m g z [J].
static double body_energy(dBodyID b, double g) {
    dMass m;
    dBodyGetMass(b, &m);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* om = dBodyGetAngularVel(b);
    const dReal* R = dBodyGetRotation(b); // rows of 4
    // omega in body axes: R^T omega; then 1/2 w_b . I w_b.
    double wb[3];
    for (int c = 0; c < 3; ++c) wb[c] = R[c] * om[0] + R[4 + c] * om[1] + R[8 + c] * om[2];
    double rot = 0.0;
    for (int r = 0; r < 3; ++r) rot += wb[r] * (m.I[4 * r] * wb[0] + m.I[4 * r + 1] * wb[1] + m.I[4 * r + 2] * wb[2]);
    const double ke = 0.5 * m.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * rot;
    return ke + m.mass * g * dBodyGetPosition(b)[2];
}

double ode_chain_energy(const ode_chain* w) {
    if (w->dead) return NAN;
    double e = 0.0;
    for (int i = 0; i < w->nbody; ++i)
        if (w->b[i].body) e += body_energy(w->b[i].body, w->g);
    for (int k = 0; k < w->nact; ++k)
        if (w->a[k].link) e += body_energy(w->a[k].link, w->g) + body_energy(w->a[k].rocker, w->g);
    return e;
}
