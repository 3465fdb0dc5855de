#!/usr/bin/env bash
# replay.launch with a bag that cannot be opened (none there; a file that is not a bag) ends, naming
# the bag (and one given player_required:=yes ends at once, naming the value), instead of leaving its nodes waiting for a replay that never comes (rosbag play exits
# with status 0 when it cannot open its bag; scripts/replay-player checks it first).
# Usage: replay_bad_bag_test.sh
set -euo pipefail
work="$(mktemp -d)"
# (A master roslaunch started for a launch it then refused stayed running after the test: the
# one on this test's port is stopped at its end.)
trap 'pkill -TERM -f "rosmaster --core -p $port " 2>/dev/null || true; rm -rf "$work"' EXIT
fail() { echo "replay_bad_bag_test: FAIL: $*" >&2; exit 1; }
export ROS_LOG_DIR="$work/log"
# Our own master on a free port (as scripts/run-main): other tests' masters and nodes are left alone.
port="$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://localhost:$port"
echo "not a bag" > "$work/text.bag"
# A recording that was not closed: a version 2.0 header whose index_pos is 0 (rosbag play plays
# nothing of it and exits with status 0).
/usr/bin/python3 - "$work/unindexed.bag" <<'PY'
import struct, sys
fields = b"".join(struct.pack("<I", len(f)) + f for f in
                  (b"op=\x03", b"index_pos=" + struct.pack("<Q", 0), b"conn_count=" + struct.pack("<I", 0),
                   b"chunk_count=" + struct.pack("<I", 0)))
with open(sys.argv[1], "wb") as f:
    f.write(b"#ROSBAG V2.0\n" + struct.pack("<I", len(fields)) + fields + struct.pack("<I", 4096) + b" " * 4096)
PY
declare -A why=(["$work/none.bag"]="No such file or directory" ["$work/text.bag"]="not a ROS bag"
                ["$work/unindexed.bag"]="rosbag reindex")
for bag in "$work/none.bag" "$work/text.bag" "$work/unindexed.bag"; do
  status=0
  timeout 90 roslaunch -p "$port" clothwind replay.launch bag:="$bag" >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -ne 124 ] || fail "replay.launch bag:=$bag was still up after 90 s: $(tail -5 "$work/out.txt")"
  grep -q "replay.launch: cannot open the bag $bag: .*${why[$bag]}" "$work/out.txt" ||
    fail "replay.launch bag:=$bag did not say why: $(tail -20 "$work/out.txt")"
done
# player_required takes true, false, 1 or 0, as roslaunch's own if does: "yes" read as true.
status=0
timeout 90 roslaunch -p "$port" clothwind replay.launch bag:="$work/text.bag" player_required:=yes >"$work/out.txt" 2>&1 ||
  status=$?
[ "$status" -ne 0 ] && [ "$status" -ne 124 ] || fail "player_required:=yes was not refused (status $status)"
grep -q "yes is not a 'bool' type" "$work/out.txt" || fail "player_required:=yes: $(tail -5 "$work/out.txt")"
echo "replay_bad_bag_test: OK"
