#!/bin/bash
# linuxcnc-sim.sh: verne's kinematics inside a real LinuxCNC, headless, checked by verne.
#   1. installs LinuxCNC from Debian's packages (linuxcnc-uspace, linuxcnc-uspace-dev) and a C
#      toolchain, when missing;
#   1b. compares verne's G-code reader with LinuxCNC's rs274 on tests/data/gcode;
#   2. builds the C interface (crates/verne-kins, a static library) and the verne binary, then the
#      kinematics component linuxcnc/vernekins.comp with halcompile, and installs it;
#   3. runs LinuxCNC headless (`linuxcnc -r`, a Python display, loopback joints, halsampler
#      recording joint.N.pos-cmd every 1 ms servo period) on two programs:
#        ok           data/linuxcnc/verne-tcp.ngc runs to its end; linuxcnc/sim/check.py checks
#                     0 kinematics failures, 0 overruns, rest-point joints == verne ik to 1e-6,
#                     verne fk of every row on the programmed path, verne verify clean;
#        unreachable  data/linuxcnc/verne-unreachable.ngc: the move is refused with the
#                     kinematics error and the joints never jump.
# Exits non-zero on any failure. Runs as root (apt-get, /usr/lib/linuxcnc/modules); LinuxCNC's
# realtime process runs as an unprivileged system user (RTAPI_UID), as it requires.
# Env: SKIP_APT=1 (no apt-get), RUN_DIR (default /tmp/verne-linuxcnc-sim), RT_USER (lcncsim).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# Outside the clone: LinuxCNC's realtime process reads the run directory as RT_USER, who may
# not be able to enter the clone's parent directories (/root is 0700).
RUN="${RUN_DIR:-/tmp/verne-linuxcnc-sim}"
RT_USER="${RT_USER:-lcncsim}"
T0=$(date +%s.%N)
say() { printf '\n=== %s\n' "$*"; }
die() { printf '\nlinuxcnc-sim: FAILED: %s\n' "$*" >&2; exit 1; }
lap() { awk -v a="$T0" -v b="$(date +%s.%N)" -v n="$1" 'BEGIN { printf "--- %s: %.1f s since start\n", n, b - a }'; }

[ "$(id -u)" = 0 ] || die "run as root (apt-get, /usr/lib/linuxcnc/modules)"
CARGO="$(PATH="$HOME/.cargo/bin:$PATH" command -v cargo || true)"
[ -n "$CARGO" ] || die "no cargo (the Rust toolchain builds the kinematics library)"
# LinuxCNC's Python modules are Debian's /usr/bin/python3's: keep /usr/bin first.
export PATH="/usr/sbin:/usr/bin:/sbin:/bin"

rm -rf "$RUN"
mkdir -p "$RUN"

say "1. LinuxCNC from Debian's packages"
need=""
for p in linuxcnc-uspace linuxcnc-uspace-dev gcc make binutils libc6-dev; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || need="$need $p"
done
if [ -n "$need" ] && [ "${SKIP_APT:-0}" != 1 ]; then
    echo "installing:$need"
    apt-get update -q > "$RUN/apt.log" 2>&1
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $need \
        >> "$RUN/apt.log" 2>&1 || { tail -30 "$RUN/apt.log"; die "apt-get install$need"; }
fi
for t in halcompile linuxcnc halcmd halsampler gcc make nm; do
    command -v $t >/dev/null || die "missing $t"
done
/usr/bin/python3 -c 'import linuxcnc, hal' || die "Debian's python3 cannot import linuxcnc"
echo "linuxcnc-uspace $(dpkg-query -W -f='${Version}' linuxcnc-uspace)"
lap "install"

say "1b. verne's G-code reader against LinuxCNC's interpreter (rs274 -g, every program of tests/data/gcode)"
(cd "$ROOT" && VERNE_REQUIRE_RS274=1 PATH="$(dirname "$CARGO"):$PATH" \
    "$CARGO" test -q -p verne-gcode --test rs274) > "$RUN/rs274.log" 2>&1 \
    || { tail -40 "$RUN/rs274.log"; die "verne-gcode against rs274"; }
grep 'test result' "$RUN/rs274.log"
lap "rs274"

say "2. build: the C interface, verne, the component"
(cd "$ROOT" && PATH="$(dirname "$CARGO"):$PATH" "$CARGO" build --release -q -p verne-kins -p verne-cli) \
    || die "cargo build"
RUSTLIB="$ROOT/target/release/libverne_kins.a"
VERNE="$ROOT/target/release/verne"
BUILD="$RUN/component"
mkdir -p "$BUILD"
cp "$ROOT/linuxcnc/vernekins.comp" "$ROOT/linuxcnc/Makefile" "$ROOT/crates/verne-kins/include/verne_kins.h" "$BUILD/"
make -C "$BUILD" RUSTLIB="$RUSTLIB" \
    > "$RUN/make.log" 2>&1 || { cat "$RUN/make.log"; die "make"; }
