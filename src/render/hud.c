// hud.c: the 2D overlay: pressure bars over each cylinder (as in the paper's
// visualisation), readouts with units, and warnings.
//
// Everything 2D is batched into one triangle list and one line list per
// frame, drawn with a single tiny shader; text comes from stb_easy_font
// (quads from a built-in vector font, no texture, no font file).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render_internal.h"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

static const char* k_hud_vs = "#version 330 core\n"
                              "layout(location = 0) in vec2 a_pos;\n"
                              "layout(location = 1) in vec4 a_col;\n"
                              "uniform vec2 u_screen;\n"
                              "out vec4 v_col;\n"
                              "void main() {\n"
                              "    v_col = a_col;\n"
                              "    gl_Position = vec4(a_pos.x / u_screen.x * 2.0 - 1.0, 1.0 - "
                              "a_pos.y / u_screen.y * 2.0, 0.0, 1.0);\n"
                              "}\n";

static const char* k_hud_fs = "#version 330 core\n"
                              "in vec4 v_col;\n"
                              "out vec4 o_color;\n"
                              "void main() { o_color = v_col; }\n";

bool render_hud_create(render_hud* h) {
    memset(h, 0, sizeof *h);
    h->prog = render_shader_build("hud", k_hud_vs, k_hud_fs);
    if (!h->prog) return false;
    h->u_screen = glGetUniformLocation(h->prog, "u_screen");
    glGenVertexArrays(1, &h->vao);
    glGenBuffers(1, &h->vbo);
    glBindVertexArray(h->vao);
    glBindBuffer(GL_ARRAY_BUFFER, h->vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(render_hud_vertex), (void*)0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(render_hud_vertex),
                          (void*)offsetof(render_hud_vertex, rgba));
    glBindVertexArray(0);
    // Generous first sizes; they only grow, so steady frames never allocate.
    h->captri = 32768;
    h->capline = 16384;
    h->tri = malloc((size_t)h->captri * sizeof *h->tri);
    h->line = malloc((size_t)h->capline * sizeof *h->line);
    h->font_scratch_size = 64 * 1024;
    h->font_scratch = malloc((size_t)h->font_scratch_size);
    return h->tri && h->line && h->font_scratch;
}

void render_hud_free(render_hud* h) {
    if (h->vbo) glDeleteBuffers(1, &h->vbo);
    if (h->vao) glDeleteVertexArrays(1, &h->vao);
    if (h->prog) glDeleteProgram(h->prog);
    free(h->tri);
    free(h->line);
    free(h->font_scratch);
    memset(h, 0, sizeof *h);
}

void render_hud_begin(render_hud* h, int w, int hh) {
    h->ntri = h->nline = 0;
    h->w = w;
    h->h = hh;
    memset(h->bar_valid, 0, sizeof h->bar_valid);
}

static bool grow(render_hud_vertex** buf, int* cap, int need) {
    if (need <= *cap) return true;
    int nc = *cap;
    while (nc < need)
        nc *= 2;
    render_hud_vertex* nb = realloc(*buf, (size_t)nc * sizeof *nb);
    if (!nb) return false;
    *buf = nb;
    *cap = nc;
    return true;
}

static render_hud_vertex hv(float x, float y, const unsigned char c[4]) {
    render_hud_vertex v = {x, y, {c[0], c[1], c[2], c[3]}};
    return v;
}

static void to_u8(const float rgba[4], unsigned char c[4]) {
    for (int k = 0; k < 4; ++k) {
        float f = rgba[k] < 0 ? 0 : rgba[k] > 1 ? 1 : rgba[k];
        c[k] = (unsigned char)(f * 255.0f + 0.5f);
    }
}

void render_hud_rect(render_hud* h, float x, float y, float w, float hh, const float rgba[4]) {
    if (!grow(&h->tri, &h->captri, h->ntri + 6)) return;
    unsigned char c[4];
    to_u8(rgba, c);
    render_hud_vertex* v = &h->tri[h->ntri];
    v[0] = hv(x, y, c), v[1] = hv(x + w, y, c), v[2] = hv(x + w, y + hh, c);
    v[3] = hv(x, y, c), v[4] = hv(x + w, y + hh, c), v[5] = hv(x, y + hh, c);
    h->ntri += 6;
}

void render_hud_line(render_hud* h, float x0, float y0, float x1, float y1, const float rgba[4]) {
    if (!grow(&h->line, &h->capline, h->nline + 2)) return;
    unsigned char c[4];
    to_u8(rgba, c);
    // Pixel centres, so 1 px lines land on whole pixels.
    h->line[h->nline++] = hv(x0 + 0.5f, y0 + 0.5f, c);
    h->line[h->nline++] = hv(x1 + 0.5f, y1 + 0.5f, c);
}

float render_hud_text_width(const char* s, float scale) {
    return (float)stb_easy_font_width((char*)s) * scale;
}

