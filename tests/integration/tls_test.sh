#!/usr/bin/env bash
# TLS between components on a network, across three "hosts" made of Linux network namespaces:
#   hosta 198.51.100.1: `launch/caliper session --listen` (naming service, logger, Model) and
#                       the user alice's caliper-ctl
#   hostb 198.51.100.2: `launch/caliper node` with two Models
#   hostc 198.51.100.3: clients that must be refused: one without a certificate, mallory with a
#                       certificate of another CA (trusting only hers, or ours too)
# Certificates by `launch/caliper certs`; hostb gets only ca.pem and its own identity, copied.
# Checks: a batch of experiments passes over TLS; every network port of hosta and hostb answers a
# TLS handshake with its host's certificate and asks for a client certificate of our CA; plain
# GIOP to the naming service and to a Model is refused; the refused clients get a message that
# says why, from the naming service and from a Model reached directly (its reference bound in the
# intruder's own naming service). Needs root (ip netns); without it the test is skipped (exit 77)
# and says why.
set -uo pipefail
BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
TAG=tl$$
NETS=("$TAG-br" "$TAG-a" "$TAG-b" "$TAG-c")
WORK=$(mktemp -d)
FAILS=0

skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }
in_ns() { local n=$1; shift; ip netns exec "$TAG-$n" "$@"; }
launcher() { bash "$SRC/launch/caliper" "$@"; }
# the launcher's environment on host N: its own PKI directory, state and session folders
host_env() {  # N
  echo "CALIPER_HOST=host$1 CALIPER_PKI=$WORK/pki-$1 XDG_RUNTIME_DIR=$WORK/run-$1 \
CALIPER_SESSIONS_DIR=$WORK/sessions-$1 CALIPER_NODE_DIR=$WORK/node-$1 CALIPER_NO_BUILD=1 \
CALIPER_BUILD_DIR=$(dirname "$BIN") HOME=$WORK/home-$1"
}
# caliper-ctl as the user alice on hosta
alice() { in_ns a env CALIPER_HOST=hosta CALIPER_PKI="$WORK/pki-a" CALIPER_TLS_IDENTITY=users/alice \
  "$BIN/caliper-ctl" --nameservice "$NS" "$@"; }
expect_refused() {  # WHAT OUTPUT-FILE RC PATTERN
  if [ "$3" -ne 0 ] && grep -q -- "$4" "$2"; then
    pass "$1: $(grep -o -- "$4.*" "$2" | head -1 | cut -c1-160)"
  else
    fail "$1 (exit $3, expected a message matching '$4'):"; cat "$2"
  fi
}

cleanup() {
  local n p
  for n in "${NETS[@]}"; do
    for p in $(ip netns pids "$n" 2>/dev/null); do kill -KILL "$p" 2>/dev/null; done
  done
  sleep 0.2
  for n in "${NETS[@]}"; do ip netns del "$n" 2>/dev/null; done
  rm -rf "$WORK"
}

[ "$(id -u)" = 0 ] || skip "network namespaces need root (run the tests as root, as CI does)"
command -v ip >/dev/null || skip "no 'ip' command (apt-get install iproute2)"
command -v openssl >/dev/null || { echo "FAIL: no openssl command (launch/deps.txt lists it)"; exit 1; }
ip netns add "$TAG-probe" 2>/dev/null || skip "this kernel or container does not allow 'ip netns add'"
ip netns del "$TAG-probe"
trap cleanup EXIT
started=$SECONDS

# ---------------------------------------------------------------- the hosts
for n in "${NETS[@]}"; do ip netns add "$n" || { echo "FAIL: ip netns add $n"; exit 1; }; done
ip -n "$TAG-br" link add br0 type bridge
ip -n "$TAG-br" link set br0 up
ip -n "$TAG-br" link set lo up
i=1
for h in a b c; do
  ip -n "$TAG-br" link add "v$h" type veth peer name eth0 netns "$TAG-$h"
  ip -n "$TAG-br" link set "v$h" master br0 up
  ip -n "$TAG-$h" addr add "198.51.100.$i/24" dev eth0
  ip -n "$TAG-$h" link set eth0 up
  ip -n "$TAG-$h" link set lo up
  i=$((i + 1))
