#!/usr/bin/env bash
# Runs every test on a fresh machine: installs what is missing, builds (Release), runs all tests
# with CTest, installs foxi into a temporary prefix and builds and runs examples/embed against it
# (scripts/embed_test.sh); then builds every test with AddressSanitizer + UndefinedBehaviorSanitizer
# and runs them again, less those labelled `slow` (whole-model meshing and solving of every shipped model,
# signal trials: minutes each in Release, too long under the sanitizers for CI's budget) and the CGAL
# Mesh_3 model tests (40-90 s each in Debug with the sanitizers; they run in Release, and the PLC side
# is fuzzed), so readers on broken files never crash. The sanitizer build keeps line tables only (-g1: what its stack traces need),
# is optimized a little (-O1, as AddressSanitizer's own documentation advises; assertions stay on: no
# NDEBUG) and links with lld (half ld.bfd's CPU per program, and it links about a hundred): CI's budget.
# -O1 against -O0, measured on the 2-core CI-class machine (2026-11-28): the build 18.8 against 12.2
# minutes, its 683 tests 4.9 against 20.5 minutes (Eigen and CGAL at -O0 crawl). The Qt
# workbench and its tests (label qt) run in the Release pass only (-DFOXI_WITH_QT=OFF there): Qt's
# platform plugins keep allocations LeakSanitizer would report, and foxi::qt's painter calls are
# those the viz tests check under the sanitizers.
# Set FOXI_SKIP_SANITIZE=1 to skip the second.
# Last, the fuzz targets (clang, libFuzzer, build-fuzz) run about FOXI_FUZZ_SECONDS each (default 20),
# two at a time, from a fixed seed (FOXI_FUZZ_SEED, default 1: the same inputs on every run, so a
# finding is reproducible and CI does not fail by chance; long exploring runs are scripts/fuzz.sh's): an estimated 6-8 minutes
# of build on 2 cores (48 sources; heavy ones measured at 18-27 CPU-s each under ASan+UBSan+coverage) and 1.5 minutes of fuzzing. FOXI_SKIP_FUZZ=1 skips them.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/check_format.sh  # every C++ source as .clang-format says (clang-format-14)
bash scripts/build.sh
bash scripts/check_exports.sh build  # what the programs and tests call is FOXI_API (shared builds link)
ctest --test-dir build --output-on-failure -j2 --timeout 900
# foxi installed into a temporary prefix, and the host programs of examples/embed built against it.
bash scripts/embed_test.sh build
if [ "${FOXI_SKIP_SANITIZE:-0}" != "1" ]; then
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DFOXI_SANITIZE=ON -DFOXI_BUILD_BENCH=OFF -DFOXI_WITH_QT=OFF \
    -DCMAKE_CXX_FLAGS_DEBUG='-g1 -O1' -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld \
    > build-asan.log 2>&1 || { cat build-asan.log; exit 1; }
  ninja -C build-asan
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp \
    ctest --test-dir build-asan --output-on-failure -j2 --timeout 1800 -LE slow -E '^(CgalMesher|MeshCgalCli)[.]'
fi
if [ "${FOXI_SKIP_FUZZ:-0}" != "1" ]; then
  FUZZ_JOBS=2 FUZZ_NICE=0 FUZZ_SEED="${FOXI_FUZZ_SEED:-1}" bash scripts/fuzz.sh "${FOXI_FUZZ_SECONDS:-20}"
fi
