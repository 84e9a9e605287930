// shadow.c: one directional light with a depth shadow map.
//
// The sun is fixed in the world (high, from the front left), so shadows fall
// on the ground and tell the operator how high the hook is. The light's
// orthographic box is refitted each frame around the crane's bounding
// sphere, so the texels are spent where the machine is, not on the horizon.
#include <stdio.h>

#include "render_internal.h"

bool render_shadow_create(render_shadow* s, int size) {
    s->size = size;
    glGenTextures(1, &s->tex);
    glBindTexture(GL_TEXTURE_2D, s->tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT,
                 GL_FLOAT, NULL);
    // Hardware depth comparison + linear filter gives 2x2 PCF for free.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    // Outside the map counts as lit.
    const float border[4] = {1, 1, 1, 1};
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &s->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, s->tex, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    GLenum st = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "render: shadow map %d^2 incomplete: 0x%x\n", size, st);
        return false;
    }
    // Sun: azimuth ~ 35 deg left of forward, elevation ~ 55 deg.
    s->light_dir = rm_norm(rm_v3(0.45f, 0.35f, 0.82f));
    rm_identity(s->light_vp);
    return true;
}

void render_shadow_free(render_shadow* s) {
    if (s->fbo) glDeleteFramebuffers(1, &s->fbo);
    if (s->tex) glDeleteTextures(1, &s->tex);
    s->fbo = s->tex = 0;
}

void render_shadow_fit(render_shadow* s, rm_vec3 centre, float radius) {
    float view[16], proj[16];
    // A fixed light view through the world origin; only the ortho box moves.
    // Snapping the box to whole texels in that fixed frame keeps shadow edges
    // from crawling while the crane (and so the fitted box) moves.
    rm_look_at(view, s->light_dir, rm_v3(0, 0, 0), rm_v3(0, 0, 1));
    float c4[4];
    rm_xform4(c4, view, centre.x, centre.y, centre.z);
    float texel = 2.0f * radius / (float)s->size;
    float cx = texel * floorf(c4[0] / texel), cy = texel * floorf(c4[1] / texel);
    // View-space z is negative in front; keep everything within 3 radii.
    float zn = -c4[2] - 3.0f * radius, zf = -c4[2] + 3.0f * radius;
    rm_ortho(proj, cx - radius, cx + radius, cy - radius, cy + radius, zn, zf);
    rm_mul(s->light_vp, proj, view);
}
