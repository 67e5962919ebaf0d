//! Property-style checks: the same program written differently gives the same rows
//! (random `$` continuation splits, inch vs mm, case/blanks/CRLF), very long lines and records
//! are read (their time is measured by `examples/cl_throughput.rs`, not here), and a random-bytes /
//! mutation loop over [`fuzz_read`] never panics.

use std::fs;

mod common;
use common::corpus_dir;
use verne_cl::{ClErrorKind, Options, Row, Units, fuzz_read, read_all};

/// xorshift64* (no dependency).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
}

fn corpus_inputs() -> Vec<(String, Vec<u8>)> {
    let dir = corpus_dir();
    let mut v: Vec<(String, Vec<u8>)> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("corpus {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().into_owned();
            !n.ends_with(".csv") && !n.ends_with(".txt") && !n.ends_with(".md")
                || (n.ends_with(".txt") && !n.contains(".expected"))
        })
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    assert_eq!(v.len(), 37);
    v
}

fn same_rows(a: &[Row], b: &[Row], tol: f64) -> Result<(), String> {
    if a.len() != b.len() {
        return Err(format!("{} rows vs {}", a.len(), b.len()));
    }
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        let feed_ok = match (x.feed_mm_min, y.feed_mm_min) {
            (None, None) => true,
            (Some(p), Some(q)) => (p - q).abs() <= tol * (1.0 + p.abs()),
            _ => false,
        };
        let num_ok = (0..3).all(|i| {
            (x.tip[i] - y.tip[i]).abs() <= tol * (1.0 + x.tip[i].abs())
                && (x.axis[i] - y.axis[i]).abs() <= tol
        });
        if x.kind != y.kind || x.motion != y.motion || x.tool != y.tool || !feed_ok || !num_ok {
            return Err(format!("row {k}: {x:?} vs {y:?}"));
        }
    }
    Ok(())
}

/// Whether a line may be split with `$` continuations: an ordinary record line, not a
/// comment, free text, header or a listing's last line, and not itself part of a
/// continuation.
fn splittable(line: &str, prev: Option<&str>) -> bool {
    let t = line.trim();
    let up = t.to_ascii_uppercase();
    !t.is_empty()
        && !t.contains('$')
        && !prev.is_some_and(|p| p.contains('$'))
        && !["PARTNO", "PPRINT", "INSERT", "REMARK", "TPRINT"]
            .iter()
            .any(|w| up.starts_with(w))
        && !t.contains(':')
        && !t.starts_with('=')
        && !up
            .split_whitespace()
            .collect::<Vec<_>>()
            .starts_with(&["TOOL", "PATH", "LISTING"])
        && t.len() >= 2
}

/// Splits some record lines of `text` with `$` continuations at random places (never next
/// to a blank, so that no blank that matters is lost), with random text after the `$` and
/// random empty continuation lines. Returns the new text and, for every old line, its new
/// line number.
fn split_randomly(text: &str, rng: &mut Rng) -> (String, Vec<u64>) {
    let eol = if text.contains("\r\n") { "\r\n" } else { "\n" };
    let lines: Vec<&str> = text
        .split('\n')
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .collect();
    let mut out = String::new();
    let mut map = Vec::new();
    let mut new_line = 1u64;
    for (k, line) in lines.iter().enumerate() {
        map.push(new_line);
        let prev = if k > 0 { Some(lines[k - 1]) } else { None };
        let last = k + 1 == lines.len();
        if !splittable(line, prev) || !rng.chance(0.6) {
            out.push_str(line);
            if !last {
                out.push_str(eol);
                new_line += 1;
            }
            continue;
        }
        let b = line.as_bytes();
        let mut cuts: Vec<usize> = (0..1 + rng.below(3))
            .map(|_| 1 + rng.below(b.len() - 1))
            .filter(|&i| !b[i - 1].is_ascii_whitespace() && !b[i].is_ascii_whitespace())
            .collect();
        cuts.sort();
        cuts.dedup();
        let mut start = 0;
        for c in cuts {
            out.push_str(&line[start..c]);
            out.push('$');
            match rng.below(3) {
                0 => {}
                1 => out.push_str("   "),
                _ => out.push_str(" ignored text, GOTO/9,9,9"),
            }
            out.push_str(eol);
            new_line += 1;
            for _ in 0..rng.below(2) {
                out.push_str("   $");
                out.push_str(eol);
                new_line += 1;
            }
            if rng.chance(0.5) {
                out.push_str("    ");
            }
            start = c;
        }
        out.push_str(&line[start..]);
        if !last {
            out.push_str(eol);
            new_line += 1;
        }
    }
    (out, map)
}

