// panel_internal.h: the panel's private struct, shared by panel.c (registry)
// and panel_imgui.cpp (the window). Not part of the public API.
#ifndef RENDER_PANEL_INTERNAL_H
#define RENDER_PANEL_INTERNAL_H

#include "panel.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct panel_param {
    char label[64], group[112], unit[16]; // group: a crane chain's "function: element (type)"
    double* value;
    double min, max, step;
    double smin, smax;          ///< range a drag covers
    bool changed;
    bool on_release;            ///< applied only when an edit is finished
    bool has_pending;           ///< an on-release edit in progress
    double pending;             ///< its value, shown but not applied
    const char* const* choices; ///< option names of a choice, or NULL
    int nchoice;
    bool drawn;                 ///< drawn in the last frame, at rect
    float rect[4];              ///< x, y, w, h [px]
    char note[24];              ///< shown after the unit ("fluid's"), or ""
} panel_param;

typedef struct panel_text {
    char label[64];
    char* buf;
    size_t n;
} panel_text;

typedef struct panel_action {
    char label[64];
    panel_action_fn fn;
    void* user;
    bool drawn;     ///< drawn in the last frame, at rect
    float rect[4];  ///< x, y, w, h [px]
} panel_action;

struct panel {
    panel_param* param;
    int nparam, capparam;
    panel_action* action;
    int naction, capaction;
    panel_text text[4];
    int ntext;
    char filter[64];
    char message[512];
    panel_change_fn on_change;
    void* on_change_user;
    char last_error[320]; // room for a group of 112 and a label of 64 with the range
    bool visible;
    bool wants_keyboard;  ///< ImGui had the keyboard at the last frame
    bool focused;         ///< the panel's window had the focus at the end of the last frame
    float win_rect[4];    ///< the window as last drawn, x y w h [px] (w 0: not drawn)
    bool have_mouse;      ///< mouse_x/y hold the last mouse event's position
    /// Keys pressed since the last frame (SDL scancodes), and key-ups held
    /// back for after it: ImGui 1.86 reads key states once per frame, so a
    /// press and release between two frames would never reach it.
    unsigned char down_since_frame[512];
    int deferred_up[16], ndeferred_up;
    float mouse_x, mouse_y;
    void* imgui_ctx; ///< ImGuiContext*, owned by panel_imgui.cpp
};

#ifdef __cplusplus
}
#endif
#endif
