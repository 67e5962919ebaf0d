//! What a calibration measures and the machine's model of it: the joints of each row, the
//! module's pose by its forward kinematics (IFToMM 2007, section VI) on the working assembly
//! mode, and the instrument's reading of it.
//!
//! - A laser tracker or CMM (`tracker`) reads the tool tip U = P + Delta n(alpha),
//!   n = (0, -sin alpha, cos alpha) the platform's z axis (eq. (27), AIM 2007), in its own frame:
//!   y = R U + t, R and t unknown (six nuisance parameters); optionally the tool axis, from the
//!   tip towards the spindle, R (0, sin alpha, -cos alpha).
//! - The module alone (`platform`): the same instrument reads the platform point P.
//! - A double ballbar (`ballbar`) reads the distance |U - T(theta1, theta2) b| between the tool
//!   ball and a ball on the table at b in the workpiece frame R_t, T the table's transform of
//!   eq. (7), AIM 2007 (b unknown: three nuisance parameters).
//! - A probe on a plane (`probe`) reads the height of the tool tip, the z of R U + t: of the
//!   instrument frame, only the plane's height and its two tilts enter (three nuisance
//!   parameters).
//!
//! The pose of each row follows the parameters: the working mode of the nominal machine (its
//! complete forward kinematics), then at every new set of parameters the mode nearest the
//! previous one, certified as the tracking of the row engine certifies it
//! ([`crate::parallel_module::track::nearest_mode`]), so that a step of the fit never lands on
//! another assembly mode.

use nalgebra::{DVector, Matrix3, Matrix4, Rotation3, Vector3, Vector4};

use crate::machine::table_transform;
use crate::parallel_module::branches::{WORKING_CONFIG, config_of};
use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::parallel_module::fk;
use crate::parallel_module::track::nearest_mode;
use crate::spec::Machine;

use super::params::Param;

/// The instrument a data set comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Device {
    /// Tool tip (and optionally tool axis) in the instrument's frame: laser tracker, CMM.
    Tracker,
    /// Platform point P in the instrument's frame: the module alone.
    Platform,
    /// Distance between the tool ball and a table ball: double ballbar.
    Ballbar,
    /// Height of the tool tip on a plane: a touch probe.
    Probe,
}

impl Device {
    pub fn name(self) -> &'static str {
        match self {
            Device::Tracker => "tracker",
            Device::Platform => "platform",
            Device::Ballbar => "ballbar",
            Device::Probe => "probe",
        }
    }

    /// The nuisance parameters the device's readings carry.
    pub fn nuisance(self) -> &'static [Nuisance] {
        use Nuisance::*;
        match self {
            Device::Tracker | Device::Platform => {
                &[FrameRx, FrameRy, FrameRz, FrameX, FrameY, FrameZ]
            }
            Device::Probe => &[FrameRx, FrameRy, FrameZ],
            Device::Ballbar => &[BallX, BallY, BallZ],
        }
    }

    /// The machine's parameters a fit frees by default: those its readings depend on, except
    /// for a ballbar, which reads the table's axes relative to the tool and leaves the module's
    /// dimensions to a tracker (with them, its readings determine most of them to centimetres:
    /// `verne calibrate plan --device ballbar --free ...` says how well).
    pub fn parameters(self) -> Vec<Param> {
        use Param::*;
        let module = [D1, LowerD1, R1, LowerR1, L1, D2, LowerD2, R2, R4, L2, L3];
        let zeros = [Rho1Zero, Rho2Zero, Rho3Zero];
        let mut out = Vec::new();
        match self {
            Device::Platform => {
                out.extend(module);
                out.extend(zeros);
            }
            Device::Tracker | Device::Probe => {
                out.extend(module);
                out.extend(zeros);
                out.push(ToolLength);
            }
            Device::Ballbar => {
                out.extend(zeros);
                out.extend([
                    ToolLength, TableDa, TableDt, TableYt, Theta1Zero, Theta2Zero,
                ]);
            }
        }
        out
    }

    /// Every parameter its readings depend on.
    pub fn sensitive(self) -> Vec<Param> {
        match self {
            Device::Ballbar => super::params::ALL.to_vec(),
            Device::Platform => super::params::ALL[..14].to_vec(),
            Device::Tracker | Device::Probe => super::params::ALL[..15].to_vec(),
        }
    }
}

