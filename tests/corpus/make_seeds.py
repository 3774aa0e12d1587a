#!/usr/bin/env python3
# Writes the hand-made mesh seeds of tests/corpus/mesh_{obj,ply,off,stl}/
# (see README.md there). Deterministic: running it again rewrites the same
# bytes. Usage: python3 tests/corpus/make_seeds.py [tests/corpus]
import math
import os
import struct
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
C = lambda t: os.path.join(root, t)
def put(target, name, data):
    if isinstance(data, str): data = data.encode()
    assert len(data) <= 8192, (target, name, len(data))
    os.makedirs(C(target), exist_ok=True)
    open(os.path.join(C(target), name), 'wb').write(data)

# ---------------- OBJ ----------------
cube_v = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
cube_q = [(1,3,4,2),(5,6,8,7),(1,2,6,5),(3,7,8,4),(1,5,7,3),(2,4,8,6)]
def obj_cube(extra_v='', face=lambda q: 'f ' + ' '.join(map(str, q))):
    s = ''.join('v %g %g %g%s\n' % (v + (extra_v,)) for v in cube_v)
    return s + ''.join(face(q) + '\n' for q in cube_q)
o = 'mesh_obj'
put(o, 'triangle.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n')
put(o, 'cube-quads.obj', obj_cube())
put(o, 'cube-negative-indices.obj', ''.join(
    'v %g %g %g\n' % v for v in cube_v[:4]) + 'f -4 -3 -2\nf -3 -1 -2\n' +
    ''.join('v %g %g %g\n' % v for v in cube_v[4:]) + 'f -4 -3 -2 -1\nf -8 -7 -3\n')
put(o, 'cube-vt-vn.obj', ''.join('v %g %g %g\n' % v for v in cube_v) +
    'vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 1 0\nvn 1 0 0\n' +
    ''.join('f ' + ' '.join('%d/%d/%d' % (i, 1 + k % 3, 1 + j % 3) for k, i in enumerate(q)) + '\n'
            for j, q in enumerate(cube_q)))
put(o, 'cube-v-vn.obj', ''.join('v %g %g %g\n' % v for v in cube_v) + 'vn 0 0 -1\nvn 0 0 1\n' +
    ''.join('f ' + ' '.join('%d//%d' % (i, 1 + j % 2) for i in q) + '\n' for j, q in enumerate(cube_q)))
# creases: each face's corners name its own normal (vertices split); one
# corner without a normal, one zero normal, a face OpenMesh drops (two
# distinct vertices) with normals, and a 20-gon naming a normal per corner
put(o, 'cube-creases.obj', ''.join('v %g %g %g\n' % v for v in cube_v) +
    'vn -1 0 0\nvn 1 0 0\nvn 0 -1 0\nvn 0 1 0\nvn 0 0 -1\nvn 0 0 1\nvn 0 0 0\n' +
    ''.join('f ' + ' '.join('%d//%d' % (i, n) for i in q) + '\n'
            for q, n in zip(cube_q, (1, 2, 3, 4, 5, 6))).replace('f 1//1 3//1', 'f 1 3//7', 1) +
    'f 1//2 1//3 2//4\n')
put(o, 'polygon-corner-normals.obj', ''.join('v %.6f %.6f 0\n' % (math.cos(k * math.pi / 10), math.sin(k * math.pi / 10)) for k in range(20)) +
    ''.join('vn %.4f 0 1\n' % (0.01 * k) for k in range(20)) +
    'f ' + ' '.join('%d//%d' % (k + 1, k + 1) for k in range(20)) + '\n')
