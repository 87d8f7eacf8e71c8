#!/usr/bin/env bash
# Installs the build into a fresh prefix, builds examples/consumer against it with
# find_package(loom), and checks that its audit of a scene agrees with `loom audit`.
# Usage: test_consumer.sh SOURCE_DIR BINARY_DIR LOOM_EXE
set -euo pipefail
src="$1" bin="$2" loom="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cmake --install "$bin" --prefix "$work/prefix" >/dev/null
cmake -S "$src/examples/consumer" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/build" >/dev/null
scene="$src/tests/data/audit/clash.toml"
set +e
"$work/build/loom_consumer" "$scene" >"$work/consumer.txt"
consumer_rc=$?
"$loom" audit "$scene" --out "$work/audit" --quiet --json >"$work/audit.json"
loom_rc=$?
set -e
cat "$work/consumer.txt"
[ "$consumer_rc" -eq "$loom_rc" ] || { echo "exit $consumer_rc, loom audit exit $loom_rc"; exit 1; }
clashes=$(python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(len(r["clashes"]))' "$work/audit/report.json")
got=$(($(wc -l <"$work/consumer.txt") - 1))
[ "$got" -eq "$clashes" ] || { echo "consumer listed $got clashes, loom audit $clashes"; exit 1; }
[ "$clashes" -gt 0 ] || { echo "the scene should clash"; exit 1; }
echo "consumer agrees with loom audit: exit $consumer_rc, $clashes clashes"
