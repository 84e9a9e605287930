// panel_imgui.cpp: the parameter panel window in Dear ImGui. The only C++
// file of the renderer; everything else reaches it through panel.h.
//
// Debian's libimgui-dev ships a static libimgui.a that already contains the
// SDL2 and OpenGL3 backends, so we link it rather than compile the backend
// sources. Each panel owns its own ImGui context.
#include <cfloat>
#include <cstdio>
#include <cstring>

#include <SDL2/SDL.h>

#include <imgui.h>
#include <backends/imgui_impl_opengl3.h>
#include <backends/imgui_impl_sdl.h>

#include "panel_internal.h"

namespace {

ImGuiContext* ctx_of(panel* p) {
    return static_cast<ImGuiContext*>(p->imgui_ctx);
}

/// Slider format showing the unit and the note ("fluid's"); a literal '%'
/// must be doubled.
void unit_format(char* out, size_t n, const char* unit, const char* note) {
    size_t k = (size_t)snprintf(out, n, "%%.4g ");
    char both[64];
    std::snprintf(both, sizeof both, note && *note ? "%s (%s)" : "%s", unit, note);
    for (const char* u = both; *u && k + 3 < n; ++u) {
        if (*u == '%') out[k++] = '%';
        out[k++] = *u;
    }
    out[k] = '\0';
}

// Label text as shown: on-release parameters (they rebuild the world) get a
// marker that the footnote explains.
void shown_label(const panel_param* q, char* out, size_t n) {
    std::snprintf(out, n, "%s%s", q->label, q->on_release ? " *" : "");
}

// One row per parameter: the whole label in a column of its own (ImGui puts
// it right of the widget and cut it at the window edge: "lifting arm m"),
// then the widget.
void draw_group(panel* p, const char* group, float label_w) {
    for (int i = 0; i < p->nparam; ++i) {
        panel_param* q = &p->param[i];
        if (std::strcmp(q->group, group) != 0 || !panel_matches(p, i)) continue;
        char label[80];
        shown_label(q, label, sizeof label);
        ImGui::PushID(i);
        ImGui::AlignTextToFramePadding();
        ImGui::TextUnformatted(label);
        ImGui::SameLine(label_w);
        ImGui::SetNextItemWidth(-1.0f);
        if (q->nchoice > 0) {
            // A choice is a list of names, not a slider over their indices.
            int cur = (int)*q->value;
            if (cur < 0 || cur >= q->nchoice) cur = 0;
            if (ImGui::BeginCombo("##choice", q->choices[cur])) {
                for (int k = 0; k < q->nchoice; ++k)
                    if (ImGui::Selectable(q->choices[k], k == cur) && k != cur) panel_set_id(p, i, k, nullptr, 0);
                ImGui::EndCombo();
            }
        } else {
            char fmt[80];
            unit_format(fmt, sizeof fmt, q->unit, q->note);
            double v = q->has_pending ? q->pending : *q->value;
            // Drag (or Ctrl+click / double-click to type): the speed is a
            // fraction of the value per pixel. A slider mapped the whole
            // range onto its width: 10 kg per pixel on a 180 kg boom.
            const float speed = (float)panel_drag_speed(p, i);
            // A drag stays in the slider range (the typical range, widened
            // to the current value); a typed value may go beyond it, and
            // panel_set_id checks it against the hard range [min, max]
            // (no AlwaysClamp: ImGui would clamp typed values too).
            double lo = q->smin < v ? q->smin : v, hi = q->smax > v ? q->smax : v;
            const bool changed = ImGui::DragScalar("##value", ImGuiDataType_Double, &v, speed, &lo, &hi, fmt, 0);
            const bool done = ImGui::IsItemDeactivatedAfterEdit();
            // Active with no mouse button down: the value is being typed
            // (Ctrl+click or double-click opened the text field), and each
            // keystroke is a "change": typing 900 passed 9 (clamped to the
            // minimum) to the crane on the way.
            const bool typing = ImGui::IsItemActive() && !ImGui::GetIO().MouseDown[0];
            if (changed || done) {
                if (typing) panel_edit_typed(p, i, v, done);
                else panel_edit(p, i, v, done);
            }
            // An edit given up (Escape while typing) leaves nothing pending.
            if (!done && !ImGui::IsItemActive()) q->has_pending = false;
        }
        const ImVec2 r0 = ImGui::GetItemRectMin(), r1 = ImGui::GetItemRectMax();
        q->rect[0] = r0.x, q->rect[1] = r0.y, q->rect[2] = r1.x - r0.x, q->rect[3] = r1.y - r0.y;
        q->drawn = ImGui::IsItemVisible(); // not scrolled or clipped out of the window
        ImGui::PopID();
    }
}

} // namespace

