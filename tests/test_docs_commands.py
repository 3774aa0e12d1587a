"""Every command the docs show runs as shown, as far as its options go: each
command line in README.md, docs/*.md, formats/*.md and runtime/**/README*.md
that runs one of our programs (vdsh-bake, vdsh-merge, vdsh-info, vdsh-eval,
vdsh-frames, vdsh-view, vdsh-export, scripts/NAME, python3 -m vdsh) uses
only options that program's --help (or its subcommand's) names, and a
build/DIR/PROG path is where the build puts PROG; every scripts/NAME the
docs mention exists; and every long option the docs name anywhere, prose
and tables included, is some program's or script's (or another tool's,
FOREIGN below). Options get renamed and removed, and the docs then go
stale without anyone noticing.

Commands are taken from code blocks (indented or fenced) and from inline
code spans (`vdsh-bake --light-region grown`). Line continuations (backslash), pipes,
&&, ;, comments, env assignments (NAME=value), wrappers (nice, timeout,
env, time), placeholders (SCENE, FILE, K, ...: values are never checked)
and optional parts in brackets ([--seed N]) are handled. Arguments after
bake-parallel's and bake-slurm's `--` are vdsh-bake's; the strings given to
a script's --extra, --variant, --eval-args, ... (NESTED below) are checked
against the program they go to. Options are those a help defines (opening
a line, or in its usage), not any it mentions.

Usage: test_docs_commands.py SOURCE_DIR BUILD_DIR [PROG=PATH ...] [--list]
  PROG=PATH: where the build's programs are (vdsh-bake=build/bake/vdsh-bake);
  a command of a program not given is counted as skipped (a build without
  the bake). --list prints every command found and what it was checked as.
"""
import ast
import concurrent.futures
import glob
import os
import re
import shlex
import subprocess
import sys

# Options the docs show that no longer exist, kept because the text says
# they were removed and the figures beside them were measured with them.
# (doc, program, option): why. Keep this short: a renamed option is fixed
# in the docs instead.
HISTORICAL = {
    # "Can order 5 reach 0.8x?": rows measured on branch framecal, commit
    # 9d2c634, which added the option; not merged (the text says so).
    ("docs/ACCURACY.md", "vdsh-bake", "--calibration-weight"):
        "framecal's unmerged option, commit 9d2c634",
    # "Training lights: speed against error": measured on branch lights,
    # commit 97a1f2f; not merged (the text says so).
    ("docs/ACCURACY.md", "vdsh-bake", "--decision-fit-pairs"):
        "lights' unmerged option, commit 97a1f2f",
}

# Long options the docs name anywhere (prose, tables, commands) must be
# some program's or script's, or one of these other tools' (so that a
# renamed option is caught also where no command shows it).
FOREIGN = {
    "chromium": ("--headless", "--no-sandbox", "--use-angle", "--enable-unsafe-swiftshader",
                 "--allow-file-access-from-files", "--window-size", "--virtual-time-budget"),
    "cmake, ctest": ("--install", "--prefix", "--test-dir", "--output-on-failure"),
    "pip, venv": ("--no-build-isolation", "--no-deps", "--target", "--system-site-packages"),
    "pkg-config": ("--cflags", "--libs", "--static"),
    "sbatch": ("--dependency", "--cpus-per-task", "--chdir", "--kill-on-invalid-dep"),
    "perf, heaptrack_print": ("--sort", "--print-peaks"),
    "tests/cpca_kchoice_tool (a measurement tool, no --help)": ("--score",),
}
LONG = re.compile(r"(?<![\w-])(--[A-Za-z0-9][\w-]*)")

PROGRAMS = ("vdsh-bake", "vdsh-merge", "vdsh-info", "vdsh-eval", "vdsh-frames", "vdsh-view",
            "vdsh-export")
