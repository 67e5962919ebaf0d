#!/bin/bash
# browser-test.sh: the HTML reports of verne in a real browser, and the JUnit XML against its
# schema.
#   1. installs Debian's chromium, nodejs, libxml2-utils (xmllint) and fonts-dejavu-core when
#      missing (nothing else: node drives Chromium over the DevTools protocol with its own
#      modules);
#   2. builds verne (release) and writes, with `verne verify --html --junit --sarif`:
#        clean      data/verify/joints.csv against data/verify/path.csv (the shipped example);
#        defects    data/verify/joints_defects.csv (five injected defects);
#        gcode      data/example-post.ngc against data/example-tcp.ngc (the shipped joint
#                   program and its tool-centre program);
#        injected   that joint program with three blocks changed (a slider 0.5 mm off, the
#                   rotary axis half a turn on, the tilting axis with the wrong sign);
#        untimed    data/verify/joints.csv without its t column;
#        recording  a 1 ms stream of data/example.cl (78,755 samples) against the CL file;
#        100k       the example's five defects in 100,000 rows (make_verify_data): the page
#                   at most 1 MB and drawn within a second;
#      and `verne modes --plot FILE.html` of a tool pose and of Table III's sliders;
#   3. validates every JUnit file with `xmllint --schema tests/data/schemas/junit-10.xsd`;
#   4. opens every page in headless Chromium (scripts/browser-test.mjs): no console error, no
#      request (all are blocked), the 3D view and the plots not blank in screenshots, a
#      finding clicked moves the 3D view to its row, the drawn machine is the kinematics'
#      (and first shows that these checks catch a page that fetches, logs an error, throws).
# Exits non-zero on any failure. Runs as root for apt-get (SKIP_APT=1: no apt-get).
# Env: RUN_DIR (default /tmp/verne-browser-test), SCREENSHOT=FILE (a screenshot of the
# defects report, as docs/verify-report.png was made).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RUN="${RUN_DIR:-/tmp/verne-browser-test}"
T0=$(date +%s.%N)
say() { printf '\n=== %s\n' "$*"; }
die() { printf '\nbrowser-test: FAILED: %s\n' "$*" >&2; exit 1; }
lap() { awk -v a="$T0" -v b="$(date +%s.%N)" -v n="$1" 'BEGIN { printf "--- %s: %.1f s since start\n", n, b - a }'; }
CARGO="$(PATH="$HOME/.cargo/bin:$PATH" command -v cargo || true)"
[ -n "$CARGO" ] || die "no cargo"

rm -rf "$RUN"
mkdir -p "$RUN/out"