float render_hud_text(render_hud* h, float x, float y, float scale, const float rgba[4],
                      const char* s) {
    unsigned char c[4];
    to_u8(rgba, c);
    // stb_easy_font writes quads of 16-byte vertices (x, y, z, rgba).
    int nq = stb_easy_font_print(0, 0, (char*)s, c, h->font_scratch, h->font_scratch_size);
    if (!grow(&h->tri, &h->captri, h->ntri + 6 * nq)) return 0;
    const char* q = h->font_scratch;
    for (int i = 0; i < nq; ++i) {
        render_hud_vertex v[4];
        for (int k = 0; k < 4; ++k) {
            const float* p = (const float*)(q + (size_t)(4 * i + k) * 16);
            v[k] = hv(x + p[0] * scale, y + p[1] * scale, c);
        }
        render_hud_vertex* o = &h->tri[h->ntri];
        o[0] = v[0], o[1] = v[1], o[2] = v[2];
        o[3] = v[0], o[4] = v[2], o[5] = v[3];
        h->ntri += 6;
    }
    return render_hud_text_width(s, scale);
}

void render_hud_flush(render_hud* h) {
    if (!h->ntri && !h->nline) return;
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(h->prog);
    glUniform2f(h->u_screen, (float)h->w, (float)h->h);
    glBindVertexArray(h->vao);
    glBindBuffer(GL_ARRAY_BUFFER, h->vbo);
    // One upload per frame into a buffer that only grows; re-specifying it
    // every frame would make llvmpipe allocate and zero fresh memory.
    size_t bt = (size_t)h->ntri * sizeof(render_hud_vertex),
           bl = (size_t)h->nline * sizeof(render_hud_vertex);
    if (bt + bl > h->vbo_bytes) {
        h->vbo_bytes = 2 * (bt + bl);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)h->vbo_bytes, NULL, GL_STREAM_DRAW);
    }
    glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)bt, h->tri);
    glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)bt, (GLsizeiptr)bl, h->line);
    if (h->ntri) glDrawArrays(GL_TRIANGLES, 0, h->ntri);
    if (h->nline) glDrawArrays(GL_LINES, h->ntri, h->nline);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
}

// ---- overlay content -------------------------------------------------------------

static const float k_white[4] = {1, 1, 1, 1};
static const float k_dim[4] = {0.75f, 0.78f, 0.82f, 1};
static const float k_panel[4] = {0.05f, 0.06f, 0.08f, 0.62f};
static const float k_warn_bg[4] = {0.70f, 0.05f, 0.05f, 0.88f};
static const float k_amber[4] = {1.0f, 0.70f, 0.15f, 1};

/// Pressure colour: green at low load, yellow in mid range, red near full scale.
static void pressure_color(double frac, float rgba[4]) {
    float f = (float)(frac < 0 ? 0 : frac > 1 ? 1 : frac);
    if (f < 0.5f) {
        float k = f / 0.5f;
        rgba[0] = 0.15f + 0.80f * k, rgba[1] = 0.80f, rgba[2] = 0.20f;
    } else {
        float k = (f - 0.5f) / 0.5f;
        rgba[0] = 0.95f, rgba[1] = 0.80f * (1.0f - k) + 0.10f * k, rgba[2] = 0.20f - 0.1f * k;
    }
    rgba[3] = 1.0f;
}

enum { BAR_W = 14, BAR_H = 96, BAR_GAP = 6, BAR_PAD = 4 };
/// More cylinders than this (a crane chain's) and the HUD is compact: its
/// readouts table in small text, the pressure bars shorter (BAR_H_MANY), so
/// a group over every cylinder fits beside the others. The two-link crane
/// (lift, jib and the slew rack) keeps the full size.
enum { HUD_FEW_CYL = 4, BAR_H_MANY = 60 };

static bool overlaps(int x, int y, int w, int h, const float b[4]) {
    return b[2] > 0 && x < b[0] + b[2] && b[0] < x + w && y < b[1] + b[3] && b[1] < y + h;
}

// A leader line from (x0, y0) to (x1, y1) [px] with the parts inside any of
// the n boxes (x, y, w, h; w <= 0: none) left out (Liang-Barsky clipping of
// the segment against each box in turn, the pieces outside kept).
static void leader_line(render_hud* h, float x0, float y0, float x1, float y1, const float (*box)[4], int n) {
    for (int k = 0; k < n; ++k) {
        const float* b = box[k];
        if (!(b[2] > 0 && b[3] > 0)) continue;
        const float dx = x1 - x0, dy = y1 - y0;
        const float p[4] = {-dx, dx, -dy, dy}, q[4] = {x0 - b[0], b[0] + b[2] - x0, y0 - b[1], b[1] + b[3] - y0};
        float ta = 0, tb = 1;
        bool out = false;
        for (int e = 0; e < 4 && !out; ++e) {
            if (p[e] == 0) {
                out = q[e] < 0;
                continue;
            }
            const float t = q[e] / p[e];
            if (p[e] < 0) ta = fmaxf(ta, t);
            else tb = fminf(tb, t);
            out = ta >= tb;
        }
        if (out) continue;
        // The pieces before and after the box, each against the boxes left.
        if (ta > 0) leader_line(h, x0, y0, x0 + ta * dx, y0 + ta * dy, box + k + 1, n - k - 1);
        if (tb < 1) leader_line(h, x0 + tb * dx, y0 + tb * dy, x1, y1, box + k + 1, n - k - 1);
        return;
    }
    render_hud_line(h, x0, y0, x1, y1, k_dim);
}

