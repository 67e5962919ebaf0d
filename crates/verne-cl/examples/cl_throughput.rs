//! Throughput of the CL reader on a generated file of 1,000,000 six-value `GOTO`s (NX style),
//! allocations per row in the steady state (counting allocator), and the time of very long
//! lines and records at two sizes (linear time shows as a ratio near the size ratio).
//!
//! `cargo run --release -p verne-cl --example cl_throughput [ROWS]`; the file is written to the temp dir.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::time::Instant;

use verne_cl::{Options, Reader, Units};

#[path = "../tests/common/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::{Counting, allocations, count_this_thread};

#[global_allocator]
static A: Counting = Counting;

fn write_file(path: &std::path::Path, rows: usize, units: bool) -> u64 {
    let mut w = BufWriter::new(File::create(path).unwrap());
    if units {
        writeln!(w, "UNITS/MM").unwrap();
    }
    writeln!(w, "TOOL PATH/BENCH,TOOL,EM10").unwrap();
    writeln!(w, "FEDRAT/MMPM,1000.0000").unwrap();
    let mut s = 12345u64;
    for _ in 0..rows {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let x = (s >> 40) as f64 / 1000.0 - 8000.0;
        let y = ((s >> 20) & 0xFFFFF) as f64 / 1000.0 - 500.0;
        let z = (s & 0xFFFF) as f64 / 1000.0 - 30.0;
        let a = ((s >> 8) & 0xFF) as f64 / 255.0;
        let (i, j, k) = (0.3 * a, -0.2 * a, 1.0);
        let n = (i * i + j * j + k * k).sqrt();
        writeln!(
            w,
            "GOTO/{x:.4},{y:.4},{z:.4},{:.7},{:.7},{:.7}",
            i / n,
            j / n,
            k / n
        )
        .unwrap();
    }
    writeln!(w, "END-OF-PATH").unwrap();
    w.flush().unwrap();
    std::fs::metadata(path).unwrap().len()
}

fn run(label: &str, path: &std::path::Path, size: u64, stated: bool) {
    let mut best = f64::INFINITY;
    let mut allocs_steady = 0;
    let mut rows = 0;
    for _ in 0..3 {
        let f = BufReader::with_capacity(64 * 1024, File::open(path).unwrap());
        let t = Instant::now();
        let mut r = if stated {
            Reader::with_units(f, Units::Mm, Options::default()).unwrap()
        } else {
            Reader::new(f, Options::default()).unwrap()
        };
        let mut n = 0u64;
        let mut sum = 0.0;
        let mut before = 0;
        for row in r.by_ref() {
            let row = row.unwrap();
            sum += row.tip[0] + row.axis[2];
            n += 1;
            if n == 1000 {
                before = allocations();
            }
        }
        let dt = t.elapsed().as_secs_f64();
        allocs_steady = allocations() - before;
        assert!(sum.is_finite());
        rows = n;
        best = best.min(dt);
    }
    println!(
        "{label:44} {rows} rows, {:.1} MB in {:.3} s: {:.0} MB/s, {:.2} M rows/s, {} allocations after row 1000",
        size as f64 / 1e6,
        best,
        size as f64 / 1e6 / best,
        rows as f64 / 1e6 / best,
        allocs_steady
    );
}

/// Reads a 1 MB-per-line file and a record continued over `lines` lines; returns the times.
fn long_records(scale: usize) -> (f64, f64) {
    let opts = Options::default();
    let big = format!("12.5{}", "0".repeat(scale));
    let text = format!(
        "UNITS/MM\nGOTO/{big},-7.25,{big}\nPPRINT/{}\n",
        "x".repeat(scale)
    );
    let t = Instant::now();
    let (rows, _) = verne_cl::read_all("long.cl", text.as_bytes(), &opts).unwrap();
    let long_line = t.elapsed().as_secs_f64();
    assert_eq!(rows[0].tip, [12.5, -7.25, 12.5]);
    let mut text = String::from("UNITS/MM\nGOTO/1.$\n");
    for _ in 0..scale / 10 {
        text.push_str("  $\n0$\n");
    }
    text.push_str(",2,3\n");
    let t = Instant::now();
    let (rows, _) = verne_cl::read_all("cont.cl", text.as_bytes(), &opts).unwrap();
    let continued = t.elapsed().as_secs_f64();
    assert_eq!(rows[0].tip, [1.0, 2.0, 3.0]);
    (long_line, continued)
}

fn main() {
    count_this_thread();
    let rows: usize = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().unwrap());
    let dir = std::env::temp_dir();
    let with = dir.join("verne_cl_bench_units.cl");
    let without = dir.join("verne_cl_bench_nx.cls");
    let s1 = write_file(&with, rows, true);
    let s2 = write_file(&without, rows, false);
    run(
        "UNITS/MM at the top (look-ahead stops there)",
        &with,
        s1,
        false,
    );
    run(
        "no UNITS (NX): look-ahead over the file",
        &without,
        s2,
        false,
    );
    run("no UNITS, units stated (one pass)", &without, s2, true);
    let (l1, c1) = long_records(1 << 20);
    let (l4, c4) = long_records(4 << 20);
    println!(
        "1 MB line {l1:.3} s, 4 MB line {l4:.3} s (x{:.1}); record over {} lines {c1:.3} s, over {} lines {c4:.3} s (x{:.1})",
        l4 / l1,
        2 * ((1 << 20) / 10),
        2 * ((4 << 20) / 10),
        c4 / c1
    );
    let _ = std::fs::remove_file(&with);
    let _ = std::fs::remove_file(&without);
}
