// mesh_io.c: reading OBJ and STL meshes into mesh_tri (the physics core's
// own readers), the importer hook for other formats, welding and cleaning.
#include "mesh_geom.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static mesh_import_fn g_importer;

void mesh_set_importer(mesh_import_fn fn) { g_importer = fn; }

static mesh_cancel_fn g_cancel;
void mesh_set_cancel(mesh_cancel_fn fn) { g_cancel = fn; }
int mesh_cancelled(void) { return g_cancel && g_cancel(); }

void mesh_free(mesh_tri* m) {
    if (!m) return;
    free(m->v);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

// Growable arrays.
static int grow(void** p, int* cap, int need, size_t elem) {
    if (need <= *cap) return 0;
    int c = *cap ? *cap : 64;
    while (c < need) {
        if (c > (1 << 28)) return -1;
        c *= 2;
    }
    void* q = realloc(*p, (size_t)c * elem);
    if (!q) return -1;
    *p = q;
    *cap = c;
    return 0;
}

// More vertices than 3 per allowed triangle cannot be a mesh within the
// limit; stop there so a huge file is refused without reading it into memory.
#define MESH_MAX_VERTICES (3 * MESH_MAX_TRIANGLES + 3)

static int add_vertex(mesh_tri* m, int* cap, float x, float y, float z) {
    if (m->nv >= MESH_MAX_VERTICES) return -2;
    if (grow((void**)&m->v, cap, 3 * (m->nv + 1), sizeof(float))) return -1;
    m->v[3 * m->nv] = x, m->v[3 * m->nv + 1] = y, m->v[3 * m->nv + 2] = z;
    return m->nv++;
}

static int add_tri(mesh_tri* m, int* cap, int a, int b, int c) {
    // One over the limit is enough to refuse the file; stop reading there.
    if (m->nt > MESH_MAX_TRIANGLES) return 0;
    if (grow((void**)&m->idx, cap, 3 * (m->nt + 1), sizeof(int))) return -1;
    m->idx[3 * m->nt] = a, m->idx[3 * m->nt + 1] = b, m->idx[3 * m->nt + 2] = c;
    ++m->nt;
    return 0;
}

// OBJ: "v x y z" and "f a b c ..." (a = v, v/vt, v//vn or v/vt/vn; negative
// indices count back from the last vertex); polygons become fans. Everything
// else (normals, texture coordinates, groups, materials) is not needed for
// collision and is skipped.
static int read_obj(FILE* f, mesh_tri* m, char* err, size_t errsz) {
    char line[4096];
    int vcap = 0, tcap = 0, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        if (++lineno % 4096 == 0 && mesh_cancelled()) goto cancelled;
        char* s = line;
        while (*s == ' ' || *s == '\t') ++s;
        if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
            double x, y, z;
            if (sscanf(s + 2, "%lf %lf %lf", &x, &y, &z) != 3) {
                snprintf(err, errsz, "line %d: a vertex needs three numbers", lineno);
                return -1;
            }
            if (!isfinite(x) || !isfinite(y) || !isfinite(z) || fabs(x) > 1e30 || fabs(y) > 1e30 || fabs(z) > 1e30) {
                snprintf(err, errsz, "line %d: vertex coordinates must be finite", lineno);
                return -1;
            }
            const int r = add_vertex(m, &vcap, (float)x, (float)y, (float)z);
            if (r == -2) goto too_big;
            if (r < 0) goto oom;
        } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t')) {
            int ids[2], k = 0;
            char* p = s + 2;
            for (;;) {
                while (*p == ' ' || *p == '\t') ++p;
                if (!*p || *p == '\n' || *p == '\r' || *p == '#') break;
                char* end;
                long i = strtol(p, &end, 10);
                if (end == p || i == 0) {
                    snprintf(err, errsz, "line %d: bad face index", lineno);
                    return -1;
                }
                long vi = i > 0 ? i - 1 : m->nv + i;
                if (vi < 0 || vi >= m->nv) {
                    snprintf(err, errsz, "line %d: face index %ld refers to no vertex (%d so far)", lineno, i, m->nv);
                    return -1;
                }
                while (*end && *end != ' ' && *end != '\t' && *end != '\n' && *end != '\r') ++end;
                p = end;
                // Fan: (first, previous, this) for every index after the second.
                if (k < 2) ids[k++] = (int)vi;
                else {
                    if (add_tri(m, &tcap, ids[0], ids[1], (int)vi)) goto oom;
                    ids[1] = (int)vi;
                }
            }
        }
    }
    return 0;