done

# ---------------------------------------------------------------- certificates
# the cluster's CA on hosta, identities for hosta, hostb and alice; hostb gets copies
launcher certs ca --dir "$WORK/pki-a" >"$WORK/certs.out" 2>&1 &&
  launcher certs host hosta --dir "$WORK/pki-a" >>"$WORK/certs.out" 2>&1 &&
  launcher certs host hostb --dir "$WORK/pki-a" >>"$WORK/certs.out" 2>&1 &&
  launcher certs user alice --dir "$WORK/pki-a" >>"$WORK/certs.out" 2>&1 ||
  { cat "$WORK/certs.out"; echo "FAIL: launch/caliper certs"; exit 1; }
modes=$(stat -c '%a %n' "$WORK"/pki-a/hosts/* "$WORK"/pki-a/users/* "$WORK"/pki-a/private/* |
  awk '$1 != 600' | xargs)
[ -z "$modes" ] && pass "keys and passwords have mode 0600" || fail "files not 0600: $modes"
mkdir -p "$WORK/pki-b/hosts"
cp -p "$WORK/pki-a/ca.pem" "$WORK/pki-b/"
cp -p "$WORK/pki-a/hosts/hostb.pem" "$WORK/pki-a/hosts/hostb.pass" "$WORK/pki-b/hosts/"
# mallory: a CA of her own, a user and a host (for her naming service); pki-m2 also trusts ours
launcher certs ca --dir "$WORK/pki-m" >>"$WORK/certs.out" 2>&1 &&
  launcher certs user mallory --dir "$WORK/pki-m" >>"$WORK/certs.out" 2>&1 &&
  launcher certs host evil --dir "$WORK/pki-m" >>"$WORK/certs.out" 2>&1 ||
  { cat "$WORK/certs.out"; echo "FAIL: launch/caliper certs for mallory"; exit 1; }
mkdir -p "$WORK/pki-m2"
cp -rp "$WORK/pki-m/users" "$WORK/pki-m/hosts" "$WORK/pki-m2/"
cat "$WORK/pki-a/ca.pem" "$WORK/pki-m/ca.pem" >"$WORK/pki-m2/ca.pem"

# ---------------------------------------------------------------- the session and the node
# shellcheck disable=SC2046
in_ns a env $(host_env a) bash "$SRC/launch/caliper" session --headless --listen 198.51.100.1 \
  >"$WORK/session.out" 2>&1 &
latest=$WORK/run-a/caliper-$(id -u)/latest-session
for _ in $(seq 1 300); do grep -q "session running" "$WORK/session.out" && break; sleep 0.1; done
NS=$(sed -n 1p "$latest" 2>/dev/null)
if grep -q "session running" "$WORK/session.out" && [[ "$NS" == corbaname:ssliop:198.51.100.1:* ]]; then
  pass "session --listen on hosta over TLS: $NS"
else
  cat "$WORK/session.out"; echo "FAIL: the TLS session did not start"; exit 1
fi
NS_PORT=${NS##*:}
# shellcheck disable=SC2046
in_ns b env $(host_env b) bash "$SRC/launch/caliper" node --nameservice "corbaname::198.51.100.1:$NS_PORT" \
  --listen 198.51.100.2 --models 2 >"$WORK/node.out" 2>&1 &
for _ in $(seq 1 300); do grep -q "node hostb: manager pid" "$WORK/node.out" && break; sleep 0.1; done
alice ls >"$WORK/ls.out" 2>&1
if [ "$(grep -c 'hostb.host_cxt/model' "$WORK/ls.out")" -eq 2 ] && grep -q 'hosta.host_cxt/model0' "$WORK/ls.out"; then
  pass "alice lists the Models of hosta and hostb (node given corbaname::, used over TLS)"
else
  cat "$WORK/node.out" "$WORK/ls.out"; fail "expected model0 on hosta and two Models on hostb"
fi

# ---------------------------------------------------------------- a batch over TLS
alice batch "$SRC/tests/data/cluster/arm_sweep.json" --out "$WORK/batch" >"$WORK/batch.out" 2>&1
rc=$?
done_rows=$(tail -n +2 "$WORK/batch/summary.csv" 2>/dev/null | cut -d, -f2 | grep -c '^done$')
if [ $rc -eq 0 ] && [ "$done_rows" -eq 6 ]; then pass "alice's batch of 6 experiments passed over TLS"
else cat "$WORK/batch.out"; fail "the batch exited $rc with $done_rows of 6 runs done"; fi

# ---------------------------------------------------------------- every network port is TLS
ports=0 tls=0
for h in a b; do
  addr=198.51.100.$([ $h = a ] && echo 1 || echo 2)
  for port in $(in_ns $h ss -ltnH | awk -v a="$addr:" 'index($4, a) == 1 {sub(/.*:/, "", $4); print $4}' | sort -u); do
    ports=$((ports + 1))
    in_ns c timeout 5 openssl s_client -connect "$addr:$port" -CAfile "$WORK/pki-a/ca.pem" \
      </dev/null >"$WORK/s_client.out" 2>&1
    if grep -q "subject=O = Caliper, OU = host, CN = host$h" "$WORK/s_client.out" &&
        grep -q "Verify return code: 0 (ok)" "$WORK/s_client.out" &&
        grep -q "Caliper CA" <(sed -n '/Acceptable client certificate CA names/,/^[A-Z]/p' "$WORK/s_client.out"); then
      tls=$((tls + 1))
    else
      echo "port $addr:$port:"; head -20 "$WORK/s_client.out"
    fi
  done
done
[ "$ports" -ge 5 ] && [ "$tls" -eq "$ports" ] &&
  pass "all $ports ports on 198.51.100.1-2 answer TLS with their host's certificate and ask for one of our CA" ||
  fail "$tls of $ports network ports answer a TLS handshake as expected"
model_port=$(in_ns b ss -ltnpH | grep caliper-model | awk '{sub(/.*:/, "", $4); print $4}' | head -1)

# ---------------------------------------------------------------- plain GIOP refused
in_ns c timeout 10 nameclt -ORBInitRef "NameService=corbaname::198.51.100.1:$NS_PORT" list \
  >"$WORK/plain-ns.out" 2>&1
expect_refused "plain GIOP to the naming service is refused" "$WORK/plain-ns.out" $? "COMM_FAILURE\|TRANSIENT"
in_ns c timeout 10 nameclt -ORBInitRef "NameService=corbaloc::198.51.100.2:$model_port/NameService" list \
  >"$WORK/plain-model.out" 2>&1
rc=$?
if grep -q "OBJECT_NOT_EXIST" "$WORK/plain-model.out"; then fail "a Model answered plain GIOP"
else expect_refused "plain GIOP to a Model (port $model_port) is refused" "$WORK/plain-model.out" $rc "COMM_FAILURE\|TRANSIENT"; fi

# ---------------------------------------------------------------- refused clients: the naming service
in_ns c env CALIPER_HOST=hostc CALIPER_INSECURE=1 "$BIN/caliper-ctl" --nameservice \
  "corbaname::198.51.100.1:$NS_PORT" ls >"$WORK/nocert.out" 2>&1
expect_refused "no certificate (--insecure), naming service" "$WORK/nocert.out" $? \
  "speaks TLS and requires a certificate of its cluster's CA"
grep -q "WARNING: INSECURE network mode" "$WORK/nocert.out" && pass "the --insecure client warned loudly" ||
  fail "no warning from the --insecure client"
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/none" "$BIN/caliper-ctl" --nameservice "$NS" ls \
  >"$WORK/nopki.out" 2>&1
expect_refused "no certificates at all: told how to make them" "$WORK/nopki.out" $? "launch/caliper certs ca"
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/pki-m" CALIPER_TLS_IDENTITY=users/mallory \
  "$BIN/caliper-ctl" --nameservice "$NS" ls >"$WORK/mallory-ns.out" 2>&1
expect_refused "another CA, naming service" "$WORK/mallory-ns.out" $? "is not signed by the cluster's CA"
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/pki-m2" CALIPER_TLS_IDENTITY=users/mallory \
  "$BIN/caliper-ctl" --nameservice "$NS" ls >"$WORK/mallory2-ns.out" 2>&1
expect_refused "another CA trusting ours, naming service" "$WORK/mallory2-ns.out" $? \
  "refused the TLS handshake (alert '.*'): it accepts only certificates of its own CA"

# ---------------------------------------------------------------- refused clients: a Model directly
# its reference, bound under the same name in the intruders' own naming services on hostc
ior=$(in_ns a bash -c "export $(host_env a); source '$SRC/launch/naming.sh'; tls_identity;
  (tls_exec nameclt -ORBInitRef 'NameService=$NS' resolve hostb.host_cxt/model0.rtc)" 2>"$WORK/ior.err")
[[ "$ior" == IOR:* ]] || { cat "$WORK/ior.err"; fail "could not resolve hostb's model0 over TLS"; }
bind_model() {  # ADDRESS-VARIABLE MODE PKI IDENTITY
  in_ns c bash -c "export CALIPER_PKI=$3 CALIPER_TLS_IDENTITY=$4; source '$SRC/launch/naming.sh';
    start_nameserver '$WORK/ns-$2' 127.0.0.1 $2 || exit 1; [ $2 = tls ] && tls_identity;
    run() { if [ $2 = tls ]; then (tls_exec \"\$@\"); else \"\$@\"; fi; }
    run nameclt -ORBInitRef NameService=\$NS_ADDR bind_new_context hostb.host_cxt >/dev/null &&
    run nameclt -ORBInitRef NameService=\$NS_ADDR bind hostb.host_cxt/model0.rtc '$ior' >/dev/null &&
    echo \$NS_ADDR" 2>"$WORK/bind-$2.err" | tail -1
}
plain_ns=$(bind_model plain plain "" "")
evil_ns=$(bind_model evil tls "$WORK/pki-m2" hosts/evil)
[ -n "$plain_ns" ] && [ -n "$evil_ns" ] || { cat "$WORK"/bind-*.err; fail "the intruders' naming services"; }
in_ns c env CALIPER_HOST=hostc "$BIN/caliper-ctl" --nameservice "$plain_ns" status --model hostb/model0 \
  >"$WORK/nocert-model.out" 2>&1
expect_refused "no certificate, a Model directly" "$WORK/nocert-model.out" $? \
  "(on 198.51.100.2) is reachable only over TLS with a certificate of its cluster's CA"
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/pki-m2" CALIPER_TLS_IDENTITY=users/mallory \
  "$BIN/caliper-ctl" --nameservice "$evil_ns" status --model hostb/model0 >"$WORK/mallory-model.out" 2>&1
expect_refused "another CA, a Model directly" "$WORK/mallory-model.out" $? \
  "198.51.100.2:[0-9]* refused the TLS handshake (alert '.*'): it accepts only certificates of its own CA"
# and alice, with the same reference from the same place, is served
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/pki-a" CALIPER_TLS_IDENTITY=users/alice CALIPER_LISTEN=198.51.100.3 \
  "$BIN/caliper-ctl" --nameservice "$NS" status --model hostb/model0 >"$WORK/alice-c.out" 2>&1 &&
  pass "alice on hostc is served by hostb's model0" || { cat "$WORK/alice-c.out"; fail "alice on hostc"; }

echo "tls_test: $((SECONDS - started)) s"
if [ $FAILS -eq 0 ]; then echo "tls_test: all checks passed"; exit 0; fi
echo "tls_test: $FAILS checks failed; the session's and the node's output:"
tail -n 20 "$WORK/session.out" "$WORK/node.out"
exit 1