# Scripts whose arguments after `--` are vdsh-bake's.
BAKE_AFTER_DASHES = ("bake-parallel", "bake-slurm")
# A script's option whose value holds another program's arguments: the
# whole value ("ARGS"), "NAME=ARGS", or "NAME=ARGS;NAME=ARGS...".
NESTED = {
    ("adaptive_curve", "--extra"): ("vdsh-bake", "ARGS"),
    ("adaptive_curve", "--bakes"): ("vdsh-bake", "NAME=ARGS;..."),
    ("frames_gap", "--variant"): ("vdsh-bake", "NAME=ARGS"),
    ("mottling", "--variant"): ("vdsh-bake", "NAME=ARGS"),
    ("pareto", "--bake-args"): ("vdsh-bake", "ARGS"),
    ("speed_vs_error", "--eval-args"): ("vdsh-eval", "ARGS"),
    ("view_pools", "--variant"): ("vdsh-bake", "NAME=ARGS"),
    ("view_pools", "--base"): ("vdsh-bake", "ARGS"),
}
# Commands that run another: the options of theirs that take a value.
WRAPPERS = {"nice": {"-n": 1}, "timeout": {}, "env": {}, "time": {}, "exec": {}, "sudo": {},
            "/usr/bin/time": {"-o": 1, "-f": 1}, "xvfb-run": {}}
SEPARATORS = {"|", "||", "&&", ";", "&", "(", ")", "$(", "`", "{", "}", "do", "then", "else",
              "!", ";;"}
OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z0-9][\w-]*)")
NUMBER = re.compile(r"^-[0-9.][0-9.eE+,-]*$")  # a value: -0.5, -4,2,2
ASSIGN = re.compile(r"^\[?[A-Za-z_][A-Za-z0-9_]*=")
SCRIPT_MENTION = re.compile(r"(?<![\w./-])(?:\./)?scripts/([A-Za-z0-9_][A-Za-z0-9_.-]*)")


def defined(help_text):
    """Options a help defines: those opening a line (`  -o, --output FILE`,
    `      --seed N`, argparse's) and those of its usage lines."""
    out = set()
    for line in help_text.split("\n"):
        m = re.match(r"^\s*((?:--?[A-Za-z0-9][\w-]*(?:[ =][A-Z][\w.,]*)?,?\s?)+)", line)
        if m:
            out |= set(OPTION.findall(m.group(1)))
        if re.match(r"^\s*(usage:|\w[\w.-]* \[)", line, re.I) or "usage" in line.lower():
            out |= set(OPTION.findall(line))
    return out


def doc_files(src):
    files = ["README.md"] + sorted(glob.glob("docs/*.md", root_dir=src)) + \
        sorted(glob.glob("formats/*.md", root_dir=src)) + \
        sorted(glob.glob("runtime/**/README*.md", root_dir=src, recursive=True))
    return [f for f in files if os.path.isfile(os.path.join(src, f))]


def snippets(text):
    """(line, kind, text): code blocks ('block', their lines joined by
    newlines) and inline code spans of the prose ('inline')."""
    lines = text.split("\n")
    out = []
    prose = []  # (line number, text) of the paragraph being read
    i = 0

    def flush():
        if not prose:
            return
        joined = ""
        starts = []  # offset in joined -> line number
        for n, t in prose:
            starts.append((len(joined), n))
            joined += t + " "
        for m in re.finditer(r"(`+)(.+?)\1", joined):
            line = max(n for off, n in starts if off <= m.start())
            out.append((line, "inline", m.group(2).strip()))
        prose.clear()

    prev_blank = True
    while i < len(lines):
        line = lines[i]
        fence = re.match(r"^\s*(```+|~~~+)", line)
        if fence:
            flush()
            start = i + 1
            i += 1
            while i < len(lines) and not lines[i].lstrip().startswith(fence.group(1)):
                i += 1
            out.append((start + 1, "block", "\n".join(lines[start:i])))
            i += 1
            prev_blank = False
            continue
        if prev_blank and re.match(r"^(    |\t)", line) and line.strip() and \
                not re.match(r"^\s*([-*+]|\d+\.)\s", line):
            flush()
            start = i
            while i < len(lines) and (re.match(r"^(    |\t)", lines[i]) or not lines[i].strip()):
                i += 1
            while i > start and not lines[i - 1].strip():
                i -= 1
            out.append((start + 1, "block", "\n".join(l[4:] if l.startswith("    ") else l[1:]
                                                      for l in lines[start:i])))
            prev_blank = False
            continue
        if not line.strip():
            flush()
            prev_blank = True
        else:
            prose.append((i + 1, line))
            prev_blank = False
        i += 1
    flush()
    return out