cancelled:
    snprintf(err, errsz, "interrupted");
    return -1;
too_big:
    snprintf(err, errsz, "more than %d vertices (the limit is %d triangles; docs/ode_world.md, \"CAD meshes\")",
             MESH_MAX_VERTICES, MESH_MAX_TRIANGLES);
    return -1;
oom:
    snprintf(err, errsz, "out of memory");
    return -1;
}

static float rd_f32(const unsigned char* p) {
    uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
    float x;
    memcpy(&x, &u, sizeof x);
    return x;
}

// Binary STL: 80-byte header, a little-endian facet count, 50 bytes a facet
// (normal, three corners as float32, a 2-byte attribute). The count and the
// file's size must agree: a file cut short or a count that is wrong would
// otherwise load as a partial mesh (or as none) without a word.
static int read_stl_binary(FILE* f, long long size, mesh_tri* m, char* err, size_t errsz) {
    unsigned char head[84];
    if (size < 84 || fread(head, 1, 84, f) != 84) {
        snprintf(err, errsz, "binary STL: %lld bytes, shorter than its 84-byte header (truncated)", size);
        return -1;
    }
    const uint32_t n =
        (uint32_t)head[80] | (uint32_t)head[81] << 8 | (uint32_t)head[82] << 16 | (uint32_t)head[83] << 24;
    const unsigned long long want = 84ull + 50ull * n;
    const long long whole = (size - 84) / 50, rest = (size - 84) % 50;
    if ((unsigned long long)size < want) {
        snprintf(err, errsz,
                 "binary STL truncated: the header says %u facets (%llu bytes) but the file has %lld bytes "
                 "(%lld whole facets%s)",
                 n, want, size, whole, rest ? " and a part of one" : "");
        return -1;
    }
    if ((unsigned long long)size > want) {
        snprintf(err, errsz,
                 "binary STL: the header says %u facets (%llu bytes) but the file has %lld bytes (%lld more than "
                 "the facets need)",
                 n, want, size, (long long)((unsigned long long)size - want));
        return -1;
    }
    if (n > MESH_MAX_TRIANGLES) {
        snprintf(err, errsz, "more than %d triangles (%u; docs/ode_world.md, \"CAD meshes\")", MESH_MAX_TRIANGLES, n);
        return -1;
    }
    int vcap = 0, tcap = 0;
    unsigned char rec[50];
    for (uint32_t t = 0; t < n; ++t) {
        if (t % 4096 == 4095 && mesh_cancelled()) {
            snprintf(err, errsz, "interrupted");
            return -1;
        }
        if (fread(rec, 1, 50, f) != 50) {
            snprintf(err, errsz, "binary STL: cannot read facet %u of %u (the file changed or is unreadable)", t + 1,
                     n);
            return -1;
        }
        int id[3];
        for (int k = 0; k < 3; ++k) {
            float x = rd_f32(rec + 12 + 12 * k), y = rd_f32(rec + 16 + 12 * k), z = rd_f32(rec + 20 + 12 * k);
            if (!isfinite(x) || !isfinite(y) || !isfinite(z)) {
                snprintf(err, errsz, "facet %u: vertex coordinates must be finite", t + 1);
                return -1;
            }
            if ((id[k] = add_vertex(m, &vcap, x, y, z)) < 0) goto oom;
        }
        if (add_tri(m, &tcap, id[0], id[1], id[2])) goto oom;
    }
    return 0;
oom:
    snprintf(err, errsz, "out of memory");
    return -1;
}

// ASCII STL tokens: whitespace-separated words, with the line each starts on.
typedef struct stl_lex {
    FILE* f;
    int line, c;
    char tok[256];
} stl_lex;

// The next word into lx->tok (cut at 255 bytes); 0 at the end of the file.
static int stl_next(stl_lex* lx) {
    int c = lx->c;
    while (c != EOF && isspace(c)) {
        if (c == '\n') ++lx->line;
        c = getc(lx->f);
    }
    if (c == EOF) {
        lx->c = EOF;
        lx->tok[0] = 0;
        return 0;
    }
    size_t n = 0;
    while (c != EOF && !isspace(c)) {
        if (n + 1 < sizeof lx->tok) lx->tok[n++] = (char)c;
        c = getc(lx->f);
    }
    lx->tok[n] = 0;
    lx->c = c;
    return 1;
}

