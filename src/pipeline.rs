//! The streaming row engine shared by `ik`, `fk` and the machine commands: reads a CSV in
//! batches, parses the required numeric columns, solves the rows of a batch in parallel (rayon),
//! then emits them in input order with the input columns passed through.
//!
//! Output columns: every input column in order, a computed column replacing an input column of
//! the same name in place, the other computed columns appended. Memory is bounded by the batch.

use csv::ByteRecord;
use rayon::prelude::*;

use crate::branches::Verdict;
use crate::error::VerneError;
use crate::table::{CellError, CsvSource, Sink, format_number, parse_number, shown};

/// Rows solved together; bounds memory and amortises thread hand-off.
pub const BATCH_ROWS: usize = 4096;

/// Most numeric input columns a job reads.
pub const MAX_INPUTS: usize = 8;

/// One computed output cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// A length or other plain number.
    Num(f64),
    /// An angle in radians, written in degrees unless `--radians`.
    Angle(f64),
    Int(i64),
    Bool(bool),
    Str(&'static str),
    /// `ok` or the verdict's reason codes.
    Verdict(Verdict),
    Empty,
}

/// How numbers and angles are written and read.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Units {
    /// Angles in radians (default: degrees).
    pub radians: bool,
    /// Fixed decimals for numbers (default: shortest round-trip form).
    pub decimals: Option<usize>,
    /// `--format halstreamer`: only the joints [`HALSTREAMER_COLUMNS`], no header, and a row
    /// that is not ok stops the run (a joint list for LinuxCNC's halstreamer cannot skip one).
    pub halstreamer: bool,
}

/// The columns of a halstreamer joint list, in order.
pub const HALSTREAMER_COLUMNS: [&str; 5] = ["rho1", "rho2", "rho3", "theta1", "theta2"];

/// The outcome of one input row, for the exit code and the summary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowOutcome {
    pub ok: bool,
    pub status: Cell,
}

/// A kind of row computation.
pub trait RowJob: Sync {
    /// Per-row result of the parallel solve.
    type Solved: Send + Default;

    /// Required numeric input columns, and whether each is an angle.
    fn inputs(&self) -> &[(&'static str, bool)];

    /// Computed output columns, in order; the last one is `status`.
    fn outputs(&self) -> &[&'static str];

    /// Solves one row (inputs in radians and mm). Runs in parallel: no shared state.
    fn solve(&self, inputs: &[f64], solved: &mut Self::Solved);

    /// Emits the output row(s) of one solved input row, in input order. May keep state
    /// between rows (branch continuity along a path).
    fn emit(
        &mut self,
        solved: &Self::Solved,
        out: &mut RowWriter<'_>,
    ) -> Result<RowOutcome, VerneError>;
}

/// Where the computed column `k` goes in the output record.
enum Slot {
    Input(usize),
    Computed(usize),
}

/// Writes output rows: the current input record's fields followed by (or merged with) computed
/// cells.
pub struct RowWriter<'a> {
    plan: &'a [Slot],
    input: &'a ByteRecord,
    record: &'a mut ByteRecord,
    scratch: &'a mut Vec<u8>,
    sink: &'a mut Sink,
    units: Units,
    n_computed: usize,
    rows: u64,
}

impl RowWriter<'_> {
    /// Writes one output row with the given computed cells (one per output column).
    pub fn row(&mut self, cells: &[Cell]) -> Result<(), VerneError> {
        debug_assert_eq!(cells.len(), self.n_computed);
        self.record.clear();
        for slot in self.plan {
            match *slot {
                Slot::Input(i) => self.record.push_field(self.input.get(i).unwrap_or(b"")),
                Slot::Computed(k) => {
                    self.scratch.clear();
                    write_cell(self.scratch, cells[k], self.units);
                    self.record.push_field(self.scratch);
                }
            }
        }
        self.rows += 1;
        self.sink.write(self.record)
    }

    pub fn units(&self) -> Units {
        self.units
    }
}

/// Appends a cell's text.
pub fn write_cell(out: &mut Vec<u8>, cell: Cell, units: Units) {
    use std::io::Write;
    match cell {
        Cell::Num(v) => format_number(out, v, units.decimals),
        Cell::Angle(v) => format_number(
            out,
            if units.radians { v } else { v.to_degrees() },
            units.decimals,
        ),
        Cell::Int(i) => {
            let _ = write!(out, "{i}");
        }
        Cell::Bool(b) => out.extend_from_slice(if b { b"true" } else { b"false" }),
        Cell::Str(s) => out.extend_from_slice(s.as_bytes()),
        Cell::Verdict(v) => {
            let _ = write!(out, "{v}");
        }
        Cell::Empty => {}
    }
}

/// Counts of a finished run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunSummary {
    pub input_rows: u64,
    pub output_rows: u64,
    pub ok_rows: u64,
    /// Input rows by status text (those not ok), in first-seen order.
    pub not_ok: Vec<(String, u64)>,
    /// The first few rows that were not ok: (line, status).
    pub first_failures: Vec<(u64, String)>,
}

impl RunSummary {
    pub fn all_ok(&self) -> bool {
        self.ok_rows == self.input_rows
    }

    fn count(&mut self, status: &str, line: u64) {
        match self.not_ok.iter_mut().find(|(s, _)| s == status) {
            Some((_, n)) => *n += 1,
            None => self.not_ok.push((status.to_string(), 1)),
        }
        if self.first_failures.len() < 5 {
            self.first_failures.push((line, status.to_string()));
        }
    }
}

struct PendingRow<S> {
    record: ByteRecord,
    values: [f64; MAX_INPUTS],
    invalid: Option<usize>,
    solved: S,
}

