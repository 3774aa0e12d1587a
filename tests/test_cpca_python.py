#!/usr/bin/python3
"""The Python reader decodes a cpca stream (VDSH.md "cpca streams") to the
C reader's floats, bit for bit: test_cpca writes a file and its C decode,
and the same of a stream with a width per basis vector (bits 0 and the
widths table: 8, 7, 6, 5, 4, 4, 4, 3, 3, 3, 2, 2, 2), whose broken widths,
padding and 2-bit weight -2 Python refuses as C does, and whose part chunk
of --cpca K,alloc:BYTES (K, budget, 0) it reads; and a stream with s8
bases (--cpca ...,bases:8), decoded bit for bit, a value of -128 refused.

Usage: test_cpca_python.py TEST_CPCA SOURCE_DIR WORK_DIR
"""
import os
import subprocess
import sys

import numpy as np

test_cpca, src, work = sys.argv[1:4]
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402
from testlib import chunks, fix_crc  # noqa: E402

os.makedirs(work, exist_ok=True)
subprocess.run([test_cpca, work], check=True, stdout=subprocess.DEVNULL)
f = vdsh.read(os.path.join(work, "cpca.vdsh"))
s = f.streams[0]
got = vdsh.coefficients(s)
want = np.fromfile(os.path.join(work, "cpca.f32"), "<f4").reshape(got.shape)
fail = []
if s["encoding"] != "cpca" or s["cpca"]["clusters"] != 3 or s["cpca"]["basis"] != 13:
    fail.append("stream header: %s %s" % (s["encoding"], s["cpca"]))
if not np.array_equal(got.view(np.uint32), want.view(np.uint32)):
    fail.append("decode differs from C at %d of %d values" % ((got != want).sum(), got.size))
# a changed cluster index (CRCs fixed) is refused by Python as by C
d = bytearray(open(os.path.join(work, "cpca.vdsh"), "rb").read())
off, _, n = next(c for c in chunks(d) if c[1] == b"COEF")
d[off + 16 + 4352] = 3
fix_crc(d, off, n)
try:
    vdsh.parse(bytes(d), "bad.vdsh")
    fail.append("a cluster index >= K accepted")
except vdsh.VdshError as e:
    if "cluster" not in str(e):
        fail.append("refused for another reason: %s" % e)


def refused(d, what, name):
    try:
        vdsh.parse(bytes(d), name)
        fail.append("%s accepted" % name)
    except vdsh.VdshError as e:
        if what not in str(e):
            fail.append("%s refused for another reason: %s" % (name, e))


# a width per basis vector
wpath = os.path.join(work, "cpca-widths.vdsh")
fw = vdsh.read(wpath)
sw = fw.streams[0]
gw = vdsh.coefficients(sw)
ww = np.fromfile(os.path.join(work, "cpca-widths.f32"), "<f4").reshape(gw.shape)
want_widths = [8, 7, 6, 5, 4, 4, 4, 3, 3, 3, 2, 2, 2]
if sw["cpca"]["bits"] != 0 or list(sw["cpca"]["widths"]) != want_widths or \
        sw["cpca"]["record_words"] != 2:
    fail.append("widths stream header: %s" % {k: sw["cpca"][k] for k in
                                              ("bits", "widths", "record_words")})
if not np.array_equal(gw.view(np.uint32), ww.view(np.uint32)):
    fail.append("widths: decode differs from C at %d of %d values" % ((gw != ww).sum(), gw.size))
L = (1 << (np.array(want_widths) - 1)) - 1
lv = np.abs(sw["cpca"]["levels"])
if not ((lv <= L).all() and (lv[:, want_widths.index(2):] == 1).any()):
    fail.append("widths: levels outside each width's -L..L, or no 2-bit weight at +-1")
dw = bytearray(open(wpath, "rb").read())
coef = [(o, n) for o, c, n in chunks(dw) if c == b"COEF"][0]
o, n = coef
for at, val, what, name in [(64, 1, "width", "width 1"), (64 + 12, 9, "width", "width 9"),
                            (64 + 13, 1, "padding", "widths padding"),
                            (60, 3, "record_words", "record_words 3")]:
    d = bytearray(dw)
    d[o + 16 + at:o + 16 + at + (4 if at == 60 else 1)] = \
        val.to_bytes(4 if at == 60 else 1, "little")
    fix_crc(d, o, n)
    refused(d, what, name)
