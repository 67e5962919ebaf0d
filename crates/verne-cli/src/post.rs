//! `verne ik --format gcode`: the simplest correct post for the machine. The row engine writes
//! its CSV (tool pose, feed, motion, joints) into a [`GcodePost`], which turns each row into one
//! block of a joint program: the five joints by the letters of the machine file's `[gcode]`
//! table, `G0` for rapids, and for feed moves `G93` inverse time, so that each block takes the
//! time of the tool tip's move at the path's feed (LinuxCNC's rule for moves of the rotary
//! axes alone: their angle at the feed in degrees per minute), or the time the path states for
//! the move (a tool-centre program's `G93` block, the `dt` column). `verne verify --joints`
//! reads the program back, one row per block.

use std::io::{self, Write};

use verne::spec::gcode::GcodeWords;

/// Joint words are written with this many decimals (mm and degrees): 1 nm, 1e-6 degree.
pub const DECIMALS: usize = 6;

/// The F of a block that does not move (inverse time, 1/min): 1 ms.
const STILL_F: f64 = 60_000.0;

/// Columns of the engine's CSV that the post reads.
struct Columns {
    line: Option<usize>,
    n: Option<usize>,
    motion: Option<usize>,
    feed: Option<usize>,
    /// The time of the move (s) where the path states it (a program's G93 block).
    dt: Option<usize>,
    tip: [usize; 3],
    joints: [usize; 5],
}

/// A writer of CSV text in, G-code out. The program's end (`M2`, `%`) is written at the first
/// flush after the header: the sink flushes once, when the run succeeded.
pub struct GcodePost {
    out: Box<dyn Write + Send>,
    words: GcodeWords,
    source: String,
    pending: Vec<u8>,
    columns: Option<Columns>,
    prev_tip: Option<[f64; 3]>,
    prev_angles: [f64; 2],
    ended: bool,
    block: Vec<u8>,
}

impl GcodePost {
    pub fn new(out: Box<dyn Write + Send>, words: GcodeWords, source: &str) -> GcodePost {
        GcodePost {
            out,
            words,
            source: source.to_string(),
            pending: Vec::new(),
            columns: None,
            prev_tip: None,
            prev_angles: [0.0; 2],
            ended: false,
            block: Vec::with_capacity(128),
        }
    }

    fn header(&mut self, fields: &[String]) -> io::Result<()> {
        let find = |name: &str| fields.iter().position(|f| f.eq_ignore_ascii_case(name));
        let need = |name: &str| {
            find(name).ok_or_else(|| {
                invalid(format!(
                    "--format gcode needs the column `{name}` (tool poses in, machine joints out)"
                ))
            })
        };
        let columns = Columns {
            line: find("line"),
            n: find("n"),
            motion: find("motion"),
            feed: find("feed"),
            dt: find("dt"),
            tip: [need("x")?, need("y")?, need("z")?],
            joints: [
                need("rho1")?,
                need("rho2")?,
                need("rho3")?,
                need("theta1")?,
                need("theta2")?,
            ],
        };
        if columns.feed.is_none() {
            return Err(invalid(
                "--format gcode times every feed move by its feed: the input needs a `feed` column (mm/min), as CL files and tool-centre programs give".into(),
            ));
        }
        self.columns = Some(columns);
        let w = &self.words.joints;
        writeln!(self.out, "%")?;
        writeln!(
            self.out,
            "(joint program for the VERNE machine, written by verne ik --format gcode from {})",
            comment_safe(&self.source)
        )?;
        writeln!(
            self.out,
            "({} = rho1, {} = rho2, {} = rho3 in mm; {} = theta1, {} = theta2 in degrees: the machine file's [gcode] table)",
            w[0].letter, w[1].letter, w[2].letter, w[3].letter, w[4].letter
        )?;
        writeln!(
            self.out,
            "(N = the line of the toolpath; G93: each feed block takes the time of the tool tip's move at the path's feed)"
        )?;
        writeln!(self.out, "G21 G90 G17 G40 G49 G80 G93")?;
        Ok(())
    }

