#!/usr/bin/env bash
# sweep.py over real ssh hosts on this machine: two network namespaces on a private bridge, each with
# its own sshd (Debian's openssh-server). Host 1 shares this machine's file system; host 2 sees its own
# disk over the sweep's output directory (a mount namespace), so its runs reach this machine only through
# rsync. Mid-sweep, every process of host 2 is killed: its running job must be retried on host 1, and
# every run, also those host 2 finished before, must end up here. Then a rerun must redo nothing.
#   scripts/check_sweep_hosts.sh        (as root; needs openssh-server, rsync, GNU parallel, iproute2
#                                        and the workspace built; about a minute)
# Exit status 0 and "sweep over ssh hosts: passed" if all of that holds.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
[ "$(id -u)" -eq 0 ] || { echo "check_sweep_hosts: run it as root (network namespaces, sshd)" >&2; exit 2; }
for tool in /usr/sbin/sshd ssh rsync parallel ip; do
  command -v "$tool" >/dev/null || { echo "check_sweep_hosts: $tool is missing" >&2; exit 2; }
done
work="$(mktemp -d /tmp/sweep_hosts.XXXXXX)"
bridge=frsweep0
net=10.231.7
hosts=(frsweep1 frsweep2)
cleanup() {
  for ns in "${hosts[@]}"; do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -9 2>/dev/null || true
    ip netns del "$ns" 2>/dev/null || true
  done
  ip link del "$bridge" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "check_sweep_hosts: FAILED: $*" >&2; exit 1; }

ip link add "$bridge" type bridge
ip addr add "$net.1/24" dev "$bridge"
ip link set "$bridge" up
ssh-keygen -q -t ed25519 -N '' -f "$work/host_key"
ssh-keygen -q -t ed25519 -N '' -f "$work/client_key"
cp "$work/client_key.pub" "$work/authorized_keys"
mkdir -p /run/sshd "$work/disk2"
out="$work/out"
mkdir -p "$out"
for i in 1 2; do
  ns=${hosts[$((i - 1))]}
  ip netns add "$ns"
  ip link add "veth$i" type veth peer name eth0 netns "$ns"
  ip link set "veth$i" master "$bridge" up
  ip -n "$ns" addr add "$net.1$i/24" dev eth0
  ip -n "$ns" link set eth0 up
  ip -n "$ns" link set lo up
  printf '%s\n' "ListenAddress $net.1$i" "HostKey $work/host_key" "AuthorizedKeysFile $work/authorized_keys" \
    "PermitRootLogin prohibit-password" "StrictModes no" "UsePAM no" "PidFile $work/sshd$i.pid" >"$work/sshd$i.conf"
done
ip netns exec "${hosts[0]}" /usr/sbin/sshd -f "$work/sshd1.conf"
ip netns exec "${hosts[1]}" unshare --mount --propagation private \
  sh -c "mount --bind '$work/disk2' '$out' && exec /usr/sbin/sshd -f '$work/sshd2.conf'"
export PARALLEL_SSH="ssh -i $work/client_key -F /dev/null -o BatchMode=yes -o StrictHostKeyChecking=no -o UserKnownHostsFile=/dev/null -o LogLevel=ERROR"
for i in 1 2; do $PARALLEL_SSH "$net.1$i" true || fail "host $i does not answer ssh"; done

# Eight runs of the 2D slider's first 20 ms with full dynamics, about 4 s each.
cat >"$work/sweep.yaml" <<YAML
base: friction_sim/scenes/pmma_2d.yaml
set: {stop.time: 0.02, integrator.fast_forward: false}
vary:
  load.normal_force: [1000, 1250, 1500, 1750, 2000, 2250, 2500, 2750]
YAML
sweep() { /usr/bin/python3 "$root/scripts/sweep.py" "$work/sweep.yaml" --hosts "1/$net.11,1/$net.12" --out "$out"; }
sweep >"$work/first.log" 2>&1 &
sweep_pid=$!
# Host 2 dies once it has finished a run (its results are back here) and is a second into another.
for _ in $(seq 600); do
  given=$(ls "$work/disk2/runs" 2>/dev/null | wc -l || true)
  finished=$(find "$work/disk2/runs" -name summary.txt 2>/dev/null | wc -l || true)
  [ "$finished" -ge 1 ] && [ "$given" -gt "$finished" ] && break
  sleep 0.1
done
sleep 1
finished_on_2=$(find "$work/disk2/runs" -name summary.txt | wc -l)
ip netns pids "${hosts[1]}" | xargs -r kill -9
echo "killed host 2 after it finished $finished_on_2 run(s)"
wait "$sweep_pid" || true
cat "$work/first.log"
runs=$(ls "$out/runs" | wc -l)
done_here=$(find "$out/runs" -name summary.txt | wc -l)
[ "$runs" -eq 8 ] && [ "$done_here" -eq 8 ] || fail "$done_here of $runs runs have their results here"
grep -q "8 of 8 runs done" "$work/first.log" || fail "the sweep did not report 8 of 8 runs done"
# Every run host 2 finished is here too, brought back by rsync.
for summary in $(cd "$work/disk2" && find runs -name summary.txt); do
  cmp -s "$work/disk2/$summary" "$out/$summary" || fail "$summary finished on host 2 but is not here"
done
# Host 2 was sent runs it never finished (their command.sh reached its disk): they were run again on host 1.
retried=$(( $(ls "$work/disk2/runs" | wc -l) - finished_on_2 ))
echo "runs host 2 was given and never finished, finished on host 1: $retried"
[ "$retried" -ge 1 ] || fail "host 2 was killed between runs, not during one"
before=$(stat -c %Y "$out"/runs/*/summary.txt | sort | md5sum)
sweep >"$work/second.log" 2>&1
after=$(stat -c %Y "$out"/runs/*/summary.txt | sort | md5sum)
[ "$before" = "$after" ] || fail "the rerun ran finished runs again"
grep -q "8 of 8 runs done" "$work/second.log" || fail "the rerun did not report 8 of 8 runs done"
echo "sweep over ssh hosts: passed (8 runs over 2 hosts, host 2 killed after $finished_on_2, $retried retried)"
