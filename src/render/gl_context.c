// gl_context.c: the SDL2 window and the OpenGL 3.3 core context, plus the
// framebuffer objects the scene renders into.
//
// Offscreen mode still makes an SDL window (hidden): under SDL's "offscreen"
// video driver that window is backed by an EGL pbuffer on Mesa, which works
// with no X server or GPU (llvmpipe). The frame itself always goes into our
// own FBO; a visible window gets it by one blit before the swap.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "gl_context.h"

static void set_err(char* err, size_t errsz, const char* what) {
    if (err && errsz) snprintf(err, errsz, "render: %s: %s", what, SDL_GetError());
}

// The display a window would go to, as the environment names it, for
// messages: "on DISPLAY=:0", "on WAYLAND_DISPLAY=wayland-0", or "".
static void display_name(char* buf, size_t n) {
    const char* x = getenv("DISPLAY");
    const char* w = getenv("WAYLAND_DISPLAY");
    if (x && *x) snprintf(buf, n, " on DISPLAY=%s", x);
    else if (w && *w) snprintf(buf, n, " on WAYLAND_DISPLAY=%s", w);
    else buf[0] = 0;
}

// WAYLAND_DISPLAY names a socket that exists (absolute, or in
// XDG_RUNTIME_DIR). Without it libwayland prints its own error line when SDL
// tries to connect, so the wayland driver is only tried when it can work.
static bool wayland_socket(const char* name) {
    char path[512];
    const char* dir = getenv("XDG_RUNTIME_DIR");
    if (name[0] == '/') snprintf(path, sizeof path, "%s", name);
    else if (dir && *dir) snprintf(path, sizeof path, "%s/%s", dir, name);
    else return false;
    struct stat st;
    return stat(path, &st) == 0;
}

bool render_display_available(char* why, size_t n) {
    const char* d = getenv("DISPLAY");
    const char* w = getenv("WAYLAND_DISPLAY");
    if (d && *d) return true;
    if (w && *w) {
        if (wayland_socket(w)) return true;
        const char* dir = getenv("XDG_RUNTIME_DIR");
        if (w[0] != '/' && !(dir && *dir))
            snprintf(why, n, "no display (WAYLAND_DISPLAY=%s, but XDG_RUNTIME_DIR is unset)", w);
        else
            snprintf(why, n, "no display (WAYLAND_DISPLAY=%s: no socket %s%s%s)", w, w[0] == '/' ? "" : dir,
                     w[0] == '/' ? "" : "/", w);
        return false;
    }
    snprintf(why, n, "no display (DISPLAY and WAYLAND_DISPLAY unset)");
    return false;
}

bool render_gl_open(render* r, char* err, size_t errsz) {
    // Prefer the offscreen driver for headless rendering, but let an explicit
    // SDL_VIDEODRIVER in the environment win (it overrides a default hint).
    if (r->cfg.offscreen && !SDL_WasInit(SDL_INIT_VIDEO))
        SDL_SetHintWithPriority(SDL_HINT_VIDEODRIVER, "offscreen", SDL_HINT_DEFAULT);
    // A window: only the drivers of the displays the environment names.
    // Left to itself, SDL falls back to its offscreen or dummy driver when
    // the X server or compositor is not there, and the "window" is then
    // invisible; it would also try wayland without one, where libwayland
    // prints its own error line. (An explicit SDL_VIDEODRIVER still wins.)
    if (!r->cfg.offscreen && !SDL_WasInit(SDL_INIT_VIDEO)) {
        const char* x = getenv("DISPLAY");
        const char* w = getenv("WAYLAND_DISPLAY");
        char list[32] = "";
        if (x && *x) snprintf(list, sizeof list, "x11");
        if (w && *w && wayland_socket(w))
            snprintf(list + strlen(list), sizeof list - strlen(list), "%swayland", list[0] ? "," : "");
        if (list[0]) SDL_SetHintWithPriority(SDL_HINT_VIDEODRIVER, list, SDL_HINT_DEFAULT);
    }
    if (!SDL_WasInit(SDL_INIT_VIDEO)) {
        if (SDL_InitSubSystem(SDL_INIT_VIDEO) != 0) {
            if (r->cfg.offscreen) {
                set_err(err, errsz, "SDL video init");
            } else if (err && errsz) {
                char d[160];
                display_name(d, sizeof d);
                snprintf(err, errsz, "render: " RENDER_ERR_NO_SCREEN "%s (%s)", d, SDL_GetError());
            }
            return false;
        }
        r->own_video = true;
    }
    if (!r->cfg.offscreen) {
        // These drivers have no screen: a window there is one nobody sees.
        const char* drv = SDL_GetCurrentVideoDriver();
        if (drv && (!strcmp(drv, "offscreen") || !strcmp(drv, "dummy"))) {
            if (err && errsz) {
                char d[160];
                display_name(d, sizeof d);
                snprintf(err, errsz, "render: " RENDER_ERR_NO_SCREEN "%s (SDL's video driver '%s' has no screen)", d,
                         drv);
            }
            return false;
        }
    }
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 24);
    // Multisampling is done in our own FBO, so the window needs none.
    SDL_GL_SetAttribute(SDL_GL_MULTISAMPLEBUFFERS, 0);
    SDL_GL_SetAttribute(SDL_GL_MULTISAMPLESAMPLES, 0);

    Uint32 flags = SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI;
    if (r->cfg.offscreen) flags |= SDL_WINDOW_HIDDEN;
    r->win = SDL_CreateWindow(r->title, SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED,
                              r->cfg.width, r->cfg.height, flags);
    if (!r->win) {
        set_err(err, errsz, "SDL_CreateWindow");
        return false;
    }
    r->gl = SDL_GL_CreateContext(r->win);
    if (!r->gl) {
        set_err(err, errsz, "OpenGL 3.3 core context");
        return false;
    }
    SDL_GL_MakeCurrent(r->win, r->gl);
    if (!r->cfg.offscreen) SDL_GL_SetSwapInterval(r->cfg.vsync ? 1 : 0);

    if (r->cfg.offscreen) {
        r->w = r->cfg.width;
        r->h = r->cfg.height;
    } else {
        SDL_GL_GetDrawableSize(r->win, &r->w, &r->h);
    }
    return render_targets_resize(r, r->w, r->h);
}

