//! The reader on every file of the CL corpus, compared as `corpus/README.md` says:
//! rows (arcs reduced to their end row) equal to `*.expected.csv` within the tolerances,
//! every interpolated arc point on the arc of `*.arcs.csv` within 1e-3 mm with the chord
//! error under the chord tolerance, errors at the line of `*.expected_error.txt`, warnings at
//! the lines of `*.expected_warnings.txt`.
//!
//! The corpus is found at `$CL_CORPUS`, else at `tests/data/cl-corpus` at the workspace root.

use std::fs;
use std::path::{Path, PathBuf};

mod common;
use common::corpus_dir;
use verne_cl::{Kind, Options, Row, read_all};

const SUFFIXES: [&str; 4] = [
    ".expected.csv",
    ".arcs.csv",
    ".expected_error.txt",
    ".expected_warnings.txt",
];

fn inputs(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("corpus {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().into_owned();
            !SUFFIXES.iter().any(|s| n.ends_with(s)) && n != "README.md" && n != "SOURCES.md"
        })
        .collect();
    v.sort();
    v
}

fn with_suffix(p: &Path, suffix: &str) -> PathBuf {
    let mut s = p.as_os_str().to_owned();
    s.push(suffix);
    PathBuf::from(s)
}

/// `line: reason` lines: the line numbers.
fn lines_of(text: &str) -> Vec<u64> {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(':').next().unwrap().trim().parse().unwrap())
        .collect()
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("number {s:?}"))
}

struct Expected {
    line: u64,
    kind: String,
    motion: String,
    feed: Option<f64>,
    tool: Option<u32>,
    p: [f64; 3],
    a: [f64; 3],
}

fn expected_rows(text: &str) -> Vec<Expected> {
    text.lines()
        .skip(1)
        .filter(|l| !l.is_empty())
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 11, "{l}");
            Expected {
                line: f[0].parse().unwrap(),
                kind: f[1].to_string(),
                motion: f[2].to_string(),
                feed: (!f[3].is_empty()).then(|| num(f[3])),
                tool: (!f[4].is_empty()).then(|| f[4].parse().unwrap()),
                p: [num(f[5]), num(f[6]), num(f[7])],
                a: [num(f[8]), num(f[9]), num(f[10])],
            }
        })
        .collect()
}

