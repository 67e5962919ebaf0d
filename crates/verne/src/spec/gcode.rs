//! The `[gcode]` table of a machine file: how G-code programs for the machine name its joints
//! (a joint program, as a post for the machine writes it) and the tool pose (a tool-centre
//! program: X Y Z the tool tip in the workpiece frame and two angle words or the I J K vector).

use crate::error::Problem;

/// A joint's word in a joint program: joint = sign * word + offset (mm or degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointWord {
    /// The axis letter, upper case (X Y Z U V W for the sliders, A B C for the table).
    pub letter: char,
    /// +1 or -1 (a letter written `-U` in the machine file).
    pub sign: f64,
    /// Added after the sign (mm or degrees).
    pub offset: f64,
}

impl JointWord {
    /// The joint's value from the word's value.
    pub fn joint(&self, word: f64) -> f64 {
        self.sign * word + self.offset
    }

    /// The word's value from the joint's value.
    pub fn word(&self, joint: f64) -> f64 {
        self.sign * (joint - self.offset)
    }
}

/// How a tool-centre program gives the tool orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GcodeOrientation {
    /// Two angle words, phi1 and phi2 of AIM 2007 eq. (8), in degrees (LinuxCNC's
    /// `vernekins` world coordinates: A and C).
    Angles {
        /// Letter of phi1.
        phi1: char,
        /// Letter of phi2.
        phi2: char,
    },
    /// The tool-axis vector as `I J K` on straight moves (the `G43.5`/ORIVECT form).
    Vector,
}

/// The `[gcode]` table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GcodeWords {
    /// rho1, rho2, rho3, theta1, theta2.
    pub joints: [JointWord; 5],
    /// The orientation words of a tool-centre program.
    pub orientation: GcodeOrientation,
}

const fn word(letter: char) -> JointWord {
    JointWord {
        letter,
        sign: 1.0,
        offset: 0.0,
    }
}

impl Default for GcodeWords {
    /// U V W A C for the joints; A C for phi1 and phi2.
    fn default() -> GcodeWords {
        GcodeWords {
            joints: [word('U'), word('V'), word('W'), word('A'), word('C')],
            orientation: GcodeOrientation::Angles {
                phi1: 'A',
                phi2: 'C',
            },
        }
    }
}

/// The largest offset of a joint's word (mm or degrees): beyond, the word written with six
/// decimals no longer carries the joint's 1e-6 (a double has 15 to 16 digits).
pub const MAX_WORD_OFFSET: f64 = 1e8;

/// The joint names of the table's keys, in order.
pub const JOINT_KEYS: [&str; 5] = ["rho1", "rho2", "rho3", "theta1", "theta2"];

/// One `[gcode]` entry as read: key (after `gcode.`), text or number, line.
pub(crate) enum GcodeValue {
    Text(String),
    Number(f64),
    /// A boolean, a date, an array or a table: never valid here.
    Other,
}

impl GcodeWords {
    /// Builds the table from its entries, reporting every problem with its line.
    pub(crate) fn from_entries(
        entries: &[(String, GcodeValue, Option<usize>)],
        problems: &mut Vec<Problem>,
    ) -> GcodeWords {
        let mut g = GcodeWords::default();
        let mut phi = ['A', 'C'];
        let mut vector = false;
        let mut bad = |line: Option<usize>, key: &str, message: String| {
            problems.push(Problem {
                line,
                key: format!("gcode.{key}"),
                message,
            })
        };
        for (key, value, line) in entries {
            let text = match value {
                GcodeValue::Text(s) => Some(s.as_str()),
                _ => None,
            };
            let number = match value {
                GcodeValue::Number(x) if x.is_finite() => Some(*x),
                _ => None,
            };
            if let Some(j) = JOINT_KEYS.iter().position(|k| k == key) {
                let rotary = j >= 3;
                match text.and_then(|t| parse_letter(t, true)) {
                    Some((letter, sign)) if is_rotary(letter) == rotary => {
                        g.joints[j].letter = letter;
                        g.joints[j].sign = sign;
                    }
                    _ => bad(
                        *line,
                        key,
                        format!(
                            "expected the letter of {key} in a joint program: {}, with `-` for a reversed axis",
                            if rotary {
                                "one of \"A\", \"B\", \"C\""
                            } else {
                                "one of \"X\", \"Y\", \"Z\", \"U\", \"V\", \"W\""
                            }
                        ),
                    ),
                }
            } else if let Some(j) = key
                .strip_suffix("_offset")
                .and_then(|k| JOINT_KEYS.iter().position(|j| *j == k))
            {
                match number {
                    Some(x) if x.abs() <= MAX_WORD_OFFSET => g.joints[j].offset = x,
                    Some(x) => bad(
                        *line,
                        key,
                        format!(
                            "{x:e} is beyond {MAX_WORD_OFFSET:e}: the joint's digits would be lost in its word (written with 1e-6 of resolution)"
                        ),
                    ),
                    None => bad(
                        *line,
                        key,
                        "expected a finite number (mm or degrees)".into(),
                    ),
                }
            } else if key == "orientation" {
                match text {
                    Some("angles") => vector = false,
                    Some("vector") => vector = true,
                    _ => bad(
                        *line,
                        key,
                        "expected \"angles\" (two angle words phi1, phi2) or \"vector\" (I J K)"
                            .into(),
                    ),
                }
            } else if key == "phi1" || key == "phi2" {
                let k = usize::from(key == "phi2");
                match text.and_then(|t| parse_letter(t, false)) {
                    Some((letter, _)) if is_rotary(letter) => phi[k] = letter,
                    _ => bad(
                        *line,
                        key,
                        format!(
                            "expected the letter of {key} in a tool-centre program: \"A\", \"B\" or \"C\""
                        ),
                    ),
                }
            } else {
                bad(
                    *line,
                    key,
                    "unknown key of [gcode]; known keys: rho1, rho2, rho3, theta1, theta2 (letters), rho1_offset .. theta2_offset, orientation, phi1, phi2".into(),
                );
            }
        }
        let joints = g.joints;
        for (a, wa) in joints.iter().enumerate() {
            for (b, wb) in joints.iter().enumerate().skip(a + 1) {
                if wa.letter == wb.letter {
                    bad(
                        None,
                        JOINT_KEYS[b],
                        format!(
                            "{} and {} have the same letter {}",
                            JOINT_KEYS[a], JOINT_KEYS[b], wa.letter
                        ),
                    );
                }
            }
        }
        if !vector && phi[0] == phi[1] {
            bad(
                None,
                "phi2",
                format!("phi1 and phi2 have the same letter {}", phi[0]),
            );
        }
        g.orientation = if vector {
            GcodeOrientation::Vector
        } else {
            GcodeOrientation::Angles {
                phi1: phi[0],
                phi2: phi[1],
            }
        };
        g
    }