static void free_targets(render* r) {
    GLuint fb[2] = {r->fbo, r->msfbo};
    GLuint rb[4] = {r->fbo_color, r->fbo_depth, r->ms_color, r->ms_depth};
    glDeleteFramebuffers(2, fb);
    glDeleteRenderbuffers(4, rb);
    r->fbo = r->msfbo = r->fbo_color = r->fbo_depth = r->ms_color = r->ms_depth = 0;
}

static GLuint make_fbo(int w, int h, int samples, GLuint* color, GLuint* depth) {
    GLuint fbo;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(1, color);
    glBindRenderbuffer(GL_RENDERBUFFER, *color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, *color);
    glGenRenderbuffers(1, depth);
    glBindRenderbuffer(GL_RENDERBUFFER, *depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, *depth);
    GLenum st = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "render: framebuffer %dx%d (%d samples) incomplete: 0x%x\n", w, h, samples,
                st);
        glDeleteFramebuffers(1, &fbo);
        return 0;
    }
    return fbo;
}

bool render_targets_resize(render* r, int w, int h) {
    if (w < 1) w = 1;
    if (h < 1) h = 1;
    free_targets(r);
    r->w = w;
    r->h = h;
    // Every frame lands in our own single-sample FBO, in a window too: it
    // survives the swap, so a screenshot can be taken at any time, and its
    // size does not depend on what the offscreen driver gives the window.
    r->fbo = make_fbo(w, h, 0, &r->fbo_color, &r->fbo_depth);
    if (!r->fbo) return false;
    if (r->cfg.msaa > 1) {
        r->msfbo = make_fbo(w, h, r->cfg.msaa, &r->ms_color, &r->ms_depth);
        // Multisampling is a nicety: without it we still draw.
        if (!r->msfbo) r->cfg.msaa = 0;
    }
    return true;
}

void render_gl_close(render* r) {
    if (r->gl) {
        free_targets(r);
        SDL_GL_DeleteContext(r->gl);
        r->gl = NULL;
    }
    if (r->win) SDL_DestroyWindow(r->win);
    r->win = NULL;
    if (r->own_video) SDL_QuitSubSystem(SDL_INIT_VIDEO);
    r->own_video = false;
}

GLuint render_target_fbo(const render* r) {
    if (r->msfbo) return r->msfbo;
    return r->fbo;
}

void render_resolve(render* r) {
    if (!r->msfbo) return;
    // Multisample resolve into the readable single-sample FBO.
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->msfbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, r->fbo);
    glBlitFramebuffer(0, 0, r->w, r->h, 0, 0, r->w, r->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
}

void render_blit_to_window(render* r) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, r->w, r->h, 0, 0, r->w, r->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo);
}
