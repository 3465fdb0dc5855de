#!/usr/bin/env bash
# What a node says after Ctrl-C reaches its stderr: rosconsole is shut down with ros::shutdown(),
# which ends spin(), and every ROS_* line after it printed nothing, so the clip buffer's closing
# tally (the clips it gave up, by name) and clip_report's "no summary" (with its exit status 1)
# were lost (ros_bridge/ros_log.h).
# Usage: last_words_test.sh BUILD_DIR
set -euo pipefail
build="$1"
nodes="$build/devel/lib/clothwind"
work="$(mktemp -d)"
fail() { echo "last_words_test: FAIL: $*" >&2; exit 1; }
export ROS_LOG_DIR="$work/log" ROS_HOME="$work/ros"
# Our own master on a free port (as scripts/run-main): other tests' masters and nodes are left alone.
port="$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://localhost:$port"
# The master alone, stopped by SIGTERM: a roscore started in the background of a script ignores
# SIGINT, and the rosmaster it had started outlived the test (one per run, each on its own port).
rosmaster --core -p "$port" -w 3 >"$work/rosmaster.txt" 2>&1 &
master=$!
trap 'kill -TERM $master 2>/dev/null; wait $master 2>/dev/null || true; rm -rf "$work"' EXIT
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done
rosparam list >/dev/null 2>&1 || fail "rosmaster did not start: $(cat "$work/rosmaster.txt")"

# run_then_interrupt NAME COMMAND...: starts it, waits for its node to register, sends SIGINT;
# its output in $work/NAME.txt, its status in $status.
run_then_interrupt() {
  local name="$1"
  shift
  "$@" >"$work/$name.txt" 2>&1 &
  local pid=$!
  for _ in $(seq 150); do rosnode list 2>/dev/null | grep -q "^/$name$" && break; sleep 0.2; done
  sleep 1
  [ "$name" != clip_report ] || rmdir "$work/gone"
  kill -INT "$pid"
  status=0
  wait "$pid" || status=$?
}

# The summary's folder is there at the start (checked then) and gone by the end.
mkdir "$work/gone"
run_then_interrupt clip_report "$nodes/clip_report_node" _summary:="$work/gone/summary.json"
[ "$status" -eq 1 ] || fail "clip_report with an unwritable summary exited $status: $(cat "$work/clip_report.txt")"
grep -q "\[ERROR\] .*clip_report: no summary: .*$work/gone/summary.json" "$work/clip_report.txt" ||
  fail "clip_report did not say why it exited 1: $(cat "$work/clip_report.txt")"

run_then_interrupt clip_buffer "$nodes/clip_buffer_node" _record_dir:="$work/rec"
[ "$status" -eq 0 ] || fail "clip_buffer exited $status: $(cat "$work/clip_buffer.txt")"
grep -q "\[INFO\] .*recording into $work/rec ends: 0 clips written" "$work/clip_buffer.txt" ||
  fail "clip_buffer's closing tally is missing: $(cat "$work/clip_buffer.txt")"
echo "last_words_test: OK"
