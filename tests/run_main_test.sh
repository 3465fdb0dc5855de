#!/usr/bin/env bash
# `make run`'s job end to end (scripts/run-main), on a small procedural session in a folder of its
# own: the session made and checked, replayed through the nodes with the shipped model and the
# report, the report's summary and plot written, and run-main's exit status 0. replay_sdn.test
# checks the estimates message by message but runs no report; nothing else ran run-main.
#   tests/run_main_test.sh <build dir>
set -euo pipefail
build="$1"
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$(mktemp -d /tmp/clothwind_run_main_test.XXXXXX)"
trap 'rm -rf "$out"' EXIT
fail() { echo "run_main_test: $*" >&2; tail -30 "$out/run-main.txt" >&2 || true; exit 1; }
# A second run into a sessions folder in use is refused at once, naming it (it removed the first
# run's dataset, and each overwrote the other's report).
exec 8>"$out/.run-main.lock"
flock -n 8 || fail "could not take the lock"
status=0
CLOTHWIND_SESSIONS="$out" "$root/scripts/run-main" "$build" >"$out/run-main.txt" 2>&1 8>&- || status=$?
exec 8>&-  # released: the run below takes it
[ "$status" -eq 1 ] && grep -q "another run-main is using $out" "$out/run-main.txt" ||
  fail "a second run into a folder in use was not refused (status $status)"
CLOTHWIND_SESSIONS="$out" CLOTHWIND_SESSION_FRAMES=procedural CLOTHWIND_SESSION_MINUTES=0.4 \
  CLOTHWIND_SDN_THREADS=1 "$root/scripts/run-main" "$build" >"$out/run-main.txt" 2>&1 ||
  fail "run-main exited $?"
grep -qx "  ok for replay" "$out/run-main.txt" || fail "bag-check did not say ok for replay"
grep -q "^estimate_report:" "$out/run-main.txt" || fail "no estimate report printed"
/usr/bin/python3 - "$out/default-replay.json" "$out/default-estimates.png" <<'PY' || fail "summary check"
import json, math, os, sys
s = json.load(open(sys.argv[1]))
e = s["estimates"]
# 0.4 min at 30 fps, clips of 30 frames resampled to 25 fps: about 20 clips, every one labelled
# (the session's anemometer reads throughout) and estimated once.
assert s["total_clips"] >= 15, s["total_clips"]
assert s["labelled_clips"] == s["total_clips"], (s["labelled_clips"], s["total_clips"])
assert e["count"] == s["total_clips"], (e["count"], s["total_clips"])
assert e["compared"] == e["count"], e
assert math.isfinite(e["rmse"]) and 0 < e["rmse"] < 5, e["rmse"]
# The report's figures recomputed from its own rows (estimate against the clip's anemometer
# label): a report comparing the estimates with themselves, or averaging the wrong column, gave a
# figure inside the loose bound above.
rows = [(r["speed"], r["reference"]) for r in e["estimates"]
        if r["speed"] is not None and r["reference"] is not None]
assert len(rows) == e["compared"], (len(rows), e["compared"])
errors = [speed - reference for speed, reference in rows]
assert len(set(round(speed, 6) for speed, _ in rows)) > 1, "every estimate the same"
for key, value in (("rmse", math.sqrt(sum(x * x for x in errors) / len(errors))),
                   ("acc05", sum(abs(x) <= 0.5 for x in errors) / len(errors)),
                   ("bias", sum(errors) / len(errors))):
    assert math.isclose(e[key], value, rel_tol=1e-9, abs_tol=1e-12), (key, e[key], value)
assert os.path.getsize(sys.argv[2]) > 1000, "no estimate plot"
print("run_main_test: %d clips, estimate RMSE %.3f m/s" % (s["total_clips"], e["rmse"]))
PY
# Without a model (CLOTHWIND_MODEL=none, docs/sdn.md: ingest only): the clips are reported, no
# estimates and no plot, exit 0. (run-main passed its plot path anyway, which the report refuses
# without estimates: the replay ended at start.)
CLOTHWIND_MODEL=none CLOTHWIND_SESSIONS="$out" CLOTHWIND_SESSION_FRAMES=procedural CLOTHWIND_SESSION_MINUTES=0.4 \
  "$root/scripts/run-main" "$build" >"$out/run-main.txt" 2>&1 || fail "run-main without a model exited $?"
/usr/bin/python3 - "$out/default-replay.json" <<'PY' || fail "summary check without a model"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["total_clips"] >= 15, s["total_clips"]
assert "estimates" not in s, "estimates reported without a model"
print("run_main_test: without a model, %d clips" % s["total_clips"])
PY
# A replay cut at its wall-time limit (here 10 s, before the 12 s replay of the 24 s session at 2x
# and its start ends): the report and summary of what was replayed, and exit status 3, not 0 (a
# cut run read as a whole one to a script).
status=0
rm -f "$out/default-replay.json"
CLOTHWIND_MODEL=none CLOTHWIND_REPLAY_MAX_WALL=10 CLOTHWIND_SESSIONS="$out" CLOTHWIND_SESSION_FRAMES=procedural \
  CLOTHWIND_SESSION_MINUTES=0.4 "$root/scripts/run-main" "$build" >"$out/run-main.txt" 2>&1 || status=$?
[ "$status" -eq 3 ] && grep -q "the replay was cut at max_wall = 10 s" "$out/run-main.txt" ||
  fail "a replay cut at its wall-time limit exited $status"
/usr/bin/python3 - "$out/default-replay.json" <<'PY' || fail "no summary of the cut replay"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["total_clips"] >= 1, s["total_clips"]
print("run_main_test: cut at 10 s, %d clips reported, exit 3" % s["total_clips"])
PY