#[test]
fn random_continuation_splits_give_the_same_rows() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let opts = Options::default();
    let mut trials = 0;
    for (name, bytes) in corpus_inputs() {
        let text = String::from_utf8(bytes.clone()).expect("corpus is ASCII");
        let base = read_all(&name, &bytes, &opts);
        for _ in 0..20 {
            let (split, map) = split_randomly(&text, &mut rng);
            let got = read_all(&name, split.as_bytes(), &opts);
            match (&base, &got) {
                (Ok((a, sa)), Ok((b, sb))) => {
                    if let Err(e) = same_rows(a, b, 0.0) {
                        panic!("{name}: {e}\n{split}");
                    }
                    for (x, y) in a.iter().zip(b) {
                        assert_eq!(
                            map[x.line as usize - 1],
                            y.line,
                            "{name}: line map\n{split}"
                        );
                    }
                    let wa: Vec<u64> = sa
                        .warnings
                        .iter()
                        .map(|w| map[w.line as usize - 1])
                        .collect();
                    let wb: Vec<u64> = sb.warnings.iter().map(|w| w.line).collect();
                    assert_eq!(wa, wb, "{name}: warnings\n{split}");
                }
                (Err(ea), Err(eb)) => {
                    assert_eq!(
                        map[ea.line as usize - 1],
                        eb.line,
                        "{name}: {ea} / {eb}\n{split}"
                    );
                }
                (a, b) => panic!(
                    "{name}: {:?} vs {:?}\n{split}",
                    a.as_ref().map(|x| x.0.len()),
                    b.as_ref().map(|x| x.0.len())
                ),
            }
            trials += 1;
        }
    }
    eprintln!("{trials} split variants read");
}

#[test]
fn case_blanks_and_crlf_give_the_same_rows() {
    let opts = Options::default();
    for (name, bytes) in corpus_inputs() {
        let text = String::from_utf8(bytes.clone()).unwrap();
        let base = read_all(&name, &bytes, &opts);
        // lower case, blanks around `/` and `,`, CRLF line ends (and the other way round)
        let variant: String = text
            .split('\n')
            .map(|l| {
                let l = l.strip_suffix('\r').unwrap_or(l);
                let t = l.trim_start();
                let free = ["PARTNO", "PPRINT", "INSERT", "REMARK", "TPRINT"]
                    .iter()
                    .any(|w| t.to_ascii_uppercase().starts_with(w));
                if t.starts_with("$$") || free || t.contains(':') || t.contains("TOOL PATH") {
                    l.to_string()
                } else {
                    l.to_ascii_lowercase()
                        .replace('/', " \t/ ")
                        .replace(',', " , ")
                }
            })
            .collect::<Vec<_>>()
            .join(if text.contains("\r\n") { "\n" } else { "\r\n" });
        let got = read_all(&name, variant.as_bytes(), &opts);
        match (&base, &got) {
            (Ok((a, _)), Ok((b, _))) => {
                if let Err(e) = same_rows(a, b, 0.0) {
                    panic!("{name}: {e}\n{variant}");
                }
            }
            (Err(ea), Err(eb)) => assert_eq!(ea.line, eb.line, "{name}: {ea} / {eb}"),
            _ => panic!("{name}: {base:?}\nvs\n{got:?}"),
        }
    }
}

