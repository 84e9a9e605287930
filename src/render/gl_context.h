// gl_context.h: window, GL context and render targets (private).
#ifndef RENDER_GL_CONTEXT_H
#define RENDER_GL_CONTEXT_H

#include "render_internal.h"

/// Open the window (hidden when offscreen) and a GL 3.3 core context.
bool render_gl_open(render* r, char* err, size_t errsz);
void render_gl_close(render* r);
/// The framebuffer the scene draws into this frame (0 = window).
GLuint render_target_fbo(const render* r);
/// Resolve multisampling into the readable framebuffer and bind that.
void render_resolve(render* r);
/// Copy the finished frame to the window's back buffer.
void render_blit_to_window(render* r);

#endif
