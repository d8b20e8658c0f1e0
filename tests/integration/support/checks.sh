# Sourced by the integration test scripts: `pass TEXT` and `fail TEXT` print one line each and
# count the failures in FAILS; a script ends with `finish`, which exits 1 when any check failed.
FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }
finish() {
  if [ "$FAILS" -eq 0 ]; then echo "all passed"; else echo "$FAILS failed"; fi
  exit $((FAILS > 0))
}
