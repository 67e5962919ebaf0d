//! The reader against LinuxCNC's own interpreter: for every program of the corpus
//! (tests/data/gcode/), the canonical moves that `rs274 -g` (Debian's `linuxcnc-uspace`) prints
//! must be the reader's rows: the same straight moves in the same order and place, each arc
//! ending where LinuxCNC ends it, its rows on LinuxCNC's circle, turning LinuxCNC's way, and
//! every straight feed move taking the time of LinuxCNC's feed rate. Skipped, with the reason
//! printed, where rs274 is not installed; `VERNE_REQUIRE_RS274=1` (set by
//! scripts/linuxcnc-sim.sh, which installs it) makes its absence a failure.

use std::path::{Path, PathBuf};
use std::process::Command;

use verne_gcode::{Axis, Kind, Motion, Options, Row, read_all};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/gcode")
}

/// The tests that run `rs274` take turns: the interpreter keeps its parameters in a file of the
/// working directory (`rs274ngc.var`), which two runs at once would share.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Holds the turn of a test that runs `rs274` (a test that failed while holding it does not
/// stop the others).
fn turn() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn rs274() -> Option<PathBuf> {
    let found = ["/usr/bin/rs274", "/usr/local/bin/rs274"]
        .iter()
        .map(PathBuf::from)
        .find(|p| p.is_file());
    if found.is_none() {
        let msg = "rs274 (LinuxCNC's G-code interpreter, Debian package linuxcnc-uspace) is not installed: the comparison is skipped (scripts/linuxcnc-sim.sh installs it and runs this test)";
        if std::env::var_os("VERNE_REQUIRE_RS274").is_some() {
            panic!("{msg}");
        }
        eprintln!("{msg}");
    }
    found
}

#[derive(Debug)]
enum Canon {
    Straight {
        end: [f64; 6],
        rapid: bool,
        rate_mm_min: Option<f64>,
    },
    Arc {
        end: [f64; 6],
        centre: [f64; 3],
        turns: i32,
        plane: [usize; 3],
    },
}

fn numbers(line: &str) -> Vec<f64> {
    let open = line.find('(').unwrap();
    let close = line.rfind(')').unwrap();
    line[open + 1..close]
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect()
}

/// The canonical moves of `rs274 -g`, in mm, zero-length traverses dropped.
fn canonical(rs274: &Path, program: &Path) -> Vec<Canon> {
    let out = Command::new(rs274)
        .arg("-g")
        .arg(program)
        .output()
        .expect("run rs274");
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    let mut scale = 1.0;
    let mut plane = [0, 1, 2];
    let mut rate = None;
    let mut per_minute = true;
    let mut at = [f64::NAN; 6];
    let mut moves = Vec::new();
    for line in text.lines() {
        assert!(
            !line.contains("error") && !line.starts_with("Bad") && !line.contains("Unknown"),
            "rs274 refused {}: {line}\n{text}",
            program.display()
        );
        let l = |v: f64| v * scale;
        if line.contains("USE_LENGTH_UNITS(CANON_UNITS_INCHES)") {
            scale = 25.4;
        } else if line.contains("USE_LENGTH_UNITS(CANON_UNITS_MM)") {
            scale = 1.0;
        } else if line.contains("SELECT_PLANE(CANON_PLANE_XY)") {
            plane = [0, 1, 2];
        } else if line.contains("SELECT_PLANE(CANON_PLANE_XZ)") {
            plane = [2, 0, 1];
        } else if line.contains("SELECT_PLANE(CANON_PLANE_YZ)") {
            plane = [1, 2, 0];
        } else if line.contains("SET_FEED_MODE(") {
            per_minute = numbers(line)[1] == 0.0;
        } else if line.contains("SET_FEED_RATE(") {
            rate = Some(numbers(line)[0] * scale).filter(|_| per_minute);
        } else if line.contains("STRAIGHT_TRAVERSE(") || line.contains("STRAIGHT_FEED(") {
            let v = numbers(line);
            let end = [l(v[0]), l(v[1]), l(v[2]), v[3], v[4], v[5]];
            let rapid = line.contains("TRAVERSE");
            if rapid && end == at {
                continue;
            }
            at = end;
            moves.push(Canon::Straight {
                end,
                rapid,
                rate_mm_min: if rapid { None } else { rate },
            });
        } else if line.contains("ARC_FEED(") {
            let v = numbers(line);
            let mut end = [0.0; 6];
            end[plane[0]] = l(v[0]);
            end[plane[1]] = l(v[1]);
            end[plane[2]] = l(v[5]);
            end[3..].copy_from_slice(&v[6..9]);
            let mut centre = [0.0; 3];
            centre[plane[0]] = l(v[2]);
            centre[plane[1]] = l(v[3]);
            at = end;
            moves.push(Canon::Arc {
                end,
                centre,
                turns: v[4] as i32,
                plane,
            });
        }
    }
    moves
}

