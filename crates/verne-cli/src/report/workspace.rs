//! The grid points CSV of `verne workspace` (`-o`): one row per classified point.

use csv::ByteRecord;
use verne::workspace::{Constraint, PointResult};

use crate::engine::pipeline::{Cell, Units, write_cell};

/// Header of the points CSV.
pub const POINTS_HEADER: [&str; 16] = [
    "tool_length",
    "x",
    "y",
    "z",
    "xp",
    "yp",
    "zp",
    "alpha",
    "rho1",
    "rho2",
    "rho3",
    "lambda1",
    "lambda2",
    "lambda3",
    "status",
    "fails",
];

/// Fills `rec` with the row of [`POINTS_HEADER`] for point `r`; `tool_length` is empty for the
/// platform.
pub fn write_point(r: &PointResult, tool_length: Option<f64>, units: Units, rec: &mut ByteRecord) {
    rec.clear();
    let mut buf = Vec::with_capacity(24);
    let mut push = |c: Cell, rec: &mut ByteRecord| {
        buf.clear();
        write_cell(&mut buf, c, units);
        rec.push_field(&buf);
    };
    push(tool_length.map_or(Cell::Empty, Cell::Num), rec);
    for d in 0..3 {
        push(Cell::Num(r.q[d]), rec);
    }
    match &r.branch {
        Some(b) => {
            for d in 0..3 {
                push(Cell::Num(b.pose.p[d]), rec);
            }
            push(Cell::Angle(b.pose.alpha), rec);
            for d in 0..3 {
                push(Cell::Num(b.rho[d]), rec);
            }
            for l in b.lambda {
                push(
                    if l.is_finite() {
                        Cell::Num(l)
                    } else {
                        Cell::Str("inf")
                    },
                    rec,
                );
            }
        }
        None => {
            for _ in 0..10 {
                push(Cell::Empty, rec);
            }
        }
    }
    rec.push_field(r.outcome.code().as_bytes());
    let fails: Vec<&str> = r.fails.iter().map(Constraint::code).collect();
    rec.push_field(fails.join(";").as_bytes());
}
