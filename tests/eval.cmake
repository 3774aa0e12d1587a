# The evaluator (bake/eval/eval.h, vdsh-eval): reconstruction against ray-cast
# ground truth on generated scenes and builtin:room (no files needed).
#   eval_<name>  test_eval.c, one part each (see its header): the test's
#                name states what the part checks
#   eval_cli     vdsh-bake + vdsh-eval end to end: exit codes, messages,
#                the JSON and the per-vertex file
#   eval_json    the JSON parses and holds what the sweep reads, and the
#                light rule it was scored with
if(TARGET vb_eval)
  add_executable(test_eval ${CMAKE_CURRENT_LIST_DIR}/test_eval.c)
  target_link_libraries(test_eval PRIVATE vb_eval)
  # test name : test_eval part
  foreach(pair heldout:heldout interpolate:interpolate sources:sources
               sphere_error_matches_analytic:sphere room_error_falls_with_order:room
               fits_beat_paper_projection:methods oracle_exact_threads_identical:oracle
               lights_around_closed_object_same_with_room:lights)
    string(REPLACE ":" ";" pair ${pair})
    list(GET pair 0 name)
    list(GET pair 1 part)
    add_test(NAME eval_${name} COMMAND test_eval ${part})
  endforeach()

  add_executable(test_eval_cli ${CMAKE_CURRENT_LIST_DIR}/test_eval_cli.c)
  target_link_libraries(test_eval_cli PRIVATE vdsh_format vt_tools)
  add_test(NAME eval_cli
           COMMAND test_eval_cli $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval>
                   ${CMAKE_CURRENT_BINARY_DIR}/eval_cli)

  # The table's columns line up with its header: the default bake's
  # streams (s8s6, decision+log: 4 and 12 characters where the columns were
  # 3 and 9 wide) pushed every column after them out of line; and a paper
  # f32 stream of the usual widths keeps the old bytes (columns 3 and 9).
  add_test(NAME eval_table_columns COMMAND bash -c [=[
bake=$1; ev=$2; d=$3
rm -rf "$d"; mkdir -p "$d"
for m in decision paper; do
  "$bake" builtin:room --max-edge 2 --rays 16 --cube-size 0 --orders 2 --method $m \
    $([ $m = paper ] && echo --encoding f32) -q -o "$d/$m.vdsh" || exit 1
  "$ev" "$d/$m.vdsh" -q --points 100 --interior 0 --directions 16 --lights 2 > "$d/$m.txt" || exit 1
  # every line of the two tables: its first '|' where the header has it
  awk '/ order offset B\/v/ { bar = index($0, "|"); n++; next }
       bar && /^  vertices .*[|]/ { if (index($0, "|") != bar) { print "FAIL: " $0; bad = 1 }; rows++ }
       /^$/ { bar = 0 }
       END { if (n != 2 || rows < 2) { print "FAIL: " n " tables, " rows " rows"; bad = 1 }; exit bad }' \
    "$d/$m.txt" || { cat "$d/$m.txt"; exit 1; }
done
grep -q " 16 f32 paper     | " "$d/paper.txt" || { echo "FAIL: paper f32 not in columns 3 and 9"; cat "$d/paper.txt"; exit 1; }
]=] sh $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> ${CMAKE_CURRENT_BINARY_DIR}/eval_table_columns)

  find_package(Python3 COMPONENTS Interpreter QUIET)
  if(Python3_Interpreter_FOUND)
    add_test(NAME eval_json
             COMMAND ${Python3_EXECUTABLE} -c
"import json, subprocess, sys, os, tempfile
bake, ev = sys.argv[1], sys.argv[2]
d = tempfile.mkdtemp()
f = os.path.join(d, 'room.vdsh')
subprocess.run([bake, 'builtin:room', '--max-edge', '1', '--rays', '64', '--method', 'paper', '--orders', '2,5',
                '--encoding', 'f32', '-q', '--record-timings', '--cube-size', '0', '-o', f], check=True)
subprocess.run([ev, f, '-q', '--interior', '500', '--points', '700', '--json', f + '.json'],
               check=True, stdout=subprocess.DEVNULL)
j = json.load(open(f + '.json'))
assert j['scene']['sources'][0]['name'] == 'builtin:room', j['scene']
assert j['bake']['rays'] == 64 and j['bake']['seconds'] > 0, j['bake']
assert j['bake']['seconds_from'] == 'time chunk'
assert [s['order'] for s in j['streams']] == [2, 5]
s = j['streams'][1]
assert s['bytes_per_vertex'] == 100 and s['encoding'] == 'f32' and s['method'] == 'paper'
for k in ('vertices', 'interior'):
    m = s[k]
    for key in ('distance_rms', 'distance_rms_se', 'distance_p50', 'distance_p90', 'distance_p99',
                'shadow_mae', 'shadow_mae_se', 'false_shadow', 'light_leak', 'binary_mae',
                'binary_false_shadow', 'binary_light_leak', 'worst'):
        assert key in m, key
    assert 0 < m['shadow_mae'] < 1 and len(m['worst']) == 10
assert j['truth']['vertices']['receivers'] == 700 and j['truth']['interior']['receivers'] == 500
assert j['eval']['directions'] == 64
assert j['eval']['scene_light_rule'] == 'uniform', j['eval']
# --light-rule: recorded, and the lights where the rule puts them (ceiling:
# the top fifth of the height)
r = subprocess.run([ev, f, '--interior', '0', '--points', '300', '--light-rule', 'ceiling',
                    '--json', f + '.c.json'], check=True, stdout=subprocess.PIPE, text=True)
assert \"light rule 'ceiling'\" in r.stdout, r.stdout
j = json.load(open(f + '.c.json'))
assert j['eval']['scene_light_rule'] == 'ceiling', j['eval']
lo, hi = j['scene']['bounds_min'][1], j['scene']['bounds_max'][1]
ys = [p[1] for p in j['eval']['scene_light_positions']]
assert ys and min(ys) >= lo + 0.8 * (hi - lo) - 1e-4 * (hi - lo), (lo, hi, min(ys))
# grown: in the bounds grown by a quarter of the diagonal, but not beyond
# a side a one-sided surface closes: the room's inward shell closes all
# six, so its grown lights stay in the bounds (9 of 32 stood outside its
# walls, lighting nothing in it); around and shell (outside the bounds,
# grown by a diagonal and a quarter) stop at the same closed sides, so a
# closed room has no room for them: said, exit 1
subprocess.run([ev, f, '-q', '--interior', '0', '--points', '300', '--light-rule', 'grown',
                '--json', f + '.g.json'], check=True, stdout=subprocess.DEVNULL)
j = json.load(open(f + '.g.json'))
assert j['eval']['scene_light_rule'] == 'grown', j['eval']
blo, bhi = j['scene']['bounds_min'], j['scene']['bounds_max']
ps = j['eval']['scene_light_positions']
assert len(ps) == 32
for p in ps:
    assert all(blo[k] <= p[k] <= bhi[k] for k in range(3)), p
for rule in ('around', 'shell'):
    r = subprocess.run([ev, f, '-q', '--interior', '0', '--points', '300', '--light-rule', rule,
                        '--json', f + '.s.json'], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True)
    assert r.returncode == 1 and 'no room for' in r.stderr and rule in r.stderr, (rule, r)
    assert not os.path.exists(f + '.s.json'), rule
print('ok')"
             $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval>)
  endif()