fn pos6(r: &Row) -> [f64; 6] {
    [
        r.get(Axis::X),
        r.get(Axis::Y),
        r.get(Axis::Z),
        r.get(Axis::A),
        r.get(Axis::B),
        r.get(Axis::C),
    ]
    .map(|v| if v.is_nan() { 0.0 } else { v })
}

fn close(a: &[f64; 6], b: &[f64; 6], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// rs274 prints 4 decimals of the program's unit: 0.5e-4 in = 1.3e-3 mm at worst.
const PRINTED: f64 = 1.5e-3;

#[test]
fn the_reader_makes_linuxcnc_s_canonical_moves() {
    let _turn = turn();
    let Some(rs274) = rs274() else { return };
    let mut checked = 0;
    let mut entries: Vec<PathBuf> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    entries.sort();
    for program in entries {
        let bytes = std::fs::read(&program).unwrap();
        let (rows, summary) = read_all(&bytes, &Options::default())
            .unwrap_or_else(|e| panic!("{}: {e}", program.display()));
        if summary.axes_used & (Axis::U.bit() | Axis::V.bit() | Axis::W.bit()) != 0 {
            eprintln!(
                "{}: uses U V W, which the standalone rs274 (X Y Z A B C) does not read: not compared",
                program.display()
            );
            continue;
        }
        let canon = canonical(&rs274, &program);
        let name = program.display();
        let mut i = 0;
        let mut prev = [f64::NAN; 6];
        for (k, c) in canon.iter().enumerate() {
            assert!(
                i < rows.len(),
                "{name}: rs274 has more moves ({}) than the reader",
                canon.len()
            );
            match c {
                Canon::Straight {
                    end,
                    rapid,
                    rate_mm_min,
                } => {
                    let r = &rows[i];
                    assert!(
                        close(&pos6(r), end, PRINTED),
                        "{name}: move {k} (line {}): reader {:?}, rs274 {end:?}",
                        r.line,
                        pos6(r)
                    );
                    assert_eq!(r.motion == Motion::Rapid, *rapid, "{name}: line {}", r.line);
                    assert_ne!(r.kind, Kind::Arc, "{name}: line {}", r.line);
                    if let (Some(rate), Some(d)) = (rate_mm_min, r.duration_s)
                        && prev[0].is_finite()
                    {
                        let len = (0..3)
                            .map(|j| (end[j] - prev[j]).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        if len > 1e-3 {
                            let expected = 60.0 * len / rate;
                            assert!(
                                (d - expected).abs() <= 1e-3 * expected,
                                "{name}: line {}: {d} s, LinuxCNC's rate gives {expected} s",
                                r.line
                            );
                        }
                    }
                    prev = pos6(r);
                    i += 1;
                }
                Canon::Arc {
                    end,
                    centre,
                    turns,
                    plane,
                } => {
                    let line = rows[i].line;
                    let start = i;
                    while i < rows.len() && rows[i].line == line && rows[i].kind == Kind::Arc {
                        i += 1;
                    }
                    let arc = &rows[start..i];
                    assert!(!arc.is_empty(), "{name}: rs274 has an arc at move {k}");
                    let last = pos6(arc.last().unwrap());
                    assert!(
                        close(&last, end, PRINTED),
                        "{name}: arc of line {line} ends at {last:?}, rs274 {end:?}"
                    );
                    let (p0, p1) = (plane[0], plane[1]);
                    let radius = |p: &[f64; 6]| {
                        ((p[p0] - centre[p0]).powi(2) + (p[p1] - centre[p1]).powi(2)).sqrt()
                    };
                    let r0 = radius(&prev);
                    let mut swept = 0.0;
                    let mut a_prev = (prev[p1] - centre[p1]).atan2(prev[p0] - centre[p0]);
                    for row in arc {
                        let p = pos6(row);
                        assert!(
                            (radius(&p) - r0).abs() < 0.01,
                            "{name}: line {line}: a row off LinuxCNC's circle"
                        );
                        let a = (p[p1] - centre[p1]).atan2(p[p0] - centre[p0]);
                        let mut d = a - a_prev;
                        d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI;
                        swept += d;
                        a_prev = a;
                    }
                    let turns_swept = swept / std::f64::consts::TAU;
                    assert_eq!(
                        turns_swept.signum() as i32,
                        turns.signum(),
                        "{name}: line {line}: direction"
                    );
                    assert!(
                        turns_swept.abs() <= f64::from(turns.abs()) + 1e-9
                            && turns_swept.abs() > f64::from(turns.abs() - 1),
                        "{name}: line {line}: {turns_swept} turns, rs274 {turns}"
                    );
                    prev = last;
                }
            }
        }
        assert_eq!(
            i,
            rows.len(),
            "{name}: the reader has more rows than rs274 has moves"
        );
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} programs compared");
}

#[test]
fn what_the_reader_refuses_it_refuses_at_the_line() {
    let expected = [
        ("cutter-comp.ngc", 3, "cutter radius"),
        ("home.ngc", 3, "home position"),
        ("o-word.ngc", 3, "o-word"),
        ("parameters.ngc", 3, "parameters"),
        ("work-offset.ngc", 2, "work offset"),
    ];
    for (file, line, what) in expected {
        let bytes = std::fs::read(corpus().join("refused").join(file)).unwrap();
        let e = read_all(&bytes, &Options::default()).expect_err(file);
        assert_eq!(e.line, line, "{file}: {e}");
        assert!(e.message.contains(what), "{file}: {e}");
    }
}

/// Blocks with two M codes: the reader refuses those LinuxCNC's interpreter refuses as two M
/// codes of one modal group, and reads the others.
#[test]
fn m_codes_of_one_modal_group_are_refused_as_linuxcnc_refuses_them() {
    let _turn = turn();
    let Some(rs274) = rs274() else { return };
    let dir = std::env::temp_dir().join(format!("verne-m-groups-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut both = [0; 2];
    for block in [
        "M3 M5",
        "M4 M19",
        "M70 M3",
        "M3 M3",
        "M2 M30",
        "M0 M1",
        "M0 M60",
        "M1 M2",
        "M7 M9",
        "M7 M8",
        "M8 M9",
        "M48 M49",
        "M50 P1 M51 P1",
        "M6 M61",
        "M100 M101",
        "M3 M8",
        "M5 M9",
        "M3 M6 M8 M48",
        "M1 M5",
        "M5 M30",
        "M7 M49",
        "M62 P1 M3",
    ] {
        let program = format!("G21 G90\nT1 F100 G0 X0 Y0 Z10\n{block} G1 X1\nM2\n");
        let path = dir.join("m.ngc");
        std::fs::write(&path, &program).unwrap();
        let out = Command::new(&rs274).arg("-g").arg(&path).output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout).to_string()
            + &String::from_utf8_lossy(&out.stderr);
        let linuxcnc_refuses = text.contains("Two m codes used from same modal group");
        let ours = read_all(program.as_bytes(), &Options::default());
        let we_refuse = ours
            .as_ref()
            .is_err_and(|e| e.message.contains("same modal group"));
        assert_eq!(
            we_refuse, linuxcnc_refuses,
            "{block}: LinuxCNC says {text:?}, the reader {ours:?}"
        );
        if !we_refuse {
            assert!(ours.is_ok(), "{block}: {ours:?}");
        }
        both[usize::from(we_refuse)] += 1;
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(both[0] >= 5 && both[1] >= 10, "{both:?}");
}
