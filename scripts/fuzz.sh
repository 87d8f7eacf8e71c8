#!/usr/bin/env bash
# Fuzzes loom's readers with libFuzzer under AddressSanitizer and UndefinedBehaviorSanitizer.
#
#   scripts/fuzz.sh [--unit-tests] [SECONDS] [TARGET...]
#
# Configures a clang Debug ASan/UBSan build in build-fuzz/ (LOOM_FUZZ=ON), builds the fuzz
# targets of tests/fuzz/ and runs each for SECONDS (default 60) on its corpus, one at a
# time at nice 10: seeds from tests/fuzz/corpus.txt, grown in build-fuzz/fuzz-corpus/.
# TARGET names a subset (harness_xml, mesh_stl, ...; default: all). With --unit-tests it
# first builds everything in that build and runs the input-facing part of the CTest suite
# under the sanitizers (named below). A crash, sanitizer report, leak, timeout or exception
# other than InputError prints the target, the report and the input in base64, and the
# script exits 1 after the remaining targets have run.
#
# Runs are reproducible: libFuzzer starts from LOOM_FUZZ_SEED (default 1), so a run from the
# repository's seeds explores the same inputs in the same order; a shorter run (a slower
# machine) explores a prefix of a longer one.
#
# CI's run is replayed by starting from the seeds alone: with LOOM_FUZZ_CORPUS_DIR=$(mktemp -d)
# and the default seed a run tries the inputs CI's did, in order, until it has run as many.
#
# Environment: LOOM_FUZZ_BUILD_DIR (default build-fuzz), LOOM_FUZZ_CORPUS_DIR (default
# fuzz-corpus in the build), LOOM_JOBS (default nproc),
# LOOM_FUZZ_TIMEOUT (seconds one input may take, default 30; six times that for routes),
# LOOM_FUZZ_RSS_MB (default 2048), LOOM_FUZZ_MAX_SEED (bytes, default 65536),
# LOOM_SHARED_DATA (default ../shared/data beside the repository), LOOM_FUZZ_KEEP_RECENT and LOOM_FUZZ_KEEP_DIR (mesh
# targets: keep the last N inputs in that directory, to replay the run up to a crash that
# surfaced after its cause: tests/fuzz/fuzz_support.hpp keep_recent).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${LOOM_FUZZ_BUILD_DIR:-$root/build-fuzz}"
jobs="${LOOM_JOBS:-$(nproc)}"
per_input="${LOOM_FUZZ_TIMEOUT:-30}"
rss_mb="${LOOM_FUZZ_RSS_MB:-2048}"
max_seed="${LOOM_FUZZ_MAX_SEED:-65536}"
seed="${LOOM_FUZZ_SEED:-1}"
corpora="${LOOM_FUZZ_CORPUS_DIR:-$build/fuzz-corpus}"
shared="${LOOM_SHARED_DATA:-$root/../shared/data}"

# The tests run under the sanitizers (--unit-tests): the suites that feed loom hostile or
# unusual input (readers, scene and harness files, KBL, point clouds, meshes, output sets,
# the certified audit's limits, the fuzz campaign's reproducers through the executable).
# The rest of the suite (geometry against brute-force oracles, planners, α-SIM) runs ~20-50x
# slower under ASan at -O1 — about an hour on two cores — and its inputs are generated, not
# hostile; it runs in the Release suite of the README's test command.
unit_test_select='^(HarnessXml|HarnessXmlProps|HarnessTopology|SceneDir|TempDir|RealCad|Mesh|MeshProps|'
unit_test_select+='InputAdversarial|FuzzRegression|GltfGeometry|DaeGeometry|LimitRegression|ScanRegression|'
unit_test_select+='Kbl[A-Za-z]*|PointCloudIo|PointCloudIoProperty|FileStems|OutputSet|AuditCli|CliOutputs|'
unit_test_select+='ClashCheck|ClashAdversarial|ClashLimits|Centerline|BSplineOps|MeshCut|PartSplit|AuditShard|ShardPlan|TessellationNeed|ArcLine|BendPlanner|regressions)\.'

unit_tests=0
seconds=60
targets=()
for a in "$@"; do
  case "$a" in
    --unit-tests) unit_tests=1 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"; exit 0 ;;
    ''|*[!0-9]*) targets+=("$a") ;;
    *) seconds="$a" ;;
  esac
done

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0}"
for s in llvm-symbolizer /usr/lib/llvm-14/bin/llvm-symbolizer; do
  if command -v "$s" >/dev/null; then export ASAN_SYMBOLIZER_PATH="$(command -v "$s")"; break; fi
done

# -O1, as libFuzzer's documentation recommends for fuzzing; still a Debug build (assertions on).
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
  -DCMAKE_CXX_COMPILER=clang++ -DLOOM_FUZZ=ON -DLOOM_BUILD_BENCH=OFF \
  -DCGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE=TRUE >/dev/null