/// A nuisance parameter: where the instrument is (its frame, or the ballbar's table ball).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Nuisance {
    /// Rotation of the instrument frame about its x, y, z (rad; R = R0 exp(\[r\]), r small).
    FrameRx,
    FrameRy,
    FrameRz,
    /// Translation of the instrument frame (mm).
    FrameX,
    FrameY,
    FrameZ,
    /// The table ball in the workpiece frame R_t (mm).
    BallX,
    BallY,
    BallZ,
}

/// A nuisance parameter of one data set's instrument: a column of the fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NuisanceParam {
    pub set: usize,
    pub which: Nuisance,
}

impl NuisanceParam {
    /// Its name in reports: `instrument.x`, or with several data sets `set2.instrument.x`
    /// (1-based).
    pub fn key(&self, sets: usize) -> String {
        if sets > 1 {
            format!("set{}.{}", self.set + 1, self.which.key())
        } else {
            self.which.key().to_string()
        }
    }
}

/// The nuisance columns of data sets of these devices, set by set.
pub fn nuisance_columns(devices: &[Device]) -> Vec<NuisanceParam> {
    devices
        .iter()
        .enumerate()
        .flat_map(|(set, d)| {
            d.nuisance()
                .iter()
                .map(move |&which| NuisanceParam { set, which })
        })
        .collect()
}

/// Each data set's instrument moved by `delta` of its columns.
pub fn moved_instruments(
    insts: &[Instrument],
    cols: &[NuisanceParam],
    delta: &[f64],
) -> Vec<Instrument> {
    insts
        .iter()
        .enumerate()
        .map(|(set, inst)| {
            let (which, d): (Vec<Nuisance>, Vec<f64>) = cols
                .iter()
                .zip(delta)
                .filter(|(c, _)| c.set == set)
                .map(|(c, d)| (c.which, *d))
                .unzip();
            inst.moved(&which, &d)
        })
        .collect()
}

impl Nuisance {
    pub fn key(self) -> &'static str {
        match self {
            Nuisance::FrameRx => "instrument.rx",
            Nuisance::FrameRy => "instrument.ry",
            Nuisance::FrameRz => "instrument.rz",
            Nuisance::FrameX => "instrument.x",
            Nuisance::FrameY => "instrument.y",
            Nuisance::FrameZ => "instrument.z",
            Nuisance::BallX => "ball.x",
            Nuisance::BallY => "ball.y",
            Nuisance::BallZ => "ball.z",
        }
    }

    pub fn is_angle(self) -> bool {
        matches!(
            self,
            Nuisance::FrameRx | Nuisance::FrameRy | Nuisance::FrameRz
        )
    }
}

/// What one row of a data set read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Observed {
    /// The tool tip (mm) and, when measured, the tool axis (unit, tip towards spindle) in the
    /// instrument's frame.
    Tip {
        tip: Vector3<f64>,
        axis: Option<Vector3<f64>>,
    },
    /// The platform point P in the instrument's frame (mm).
    Platform(Vector3<f64>),
    /// The distance between the tool ball and the table ball (mm).
    Distance(f64),
    /// The height of the tool tip (mm), along the instrument's z.
    Height(f64),
}

impl Observed {
    /// How many numbers the row gives the fit.
    pub fn len(&self) -> usize {
        match self {
            Observed::Tip { axis: Some(_), .. } => 6,
            Observed::Tip { axis: None, .. } | Observed::Platform(_) => 3,
            Observed::Distance(_) | Observed::Height(_) => 1,
        }
    }

    /// Always false: every reading gives at least one number.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The device that reads this.
    pub fn device(&self) -> Device {
        match self {
            Observed::Tip { .. } => Device::Tracker,
            Observed::Platform(_) => Device::Platform,
            Observed::Distance(_) => Device::Ballbar,
            Observed::Height(_) => Device::Probe,
        }
    }
}

/// One row of a data set: the joints the machine was at and what the instrument read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Slider joints (mm).
    pub rho: Sliders,
    /// Table joints theta1, theta2 (rad).
    pub theta: [f64; 2],
    pub observed: Observed,
    /// The data set the row belongs to (0, 1, ...): each set has its instrument, placed
    /// anywhere (its own nuisance parameters); sets of several devices are fitted together.
    pub set: usize,
    /// Where the row came from (its line in its file), for messages.
    pub line: u64,
}

