# scripts/shard_args.sh - sourced by scripts/bake-parallel and
# scripts/bake-slurm (not run): the checks of their command line that both
# make, in the same words.
#
#   shard_count PROG N           N is a whole number >= 1, else exit 2
#   shard_bake_args PROG USAGE ARGS...
#                                ARGS (what follows the scheduler's options)
#                                start with '--' and hold vdsh-bake's
#                                arguments, none of them -o, --output or
#                                --shard, nor an abbreviation getopt_long
#                                takes for them (the script sets those), else
#                                exit 2;
#                                sets shard_args to those arguments less
#                                any --report FILE, and shard_report to
#                                FILE (else empty): every shard writing
#                                FILE, the last one won; the caller gives
#                                each shard its own: FILE less .json, then
#                                .part-I.json, beside FILE (like the parts)
#   shard_sh_quote ARGS...       ARGS as words any POSIX sh reads back
#                                (eval "set -- $(shard_sh_quote ...)"): each
#                                in single quotes, a ' as '\'' (bash's %q
#                                writes $'...' for a newline: not sh's)
#   shard_out_dir PROG OUT       OUT's folder exists and is writable, else
#                                exit 1 naming it (bake-slurm made an absolute
#                                path of a missing folder as "/OUT": the root)
#   shard_stale_parts PROG N STEM
#                                a part STEM.part-I.vdsh with I >= N (an
#                                earlier run with more shards) is refused:
#                                exit 1 naming it
#   shard_stale_reports PROG N STEM REPORT_STEM
#                                a report REPORT_STEM.part-I.json (empty
#                                REPORT_STEM: none) with I >= N, or whose part
#                                STEM.part-I.vdsh is not there (its shard
#                                bakes again), is removed: a rerun with fewer
#                                shards kept the extra ones beside the new

shard_count() {
  [[ $2 =~ ^[1-9][0-9]*$ ]] || { echo "$1: N is a whole number >= 1, not '$2'" >&2; exit 2; }
}

shard_bake_args() {
  local prog=$1 synopsis=$2 a
  shift 2
  # Without '--' every word would go to the scheduler (the mesh as its option or command).
  if [[ $# -eq 0 ]]; then
    echo "$prog: no '--' before vdsh-bake's arguments: $synopsis" >&2
    exit 2
  fi
  shift
  if [[ $# -eq 0 ]]; then
    echo "$prog: no vdsh-bake arguments after '--' (the meshes and options every shard bakes)" >&2
    exit 2
  fi
  shard_args=() shard_report=""
  while [[ $# -gt 0 ]]; do # the script writes OUT and the shards: none of vdsh-bake's own
    a=$1
    shift
    # getopt_long takes any unique prefix of a long option: --ou, --sh ...
    local name=${a%%=*}
    [[ $a =~ ^-o || ( $name == --??* && ( "--output" == "$name"* || "--shard" == "$name"* ) ) ]] &&
      { echo "$prog: '$a' among vdsh-bake's arguments: the output is OUT (the second argument) and the script sets --shard" >&2; exit 2; }
    # --report and its abbreviations (getopt_long takes --rep, --repo ...).
    if [[ $a =~ ^--rep(o|or|ort)?(=.*)?$ ]]; then
      if [[ $a == *=* ]]; then
        shard_report=${a#*=}
      elif [[ $# -gt 0 ]]; then
        shard_report=$1
        shift
      else
        echo "$prog: '$a' without a FILE among vdsh-bake's arguments" >&2
        exit 2
      fi
      [[ -n $shard_report ]] || { echo "$prog: '$a' with an empty FILE among vdsh-bake's arguments" >&2; exit 2; }
      continue
    fi
    shard_args+=("$a")
  done
  [[ ${#shard_args[@]} -gt 0 ]] ||
    { echo "$prog: no vdsh-bake arguments after '--' (the meshes and options every shard bakes)" >&2; exit 2; }
  return 0
}

shard_out_dir() {
  local dir
  dir=$(dirname -- "$2")
  if [[ ! -d $dir ]]; then
    echo "$1: no folder '$dir' for $2 (and its parts): create it first; nothing run" >&2
    exit 1
  fi
  if [[ ! -w $dir ]]; then
    echo "$1: the folder '$dir' of $2 is not writable: nothing run" >&2
    exit 1
  fi
  return 0
}

shard_stale_parts() { # shard_stale_parts PROG N STEM
  local prog=$1 n=$2 stem=$3 f i
  for f in "$stem".part-*.vdsh; do
    [[ -e $f ]] || continue
    i=${f#"$stem".part-}
    i=${i%.vdsh}
    if [[ $i =~ ^(0|[1-9][0-9]*)$ ]] && ((i >= n)); then
      echo "$prog: '$f' is a part of a bake with more than $n shards: remove it (or rerun with that count); nothing run" >&2
      exit 1
    fi
  done
  return 0
}

shard_stale_reports() { # shard_stale_reports PROG N STEM REPORT_STEM
  local prog=$1 n=$2 stem=$3 rstem=$4 f i
  [[ -n $rstem ]] || return 0
  for f in "$rstem".part-*.json; do
    [[ -e $f ]] || continue
    i=${f#"$rstem".part-}
    i=${i%.json}
    [[ $i =~ ^(0|[1-9][0-9]*)$ ]] || continue # not one of ours
    if ((i >= n)) || [[ ! -e $stem.part-$i.vdsh ]]; then
      rm -f -- "$f" || { echo "$prog: cannot remove the stale report '$f': nothing run" >&2; exit 1; }
      if ((i >= n)); then
        echo "$prog: removed '$f', the report of a shard of an earlier bake with more shards" >&2
      fi
    fi
  done
  return 0
}

shard_sh_quote() {
  local a q=\' out="" sep=""
  for a in "$@"; do
    out+="$sep'${a//$q/$q\\$q$q}'"
    sep=" "
  done
  printf '%s' "$out"
}
