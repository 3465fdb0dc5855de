#!/usr/bin/env bash
# The launch files' parameters as roslaunch resolves them (--dump-params: no master, no node):
# a record_dir set in the clip buffer's YAML (clip_config) is kept unless record_dir:= is given
# (an empty arg used to replace it, and a field session set up to record recorded nothing, its
# diagnostics OK), one given as a number stays text, and record:=false turns recording off; bag:=true
# watches the session bags it records.
# Usage: launch_params_test.sh
set -euo pipefail
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "launch_params_test: FAIL: $*" >&2; exit 1; }
config="$(rospack find clothwind)/config/clip_buffer.yaml"
sed 's#^record_dir: ""#record_dir: /data/from-yaml#' "$config" >"$work/clip_buffer.yaml"
grep -q '^record_dir: /data/from-yaml' "$work/clip_buffer.yaml" || fail "no record_dir line to set in $config"
for launch in "replay.launch bag:=/tmp/none.bag" "field.launch"; do
  # shellcheck disable=SC2086
  roslaunch --dump-params clothwind $launch clip_config:="$work/clip_buffer.yaml" >"$work/params.txt" 2>&1 ||
    fail "roslaunch --dump-params $launch: $(cat "$work/params.txt")"
  grep -q '^/clip_buffer/record_dir: /data/from-yaml$' "$work/params.txt" ||
    fail "$launch dropped the YAML's record_dir: $(grep record_dir "$work/params.txt")"
  # shellcheck disable=SC2086
  roslaunch --dump-params clothwind $launch clip_config:="$work/clip_buffer.yaml" record_dir:=20261206 \
    >"$work/params.txt" 2>&1 || fail "roslaunch --dump-params $launch record_dir:=20261206: $(cat "$work/params.txt")"
  grep -q "^/clip_buffer/record_dir: '20261206'$" "$work/params.txt" ||
    fail "$launch record_dir:=20261206 is not the text given: $(grep record_dir "$work/params.txt")"
  # record:=false turns the YAML's recording off, and a record_dir:= given beside it too.
  for extra in "" "record_dir:=/data/given"; do
    # shellcheck disable=SC2086
    roslaunch --dump-params clothwind $launch clip_config:="$work/clip_buffer.yaml" record:=false $extra \
      >"$work/params.txt" 2>&1 || fail "roslaunch --dump-params $launch record:=false $extra: $(cat "$work/params.txt")"
    grep -q "^/clip_buffer/record_dir: ''$" "$work/params.txt" ||
      fail "$launch record:=false $extra still records: $(grep record_dir "$work/params.txt")"
  done
done
# bag:=true runs the session recorder and its watch on the same prefix.
roslaunch --dump-params clothwind field.launch bag:=true bag_prefix:=/data/session >"$work/params.txt" 2>&1 ||
  fail "roslaunch --dump-params field.launch bag:=true: $(cat "$work/params.txt")"
grep -q "^/session_bag_watch/bag_prefix: /data/session$" "$work/params.txt" ||
  fail "field.launch bag:=true has no session_bag_watch on the bag's prefix: $(grep -i bag "$work/params.txt")"
# Every clothwind node's parameters are cleared before its launch sets them (roslaunch's own
# reading of the files, every optional node on): a value an earlier launch set and this one leaves
# out (sdn's ~camera_heading, the anemometer YAML's ~magnetic_declination) was kept on a running
# master and used without a word.
/usr/bin/env python3 - "$(rospack find clothwind)/launch" <<'PY' || fail "a clothwind node keeps an earlier launch's parameters"
import sys
import roslaunch.config
folder = sys.argv[1]
args = {"field.launch": ["bag:=true"], "replay.launch": ["bag:=/tmp/none.bag", "report:=true", "model:=/tmp/m.pt"],
        "sdn.launch": ["model:=/tmp/m.pt"], "monitor.launch": ["model:=/tmp/m.pt", "rviz:=false"]}
bad = []
for name, extra in args.items():
    sys.argv = ["roslaunch"] + extra
    config = roslaunch.config.load_config_default([folder + "/" + name], None)
    nodes = [n for n in config.nodes if n.package == "clothwind"]
    assert nodes, name
    for n in nodes:
        ns = n.namespace.rstrip("/") + "/" + n.name + "/"
        if ns not in config.clear_params:
            bad.append("%s: %s" % (name, ns))
print("\n".join(bad), file=sys.stderr)
sys.exit(1 if bad else 0)
PY
# roslaunch --ros-args is how a user learns a launch file's arguments: every declared arg needs a
# doc= (what it does, its unit, what empty means), or the user reads 'undocumented' for it.
for launch in field.launch replay.launch sdn.launch monitor.launch; do
  roslaunch --ros-args "$(rospack find clothwind)/launch/$launch" >"$work/args.txt" 2>&1 ||
    fail "roslaunch --ros-args $launch: $(cat "$work/args.txt")"
  if grep -q undocumented "$work/args.txt"; then
    fail "$launch has args without doc=: $(grep undocumented "$work/args.txt" | sed 's/^ *//; s/[ (:].*//' | paste -sd ' ' -)"
  fi
done
echo "launch_params_test: OK"
