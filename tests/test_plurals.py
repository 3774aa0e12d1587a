"""Messages that count with a plural noun say one thing in the singular
("truncated: 1 byte", "1 vertex", "1 chunk announced"), in the C reader
(vdsh-info), the Python reader (python/vdsh), the mesh readers (vdsh-bake)
and the bake's light placement; counts other than 1 keep the plural.

Usage: test_plurals.py VDSH_BAKE VDSH_INFO SOURCE_DIR WORKDIR [VDSH_EVAL]
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

bake, info, src, work = sys.argv[1:5]
evaluate = sys.argv[5] if len(sys.argv) > 5 else None
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402

failures = []
BAD = re.compile(r"(^|[^0-9.])1 (bytes|vertices|triangles|chunks|lights|candidates|samples)\b")


def c_message(path):
    p = subprocess.run([info, path], capture_output=True, text=True)
    return p.returncode, p.stderr.strip()


def py_message(path):
    try:
        vdsh.read(path)
    except Exception as e:  # noqa: BLE001
        return str(e)
    return ""


def expect(label, msg, want):
    if want not in msg:
        failures.append("%s: %r lacks %r" % (label, msg, want))
    if BAD.search(msg):
        failures.append("%s: '1 <plural>' in %r" % (label, msg))


def write(name, data):
    path = os.path.join(work, name)
    open(path, "wb").write(data)
    return path


def header(chunks, size, flags=0):
    h = b"VDSH\r\n\x1a\n" + struct.pack("<IIQI", 1, chunks, size, flags)
    return h + struct.pack("<I", zlib.crc32(h))


# A 1-byte file (the magic's first byte): both readers.
p = write("one.vdsh", b"V")
expect("C, 1-byte file", c_message(p)[1], "truncated: 1 byte,")
expect("Python, 1-byte file", py_message(p), "truncated: 1 byte,")
p = write("two.vdsh", b"VD")
expect("C, 2-byte file", c_message(p)[1], "truncated: 2 bytes,")
# One chunk announced, none there.
p = write("nochunk.vdsh", header(1, 32))
expect("C, one chunk announced", c_message(p)[1], "(1 chunk announced)")
# A baked file with one byte after its last chunk (file_size says so).
one_obj = os.path.join(work, "one.obj")
open(one_obj, "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
good = os.path.join(work, "good.vdsh")
subprocess.run([bake, one_obj, "--rays", "16", "--orders", "1", "--cube-size", "0", "-q", "-o", good],
               check=True)
d = open(good, "rb").read()
n = struct.unpack_from("<I", d, 12)[0]
p = write("extra.vdsh", header(n, len(d) + 1) + d[32:] + b"\0")
expect("C, 1 byte after the chunks", c_message(p)[1], "1 byte after the last of")
# A file truncated by one byte: the header's size is said, not "1 bytes".
p = write("cut.vdsh", d[:-1])
expect("C, 1 byte missing", c_message(p)[1], "truncated: %d bytes, the header says %d" % (len(d) - 1, len(d)))
expect("Python, 1 byte missing", py_message(p), "truncated: %d bytes, the header says %d" % (len(d) - 1, len(d)))

# Mesh readers: one vertex, a face of one vertex.
for name, text, want in (
        ("onev.obj", "v 0 0 0\nf 1 2 3\n", "(1 vertex"),
        ("face1.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1\n", "face has 1 vertex (needs at least 3)"),
        ("onev.off", "OFF\n1 1 0\n0 0 0\n3 0 1 2\n", "(1 vertex)"),
        ("twov.off", "OFF\n2 1 0\n0 0 0\n1 0 0\n3 0 1 2\n", "(2 vertices)"),
        ("degen.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 0 1\n", "its 1 triangle repeats a vertex")):
    path = os.path.join(work, name)
    open(path, "w").write(text)
    q = subprocess.run([bake, path, "--rays", "16", "-q", "-o", os.path.join(work, "x.vdsh")],
                       capture_output=True, text=True)
    if q.returncode == 0:
        failures.append("%s: baked" % name)
    expect(name, q.stderr.strip(), want)

# vdsh-eval's summary of a one-triangle bake.
if evaluate:
    q = subprocess.run([evaluate, good, one_obj, "--points", "4", "--lights", "2", "--directions", "2",
                        "--threads", "1"], capture_output=True, text=True)
    line = [x for x in q.stdout.splitlines() if "receiver" in x and "occluder" in x]
    expect("vdsh-eval summary", line[0] if line else q.stdout + q.stderr,
           "3 receiver vertices, 1 triangle; 1 occluder triangle;")

if failures:
    print("\n".join(failures))
    sys.exit(1)
print("plurals: one byte, chunk, vertex, triangle in the singular")