def tokens(command):
    """Shell words and operators of one command (comments dropped), or None
    when it does not parse (an unclosed quote)."""
    command = re.sub(r"\$\{[^}]*\}", "VAR", command)  # ${v%% *}: one word
    lex = shlex.shlex(command, posix=True, punctuation_chars=True)
    lex.whitespace_split = True
    lex.commenters = "#"
    try:
        return list(lex)
    except ValueError:
        return None


def block_commands(line0, text):
    """(line, command) for each command of a code block: continuations
    joined, a quote left open carried onto the next lines."""
    out = []
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        start = i
        cmd = lines[i]
        while True:
            if cmd.endswith("\\") and i + 1 < len(lines):
                i += 1
                cmd = cmd[:-1] + " " + lines[i]
                continue
            if tokens(cmd) is None and i + 1 < len(lines):
                i += 1
                cmd = cmd + "\n" + lines[i]
                continue
            break
        out.append((line0 + start, cmd))
        i += 1
    return out


def segments(words):
    """The simple commands of a word list, split at operators."""
    seg = []
    for w in words:
        redirect = w in ("<", ">", ">>", ">&", "<&")
        if w in SEPARATORS or (w and set(w) <= set("|&;()<>") and not redirect):
            if seg:
                yield seg
            seg = []
        else:
            seg.append(w)
    if seg:
        yield seg


def clean(w):
    """A word as the docs mean it: optional brackets dropped."""
    return w.strip("[]") if w.startswith("[") or w.endswith("]") else w


def program_of(seg):
    """(program, rest of the words, the path as written) of a simple
    command, or None when it runs none of ours. Program: 'vdsh-bake', ...,
    'scripts/NAME', or 'python -m vdsh'."""
    words = [clean(w) for w in seg if w not in ("[", "]")]
    i = 0
    while i < len(words):
        w = words[i]
        if ASSIGN.match(w) or not w:
            i += 1
            continue
        base = os.path.basename(w)
        if w in WRAPPERS or base in WRAPPERS:
            takes = WRAPPERS.get(w, WRAPPERS.get(base))
            i += 1
            while i < len(words) and words[i].startswith("-"):
                i += 1 + takes.get(words[i], 0)
            if base == "timeout" and i < len(words) and re.match(r"^[0-9.]+[smhd]?$", words[i]):
                i += 1
            continue
        break
    if i >= len(words):
        return None
    w = words[i]
    base = os.path.basename(w)
    rest = words[i + 1:]
    if base in PROGRAMS:
        return base, rest, w
    if re.match(r"^(\.{0,2}/)?(.*/)?scripts/[\w.-]+$", w) or base in BAKE_AFTER_DASHES:
        return "scripts/" + base, rest, w
    if base in ("python3", "python", "/usr/bin/python3"):
        if len(rest) >= 2 and rest[0] == "-m" and rest[1] == "vdsh":
            return "python -m vdsh", rest[2:], w
        if rest and re.match(r"^(\.{0,2}/)?(.*/)?scripts/[\w.-]+$", rest[0]):
            return "scripts/" + os.path.basename(rest[0]), rest[1:], rest[0]
    return None


def options_of(words):
    """(option, index) of each option word, up to a lone `--`; and the
    words after that `--` (None without one)."""
    opts = []
    for k, w in enumerate(words):
        if w == "--":
            return opts, words[k + 1:]
        if not w.startswith("-") or w == "-" or NUMBER.match(w) or " " in w or w.startswith("--="):
            continue
        opts.append((w.split("=", 1)[0], k))
    return opts, None


