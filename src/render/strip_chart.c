// strip_chart.c: scrolling time histories (pressures, strokes, spool
// openings) in plot boxes along the bottom of the HUD.
//
// Each channel is a fixed ring buffer of RENDER_CHART_CAP samples. Pushes
// closer together than window/cap are dropped, so a 1 kHz physics rate and a
// 60 Hz frame rate both fill exactly the visible window; nothing allocates.
#include <math.h>
#include <stdio.h>

#include "render_internal.h"

int render_chart_add(render* r, const render_chart_def* def) {
    render_charts* c = &r->charts;
    if (c->n >= RENDER_MAX_CHARTS || !def) return -1;
    render_chart* ch = &c->ch[c->n];
    memset(ch, 0, sizeof *ch);
    ch->def = *def;
    snprintf(ch->label, sizeof ch->label, "%s", def->label ? def->label : "");
    snprintf(ch->unit, sizeof ch->unit, "%s", def->unit ? def->unit : "");
    ch->def.label = ch->label;
    ch->def.unit = ch->unit;
    if (ch->def.scale == 0) ch->def.scale = 1.0;
    return c->n++;
}

int render_chart_count(const render* r) { return r->charts.n; }

const char* render_chart_label(const render* r, int id) {
    return id >= 0 && id < r->charts.n ? r->charts.ch[id].label : NULL;
}

void render_chart_push(render* r, int id, double t, double value) {
    render_charts* c = &r->charts;
    if (id < 0 || id >= c->n) return;
    render_chart* ch = &c->ch[id];
    if (ch->count > 0) {
        int last = (ch->head + RENDER_CHART_CAP - 1) % RENDER_CHART_CAP;
        // Time went backwards: the run was reset, start the trace afresh.
        if (t < ch->t[last])
            ch->count = 0;
        else if (t - ch->t[last] < c->window / (0.9 * RENDER_CHART_CAP))
            return;
    }
    ch->t[ch->head] = t;
    ch->v[ch->head] = (float)(value * ch->def.scale);
    ch->head = (ch->head + 1) % RENDER_CHART_CAP;
    if (ch->count < RENDER_CHART_CAP) ++ch->count;
}

void render_chart_clear(render* r) {
    for (int i = 0; i < r->charts.n; ++i)
        r->charts.ch[i].count = 0;
}

static const float k_palette[8][4] = {
    {0.95f, 0.35f, 0.30f, 1}, {0.35f, 0.70f, 1.00f, 1}, {1.00f, 0.80f, 0.25f, 1},
    {0.45f, 0.90f, 0.45f, 1}, {0.85f, 0.50f, 0.95f, 1}, {0.30f, 0.90f, 0.90f, 1},
    {1.00f, 0.60f, 0.80f, 1}, {0.80f, 0.80f, 0.80f, 1},
};

