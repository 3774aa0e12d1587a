"""python -m vdsh info [--json OUT] FILE.vdsh... - what a .vdsh file holds
(vdsh-info's main figures, its --json field names), read by this package."""
from __future__ import annotations

import json
import os
import stat
import sys
import tempfile
from typing import Any, Dict, List, Optional

import numpy as np

from . import VdshError, VdshFile, __version__, coefficients, read

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
    return dict(
        file=path, valid=True, file_size=size, bytes_per_vertex=size / h["vertex_count"],
        format_version=1, vertex_count=h["vertex_count"], triangle_count=h["triangle_count"],
        receiver_bounds=dict(min=[float(x) for x in p.min(axis=0)],
                             max=[float(x) for x in p.max(axis=0)]),
        bake=dict(rays=h["rays"], sampling=h["sampling"], seed=h["seed"],
                  max_distance=float(h["max_distance"]), max_edge=float(h["max_edge"]),
                  offset_rule=["none", "wb-avg"][h["offset_rule"]], load_flags=h["load_flags"],
                  welded=bool(h["load_flags"] & 1), trace_flags=h["trace_flags"],
                  robust=bool(h["trace_flags"] & 1), cube_size=h["cube_size"],
                  occluder_vertex_count=h["occluder_vertex_count"],
                  occluder_triangle_count=h["occluder_triangle_count"],
                  occluder_bounds=dict(min=[float(x) for x in h["bounds_min"]],
                                       max=[float(x) for x in h["bounds_max"]])),
        sources=f.sources, streams=streams, stats=f.stats, timings=f.timings,
        **{k: v for k, v in (("part", f.part), ("adaptive", f.adaptive)) if v is not None})


def _text(d: Dict[str, Any]) -> str:
    b = d["bake"]

    def vec(v: List[float]) -> str:
        return "(%s)" % ", ".join("%g" % x for x in v)
    lines = [d["file"],
             "  receivers    %d vertices, %d triangles" % (d["vertex_count"], d["triangle_count"]),
             "               bounds %s .. %s" % (vec(d["receiver_bounds"]["min"]),
                                                 vec(d["receiver_bounds"]["max"])),
             "  occluders    %d vertices, %d triangles" % (b["occluder_vertex_count"],
                                                           b["occluder_triangle_count"]),
             "  bake         rays %d per receiver, sampling %s, seed %d"
             % (b["rays"], b["sampling"], b["seed"]),
             "               max_distance %g, max_edge %g" % (b["max_distance"], b["max_edge"]),
             "  sources      %d" % len(d["sources"])]
    lines += ["    [%d] %s (%d bytes)" % (i, s["name"], s["size"]) for i, s in enumerate(d["sources"])]
    lines.append("  streams      %d" % len(d["streams"]))
    for i, s in enumerate(d["streams"]):
        lines.append("    [%d] order %d%s (%d coefficients), %s, method %s, quantity %s"
                     % (i, s["order"], " (variable)" if s["variable_order"] else "",
                        s["coefficients"], s["encoding"], s["method"], s["quantity"]))
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
    lines.append("  size         %d bytes, %.2f bytes per vertex" % (d["file_size"],
                                                                    d["bytes_per_vertex"]))
    return "\n".join(lines) + "\n"


def _write_atomic(path: str, text: str) -> None:
    """`text` into `path` through a temporary file beside it and a rename."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=os.path.basename(path) + ".tmp.", dir=folder)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _same_file(a: str, b: str) -> bool:
    """Whether a and b name one existing regular file (device and inode)."""
    try:
        sa, sb = os.stat(a), os.stat(b)
    except OSError:
        return False
    return stat.S_ISREG(sa.st_mode) and (sa.st_dev, sa.st_ino) == (sb.st_dev, sb.st_ino)


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
    if out is not None and out != "-":
        # as vdsh-info: never over an input (the same file by device and
        # inode, whatever the names), never a folder; checked before any work
        for path in files:
            if _same_file(out, path):
                print("%s: %s is the input %s (the same file): not overwriting it"
                      % (PROG, out, path), file=sys.stderr)
                return 1
        if os.path.isdir(out):
            print("%s: %s: cannot write: is a directory" % (PROG, out), file=sys.stderr)
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