def python_options(path):
    """The options a Python script's --help lists, read from its source
    without running it (importing numpy and matplotlib for each script
    took most of this test's time): the option strings of its argparse
    add_argument calls (argparse's -h, --help added), or, in a script
    that parses sys.argv itself, every option-like string in it."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), path)
    strings = []
    argparse_opts = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            strings.append(node.value)
        if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "add_argument":
            argparse_opts += [a.value for a in node.args
                              if isinstance(a, ast.Constant) and isinstance(a.value, str)]
    found = argparse_opts + ["-h", "--help"] if argparse_opts else strings
    return sorted(o for o in found if re.match(r"^--?[A-Za-z0-9][\w-]*$", o))


class Helps:
    """--help of each program (and subcommand), fetched once; a Python
    script's options from its source (python_options)."""

    def __init__(self, src, progs):
        self.src = src
        self.progs = progs
        self.cache = {}
        self.errors = {}

    def argv(self, prog):
        if prog == "python -m vdsh":
            return [sys.executable, "-m", "vdsh"]
        if prog.startswith("scripts/"):
            path = os.path.join(self.src, prog)
            if not os.path.isfile(path):
                return None
            with open(path, "rb") as f:
                first = f.readline()
            if first.startswith(b"#!") and b"python" in first:
                return [sys.executable, path]
            return ["bash", path]
        return [self.progs[prog]] if prog in self.progs else None

    def text(self, prog, sub=None):
        key = (prog, sub)
        if key not in self.cache:
            argv = self.argv(prog)
            if argv is None:
                self.cache[key] = None
            elif argv[0] == sys.executable and prog.startswith("scripts/"):
                try:
                    self.cache[key] = "".join("  %s\n" % o for o in python_options(argv[1]))
                except (SyntaxError, ValueError) as e:
                    self.cache[key] = ""
                    self.errors[key] = f"does not parse: {e}"
            else:
                env = dict(os.environ, PYTHONPATH=os.path.join(self.src, "python"))
                p = subprocess.run(argv + ([sub] if sub else []) + ["--help"], capture_output=True,
                                   text=True, timeout=60, cwd=self.src, env=env)
                self.cache[key] = (p.stdout + p.stderr) if p.returncode == 0 else ""
                if p.returncode != 0:
                    self.errors[key] = f"exit {p.returncode}: {(p.stderr or p.stdout)[:300]}"
        return self.cache[key]

    def subcommands(self, prog):
        """Words the program's --help shows as `PROG WORD`: its subcommands.
        Not asked of scripts: a script need not read --help after a subcommand."""
        if prog.startswith("scripts/"):
            return set()
        t = self.text(prog) or ""
        name = "vdsh" if prog == "python -m vdsh" else os.path.basename(prog)
        subs = set(re.findall(re.escape(name) + r" ([a-z][a-z0-9-]+)\b", t))
        return {s for s in subs if s not in ("is", "and", "or", "the", "with", "a")}

    def options(self, prog, sub=None):
        """The options a help names; for a subcommand whose help has a
        section of its own (vdsh-frames: `score:` ... up to the next
        heading), that section's and the common ones'."""
        t = self.text(prog, sub)
        if t is None:
            return None
        sections = {}
        name = None
        for line in t.split("\n"):
            m = re.match(r"^([A-Za-z][A-Za-z ]*):", line)
            if m:
                name = m.group(1)
            sections.setdefault(name, []).append(line)
        if sub and sub in sections:
            t = "\n".join(sections[sub] + sections.get("Common options", []))
        return defined(t)