/// The noise of the readings (1 sigma of each coordinate): the weights of the fit, and the
/// scale of the predicted sigmas of a plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Lengths: tool tip, platform point, distance, height (mm).
    pub length_mm: f64,
    /// Tool axis (rad).
    pub axis_rad: f64,
}

/// A laser tracker's noise, 10 um, and that of a tool axis measured over a 100 mm probe.
pub const DEFAULT_NOISE: Noise = Noise {
    length_mm: 0.01,
    axis_rad: 1e-4,
};

/// Where the instrument is: its frame in the base frame (y = R x + t) and the table ball.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instrument {
    pub rotation: Rotation3<f64>,
    pub translation: Vector3<f64>,
    /// The ballbar's table ball in the workpiece frame R_t (mm).
    pub ball: Vector3<f64>,
}

impl Default for Instrument {
    fn default() -> Self {
        Instrument {
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
            ball: Vector3::zeros(),
        }
    }
}

impl Instrument {
    /// The instrument moved by `delta` of each nuisance parameter (rotations composed on the
    /// right: R exp(\[r\])).
    pub fn moved(&self, which: &[Nuisance], delta: &[f64]) -> Instrument {
        let mut out = *self;
        let mut r = Vector3::zeros();
        for (n, d) in which.iter().zip(delta) {
            match n {
                Nuisance::FrameRx => r.x += d,
                Nuisance::FrameRy => r.y += d,
                Nuisance::FrameRz => r.z += d,
                Nuisance::FrameX => out.translation.x += d,
                Nuisance::FrameY => out.translation.y += d,
                Nuisance::FrameZ => out.translation.z += d,
                Nuisance::BallX => out.ball.x += d,
                Nuisance::BallY => out.ball.y += d,
                Nuisance::BallZ => out.ball.z += d,
            }
        }
        out.rotation = self.rotation * Rotation3::new(r);
        out
    }

    /// The value of a nuisance parameter, for reports: the frame's rotation as a rotation
    /// vector (rad), its translation and the ball (mm).
    pub fn value(&self, n: Nuisance) -> f64 {
        let r = self.rotation.scaled_axis();
        match n {
            Nuisance::FrameRx => r.x,
            Nuisance::FrameRy => r.y,
            Nuisance::FrameRz => r.z,
            Nuisance::FrameX => self.translation.x,
            Nuisance::FrameY => self.translation.y,
            Nuisance::FrameZ => self.translation.z,
            Nuisance::BallX => self.ball.x,
            Nuisance::BallY => self.ball.y,
            Nuisance::BallZ => self.ball.z,
        }
    }
}

/// The platform's z axis n(alpha) = (0, -sin alpha, cos alpha): the tool tip is P + Delta n.
#[inline]
pub fn platform_axis(alpha: f64) -> Vector3<f64> {
    let (s, c) = alpha.sin_cos();
    Vector3::new(0.0, -s, c)
}

/// The tool tip U = P + Delta n(alpha) in the base frame (eq. (27), AIM 2007).
#[inline]
pub fn tool_tip(m: &Machine, pose: &ModulePose) -> Vector3<f64> {
    pose.p + m.tool_length * platform_axis(pose.alpha)
}

/// The table ball in the base frame at the row's table joints.
pub fn ball_in_base(m: &Machine, theta: [f64; 2], ball: &Vector3<f64>) -> Vector3<f64> {
    let t: Matrix4<f64> = table_transform(&m.table, theta[0], theta[1]);
    (t * Vector4::new(ball.x, ball.y, ball.z, 1.0)).xyz()
}

/// What the model says the instrument reads for a row at the module pose `pose`, into `out`
/// (the numbers in the order of [`Observed`]).
pub fn predicted(
    m: &Machine,
    inst: &Instrument,
    row: &Measurement,
    pose: &ModulePose,
    out: &mut [f64],
) {
    let r = inst.rotation;
    match row.observed {
        Observed::Tip { axis, .. } => {
            let y = r * tool_tip(m, pose) + inst.translation;
            out[..3].copy_from_slice(y.as_slice());
            if axis.is_some() {
                let a = r * -platform_axis(pose.alpha);
                out[3..6].copy_from_slice(a.as_slice());
            }
        }
        Observed::Platform(_) => {
            let y = r * pose.p + inst.translation;
            out[..3].copy_from_slice(y.as_slice());
        }
        Observed::Distance(_) => {
            out[0] = (tool_tip(m, pose) - ball_in_base(m, row.theta, &inst.ball)).norm();
        }
        Observed::Height(_) => {
            out[0] = (r * tool_tip(m, pose) + inst.translation).z;
        }
    }
}

