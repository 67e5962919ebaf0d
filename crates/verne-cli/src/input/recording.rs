//! Recorded joints for `verne verify --recording`: a controller's servo samples as LinuxCNC's
//! `halsampler` writes them (whitespace-separated numbers, no header, one line per servo period;
//! with `-t` a sample number first; a line `overrun` where samples were lost), or a halstreamer
//! stream written by `verne ik --format halstreamer --period`. The columns are named by
//! `--columns` (default: rho1,rho2,rho3,theta1,theta2, the halstreamer order); joints in mm and
//! degrees (the machine's units); the time of each sample is its number times the period.

use std::io::{BufRead, Read};
use std::path::Path;

use verne::error::shown;
use verne::parallel_module::equations::Sliders;
use verne::verify::{Item, JOINT_NAMES, JointSource, Joints, RowSource};

use crate::error::VerneError;

/// The longest line of a recording (a sample is a few numbers).
pub const MAX_RECORDING_LINE_BYTES: usize = 64 << 10;

/// The default columns: a halstreamer stream written by `verne ik --format halstreamer`.
pub const DEFAULT_COLUMNS: &str = "rho1,rho2,rho3,theta1,theta2";

/// What one column of the recording holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Column {
    /// Joint k of [`JOINT_NAMES`].
    Joint(usize),
    /// The sample number (`halsampler -t`): the time is tag x period.
    Tag,
    /// Not used (`_`).
    Skip,
}

/// Parses `--columns`: names from rho1 rho2 rho3 theta1 theta2 tag and `_`, each joint once.
pub fn parse_columns(s: &str) -> Result<Vec<Column>, String> {
    let mut cols = Vec::new();
    for name in s.split(',').map(str::trim) {
        let c = match name {
            "tag" => Column::Tag,
            "_" => Column::Skip,
            n => match JOINT_NAMES.iter().position(|j| *j == n) {
                Some(k) => Column::Joint(k),
                None => {
                    return Err(format!(
                        "`{n}` is not a recording column: expected rho1, rho2, rho3, theta1, theta2, tag or _"
                    ));
                }
            },
        };
        if c != Column::Skip && cols.contains(&c) {
            return Err(format!("`{name}` is named twice"));
        }
        cols.push(c);
    }
    for (k, j) in JOINT_NAMES.iter().enumerate() {
        if !cols.contains(&Column::Joint(k)) {
            return Err(format!("`{j}` is missing: the five joints must be named"));
        }
    }
    Ok(cols)
}

/// A recording, read sample by sample for the core's checks.
pub struct RecordingReader {
    input: Box<dyn BufRead + Send>,
    name: String,
    columns: Vec<Column>,
    period: f64,
    line: u64,
    index: u64,
    buf: Vec<u8>,
    /// The last sample number read (`tag`).
    last_tag: Option<f64>,
}

impl RecordingReader {
    /// Opens `path` (`-`: stdin).
    pub fn open(path: &Path, columns: Vec<Column>, period: f64) -> Result<Self, VerneError> {
        let name = if path.as_os_str() == "-" {
            "<stdin>".to_string()
        } else {
            path.display().to_string()
        };
        let input: Box<dyn BufRead + Send> = if path.as_os_str() == "-" {
            Box::new(std::io::BufReader::new(std::io::stdin()))
        } else {
            let f = crate::files::open_input_file(path).map_err(|e| VerneError::io(&name, e))?;
            Box::new(std::io::BufReader::with_capacity(64 * 1024, f))
        };
        Ok(Self::from_reader(input, &name, columns, period))
    }

    /// A recording from any reader (`name` for messages).
    pub fn from_reader(
        input: Box<dyn BufRead + Send>,
        name: &str,
        columns: Vec<Column>,
        period: f64,
    ) -> Self {
        RecordingReader {
            input,
            name: name.to_string(),
            columns,
            period,
            line: 0,
            index: 0,
            buf: Vec::new(),
            last_tag: None,
        }
    }

    fn error(&self, column: Option<&str>, message: String) -> VerneError {
        VerneError::input(&self.name, Some(self.line), column, message)
    }

