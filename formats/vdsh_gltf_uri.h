/*
 * vdsh_gltf_uri.h - internal (not installed): the file name a glTF URI
 * names, for the baker's glTF reader (bake/lib/mesh_gltf.cpp) and
 * vdsh-export's source reader (tools/vdsh_export_source.c), which decoded
 * URIs two ways ('+' a space in one, kept in the other), so that "a+b.bin"
 * named different files in bake and export. Static inline; C and C++.
 *
 * The rule is the one the baker cannot change: tinygltf's
 * dlib::urldecode, which tinygltf applies to every buffer and image URI
 * before joining it to the glTF's directory (tests/test_gltf_uri.py holds
 * both programs to it).
 */
#ifndef VDSH_GLTF_URI_H
#define VDSH_GLTF_URI_H

#include <stddef.h>
#include <string.h>

/* One hex digit's value; any other character counts as 0 (tinygltf's
 * from_hex: "%2z" is a space). */
static inline int vdsh_gltf_uri_hex(int c)
{
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : 0;
}

/* Decodes the n bytes of uri into out (room for n + 1 bytes; a NUL is
 * written after the result): '+' is a space; '%' followed by at least two
 * more characters is the byte those two make (vdsh_gltf_uri_hex); a '%'
 * among the last two characters, and every other character, is kept.
 * Returns the decoded length. The result can hold a NUL byte ("%00",
 * "%zz"): the caller refuses the URI when the length differs from
 * strlen(out), since no file name holds one. */
static inline size_t vdsh_gltf_uri_decode(const char *uri, size_t n, char *out)
{
    size_t o = 0;
    for (size_t i = 0; i < n; i++) {
        if (uri[i] == '+') {
            out[o++] = ' ';
        } else if (uri[i] == '%' && n > i + 2) {
            out[o++] = (char)(vdsh_gltf_uri_hex((unsigned char)uri[i + 1]) << 4 |
                              vdsh_gltf_uri_hex((unsigned char)uri[i + 2]));
            i += 2;
        } else {
            out[o++] = uri[i];
        }
    }
    out[o] = 0;
    return o;
}

#endif
