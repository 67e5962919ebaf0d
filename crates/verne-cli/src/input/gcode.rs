//! G-code programs in the CLI (the reader is the `verne-gcode` crate; the rules are in
//! docs/gcode.md). The machine file's `[gcode]` table gives the words their meaning:
//!
//! - a *tool-centre program* (`verne ik PROGRAM.ngc`, `verne verify --path PROGRAM.ngc`): X Y Z
//!   the tool tip in the workpiece frame, the orientation as two angle words (phi1, phi2) or as
//!   I J K (read as a toolpath: [`crate::toolpath::gcode`]);
//! - a *joint program* (`verne verify --joints POST.ngc`): one letter per joint
//!   ([`JointProgram`]).
//!
//! A word the program's kind does not use is an error at its line, never ignored.

use std::io::{BufRead, Write};

use verne::parallel_module::equations::Sliders;
use verne::spec::gcode::{GcodeOrientation, GcodeWords, JOINT_KEYS};
use verne::verify::{Item, JointSource, Joints, PathTag, RowSource};
use verne_gcode::{AXES, Axis, GcodeError, Motion, Options, Reader, Summary};

use crate::error::VerneError;

/// A G-code reader over a boxed input, as the CLI reads files and stdin alike.
pub type GcodeReader = Reader<Box<dyn BufRead + Send>>;

/// A G-code error as the CLI's input error: file, line, column, what was expected.
pub fn gcode_error(file: &str, e: &GcodeError) -> VerneError {
    let line = (e.line > 0).then_some(e.line);
    let column = e.column.map(|c| c.to_string());
    VerneError::input(file, line, column.as_deref(), e.message.clone())
}

/// The letters of a mask, e.g. `U V`.
pub(crate) fn letters(mask: u16) -> String {
    let v: Vec<String> = AXES
        .iter()
        .filter(|a| mask & a.bit() != 0)
        .map(|a| a.letter().to_string())
        .collect();
    v.join(" ")
}

/// `is not a word of` or `are not words of`, for the letters of a mask.
pub(crate) fn not_words(mask: u16) -> &'static str {
    if mask.count_ones() == 1 {
        "is not a word of"
    } else {
        "are not words of"
    }
}

pub(crate) fn axis_of(letter: char) -> Axis {
    // The machine file's letters are validated (X Y Z A B C U V W).
    Axis::from_letter(letter as u8).unwrap_or(Axis::X)
}

/// Prints what the reader saw besides the rows to stderr, prefixed `verne CMD: NAME:`.
pub fn report_summary(cmd: &str, name: &str, s: &Summary) {
    if crate::verbosity() == 0 {
        return;
    }
    let mut err = std::io::stderr().lock();
    crate::input::write_warnings(&mut err, cmd, name, &s.warnings, s.warnings_dropped);
    let mut line = format!(
        "verne {cmd}: {name}: {} rows from {} blocks (G-code, {}, axes {})",
        s.rows,
        s.blocks,
        s.units.as_str(),
        s.axes_used_letters()
    );
    if !s.ignored.is_empty() {
        line.push_str("; codes that do not move the machine: ");
        line.push_str(&s.ignored_line());
    }
    let _ = writeln!(err, "{line}");
    if s.lines_after_end > 0 {
        let _ = writeln!(
            err,
            "verne {cmd}: {name}: {} lines after the program's end (line {}) not read",
            s.lines_after_end,
            s.end_line.unwrap_or(0)
        );
    }
}

/// A joint program (the output of a post for the machine) as the joint table of `verne
/// verify`: one row per block, the joints from the `[gcode]` letters, the time of each move
/// from the program's feeds, `G0` moves rapid. Rows are labelled by their `N` word when they
/// have one.
pub struct JointProgram {
    reader: GcodeReader,
    name: String,
    words: GcodeWords,
    allowed: u16,
    index: u64,
}