/// The readings of a row, in the order of [`predicted`].
pub fn observed_values(row: &Measurement, out: &mut [f64]) {
    match row.observed {
        Observed::Tip { tip, axis } => {
            out[..3].copy_from_slice(tip.as_slice());
            if let Some(a) = axis {
                out[3..6].copy_from_slice(a.as_slice());
            }
        }
        Observed::Platform(p) => out[..3].copy_from_slice(p.as_slice()),
        Observed::Distance(d) => out[0] = d,
        Observed::Height(h) => out[0] = h,
    }
}

/// The 1-sigma noise of each number of a row (the axis's numbers are angles).
pub fn noise_of(row: &Measurement, noise: &Noise, out: &mut [f64]) {
    for (k, o) in out.iter_mut().enumerate().take(row.observed.len()) {
        *o = if k >= 3 {
            noise.axis_rad
        } else {
            noise.length_mm
        };
    }
}

/// Why a row cannot be used.
#[derive(Debug, Clone, PartialEq)]
pub struct RowProblem {
    pub line: u64,
    pub message: String,
}

/// The module's pose of each row on the nominal machine: its working assembly mode, by the
/// complete forward kinematics (the mode of the machine's kind: every slider attachment above
/// its platform attachment, leg I's rods not crossing; the joints' limits are not asked, since
/// the machine was there). Every row without one is a problem.
pub fn initial_poses(
    m: &Machine,
    rows: &[Measurement],
) -> Result<Vec<ModulePose>, Vec<RowProblem>> {
    let mut poses = Vec::with_capacity(rows.len());
    let mut problems = Vec::new();
    for row in rows {
        let modes = fk::solve(m, &row.rho);
        let mode = modes
            .iter()
            .filter(|f| f.config == WORKING_CONFIG && (f.working() || f.verdict.only_limits()))
            .min_by(|a, b| a.pose.alpha.abs().total_cmp(&b.pose.alpha.abs()));
        match mode {
            Some(f) => poses.push(f.pose),
            None => problems.push(RowProblem {
                line: row.line,
                message: format!(
                    "the nominal machine has no assembly mode of its kind at rho = ({}, {}, {}) mm: the joints are not the machine's",
                    row.rho.x, row.rho.y, row.rho.z
                ),
            }),
        }
    }
    if problems.is_empty() {
        Ok(poses)
    } else {
        Err(problems)
    }
}

/// The module's pose of each row for the machine `m`, each followed from `previous` and
/// certified nearest it ([`nearest_mode`]), still of the machine's configuration with leg I's
/// rods not crossing; with A^-1 at each pose. None when a row's mode cannot be followed: the
/// step is then too large (a fit takes a shorter one).
pub fn followed_poses(
    m: &Machine,
    rows: &[Measurement],
    previous: &[ModulePose],
) -> Option<(Vec<ModulePose>, Vec<Matrix4<f64>>)> {
    let g = &m.module;
    let mut poses = Vec::with_capacity(rows.len());
    let mut inverses = Vec::with_capacity(rows.len());
    for (row, prev) in rows.iter().zip(previous) {
        let (pose, inv) = nearest_mode(g, prev, &row.rho)?;
        if config_of(g, &pose, &row.rho) != WORKING_CONFIG
            || g.r_big1 * pose.alpha.cos() <= g.r_small1
        {
            return None;
        }
        poses.push(pose);
        inverses.push(inv);
    }
    Some((poses, inverses))
}

/// The weighted residuals (model minus reading, over its noise) of every row, in row order,
/// each row read by its data set's instrument.
pub fn residuals(
    m: &Machine,
    insts: &[Instrument],
    rows: &[Measurement],
    poses: &[ModulePose],
    noise: &Noise,
) -> DVector<f64> {
    let n: usize = rows.iter().map(|r| r.observed.len()).sum();
    let mut out = DVector::zeros(n);
    let (mut pred, mut obs, mut sigma) = ([0.0; 6], [0.0; 6], [0.0; 6]);
    let mut k = 0;
    for (row, pose) in rows.iter().zip(poses) {
        let len = row.observed.len();
        predicted(m, &insts[row.set], row, pose, &mut pred);
        observed_values(row, &mut obs);
        noise_of(row, noise, &mut sigma);
        for j in 0..len {
            out[k + j] = (pred[j] - obs[j]) / sigma[j];
        }
        k += len;
    }
    out
}

