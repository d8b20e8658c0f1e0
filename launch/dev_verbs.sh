# Developer verbs of the Caliper launcher: bench, fuzz, faults, soak, and the sanitizer and CI
# runs of `test` (--sanitize; CI=true). Sourced by launch/caliper, not run: it uses that script's
# ROOT, BUILD, BIN, say, die, cmd_deps, cmd_build, ensure_built and run_ctest.
# shellcheck shell=bash

# their lines of `launch/caliper help`, between deps and ctl
dev_usage() {
  cat <<'USAGE'
  bench [physics|collada|model|gui|cluster|calibration|python|slurm|all]
                          build and run the benchmarks (all by default; physics: the engine
                          against raw Bullet and MuJoCo, collada: COLLADA and URDF load
                          times, model: the control cycle and DAQ, gui: plotter drawing, log
                          viewer filtering,
                          cluster: batch throughput with 1 and 2 Models, per-run overhead,
                          calibration: evaluations/s with 1 and 2 Models, python: the
                          package's control cycle against C++, record rate, vector
                          environment with 2 Models against 1, slurm (root): a sweep
                          through a real Slurm cluster of namespaces against directly started
                          managers, 1,000 runs with a node killed; model also: a call on a
                          unix socket against loopback TCP); one line
                          per figure: RATIO <name> <value> (target <target>)
  faults [--freeze S]     the fault suite on a GUI session with a controller (Xvfb when there is no
                          display): renderer and plotter stopped for S s (default 30), renderer,
                          main window, plotter, log viewer, logger, controller and naming service
                          killed and restarted in turn; then the full log disk (root); PASS/FAIL
  soak [--minutes M]      a GUI session with the controller at 1 kHz and a recording for M minutes
                          (default 10): every process's memory, descriptors and threads in a
                          table, PASS when flat after the warm-up (memory within 5 MiB)
  fuzz list | TARGET|all [--time S] [--runs N] [--keep-going]
                          fuzz a parser of outside input with libFuzzer (ASan+UBSan; installs
                          clang-14 when missing, builds build-fuzz/) for S seconds (default 60);
                          prints executions, coverage and findings, saved under
                          build-fuzz/findings/TARGET/ (see `fuzz --help`)
USAGE
}

