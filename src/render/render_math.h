// render_math.h: the few 4x4 / 3-vector operations the renderer needs.
//
// Matrices are column-major float[16] (OpenGL's layout), so they go to
// glUniformMatrix4fv without transposing. Private to src/render.
#ifndef RENDER_MATH_H
#define RENDER_MATH_H

#include <math.h>
#include <string.h>

// Strict C11 (no extensions) does not define M_PI in <math.h>.
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#ifndef M_PI_2
#define M_PI_2 1.57079632679489661923
#endif

typedef struct rm_vec3 {
    float x, y, z;
} rm_vec3;

static inline rm_vec3 rm_v3(float x, float y, float z) {
    rm_vec3 v = {x, y, z};
    return v;
}
static inline rm_vec3 rm_add(rm_vec3 a, rm_vec3 b) {
    return rm_v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline rm_vec3 rm_sub(rm_vec3 a, rm_vec3 b) {
    return rm_v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline rm_vec3 rm_scale(rm_vec3 a, float s) {
    return rm_v3(a.x * s, a.y * s, a.z * s);
}
static inline float rm_dot(rm_vec3 a, rm_vec3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline rm_vec3 rm_cross(rm_vec3 a, rm_vec3 b) {
    return rm_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float rm_len(rm_vec3 a) {
    return sqrtf(rm_dot(a, a));
}
static inline rm_vec3 rm_norm(rm_vec3 a) {
    float l = rm_len(a);
    return l > 1e-12f ? rm_scale(a, 1.0f / l) : rm_v3(0, 0, 1);
}

static inline void rm_identity(float m[16]) {
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1.0f;
}

/// out = a * b (applies b first). out may alias neither a nor b.
static inline void rm_mul(float out[16], const float a[16], const float b[16]) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            float s = 0;
            for (int k = 0; k < 4; ++k)
                s += a[k * 4 + r] * b[c * 4 + k];
            out[c * 4 + r] = s;
        }
}

/// Transform a point (w = 1) and return clip coordinates in out[4].
static inline void rm_xform4(float out[4], const float m[16], float x, float y, float z) {
    for (int r = 0; r < 4; ++r)
        out[r] = m[r] * x + m[4 + r] * y + m[8 + r] * z + m[12 + r];
}

/// Right-handed look-at view matrix (camera looks down its -z).
static inline void rm_look_at(float m[16], rm_vec3 eye, rm_vec3 at, rm_vec3 up) {
    rm_vec3 f = rm_norm(rm_sub(at, eye));
    rm_vec3 s = rm_cross(f, up);
    // Looking straight along up would give a zero side vector: pick any side.
    if (rm_len(s) < 1e-6f) s = rm_cross(f, rm_v3(1, 0, 0));
    s = rm_norm(s);
    rm_vec3 u = rm_cross(s, f);
    rm_identity(m);
    m[0] = s.x, m[4] = s.y, m[8] = s.z;
    m[1] = u.x, m[5] = u.y, m[9] = u.z;
    m[2] = -f.x, m[6] = -f.y, m[10] = -f.z;
    m[12] = -rm_dot(s, eye);
    m[13] = -rm_dot(u, eye);
    m[14] = rm_dot(f, eye);
}

static inline void rm_perspective(float m[16], float fovy_rad, float aspect, float zn, float zf) {
    float f = 1.0f / tanf(0.5f * fovy_rad);
    memset(m, 0, 16 * sizeof(float));
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (zf + zn) / (zn - zf);
    m[11] = -1.0f;
    m[14] = 2.0f * zf * zn / (zn - zf);
}

static inline void rm_ortho(float m[16], float l, float r, float b, float t, float n, float f) {
    rm_identity(m);
    m[0] = 2.0f / (r - l);
    m[5] = 2.0f / (t - b);
    m[10] = -2.0f / (f - n);
    m[12] = -(r + l) / (r - l);
    m[13] = -(t + b) / (t - b);
    m[14] = -(f + n) / (f - n);
}

/// Model matrix from a row-major 3x3 rotation (as in world_snapshot), a
/// per-axis scale applied first, and a translation.
static inline void rm_model(float m[16], const double rot[9], const float scale[3],
                            const double pos[3]) {
    rm_identity(m);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            m[c * 4 + r] = (float)rot[r * 3 + c] * scale[c];
    m[12] = (float)pos[0];
    m[13] = (float)pos[1];
    m[14] = (float)pos[2];
}

/// Normal matrix (inverse transpose of the upper 3x3), column-major 3x3.
/// Needed because booms and cylinders are drawn with non-uniform scale.
static inline void rm_normal_matrix(float n[9], const float m[16]) {
    float a = m[0], b = m[4], c = m[8];
    float d = m[1], e = m[5], f = m[9];
    float g = m[2], h = m[6], i = m[10];
    float A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    float D = -(b * i - c * h), E = a * i - c * g, F = -(a * h - b * g);
    float G = b * f - c * e, H = -(a * f - c * d), I = a * e - b * d;
    float det = a * A + b * B + c * C;
    float s = fabsf(det) > 1e-20f ? 1.0f / det : 0.0f;
    // inverse = adj^T / det; its transpose = cofactor matrix / det.
    // Column-major: n[col*3+row] = cof(row, col).
    n[0] = A * s, n[1] = D * s, n[2] = G * s;
    n[3] = B * s, n[4] = E * s, n[5] = H * s;
    n[6] = C * s, n[7] = F * s, n[8] = I * s;
}

#endif