// keep_out: the warnings' box at the top centre (x, y, w, h [px]; w = 0 for
// none): a bar group there goes below it, not under it. readouts: the
// readouts box (top left), kept clear of the groups in the compact HUD
// (where the groups are many; w = 0: not kept).
static void draw_pressure_bars(render* r, const world_snapshot* s, const float keep_out[4], const float readouts[4]) {
    render_hud* h = &r->hud;
    const float empty[4] = {((RENDER_BAR_EMPTY_RGB >> 16) & 255) / 255.0f,
                            ((RENDER_BAR_EMPTY_RGB >> 8) & 255) / 255.0f,
                            (RENDER_BAR_EMPTY_RGB & 255) / 255.0f, 1.0f};
    const float frame[4] = {0.85f, 0.87f, 0.9f, 1.0f};
    const float relief[4] = {1.0f, 0.1f, 0.1f, 1.0f};
    int placed[WORLD_SNAP_MAX_CYLINDERS][4];
    int nplaced = 0;
    int ncyl = s->ncyl < WORLD_SNAP_MAX_CYLINDERS ? s->ncyl : WORLD_SNAP_MAX_CYLINDERS;
    const bool many = ncyl > HUD_FEW_CYL;
    const int bar_h = many ? BAR_H_MANY : BAR_H;
    // Many groups: every place first (pass 0), then the groups with their
    // leader lines clipped out of the other groups and the boxes (pass 1):
    // the HUD draws its lines over its rectangles, so a line across another
    // cylinder's bar would read as its pressure. Few: each group with its
    // line in one pass, as it always was drawn.
    int gpos[WORLD_SNAP_MAX_CYLINDERS][2], gidx[WORLD_SNAP_MAX_CYLINDERS];
    bool gok[WORLD_SNAP_MAX_CYLINDERS] = {false};
    for (int pass = 0; pass < (many ? 2 : 1); ++pass)
    for (int i = 0; i < ncyl; ++i) {
        const world_snap_cylinder* c = &s->cyl[i];
        double mid[3] = {0.5 * (c->base[0] + c->rod_end[0]), 0.5 * (c->base[1] + c->rod_end[1]),
                         0.5 * (c->base[2] + c->rod_end[2])};
        double px[2];
        if (!render_project(r, mid, px)) continue;
        // The group: two bars side by side, raised above the cylinder, with a
        // leader line down to it. Keep it on screen and clear of the others.
        int gw = 2 * BAR_W + BAR_GAP + 2 * BAR_PAD, gh = bar_h + 2 * BAR_PAD + 30;
        int gx = (int)px[0] - gw / 2, gy = (int)px[1] - 40 - gh;
        if (pass == 1) {
            if (!gok[i]) continue;
            gx = gpos[i][0], gy = gpos[i][1];
            float avoid[WORLD_SNAP_MAX_CYLINDERS + 2][4];
            int na = 0;
            for (int k = 0; k < nplaced; ++k)
                if (k != gidx[i])
                    avoid[na][0] = (float)placed[k][0], avoid[na][1] = (float)placed[k][1],
                    avoid[na][2] = (float)placed[k][2], avoid[na++][3] = (float)placed[k][3];
            memcpy(avoid[na++], keep_out, sizeof avoid[0]);
            memcpy(avoid[na++], readouts, sizeof avoid[0]);
            leader_line(h, (float)gx + gw * 0.5f, (float)(gy + gh), (float)px[0], (float)px[1], avoid, na);
            goto draw_group;
        }
        if (gx < 4) gx = 4;
        if (gy < 4) gy = 4;
        if (keep_out[2] > 0 && gx < keep_out[0] + keep_out[2] && keep_out[0] < gx + gw &&
            gy < keep_out[1] + keep_out[3])
            gy = (int)(keep_out[1] + keep_out[3]) + 4;
        if (gx + gw > h->w - 4) gx = h->w - 4 - gw;
        if (gy + gh > h->h - 4) gy = h->h - 4 - gh;
        for (int pass = 0; pass < 4; ++pass)
            for (int k = 0; k < nplaced; ++k)
                if (gx < placed[k][0] + placed[k][2] + 6 && placed[k][0] < gx + gw + 6 &&
                    gy < placed[k][1] + placed[k][3] && placed[k][1] < gy + gh)
                    gx = placed[k][0] + placed[k][2] + 8;
        if (many) {
            // Many groups (a crane chain's cylinders along its booms): one
            // that overlaps another, the readouts or the warnings, or runs
            // off the right edge, takes the first free place right of the
            // readouts box at its height, else under that box, else in rows
            // of groups from the top right of the box (clear of the charts).
            bool clash = gx + gw > h->w - 4 || overlaps(gx, gy, gw, gh, readouts) || overlaps(gx, gy, gw, gh, keep_out);
            for (int k = 0; k < nplaced && !clash; ++k) {
                const float b[4] = {(float)placed[k][0] - 6, (float)placed[k][1], (float)placed[k][2] + 12,
                                    (float)placed[k][3]};
                clash = overlaps(gx, gy, gw, gh, b);
            }
            const int x0 = readouts[2] > 0 ? (int)(readouts[0] + readouts[2]) + 8 : 4;
            // Nearest first: beside the readouts at its own height, then
            // under them above the cylinder; then the rows from the top.
            const int near[2][2] = {{x0, gy}, {gx, readouts[2] > 0 ? (int)(readouts[1] + readouts[3]) + 8 : gy}};
            for (int row = -2; clash && row < 4; ++row)
                for (int x = row < 0 ? near[row + 2][0] : x0; clash && x + gw <= h->w - 4; x += gw + 8) {
                    const int y = row < 0 ? near[row + 2][1] : 4 + row * (gh + 8);
                    if (y < 4 || y + gh > h->h - 150) break; // not over the strip charts at the bottom
                    clash = overlaps(x, y, gw, gh, readouts) || overlaps(x, y, gw, gh, keep_out);
                    for (int k = 0; k < nplaced && !clash; ++k) {
                        const float b[4] = {(float)placed[k][0] - 6, (float)placed[k][1], (float)placed[k][2] + 12,
                                            (float)placed[k][3]};
                        clash = overlaps(x, y, gw, gh, b);
                    }
                    if (!clash) gx = x, gy = y;
                }
        }
        placed[nplaced][0] = gx, placed[nplaced][1] = gy, placed[nplaced][2] = gw,
        placed[nplaced][3] = gh;
        ++nplaced;

        if (many) { // the group and its line in pass 1
            gpos[i][0] = gx, gpos[i][1] = gy, gok[i] = true, gidx[i] = nplaced - 1;
            continue;
        }
        render_hud_line(h, (float)gx + gw * 0.5f, (float)(gy + gh), (float)px[0], (float)px[1],
                        k_dim);
    draw_group:
        render_hud_rect(h, (float)gx, (float)gy, (float)gw, (float)gh, k_panel);
        char buf[64];
        snprintf(buf, sizeof buf, "%s", c->name[0] ? c->name : "cyl");
        render_hud_text(h, (float)gx + BAR_PAD, (float)gy + 3, 1.0f,
                        c->end_stop ? k_amber : k_white, buf);
        double p[2] = {c->pA, c->pB};
        for (int ch = 0; ch < 2; ++ch) {
            int bx = gx + BAR_PAD + ch * (BAR_W + BAR_GAP), by = gy + 14;
            const int BAR_H = bar_h; // this frame's height (compact with many cylinders)
            double frac = p[ch] / r->cfg.p_full_scale;
            if (!(frac > 0)) frac = 0; // also catches NaN
            if (frac > 1) frac = 1;
            // Outline (red while a port relief passes flow), then the empty
            // bar, then the fill from the bottom.
            render_hud_rect(h, (float)bx - 1, (float)by - 1, BAR_W + 2, BAR_H + 2,
                            c->relief_open ? relief : frame);
            render_hud_rect(h, (float)bx, (float)by, BAR_W, BAR_H, empty);
            float fill = (float)(frac * BAR_H);
            float col[4];
            pressure_color(frac, col);
            if (fill > 0) render_hud_rect(h, (float)bx, (float)by + BAR_H - fill, BAR_W, fill, col);
            int* rr = r->hud.bar_rect[i][ch];
            rr[0] = bx, rr[1] = by, rr[2] = BAR_W, rr[3] = BAR_H;
            render_hud_text(h, (float)bx + 4, (float)(by + BAR_H + 3), 1.0f, k_dim, ch ? "B" : "A");
        }
        snprintf(buf, sizeof buf, "%.1f/%.1f", c->pA * 1e-6, c->pB * 1e-6);
        render_hud_text(h, (float)gx + 2, (float)(gy + gh - 11), 1.0f, k_white, buf);
        r->hud.bar_valid[i] = true;
    }
}

