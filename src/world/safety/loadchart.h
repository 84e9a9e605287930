// loadchart.h: the crane's rated capacity against outreach (the load chart):
// the hydraulic limit (static holding pressure of each cylinder against its
// port relief setting less a margin) and, on a truck, the stability limit
// (tipping moment about the support polygon's edges, with a stability
// factor) per slew sector. No SDL. See docs/safety.md.
#ifndef LOADCHART_H
#define LOADCHART_H
#include <stdbool.h>
#include <stddef.h>

#include "model.h"
#include "world_desc.h"

#ifdef __cplusplus
extern "C" {
#endif

#define LOADCHART_MAX_POINTS 1000
#define LOADCHART_MAX_SECTORS 36

/// What the stability limit needs of the truck, from its world description.
typedef struct lc_truck {
    bool present;      ///< false: no truck (validation world): hydraulic limit only
    double mass;       ///< truck without the crane [kg], its centre of mass at the chassis centre
    double column_x;   ///< slew axis along truck x from the chassis centre [m]
    double edge_x[2];  ///< support polygon front and rear x (pads, or axles without outriggers) [m]
    double edge_y;     ///< half the support width (pads, or half the track) [m]
    double hook_mass;  ///< hook block plus rope, hanging at the tip [kg]
} lc_truck;

/// From a world description: no truck for the validation world.
void lc_truck_from_world(const world_desc* wd, lc_truck* t);

typedef struct lc_opts {
    double margin;  ///< relief setting less this fraction, in [0, 0.5] (default 0.10)
    double sf;      ///< stability factor, > 1 (default 1.25)
    double lo, hi;  ///< outreach range [m], measured from the slew axis
    int n;          ///< outreach points (>= 2)
    int sectors;    ///< slew sectors over 0..180 deg (the truck is symmetric), >= 1
} lc_opts;
lc_opts lc_default_opts(void);

/// Check options: one line "--name: problem" in err, -1; else 0.
int lc_check_opts(const lc_opts* o, char* err, size_t errsz);

/// What governs a point of the printed chart.
typedef enum lc_gov {
    LC_GOV_LIFT = 0, ///< hydraulic limit, the lift cylinder
    LC_GOV_JIB,      ///< hydraulic limit, the jib cylinder
    LC_GOV_STAB,     ///< stability limit of the sector
    LC_GOV_RATED,    ///< the model's rated capacity (rated_load, rated_moment)
    LC_GOV_ACT,      ///< a crane chain's hydraulic limit: LC_GOV_ACT + k for its actuator k
} lc_gov;
/// "lift", "jib", "stability", "rated" ("actuator" for a chain's LC_GOV_ACT + k:
/// loadchart_gov_name names it).
const char* lc_gov_name(int gov);

typedef struct loadchart {
    int n, nsec;
    double R[LOADCHART_MAX_POINTS];   ///< outreach [m]
    double hyd[LOADCHART_MAX_POINTS]; ///< hydraulic limit, payload [kg] (NAN: not reachable)
    int hyd_cyl[LOADCHART_MAX_POINTS];///< the cylinder that governs it (0 lift, 1 jib)
    double hyd_q[LOADCHART_MAX_POINTS][2]; ///< the pose that governs it (q1, q2) [rad]
    double* stab;                     ///< n x nsec stability limit, payload [kg] (INFINITY: cannot tip); NULL without truck
    double (*stab_q)[3];              ///< n x nsec: the pose and slew that govern it (q1, q2, slew) [rad]; NULL without truck
    double rating[LOADCHART_MAX_POINTS]; ///< the model's rated capacity at R, payload [kg]: min(rated_load,
                                         ///< rated_moment / (g R)) less the hook (INFINITY: the model gives none)
    double* env;   ///< n x nsec raw envelope: min(hydraulic, stability) [kg], what the crane can do
    double* chart; ///< n x nsec printed chart [kg]: from the sector's minimum outreach (imin) outward the
                   ///< running minimum of min(envelope, rating); NAN closer than imin (not printed)
    double* cap;   ///< n x nsec what the limiter holds the crane to [kg]: the chart from imin outward,
                   ///< min(envelope, rating) at the point itself closer than imin
    int* gov;      ///< n x nsec: what governs cap (lc_gov)
    int* gov_at;   ///< n x nsec: the point where that limit is met: i itself closer than imin; from
                   ///< imin on a point in [imin, i], < i where a closer outreach's lower value holds
                   ///< the chart down (it may not rise with outreach)
    int imin[LOADCHART_MAX_SECTORS]; ///< per sector, the chart's minimum outreach: the first point where
                                     ///< min(envelope, rating) is largest (the chart's peak)
    double sec_lo[LOADCHART_MAX_SECTORS], sec_hi[LOADCHART_MAX_SECTORS]; ///< sector bounds [rad], 0..pi
    double reach_min, reach_max;      ///< outreach the workspace covers [m]
    bool truck;
    double hook_mass;                 ///< subtracted from the tip load (payload under the hook) [kg]
    double rated_moment, rated_load;  ///< the model's rating [N m], [kg]; 0: none
    double gravity;                   ///< the model's g [m/s^2], for the rated moment
    // A crane chain (model.chain not the two-link shorthand; docs/safety.md
    // "On a crane chain"): hyd_cyl is the actuator index, hyd_q and stab_q's
    // first two the first two boom DOFs, and the whole poses are here.
    bool chain;
    int nd;                           ///< boom DOFs (every joint coordinate, extensions included)
    int nact;                         ///< actuators
    char (*dof_name)[48];             ///< [nd] the body of each DOF
    char (*act_name)[48];             ///< [nact]
    bool* dof_prismatic;              ///< [nd] the DOF is a slide [m] (else an angle [rad])
    double (*dof_range)[2];           ///< [nd] its joint limits [rad or m]
    double* pose;                     ///< n x nd the weakest pose of the hydraulic limit
    double* stab_pose;                ///< n x nsec x nd the weakest pose of the stability limit (slew: stab_q[.][2])
    int* npose;                       ///< [n] the poses of the search within one step of R[i]
    long nsearch;                     ///< poses searched (within the joint limits and strokes)
} loadchart;

/// Compute the chart. Returns 0, or -1 with one line in err (an outreach
/// range the crane cannot reach, a relief it cannot find).
int loadchart_compute(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz);
void loadchart_free(loadchart* c);

/// The outreach the crane's workspace covers [m] (tip from the slew axis).
void loadchart_reach(const model* m, double* rmin, double* rmax);

/// Static holding limit of one pose: the largest tip mass [kg] whose holding
/// pressure stays below (1 - margin) of each cylinder's port relief; *gov:
/// the governing cylinder. -1 when the crane cannot hold itself there.
double loadchart_hyd_pose(const model* m, double q1, double q2, double margin, int* gov);

/// Stability limit of one pose at slew angle slew [rad] (0: over the cab):
/// the largest mass hanging at the tip [kg] (hook, rope and payload
/// together) with sf times its tipping moment below the restoring moment of
/// truck and crane about every support edge; INFINITY when the tip is
/// inside the support polygon. The chart subtracts the hook once.
double loadchart_stab_pose(const model* m, const lc_truck* t, double q1, double q2, double slew, double sf);

/// The sector of slew angle slew [rad] (any value; folded to 0..pi).
int loadchart_sector(const loadchart* c, double slew);
/// Rated capacity [kg] at outreach R [m] and slew [rad], what the limiter
/// holds the crane to: the column cap (the printed chart from the sector's
/// minimum outreach outward, min(envelope, rating) closer in), interpolated
/// linearly (clamped to the chart's range) and capped by the model's rating
/// at R itself; *gov (may be NULL): what governs at the chart point at or
/// below R (lc_gov).
double loadchart_capacity(const loadchart* c, double R, double slew, int* gov);
/// The raw envelope [kg] at R and slew: min(hydraulic, stability), no
/// rating, not made monotone; interpolated as loadchart_capacity.
double loadchart_envelope(const loadchart* c, double R, double slew);
/// The pose that governs point i of sector s of the printed chart, to check
/// it by simulation: q[0], q[1] the joint angles [rad], q[2] the slew [rad].
/// Hydraulic limit: its weakest pose at the outreach where it governs
/// (gov_at), slewed to the sector's middle (the hydraulic limit does not
/// depend on the slew); stability: the weakest pose and slew angle; rated:
/// the weakest pose of the raw envelope there.
void loadchart_point_pose(const loadchart* c, int i, int s, double q[3]);
/// What governs, by name: lc_gov_name, a chain's actuator by its name.
const char* loadchart_gov_name(const loadchart* c, int gov);
/// A crane chain's governing pose of point i, sector s: q[nd] every boom
/// joint coordinate [rad or m], *slew [rad]; as loadchart_point_pose picks it.
void loadchart_point_pose_chain(const loadchart* c, int i, int s, double* q, double* slew);

/// The model's rated capacity [kg] at R [m] (payload: the hook subtracted);
/// INFINITY when the model gives no rating.
double loadchart_rating(const loadchart* c, double R);

/// Port relief cracking setting [Pa] of each chamber (A, B) of actuator k.
int loadchart_reliefs(const model* m, int k, double p[2]);
/// The same for the circuit's cylinder cyl (its index in h).
int loadchart_cylinder_reliefs(const struct hyd_model* h, int cyl, double p[2]);

// The chart's two files share (loadchart.c, loadchart_chain.c: a crane
// chain's chart):
/// A crane chain's outreach over every pose of the chart's search [m]; NaN
/// both where the chain cannot be searched (loadchart_compute says why).
void lc_chain_reach(const model* m, double* rmin, double* rmax);
/// loadchart_compute for a crane chain (docs/safety.md "On a crane chain").
int lc_chain_compute(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz);
/// Sizes c for o's points and sectors (t's truck), the sectors' bounds and
/// the rating; 0, or -1 with err (c freed).
int lc_chart_alloc(const model* m, const lc_truck* t, const lc_opts* o, loadchart* c, char* err, size_t errsz);
/// The printed chart from hyd, stab and rating: env, cap, chart, gov, imin.
void lc_chart_print(loadchart* c);
/// Mass moment [kg m] about support edge `edge` (0 front, 1 rear, 2 left,
/// 3 right) of a mass at horizontal distance rho [m] from the slew axis
/// along slew angle s [rad]: mass times its distance inside the polygon.
double lc_edge_moment(const lc_truck* t, int edge, double rho, double s, double mass);

#ifdef __cplusplus
}
#endif
#endif
