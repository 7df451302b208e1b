#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs every test of every package and
# ends with one line "N passed, N failed". Exits non-zero if anything failed or did not run.
set -uo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/scripts/install_deps.sh" || exit 1
"$here/scripts/build.sh" -j2 || { echo "0 passed, 1 failed"; exit 1; }
source "$here/scripts/ros_env.sh"
# The tests talk only to themselves: on loopback they need no resolvable host name (a fresh container
# or chroot may not list its own in /etc/hosts), and in a network namespace that holds only loopback
# they listen on no network, as scripts/rig_launch.sh.
export ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
results="$RIG_WS/build/test_results"
rm -rf "$results"
# A step that did not finish: the end of its log, and the one-line verdict.
step_failed() {
  tail -n 50 "$1"
  echo "0 passed, 1 failed"
  exit 1
}
# The test programs build on both cores; the tests then run one at a time: several watch a live rig
# against the wall clock (its pace, its services' answers), and two at once share the machine's cores.
catkin_make -C "$RIG_WS" --source "$RIG_ROOT" tests -j2 >"$RIG_WS/build_tests.log" 2>&1 ||
  step_failed "$RIG_WS/build_tests.log"
# catkin_make run_tests exits 0 even when tests fail: the verdict comes from catkin_test_results.
# The rviz test draws: the tests run on a virtual screen (Xvfb, software GL).
"$here/scripts/loopback_only.sh" xvfb-run -a -s "-screen 0 1400x900x24" \
  catkin_make -C "$RIG_WS" --source "$RIG_ROOT" run_tests -j1 >"$RIG_WS/run_tests.log" 2>&1 ||
  step_failed "$RIG_WS/run_tests.log"
# catkin_test_results decides pass/fail; count_results.py counts (catkin's summary counts gtest twice).
catkin_test_results "$results" >/dev/null 2>&1
verdict=$?
catkin_test_results --all "$results" 2>&1 | grep -E 'FAILURE|ERROR|Failure|failed' | head -n 40 || true
/usr/bin/python3 "$RIG_ROOT/tests/count_results.py" "$results"
counted=$?
[ "$verdict" -eq 0 ] && [ "$counted" -eq 0 ]