put(o, 'tabs-crlf-comments.obj', 'mtllib cube.mtl\r\n# comment\r\no box\r\ng side\r\nusemtl red\r\nv\t0 0 0\r\nv\t1 0 0 # inline\r\nv\t0 1 0\r\nv 0 0 1 1.0\r\ns 1\r\nf 1 2 3\r\nf\t1 3 4 # c\r\nl 1 2\r\np 3\r\n')
put(o, 'no-final-newline.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3')
put(o, 'vertex-colors.obj', 'v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n')
put(o, 'number-formats.obj', 'v +1.5e+0 -2.E-3 .5\nv 1e-45 3.4028234e38 -0\nv 0x10 1 1\nv 1e-50 0 0\nf 1 2 3\nf 1 2 4\n')
put(o, 'nan.obj', 'v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n')
put(o, 'inf.obj', 'v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n')
put(o, 'overflow.obj', 'v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n')
put(o, 'index-out-of-range.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n')
put(o, 'index-zero.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n')
put(o, 'index-negative-too-far.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n')
put(o, 'index-huge.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\nf 1 2 -9223372036854775808\n')
put(o, 'face-two-corners.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n')
put(o, 'face-repeated-corner.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2 3\nf 1 1 2\n')
put(o, 'vertex-two-numbers.obj', 'v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n')
put(o, 'vertex-garbage.obj', 'v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n')
put(o, 'forward-reference.obj', 'f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n')
put(o, 'points-lines-only.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\nl 1 2 3\n')
put(o, 'no-faces.obj', 'v 0 0 0\nv 1 0 0\n')
put(o, 'utf16le-bom.obj', b'\xff\xfev\x00 \x000\x00')
put(o, 'zero-area-duplicates.obj', 'v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\nf 1 2 4\nf 2 1 4\n')
put(o, 'nonmanifold.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 2 5\nf 2 1 3\n')
put(o, 'polygon-octagon.obj', ''.join('v %g %g 0\n' % (round(math.cos(k * 0.785398), 3), round(math.sin(k * 0.785398), 3)) for k in range(8)) + 'f 1 2 3 4 5 6 7 8\n')
put(o, 'far-from-origin.obj', 'v 100000 100000 100000\nv 100000.01 100000 100000\nv 100000 100000.01 100000\nf 1 2 3\n')
put(o, 'tiny.obj', 'v 0 0 0\nv 1e-4 0 0\nv 0 1e-4 0\nf 1 2 3\n')
# the assimp invalid files' interesting bytes: malformed.obj has faces
# pointing past its 8 vertices; malformed2.obj a material that is not there
put(o, 'assimp-malformed-out-of-range.obj', '#\t\tVertices: 8\n' + ''.join('v %g %g %g\n' % v for v in cube_v) + 'f 1 2 3 4\nf 5 6 7 80\n')
put(o, 'assimp-malformed2-missing-material.obj', 'mtllib nonexistent.mtl\nusemtl nothing\n' + obj_cube())
put(o, 'mtllib-dev-zero.obj', 'mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n')
put(o, 'long-line.obj', 'v 0 0 0\nv 1 0 0\nv 0 1 0\n# ' + 'x' * 3000 + '\nf 1 2 3\n')
for n in (5, 17, 30, 44):
    put(o, 'truncated-%d.obj' % n, obj_cube()[:n])

# ---------------- PLY ----------------
p = 'mesh_ply'
cube_t = [(0,1,3),(0,3,2),(4,6,7),(4,7,5),(0,4,5),(0,5,1),(2,3,7),(2,7,6),(0,2,6),(0,6,4),(1,5,7),(1,7,3)]
def ply(fmt, verts, faces, vprops=('float x', 'float y', 'float z'), flist='uchar int', extra_header='', vfmt=None):
    h = 'ply\nformat %s 1.0\n%selement vertex %d\n' % (fmt, extra_header, len(verts))
    h += ''.join('property %s\n' % q for q in vprops)
    h += 'element face %d\nproperty list %s vertex_indices\nend_header\n' % (len(faces), flist)
    if fmt == 'ascii':
        body = ''.join(' '.join('%g' % c for c in v) + '\n' for v in verts)
        body += ''.join('%d %s\n' % (len(f), ' '.join(map(str, f))) for f in faces)
        return (h + body).encode()
    e = '<' if fmt == 'binary_little_endian' else '>'
    ct, it = flist.split()
    code = {'uchar': 'B', 'uint8': 'B', 'uint16': 'H', 'ushort': 'H', 'int': 'i', 'uint': 'I', 'char': 'b', 'short': 'h', 'int32': 'i', 'uint32': 'I'}
    body = b''.join(struct.pack(e + (vfmt or 'fff'), *v) for v in verts)
    body += b''.join(struct.pack(e + code[ct], len(f)) + struct.pack(e + code[it] * len(f), *f) for f in faces)
    return h.encode() + body
