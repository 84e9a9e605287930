// hud_mapping.c: the HUD's input mapping box: which stick, button pair and
// keys drive each function of the crane (input_mapping_text gives the lines,
// the drive session sets them). Shown for the first seconds of a drive and on
// M, so an operator of a model with five or eight functions need not guess.
#include <stdio.h>
#include <string.h>

#include "render_internal.h"

void render_set_mapping(render* r, const char* title, const char* text) {
    snprintf(r->mapping_title, sizeof r->mapping_title, "%s", title ? title : "");
    snprintf(r->mapping_text, sizeof r->mapping_text, "%s", text ? text : "");
}

void render_show_mapping(render* r, bool on) {
    r->mapping_shown = on;
}

bool render_mapping_shown(const render* r) {
    return r->mapping_shown;
}

const char* render_mapping_text(const render* r) {
    return r->mapping_text;
}

bool render_mapping_rect(const render* r, int rect[4]) {
    for (int k = 0; k < 4; ++k)
        rect[k] = (int)r->mapping_rect[k];
    return r->mapping_rect[2] > 0;
}

void render_hud_draw_mapping(render* r) {
    r->mapping_rect[2] = 0;
    if (!r->mapping_shown || !r->mapping_text[0]) return;
    static const float bg[4] = {0.05f, 0.06f, 0.08f, 0.72f}, white[4] = {1, 1, 1, 1},
                       head[4] = {0.55f, 0.85f, 1.0f, 1};
    render_hud* h = &r->hud;
    // Measure: the widest line at scale 1 (stb_easy_font, ~12 px per line).
    char line[160];
    float tw = render_hud_text_width(r->mapping_title, 1.0f);
    int nline = 0;
    for (const char* p = r->mapping_text; *p;) {
        const char* e = strchr(p, '\n');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line ? len : sizeof line - 1), p);
        const float w = render_hud_text_width(line, 1.0f);
        if (w > tw) tw = w;
        ++nline;
        p += len + (e ? 1 : 0);
    }
    // Right, above the load-moment bar (hud.c draws it 150 px over the
    // bottom, 18 px over its bar): clear of the readouts (top left), the
    // warnings (top centre), the link line (top right) and the charts.
    const float lh = 13, bw = tw + 12, bh = lh * (float)(nline + 1) + 10;
    const float x = (float)h->w - bw - 8, y = (float)h->h - 164 - 18 - 12 - bh + 6;
    render_hud_rect(h, x - 6, y - 6, bw, bh, bg);
    r->mapping_rect[0] = x - 6, r->mapping_rect[1] = y - 6, r->mapping_rect[2] = bw,
    r->mapping_rect[3] = bh;
    render_hud_text(h, x, y, 1.0f, head, r->mapping_title);
    float yy = y + lh + 2;
    for (const char* p = r->mapping_text; *p; yy += lh) {
        const char* e = strchr(p, '\n');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line ? len : sizeof line - 1), p);
        render_hud_text(h, x, yy, 1.0f, white, line);
        p += len + (e ? 1 : 0);
    }
}
