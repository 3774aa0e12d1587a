"""python -m vdsh info [--json OUT] FILE.vdsh... - what a .vdsh file holds
(vdsh-info's main figures, its --json field names), read by this package."""
from __future__ import annotations

import errno
import json
import os
import stat
import sys
from typing import Any, Dict, List, Optional

import numpy as np

from . import UP_AXES, VdshError, VdshFile, __version__, coefficients, read

PROG = "python -m vdsh"
USAGE = """usage: %s info [--json OUT.json] FILE.vdsh...

Print what a .vdsh file holds, as vdsh-info does (its main figures):
counts, bounds, bake parameters, sources, coefficient streams, statistics.

  -j, --json OUT.json  write it as JSON instead (vdsh-info --json's field
                 names; -: on stdout): one object, an array for several files
  -h, --help     print this help and exit
  -V, --version  print the version and exit

Exit status: 0 every file is fine, 1 a file could not be read, 2 usage
error.
""" % PROG


def _bytes_per_vertex(s: Dict[str, Any]) -> int:
    """Bytes of one record at the stream's order (vdsh_stream_bytes_per_vertex)."""
    nc = s["order"] ** 2
    if s["encoding"] == "cpca":
        return 4 * s["cpca"]["record_words"]
    words = (nc - 4 + 4) // 5 if s["encoding"] == "s8s6" and nc > 4 else 0
    return {"f32": 4 * nc, "f16": 2 * nc, "s8": nc, "s8s6": min(nc, 4) + 4 * words}[s["encoding"]]


def _cpca(s: Dict[str, Any], rows: int) -> Dict[str, Any]:
    """vdsh-info --json's "cpca" of a cpca stream: the model (its bytes as
    formats/vdsh_encode.c's vdsh_cpca_stream_model_bytes: the 16-byte
    header, the scales, means and bases each padded to 16 bytes, the widths
    table when bits is 0) and the bytes per vertex with it."""
    c = s["cpca"]
    r16 = lambda x: (x + 15) // 16 * 16  # noqa: E731
    k, b, n = c["clusters"], c["basis"], s["order"] ** 2
    model = 16 + r16(4 * k * b) + r16(2 * k * n) + r16(2 * k * b * n) + (0 if c["bits"] else r16(b))
    o: Dict[str, Any] = dict(clusters=k, basis=b, bits=c["bits"], record_words=c["record_words"],
                             model_bytes=model)
    if not c["bits"]:
        o["widths"] = [int(w) for w in c["widths"]]
    o["mean_bytes_per_vertex"] = 4 * c["record_words"] + (model / rows if rows else 0.0)
    return o


def summary(f: VdshFile, path: str) -> Dict[str, Any]:
    """The figures of vdsh-info --json this package knows, under its names."""
    h = f.header
    size = os.path.getsize(path)
    streams: List[Dict[str, Any]] = []
    for s in f.streams:
        c0 = coefficients(s)[:, 0]
        o: Dict[str, Any] = dict(
            order=s["order"], coefficients=s["order"] ** 2, encoding=s["encoding"],
            method=s["method"] if isinstance(s["method"], str) else "?",
            method_id=s["method_id"], method_param=float(s["method_param"]),
            quantity=s["quantity"], quantity_param=float(s["quantity_param"]),
            window=s["window"], window_param=float(s["window_param"]), scale=float(s["scale"]),
            bytes_per_vertex=_bytes_per_vertex(s), variable_order=s["variable_order"],
            coefficient0=dict(min=float(c0.min()), max=float(c0.max()),
                              mean=float(c0.astype(np.float64).mean())))
        if s["coef_scales"] is not None:
            o["coef_scales"] = [float(x) for x in s["coef_scales"]]
        if s["encoding"] == "cpca":
            o["cpca"] = _cpca(s, len(s["cpca"]["cluster"]))
        if s["variable_order"]:
            # as vdsh_stream_size_of: records padded to 4 bytes, after the
            # order table (rows padded to 16)
            per = np.bincount(s["orders"], minlength=s["order"] + 1)
            rec = [(_bytes_per_vertex(dict(s, order=k)) + 3) // 4 * 4
                   for k in range(s["order"] + 1)]
            rows = len(s["orders"])
            o["bytes_per_vertex"] = 0
            o["mean_bytes_per_vertex"] = ((rows + 15) // 16 * 16 + sum(
                int(n) * r for n, r in zip(per, rec))) / rows
            o["max_bytes_per_vertex"] = max(r for n, r in zip(per, rec) if n)
            o["vertices_per_order"] = [int(x) for x in per[1:]]
        streams.append(o)
    p = f.positions
    bake = dict(rays=h["rays"], sampling=h["sampling"], seed=h["seed"],
                max_distance=float(h["max_distance"]), max_edge=float(h["max_edge"]),
                offset_rule=["none", "wb-avg"][h["offset_rule"]], load_flags=h["load_flags"],
                welded=bool(h["load_flags"] & 1),
                up_axis=UP_AXES[(h["load_flags"] >> 1) & 7])
    if (h["load_flags"] >> 8) & 0xff:  # as vdsh-info: only when the bake split at creases
        bake["crease"] = (h["load_flags"] >> 8) & 0xff
    bake.update(trace_flags=h["trace_flags"],
                robust=bool(h["trace_flags"] & 1), cube_size=h["cube_size"],
                occluder_vertex_count=h["occluder_vertex_count"],
                occluder_triangle_count=h["occluder_triangle_count"],
                occluder_bounds=dict(min=[float(x) for x in h["bounds_min"]],
                                     max=[float(x) for x in h["bounds_max"]]))
    return dict(
        file=path, valid=True, file_size=size, bytes_per_vertex=size / h["vertex_count"],
        format_version=1, vertex_count=h["vertex_count"], triangle_count=h["triangle_count"],
        receiver_bounds=dict(min=[float(x) for x in p.min(axis=0)],
                             max=[float(x) for x in p.max(axis=0)]),
        bake=bake,
        sources=f.sources, streams=streams, stats=f.stats, timings=f.timings,
        **{k: v for k, v in (("part", _part(f)), ("adaptive", f.adaptive),
                             ("light_region", f.light_region)) if v is not None})