# the part of `launch/caliper test --help` on --sanitize and CI
test_sanitize_usage() {
  cat <<'USAGE'
--sanitize address,undefined  build into build-asan-ubsan/ with ASan+UBSan and run the whole suite
                              (leaks are checked in the unit tests, not in the multi-process ones)
--sanitize thread             build into build-tsan/ with TSan and run all but the GUI tests (Qt,
                              Coin and Mesa are not instrumented: TSan reports races inside them)
  Reports (also those of the programs the tests start) are written under <dir>/sanitizer-reports/
  and printed at the end; any report fails the run. Suppressions of third-party reports:
  tests/sanitizers/*.supp.

With CI=true: after the plain suite, the unit tests (no ctest label) again under address,undefined
(CALIPER_CI_SANITIZE=none leaves them out, another value picks the sanitizers), and the run fails if
a test was skipped, unless tests/ci_allowed_skips.txt lists it with the reason.
USAGE
}

# ---------------------------------------------------------------- benchmarks
cmd_bench() {
  local which=${1:-all}
  [ $# -gt 0 ] && shift
  cmd_build
  case "$which" in
    physics|collada|model|gui|cluster|calibration|python|slurm|all) ;;
    *) die "bench physics|collada|model|gui|cluster|calibration|python|slurm|all" ;;
  esac
  if [ "$which" = physics ] || [ "$which" = all ]; then
    say "physics benchmarks (a minute or two)"
    "$BUILD/bench/physics_bench" "$@"
    "$BUILD/bench/actuators_bench"
  fi
  if [ "$which" = collada ] || [ "$which" = all ]; then
    "$BUILD/bench/collada_bench"
  fi
  if [ "$which" = model ] || [ "$which" = all ]; then
    say "model benchmarks (about half a minute)"
    "$BUILD/bench/model_bench"
    "$BUILD/bench/daq_bench"
    "$BUILD/bench/recording_bench"
  fi
  if [ "$which" = cluster ] || [ "$which" = all ]; then
    say "cluster benchmarks (about a minute)"
    CALIPER_BIN_DIR=$BIN bash "$ROOT/bench/cluster_bench.sh"
  fi
  if [ "$which" = slurm ] || [ "$which" = all ]; then
    if [ "$(id -u)" = 0 ]; then
      cmd_deps slurm
      say "slurm benchmarks (two minutes: a Slurm cluster of network namespaces, 200-run sweeps)"
      CALIPER_BIN_DIR=$BIN bash "$ROOT/bench/slurm_bench.sh"
    else
      say "slurm benchmarks skipped: they make a Slurm cluster of network namespaces, which needs root"
    fi
  fi
  if [ "$which" = calibration ] || [ "$which" = all ]; then
    say "calibration benchmarks (a minute; --example adds the example's wall time, minutes)"
    CALIPER_BIN_DIR=$BIN bash "$ROOT/bench/calibration_bench.sh" "$@"
  fi
  if [ "$which" = python ] || [ "$which" = all ]; then
    say "python benchmarks (about a minute)"
    PYTHONPATH=$BUILD/python CALIPER_BIN_DIR=$BIN /usr/bin/python3 "$ROOT/bench/python_bench.py" \
      --cpp-cycle "$BUILD/bench/control_cycle_bench"
  fi
  if [ "$which" = gui ] || [ "$which" = all ]; then
    # offscreen: no display needed
    for b in plotter_bench log_viewer_bench; do
      if [ -x "$BUILD/bench/$b" ]; then
        QT_QPA_PLATFORM=offscreen "$BUILD/bench/$b"
      else
        say "$b not built (CALIPER_GUI is off)"
      fi
    done
  fi
}

# ---------------------------------------------------------------- fuzzing
# libFuzzer targets of the parsers (fuzz/targets.txt) in their own clang build, build-fuzz/.
FUZZ_BUILD=${CALIPER_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}

fuzz_usage() {
  cat <<'USAGE'
Usage: launch/caliper fuzz list
       launch/caliper fuzz TARGET|all [--time S] [--runs N] [--keep-going] [-- LIBFUZZER ARGS]

Fuzzes a parser of outside input with libFuzzer, under ASan and UBSan: installs clang-14 and
libclang-rt-14-dev when missing, builds build-fuzz/ (clang, CALIPER_FUZZ=ON: only the targets and
the libraries they read with) and runs the target for S seconds (default 60; all: each target in
turn) or N executions. Seeds: the target's files in the source tree (fuzz/targets.txt), its
tests/data/fuzz/TARGET/ (seeds and regressions) and the shared corpus ($CALIPER_CORPUS, else
../shared/corpus) when present. What it found grows build-fuzz/corpus/TARGET/ (kept between runs).
Prints executions, executions/s, coverage (cov: edges, ft: features) and the findings: libFuzzer
stops at the first (--keep-going: goes on, in fork mode) and saves the input as
build-fuzz/findings/TARGET/crash-* (leak-, timeout-, oom-); the log is build-fuzz/logs/TARGET.log.
Reproduce with build-fuzz/fuzz/fuzz_TARGET FILE; once fixed, copy FILE into
tests/data/fuzz/TARGET/regressions/ (ctest's fuzz_TARGET_replay then runs it in every build).
A hang (10 s) or more than 2 GB of memory counts as a finding. Environment: CALIPER_JOBS,
CALIPER_FUZZ_BUILD_DIR (default build-fuzz/).
USAGE
}

# "NAME MAX_LEN DICT SEED..." lines of fuzz/targets.txt
fuzz_targets() { grep -E '^[a-z]' "$ROOT/fuzz/targets.txt"; }

fuzz_build() {  # TARGET...
  local missing="" p
  for p in clang-14 libclang-rt-14-dev; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
  done
  if [ -n "$missing" ]; then
    say "installing:$missing"
    local sudo=""
    [ "$(id -u)" = 0 ] || sudo=sudo
    # shellcheck disable=SC2086
    DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=300 install -y -qq \
      --no-install-recommends $missing >/dev/null || die "could not install$missing"
  fi
  cmd_deps
  if [ ! -f "$FUZZ_BUILD/build.ninja" ]; then
    say "configuring $FUZZ_BUILD (clang-14, libFuzzer, ASan, UBSan)"
    CC=clang-14 CXX=clang++-14 cmake -S "$ROOT" -B "$FUZZ_BUILD" -G Ninja \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCALIPER_FUZZ=ON -DCALIPER_TESTS=OFF \
      -DCALIPER_BENCH=OFF -DCALIPER_GUI=OFF -DCALIPER_WERROR=OFF >/dev/null || die "cmake failed"
  fi
  local targets=() t
  for t in "$@"; do targets+=("fuzz_$t"); done
  cmake --build "$FUZZ_BUILD" --target "${targets[@]}" -- -j"${CALIPER_JOBS:-$(nproc)}" >/dev/null ||
    die "building ${targets[*]} failed (run: cmake --build $FUZZ_BUILD)"
}

# one target; returns 1 when it found something
fuzz_run() {  # NAME MAX_LEN DICT SEEDS(space-separated) TIME RUNS KEEP [LIBFUZZER ARGS]
  local name=$1 max_len=$2 dict=$3 seeds=$4 time=$5 runs=$6 keep=$7
  shift 7
  local corpus=$FUZZ_BUILD/corpus/$name findings=$FUZZ_BUILD/findings/$name
  local log=$FUZZ_BUILD/logs/$name.log
  mkdir -p "$corpus" "$findings" "$FUZZ_BUILD/logs"
  local -a dirs=("$corpus") args=()
  local seed corpus_root=${CALIPER_CORPUS:-$ROOT/../shared/corpus}
  for seed in $seeds "tests/data/fuzz/$name"; do
    case "$seed" in
      CORPUS/*) seed=$corpus_root/${seed#CORPUS/} ;;
      *) seed=$ROOT/$seed ;;
    esac
    if [ -e "$seed" ]; then dirs+=("$seed"); else say "$name: no seeds at $seed (skipped)"; fi
  done
  [ "$dict" = - ] || args+=(-dict="$ROOT/fuzz/$dict")
  args+=(-max_len="$max_len" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
    -artifact_prefix="$findings/")
  [ -z "$time" ] || args+=(-max_total_time="$time")
  [ -z "$runs" ] || args+=(-runs="$runs")
  [ -z "$keep" ] || args+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  local before new started=$SECONDS
  before=$(find "$findings" -type f | sort)
  say "fuzzing $name for ${runs:+$runs executions}${runs:+${time:+ or }}${time:+$time s}: log $log"
  # the leaks of third-party libraries that the sanitizer runs suppress too (tests/sanitizers)
  (cd "$findings" && LSAN_OPTIONS="suppressions=$ROOT/tests/sanitizers/lsan.supp:print_suppressions=0" \
    "$FUZZ_BUILD/fuzz/fuzz_$name" "${args[@]}" "$@" "${dirs[@]}") >"$log" 2>&1 || true
  new=$(comm -13 <(echo "$before") <(find "$findings" -type f | sort) | sed '/^$/d')
  local last execs rate
  last=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 || true)
  # the final statistics; fork mode (--keep-going) counts only in its status lines
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  [ "${execs:-0}" != 0 ] || execs=$(sed -n 's/^#\([0-9]*\).*/\1/p' <<<"$last")
  rate=$(( ${execs:-0} / (SECONDS - started > 0 ? SECONDS - started : 1) ))
  printf '%s: %s executions in %d s (%s/s), cov %s, ft %s, corpus %s, findings %d new\n' \
    "$name" "${execs:-?}" "$((SECONDS - started))" "$rate" \
    "$(sed -n 's/.*cov: \([0-9]*\).*/\1/p' <<<"$last")" \
    "$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")" \
    "$(sed -n 's/.* corp: \([^ ]*\).*/\1/p' <<<"$last")" "$(grep -c . <<<"$new" || true)"
  if [ -n "$new" ]; then
    grep -E '^(==[0-9]+==ERROR|SUMMARY|fuzz: check failed)' "$log" | head -5 >&2 || true
    sed 's/^/  finding: /' <<<"$new" >&2
    say "reproduce: $FUZZ_BUILD/fuzz/fuzz_$name FILE; once fixed, copy FILE into tests/data/fuzz/$name/regressions/"
    return 1
  fi
  return 0
}