endif()

#   eval_offsets    vdsh-eval --offsets: a copy at offset 0 scores as the
#                   stream (fixed and adaptive order) and reports its bytes
if(TARGET vdsh-eval AND Python3_Interpreter_FOUND)
  add_test(NAME eval_offsets
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_eval_offsets.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> ${CMAKE_CURRENT_BINARY_DIR}/eval_offsets)
endif()

#   eval_closed_object  a closed cube fills its bounds: the default bake runs
#                       the decision fit, vdsh-eval places its lights around
#                       it by every rule (formats/vdsh_light.h's light region)
if(TARGET vdsh-eval AND Python3_Interpreter_FOUND)
  add_test(NAME eval_closed_object
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_closed_object.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> ${CMAKE_CURRENT_BINARY_DIR}/eval_closed_object)
endif()

#   eval_decision_shell  vdsh-bake --decision-shell 4 on a unit cube on a
#                        4 x 4 floor: under lights around it (--light-rule
#                        grown) the interior false shadows at orders 3 and
#                        5 fall below the default bake's (docs/ACCURACY.md,
#                        "A mixed pool for objects")
if(TARGET vdsh-eval AND Python3_Interpreter_FOUND)
  add_test(NAME eval_decision_shell
           COMMAND ${Python3_EXECUTABLE} -c
"import json, os, subprocess, sys, tempfile
bake, ev = sys.argv[1], sys.argv[2]
d = tempfile.mkdtemp()
obj = os.path.join(d, 'cube_floor.obj')
v = [(-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2)] + [(x, y, z) for y in (0, 1)
     for x, z in ((-.5, -.5), (.5, -.5), (.5, .5), (-.5, .5))]
f = [(1, 2, 3), (1, 3, 4), (5, 9, 10), (5, 10, 6), (6, 10, 11), (6, 11, 7), (7, 11, 12),
     (7, 12, 8), (8, 12, 9), (8, 9, 5), (9, 12, 11), (9, 11, 10)]
open(obj, 'w').write(''.join('v %g %g %g\\n' % p for p in v) + ''.join('f %d %d %d\\n' % t for t in f))
false = {}
for name, extra in (('default', []), ('shell', ['--decision-shell', '4'])):
    out = os.path.join(d, name + '.vdsh')
    subprocess.run([bake, obj, '--max-edge', '0.1', '--rays', '64', '--cube-size', '0', '-q',
                    '-o', out] + extra, check=True)
    subprocess.run([ev, out, '-q', '--json', out + '.json', '--points', '5000', '--interior',
                    '5000', '--light-rule', 'grown', '--seed', '202'], check=True,
                   stdout=subprocess.DEVNULL)
    false[name] = {s['order']: s['scene_lights']['interior']['false_shadow']
                   for s in json.load(open(out + '.json'))['streams']}
for o in (3, 5):
    assert false['shell'][o] < false['default'][o], (o, false)
print('ok', false)"
             $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval>)
endif()

#   light_region  vdsh-bake --light-region (auto, grown, a box): refused
#                 values, the default's bytes, the lreg chunk in both
#                 readers, threads and shards, vdsh-eval's lights where
#                 the file says, and under lights around an object fewer
#                 false shadows than the default's (docs/ACCURACY.md,
#                 "Where your lights go")
if(TARGET vdsh-eval AND Python3_Interpreter_FOUND)
  add_test(NAME light_region
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/test_light_region.py
                   $<TARGET_FILE:vdsh-bake> $<TARGET_FILE:vdsh-eval> $<TARGET_FILE:vdsh-merge>
                   $<TARGET_FILE:vdsh-info> ${PROJECT_SOURCE_DIR}
                   ${CMAKE_CURRENT_BINARY_DIR}/light_region)
endif()