    fn row(&mut self, fields: &[String]) -> io::Result<()> {
        let Some(c) = &self.columns else {
            return Ok(());
        };
        let num = |i: usize| -> io::Result<f64> {
            fields
                .get(i)
                .and_then(|f| f.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    invalid(format!(
                        "--format gcode: a row without a number in column {}",
                        i + 1
                    ))
                })
        };
        let line = c
            .line
            .and_then(|i| fields.get(i))
            .cloned()
            .unwrap_or_default();
        let at = if line.is_empty() {
            String::new()
        } else {
            format!("line {line}: ")
        };
        let tip = [num(c.tip[0])?, num(c.tip[1])?, num(c.tip[2])?];
        let joints = [
            num(c.joints[0])?,
            num(c.joints[1])?,
            num(c.joints[2])?,
            num(c.joints[3])?,
            num(c.joints[4])?,
        ];
        let rapid = c
            .motion
            .and_then(|i| fields.get(i))
            .is_some_and(|m| m == "rapid")
            || self.prev_tip.is_none();
        self.block.clear();
        // N: the toolpath's own line (a G-code program's N word when it has one).
        let n =
            c.n.and_then(|i| fields.get(i))
                .and_then(|n| n.strip_prefix('N').map(str::to_string))
                .filter(|n| !n.is_empty())
                .or_else(|| (!line.is_empty()).then(|| line.clone()));
        if let Some(n) = n {
            write!(self.block, "N{n} ")?;
        }
        self.block
            .extend_from_slice(if rapid { b"G0" } else { b"G1" });
        for (w, v) in self.words.joints.iter().zip(joints) {
            write!(self.block, " {}{}", w.letter, number(w.word(v)))?;
        }
        let stated =
            c.dt.and_then(|i| fields.get(i))
                .and_then(|t| t.parse::<f64>().ok())
                .filter(|t| t.is_finite() && *t >= 0.0);
        if let (false, Some(seconds)) = (rapid, stated) {
            // The path states the move's time (a G93 block): the joint block takes it.
            let f = if seconds > 0.0 {
                60.0 / seconds
            } else {
                STILL_F
            };
            write!(self.block, " F{}", number(f))?;
        } else if !rapid {
            let feed = c
                .feed
                .and_then(|i| fields.get(i))
                .and_then(|f| f.parse::<f64>().ok())
                .filter(|f| f.is_finite() && *f > 0.0)
                .ok_or_else(|| {
                    invalid(format!(
                        "{at}a feed move without a feed: --format gcode times each feed move by the path's feed (a CL file's FEDRAT, a program's F, a `feed` column)"
                    ))
                })?;
            let prev = self.prev_tip.unwrap_or(tip);
            let length = (0..3)
                .map(|k| (tip[k] - prev[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            // Time of the move (min): the tip's path at the feed, or, when the tip stays, the
            // table's angles at the feed in degrees per minute (LinuxCNC's rule for A B C).
            let turn = ((joints[3] - self.prev_angles[0]).powi(2)
                + (joints[4] - self.prev_angles[1]).powi(2))
            .sqrt();
            let minutes = if length > 1e-9 {
                length / feed
            } else {
                turn / feed
            };
            let f = if minutes > 0.0 {
                1.0 / minutes
            } else {
                STILL_F
            };
            write!(self.block, " F{}", number(f))?;
        }
        self.block.push(b'\n');
        self.out.write_all(&self.block)?;
        self.prev_tip = Some(tip);
        self.prev_angles = [joints[3], joints[4]];
        Ok(())
    }

    fn line(&mut self, text: &[u8]) -> io::Result<()> {
        let fields = split_csv(text);
        if self.columns.is_none() {
            self.header(&fields)
        } else {
            self.row(&fields)
        }
    }
}

impl Write for GcodePost {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.pending.extend_from_slice(buf);
        let mut start = 0;
        while let Some(p) = self.pending[start..].iter().position(|&b| b == b'\n') {
            let end = start + p;
            let text = self.pending[start..end].to_vec();
            self.line(&text)?;
            start = end + 1;
        }
        self.pending.drain(..start);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        if self.columns.is_some() && !self.ended {
            self.ended = true;
            writeln!(self.out, "M2")?;
            writeln!(self.out, "%")?;
        }
        self.out.flush()
    }
}

/// A number with [`DECIMALS`] decimals, trailing zeros dropped (`12.5`, `-0.000001`, `3`).
fn number(v: f64) -> String {
    let s = format!("{v:.DECIMALS$}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// Text that can stand inside a G-code comment: no parentheses, printable ASCII.
fn comment_safe(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '(' | ')' => '_',
            c if c.is_ascii_graphic() || c == ' ' => c,
            _ => '?',
        })
        .collect()
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, message)
}

/// The fields of one CSV line (quotes as the engine's writer makes them).
fn split_csv(text: &[u8]) -> Vec<String> {
    let mut fields = Vec::new();
    let mut cur = Vec::new();
    let mut quoted = false;
    let mut i = 0;
    while i < text.len() {
        let b = text[i];
        match (quoted, b) {
            (true, b'"') if text.get(i + 1) == Some(&b'"') => {
                cur.push(b'"');
                i += 1;
            }
            (true, b'"') => quoted = false,
            (false, b'"') if cur.is_empty() => quoted = true,
            (false, b',') => {
                fields.push(String::from_utf8_lossy(&std::mem::take(&mut cur)).into_owned())
            }
            (_, b) => cur.push(b),
        }
        i += 1;
    }
    fields.push(String::from_utf8_lossy(&cur).into_owned());
    fields
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_fields() {
        assert_eq!(number(12.5), "12.5");
        assert_eq!(number(-1e-7), "0");
        assert_eq!(number(3.0), "3");
        assert_eq!(
            split_csv(b"a,\"b,c\",,\"d\"\"e\""),
            ["a", "b,c", "", "d\"e"]
        );
        assert_eq!(comment_safe("a(b).cl"), "a_b_.cl");
    }
}
