// screenshot.c: read the last frame back and write it as PNG (stb from
// Debian's libstb; the implementation lives in the library, not here).
//
// The frame is kept in the renderer's own FBO (also in a window), so this
// works before or after render_present().
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

// stbi_write_png() ignores fwrite's and fclose's results, so a full disk
// would pass for a saved picture: write through a callback that keeps the
// first error instead.
typedef struct png_sink {
    FILE* f;
    int err; ///< errno of the first failed write, 0 if none
} png_sink;

static void png_write(void* ctx, void* data, int size) {
    png_sink* k = ctx;
    if (k->err || size <= 0) return;
    if (fwrite(data, 1, (size_t)size, k->f) != (size_t)size) k->err = errno ? errno : EIO;
}

int render_save_png(render* r, const char* path, char* err, size_t errsz) {
    if (!r || !path) return -1;
    unsigned char* px = malloc((size_t)r->w * (size_t)r->h * 4);
    if (!px || render_read_pixels(r, px, r->w, r->h) != 0) {
        free(px);
        if (err && errsz) snprintf(err, errsz, "cannot write %s: no frame to save", path);
        return -1;
    }
    // The alpha channel holds blending leftovers; force opaque.
    for (size_t i = 3; i < (size_t)r->w * (size_t)r->h * 4; i += 4)
        px[i] = 255;
    png_sink k = {fopen(path, "wb"), 0};
    int rc = 0;
    if (!k.f) {
        k.err = errno;
        rc = -1;
    } else {
        errno = 0;
        // Whatever was written stays: a partial file says more than none.
        if (!stbi_write_png_to_func(png_write, &k, r->w, r->h, 4, px, r->w * 4) && !k.err) k.err = ENOMEM;
        if (fflush(k.f) != 0 && !k.err) k.err = errno;
        if (fclose(k.f) != 0 && !k.err) k.err = errno;
        if (k.err) rc = -1;
    }
    free(px);
    if (rc && err && errsz) snprintf(err, errsz, "cannot write %s: %s", path, strerror(k.err ? k.err : EIO));
    return rc;
}

int render_screenshot(render* r, const char* path) {
    char err[512];
    int rc = render_save_png(r, path, err, sizeof err);
    if (rc) fprintf(stderr, "render: %s\n", err);
    return rc;
}
