//! The I/O floor of `verne ik` and `verne fk` (docs/benchmarks.md): reads the same CSV with the
//! csv crate into one reused `ByteRecord`, parses the same three numeric columns, and writes the
//! same output shape (every input column, then four numbers formatted with ryu and a `status`
//! cell, a computed column replacing an input column of the same name in place) with no
//! kinematics: the four numbers are a few arithmetic operations on the inputs. The time of
//! `verne` divided by the time of this program is the figure `scripts/bench.sh` reports.
//!
//! Usage: `io_floor [ik|fk] [INPUT] [-o FILE]`; absent INPUT or `-` reads stdin, absent `-o`
//! writes stdout. Exit code 0, or 2 with one message on stderr.

use std::fs::File;
use std::io::{self, BufReader, BufWriter, Read, Write};
use std::process::ExitCode;

use csv::ByteRecord;

/// Buffer sizes: the same as `verne_cli::table`.
const BUFFER_BYTES: usize = 1 << 16;

const IK_INPUTS: [&str; 3] = ["xp", "yp", "zp"];
const IK_OUTPUTS: [&str; 5] = ["alpha", "rho1", "rho2", "rho3", "status"];
const FK_INPUTS: [&str; 3] = ["rho1", "rho2", "rho3"];
const FK_OUTPUTS: [&str; 5] = ["xp", "yp", "zp", "alpha", "status"];

/// Where output column k comes from.
enum Slot {
    Input(usize),
    Computed(usize),
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("io_floor: error: {e}");
            ExitCode::from(2)
        }
    }
}

/// A csv error as the I/O error it wraps (so that a broken pipe stays one), or as text.
fn csv_io(e: csv::Error) -> io::Error {
    match e.into_kind() {
        csv::ErrorKind::Io(e) => e,
        other => io::Error::other(format!("{other:?}")),
    }
}

fn run() -> io::Result<()> {
    let mut fk = false;
    let mut input: Option<String> = None;
    let mut output: Option<String> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "ik" => fk = false,
            "fk" => fk = true,
            "-o" | "--output" => output = args.next(),
            _ if input.is_none() => input = Some(a),
            _ => return Err(io::Error::other(format!("unexpected argument `{a}`"))),
        }
    }
    let (inputs, outputs) = if fk {
        (FK_INPUTS, FK_OUTPUTS)
    } else {
        (IK_INPUTS, IK_OUTPUTS)
    };
    let source: Box<dyn Read> = match input.as_deref() {
        None | Some("-") => Box::new(io::stdin().lock()),
        Some(p) => Box::new(BufReader::with_capacity(BUFFER_BYTES, File::open(p)?)),
    };
    let sink: Box<dyn Write> = match output.as_deref() {
        None | Some("-") => Box::new(BufWriter::with_capacity(BUFFER_BYTES, io::stdout())),
        Some(p) => Box::new(BufWriter::with_capacity(BUFFER_BYTES, File::create(p)?)),
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .buffer_capacity(BUFFER_BYTES)
        .from_reader(source);
    let mut writer = csv::WriterBuilder::new().from_writer(sink);

    let headers = reader.byte_headers().map_err(csv_io)?.clone();
    let column = |name: &str| headers.iter().position(|h| h == name.as_bytes());
    let mut idx = [0usize; 3];
    for (k, name) in inputs.iter().enumerate() {
        idx[k] = column(name)
            .ok_or_else(|| io::Error::other(format!("missing column `{name}` in the header")))?;
    }
    let mut plan = Vec::new();
    let mut out = ByteRecord::new();
    for (i, h) in headers.iter().enumerate() {
        match outputs.iter().position(|o| o.as_bytes() == h) {
            Some(k) => plan.push(Slot::Computed(k)),
            None => plan.push(Slot::Input(i)),
        }
        out.push_field(h);
    }
    for (k, o) in outputs.iter().enumerate() {
        if column(o).is_none() {
            plan.push(Slot::Computed(k));
            out.push_field(o.as_bytes());
        }
    }
    writer.write_byte_record(&out).map_err(csv_io)?;

    let mut record = ByteRecord::new();
    let mut fmt = ryu::Buffer::new();
    let mut texts = [[0u8; 32]; 4];
    let mut lens = [0usize; 4];
    while reader.read_byte_record(&mut record).map_err(csv_io)? {
        let mut v = [0.0f64; 3];
        for k in 0..3 {
            let field = record.get(idx[k]).unwrap_or(b"");
            v[k] = std::str::from_utf8(field)
                .ok()
                .and_then(|s| s.parse::<f64>().ok())
                .ok_or_else(|| {
                    io::Error::other(format!(
                        "line {}: `{}` is not a number",
                        record.position().map_or(0, |p| p.line()),
                        String::from_utf8_lossy(field)
                    ))
                })?;
        }
        // Four full-precision numbers of the size of alpha, rho1, rho2, rho3 (or xp, yp, zp, alpha).
        let computed = [
            (v[0] - v[1]).to_radians(),
            v[2] - 0.5 * v[0],
            v[2] + std::f64::consts::FRAC_1_SQRT_2 * v[1],
            (v[0] * v[0] + v[1] * v[1]).sqrt(),
        ];
        for k in 0..4 {
            let x = if computed[k] == 0.0 { 0.0 } else { computed[k] };
            let s = fmt.format(x);
            let s = s.strip_suffix(".0").unwrap_or(s).as_bytes();
            texts[k][..s.len()].copy_from_slice(s);
            lens[k] = s.len();
        }
        let cells: [&[u8]; 5] = [
            &texts[0][..lens[0]],
            &texts[1][..lens[1]],
            &texts[2][..lens[2]],
            &texts[3][..lens[3]],
            b"ok",
        ];
        out.clear();
        for slot in &plan {
            match *slot {
                Slot::Input(i) => out.push_field(record.get(i).unwrap_or(b"")),
                Slot::Computed(k) => out.push_field(cells[k]),
            }
        }
        writer.write_byte_record(&out).map_err(csv_io)?;
    }
    writer.flush()
}
