#!/usr/bin/env bash
# Runs docs/tutorial.md as a new user would: writes its scene block to pumpjack.yaml and runs
# every command block marked `<!-- tutorial-run -->` (exit status 0, or the `exit=N` it
# states) in a fresh folder, with `build/rdyn` the binary under test. Then checks what the text
# claims against closed forms: at 1 Hz and 20 W the calibrated drive torque is 20/(2π) N·m
# (gravity does no net work over a stroke), and the prescribed 1 rev/s with the scene's own drive
# off needs a mean power of c·(2π)² W, c the bearing's viscous coefficient (0.05).
# Usage: tutorial_test.sh RDYN_BINARY REPOSITORY_ROOT
set -euo pipefail
rdyn=$1
doc=$2/docs/tutorial.md
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/build" "$work/out"
ln -s "$rdyn" "$work/build/rdyn"
cd "$work"

# The blocks: a marker line, then a fenced block.
awk '/^<!-- tutorial-scene -->$/ {s=1; next} s && /^```yaml/ {g=1; next} g && /^```/ {exit} g {print}' "$doc" > pumpjack.yaml
test -s pumpjack.yaml || { echo "tutorial: no scene block" >&2; exit 1; }
awk '/^<!-- tutorial-run( exit=[0-9]+)? -->$/ {e=0; if (match($0, /exit=[0-9]+/)) e=substr($0, RSTART+5, RLENGTH-5); s=1; next}
     s && /^```sh/ {g=1; next}
     g && /^```/ {g=0; s=0; next}
     g {print e "\t" $0}' "$doc" > commands.tsv
n=$(wc -l < commands.tsv)
test "$n" -ge 8 || { echo "tutorial: expected at least 8 commands, found $n" >&2; exit 1; }
while IFS=$'\t' read -r expected cmd; do
  echo "+ $cmd (expect exit $expected)"
  set +e
  bash -c "$cmd" > last.out 2> last.err
  status=$?
  set -e
  if [ "$status" != "$expected" ]; then
    echo "tutorial: '$cmd' exited $status, the tutorial says $expected" >&2
    tail -5 last.err >&2
    exit 1
  fi
done < commands.tsv

python3 - <<'PY'
import json, math, sys
cal = json.load(open("out/pj-cal.json"))
torque = cal["drive_torque_Nm"]
if abs(torque - 20 / (2 * math.pi)) > 1e-6 * torque:
    sys.exit(f"tutorial: calibrated torque {torque} N·m, closed form {20 / (2 * math.pi)}")
if abs(cal["mean_cadence_hz_full"] - 1.0) > 1e-3:
    sys.exit(f"tutorial: full model's cadence {cal['mean_cadence_hz_full']} Hz at the calibrated values")
drive = json.load(open("out/pj-drive/run.json"))
p = 0.05 * (2 * math.pi) ** 2
if abs(drive["mean_power_W"] - p) > 1e-3 * p:
    sys.exit(f"tutorial: drive mean power {drive['mean_power_W']} W, closed form {p} W")
if not drive["motor_check"]["covers"]:
    sys.exit("tutorial: the 10 N·m motor should cover the drive")
opt = json.load(open("out/pj-opt/summary.json"))
if not opt["peak_reduction_full"] > 0.5:
    sys.exit(f"tutorial: optimize lowered the peak by {opt['peak_reduction_full']}, the text says about 0.74")
val = json.load(open("out/pj-validate/summary.json"))
if val["status"] != "pass":
    sys.exit(f"tutorial: validate of the calibrated scene: {val['status']} {val['failures']}")
print("tutorial: every command ran; torque", torque, "drive power", drive["mean_power_W"],
      "peak reduction", opt["peak_reduction_full"])
PY