def _part(f: Any) -> Any:
    """The part's dict; a cpca part's with its light mix and pool size
    (`lpol`; none: light mix 0), as vdsh-info's."""
    if not f.part or f.part.get("encoding") != "cpca":
        return f.part
    lp = f.light_pool
    return dict(f.part, cpca_light_mix=float(lp["mix"]) if lp else 0.0,
                cpca_light_pool=len(lp["lights"]) if lp else 0)


def _n(n: int, one: str, many: str = "") -> str:
    """'1 triangle', '2 triangles' (vdsh-info's plurals)."""
    return "%d %s" % (n, one if n == 1 else (many or one + "s"))


def _text(d: Dict[str, Any]) -> str:
    b = d["bake"]

    def vec(v: List[float]) -> str:
        return "(%s)" % ", ".join("%g" % x for x in v)
    lines = [d["file"],
             "  receivers    %s, %s" % (_n(d["vertex_count"], "vertex", "vertices"),
                                       _n(d["triangle_count"], "triangle")),
             "               bounds %s .. %s" % (vec(d["receiver_bounds"]["min"]),
                                                 vec(d["receiver_bounds"]["max"])),
             "  occluders    %s, %s" % (_n(b["occluder_vertex_count"], "vertex", "vertices"),
                                       _n(b["occluder_triangle_count"], "triangle")),
             "  bake         rays %d per receiver, sampling %s, seed %d"
             % (b["rays"], b["sampling"], b["seed"]),
             "               max_distance %g, max_edge %g" % (b["max_distance"], b["max_edge"]),
             "  sources      %d" % len(d["sources"])]
    lines += ["    [%d] %s (%s)" % (i, s["name"], _n(s["size"], "byte"))
              for i, s in enumerate(d["sources"])]
    lines.append("  streams      %d" % len(d["streams"]))
    for i, s in enumerate(d["streams"]):
        lines.append("    [%d] order %d%s (%s), %s, method %s, quantity %s"
                     % (i, s["order"], " (variable)" if s["variable_order"] else "",
                        _n(s["coefficients"], "coefficient"), s["encoding"], s["method"],
                        s["quantity"]))
        if s["variable_order"]:
            lines.append("        vertices per order 1..%d: %s" % (
                s["order"], " ".join(str(n) for n in s["vertices_per_order"])))
        c0 = s["coefficient0"]
        lines.append("        coefficient 0: min %g, max %g, mean %g" % (c0["min"], c0["max"],
                                                                       c0["mean"]))
    if d["stats"]:
        st = d["stats"]
        lines.append("  stats        rays traced %d, missed %d" % (st["rays_traced"],
                                                                 st["rays_missed"]))
    if d.get("part"):
        pt = d["part"]
        lines.append("  part         %d of %d, receivers %d..%d" % (
            pt["index"], pt["count"], pt["range_begin"], pt["range_end"]))
    if d.get("light_region"):
        lr = d["light_region"]
        lines.append("  lights       region %s: %s .. %s (vdsh-bake --light-region)" % (
            lr["rule"], " ".join("%g" % x for x in lr["min"]),
            " ".join("%g" % x for x in lr["max"])))
    lines.append("  size         %d bytes, %.2f bytes per vertex" % (d["file_size"],
                                                                    d["bytes_per_vertex"]))
    return "\n".join(lines) + "\n"


def _is_descriptor(path: str) -> bool:
    """Whether `path` leads through /proc/<pid>/fd (/dev/stdout, /dev/fd/N,
    /proc/self/fd/N): a descriptor already open, whatever it is (a terminal,
    a pipe, or a regular file the shell redirected to), to be written in
    place and appended to, never replaced by a rename (which would replace
    the link /dev/stdout itself)."""
    q = os.path.abspath(path)
    for _ in range(40):
        folder = os.path.realpath(os.path.dirname(q))
        if folder == "/proc" or folder.startswith("/proc/"):
            return True
        q = os.path.join(folder, os.path.basename(q))
        if not os.path.islink(q):
            return False
        q = os.path.join(folder, os.readlink(q))
    return False


