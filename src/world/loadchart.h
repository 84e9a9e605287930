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

typedef struct loadchart {
    int n, nsec;
    double R[LOADCHART_MAX_POINTS];   ///< outreach [m]
    double hyd[LOADCHART_MAX_POINTS]; ///< hydraulic limit, payload [kg] (NAN: not reachable)
    int hyd_cyl[LOADCHART_MAX_POINTS];///< the cylinder that governs it (0 lift, 1 jib)
    double hyd_q[LOADCHART_MAX_POINTS][2]; ///< the pose that governs it (q1, q2) [rad]
    double* stab;                     ///< n x nsec stability limit [kg] (INFINITY: cannot tip); NULL without truck
    double sec_lo[LOADCHART_MAX_SECTORS], sec_hi[LOADCHART_MAX_SECTORS]; ///< sector bounds [rad], 0..pi
    double reach_min, reach_max;      ///< outreach the workspace covers [m]
    bool truck;
    double hook_mass;                 ///< subtracted from the tip load (payload under the hook) [kg]
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
/// the largest tip mass [kg] (besides the hook) with sf times the tipping
/// moment below the restoring moment about every support edge; INFINITY
/// when the tip is inside the support polygon.
double loadchart_stab_pose(const model* m, const lc_truck* t, double q1, double q2, double slew, double sf);

/// The sector of slew angle slew [rad] (any value; folded to 0..pi).
int loadchart_sector(const loadchart* c, double slew);
/// Rated capacity [kg] at outreach R [m] and slew [rad]: the smaller limit,
/// interpolated linearly (clamped to the chart's range); *stab_governs when
/// the stability limit is the smaller.
double loadchart_capacity(const loadchart* c, double R, double slew, bool* stab_governs);

/// Port relief cracking setting [Pa] of each chamber (A, B) of actuator k.
int loadchart_reliefs(const model* m, int k, double p[2]);

#ifdef __cplusplus
}
#endif
#endif
