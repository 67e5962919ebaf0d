//! The streaming row engine shared by `ik`, `fk` and the machine commands: reads a CSV in
//! batches, parses the required numeric columns, solves the rows of a batch in parallel (rayon),
//! then emits them in input order with the input columns passed through.
//!
//! Output columns: every input column in order, a computed column replacing an input column of
//! the same name in place, the other computed columns appended. Memory is bounded by the batch.

use csv::ByteRecord;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::VerneError;
use crate::files::Sink;
use crate::table::{CellError, CsvSource, TableRow, encode_field, format_number, parse_number};
use verne::error::shown;
use verne::parallel_module::branches::Verdict;

/// Input rows read together; bounds memory and amortises thread hand-off.
pub const BATCH_ROWS: usize = 4096;
/// Output rows a batch aims at: a job that writes several rows per input row (`--all`) reads
/// fewer input rows per batch, so memory stays bounded whatever the input.
const BATCH_OUTPUT_ROWS: usize = 2 * BATCH_ROWS;
/// Bytes of pending rows a batch may hold (three batches are in flight): a row keeps what its
/// job's `emit` needs, a few dozen bytes for the module's working branch or mode
/// (`module_rows::Working`), about 1 KB for every branch of the module (`--all`) and 6 KB for
/// the machine (every branch of both orientation solutions), so those batches are shorter.
const BATCH_BYTES: usize = 4 << 20;

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
pub trait RowJob: Sync + Send {
    /// Per-row result of the parallel solve.
    type Solved: Send + Sync + Default;

    /// Required numeric input columns, and whether each is an angle.
    fn inputs(&self) -> &[(&'static str, bool)];

    /// Computed output columns, in order; the last one is `status`.
    fn outputs(&self) -> &[&'static str];

    /// Solves one row (inputs in radians and mm). Runs in parallel: no shared state.
    fn solve(&self, inputs: &[f64], solved: &mut Self::Solved);

    /// Solves a run of consecutive rows (at most [`RUN_ROWS`]) in input order, on one thread;
    /// `None` marks an invalid row, left unsolved. Runs start at fixed row counts, so a job that
    /// carries something from row to row within a run (a tracker) gives the same output whatever
    /// the number of threads. The default solves each row on its own.
    fn solve_run<'a>(
        &self,
        rows: &mut dyn Iterator<Item = (Option<&'a [f64]>, &'a mut Self::Solved)>,
    ) where
        Self::Solved: 'a,
    {
        for (inputs, solved) in rows {
            if let Some(inputs) = inputs {
                self.solve(inputs, solved);
            }
        }
    }

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

/// Collects the output rows of one input row: its computed cells, to be written after the
/// input columns (or merged with them) when the batch is encoded.
pub struct RowWriter<'a> {
    input: u32,
    out_input: &'a mut Vec<u32>,
    out_cells: &'a mut Vec<Cell>,
    units: Units,
    n_computed: usize,
    rows: u64,
}

impl RowWriter<'_> {
    /// Writes one output row with the given computed cells (one per output column).
    pub fn row(&mut self, cells: &[Cell]) -> Result<(), VerneError> {
        debug_assert_eq!(cells.len(), self.n_computed);
        self.out_input.push(self.input);
        self.out_cells.extend_from_slice(cells);
        self.rows += 1;
        Ok(())
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

    pub(crate) fn count(&mut self, status: &str, line: u64) {
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
    input: TableRow,
    values: [f64; MAX_INPUTS],
    /// The first input column that is empty or not finite (the row is `invalid_input`).
    invalid: Option<usize>,
    /// The first input column that is not a number at all (a fatal error).
    not_a_number: Option<usize>,
    solved: S,
}

/// Rows in flight: read, being solved, or being written. Reused from batch to batch.
struct Batch<S> {
    rows: Vec<PendingRow<S>>,
    filled: usize,
    /// For each output row, the input row it belongs to; its computed cells follow in order.
    out_input: Vec<u32>,
    out_cells: Vec<Cell>,
    /// The encoded output, one buffer per run of output rows.
    encoded: Vec<Vec<u8>>,
    encoded_runs: usize,
}

impl<S: Default> Batch<S> {
    /// Most rows a batch of this job reads: [`BATCH_ROWS`], fewer when its rows are large
    /// ([`BATCH_BYTES`]).
    fn max_rows() -> usize {
        (BATCH_BYTES / size_of::<PendingRow<S>>().max(1)).clamp(RUN_ROWS, BATCH_ROWS)
    }

    fn new() -> Batch<S> {
        Batch {
            rows: Vec::with_capacity(Self::max_rows()),
            filled: 0,
            out_input: Vec::new(),
            out_cells: Vec::new(),
            encoded: Vec::new(),
            encoded_runs: 0,
        }
    }

    /// Reads up to `rows` records, reusing the rows in place (a row can hold a solver's
    /// fixed-capacity result, a kilobyte or more: moving rows would cost more than solving).
    fn fill(&mut self, source: &mut CsvSource, rows: usize) -> Result<(), VerneError> {
        self.filled = 0;
        self.encoded_runs = 0;
        while self.filled < rows {
            if self.filled == self.rows.len() {
                self.rows.push(PendingRow {
                    input: TableRow::default(),
                    values: [0.0; MAX_INPUTS],
                    invalid: None,
                    not_a_number: None,
                    solved: S::default(),
                });
            }
            if !source.read_row(&mut self.rows[self.filled].input)? {
                break;
            }
            self.filled += 1;
        }
        Ok(())
    }

    fn write(&self, sink: &mut Sink) -> Result<(), VerneError> {
        for bytes in &self.encoded[..self.encoded_runs] {
            sink.write_encoded(bytes)?;
        }
        Ok(())
    }
}

/// Rows handed to one thread at a time, for solving and for encoding.
pub const RUN_ROWS: usize = 256;

/// What stays fixed over a run.
struct Plan<'a> {
    inputs: &'a [(&'static str, bool)],
    idx: &'a [usize],
    slots: &'a [Slot],
    n_computed: usize,
    units: Units,
    delimiter: u8,
    file: &'a str,
}