def check_docs(src, build, progs, helps, docs, listing=False):
    """The failures (text) and counts (commands, checked, skipped, scripts
    mentioned) of the docs, a list of (name, text)."""
    fails = []
    commands = []  # (doc, line, text, program, words, written)
    script_mentions = {}  # name -> first (doc, line)
    for doc, text in docs:
        for n, line in enumerate(text.split("\n"), 1):
            for m in SCRIPT_MENTION.finditer(line):
                name = m.group(1).rstrip(".")
                script_mentions.setdefault(name, (doc, n))
        for line, kind, snippet in snippets(text):
            cmds = block_commands(line, snippet) if kind == "block" else [(line, snippet)]
            for ln, cmd in cmds:
                words = tokens(cmd)
                if words is None:
                    continue
                for seg in segments(words):
                    found = program_of(seg)
                    if found is None:
                        continue
                    commands.append((doc, ln, cmd.strip(), found[0], found[1], found[2]))

    for name, (doc, n) in sorted(script_mentions.items()):
        if not os.path.exists(os.path.join(src, "scripts", name)):
            fails.append(f"{doc}:{n}: scripts/{name} does not exist")

    # Fetch the helps in parallel (each program and bash script runs once).
    wanted = set()
    for doc, ln, cmd, prog, words, written in commands:
        if words or not prog.startswith("scripts/"):
            wanted.add((prog, None))
    with concurrent.futures.ThreadPoolExecutor(8) as pool:
        list(pool.map(lambda k: helps.text(*k), wanted))
    subs_wanted = set()
    for doc, ln, cmd, prog, words, written in commands:
        first = next((w for w in words if not w.startswith("-")), None)
        if first and first in helps.subcommands(prog):
            subs_wanted.add((prog, first))
    with concurrent.futures.ThreadPoolExecutor(8) as pool:
        list(pool.map(lambda k: helps.text(*k), subs_wanted))

    checked = skipped = 0
    where = {p: os.path.relpath(os.path.realpath(path), os.path.realpath(build))
             for p, path in progs.items()}

    def check(doc, ln, cmd, prog, words, label):
        nonlocal checked, skipped
        sub = None
        opts, after = options_of(words)
        first = next((w for w in words if not w.startswith("-")), None)
        if first and first in helps.subcommands(prog) and \
                (not opts or words.index(first) < opts[0][1]):
            sub = first
        if not words and prog.startswith("scripts/"):
            if not os.path.isfile(os.path.join(src, prog)):
                fails.append(f"{doc}:{ln}: {prog} does not exist: {cmd}")
            return
        known = helps.options(prog, sub)
        name = prog + (" " + sub if sub else "")
        if known is None:
            if prog.startswith("scripts/"):
                fails.append(f"{doc}:{ln}: {prog} does not exist: {cmd}")
            else:
                skipped += 1
            return
        if not helps.text(prog, sub):
            why = helps.errors.get((prog, sub))
            fails.append(f"{doc}:{ln}: `{name} --help` failed, {why} (for: {cmd})")
            return
        checked += 1
        bad = []
        base = prog.split("/")[-1]
        for opt, k in opts:
            if after is not None and base in BAKE_AFTER_DASHES:
                continue  # GNU parallel's or sbatch's options
            if opt in known or (not opt.startswith("--") and opt[:2] in known):
                continue
            if (doc, name, opt) in HISTORICAL:
                continue
            bad.append(opt)
        if bad:
            fails.append(f"{doc}:{ln}: {name}: not in its --help: {' '.join(bad)}   (in: {cmd})")
        if listing:
            print(f"{doc}:{ln}: [{label or name}] {' '.join(o for o, _ in opts)}"
                  + (f"  -- {' '.join(after)}" if after is not None else ""))
        if after is not None and base in BAKE_AFTER_DASHES:
            check(doc, ln, cmd, "vdsh-bake", after, f"{name} -- vdsh-bake")
        for opt, k in opts:
            nested, form = NESTED.get((base, opt), (None, None))
            if not nested:
                continue
            value = words[k].split("=", 1)[1] if "=" in words[k] else \
                (words[k + 1] if k + 1 < len(words) else "")
            for part in value.split(";") if form.endswith(";...") else [value]:
                if form.startswith("NAME="):
                    part = part.partition("=")[2]
                if part.strip():
                    check(doc, ln, cmd, nested, tokens(part) or [], f"{name} {opt} -> {nested}")

    for doc, ln, cmd, prog, words, written in commands:
        check(doc, ln, cmd, prog, words, None)
        # build/DIR/PROG: where this build puts PROG
        if written.startswith("build/") and prog in where:
            if written[len("build/"):] != where[prog]:
                fails.append(f"{doc}:{ln}: {written}: the build puts {prog} at build/{where[prog]}")

    # Every long option named anywhere: some program's, script's or tool's
    # (with every program built: a build without the bake cannot tell).
    if all(p in progs for p in PROGRAMS):
        known = set(o for opts in FOREIGN.values() for o in opts)
        every = [(p, None) for p in PROGRAMS] + [("python -m vdsh", "info")]
        for name in sorted(os.listdir(os.path.join(src, "scripts"))):
            path = os.path.join(src, "scripts", name)
            if os.path.isfile(path) and os.access(path, os.X_OK):
                every.append(("scripts/" + name, None))
        with concurrent.futures.ThreadPoolExecutor(8) as pool:
            list(pool.map(lambda k: helps.text(*k), every))
        for prog, sub in every:
            known |= helps.options(prog, sub) or set()
        for doc, text in docs:
            for n, line in enumerate(text.split("\n"), 1):
                for opt in LONG.findall(line):
                    if opt not in known and not any(d == doc and o == opt
                                                     for d, _, o in HISTORICAL):
                        fails.append(f"{doc}:{n}: {opt} is no program's, script's or listed "
                                     f"tool's option: {line.strip()[:120]}")
                        known.add(opt)  # once per option
    return fails, (len(commands), checked, skipped, len(script_mentions))



