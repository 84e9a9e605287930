// mesh.c: GPU meshes: upload, built-in unit primitives, and files loaded
// through assimp (OBJ, STL, glTF, Collada, FBX, ...), cached by file name.
//
// Every mesh is uploaded once into its own VAO/VBO/IBO and never touched
// again per frame; the per-body pose goes in as a uniform.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "render_internal.h"

render_mesh render_mesh_upload(const render_vertex* v, int nv, const unsigned* idx, int ni) {
    render_mesh m;
    memset(&m, 0, sizeof m);
    glGenVertexArrays(1, &m.vao);
    glBindVertexArray(m.vao);
    glGenBuffers(1, &m.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * sizeof *v), v, GL_STATIC_DRAW);
    glGenBuffers(1, &m.ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(ni * sizeof *idx), idx, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof *v, (void*)offsetof(render_vertex, p));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof *v, (void*)offsetof(render_vertex, n));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, sizeof *v, (void*)offsetof(render_vertex, c));
    glBindVertexArray(0);
    m.nidx = ni;
    // Back-face culling halves the triangles llvmpipe rasterises, but is
    // only safe when the winding is consistent: CAD exports often mix it.
    // Cull a mesh only if no triangle's winding disagrees with its normals.
    int agree = 0, disagree = 0;
    for (int t = 0; t + 2 < ni; t += 3) {
        const render_vertex *a = &v[idx[t]], *b = &v[idx[t + 1]], *c = &v[idx[t + 2]];
        rm_vec3 g = rm_cross(rm_v3(b->p[0] - a->p[0], b->p[1] - a->p[1], b->p[2] - a->p[2]),
                             rm_v3(c->p[0] - a->p[0], c->p[1] - a->p[1], c->p[2] - a->p[2]));
        if (rm_dot(g, g) < 1e-20f) continue;
        rm_vec3 ns = rm_v3(a->n[0] + b->n[0] + c->n[0], a->n[1] + b->n[1] + c->n[1], a->n[2] + b->n[2] + c->n[2]);
        float d = rm_dot(g, ns);
        agree += d > 0;
        disagree += d < 0;
    }
    m.cull = agree > 0 && disagree == 0;
    for (int k = 0; k < 3; ++k) {
        m.bmin[k] = nv ? 1e30f : 0;
        m.bmax[k] = nv ? -1e30f : 0;
    }
    for (int i = 0; i < nv; ++i)
        for (int k = 0; k < 3; ++k) {
            if (v[i].p[k] < m.bmin[k]) m.bmin[k] = v[i].p[k];
            if (v[i].p[k] > m.bmax[k]) m.bmax[k] = v[i].p[k];
        }
    return m;
}

void render_mesh_free(render_mesh* m) {
    if (m->vao) glDeleteVertexArrays(1, &m->vao);
    if (m->vbo) glDeleteBuffers(1, &m->vbo);
    if (m->ibo) glDeleteBuffers(1, &m->ibo);
    memset(m, 0, sizeof *m);
}

void render_mesh_draw(const render_mesh* m) {
    glBindVertexArray(m->vao);
    glDrawElements(GL_TRIANGLES, m->nidx, GL_UNSIGNED_INT, 0);
}

// ---- primitives ------------------------------------------------------------

/// Growable vertex/index arrays used while building a primitive.
typedef struct builder {
    render_vertex* v;
    unsigned* i;
    int nv, ni, capv, capi;
} builder;

static int b_vert(builder* b, float px, float py, float pz, float nx, float ny, float nz) {
    if (b->nv == b->capv) {
        b->capv = b->capv ? 2 * b->capv : 256;
        b->v = realloc(b->v, (size_t)b->capv * sizeof *b->v);
    }
    render_vertex* v = &b->v[b->nv];
    v->p[0] = px, v->p[1] = py, v->p[2] = pz;
    v->n[0] = nx, v->n[1] = ny, v->n[2] = nz;
    v->c[0] = v->c[1] = v->c[2] = 1.0f;
    return b->nv++;
}

