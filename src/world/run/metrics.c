// metrics.c: a run's metrics from its rows (metrics.h).
#include "metrics.h"

#include "energy_acc.h"
#include "ode_world.h"

#include <math.h>
#include <string.h>

typedef struct metric_def {
    const char* name;
    const char* unit;
    int col;      ///< the channel it is made from
} metric_def;

static const metric_def k_metric[MET_COUNT] = {
    [MET_PEAK_P1A] = {"peak_p1A", "Pa", COL_P1A},
    [MET_PEAK_P1B] = {"peak_p1B", "Pa", COL_P1B},
    [MET_PEAK_P2A] = {"peak_p2A", "Pa", COL_P2A},
    [MET_PEAK_P2B] = {"peak_p2B", "Pa", COL_P2B},
    [MET_PEAK_P3A] = {"peak_p3A", "Pa", COL_P3A},
    [MET_PEAK_P3B] = {"peak_p3B", "Pa", COL_P3B},
    [MET_PEAK_P_PUMP] = {"peak_p_pump", "Pa", COL_P_PUMP},
    [MET_RELIEF_TIME] = {"relief_open_time", "s", COL_RELIEF_OPEN},
    [MET_STOP_LIFT] = {"end_stop_hits_lift", "count", COL_END_STOP},
    [MET_STOP_JIB] = {"end_stop_hits_jib", "count", COL_END_STOP},
    // The slew actuator is bit 2 of end_stop; only the ode world has one,
    // so the metric is there only when the run has the slew channels.
    [MET_STOP_SLEW] = {"end_stop_hits_slew", "count", COL_X3},
    [MET_MAX_TILT] = {"max_truck_tilt", "rad", COL_TRUCK_TILT},
    // Not from a channel (COL_T: every backend has them), from the energy balance.
    [MET_ENERGY_IN] = {"energy_in", "J", COL_T},
    [MET_ENERGY_LOSS] = {"energy_loss", "J", COL_T},
    [MET_MAX_SWAY] = {"max_hook_sway", "rad", COL_TIP_WZ},
    [MET_MAX_SWAY_AMP] = {"max_hook_sway_amplitude", "m", COL_TIP_WZ},
    [MET_MIN_PAD_F] = {"min_pad_force", "N", COL_PAD_F1},
    [MET_MIN_STAB_MARGIN] = {"min_stab_margin", "-", COL_STAB_MARGIN},
    [MET_PAD_LIFTOFFS] = {"pad_liftoffs", "count", COL_PAD_F1},
    // Possible wherever the ode world's channels are; present only when the
    // run's world reports collisions (the sandbox, not the validation world).
    [MET_COLLISIONS] = {"collision_count", "count", COL_TRUCK_TILT},
};

// A time summed from row or step intervals, to 1 ns: far below any step,
// and the sum then prints as the decimal the steps add up to (7.431 s, not
// the 7.431000000000001 s that summing 1 ms in binary leaves). An integer
// count of ns over 1e9 is the double nearest that decimal.
static double metric_time(double t) { return round(t * 1e9) / 1e9; }

bool metrics_present(metric_id id, int ncol) { return id >= 0 && id < MET_COUNT && k_metric[id].col < ncol; }
const char* metric_name(metric_id id) { return k_metric[id].name; }
const char* metric_unit(metric_id id) { return k_metric[id].unit; }

int metric_find(const char* name) {
    for (int i = 0; i < MET_COUNT; ++i)
        if (!strcmp(name, k_metric[i].name)) return i;
    return -1;
}

void metric_names(char* buf, size_t n) {
    size_t k = 0;
    buf[0] = 0;
    for (int i = 0; i < MET_COUNT && k < n; ++i)
        k += (size_t)snprintf(buf + k, n - k, "%s%s", i ? ", " : "", k_metric[i].name);
}

void metrics_init(run_metrics* m, int ncol) {
    memset(m, 0, sizeof *m);
    m->ncol = ncol;
    for (int i = 0; i < MET_COUNT; ++i) {
        // The energy metrics wait for metrics_energy.
        m->present[i] = metrics_present((metric_id)i, ncol) && i != MET_ENERGY_IN && i != MET_ENERGY_LOSS &&
                        i != MET_COLLISIONS;
        m->value[i] = i <= MET_PEAK_P_PUMP ? -INFINITY : 0.0;
    }
}