/// Progress callback: rows done so far.
pub type Progress<'a> = &'a (dyn Fn(u64) + Sync);

/// Runs a job over a CSV source into a sink. Fatal errors stop the run (the sink is then
/// discarded by the caller); row-level problems are written as statuses and counted.
///
/// Three batches are in flight: while one is read (CSV parsing, in order), the previous one is
/// solved and encoded (in parallel, emitted in order) and the one before is written.
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
    let mut slots = Vec::new();
    let mut header = ByteRecord::new();
    for (i, h) in source.headers().iter().enumerate() {
        match outputs
            .iter()
            .position(|o| o.as_bytes().eq_ignore_ascii_case(h))
        {
            Some(k) => slots.push(Slot::Computed(k)),
            None => slots.push(Slot::Input(i)),
        }
        header.push_field(h);
    }
    for (k, o) in outputs.iter().enumerate() {
        if source.column(o).is_none() {
            slots.push(Slot::Computed(k));
            header.push_field(o.as_bytes());
        }
    }
    sink.write(&header)?;
    let file = source.name().to_string();
    // Computed cells (numbers, `ok`, reason codes joined by `;`) are written unquoted.
    debug_assert!(matches!(sink.delimiter(), b',' | b' ' | b'\t'));
    let plan = Plan {
        inputs: &inputs,
        idx: &idx,
        slots: &slots,
        n_computed: outputs.len(),
        units,
        delimiter: sink.delimiter(),
        file: &file,
    };
    stream_batches(job, source, sink, &plan, progress)
}

/// The loop of [`run`] on the core's row engine ([`verne::stream::run_batches`]): while one
/// batch is read, the previous one is solved and encoded and the one before is written.
fn stream_batches<J: RowJob>(
    job: &mut J,
    source: &mut CsvSource,
    sink: &mut Sink,
    plan: &Plan<'_>,
    progress: Progress<'_>,
) -> Result<RunSummary, VerneError> {
    let mut summary = RunSummary::default();
    // Rows per batch, from the output rows per input row of a batch solved: the first batch is
    // small, and batch k + 2 is sized by batch k (solved while batch k + 1 is read). The size
    // goes through one slot per parity of k, so that a read never sees a value stored while it
    // runs: the batches, and so the runs, are the same from run to run.
    let sizes = [AtomicUsize::new(RUN_ROWS), AtomicUsize::new(RUN_ROWS)];
    let (mut reads, mut solved) = (0usize, 0usize);
    let max_rows = Batch::<J::Solved>::max_rows();
    verne::stream::run_batches(
        [Batch::new(), Batch::new(), Batch::new()],
        |batch: &mut Batch<J::Solved>| {
            batch.fill(source, sizes[reads % 2].load(Ordering::Relaxed))?;
            reads += 1;
            Ok(batch.filled > 0)
        },
        |batch: &mut Batch<J::Solved>| {
            process(job, batch, plan, &mut summary)?;
            progress(summary.input_rows);
            let per_input = batch.out_input.len().div_ceil(batch.filled.max(1)).max(1);
            let rows = (BATCH_OUTPUT_ROWS / per_input).clamp(RUN_ROWS, max_rows);
            sizes[solved % 2].store(rows, Ordering::Relaxed);
            solved += 1;
            Ok(())
        },
        |batch: &mut Batch<J::Solved>| batch.write(sink),
    )?;
    Ok(summary)
}

