// mesh_import.c: the physics core's importer for the formats it does not
// read itself (glTF/GLB, Collada, FBX, ...), through assimp. The application
// installs it with mesh_set_importer (main.c); the core stays free of assimp.
#include "render.h"
#include "world/sandbox/mesh_geom.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int render_mesh_import(const char* path, mesh_tri* out, char* err, size_t errsz) {
    memset(out, 0, sizeof *out);
    const char* dot = strrchr(path, '.');
    // aiGetExtensionList is broken in assimp 5.2; ask about this one extension.
    if (!dot || aiIsExtensionSupported(dot) != AI_TRUE) {
        snprintf(err, errsz, "format \"%s\" is not one assimp reads", dot ? dot : "");
        return -1;
    }
    // Pre-transformed: every node's meshes in the file's frame, as drawn.
    const struct aiScene* sc = aiImportFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                      aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!sc) {
        snprintf(err, errsz, "unreadable mesh (%s)", aiGetErrorString());
        return -1;
    }
    size_t nv = 0, nt = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; ++i) {
        const struct aiMesh* m = sc->mMeshes[i];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        nv += m->mNumVertices;
        nt += m->mNumFaces;
    }
    if (nt > MESH_MAX_TRIANGLES) {
        aiReleaseImport(sc);
        snprintf(err, errsz, "more than %d triangles (%zu; docs/ode_world.md, \"CAD meshes\")", MESH_MAX_TRIANGLES, nt);
        return -1;
    }
    out->v = malloc((nv ? nv : 1) * 3 * sizeof *out->v);
    out->idx = malloc((nt ? nt : 1) * 3 * sizeof *out->idx);
    if (!out->v || !out->idx) {
        aiReleaseImport(sc);
        free(out->v);
        free(out->idx);
        memset(out, 0, sizeof *out);
        snprintf(err, errsz, "out of memory");
        return -1;
    }
    for (unsigned i = 0; i < sc->mNumMeshes; ++i) {
        const struct aiMesh* m = sc->mMeshes[i];
        if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        const int base = out->nv;
        for (unsigned k = 0; k < m->mNumVertices; ++k) {
            out->v[3 * out->nv] = m->mVertices[k].x;
            out->v[3 * out->nv + 1] = m->mVertices[k].y;
            out->v[3 * out->nv + 2] = m->mVertices[k].z;
            ++out->nv;
        }
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            if (m->mFaces[f].mNumIndices != 3) continue;
            for (int k = 0; k < 3; ++k) out->idx[3 * out->nt + k] = base + (int)m->mFaces[f].mIndices[k];
            ++out->nt;
        }
    }
    aiReleaseImport(sc);
    return 0;
}