/// One program in mm; `inch` writes every length in inches (feeds included), with the same
/// meaning.
fn program(inch: bool, nx: bool) -> String {
    let k = if inch { 1.0 / 25.4 } else { 1.0 };
    let l = |v: f64| format!("{:.15e}", v * k).replace('e', "D");
    let p = |x: f64, y: f64, z: f64| format!("{},{},{}", l(x), l(y), l(z));
    let mut s = String::new();
    if nx {
        s += "TOOL PATH/OP1,TOOL,EM10\n";
        s += &format!("TLDATA/MILL,{},0,{},0,0\n", l(10.0), l(75.0));
        s += &format!("MSYS/{},1,0,0,0,1,0\n", p(100.0, 50.0, 20.0));
        s += "LOAD/TOOL,3\n";
    } else {
        s += if inch { "UNITS/INCHES\n" } else { "UNITS/MM\n" };
        s += "LOADTL/3\n";
    }
    s += "SPINDL/RPM,2000,CLW\nRAPID\n";
    s += &format!("GOTO/{},0,0,1\n", p(-12.0, 0.0, 50.0));
    s += &format!("FEDRAT/{}\n", l(250.0));
    s += &format!("GOTO/{}\n", p(-12.0, 0.0, 0.0));
    s += &format!("GOTO/{}\n", p(20.0, 0.0, 0.0));
    s += &format!("CIRCLE/{},0,0,1,{}\n", p(20.0, 10.0, 0.0), l(10.0));
    s += &format!("GOTO/{}\n", p(30.0, 10.0, -1.5));
    s += &format!("GODLTA/{}\n", l(-2.0));
    s += &format!("GODLTA/{}\n", p(5.0, 0.0, 0.0));
    s += &format!("FEDRAT/PERREV,{}\n", l(0.05));
    s += &format!("GOTO/{},0,0.6,0.8\n", p(40.0, 10.0, -3.5));
    s += &format!("FEDRAT/INVERS,{}\n", 12.5);
    s += &format!("GOTO/{}\n", p(50.0, 10.0, -3.5));
    s += &format!(
        "CYCLE/DRILL,RAPTO,{},FEDTO,{},RTRCTO,{},MMPM,120\n",
        l(3.0),
        l(-20.0),
        l(10.0)
    );
    s += &format!("GOTO/{},0,0,1\n", p(60.0, 10.0, 0.0));
    s += &format!("GOTO/{}\n", p(70.0, 10.0, 0.0));
    s += "CYCLE/OFF\n";
    // MMPR is an explicit mm unit: not converted
    s += &format!("CYCLE/DRILL,{},MMPR,0.1,{}\n", l(12.0), l(2.0));
    s += &format!("GOTO/{}\n", p(80.0, 10.0, 0.0));
    s += "CYCLE/OFF\n";
    s += &format!("FROM/{}\n", p(0.0, 0.0, 100.0));
    s += if nx { "END-OF-PATH\n" } else { "FINI\n" };
    s
}

