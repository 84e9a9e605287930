// panel_internal.h: the panel's private struct, shared by panel.c (registry)
// and panel_imgui.cpp (the window). Not part of the public API.
#ifndef RENDER_PANEL_INTERNAL_H
#define RENDER_PANEL_INTERNAL_H

#include "panel.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct panel_param {
    char label[64], group[64], unit[16];
    double* value;
    double min, max, step;
    bool changed;
} panel_param;

typedef struct panel_action {
    char label[64];
    panel_action_fn fn;
    void* user;
} panel_action;

struct panel {
    panel_param* param;
    int nparam, capparam;
    panel_action* action;
    int naction, capaction;
    panel_change_fn on_change;
    void* on_change_user;
    char last_error[256];
    bool visible;
    void* imgui_ctx; ///< ImGuiContext*, owned by panel_imgui.cpp
};

#ifdef __cplusplus
}
#endif
#endif