// "   margin 1.17", or "   margin >= 10" at the world's cap (nothing outboard).
static void pad_margin_text(const world_snapshot* s, char* buf, size_t n) {
    if (s->stab_margin >= 10.0) snprintf(buf, n, "   margin >= 10");
    else snprintf(buf, n, "   margin %.2f", s->stab_margin);
}

/// Readouts table, top left. Units in every row header.
static float draw_readouts(render* r, const world_snapshot* s) {
    render_hud* h = &r->hud;
    int ncyl = s->ncyl < WORLD_SNAP_MAX_CYLINDERS ? s->ncyl : WORLD_SNAP_MAX_CYLINDERS;
    // The cylinder table: text scale, row height and columns [px]. With
    // many cylinders (a crane chain) it is set in small text, each column as
    // wide as its longest entry, so ten of them fit half the width.
    const bool many = ncyl > HUD_FEW_CYL;
    const float sc = 1.5f, lh = 14.0f, tsc = many ? 1.0f : sc, tlh = many ? 11.0f : lh, col0 = many ? 64.0f : 96.0f;
    float colw = 84.0f;
    if (many) {
        colw = render_hud_text_width("-00000.0", tsc);
        for (int i = 0; i < ncyl; ++i) colw = fmaxf(colw, render_hud_text_width(s->cyl[i].name, tsc));
        colw += 8;
    }
    const int nrows = 14 + r->nreadout + (s->npad ? 1 : 0);
    const float height = lh * (float)(nrows - 8) + tlh * 8 + (many ? 0.3f * (lh - tlh) : 0.0f);
    float x = 10, y = 10, w = col0 + colw * (float)(ncyl > 2 ? ncyl : 2) + 24;
    // The status line ("[keys: panel - Enter/Esc gives them back]") is the
    // widest text; the box grows to hold it rather than cut it at its edge.
    if (r->status[0]) w = fmaxf(w, render_hud_text_width(r->status, sc) + 12);
    if (s->npad) {
        char line[160];
        int k = snprintf(line, sizeof line, "pads kN");
        for (int i = 0; i < 4; ++i)
            k += snprintf(line + k, sizeof line - (size_t)k, "  %s %.1f", render_pad_name(i), s->pad_F[i] * 1e-3);
        pad_margin_text(s, line + k, sizeof line - (size_t)k);
        w = fmaxf(w, render_hud_text_width(line, sc) + 12);
    }
    render_hud_rect(h, x - 6, y - 6, w, height + 10, k_panel);
    h->readouts_rect[0] = x - 6, h->readouts_rect[1] = y - 6, h->readouts_rect[2] = w,
    h->readouts_rect[3] = height + 10;
    char buf[160], rt[32];
    // rt_factor 0 means unknown (world_snapshot.h), e.g. over the first
    // instants, where a ratio of two tiny times means nothing.
    if (s->rt_factor > 0) snprintf(rt, sizeof rt, "%.2fx", s->rt_factor);
    else snprintf(rt, sizeof rt, "n/a");
    if (r->frame_dt_avg > 0)
        snprintf(buf, sizeof buf, "t %.2f s   RT %s   %.0f fps", s->t, rt, 1.0 / r->frame_dt_avg);
    else
        snprintf(buf, sizeof buf, "t %.2f s   RT %s", s->t, rt);
    render_hud_text(h, x, y, sc, k_white, buf);
    y += lh * 1.3f;
    for (int i = 0; i < ncyl; ++i)
        render_hud_text(h, x + col0 + colw * (float)i, y, tsc, k_dim,
                        s->cyl[i].name[0] ? s->cyl[i].name : "cyl");
    y += tlh;
    static const char* rows[] = {"x [mm]", "v [mm/s]",  "pA [MPa]", "pB [MPa]",
                                 "u [%]",  "u_cmd [%]", "F [kN]"};
    for (int row = 0; row < 7; ++row) {
        render_hud_text(h, x, y, tsc, k_dim, rows[row]);
        for (int i = 0; i < ncyl; ++i) {
            const world_snap_cylinder* c = &s->cyl[i];
            double v[7] = {c->x * 1e3, c->v * 1e3,     c->pA * 1e-6,   c->pB * 1e-6,
                           c->u * 100, c->u_cmd * 100, c->force * 1e-3};
            // Never "-0.0" (a stroke or rate of a few micrometres).
            render_fmt_fixed(buf, sizeof buf, v[row], row == 4 || row == 5 ? 0 : row == 0 || row == 1 ? 1 : 2,
                             row == 4 || row == 5);
            // u_cmd in amber where the limiter cut the operator's demand (the
            // warning line gives the demand beside it).
            const float* colr = ((row == 2 || row == 3) && c->relief_open) || (row == 5 && c->rcl_cut) ? k_amber : k_white;
            render_hud_text(h, x + col0 + colw * (float)i, y, tsc, colr, buf);
        }
        y += tlh;
    }
    y += 4;
    char f0[32], f1[32], f2[32];
    snprintf(buf, sizeof buf, "tip  x %s  y %s  z %s m", render_fmt_fixed(f0, sizeof f0, s->tip[0], 2, false),
             render_fmt_fixed(f1, sizeof f1, s->tip[1], 2, false), render_fmt_fixed(f2, sizeof f2, s->tip[2], 2, false));
    render_hud_text(h, x, y, sc, k_white, buf);
    y += lh;
    snprintf(buf, sizeof buf, "hook z %s m   load %.0f kg%s", render_fmt_fixed(f0, sizeof f0, s->hook[2], 2, false),
             s->load_mass,
             s->attached ? " (on hook)" : "");
    render_hud_text(h, x, y, sc, k_white, buf);
    y += lh;
    snprintf(buf, sizeof buf, "slew %s deg  tilt %s deg  p_s %s MPa",
             render_fmt_fixed(f0, sizeof f0, s->slew * 180.0 / M_PI, 1, false),
             render_fmt_fixed(f1, sizeof f1, s->truck_tilt * 180.0 / M_PI, 1, false),
             render_fmt_fixed(f2, sizeof f2, s->p_supply * 1e-6, 1, false));
    render_hud_text(h, x, y, sc, k_white, buf);
    y += lh;
    if (s->npad) {
        // The supports' ground reactions [kN], a lifted one in amber, and the
        // stability margin (amber below 1.25, a usual stability factor; red
        // text is kept for the warnings).
        float px = x;
        px += render_hud_text(h, px, y, sc, k_dim, "pads kN");
        for (int i = 0; i < s->npad && i < 4; ++i) {
            snprintf(buf, sizeof buf, "  %s %s", render_pad_name(i), render_fmt_fixed(f0, sizeof f0, s->pad_F[i] * 1e-3, 1, false));
            px += render_hud_text(h, px, y, sc, (s->pad_lifted >> i & 1) ? k_amber : k_white, buf);
        }
        pad_margin_text(s, buf, sizeof buf);
        render_hud_text(h, px, y, sc, s->stab_margin < 1.25 ? k_amber : k_white, buf);
        y += lh;
    }
    // The app's channel readouts (render_set_readouts): name, value, unit
    // as its channel list gives them.
    for (int i = 0; i < r->nreadout; ++i) {
        // No value (NaN): the unit field says why ("not sent": a remote view's circuit channel).
        if (isnan(r->readout[i].value)) snprintf(buf, sizeof buf, "%s: %s", r->readout[i].name, r->readout[i].unit);
        else
            snprintf(buf, sizeof buf, "%s %s %s", r->readout[i].name,
                     render_fmt_unit(f0, sizeof f0, r->readout[i].value, r->readout[i].unit), r->readout[i].unit);
        render_hud_text(h, x, y, sc, k_white, buf);
        y += lh;
    }
    if (r->status[0]) {
        render_hud_text(h, x, y, sc, k_amber, r->status);
        y += lh;
    }
    return y;
}

