//! Reads CL files and prints the rows as CSV (`line,kind,motion,feed_mm_min,tool,x,y,z,i,j,k`),
//! then the summary, to standard error. `cargo run --example clread -- FILE [CHORD_TOL_MM]`.

use std::io::Write;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        eprintln!("usage: clread FILE [CHORD_TOL_MM]");
        std::process::exit(2);
    };
    let mut opts = verne_cl::Options::default();
    if let Some(t) = args.get(1) {
        opts.chord_tol_mm = t.parse().expect("chord tolerance");
    }
    let mut reader = match verne_cl::open(std::path::Path::new(path), opts) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(1);
        }
    };
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    writeln!(out, "line,kind,motion,feed_mm_min,tool,x,y,z,i,j,k").unwrap();
    let mut failed = false;
    for r in reader.by_ref() {
        match r {
            Ok(r) => {
                let feed = r.feed_mm_min.map(|f| format!("{f}")).unwrap_or_default();
                let tool = r.tool.map(|t| t.to_string()).unwrap_or_default();
                writeln!(
                    out,
                    "{},{},{},{feed},{tool},{},{},{},{},{},{}",
                    r.line,
                    r.kind,
                    r.motion,
                    r.tip[0],
                    r.tip[1],
                    r.tip[2],
                    r.axis[0],
                    r.axis[1],
                    r.axis[2]
                )
                .unwrap();
            }
            Err(e) => {
                out.flush().unwrap();
                eprintln!("{path}: {e}");
                failed = true;
            }
        }
    }
    out.flush().unwrap();
    let s = reader.summary();
    eprintln!(
        "{path}: {} rows, {} lines, {} ({:?}), units {} ({:?}), arcs {:?}",
        s.rows, s.lines, s.dialect, s.dialect, s.units, s.units_source, s.arc_rule
    );
    if !s.skipped.is_empty() {
        eprintln!("skipped: {}", s.skipped_line());
    }
    for t in &s.tools {
        eprintln!(
            "tool change at line {} (first row line {}): tool {:?} {:?} length {:?} mm",
            t.line, t.first_row_line, t.tool, t.name, t.length_mm
        );
    }
    for w in &s.warnings {
        eprintln!("warning: {w}");
    }
    if failed {
        std::process::exit(1);
    }
}
