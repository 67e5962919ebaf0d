#!/usr/bin/env bash
# End-to-end benchmark of `verne ik` and `verne fk` against the I/O floor
# (crates/verne-cli/examples/io_floor.rs), plus the criterion kernels
# (crates/verne-cli/benches/kernels.rs); writes the figures into docs/benchmarks.md
# between the `bench.sh:begin` / `bench.sh:end` markers (the text around them is kept).
#
# Usage: scripts/bench.sh [--rows N] [--big] [--runs N] [--no-kernels] [--no-docs]
#   --rows N      rows of the timing trajectory (default 1000000; the tool-pose path has N / 10)
#   --big         also run the 10,000,000-row memory check (peak RSS of verne ik and fk)
#   --runs N      timed runs per command (default 5)
#   --no-kernels  skip `cargo bench -p verne-cli --bench kernels`
#   --no-docs     print the figures, leave docs/benchmarks.md alone
#
# Timing uses hyperfine (installed with apt-get when missing and possible), else /usr/bin/time
# (Debian package `time`, installed when missing); peak RSS always comes from /usr/bin/time -v.
set -euo pipefail
cd "$(dirname "$0")/.."

ROWS=1000000
BIG_ROWS=10000000
BIG=0
RUNS=5
KERNELS=1
DOCS=1
while [ $# -gt 0 ]; do
    case "$1" in
        --rows) ROWS="$2"; shift 2 ;;
        --big) BIG=1; shift ;;
        --runs) RUNS="$2"; shift 2 ;;
        --no-kernels) KERNELS=0; shift ;;
        --no-docs) DOCS=0; shift ;;
        -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
        *) echo "bench.sh: unknown argument $1" >&2; exit 2 ;;
    esac
done

log() { echo "bench.sh: $*" >&2; }

apt_install() {
    if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
        log "installing $1 with apt-get"
        apt-get install -y -qq "$1" >/dev/null 2>&1 || {
            apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq "$1" >/dev/null 2>&1
        } || log "could not install $1"
    else
        log "$1 is missing and apt-get is not usable here"
    fi
}

[ -x /usr/bin/time ] || apt_install time
[ -x /usr/bin/time ] || { log "/usr/bin/time is required (Debian package time)"; exit 2; }
command -v hyperfine >/dev/null 2>&1 || apt_install hyperfine
HYPERFINE=$(command -v hyperfine || true)

TARGET_DIR=${CARGO_TARGET_DIR:-target}
WORK="$TARGET_DIR/bench-data"
mkdir -p "$WORK"
log "building the release binary and the I/O floor"
cargo build --release -p verne-cli --bin verne --example io_floor 2>&1 | tail -1 >&2
VERNE="$TARGET_DIR/release/verne"
FLOOR="$TARGET_DIR/release/examples/io_floor"

# The trajectory: the kernels' helix (radius 120 mm around (-250, 0), 4096 rows per turn, about
# 0.2 mm per row) rising from z = 1000 to 1300 mm over the file.
gen_path() { # rows file
    awk -v n="$1" 'BEGIN {
        print "xp,yp,zp"; tau = 6.283185307179586
        for (i = 0; i < n; i++) {
            t = tau * i / 4096
            printf "%.4f,%.4f,%.4f\n", -250 + 120 * cos(t), 120 * sin(t), 1000 + 300 * i / n
        }
    }' > "$2"
}

# The CAM job's input: tool poses (tip + axis in the workpiece frame) on the kernels' dome spiral
# (crates/verne-cli/benches/kernels.rs: centre (0, 0, -100), radius 150 mm, tool tilted 6 to
# 30 deg along the normal, tips 0.5 mm apart), tips with 4 decimals and axes with 7.
gen_tool_path() { # rows file
    awk -v n="$1" 'BEGIN {
        print "x,y,z,i,j,k"; pi = 3.141592653589793; r = 150; step = 0.5
        b0 = 6 * pi / 180; b1 = 30 * pi / 180
        turns = n * step / (2 * pi * r * (cos(b0) - cos(b1)) / (b1 - b0))
        db = (b1 - b0) / (2 * pi * turns); psi = 0
        for (i = 0; i < n; i++) {
            beta = b0 + db * psi
            nx = sin(beta) * cos(psi); ny = sin(beta) * sin(psi); nz = cos(beta)
            printf "%.4f,%.4f,%.4f,%.7f,%.7f,%.7f\n", r * nx, r * ny, -100 + r * nz, nx, ny, nz
            psi += step / (r * sqrt(sin(beta) ^ 2 + db ^ 2))
        }
    }' > "$2"
}

