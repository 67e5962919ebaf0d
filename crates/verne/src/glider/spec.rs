//! Glider mechanism description (section 2.2, Wenger 2001): dimensions, guide angles, joint
//! ranges, its TOML file format, validation and the three presets of section 3.1.
//!
//! Placement (docs/gliders.md): guide origin A at (0, 0), guide origin B at (l0, 0); slider C at
//! a + rho1 u1 and D at b + rho2 u2 with u_i = (cos alpha_i, sin alpha_i); |CP| = l1, |DP| = l2.

use std::fmt;

use nalgebra::{Point2, Vector2};
use serde::{Deserialize, Serialize};

/// One planar 2-DOF glider: two struts of fixed length gliding along two actuated linear guides.
/// Lengths are in any one unit (the presets use L = 1, so they read as multiples of L).
#[derive(Debug, Clone, PartialEq)]
pub struct GliderSpec {
    pub name: String,
    /// Direction of guide 1 from the x axis (rad), section 2.3.
    pub alpha1: f64,
    /// Direction of guide 2 from the x axis (rad).
    pub alpha2: f64,
    /// Length of strut CP.
    pub l1: f64,
    /// Length of strut DP.
    pub l2: f64,
    /// Distance between the guide origins A and B (A at the origin, B on the +x axis).
    pub l0: f64,
    /// [min, max] of rho1, the position of C along guide 1 measured from A.
    pub rho1_range: [f64; 2],
    /// [min, max] of rho2, the position of D along guide 2 measured from B.
    pub rho2_range: [f64; 2],
}

/// The TOML form: angles in degrees.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecFile {
    kind: String,
    name: String,
    alpha1_deg: f64,
    alpha2_deg: f64,
    l1: f64,
    l2: f64,
    l0: f64,
    /// `[min, max]`; read as a list so that a list of another length is refused by name and
    /// line (a fixed-size array would take the first two numbers of three).
    rho1_range: Vec<f64>,
    rho2_range: Vec<f64>,
}

/// One problem found in a glider description, naming its key.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecProblem {
    /// 1-based line in the text, when the description came from a text and the problem is on
    /// one of its lines.
    pub line: Option<usize>,
    /// The TOML key concerned (`l0`, `rho1_range`), empty for a syntax error.
    pub key: String,
    pub message: String,
}

/// Every problem found in one glider description.
#[derive(Debug, Clone, PartialEq)]
pub struct GliderSpecError {
    /// Where the description came from (file name, `preset biglide1`, ...).
    pub source: String,
    pub problems: Vec<SpecProblem>,
}

