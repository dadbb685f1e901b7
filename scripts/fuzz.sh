#!/usr/bin/env bash
# Runs one libFuzzer target of tests/fuzz for SECONDS (docs/fuzz.md).
#
#   scripts/fuzz.sh TARGET SECONDS [JOBS]
#
# TARGET: rawlog | ini | tum | labels | image | stray | stray_capture | bag | mcap | db3 | cdr. Builds the target with clang,
# AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer in build-fuzz/
# (BIMS_FUZZ_BUILD=DIR for another folder; GUI, OpenNI2 and benchmarks
# off), seeds a working corpus from tests/fuzz/corpus/TARGET (and config/
# for ini), fuzzes with JOBS processes (default 1), and prints the
# executions and any finding. A finding's input is written to
# BUILD/findings/TARGET/; copy it into tests/fuzz/corpus/TARGET/ so that
# CTest replays it from then on (Fuzz.TARGET.CorpusReplays).
set -euo pipefail
TARGET=${1:?usage: scripts/fuzz.sh TARGET SECONDS [JOBS]}
SECONDS_TOTAL=${2:?usage: scripts/fuzz.sh TARGET SECONDS [JOBS]}
JOBS=${3:-1}
case "$TARGET" in rawlog | ini | tum | labels | image | stray | stray_capture | bag | mcap | db3 | cdr) ;; *)
	echo "fuzz.sh: unknown target '$TARGET' (rawlog, ini, tum, labels, image, stray, stray_capture, bag, mcap, db3, cdr)" >&2
	exit 2
	;;
esac
[[ $SECONDS_TOTAL =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number, got '$SECONDS_TOTAL'" >&2; exit 2; }
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${BIMS_FUZZ_BUILD:-$ROOT/build-fuzz}
./scripts/install-deps.sh fuzz > /dev/null
SAN="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fsanitize=fuzzer-no-link"
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
	CC=clang CXX=clang++ cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
		-DBIMS_FUZZ=ON -DBIMS_BUILD_GUI=OFF -DBIMS_WITH_OPENNI2=OFF -DBIMS_BUILD_BENCH=OFF -DBIMS_BUILD_PYTHON=OFF \
		"-DCMAKE_CXX_FLAGS=$SAN" > /dev/null
fi
cmake --build "$BUILD" --target "fuzz_$TARGET" -j"$(nproc)" > "$BUILD/build_$TARGET.log" 2>&1 ||
	{ tail -30 "$BUILD/build_$TARGET.log" >&2; exit 1; }
WORK="$BUILD/corpus/$TARGET"
FOUND="$BUILD/findings/$TARGET"
mkdir -p "$WORK" "$FOUND"
SEEDS=("$ROOT/tests/fuzz/corpus/$TARGET")
[ "$TARGET" = ini ] && SEEDS+=("$ROOT/config" "$ROOT/config/sim")
# MRPT-internal leaks only, each named and explained in the file
export LSAN_OPTIONS="suppressions=$ROOT/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1"
# the bag target writes each input to a file (rosbag opens files only): in
# memory when the machine has /dev/shm
case "$TARGET" in bag | mcap | db3) [ -d /dev/shm ] && [ -w /dev/shm ] && export TMPDIR=/dev/shm ;; esac
echo "fuzz.sh: $TARGET for $SECONDS_TOTAL s, $JOBS job(s); corpus $WORK; findings $FOUND"
PAR=()
[ "$JOBS" -gt 1 ] && PAR=(-jobs="$JOBS" -workers="$JOBS")
set +e
(cd "$BUILD" && "$BUILD/bin/fuzz_$TARGET" "$WORK" "${SEEDS[@]}" -max_total_time="$SECONDS_TOTAL" \
	-max_len=65536 -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 \
	"${PAR[@]}" -artifact_prefix="$FOUND/" > "$BUILD/fuzz_$TARGET.log" 2>&1)
rc=$?
set -e
grep -h "stat::number_of_executed_units\|stat::peak_rss_mb" "$BUILD/fuzz_$TARGET.log" "$BUILD"/fuzz-*.log 2>/dev/null || true
echo "corpus: $(ls "$WORK" | wc -l) inputs"
n=$(ls "$FOUND" | wc -l)
echo "findings: $n (in $FOUND)"
[ "$n" -eq 0 ] || { grep -h -m3 "ERROR:\|runtime error" "$BUILD/fuzz_$TARGET.log" "$BUILD"/fuzz-*.log 2>/dev/null || true; exit 1; }
exit $rc