put(p, 'cube-ascii.ply', ply('ascii', cube_v, cube_t))
put(p, 'cube-ascii-quads.ply', ply('ascii', cube_v, [tuple(i - 1 for i in q) for q in cube_q]))
put(p, 'cube-binary-le.ply', ply('binary_little_endian', cube_v, cube_t))
put(p, 'cube-binary-be.ply', ply('binary_big_endian', cube_v, cube_t))
put(p, 'cube-binary-le-uint-uint16.ply', ply('binary_little_endian', cube_v, cube_t, flist='uint16 uint'))
put(p, 'cube-binary-le-double.ply', ply('binary_little_endian', cube_v, cube_t, vprops=('double x', 'double y', 'double z'), vfmt='ddd'))
put(p, 'cube-binary-le-normals.ply', ply('binary_little_endian', [v + (0.0, 0.0, 1.0) for v in cube_v], cube_t,
    vprops=('float x', 'float y', 'float z', 'float nx', 'float ny', 'float nz'), vfmt='ffffff'))
put(p, 'cube-ascii-normals-colors.ply', ply('ascii', [v + (0, 1, 0, 255, 0, 0) for v in cube_v], cube_t,
    vprops=('float x', 'float y', 'float z', 'float nx', 'float ny', 'float nz', 'uchar red', 'uchar green', 'uchar blue')))
