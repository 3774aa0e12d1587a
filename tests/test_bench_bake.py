#!/usr/bin/python3
"""scripts/bench_bake's bookkeeping, with a stand-in vdsh-bake (a script
that writes a report of the fields bench_bake reads; the real bake's
timings are not what is tested): --out FILE in the current folder is
written (makedirs('') raised FileNotFoundError after the whole run, the
measurements lost), --quick does not say that Sponza was not found, and
--repeat 0 is a usage error (it was a traceback).

Usage: test_bench_bake.py SCRIPTS_DIR
"""
import os
import subprocess
import sys
import tempfile

import testlib

scripts = sys.argv[1]
script = os.path.join(scripts, "bench_bake")
fails = []
check = testlib.checker(fails)

STUB = r'''#!/usr/bin/python3
import json, sys
a = sys.argv[1:]
if a == ["--version"]:
    print("vdsh-bake stand-in"); sys.exit(0)
rep = {"seconds": {"bare": 1.0, "total": 1.25, "load": 0.1, "refine": 0.05, "write": 0.01,
                   "trace": 0.8},
       "rays_traced": 1000, "rays_missed": 1, "receivers": 10, "occluder_triangles": 20,
       "rays_per_receiver": 100, "threads": 2, "coefficient_bytes_per_vertex": 36,
       "file_bytes": 500}
with open(a[a.index("--report") + 1], "w") as f:
    json.dump(rep, f)
'''

with tempfile.TemporaryDirectory() as tmp:
    build = os.path.join(tmp, "build")
    os.makedirs(os.path.join(build, "bake"))
    stub = os.path.join(build, "bake", "vdsh-bake")
    with open(stub, "w") as f:
        f.write(STUB)
    os.chmod(stub, 0o755)
    r = subprocess.run([script, "--build", build, "--quick", "--repeat", "1", "--out",
                        "bench.md"], cwd=tmp, capture_output=True, text=True)
    check(r.returncode == 0, "--out bench.md: exit %d, %s" % (r.returncode, r.stderr[-600:]))
    out = os.path.join(tmp, "bench.md")
    text = open(out).read() if os.path.exists(out) else ""
    check("## Bake throughput against a bare Embree loop" in text and
          "| built-in room, paper size | paper |" in text,
          "bench.md holds the section: %r" % text[:300])
    check("Sponza skipped" not in r.stderr, "--quick: %r" % r.stderr)
    r = subprocess.run([script, "--build", build, "--repeat", "0", "--out", "x.md"], cwd=tmp,
                       capture_output=True, text=True)
    check(r.returncode == 2 and "--repeat" in r.stderr and "Traceback" not in r.stderr and
          not os.path.exists(os.path.join(tmp, "x.md")),
          "--repeat 0: exit %d, %r" % (r.returncode, r.stderr[-300:]))
sys.exit(1 if fails else 0)
