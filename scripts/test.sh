#!/usr/bin/env bash
# The whole test suite, five builds in separate directories:
#   1. Release: every test (unit, integration, the C API, the installed-package consumer, the live
#      view in Chromium), then the Python module's pytest suite with Debian's /usr/bin/python3, the
#      Godot addon's headless tests (godot3-server against uh serve) and the Unity package's
#      console tests (UnrealHaptics.dll under mono against libuh);
#   2. AddressSanitizer + UndefinedBehaviorSanitizer: every test (the live view's browser test once,
#      in the Release stage, is enough);
#   3. ThreadSanitizer: the tests labelled "threads" (cross-thread primitives, loops, sessions),
#      built alone (target uh_thread_tests);
#   4. Windows x64 (mingw-w64 cross build): the modules, uh.dll and the C API's tests, run under
#      wine64 (cmake/mingw-w64-x86_64.cmake);
#   5. libFuzzer (clang): short fuzz runs of the .ist loader (generated seeds), the scene
#      parser (the repository's scenes as seeds), the CSV reader (fuzz/csv_seeds), the service's
#      message parser (fuzz/protocol_seeds) and its inline-mesh frames (fuzz/mesh_binary_seeds),
#      the in-tree OBJ/STL reader (fuzz/mesh_seeds) and the museum's messages (fuzz/museum_seeds).
# Ends with one summary line: "tests: N passed, N failed".
set -uo pipefail
source "$(dirname "$0")/common.sh"
bash "$uh_root/scripts/install-deps.sh" || exit 1

passed=0
failed=0
status=0
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}

run_ctest() {
  local name=$1 dir=$2; shift 2
  echo "== ctest ($name) =="
  local log="$uh_root/$dir/ctest.log"
  # one test per core: most tests wait on threads, sockets and child processes as much as they
  # compute (the slowest start first, the load tests run alone: tests/CMakeLists.txt)
  (cd "$uh_root/$dir" && ctest --output-on-failure --timeout 900 --parallel "$uh_jobs" "$@") 2>&1 | tee "$log"
  local line
  line=$(grep -E "tests passed, [0-9]+ tests? failed out of" "$log" | tail -n 1)
  if [ -z "$line" ]; then echo "test: no ctest summary for $name"; status=1; return; fi
  local total fail
  total=$(sed -E 's/.*out of ([0-9]+).*/\1/' <<<"$line")
  fail=$(sed -E 's/.*tests passed, ([0-9]+) tests? failed.*/\1/' <<<"$line")
  passed=$((passed + total - fail))
  failed=$((failed + fail))
  [ "$fail" -eq 0 ] || status=1
}

# pytest's summary line, e.g. "2 failed, 11 passed, 1 error in 9.38s"
run_pytest() {
  echo "== pytest (Python module, /usr/bin/python3) =="
  local log="$uh_root/build/release/pytest.log"
  (cd "$uh_root" && PYTHONPATH="$uh_root/build/release/python" /usr/bin/python3 -m pytest -q -p no:cacheprovider \
     python/tests) 2>&1 | tee "$log"
  local line
  line=$(grep -E "^(=+ )?[0-9]+ (passed|failed|errors?)" "$log" | tail -n 1)
  if [ -z "$line" ]; then echo "test: no pytest summary"; status=1; failed=$((failed + 1)); return; fi
  local p f e
  p=$(grep -oE "[0-9]+ passed" <<<"$line" | grep -oE "[0-9]+" || true)
  f=$(grep -oE "[0-9]+ failed" <<<"$line" | grep -oE "[0-9]+" || true)
  e=$(grep -oE "[0-9]+ errors?" <<<"$line" | grep -oE "[0-9]+" || true)
  passed=$((passed + ${p:-0}))
  failed=$((failed + ${f:-0} + ${e:-0}))
  [ $((${f:-0} + ${e:-0})) -eq 0 ] || status=1
}

# An engine's own test runner, which ends with "N passed, N failed" (Godot's and the C# tests').
run_counted() {
  local name=$1 log=$2; shift 2
  echo "== $name =="
  "$@" 2>&1 | tee "$log"
  local line
  line=$(grep -E "^[0-9]+ passed, [0-9]+ failed$" "$log" | tail -n 1)
  if [ -z "$line" ]; then echo "test: no summary from $name"; status=1; failed=$((failed + 1)); return; fi
  local p f
  p=$(sed -E 's/^([0-9]+) passed.*/\1/' <<<"$line")
  f=$(sed -E 's/.*passed, ([0-9]+) failed$/\1/' <<<"$line")
  passed=$((passed + p))
  failed=$((failed + f))
  [ "$f" -eq 0 ] || status=1
}

