"""testlib - what the Python tests in tests/ share (imported from the
test's own folder, which Python puts first on sys.path)."""
import json
import os
import subprocess
import sys


def checker(fails):
    """check(ok, what): a failed check is appended to `fails` and printed."""
    def check(ok, what):
        if not ok:
            fails.append(what)
            print("FAIL: " + what, file=sys.stderr)
    return check


def pip_install(pkg, target):
    """python/ (pkg) installed with Debian's pip into `target`: no network,
    no build isolation, no dependencies. The finished process."""
    return subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-build-isolation",
                           "--no-deps", "--no-index", "--target", target, pkg],
                          capture_output=True, text=True)


def bake_room(bake, out, max_edge, rays, args):
    """vdsh-bake builtin:room at this edge and ray count, no cubemaps, -o
    out, then args: None when it succeeds, else its stderr."""
    r = subprocess.run([bake, "builtin:room", "--max-edge", max_edge, "--rays", rays, "-q",
                        "--cube-size", "0", "-o", out] + args, capture_output=True, text=True)
    return r.stderr.strip() if r.returncode else None


def write_view(path, name, width, height, eye, target, light_sets):
    """A view set of one view (up +y, 60 degrees) at `path`."""
    json.dump({"width": width, "height": height,
               "views": [{"name": name, "eye": eye, "target": target, "up": [0, 1, 0],
                          "fov_y": 60, "light_sets": light_sets}]}, open(path, "w"))


def view_frames(view, views, frames, modes, vd):
    """vdsh-view's shadow-only frames of `vd` for the view set into
    `frames`, in each of `modes`; exits 77 without a GL context, 1 when
    vdsh-view fails otherwise."""
    p = subprocess.run([view, "-q", "--views", views, "--frames", frames, "--modes", ",".join(modes), vd],
                       capture_output=True, text=True)
    if p.returncode != 0:
        if "EGL" in p.stderr or "context" in p.stderr or "display" in p.stderr:
            print("no GL context: skipped\n" + p.stderr)
            sys.exit(77)
        print("FAIL: vdsh-view: " + p.stderr)
        sys.exit(1)


def chunks(d):
    """(offset, id, size) of every chunk of .vdsh file bytes d (past the
    32-byte header; formats/VDSH.md: 16-byte chunk headers, payloads padded
    to 16)."""
    out, off = [], 32
    while off + 16 <= len(d):
        size = int.from_bytes(d[off + 8:off + 16], "little")
        out.append((off, bytes(d[off:off + 4]), size))
        off += 16 + size + (-size % 16)
    return out


def fix_crc(d, off, size):
    """Rewrite the CRC of the chunk at `off` of bytearray d (id, size and
    padded payload), so that a reader gets past it to the damage a test made."""
    import zlib
    crc = zlib.crc32(bytes(d[off + 8:off + 16]), zlib.crc32(bytes(d[off:off + 4])))
    crc = zlib.crc32(bytes(d[off + 16:off + 16 + size + (-size % 16)]), crc)
    d[off + 4:off + 8] = crc.to_bytes(4, "little")


def load_script(path):
    """The script at `path` (a file without .py, like scripts/cpca_study)
    imported as a module, its main() not run (scripts guard it)."""
    import importlib.machinery
    import importlib.util
    name = os.path.basename(path).replace("-", "_")
    loader = importlib.machinery.SourceFileLoader(name, path)
    module = importlib.util.module_from_spec(importlib.util.spec_from_loader(name, loader))
    loader.exec_module(module)
    return module


class Pages:
    """Headless-browser pages run a few at a time: each launch mostly waits
    (about 2 s of start-up for 0.5 s of CPU), so the web tests start up to
    `workers` at once. submit(fn, *args) runs fn in a worker; fn returns
    (lines, fails). drain() waits for every job submitted so far, prints
    their lines and extends `fails` in submission order, so the output
    reads as if run one by one; call it before changing a file the pages
    read."""

    def __init__(self, fails, workers=3):
        import concurrent.futures
        self.fails, self.jobs = fails, []
        self.pool = concurrent.futures.ThreadPoolExecutor(max_workers=workers)

    def submit(self, fn, *args):
        self.jobs.append(self.pool.submit(fn, *args))

    def drain(self):
        jobs, self.jobs = self.jobs, []
        for j in jobs:
            lines, fails = j.result()
            for line in lines:
                print(line)
            self.fails.extend(fails)
        sys.stdout.flush()

    def close(self):
        self.drain()
        self.pool.shutdown()