# The checker checked: a document with a stale option in each place a
# command can be (a continued block line, a pipe, a wrapper, an inline
# span, a script's nested bake arguments, after `&&`) must fail on
# exactly those, and not on a comment or a value.
SELF_TEST = """Prose: `vdsh-info --no-such-option x.vdsh`; see scripts/no_such_script.

    build/tools/vdsh-info --verify \\
        --bogus-two x.vdsh | head -n 3     # a comment: --not-an-option
    FOO=1 nice -n 10 scripts/frames_gap --variant 'a=--bogus-bake 1' && vdsh-info -Z x
    vdsh-view x.vdsh --light -4,2,2 --json -
"""


def self_test(src, build, progs, helps):
    fails, _ = check_docs(src, build, progs, helps, [("SELF_TEST", SELF_TEST)])
    want = {"--no-such-option", "scripts/no_such_script", "--bogus-two", "-Z"}
    if "vdsh-bake" in progs:
        want.add("--bogus-bake")
    if all(p in progs for p in PROGRAMS):
        want |= {"--no-such-option anywhere", "--bogus-two anywhere", "--bogus-bake anywhere",
                 "--not-an-option anywhere"}
    got = set()
    for f in fails:
        m = re.search(r"not in its --help: (.*?)   \(in:", f)
        if m:
            got |= set(m.group(1).split())
        elif "does not exist" in f:
            got.add(f.split(": ")[1].split()[0])
        elif "is no program's" in f:
            got.add(f.split(": ")[1].split()[0] + " anywhere")
        else:
            got.add(f)
    return [] if got == want else [f"self-test: flagged {sorted(got)}, want {sorted(want)}"]


def main():
    args = [a for a in sys.argv[1:] if a != "--list"]
    listing = "--list" in sys.argv
    src, build = args[0], args[1]
    progs = {p: os.path.abspath(path) for p, path in (a.split("=", 1) for a in args[2:])}
    helps = Helps(src, progs)
    docs = []
    for doc in doc_files(src):
        with open(os.path.join(src, doc), encoding="utf-8") as f:
            docs.append((doc, f.read()))
    fails, (found, checked, skipped, scripts) = check_docs(src, build, progs, helps, docs, listing)
    fails += self_test(src, build, progs, helps)
    print(f"docs_commands: {len(docs)} documents, {found} commands found, {checked} checked "
          f"against --help (nested ones included), {skipped} skipped (program not built), "
          f"{scripts} scripts/NAME mentioned")
    for f in fails:
        print("FAIL: " + f, file=sys.stderr)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