def _write_atomic(path: str, text: str) -> None:
    """`text` into `path` as formats/vdsh_output.h writes files: through a
    temporary file beside it ("<path>.tmp.<pid>.<n>", created exclusively,
    mode 0666 less the umask) renamed over it, so that a reader sees the old
    file or the whole new one; an existing character device or FIFO
    (/dev/null, a pipe) or a path through /proc/<pid>/fd (/dev/stdout) is
    written in place, never replaced; a directory
    or any other kind of file is refused (OSError naming it)."""
    if _is_descriptor(path):
        with open(path, "a") as fh:
            fh.write(text)
        return
    try:
        st = os.stat(path)
    except OSError:
        st = None
    if st is not None and not stat.S_ISREG(st.st_mode):
        if not (stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode)):
            raise OSError(errno.EISDIR if stat.S_ISDIR(st.st_mode) else errno.EINVAL,
                          "cannot write: %s" % ("is a directory" if stat.S_ISDIR(st.st_mode)
                                                else "not a regular file"))
        with open(path, "w") as fh:
            fh.write(text)
        return
    for n in range(1000):
        tmp = "%s.tmp.%d.%d" % (path, os.getpid(), n)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOCTTY, 0o666)
            break
        except FileExistsError:
            continue
    else:
        raise OSError(errno.EEXIST, "cannot create a temporary file beside it: every name taken")
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _check_output(out: str, files: List[str]) -> Optional[str]:
    """Why `out` cannot be written (the same file as an input, a folder that
    is not there), checked before any file is read; None when it can."""
    try:
        st = os.stat(out)
    except OSError:
        st = None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            return "%s: cannot write: is a directory" % out
        if stat.S_ISREG(st.st_mode):
            for f in files:
                try:
                    if os.path.samefile(out, f):
                        return "%s: is the input %s (the same file): refusing to overwrite it" % (out, f)
                except OSError:
                    pass
        return None
    folder = os.path.dirname(out) or "."
    if not os.path.isdir(folder):
        return "%s: cannot write: no folder %s" % (out, folder)
    if not os.access(folder, os.W_OK | os.X_OK):
        return "%s: cannot write: folder %s is not writable" % (out, folder)
    return None


def info(argv: List[str]) -> int:
    """`info [--json OUT] FILE...`; returns the exit status."""
    out: Optional[str] = None
    files: List[str] = []
    k = 0
    while k < len(argv):
        a = argv[k]
        if a in ("-j", "--json") or a.startswith("--json="):
            if "=" in a:
                out = a.split("=", 1)[1]
            elif k + 1 < len(argv):
                k += 1
                out = argv[k]
            else:
                return _usage("%s needs a file name (-: stdout)" % a)
            if not out:
                return _usage("--json needs a file name (-: stdout), not ''")
        elif a == "--":
            files += argv[k + 1:]
            break
        elif a.startswith("-") and a != "-":
            return _usage("unknown option %s" % a)
        else:
            files.append(a)
        k += 1
    if not files:
        return _usage("no file given")
    why = _check_output(out, files) if out not in (None, "-") else None
    if why:
        print("%s: %s" % (PROG, why), file=sys.stderr)
        return 1
    docs, status = [], 0
    for path in files:
        try:
            d = summary(read(path), path)
        except (VdshError, OSError) as e:
            msg = str(e) if isinstance(e, VdshError) else "%s: %s" % (path, e.strerror or e)
            print("%s: %s" % (PROG, msg), file=sys.stderr)
            status = 1
            d = dict(file=path, valid=False, error=msg)
        docs.append(d)
        if out is None and d["valid"]:
            sys.stdout.write(_text(d))
    if out is not None:
        text = json.dumps(docs[0] if len(docs) == 1 else docs, indent=2) + "\n"
        if out == "-":
            sys.stdout.write(text)
        else:
            try:
                _write_atomic(out, text)
            except OSError as e:
                print("%s: %s: %s" % (PROG, out, e.strerror or e), file=sys.stderr)
                return 1
    return status


def _usage(msg: str) -> int:
    print("%s: %s\nTry '%s --help'." % (PROG, msg, PROG), file=sys.stderr)
    return 2


def main(argv: Optional[List[str]] = None) -> int:
    """The entry point of `python -m vdsh`; returns the exit status."""
    argv = sys.argv[1:] if argv is None else argv
    if not argv:
        return _usage("no command (info)")
    if argv[0] in ("-h", "--help"):
        sys.stdout.write(USAGE)
        return 0
    if argv[0] in ("-V", "--version"):
        print("vdsh (python) %s (.vdsh format 1)" % __version__)
        return 0
    if argv[0] == "info":
        if any(a in ("-h", "--help") for a in argv[1:]):
            sys.stdout.write(USAGE)
            return 0
        return info(argv[1:])
    return _usage("unknown command %s (info)" % argv[0])


if __name__ == "__main__":
    sys.exit(main())