const char* render_pad_name(int i) {
    static const char* const k_name[4] = {"FL", "FR", "RL", "RR"};
    return i >= 0 && i < 4 ? k_name[i] : "?";
}

int render_pad_event(const world_snapshot* s, int* prev, char* buf, size_t n) {
    const int now = s->npad ? s->pad_lifted : 0, rising = now & ~*prev;
    *prev = now;
    if (!rising) return 0;
    int k = snprintf(buf, n, "t = %.2f s: outrigger pad lifted off:", s->t);
    for (int i = 0; i < 4 && k > 0 && (size_t)k < n; ++i)
        if (rising >> i & 1)
            k += snprintf(buf + k, n - (size_t)k, " %s (%.2f kN)", render_pad_name(i), s->pad_F[i] * 1e-3);
    if (k > 0 && (size_t)k < n) render_pad_margin_text(s, buf + k, n - (size_t)k);
    return 1;
}

void render_pad_margin_text(const world_snapshot* s, char* buf, size_t n) {
    // A pad lifts off (below 1 % of the weight) long before the truck tips:
    // one corner unloads and the truck stands on three pads, rocking about
    // their diagonal, while the margin about the tipping lines (the pad
    // rectangle's edges) can still be 2. Said so, the two figures do not
    // read as a contradiction ("PAD LIFTED OFF (margin 2.04)").
    const int lifted = s->pad_lifted & 15;
    const bool one = lifted && !(lifted & (lifted - 1));
    char m[16];
    if (s->stab_margin >= 10.0) snprintf(m, sizeof m, ">= 10"); // the world's cap: nothing outboard
    else snprintf(m, sizeof m, "%.2f", s->stab_margin);
    if (one && s->stab_margin >= 1.0) snprintf(buf, n, " - on three pads, not tipping (tipping margin %s)", m);
    else snprintf(buf, n, " - tipping margin %s", m);
}