void metrics_row(run_metrics* m, const double* row) {
    for (int i = 0; i <= MET_PEAK_P_PUMP; ++i)
        if (m->present[i]) m->value[i] = fmax(m->value[i], row[k_metric[i].col]);
    const int stops = (int)row[COL_END_STOP];
    if (m->rows > 0) {
        if (row[COL_RELIEF_OPEN] > 0) {
            // Neumaier's compensated sum: a long run's many small intervals
            // lose nothing to rounding before metric_time.
            const double dt = row[COL_T] - m->t_prev, s = m->relief_sum + dt;
            m->relief_c += fabs(m->relief_sum) >= fabs(dt) ? (m->relief_sum - s) + dt : (dt - s) + m->relief_sum;
            m->relief_sum = s;
            m->value[MET_RELIEF_TIME] = metric_time(m->relief_sum + m->relief_c);
        }
    }
    const int rising = stops & ~(m->rows > 0 ? m->stop_prev : 0);
    for (int k = 0; k < 3; ++k)
        if (m->present[MET_STOP_LIFT + k] && (rising >> k & 1)) m->value[MET_STOP_LIFT + k] += 1;
    if (m->present[MET_MAX_TILT]) m->value[MET_MAX_TILT] = fmax(m->value[MET_MAX_TILT], fabs(row[COL_TRUCK_TILT]));
    if (m->present[MET_MAX_SWAY]) {
        // The rope from the tip to the hook: its horizontal offset [m] and
        // its angle from hanging straight down [rad] (0 where the hook is
        // the tip, as in the validation world).
        const double dx = row[COL_HOOK_X] - row[COL_TIP_WX], dy = row[COL_HOOK_Y] - row[COL_TIP_WY];
        const double drop = row[COL_TIP_WZ] - row[COL_HOOK_Z];
        const double off = hypot(dx, dy);
        m->value[MET_MAX_SWAY_AMP] = fmax(m->value[MET_MAX_SWAY_AMP], off);
        m->value[MET_MAX_SWAY] = fmax(m->value[MET_MAX_SWAY], off > 0 ? atan2(off, drop) : 0.0);
    }
    if (m->present[MET_MIN_PAD_F] && row[COL_T] >= ODE_SUPPORT_SETTLE_T - 1e-12) {
        double fmin_ = INFINITY, sum = 0;
        for (int i = 0; i < 4; ++i) {
            fmin_ = fmin(fmin_, row[COL_PAD_F1 + i]);
            sum += row[COL_PAD_F1 + i];
        }
        if (sum > 0) m->pads_seen = true;
        int lifted = 0;
        for (int i = 0; i < 4; ++i)
            if (row[COL_PAD_F1 + i] < ODE_PAD_LIFT_FRAC * sum) lifted |= 1 << i;
        const int rising_pads = lifted & ~(m->pad_rows > 0 ? m->pad_lift_prev : 0);
        for (int i = 0; i < 4; ++i) m->value[MET_PAD_LIFTOFFS] += rising_pads >> i & 1;
        const double margin = row[COL_STAB_MARGIN];
        m->value[MET_MIN_PAD_F] = m->pad_rows ? fmin(m->value[MET_MIN_PAD_F], fmin_) : fmin_;
        m->value[MET_MIN_STAB_MARGIN] = m->pad_rows ? fmin(m->value[MET_MIN_STAB_MARGIN], margin) : margin;
        m->pad_lift_prev = lifted;
        ++m->pad_rows;
    }
    m->stop_prev = stops;
    m->t_prev = row[COL_T];
    ++m->rows;
}

void metrics_finish(run_metrics* m, const sim_result* r) {
    if (r->coll.have && metrics_present(MET_COLLISIONS, m->ncol)) {
        m->coll = r->coll;
        m->value[MET_COLLISIONS] = (double)r->coll.count;
        m->present[MET_COLLISIONS] = m->per_step[MET_COLLISIONS] = true;
    }
    if (!r->peak_steps) return;
    for (int k = 0; k < 4; ++k) {
        // A run stopped before its first step has no step peak (0).
        if (r->p_peak[k] >= m->value[MET_PEAK_P1A + k]) {
            m->value[MET_PEAK_P1A + k] = r->p_peak[k];
            m->per_step[MET_PEAK_P1A + k] = true;
        }
    }
}

void metrics_energy(run_metrics* m, const sim_energy* e) {
    sim_energy_balance b;
    sim_energy_result(e, &b);
    if (b.samples < 1) return;
    m->value[MET_ENERGY_IN] = b.in;
    m->value[MET_ENERGY_LOSS] = b.loss;
    m->present[MET_ENERGY_IN] = m->present[MET_ENERGY_LOSS] = true;
    m->per_step[MET_ENERGY_IN] = m->per_step[MET_ENERGY_LOSS] = true;
    m->nrelief = 0;
    for (int i = 0; i < sim_energy_ncol(e) && m->nrelief < METRICS_MAXRELIEF; ++i) {
        if (sim_energy_col_group(e, i) != SIM_EG_RELIEF) continue;
        snprintf(m->relief_name[m->nrelief], sizeof m->relief_name[0], "%s", sim_energy_col_name(e, i));
        m->relief_time[m->nrelief++] = metric_time(sim_energy_col_open_time(e, i));
    }
}