/// Rows with every CIRCLE row that is not the last of its arc removed (README step 1).
fn reduce_arcs(rows: &[Row]) -> Vec<Row> {
    let mut out = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let next_same_arc = rows
            .get(i + 1)
            .is_some_and(|n| n.kind == Kind::Circle && n.line == r.line);
        if r.kind == Kind::Circle && next_same_arc {
            continue;
        }
        out.push(*r);
    }
    out
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// README step 3, plus the chord error: returns the number of arc points checked.
fn check_arcs(name: &str, text: &str, rows: &[Row], tol: f64) -> usize {
    let mut checked = 0;
    for l in text.lines().skip(1).filter(|l| !l.is_empty()) {
        let f: Vec<&str> = l.split(',').collect();
        assert_eq!(f.len(), 20, "{l}");
        let line: u64 = f[0].parse().unwrap();
        let v = |i: usize| num(f[i]);
        let c = [v(2), v(3), v(4)];
        let r = [v(9), v(10), v(11)];
        let radius = v(12);
        let s = [v(13), v(14), v(15)];
        let e = [v(16), v(17), v(18)];
        let sweep = v(19).to_radians();
        let pts: Vec<[f64; 3]> = std::iter::once(s)
            .chain(
                rows.iter()
                    .filter(|x| x.kind == Kind::Circle && x.line == line)
                    .map(|x| x.tip),
            )
            .collect();
        assert!(pts.len() >= 2, "{name}: arc at line {line} has no rows");
        let ds = sub(s, c);
        let e1 = sub(ds, scale(r, dot(ds, r)));
        let e1 = scale(e1, 1.0 / norm(e1));
        let e2 = cross(r, e1);
        let axial_total = dot(sub(e, s), r);
        let mut prev_angle = 0.0f64;
        let mut angles = Vec::new();
        for (k, p) in pts.iter().enumerate() {
            let d = sub(*p, c);
            let radial = sub(d, scale(r, dot(d, r)));
            assert!(
                (norm(radial) - radius).abs() < 1e-3,
                "{name}: arc {line} point {k} {p:?}: radius {} vs {radius}",
                norm(radial)
            );
            let mut ang = dot(radial, e2).atan2(dot(radial, e1));
            if ang < 0.0 {
                ang += std::f64::consts::TAU;
            }
            // unwrap: increasing from the start
            while ang < prev_angle - 1e-6 {
                ang += std::f64::consts::TAU;
            }
            if k == pts.len() - 1 && (sweep - ang).abs() > 1e-6 {
                // the last point of a full circle sits at 2π, not 0
                if (sweep - (ang + std::f64::consts::TAU)).abs() < 1e-6 {
                    ang += std::f64::consts::TAU;
                }
            }
            assert!(
                ang >= -1e-9 && ang <= sweep + 1e-6,
                "{name}: arc {line} point {k}: angle {ang} outside [0, {sweep}]"
            );
            let axial = dot(sub(*p, s), r);
            let want = axial_total * ang / sweep;
            assert!(
                (axial - want).abs() < 1e-3,
                "{name}: arc {line} point {k}: axial {axial} vs {want}"
            );
            prev_angle = ang;
            angles.push(ang);
        }
        let last = pts[pts.len() - 1];
        assert!(
            norm(sub(last, e)) < 1e-5,
            "{name}: arc {line}: end {last:?} vs {e:?}"
        );
        assert!(
            (angles[angles.len() - 1] - sweep).abs() < 1e-6,
            "{name}: arc {line}: ends at angle {} of {sweep}",
            angles[angles.len() - 1]
        );
        // chord error: the middle of each chord against the arc point at the middle angle
        for k in 1..pts.len() {
            let mid_ang = 0.5 * (angles[k - 1] + angles[k]);
            let (sn, cs) = mid_ang.sin_cos();
            let on_arc = [
                c[0] + radius * (e1[0] * cs + e2[0] * sn)
                    + r[0] * (dot(sub(s, c), r) + axial_total * mid_ang / sweep),
                c[1] + radius * (e1[1] * cs + e2[1] * sn)
                    + r[1] * (dot(sub(s, c), r) + axial_total * mid_ang / sweep),
                c[2] + radius * (e1[2] * cs + e2[2] * sn)
                    + r[2] * (dot(sub(s, c), r) + axial_total * mid_ang / sweep),
            ];
            let mid = scale(
                [
                    pts[k - 1][0] + pts[k][0],
                    pts[k - 1][1] + pts[k][1],
                    pts[k - 1][2] + pts[k][2],
                ],
                0.5,
            );
            let err = norm(sub(mid, on_arc));
            assert!(
                err <= tol * (1.0 + 1e-6) + 1e-9,
                "{name}: arc {line} chord {k}: error {err} > {tol}"
            );
            checked += 1;
        }
    }
    checked
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// Runs one corpus file; returns (rows compared, arc points checked, errors, warnings).
fn run_file(path: &Path, opts: &Options) -> (usize, usize, usize, usize) {
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let bytes = fs::read(path).unwrap();
    let result = read_all(&name, &bytes, opts);
    let err_file = with_suffix(path, ".expected_error.txt");
    if err_file.exists() {
        let want = lines_of(&fs::read_to_string(&err_file).unwrap());
        match result {
            Ok((rows, _)) => panic!(
                "{name}: expected an error at line {want:?}, read {} rows",
                rows.len()
            ),
            Err(e) => {
                assert_eq!(vec![e.line], want, "{name}: error {e}");
                return (0, 0, 1, 0);
            }
        }
    }
    let (rows, summary) = result.unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(
        summary.rows as usize,
        rows.len(),
        "{name}: summary row count"
    );
    let exp = expected_rows(&fs::read_to_string(with_suffix(path, ".expected.csv")).unwrap());
    let got = reduce_arcs(&rows);
    assert_eq!(got.len(), exp.len(), "{name}: row count\n{got:#?}");
    for (k, (g, e)) in got.iter().zip(&exp).enumerate() {
        let ctx = format!("{name} row {k} (line {}): {g:?}", e.line);
        assert_eq!(g.line, e.line, "{ctx}");
        assert_eq!(g.kind.as_str(), e.kind, "{ctx}");
        assert_eq!(g.motion.as_str(), e.motion, "{ctx}");
        assert_eq!(g.tool, e.tool, "{ctx}");
        match (g.feed_mm_min, e.feed) {
            (None, None) => {}
            (Some(a), Some(b)) => assert!(close(a, b, 1e-4), "{ctx}: feed {a} vs {b}"),
            (a, b) => panic!("{ctx}: feed {a:?} vs {b:?}"),
        }
        for i in 0..3 {
            assert!(close(g.tip[i], e.p[i], 1e-5), "{ctx}: tip vs {:?}", e.p);
            assert!(close(g.axis[i], e.a[i], 1e-5), "{ctx}: axis vs {:?}", e.a);
        }
    }
    let arcs_file = with_suffix(path, ".arcs.csv");
    let mut arc_points = 0;
    if arcs_file.exists() {
        arc_points = check_arcs(
            &name,
            &fs::read_to_string(&arcs_file).unwrap(),
            &rows,
            opts.chord_tol_mm,
        );
    } else {
        assert!(
            rows.iter().all(|r| r.kind != Kind::Circle),
            "{name}: CIRCLE rows without an arcs file"
        );
    }
    let warn_file = with_suffix(path, ".expected_warnings.txt");
    let want_w = if warn_file.exists() {
        lines_of(&fs::read_to_string(&warn_file).unwrap())
    } else {
        Vec::new()
    };
    let got_w: Vec<u64> = summary.warnings.iter().map(|w| w.line).collect();
    assert_eq!(got_w, want_w, "{name}: warnings {:?}", summary.warnings);
    (got.len(), arc_points, 0, got_w.len())
}

#[test]
fn corpus_default_tolerance() {
    let dir = corpus_dir();
    let files = inputs(&dir);
    assert_eq!(files.len(), 37, "corpus inputs in {}", dir.display());
    let (mut rows, mut pts, mut errs, mut warns) = (0, 0, 0, 0);
    for f in &files {
        let (r, p, e, w) = run_file(f, &Options::default());
        rows += r;
        pts += p;
        errs += e;
        warns += w;
    }
    eprintln!(
        "corpus: {} files, {rows} rows compared, {pts} arc chords checked, {errs} errors and {warns} warnings at the expected lines",
        files.len()
    );
    assert_eq!(errs, 12);
}

#[test]
fn corpus_other_tolerances() {
    // the arcs hold at other chord tolerances too (more or fewer interpolated points)
    let dir = corpus_dir();
    for tol in [1e-4, 0.05, 1.0, 100.0] {
        let opts = Options {
            chord_tol_mm: tol,
            ..Options::default()
        };
        for f in inputs(&dir) {
            run_file(&f, &opts);
        }
    }
}