# The same tool poses as a CL file (UNITS/MM, MULTAX/ON, one 6-value GOTO per pose): the CL
# reader against the CSV reader on identical poses.
gen_tool_cl() { # tool-csv cl-file
    { echo "UNITS/MM"; echo "MULTAX/ON"; tail -n +2 "$1" | sed 's|^|GOTO/|'; echo "FINI"; } > "$2"
}

PATH_CSV="$WORK/path_$ROWS.csv"
TOOL_ROWS=$((ROWS / 10))
TOOL_CSV="$WORK/tool_path_$TOOL_ROWS.csv"
[ -s "$TOOL_CSV" ] || { log "generating $TOOL_CSV"; gen_tool_path "$TOOL_ROWS" "$TOOL_CSV"; }
CL_CSV="$WORK/tool_path_$ROWS.csv"
CL_FILE="$WORK/tool_path_$ROWS.cl"
[ -s "$CL_CSV" ] || { log "generating $CL_CSV"; gen_tool_path "$ROWS" "$CL_CSV"; }
[ -s "$CL_FILE" ] || { log "generating $CL_FILE"; gen_tool_cl "$CL_CSV" "$CL_FILE"; }
JOINTS_CSV="$WORK/joints_$ROWS.csv"
[ -s "$PATH_CSV" ] || { log "generating $PATH_CSV"; gen_path "$ROWS" "$PATH_CSV"; }
log "verne ik -> $JOINTS_CSV (the fk input)"
"$VERNE" ik "$PATH_CSV" -o "$JOINTS_CSV"