    /// The table as TOML lines (for `Machine::to_toml`).
    pub fn to_toml(&self) -> String {
        let mut s = String::from("[gcode]\n");
        for (k, w) in JOINT_KEYS.iter().zip(&self.joints) {
            let sign = if w.sign < 0.0 { "-" } else { "" };
            s.push_str(&format!("{k} = \"{sign}{}\"\n", w.letter));
            if w.offset != 0.0 {
                s.push_str(&format!("{k}_offset = {}\n", w.offset));
            }
        }
        match self.orientation {
            GcodeOrientation::Angles { phi1, phi2 } => {
                s.push_str(&format!(
                    "orientation = \"angles\"\nphi1 = \"{phi1}\"\nphi2 = \"{phi2}\"\n"
                ));
            }
            GcodeOrientation::Vector => s.push_str("orientation = \"vector\"\n"),
        }
        s
    }
}

fn is_rotary(c: char) -> bool {
    matches!(c, 'A' | 'B' | 'C')
}

/// `"U"`, `"-u"`: an axis letter of RS274/NGC and its sign.
fn parse_letter(t: &str, signed: bool) -> Option<(char, f64)> {
    let t = t.trim();
    let (sign, rest) = match t.strip_prefix('-') {
        Some(r) if signed => (-1.0, r.trim()),
        Some(_) => return None,
        None => (1.0, t),
    };
    let mut chars = rest.chars();
    let c = chars.next()?.to_ascii_uppercase();
    (chars.next().is_none() && "XYZABCUVW".contains(c)).then_some((c, sign))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(entries: &[(&str, GcodeValue)]) -> (GcodeWords, Vec<Problem>) {
        let e: Vec<(String, GcodeValue, Option<usize>)> = entries
            .iter()
            .enumerate()
            .map(|(i, (k, v))| {
                let v = match v {
                    GcodeValue::Text(s) => GcodeValue::Text(s.clone()),
                    GcodeValue::Number(x) => GcodeValue::Number(*x),
                    GcodeValue::Other => GcodeValue::Other,
                };
                (k.to_string(), v, Some(i + 1))
            })
            .collect();
        let mut problems = Vec::new();
        let g = GcodeWords::from_entries(&e, &mut problems);
        (g, problems)
    }

    #[test]
    fn letters_signs_offsets_and_orientation() {
        let t = |s: &str| GcodeValue::Text(s.into());
        let (g, p) = read(&[
            ("rho1", t("x")),
            ("rho2", t("-Y")),
            ("rho3", t("Z")),
            ("theta2_offset", GcodeValue::Number(90.0)),
            ("orientation", t("vector")),
        ]);
        assert!(p.is_empty(), "{p:?}");
        assert_eq!(g.joints[0].letter, 'X');
        assert_eq!(g.joints[1].joint(5.0), -5.0);
        assert_eq!(g.joints[4].joint(10.0), 100.0);
        assert_eq!(g.joints[4].word(100.0), 10.0);
        assert_eq!(g.orientation, GcodeOrientation::Vector);
    }

    #[test]
    fn every_problem_is_reported() {
        let t = |s: &str| GcodeValue::Text(s.into());
        let (_, p) = read(&[
            ("rho1", t("A")),
            ("theta1", t("U")),
            ("rho2", t("W")),
            ("orientation", t("euler")),
            ("phi1", t("-A")),
            ("feed", GcodeValue::Number(1.0)),
        ]);
        let keys: Vec<&str> = p.iter().map(|p| p.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "gcode.rho1",
                "gcode.theta1",
                "gcode.orientation",
                "gcode.phi1",
                "gcode.feed",
                "gcode.rho3"
            ]
        );
    }
}