// The standard channels of ncyl cylinders, labelled p1A, x1, u1 ... or,
// with names (the snapshot's cylinders), "pA lift", "x lift", "u lift".
static void charts_std(render* r, int ncyl, const world_snapshot* named) {
    if (ncyl > WORLD_SNAP_MAX_CYLINDERS) ncyl = WORLD_SNAP_MAX_CYLINDERS;
    // Four charts a cylinder, as many as fit.
    if (ncyl > (RENDER_MAX_CHARTS - r->charts.n) / 4) ncyl = (RENDER_MAX_CHARTS - r->charts.n) / 4;
    r->charts.std_first = r->charts.n;
    for (int i = 0; i < ncyl; ++i) {
        char label[32];
        const char* nm = named && named->cyl[i].name[0] ? named->cyl[i].name : NULL;
        render_chart_def d;
        memset(&d, 0, sizeof d);
        // Pressures: chamber A solid colour, B the next palette entry.
        for (int ch = 0; ch < 2; ++ch) {
            if (nm) snprintf(label, sizeof label, "p%c %s", ch ? 'B' : 'A', nm);
            else snprintf(label, sizeof label, "p%d%c", i + 1, ch ? 'B' : 'A');
            d.label = label, d.unit = "MPa", d.scale = 1e-6, d.ymin = 0,
            d.ymax = r->cfg.p_full_scale * 1e-6;
            memcpy(d.rgba, k_palette[(2 * i + ch) % 8], sizeof d.rgba);
            d.group = 0;
            render_chart_add(r, &d);
        }
        if (nm) snprintf(label, sizeof label, "x %s", nm);
        else snprintf(label, sizeof label, "x%d", i + 1);
        d.label = label, d.unit = "mm", d.scale = 1e3, d.ymin = d.ymax = 0; // autoscale
        memcpy(d.rgba, k_palette[(2 * i) % 8], sizeof d.rgba);
        d.group = 1;
        render_chart_add(r, &d);
        if (nm) snprintf(label, sizeof label, "u %s", nm);
        else snprintf(label, sizeof label, "u%d", i + 1);
        d.label = label, d.unit = "%", d.scale = 100, d.ymin = -100, d.ymax = 100;
        d.group = 2;
        render_chart_add(r, &d);
    }
    r->charts.std_ncyl = ncyl;
}

void render_charts_default(render* r, int ncyl) { charts_std(r, ncyl, NULL); }

void render_charts_default_named(render* r, const world_snapshot* s) { charts_std(r, s->ncyl, s); }

void render_charts_reset(render* r) {
    r->charts.n = 0;
    r->charts.std_ncyl = 0;
    r->charts.std_first = 0;
}

void render_charts_sample(render* r, const world_snapshot* s) {
    int n = r->charts.std_ncyl < s->ncyl ? r->charts.std_ncyl : s->ncyl;
    for (int i = 0; i < n; ++i) {
        int id = r->charts.std_first + 4 * i;
        render_chart_push(r, id + 0, s->t, s->cyl[i].pA);
        render_chart_push(r, id + 1, s->t, s->cyl[i].pB);
        render_chart_push(r, id + 2, s->t, s->cyl[i].x);
        render_chart_push(r, id + 3, s->t, s->cyl[i].u);
    }
}

static double latest_t(const render_charts* c) {
    double t = -INFINITY;
    for (int i = 0; i < c->n; ++i)
        if (c->ch[i].count) {
            int last = (c->ch[i].head + RENDER_CHART_CAP - 1) % RENDER_CHART_CAP;
            if (c->ch[i].t[last] > t) t = c->ch[i].t[last];
        }
    return t;
}

