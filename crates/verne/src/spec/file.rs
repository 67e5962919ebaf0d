//! The VERNE machine file (TOML or two-column CSV): its schema, reading and validation.
//!
//! Both formats map to the same dotted keys (`module.R1`, `limits.rho1_max`, ...). Reading never
//! stops at the first problem: every missing, unknown, mistyped or out-of-range key is reported,
//! each with the line it is on.

use std::collections::{HashMap, HashSet};

use super::drives::Drives;
use super::gcode::{GcodeValue, GcodeWords};
use super::{Limits, Machine, ModuleGeometry, TableGeometry};
use crate::error::{MachineError, Problem};

/// Largest length of the module a machine file may give (mm): the forward kinematics' degree-8
/// polynomial has coefficients of the eighth power of the lengths, and 1e30^8 is near the largest
/// double; a kilometre is 1e6 mm.
pub const MAX_LENGTH_MM: f64 = 1e30;

/// The shortest rod (mm) a machine file may give: the solvers' tolerances are absolute, in mm
/// (tolerance.rs: residuals accepted below 1e-6 mm), so a machine much smaller than a millimetre
/// (or one written in metres) would be solved to nothing it can resolve.
pub const MIN_ROD_MM: f64 = 1.0;

/// Two lengths closer than this fraction of the machine's longest rod count as equal where
/// the kinematics divides by their difference (D1 - d1 and D2 - d2; R1 and r1): 1e-8, 9.5e-6 mm
/// on the default machine (L3 = 950.46 mm).
pub const SAME_LENGTH_REL: f64 = 1e-8;

/// How a key's value is read and checked.
#[derive(Clone, Copy)]
enum Check {
    /// A length that must be > 0 (mm).
    Positive,
    /// Any finite number (mm).
    Finite,
    /// A length that must be >= 0 (mm).
    NonNegative,
    /// An angle in degrees within (0, 90].
    TiltDegrees,
    /// An angle in degrees within [-180, 180].
    AngleDegrees,
}

/// The schema of a VERNE machine file: (section, key, check, meaning).
const SCHEMA: &[(&str, &str, Check, &str)] = &[
    (
        "module",
        "D1",
        Check::Finite,
        "x offset of leg I, base side (mm)",
    ),
    (
        "module",
        "d1",
        Check::Finite,
        "x offset of leg I, platform side (mm)",
    ),
    (
        "module",
        "R1",
        Check::Positive,
        "leg-I platform half-width (mm)",
    ),
    (
        "module",
        "r1",
        Check::Positive,
        "leg-I slider half-width (mm)",
    ),
    ("module", "L1", Check::Positive, "leg-I rod length (mm)"),
    (
        "module",
        "D2",
        Check::Finite,
        "x offset of legs II-III, base side (mm)",
    ),
    (
        "module",
        "d2",
        Check::Finite,
        "x offset of legs II-III, platform side (mm)",
    ),
    (
        "module",
        "R2",
        Check::Positive,
        "legs II-III platform half-width (mm)",
    ),
    (
        "module",
        "r4",
        Check::Positive,
        "half-distance between sliders II and III (mm)",
    ),
    ("module", "L2", Check::Positive, "leg-II rod length (mm)"),
    ("module", "L3", Check::Positive, "leg-III rod length (mm)"),
    (
        "limits",
        "rho1_min",
        Check::Finite,
        "slider 1 lower stroke limit (mm)",
    ),
    (
        "limits",
        "rho1_max",
        Check::Finite,
        "slider 1 upper stroke limit (mm)",
    ),
    (
        "limits",
        "rho2_min",
        Check::Finite,
        "slider 2 lower stroke limit (mm)",
    ),
    (
        "limits",
        "rho2_max",
        Check::Finite,
        "slider 2 upper stroke limit (mm)",
    ),
    (
        "limits",
        "rho3_min",
        Check::Finite,
        "slider 3 lower stroke limit (mm)",
    ),
    (
        "limits",
        "rho3_max",
        Check::Finite,
        "slider 3 upper stroke limit (mm)",
    ),
    (
        "limits",
        "rod_tilt_max",
        Check::TiltDegrees,
        "largest rod tilt (degrees, 0 < v <= 90)",
    ),
    (
        "limits",
        "theta1_min",
        Check::AngleDegrees,
        "tilting axis lower limit (degrees)",
    ),
    (
        "limits",
        "theta1_max",
        Check::AngleDegrees,
        "tilting axis upper limit (degrees)",
    ),
    (
        "table",
        "d_a",
        Check::Finite,
        "table: base to tilting axis along z (mm)",
    ),
    (
        "table",
        "d_t",
        Check::Finite,
        "table: tilting axis to table top along z (mm)",
    ),
    (
        "tool",
        "length",
        Check::NonNegative,
        "tool length Delta (mm)",
    ),
];

