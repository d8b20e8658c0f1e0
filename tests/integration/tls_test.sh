#!/usr/bin/env bash
# TLS between components on a network, across three "hosts" made of Linux network namespaces:
#   hosta 198.51.100.1: `launch/caliper session --listen` (naming service, logger, Model) and
#                       the user alice's caliper-ctl
#   hostb 198.51.100.2: `launch/caliper node` with two Models
#   hostc 198.51.100.3: clients that must be refused: one without a certificate, mallory with a
#                       certificate of another CA (trusting only hers, or ours too)
# Certificates by `launch/caliper certs`; hostb gets only ca.pem and its own identity, copied.
# Checks: a batch of experiments passes over TLS; every network port of hosta and hostb (naming
# service, logger, Models, manager) answers a TLS handshake with its host's certificate, asks for
# a client certificate of our CA, and refuses a real handshake without a certificate (alert
# "certificate required") and with one of another CA (alert "unknown CA"); plain GIOP to the
# naming service and to a Model is refused, and so is a plain endpoint added with -ORBendPoint;
# the refused clients get a message that says why, from the naming service and from a Model, the
# logger and the manager reached directly (their references bound in the intruder's own naming
# service). Needs root (ip netns); without it the test is skipped (exit 77) and says why.
set -uo pipefail
TAG=tl$$
# shellcheck source=support/netns.sh
source "$(dirname "${BASH_SOURCE[0]}")/support/netns.sh"  # BIN, SRC, WORK, skip, fail, pass, in_ns...

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

netns_require
command -v openssl >/dev/null || { echo "FAIL: no openssl command (launch/deps.txt lists it)"; exit 1; }
started=$SECONDS

# ---------------------------------------------------------------- the hosts
netns_hosts

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

# ---------------------------------------------------------------- the Python package over TLS
# alice's Python: Models of both hosts, a scene sent by content to hostb, steps, the same batch
PY_DIR=$(cd "$BIN/.." && pwd)/python
if [ -f "$PY_DIR/caliper/__init__.py" ]; then
  in_ns a env CALIPER_HOST=hosta CALIPER_PKI="$WORK/pki-a" CALIPER_TLS_IDENTITY=users/alice \
    PYTHONPATH="$PY_DIR" CALIPER_BIN_DIR="$BIN" PYTHONDONTWRITEBYTECODE=1 \
    /usr/bin/python3 - "$NS" "$SRC" >"$WORK/python.out" 2>&1 <<'PYTHON'
import sys
import caliper
session = caliper.connect(sys.argv[1])
models = session.models()
remote = [m for m in models if m.endswith("@hostb")]
assert len(remote) == 2 and "model0@hosta" in models, models
arm = session.model(remote[0])
assert not arm.local
arm.load(sys.argv[2] + "/models/ecce_arm.dae")  # another host: by content
arm.set_commands({"elbow_flexor": 6.0})
assert arm.step(200) == 200 and float(arm.get("ecce_arm.elbow.position")) > 0.001
batch = caliper.run_batch(sys.argv[2] + "/tests/data/cluster/arm_sweep.json", session,
                          progress=False)
assert len(batch.results) == 6 and not batch.failures, batch.failures
print("python over TLS:", " ".join(models), "|", len(batch.results), "runs")
PYTHON
  rc=$?
  if [ $rc -eq 0 ]; then pass "$(grep 'python over TLS' "$WORK/python.out")"
  else cat "$WORK/python.out"; fail "alice's Python over TLS exited $rc"; fi
else
  echo "note: the Python package is not built (CALIPER_PYTHON off): its part is left out"
fi

