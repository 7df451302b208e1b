#!/usr/bin/env bash
# Runs a command in a network namespace of its own that holds only loopback, so that nothing it starts
# listens on the machine's networks: roscpp binds every node's XML-RPC and TCPROS servers to all
# interfaces, and nothing in ROS 1 binds them to one. A new user namespace maps the caller to root in
# it, so no privilege is needed. Where the system gives no such namespace (unprivileged user namespaces
# turned off), it says so and runs the command in the machine's network.
#   scripts/loopback_only.sh COMMAND [ARG]...
# Every step execs, so the command keeps this process's pid, PID: `nsenter --target PID --user --net
# --preserve-credentials` enters its network. Inside, FRICTION_LOOPBACK_NAMESPACE holds that pid.
set -euo pipefail
if [ "${FRICTION_LOOPBACK_NAMESPACE:-}" = "$$" ]; then
  /usr/bin/python3 -c '
import fcntl, socket, struct
probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
request = struct.pack("16sh22x", b"lo", 0)  # struct ifreq: the name, then the flags
flags = struct.unpack("16sh22x", fcntl.ioctl(probe, 0x8913, request))[1]  # SIOCGIFFLAGS
fcntl.ioctl(probe, 0x8914, struct.pack("16sh22x", b"lo", flags | 1))  # SIOCSIFFLAGS with IFF_UP'
  exec "$@"
fi
if unshare --user --map-root-user --net true 2>/dev/null; then
  FRICTION_LOOPBACK_NAMESPACE=$$ exec unshare --user --map-root-user --net -- bash "$0" "$@"
fi
echo "loopback_only: WARNING: this system gives no private network namespace (unshare --user --net" \
     "failed): '$*' runs in the machine's network, where its servers listen on every interface" >&2
exec "$@"