say "1. Chromium, node and xmllint from Debian's packages"
need=""
command -v chromium >/dev/null || need="$need chromium"
command -v xmllint >/dev/null || need="$need libxml2-utils"
command -v node >/dev/null || need="$need nodejs"
# A font for the pages' text (Chromium's package only recommends one).
[ -e /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need="$need fonts-dejavu-core"
if [ -n "$need" ]; then
    [ "${SKIP_APT:-0}" != 1 ] || die "missing:$need (SKIP_APT=1)"
    [ "$(id -u)" = 0 ] || die "run as root to install:$need"
    echo "installing:$need"
    apt-get update -q > "$RUN/apt.log" 2>&1
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $need \
        >> "$RUN/apt.log" 2>&1 || { tail -30 "$RUN/apt.log"; die "apt-get install$need"; }
fi
echo "$(chromium --version 2>/dev/null | tail -1); $(xmllint --version 2>&1 | head -1); node $(node --version)"
lap "install"

say "2. the reports"
(cd "$ROOT" && "$CARGO" build -q --release -p verne-cli --bin verne \
    && "$CARGO" build -q --release -p verne --example make_verify_data) || die "cargo build"
VERNE="$ROOT/target/release/verne"
OUT="$RUN/out"
cd "$ROOT"
# verify exits 1 when it finds something: that is expected here, 2 is not.
report() {
    local name="$1"; shift
    local rc=0
    "$VERNE" verify "$@" --html "$OUT/$name.html" --junit "$OUT/$name.xml" \
        --sarif "$OUT/$name.sarif" --summary "$OUT/$name.txt" || rc=$?
    [ "$rc" -le 1 ] || die "verne verify for $name exited $rc"
    printf '%-10s exit %d, %s\n' "$name" "$rc" "$(head -1 "$OUT/$name.txt" | sed 's/.*: //')"
}
report clean --joints data/verify/joints.csv --path data/verify/path.csv
report defects --joints data/verify/joints_defects.csv --path data/verify/path.csv
report gcode --joints data/example-post.ngc --path data/example-tcp.ngc
# Three blocks of the shipped joint program changed.
awk '
    /^N200 / { for (i = 1; i <= NF; i++) if ($i ~ /^U/) $i = sprintf("U%.6f", substr($i, 2) + 0.5) }
    /^N300 / { for (i = 1; i <= NF; i++) if ($i ~ /^C/) $i = sprintf("C%.6f", substr($i, 2) + 180) }
    /^N400 / { for (i = 1; i <= NF; i++) if ($i ~ /^A/) $i = sprintf("A%.6f", -substr($i, 2)) }
    { print }' data/example-post.ngc > "$RUN/injected.ngc"
report injected --joints "$RUN/injected.ngc" --path data/example-tcp.ngc
cut -d, -f1,3- data/verify/joints.csv > "$RUN/untimed.csv"
report untimed --joints "$RUN/untimed.csv" --path data/verify/path.csv
"$VERNE" ik data/example.cl --format halstreamer --period 1ms --rapid 5000 -o "$RUN/stream.txt"
report recording --joints "$RUN/stream.txt" --recording --period 1ms --path data/example.cl
"$ROOT/target/release/examples/make_verify_data" 100000 "$RUN/verify100k" > /dev/null
report 100k --joints "$RUN/verify100k/joints_defects.csv" --path "$RUN/verify100k/path.csv"
size=$(stat -c %s "$OUT/100k.html")
[ "$size" -le 1000000 ] || die "the report of 100,000 rows is $size bytes, over 1 MB"
"$VERNE" modes --tool 80,0,30,0.342020,0,0.939693 --plot "$OUT/modes-tool.html" > /dev/null
"$VERNE" modes --joints 674,685,250 --plot "$OUT/modes-table3.html" > /dev/null
ls -l "$OUT"
lap "reports"

say "3. JUnit XML against tests/data/schemas/junit-10.xsd"
xmllint --noout --schema "$ROOT/tests/data/schemas/junit-10.xsd" "$OUT"/*.xml \
    || die "a JUnit file does not follow the schema"

say "4. the pages in headless Chromium"
injected_line=$(grep -n '^N200 ' "$RUN/injected.ngc" | cut -d: -f1)
cat > "$RUN/cases.json" <<EOF
[
  {"name": "clean", "file": "$OUT/clean.html", "verdict": "Clean: no finding in 3000 rows",
   "findings": 0, "canvases": ["#view3d", "#charts canvas"], "geometry": true},
  {"name": "defects", "file": "$OUT/defects.html", "verdict": "12 findings in 7 checks",
   "canvases": ["#view3d", "#charts canvas"], "geometry": true,
   "closeUp": true, "click": {"check": "tip_error", "row": "1000"}${SCREENSHOT:+, \"screenshot\": \"$SCREENSHOT\"}},
  {"name": "gcode", "file": "$OUT/gcode.html", "canvases": ["#view3d", "#charts canvas"], "geometry": true},
  {"name": "injected", "file": "$OUT/injected.html", "canvases": ["#view3d", "#charts canvas"],
   "geometry": true, "click": {"check": "tip_error", "row": "N200"},
   "texts": ["N200 G1 U414.646215", "injected.ngc:$injected_line"]},
  {"name": "untimed", "file": "$OUT/untimed.html", "verdict": "not checked: velocity, acceleration",
   "texts": ["Velocity and acceleration were not checked"], "canvases": ["#view3d", "#charts canvas"]},
  {"name": "recording", "file": "$OUT/recording.html", "canvases": ["#view3d", "#charts canvas"],
   "geometry": true, "maxDrawMs": 3000},
  {"name": "100k", "file": "$OUT/100k.html", "verdict": "12 findings in 7 checks",
   "canvases": ["#view3d", "#charts canvas"], "geometry": true,
   "click": {"check": "tip_error", "row": "500"}, "maxDrawMs": 1000},
  {"name": "modes-tool", "file": "$OUT/modes-tool.html", "canvases": ["#branches canvas"]},
  {"name": "modes-table3", "file": "$OUT/modes-table3.html", "canvases": ["#branches canvas"]}
]
EOF
node "$ROOT/scripts/browser-test.mjs" "$RUN/cases.json" \
    || die "the pages in the browser"
lap "browser"
