#!/usr/bin/env bash
# Python in scripts/ is Debian's /usr/bin/python3 (tests/CMakeLists.txt),
# named once, in the shebang: every Python program in scripts/ (a file
# with a python shebang, or a .py no script imports) starts with
# "#!/usr/bin/python3" and is executable, and the scripts run them as
# themselves, not through an interpreter named at the call
# (scripts/obj_to_glb.py had no shebang, and its two callers named
# /usr/bin/python3 each their own way). Then obj_to_glb.py, run so,
# writes a .glb of a one-triangle OBJ.
# Usage: test_scripts_python.sh SOURCE_DIR WORK
set -u
src=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
fail=0
files=()
for f in "$src"/scripts/*; do
  [[ -f $f ]] && files+=("$f")
done
progs=()
for f in "${files[@]}"; do
  name=$(basename "$f")
  first=$(head -n 1 "$f")
  # a .py that no script imports is a program (vdsh_scenes.py is a module)
  program=0
  [[ $name == *.py ]] && ! grep -qE "^ *(import|from) ${name%.py}\b" "${files[@]}" && program=1
  if [[ $first == '#!'*python* || $program -eq 1 ]]; then
    progs+=("$name")
    if [[ $first != '#!/usr/bin/python3' ]]; then
      echo "FAIL: scripts/$name: first line '$first', want '#!/usr/bin/python3'" >&2
      fail=1
    fi
    [[ -x $f ]] || { echo "FAIL: scripts/$name: not executable" >&2; fail=1; }
    # its callers run it as itself
    if grep -nE "(python3?|\\\$py|\\\$\\{py\\})[\"']? +[\"']?[^ ]*scripts/$name\\b" "${files[@]}" >&2; then
      echo "FAIL: scripts/$name: run through an interpreter named at the call (above)" >&2
      fail=1
    fi
  fi
done
[[ " ${progs[*]} " == *" obj_to_glb.py "* ]] || { echo "FAIL: obj_to_glb.py not seen as a Python program" >&2; fail=1; }

printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nf 1//1 2//2 3//3\n' > "$work/tri.obj"
if ! "$src/scripts/obj_to_glb.py" "$work/tri.obj" "$work/tri.glb"; then
  echo "FAIL: scripts/obj_to_glb.py does not run as a program" >&2
  fail=1
elif [[ $(head -c 4 "$work/tri.glb") != glTF ]]; then
  echo "FAIL: scripts/obj_to_glb.py wrote no .glb" >&2
  fail=1
fi
[[ $fail -eq 0 ]] && echo "scripts: ${#progs[@]} Python programs, each #!/usr/bin/python3 and run as itself"
exit $fail
