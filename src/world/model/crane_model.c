// crane_model.c: default crane geometry and the paper's cylinder kinematics (Eq. 5).
#include "crane_model.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static crane_link make_link(const char* name, double length, double mass, double w, double h) {
    crane_link l;
    memset(&l, 0, sizeof l);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.length = length;
    l.mass = mass;
    l.com = 0.5 * length;             // uniform beam estimate (docs/model.md)
    l.inertia = mass * length * length / 12.0;
    l.width = w;
    l.height = h;
    return l;
}

crane_mech crane_default_mech(void) {
    crane_mech m;
    memset(&m, 0, sizeof m);
    m.gravity = 9.81;
    m.column_height = 1.6;
    m.column_mass = 250.0;
    m.link[0] = make_link("lifting_arm", 2.3, 180.0, 0.18, 0.24);
    m.link[1] = make_link("end_arm", 2.5, 140.0, 0.15, 0.20);
    m.load_mass = 500.0;

    // Mount points chosen in docs/model.md so that each stroke spans its joint
    // range (lift: elevation -20..+70 deg; jib: about 100 deg) with phi well
    // inside (15, 165) deg and closed length >= stroke + 0.25 m.
    crane_actuator* a = &m.act[0];
    snprintf(a->name, sizeof a->name, "lift");
    a->joint = 0;
    snprintf(a->cylinder, sizeof a->cylinder, "lift_cyl");
    snprintf(a->valve, sizeof a->valve, "lift_valve");
    a->base_mount[0] = 0.2113; // 0.50 m from joint 1 at -65 deg (column frame)
    a->base_mount[1] = -0.4532;
    a->rod_mount[0] = 1.5541;  // 1.56 m from joint 1 at -5 deg (lifting-arm frame)
    a->rod_mount[1] = -0.1360;
    a->closed_length = 1.2201;
    a = &m.act[1];
    snprintf(a->name, sizeof a->name, "jib");
    a->joint = 1;
    snprintf(a->cylinder, sizeof a->cylinder, "jib_cyl");
    snprintf(a->valve, sizeof a->valve, "jib_valve");
    a->base_mount[0] = -1.1954; // 1.20 m back from joint 2 at 175 deg (lifting-arm frame)
    a->base_mount[1] = 0.1046;
    a->rod_mount[0] = 0.3864;   // 0.40 m from joint 2 at -15 deg (end-arm frame)
    a->rod_mount[1] = -0.1035;
    a->closed_length = 0.9020;
    crane_mech_derive(&m);
    return m;
}

void crane_mech_derive(crane_mech* m) {
    for (int k = 0; k < 2; ++k) {
        crane_actuator* a = &m->act[k];
        a->a = hypot(a->base_mount[0], a->base_mount[1]);
        a->b = hypot(a->rod_mount[0], a->rod_mount[1]);
        // phi is the angle at the joint from the barrel pin to the rod pin. The
        // child frame is rotated from the parent by (q1 - pi/2) at joint 1 (q1
        // is measured from the downward vertical) and by q2 at joint 2.
        double off = atan2(a->rod_mount[1], a->rod_mount[0]) - atan2(a->base_mount[1], a->base_mount[0]);
        if (a->joint == 0) off -= 0.5 * M_PI;
        // Wrap to (-pi, pi]: only cos(phi) and sin(phi) are used.
        off = atan2(sin(off), cos(off));
        a->phi_offset = off;
        a->sin_offset = sin(off);
        a->cos_offset = cos(off);
    }
}

double crane_pin_length(const crane_actuator* a, double q, double* dx_dq) {
    double phi = q + a->phi_offset;
    double s = sin(phi), c = cos(phi);
    double x = sqrt(a->a * a->a + a->b * a->b - 2.0 * a->a * a->b * c);
    if (dx_dq) *dx_dq = a->a * a->b * s / x;
    return x;
}

double crane_stroke(const crane_actuator* a, double q) {
    return crane_pin_length(a, q, NULL) - a->closed_length;
}

double crane_joint_for_stroke(const crane_actuator* a, double x) {
    double L = x + a->closed_length;
    double c = (a->a * a->a + a->b * a->b - L * L) / (2.0 * a->a * a->b);
    if (c < -1.0 || c > 1.0) return NAN;
    // The mounts keep phi in (0, pi) (crane_mech_check), so acos picks the branch.
    double q = acos(c) - a->phi_offset;
    q = atan2(sin(q), cos(q));
    if (a->joint == 0 && q < 0) q += 2.0 * M_PI; // q1 lives in (0, 2 pi)
    return q;
}