/// The optional keys, 0 when absent, so that a file without them is read as before: the
/// real machine's offsets from its drawing, which `verne calibrate` identifies. (section, key,
/// check, meaning.)
const OPTIONAL: &[(&str, &str, Check, &str)] = &[
    (
        "zeros",
        "rho1",
        Check::Finite,
        "slider 1 zero offset: the equations' rho1 is the joint's plus this (mm)",
    ),
    (
        "zeros",
        "rho2",
        Check::Finite,
        "slider 2 zero offset: the equations' rho2 is the joint's plus this (mm)",
    ),
    (
        "zeros",
        "rho3",
        Check::Finite,
        "slider 3 zero offset: the equations' rho3 is the joint's plus this (mm)",
    ),
    (
        "zeros",
        "theta1",
        Check::AngleDegrees,
        "tilting axis zero offset: the equations' theta1 is the joint's plus this (degrees)",
    ),
    (
        "zeros",
        "theta2",
        Check::AngleDegrees,
        "rotary axis zero offset: the equations' theta2 is the joint's plus this (degrees)",
    ),
    (
        "table",
        "y_t",
        Check::Finite,
        "table: tilting axis to rotary axis along y of the tilted frame (mm)",
    ),
];

const TOP_LEVEL_KEYS: &[&str] = &["kind", "name", "base"];

impl Machine {
    /// Parses a machine file, choosing the format from its content: a first non-comment line
    /// `key,value` means CSV, anything else TOML.
    pub fn from_str_auto(text: &str, source: &str) -> Result<Machine, MachineError> {
        Machine::from_str_on_base(text, source, None)
    }

    /// Parses and validates a TOML machine file. A file may start from a base, `base = "verne"`
    /// (the embedded default machine), and give only the keys it changes; a base given by a
    /// path is read by the caller ([`Machine::from_str_on_base`]).
    pub fn from_toml_str(text: &str, source: &str) -> Result<Machine, MachineError> {
        Machine::from_str_on_base(text, source, None)
    }

    /// Parses a machine file (TOML or key,value CSV) over the base it names, if any: every key
    /// of the base, then the file's keys in place of the base's. `resolve` turns a base's name
    /// into its text and a name for messages (the command line tool reads paths); `verne` is
    /// always the embedded default. A base may name its own base, up to
    /// [`MAX_BASE_DEPTH`] files.
    pub fn from_str_on_base(
        text: &str,
        source: &str,
        resolve: Option<&BaseResolver<'_>>,
    ) -> Result<Machine, MachineError> {
        let (entries, problems) = entries_over_base(text, source, resolve, 0)?;
        finish(entries, problems, source)
    }

    /// The entries of a TOML machine file (dotted keys with their lines), and the problems of
    /// its sections; an error when it is not TOML.
    fn toml_entries(text: &str, source: &str) -> Result<(Vec<Entry>, Vec<Problem>), MachineError> {
        let text = text.trim_start_matches('\u{feff}');
        let table: toml::Table = match text.parse() {
            Ok(t) => t,
            Err(e) => {
                let line = e
                    .span()
                    .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
                return Err(MachineError {
                    source: source.to_string(),
                    problems: vec![Problem {
                        line,
                        key: String::new(),
                        message: format!(
                            "not valid TOML: {}",
                            e.message().trim().replace('\n', "; ")
                        ),
                    }],
                });
            }
        };
        let mut entries = Vec::new();
        let mut problems = Vec::new();
        let lines = TomlLines::new(text);
        for (k, v) in &table {
            match v {
                toml::Value::Table(section) => {
                    for (kk, vv) in section {
                        let key = format!("{k}.{kk}");
                        let line = lines.get(k, kk);
                        entries.push(Entry {
                            key,
                            value: toml_value(vv),
                            line,
                        });
                    }
                }
                other => entries.push(Entry {
                    key: k.clone(),
                    value: toml_value(other),
                    line: lines.get("", k),
                }),
            }
        }
        problems.extend(check_sections(&table, &lines));
        Ok((entries, problems))
    }

    /// Parses and validates a two-column CSV machine file (`key,value` header, dotted keys),
    /// over the base it names, if any.
    pub fn from_csv_str(text: &str, source: &str) -> Result<Machine, MachineError> {
        Machine::from_str_on_base(text, source, None)
    }

