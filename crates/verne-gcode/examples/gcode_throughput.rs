//! Throughput of the G-code reader on a generated program of 1,000,000 five-axis blocks as a
//! post writes them (`N.. G1 X.. Y.. Z.. A.. C..`, a feed every 50 blocks, an arc every 1000),
//! read from a file on one thread; and the time of one block per core-second budget.
//!
//! `cargo run --release -p verne-gcode --example gcode_throughput [BLOCKS]`; the file is written to
//! the temp dir and removed.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::time::Instant;

use verne_gcode::{Options, Reader};

fn write_program(path: &std::path::Path, blocks: usize) -> u64 {
    let mut w = BufWriter::new(File::create(path).unwrap());
    writeln!(
        w,
        "%\n(throughput)\nG21 G90 G17 G94 G40 G49 G80\nG0 X0 Y0 Z50 A0 C0"
    )
    .unwrap();
    let mut s = 12345u64;
    let (mut x, mut y) = (0.0f64, 0.0f64);
    for n in 0..blocks {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let dx = ((s >> 40) & 0xFFF) as f64 / 4096.0 - 0.5;
        let dy = ((s >> 20) & 0xFFF) as f64 / 4096.0 - 0.5;
        let z = ((s >> 8) & 0xFF) as f64 / 64.0;
        let a = ((s >> 4) & 0xF) as f64 / 2.0;
        let c = (n % 3600) as f64 / 10.0;
        if n % 1000 == 999 {
            // A half circle back to the same x.
            writeln!(w, "N{} G2 X{:.4} Y{:.4} I1. J0", n + 10, x + 2.0, y).unwrap();
            x += 2.0;
            continue;
        }
        x += dx;
        y += dy;
        if n % 50 == 0 {
            writeln!(
                w,
                "N{} G1 X{x:.4} Y{y:.4} Z{z:.4} A{a:.3} C{c:.3} F{}",
                n + 10,
                1000 + n % 7
            )
            .unwrap();
        } else {
            writeln!(w, "N{} X{x:.4} Y{y:.4} Z{z:.4} A{a:.3} C{c:.3}", n + 10).unwrap();
        }
    }
    writeln!(w, "M2\n%").unwrap();
    w.flush().unwrap();
    std::fs::metadata(path).unwrap().len()
}

fn main() {
    let blocks: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let path =
        std::env::temp_dir().join(format!("verne-gcode-throughput-{}.ngc", std::process::id()));
    let bytes = write_program(&path, blocks);
    let mut best = f64::INFINITY;
    let mut rows = 0;
    for _ in 0..3 {
        let t = Instant::now();
        let f = BufReader::with_capacity(64 * 1024, File::open(&path).unwrap());
        let mut reader = Reader::new(f, Options::default()).unwrap();
        let mut n = 0u64;
        let mut check = 0.0;
        for r in reader.by_ref() {
            let r = r.unwrap();
            n += 1;
            check += r.position[0];
        }
        let dt = t.elapsed().as_secs_f64();
        assert!(check.is_finite());
        rows = n;
        best = best.min(dt);
        assert_eq!(reader.summary().blocks as usize, blocks + 3);
    }
    std::fs::remove_file(&path).ok();
    println!(
        "{blocks} blocks ({:.1} MiB, {rows} rows with the arcs interpolated): best of 3 {:.3} s = {:.2} M blocks/s, {:.0} MB/s, one thread",
        bytes as f64 / (1 << 20) as f64,
        best,
        blocks as f64 / best / 1e6,
        bytes as f64 / best / 1e6
    );
}
