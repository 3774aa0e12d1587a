"""vdsh-merge of parts whose SRCS record a .gltf source two ways
(formats/VDSH.md, SRCS): a bake before 2026-11-30 hashed the .gltf alone,
later ones the file and its external buffers. Parts of one bake baked by
both kinds of baker are merged when both records match the same file
(found by its recorded name, as given or beside the part), in either part
order, into the bytes the whole bake writes now (the record with the
buffers); refused, naming the part, when the .bin changed since or the
file is not found.

Usage: test_merge_source_record.py VDSH_BAKE VDSH_MERGE WORKDIR
"""
import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_fixtures  # noqa: E402

bake, merge, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []

# Two quads side by side (8 vertices: one receiver range per shard).
name, g, binary, expected = gltf_fixtures.fixtures()[0]
g = json.loads(json.dumps(g))
g["buffers"][0]["uri"] = "scene.bin"
text = json.dumps(g).encode()
src = os.path.join(work, "scene.gltf")
open(src, "wb").write(text)
open(os.path.join(work, "scene.bin"), "wb").write(binary)

opts = ["-q", "--rays", "16", "--orders", "2", "--cube-size", "0"]
whole = os.path.join(work, "whole.vdsh")
parts = [os.path.join(work, "part%d.vdsh" % i) for i in range(2)]
os.chdir(work)  # the sources recorded by the name given: scene.gltf
for cmd in [[bake, "scene.gltf", "-o", whole] + opts] + \
        [[bake, "scene.gltf", "-o", parts[i], "--shard", "%d/2" % i] + opts for i in range(2)]:
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("%s: rc %d: %s" % (cmd, p.returncode, p.stderr))


def old_record(path, out):
    """The part at path with its SRCS record the old way (the .gltf's bytes
    alone), its chunk CRC made again: as a bake before 2026-11-30 wrote it."""
    d = bytearray(open(path, "rb").read())
    at = 32
    while at < len(d):
        cid, size = bytes(d[at:at + 4]), struct.unpack_from("<Q", d, at + 8)[0]
        pay = at + 16
        pad = (16 - size % 16) % 16
        if cid == b"SRCS":
            assert struct.unpack_from("<I", d, pay)[0] == 1
            d[pay + 4:pay + 36] = hashlib.sha256(text).digest()
            struct.pack_into("<Q", d, pay + 36, len(text))
            crc = zlib.crc32(bytes(d[at + 8:at + 16]), zlib.crc32(cid))
            crc = zlib.crc32(bytes(d[pay:pay + size + pad]), crc)
            struct.pack_into("<I", d, at + 4, crc)
        at = pay + size + pad
    open(out, "wb").write(bytes(d))


old0 = os.path.join(work, "old0.vdsh")
old_record(parts[0], old0)
old1 = os.path.join(work, "old1.vdsh")
old_record(parts[1], old1)
want = open(whole, "rb").read()


def run(args):
    return subprocess.run([merge] + args, capture_output=True, text=True)


# Both orders, and both parts old (unchanged: the old record kept).
for label, ps in (("old first", [old0, parts[1]]), ("old second", [parts[0], old1])):
    out = os.path.join(work, "merged.vdsh")
    p = run(ps + ["-o", out])
    if p.returncode != 0:
        failures.append("%s: rc %d: %s" % (label, p.returncode, p.stderr.strip()))
    elif open(out, "rb").read() != want:
        failures.append("%s: the merged file is not the whole bake's bytes" % label)
    elif "recorded without its external buffers" not in p.stderr:
        failures.append("%s: no note of the old record: %s" % (label, p.stderr.strip()))
    os.path.exists(out) and os.remove(out)
p = run([old0, old1, "-o", "both-old.vdsh", "-q"])
if p.returncode != 0:
    failures.append("both old: rc %d: %s" % (p.returncode, p.stderr.strip()))

# Found beside the part when run from elsewhere.
os.chdir("/")
p = run([old0, parts[1], "-o", os.path.join(work, "beside.vdsh"), "-q"])
if p.returncode != 0 or open(os.path.join(work, "beside.vdsh"), "rb").read() != want:
    failures.append("source beside the parts: rc %d: %s" % (p.returncode, p.stderr.strip()))
os.chdir(work)

# The .bin changed since: the records do not both match; refused.
moved = bytearray(binary)
moved[0:4] = struct.pack("<f", 0.5)
open("scene.bin", "wb").write(moved)
p = run([old0, parts[1], "-o", "changed.vdsh"])
if p.returncode != 1 or "does not belong with" not in p.stderr or "part1.vdsh" not in p.stderr \
        or os.path.exists("changed.vdsh"):
    failures.append("a changed .bin: rc %d: %s" % (p.returncode, p.stderr.strip()))
open("scene.bin", "wb").write(binary)

# The source gone: refused, saying so.
os.rename("scene.gltf", "gone.gltf")
p = run([old0, parts[1], "-o", "gone.vdsh"])
if p.returncode != 1 or "not found" not in p.stderr or os.path.exists("gone.vdsh"):
    failures.append("the source missing: rc %d: %s" % (p.returncode, p.stderr.strip()))
os.rename("gone.gltf", "scene.gltf")

if failures:
    print("\n".join(failures))
    sys.exit(1)
print("merge of old and new source records: both orders, beside the parts; a changed .bin and a "
      "missing source refused")
