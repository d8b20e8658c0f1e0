# A private omniNames: sourced by launch/caliper and launch/local_models.sh.
# Uses say and die when the sourcing script has them.
command -v say >/dev/null || say() { printf '%s\n' "$*" >&2; }
command -v die >/dev/null || die() { printf 'error: %s\n' "$*" >&2; exit 1; }

free_port() {
  local port
  for _ in $(seq 1 100); do
    port=$((20000 + RANDOM % 20000))
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
      echo "$port"
      return 0
    fi
  done
  die "no free port found"
}

naming_answers() {  # ADDRESS
  timeout 5 nameclt -ORBInitRef "NameService=$1" list >/dev/null 2>&1
}

# Starts omniNames in DIR; sets NS_PORT, NS_PID, NS_ADDR.
start_nameserver() {  # DIR [LISTEN_ADDRESS]
  local dir=$1 addr=${2:-127.0.0.1} try
  mkdir -p "$dir"
  for try in 1 2 3; do
    NS_PORT=$(free_port)
    mkdir -p "$dir/omninames-$NS_PORT"
    omniNames -start "$NS_PORT" -always -nohostname -datadir "$dir/omninames-$NS_PORT" \
      -ORBendPoint "giop:tcp:$addr:$NS_PORT" -ORBgiopMaxMsgSize 268435456 \
      >"$dir/omninames.log" 2>&1 &
    NS_PID=$!
    NS_ADDR="corbaname::$addr:$NS_PORT"
    for _ in $(seq 1 50); do
      naming_answers "$NS_ADDR" && return 0
      kill -0 "$NS_PID" 2>/dev/null || break
      sleep 0.1
    done
    kill "$NS_PID" 2>/dev/null || true
    say "omniNames did not start on port $NS_PORT (try $try), see $dir/omninames.log"
  done
  die "could not start the naming service"
}

