#!/usr/bin/env bash
# What the launcher says before it installs or builds on its own, without real apt or a real
# build: a copy of launch/ with a deps.txt of two made-up packages, and stand-ins for dpkg-query,
# apt-get, sudo and cmake on PATH that log their calls. `node` is the verb under test (it builds
# through ensure_built like session and demo); its caliper-manager is a stand-in that exits.
set -uo pipefail
SRC=${CALIPER_SOURCE_DIR:?set CALIPER_SOURCE_DIR to the source tree}
FAILS=0
fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
pass() { echo "ok: $*"; }

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
ROOT=$WORK/root FAKE=$WORK/fake LOG=$WORK/calls.log
mkdir -p "$ROOT/launch" "$FAKE/bin" "$FAKE/installed"
cp "$SRC"/launch/*.sh "$SRC/launch/caliper" "$ROOT/launch/"
printf 'caliper-fake-a  # a made-up package\ncaliper-fake-b\n' >"$ROOT/launch/deps.txt"
export FAKE LOG

cat >"$FAKE/bin/dpkg-query" <<'STUB'
#!/bin/bash
echo "dpkg-query $*" >>"$LOG"
[ -e "$FAKE/installed/${!#}" ] && printf 'install ok installed'
exit 0
STUB
cat >"$FAKE/bin/apt-get" <<'STUB'
#!/bin/bash
echo "apt-get $*" >>"$LOG"
if [[ " $* " == *" install "* ]]; then
  for a in "$@"; do [[ "$a" == caliper-fake-* ]] && touch "$FAKE/installed/$a"; done
fi
exit 0
STUB
cat >"$FAKE/bin/sudo" <<'STUB'
#!/bin/bash
exec "$@"
STUB
# cmake: -S/-B configures (writes build.ninja); --build prints what ninja prints, work or none
cat >"$FAKE/bin/cmake" <<'STUB'
#!/bin/bash
echo "cmake $*" >>"$LOG"
if [ "$1" = -S ]; then touch "$4/build.ninja"; exit 0; fi
echo "[0/2] Re-checking globbed directories..."
if [ -e "$FAKE/uptodate" ]; then echo "ninja: no work to do."; exit 0; fi
echo "[1/2] Building CXX object x.o"
echo "[2/2] Linking CXX executable bin/caliper-model"
exit "${FAKE_BUILD_RC:-0}"
STUB
chmod +x "$FAKE/bin/"*

BUILD=$WORK/build
mkdir -p "$BUILD/bin"
printf '#!/bin/sh\nexit 0\n' >"$BUILD/bin/caliper-manager"
chmod +x "$BUILD/bin/caliper-manager"

# runs the launcher with ARGS; sets OUT (stdout and stderr) and RC; the call log starts empty
launcher() {
  : >"$LOG"
  OUT=$(PATH="$FAKE/bin:$PATH" CALIPER_BUILD_DIR=$BUILD CALIPER_NODE_DIR=$WORK/node \
    XDG_RUNTIME_DIR=$WORK/run timeout 20 "$ROOT/launch/caliper" "$@" 2>&1)
  RC=$?
}
has() { grep -qF -- "$1" <<<"$OUT"; }
NODE=(node --nameservice corbaname::127.0.0.1:1)
HINT="(set CALIPER_NO_BUILD=1 to skip)"

# a fresh machine: both packages missing, nothing configured
launcher "${NODE[@]}"
if [ "$RC" = 0 ] &&
    has "caliper: installing missing Debian packages with apt-get: caliper-fake-a caliper-fake-b $HINT" &&
    has "caliper: configuring $BUILD (cmake, Ninja) $HINT" &&
    has "caliper: building $BUILD (minutes the first time) $HINT" &&
    grep -q "^apt-get .* install .*caliper-fake-a caliper-fake-b" "$LOG" &&
    grep -q "^cmake --build $BUILD" "$LOG"; then
  pass "a fresh machine: one line before installing, configuring and building"
else fail "a fresh machine (rc $RC):"; echo "$OUT"; cat "$LOG"; fi
# the announcement comes before the build's own output
if [ "$(grep -nF "caliper: building" <<<"$OUT" | cut -d: -f1)" -lt \
     "$(grep -nF "[1/2] Building" <<<"$OUT" | cut -d: -f1)" ] 2>/dev/null; then
  pass "the building line comes before the build's output"
else fail "the building line is not before the build's output"; echo "$OUT"; fi

# everything installed and built: nothing said about installing or building
touch "$FAKE/uptodate"
launcher "${NODE[@]}"
if [ "$RC" = 0 ] && ! grep -qiE "install|configur|building|up to date|Re-checking|no work" <<<"$OUT" &&
    ! grep -q "^apt-get" "$LOG" && grep -q "^cmake --build" "$LOG"; then
  pass "up to date: checked, and nothing said about it"
else fail "up to date (rc $RC):"; echo "$OUT"; cat "$LOG"; fi

# `build` asked for by name says in one line that there was nothing to do
launcher build
if [ "$RC" = 0 ] && [ "$OUT" = "caliper: $BUILD is up to date" ]; then
  pass "build when up to date: '$OUT'"
else fail "build when up to date (rc $RC): '$OUT'"; fi

# a source changed: the building line again
rm "$FAKE/uptodate"
launcher "${NODE[@]}"
if [ "$RC" = 0 ] && has "caliper: building $BUILD (minutes the first time) $HINT" &&
    ! has "installing"; then
  pass "a changed source: the building line, no installing"
else fail "a changed source (rc $RC):"; echo "$OUT"; fi

# a failing build fails the verb, with its output
FAKE_BUILD_RC=1 launcher "${NODE[@]}"
if [ "$RC" != 0 ] && has "[2/2] Linking"; then pass "a failed build fails the verb (rc $RC)"
else fail "a failed build (rc $RC):"; echo "$OUT"; fi
unset FAKE_BUILD_RC

# CALIPER_NO_BUILD=1 with a built caliper-model: no dpkg-query, no apt-get, no cmake, no line
printf '#!/bin/sh\nexit 0\n' >"$BUILD/bin/caliper-model"
chmod +x "$BUILD/bin/caliper-model"
rm -f "$FAKE/installed/caliper-fake-a"
CALIPER_NO_BUILD=1 launcher "${NODE[@]}"
if [ "$RC" = 0 ] && [ ! -s "$LOG" ] && ! grep -qiE "install|build" <<<"$OUT"; then
  pass "CALIPER_NO_BUILD=1: no package check, no build, nothing said"
else fail "CALIPER_NO_BUILD=1 (rc $RC):"; echo "$OUT"; cat "$LOG"; fi

# CALIPER_NO_BUILD=1 without caliper-model builds anyway and says why
rm "$BUILD/bin/caliper-model"
CALIPER_NO_BUILD=1 launcher "${NODE[@]}"
if [ "$RC" = 0 ] && has "caliper: CALIPER_NO_BUILD=1, but $BUILD/bin/caliper-model is missing: building" &&
    has "caliper: installing missing Debian packages with apt-get: caliper-fake-a" &&
    ! has "$HINT"; then
  pass "CALIPER_NO_BUILD=1 without caliper-model: builds and says why"
else fail "CALIPER_NO_BUILD=1 without caliper-model (rc $RC):"; echo "$OUT"; fi

# help documents the variable
launcher help
if has "CALIPER_NO_BUILD=1" && has "kill -INT"; then pass "help names CALIPER_NO_BUILD and kill -INT"
else fail "help does not document CALIPER_NO_BUILD or kill -INT"; fi

[ "$FAILS" = 0 ] && echo "PASS" || { echo "FAILED: $FAILS"; exit 1; }