cmd_fuzz() {
  local which=${1:-}
  [ $# -gt 0 ] && shift
  case "$which" in
    ""|-h|--help|help) fuzz_usage; return 0 ;;
    list) fuzz_targets | awk '{printf "%-17s max %6s bytes, dictionary %s, seeds:", $1, $2, $3;
                                for (i = 4; i <= NF; i++) printf " %s", $i; print ""}'; return 0 ;;
  esac
  local time="" runs="" keep=""
  while [ $# -gt 0 ]; do
    case "$1" in
      --time) [[ "${2:-}" =~ ^[0-9]+$ ]] || die "fuzz: --time takes seconds"; time=$2; shift 2 ;;
      --runs) [[ "${2:-}" =~ ^[0-9]+$ ]] || die "fuzz: --runs takes a count"; runs=$2; shift 2 ;;
      --keep-going) keep=1; shift ;;
      --) shift; break ;;
      *) die "fuzz: unknown argument $1 (see launch/caliper fuzz --help)" ;;
    esac
  done
  [ -n "$time$runs" ] || time=60
  local -a lines=()
  mapfile -t lines < <(fuzz_targets | awk -v t="$which" 't == "all" || $1 == t')
  [ ${#lines[@]} -gt 0 ] || die "fuzz: no target '$which' (launch/caliper fuzz list)"
  local names=() line
  for line in "${lines[@]}"; do names+=("${line%% *}"); done
  fuzz_build "${names[@]}"
  local rc=0 name max_len dict seeds
  for line in "${lines[@]}"; do
    read -r name max_len dict seeds <<<"$line"
    fuzz_run "$name" "$max_len" "$dict" "$seeds" "$time" "$runs" "$keep" "$@" || rc=1
  done
  return $rc
}

# ---------------------------------------------------------------- faults and soak
# the suites of tests/faults, long forms (ctest runs short ones: fault_test --freeze 5, soak_test
# --minutes 1); each starts its own Xvfb when there is no display
faults_env() {
  export CALIPER_BIN_DIR=$BIN CALIPER_SOURCE_DIR=$ROOT CALIPER_CONFIG_DIR=$ROOT/config
  [ -x "$BIN/caliper-renderer" ] || die "the GUI is not built (it needs Qt5, Coin/SoQt and Qwt)"
}

cmd_faults() {
  local freeze=30
  while [ $# -gt 0 ]; do
    case "$1" in
      --freeze) [ $# -ge 2 ] || die "--freeze takes seconds"; freeze=$2; shift 2 ;;
      -h|--help) bash "$ROOT/tests/faults/fault_test.sh" --help; return 0 ;;
      *) die "faults: unknown argument $1 (see launch/caliper faults --help)" ;;
    esac
  done
  ensure_built
  faults_env
  local rc=0 out
  bash "$ROOT/tests/faults/fault_test.sh" --freeze "$freeze" || rc=1
  out=0
  bash "$ROOT/tests/faults/disk_full_test.sh" || out=$?
  case "$out" in 0) ;; 77) say "the full-disk test was skipped (see above)" ;; *) rc=1 ;; esac
  [ "$rc" = 0 ] && say "faults: PASS" || say "faults: FAIL"
  return $rc
}

