/*
 * vdsh_gltf_component.h - internal (not installed): the size of a glTF
 * accessor component type, and one component read as a double, for the baker's glTF reader
 * (bake/lib/mesh_gltf.cpp) and vdsh-export's source reader
 * (tools/vdsh_export_source.c), which each had a copy. Static inline; C
 * and C++.
 */
#ifndef VDSH_GLTF_COMPONENT_H
#define VDSH_GLTF_COMPONENT_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* glTF componentType values (glTF 2.0, 3.6.2.2). */
enum {
    VDSH_GLTF_BYTE = 5120,
    VDSH_GLTF_UNSIGNED_BYTE = 5121,
    VDSH_GLTF_SHORT = 5122,
    VDSH_GLTF_UNSIGNED_SHORT = 5123,
    VDSH_GLTF_UNSIGNED_INT = 5125,
    VDSH_GLTF_FLOAT = 5126
};

/* The size of a component of type t in bytes, 0 for an unknown type. */
static inline size_t vdsh_gltf_component_size(int t)
{
    switch (t) {
    case VDSH_GLTF_BYTE:
    case VDSH_GLTF_UNSIGNED_BYTE: return 1;
    case VDSH_GLTF_SHORT:
    case VDSH_GLTF_UNSIGNED_SHORT: return 2;
    case VDSH_GLTF_UNSIGNED_INT:
    case VDSH_GLTF_FLOAT: return 4;
    default: return 0;
    }
}

/* The component of type t at p (unaligned, little-endian host), scaled
 * to [-1, 1] or [0, 1] when normalized (signed: the glTF rule, max(c /
 * MAX, -1)); an unknown type reads as a float. */
static inline double vdsh_gltf_component(const uint8_t *p, int t, int normalized)
{
    switch (t) {
    case VDSH_GLTF_BYTE: {
        int8_t v;
        memcpy(&v, p, 1);
        return normalized ? fmax(v / 127.0, -1.0) : v;
    }
    case VDSH_GLTF_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case VDSH_GLTF_SHORT: {
        int16_t v;
        memcpy(&v, p, 2);
        return normalized ? fmax(v / 32767.0, -1.0) : v;
    }
    case VDSH_GLTF_UNSIGNED_SHORT: {
        uint16_t v;
        memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case VDSH_GLTF_UNSIGNED_INT: {
        uint32_t v;
        memcpy(&v, p, 4);
        return v;
    }
    default: {
        float v;
        memcpy(&v, p, 4);
        return v;
    }
    }
}

#endif