// The rest of the current line skipped (the solid's name, which may hold spaces).
static void stl_skip_line(stl_lex* lx) {
    int c = lx->c;
    while (c != EOF && c != '\n') c = getc(lx->f);
    lx->c = c;
}

// ASCII STL, the whole grammar: "solid name", then facets ("facet normal
// nx ny nz", "outer loop", three "vertex x y z", "endloop", "endfacet"), then
// "endsolid". Anything else, or the end of the file before "endsolid", is
// refused with the line and the facet: a file cut short must not pass as a
// smaller mesh.
static int read_stl_ascii(FILE* f, mesh_tri* m, char* err, size_t errsz) {
    stl_lex lx = {.f = f, .line = 1, .c = ' '};
    int vcap = 0, tcap = 0, facet = 0;
    if (!stl_next(&lx) || strcasecmp(lx.tok, "solid")) {
        snprintf(err, errsz, "ASCII STL: line %d: expected \"solid\"", lx.line);
        return -1;
    }
    stl_skip_line(&lx);
    const char* want;
    for (;;) {
        if (!stl_next(&lx)) {
            snprintf(err, errsz, "ASCII STL truncated: the file ends at line %d after %d facets without \"endsolid\"",
                     lx.line, facet);
            return -1;
        }
        if (!strcasecmp(lx.tok, "endsolid")) break;
        if (strcasecmp(lx.tok, "facet")) {
            snprintf(err, errsz, "ASCII STL: line %d: expected \"facet\" or \"endsolid\", found \"%s\"", lx.line,
                     lx.tok);
            return -1;
        }
        if (++facet % 1024 == 0 && mesh_cancelled()) {
            snprintf(err, errsz, "interrupted");
            return -1;
        }
        // "normal nx ny nz": the normal is not used (the winding gives it).
        static const char* const seq[] = {"normal", NULL, NULL, NULL, "outer", "loop"};
        for (int i = 0; i < 6; ++i) {
            if (!stl_next(&lx)) goto cut;
            if (seq[i] && strcasecmp(lx.tok, seq[i])) {
                want = seq[i];
                goto bad;
            }
        }
        int id[3];
        for (int k = 0; k < 3; ++k) {
            if (!stl_next(&lx)) goto cut;
            if (strcasecmp(lx.tok, "vertex")) {
                want = "vertex";
                goto bad;
            }
            double x[3];
            for (int j = 0; j < 3; ++j) {
                if (!stl_next(&lx)) goto cut;
                char* end;
                x[j] = strtod(lx.tok, &end);
                if (end == lx.tok || *end || !isfinite(x[j]) || fabs(x[j]) > 1e30) {
                    snprintf(err, errsz, "ASCII STL: line %d (facet %d): a vertex needs three finite numbers, found "
                             "\"%s\"", lx.line, facet, lx.tok);
                    return -1;
                }
            }
            id[k] = add_vertex(m, &vcap, (float)x[0], (float)x[1], (float)x[2]);
            if (id[k] == -2) {
                snprintf(err, errsz, "more than %d triangles (docs/ode_world.md, \"CAD meshes\")", MESH_MAX_TRIANGLES);
                return -1;
            }
            if (id[k] < 0) goto oom;
        }
        static const char* const tail[] = {"endloop", "endfacet"};
        for (int i = 0; i < 2; ++i) {
            if (!stl_next(&lx)) goto cut;
            if (strcasecmp(lx.tok, tail[i])) {
                want = tail[i];
                goto bad;
            }
        }
        if (add_tri(m, &tcap, id[0], id[1], id[2])) goto oom;
    }
    return 0;
cut:
    snprintf(err, errsz, "ASCII STL truncated: the file ends at line %d inside facet %d", lx.line, facet);
    return -1;
bad:
    snprintf(err, errsz, "ASCII STL: line %d (facet %d): expected \"%s\", found \"%s\"", lx.line, facet, want,
             lx.tok);
    return -1;
oom:
    snprintf(err, errsz, "out of memory");
    return -1;
}