int render_hud_warnings(const render* r, const world_snapshot* s, char w[][RENDER_WARN_LEN], int max) {
    int n = 0;
    if (max > RENDER_WARN_MAX) max = RENDER_WARN_MAX;
    // A dropped link first: everything below is the last state received.
    if (r->link_down[0] && n < max) snprintf(w[n++], RENDER_WARN_LEN, "%s", r->link_down);
    int ncyl = s->ncyl < WORLD_SNAP_MAX_CYLINDERS ? s->ncyl : WORLD_SNAP_MAX_CYLINDERS;
    // Each open relief by its circuit name, with the cylinder chamber it
    // guards: "MAIN RELIEF OPEN" for every relief sent an operator slewing
    // into a wall looking at the pump line. A snapshot without names (an
    // older producer, the demo scene) keeps the flags.
    int nrel = s->nrelief < WORLD_SNAP_MAX_RELIEFS ? s->nrelief : WORLD_SNAP_MAX_RELIEFS;
    for (int k = 0; k < nrel && n < max - 2; ++k) {
        const int c = s->relief_cyl[k];
        if (c >= 0 && c < ncyl)
            snprintf(w[n++], RENDER_WARN_LEN, "RELIEF OPEN: %s (%s %c)", s->relief[k],
                     s->cyl[c].name[0] ? s->cyl[c].name : "cylinder", s->relief_port[k] ? 'B' : 'A');
        else
            snprintf(w[n++], RENDER_WARN_LEN, "RELIEF OPEN: %s", s->relief[k]);
    }
    if (nrel == 0 && s->main_relief_open && n < max - 2) snprintf(w[n++], RENDER_WARN_LEN, "MAIN RELIEF OPEN");
    for (int i = 0; i < ncyl && n < max - 2; ++i) {
        const char* nm = s->cyl[i].name[0] ? s->cyl[i].name : "cylinder";
        if (nrel == 0 && s->cyl[i].relief_open) snprintf(w[n++], RENDER_WARN_LEN, "RELIEF OPEN: %s", nm);
        if (s->cyl[i].end_stop && n < max - 2) snprintf(w[n++], RENDER_WARN_LEN, "END STOP: %s", nm);
    }
    if (s->rcl_have && n < max - 1) {
        // Where the limiter cut the operator's demand, a second line gives
        // the demand beside what it let through ("jib: demand +100 %, let
        // through +0 %"), so the operator sees which stick is held and by
        // how much. A remote watcher does not know the controller's demand.
        bool cut = false, stopped = false;
        for (int i = 0; i < ncyl; ++i)
            if (s->cyl[i].rcl_cut) cut = true, stopped |= fabs(s->cyl[i].u_cmd) < 0.005;
        if (s->rcl_util >= 0.9 || cut) {
            // Below 90 % where the tip is, a cut comes from the limiter's
            // look-ahead (a weaker chart point within reach) or a weaker
            // slew sector: "LIMIT AHEAD", or 67 % and STOPPED read as a
            // contradiction.
            snprintf(w[n++], RENDER_WARN_LEN, "RATED CAPACITY %.0f %%%s%s", 100 * s->rcl_util,
                     cut && s->rcl_util < 0.9 ? ", LIMIT AHEAD" : "",
                     !cut ? "" : stopped ? ": MOTIONS STOPPED" : ": MOTIONS SLOWED");
            if (cut && n < max - 1) {
                int k = 0;
                const char* sep = "";
                for (int i = 0; i < ncyl && k >= 0 && k < RENDER_WARN_LEN; ++i) {
                    const world_snap_cylinder* c = &s->cyl[i];
                    if (!c->rcl_cut) continue;
                    const char* nm = c->name[0] ? c->name : "cylinder";
                    if (isnan(c->u_op))
                        k += snprintf(w[n] + k, (size_t)(RENDER_WARN_LEN - k), "%s%s: cut to %+.0f %%", sep, nm,
                                      100 * c->u_cmd);
                    else
                        k += snprintf(w[n] + k, (size_t)(RENDER_WARN_LEN - k), "%s%s: demand %+.0f %%, let through %+.0f %%",
                                      sep, nm, 100 * c->u_op, 100 * c->u_cmd);
                    sep = "; ";
                }
                ++n;
            }
        }
    }
    if (s->tipping && n < max - 1)
        snprintf(w[n++], RENDER_WARN_LEN, "TIPPING! tilt %.1f deg", s->truck_tilt * 180.0 / M_PI);
    if (s->collision && n < max - 1) snprintf(w[n++], RENDER_WARN_LEN, "COLLISION");
    if (s->npad && s->pad_lifted && n < max - 1) {
        int k = snprintf(w[n], RENDER_WARN_LEN, "PAD LIFTED OFF:");
        for (int i = 0; i < 4; ++i)
            if (s->pad_lifted >> i & 1)
                k += snprintf(w[n] + k, (size_t)(RENDER_WARN_LEN - k), " %s", render_pad_name(i));
        render_pad_margin_text(s, w[n] + k, (size_t)(RENDER_WARN_LEN - k));
        ++n;
    }
    if (s->npad && s->stab_margin < 1 && !s->tipping && n < max - 1)
        snprintf(w[n++], RENDER_WARN_LEN, "UNSTABLE: margin %.2f < 1", s->stab_margin);
    // Real time: the app's missed deadlines, or a measured factor below 1.
    bool slow = r->missed_deadlines > 0 || (s->rt_factor > 0 && s->rt_factor < 0.97);
    if (slow && n < max) snprintf(w[n++], RENDER_WARN_LEN, "CANNOT KEEP UP WITH REAL TIME (%.2fx)", s->rt_factor);
    return n;
}

