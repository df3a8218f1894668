#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang, ASan + UBSan, in build-fuzz) and runs each for
# SECONDS of wall time, then prints per target the executions, the CPU time, the corpus size and what
# it found. Usage: scripts/fuzz.sh SECONDS [TARGET...]   (targets: gmsh vtu vtk medit tetgen poly
# model expression mesh_pipeline frd csv; default all).
# Environment: FUZZ_JOBS (targets run at once, default 1), FUZZ_KEEP_GOING=1 (go on after a crash,
# hang or out-of-memory, collecting every one: libFuzzer's fork mode), FUZZ_NICE (default 19),
# FUZZ_NO_BUILD=1 (run what build-fuzz holds), FUZZ_SEED=N (reproducible: a fixed seed and a fixed
# number of inputs per target, about SECONDS at the target's rate on the CI machine (runs_per_second
# below), stopping at 3 x SECONDS whatever happens; CI uses it so that a run that passes here passes
# there, and a finding is reproduced by running the same command).
# The corpus grows in build-fuzz/corpus/TARGET across runs; seeds are written afresh each run into
# build-fuzz/seeds; inputs that crashed, hung or over-allocated land in build-fuzz/artifacts/TARGET/
# (crash-*, timeout-*, oom-*, leak-*): each becomes a file in tests/data/bad with a test.
# Exit status: 0 when no target found anything, 1 otherwise (or when the build fails).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:?usage: scripts/fuzz.sh SECONDS [TARGET...]}
shift
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(gmsh vtu vtk medit tetgen poly model expression mesh_pipeline frd csv)
jobs=${FUZZ_JOBS:-1}
nice_level=${FUZZ_NICE:-19}
cxx=${FUZZ_CXX:-clang++-14}
build=build-fuzz

if [ ! -f "$build/build.ninja" ]; then
  CMAKE_CXX_COMPILER_LAUNCHER=$(command -v ccache || true) \
  cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Fuzz \
    -DFOXI_BUILD_FUZZERS=ON -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DFOXI_BUILD_TESTS=OFF -DFOXI_BUILD_BENCH=OFF -DFOXI_WITH_QT=OFF -DFOXI_WITH_X11=OFF \
    > "$build.log" 2>&1 || { cat "$build.log"; exit 1; }
fi
[ "${FUZZ_NO_BUILD:-0}" = "1" ] || nice -n "$nice_level" ninja -C "$build" -j2 foxi_fuzzers
rm -rf "$build/seeds"
"$build/tests/fuzz/fuzz_make_seeds" "$build/seeds" > /dev/null

# Per target: the longest input (a few times the largest seed; the pipeline decodes at most ~500
# bytes), and the limits that turn a hang or an over-allocation into a finding: 10 s for one input,
# 2 GB of memory in all, 512 MB in one allocation (no input of this size may ask for more).
max_len() {
  case $1 in
    mesh_pipeline) echo 600 ;;
    expression) echo 4096 ;;
    *) echo 32768 ;;
  esac
}

# Inputs per second of each target on the CI machine (its log of 2026-11-26, ASan+UBSan+coverage;
# frd and csv: executions per CPU second of a 60 s run on 2026-11-27, 288k and 183k inputs;
# mesh_pipeline since it checks the volume painter on one input in 64, 2026-11-28: 2141 a second
# here against 4657 before, so 2900 scaled to 1300).
runs_per_second() {
  case $1 in
    gmsh) echo 9000 ;; vtu | vtk) echo 11000 ;; medit) echo 18000 ;; tetgen) echo 21000 ;;
    poly) echo 18000 ;; model) echo 100 ;; expression) echo 18000 ;; mesh_pipeline) echo 1300 ;;
    frd) echo 12000 ;; csv) echo 12000 ;;
    *) echo 1000 ;;
  esac
}

run_target() {
  local t=$1 corpus="$build/corpus/$1" art="$build/artifacts/$1/" log="$build/fuzz-$1.log"
  mkdir -p "$corpus" "$art"
  local extra=() limit=(-max_total_time="$seconds")
  if [ -n "${FUZZ_SEED:-}" ]; then
    # Reproducible: no corpus from earlier runs, no reloading, a fixed seed and count.
    rm -rf "$corpus" && mkdir -p "$corpus"
    limit=(-seed="$FUZZ_SEED" -runs=$(($(runs_per_second "$t") * seconds)) -max_total_time=$((3 * seconds)) -reload=0)
  fi
  if [ "${FUZZ_KEEP_GOING:-0}" = "1" ]; then
    extra=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  fi
  local status=0 TIMEFORMAT='%R %U %S'
  # bash's time: wall, and user and system CPU time of the fuzzer with its children (fork mode).
  { time nice -n "$nice_level" "$build/tests/fuzz/fuzz_$t" "${limit[@]}" \
      -max_len="$(max_len "$t")" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512 -print_final_stats=1 \
      -artifact_prefix="$art" "${extra[@]}" "$corpus" "$build/seeds/$t" > "$log" 2>&1 || status=$?; } \
    2> "$log.time"
  echo "$status $(cat "$log.time")" > "$log.status"
}

touch "$build/fuzz-start"
running=0
for t in "${targets[@]}"; do
  [ -f "tests/fuzz/fuzz_$t.cpp" ] || { echo "fuzz.sh: no target '$t'" >&2; exit 2; }
  run_target "$t" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait || true

found=0
printf '%-14s %12s %8s %8s %10s %8s %s\n' target executions wall_s cpu_s "exec/s" corpus findings
for t in "${targets[@]}"; do
  log="$build/fuzz-$t.log"
  read -r status wall user sys < "$log.status"
  # Plain mode prints stat::number_of_executed_units; fork mode prints "#N ... exec/s" lines only.
  execs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || true)
  [ -n "$execs" ] || execs=$(grep -o '^#[0-9]*' "$log" | tail -1 | tr -d '#' || true)
  [ -n "$execs" ] || execs=0
  corpus=$(find "$build/corpus/$t" -type f | wc -l)
  findings=$(find "$build/artifacts/$t" -type f -newer "$build/fuzz-start" | wc -l)
  rate=$(awk -v e="$execs" -v w="$wall" 'BEGIN { printf "%d", (w > 0 ? e / w : 0) }')
  printf '%-14s %12s %8.0f %8.0f %10s %8s %s\n' "$t" "$execs" "$wall" "$(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }')" "$rate" "$corpus" \
    "$([ "$findings" -gt 0 ] && echo "$findings in $build/artifacts/$t (log $log)" || echo none)"
  if [ "$status" != 0 ] || [ "$findings" -gt 0 ]; then found=1; fi
done
# What was found, in full: the report and each input in hex, so that a finding on another machine (CI
# keeps no files) can be read and reproduced (xxd -r -p).
if [ "$found" = 1 ]; then
  for t in "${targets[@]}"; do
    log="$build/fuzz-$t.log"
    read -r status _ < "$log.status"
    inputs=$(find "$build/artifacts/$t" -type f -newer "$build/fuzz-start")
    [ "$status" != 0 ] || [ -n "$inputs" ] || continue
    echo "=== $t (exit status $status): the end of $log"
    grep -a -v -E '^#[0-9]+|NEW_FUNC|^\s*$' "$log" | tail -60
    for f in $inputs; do
      echo "=== $t: $f ($(stat -c %s "$f") bytes), hex:"
      od -An -v -tx1 "$f" | tr -d ' \n' | fold -w 128
      echo
    done
  done
fi
exit $found