extern "C" bool panel_gui_init(panel* p, SDL_Window* win, void* gl_context) {
    if (!p || !win) return false;
    ImGuiContext* prev = ImGui::GetCurrentContext();
    ImGuiContext* ctx = ImGui::CreateContext();
    ImGui::SetCurrentContext(ctx);
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr; // no imgui.ini littering the working directory
    ImGui::StyleColorsDark();
    ImGui::GetStyle().Alpha = 0.92f;
    bool ok = ImGui_ImplSDL2_InitForOpenGL(win, gl_context) &&
              ImGui_ImplOpenGL3_Init("#version 330 core");
    if (!ok) {
        ImGui::DestroyContext(ctx);
        ImGui::SetCurrentContext(prev);
        return false;
    }
    p->imgui_ctx = ctx;
    return true;
}

extern "C" void panel_gui_shutdown(panel* p) {
    if (!p || !p->imgui_ctx) return;
    ImGui::SetCurrentContext(ctx_of(p));
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplSDL2_Shutdown();
    ImGui::DestroyContext(ctx_of(p));
    p->imgui_ctx = nullptr;
}

extern "C" bool panel_gui_event(panel* p, const SDL_Event* ev) {
    if (!p || !p->imgui_ctx || !p->visible) return false;
    ImGui::SetCurrentContext(ctx_of(p));
    const int sc = ev->type == SDL_KEYDOWN || ev->type == SDL_KEYUP ? (int)ev->key.keysym.scancode : -1;
    if (ev->type == SDL_KEYUP && sc >= 0 && sc < 512 && p->down_since_frame[sc] && p->ndeferred_up < 16) {
        // Pressed and released before ImGui saw it down: release it after
        // the next frame (panel_gui_draw), or the Enter that ends typing
        // is lost and the panel keeps the keyboard.
        p->deferred_up[p->ndeferred_up++] = sc;
    } else {
        ImGui_ImplSDL2_ProcessEvent(ev);
        if (ev->type == SDL_KEYDOWN && sc >= 0 && sc < 512) p->down_since_frame[sc] = 1;
    }
    if (ev->type == SDL_MOUSEMOTION) p->mouse_x = (float)ev->motion.x, p->mouse_y = (float)ev->motion.y, p->have_mouse = true;
    if (ev->type == SDL_MOUSEBUTTONDOWN || ev->type == SDL_MOUSEBUTTONUP)
        p->mouse_x = (float)ev->button.x, p->mouse_y = (float)ev->button.y, p->have_mouse = true;
    // A mouse that left the window is nowhere over the panel.
    if (ev->type == SDL_WINDOWEVENT && ev->window.event == SDL_WINDOWEVENT_LEAVE) p->have_mouse = false;
    const ImGuiIO& io = ImGui::GetIO();
    switch (ev->type) {
    case SDL_MOUSEMOTION:
    case SDL_MOUSEBUTTONDOWN:
    case SDL_MOUSEBUTTONUP:
    case SDL_MOUSEWHEEL:
        return io.WantCaptureMouse;
    case SDL_KEYDOWN:
    case SDL_KEYUP:
    case SDL_TEXTINPUT:
        return io.WantCaptureKeyboard;
    default:
        return false;
    }
}