#[test]
fn inch_and_mm_give_the_same_rows() {
    for nx in [false, true] {
        let mm_text = program(false, nx);
        let in_text = program(true, nx);
        // NX files carry no UNITS: the units are stated (as `--units` would)
        let (o_mm, o_in) = if nx {
            (
                Options {
                    units: Some(Units::Mm),
                    ..Options::default()
                },
                Options {
                    units: Some(Units::Inch),
                    ..Options::default()
                },
            )
        } else {
            (Options::default(), Options::default())
        };
        let (a, sa) = read_all("mm.cl", mm_text.as_bytes(), &o_mm)
            .unwrap_or_else(|e| panic!("{e}\n{mm_text}"));
        let (b, sb) = read_all("in.cl", in_text.as_bytes(), &o_in)
            .unwrap_or_else(|e| panic!("{e}\n{in_text}"));
        assert!(a.len() > 20, "{}", a.len());
        same_rows(&a, &b, 1e-12).unwrap_or_else(|e| panic!("nx {nx}: {e}"));
        assert_eq!(sa.units, Units::Mm);
        assert_eq!(sb.units, Units::Inch);
        assert_eq!(sa.tools.len(), sb.tools.len());
        for (x, y) in sa.tools.iter().zip(&sb.tools) {
            assert_eq!(x.tool, y.tool);
            match (x.length_mm, y.length_mm) {
                (Some(p), Some(q)) => assert!((p - q).abs() < 1e-9),
                (p, q) => assert_eq!(p, q),
            }
        }
    }
}

#[test]
fn long_lines_and_long_records_are_read() {
    let opts = Options::default();
    // a 1 MB line: a GOTO whose number has a million digits, then a PPRINT of 1 MB
    let big = format!("12.5{}", "0".repeat(1_000_000));
    let text = format!(
        "UNITS/MM\nGOTO/{big},-7.25,{big}\nPPRINT/{}\nGOTO/1,2,3\n",
        "x".repeat(1 << 20)
    );
    let (rows, _) = read_all("long.cl", text.as_bytes(), &opts).unwrap();
    assert_eq!(rows[0].tip, [12.5, -7.25, 12.5]);
    // a record continued over 200 000 lines (empty continuation lines too)
    let mut text = String::from("UNITS/MM\nGOTO/1.$\n");
    for _ in 0..100_000 {
        text.push_str("  $\n0$\n");
    }
    text.push_str(",2,3\nGOTO/4,5,6\n");
    let (rows, s) = read_all("cont.cl", text.as_bytes(), &opts).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].tip, [1.0, 2.0, 3.0]);
    assert_eq!(rows[1].line, 200_004);
    assert_eq!(s.lines, 200_004);
    // a comment continued over 200 000 lines
    let mut text = String::from("UNITS/MM\n$$ start $\n");
    for _ in 0..200_000 {
        text.push_str("  more text $\n");
    }
    text.push_str("end\nGOTO/4,5,6\n");
    let (rows, _) = read_all("com.cl", text.as_bytes(), &opts).unwrap();
    assert_eq!(rows[0].line, 200_004);
}

#[test]
fn record_size_limit() {
    // the default limit: 16 MiB; a 17 MiB line is an error naming its line and the limit
    let text = format!(
        "UNITS/MM\nGOTO/0,0,0\nPPRINT/{}\nGOTO/1,2,3\n",
        "x".repeat(17 << 20)
    );
    let e = read_all("big.cl", text.as_bytes(), &Options::default()).unwrap_err();
    assert_eq!(e.line, 3);
    assert_eq!(e.kind, ClErrorKind::RecordTooLong { limit: 16 << 20 });
    assert!(e.to_string().contains("16 MiB"), "{e}");
    // a record over many lines, with a small limit
    let small = Options {
        max_record_bytes: 1000,
        ..Options::default()
    };
    let mut text = String::from("UNITS/MM\nGOTO/0,0,0\nCUTTER/1$\n");
    for _ in 0..2000 {
        text.push_str("0$\n");
    }
    text.push_str("0\n");
    let e = read_all("big.cl", text.as_bytes(), &small).unwrap_err();
    assert_eq!(
        (e.line, e.kind),
        (3, ClErrorKind::RecordTooLong { limit: 1000 })
    );
}