# "== NAME ==" and the time the previous stage took, so a run's log shows where its minutes go
stage_name=""
stage_start=$SECONDS
stage() {
  [ -n "$stage_name" ] && echo "time: $stage_name and its tests took $((SECONDS - stage_start)) s"
  stage_name=$1
  stage_start=$SECONDS
  [ -n "$1" ] && echo "== $1 =="
}

stage "build (Release)"
if uh_build build/release -- -DCMAKE_BUILD_TYPE=Release -DUH_BUILD_TESTS=ON -DUH_BUILD_BENCHMARKS=ON; then
  run_ctest release build/release
  run_pytest
  run_counted "Godot addon (godot3-server, headless)" "$uh_root/build/release/godot-test.log" \
    bash "$uh_root/scripts/godot-test.sh" "$uh_root/build/release"
  run_counted "Unity package (C# under mono)" "$uh_root/build/release/unity-test.log" \
    env UH_SOURCE_DIR="$uh_root" UH_CACHE_DIR="$uh_root/build/release/test-cache" \
    timeout -k 5 300 mono "$uh_root/build/release/unity/UnrealHaptics.Tests.exe"
else
  echo "test: Release build failed"; status=1; failed=$((failed + 1))
fi

# The sanitizer builds: -O1 and line tables only (-g1) are all a sanitizer's report needs, and
# compile in half the time of -O2 -g (Boost.Beast's templates under ASan dominate the stage).
sanitizer_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
                 "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DUH_BUILD_BENCHMARKS=OFF -DUH_BUILD_VIEW=OFF)

stage "build (AddressSanitizer + UndefinedBehaviorSanitizer)"
if uh_build build/asan -- "${sanitizer_flags[@]}" -DUH_SANITIZE=address,undefined; then
  # fontconfig's process-long caches (cairo text in the PNG plots) are not ours to free
  LSAN_OPTIONS="suppressions=$uh_root/tests/support/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}" \
    run_ctest asan+ubsan build/asan -LE no_sanitizer
else
  echo "test: sanitizer build failed"; status=1; failed=$((failed + 1))
fi

stage "build (ThreadSanitizer)"
# only what the tests labelled "threads" run (tests/CMakeLists.txt, uh_thread_tests)
if uh_build build/tsan uh_thread_tests -- "${sanitizer_flags[@]}" -DUH_SANITIZE=thread; then
  run_ctest tsan build/tsan -L threads
else
  echo "test: ThreadSanitizer build failed"; status=1; failed=$((failed + 1))
fi

stage "build (Windows x64, mingw-w64; the C API's tests under wine64)"
if uh_build build/windows uh_capi_test -- -DCMAKE_TOOLCHAIN_FILE="$uh_root/cmake/mingw-w64-x86_64.cmake" \
     -DCMAKE_BUILD_TYPE=Release; then
  run_ctest windows build/windows
  # wine's server and its services outlive the last test program by a few seconds: end them now
  WINEPREFIX="$uh_root/build/windows/wine-prefix" /usr/lib/wine/wineserver -k 2>/dev/null || true
else
  echo "test: Windows build failed"; status=1; failed=$((failed + 1))
fi

stage "build (libFuzzer, clang)"
if command -v clang++ >/dev/null 2>&1; then
  if uh_build build/fuzz uh_ist_loader_fuzz uh_ist_seed_corpus uh_scene_parser_fuzz uh_csv_reader_fuzz uh_service_protocol_fuzz uh_service_mesh_binary_fuzz uh_mesh_reader_fuzz uh_museum_protocol_fuzz -- -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
       -DUH_BUILD_FUZZERS=ON -DUH_BUILD_APPS=OFF -DUH_BUILD_BENCHMARKS=OFF; then
    run_ctest fuzz build/fuzz -R '^(ist_|scene_parser_fuzz|csv_reader_fuzz|service_protocol_fuzz|service_mesh_binary_fuzz|mesh_reader_fuzz|museum_protocol_fuzz)'
  else
    echo "test: fuzzer build failed"; status=1; failed=$((failed + 1))
  fi
else
  echo "test: clang++ not found (scripts/install-deps.sh installs it)"; status=1; failed=$((failed + 1))
fi

stage ""
echo "time: the whole command took $SECONDS s"
echo "tests: $passed passed, $failed failed"
exit $status