// The warnings' box at the top centre (x, y, w, h [px]), w = 0 for none.
static void warnings_box(const render* r, char w[][RENDER_WARN_LEN], int n, float box[4]) {
    float tw = 0;
    for (int i = 0; i < n; ++i) tw = fmaxf(tw, render_hud_text_width(w[i], 2.0f));
    box[0] = 0.5f * ((float)r->hud.w - tw) - 8, box[1] = 5, box[2] = n ? tw + 16 : 0, box[3] = 30.0f * (float)n;
}

static void draw_warnings(render* r, char w[][RENDER_WARN_LEN], int n) {
    render_hud* h = &r->hud;
    float y = 10;
    for (int i = 0; i < n; ++i) {
        float tw = render_hud_text_width(w[i], 2.0f);
        float x = 0.5f * ((float)h->w - tw);
        render_hud_rect(h, x - 8, y - 5, tw + 16, 26, k_warn_bg);
        render_hud_text(h, x, y, 2.0f, k_white, w[i]);
        y += 30;
    }
}

// The rated capacity limiter's utilisation as a bar, bottom right: green
// below 90 %, amber to 100 %, red beyond (the fill stops at 120 %).
static void draw_rcl_bar(render* r, const world_snapshot* s) {
    r->hud.rcl_rect[2] = 0;
    if (!s->rcl_have) return;
    render_hud* h = &r->hud;
    const float w = 220, hh = 14, x = (float)h->w - w - 14, y = (float)h->h - hh - 150;
    const float green[4] = {0.2f, 0.8f, 0.3f, 1}, red[4] = {1.0f, 0.1f, 0.1f, 1};
    const double u = s->rcl_util > 0 ? s->rcl_util : 0;
    render_hud_rect(h, x - 6, y - 18, w + 12, hh + 24, k_panel);
    h->rcl_rect[0] = x - 6, h->rcl_rect[1] = y - 18, h->rcl_rect[2] = w + 12, h->rcl_rect[3] = hh + 24;
    char buf[64];
    snprintf(buf, sizeof buf, "load moment %.0f %% of rated%s", 100 * u, s->rcl_on ? "" : " (RCL off)");
    render_hud_text(h, x, y - 14, 1.0f, u >= 0.9 ? k_amber : k_white, buf);
    render_hud_rect(h, x, y, w, hh, k_dim);
    const float fill = (float)(u > 1.2 ? 1.0 : u / 1.2) * w;
    render_hud_rect(h, x, y, fill, hh, u >= 1.0 ? red : (u >= 0.9 ? k_amber : green));
    render_hud_rect(h, x + w / 1.2f - 1, y - 2, 2, hh + 4, k_white); // the 100 % mark
}