# ---------------------------------------------------------------- every network port is TLS
# s_client CLIENT-OPTIONS... against ADDR:PORT from hostc; -ign_eof keeps it reading after the
# handshake until the server closes: a TLS 1.3 server refuses a client certificate (or its
# absence) after the client's side of the handshake, with an alert the client must wait for
s_client() {  # ADDR:PORT OUT [OPTIONS...]
  local to=$1 out=$2; shift 2
  in_ns c timeout 5 openssl s_client -ign_eof -connect "$to" -CAfile "$WORK/pki-a/ca.pem" "$@" \
    </dev/null >"$out" 2>&1
}
ports=0 tls=0 nocert=0 foreign=0 owners=""
for h in a b; do
  addr=198.51.100.$([ $h = a ] && echo 1 || echo 2)
  for port in $(in_ns $h ss -ltnH | awk -v a="$addr:" 'index($4, a) == 1 {sub(/.*:/, "", $4); print $4}' | sort -u); do
    ports=$((ports + 1))
    owner=$(in_ns $h ss -ltnpH "sport = :$port" | grep -o 'users:(("[^"]*"' | cut -d'"' -f2 | head -1)
    owners="$owners $owner"
    s_client "$addr:$port" "$WORK/s_client.out"
    if grep -q "subject=O = Caliper, OU = host, CN = host$h" "$WORK/s_client.out" &&
        grep -q "Verify return code: 0 (ok)" "$WORK/s_client.out" &&
        grep -q "Caliper CA" <(sed -n '/Acceptable client certificate CA names/,/^[A-Z]/p' "$WORK/s_client.out"); then
      tls=$((tls + 1))
    else
      echo "port $addr:$port ($owner):"; head -20 "$WORK/s_client.out"
    fi
    # the same handshake, which sent no certificate, refused by the server
    if grep -q "alert certificate required" "$WORK/s_client.out"; then nocert=$((nocert + 1))
    else echo "port $addr:$port ($owner) without a certificate:"; grep -i "alert\|error\|Verify" "$WORK/s_client.out"; fi
    # mallory's certificate, of another CA
    s_client "$addr:$port" "$WORK/s_client-m.out" -cert "$WORK/pki-m/users/mallory.pem" \
      -pass "file:$WORK/pki-m/users/mallory.pass"
    if grep -q "alert unknown ca" "$WORK/s_client-m.out"; then foreign=$((foreign + 1))
    else echo "port $addr:$port ($owner) with another CA's certificate:"; grep -i "alert\|error\|Verify" "$WORK/s_client-m.out"; fi
  done
done
owners=$(echo "$owners" | xargs -n1 | sort | uniq -c | xargs)
echo "network ports: $owners"
for p in omniNames caliper-logger caliper-model caliper-manager; do
  [[ " $owners " == *" $p "* ]] || fail "no network port of $p among the ports checked"
done
[ "$ports" -ge 6 ] && [ "$tls" -eq "$ports" ] &&
  pass "all $ports ports on 198.51.100.1-2 answer TLS with their host's certificate and ask for one of our CA" ||
  fail "$tls of $ports network ports answer a TLS handshake as expected"
[ "$ports" -ge 6 ] && [ "$nocert" -eq "$ports" ] &&
  pass "all $ports ports refuse a TLS handshake without a client certificate (alert 'certificate required')" ||
  fail "$nocert of $ports network ports refuse a client without a certificate"
[ "$ports" -ge 6 ] && [ "$foreign" -eq "$ports" ] &&
  pass "all $ports ports refuse a client certificate of another CA (alert 'unknown CA')" ||
  fail "$foreign of $ports network ports refuse a certificate of another CA"
# the control: alice's certificate is not refused (the connection stays up until timeout ends it)
s_client "198.51.100.1:$NS_PORT" "$WORK/s_client-alice.out" -cert "$WORK/pki-a/users/alice.pem" \
  -pass "file:$WORK/pki-a/users/alice.pass"
if ! grep -qi "alert" "$WORK/s_client-alice.out" && grep -q "Verify return code: 0 (ok)" "$WORK/s_client-alice.out"; then
  pass "the same handshake with alice's certificate is accepted by the naming service"
else
  fail "alice's certificate refused by the naming service:"; grep -i "alert\|error" "$WORK/s_client-alice.out"
fi
model_port=$(in_ns b ss -ltnpH | grep caliper-model | awk '{sub(/.*:/, "", $4); print $4}' | head -1)
[ -n "$model_port" ] || fail "no port of a caliper-model on hostb"