# time_cmd NAME CMD...: sets MEAN (s), USER (s), SYS (s) of the command (output to a file).
time_cmd() {
    local name=$1; shift
    if [ -n "$HYPERFINE" ]; then
        "$HYPERFINE" --style none --warmup 1 --runs "$RUNS" --export-csv "$WORK/$name.csv" \
            -- "$(printf '%q ' "$@")" >/dev/null
        # command,mean,stddev,median,user,system,min,max
        read -r MEAN USER SYS < <(awk -F, 'NR == 2 { print $4, $5, $6 }' "$WORK/$name.csv")
    else
        local i
        : > "$WORK/$name.times"
        "$@" >/dev/null # warm-up
        for ((i = 0; i < RUNS; i++)); do
            /usr/bin/time -f "%e %U %S" -a -o "$WORK/$name.times" "$@" >/dev/null
        done
        read -r MEAN USER SYS < <(sort -n "$WORK/$name.times" | awk '{ e[NR] = $1; u[NR] = $2; s[NR] = $3 }
            END { m = int((NR + 1) / 2); print e[m], u[m], s[m] }')
    fi
}

# peak_rss CMD...: sets RSS_MB, the peak resident set size (MiB) from /usr/bin/time -v.
peak_rss() {
    /usr/bin/time -v -o "$WORK/rss.txt" "$@" >/dev/null 2>"$WORK/rss.err" || true
    RSS_MB=$(awk -F: '/Maximum resident set size/ { printf "%.1f", $2 / 1024 }' "$WORK/rss.txt")
}

declare -A T U S R
run_case() { # key CMD...
    local key=$1; shift
    log "timing $key"
    time_cmd "$key" "$@"
    T[$key]=$MEAN; U[$key]=$USER; S[$key]=$SYS
    peak_rss "$@"
    R[$key]=$RSS_MB
}

OUT="$WORK/out.csv"
LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
run_case ik "$VERNE" ik "$PATH_CSV" -o "$OUT"
run_case ik1 env RAYON_NUM_THREADS=1 "$VERNE" ik "$PATH_CSV" -o "$OUT"
run_case floor_ik "$FLOOR" ik "$PATH_CSV" -o "$OUT"
run_case fk "$VERNE" fk "$JOINTS_CSV" -o "$OUT"
run_case fk1 env RAYON_NUM_THREADS=1 "$VERNE" fk "$JOINTS_CSV" -o "$OUT"
run_case floor_fk "$FLOOR" fk "$JOINTS_CSV" -o "$OUT"
run_case tool "$VERNE" ik "$TOOL_CSV" -o "$OUT"
run_case tool1 env RAYON_NUM_THREADS=1 "$VERNE" ik "$TOOL_CSV" -o "$OUT"
run_case cl_csv "$VERNE" ik "$CL_CSV" -o "$OUT"
run_case cl "$VERNE" ik "$CL_FILE" -o "$OUT"
rm -f "$OUT"

BIG_IK=""; BIG_FK=""
if [ "$BIG" = 1 ]; then
    BIG_CSV="$WORK/path_$BIG_ROWS.csv"
    BIG_JOINTS="$WORK/joints_$BIG_ROWS.csv"
    [ -s "$BIG_CSV" ] || { log "generating $BIG_CSV"; gen_path "$BIG_ROWS" "$BIG_CSV"; }
    log "memory check: verne ik on $BIG_ROWS rows"
    /usr/bin/time -v -o "$WORK/rss.txt" "$VERNE" ik "$BIG_CSV" -o "$BIG_JOINTS" 2>/dev/null || true
    BIG_IK=$(awk -F: '/Maximum resident set size/ { printf "%.1f", $2 / 1024 }' "$WORK/rss.txt")
    log "memory check: verne fk on $BIG_ROWS rows"
    peak_rss "$VERNE" fk "$BIG_JOINTS"
    BIG_FK=$RSS_MB
    rm -f "$BIG_JOINTS"
fi

KERNEL_TABLE=""
if [ "$KERNELS" = 1 ]; then
    log "cargo bench -p verne-cli --bench kernels (a few minutes)"
    VERNE_BENCH_SUMMARY="$(realpath -m "$WORK/kernels.md")" cargo bench -p verne-cli --bench kernels >"$WORK/kernels.log" 2>&1
    KERNEL_TABLE=$(cat "$WORK/kernels.md")
fi

# ------------------------------------------------------------------------------- report
rate() { awk -v n="${2:-$ROWS}" -v t="$1" 'BEGIN { printf "%.2f M", n / t / 1e6 }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }
cpu() { awk -v u="$1" -v s="$2" 'BEGIN { printf "%.3f", u + s }'; }
line() { # key floor-key label
    local k=$1 f=$2
    printf '| %s | %.3f | %s | %s | %s | %s | %s |\n' "$3" "${T[$k]}" "$(cpu "${U[$k]}" "${S[$k]}")" \
        "$(rate "${T[$k]}")" "$(ratio "${T[$k]}" "${T[$f]}")" \
        "$(ratio "$(cpu "${U[$k]}" "${S[$k]}")" "$(cpu "${U[$f]}" "${S[$f]}")")" "${R[$k]}"
}

LOAD_BEFORE=${LOAD_BEFORE:-?}
LOAD_AFTER=$(cut -d' ' -f1-3 /proc/loadavg)
CPU_MODEL=$(awk -F: '/model name/ { gsub(/^ +/, "", $2); print $2; exit }' /proc/cpuinfo)
TOOL=$([ -n "$HYPERFINE" ] && echo "hyperfine $("$HYPERFINE" --version | awk '{print $2}') (median of $RUNS runs after 1 warm-up)" || echo "/usr/bin/time (median of $RUNS runs after 1 warm-up)")
REPORT="$WORK/report.md"
{
    echo "Measured $(date -u +%Y-%m-%d) on $(nproc) cores ($CPU_MODEL), $(rustc --version), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?') plus working tree; timing by $TOOL; peak RSS by /usr/bin/time -v. Load average (1, 5, 15 min) before the timings: $LOAD_BEFORE; after: $LOAD_AFTER (other work on the machine inflates wall times; the CPU columns are less affected)."
    echo
    echo "End to end, $ROWS rows (\`$PATH_CSV\`, helix, about 0.2 mm per row):"
    echo
    echo "| command | wall s | CPU s | rows/s (wall) | wall / floor | CPU / floor | peak RSS MiB |"
    echo "|---|---:|---:|---:|---:|---:|---:|"
    line ik floor_ik "\`verne ik\`"
    line ik1 floor_ik "\`verne ik\`, RAYON_NUM_THREADS=1"
    line floor_ik floor_ik "\`io_floor ik\`"
    line fk floor_fk "\`verne fk\` (on the ik output)"
    line fk1 floor_fk "\`verne fk\`, RAYON_NUM_THREADS=1"
    line floor_fk floor_fk "\`io_floor fk\`"
    echo
    echo "The CAM job, $TOOL_ROWS tool poses (\`$TOOL_CSV\`, dome spiral, tip + axis; every row solves both orientation solutions and follows one branch; no I/O floor target):"
    echo
    echo "| command | wall s | CPU s | rows/s (wall) | us per row (CPU) | peak RSS MiB |"
    echo "|---|---:|---:|---:|---:|---:|"
    for k in tool tool1; do
        label="\`verne ik\`"; [ "$k" = tool1 ] && label="$label, RAYON_NUM_THREADS=1"
        printf '| %s | %.3f | %s | %s | %s | %s |\n' "$label" "${T[$k]}" "$(cpu "${U[$k]}" "${S[$k]}")" \
            "$(rate "${T[$k]}" "$TOOL_ROWS")" \
            "$(awk -v c="$(cpu "${U[$k]}" "${S[$k]}")" -v n="$TOOL_ROWS" 'BEGIN { printf "%.1f", c / n * 1e6 }')" "${R[$k]}"
    done
    echo
    echo "CL input, $ROWS tool poses of the same spiral as a CL file (\`$CL_FILE\`, 6-value GOTOs) and as CSV (target: CL no slower than 1.2x CSV, memory under 32 MB):"
    echo
    echo "| command | wall s | CPU s | wall / CSV | peak RSS MiB |"
    echo "|---|---:|---:|---:|---:|"
    for k in cl_csv cl; do
        label="\`verne ik\` on the CSV"; [ "$k" = cl ] && label="\`verne ik\` on the CL file"
        printf '| %s | %.3f | %s | %s | %s |\n' "$label" "${T[$k]}" "$(cpu "${U[$k]}" "${S[$k]}")" \
            "$(ratio "${T[$k]}" "${T[cl_csv]}")" "${R[$k]}"
    done
    if [ -n "$BIG_IK" ]; then
        echo
        echo "Memory check, $BIG_ROWS rows: peak RSS \`verne ik\` $BIG_IK MiB, \`verne fk\` $BIG_FK MiB (target < 32 MB)."
    fi
    echo
    echo "Commands (\`scripts/bench.sh\` runs them):"
    echo
    echo '```sh'
    echo "cargo build --release -p verne-cli --bin verne --example io_floor"
    echo "$VERNE ik $PATH_CSV -o $OUT"
    echo "RAYON_NUM_THREADS=1 $VERNE ik $PATH_CSV -o $OUT"
    echo "$FLOOR ik $PATH_CSV -o $OUT"
    echo "$VERNE ik $PATH_CSV -o $JOINTS_CSV"
    echo "$VERNE fk $JOINTS_CSV -o $OUT"
    echo "RAYON_NUM_THREADS=1 $VERNE fk $JOINTS_CSV -o $OUT"
    echo "$FLOOR fk $JOINTS_CSV -o $OUT"
    echo "$VERNE ik $TOOL_CSV -o $OUT"
    echo "RAYON_NUM_THREADS=1 $VERNE ik $TOOL_CSV -o $OUT"
    echo "$VERNE ik $CL_CSV -o $OUT"
    echo "$VERNE ik $CL_FILE -o $OUT"
    [ -n "$BIG_IK" ] && echo "/usr/bin/time -v $VERNE ik $WORK/path_$BIG_ROWS.csv -o $WORK/joints_$BIG_ROWS.csv"
    [ -n "$BIG_IK" ] && echo "/usr/bin/time -v $VERNE fk $WORK/joints_$BIG_ROWS.csv > /dev/null"
    [ -n "$KERNEL_TABLE" ] && echo "VERNE_BENCH_SUMMARY=$WORK/kernels.md cargo bench -p verne-cli --bench kernels"
    echo '```'
    if [ -n "$KERNEL_TABLE" ]; then
        echo
        echo "Kernels (\`cargo bench -p verne-cli --bench kernels\`; medians of criterion's samples, ns per pose; every ratio is measured in the same run):"
        echo
        echo "$KERNEL_TABLE"
    fi
} > "$REPORT"
cat "$REPORT"

if [ "$DOCS" = 1 ]; then
    DOC=docs/benchmarks.md
    if [ ! -f "$DOC" ]; then
        printf '# Benchmarks\n\n<!-- bench.sh:begin -->\n<!-- bench.sh:end -->\n' > "$DOC"
    fi
    awk -v report="$REPORT" '
        /<!-- bench.sh:begin -->/ { print; while ((getline l < report) > 0) print l; skip = 1; next }
        /<!-- bench.sh:end -->/ { skip = 0 }
        !skip { print }' "$DOC" > "$DOC.tmp" && mv "$DOC.tmp" "$DOC"
    log "updated $DOC"
fi