void render_hud_draw_overlay(render* r, const world_snapshot* s) {
    render_hud* h = &r->hud;
    // Warnings first as text, so the pressure bars keep clear of them.
    char w[RENDER_WARN_MAX][RENDER_WARN_LEN];
    const int nw = render_hud_warnings(r, s, w, RENDER_WARN_MAX);
    float box[4];
    warnings_box(r, w, nw, box);
    // The readouts first where the bars must keep clear of them (many
    // cylinders: compact HUD); else in the order they always had.
    const int ncyl = s->ncyl < WORLD_SNAP_MAX_CYLINDERS ? s->ncyl : WORLD_SNAP_MAX_CYLINDERS;
    if (ncyl > HUD_FEW_CYL) {
        draw_readouts(r, s);
        draw_pressure_bars(r, s, box, h->readouts_rect);
    } else {
        const float none[4] = {0, 0, 0, 0};
        draw_pressure_bars(r, s, box, none);
        draw_readouts(r, s);
    }
    draw_rcl_bar(r, s);
    draw_warnings(r, w, nw);
    render_hud_draw_mapping(r);
    if (r->link[0]) { // the remote link, top right, clear of the warnings at the centre
        const float tw = render_hud_text_width(r->link, 1.0f);
        render_hud_rect(h, (float)h->w - tw - 16, 4, tw + 12, 16, k_panel);
        render_hud_text(h, (float)h->w - tw - 10, 7, 1.0f, r->link_down[0] ? k_amber : k_white, r->link);
    }
    if (r->charts.n > 0) {
        float ch = 124.0f;
        render_charts_draw(h, &r->charts, 10, (float)h->h - ch - 10, (float)h->w - 20, ch);
    }
}
