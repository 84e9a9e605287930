// screenshot.c: read the last frame back and write it as PNG (stb from
// Debian's libstb; the implementation lives in the library, not here).
//
// The frame is kept in the renderer's own FBO (also in a window), so this
// works before or after render_present().
#include <stdio.h>
#include <stdlib.h>

#include <stb/stb_image_write.h>

#include "render_internal.h"

int render_read_pixels(render* r, unsigned char* rgba, int w, int h) {
    if (!r || !rgba || w != r->w || h != r->h || !r->have_frame) return -1;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    // GL rows start at the bottom; images start at the top. Flip in place
    // (rather than stb's global flip flag) to keep no global state.
    size_t row = (size_t)w * 4;
    unsigned char* tmp = malloc(row);
    if (!tmp) return -1;
    for (int y = 0; y < h / 2; ++y) {
        unsigned char* a = rgba + (size_t)y * row;
        unsigned char* b = rgba + (size_t)(h - 1 - y) * row;
        memcpy(tmp, a, row);
        memcpy(a, b, row);
        memcpy(b, tmp, row);
    }
    free(tmp);
    return glGetError() == GL_NO_ERROR ? 0 : -1;
}

int render_screenshot(render* r, const char* path) {
    if (!r || !path) return -1;
    unsigned char* px = malloc((size_t)r->w * (size_t)r->h * 4);
    if (!px) return -1;
    int rc = render_read_pixels(r, px, r->w, r->h);
    if (rc == 0) {
        // The alpha channel holds blending leftovers; force opaque.
        for (size_t i = 3; i < (size_t)r->w * (size_t)r->h * 4; i += 4)
            px[i] = 255;
        if (!stbi_write_png(path, r->w, r->h, 4, px, r->w * 4)) rc = -1;
    }
    free(px);
    if (rc != 0) fprintf(stderr, "render: cannot write screenshot %s\n", path);
    return rc;
}