// STL, binary or ASCII. A binary file whose size matches its facet count is
// binary whatever its header says (some exporters start binary headers with
// "solid" too); else a file that starts with "solid" and whose first bytes
// are text is ASCII; anything else is binary, and its size is checked
// against its count there.
static int read_stl(FILE* f, long long size, mesh_tri* m, char* err, size_t errsz) {
    unsigned char head[512];
    const size_t got = fread(head, 1, sizeof head, f);
    rewind(f);
    if (got >= 84) {
        const uint32_t n =
            (uint32_t)head[80] | (uint32_t)head[81] << 8 | (uint32_t)head[82] << 16 | (uint32_t)head[83] << 24;
        if ((unsigned long long)size == 84ull + 50ull * n) return read_stl_binary(f, size, m, err, errsz);
    }
    size_t i = 0;
    while (i < got && isspace(head[i])) ++i;
    int text = got - i >= 5 && !strncasecmp((const char*)head + i, "solid", 5);
    for (size_t j = 0; j < got && text; ++j)
        if ((head[j] < 0x20 && !isspace(head[j])) || head[j] == 0x7f) text = 0; // UTF-8 names pass
    if (text) return read_stl_ascii(f, m, err, errsz);
    return read_stl_binary(f, size, m, err, errsz);
}

// Weld vertices with identical coordinates (after conversion), so shared
// edges are shared indices: closedness and hulls need it, and STL stores
// every facet's corners separately. Open addressing on the bit patterns.
static int weld(mesh_tri* m) {
    size_t cap = 16;
    while (cap < 2 * (size_t)m->nv) cap *= 2;
    int* slot = malloc(cap * sizeof *slot);
    int* remap = malloc((size_t)(m->nv ? m->nv : 1) * sizeof *remap);
    if (!slot || !remap) {
        free(slot);
        free(remap);
        return -1;
    }
    for (size_t i = 0; i < cap; ++i) slot[i] = -1;
    int nu = 0;
    for (int i = 0; i < m->nv; ++i) {
        float* p = m->v + 3 * i;
        for (int k = 0; k < 3; ++k)
            if (p[k] == 0.0f) p[k] = 0.0f; // -0 and +0 are one point
        uint32_t b[3];
        memcpy(b, p, sizeof b);
        uint64_t h = (b[0] * 0x9E3779B1u) ^ ((uint64_t)b[1] * 0x85EBCA77u) ^ ((uint64_t)b[2] * 0xC2B2AE3Du << 7);
        size_t s = (size_t)(h ^ (h >> 29)) & (cap - 1);
        for (;;) {
            if (slot[s] < 0) {
                memmove(m->v + 3 * nu, p, 3 * sizeof(float));
                slot[s] = nu;
                remap[i] = nu++;
                break;
            }
            if (!memcmp(m->v + 3 * slot[s], p, 3 * sizeof(float))) {
                remap[i] = slot[s];
                break;
            }
            s = (s + 1) & (cap - 1);
        }
    }
    for (int i = 0; i < 3 * m->nt; ++i) m->idx[i] = remap[m->idx[i]];
    m->nv = nu;
    free(slot);
    free(remap);
    return 0;
}