# ---------------------------------------------------------------- plain GIOP refused
in_ns c timeout 10 nameclt -ORBInitRef "NameService=corbaname::198.51.100.1:$NS_PORT" list \
  >"$WORK/plain-ns.out" 2>&1
expect_refused "plain GIOP to the naming service is refused" "$WORK/plain-ns.out" $? "COMM_FAILURE\|TRANSIENT"
plain_giop() {  # WHAT ADDR:PORT: a plain GIOP request to a port that must refuse it
  in_ns c timeout 10 nameclt -ORBInitRef "NameService=corbaloc::$2/NameService" list \
    >"$WORK/plain.out" 2>&1
  local rc=$?
  if grep -q "OBJECT_NOT_EXIST" "$WORK/plain.out"; then fail "$1 answered plain GIOP"
  else expect_refused "plain GIOP to $1 ($2) is refused" "$WORK/plain.out" $rc "COMM_FAILURE\|TRANSIENT"; fi
}
[ -n "$model_port" ] && plain_giop "a Model" "198.51.100.2:$model_port"
# a plain endpoint added with -ORBendPoint listens, but over TLS refuses plain GIOP as well: next
# to --listen (the Model serves alice on its TLS endpoint), and in a Model that listens on
# loopback only, in TLS mode for its naming service (no TLS endpoint: it serves nobody)
extra_model() {  # INSTANCE PORT [OPTIONS...]
  local instance=$1 port=$2; shift 2
  # shellcheck disable=SC2046
  in_ns b env $(host_env b) "$BIN/caliper-model" --nameservice "$NS" --instance "$instance" "$@" \
    -o "log.spool_dir=$WORK/spool" -ORBendPoint "giop:tcp:198.51.100.2:$port" \
    >"$WORK/$instance.out" 2>&1 &
  for _ in $(seq 1 100); do grep -q "is up as" "$WORK/$instance.out" 2>/dev/null && break; sleep 0.1; done
  if in_ns b ss -ltnpH "sport = :$port" | grep -q caliper-model; then
    plain_giop "a Model's extra -ORBendPoint giop:tcp:198.51.100.2:$port (${*:-listening on loopback})" "198.51.100.2:$port"
  else
    cat "$WORK/$instance.out"; fail "no Model listening on the extra endpoint 198.51.100.2:$port"
  fi
}
extra_model extra 2999 --listen 198.51.100.2
alice status --model hostb/extra0 >"$WORK/extra-status.out" 2>&1 &&
  pass "that Model serves alice over TLS" || { cat "$WORK/extra-status.out"; fail "the Model with an extra endpoint"; }
extra_model extraloop 2998
# in loopback mode, a network endpoint passed to omniORB means network mode, here without a PKI
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/none" "$BIN/caliper-model" \
  --nameservice corbaname::127.0.0.1:2809 -ORBendPoint giop:tcp:: >"$WORK/extra-nopki.out" 2>&1
expect_refused "-ORBendPoint giop:tcp:: without certificates" "$WORK/extra-nopki.out" $? \
  "network mode uses TLS with certificates (listening on giop:tcp:: (-ORBendPoint)): there is no CA"

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