extern "C" void panel_gui_show(panel* p, bool show) {
    if (p) p->visible = show;
}

extern "C" bool panel_gui_visible(const panel* p) { return p && p->visible; }

extern "C" bool panel_gui_wants_keyboard(const panel* p) { return p && p->visible && p->wants_keyboard; }

extern "C" bool panel_gui_has_focus(const panel* p) { return p && p->visible && p->focused; }

extern "C" bool panel_gui_action_rect(const panel* p, int id, float rect[4]) {
    if (!p || id < 0 || id >= p->naction || !p->visible || !p->action[id].drawn) return false;
    std::memcpy(rect, p->action[id].rect, 4 * sizeof(float));
    return true;
}

extern "C" bool panel_gui_window_rect(const panel* p, float rect[4]) {
    if (!p || !p->visible || !(p->win_rect[2] > 0)) return false;
    std::memcpy(rect, p->win_rect, 4 * sizeof(float));
    return true;
}

extern "C" bool panel_gui_item_rect(const panel* p, int id, float rect[4]) {
    if (!p || id < 0 || id >= p->nparam || !p->visible || !p->param[id].drawn) return false;
    std::memcpy(rect, p->param[id].rect, 4 * sizeof(float));
    return true;
}

extern "C" void panel_gui_draw(panel* p) {
    if (!p || !p->imgui_ctx) return;
    ImGui::SetCurrentContext(ctx_of(p));
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplSDL2_NewFrame();
    // The backend reads the mouse only when SDL gives the window mouse or
    // keyboard focus, which an offscreen view never has: there the events'
    // own position is used, so the panel still answers the mouse.
    ImGuiIO& io = ImGui::GetIO();
    if (io.MousePos.x == -FLT_MAX && p->have_mouse) io.MousePos = ImVec2(p->mouse_x, p->mouse_y);
    ImGui::NewFrame();
    // This frame has seen the keys down; the releases held back go in now
    // and count from the next frame.
    std::memset(p->down_since_frame, 0, sizeof p->down_since_frame);
    for (int k = 0; k < p->ndeferred_up; ++k) {
        SDL_Event up;
        std::memset(&up, 0, sizeof up);
        up.type = SDL_KEYUP;
        up.key.state = SDL_RELEASED;
        up.key.keysym.scancode = (SDL_Scancode)p->deferred_up[k];
        ImGui_ImplSDL2_ProcessEvent(&up);
    }
    p->ndeferred_up = 0;
    for (int i = 0; i < p->nparam; ++i) p->param[i].drawn = false;
    for (int a = 0; a < p->naction; ++a) p->action[a].drawn = false;
    p->win_rect[2] = 0;
    if (p->visible) {
        // The label column is as wide as the longest label.
        float label_w = 0.0f;
        bool any_release = false;
        for (int i = 0; i < p->nparam; ++i) {
            char label[80];
            shown_label(&p->param[i], label, sizeof label);
            const float w = ImGui::CalcTextSize(label).x;
            if (w > label_w) label_w = w;
            any_release |= p->param[i].on_release;
        }
        label_w += 2.0f * ImGui::GetStyle().ItemSpacing.x;
        const ImVec2 disp = ImGui::GetIO().DisplaySize;
        const float win_w = label_w + 190.0f;
        ImGui::SetNextWindowPos(ImVec2(disp.x - win_w - 10.0f, 10.0f), ImGuiCond_FirstUseEver);
        // Down to above the load-moment bar and the strip charts, so they
        // stay visible (it covered the bar); the list scrolls.
        const float win_h = disp.y - 10.0f - PANEL_BOTTOM_CLEAR > 200.0f ? disp.y - 10.0f - PANEL_BOTTOM_CLEAR : 200.0f;
        ImGui::SetNextWindowSize(ImVec2(win_w, win_h), ImGuiCond_FirstUseEver);
        ImGui::Begin("Parameters", &p->visible);
        {
            const ImVec2 wp = ImGui::GetWindowPos(), ws = ImGui::GetWindowSize();
            p->win_rect[0] = wp.x, p->win_rect[1] = wp.y, p->win_rect[2] = ws.x, p->win_rect[3] = ws.y;
        }
        // The buttons in rows as wide as the window: in one row the last
        // ("load model") was cut off at the window's edge.
        const ImGuiStyle& style = ImGui::GetStyle();
        const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
        for (int a = 0; a < p->naction; ++a) {
            const float bw = ImGui::CalcTextSize(p->action[a].label).x + 2.0f * style.FramePadding.x;
            if (a && ImGui::GetItemRectMax().x + style.ItemSpacing.x + bw <= right) ImGui::SameLine();
            if (ImGui::Button(p->action[a].label)) panel_run_action_id(p, a);
            const ImVec2 r0 = ImGui::GetItemRectMin(), r1 = ImGui::GetItemRectMax();
            panel_action* act = &p->action[a];
            act->rect[0] = r0.x, act->rect[1] = r0.y, act->rect[2] = r1.x - r0.x, act->rect[3] = r1.y - r0.y;
            act->drawn = true;
        }
        for (int t = 0; t < p->ntext; ++t) {
            ImGui::PushID(1000 + t);
            ImGui::SetNextItemWidth(-1.0f);
            ImGui::InputTextWithHint("##text", p->text[t].label, p->text[t].buf, p->text[t].n);
            ImGui::PopID();
        }
        ImGui::SetNextItemWidth(-1.0f);
        ImGui::InputTextWithHint("##filter", "filter (component or parameter)", p->filter, sizeof p->filter);
        if (p->message[0]) {
            ImGui::PushTextWrapPos(0.0f);
            ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.2f, 1.0f), "%s", p->message);
            ImGui::PopTextWrapPos();
        }
        // Who has the keyboard: while a value is typed the crane's keys go
        // here; Enter or Escape gives them back (below). Esc in the panel
        // never quits the drive (drive_session.c).
        ImGui::PushTextWrapPos(0.0f);
        if (p->wants_keyboard)
            ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.2f, 1.0f),
                               "The panel has the keyboard: Enter applies the value, Esc drops it; both give "
                               "the keyboard back to the crane.");
        if (any_release) ImGui::TextDisabled("* applied on release; rebuilds the world (loads back at their start)");
        ImGui::PopTextWrapPos();
        // Groups in the order they were first registered.
        for (int i = 0; i < p->nparam; ++i) {
            bool first = true;
            for (int j = 0; j < i && first; ++j)
                first = std::strcmp(p->param[j].group, p->param[i].group) != 0;
            if (!first) continue;
            bool any = false;
            for (int j = i; j < p->nparam && !any; ++j)
                any = std::strcmp(p->param[j].group, p->param[i].group) == 0 && panel_matches(p, j);
            if (!any) continue;
            if (ImGui::CollapsingHeader(p->param[i].group, ImGuiTreeNodeFlags_DefaultOpen))
                draw_group(p, p->param[i].group, label_w);
        }
        if (p->last_error[0])
            ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.3f, 1.0f), "%s", p->last_error);
        // Enter or Escape ends typing and takes the focus off the window, so
        // the next keys drive the crane again. ImGui itself kept the window
        // focused after Enter, and the crane ignored every key until the 3D
        // view was clicked, with nothing saying why.
        const bool enter = ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Enter), false) ||
                           ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_KeyPadEnter), false);
        const bool esc = ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape), false);
        const bool focused = ImGui::IsWindowFocused(ImGuiFocusedFlags_RootAndChildWindows);
        ImGui::End();
        if ((enter || esc) && focused) ImGui::SetWindowFocus(nullptr);
        p->focused = focused && !enter && !esc;
    } else {
        p->focused = false;
    }
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    // As ImGui decided it for the frame just built (after the focus release).
    p->wants_keyboard = ImGui::GetIO().WantCaptureKeyboard;
}
