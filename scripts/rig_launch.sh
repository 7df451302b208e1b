#!/usr/bin/env bash
# Runs roslaunch with a private master on 127.0.0.1 and a free port, so that the rig disturbs no other
# ROS system on the machine, in a network of its own that holds only loopback (scripts/loopback_only.sh),
# so that it listens on no network.
#   scripts/rig_launch.sh launch/rig.launch [arg:=value]...
#   scripts/rig_launch.sh friction_sim rig.launch [arg:=value]...   (or any package's launch file)
#   FRICTION_RIG_NETWORK=host scripts/rig_launch.sh ...   (the machine's network, e.g. for other hosts)
# The caller's environment stays (their overlay and packages: a launch file may start their own nodes);
# the rig's workspace is added to it. Output that is not a terminal carries no colour or title codes.
# Exit status: 0 only if roslaunch and every node it ran ended cleanly. roslaunch itself exits 0 when a
# node refuses its scene or protocol or crashes, so the nodes' exit codes are read from roslaunch's log
# afterwards and a failing node is named, with status 1, so that scripts and sweeps can tell a failed
# run from a run. 130 when interrupted (Ctrl-C, kill, hang-up), after roslaunch has stopped every node.
set -euo pipefail

case "${FRICTION_RIG_NETWORK:-private}" in
  private)
    # Once through scripts/loopback_only.sh, which runs this script again in the same process.
    [ "${FRICTION_RIG_NAMESPACE:-}" = "$$" ] ||
      FRICTION_RIG_NAMESPACE=$$ exec "$(dirname "$0")/loopback_only.sh" bash "$0" "$@"
    ;;
  host) echo "rig_launch: FRICTION_RIG_NETWORK=host: the rig's nodes listen on every network interface" >&2 ;;
  *)
    echo "rig_launch: FRICTION_RIG_NETWORK: value '$FRICTION_RIG_NETWORK' is not allowed; allowed: private, host" >&2
    exit 2
    ;;
esac
namespace_entry=""
[ "${FRICTION_LOOPBACK_NAMESPACE:-}" != "$$" ] || namespace_entry="nsenter --target $$ --user --net --preserve-credentials"

source "$(dirname "$0")/ros_env.sh"
caller_package_path="${ROS_PACKAGE_PATH:-}"
set +u; source "$RIG_WS/devel/setup.bash" --extend; set -u
# The setup rebuilds ROS_PACKAGE_PATH from the workspaces: packages the caller listed by hand stay too.
export ROS_PACKAGE_PATH="$ROS_PACKAGE_PATH${caller_package_path:+:$caller_package_path}"
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
export ROS_HOME="${ROS_HOME:-$RIG_WS/ros_home}"
# The nodes' log lines reach a pipe (a filter, a test, a file) as they are written and in order with
# roslaunch's own, not in blocks when a node ends.
export ROSCONSOLE_STDOUT_LINE_BUFFERED="${ROSCONSOLE_STDOUT_LINE_BUFFERED:-1}"
echo "rig_launch: private master at $ROS_MASTER_URI; to reach it from another shell:"
[ -z "$namespace_entry" ] || echo "  $namespace_entry bash   (the rig's own network: loopback only)"
echo "  source $RIG_WS/devel/setup.bash; export ROS_MASTER_URI=$ROS_MASTER_URI ROS_IP=127.0.0.1"

# roslaunch runs its nodes in $ROS_HOME: a relative scene, protocol or bag path on the command line is
# taken from the directory the user is in, as they would expect, not from there.
relative_path_argument='^(scene|protocol|bag):=([^/$].*)$'
arguments=()
for argument in "$@"; do
  [[ "$argument" =~ $relative_path_argument ]] && argument="${BASH_REMATCH[1]}:=$PWD/${BASH_REMATCH[2]}"
  arguments+=("$argument")
done

# roslaunch colours its own lines and sets the terminal's title, and rosconsole colours warnings,
# whatever the output is: into a file or a pipe they go through a filter that drops the codes.
without_codes() { sed -u -E $'s/\x1b\\][^\x07]*\x07//g; s/\x1b\\[[0-9;?]*[A-Za-z]//g'; }
filters=()
launch_options=()
if [ -t 1 ]; then exec 3>&1; else exec 3> >(trap "" INT TERM HUP; without_codes); filters+=($!); launch_options+=(--disable-title); fi
if [ -t 2 ]; then exec 4>&2; else exec 4> >(trap "" INT TERM HUP; without_codes >&2); filters+=($!); fi

launched_after=$(mktemp)
finish() {
  rm -f "$launched_after"
  exec 3>&- 4>&-
  [ "${#filters[@]}" -eq 0 ] || wait "${filters[@]}" 2>/dev/null || true
}
trap finish EXIT
# roslaunch runs as a job of its own, so that this script can read its log when it ends and pass on a
# signal meanwhile; job control keeps it from starting with SIGINT ignored, as a script's background
# jobs otherwise do. Every signal is passed on as SIGINT, on which roslaunch stops its nodes cleanly.
set -m
roslaunch --port "$port" "${launch_options[@]}" "${arguments[@]}" >&3 2>&4 &
launch_pid=$!
interrupted=0
trap 'interrupted=1; kill -INT "$launch_pid" 2>/dev/null || true' INT TERM HUP
while :; do
  launch_status=0
  wait "$launch_pid" || launch_status=$?
  kill -0 "$launch_pid" 2>/dev/null || break  # still running: the wait was cut short by a signal
done
if [ "$interrupted" -eq 1 ]; then
  echo "rig_launch: interrupted" >&2
  exit 130
fi
[ "$launch_status" -eq 0 ] || exit "$launch_status"

# roslaunch names its log after its pid.
launch_log=$(find "${ROS_LOG_DIR:-$ROS_HOME/log}" -name "roslaunch-*-$launch_pid.log" -newer "$launched_after" \
             2>/dev/null | head -n 1)
if [ -z "$launch_log" ]; then
  echo "rig_launch: roslaunch wrote no log (it launched nothing?), so no node's exit code was checked" >&2
  exit 0
fi
# A node that ends by itself with a non-zero code, or is killed by a signal (a negative code), is logged
#   process has died [pid 8609, exit code 2, cmd /path/to/stage_controller __name:=controller ...
# Nodes that roslaunch stops at shutdown are logged as killed, not as died.
failures=$(grep -oE 'process has died \[pid [0-9]+, exit code -?[1-9][0-9]*, cmd [^ ]+' "$launch_log" |
           sed -E 's|.*exit code (-?[0-9]+), cmd .*/([^/]+)$|\2 (exit code \1)|' || true)
if [ -n "$failures" ]; then
  echo "rig_launch: failed: $(echo "$failures" | paste -sd, - | sed 's/,/, /g'); the reasons are above or in" \
       "the nodes' logs in $(dirname "$launch_log")" >&2
  exit 1
fi