    /// The entries of a key,value CSV machine file, with their lines, and its problems.
    fn csv_entries(text: &str) -> (Vec<Entry>, Vec<Problem>) {
        let mut entries = Vec::new();
        let mut problems = Vec::new();
        let mut seen_header = false;
        for (i, raw) in text.trim_start_matches('\u{feff}').lines().enumerate() {
            let line_no = i + 1;
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if !seen_header {
                seen_header = true;
                continue;
            }
            let Some((k, v)) = line.split_once(',') else {
                problems.push(Problem {
                    line: Some(line_no),
                    key: String::new(),
                    message: format!("expected `key,value`, found `{line}`"),
                });
                continue;
            };
            let v = v.trim().trim_matches('"');
            let value = match v.parse::<f64>() {
                Ok(x) => Value::Number(x),
                Err(_) => Value::Text(v.to_string()),
            };
            entries.push(Entry {
                key: k.trim().trim_matches('"').to_string(),
                value,
                line: Some(line_no),
            });
        }
        (entries, problems)
    }

    /// Validates the machine as a whole (what the schema of single keys cannot see).
    fn cross_checks(&self, lines: &dyn Fn(&str) -> Option<usize>) -> Vec<Problem> {
        let mut out = Vec::new();
        let m = &self.module;
        let mut push = |key: &str, message: String| {
            out.push(Problem {
                line: lines(key),
                key: key.to_string(),
                message,
            })
        };
        let lengths = [
            ("module.D1", m.dx1),
            ("module.D2", m.dx2),
            ("module.R1", m.r_big1),
            ("module.r1", m.r_small1),
            ("module.L1", m.l1),
            ("module.R2", m.r_big2),
            ("module.r4", m.r4),
            ("module.L2", m.l2),
            ("module.L3", m.l3),
        ];
        for (key, v) in lengths {
            if v.abs() > MAX_LENGTH_MM {
                push(
                    key,
                    format!(
                        "{v:e} mm is beyond {MAX_LENGTH_MM:e} mm: the forward kinematics' degree-8 polynomial in it would overflow"
                    ),
                );
            }
        }
        for (key, v) in [
            ("module.L1", m.l1),
            ("module.L2", m.l2),
            ("module.L3", m.l3),
        ] {
            if v.is_finite() && v.abs() < MIN_ROD_MM {
                push(
                    key,
                    format!(
                        "{v:e} mm is shorter than {MIN_ROD_MM} mm: machine lengths are in mm (a file in metres?), and the solvers resolve 1e-6 mm"
                    ),
                );
            }
        }
        // Relative to the machine's size (its longest rod), so that a machine and the same
        // machine scaled are accepted or refused alike.
        let same = SAME_LENGTH_REL * m.l1.abs().max(m.l2.abs()).max(m.l3.abs());
        if (m.dx1 - m.dx2).abs() <= same {
            push(
                "module.D2",
                format!(
                    "D2 - d2 must differ from D1 - d1 by more than {same:e} mm ({SAME_LENGTH_REL:e} of the longest rod): the forward kinematics eliminates xp between legs I and II"
                ),
            );
        }
        if (m.r_big1 - m.r_small1).abs() <= same {
            push(
                "module.r1",
                format!(
                    "r1 must differ from R1 by more than {same:e} mm ({SAME_LENGTH_REL:e} of the longest rod): leg I would be a parallelogram and the platform could not rotate"
                ),
            );
        }
        if m.l1 <= (m.r_big1 - m.r_small1).abs() {
            push(
                "module.L1",
                format!(
                    "L1 = {} mm is too short to reach: it must exceed |R1 - r1| = {} mm",
                    m.l1,
                    (m.r_big1 - m.r_small1).abs()
                ),
            );
        }
        let gap = m.r4 - m.r_big2;
        for (key, l) in [("module.L2", m.l2), ("module.L3", m.l3)] {
            if l <= gap {
                push(
                    key,
                    format!(
                        "{} = {l} mm is too short to reach: the slider and platform joints are at least r4 - R2 = {gap} mm apart, so the machine has no workspace",
                        &key[7..]
                    ),
                );
            }
        }
        if m.r_big1 <= m.r_small1 {
            push(
                "module.R1",
                format!(
                    "R1 = {} mm <= r1 = {} mm: R1 cos(alpha) > r1 never holds, the leg-I rods always cross",
                    m.r_big1, m.r_small1
                ),
            );
        }
        for j in 0..3 {
            if self.limits.rho_min[j] >= self.limits.rho_max[j] {
                push(
                    &format!("limits.rho{}_max", j + 1),
                    format!(
                        "rho{}_max = {} must be greater than rho{}_min = {}",
                        j + 1,
                        self.limits.rho_max[j],
                        j + 1,
                        self.limits.rho_min[j]
                    ),
                );
            }
        }
        if self.limits.theta1_min >= self.limits.theta1_max {
            push(
                "limits.theta1_max",
                "theta1_max must be greater than theta1_min".into(),
            );
        }
        for j in 0..3 {
            let stroke = self.limits.rho_max[j] - self.limits.rho_min[j];
            let zero = m.rho_zero[j];
            if zero.abs() > stroke {
                push(
                    &format!("zeros.rho{}", j + 1),
                    format!(
                        "a zero offset of {zero} mm is larger than slider {}'s stroke ({stroke} mm): a slider's zero is a small correction",
                        j + 1
                    ),
                );
            }
        }
        if self.table.y_t.abs() > MAX_LENGTH_MM {
            push(
                "table.y_t",
                format!("{:e} mm is beyond {MAX_LENGTH_MM:e} mm", self.table.y_t),
            );
        }
        out
    }