cmd_soak() {
  local minutes=10
  while [ $# -gt 0 ]; do
    case "$1" in
      --minutes) [ $# -ge 2 ] || die "--minutes takes a number"; minutes=$2; shift 2 ;;
      -h|--help) bash "$ROOT/tests/faults/soak_test.sh" --help; return 0 ;;
      *) die "soak: unknown argument $1 (see launch/caliper soak --help)" ;;
    esac
  done
  ensure_built
  faults_env
  bash "$ROOT/tests/faults/soak_test.sh" --minutes "$minutes"
}

# ---------------------------------------------------------------- sanitizers and CI
# Sanitizer builds live beside build/: build-asan-ubsan/ and build-tsan/. What each cannot run:
#  - address,undefined: everything runs (LeakSanitizer in the unit tests only, see run_sanitized).
#  - thread: the GUI tests (label gui) are left out: Qt, Coin and Mesa are not built with TSan and
#    synchronise through atomics it cannot see, so it reports races inside them that are not ours.
# CI (CI=true) runs only the unit tests (no label: one process, no display) under address,undefined,
# after the plain suite: the integration and GUI tests would take it past its time.
SANITIZER_SUPP=$ROOT/tests/sanitizers
CI_ALLOWED_SKIPS=$ROOT/tests/ci_allowed_skips.txt

