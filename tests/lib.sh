# tests/lib.sh - what the shell tests share. Sourced after `set -u`:
#   . "$(dirname "$0")/lib.sh"
# A test counts its failures in $fail (set to 0 here) and ends with
# `exit $fail`; the helpers below only ever set it to 1.

fail=0
test_lib_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

make_tmp() { # make_tmp: $tmp, a fresh folder removed when the test exits
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
}

check() { # check DESCRIPTION COMMAND...
  local what=$1; shift
  if ! "$@"; then echo "FAIL: $what" >&2; fail=1; fi
}

expect_exit() { # expect_exit CODE DESCRIPTION COMMAND...: stdout and stderr in $tmp
  local want=$1 what=$2; shift 2
  "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
  local got=$?
  if [[ $got -ne $want ]]; then
    echo "FAIL: $what: exit $got, want $want; stderr:" >&2; cat "$tmp/err.txt" >&2; fail=1
  fi
}

says() { # says DESCRIPTION TEXT: the last command's stderr holds TEXT
  if ! grep -qF -- "$2" "$tmp/err.txt"; then
    echo "FAIL: $1: stderr lacks '$2':" >&2; cat "$tmp/err.txt" >&2; fail=1
  fi
}

says_any() { # says_any DESCRIPTION TEXT: the last command's stderr or stdout holds TEXT
  if ! grep -qF -- "$2" "$tmp/err.txt" "$tmp/out.txt"; then
    echo "FAIL: $1: output lacks '$2':" >&2; cat "$tmp/err.txt" >&2; fail=1
  fi
}

room_box_pair() { # room_box_pair < OBJ_LINES: $tmp/a.obj the room (10 x 4 x
  # 10, faces inward; a unit box on its floor), $tmp/b.obj the same with
  # the lines read from stdin added
  local room=$test_lib_dir/data/room_box.obj
  cat "$room" >"$tmp/a.obj"
  { cat "$room"; cat; } >"$tmp/b.obj"
}

check_recipe_usage() { # check_recipe_usage SCRIPT: scripts/SCRIPT (needs
  # $scripts) without arguments exits 2 with its usage line, a text that is
  # the header comment only (issue 26), and the same line for --help
  local name=$1 usage rc
  usage=$("$scripts/$name" 2>&1); rc=$?
  [[ $rc -eq 2 ]] || { echo "FAIL: $name without arguments exits $rc, not 2" >&2; fail=1; }
  grep -q "scripts/$name N OUT.vdsh" <<<"$usage" || { echo "FAIL: no usage line: $usage" >&2; fail=1; }
  if grep -qE 'set -e|pipefail|^if |^fi' <<<"$usage"; then
    echo "FAIL: the usage text shows code:" >&2; echo "$usage" | tail -3 >&2; fail=1
  fi
  "$scripts/$name" --help 2>/dev/null | grep -q "scripts/$name N OUT.vdsh" ||
    { echo "FAIL: $name --help" >&2; fail=1; }
  # No '--' (every word went to the scheduler: parallel ran the mesh as a
  # command, exit 127), or nothing after it: usage errors, before anything runs.
  local args
  for args in "2 nodash.vdsh builtin:room --max-edge 1" "2 nodash.vdsh -j 2 --"; do
    usage=$(cd "${TMPDIR:-/tmp}" && "$scripts/$name" $args 2>&1); rc=$?
    [[ $rc -eq 2 && $usage == *"'--'"* && $usage == "$name: "* ]] ||
      { echo "FAIL: $name $args: exit $rc, not 2 naming '--': $usage" >&2; fail=1; }
  done
  [[ -e ${TMPDIR:-/tmp}/nodash.vdsh ]] && { echo "FAIL: $name wrote nodash.vdsh" >&2; fail=1; }
}