    /// The machine as a TOML file (degrees), suitable for `-m`.
    pub fn to_toml(&self) -> String {
        let m = &self.module;
        let l = &self.limits;
        let mut text = format!(
            "kind = \"verne\"\nname = {:?}\n\n[module]\nD1 = {}\nd1 = {:?}\nR1 = {}\nr1 = {}\nL1 = {}\nD2 = {}\nd2 = {:?}\nR2 = {}\nr4 = {}\nL2 = {}\nL3 = {}\n\n[limits]\nrho1_min = {}\nrho1_max = {}\nrho2_min = {}\nrho2_max = {}\nrho3_min = {}\nrho3_max = {}\nrod_tilt_max = {}\ntheta1_min = {}\ntheta1_max = {}\n\n[table]\nd_a = {}\nd_t = {}\n{}\n[tool]\nlength = {}\n\n{}\n{}",
            self.name,
            m.dx1 + m.d1,
            m.d1,
            m.r_big1,
            m.r_small1,
            m.l1,
            m.dx2 + m.d2,
            m.d2,
            m.r_big2,
            m.r4,
            m.l2,
            m.l3,
            l.rho_min[0],
            l.rho_max[0],
            l.rho_min[1],
            l.rho_max[1],
            l.rho_min[2],
            l.rho_max[2],
            l.rod_tilt_max.to_degrees(),
            l.theta1_min.to_degrees(),
            l.theta1_max.to_degrees(),
            self.table.d_a,
            self.table.d_t,
            // The optional keys only when they are not zero: a file without them reads as 0.
            if self.table.y_t != 0.0 {
                format!("y_t = {}\n", self.table.y_t)
            } else {
                String::new()
            },
            self.tool_length,
            self.drives.to_toml(),
            self.gcode.to_toml()
        );
        let (rz, tz) = (m.rho_zero, self.table.theta_zero);
        if self.has_zeros() {
            text.push_str(&format!(
                "\n[zeros]\nrho1 = {}\nrho2 = {}\nrho3 = {}\ntheta1 = {}\ntheta2 = {}\n",
                rz[0],
                rz[1],
                rz[2],
                tz[0].to_degrees(),
                tz[1].to_degrees()
            ));
        }
        text
    }
}

