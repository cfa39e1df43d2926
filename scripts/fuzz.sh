#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, clang + AddressSanitizer + UndefinedBehaviorSanitizer)
# in build-fuzz/ and runs each over its crash reproducers, then fuzzes it (docs/FUZZING.md).
# Usage: scripts/fuzz.sh [--runs N | --seconds S] [--regressions-only] [--merge] [target...]
#   --runs N            executions per target (default: --seconds 60)
#   --seconds S         wall time per target
#   --regressions-only  only replay tests/fuzz/regressions/<target>/ (no fuzzing)
#   --merge             afterwards, minimise tests/fuzz/corpus/<target>/ with what the run found
#   target...           fuzz_gltf fuzz_config ... (default: all of them)
# Environment: ARPIPE_BUILD_LOCK=/path: build under `flock` on that file (a shared machine);
# ARPIPE_FUZZ_JOBS: parallel compile jobs (default: nproc).
# Exit status: 0 when no target found anything, 1 on any crash, hang, leak or over-limit allocation
# (the input is saved under build-fuzz/fuzz-findings/<target>/), 2 on a usage or build error.
set -euo pipefail
cd "$(dirname "$0")/.."

# Every target of tests/fuzz/CMakeLists.txt, read from there so that a new one is never missed here.
mapfile -t all_targets < <(sed -n 's/^arpipe_fuzz_target(\(fuzz_[a-z_]*\).*/\1/p' tests/fuzz/CMakeLists.txt)
# Seeds beyond the target's own tests/fuzz/corpus/<target>/, one line per target (shared with the
# ctest runs in tests/fuzz/CMakeLists.txt); libFuzzer reads corpus folders recursively.
declare -A extra_seeds=()
while read -r target dirs; do
  case "$target" in ''|'#'*) continue ;; esac
  extra_seeds[$target]=$dirs
done <tests/fuzz/seed_dirs.txt
# fuzz_recording reads one file: a recording's parts joined by its separator line
# (tests/fuzz/fuzz_recording.cpp); every recording folder under tests/capture/corpus becomes one.
join_recordings() {
  local out=$1 dir part n=0
  local separator=$'\n--arpipe-fuzz-part--\n'
  while IFS= read -r dir; do
    dir=$(dirname "$dir")
    n=$((n + 1))
    for part in recording.json camera.cameramodel frames.jsonl ground_truth.jsonl; do
      if [ -f "$dir/$part" ]; then cat "$dir/$part"; fi
      printf '%s' "$separator"
    done >"$out/joined-$n"
    if [ -f "$dir/frames.bin" ]; then cat "$dir/frames.bin" >>"$out/joined-$n"; fi
  done < <(find tests/capture/corpus -name recording.json 2>/dev/null)
}
# The limits every run holds the parsers to (issue 18): a crash, a hang over 10 s, an allocation
# over 1 GB or a resident size over 2 GB is a finding. close_fd_mask=3 silences the parsers'
# stdout/stderr (libFuzzer keeps its own and the sanitizers' reports).
limits=(-rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=10 -close_fd_mask=3)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

budget=(-max_total_time=60)
regressions_only=0
merge=0
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) budget=(-runs="$2"); shift 2 ;;
    --seconds) budget=(-max_total_time="$2"); shift 2 ;;
    --regressions-only) regressions_only=1; shift ;;
    --merge) merge=1; shift ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    fuzz_*) targets+=("$1"); shift ;;
    *) echo "fuzz.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "fuzz.sh: no target '$t' (${all_targets[*]})" >&2; exit 2; }
done

# libFuzzer is part of clang: clang-14 and its runtime libraries (libclang_rt.fuzzer), Debian 12.
fuzz_packages=(clang-14 libclang-rt-14-dev)
missing=()
for p in "${fuzz_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "fuzz.sh: installing ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

build_dir=build-fuzz
lock=()
if [ -n "${ARPIPE_BUILD_LOCK:-}" ]; then lock=(flock "$ARPIPE_BUILD_LOCK"); fi
if [ ! -f "$build_dir/CMakeCache.txt" ]; then
  # -O1 -g1 without NDEBUG: fast enough to fuzz, line numbers in every report, assertions of the
  # header-only libraries (nlohmann-json, toml++, tinygltf) left on.
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DARPIPE_FUZZ=ON -DARPIPE_WERROR=OFF -DARPIPE_BUILD_BENCH=OFF >/dev/null
fi
"${lock[@]}" nice cmake --build "$build_dir" -j "${ARPIPE_FUZZ_JOBS:-$(nproc)}" --target "${targets[@]}" || exit 2