static void b_tri(builder* b, int a, int c, int d) {
    if (b->ni + 3 > b->capi) {
        b->capi = b->capi ? 2 * b->capi : 768;
        b->i = realloc(b->i, (size_t)b->capi * sizeof *b->i);
    }
    b->i[b->ni++] = (unsigned)a;
    b->i[b->ni++] = (unsigned)c;
    b->i[b->ni++] = (unsigned)d;
}

static render_mesh b_finish(builder* b) {
    render_mesh m = render_mesh_upload(b->v, b->nv, b->i, b->ni);
    free(b->v);
    free(b->i);
    memset(b, 0, sizeof *b);
    return m;
}

static void build_box(builder* b) {
    // Six faces with their own vertices so edges stay sharp.
    static const float n[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    for (int f = 0; f < 6; ++f) {
        float nx = n[f][0], ny = n[f][1], nz = n[f][2];
        // Two tangents spanning the face, with t1 x t2 = n for CCW winding.
        float t1[3] = {ny != 0 || nz != 0 ? 1.0f : 0.0f, nx != 0 ? 1.0f : 0.0f, 0};
        if (nz != 0) t1[0] = 1, t1[1] = 0;
        float t2[3] = {ny * t1[2] - nz * t1[1], nz * t1[0] - nx * t1[2], nx * t1[1] - ny * t1[0]};
        int base = b->nv;
        for (int k = 0; k < 4; ++k) {
            float s = (k == 1 || k == 2) ? 0.5f : -0.5f, t = (k >= 2) ? 0.5f : -0.5f;
            b_vert(b, 0.5f * nx + s * t1[0] + t * t2[0], 0.5f * ny + s * t1[1] + t * t2[1],
                   0.5f * nz + s * t1[2] + t * t2[2], nx, ny, nz);
        }
        b_tri(b, base, base + 1, base + 2);
        b_tri(b, base, base + 2, base + 3);
    }
}

/// Cylinder of radius 1 between a0 and a1 along axis `ax` (0 = x, 2 = z), capped.
static void build_cyl(builder* b, int ax, float a0, float a1, int seg) {
    for (int end = 0; end < 2; ++end) {
        float a = end ? a1 : a0, sgn = end ? 1.0f : -1.0f;
        int c = ax == 2 ? b_vert(b, 0, 0, a, 0, 0, sgn) : b_vert(b, a, 0, 0, sgn, 0, 0);
        int first = b->nv;
        for (int k = 0; k < seg; ++k) {
            float th = 2.0f * (float)M_PI * (float)k / (float)seg, u = cosf(th), w = sinf(th);
            if (ax == 2)
                b_vert(b, u, w, a, 0, 0, sgn);
            else
                b_vert(b, a, u, w, sgn, 0, 0);
        }
        for (int k = 0; k < seg; ++k) {
            int p = first + k, q = first + (k + 1) % seg;
            // The +end cap faces along +axis: CCW seen from outside.
            if (end)
                b_tri(b, c, p, q);
            else
                b_tri(b, c, q, p);
        }
    }
    int first = b->nv;
    for (int k = 0; k <= seg; ++k) {
        float th = 2.0f * (float)M_PI * (float)k / (float)seg, u = cosf(th), w = sinf(th);
        if (ax == 2) {
            b_vert(b, u, w, a0, u, w, 0);
            b_vert(b, u, w, a1, u, w, 0);
        } else {
            b_vert(b, a0, u, w, 0, u, w);
            b_vert(b, a1, u, w, 0, u, w);
        }
    }
    for (int k = 0; k < seg; ++k) {
        int p0 = first + 2 * k, p1 = p0 + 1, q0 = p0 + 2, q1 = p0 + 3;
        b_tri(b, p0, q0, q1);
        b_tri(b, p0, q1, p1);
    }
}

/// UV sphere of radius 1; hemisphere keeps only z >= 0.
static void build_sphere(builder* b, bool half, int rings, int seg) {
    int r0 = half ? rings / 2 : 0;
    int first = b->nv;
    for (int i = r0; i <= rings; ++i) {
        float ph = (float)M_PI * (1.0f - (float)i / (float)rings) - (float)M_PI_2; // -pi/2..pi/2
        for (int k = 0; k <= seg; ++k) {
            float th = 2.0f * (float)M_PI * (float)k / (float)seg;
            float x = cosf(ph) * cosf(th), y = cosf(ph) * sinf(th), z = -sinf(ph);
            b_vert(b, x, y, z, x, y, z);
        }
    }
    int nr = rings - r0;
    for (int i = 0; i < nr; ++i)
        for (int k = 0; k < seg; ++k) {
            int p0 = first + i * (seg + 1) + k, p1 = p0 + seg + 1;
            b_tri(b, p0, p0 + 1, p1 + 1);
            b_tri(b, p0, p1 + 1, p1);
        }
}

void render_prims_create(render_mesh prims[RENDER_PRIM_COUNT]) {
    builder b;
    memset(&b, 0, sizeof b);
    build_box(&b);
    prims[RENDER_PRIM_BOX] = b_finish(&b);
    build_cyl(&b, 2, -0.5f, 0.5f, 32);
    prims[RENDER_PRIM_CYLINDER] = b_finish(&b);
    build_sphere(&b, false, 16, 32);
    prims[RENDER_PRIM_SPHERE] = b_finish(&b);
    build_sphere(&b, true, 16, 32);
    prims[RENDER_PRIM_HEMISPHERE] = b_finish(&b);
    build_cyl(&b, 0, 0.0f, 1.0f, 24);
    prims[RENDER_PRIM_TUBE_X] = b_finish(&b);
}

// ---- files through assimp --------------------------------------------------

static bool has_supported_ext(const char* path) {
    const char* dot = strrchr(path, '.');
    if (!dot) return false;
    // aiGetExtensionList is broken in assimp 5.2; ask about this one extension.
    return aiIsExtensionSupported(dot) == AI_TRUE;
}

static void put_vertex(builder* b, int up, struct aiVector3D p, struct aiVector3D n,
                       const float tint[3]) {
    int vi;
    // y-up files: mesh y becomes body z, mesh z becomes body -y.
    if (up == 1)
        vi = b_vert(b, p.x, -p.z, p.y, n.x, -n.z, n.y);
    else
        vi = b_vert(b, p.x, p.y, p.z, n.x, n.y, n.z);
    memcpy(b->v[vi].c, tint, 3 * sizeof(float));
}

static bool bad_normal(struct aiVector3D n) {
    float l2 = n.x * n.x + n.y * n.y + n.z * n.z;
    return !(l2 > 1e-12f) || !isfinite(l2);
}

/// Append all triangle meshes of an assimp scene (already pre-transformed).
/// Meshes whose normals are missing or zero (STL exporters often write
/// "facet normal 0 0 0") get flat normals from their triangles instead.
static bool convert_scene(const struct aiScene* sc, int up, builder* b) {
    for (unsigned mi = 0; mi < sc->mNumMeshes; ++mi) {
        const struct aiMesh* m = sc->mMeshes[mi];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        struct aiColor4D kd = {1, 1, 1, 1};
        if (m->mMaterialIndex < sc->mNumMaterials)
            aiGetMaterialColor(sc->mMaterials[m->mMaterialIndex], AI_MATKEY_COLOR_DIFFUSE, &kd);
        bool flat = !m->mNormals;
        for (unsigned i = 0; !flat && i < m->mNumVertices; ++i)
            flat = bad_normal(m->mNormals[i]);
        int base = b->nv;
        if (!flat) {
            for (unsigned i = 0; i < m->mNumVertices; ++i) {
                float tint[3] = {kd.r, kd.g, kd.b};
                if (m->mColors[0])
                    tint[0] *= m->mColors[0][i].r, tint[1] *= m->mColors[0][i].g,
                        tint[2] *= m->mColors[0][i].b;
                put_vertex(b, up, m->mVertices[i], m->mNormals[i], tint);
            }
        }
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            const struct aiFace* face = &m->mFaces[f];
            if (face->mNumIndices != 3) continue;
            const unsigned* ix = face->mIndices;
            if (!flat) {
                b_tri(b, base + (int)ix[0], base + (int)ix[1], base + (int)ix[2]);
                continue;
            }
            struct aiVector3D p0 = m->mVertices[ix[0]], p1 = m->mVertices[ix[1]],
                              p2 = m->mVertices[ix[2]];
            rm_vec3 e1 = rm_v3(p1.x - p0.x, p1.y - p0.y, p1.z - p0.z),
                    e2 = rm_v3(p2.x - p0.x, p2.y - p0.y, p2.z - p0.z);
            rm_vec3 fn = rm_norm(rm_cross(e1, e2));
            struct aiVector3D n = {fn.x, fn.y, fn.z};
            float tint[3] = {kd.r, kd.g, kd.b};
            int v0 = b->nv;
            for (int k = 0; k < 3; ++k)
                put_vertex(b, up, m->mVertices[ix[k]], n, tint);
            b_tri(b, v0, v0 + 1, v0 + 2);
        }
    }
    return b->ni > 0;
}