    /// The next line's bytes (without its end), or None at the end of the file.
    fn next_line(&mut self) -> Result<Option<()>, VerneError> {
        self.buf.clear();
        let n = (&mut self.input)
            .take(MAX_RECORDING_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| VerneError::io(&self.name, e))?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        if self.buf.len() > MAX_RECORDING_LINE_BYTES && !self.buf.ends_with(b"\n") {
            return Err(self.error(
                None,
                format!(
                    "a line longer than {MAX_RECORDING_LINE_BYTES} bytes: expected one sample of {} numbers",
                    self.columns.len()
                ),
            ));
        }
        while self.buf.last().is_some_and(|b| *b == b'\n' || *b == b'\r') {
            self.buf.pop();
        }
        Ok(Some(()))
    }
}

impl RowSource for RecordingReader {
    type Row = Joints;
    type Error = VerneError;

    fn name(&self) -> &str {
        &self.name
    }

    fn has_id(&self) -> bool {
        false
    }

    fn next_item(&mut self) -> Result<Option<Item<Joints>>, VerneError> {
        loop {
            if self.next_line()?.is_none() {
                return Ok(None);
            }
            let text = String::from_utf8_lossy(&self.buf).into_owned();
            let fields: Vec<&str> = text.split_ascii_whitespace().collect();
            if fields.is_empty() {
                continue;
            }
            self.index += 1;
            let item = |value| Item {
                index: self.index,
                line: self.line,
                id: None,
                value,
                tag: None,
            };
            if fields == ["overrun"] {
                // halsampler lost samples here: the times around it are not a servo period apart.
                return Ok(Some(item(Err(
                    "halsampler overrun: samples were lost here".to_string(),
                ))));
            }
            if fields.len() != self.columns.len() {
                return Err(self.error(
                    None,
                    format!(
                        "{} values: expected one sample of {} ({})",
                        fields.len(),
                        self.columns.len(),
                        self.columns
                            .iter()
                            .map(|c| match c {
                                Column::Joint(k) => JOINT_NAMES[*k],
                                Column::Tag => "tag",
                                Column::Skip => "_",
                            })
                            .collect::<Vec<_>>()
                            .join(" ")
                    ),
                ));
            }
            let mut joints = [0.0; 5];
            let mut tag = None;
            let mut bad = None;
            for (field, col) in fields.iter().zip(&self.columns) {
                let name = match col {
                    Column::Skip => continue,
                    Column::Tag => "tag",
                    Column::Joint(k) => JOINT_NAMES[*k],
                };
                let v: f64 = field.parse().map_err(|_| {
                    self.error(
                        Some(name),
                        format!("expected a number, found `{}`", shown(field.as_bytes())),
                    )
                })?;
                if !v.is_finite() {
                    bad.get_or_insert(format!("{name} is not finite (`{field}`)"));
                }
                match col {
                    Column::Tag => tag = Some(v),
                    Column::Joint(k) => joints[*k] = v,
                    Column::Skip => {}
                }
            }
            if let Some(e) = bad {
                return Ok(Some(item(Err(e))));
            }
            // A tag is halsampler's sample number: an integer, each above the one before.
            if let Some(v) = tag {
                if v.fract() != 0.0 || !(0.0..=9.007e15).contains(&v) {
                    return Err(self.error(
                        Some("tag"),
                        format!("expected a sample number (a whole number from 0), found {v}"),
                    ));
                }
                if let Some(last) = self.last_tag
                    && v <= last
                {
                    return Err(self.error(
                        Some("tag"),
                        format!(
                            "sample number {v} does not follow {last}: the tags of a recording increase"
                        ),
                    ));
                }
                self.last_tag = Some(v);
            }
            let t = tag.unwrap_or((self.index - 1) as f64) * self.period;
            return Ok(Some(item(Ok(Joints {
                rho: Sliders::new(joints[0], joints[1], joints[2]),
                theta1: joints[3].to_radians(),
                theta2: joints[4].to_radians(),
                t: Some(t),
                feed: None,
                duration: None,
                rapid: false,
            }))));
        }
    }
}

impl JointSource for RecordingReader {
    fn timed(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_name_every_joint_once() {
        let c = parse_columns("tag,rho1,rho2,rho3,theta1,theta2,_,_").unwrap();
        assert_eq!(c[0], Column::Tag);
        assert_eq!(c[5], Column::Joint(4));
        assert!(
            parse_columns("rho1,rho2,rho3,theta1")
                .unwrap_err()
                .contains("theta2")
        );
        assert!(
            parse_columns("rho1,rho1,rho2,rho3,theta1,theta2")
                .unwrap_err()
                .contains("twice")
        );
        assert!(
            parse_columns("rho1,x,rho2,rho3,theta1,theta2")
                .unwrap_err()
                .contains("`x`")
        );
    }
}
