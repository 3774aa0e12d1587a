#!/usr/bin/python3
"""The Python reader decodes a cpca stream (VDSH.md "cpca streams") to the
C reader's floats, bit for bit: test_cpca writes a file and its C decode.

Usage: test_cpca_python.py TEST_CPCA SOURCE_DIR WORK_DIR
"""
import os
import subprocess
import sys

import numpy as np

test_cpca, src, work = sys.argv[1:4]
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402

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
off = 32
while off + 16 <= len(d):
    n = int.from_bytes(d[off + 8:off + 16], "little")
    if d[off:off + 4] == b"COEF":
        d[off + 16 + 4352] = 3
        import zlib
        pad = (n + 15) // 16 * 16
        crc = zlib.crc32(d[off + 8:off + 16], zlib.crc32(d[off:off + 4]))
        d[off + 4:off + 8] = zlib.crc32(d[off + 16:off + 16 + pad], crc).to_bytes(4, "little")
    off += 16 + (n + 15) // 16 * 16
try:
    vdsh.parse(bytes(d), "bad.vdsh")
    fail.append("a cluster index >= K accepted")
except vdsh.VdshError as e:
    if "cluster" not in str(e):
        fail.append("refused for another reason: %s" % e)
for m in fail:
    print("FAIL:", m)
print("cpca python: %d values compared, %s" % (got.size, "bit-identical" if not fail else "FAILED"))
sys.exit(1 if fail else 0)