void metrics_print(const run_metrics* m, FILE* f) {
    if (m->rows == 0) return;
    fprintf(f, "  metrics: relief open %.3f s; end-stop hits lift %.0f, jib %.0f", m->value[MET_RELIEF_TIME],
            m->value[MET_STOP_LIFT], m->value[MET_STOP_JIB]);
    if (m->present[MET_STOP_SLEW]) fprintf(f, ", slew %.0f", m->value[MET_STOP_SLEW]);
    fprintf(f, "; peak pump %.2f MPa", m->value[MET_PEAK_P_PUMP] * 1e-6);
    if (m->present[MET_PEAK_P3A])
        fprintf(f, ", slew p3A %.2f, p3B %.2f MPa", m->value[MET_PEAK_P3A] * 1e-6, m->value[MET_PEAK_P3B] * 1e-6);
    if (m->present[MET_MAX_TILT]) fprintf(f, "; max truck tilt %.3f deg", m->value[MET_MAX_TILT] * 57.29577951308232);
    if (m->present[MET_MAX_SWAY])
        fprintf(f, "; max hook sway %.2f deg, %.3f m", m->value[MET_MAX_SWAY] * 57.29577951308232,
                m->value[MET_MAX_SWAY_AMP]);
    if (m->pads_seen)
        fprintf(f, "; min pad force %.2f kN, min stability margin %.3f, pad lift-offs %.0f",
                m->value[MET_MIN_PAD_F] * 1e-3, m->value[MET_MIN_STAB_MARGIN], m->value[MET_PAD_LIFTOFFS]);
    if (m->present[MET_COLLISIONS]) {
        char t[SIM_COLL_TEXT];
        sim_collisions_text(&m->coll, t, sizeof t);
        fprintf(f, "; %s", t);
    }
    fprintf(f, "\n");
    // Which reliefs were open, and how long (only those that opened).
    bool any = false;
    for (int k = 0; k < m->nrelief; ++k) {
        if (m->relief_time[k] <= 0) continue;
        fprintf(f, "%s%s %.3f s", any ? ", " : "  metrics: open per relief: ", m->relief_name[k], m->relief_time[k]);
        any = true;
    }
    if (any) fprintf(f, "\n");
    if (m->present[MET_ENERGY_IN])
        fprintf(f, "  metrics: energy in %.3f kJ, losses %.3f kJ\n", m->value[MET_ENERGY_IN] * 1e-3,
                m->value[MET_ENERGY_LOSS] * 1e-3);
}

int metrics_write_json(const run_metrics* m, FILE* f) {
    fprintf(f, "{\n  \"rows\": %ld,\n  \"metrics\": {", m->rows);
    bool first = true;
    for (int i = 0; i < MET_COUNT; ++i) {
        if (!m->present[i] || m->rows == 0) continue;
        const bool peak = i <= MET_PEAK_P_PUMP || i == MET_ENERGY_IN || i == MET_ENERGY_LOSS || i == MET_COLLISIONS;
        // The collision count is "collisions" in the file (the sweep's
        // collision_count), next to its pairs.
        fprintf(f, "%s\n    \"%s\": {\"value\": %.17g, \"unit\": \"%s\", \"over\": \"%s\"}", first ? "" : ",",
                i == MET_COLLISIONS ? "collisions" : k_metric[i].name, m->value[i], k_metric[i].unit,
                peak && m->per_step[i] ? "steps" : "rows");
        first = false;
    }
    for (int k = 0; k < m->nrelief && m->rows > 0; ++k) {
        fprintf(f, "%s\n    \"relief_open_time.%s\": {\"value\": %.17g, \"unit\": \"s\", \"over\": \"steps\"}",
                first ? "" : ",", m->relief_name[k], m->relief_time[k]);
        first = false;
    }
    fprintf(f, "\n  }");
    if (m->present[MET_COLLISIONS] && m->rows > 0) {
        // Body names are the world file's (letters, digits, '_'), written
        // escaped all the same.
        fprintf(f, ",\n  \"collision_pairs\": [");
        for (int k = 0; k < m->coll.npair; ++k) {
            fprintf(f, "%s\n    {\"bodies\": \"", k ? "," : "");
            for (const char* p = m->coll.pair[k]; *p; ++p) {
                if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
                else if ((unsigned char)*p < 0x20) fprintf(f, "\\u%04x", (unsigned char)*p);
                else fputc(*p, f);
            }
            fprintf(f, "\", \"first_t\": %.17g}", m->coll.first_t[k]);
        }
        fprintf(f, "%s]", m->coll.npair ? "\n  " : "");
    }
    fprintf(f, "\n}\n");
    return ferror(f) ? -1 : 0;
}