impl JointProgram {
    pub fn new(reader: GcodeReader, name: &str, words: &GcodeWords) -> JointProgram {
        let allowed = words
            .joints
            .iter()
            .fold(0, |m, w| m | axis_of(w.letter).bit());
        JointProgram {
            reader,
            name: name.to_string(),
            words: *words,
            allowed,
            index: 0,
        }
    }

    /// What the reader saw besides the rows.
    pub fn summary(&self) -> &Summary {
        self.reader.summary()
    }

    fn joint_words(&self) -> String {
        let v: Vec<String> = JOINT_KEYS
            .iter()
            .zip(&self.words.joints)
            .map(|(k, w)| format!("{} = {k}", w.letter))
            .collect();
        v.join(", ")
    }
}

impl RowSource for JointProgram {
    type Row = Joints;
    type Error = VerneError;

    fn name(&self) -> &str {
        &self.name
    }

    fn has_id(&self) -> bool {
        false
    }

    fn next_item(&mut self) -> Result<Option<Item<Joints>>, VerneError> {
        let row = match self.reader.next() {
            None => return Ok(None),
            Some(r) => r.map_err(|e| gcode_error(&self.name, &e))?,
        };
        let fail = |m: String| Err(VerneError::input(&self.name, Some(row.line), None, m));
        let stray = row.written & !self.allowed;
        if stray != 0 {
            return fail(format!(
                "{} {} a joint program of the machine ({}; the machine file's [gcode] table): is this a tool-centre program? give it with --path",
                letters(stray),
                not_words(stray),
                self.joint_words()
            ));
        }
        let missing = self.allowed & !row.known;
        if missing != 0 {
            return fail(format!(
                "the joints are not all known yet ({} not given): a joint program gives every joint ({}) by its first move",
                letters(missing),
                self.joint_words()
            ));
        }
        self.index += 1;
        let v: [f64; 5] = std::array::from_fn(|j| {
            let w = self.words.joints[j];
            let x = w.joint(row.get(axis_of(w.letter)));
            if j < 3 { x } else { x.to_radians() }
        });
        Ok(Some(Item {
            index: self.index,
            line: row.line,
            id: row.n.map(|n| format!("N{n}")),
            tag: row.comment.as_ref().and_then(|c| path_tag(c.as_str())),
            value: Ok(Joints {
                rho: Sliders::new(v[0], v[1], v[2]),
                theta1: v[3],
                theta2: v[4],
                t: None,
                feed: None,
                duration: row.duration_s,
                rapid: row.motion == Motion::Rapid,
            }),
        }))
    }
}

/// The path row a block's comment names, as `verne ik --format gcode` writes it: `path row R
/// line L` for the row itself, `path row R at S line L` for a pose inserted at fraction S of the
/// move to it. Any other comment names none.
pub fn path_tag(comment: &str) -> Option<PathTag> {
    let rest = comment.strip_prefix("path row ")?;
    let mut words = rest.split_ascii_whitespace();
    let row: u64 = words.next()?.parse().ok()?;
    let fraction = match words.next()? {
        "at" => {
            let f: f64 = words.next()?.parse().ok()?;
            (f.is_finite() && (0.0..=1.0).contains(&f)).then_some(f)?;
            if words.next()? != "line" {
                return None;
            }
            Some(f)
        }
        "line" => None,
        _ => return None,
    };
    Some(PathTag { row, fraction })
}

impl JointSource for JointProgram {
    /// A program's feed moves are timed by its feeds.
    fn timed(&self) -> bool {
        true
    }

    /// The controller starts still, and stops at a rapid and at the program's end.
    fn starts_at_rest(&self) -> bool {
        true
    }
}

/// The reader's options from the command line's and the machine's.
pub fn options(
    chord_tol_mm: f64,
    units: Option<verne_gcode::Units>,
    words: &GcodeWords,
) -> Options {
    Options {
        chord_tol_mm,
        units,
        ijk_tool_vector: words.orientation == GcodeOrientation::Vector,
        ..Options::default()
    }
}