put(p, 'cube-binary-comment-before-end.ply', ply('binary_little_endian', cube_v, cube_t).replace(b'end_header\n', b'comment trailing \nend_header\n'))
put(p, 'cube-ascii-obj-info-comment.ply', ply('ascii', cube_v, cube_t, extra_header='comment made by hand\nobj_info test\n'))
put(p, 'property-type-after-name.ply', ply('ascii', cube_v, cube_t, vprops=('x float', 'y float', 'z float')))
put(p, 'int8-names.ply', ply('ascii', cube_v, cube_t, vprops=('float32 x', 'float32 y', 'float32 z'), flist='uint8 int32'))
put(p, 'extra-element-after-face.ply', ply('ascii', cube_v, cube_t).replace(b'end_header\n', b'element edge 1\nproperty int v1\nproperty int v2\nend_header\n') + b'0 1\n')
put(p, 'element-before-vertex.ply', b'ply\nformat ascii 1.0\nelement material 1\nproperty float r\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0.5\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put(p, 'texcoord-list.ply', b'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 0 0 1 0 0 1\n')
put(p, 'nan.ply', ply('ascii', [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)]).replace(b'\n0 1 0\n', b'\nnan 1 0\n'))
put(p, 'nan-binary.ply', ply('binary_little_endian', [(0, 0, 0), (1, 0, 0), (0, float('nan'), 0)], [(0, 1, 2)]))
put(p, 'inf-binary-be.ply', ply('binary_big_endian', [(0, 0, 0), (1, 0, 0), (0, float('inf'), 0)], [(0, 1, 2)]))
put(p, 'index-out-of-range.ply', ply('ascii', [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 3)]))
put(p, 'index-negative-binary.ply', ply('binary_little_endian', [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, -1)]))
put(p, 'face-two-vertices.ply', ply('binary_little_endian', [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1)]))
put(p, 'absurd-vertex-count.ply', b'ply\nformat binary_little_endian 1.0\nelement vertex 2147483647\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n' + b'\0' * 40)
put(p, 'absurd-list-count.ply', b'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list int int vertex_indices\nend_header\n' + b'\0' * 36 + b'\xff\xff\xff\x7f' + b'\0' * 8)
put(p, 'face-property-before-indices.ply', b'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 3 0 1 2\n')
put(p, 'two-face-elements.ply', b'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 2\n3 2 1 0\n')
put(p, 'no-end-header.ply', b'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n')
put(p, 'no-format.ply', b'ply\nelement vertex 0\nend_header\n')
put(p, 'points-only.ply', b'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n')
put(p, 'uppercase-PLY-crlf.ply', ply('ascii', cube_v, cube_t).replace(b'ply\n', b'PLY\r\n', 1))
full = ply('binary_little_endian', cube_v, cube_t)
for n in (3, 40, len(full) // 2, len(full) - 1):
    put(p, 'truncated-binary-%d.ply' % n, full[:n])
fa = ply('ascii', cube_v, cube_t)
put(p, 'truncated-ascii-%d.ply' % (len(fa) - 9), fa[:-9])

# ---------------- OFF ----------------
f = 'mesh_off'
def off(verts, faces, head='OFF', edges=0, normals=None):
    s = head + '\n%d %d %d\n' % (len(verts), len(faces), edges)
    for i, v in enumerate(verts):
        s += ' '.join('%g' % c for c in v) + (' ' + ' '.join('%g' % c for c in normals[i]) if normals else '') + '\n'
    s += ''.join('%d %s\n' % (len(q), ' '.join(map(str, q))) for q in faces)
    return s.encode()
def off_bin(verts, faces, head='OFF BINARY', normals=None):
    b = (head + '\n').encode() + struct.pack('<III', len(verts), len(faces), 0)
    for i, v in enumerate(verts):
        b += struct.pack('<fff', *v) + (struct.pack('<fff', *normals[i]) if normals else b'')
    for q in faces:
        b += struct.pack('<I', len(q)) + struct.pack('<%dI' % len(q), *q)
    return b
quads0 = [tuple(i - 1 for i in q) for q in cube_q]
put(f, 'cube.off', off(cube_v, quads0, edges=12))
put(f, 'cube-triangles.off', off(cube_v, cube_t))
put(f, 'cube-normals.off', off(cube_v, cube_t, head='NOFF', normals=[(0, 0, 1)] * 8))
put(f, 'cube-colors.off', off(cube_v, quads0, head='COFF').replace(b'\n4 ', b' 255 0 0 255\n4 ', 1))
put(f, 'cube-face-colors.off', b''.join(l + (b' 1 0 0' if l[:2] == b'4 ' else b'') + b'\n' for l in off(cube_v, quads0, head='COFF').split(b'\n')))
put(f, 'cube-texcoords.off', off(cube_v, quads0, head='STOFF'))
put(f, 'cube-binary.off', off_bin(cube_v, quads0))
put(f, 'cube-binary-normals.off', off_bin(cube_v, cube_t, head='NOFF BINARY', normals=[(1, 0, 0)] * 8))
put(f, 'comment-and-blank.off', b'OFF\n# a comment\n\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put(f, 'counts-on-header-line.off', b'OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put(f, '4off.off', b'4OFF\n3 1 0\n0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n')
put(f, 'nan.off', b'OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n')
put(f, 'inf-binary.off', off_bin([(0, 0, 0), (1, 0, 0), (0, float('inf'), 0)], [(0, 1, 2)]))
put(f, 'index-out-of-range.off', b'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n')
put(f, 'index-negative.off', b'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n')
put(f, 'face-two-vertices.off', b'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n')
put(f, 'face-huge-count.off', b'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4294967295 0 1 2\n')
# assimp's invalid/OutOfMemory.off: a face count far beyond the file
put(f, 'assimp-out-of-memory-counts.off', b'OFF\n35353523535358 6 0\n-0.5 -0.5 0.5\n0.5 -0.5 0.5\n3 0 1 0\n')
put(f, 'absurd-face-count.off', b'OFF\n3 3000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n')
put(f, 'absurd-binary-counts.off', b'OFF BINARY\n' + struct.pack('<III', 0xffffffff, 0xffffffff, 0) + b'\0' * 24)
# assimp's OFF/invalid.off: "3 4" counts, a face "2\r20" and "4" short
put(f, 'assimp-invalid-short-faces.off', b'OFF\n3 4\n0.1 0.2 0.3\n0.2 0.3 0.4\n0.3 0.4 0.5\n0\n2\r20\n4\n')
put(f, 'no-counts.off', b'OFF\n')
put(f, 'not-off.off', b'OFFX\n3 1 0\n')
put(f, 'crlf.off', off(cube_v, cube_t).replace(b'\n', b'\r\n'))
full = off_bin(cube_v, quads0)
for n in (11, 20, 60, len(full) - 2):
    put(f, 'truncated-binary-%d.off' % n, full[:n])
fa = off(cube_v, quads0)
for n in (9, len(fa) // 2, len(fa) - 4):
    put(f, 'truncated-ascii-%d.off' % n, fa[:n])

# ---------------- STL ----------------
s = 'mesh_stl'
def tri_list(verts, tris): return [tuple(verts[i] for i in t) for t in tris]
def stl_ascii(tris, name='cube', normal=(0, 0, 0)):
    out = 'solid %s\n' % name
    for t in tris:
        out += '  facet normal %g %g %g\n    outer loop\n' % normal
        out += ''.join('      vertex %g %g %g\n' % v for v in t)
        out += '    endloop\n  endfacet\n'
    return (out + 'endsolid %s\n' % name).encode()
def stl_bin(tris, header=b'binary stl', attr=0):
    b = header.ljust(80, b'\0') + struct.pack('<I', len(tris))
    for t in tris:
        b += struct.pack('<fff', 0, 0, 0) + b''.join(struct.pack('<fff', *v) for v in t) + struct.pack('<H', attr)
    return b
ct = tri_list(cube_v, cube_t)
put(s, 'cube-ascii.stl', stl_ascii(ct))
put(s, 'cube-binary.stl', stl_bin(ct))
put(s, 'cube-binary-solid-header.stl', stl_bin(ct, header=b'solid but binary'))
put(s, 'triangle-ascii.stl', stl_ascii(ct[:1], name=''))
put(s, 'triangle-ascii-uppercase.stl', stl_ascii(ct[:1]).upper())
put(s, 'two-solids.stl', stl_ascii(ct[:2], 'a') + stl_ascii(ct[2:4], 'b'))
put(s, 'empty-solid.stl', b'solid empty\nendsolid empty\n')
put(s, 'degenerate-binary.stl', stl_bin([((0, 0, 0), (0, 0, 0), (1, 0, 0)), ((0, 0, 0), (1, 0, 0), (0, 1, 0))]))
put(s, 'all-degenerate.stl', stl_ascii([((0, 0, 0), (0, 0, 0), (1, 0, 0))]))
put(s, 'nan-ascii.stl', stl_ascii(ct[:1]).replace(b'vertex 0 0 0', b'vertex nan 0 0', 1))
put(s, 'nan-binary.stl', stl_bin([((0, 0, 0), (1, 0, 0), (0, float('nan'), 0))]))
put(s, 'inf-binary.stl', stl_bin([((0, 0, 0), (1, 0, 0), (0, float('-inf'), 0))]))
put(s, 'huge-ascii.stl', stl_ascii(ct[:1]).replace(b'vertex 0 0 0', b'vertex 1e39 0 0', 1))
put(s, 'absurd-count-binary.stl', (b'x' * 80) + struct.pack('<I', 0xffffffff) + b'\0' * 50)
put(s, 'count-mismatch-binary.stl', stl_bin(ct)[:-50])
put(s, 'two-vertices-facet.stl', b'solid t\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid t\n')
put(s, 'garbage-coordinate.stl', stl_ascii(ct[:1]).replace(b'vertex 0 0 0', b'vertex 0 x 0', 1))
put(s, 'outer-in-name.stl', b'solid outer\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n')
put(s, 'not-stl.stl', b'hello world\n')
put(s, 'crlf-ascii.stl', stl_ascii(ct[:2]).replace(b'\n', b'\r\n'))
put(s, 'shared-vertices-fan.stl', stl_bin([((0, 0, 0), (math.cos(a), math.sin(a), 0), (math.cos(a + 1), math.sin(a + 1), 0)) for a in range(6)]))
fa = stl_ascii(ct[:2])
for n in (5, 40, len(fa) // 2, len(fa) - 20):
    put(s, 'truncated-ascii-%d.stl' % n, fa[:n])
fb = stl_bin(ct)
for n in (50, 83, 84 + 25, len(fb) - 1):
    put(s, 'truncated-binary-%d.stl' % n, fb[:n])