int crane_check_pose(const crane_actuator* a, double stroke, double q, char* err, size_t errsz) {
    const double deg = 180.0 / M_PI;
    double lo = crane_joint_for_stroke(a, 0.0), hi = crane_joint_for_stroke(a, stroke);
    if (lo > hi) {
        double t = lo;
        lo = hi;
        hi = t;
    }
    // The stroke alone cannot tell a pose from its mirror image about the
    // cylinder's mounts (phi and -phi give the same pin length), so the pose
    // must also be the one the stroke maps back to on the mounts' branch.
    const double x = crane_stroke(a, q);
    const double back = crane_joint_for_stroke(a, x);
    const bool on_branch = isfinite(back) && fabs(remainder(q - back, 2.0 * M_PI)) < 1e-6;
    if (x >= -1e-9 && x <= stroke + 1e-9 && on_branch) return 0;
    snprintf(err, errsz, "initial.q%d_deg: %.2f deg is outside joint %d's range %.1f..%.1f deg (cylinder %s over its stroke 0..%.3f m)",
             a->joint + 1, q * deg, a->joint + 1, lo * deg, hi * deg, a->cylinder, stroke);
    return -1;
}

void crane_tip(const crane_mech* m, double q1, double q2, double* x, double* z) {
    *x = m->link[0].length * sin(q1) + m->link[1].length * sin(q1 + q2);
    *z = -m->link[0].length * cos(q1) - m->link[1].length * cos(q1 + q2);
}

void crane_gravity(const crane_mech* m, double m3, const double q[2], double G[2]) {
    const double g = m->gravity;
    const double L1 = m->link[0].length, L2 = m->link[1].length;
    const double m1 = m->link[0].mass, m2 = m->link[1].mass;
    const double e1 = m->link[0].com, e2 = m->link[1].com;
    // The moments of the masses beyond each joint, times g [N m]: A of the
    // lifting arm and everything it carries at L1, B of the end arm and the
    // tip mass about joint 2 (docs/lagrange.md, G).
    const double A = (m1 * e1 + (m2 + m3) * L1) * g;
    const double B = (m2 * e2 + m3 * L2) * g;
    const double s1 = sin(q[0]), c1 = cos(q[0]), s2 = sin(q[1]), c2 = cos(q[1]);
    const double s12 = s1 * c2 + c1 * s2; // sin(q1 + q2), as the analytic backend forms it
    G[0] = A * s1 + B * s12;
    G[1] = B * s12;
}

int crane_mech_check(const crane_mech* m, const double stroke[2], char* err, int errsz) {
    static const char* const lname[2] = {"links[0]", "links[1]"};
    for (int i = 0; i < 2; ++i) {
        const crane_link* l = &m->link[i];
        // As model.c reads them: the centre of mass on the link, a positive
        // inertia (the ODE world's bodies need a positive-definite mass matrix).
        if (!(l->length > 0) || !(l->mass > 0) || !(l->inertia > 0) || !(l->com >= 0) || !(l->com <= l->length)) {
            snprintf(err, (size_t)errsz, "mechanics.%s: length, mass and inertia must be > 0, com in 0..length",
                     lname[i]);
            return -1;
        }
    }
    for (int k = 0; k < 2; ++k) {
        const crane_actuator* a = &m->act[k];
        if (!(a->a > 0.05) || !(a->b > 0.05)) {
            snprintf(err, (size_t)errsz, "mechanics.actuators[%d]: mounts must be > 50 mm from the joint", k);
            return -1;
        }
        // phi must stay in (15, 165) deg over the whole stroke so the lever arm
        // a b sin(phi) / x never collapses (docs/lagrange.md).
        double lo = a->closed_length, hi = a->closed_length + stroke[k];
        double xmin = fabs(a->a - a->b), xmax = a->a + a->b;
        if (lo <= xmin || hi >= xmax) {
            // The mounts fix the reachable pin lengths |a - b|..a + b; the
            // closed length and the stroke must fit inside. Which of the
            // three is wrong only the user knows, so the message names all
            // three and the closed lengths these mounts would take (a
            // rod_mount copied from base_mount used to read as a wrong
            // closed_length).
            char fit[160];
            if (xmax - stroke[k] > xmin)
                snprintf(fit, sizeof fit, "for these mounts closed_length would have to lie in %.3f..%.3f m", xmin,
                         xmax - stroke[k]);
            else
                snprintf(fit, sizeof fit, "no closed_length fits a %.3f m stroke between these mounts", stroke[k]);
            const bool same = a->base_mount[0] == a->rod_mount[0] && a->base_mount[1] == a->rod_mount[1];
            snprintf(err, (size_t)errsz,
                     "mechanics.actuators[%d]: base_mount (%.3f m from the joint) and rod_mount (%.3f m)%s reach "
                     "pin lengths %.3f..%.3f m only, but closed_length %.3f m and the %.3f m stroke of %s need %.3f..%.3f m "
                     "(%s)",
                     k, a->a, a->b, same ? ", given the same coordinates," : "", xmin, xmax, lo, stroke[k], a->cylinder, lo, hi,
                     fit);
            return -1;
        }
        for (int e = 0; e < 2; ++e) {
            double L = e ? hi : lo;
            double c = (a->a * a->a + a->b * a->b - L * L) / (2.0 * a->a * a->b);
            double phi = acos(c) * 180.0 / M_PI;
            if (phi < 15.0 || phi > 165.0) {
                snprintf(err, (size_t)errsz,
                         "mechanics.actuators[%d]: joint angle phi = %.1f deg at %s stroke, must stay in (15, 165) deg",
                         k, phi, e ? "full" : "zero");
                return -1;
            }
        }
    }
    return 0;
}
