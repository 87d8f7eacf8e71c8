#!/usr/bin/env bash
# Replays every minimised reproducer of the external fuzz campaign (../shared/fuzz-findings,
# one folder each, with the command that once crashed, hung or misled loom) against the
# `loom` executable, and checks what each should do now:
#  - no signal and no hang (each run is bounded by `timeout`);
#  - the expected exit status; on exit 2 the message names the file at fault and --out
#    holds nothing (no half-written output set);
#  - no `nan`/`inf` text in anything loom printed or wrote.
#
#   replay_fuzz_findings.sh LOOM FINDINGS_DIR
#
# A folder of FINDINGS_DIR that this script has no case for fails the test, so that a new
# finding cannot be forgotten. With CI set, a missing FINDINGS_DIR fails; else it skips (77).
set -uo pipefail
loom="$(realpath "$1")"
findings="$2"
if [ ! -d "$findings" ]; then
  echo "fuzz findings not found: $findings" >&2
  [ -n "${CI:-}" ] && exit 1
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# Seconds one replay may take: the hangs found ran for minutes; a fixed reader answers in
# well under a second (the obj-many-objects load, the slowest case, in about two).
limit=60
failures=0
known=()

fail() {
  echo "FAIL $1: $2" >&2
  failures=$((failures + 1))
}

# run CASE DIR EXPECTED_EXIT NAMED -- ARGS...: runs loom ARGS inside DIR with --out (when
# given as @OUT) in a fresh directory, and checks the outcome. NAMED is a text the message
# must contain on exit 2 (the file at fault), or '-' for none.
run() {
  local name="$1" dir="$2" expect="$3" named="$4"
  shift 5
  local out="$work/$name.out" log="$work/$name.log" args=() a rc
  for a in "$@"; do [ "$a" = @OUT ] && args+=("$out") || args+=("$a"); done
  rm -rf "$out"
  (cd "$findings/$dir" && LOOM_CACHE_DIR="$work/cache" timeout "$limit" "$loom" "${args[@]}" --quiet) >"$log" 2>&1
  rc=$?
  if [ "$rc" -eq 124 ]; then fail "$name" "no answer within $limit s"; return; fi
  if [ "$rc" -ge 128 ]; then fail "$name" "killed by signal $((rc - 128))"; cat "$log" >&2; return; fi
  if [ "$rc" -ne "$expect" ]; then fail "$name" "exit $rc, expected $expect"; cat "$log" >&2; return; fi
  if [ "$rc" -eq 2 ]; then
    [ "$named" = - ] || grep -qF "$named" "$log" || { fail "$name" "the message does not name '$named'"; cat "$log" >&2; }
    if [ -e "$out" ] && [ -n "$(ls -A "$out" 2>/dev/null)" ]; then fail "$name" "exit 2 left files in --out: $(ls "$out")"; fi
  fi
  if grep -qiwE 'nan|-?inf' "$log" || { [ -d "$out" ] && grep -rqiwE 'nan|-?inf' "$out"; }; then
    fail "$name" "nan/inf text in the output"
    grep -riwE 'nan|-?inf' "$log" "$out" 2>/dev/null | head -n 5 >&2
  fi
  echo "ok   $name (exit $rc)"
}

case_() { known+=("$1"); }

case_ audit-discrete-spacing-memory-before-limit
run audit-discrete-spacing audit-discrete-spacing-memory-before-limit 2 harness_clash.xml -- \
  audit scene.toml --out @OUT --method discrete --spacing 1e-6
case_ audit-limit-error-names-no-file
run audit-limit-names-file audit-limit-error-names-no-file 2 .xml -- audit scene.toml --out @OUT
case_ dae-accessor-huge-stride-segv
run dae-stride dae-accessor-huge-stride-segv 2 .dae -- info scene.toml
case_ dae-instance-node-cycle
run dae-cycle dae-instance-node-cycle 2 cycle.dae -- info scene.toml
case_ dae-non-integer-index-hang-memory
run dae-index dae-non-integer-index-hang-memory 2 .dae -- info scene.toml
case_ mesh-node-fanout-exponential
run fanout-dae mesh-node-fanout-exponential 2 .dae -- info scene-dae.toml
run fanout-gltf mesh-node-fanout-exponential 2 .gltf -- info scene-gltf.toml
case_ obj-many-objects-superlinear-load
run obj-many-objects obj-many-objects-superlinear-load 0 - -- info scene.toml
case_ ply-ascii-short-face-list-abort
run ply-short-faces ply-ascii-short-face-list-abort 2 .ply -- info scene.toml
case_ ply-mesh-unterminated-header-hang-segv
run ply-no-end-header ply-mesh-unterminated-header-hang-segv 2 no-end-header.ply -- info scene.toml
run ply-nul-in-header ply-mesh-unterminated-header-hang-segv 2 nul-in-header.ply -- info scene-segv.toml
case_ scan-axis-tiny-diameter-unnamed-error
run scan-tiny-diameter scan-axis-tiny-diameter-unnamed-error 2 tube.ply -- \
  scan tube.ply --method axis --diameter 1e-300 --out @OUT
case_ simplify-json-inf-text
run simplify-inf-text simplify-json-inf-text 0 - -- simplify scene.toml --out @OUT --dim-pre 1e-300
case_ simplify-open-sparse-mesh-memory
run simplify-open-sparse simplify-open-sparse-mesh-memory 0 - -- simplify scene.toml --out @OUT --dim-pre 0.5
case_ step-vector-missing-direction-segv
run step-vector step-vector-missing-direction-segv 2 .step -- info scene.toml
case_ toml-deep-dotted-table-segv
run toml-deep toml-deep-dotted-table-segv 2 deep.toml -- info deep.toml
case_ toml-planner-error-names-no-file
run toml-planner toml-planner-error-names-no-file 2 scene.toml -- \
  route scene.toml --out @OUT --iterations 200 --time-limit 0.2
case_ xml-blank-number-read-as-zero
run xml-blank-number xml-blank-number-read-as-zero 2 .xml -- info scene.toml
case_ xml-leaf-children-ignored
run xml-leaf-children xml-leaf-children-ignored 2 .xml -- audit scene.toml --out @OUT

# Two simplify runs into one --out: the second set replaces the first as a whole, so no
# part file of the first run that the second does not write survives.
case_ simplify-step-stale-output
stale_out="$work/stale.out"
(cd "$findings/simplify-step-stale-output" &&
  timeout "$limit" "$loom" simplify scene1.toml --out "$stale_out" --step --quiet &&
  cp "$stale_out/p.step" "$work/first-p.step" &&
  timeout "$limit" "$loom" simplify scene2.toml --out "$stale_out" --step --quiet) >"$work/stale.log" 2>&1
rc=$?
if [ "$rc" -ne 0 ]; then
  fail simplify-step-stale "exit $rc"; cat "$work/stale.log" >&2
elif [ -e "$stale_out/p.step" ] && cmp -s "$stale_out/p.step" "$work/first-p.step"; then
  fail simplify-step-stale "the first run's p.step survives the second run"
else
  echo "ok   simplify-step-stale ($(ls "$stale_out" | tr '\n' ' '))"
fi

for d in "$findings"/*/; do
  d="$(basename "$d")"
  [[ " ${known[*]} " == *" $d "* ]] || fail "$d" "a finding this script has no case for"
done
if [ "$failures" -ne 0 ]; then
  echo "$failures of the fuzz findings are not handled" >&2
  exit 1
fi
echo "all ${#known[@]} fuzz findings handled"
