# Three "hosts" made of Linux network namespaces, for the network tests (sourced by
# tests/integration/cluster_test.sh and tls_test.sh):
#   hosta 198.51.100.1, hostb 198.51.100.2, hostc 198.51.100.3 (eth0/24 and lo up each)
# joined by a bridge (br0) that lives in a namespace of its own (support/netns_hosts.sh makes
# and removes them; the documentation tests use it too). The sourcing script sets TAG (a
# prefix unique to the run, e.g. cl$$) first. Sets BIN and SRC (from CALIPER_BIN_DIR and
# CALIPER_SOURCE_DIR) and WORK, a new temporary directory; on exit, also when the test skips,
# cleanup kills every process in the namespaces, deletes them and removes WORK. Also FAILS,
# skip/fail/pass and in_ns.

BIN=${CALIPER_BIN_DIR:?set CALIPER_BIN_DIR to the bin folder of the build}
SRC=${CALIPER_SOURCE_DIR:?}
WORK=$(mktemp -d)
FAILS=0
trap cleanup EXIT  # cleanup is defined below

skip() { echo "SKIPPED: $*"; exit 77; }
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }
in_ns() { local n=$1; shift; ip netns exec "$TAG-$n" "$@"; }  # N COMMAND...: on host N (a, b, c)

# shellcheck source=netns_hosts.sh
source "$(dirname "${BASH_SOURCE[0]}")/netns_hosts.sh"

cleanup() {
  netns_remove "$TAG"
  rm -rf "$WORK"
}

# skips (exit 77) with the reason where namespaces cannot be made: not root, no ip, not allowed
netns_require() {
  [ "$(id -u)" = 0 ] || skip "network namespaces need root (run the tests as root, as CI does)"
  command -v ip >/dev/null || skip "no 'ip' command (apt-get install iproute2)"
  ip netns add "$TAG-probe" 2>/dev/null || skip "this kernel or container does not allow 'ip netns add'"
  ip netns del "$TAG-probe"
}

# the namespaces, the bridge and the three hosts on it (exit 1 when a namespace cannot be added)
netns_hosts() {
  netns_make "$TAG" || { echo "FAIL: the namespaces of $TAG"; exit 1; }
}
