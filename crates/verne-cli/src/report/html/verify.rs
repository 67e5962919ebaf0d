//! The HTML report of `verne verify --html` (docs/verify.md): the verdict, the summary, the
//! findings at their lines, plots of what the checks measured along the program, and the
//! machine in 3D at any row. Fed as the run streams (each row's observation, each finding), in
//! memory bounded whatever the length of the program: the plots are decimated
//! ([`super::decimate`]), the 3D view keeps at most [`MAX_FRAMES`] rows evenly spread plus the
//! rows of the findings listed, and the list keeps the first [`MAX_LISTED`] findings and the
//! worst of each check.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fmt::Write as _;
use std::io::BufRead;
use std::path::Path;

use verne::spec::Machine;
use verne::verify::{Check, RowObservation, Summary, THRESHOLDS, Th, VerifyOptions, Violation};

use super::decimate::Decimator;
use super::{Page, escape, f32_array, json_num, json_opt, json_str, machine_json, u32_array};
use crate::report::verify::rounded_number;

const VERIFY_JS: &str = include_str!("../../../assets/report/verify.js");

/// Rows kept for the 3D view besides the findings' (evenly spread; every row when fewer).
pub const MAX_FRAMES: usize = 2048;
/// Findings listed in the report in row order (the worst of each check is listed too); the
/// others are counted (the `--report` CSV has them all).
pub const MAX_LISTED: usize = 500;
/// Characters of a source line shown with a finding.
const LINE_TEXT_MAX: usize = 160;

/// The series plotted, in the order of the data's arrays (angles in degrees).
pub const SERIES: [&str; 23] = [
    "rho1",
    "rho2",
    "rho3",
    "theta1",
    "theta2",
    "tip_error",
    "axis_error",
    "chord_error",
    "chord_axis",
    "lambda_max",
    "lambda_min",
    "parallel_margin",
    "rod_tilt",
    "v_rho1",
    "v_rho2",
    "v_rho3",
    "v_theta1",
    "v_theta2",
    "a_rho1",
    "a_rho2",
    "a_rho3",
    "a_theta1",
    "a_theta2",
];
const N: usize = SERIES.len();

/// What the 3D view needs of a row: the joints, the module's pose, the intended and the
/// achieved tip (workpiece frame); mm and degrees.
pub const CHANNELS: [&str; 15] = [
    "rho1", "rho2", "rho3", "theta1", "theta2", "px", "py", "pz", "alpha", "tip_x", "tip_y",
    "tip_z", "fk_x", "fk_y", "fk_z",
];
const C: usize = CHANNELS.len();

/// The kinds of x a row has: the joint table's `t`, and the segments' times summed.
const X_T: usize = 0;
const X_SUM: usize = 1;

/// Every threshold, in the order of [`THRESHOLDS`].
const ALL_TH: [Th; 17] = [
    Th::TipErrorMm,
    Th::AxisErrorDeg,
    Th::ChordErrorMm,
    Th::LambdaMin,
    Th::LambdaMax,
    Th::ParallelMarginMin,
    Th::RhoStepMm,
    Th::Theta1StepDeg,
    Th::Theta2StepDeg,
    Th::Theta2FlipTolDeg,
    Th::RhoVelocityMmS,
    Th::Theta1VelocityDegS,
    Th::Theta2VelocityDegS,
    Th::RhoAccelMmS2,
    Th::Theta1AccelDegS2,
    Th::Theta2AccelDegS2,
    Th::ChordAxisErrorDeg,
];

/// The checks that need a time (a `t` or `feed` column, or the path's feeds).
const TIMED_CHECKS: [Check; 2] = [Check::Velocity, Check::Acceleration];
/// The checks of a segment between two rows.
const SEGMENT_CHECKS: [Check; 7] = [
    Check::ChordError,
    Check::ChordAxis,
    Check::Motion,
    Check::JointJump,
    Check::Theta2Flip,
    Check::Velocity,
    Check::Acceleration,
];

/// Whether a check ran, for the verdict: a check that could not run is not clean.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Clean,
    Found(u64),
    NotChecked(&'static str),
}

