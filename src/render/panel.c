// panel.c: the parameter registry behind panel.h: lookup, range checks,
// changed flags and actions. Pure C, no ImGui, so tests and a network
// interface can use it without a window.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "panel.h"
#include "panel_internal.h"

panel* panel_create(void) {
    panel* p = calloc(1, sizeof *p);
    if (p) p->visible = true;
    return p;
}

void panel_destroy(panel* p) {
    if (!p) return;
    free(p->param);
    free(p->action);
    free(p);
}

int panel_add_param(panel* p, const panel_param_def* d) {
    if (!p || !d || !d->value || !d->label || !d->label[0] || !(d->min <= d->max)) return -1;
    const char* group = d->group && d->group[0] ? d->group : "general";
    for (int i = 0; i < p->nparam; ++i)
        if (strcmp(p->param[i].label, d->label) == 0 && strcmp(p->param[i].group, group) == 0)
            return -1;
    if (p->nparam == p->capparam) {
        int nc = p->capparam ? 2 * p->capparam : 32;
        panel_param* np = realloc(p->param, (size_t)nc * sizeof *np);
        if (!np) return -1;
        p->param = np;
        p->capparam = nc;
    }
    panel_param* q = &p->param[p->nparam];
    memset(q, 0, sizeof *q);
    snprintf(q->label, sizeof q->label, "%s", d->label);
    snprintf(q->group, sizeof q->group, "%s", group);
    snprintf(q->unit, sizeof q->unit, "%s", d->unit ? d->unit : "");
    q->value = d->value;
    q->min = d->min;
    q->max = d->max;
    q->step = d->step > 0 ? d->step : (d->max - d->min) / 100.0;
    q->smin = d->min;
    q->smax = d->max;

    q->on_release = d->on_release;
    return p->nparam++;
}

int panel_add_choice(panel* p, const char* label, const char* group, double* value, const char* const* options,
                     int n) {
    if (!options || n < 1) return -1;
    panel_param_def d = {label, group, "", value, 0, n - 1, 1, false};
    int id = panel_add_param(p, &d);
    if (id < 0) return -1;
    p->param[id].choices = options;
    p->param[id].nchoice = n;
    return id;
}

int panel_choice_count(const panel* p, int id) {
    return p && id >= 0 && id < p->nparam ? p->param[id].nchoice : 0;
}

const char* panel_choice_label(const panel* p, int id, int k) {
    if (!p || id < 0 || id >= p->nparam || k < 0 || k >= p->param[id].nchoice) return NULL;
    return p->param[id].choices[k];
}

bool panel_on_release(const panel* p, int id) {
    return p && id >= 0 && id < p->nparam && p->param[id].on_release;
}

double panel_drag_speed(const panel* p, int id) {
    if (!p || id < 0 || id >= p->nparam) return 0;
    const panel_param* q = &p->param[id];
    const double v = q->has_pending ? q->pending : *q->value;
    double floor = PANEL_DRAG_FLOOR * (q->smax - q->smin); // the slider range: a hard range spans decades
    if (PANEL_DRAG_REL * fabs(q->smin) > floor) floor = PANEL_DRAG_REL * fabs(q->smin);
    const double rel = PANEL_DRAG_REL * fabs(v);
    return rel > floor ? rel : floor;
}

panel_status panel_edit(panel* p, int id, double v, bool done) {
    if (!p || id < 0 || id >= p->nparam) return panel_set_id(p, id, v, NULL, 0);
    panel_param* q = &p->param[id];
    if (q->on_release && !done) {
        // Shown, not applied: the app sees one change when the edit ends.
        q->pending = v;
        q->has_pending = true;
        return PANEL_OK;
    }
    q->has_pending = false;
    return panel_set_id(p, id, v, NULL, 0);
}

panel_status panel_edit_typed(panel* p, int id, double v, bool done) {
    if (!p || id < 0 || id >= p->nparam) return panel_set_id(p, id, v, NULL, 0);
    panel_param* q = &p->param[id];
    if (!done) {
        q->pending = v;
        q->has_pending = true;
        return PANEL_OK;
    }
    q->has_pending = false;
    return panel_set_id(p, id, v, NULL, 0);
}

bool panel_pending(const panel* p, int id, double* v) {
    if (!p || id < 0 || id >= p->nparam || !p->param[id].has_pending) return false;
    if (v) *v = p->param[id].pending;
    return true;
}