#[derive(Debug, Clone)]
enum Value {
    Number(f64),
    Text(String),
    Other(&'static str),
}

struct Entry {
    key: String,
    value: Value,
    line: Option<usize>,
}

fn toml_value(v: &toml::Value) -> Value {
    match v {
        toml::Value::Float(x) => Value::Number(*x),
        toml::Value::Integer(i) => Value::Number(*i as f64),
        toml::Value::String(s) => Value::Text(s.clone()),
        toml::Value::Boolean(_) => Value::Other("a boolean"),
        toml::Value::Datetime(_) => Value::Other("a date"),
        toml::Value::Array(_) => Value::Other("an array"),
        toml::Value::Table(_) => Value::Other("a table"),
    }
}

/// Turns a base's name into its text and a name for messages, or says why it cannot.
pub type BaseResolver<'a> = dyn Fn(&str) -> Result<(String, String), String> + 'a;

/// Most files in a chain of bases (a file, its base, the base's base, ...).
pub const MAX_BASE_DEPTH: usize = 8;

/// The entries of a machine file with its base's merged under them (see
/// [`Machine::from_str_on_base`]).
fn entries_over_base(
    text: &str,
    source: &str,
    resolve: Option<&BaseResolver<'_>>,
    depth: usize,
) -> Result<(Vec<Entry>, Vec<Problem>), MachineError> {
    let (mut entries, problems) = entries_of(text, source)?;
    let Some(i) = entries.iter().position(|e| e.key == "base") else {
        return Ok((entries, problems));
    };
    let e = entries.remove(i);
    // A base that cannot be used is the one problem reported: the keys it would have given
    // are not missing from this file.
    let fail = |message: String| MachineError {
        source: source.to_string(),
        problems: vec![Problem {
            line: e.line,
            key: "base".into(),
            message,
        }],
    };
    let Value::Text(name) = &e.value else {
        return Err(fail(
            "expected a string: \"verne\" or the path of a machine file".into(),
        ));
    };
    if depth + 1 >= MAX_BASE_DEPTH {
        return Err(fail(format!(
            "more than {MAX_BASE_DEPTH} files in the chain of bases (a cycle?)"
        )));
    }
    let resolved = match (name.as_str(), resolve) {
        ("verne", _) => Ok((
            super::DEFAULT_MACHINE_TOML.to_string(),
            "the embedded default machine".to_string(),
        )),
        (_, Some(r)) => r(name),
        (_, None) => Err(format!(
            "base `{name}` is not known here: \"verne\" (the embedded default), or a path read by the command line tool"
        )),
    };
    let (base_text, base_source) = resolved.map_err(fail)?;
    // The base's own errors name the base's file and line.
    let (base_entries, base_problems) =
        entries_over_base(&base_text, &base_source, resolve, depth + 1)?;
    if !base_problems.is_empty() {
        return Err(MachineError {
            source: base_source,
            problems: base_problems,
        });
    }
    // The base's keys (no line: they are not in this file), then this file's.
    let own: HashSet<String> = entries.iter().map(|e| e.key.clone()).collect();
    let mut merged: Vec<Entry> = base_entries
        .into_iter()
        .filter(|b| !own.contains(&b.key))
        .map(|b| Entry { line: None, ..b })
        .collect();
    merged.append(&mut entries);
    Ok((merged, problems))
}

/// The entries of a machine file in either format (the first non-comment line `key,value`
/// means CSV), and the problems found while reading them.
fn entries_of(text: &str, source: &str) -> Result<(Vec<Entry>, Vec<Problem>), MachineError> {
    let first = text
        .trim_start_matches('\u{feff}')
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'));
    match first {
        Some(l) if l.replace(' ', "").eq_ignore_ascii_case("key,value") => {
            Ok(Machine::csv_entries(text))
        }
        Some(l) if l.replace(' ', "").eq_ignore_ascii_case("key;value") => Err(MachineError {
            source: source.to_string(),
            problems: vec![Problem {
                line: text
                    .lines()
                    .position(|x| x.trim() == l)
                    .map(|i| i + 1),
                key: String::new(),
                message: "a key;value table: machine CSV files are comma-separated (`key,value`, then `module.R1,130`)".into(),
            }],
        }),
        _ => Machine::toml_entries(text, source),
    }
}

/// Sections that are not tables, or unknown sections, are reported once.
fn check_sections(table: &toml::Table, lines: &TomlLines) -> Vec<Problem> {
    let mut out = Vec::new();
    for section in [
        "module", "limits", "table", "tool", "drives", "verify", "gcode", "zeros",
    ] {
        if let Some(v) = table.get(section)
            && !v.is_table()
        {
            out.push(Problem {
                line: lines.get("", section),
                key: section.to_string(),
                message: format!("expected a [{section}] table"),
            });
        }
    }
    out
}

/// The 1-based line of every `key = ...` of a TOML text by (section, key), the first when a key
/// repeats: one pass over the text, so that a file of many keys is indexed in linear time.
struct TomlLines(HashMap<(String, String), usize>);

impl TomlLines {
    fn new(text: &str) -> TomlLines {
        let mut map = HashMap::new();
        let mut current = String::new();
        for (i, line) in text.lines().enumerate() {
            let t = line.trim();
            if let Some(rest) = t.strip_prefix('[') {
                // `[module] # a comment`: the name ends at the first `]`.
                current = rest.split(']').next().unwrap_or("").trim().to_string();
                // A nested table `[verify.sub]` is the key `sub` of `[verify]`, at this line.
                if let Some((outer, inner)) = current.rsplit_once('.') {
                    map.entry((outer.trim().to_string(), inner.trim().to_string()))
                        .or_insert(i + 1);
                }
                continue;
            }
            if t.contains('=') {
                let lhs = t.split('=').next().unwrap_or("").trim().trim_matches('"');
                map.entry((current.clone(), lhs.to_string()))
                    .or_insert(i + 1);
            }
        }
        TomlLines(map)
    }