# ---------------------------------------------------------------- refused clients: components directly
# their references (hostb's model0 and manager0, hosta's logger0), bound under the same names in
# the intruders' own naming services on hostc
binds=""
for path in hostb.host_cxt/model0.rtc hostb.host_cxt/manager0.rtc hosta.host_cxt/logger0.rtc; do
  ior=$(in_ns a bash -c "export $(host_env a); source '$SRC/launch/naming.sh'; tls_identity;
    (tls_exec nameclt -ORBInitRef 'NameService=$NS' resolve $path)" 2>"$WORK/ior.err")
  [[ "$ior" == IOR:* ]] || { cat "$WORK/ior.err"; fail "could not resolve $path over TLS"; }
  binds="$binds run nameclt -ORBInitRef NameService=\$NS_ADDR bind $path '$ior' >/dev/null &&"
  [ "$path" = hostb.host_cxt/model0.rtc ] && model_ior=$ior
done
# the naming service takes messages up to 4 MiB (launch/naming.sh): a reference is far smaller
echo "note: hostb's model0 reference with its TLS profile: $(( (${#model_ior} - 4) / 2 )) bytes"
bind_refs() {  # MODE PKI IDENTITY
  in_ns c bash -c "export CALIPER_PKI=$2 CALIPER_TLS_IDENTITY=$3; source '$SRC/launch/naming.sh';
    start_nameserver '$WORK/ns-$1' 127.0.0.1 $1 || exit 1; [ $1 = tls ] && tls_identity;
    run() { if [ $1 = tls ]; then (tls_exec \"\$@\"); else \"\$@\"; fi; }
    run nameclt -ORBInitRef NameService=\$NS_ADDR bind_new_context hostb.host_cxt >/dev/null &&
    run nameclt -ORBInitRef NameService=\$NS_ADDR bind_new_context hosta.host_cxt >/dev/null &&
    $binds echo \$NS_ADDR" 2>"$WORK/bind-$1.err" | tail -1
}
plain_ns=$(bind_refs plain "" "")
evil_ns=$(bind_refs tls "$WORK/pki-m2" hosts/evil)
[ -n "$plain_ns" ] && [ -n "$evil_ns" ] || { cat "$WORK"/bind-*.err; fail "the intruders' naming services"; }
nocert() { in_ns c env CALIPER_HOST=hostc "$BIN/caliper-ctl" --nameservice "$plain_ns" "$@"; }
mallory() { in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/pki-m2" CALIPER_TLS_IDENTITY=users/mallory \
  "$BIN/caliper-ctl" --nameservice "$evil_ns" "$@"; }
nocert status --model hostb/model0 >"$WORK/nocert-model.out" 2>&1
expect_refused "no certificate, a Model directly" "$WORK/nocert-model.out" $? \
  "(on [^)]*198.51.100.2[^)]*) is reachable only over TLS with a certificate of its cluster's CA"
mallory status --model hostb/model0 >"$WORK/mallory-model.out" 2>&1
expect_refused "another CA, a Model directly" "$WORK/mallory-model.out" $? \
  "198.51.100.2:[0-9]* refused the TLS handshake (alert '.*'): it accepts only certificates of its own CA"
for who in hostb/manager0 hosta/logger0; do
  addr=198.51.100.$([ "${who%%/*}" = hosta ] && echo 1 || echo 2)
  nocert state "$who" >"$WORK/nocert-${who#*/}.out" 2>&1
  expect_refused "no certificate, $who directly" "$WORK/nocert-${who#*/}.out" $? \
    "(on [^)]*$addr[^)]*) is reachable only over TLS with a certificate of its cluster's CA"
  mallory state "$who" >"$WORK/mallory-${who#*/}.out" 2>&1
  expect_refused "another CA, $who directly" "$WORK/mallory-${who#*/}.out" $? \
    "$addr:[0-9]* refused the TLS handshake (alert '.*'): it accepts only certificates of its own CA"
done
# and alice, with the same reference from the same place, is served
in_ns c env CALIPER_HOST=hostc CALIPER_PKI="$WORK/pki-a" CALIPER_TLS_IDENTITY=users/alice CALIPER_LISTEN=198.51.100.3 \
  "$BIN/caliper-ctl" --nameservice "$NS" status --model hostb/model0 >"$WORK/alice-c.out" 2>&1 &&
  pass "alice on hostc is served by hostb's model0" || { cat "$WORK/alice-c.out"; fail "alice on hostc"; }

echo "tls_test: $((SECONDS - started)) s"
if [ $FAILS -eq 0 ]; then echo "tls_test: all checks passed"; exit 0; fi
echo "tls_test: $FAILS checks failed; the session's and the node's output:"
tail -n 20 "$WORK/session.out" "$WORK/node.out"
exit 1