int panel_add_action(panel* p, const char* label, panel_action_fn fn, void* user) {
    if (!p || !label || !fn) return -1;
    if (p->naction == p->capaction) {
        int nc = p->capaction ? 2 * p->capaction : 8;
        panel_action* na = realloc(p->action, (size_t)nc * sizeof *na);
        if (!na) return -1;
        p->action = na;
        p->capaction = nc;
    }
    panel_action* a = &p->action[p->naction];
    snprintf(a->label, sizeof a->label, "%s", label);
    a->fn = fn;
    a->user = user;
    return p->naction++;
}

/// Lookup; *ambiguous tells a duplicate label in several groups from "absent".
static int find(const panel* p, const char* label, bool* ambiguous) {
    *ambiguous = false;
    if (!p || !label) return -1;
    const char* slash = strrchr(label, '/');
    if (slash) {
        size_t glen = (size_t)(slash - label);
        for (int i = 0; i < p->nparam; ++i)
            if (strlen(p->param[i].group) == glen && strncmp(p->param[i].group, label, glen) == 0 &&
                strcmp(p->param[i].label, slash + 1) == 0)
                return i;
        // A label may itself contain '/', so also try it whole.
    }
    int found = -1;
    for (int i = 0; i < p->nparam; ++i)
        if (strcmp(p->param[i].label, label) == 0) {
            if (found >= 0) {
                *ambiguous = true;
                return -1;
            }
            found = i;
        }
    return found;
}

int panel_find(const panel* p, const char* label) {
    bool amb;
    return find(p, label, &amb);
}

static void say(panel* p, char* msg, size_t msgsz, const char* text) {
    snprintf(p->last_error, sizeof p->last_error, "%s", text);
    if (msg && msgsz) snprintf(msg, msgsz, "%s", text);
}

panel_status panel_set_id(panel* p, int id, double value, char* msg, size_t msgsz) {
    char text[sizeof p->last_error];
    if (!p || id < 0 || id >= p->nparam) {
        snprintf(text, sizeof text, "panel: no parameter with id %d", id);
        if (p) say(p, msg, msgsz, text);
        return PANEL_NOT_FOUND;
    }
    panel_param* q = &p->param[id];
    if (!isfinite(value)) {
        snprintf(text, sizeof text, "panel: %s/%s: value must be finite", q->group, q->label);
        say(p, msg, msgsz, text);
        return PANEL_NOT_FINITE;
    }
    if (q->nchoice && value != floor(value)) {
        snprintf(text, sizeof text, "panel: %s/%s: %g is not one of the options 0..%d; unchanged", q->group,
                 q->label, value, q->nchoice - 1);
        say(p, msg, msgsz, text);
        return PANEL_OUT_OF_RANGE;
    }
    if (value < q->min || value > q->max) {
        snprintf(text, sizeof text, "panel: %s/%s: %g %s is outside [%g, %g] %s; unchanged",
                 q->group, q->label, value, q->unit, q->min, q->max, q->unit);
        say(p, msg, msgsz, text);
        return PANEL_OUT_OF_RANGE;
    }
    if (msg && msgsz) msg[0] = '\0';
    p->last_error[0] = '\0';
    if (*q->value != value) {
        *q->value = value;
        q->changed = true;
        if (p->on_change) p->on_change(p->on_change_user, id, q->label, value);
    }
    return PANEL_OK;
}

panel_status panel_set(panel* p, const char* label, double value, char* msg, size_t msgsz) {
    if (!p) return PANEL_NOT_FOUND;
    bool amb;
    int id = find(p, label, &amb);
    if (id < 0) {
        char text[sizeof p->last_error];
        snprintf(text, sizeof text,
                 amb ? "panel: \"%s\" is in several groups; say \"group/%s\""
                     : "panel: no parameter \"%s\"",
                 label ? label : "(null)", label ? label : "");
        say(p, msg, msgsz, text);
        return amb ? PANEL_AMBIGUOUS : PANEL_NOT_FOUND;
    }
    return panel_set_id(p, id, value, msg, msgsz);
}

double panel_get(const panel* p, int id) {
    if (!p || id < 0 || id >= p->nparam) return NAN;
    return *p->param[id].value;
}

bool panel_take_changed(panel* p, int id) {
    if (!p || id < 0 || id >= p->nparam) return false;
    bool c = p->param[id].changed;
    p->param[id].changed = false;
    return c;
}

int panel_next_changed(panel* p) {
    for (int i = 0; p && i < p->nparam; ++i)
        if (p->param[i].changed) {
            p->param[i].changed = false;
            return i;
        }
    return -1;
}

