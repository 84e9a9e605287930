// panel_imgui.cpp: the parameter panel window in Dear ImGui. The only C++
// file of the renderer; everything else reaches it through panel.h.
//
// Debian's libimgui-dev ships a static libimgui.a that already contains the
// SDL2 and OpenGL3 backends, so we link it rather than compile the backend
// sources. Each panel owns its own ImGui context.
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

/// Slider format showing the unit; a literal '%' must be doubled.
void unit_format(char* out, size_t n, const char* unit) {
    size_t k = (size_t)snprintf(out, n, "%%.4g ");
    for (const char* u = unit; *u && k + 3 < n; ++u) {
        if (*u == '%') out[k++] = '%';
        out[k++] = *u;
    }
    out[k] = '\0';
}

void draw_group(panel* p, const char* group) {
    for (int i = 0; i < p->nparam; ++i) {
        panel_param* q = &p->param[i];
        if (std::strcmp(q->group, group) != 0) continue;
        char fmt[40];
        unit_format(fmt, sizeof fmt, q->unit);
        double v = *q->value;
        ImGui::PushID(i);
        // Ctrl+click turns the slider into a text field for exact values;
        // either way the new value goes through the same range check.
        if (ImGui::SliderScalar(q->label, ImGuiDataType_Double, &v, &q->min, &q->max, fmt))
            panel_set_id(p, i, v, nullptr, 0);
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
    ImGui_ImplSDL2_ProcessEvent(ev);
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

extern "C" void panel_gui_draw(panel* p) {
    if (!p || !p->imgui_ctx) return;
    ImGui::SetCurrentContext(ctx_of(p));
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplSDL2_NewFrame();
    ImGui::NewFrame();
    if (p->visible) {
        const ImVec2 disp = ImGui::GetIO().DisplaySize;
        ImGui::SetNextWindowPos(ImVec2(disp.x - 350.0f, 10.0f), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(340.0f, 430.0f), ImGuiCond_FirstUseEver);
        ImGui::Begin("Parameters", &p->visible);
        for (int a = 0; a < p->naction; ++a) {
            if (a) ImGui::SameLine();
            if (ImGui::Button(p->action[a].label)) panel_run_action_id(p, a);
        }
        // Groups in the order they were first registered.
        for (int i = 0; i < p->nparam; ++i) {
            bool first = true;
            for (int j = 0; j < i && first; ++j)
                first = std::strcmp(p->param[j].group, p->param[i].group) != 0;
            if (!first) continue;
            if (ImGui::CollapsingHeader(p->param[i].group, ImGuiTreeNodeFlags_DefaultOpen))
                draw_group(p, p->param[i].group);
        }
        if (p->last_error[0])
            ImGui::TextColored(ImVec4(1.0f, 0.35f, 0.3f, 1.0f), "%s", p->last_error);
        ImGui::End();
    }
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}