/// Progress callback: rows done so far.
pub type Progress<'a> = &'a (dyn Fn(u64) + Sync);

/// Runs a job over a CSV source into a sink. Fatal errors stop the run (the sink is then
/// discarded by the caller); row-level problems are written as statuses and counted.
pub fn run<J: RowJob>(
    job: &mut J,
    source: &mut CsvSource,
    sink: &mut Sink,
    units: Units,
    progress: Progress<'_>,
) -> Result<RunSummary, VerneError> {
    let inputs: Vec<(&'static str, bool)> = job.inputs().to_vec();
    let outputs: Vec<&'static str> = job.outputs().to_vec();
    assert!(inputs.len() <= MAX_INPUTS);
    let names: Vec<&str> = inputs.iter().map(|(n, _)| *n).collect();
    let idx = source.require(&names)?;
    // Output plan: input columns (computed ones replace same-named inputs), then the rest.
    let mut plan = Vec::new();
    let mut header = ByteRecord::new();
    if units.halstreamer {
        for name in HALSTREAMER_COLUMNS {
            let Some(k) = outputs.iter().position(|o| *o == name) else {
                return Err(VerneError::Usage(format!(
                    "--format halstreamer writes the machine joints {}; this input gives no `{name}` (use tool poses x,y,z with i,j,k or phi1,phi2)",
                    HALSTREAMER_COLUMNS.join(",")
                )));
            };
            plan.push(Slot::Computed(k));
        }
    } else {
        for (i, h) in source.headers().iter().enumerate() {
            match outputs.iter().position(|o| o.as_bytes() == h) {
                Some(k) => plan.push(Slot::Computed(k)),
                None => plan.push(Slot::Input(i)),
            }
            header.push_field(h);
        }
        for (k, o) in outputs.iter().enumerate() {
            if source.column(o).is_none() {
                plan.push(Slot::Computed(k));
                header.push_field(o.as_bytes());
            }
        }
        sink.write(&header)?;
    }
    let status_col = outputs.len() - 1;
    let file = source.name().to_string();
    let mut summary = RunSummary::default();
    let mut batch: Vec<PendingRow<J::Solved>> = Vec::with_capacity(BATCH_ROWS);
    let mut record = ByteRecord::new();
    let mut scratch = Vec::with_capacity(64);
    let mut out_cells = vec![Cell::Empty; outputs.len()];
    loop {
        // Fill a batch, reusing its rows in place (a row holds a solver's fixed-capacity result,
        // a kilobyte or more: moving rows would cost more than solving them).
        let mut filled = 0;
        while filled < BATCH_ROWS {
            if filled == batch.len() {
                batch.push(PendingRow {
                    record: ByteRecord::new(),
                    values: [0.0; MAX_INPUTS],
                    invalid: None,
                    solved: J::Solved::default(),
                });
            }
            let row = &mut batch[filled];
            if !source.read(&mut row.record)? {
                break;
            }
            row.invalid = None;
            for (k, &i) in idx.iter().enumerate() {
                let field = row.record.get(i).unwrap_or(b"");
                match parse_number(field) {
                    Ok(v) => {
                        row.values[k] = if inputs[k].1 && !units.radians {
                            v.to_radians()
                        } else {
                            v
                        }
                    }
                    Err(CellError::NotFinite) => {
                        if row.invalid.is_none() {
                            row.invalid = Some(k);
                        }
                    }
                    Err(CellError::NotANumber) => {
                        let line = row.record.position().map(|p| p.line());
                        return Err(VerneError::input(
                            &file,
                            line,
                            Some(inputs[k].0),
                            format!(
                                "expected a number{}, found `{}`",
                                if inputs[k].1 {
                                    if units.radians {
                                        " (radians)"
                                    } else {
                                        " (degrees)"
                                    }
                                } else {
                                    " (mm)"
                                },
                                shown(field)
                            ),
                        ));
                    }
                }
            }
            filled += 1;
        }
        if filled == 0 {
            break;
        }
        // Solve in parallel.
        let n_in = inputs.len();
        let job_ref: &J = job;
        batch[..filled]
            .par_iter_mut()
            .with_min_len(64)
            .for_each(|row| {
                if row.invalid.is_none() {
                    job_ref.solve(&row.values[..n_in], &mut row.solved);
                }
            });
        // Emit in order.
        for row in &batch[..filled] {
            summary.input_rows += 1;
            let line = row.record.position().map(|p| p.line()).unwrap_or(0);
            let mut writer = RowWriter {
                plan: &plan,
                input: &row.record,
                record: &mut record,
                scratch: &mut scratch,
                sink,
                units,
                n_computed: outputs.len(),
                rows: 0,
            };
            let outcome = if row.invalid.is_some() {
                out_cells.iter_mut().for_each(|c| *c = Cell::Empty);
                out_cells[status_col] = Cell::Str("invalid_input");
                writer.row(&out_cells)?;
                RowOutcome {
                    ok: false,
                    status: Cell::Str("invalid_input"),
                }
            } else {
                job.emit(&row.solved, &mut writer)?
            };
            summary.output_rows += writer.rows;
            if outcome.ok {
                summary.ok_rows += 1;
            } else {
                scratch.clear();
                write_cell(&mut scratch, outcome.status, units);
                let text = String::from_utf8_lossy(&scratch).into_owned();
                if units.halstreamer {
                    return Err(VerneError::input(
                        &file,
                        Some(line),
                        None,
                        format!(
                            "row status `{text}`: a halstreamer joint list cannot leave out a row; fix the path or use CSV output to see every row's status"
                        ),
                    ));
                }
                summary.count(&text, line);
            }
        }
        progress(summary.input_rows);
    }
    Ok(summary)
}