SO="$BUILD/vernekins.so"
# The Rust code is inside the module, and only the kinematics entry points are exported.
if nm -D --undefined-only "$SO" | grep -q verne_kins; then die "unresolved verne_kins_* in $SO"; fi
for s in kinematicsType kinematicsForward kinematicsInverse kinematicsHome rtapi_app_main; do
    nm -D --defined-only "$SO" | grep -qw "$s" || die "$s not exported by $SO"
done
make -C "$BUILD" RUSTLIB="$RUSTLIB" install \
    >> "$RUN/make.log" 2>&1 || die "make install"
lap "build"

say "3. headless runs"
id -u "$RT_USER" >/dev/null 2>&1 || useradd --system --no-create-home --shell /usr/sbin/nologin "$RT_USER"
export RTAPI_UID="$(id -u "$RT_USER")"
mkdir -p "$RUN/rt"
chown "$RT_USER" "$RUN/rt"
export RTAPI_FIFO_PATH="$RUN/rt/rtapi_fifo"
live_rt() { ps -C rtapi_app,milltask -o stat=,pid=,comm= | grep -v '^Z' || true; }
[ -z "$(live_rt)" ] || die "another LinuxCNC session is running: $(live_rt | tr '\n' ' ')"

# The machine: the embedded default, its tool length; home = verne ik of X0 Y0 Z100 A0 C0.
TOOL=$("$VERNE" machine show | awk -F' = ' '/^\[tool\]/ { t = 1 } t && $1 == "length" { print $2; exit }')
HOME_J=$(printf 'x,y,z,phi1,phi2\n0,0,100,0,0\n' | "$VERNE" ik | awk -F, 'NR == 2 { print $6, $7, $8, $9, $10 }')
read -r H0 H1 H2 H3 H4 <<< "$HOME_J"
echo "tool length $TOOL mm; home joints $HOME_J"
cp "$ROOT/linuxcnc/sim/verne.hal" "$ROOT/linuxcnc/sim/sim.tbl" "$ROOT"/data/linuxcnc/*.ngc "$RUN/"
install -m 755 "$ROOT/linuxcnc/sim/display.py" "$RUN/display.py"

overall=0
for S in ok unreachable; do
    case $S in
        ok) prog="$RUN/verne-tcp.ngc"; expect=ok ;;
        unreachable) prog="$RUN/verne-unreachable.ngc"; expect=error ;;
    esac
    mkdir -p "$RUN/$S"
    : > "$RUN/$S/sim.var"
    sed -e "s|@RUN@|$RUN|g; s|@SCEN@|$S|g; s|@KINS@|vernekins|; s|@PROGRAM@|$prog|; s|@EXPECT@|$expect|" \
        -e "s|@TOOL@|$TOOL|; s|@HOME0@|$H0|g; s|@HOME1@|$H1|g; s|@HOME2@|$H2|g; s|@HOME3@|$H3|g; s|@HOME4@|$H4|g" \
        "$ROOT/linuxcnc/sim/verne.ini.in" > "$RUN/$S.ini"
    chmod -R a+rX "$RUN"
    chown -R "$RT_USER" "$RUN/$S"
    echo "--- $S: linuxcnc -r $RUN/$S.ini"
    rc=0
    ( cd "$RUN" && timeout 300 linuxcnc -r "$RUN/$S.ini" ) > "$RUN/$S/linuxcnc.log" 2>&1 || rc=$?
    grep -v '^Running with fallback_uid' "$RUN/$S/linuxcnc.log" | grep -E 'display|error|Error|vernekins' | sed 's/^/    | /' || true
    lap "linuxcnc $S (exit $rc)"
    [ $rc -eq 0 ] || { echo "$S: linuxcnc/display exit status $rc"; overall=1; }
    for i in $(seq 50); do [ -z "$(live_rt)" ] && break; sleep 0.1; done
    [ -z "$(live_rt)" ] || { echo "$S: still running after shutdown: $(live_rt)"; overall=1; }
    [ -f "$RUN/$S/result.json" ] || { echo "$S: no result.json"; overall=1; continue; }
    /usr/bin/python3 "$ROOT/linuxcnc/sim/check.py" "$VERNE" "$RUN/$S" "$prog" "$S" | tee "$RUN/$S/check.txt" || overall=1
done
lap "total"
[ $overall -eq 0 ] || die "see $RUN"
echo "linuxcnc-sim: ALL PASSED (outputs in $RUN)"
