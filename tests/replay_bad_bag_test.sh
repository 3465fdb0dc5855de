#!/usr/bin/env bash
# replay.launch with a bag that cannot be opened (none there; a file that is not a bag) ends, naming
# the bag, instead of leaving its nodes waiting for a replay that never comes (rosbag play exits
# with status 0 when it cannot open its bag; scripts/replay-player checks it first).
# Usage: replay_bad_bag_test.sh
set -euo pipefail
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "replay_bad_bag_test: FAIL: $*" >&2; exit 1; }
export ROS_LOG_DIR="$work/log"
port=$((20000 + RANDOM % 20000))
export ROS_MASTER_URI="http://localhost:$port"
echo "not a bag" > "$work/text.bag"
for bag in "$work/none.bag" "$work/text.bag"; do
  status=0
  timeout 90 roslaunch -p "$port" clothwind replay.launch bag:="$bag" >"$work/out.txt" 2>&1 || status=$?
  [ "$status" -ne 124 ] || fail "replay.launch bag:=$bag was still up after 90 s: $(tail -5 "$work/out.txt")"
  grep -q "replay.launch: cannot open the bag $bag" "$work/out.txt" ||
    fail "replay.launch bag:=$bag did not name the bag: $(tail -20 "$work/out.txt")"
done
echo "replay_bad_bag_test: OK"