    /// The line of `key` inside `[section]` (or at top level when `section` is empty).
    fn get(&self, section: &str, key: &str) -> Option<usize> {
        self.0.get(&(section.to_string(), key.to_string())).copied()
    }
}

fn finish(
    entries: Vec<Entry>,
    mut problems: Vec<Problem>,
    source: &str,
) -> Result<Machine, MachineError> {
    let line_of = |key: &str| entries.iter().find(|e| e.key == key).and_then(|e| e.line);
    let mut values = [f64::NAN; SCHEMA.len()];
    let mut optional = [0.0; OPTIONAL.len()];
    let mut kind_seen = false;
    let mut verify = Vec::new();
    let mut drives = Vec::new();
    let mut gcode = Vec::new();
    let mut name = String::from("unnamed");
    // Unknown and duplicated keys.
    let mut seen = HashSet::with_capacity(entries.len());
    for e in &entries {
        if !seen.insert(e.key.as_str()) {
            problems.push(Problem {
                line: e.line,
                key: e.key.clone(),
                message: "given twice".into(),
            });
            continue;
        }
        if e.key == "kind" {
            kind_seen = true;
            match &e.value {
                Value::Text(s) if s == "verne" => {}
                Value::Text(s) if s == "glider" => problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: "a glider machine file was given where a VERNE machine is expected"
                        .into(),
                }),
                _ => problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: "expected \"verne\"".into(),
                }),
            }
            continue;
        }
        if let Some(key) = e.key.strip_prefix("gcode.") {
            let value = match &e.value {
                Value::Number(x) => GcodeValue::Number(*x),
                Value::Text(s) => GcodeValue::Text(s.clone()),
                Value::Other(_) => GcodeValue::Other,
            };
            gcode.push((key.to_string(), value, e.line));
            continue;
        }
        if let Some(name) = e.key.strip_prefix("drives.") {
            match &e.value {
                Value::Number(x) => drives.push((name.to_string(), *x, e.line)),
                _ => problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: "expected a positive number (a drive limit)".into(),
                }),
            }
            continue;
        }
        if let Some(name) = e.key.strip_prefix("verify.") {
            match &e.value {
                Value::Number(x) if x.is_finite() => verify.push((name.to_string(), *x, e.line)),
                _ => problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: "expected a finite number (a verify threshold)".into(),
                }),
            }
            continue;
        }
        if e.key == "name" {
            match &e.value {
                Value::Text(s) => name = s.clone(),
                Value::Number(x) => name = x.to_string(),
                Value::Other(what) => problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: format!("expected a string, found {what}"),
                }),
            }
            continue;
        }
        // Required keys first, then the optional ones (their positions after SCHEMA's).
        let Some(pos) = SCHEMA
            .iter()
            .chain(OPTIONAL)
            .position(|(s, k, _, _)| format!("{s}.{k}") == e.key)
        else {
            let hint = SCHEMA
                .iter()
                .chain(OPTIONAL)
                .map(|(s, k, _, _)| format!("{s}.{k}"))
                .find(|full| full.eq_ignore_ascii_case(&e.key))
                .map(|full| format!(" (did you mean `{full}`?)"))
                .unwrap_or_default();
            let known: Vec<String> = TOP_LEVEL_KEYS
                .iter()
                .map(|k| k.to_string())
                .chain(
                    SCHEMA
                        .iter()
                        .chain(OPTIONAL)
                        .map(|(s, k, _, _)| format!("{s}.{k}")),
                )
                .collect();
            problems.push(Problem {
                line: e.line,
                key: e.key.clone(),
                message: format!("unknown key{hint}; known keys: {}", known.join(", ")),
            });
            continue;
        };
        let (_, _, check, meaning) = if pos < SCHEMA.len() {
            SCHEMA[pos]
        } else {
            OPTIONAL[pos - SCHEMA.len()]
        };
        let x = match &e.value {
            Value::Number(x) => *x,
            Value::Text(s) => {
                problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: format!("expected a number ({meaning}), found `{s}`"),
                });
                continue;
            }
            Value::Other(what) => {
                problems.push(Problem {
                    line: e.line,
                    key: e.key.clone(),
                    message: format!("expected a number ({meaning}), found {what}"),
                });
                continue;
            }
        };
        let bad = match check {
            _ if !x.is_finite() => Some("must be a finite number"),
            Check::Positive if x <= 0.0 => Some("must be a positive length"),
            Check::NonNegative if x < 0.0 => Some("must be a length >= 0"),
            Check::TiltDegrees if !(x > 0.0 && x <= 90.0) => Some("must be in (0, 90] degrees"),
            Check::AngleDegrees if !(-180.0..=180.0).contains(&x) => {
                Some("must be in [-180, 180] degrees")
            }
            _ => None,
        };
        if let Some(why) = bad {
            problems.push(Problem {
                line: e.line,
                key: e.key.clone(),
                message: format!("{why} ({meaning}), found {x}"),
            });
            continue;
        }
        if pos < SCHEMA.len() {
            values[pos] = x;
        } else {
            optional[pos - SCHEMA.len()] = x;
        }
    }
    let gcode = GcodeWords::from_entries(&gcode, &mut problems);
    let drives = Drives::from_entries(&drives, &mut problems);
    if !kind_seen {
        problems.push(Problem {
            line: None,
            key: "kind".into(),
            message: "missing (expected kind = \"verne\")".into(),
        });
    }
    for (pos, (s, k, _, meaning)) in SCHEMA.iter().enumerate() {
        let key = format!("{s}.{k}");
        if values[pos].is_nan() && !entries.iter().any(|e| e.key == key) {
            problems.push(Problem {
                line: None,
                key,
                message: format!("missing required key ({meaning})"),
            });
        }
    }
    problems.sort_by_key(|p| p.line.unwrap_or(usize::MAX));
    if !problems.is_empty() {
        return Err(MachineError {
            source: source.to_string(),
            problems,
        });
    }
    let v = |i: usize| values[i];
    let machine = Machine {
        name,
        module: ModuleGeometry {
            dx1: v(0) - v(1),
            r_big1: v(2),
            r_small1: v(3),
            l1: v(4),
            dx2: v(5) - v(6),
            r_big2: v(7),
            r4: v(8),
            l2: v(9),
            l3: v(10),
            d1: v(1),
            d2: v(6),
            rho_zero: [optional[0], optional[1], optional[2]],
        },
        limits: Limits {
            rho_min: [v(11), v(13), v(15)],
            rho_max: [v(12), v(14), v(16)],
            rod_tilt_max: v(17).to_radians(),
            cos_rod_tilt_max: (v(17).to_radians() + crate::tolerance::LIMIT_SLACK).cos(),
            theta1_min: v(18).to_radians(),
            theta1_max: v(19).to_radians(),
        },
        table: TableGeometry {
            d_a: v(20),
            d_t: v(21),
            y_t: optional[5],
            theta_zero: [optional[3].to_radians(), optional[4].to_radians()],
        },
        tool_length: v(22),
        drives,
        verify,
        gcode,
    };
    let cross = machine.cross_checks(&line_of);
    if cross.is_empty() {
        Ok(machine)
    } else {
        Err(MachineError {
            source: source.to_string(),
            problems: cross,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::DEFAULT_MACHINE_TOML;

    #[test]
    fn a_file_on_a_base_gives_only_what_it_changes() {
        let m = Machine::from_toml_str(
            "base = \"verne\"\nname = \"long\"\n[tool]\nlength = 120\n",
            "long.toml",
        )
        .unwrap();
        let d = Machine::default_verne();
        assert_eq!((m.name.as_str(), m.tool_length), ("long", 120.0));
        assert_eq!((m.module, m.limits, m.table), (d.module, d.limits, d.table));
        let csv =
            Machine::from_csv_str("key,value\nbase,verne\nlimits.rho1_max,900\n", "c.csv").unwrap();
        assert_eq!(csv.limits.rho_max[0], 900.0);
        // A key of the file keeps its line; an unknown base is the one problem.
        let e = Machine::from_toml_str("base = \"verne\"\n[module]\nL1 = -1\n", "f").unwrap_err();
        assert_eq!((e.problems.len(), e.problems[0].line), (1, Some(3)));
        let e = Machine::from_toml_str("base = \"shop.toml\"\n", "f").unwrap_err();
        assert_eq!(e.problems.len(), 1);
        assert!(e.problems[0].message.contains("not known here"), "{e}");
        // Chains resolve through the caller, and a cycle stops.
        let resolve = |name: &str| -> Result<(String, String), String> {
            match name {
                "shop" => Ok((
                    "base = \"verne\"\n[tool]\nlength = 80\n".into(),
                    "shop".into(),
                )),
                "loop" => Ok(("base = \"loop\"\n".into(), "loop".into())),
                _ => Err(format!("no {name}")),
            }
        };
        let m = Machine::from_str_on_base("base = \"shop\"\n", "job", Some(&resolve)).unwrap();
        assert_eq!(m.tool_length, 80.0);
        let e = Machine::from_str_on_base("base = \"loop\"\n", "job", Some(&resolve)).unwrap_err();
        assert!(e.to_string().contains("chain of bases"), "{e}");
    }

    #[test]
    fn default_machine_matches_reference_geometry() {
        let m = Machine::default_verne();
        assert_eq!(m.module.dx1, -320.0);
        assert_eq!(m.module.r_big1, 130.0);
        assert_eq!(m.module.r_small1, 80.0);
        assert_eq!(m.module.l1, 850.0);
        assert_eq!(m.module.dx2, 240.74);
        assert_eq!(m.module.r_big2, 190.11);
        assert_eq!(m.module.r4, 565.37);
        assert_eq!(m.module.l2, 950.30);
        assert_eq!(m.module.l3, 950.46);
        assert_eq!(m.tool_length, 50.0);
        assert!((m.limits.rod_tilt_max - 60f64.to_radians()).abs() < 1e-15);
    }

    #[test]
    fn toml_round_trips_through_to_toml() {
        let m = Machine::default_verne();
        let again = Machine::from_toml_str(&m.to_toml(), "x").unwrap();
        assert_eq!(m, again);
    }

    #[test]
    fn csv_and_toml_agree() {
        let m = Machine::default_verne();
        let mut csv = String::from("key,value\nkind,verne\nname,VERNE\n");
        let table: toml::Table = DEFAULT_MACHINE_TOML.parse().unwrap();
        for (s, v) in &table {
            if let toml::Value::Table(t) = v {
                for (k, x) in t {
                    csv.push_str(&format!("{s}.{k},{x}\n"));
                }
            }
        }
        assert_eq!(Machine::from_str_auto(&csv, "m.csv").unwrap(), m);
    }

    #[test]
    fn every_problem_is_reported_with_its_line() {
        let text = DEFAULT_MACHINE_TOML
            .replace("R1 = 130.0", "R1 = -130.0")
            .replace("L2 = 950.30", "L2 = \"long\"")
            .replace("length = 50.0", "length = 50.0\nlenght = 3");
        let text = text.replace(
            "r4 = 565.37   # half-distance between the leg-II and leg-III sliders\n",
            "",
        );
        let err = Machine::from_toml_str(&text, "bad.toml").unwrap_err();
        let keys: Vec<&str> = err.problems.iter().map(|p| p.key.as_str()).collect();
        assert!(keys.contains(&"module.R1"), "{err}");
        assert!(keys.contains(&"module.L2"), "{err}");
        assert!(keys.contains(&"tool.lenght"), "{err}");
        assert!(keys.contains(&"module.r4"), "{err}");
        let r1 = err.problems.iter().find(|p| p.key == "module.R1").unwrap();
        let expected_line = text.lines().position(|l| l.starts_with("R1 =")).unwrap() + 1;
        assert_eq!(r1.line, Some(expected_line));
        assert!(err.to_string().contains("bad.toml:"));
    }

    /// The tool tip is at distance Delta >= 0 from P along the platform's z axis (eq. (27),
    /// AIM 2007): a negative length is refused at its line, zero is read.
    #[test]
    fn a_negative_tool_length_is_refused_at_its_line() {
        for bad in ["-5.0", "-1e-9", "-0.5e3"] {
            let text = DEFAULT_MACHINE_TOML.replace("length = 50.0", &format!("length = {bad}"));
            let err = Machine::from_toml_str(&text, "t.toml").unwrap_err();
            let line = text
                .lines()
                .position(|l| l.starts_with("length ="))
                .unwrap()
                + 1;
            assert_eq!(err.problems.len(), 1, "{err}");
            let p = &err.problems[0];
            assert_eq!(
                (p.key.as_str(), p.line),
                ("tool.length", Some(line)),
                "{err}"
            );
            assert!(
                err.to_string()
                    .contains(&format!("t.toml:{line}: tool.length")),
                "{err}"
            );
        }
        let text = DEFAULT_MACHINE_TOML.replace("length = 50.0", "length = 0.0");
        assert_eq!(Machine::from_toml_str(&text, "t").unwrap().tool_length, 0.0);
    }

    #[test]
    fn crossing_rods_and_short_rods_are_rejected() {
        let text = DEFAULT_MACHINE_TOML.replace("r1 = 80.0", "r1 = 200.0");
        let err = Machine::from_toml_str(&text, "m").unwrap_err();
        assert!(err.to_string().contains("always cross"), "{err}");
        let text = DEFAULT_MACHINE_TOML.replace("L1 = 850.0", "L1 = 40.0");
        let err = Machine::from_toml_str(&text, "m").unwrap_err();
        assert!(err.to_string().contains("too short"), "{err}");
    }

    /// The default machine scaled by 1e-2 to 1e4, every length with it: r1 within 1e-12 of R1
    /// (relative), or D2 - d2 within 1e-12 times the longest rod of D1 - d1, is refused at every
    /// scale; r1 2e-7 of R1 from it, or D2 - d2 2e-8 of the longest rod from D1 - d1, accepted at
    /// every scale (an absolute 1e-6 mm accepted the first two at 1e4 and refused the others at
    /// 1e-2).
    #[test]
    fn the_same_machine_scaled_is_accepted_or_refused_alike() {
        let scaled = |k: f64, r1_rel: f64, d2_rel: f64| {
            let mut m = Machine::default_verne().scaled(k);
            let g = &mut m.module;
            g.r_small1 = g.r_big1 * (1.0 - r1_rel);
            g.dx2 = g.dx1 + d2_rel * g.l1.max(g.l2).max(g.l3);
            Machine::from_toml_str(&m.to_toml(), "scaled")
        };
        for k in [1e-2, 1.0, 1e2, 1e4] {
            assert!(
                scaled(k, 2e-7, 2e-8).is_ok(),
                "{k}: {:?}",
                scaled(k, 2e-7, 2e-8)
            );
            let err = scaled(k, 1e-12, 2e-8).unwrap_err().to_string();
            assert!(
                err.contains("module.r1") && err.contains("r1 must differ from R1"),
                "{k}: {err}"
            );
            let err = scaled(k, 2e-7, 1e-12).unwrap_err().to_string();
            assert!(
                err.contains("module.D2") && err.contains("must differ from D1"),
                "{k}: {err}"
            );
        }
    }
}