void mesh_bounds(const mesh_tri* m, double lo[3], double hi[3]) {
    for (int k = 0; k < 3; ++k) lo[k] = m->nv ? INFINITY : 0, hi[k] = m->nv ? -INFINITY : 0;
    for (int i = 0; i < m->nv; ++i)
        for (int k = 0; k < 3; ++k) {
            const double x = m->v[3 * i + k];
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
}

// Drop triangles of (near) zero area: repeated corners, or corners on a line.
// ODE's trimesh colliders divide by a triangle's normal length, so such a
// triangle would give a NaN contact normal. Area below 1e-12 of the mesh's
// size squared counts as zero (float corners of a mesh 100 m across are
// resolved to about 1e-5 m).
static void drop_degenerate(mesh_tri* m) {
    double lo[3], hi[3];
    mesh_bounds(m, lo, hi);
    const double d2 = (hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                      (hi[2] - lo[2]) * (hi[2] - lo[2]);
    int n = 0;
    for (int t = 0; t < m->nt; ++t) {
        const int* ix = m->idx + 3 * t;
        const float *a = m->v + 3 * ix[0], *b = m->v + 3 * ix[1], *c = m->v + 3 * ix[2];
        const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
                     cz = e1[0] * e2[1] - e1[1] * e2[0];
        const double area2 = sqrt(cx * cx + cy * cy + cz * cz);
        if (ix[0] == ix[1] || ix[1] == ix[2] || ix[0] == ix[2] || !(area2 > 2e-12 * d2)) continue;
        memmove(m->idx + 3 * n++, ix, 3 * sizeof(int));
    }
    m->dropped = m->nt - n;
    m->nt = n;
}

// Keep only the vertices some triangle uses, in their order. A vertex no
// triangle names is not part of the surface: it would widen the bounds and
// the convex hull of a loose body (a closed cube with 505 stray vertices had
// a hull of 79,151 faces, item 23 of issue 25) without being in the solid.
static int drop_unused(mesh_tri* m) {
    int* map = malloc((size_t)(m->nv ? m->nv : 1) * sizeof *map);
    if (!map) return -1;
    for (int i = 0; i < m->nv; ++i) map[i] = -1;
    for (int i = 0; i < 3 * m->nt; ++i) map[m->idx[i]] = 0;
    int nu = 0;
    for (int i = 0; i < m->nv; ++i)
        if (map[i] == 0) {
            memmove(m->v + 3 * nu, m->v + 3 * i, 3 * sizeof(float));
            map[i] = nu++;
        }
    for (int i = 0; i < 3 * m->nt; ++i) m->idx[i] = map[m->idx[i]];
    m->nv = nu;
    free(map);
    return 0;
}

static const char* ext_of(const char* path) {
    const char* slash = strrchr(path, '/');
    const char* dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

// A mesh file must be a regular file (a directory, a device such as
// /dev/zero, a pipe or a socket is refused before it is opened: reading one
// may never end) of at most MESH_MAX_FILE_BYTES. Returns 0 with its status
// in st, or -1 with the problem in err.
static int check_file(const char* path, struct stat* st, char* err, size_t errsz) {
    if (stat(path, st)) {
        snprintf(err, errsz, "cannot open the mesh file (%s)", strerror(errno));
        return -1;
    }
    if (S_ISDIR(st->st_mode)) {
        snprintf(err, errsz, "is a directory, not a mesh file");
        return -1;
    }
    if (!S_ISREG(st->st_mode)) {
        snprintf(err, errsz, "is not a regular file (a device, pipe or socket); a mesh must be a file");
        return -1;
    }
    if (st->st_size > MESH_MAX_FILE_BYTES) {
        snprintf(err, errsz, "the file is %.1f MiB, more than the %d MiB a mesh file may have (docs/ode_world.md, "
                 "\"CAD meshes\")", (double)st->st_size / (1 << 20), (int)(MESH_MAX_FILE_BYTES >> 20));
        return -1;
    }
    return 0;
}

static int load_uncached(const char* path, double scale, int up, mesh_tri* out, char* err, size_t errsz) {
    memset(out, 0, sizeof *out);
    const char* ext = ext_of(path);
    const int obj = !strcasecmp(ext, ".obj"), stl = !strcasecmp(ext, ".stl");
    struct stat st;
    if (check_file(path, &st, err, errsz)) return -1;
    FILE* f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errsz, "cannot open the mesh file (%s)", strerror(errno));
        return -1;
    }
    int rc;
    if (obj || stl) {
        rc = obj ? read_obj(f, out, err, errsz) : read_stl(f, (long long)st.st_size, out, err, errsz);
        fclose(f);
    } else {
        fclose(f);
        if (!g_importer) {
            snprintf(err, errsz,
                     "format \"%s\" needs the assimp importer, which this program does not have (OBJ and STL are read "
                     "without it)",
                     ext);
            rc = -1;
        } else {
            rc = g_importer(path, out, err, errsz);
        }
    }
    if (rc == 0 && out->nt > MESH_MAX_TRIANGLES) {
        snprintf(err, errsz, "more than %d triangles (docs/ode_world.md, \"CAD meshes\")", MESH_MAX_TRIANGLES);
        rc = -1;
    }
    if (rc == 0 && out->nt == 0) {
        snprintf(err, errsz, "the mesh has no triangles");
        rc = -1;
    }
    if (rc) {
        mesh_free(out);
        return -1;
    }
    // To the world's z-up metres (the renderer converts the same way).
    for (int i = 0; i < out->nv; ++i) {
        float* p = out->v + 3 * i;
        const double x = p[0], y = p[1], z = p[2];
        if (up == 1) p[0] = (float)(scale * x), p[1] = (float)(-scale * z), p[2] = (float)(scale * y);
        else p[0] = (float)(scale * x), p[1] = (float)(scale * y), p[2] = (float)(scale * z);
    }
    if (weld(out)) {
        mesh_free(out);
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    drop_degenerate(out);
    if (out->nt == 0) {
        snprintf(err, errsz, "all %d triangles are degenerate (zero area)", out->dropped);
        mesh_free(out);
        return -1;
    }
    if (drop_unused(out)) {
        mesh_free(out);
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    return 0;
}

// ---- the per-process cache ----
// One command loads a world file in several steps (validation, the ODE
// world, the renderer's collision view), and each step used to parse the
// same OBJ again (about 0.1 s each for 50,000 triangles). The finished mesh
// (scaled, welded, cleaned) is kept per path, modification time, size, scale
// and up axis, plus a hash of the bytes: file times tick in milliseconds on
// some file systems, so a rewrite of equal size within one tick (tests do
// that) would otherwise look unchanged. Hashing reads the file once more,
// about 1 ms for 3 MB, against about 100 ms for parsing it. Callers get
// their own copy, so they free it as before. A mutex guards the table: sweep
// workers load world files from several threads.
#define MESH_CACHE_SLOTS 8
typedef struct {
    char* path;
    long long mtime_ns, size;
    unsigned long long hash;
    double scale;
    int up;
    unsigned long long used; // for least-recently-used eviction
    mesh_tri m;
    int has_flat;            // flat: m with its flat faces merged (mesh_load_flat)
    mesh_tri flat;
} cache_entry;

static cache_entry g_cache[MESH_CACHE_SLOTS];
static unsigned long long g_cache_clock;
static int g_cache_atexit;
static pthread_mutex_t g_cache_mu = PTHREAD_MUTEX_INITIALIZER;

static void entry_free(cache_entry* e) {
    free(e->path);
    mesh_free(&e->m);
    mesh_free(&e->flat);
    memset(e, 0, sizeof *e);
}

void mesh_cache_clear(void) {
    pthread_mutex_lock(&g_cache_mu);
    for (int i = 0; i < MESH_CACHE_SLOTS; ++i) entry_free(&g_cache[i]);
    pthread_mutex_unlock(&g_cache_mu);
}

static int mesh_copy(const mesh_tri* src, mesh_tri* dst) {
    *dst = *src;
    dst->v = malloc((size_t)3 * (src->nv ? src->nv : 1) * sizeof *dst->v);
    dst->idx = malloc((size_t)3 * (src->nt ? src->nt : 1) * sizeof *dst->idx);
    if (!dst->v || !dst->idx) {
        mesh_free(dst);
        return -1;
    }
    memcpy(dst->v, src->v, (size_t)3 * src->nv * sizeof *dst->v);
    memcpy(dst->idx, src->idx, (size_t)3 * src->nt * sizeof *dst->idx);
    return 0;
}

static unsigned long long g_cache_parses;
unsigned long long mesh_cache_parses(void) {
    pthread_mutex_lock(&g_cache_mu);
    const unsigned long long n = g_cache_parses;
    pthread_mutex_unlock(&g_cache_mu);
    return n;
}

// FNV-1a over the file's bytes, 8 at a time (as 64-bit words) for speed;
// 0 if unreadable or longer than MESH_MAX_FILE_BYTES (then the file is not
// cached; the loader says what is wrong). Called after check_file, but the
// file may have grown since: it reads no more than the limit either way.
static unsigned long long file_hash(const char* path) {
    FILE* f = fopen(path, "rb");
    if (!f) return 0;
    static const unsigned long long prime = 1099511628211ULL;
    unsigned long long h = 14695981039346656037ULL;
    unsigned char buf[65536];
    size_t n;
    long long total = 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        if ((total += (long long)n) > MESH_MAX_FILE_BYTES) {
            fclose(f);
            return 0;
        }
        size_t i = 0;
        for (; i + 8 <= n; i += 8) {
            uint64_t w;
            memcpy(&w, buf + i, 8);
            h = (h ^ w) * prime;
        }
        for (; i < n; ++i) h = (h ^ buf[i]) * prime;
    }
    const int bad = ferror(f);
    fclose(f);
    return bad ? 0 : (h ? h : 1);
}

// The cache key of a file as it is now: 0, or -1 when it is not a regular
// file within the size limit or cannot be read.
typedef struct {
    long long mt, sz;
    unsigned long long hash;
} file_key;
static int key_of(const char* path, file_key* k) {
    struct stat st;
    char why[256];
    k->hash = check_file(path, &st, why, sizeof why) ? 0 : file_hash(path);
    if (!k->hash) return -1;
    k->mt = (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec, k->sz = (long long)st.st_size;
    return 0;
}

// The entry for path at k, scale, up, or NULL; call with the lock held.
static cache_entry* find_entry(const char* path, const file_key* k, double scale, int up) {
    for (int i = 0; i < MESH_CACHE_SLOTS; ++i) {
        cache_entry* e = &g_cache[i];
        if (e->path && !strcmp(e->path, path) && e->mtime_ns == k->mt && e->size == k->sz && e->hash == k->hash &&
            e->scale == scale && e->up == up)
            return e;
    }
    return NULL;
}

int mesh_load_flat(const char* path, double scale, int up, mesh_tri* out, char* err, size_t errsz) {
    // The merge costs about half a parse on the 51,104-triangle wall (0.2 G
    // instructions) and a world is built once per run: a sweep or the bench
    // building it again gets the merged mesh from the cache.
    struct stat st;
    if (check_file(path, &st, err, errsz)) return -1;
    file_key k;
    if (!key_of(path, &k)) {
        pthread_mutex_lock(&g_cache_mu);
        cache_entry* e = find_entry(path, &k, scale, up);
        if (e && e->has_flat) {
            e->used = ++g_cache_clock;
            const int rc = mesh_copy(&e->flat, out);
            pthread_mutex_unlock(&g_cache_mu);
            if (rc) snprintf(err, errsz, "out of memory");
            return rc ? -1 : 0;
        }
        pthread_mutex_unlock(&g_cache_mu);
    }
    if (mesh_load(path, scale, up, out, err, errsz)) return -1;
    mesh_merge_coplanar(out, MESH_FLAT_TOL_RAD, MESH_FLAT_TOL_M); // out of memory: as loaded
    if (key_of(path, &k)) return 0;
    mesh_tri copy;
    if (mesh_copy(out, &copy)) return 0; // not cached; the caller's mesh is fine
    pthread_mutex_lock(&g_cache_mu);
    cache_entry* e = find_entry(path, &k, scale, up);
    if (e && !e->has_flat) {
        e->flat = copy;
        e->has_flat = 1;
    } else mesh_free(&copy);
    pthread_mutex_unlock(&g_cache_mu);
    return 0;
}

int mesh_load(const char* path, double scale, int up, mesh_tri* out, char* err, size_t errsz) {
    struct stat st;
    if (check_file(path, &st, err, errsz)) return -1;
    file_key k;
    if (key_of(path, &k)) return load_uncached(path, scale, up, out, err, errsz); // gives the error
    const long long mt = k.mt, sz = k.sz;
    const unsigned long long hash = k.hash;
    pthread_mutex_lock(&g_cache_mu);
    {
        cache_entry* e = find_entry(path, &k, scale, up);
        if (e) {
            e->used = ++g_cache_clock;
            const int rc = mesh_copy(&e->m, out);
            pthread_mutex_unlock(&g_cache_mu);
            if (rc) snprintf(err, errsz, "out of memory");
            return rc ? -1 : 0;
        }
    }
    ++g_cache_parses;
    pthread_mutex_unlock(&g_cache_mu);
    // Parsed outside the lock: another thread's different file need not wait.
    if (load_uncached(path, scale, up, out, err, errsz)) return -1;
    cache_entry n = {0};
    n.path = malloc(strlen(path) + 1);
    if (!n.path || mesh_copy(out, &n.m)) {
        free(n.path);
        return 0; // not cached; the caller's mesh is fine
    }
    strcpy(n.path, path);
    n.mtime_ns = mt, n.size = sz, n.hash = hash, n.scale = scale, n.up = up;
    pthread_mutex_lock(&g_cache_mu);
    if (!g_cache_atexit) g_cache_atexit = !atexit(mesh_cache_clear);
    int slot = 0;
    for (int i = 0; i < MESH_CACHE_SLOTS; ++i) {
        if (!g_cache[i].path) {
            slot = i;
            break;
        }
        if (g_cache[i].used < g_cache[slot].used) slot = i;
    }
    entry_free(&g_cache[slot]);
    n.used = ++g_cache_clock;
    g_cache[slot] = n;
    pthread_mutex_unlock(&g_cache_mu);
    return 0;
}