/// Parses, solves, emits and encodes one batch.
fn process<J: RowJob>(
    job: &mut J,
    batch: &mut Batch<J::Solved>,
    plan: &Plan<'_>,
    summary: &mut RunSummary,
) -> Result<(), VerneError> {
    let rows = &mut batch.rows[..batch.filled];
    // Parse and solve, in runs of consecutive rows.
    let job_ref: &J = job;
    rows.par_chunks_mut(RUN_ROWS).for_each(|run| {
        for row in run.iter_mut() {
            parse_row(row, plan);
        }
        let n_in = plan.inputs.len();
        job_ref.solve_run(&mut run.iter_mut().map(|row| {
            let PendingRow {
                values,
                invalid,
                not_a_number,
                solved,
                ..
            } = row;
            let ok = invalid.is_none() && not_a_number.is_none();
            (ok.then_some(&values[..n_in]), solved)
        }));
    });
    // A cell that is not a number stops the run at the first such row.
    if let Some(row) = rows.iter().find(|r| r.not_a_number.is_some()) {
        let k = row.not_a_number.unwrap_or(0);
        let field = row.input.record.get(plan.idx[k]).unwrap_or(b"");
        let line = Some(row.input.line);
        let unit = match (plan.inputs[k].1, plan.units.radians) {
            (false, _) => " (mm)",
            (true, true) => " (radians)",
            (true, false) => " (degrees)",
        };
        return Err(VerneError::input(
            plan.file,
            line,
            Some(plan.inputs[k].0),
            format!("expected a number{unit}, found `{}`", shown(field)),
        ));
    }
    // Emit in order (a job may carry state from row to row).
    batch.out_input.clear();
    batch.out_cells.clear();
    let status_col = plan.n_computed - 1;
    let mut cells = vec![Cell::Empty; plan.n_computed];
    let mut scratch = Vec::new();
    for (i, row) in rows.iter().enumerate() {
        summary.input_rows += 1;
        let line = row.input.line;
        let mut writer = RowWriter {
            input: i as u32,
            out_input: &mut batch.out_input,
            out_cells: &mut batch.out_cells,
            units: plan.units,
            n_computed: plan.n_computed,
            rows: 0,
        };
        let outcome = if row.invalid.is_some() {
            cells.iter_mut().for_each(|c| *c = Cell::Empty);
            cells[status_col] = Cell::Str("invalid_input");
            writer.row(&cells)?;
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
            write_cell(&mut scratch, outcome.status, plan.units);
            let text = String::from_utf8_lossy(&scratch).into_owned();
            summary.count(&text, line);
        }
    }
    // Encode, in runs of output rows.
    let n_out = batch.out_input.len();
    batch.encoded_runs = n_out.div_ceil(RUN_ROWS);
    if batch.encoded.len() < batch.encoded_runs {
        batch.encoded.resize_with(batch.encoded_runs, Vec::new);
    }
    let (out_input, out_cells, rows) = (&batch.out_input, &batch.out_cells, &batch.rows);
    batch.encoded[..batch.encoded_runs]
        .par_iter_mut()
        .enumerate()
        .for_each(|(j, bytes)| {
            bytes.clear();
            for o in j * RUN_ROWS..n_out.min((j + 1) * RUN_ROWS) {
                let input = &rows[out_input[o] as usize].input;
                let cells = &out_cells[o * plan.n_computed..(o + 1) * plan.n_computed];
                for (f, slot) in plan.slots.iter().enumerate() {
                    match *slot {
                        Slot::Input(i) if !input.numbers.is_empty() => {
                            // A number given on the command line, as it was given.
                            if f > 0 {
                                bytes.push(plan.delimiter);
                            }
                            if let Some(v) = input.numbers.get(i) {
                                let _ = std::io::Write::write_fmt(bytes, format_args!("{v}"));
                            }
                        }
                        Slot::Input(i) => {
                            let field = input.record.get(i).unwrap_or(b"");
                            encode_field(bytes, plan.delimiter, f == 0, field);
                        }
                        Slot::Computed(k) => {
                            // Numbers and status codes never need quotes: written in place.
                            if f > 0 {
                                bytes.push(plan.delimiter);
                            }
                            write_cell(bytes, cells[k], plan.units);
                        }
                    }
                }
                bytes.push(b'\n');
            }
        });
    Ok(())
}

/// Parses a row's input columns (converting degrees), marking empty or non-finite cells
/// (the row is invalid) and cells that are not numbers (a fatal error).
fn parse_row<S>(row: &mut PendingRow<S>, plan: &Plan<'_>) {
    row.invalid = None;
    row.not_a_number = None;
    for (k, &i) in plan.idx.iter().enumerate() {
        let parsed = if row.input.numbers.is_empty() {
            parse_number(row.input.record.get(i).unwrap_or(b""))
        } else {
            // A number given on the command line: parsed once, where it was given.
            match row.input.numbers.get(i) {
                Some(v) if v.is_finite() => Ok(*v),
                _ => Err(CellError::NotFinite),
            }
        };
        match parsed {
            Ok(v) => {
                row.values[k] = if plan.inputs[k].1 && !plan.units.radians {
                    v.to_radians()
                } else {
                    v
                }
            }
            Err(CellError::NotFinite) => {
                row.invalid.get_or_insert(k);
            }
            Err(CellError::NotANumber) => {
                row.not_a_number = Some(k);
                return;
            }
        }
    }
}