static bool load_file(const char* path, int up, render_mesh* out, char* why, size_t whysz) {
    if (!has_supported_ext(path)) {
        snprintf(why, whysz, "format not supported by assimp");
        return false;
    }
    FILE* f = fopen(path, "rb");
    if (!f) {
        snprintf(why, whysz, "cannot open file");
        return false;
    }
    fclose(f);
    struct aiPropertyStore* props = aiCreatePropertyStore();
    // Files without normals get smooth normals only across gentle bends, so
    // box sections keep their sharp edges.
    aiSetImportPropertyFloat(props, AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 40.0f);
    unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                     aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                     aiProcess_SortByPType;
    const struct aiScene* sc = aiImportFileExWithProperties(path, flags, NULL, props);
    aiReleasePropertyStore(props);
    if (!sc) {
        snprintf(why, whysz, "%s", aiGetErrorString());
        return false;
    }
    builder b;
    memset(&b, 0, sizeof b);
    bool ok = convert_scene(sc, up, &b);
    aiReleaseImport(sc);
    if (!ok) {
        free(b.v);
        free(b.i);
        snprintf(why, whysz, "no triangles");
        return false;
    }
    *out = b_finish(&b);
    return true;
}

const render_mesh* render_mesh_get(render_mesh_cache* c, const char* file, int up) {
    if (!file || !file[0]) return NULL;
    if (up != 1) up = 2;
    char key[sizeof c->e[0]->key];
    snprintf(key, sizeof key, "%d:%s", up, file);
    for (int i = 0; i < c->n; ++i)
        if (strcmp(c->e[i]->key, key) == 0) return c->e[i]->ok ? &c->e[i]->mesh : NULL;

    if (c->n == c->cap) {
        const int cap = c->cap ? 2 * c->cap : 32;
        render_mesh_entry** ne = realloc(c->e, (size_t)cap * sizeof *ne);
        if (!ne) return NULL; // out of memory: the primitive is drawn
        c->e = ne;
        c->cap = cap;
    }
    render_mesh_entry* e = calloc(1, sizeof *e);
    if (!e) return NULL;
    c->e[c->n++] = e;
    snprintf(e->key, sizeof e->key, "%s", key);
    char path[1024];
    if (file[0] == '/' || !c->dir[0])
        snprintf(path, sizeof path, "%s", file);
    else
        snprintf(path, sizeof path, "%s/%s", c->dir, file);
    char why[256] = "";
    e->ok = load_file(path, up, &e->mesh, why, sizeof why);
    if (!e->ok) {
        ++c->warnings;
        fprintf(stderr, "render: warning: mesh %s: %s; drawing its primitive shape instead\n", path,
                why);
        return NULL;
    }
    return &e->mesh;
}

void render_mesh_cache_free(render_mesh_cache* c) {
    for (int i = 0; i < c->n; ++i) {
        if (c->e[i]->ok) render_mesh_free(&c->e[i]->mesh);
        free(c->e[i]);
    }
    free(c->e);
    c->e = NULL;
    c->n = c->cap = 0;
}