const TOKENS: [&str; 40] = [
    "GOTO/",
    "FROM/",
    "CIRCLE/",
    "CYCLE/",
    "FEDRAT/",
    "RAPID\n",
    "$",
    "$$",
    "$\n",
    "\n",
    ",",
    "/",
    " ",
    "1e308",
    "-1e308",
    "0",
    "0.0",
    ".5",
    "5.",
    "1D+2",
    "IPM",
    "MMPR",
    "INVERS,",
    "SPINDL/OFF\n",
    "MSYS/",
    "CSYS/",
    "TRNTYP/WORLD\n",
    "UNITS/INCH\n",
    "UNITS/MM\n",
    "FINI\n",
    "END-OF-PATH\n",
    "TOOL PATH/X\n",
    "$$-> CSYS / ",
    "$$*CATIA0\n",
    "\r",
    "\r\n",
    "GODLTA/",
    "LOADTL/",
    "Information Units : in\n",
    "    1,2,3\n",
];

fn mutate(rng: &mut Rng, corpus: &[(String, Vec<u8>)], buf: &mut Vec<u8>) {
    match rng.below(8) {
        0 => {
            // random bytes
            buf.clear();
            for _ in 0..rng.below(300) {
                buf.push(rng.next() as u8);
            }
        }
        1 => {
            // random tokens
            buf.clear();
            for _ in 0..rng.below(80) {
                buf.extend_from_slice(TOKENS[rng.below(TOKENS.len())].as_bytes());
                if rng.chance(0.5) {
                    buf.extend_from_slice(format!("{}", rng.below(200) as i64 - 100).as_bytes());
                }
            }
        }
        _ => {
            *buf = corpus[rng.below(corpus.len())].1.clone();
            for _ in 0..1 + rng.below(6) {
                let n = buf.len().max(1);
                match rng.below(6) {
                    0 => {
                        let i = rng.below(n);
                        if i < buf.len() {
                            buf[i] = rng.next() as u8;
                        }
                    }
                    1 => {
                        let i = rng.below(n).min(buf.len());
                        let t = TOKENS[rng.below(TOKENS.len())].as_bytes();
                        buf.splice(i..i, t.iter().copied());
                    }
                    2 => {
                        let i = rng.below(n).min(buf.len());
                        let j = (i + rng.below(40)).min(buf.len());
                        buf.drain(i..j);
                    }
                    3 => {
                        let i = rng.below(n).min(buf.len());
                        let j = (i + rng.below(200)).min(buf.len());
                        let piece = buf[i..j].to_vec();
                        let k = rng.below(n).min(buf.len());
                        buf.splice(k..k, piece);
                    }
                    4 => {
                        let other = &corpus[rng.below(corpus.len())].1;
                        let i = rng.below(n).min(buf.len());
                        let j = rng.below(other.len().max(1)).min(other.len());
                        buf.truncate(i);
                        buf.extend_from_slice(&other[j..]);
                    }
                    _ => {
                        // change a digit run into an extreme number
                        if let Some(i) = buf.iter().position(|b| b.is_ascii_digit()) {
                            let ext = ["1e300", "0", "-0", "1e-300", "99999999999", "1D400"];
                            let e = ext[rng.below(ext.len())].as_bytes();
                            let start = (i + rng.below(buf.len() - i)).min(buf.len() - 1);
                            buf.splice(start..start + 1, e.iter().copied());
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn fuzz_loop_never_panics() {
    // A fixed number of inputs, not a time budget: the same inputs on every machine.
    let count: u64 = std::env::var("FUZZ_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let seed: u64 = std::env::var("FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5EED_1234_ABCD_0001);
    let corpus = corpus_inputs();
    for (_, b) in &corpus {
        fuzz_read(b);
    }
    let mut rng = Rng(seed);
    let mut buf = Vec::new();
    for _ in 0..count {
        mutate(&mut rng, &corpus, &mut buf);
        let input = buf.clone();
        if std::panic::catch_unwind(|| fuzz_read(&input)).is_err() {
            let path = std::env::temp_dir().join("verne_cl_fuzz_crash.cl");
            fs::write(&path, &input).unwrap();
            panic!("fuzz_read panicked; input saved to {}", path.display());
        }
    }
}
