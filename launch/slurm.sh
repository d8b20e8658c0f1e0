# shellcheck shell=bash
# `launch/caliper slurm`: Caliper on a Slurm cluster (docs/slurm.md). Sourced by launch/caliper
# (ROOT, BUILD, BIN, say, die), not run. The job scripts are in launch/slurm/ for those who
# prefer sbatch by hand.

slurm_usage() {
  cat <<'USAGE'
Usage: launch/caliper slurm VERB ...

  batch FILE --out DIR [--nodes N] [--models-per-node M] [--array K] [--insecure]
        [--batch-args "..."] [SBATCH OPTIONS...]
      submit a batch of experiments (caliper-ctl batch FILE). One job (default): N nodes
      (default 2), the naming service and logger on the first, a manager with M Models (default
      2, also the CPUs asked per node) on each, over TLS with the certificates in $CALIPER_PKI
      (launch/caliper certs; hosts/NODE for every node, users/$USER for you), --insecure for
      plain GIOP. --array K: K array tasks instead, each with its share of the runs on M Models
      of its own node (a local session: no network, no certificates), then a merge job (after
      all of them) that gives DIR/runs/ and DIR/summary.csv as one job does.
      Further options go to sbatch as they are (--time, --partition, --account, --requeue, ...).
  calibrate FILE --out DIR [--nodes N] [--models-per-node M] [--insecure] [--calibrate-args "..."]
        [SBATCH OPTIONS...]
      submit a calibration (caliper-calibrate FILE) across N nodes, one island per Model
  status JOB|DIR
      the job's state (squeue) and its progress: runs done, failed, sim-s/s, ETA
  rerun DIR [--array K] [SBATCH OPTIONS...]
      submit again only the runs of DIR that have no result (cancelled, interrupted or in lost
      array tasks; a failed run, a physics fault, stays failed), as an array (default one task per 10 missing runs, at most 8) and a merge
  merge DIR
      put an array's results together now (the merge job does this by itself)

DIR must be on a filesystem every node sees. The checkout (and its build/) too: build it once on
the login node (launch/caliper build). Progress: launch/caliper slurm status JOB; logs in
DIR/session/ (one job) or DIR/tasks/*/ (arrays) and Slurm's slurm-JOB.out.
USAGE
}

slurm_need() {
  local c
  for c in sbatch squeue; do
    command -v "$c" >/dev/null ||
      die "no '$c': run this on a Slurm login node (launch/caliper deps slurm installs Debian's slurm-wlm, for a test cluster of your own)"
  done
}

SLURM_JOBS_DIR=${XDG_STATE_HOME:-$HOME/.local/state}/caliper/slurm-jobs

# remembers where a job writes, for `slurm status JOB`
slurm_remember() {  # JOB DIR
  mkdir -p "$SLURM_JOBS_DIR"
  printf '%s\n' "$2" >"$SLURM_JOBS_DIR/$1"
}

slurm_submit() {  # SBATCH ARGS...: prints the job id
  local out id
  out=$(sbatch --parsable "$@" 2>&1) || die "sbatch: $out"
  id=${out%%;*}
  [[ "$id" =~ ^[0-9]+$ ]] || die "sbatch said: $out"
  echo "$id"
}

# the runs of FILE as caliper-ctl batch makes them, in order
slurm_run_names() {  # FILE [--only @LIST]
  "$BIN/caliper-ctl" batch "$@" --list || die "cannot read the experiments of $1"
}

# an array of K tasks over the names in NAMES_FILE (round-robin), and its merge job; ROUND
# numbers the submissions of DIR (0 first, then each rerun)
slurm_submit_array() {  # FILE DIR ROUND K NAMES_FILE SBATCH_ARGS...
  local file=$1 dir=$2 round=$3 k=$4 names=$5 n total id merge
  shift 5
  total=$(grep -c . "$names" || true)
  [ "$total" -gt 0 ] || die "no runs to submit"
  [ "$k" -le "$total" ] || k=$total
  mkdir -p "$dir/array/$round"
  rm -f "$dir/array/$round"/task-*.txt
  n=0
  while IFS= read -r name; do
    printf '%s\n' "$name" >>"$dir/array/$round/task-$((n % k)).txt"
    n=$((n + 1))
  done <"$names"
  id=$(slurm_submit --array "0-$((k - 1))" --cpus-per-task "$MODELS_PER_NODE" \
    -o "$dir/array/$round/slurm-%A_%a.out" "$@" \
    "$ROOT/launch/slurm/caliper-array-task.sbatch" "$file" "$dir" "$round")
  merge=$(slurm_submit --dependency "afterany:$id" -o "$dir/array/$round/slurm-merge-%j.out" \
    "$ROOT/launch/slurm/caliper-array-merge.sbatch" "$dir")
  printf 'round %s: array job %s (%s tasks, %s runs), merge job %s\n' "$round" "$id" "$k" "$total" \
    "$merge" >>"$dir/array/jobs.txt"
  slurm_remember "$id" "$dir"
  slurm_remember "$merge" "$dir"
  say "array job $id: $total runs in $k tasks of $MODELS_PER_NODE Models; merge job $merge after it"
  say "watch: launch/caliper slurm status $id    results: $dir/runs/, $dir/summary.csv"
  echo "$id $merge"
}

cmd_slurm() {
  local verb=${1:-help}
  [ $# -gt 0 ] && shift
  case "$verb" in
    help|-h|--help) slurm_usage; return 0 ;;
    batch|calibrate) slurm_job "$verb" "$@" ;;
    status) slurm_status "$@" ;;
    rerun) slurm_rerun "$@" ;;
    merge) [ $# -eq 1 ] || die "usage: launch/caliper slurm merge DIR"; /usr/bin/python3 "$ROOT/launch/slurm/merge.py" "$1" ;;
    *) slurm_usage >&2; die "unknown slurm verb '$verb'" ;;
  esac
}

slurm_job() {  # batch|calibrate FILE --out DIR ...
  local mode=$1 file="" dir="" nodes=2 array=0 id
  MODELS_PER_NODE=2
  shift
  local -a sbatch_args=()
  while [ $# -gt 0 ]; do
    case "$1" in
      --out) dir=${2:?--out takes a directory}; shift 2 ;;
      --nodes|-N) nodes=${2:?--nodes takes a number}; shift 2 ;;
      --models-per-node) MODELS_PER_NODE=${2:?--models-per-node takes a number}; shift 2 ;;
      --array) array=${2:?--array takes a number of tasks}; shift 2 ;;
      --insecure) export CALIPER_INSECURE=1; shift ;;
      --batch-args) export CALIPER_BATCH_ARGS=${2:-}; shift 2 ;;
      --calibrate-args) export CALIPER_CALIBRATE_ARGS=${2:-}; shift 2 ;;
      -h|--help) slurm_usage; return 0 ;;
      -*) sbatch_args+=("$1"); shift ;;
      *) if [ -z "$file" ]; then file=$1; else sbatch_args+=("$1"); fi; shift ;;
    esac
  done
  [ -n "$file" ] || die "slurm $mode: which FILE? (launch/caliper slurm --help)"
  [ -f "$file" ] || die "no file $file"
  [ -n "$dir" ] || die "slurm $mode: --out DIR (a directory every node sees) is needed"
  for n in "$nodes" "$MODELS_PER_NODE" "$array"; do
    [[ "$n" =~ ^[0-9]+$ ]] || die "--nodes, --models-per-node and --array take whole numbers, not '$n'"
  done
  [ "$MODELS_PER_NODE" -ge 1 ] || die "--models-per-node: at least 1"
  slurm_need
  [ -x "$BIN/caliper-ctl" ] || die "no build at $BIN: run launch/caliper build first (on a filesystem the nodes see)"
  file=$(realpath "$file")
  mkdir -p "$dir" || die "cannot make $dir"
  dir=$(realpath "$dir")
  export CALIPER_ROOT=$ROOT CALIPER_BUILD_DIR=$BUILD
  # what a rerun needs
  printf 'mode=%q\nfile=%q\nmodels_per_node=%q\n' "$mode" "$file" "$MODELS_PER_NODE" >"$dir/submit.env"
  if [ "$array" -gt 0 ]; then
    [ "$mode" = batch ] || die "--array is for batch runs"
    mkdir -p "$dir/array"
    slurm_run_names "$file" >"$dir/array/names.txt.tmp"
    mv "$dir/array/names.txt.tmp" "$dir/array/names.txt"
    slurm_submit_array "$file" "$dir" 0 "$array" "$dir/array/names.txt" "${sbatch_args[@]}" >/dev/null
    return 0
  fi
  [ "${CALIPER_INSECURE:-}" = 1 ] || slurm_check_pki
  id=$(slurm_submit -N "$nodes" --cpus-per-task "$MODELS_PER_NODE" -o "$dir/slurm-%j.out" \
    "${sbatch_args[@]}" "$ROOT/launch/slurm/caliper-job.sbatch" "$mode" "$file" "$dir")
  slurm_remember "$id" "$dir"
  say "job $id: $mode of $file on $nodes nodes with $MODELS_PER_NODE Models each; results in $dir"
  say "watch: launch/caliper slurm status $id    cancel: scancel $id"
  echo "$id"
}

# TLS: the CA and the user's identity must exist before the job waits in the queue for nothing
slurm_check_pki() {
  local pki=${CALIPER_PKI:-$HOME/.config/caliper/pki}
  [ -r "$pki/ca.pem" ] && [ -r "$pki/users/${USER:-$(id -un)}.pem" ] && return 0
  die "the job talks TLS between nodes: no $pki/ca.pem or users/${USER:-$(id -un)}.pem; make them once with launch/caliper certs ca, certs user ${USER:-$(id -un)} and certs host NODE for every node (docs/slurm.md), or pass --insecure"
}

slurm_dir_of() {  # JOB|DIR: prints DIR
  if [ -d "$1" ]; then realpath "$1"; return 0; fi
  [ -f "$SLURM_JOBS_DIR/$1" ] || die "no job $1 submitted from here (and no directory $1)"
  cat "$SLURM_JOBS_DIR/$1"
}

slurm_status() {
  [ $# -eq 1 ] || die "usage: launch/caliper slurm status JOB|DIR"
  local dir
  dir=$(slurm_dir_of "$1")
  if command -v squeue >/dev/null; then
    local jobs
    jobs=$(cat "$dir/job.txt" "$dir/array/jobs.txt" 2>/dev/null | grep -o 'job [0-9]*' |
      awk '{print $2}' | xargs | tr ' ' ',' || true)
    if [ -n "$jobs" ]; then
      squeue -h -j "$jobs" -o '%i %j %T %M %R' 2>/dev/null | sed 's/^/queue: /' || true
    fi
  fi
  /usr/bin/python3 - "$dir" <<'PY'
import csv, glob, json, os, sys, time
d = sys.argv[1]
files = [os.path.join(d, "status.json")] + sorted(glob.glob(os.path.join(d, "tasks", "*", "status.json")))
rows = []
for f in files:
    try:
        with open(f) as fh:
            rows.append((f, json.load(fh)))
    except (OSError, ValueError):
        pass
if not rows:
    print(f"{d}: no status yet (the job has not started)")
    sys.exit(0)
def num(s, k):
    try:
        return float(s.get(k) or 0)
    except ValueError:
        return 0.0
total = sum(num(s, "runs_total") for _, s in rows)
done = sum(num(s, "runs_done") for _, s in rows)
failed = sum(num(s, "runs_failed") for _, s in rows)
running = [s for _, s in rows if s.get("state") in ("running", "starting", "finishing")]
rate = sum(num(s, "sim_s_per_s") for s in running)
eta = max([num(s, "eta_s") for s in running] or [0])
states = sorted({s.get("state", "?") for _, s in rows})
age = time.time() - max(num(s, "updated_unix_s") for _, s in rows)
parts = [f"{int(done)}/{int(total)} runs done" if total else "starting"]
if failed:
    parts.append(f"{int(failed)} failed")
if running and rate:
    parts.append(f"{rate:.2f} sim-s/s")
if running and eta:
    parts.append(f"ETA {eta:.0f} s")
print(f"{d}: {', '.join(parts)} ({'/'.join(states)}; updated {age:.0f} s ago)")
summary = os.path.join(d, "summary.csv")
if os.path.exists(summary) and not running:
    with open(summary, newline="") as fh:
        lines = [r for r in csv.reader(fh) if r][1:]
    left = [r[0] for r in lines if r[1:2] != ["done"]]
    print(f"summary: {summary}: {len(lines) - len(left)} of {len(lines)} done" +
          (f"; not done: {', '.join(left[:10])}{' ...' if len(left) > 10 else ''}"
           f" (launch/caliper slurm rerun {d})" if left else ""))
PY
}

slurm_rerun() {
  local dir="" k=0 round
  local -a sbatch_args=()
  while [ $# -gt 0 ]; do
    case "$1" in
      --array) k=${2:?--array takes a number}; shift 2 ;;
      -*) sbatch_args+=("$1"); shift ;;
      *) if [ -z "$dir" ]; then dir=$1; else sbatch_args+=("$1"); fi; shift ;;
    esac
  done
  [ -n "$dir" ] && [ -f "$dir/submit.env" ] || die "usage: launch/caliper slurm rerun DIR (a directory of slurm batch)"
  slurm_need
  dir=$(realpath "$dir")
  local mode file models_per_node
  # shellcheck disable=SC1091
  source "$dir/submit.env"
  MODELS_PER_NODE=$models_per_node
  [ "$mode" = batch ] || die "rerun is for batch runs (a calibration resumes: caliper-calibrate --resume)"
  export CALIPER_ROOT=$ROOT CALIPER_BUILD_DIR=$BUILD
  mkdir -p "$dir/array"
  [ -s "$dir/array/names.txt" ] || slurm_run_names "$file" >"$dir/array/names.txt"
  # bring the summary up to date with what every task left, then take what is not done
  # (merge.py writes array/missing.txt; exit 1 when some are missing)
  /usr/bin/python3 "$ROOT/launch/slurm/merge.py" "$dir" >/dev/null || true
  local n
  n=$(grep -c . "$dir/array/missing.txt" || true)
  [ "$n" -gt 0 ] || { say "every run of $dir is done: nothing to rerun"; return 0; }
  round=1
  while [ -d "$dir/array/$round" ]; do round=$((round + 1)); done
  [ "$k" -gt 0 ] || k=$(( (n + 9) / 10 > 8 ? 8 : (n + 9) / 10 ))
  say "$n runs without a result: submitting them again"
  slurm_submit_array "$file" "$dir" "$round" "$k" "$dir/array/missing.txt" "${sbatch_args[@]}"
}
