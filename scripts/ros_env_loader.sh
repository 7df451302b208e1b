#!/usr/bin/env bash
# env-loader for <machine> tags: the rig's environment on a remote host, then the given command.
source "$(dirname "$0")/ros_env.sh"
source "$RIG_WS/devel/setup.bash"
exec "$@"