if [ "$unit_tests" = 1 ]; then
  start=$SECONDS
  cmake --build "$build" -j "$jobs"
  echo "fuzz.sh: sanitizer build $((SECONDS - start)) s"
  start=$SECONDS
  (cd "$build" && ctest --output-on-failure -j "$jobs" --timeout 900 -R "$unit_test_select")
  echo "fuzz.sh: unit tests under ASan/UBSan $((SECONDS - start)) s ($unit_test_select)"
fi

all_targets=()
while read -r t kind _; do
  [[ -z "$t" || "$t" == \#* || "$kind" != dict ]] && continue
  all_targets+=("$t")
done <"$root/tests/fuzz/corpus.txt"
[ ${#targets[@]} -eq 0 ] && targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "fuzz.sh: unknown target '$t' (${all_targets[*]})" >&2; exit 2; }
done
# One run of a target per build at a time: two would share its log, artifacts and scratch
# directory, and each would delete the other's. The locks go with this shell.
mkdir -p "$build/fuzz-logs"
for t in "${targets[@]}"; do
  exec {lock}>"$build/fuzz-logs/$t.lock"
  flock -n "$lock" || { echo "fuzz.sh: fuzz_$t is already running in $build" >&2; exit 2; }
done
cmake --build "$build" -j "$jobs" --target $(printf 'fuzz_%s ' "${targets[@]}")

# seed_corpus TARGET DIR: copies the target's seeds into DIR; prints its dictionary option.
seed_corpus() {
  local target="$1" dir="$2" t kind path f
  mkdir -p "$dir"
  while read -r t kind path; do
    [[ "$t" != "$target" ]] && continue
    if [ "$kind" = dict ]; then echo "-dict=$root/tests/fuzz/dict/$path"; continue; fi
    [[ "$path" == shared/* ]] && path="$shared/${path#shared/}" || path="$root/$path"
    for f in $path; do
      # Named by content, as libFuzzer names what it adds (examples/*/harness.xml share a name).
      [ -f "$f" ] && [ "$(stat -c %s "$f")" -le "$max_seed" ] && cp "$f" "$dir/$(sha1sum <"$f" | cut -c1-40)"
    done
  done <"$root/tests/fuzz/corpus.txt"
  return 0
}

# report_finding TARGET LOG ARTIFACTS: the sanitizer/libFuzzer report and each input, in base64.
report_finding() {
  local target="$1" log="$2" art="$3" f
  echo "==================== FINDING in fuzz_$target ===================="
  # The report starts at the first sanitizer, libFuzzer or loom-fuzz error line.
  awk '/^==[0-9]+==|^==loom-fuzz==|ERROR: libFuzzer|^SUMMARY|runtime error:|^ALARM|^MS:/ {on=1} on' "$log" |
    head -n 150
  for f in "$art"/*; do
    [ -f "$f" ] || continue
    echo "--- input $(basename "$f") ($(stat -c %s "$f") bytes), base64:"
    base64 -w 76 "$f"
    echo "--- replay: base64 -d > input.bin <<'EOF' ... EOF; $build/tests/fuzz/fuzz_$target input.bin"
  done
  echo "==================== end of fuzz_$target finding ===================="
}

failed=()
summary=()
for t in "${targets[@]}"; do
  corpus="$corpora/$t"
  art="$build/fuzz-artifacts/$t"
  log="$build/fuzz-logs/$t.log"
  rm -rf "$art" && mkdir -p "$art" "$(dirname "$log")"
  dict_opt="$(seed_corpus "$t" "$corpus")"
  # The targets write their inputs to files in a scratch directory of their own; one that
  # ends in a crash leaves it behind, so all of them live here and go after each run.
  export TMPDIR="$build/fuzz-tmp/$t"
  rm -rf "$TMPDIR" && mkdir -p "$TMPDIR"
  echo "fuzz.sh: fuzz_$t for $seconds s ($(ls "$corpus" | wc -l) corpus files)"
  rc=0
  # A routes input is audited, and the audit's work grows with route length up to its own
  # limits (10⁷ chords): a route folded over itself for kilometres takes 1.4 s in Release
  # and ~56 s under the sanitizers and coverage tracing, which is slow, not hung.
  timeout_s="$per_input"
  [ "$t" = routes ] && timeout_s=$((per_input * 6))
  nice -n 10 "$build/tests/fuzz/fuzz_$t" $dict_opt -max_total_time="$seconds" -seed="$seed" -timeout="$timeout_s" \
    -rss_limit_mb="$rss_mb" -artifact_prefix="$art/" -print_final_stats=1 "$corpus" >"$log" 2>&1 || rc=$?
  rm -rf "$TMPDIR"
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n1)"
  rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n1)"
  if [ "$rc" -ne 0 ]; then
    report_finding "$t" "$log" "$art"
    failed+=("$t")
    result="FINDING (exit $rc, log $log)"
  else
    result="ok"
  fi
  summary+=("$(printf '%-12s %10s execs %8s exec/s %6s corpus  %s' "$t" "${execs:-?}" "${rate:-?}" \
    "$(ls "$corpus" | wc -l)" "$result")")
done

echo "fuzz.sh: $seconds s per target, build $build"
printf '  %s\n' "${summary[@]}"
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz.sh: findings in ${failed[*]}" >&2
  exit 1
fi