/// Each check's status in a run.
pub fn statuses(summary: &Summary) -> Vec<(Check, Status)> {
    summary
        .checks
        .iter()
        .map(|(c, st)| {
            let status = if st.count > 0 {
                Status::Found(st.count)
            } else if summary.segments == 0 && SEGMENT_CHECKS.contains(c) {
                Status::NotChecked("no segment between two usable rows was checked")
            } else if !summary.timed && TIMED_CHECKS.contains(c) {
                Status::NotChecked(
                    "no time: the joint table has no t or feed column and the path gives no feed",
                )
            } else {
                Status::Clean
            };
            (*c, status)
        })
        .collect()
}

/// The verdict in words: clean, or N findings in K checks; and every check not checked.
pub fn verdict(summary: &Summary) -> (bool, String) {
    let st = statuses(summary);
    let found: Vec<&Check> = st
        .iter()
        .filter(|(_, s)| matches!(s, Status::Found(_)))
        .map(|(c, _)| c)
        .collect();
    let mut text = if found.is_empty() {
        format!(
            "Clean: no finding in {} rows and {} segments",
            summary.rows, summary.segments
        )
    } else {
        format!(
            "{} finding{} in {} check{} ({})",
            summary.violations(),
            if summary.violations() == 1 { "" } else { "s" },
            found.len(),
            if found.len() == 1 { "" } else { "s" },
            found
                .iter()
                .map(|c| c.code())
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let mut not: Vec<(&str, &str)> = Vec::new();
    for (c, s) in &st {
        if let Status::NotChecked(why) = s {
            not.push((c.code(), why));
        }
    }
    let mut whys: Vec<&str> = not.iter().map(|(_, w)| *w).collect();
    whys.dedup();
    for why in whys {
        let names: Vec<&str> = not
            .iter()
            .filter(|(_, w)| *w == why)
            .map(|(n, _)| *n)
            .collect();
        let _ = write!(text, "; not checked: {} ({why})", names.join(", "));
    }
    (found.is_empty(), text)
}

/// A row kept for the 3D view.
#[derive(Debug, Clone)]
struct Frame {
    seq: u64,
    label: String,
    joints_line: u64,
    path_line: Option<u64>,
    x: [f64; 2],
    ch: [f32; C],
}

/// A finding kept for the list, with the row it is drawn at.
#[derive(Debug, Clone)]
struct Listed {
    seq: u64,
    x: [f64; 2],
    v: Violation,
}

/// The inputs, as the report names them.
#[derive(Debug, Clone)]
pub struct Inputs<'a> {
    pub joints: &'a Path,
    pub path: &'a Path,
    /// The joints are a recording: its path rows are the nearest points, not lines of the
    /// path file.
    pub recording: bool,
    pub machine: &'a str,
}

/// The report, fed as the run streams.
pub struct VerifyHtml {
    plot: Decimator<N, 2>,
    stride: u64,
    frames: Vec<Frame>,
    pinned: BTreeMap<u64, Frame>,
    /// The last two rows seen: a finding is at one of them.
    recent: [Option<Frame>; 2],
    listed: Vec<Listed>,
    worst: HashMap<&'static str, Listed>,
    total: u64,
    /// Timing: every row has a `t`, never decreasing; every segment after the first row is timed.
    all_t: bool,
    t_monotone: bool,
    all_dt: bool,
    last_t: f64,
    sum_t: f64,
    /// The largest distance of an intended tip from the table's axis (mm).
    reach: f64,
}

impl Default for VerifyHtml {
    fn default() -> Self {
        VerifyHtml {
            plot: Decimator::default(),
            stride: 1,
            frames: Vec::new(),
            pinned: BTreeMap::new(),
            recent: [None, None],
            listed: Vec::new(),
            worst: HashMap::new(),
            total: 0,
            all_t: true,
            t_monotone: true,
            all_dt: true,
            last_t: f64::NEG_INFINITY,
            sum_t: 0.0,
            reach: 0.0,
        }
    }
}

fn check_bit(c: Check) -> u32 {
    1 << Check::ALL.iter().position(|k| *k == c).unwrap_or(0)
}

impl VerifyHtml {
    pub fn new() -> VerifyHtml {
        VerifyHtml::default()
    }

    /// A row, in order.
    pub fn observe(&mut self, o: &RowObservation) {
        let seq = self.plot.rows();
        let nan = f64::NAN;
        let q = o.joints;
        let t = q.and_then(|q| q.t);
        match t {
            Some(t) => {
                if t < self.last_t {
                    self.t_monotone = false;
                }
                self.last_t = t;
            }
            None => self.all_t = false,
        }
        let seg = o.segment;
        match seg.and_then(|s| s.dt) {
            Some(dt) => self.sum_t += dt,
            None if seq > 0 => self.all_dt = false,
            None => {}
        }
        let x = [t.unwrap_or(nan), self.sum_t];
        let mut v = [nan; N];
        if let Some(q) = q {
            v[0] = q.rho.x;
            v[1] = q.rho.y;
            v[2] = q.rho.z;
            v[3] = q.theta1.to_degrees();
            v[4] = q.theta2.to_degrees();
        }
        if let Some(p) = o.pose {
            v[5] = p.tip_error_mm;
            v[6] = p.axis_error_deg;
            v[9] = p.amplification[0];
            v[10] = p.amplification[2];
            v[11] = p.parallel_margin;
            v[12] = p.rod_tilt_deg;
        }
        if let Some(s) = seg {
            v[7] = s.chord_error_mm.unwrap_or(nan);
            v[8] = s.chord_axis_deg.unwrap_or(nan);
            let unit = |i: usize, r: f64| if i < 3 { r } else { r.to_degrees() };
            if let Some(r) = s.rates {
                for i in 0..5 {
                    v[13 + i] = unit(i, r[i]);
                }
            }
            if let Some(a) = s.acceleration {
                for i in 0..5 {
                    v[18 + i] = unit(i, a[i]);
                }
            }
        }
        self.plot.push(x, &v);
        let mut ch = [f32::NAN; C];
        for i in 0..5 {
            ch[i] = v[i] as f32;
        }
        if let Some(p) = o.pose {
            ch[5] = p.module.p.x as f32;
            ch[6] = p.module.p.y as f32;
            ch[7] = p.module.p.z as f32;
            ch[8] = p.module.alpha.to_degrees() as f32;
            ch[12] = p.tip.x as f32;
            ch[13] = p.tip.y as f32;
            ch[14] = p.tip.z as f32;
        }
        if let Some(i) = o.intended {
            ch[9] = i.tip.x as f32;
            ch[10] = i.tip.y as f32;
            ch[11] = i.tip.z as f32;
            self.reach = self.reach.max(i.tip.x.hypot(i.tip.y));
        }
        let frame = Frame {
            seq,
            label: o.label.clone(),
            joints_line: o.joints_line,
            path_line: o.path_line,
            x,
            ch,
        };
        if seq % self.stride == 0 {
            self.frames.push(frame.clone());
            if self.frames.len() > MAX_FRAMES {
                self.stride *= 2;
                let s = self.stride;
                self.frames.retain(|f| f.seq % s == 0);
            }
        }
        self.recent = [Some(frame), self.recent[0].take()];
    }

    /// A finding, in order (after its row's observation).
    pub fn finding(&mut self, v: &Violation) {
        self.total += 1;
        let at = self
            .recent
            .iter()
            .flatten()
            .find(|f| Some(f.joints_line) == v.joints_line && f.label == v.row)
            .or(self.recent[0].as_ref())
            .cloned();
        let Some(frame) = at else {
            return;
        };
        self.plot.mark(frame.seq, check_bit(v.check));
        let item = Listed {
            seq: frame.seq,
            x: frame.x,
            v: v.clone(),
        };
        let code = v.check.code();
        let mut pin = false;
        if self.listed.len() < MAX_LISTED {
            self.listed.push(item.clone());
            pin = true;
        }
        let worse = self
            .worst
            .get(code)
            .is_none_or(|w| v.severity >= w.v.severity);
        if worse {
            if let Some(old) = self.worst.insert(code, item) {
                self.unpin(old.seq);
            }
            pin = true;
        }
        if pin {
            self.pinned.entry(frame.seq).or_insert(frame);
        }
    }

    /// Drops a pinned row no listed finding needs.
    fn unpin(&mut self, seq: u64) {
        let needed =
            self.listed.iter().any(|l| l.seq == seq) || self.worst.values().any(|l| l.seq == seq);
        if !needed {
            self.pinned.remove(&seq);
        }
    }

    /// The x axis: the joint table's time when every row has one and it never decreases, else
    /// the segments' times summed when every segment is timed, else the row.
    fn x_axis(&self, summary: &Summary) -> Option<usize> {
        if !summary.timed || summary.rows == 0 {
            None
        } else if self.all_t && self.t_monotone {
            Some(X_T)
        } else if self.all_dt {
            Some(X_SUM)
        } else {
            None
        }
    }

    /// The page.
    pub fn render(
        self,
        machine: &Machine,
        opt: &VerifyOptions,
        summary: &Summary,
        inputs: &Inputs,
        report_path: &Path,
    ) -> String {
        let axis = self.x_axis(summary);
        let x_of = |row: u64, x: &[f64; 2]| axis.map_or(row as f64 + 1.0, |k| x[k]);
        // The findings listed: the first ones and each check's worst, in row order.
        let mut listed = self.listed.clone();
        for w in self.worst.values() {
            let known = listed
                .iter()
                .any(|l| l.seq == w.seq && l.v.check == w.v.check && l.v.detail == w.v.detail);
            if !known {
                listed.push(w.clone());
            }
        }
        listed.sort_by_key(|l| l.seq);
        // The rows of the 3D view: evenly spread, and every listed finding's.
        let mut frames: BTreeMap<u64, &Frame> = self.frames.iter().map(|f| (f.seq, f)).collect();
        for (seq, f) in &self.pinned {
            frames.insert(*seq, f);
        }
        let frames: Vec<&Frame> = frames.into_values().collect();
        let frame_of = |seq: u64| frames.iter().position(|f| f.seq == seq);
        // The source lines of the listed findings.
        let joints_lines: BTreeSet<u64> = listed.iter().filter_map(|l| l.v.joints_line).collect();
        let path_lines: BTreeSet<u64> = if inputs.recording {
            BTreeSet::new()
        } else {
            listed.iter().filter_map(|l| l.v.path_line).collect()
        };
        let joints_text = source_lines(inputs.joints, &joints_lines);
        let path_text = source_lines(inputs.path, &path_lines);
        let (clean, verdict_text) = verdict(summary);
        let title = format!(
            "verne verify: {} against {}",
            inputs.joints.display(),
            inputs.path.display()
        );
        let mut d = String::with_capacity(1 << 20);
        let _ = write!(
            d,
            "{{\"kind\":\"verify\",\"version\":{},\"title\":{},\"clean\":{},\"verdict\":{},",
            json_str(env!("CARGO_PKG_VERSION")),
            json_str(&title),
            clean,
            json_str(&verdict_text)
        );
        let file = |p: &Path, lines: bool| {
            format!(
                "{{\"name\":{},\"href\":{},\"lines\":{}}}",
                json_str(&p.display().to_string()),
                json_str(&href(report_path, p)),
                lines
            )
        };
        let _ = write!(
            d,
            "\"inputs\":{{\"joints\":{},\"path\":{},\"recording\":{},\"machine\":{}}},",
            file(inputs.joints, true),
            file(inputs.path, !inputs.recording),
            inputs.recording,
            json_str(inputs.machine)
        );
        let _ = write!(d, "\"machine\":{},", machine_json(machine, opt.tool_length));
        d.push_str("\"thresholds\":{");
        for (k, t) in THRESHOLDS.iter().enumerate() {
            if k > 0 {
                d.push(',');
            }
            let _ = write!(
                d,
                "{}:{{\"value\":{},\"unit\":{},\"default\":{}}}",
                json_str(t.name),
                json_num(opt.thresholds.get(ALL_TH[k])),
                json_str(t.unit),
                json_num(t.default)
            );
        }
        d.push_str("},");
        // The summary.
        let _ = write!(
            d,
            "\"summary\":{{\"rows\":{},\"segments\":{},\"skipped\":{},\"timed\":{},\"violations\":{},\"checks\":[",
            summary.rows,
            summary.segments,
            summary.segments_skipped,
            summary.timed,
            summary.violations()
        );
        for (k, ((c, st), (_, status))) in summary.checks.iter().zip(statuses(summary)).enumerate()
        {
            if k > 0 {
                d.push(',');
            }
            let (status, why) = match status {
                Status::Clean => ("clean", ""),
                Status::Found(_) => ("found", ""),
                Status::NotChecked(why) => ("not_checked", why),
            };
            let worst_finding = self.worst.get(c.code()).and_then(|w| {
                listed.iter().position(|l| {
                    l.seq == w.seq && l.v.check == w.v.check && l.v.detail == w.v.detail
                })
            });
            let _ = write!(
                d,
                "{{\"code\":{},\"count\":{},\"status\":{},\"why\":{},\"finding\":{}",
                json_str(c.code()),
                st.count,
                json_str(status),
                json_str(why),
                worst_finding.map_or("null".into(), |i| i.to_string())
            );
            match &st.worst {
                Some(w) => {
                    let _ = write!(
                        d,
                        ",\"worst\":{},\"limit\":{},\"row\":{},\"detail\":{}}}",
                        json_num(w.value),
                        json_num(w.limit),
                        json_str(&w.row),
                        json_str(&w.detail)
                    );
                }
                None => d.push_str(",\"worst\":null,\"limit\":null,\"row\":null,\"detail\":null}"),
            }
        }
        d.push_str("]},");
        let _ = write!(
            d,
            "\"checks\":[{}],",
            Check::ALL
                .iter()
                .map(|c| json_str(c.code()))
                .collect::<Vec<_>>()
                .join(",")
        );
        let _ = write!(
            d,
            "\"x\":{{\"kind\":{},\"label\":{}}},",
            json_str(match axis {
                None => "row",
                Some(_) => "time",
            }),
            json_str(match axis {
                None => "row",
                Some(X_T) => "t (s)",
                Some(_) => "time (s, segment times summed)",
            })
        );
        // The plots.
        let p = self.plot.points();
        let _ = write!(
            d,
            "\"plot\":{{\"n\":{},\"width\":{},\"x\":{},\"row\":{},\"marks\":{},\"series\":{{",
            p.row.len(),
            p.width,
            f32_array(
                p.row
                    .iter()
                    .enumerate()
                    .map(|(i, r)| x_of(*r, &[p.x[0][i], p.x[1][i]]))
            ),
            u32_array(p.row.iter().map(|r| r + 1)),
            u32_array(p.marks.iter().map(|m| u64::from(*m)))
        );
        for (k, name) in SERIES.iter().enumerate() {
            if k > 0 {
                d.push(',');
            }
            let _ = write!(
                d,
                "{}:{}",
                json_str(name),
                f32_array(p.series[k].iter().copied())
            );
        }
        d.push_str("}},");
        // The 3D view's rows.
        let plain_labels = frames.iter().all(|f| f.label == (f.seq + 1).to_string());
        let _ = write!(
            d,
            "\"frames\":{{\"n\":{},\"stride\":{},\"channels\":[{}],\"row\":{},\"x\":{},\"jl\":{},\"pl\":{},\"ch\":{},\"labels\":",
            frames.len(),
            self.stride,
            CHANNELS
                .iter()
                .map(|c| json_str(c))
                .collect::<Vec<_>>()
                .join(","),
            u32_array(frames.iter().map(|f| f.seq + 1)),
            f32_array(frames.iter().map(|f| x_of(f.seq, &f.x))),
            u32_array(frames.iter().map(|f| f.joints_line)),
            u32_array(frames.iter().map(|f| if inputs.recording {
                0
            } else {
                f.path_line.unwrap_or(0)
            })),
            f32_array(frames.iter().flat_map(|f| f.ch.map(f64::from)))
        );
        if plain_labels {
            d.push_str("null");
        } else {
            d.push('[');
            for (k, f) in frames.iter().enumerate() {
                if k > 0 {
                    d.push(',');
                }
                d.push_str(&json_str(&f.label));
            }
            d.push(']');
        }
        let _ = write!(d, ",\"reach\":{}}},", json_num(self.reach));
        // The findings listed.
        let _ = write!(d, "\"findings_total\":{},\"findings\":[", self.total);
        for (k, l) in listed.iter().enumerate() {
            if k > 0 {
                d.push(',');
            }
            let v = &l.v;
            let pl = if inputs.recording { None } else { v.path_line };
            let _ = write!(
                d,
                "{{\"row\":{},\"frame\":{},\"x\":{},\"check\":{},\"value\":{},\"limit\":{},\"detail\":{},\"jl\":{},\"pl\":{},\"jt\":{},\"pt\":{}}}",
                json_str(&v.row),
                frame_of(l.seq).map_or("null".into(), |i| i.to_string()),
                json_num(x_of(l.seq, &l.x)),
                json_str(v.check.code()),
                json_num(v.value),
                json_num(v.limit),
                json_str(&v.detail),
                json_opt(v.joints_line.map(|x| x as f64)),
                json_opt(pl.map(|x| x as f64)),
                v.joints_line
                    .and_then(|n| joints_text.get(&n))
                    .map_or("null".into(), |t| json_str(t)),
                pl.and_then(|n| path_text.get(&n))
                    .map_or("null".into(), |t| json_str(t)),
            );
        }
        d.push_str("]}");
        let body = body(&title, clean, &verdict_text, summary, inputs);
        Page {
            title: &title,
            body: &body,
            data: &d,
            plots: true,
            script: VERIFY_JS,
        }
        .render()
    }
}

/// The page's frame: the verdict and the summary are written here (they read without the
/// script); the script fills the findings, the 3D view and the plots.
fn body(title: &str, clean: bool, verdict: &str, summary: &Summary, inputs: &Inputs) -> String {
    let mut b = String::new();
    let _ = writeln!(
        b,
        "<header><h1>{}</h1><p class=\"meta\">machine {} &middot; {} rows, {} segments checked, {} skipped next to a failed row &middot; verne {}</p>\
         <p id=\"verdict\" class=\"verdict {}\">{}</p></header>",
        escape(title),
        escape(inputs.machine),
        summary.rows,
        summary.segments,
        summary.segments_skipped,
        env!("CARGO_PKG_VERSION"),
        if clean { "clean" } else { "found" },
        escape(verdict)
    );
    b.push_str(
        "<section id=\"summary\"><h2>Checks</h2><table class=\"checks\"><thead><tr><th>check</th><th>result</th>\
         <th>worst</th><th>limit</th><th>row</th><th>detail of the worst</th></tr></thead><tbody>\n",
    );
    for ((c, st), (_, status)) in summary.checks.iter().zip(statuses(summary)) {
        let (class, result) = match &status {
            Status::Clean => ("clean", "clean".to_string()),
            Status::Found(n) => (
                "found",
                format!("{n} finding{}", if *n == 1 { "" } else { "s" }),
            ),
            Status::NotChecked(why) => ("not-checked", format!("not checked: {why}")),
        };
        let (worst, limit, row, detail) = match (&st.worst, &status) {
            (_, Status::NotChecked(_)) | (None, _) => Default::default(),
            (Some(w), _) => (
                rounded_number(w.value, 6),
                rounded_number(w.limit, 6),
                w.row.clone(),
                w.detail.clone(),
            ),
        };
        let _ = writeln!(
            b,
            "<tr class=\"{class}\" data-check=\"{}\"><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td></tr>",
            c.code(),
            c.code(),
            escape(&result),
            escape(&worst),
            escape(&limit),
            escape(&row),
            escape(&detail)
        );
    }
    b.push_str("</tbody></table></section>\n");
    b.push_str(
        "<section id=\"machine\"><h2>The machine along the program</h2><div class=\"viewwrap\">\
         <div class=\"view\"><canvas id=\"view3d\" width=\"720\" height=\"600\"></canvas>\
         <div class=\"controls\"><button id=\"prev\" title=\"previous row (left arrow)\">&#9664;</button>\
         <input id=\"scrub\" type=\"range\" min=\"0\" max=\"0\" value=\"0\" aria-label=\"row\">\
         <button id=\"next\" title=\"next row (right arrow)\">&#9654;</button><button id=\"play\">play</button>\
         <label title=\"follow the tool tip, the part's path around it\"><input id=\"closeup\" type=\"checkbox\"> close-up</label></div></div>\
         <div class=\"side\"><div id=\"rowinfo\" class=\"rowinfo\"></div>\
         <p class=\"hint\">Drag the view to turn it, wheel to zoom, double-click to reset. The slider, the arrow keys, \
         a click on a finding or on a plot move the machine to a row. Blue: the intended tip path on the table \
         (darker up to this row) and the intended tip at this row; orange: the tip of the joints; red: the tool tip.</p>\
         <p class=\"legend\"><span style=\"color:#1f77b4\">&#9632; leg I (slider 1, two rods)</span> \
         <span style=\"color:#d62728\">&#9632; leg II (slider 2)</span> <span style=\"color:#2ca02c\">&#9632; leg III (slider 3)</span></p></div></div></section>\n\
         <section id=\"findings-section\"><h2 id=\"findings-title\">Findings</h2><div class=\"scroll\"><table id=\"findings\"><thead><tr>\
         <th>row</th><th>check</th><th>value</th><th>limit</th><th>detail</th><th>joint program</th><th>intended path</th></tr></thead>\
         <tbody></tbody></table></div></section>\n\
         <section id=\"plots\"><h2>Along the program</h2><p id=\"plots-note\" class=\"hint\"></p><div id=\"charts\"></div></section>\n\
         <noscript><p>The findings, the 3D view and the plots need JavaScript; the verdict and the checks above do not.</p></noscript>\n",
    );
    b
}

/// The text of `lines` (1-based) of a file, each cut to [`LINE_TEXT_MAX`] characters; nothing
/// for a file that cannot be read again (the report is written all the same).
fn source_lines(path: &Path, lines: &BTreeSet<u64>) -> HashMap<u64, String> {
    let mut out = HashMap::new();
    let Some(&last) = lines.iter().next_back() else {
        return out;
    };
    let Ok(f) = std::fs::File::open(path) else {
        return out;
    };
    let mut r = std::io::BufReader::new(f);
    let mut buf = Vec::new();
    let mut n = 0u64;
    while n < last {
        buf.clear();
        match r.read_until(b'\n', &mut buf) {
            Ok(0) | Err(_) => break,
            Ok(_) => n += 1,
        }
        if lines.contains(&n) {
            let text = String::from_utf8_lossy(&buf);
            let text = text.trim_end_matches(['\n', '\r']);
            let mut cut: String = text.chars().take(LINE_TEXT_MAX).collect();
            if cut.len() < text.len() {
                cut.push_str(" ...");
            }
            out.insert(n, cut);
        }
    }
    out
}

/// The link from the report to an input: relative to the report's folder when both resolve,
/// else the input's absolute `file:` URL.
fn href(report: &Path, input: &Path) -> String {
    let dir = report
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let (Ok(from), Ok(to)) = (dir.canonicalize(), input.canonicalize()) else {
        return String::new();
    };
    let (a, b): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let rel = if common > 1 {
        let mut parts: Vec<String> = vec!["..".into(); a.len() - common];
        parts.extend(
            b[common..]
                .iter()
                .map(|c| c.as_os_str().to_string_lossy().into_owned()),
        );
        parts.join("/")
    } else {
        format!("file://{}", to.display())
    };
    percent_encode(&rel)
}

/// A path as a URL's: every byte but the unreserved characters, `/`, `:` and `.` escaped.
fn percent_encode(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/:".contains(&b) {
            out.push(b as char);
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

/// The thresholds of a run, for the test that [`ALL_TH`] follows [`THRESHOLDS`].
#[cfg(test)]
fn by_name(t: &verne::verify::Thresholds, name: &str) -> f64 {
    let k = THRESHOLDS.iter().position(|s| s.name == name).unwrap();
    t.get(ALL_TH[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ALL_TH[k]` is the threshold named `THRESHOLDS[k].name`: a set value reads back by name.
    #[test]
    fn the_thresholds_are_listed_in_order() {
        for (k, spec) in THRESHOLDS.iter().enumerate() {
            assert_eq!(ALL_TH[k] as usize, k, "{}", spec.name);
            let mut t = verne::verify::Thresholds::default();
            let v = if spec.name == "parallel_margin_min" {
                0.5
            } else if spec.name == "theta2_flip_tol_deg" {
                45.0
            } else {
                1234.5
            };
            t.set(spec.name, v).unwrap();
            assert_eq!(by_name(&t, spec.name), v);
        }
    }

    /// A million rows, a finding every thousand rows and a single-row tip error spike among
    /// rows without one: the page stays under 1 MB, the spike is in the plot at its value, the
    /// 3D view holds at most MAX_FRAMES rows plus the listed findings', each listed finding at
    /// its own row, and the first MAX_LISTED are listed with each check's worst.
    #[test]
    fn a_million_rows_make_a_bounded_page_that_keeps_its_peaks() {
        use nalgebra::Vector3;
        use verne::parallel_module::equations::ModulePose;
        use verne::verify::{
            CheckStats, Joints, PathPoint, PoseObservation, SegmentObservation, Summary,
        };
        let m = Machine::default_verne();
        let opt = VerifyOptions {
            thresholds: verne::verify::Thresholds::default(),
            tool_length: m.tool_length,
        };
        let n = 1_000_000u64;
        let spike = 654_321u64;
        let mut h = VerifyHtml::new();
        let mut found = 0u64;
        for k in 0..n {
            let s = k as f64 * 1e-3;
            let tip = Vector3::new(100.0 * s.cos(), 100.0 * s.sin(), 20.0);
            let o = RowObservation {
                label: (k + 1).to_string(),
                index: k + 1,
                joints_line: k + 2,
                path_line: Some(k + 2),
                joints: Some(Joints {
                    rho: Vector3::new(400.0, 350.0, 350.0 + s.sin()),
                    theta1: 0.1,
                    theta2: s,
                    t: Some(s),
                    feed: None,
                    duration: None,
                    rapid: false,
                }),
                intended: Some(PathPoint::new(tip, Vector3::z())),
                pose: Some(PoseObservation {
                    module: ModulePose {
                        p: Vector3::new(0.0, 0.0, 1150.0),
                        alpha: 0.0,
                    },
                    tip,
                    axis: Vector3::z(),
                    tip_error_mm: if k == spike { 7.5 } else { 1e-6 },
                    axis_error_deg: 1e-6,
                    rod_tilt_deg: 30.0,
                    amplification: [1.5, 1.0, 0.5],
                    parallel_margin: 0.3,
                }),
                segment: (k > 0).then_some(SegmentObservation {
                    dt: Some(1e-3),
                    rates: Some([0.0, 0.0, 1.0, 0.0, 1.0]),
                    acceleration: None,
                    chord_error_mm: Some(1e-4),
                    chord_axis_deg: Some(1e-5),
                }),
            };
            h.observe(&o);
            if k % 1000 == 999 || k == spike {
                let mut v = Violation {
                    row: o.label.clone(),
                    check: Check::TipError,
                    value: if k == spike { 7.5 } else { 0.01 },
                    limit: 0.005,
                    detail: String::new(),
                    severity: if k == spike { 1500.0 } else { 2.0 },
                    joints_line: Some(k + 2),
                    path_line: Some(k + 2),
                };
                if k != spike {
                    v.check = Check::JointJump;
                }
                h.finding(&v);
                found += 1;
            }
        }
        let summary = Summary {
            rows: n,
            segments: n - 1,
            segments_skipped: 0,
            timed: true,
            checks: Check::ALL
                .iter()
                .map(|c| (*c, CheckStats::default()))
                .collect(),
        };
        let inputs = Inputs {
            joints: Path::new("j.csv"),
            path: Path::new("p.csv"),
            recording: false,
            machine: "<default>",
        };
        assert_eq!(h.total, found);
        let frames = h.frames.len();
        assert!(frames <= MAX_FRAMES && frames > MAX_FRAMES / 2, "{frames}");
        let listed_rows: BTreeSet<u64> = h.listed.iter().map(|l| l.seq).collect();
        assert_eq!(h.listed.len(), MAX_LISTED);
        assert_eq!(h.worst["tip_error"].seq, spike);
        for seq in listed_rows.iter().chain([&spike]) {
            assert!(h.pinned.contains_key(seq), "row {seq} kept for the 3D view");
        }
        let points = h.plot.points();
        let k = points.series[5]
            .iter()
            .position(|v| *v == 7.5)
            .expect("the spike is plotted");
        // Two points a bucket: its first and its last row.
        let first = k - k % 2;
        assert!(points.row[first] <= spike && spike <= points.row[first + 1]);
        assert_ne!(points.marks[k] & check_bit(Check::TipError), 0);
        let page = h.render(&m, &opt, &summary, &inputs, Path::new("r.html"));
        assert!(page.len() < 1_000_000, "{} bytes", page.len());
    }

    #[test]
    fn links_are_relative_to_the_report_and_escaped() {
        let dir = std::env::temp_dir().join(format!("verne-href-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("out")).unwrap();
        std::fs::create_dir_all(dir.join("in put")).unwrap();
        std::fs::write(dir.join("in put/j#1.csv"), "x").unwrap();
        let h = href(&dir.join("out/r.html"), &dir.join("in put/j#1.csv"));
        assert_eq!(h, "../in%20put/j%231.csv");
        assert_eq!(href(&dir.join("out/r.html"), &dir.join("missing.csv")), "");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn source_lines_are_read_and_cut() {
        let dir = std::env::temp_dir().join(format!("verne-lines-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("p.ngc");
        let long = "X".repeat(400);
        std::fs::write(&f, format!("G90\r\nN20 U1 V2\n{long}\nlast")).unwrap();
        let got = source_lines(&f, &[2, 3, 4, 9].into_iter().collect());
        assert_eq!(got[&2], "N20 U1 V2");
        assert_eq!(got[&3].len(), LINE_TEXT_MAX + 4);
        assert_eq!(got[&4], "last");
        assert!(!got.contains_key(&9));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