# vector 10 (2 bits) at word 1 bits 26..27 of vertex 0's record: -2
recs = 64 + 16 + 160 + 304 + 3824
d = bytearray(dw)
w1 = int.from_bytes(d[o + 16 + recs + 4:o + 16 + recs + 8], "little")
d[o + 16 + recs + 4:o + 16 + recs + 8] = ((w1 & ~(3 << 26)) | (2 << 26)).to_bytes(4, "little")
fix_crc(d, o, n)
refused(d, "below -1", "2-bit weight -2")
# the part chunk --cpca K,alloc:BYTES writes: clusters K, budget, bits 0
V = fw.header["vertex_count"]


def with_part(ck, cb, cbits):
    import struct
    body = struct.pack("<8I", 0, 1, 0, V, 4, ck, cb, cbits)
    c = bytearray(b"part" + b"\0" * 4 + len(body).to_bytes(8, "little") + body)
    fix_crc(c, 0, len(body))
    d = bytearray(dw) + c  # one more chunk: the file header's count, size and CRC
    d[12:16] = (int.from_bytes(d[12:16], "little") + 1).to_bytes(4, "little")
    d[16:24] = len(d).to_bytes(8, "little")
    import zlib
    d[28:32] = zlib.crc32(d[:28]).to_bytes(4, "little")
    return d


try:
    fp = vdsh.parse(bytes(with_part(3, 16, 0)), "alloc-part.vdsh")
    if (fp.part or {}).get("cpca_clusters") != 3 or fp.part.get("cpca_basis") != 16:
        fail.append("alloc part read as %s" % fp.part)
except vdsh.VdshError as e:
    fail.append("alloc part refused: %s" % e)
refused(with_part(3, 0, 0), "out of range", "alloc part of budget 0")
try:  # --cpca K,alloc:BYTES,bases:8: cpca_bits 0x100
    fp = vdsh.parse(bytes(with_part(3, 16, 0x100)), "s8-part.vdsh")
    if (fp.part or {}).get("cpca_bits") != 0x100:
        fail.append("s8 alloc part read as %s" % fp.part)
except vdsh.VdshError as e:
    fail.append("s8 alloc part refused: %s" % e)
refused(with_part(0, 16, 0x100), "out of range", "auto part with s8 bases")

# s8 bases (--cpca ...,bases:8; the bits word's 0x100): the decode bit for
# bit, and a basis value of -128 refused
spath = os.path.join(work, "cpca-s8.vdsh")
s8 = vdsh.read(spath).streams[0]
g8 = vdsh.coefficients(s8)
w8 = np.fromfile(os.path.join(work, "cpca-s8.f32"), "<f4").reshape(g8.shape)
c8 = s8["cpca"]
if not c8["bases_s8"] or c8["bits"] != 0 or np.abs(c8["bases"]).max() != 127:
    fail.append("s8 stream header: bases_s8 %s, bits %s" % (c8["bases_s8"], c8["bits"]))
if not np.array_equal(g8.view(np.uint32), w8.view(np.uint32)):
    fail.append("s8: decode differs from C at %d of %d values" % ((g8 != w8).sum(), g8.size))
d8 = bytearray(open(spath, "rb").read())
o8, n8 = [(o, n) for o, c, n in chunks(d8) if c == b"COEF"][0]
K8, B8, nc8 = c8["clusters"], c8["basis"], s8["order"] ** 2
r16 = lambda n: (n + 15) // 16 * 16  # noqa: E731
first = 64 + r16(B8) + r16(4 * K8 * B8) + r16(2 * K8 * nc8)
d8[o8 + 16 + first] = 0x80
fix_crc(d8, o8, n8)
refused(d8, "-128", "s8 basis value -128")
for m in fail:
    print("FAIL:", m)
print("cpca python: %d values compared, %s" % (got.size, "bit-identical" if not fail else "FAILED"))
sys.exit(1 if fail else 0)
