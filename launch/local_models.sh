# Sourced by scripts that need Models on this machine alone (benchmarks, the calibration example,
# tests): a private naming service on a free loopback port and N Models, all stopped by
# local_models_stop. Needs BIN (the build's bin/); exports CALIPER_NAMESERVICE.
LOCAL_MODELS_PIDS=()

local_models_start() {  # WORKDIR COUNT
  local dir=$1 count=$2 port i
  # a port nobody listens on
  for _ in $(seq 1 100); do
    port=$((20000 + RANDOM % 20000))
    (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || break
  done
  mkdir -p "$dir"
  omniNames -start "$port" -always -nohostname -datadir "$dir" \
    -ORBendPoint "giop:tcp:127.0.0.1:$port" >"$dir/naming-service.out" 2>&1 &  # (omninames.log is its data file)
  LOCAL_MODELS_PIDS+=($!)
  export CALIPER_NAMESERVICE=corbaname::127.0.0.1:$port
  for _ in $(seq 1 50); do
    nameclt -ORBInitRef "NameService=$CALIPER_NAMESERVICE" list >/dev/null 2>&1 && break
    sleep 0.1
  done
  for i in $(seq 0 $((count - 1))); do local_models_add "$dir"; done
  for i in $(seq 0 $((count - 1))); do
    for _ in $(seq 1 100); do "$BIN/caliper-ctl" state "model$i" >/dev/null 2>&1 && break; sleep 0.1; done
  done
}

local_models_add() {  # WORKDIR: one more Model; LOCAL_MODEL_PID is its pid
  "$BIN/caliper-model" -o "log.spool_dir=$1/spool" -o log.level=warn >>"$1/models.out" 2>&1 &
  LOCAL_MODEL_PID=$!
  LOCAL_MODELS_PIDS+=($!)
}

local_models_stop() {
  local p
  for p in "${LOCAL_MODELS_PIDS[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${LOCAL_MODELS_PIDS[@]}"; do wait "$p" 2>/dev/null || true; done
}
