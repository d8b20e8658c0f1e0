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

# TLS for omniNames and nameclt, which are not linked with omniORB's SSL transport: it is
# preloaded, and configured through ORB* environment variables (the key's password too: the
# environment of a process is readable by its user and root only, its command line by all).
# Empty until omniORB is installed (a fresh machine sources this before `deps`): no pipeline here,
# whose failing `ls` would end the sourcing script under `set -euo pipefail` without a word.
SSL_TRANSPORT=
for lib in /usr/lib/*/libomnisslTP4.so.2; do
  [ -e "$lib" ] && { SSL_TRANSPORT=$lib; break; }
done
unset lib

# Finds this host's TLS identity as the components do (transport_security.h); sets TLS_CA,
# TLS_KEY, TLS_PASS_FILE, or dies saying which launch/caliper certs commands make them.
tls_identity() {
  local pki=${CALIPER_PKI:-$HOME/.config/caliper/pki}
  local id=${CALIPER_TLS_IDENTITY:-hosts/${CALIPER_HOST:-$(hostname -s)}}
  local d=${CALIPER_PKI:+ --dir $CALIPER_PKI}
  local make="launch/caliper certs ca$d (once per cluster) and launch/caliper certs host ${CALIPER_HOST:-$(hostname -s)}$d, or copy ca.pem and the host's .pem and .pass from the machine holding the CA; --insecure runs without TLS"
  TLS_CA=$pki/ca.pem
  case "$id" in *.pem) TLS_KEY=$id ;; *) TLS_KEY=$pki/$id.pem ;; esac
  TLS_PASS_FILE=${TLS_KEY%.pem}.pass
  [ -r "$TLS_CA" ] || die "network mode uses TLS: no CA certificate $TLS_CA; make it with $make"
  [ -r "$TLS_KEY" ] || die "network mode uses TLS: no identity $TLS_KEY for this host; make it with $make"
  [ -s "$TLS_PASS_FILE" ] || die "network mode uses TLS: no key password $TLS_PASS_FILE beside $TLS_KEY (launch/caliper certs writes both)"
  [ -n "$SSL_TRANSPORT" ] || die "omniORB's SSL transport libomnisslTP4.so.2 is missing (apt-get install libomniorb4-2)"
}

# runs an omniORB tool (omniNames, nameclt) with the SSL transport and this host's identity, in
# place of the calling (sub)shell: `(tls_exec omniNames ...) &` leaves omniNames's pid in $!
tls_exec() {  # COMMAND ARGS...
  local password
  password=$(cat "$TLS_PASS_FILE")
  export LD_PRELOAD=$SSL_TRANSPORT ORBsslCAFile=$TLS_CA ORBsslKeyFile=$TLS_KEY \
    ORBsslKeyPassword=$password ORBsslVerifyMode=peer,fail
  exec "$@"
}

# A directory for a session's unix sockets, only this user can enter: SESSION_DIR/sock, or a
# private one under /tmp when that path would be too long for a socket (107 bytes in all, so 87 for the directory). Sets
# and exports CALIPER_SOCKET_DIR.
session_socket_dir() {  # SESSION_DIR
  local dir=$1/sock
  if [ ${#dir} -gt 80 ]; then
    dir=$(mktemp -d "${TMPDIR:-/tmp}/caliper-sock.XXXXXX") || die "cannot make a socket directory"
    ln -sfn "$dir" "$1/sock"
  fi
  mkdir -p -m 700 "$dir" && chmod 700 "$dir"
  export CALIPER_SOCKET_DIR=$dir
}

naming_answers() {  # ADDRESS
  case "$1" in
    *:ssliop:*) (tls_exec timeout 5 nameclt -ORBInitRef "NameService=$1" list) >/dev/null 2>&1 ;;
    *) timeout 5 nameclt -ORBInitRef "NameService=$1" list >/dev/null 2>&1 ;;
  esac
}

# the omniNames of NS_PID answers at NS_ADDR within 5 s; else it is stopped and 1 returned
naming_started() {
  for _ in $(seq 1 50); do
    # ours answers (not another that took the port first: ours would have ended)
    naming_answers "$NS_ADDR" && kill -0 "$NS_PID" 2>/dev/null && return 0
    kill -0 "$NS_PID" 2>/dev/null || break
    sleep 0.1
  done
  kill "$NS_PID" 2>/dev/null || true
  return 1
}

# Starts omniNames in DIR; sets NS_PID, NS_ADDR (and NS_PORT on TCP). local (the default): on
# the unix socket SOCKDIR/naming.sock (SOCKDIR = $CALIPER_SOCKET_DIR, which must be a directory
# only this user can enter), address corbaname:omniunix:SOCKDIR/naming.sock: no other user of the
# host reaches it (libs/rtc local_sockets.h). tls: on giop:ssl only (plain TCP refused), with this
# host's identity; the address is then corbaname:ssliop:ADDRESS:PORT. plain: giop:tcp (network
# mode with --insecure).
# Messages up to 4 MiB (omniORB refuses larger ones): a reference with its TLS profile takes
# under a kilobyte, a binding's name a few dozen bytes; the components' messages go elsewhere.
start_nameserver() {  # DIR [LISTEN_ADDRESS [local|tls|plain]]
  local dir=$1 addr=${2:-127.0.0.1} mode=${3:-local} try
  local -a run=(exec) proto=tcp scheme="corbaname::"
  mkdir -p "$dir"
  if [ "$mode" = local ]; then
    # the sockets in DIR/sock unless the caller chose (session_socket_dir)
    [ -n "${CALIPER_SOCKET_DIR:-}" ] || session_socket_dir "$dir"
    local sock=$CALIPER_SOCKET_DIR/naming.sock
    rm -f "$sock"
    mkdir -p "$dir/omninames"
    # other ORBs (Tcl Combat) have no unix transport: loopback TCP too when asked
    local -a tcp=()
    NS_PORT=
    NS_TCP_ADDR=
    if [ "${CALIPER_LOOPBACK_TCP:-}" = 1 ]; then
      NS_PORT=$(free_port)
      tcp=(-ORBendPoint "giop:tcp:127.0.0.1:$NS_PORT")
      NS_TCP_ADDR="corbaname::127.0.0.1:$NS_PORT"
      say "WARNING: --loopback-tcp: the session also listens on 127.0.0.1 ($NS_TCP_ADDR, for other ORBs): every user of this host can reach it"
    fi
    (exec omniNames -start -always -nohostname -datadir "$dir/omninames" \
      -ORBendPoint "giop:unix:$sock" "${tcp[@]}" -ORBunixTransportPermission 0600 \
      -ORBgiopMaxMsgSize 4194304 >"$dir/omninames.log" 2>&1) &
    NS_PID=$!
    NS_ADDR="corbaname:omniunix:$sock"
    naming_started && return 0
    die "omniNames did not start on $sock, see $dir/omninames.log"
  fi
  if [ "$mode" = tls ]; then
    tls_identity
    run=(tls_exec env "ORBserverTransportRule=* ssl" "ORBclientTransportRule=* ssl")
    proto=ssl
    scheme="corbaname:ssliop:"
  fi
  local tries=3
  if [ -n "${CALIPER_NAMING_PORT:-}" ]; then
    tries=1
    # a port already served (another session's naming service) would seem to answer for ours
    if (exec 3<>"/dev/tcp/$addr/$CALIPER_NAMING_PORT") 2>/dev/null; then
      die "port $CALIPER_NAMING_PORT (--port) of $addr is taken: another session or program listens there (ss -ltnp)"
    fi
  fi
  for try in $(seq 1 $tries); do
    NS_PORT=${CALIPER_NAMING_PORT:-$(free_port)}
    mkdir -p "$dir/omninames-$NS_PORT"
    ("${run[@]}" omniNames -start "$NS_PORT" -always -nohostname \
      -datadir "$dir/omninames-$NS_PORT" -ORBendPoint "giop:$proto:$addr:$NS_PORT" \
      -ORBgiopMaxMsgSize 4194304 >"$dir/omninames.log" 2>&1) &
    NS_PID=$!
    NS_ADDR="$scheme$addr:$NS_PORT"
    naming_started && return 0
    say "omniNames did not start on port $NS_PORT (try $try), see $dir/omninames.log"
  done
  [ -z "${CALIPER_NAMING_PORT:-}" ] ||
    die "the naming service could not listen on port $CALIPER_NAMING_PORT (--port): is it taken? (ss -ltnp)"
  die "could not start the naming service"
}