void panel_on_change(panel* p, panel_change_fn fn, void* user) {
    p->on_change = fn;
    p->on_change_user = user;
}

bool panel_run_action_id(panel* p, int id) {
    if (!p || id < 0 || id >= p->naction) return false;
    p->action[id].fn(p->action[id].user);
    return true;
}

bool panel_run_action(panel* p, const char* label) {
    for (int i = 0; p && label && i < p->naction; ++i)
        if (strcmp(p->action[i].label, label) == 0) return panel_run_action_id(p, i);
    return false;
}

int panel_count(const panel* p) {
    return p ? p->nparam : 0;
}
const char* panel_label(const panel* p, int id) {
    return p && id >= 0 && id < p->nparam ? p->param[id].label : NULL;
}
const char* panel_group(const panel* p, int id) {
    return p && id >= 0 && id < p->nparam ? p->param[id].group : NULL;
}
const char* panel_unit(const panel* p, int id) {
    return p && id >= 0 && id < p->nparam ? p->param[id].unit : NULL;
}
void panel_range(const panel* p, int id, double* min, double* max, double* step) {
    if (!p || id < 0 || id >= p->nparam) return;
    if (min) *min = p->param[id].min;
    if (max) *max = p->param[id].max;
    if (step) *step = p->param[id].step;
}
int panel_action_count(const panel* p) {
    return p ? p->naction : 0;
}
const char* panel_action_label(const panel* p, int id) {
    return p && id >= 0 && id < p->naction ? p->action[id].label : NULL;
}
const char* panel_last_error(const panel* p) {
    return p ? p->last_error : "";
}

void panel_set_slider_range(panel* p, int id, double min, double max) {
    if (!p || id < 0 || id >= p->nparam || !(min < max)) return;
    panel_param* q = &p->param[id];
    q->smin = min > q->min ? min : q->min;
    q->smax = max < q->max ? max : q->max;
    if (!(q->smin < q->smax)) q->smin = q->min, q->smax = q->max;
}

void panel_set_note(panel* p, int id, const char* note) {
    if (!p || id < 0 || id >= p->nparam) return;
    snprintf(p->param[id].note, sizeof p->param[id].note, "%s", note ? note : "");
}

const char* panel_note(const panel* p, int id) {
    return p && id >= 0 && id < p->nparam ? p->param[id].note : NULL;
}

void panel_slider_range(const panel* p, int id, double* min, double* max) {
    if (!p || id < 0 || id >= p->nparam) return;
    if (min) *min = p->param[id].smin;
    if (max) *max = p->param[id].smax;
}

int panel_add_text(panel* p, const char* label, char* buf, size_t n) {
    const int cap = (int)(sizeof p->text / sizeof p->text[0]);
    if (!p || !label || !buf || n == 0 || p->ntext == cap) return -1;
    panel_text* t = &p->text[p->ntext];
    snprintf(t->label, sizeof t->label, "%s", label);
    t->buf = buf;
    t->n = n;
    return p->ntext++;
}

int panel_text_count(const panel* p) { return p ? p->ntext : 0; }

const char* panel_text_label(const panel* p, int id) {
    return p && id >= 0 && id < p->ntext ? p->text[id].label : NULL;
}

bool panel_set_text(panel* p, const char* label, const char* text) {
    for (int i = 0; p && label && i < p->ntext; ++i)
        if (strcmp(p->text[i].label, label) == 0) {
            snprintf(p->text[i].buf, p->text[i].n, "%s", text ? text : "");
            return true;
        }
    return false;
}

void panel_set_filter(panel* p, const char* text) {
    if (p) snprintf(p->filter, sizeof p->filter, "%s", text ? text : "");
}

const char* panel_filter(const panel* p) { return p ? p->filter : ""; }

// Case-insensitive substring test (ASCII: the names are identifiers).
static bool contains(const char* hay, const char* needle) {
    const size_t n = strlen(needle);
    for (const char* h = hay; *h; ++h) {
        size_t k = 0;
        while (k < n && h[k] && (h[k] | 0x20) == (needle[k] | 0x20)) ++k;
        if (k == n) return true;
    }
    return n == 0;
}

bool panel_matches(const panel* p, int id) {
    if (!p || id < 0 || id >= p->nparam) return false;
    return !p->filter[0] || contains(p->param[id].group, p->filter) || contains(p->param[id].label, p->filter);
}

void panel_set_message(panel* p, const char* text) {
    if (p) snprintf(p->message, sizeof p->message, "%s", text ? text : "");
}

const char* panel_message(const panel* p) { return p ? p->message : ""; }