static void draw_box(render_hud* h, const render_charts* c, int group, double t1, float x, float y,
                     float w, float hh) {
    static const float bg[4] = {0.04f, 0.05f, 0.07f, 0.70f};
    static const float grid[4] = {1, 1, 1, 0.18f};
    static const float dim[4] = {0.75f, 0.78f, 0.82f, 1};
    render_hud_rect(h, x, y, w, hh, bg);
    double t0 = t1 - c->window;
    // Range: fixed from the first channel of the group, or autoscaled.
    double lo = 0, hi = 0;
    const char* unit = "";
    bool first = true, fixed = false, have = false;
    for (int i = 0; i < c->n; ++i) {
        const render_chart* ch = &c->ch[i];
        if (ch->def.group != group) continue;
        if (first) {
            unit = ch->unit;
            fixed = ch->def.ymin < ch->def.ymax;
            if (fixed) lo = ch->def.ymin, hi = ch->def.ymax;
            first = false;
        }
        if (fixed) continue;
        for (int k = 0; k < ch->count; ++k) {
            int j = (ch->head - ch->count + k + RENDER_CHART_CAP) % RENDER_CHART_CAP;
            if (ch->t[j] < t0) continue;
            if (!have) lo = hi = ch->v[j], have = true;
            if (ch->v[j] < lo) lo = ch->v[j];
            if (ch->v[j] > hi) hi = ch->v[j];
        }
    }
    if (have) {
        // A little headroom so traces do not sit on the frame.
        double pad = 0.05 * (hi - lo);
        lo -= pad, hi += pad;
    }
    if (!(hi > lo)) {
        double m = 0.5 * (lo + hi);
        lo = m - 1, hi = m + 1;
    }
    const float px = x + 44, pw = w - 50, py = y + 16, ph = hh - 30;
    for (int g = 0; g <= 4; ++g)
        render_hud_line(h, px, py + ph * (float)g / 4, px + pw, py + ph * (float)g / 4, grid);
    char buf[64];
    snprintf(buf, sizeof buf, "%.4g", hi);
    render_hud_text(h, x + 3, py - 3, 1.0f, dim, buf);
    snprintf(buf, sizeof buf, "%.4g", lo);
    render_hud_text(h, x + 3, py + ph - 6, 1.0f, dim, buf);
    snprintf(buf, sizeof buf, "[%s]", unit);
    render_hud_text(h, x + 3, py + ph * 0.5f - 4, 1.0f, dim, buf);
    snprintf(buf, sizeof buf, "-%.0f s", c->window);
    render_hud_text(h, px, py + ph + 4, 1.0f, dim, buf);
    render_hud_text(h, px + pw - 22, py + ph + 4, 1.0f, dim, "now");

    float lx = px, ly = y + 3;
    for (int i = 0; i < c->n; ++i) {
        const render_chart* ch = &c->ch[i];
        if (ch->def.group != group) continue;
        // Legend with the latest value and unit, wrapped inside the box.
        if (ch->count) {
            int last = (ch->head + RENDER_CHART_CAP - 1) % RENDER_CHART_CAP;
            char v[32]; // decimals by unit, no exponent, no -0 (hud_fmt.c)
            snprintf(buf, sizeof buf, "%s %s %s", ch->label, render_fmt_unit(v, sizeof v, ch->v[last], ch->unit),
                     ch->unit);
        } else {
            snprintf(buf, sizeof buf, "%s", ch->label);
        }
        if (lx > px && lx + render_hud_text_width(buf, 1.0f) > x + w - 4) lx = px, ly += 10;
        lx += render_hud_text(h, lx, ly, 1.0f, ch->def.rgba, buf) + 10;
        float ox = 0, oy = 0;
        bool have = false;
        for (int k = 0; k < ch->count; ++k) {
            int j = (ch->head - ch->count + k + RENDER_CHART_CAP) % RENDER_CHART_CAP;
            if (ch->t[j] < t0) continue;
            double f = (ch->v[j] - lo) / (hi - lo);
            if (f < 0) f = 0;
            if (f > 1) f = 1;
            float sx = px + pw * (float)((ch->t[j] - t0) / c->window),
                  sy = py + ph * (float)(1.0 - f);
            // At most one segment per 2 px column: more is invisible and
            // each line costs llvmpipe a primitive setup.
            if (have && sx < ox + 2.0f && k + 1 < ch->count) continue;
            if (have) render_hud_line(h, ox, oy, sx, sy, ch->def.rgba);
            ox = sx, oy = sy, have = true;
        }
    }
}

void render_charts_draw(render_hud* h, const render_charts* c, float x, float y, float w,
                        float hh) {
    int groups[RENDER_MAX_CHARTS], ng = 0;
    for (int i = 0; i < c->n; ++i) {
        bool seen = false;
        for (int g = 0; g < ng; ++g)
            seen |= groups[g] == c->ch[i].def.group;
        if (!seen) groups[ng++] = c->ch[i].def.group;
    }
    double t1 = latest_t(c);
    if (!ng || !isfinite(t1)) return;
    float gap = 8, bw = (w - gap * (float)(ng - 1)) / (float)ng;
    for (int g = 0; g < ng; ++g)
        draw_box(h, c, groups[g], t1, x + (bw + gap) * (float)g, y, bw, hh);
}