/// The instrument's frame that best maps the model's points onto the readings (least squares,
/// Kabsch's method: the rotation from the SVD of the points' cross-covariance), for a data set
/// of tool tips or platform points.
pub fn aligned_frame(model: &[Vector3<f64>], read: &[Vector3<f64>]) -> Instrument {
    let n = model.len().max(1) as f64;
    let cm = model.iter().sum::<Vector3<f64>>() / n;
    let cr = read.iter().sum::<Vector3<f64>>() / n;
    let h: Matrix3<f64> = model
        .iter()
        .zip(read)
        .map(|(p, y)| (p - cm) * (y - cr).transpose())
        .sum();
    let svd = h.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Instrument::default();
    };
    let v = vt.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    let rotation = Rotation3::from_matrix_unchecked(r);
    Instrument {
        rotation,
        translation: cr - rotation * cm,
        ball: Vector3::zeros(),
    }
}

/// The table ball that best fits the distances: the tool ball's centres in the workpiece frame
/// U_k lie at d_k from b, |U_k|^2 - 2 U_k.b + |b|^2 = d_k^2, linear in (b, |b|^2) (least
/// squares).
pub fn fitted_ball(m: &Machine, rows: &[Measurement], poses: &[ModulePose]) -> Vector3<f64> {
    let mut ata = nalgebra::Matrix4::<f64>::zeros();
    let mut atb = Vector4::<f64>::zeros();
    for (row, pose) in rows.iter().zip(poses) {
        let Observed::Distance(d) = row.observed else {
            continue;
        };
        let t = table_transform(&m.table, row.theta[0], row.theta[1]);
        let Some(inv) = t.try_inverse() else { continue };
        let u = tool_tip(m, pose);
        let u = (inv * Vector4::new(u.x, u.y, u.z, 1.0)).xyz();
        let a = Vector4::new(2.0 * u.x, 2.0 * u.y, 2.0 * u.z, -1.0);
        ata += a * a.transpose();
        atb += a * (u.norm_squared() - d * d);
    }
    ata.try_inverse()
        .map(|inv| (inv * atb).xyz())
        .unwrap_or_else(Vector3::zeros)
}

/// Each data set's instrument, first estimated on the nominal machine ([`initial_instrument`]).
pub fn initial_instruments(
    m: &Machine,
    rows: &[Measurement],
    poses: &[ModulePose],
    sets: usize,
) -> Vec<Instrument> {
    (0..sets)
        .map(|set| {
            let (r, p): (Vec<Measurement>, Vec<ModulePose>) = rows
                .iter()
                .zip(poses)
                .filter(|(r, _)| r.set == set)
                .map(|(r, p)| (*r, *p))
                .unzip();
            initial_instrument(m, &r, &p)
        })
        .collect()
}

/// The instrument's first estimate on the nominal machine, for the rows of one data set:
/// Kabsch's frame for points, the fitted ball for distances, the plane's height for heights.
pub fn initial_instrument(m: &Machine, rows: &[Measurement], poses: &[ModulePose]) -> Instrument {
    let device = rows
        .first()
        .map_or(Device::Tracker, |r| r.observed.device());
    match device {
        Device::Tracker | Device::Platform => {
            let (mut model, mut read) = (Vec::new(), Vec::new());
            for (row, pose) in rows.iter().zip(poses) {
                match row.observed {
                    Observed::Tip { tip, .. } => {
                        model.push(tool_tip(m, pose));
                        read.push(tip);
                    }
                    Observed::Platform(p) => {
                        model.push(pose.p);
                        read.push(p);
                    }
                    _ => {}
                }
            }
            aligned_frame(&model, &read)
        }
        Device::Ballbar => Instrument {
            ball: fitted_ball(m, rows, poses),
            ..Instrument::default()
        },
        Device::Probe => {
            let n = rows.len().max(1) as f64;
            let z = rows
                .iter()
                .zip(poses)
                .map(|(row, pose)| match row.observed {
                    Observed::Height(h) => h - tool_tip(m, pose).z,
                    _ => 0.0,
                })
                .sum::<f64>()
                / n;
            Instrument {
                translation: Vector3::new(0.0, 0.0, z),
                ..Instrument::default()
            }
        }
    }
}