# A private scratch folder for the targets' temporary files (a crashing target leaves its own).
scratch=$(mktemp -d "${TMPDIR:-/tmp}/arpipe-fuzz.XXXXXX")
[ -d /dev/shm ] && { rmdir "$scratch"; scratch=$(mktemp -d /dev/shm/arpipe-fuzz.XXXXXX); }
trap 'rm -rf "$scratch"' EXIT
export ARPIPE_FUZZ_TMPDIR=$scratch

findings=0
summary=()
for t in "${targets[@]}"; do
  exe=$build_dir/tests/fuzz/$t
  log_dir=$build_dir/fuzz-logs
  findings_dir=$build_dir/fuzz-findings/$t
  mkdir -p "$log_dir" "$findings_dir"

  # Every saved crash reproducer must now load without a finding.
  regressions=tests/fuzz/regressions/$t
  if [ -d "$regressions" ] && [ -n "$(ls -A "$regressions")" ]; then
    if "$exe" "${limits[@]}" "$regressions"/* >"$log_dir/$t.regressions.log" 2>&1; then
      summary+=("$(printf '%-18s regressions: %d inputs, ok' "$t" "$(ls "$regressions" | wc -l)")")
    else
      findings=1
      summary+=("$(printf '%-18s regressions: FAILED (%s)' "$t" "$log_dir/$t.regressions.log")")
    fi
  fi
  [ "$regressions_only" -eq 1 ] && continue

  # New inputs go to a working corpus in the build folder; the committed seeds are read only.
  work=$build_dir/fuzz-corpus/$t
  mkdir -p "$work"
  seeds=(tests/fuzz/corpus/"$t")
  for d in ${extra_seeds[$t]}; do [ -d "$d" ] && seeds+=("$d"); done
  if [ "$t" = fuzz_recording ]; then
    mkdir -p "$scratch/joined-recordings"
    join_recordings "$scratch/joined-recordings"
    seeds+=("$scratch/joined-recordings")
  fi
  dict=()
  [ -f "tests/fuzz/dict/$t.dict" ] && dict=(-dict="tests/fuzz/dict/$t.dict")
  start=$(date +%s.%N)
  status=0
  "$exe" "${limits[@]}" "${budget[@]}" "${dict[@]}" -print_final_stats=1 -artifact_prefix="$findings_dir/" \
    "$work" "${seeds[@]}" >"$log_dir/$t.log" 2>&1 || status=$?
  seconds=$(echo "$(date +%s.%N) - $start" | bc)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log_dir/$t.log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log_dir/$t.log" | tail -1)
  if [ "$status" -eq 0 ]; then
    result=ok
  else
    findings=1
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log_dir/$t.log" | tail -1)
    kind=$(grep -m1 -o -E 'ERROR: (AddressSanitizer|UndefinedBehaviorSanitizer|libFuzzer|LeakSanitizer): [a-zA-Z-]+|runtime error: .*|broken promise: .*' \
             "$log_dir/$t.log" | head -c 120 || true)
    result="FINDING: ${kind:-exit $status} -> ${artifact:-see $log_dir/$t.log}"
  fi
  summary+=("$(printf '%-18s %10s execs  %7s exec/s  %6.0f s  %s' "$t" "${execs:-?}" "${rate:-?}" "$seconds" "$result")")

  if [ "$merge" -eq 1 ] && [ "$status" -eq 0 ]; then
    # Minimise: keep the smallest set of inputs that covers what the committed corpus and this
    # run's corpus cover together.
    merged=$(mktemp -d "$scratch/merge.XXXXXX")
    "$exe" -merge=1 "${limits[@]}" "$merged" tests/fuzz/corpus/"$t" "$work" >"$log_dir/$t.merge.log" 2>&1
    rm -rf tests/fuzz/corpus/"$t" && mkdir -p tests/fuzz/corpus/"$t" && cp "$merged"/* tests/fuzz/corpus/"$t"/
    summary+=("$(printf '%-18s corpus minimised: %d files, %s' "$t" "$(ls tests/fuzz/corpus/"$t" | wc -l)" \
                 "$(du -sh tests/fuzz/corpus/"$t" | cut -f1)")")
  fi
done

echo
echo "fuzz.sh: ${budget[*]}, ${limits[*]} (logs in $build_dir/fuzz-logs)"
printf '%s\n' "${summary[@]}"
exit "$findings"
