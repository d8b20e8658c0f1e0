# Sourced by scripts that need Models on this machine alone (benchmarks, the calibration example,
# tests): a private naming service on a unix socket only this user reaches and N Models, all stopped by
# local_models_stop. Needs BIN (the build's bin/); exports CALIPER_NAMESERVICE.
LOCAL_MODELS_PIDS=()

# shellcheck source=naming.sh
source "$(dirname "${BASH_SOURCE[0]}")/naming.sh"

local_models_start() {  # WORKDIR COUNT
  local dir=$1 count=$2 i
  session_socket_dir "$dir"
  start_nameserver "$dir"
  LOCAL_MODELS_PIDS+=("$NS_PID")
  export CALIPER_NAMESERVICE=$NS_ADDR
  for i in $(seq 0 $((count - 1))); do local_models_add "$dir"; done
  for i in $(seq 0 $((count - 1))); do
    for _ in $(seq 1 100); do "$BIN/caliper-ctl" state "model$i" >/dev/null 2>&1 && break; sleep 0.1; done
  done
}

local_models_add() {  # WORKDIR: one more Model; LOCAL_MODEL_PID is its pid
  # it dies with the script that started it (setpriv --pdeathsig), also when that is killed
  setpriv --pdeathsig TERM "$BIN/caliper-model" -o "log.spool_dir=$1/spool" -o log.level=warn \
    >>"$1/models.out" 2>&1 &
  LOCAL_MODEL_PID=$!
  LOCAL_MODELS_PIDS+=($!)
}

local_models_stop() {
  local p
  for p in "${LOCAL_MODELS_PIDS[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${LOCAL_MODELS_PIDS[@]}"; do wait "$p" 2>/dev/null || true; done
}

# The usual use: a temporary directory (WORK) and COUNT Models, all gone when the script exits.
local_models_session() {  # COUNT
  WORK=$(mktemp -d)
  trap 'local_models_stop; rm -rf "$WORK"' EXIT
  local_models_start "$WORK" "$1"
}