# "CTEST-NAME CASE" for each test ctest skipped in its last run in DIR (CASE: each GoogleTest case
# skipped, "-" for a script test), followed by a tab and the reason the test gave
skipped_cases() {  # DIR CTEST-OUTPUT
  local name
  for name in $(sed -n 's/^[[:space:]]*[0-9]* - \(.*\) (Skipped)$/\1/p' "$2"); do
    awk -v name="$name" '
      $0 ~ "^[0-9]+/[0-9]+ Testing: " { inside = ($3 == name); next }
      !inside { next }
      / Skipped$/ && $1 ~ /:[0-9]+:$/ { getline reason; next }
      /^SKIPPED: / { script = substr($0, 10) }
      /^\[  SKIPPED \] [^ ]+ \([0-9]+ ms\)$/ { print name, $4 "\t" reason; found = 1 }
      END { if (!found) print name, "-\t" script }
    ' "$1/Testing/Temporary/LastTest.log"
  done
}

# CI: every skip must be on the allow-list (CTEST-NAME CASE  # reason)
check_skips() {  # DIR CTEST-OUTPUT
  local bad=0 name case reason
  while IFS=$'\t' read -r line reason; do
    name=${line%% *}
    case=${line#* }
    if ! grep -v '^[[:space:]]*#' "$CI_ALLOWED_SKIPS" 2>/dev/null |
        awk -v n="$name" -v c="$case" '$1 == n && $2 == c && /#[[:space:]]*[^[:space:]]/ {f = 1} END {exit !f}'; then
      say "CI: $name skipped ${case/#-/the whole test}: ${reason:-no reason given}"
      bad=1
    fi
  done < <(skipped_cases "$1" "$2")
  [ "$bad" = 0 ] && return 0
  say "CI: tests were skipped (above); nothing should be skipped in CI (the corpus is beside the"
  say "    clone, Xvfb is started, CI is root). Fix the cause, or add the case to"
  say "    tests/ci_allowed_skips.txt with the reason CI may skip it."
  return 1
}

# build DIR with SANITIZERS and run ctest there (SCOPE all: everything the sanitizer can run;
# unit: the unit tests only); reports of every process go to DIR/sanitizer-reports
run_sanitized() {  # SANITIZERS SCOPE [CTEST ARGS]
  local sanitize=$1 scope=$2 dir
  shift 2
  local -a select=()
  case "$sanitize" in
    address,undefined|undefined,address) sanitize=address,undefined; dir=$BUILD-asan-ubsan ;;
    thread) dir=$BUILD-tsan; select=(-LE gui) ;;
    *) die "--sanitize takes address,undefined or thread, not '$sanitize'" ;;
  esac
  [ "$scope" = unit ] && select=(-LE 'gui|integration')
  if [ ! -f "$dir/build.ninja" ]; then
    say "configuring $dir (sanitizers $sanitize)"
    mkdir -p "$dir/.cmake/api/v1/query" && : >"$dir/.cmake/api/v1/query/codemodel-v2"
    cmake -S "$ROOT" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCALIPER_SANITIZE="$sanitize" -DCALIPER_WERROR=OFF -DCALIPER_BENCH=OFF >/dev/null || return 1
  fi
  # the unit tests alone need none of the programs: build only their targets (test name = target)
  local -a targets=()
  [ "$scope" = unit ] &&
    mapfile -t targets < <(ctest --test-dir "$dir" -N "${select[@]}" | sed -n 's/^ *Test *#[0-9]*: //p')
  local started=$SECONDS
  say "building $dir (sanitizers $sanitize${targets:+, the unit tests}; long the first time)"
  cmake --build "$dir" ${targets:+--target "${targets[@]}"} -- -j"${CALIPER_JOBS:-$(nproc)}" || return 1
  local reports=$dir/sanitizer-reports
  rm -rf "$reports"
  mkdir -p "$reports"
  say "built in $((SECONDS - started)) s"
  started=$SECONDS
  local rc=0 asan="halt_on_error=1:check_initialization_order=1:log_path=$reports/asan"
  export LSAN_OPTIONS="suppressions=$SANITIZER_SUPP/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$reports/ubsan"
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:suppressions=$SANITIZER_SUPP/tsan.supp:log_path=$reports/tsan"
  if [ "$sanitize" = address,undefined ] && [ "$scope" = all ]; then
    # leaks are checked in the unit tests; the processes of the integration and GUI tests keep
    # their ORB (and Qt, Coin, fontconfig, Mesa) until they exit, and LeakSanitizer cannot name
    # the frames of those uninstrumented libraries to suppress them one by one
    ASAN_OPTIONS="$asan:detect_leaks=1" run_ctest "$dir" -LE 'gui|integration' "$@" || rc=$?
    ASAN_OPTIONS="$asan:detect_leaks=0" run_ctest "$dir" -L 'gui|integration' "$@" || rc=$?
  else
    ASAN_OPTIONS="$asan:detect_leaks=1" run_ctest "$dir" "${select[@]}" "$@" || rc=$?
  fi
  unset LSAN_OPTIONS UBSAN_OPTIONS TSAN_OPTIONS
  local report
  for report in "$reports"/*; do
    [ -s "$report" ] || continue
    say "sanitizer report $report:"
    head -n 60 "$report" >&2
    rc=1
  done
  say "tests ran in $((SECONDS - started)) s"
  [ "$rc" = 0 ] && say "sanitizers $sanitize: no report" || say "sanitizers $sanitize: FAILED (above)"
  return "$rc"
}

# CI: after the plain suite, the unit tests again under CALIPER_CI_SANITIZE (default
# address,undefined; none leaves them out)
ci_sanitized_unit_tests() {  # [CTEST ARGS]
  local ci_sanitize=${CALIPER_CI_SANITIZE-address,undefined}
  if [ "${CI:-}" = true ] && [ -n "$ci_sanitize" ] && [ "$ci_sanitize" != none ]; then
    say "CI: the unit tests again under $ci_sanitize"
    run_sanitized "$ci_sanitize" unit "$@"
  fi
}