impl fmt::Display for GliderSpecError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.problems.len();
        write!(
            f,
            "invalid glider description {}: {} problem{}",
            self.source,
            n,
            if n == 1 { "" } else { "s" }
        )?;
        for p in &self.problems {
            write!(f, "\n  {}", self.source)?;
            if let Some(line) = p.line {
                write!(f, ":{line}")?;
            }
            if p.key.is_empty() {
                write!(f, ": {}", p.message)?;
            } else {
                write!(f, ": {}: {}", p.key, p.message)?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for GliderSpecError {}

/// The 1-based line of byte offset `at` of `text`.
fn line_at(text: &str, at: usize) -> usize {
    text.as_bytes()[..at.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The 1-based line of the first `key = ...` of a glider file (a flat TOML table).
fn key_line(text: &str, key: &str) -> Option<usize> {
    if key.is_empty() {
        return None;
    }
    text.lines()
        .position(|l| {
            l.split_once('=')
                .is_some_and(|(lhs, _)| lhs.trim().trim_matches('"') == key)
        })
        .map(|i| i + 1)
}

/// Names of the presets of section 3.1, Wenger 2001, in the paper's order.
pub const PRESET_NAMES: [&str; 3] = ["biglide1", "biglide2", "orthoglide"];

const BIGLIDE1_TOML: &str = include_str!("../../data/biglide1.toml");
const BIGLIDE2_TOML: &str = include_str!("../../data/biglide2.toml");
const ORTHOGLIDE_TOML: &str = include_str!("../../data/orthoglide.toml");

impl GliderSpec {
    /// A preset of section 3.1 (`biglide1`, `biglide2`, `orthoglide`), dimensioned for L = 1 by
    /// the rule of section 3.2; `None` for any other name.
    pub fn preset(name: &str) -> Option<GliderSpec> {
        let text = match name {
            "biglide1" => BIGLIDE1_TOML,
            "biglide2" => BIGLIDE2_TOML,
            "orthoglide" => ORTHOGLIDE_TOML,
            _ => return None,
        };
        // The preset files are part of the crate and tested; a broken one is a build defect.
        Some(
            GliderSpec::from_toml_str(text, &format!("preset {name}"))
                .expect("preset glider files are valid"),
        )
    }

    /// Reads and validates a glider description in TOML (`kind = "glider"`, angles in degrees).
    /// `source` names the text in error messages. Every problem found is reported at once.
    pub fn from_toml_str(text: &str, source: &str) -> Result<GliderSpec, GliderSpecError> {
        let error = |problems| GliderSpecError {
            source: source.to_string(),
            problems,
        };
        let file: SpecFile = toml::from_str(text).map_err(|e| {
            error(vec![SpecProblem {
                line: e.span().map(|r| line_at(text, r.start)),
                key: String::new(),
                message: e.to_string().trim_end().replace('\n', "\n    "),
            }])
        })?;
        let mut problems = Vec::new();
        if file.kind != "glider" {
            problems.push(SpecProblem {
                line: None,
                key: "kind".into(),
                message: format!("is {:?}, expected \"glider\"", file.kind),
            });
        }
        let mut range = |key: &str, v: &[f64]| match *v {
            [lo, hi] => [lo, hi],
            _ => {
                problems.push(SpecProblem {
                    line: None,
                    key: key.into(),
                    message: format!(
                        "has {} number{}, expected two: [min, max]",
                        v.len(),
                        if v.len() == 1 { "" } else { "s" }
                    ),
                });
                [0.0, 0.0]
            }
        };
        let (rho1_range, rho2_range) = (
            range("rho1_range", &file.rho1_range),
            range("rho2_range", &file.rho2_range),
        );
        let spec = GliderSpec {
            name: file.name,
            alpha1: file.alpha1_deg.to_radians(),
            alpha2: file.alpha2_deg.to_radians(),
            l1: file.l1,
            l2: file.l2,
            l0: file.l0,
            rho1_range,
            rho2_range,
        };
        problems.extend(spec.validate());
        for p in &mut problems {
            p.line = p.line.or_else(|| key_line(text, &p.key));
        }
        if problems.is_empty() {
            Ok(spec)
        } else {
            Err(error(problems))
        }
    }

    /// The TOML form read by [`GliderSpec::from_toml_str`].
    pub fn to_toml_string(&self) -> String {
        let file = SpecFile {
            kind: "glider".into(),
            name: self.name.clone(),
            alpha1_deg: self.alpha1.to_degrees(),
            alpha2_deg: self.alpha2.to_degrees(),
            l1: self.l1,
            l2: self.l2,
            l0: self.l0,
            rho1_range: self.rho1_range.to_vec(),
            rho2_range: self.rho2_range.to_vec(),
        };
        toml::to_string(&file).expect("a flat struct of numbers and strings serialises")
    }

    /// Every problem of this description, each naming its TOML key; empty when valid.
    pub fn validate(&self) -> Vec<SpecProblem> {
        let mut problems = Vec::new();
        let mut push = |key: &str, message: String| {
            problems.push(SpecProblem {
                line: None,
                key: key.into(),
                message,
            })
        };
        if self.name.trim().is_empty() {
            push("name", "is empty".into());
        }
        for (key, v) in [("alpha1_deg", self.alpha1), ("alpha2_deg", self.alpha2)] {
            if !v.is_finite() {
                push(key, format!("is {v}, expected a finite angle in degrees"));
            }
        }
        for (key, v) in [("l1", self.l1), ("l2", self.l2), ("l0", self.l0)] {
            if !(v.is_finite() && v > 0.0) {
                push(key, format!("is {v}, expected a finite length > 0"));
            }
        }
        for (key, [lo, hi]) in [
            ("rho1_range", self.rho1_range),
            ("rho2_range", self.rho2_range),
        ] {
            if !(lo.is_finite() && hi.is_finite()) {
                push(key, format!("is [{lo}, {hi}], expected finite bounds"));
            } else if lo > hi {
                push(key, format!("is [{lo}, {hi}]: minimum {lo} > maximum {hi}"));
            }
        }
        problems
    }

    /// Guide origin A (section 2.3): the origin.
    pub fn a(&self) -> Point2<f64> {
        Point2::origin()
    }

    /// Guide origin B: (l0, 0).
    pub fn b(&self) -> Point2<f64> {
        Point2::new(self.l0, 0.0)
    }

    /// Unit direction of guide 1, (cos alpha1, sin alpha1).
    pub fn u1(&self) -> Vector2<f64> {
        Vector2::new(self.alpha1.cos(), self.alpha1.sin())
    }

    /// Unit direction of guide 2, (cos alpha2, sin alpha2).
    pub fn u2(&self) -> Vector2<f64> {
        Vector2::new(self.alpha2.cos(), self.alpha2.sin())
    }

    /// Slider points C = a + rho1 u1 and D = b + rho2 u2.
    pub fn sliders(&self, rho: Vector2<f64>) -> (Point2<f64>, Point2<f64>) {
        (self.a() + self.u1() * rho.x, self.b() + self.u2() * rho.y)
    }

    /// Whether rho lies in the joint box (with the slack of
    /// [`JOINT_LIMIT_REL`](super::tolerance::JOINT_LIMIT_REL)).
    pub fn within_limits(&self, rho: Vector2<f64>) -> bool {
        self.limits_passed(rho) == 0
    }

    /// The joint limits `rho` passes (beyond the slack of [`within_limits`](Self::within_limits)),
    /// a bit set: rho1 below its range 1, above 2; rho2 below 4, above 8. A joint that is not a
    /// number passes both of its limits.
    pub fn limits_passed(&self, rho: Vector2<f64>) -> u8 {
        let slack = super::tolerance::JOINT_LIMIT_REL * self.l1;
        use std::cmp::Ordering::{Equal, Greater, Less};
        let passed = |v: f64, [lo, hi]: [f64; 2]| {
            let below = !matches!(v.partial_cmp(&(lo - slack)), Some(Greater | Equal));
            let above = !matches!(v.partial_cmp(&(hi + slack)), Some(Less | Equal));
            u8::from(below) | u8::from(above) << 1
        };
        passed(rho.x, self.rho1_range) | passed(rho.y, self.rho2_range) << 2
    }

    /// This mechanism with every length multiplied by `k` (angles unchanged).
    pub fn scaled(&self, k: f64) -> GliderSpec {
        GliderSpec {
            name: self.name.clone(),
            alpha1: self.alpha1,
            alpha2: self.alpha2,
            l1: self.l1 * k,
            l2: self.l2 * k,
            l0: self.l0 * k,
            rho1_range: self.rho1_range.map(|v| v * k),
            rho2_range: self.rho2_range.map(|v| v * k),
        }
    }
}
