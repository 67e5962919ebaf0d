//! Recorded joints against the intended path: a controller's servo samples (a `halsampler`
//! recording, a halstreamer stream) have no row of the path to be paired with, so each sample is
//! paired with the nearest point of the path instead, and the row checks measure the contour
//! error (how far the tool is from the programmed path), not the tracking error (how late it is
//! there). Everything else (limits, singularity, branch, jumps, speeds from the samples' times)
//! is checked as for a joint table.
//!
//! The path between two points is the straight line of the tip and the linear interpolation of
//! the tool angles (phi1, phi2) (AIM 2007 eq. (8)), as a controller whose world coordinates are
//! X Y Z and the two tool angles interpolates it (LinuxCNC with `vernekins`), the angles of each
//! move by [`move_angles`] (as stated by the path, or from the axes), the same interpolation as
//! `verne ik --period` streams. Nearest is measured
//! in X Y Z (mm) and the angle between the axes weighted by [`ANGLE_WEIGHT_MM_PER_RAD`] (1 mm
//! per degree, the controller's own units): the segment by a projection in the angles (phi2
//! counted with sin(phi1), its arc on the sphere of axes), the point on it by a golden-section
//! search on that distance.

use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

use nalgebra::{SVector, Vector3};

use super::row::mode_of_kind;
use super::{
    Check, Item, JointSource, Joints, Observer, PairingError, PathPoint, RowSource, Summary, Th,
    VerifyOptions, Violation, verify_observed,
};
use crate::machine::orientation::{move_angles, tool_axis};
use crate::machine::{MachineFkModes, machine_fk};
use crate::parallel_module::ik::wrap_angle;
use crate::spec::Machine;

/// Weight of the tool angles against the tip when finding the nearest point (mm per rad): one
/// millimetre per degree.
pub const ANGLE_WEIGHT_MM_PER_RAD: f64 = 180.0 / PI;

/// Segments searched on each side of the previous sample's segment before the whole path is
/// searched (samples move along the path, a few per segment or many).
pub const SEARCH_WINDOW: usize = 64;

/// A sample farther than this (weighted mm) from the path inside the window is looked for on the
/// whole path (the window may have lost it: a sample that jumped, the path's start).
pub const WINDOW_TRUST_MM: f64 = 1.0;

/// Distances to two passes of the path (points more than [`WINDOW_TRUST_MM`] apart along it)
/// closer than this (mm) are a tie: above a recording's resolution at the tool tip
/// (halsampler's six decimals of mm and degrees: about 2e-5 mm a metre from the axes), far
/// below any tolerance a check uses.
const TIE_MM: f64 = 1e-4;

/// Golden-section steps refining the parameter on the nearest segment (0.618^60 ~ 3e-13).
const GOLDEN_STEPS: usize = 60;

/// The two ends of a segment in tool angles, as the controller interpolates them.
#[derive(Debug, Clone, Copy)]
struct SegmentAngles {
    a: (f64, f64),
    b: (f64, f64),
    /// |sin(phi1)| at the middle: the weight of a phi2 difference.
    s: f64,
}

impl SegmentAngles {
    fn at(&self, u: f64) -> (f64, f64) {
        (
            self.a.0 + u * (self.b.0 - self.a.0),
            self.a.1 + u * (self.b.1 - self.a.1),
        )
    }
}

/// The intended path, held whole, for the nearest-point search.
#[derive(Debug, Clone)]
pub struct ContourPath {
    nodes: Vec<PathPoint>,
    /// The angles of each segment ([`move_angles`]), one per segment (one for a single point).
    segments: Vec<SegmentAngles>,
    /// The segment of the previous sample (the search starts there).
    cursor: usize,
    /// The length of the path's tips up to each point (mm).
    along: Vec<f64>,
}

/// The nearest point of the path to a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// The intended pose there (tip and axis interpolated).
    pub point: PathPoint,
    /// The segment (0-based: from point k to point k + 1) and the parameter along it, in [0, 1].
    pub segment: usize,
    pub u: f64,
    /// The weighted distance (mm).
    pub distance: f64,
}

/// The two tool-angle solutions of one axis direction (AIM 2007 eq. (8)).
fn both(phi1: f64, phi2: f64) -> [(f64, f64); 2] {
    [(phi1, phi2), (-phi1, wrap_angle(phi2 + PI))]
}

impl ContourPath {
    /// The path's points in order.
    pub fn new(points: Vec<PathPoint>) -> ContourPath {
        // One segment per pair of points; a single point is a segment from itself to itself.
        let count = match points.len() {
            0 => 0,
            1 => 1,
            n => n - 1,
        };
        let segments = (0..count)
            .map(|k| {
                let (a, b) = (&points[k], &points[(k + 1).min(points.len() - 1)]);
                let [ea, eb] = move_angles(&a.axis, a.angles, &b.axis, b.angles);
                SegmentAngles {
                    a: ea,
                    b: eb,
                    s: (0.5 * (ea.0 + eb.0)).sin().abs(),
                }
            })
            .collect();
        let along = std::iter::once(0.0)
            .chain(points.windows(2).scan(0.0, |total, w| {
                *total += (w[1].tip - w[0].tip).norm();
                Some(*total)
            }))
            .collect();
        ContourPath {
            nodes: points,
            segments,
            cursor: 0,
            along,
        }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The nearest point of the path to a tool pose (tip, and angles as the machine's forward
    /// kinematics gives them, either orientation solution); None for an empty path.
    pub fn nearest(&mut self, tip: &Vector3<f64>, phi1: f64, phi2: f64) -> Option<Nearest> {
        let n = self.nodes.len();
        if n == 0 {
            return None;
        }
        let segments = (n - 1).max(1);
        let lo = self.cursor.saturating_sub(SEARCH_WINDOW);
        let hi = (self.cursor + SEARCH_WINDOW + 1).min(segments);
        let mut best = self.best_in(lo..hi, tip, phi1, phi2);
        if best.distance > WINDOW_TRUST_MM && (lo > 0 || hi < segments) {
            let whole = self.best_in(0..segments, tip, phi1, phi2);
            if whole.distance < best.distance {
                best = whole;
            }
        }
        self.cursor = best.segment;
        Some(best)
    }

    fn best_in(
        &self,
        range: std::ops::Range<usize>,
        tip: &Vector3<f64>,
        phi1: f64,
        phi2: f64,
    ) -> Nearest {
        let mut best: Option<(usize, f64, f64, SegmentAngles)> = None;
        // Two passes of the path as near the sample (a closed path's start and end, a pass over
        // the same place again): the one nearest the cursor, where the samples before went.
        // Otherwise the nearer point, exactly.
        let at = |k: usize, u: f64| {
            let k1 = (k + 1).min(self.along.len() - 1);
            self.along[k] + u * (self.along[k1] - self.along[k])
        };
        let nearer_cursor = |k: usize, b: usize| k.abs_diff(self.cursor) < b.abs_diff(self.cursor);
        for k in range {
            let seg = self.segments[k];
            for sample in both(phi1, phi2) {
                let (u, d) = self.project(k, &seg, tip, sample);
                if best.is_none_or(|b| {
                    let other_pass = (at(k, u) - at(b.0, b.1)).abs() > WINDOW_TRUST_MM;
                    if other_pass && (d - b.2).abs() <= TIE_MM {
                        nearer_cursor(k, b.0)
                    } else {
                        d < b.2
                    }
                }) {
                    best = Some((k, u, d, seg));
                }
            }
        }
        let (segment, u0, _, seg) = best.expect("a non-empty range");
        // The projection weighs phi2 by the segment's mean tilt; the distance that counts
        // compares the axes themselves (none of phi2 at the table normal): refine on it.
        let axis = tool_axis(phi1, phi2);
        let d = |u: f64| self.pose_distance(segment, &seg, u, tip, &axis);
        let (mut u, mut distance) = (u0, d(u0));
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        let (mut f1, mut f2) = (d(x1), d(x2));
        for _ in 0..GOLDEN_STEPS {
            if f1 <= f2 {
                hi = x2;
                (x2, f2) = (x1, f1);
                x1 = hi - g * (hi - lo);
                f1 = d(x1);
            } else {
                lo = x1;
                (x1, f1) = (x2, f2);
                x2 = lo + g * (hi - lo);
                f2 = d(x2);
            }
        }
        for (x, f) in [(x1, f1), (x2, f2), (0.0, d(0.0)), (1.0, d(1.0))] {
            if f < distance {
                (u, distance) = (x, f);
            }
        }
        Nearest {
            point: self.at(segment, &seg, u),
            segment,
            u,
            distance,
        }
    }

    /// The distance that counts: the tips (mm) and the angle between the axes, weighted.
    fn pose_distance(
        &self,
        k: usize,
        seg: &SegmentAngles,
        u: f64,
        tip: &Vector3<f64>,
        axis: &Vector3<f64>,
    ) -> f64 {
        let p = self.at(k, seg, u);
        let angle = axis.cross(&p.axis).norm().atan2(axis.dot(&p.axis));
        ((tip - p.tip).norm_squared() + (ANGLE_WEIGHT_MM_PER_RAD * angle).powi(2)).sqrt()
    }

    /// The parameter of the point of segment `k` nearest the sample (the projection in X Y Z
    /// and the weighted angles, clamped to the segment) and the weighted distance there.
    fn project(
        &self,
        k: usize,
        seg: &SegmentAngles,
        tip: &Vector3<f64>,
        (phi1, phi2): (f64, f64),
    ) -> (f64, f64) {
        let w = ANGLE_WEIGHT_MM_PER_RAD;
        let coords = |x: &Vector3<f64>, p1: f64, p2: f64| {
            SVector::<f64, 5>::new(x.x, x.y, x.z, w * p1, w * seg.s * p2)
        };
        let a = &self.nodes[k];
        let b = &self.nodes[(k + 1).min(self.nodes.len() - 1)];
        let pa = coords(&a.tip, seg.a.0, seg.a.1);
        let pb = coords(&b.tip, seg.b.0, seg.b.1);
        // The sample's phi2 taken near the segment's.
        let q = coords(tip, phi1, seg.a.1 + wrap_angle(phi2 - seg.a.1));
        let d = pb - pa;
        let dd = d.norm_squared();
        let u = if dd == 0.0 {
            0.0
        } else {
            ((q - pa).dot(&d) / dd).clamp(0.0, 1.0)
        };
        let (p1, p2) = seg.at(u);
        let t = a.tip + u * (b.tip - a.tip);
        let da = w * (phi1 - p1);
        let db = w * p1.sin().abs() * wrap_angle(phi2 - p2);
        (u, ((tip - t).norm_squared() + da * da + db * db).sqrt())
    }

    /// The intended pose at parameter `u` of segment `k`: the tip on the straight line, the axis
    /// of the interpolated angles; the move's rapid flag, feed and time are the end point's.
    fn at(&self, k: usize, seg: &SegmentAngles, u: f64) -> PathPoint {
        let a = &self.nodes[k];
        let b = &self.nodes[(k + 1).min(self.nodes.len() - 1)];
        let (p1, p2) = seg.at(u);
        PathPoint {
            tip: a.tip + u * (b.tip - a.tip),
            axis: tool_axis(p1, p2),
            ..*b
        }
    }
}

/// The last joint row read, shared between the joint source and the path it is projected on.
type LastRow = Arc<Mutex<Option<Result<Joints, String>>>>;

/// The recording, remembering each row for [`Projected`].
struct Tee<'a, J> {
    inner: &'a mut J,
    last: LastRow,
}

impl<J: JointSource> RowSource for Tee<'_, J> {
    type Row = Joints;
    type Error = J::Error;

    fn name(&self) -> &str {
        self.inner.name()
    }

    fn has_id(&self) -> bool {
        false
    }

    fn next_item(&mut self) -> Result<Option<Item<Joints>>, J::Error> {
        let item = self.inner.next_item()?;
        *self.last.lock().unwrap_or_else(|e| e.into_inner()) =
            item.as_ref().map(|i| i.value.clone());
        Ok(item)
    }
}

impl<J: JointSource> JointSource for Tee<'_, J> {
    fn timed(&self) -> bool {
        self.inner.timed()
    }
}

/// The intended path as a row source: for each joint row just read, its nearest point.
struct Projected<'a, E> {
    machine: &'a Machine,
    tool_length: f64,
    path: ContourPath,
    name: String,
    last: LastRow,
    index: u64,
    previous: Option<PathPoint>,
    /// The assembly modes of the joint row just projected, for the row check.
    modes: Option<Box<MachineFkModes>>,
    /// How much of the path the samples covered: the first and the farthest nearest points
    /// (segment, parameter), and the last sample's.
    reach: Option<Reach>,
    _error: std::marker::PhantomData<E>,
}

/// Where the samples of a recording fell on the path.
#[derive(Debug, Clone, Copy)]
struct Reach {
    first: (usize, f64),
    farthest: (usize, f64),
    last: (usize, f64),
}

impl<E> RowSource for Projected<'_, E> {
    type Row = PathPoint;
    type Error = E;

    fn name(&self) -> &str {
        &self.name
    }

    fn has_id(&self) -> bool {
        false
    }

    fn take_joint_modes(&mut self) -> Option<Box<MachineFkModes>> {
        self.modes.take()
    }

    fn next_item(&mut self) -> Result<Option<Item<PathPoint>>, E> {
        self.modes = None;
        let Some(row) = self.last.lock().unwrap_or_else(|e| e.into_inner()).take() else {
            return Ok(None);
        };
        self.index += 1;
        let nearest = row.ok().and_then(|q| {
            // The tool pose of the machine's assembly mode (the row check picks the same kind,
            // from these modes: they go with the row).
            let modes = machine_fk(self.machine, &q.rho, q.theta1, q.theta2, self.tool_length);
            let modes = &**self.modes.insert(Box::new(modes));
            let previous = self.previous.as_ref().map(|p| &p.tip);
            let mode = mode_of_kind(modes, self.machine, previous)?;
            self.path
                .nearest(&mode.tool.tip, mode.tool.phi1, mode.tool.phi2)
        });
        if let Some(n) = &nearest {
            let at = (n.segment, n.u);
            let later = |a: (usize, f64), b: (usize, f64)| a.0 > b.0 || (a.0 == b.0 && a.1 > b.1);
            self.reach = Some(match self.reach {
                None => Reach {
                    first: at,
                    farthest: at,
                    last: at,
                },
                Some(r) => Reach {
                    first: r.first,
                    farthest: if later(at, r.farthest) {
                        at
                    } else {
                        r.farthest
                    },
                    last: at,
                },
            });
        }
        // A row that cannot be solved is reported by the row check; pair it with the last point.
        let point = match (nearest, self.previous) {
            (Some(n), _) => n.point,
            (None, Some(p)) => p,
            (None, None) => self.path.nodes[0],
        };
        self.previous = Some(point);
        Ok(Some(Item {
            index: self.index,
            line: self.index,
            id: None,
            value: Ok(point),
            tag: None,
        }))
    }
}

/// [`verify`](super::verify) of a recording: each joint row against the nearest point of `path` (module
/// documentation). An empty path is an error of the caller (nothing to compare with).
pub fn verify_recording<J, E>(
    m: &Machine,
    opt: &VerifyOptions,
    joints: &mut J,
    path: ContourPath,
    path_name: &str,
    report: &mut (dyn FnMut(&Violation) -> Result<(), E> + Send),
) -> Result<Summary, E>
where
    J: JointSource<Error = E> + Send,
    E: From<PairingError> + Send,
{
    verify_recording_observed(m, opt, joints, path, path_name, report, None)
}

/// [`verify_recording`] with an observer of each row, as [`verify_observed`].
pub fn verify_recording_observed<J, E>(
    m: &Machine,
    opt: &VerifyOptions,
    joints: &mut J,
    path: ContourPath,
    path_name: &str,
    report: &mut (dyn FnMut(&Violation) -> Result<(), E> + Send),
    observe: Option<Observer<'_>>,
) -> Result<Summary, E>
where
    J: JointSource<Error = E> + Send,
    E: From<PairingError> + Send,
{
    assert!(!path.is_empty(), "verify_recording needs a path");
    let last: LastRow = Arc::new(Mutex::new(None));
    let mut tee = Tee {
        inner: joints,
        last: last.clone(),
    };
    let mut projected = Projected {
        machine: m,
        tool_length: opt.tool_length,
        path,
        name: path_name.to_string(),
        last,
        index: 0,
        previous: None,
        modes: None,
        reach: None,
        _error: std::marker::PhantomData,
    };
    let mut summary = verify_observed(m, opt, &mut tee, &mut projected, report, observe)?;
    // The recording must cover the path, from its first point to its last: its first sample at
    // the path's start, some sample at its end, and its last sample there.
    let nodes = &projected.path.nodes;
    let tol = opt.thresholds.get(Th::TipErrorMm);
    let along = |(k, u): (usize, f64)| -> f64 {
        let seg = |i: usize| (nodes[i + 1].tip - nodes[i].tip).norm();
        (0..k).map(seg).sum::<f64>() + if k + 1 < nodes.len() { u * seg(k) } else { 0.0 }
    };
    let total = along((nodes.len().saturating_sub(1), 0.0));
    let gap = match projected.reach {
        None => Some("the recording has no sample on the path: it covers nothing".to_string()),
        Some(r) => {
            let (start, far, end) = (along(r.first), along(r.farthest), along(r.last));
            if start > tol {
                Some(format!(
                    "the recording starts {start:.4} mm along the path, not at its first point"
                ))
            } else if total - far > tol || total - end > tol {
                Some(format!(
                    "the recording ends {:.4} mm along the path, {:.4} mm before its last point (it reached {far:.4} mm)",
                    end,
                    total - end
                ))
            } else {
                None
            }
        }
    };
    if let Some(detail) = gap {
        let v = Violation::plain(&summary.rows.to_string(), Check::Pairing, f64::NAN, detail);
        summary.add(&v);
        report(&v)?;
    }
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::orientation::tool_axis;

    fn point(x: f64, y: f64, z: f64, phi1_deg: f64, phi2_deg: f64) -> PathPoint {
        PathPoint::new(
            Vector3::new(x, y, z),
            tool_axis(phi1_deg.to_radians(), phi2_deg.to_radians()),
        )
    }

    /// A closed path (it ends where it starts, as a program that returns home): the first
    /// sample there is the path's start, the last one its end.
    #[test]
    fn a_closed_path_starts_at_its_start_and_ends_at_its_end() {
        let home = point(0.0, 0.0, 100.0, 0.0, 0.0);
        let mut path = ContourPath::new(vec![
            home,
            point(20.0, 10.0, 80.0, 0.0, 0.0),
            point(40.0, 10.0, 80.0, 10.0, 45.0),
            point(0.0, 0.0, 100.0, 0.0, 0.0),
        ]);
        // The tip rounded as a recording is: a few 1e-7 mm off home.
        let at_home = Vector3::new(3e-7, -2e-7, 100.0 + 1e-7);
        let first = path.nearest(&at_home, 0.0, 0.0).unwrap();
        assert!(first.segment == 0 && first.u < 1e-6, "{first:?}");
        // Along the way (the way back on the last segment), as a recording's samples follow it.
        for p in [
            Vector3::new(10.0, 5.0, 90.0),
            Vector3::new(30.0, 10.0, 80.0),
            Vector3::new(20.0, 5.0, 90.0),
        ] {
            path.nearest(&p, 0.0, 0.0).unwrap();
        }
        let last = path.nearest(&at_home, 0.0, 0.0).unwrap();
        assert!(last.segment == 2 && last.u > 1.0 - 1e-6, "{last:?}");
    }

    #[test]
    fn a_point_on_the_path_is_its_own_nearest() {
        let mut path = ContourPath::new(vec![
            point(0.0, 0.0, 100.0, 0.0, 0.0),
            point(50.0, 0.0, 100.0, 20.0, 0.0),
            point(50.0, 40.0, 80.0, 20.0, 90.0),
        ]);
        // A third of the way along the second segment: tip, phi1 = 20, phi2 = 30 degrees.
        let tip = Vector3::new(50.0, 40.0 / 3.0, 100.0 - 20.0 / 3.0);
        let n = path
            .nearest(&tip, 20f64.to_radians(), 30f64.to_radians())
            .unwrap();
        assert_eq!(n.segment, 1);
        assert!((n.u - 1.0 / 3.0).abs() < 1e-12, "{}", n.u);
        assert!(n.distance < 1e-9);
        assert!((n.point.tip - tip).norm() < 1e-12);
        let axis = tool_axis(20f64.to_radians(), 30f64.to_radians());
        assert!((n.point.axis - axis).norm() < 1e-12);
        // The same pose in orientation solution 2 is the same point.
        let m = path
            .nearest(&tip, -20f64.to_radians(), (30f64 - 180.0).to_radians())
            .unwrap();
        assert!(m.distance < 1e-9 && m.segment == 1);
    }

    #[test]
    fn a_tilt_through_the_table_normal_is_interpolated_as_the_controller_does() {
        // A10 C45 -> A-5 C90 (data/linuxcnc/verne-tcp.ngc): the controller moves A through 0.
        // The axes alone give (10, 45) and (5, -90); the path through the pole is the pair
        // with the smaller table move.
        let mut path = ContourPath::new(vec![
            point(40.0, 10.0, 80.0, 10.0, 45.0),
            point(10.0, -20.0, 70.0, -5.0, 90.0),
        ]);
        for u in [0.25, 0.5, 2.0 / 3.0, 0.9] {
            let (p1, p2) = (10.0 + u * (-15.0), 45.0 + u * 45.0);
            let tip = Vector3::new(40.0 - 30.0 * u, 10.0 - 30.0 * u, 80.0 - 10.0 * u);
            let n = path
                .nearest(&tip, f64::to_radians(p1), f64::to_radians(p2))
                .unwrap();
            assert!(n.distance < 1e-9, "u {u}: {}", n.distance);
            assert!((n.u - u).abs() < 1e-9);
            let axis = tool_axis(p1.to_radians(), p2.to_radians());
            assert!((n.point.axis - axis).norm() < 1e-12);
        }
        // A vertical end takes the other end's phi2: A0 C0 -> A10 C45 tilts in the C45 plane.
        let mut path = ContourPath::new(vec![
            point(20.0, 10.0, 80.0, 0.0, 0.0),
            point(40.0, 10.0, 80.0, 10.0, 45.0),
        ]);
        let n = path
            .nearest(
                &Vector3::new(30.0, 10.0, 80.0),
                5f64.to_radians(),
                45f64.to_radians(),
            )
            .unwrap();
        assert!(n.distance < 1e-9, "{}", n.distance);
    }

    #[test]
    fn an_offset_sample_measures_its_distance_and_a_far_one_is_found_outside_the_window() {
        let points: Vec<PathPoint> = (0..1000)
            .map(|k| point(k as f64, 0.0, 100.0, 10.0, 0.0))
            .collect();
        let mut path = ContourPath::new(points);
        // 0.3 mm beside the line near its start.
        let n = path
            .nearest(&Vector3::new(5.5, 0.3, 100.0), 10f64.to_radians(), 0.0)
            .unwrap();
        assert_eq!(n.segment, 5);
        assert!((n.distance - 0.3).abs() < 1e-12);
        // A sample near the end: beyond the window from segment 5, found by the whole search.
        let n = path
            .nearest(&Vector3::new(900.25, 0.0, 100.0), 10f64.to_radians(), 0.0)
            .unwrap();
        assert_eq!(n.segment, 900);
        assert!(n.distance < 1e-9);
        // An angle error weighs 1 mm per degree (phi1; phi2 by sin phi1).
        let n = path
            .nearest(&Vector3::new(900.25, 0.0, 100.0), 12f64.to_radians(), 0.0)
            .unwrap();
        assert!((n.distance - 2.0).abs() < 1e-9, "{}", n.distance);
    }

    /// A segment between two random poses (tilts up to 60 degrees, any phi2) and a sample off
    /// it: each coordinate of its tip up to 5 mm off, its angles up to 10 degrees off.
    fn random_case(unit: &mut impl FnMut() -> f64) -> (ContourPath, Vector3<f64>, f64, f64) {
        let mut pose = || {
            let tilt = 120.0 * unit() - 60.0;
            let phi2 = 360.0 * unit() - 180.0;
            point(100.0 * unit(), 100.0 * unit(), 100.0 * unit(), tilt, phi2)
        };
        let path = ContourPath::new(vec![pose(), pose()]);
        let (a, b) = (&path.nodes[0], &path.nodes[1]);
        let u = 1.4 * unit() - 0.2;
        let off = Vector3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 10.0;
        let tip = a.tip + u * (b.tip - a.tip) + off;
        let (p1, p2) = path.segments[0].at(u.clamp(0.0, 1.0));
        let (d1, d2) = (
            (20.0 * unit() - 10.0).to_radians(),
            (20.0 * unit() - 10.0).to_radians(),
        );
        (path, tip, p1 + d1, p2 + d2)
    }

    /// The projection that picks the segment is the nearest point of the segment in its own
    /// coordinates (X Y Z and the angles weighted, phi2 by the segment's mean |sin(phi1)|):
    /// its parameter is a brute-force search's (20,001 points) to the grid's spacing; a sample
    /// on the segment projects to itself at distance 0, and one moved across the line of tips
    /// (angles unchanged) is that far.
    #[test]
    fn the_projection_is_the_nearest_point_in_its_coordinates() {
        let mut unit = crate::math::test_rng::lcg(0x5eed_c047);
        let w = ANGLE_WEIGHT_MM_PER_RAD;
        for _ in 0..400 {
            let (path, tip, phi1, phi2) = random_case(&mut unit);
            let seg = path.segments[0];
            let (a, b) = (path.nodes[0], path.nodes[1]);
            let coords = |x: Vector3<f64>, p1: f64, p2: f64| {
                SVector::<f64, 5>::new(x.x, x.y, x.z, w * p1, w * seg.s * p2)
            };
            let q = coords(tip, phi1, seg.a.1 + wrap_angle(phi2 - seg.a.1));
            let gap = |u: f64| {
                let (p1, p2) = seg.at(u);
                (q - coords(a.tip + u * (b.tip - a.tip), p1, p2)).norm()
            };
            let brute = (0..=20_000)
                .map(|i| i as f64 / 20_000.0)
                .min_by(|x, y| gap(*x).total_cmp(&gap(*y)))
                .unwrap();
            let (u, _) = path.project(0, &seg, &tip, (phi1, phi2));
            assert!(
                gap(u) <= gap(brute) + 1e-9 && (u - brute).abs() <= 1e-3,
                "u {u} ({}), brute force {brute} ({})",
                gap(u),
                gap(brute)
            );
            // On the segment, then moved across the line of tips by 0.7 mm.
            let v = unit();
            let (p1, p2) = seg.at(v);
            let on = a.tip + v * (b.tip - a.tip);
            let (u, d) = path.project(0, &seg, &on, (p1, p2));
            assert!((u - v).abs() <= 1e-9 && d <= 1e-9, "{v}: {u} {d}");
            let along = (b.tip - a.tip).normalize();
            let across = along
                .cross(&Vector3::new(unit(), unit(), unit()))
                .normalize()
                * 0.7;
            let (u, d) = path.project(0, &seg, &(on + across), (p1, p2));
            assert!(
                (u - v).abs() <= 1e-9 && (d - 0.7).abs() <= 1e-9,
                "{v}: {u} {d}"
            );
        }
    }

    /// The point reported on the segment is the nearest by the distance that counts (tips, and
    /// the angle between the axes weighted), which the projection only approximates: no point
    /// of a brute-force search (20,001 points) is nearer, and on these segments the projection's
    /// own parameter alone is often farther (the golden-section refinement is what finds it).
    #[test]
    fn the_nearest_point_is_a_brute_force_searchs_on_the_axes() {
        let mut unit = crate::math::test_rng::lcg(0x5eed_c048);
        let mut refined = 0;
        for _ in 0..400 {
            let (path, tip, phi1, phi2) = random_case(&mut unit);
            let seg = path.segments[0];
            let axis = tool_axis(phi1, phi2);
            let distance = |u: f64| {
                let p = path.at(0, &seg, u);
                let angle = p.axis.dot(&axis).clamp(-1.0, 1.0).acos();
                ((tip - p.tip).norm_squared() + (ANGLE_WEIGHT_MM_PER_RAD * angle).powi(2)).sqrt()
            };
            let brute = (0..=20_000)
                .map(|i| distance(i as f64 / 20_000.0))
                .fold(f64::MAX, f64::min);
            let (u0, _) = path.project(0, &seg, &tip, (phi1, phi2));
            let n = path.clone().nearest(&tip, phi1, phi2).unwrap();
            assert!(
                n.distance <= brute + 1e-9 && (n.distance - distance(n.u)).abs() <= 1e-9,
                "{} at {} vs brute force {brute}",
                n.distance,
                n.u
            );
            assert!(
                ((n.point.tip - tip).norm() - (path.at(0, &seg, n.u).tip - tip).norm()).abs()
                    < 1e-12
            );
            refined += (distance(u0) > n.distance + 1e-6) as usize;
        }
        assert!(
            refined >= 40,
            "{refined} of 400 refined past the projection"
        );
    }

    /// The search window: a sample within [`WINDOW_TRUST_MM`] of a segment within
    /// [`SEARCH_WINDOW`] segments of the previous sample's stays there, even where another part
    /// of the path is nearer (a path that comes back 0.6 mm beside itself, the nearer part more
    /// than 64 segments away), and goes to that part once it is 64 away; a sample farther than
    /// the trust from the window is found on the whole path; an empty path has no nearest point.
    #[test]
    fn a_sample_stays_on_the_part_of_the_path_it_follows() {
        // The way out (segments 0 to 399), a turn of two segments, the way back 0.6 mm beside
        // (segment 402 + j from x = 400 - j to 399 - j: beside x = k + 0.5, segment 801 - k).
        let out = (0..=400).map(|k| point(k as f64, 0.0, 100.0, 10.0, 0.0));
        let turn = std::iter::once(point(400.0, 0.3, 100.0, 10.0, 0.0));
        let back = (0..=400)
            .rev()
            .map(|k| point(k as f64, 0.6, 100.0, 10.0, 0.0));
        let points: Vec<PathPoint> = out.chain(turn).chain(back).collect();
        let mut path = ContourPath::new(points);
        assert_eq!((path.len(), path.is_empty()), (803, false));
        let a = 10f64.to_radians();
        // The way out at y = 0.35 (0.25 from the way back): followed while the way back there is
        // beyond the window (802 - 2 k segments past the previous sample's, 66 at k = 368); at
        // k = 369 it is 64 past, inside the window, and the sample goes to it.
        for k in 0..369 {
            let x = 0.5 + k as f64;
            let n = path.nearest(&Vector3::new(x, 0.35, 100.0), a, 0.0).unwrap();
            assert_eq!(n.segment, k, "{x}: {n:?}");
            assert!((n.distance - 0.35).abs() < 1e-9, "{x}: {n:?}");
        }
        let n = path
            .nearest(&Vector3::new(369.5, 0.35, 100.0), a, 0.0)
            .unwrap();
        assert_eq!((n.segment, SEARCH_WINDOW), (432, 64), "{n:?}");
        assert!((n.distance - 0.25).abs() < 1e-9, "{n:?}");
        // Along the way out, round the turn, then back: samples 0.25 mm from the way back (0.35
        // from the way out), and where the way out is beyond the window (x below 360), samples
        // 0.25 mm from the way out, still found on the way back.
        for (x, y, segment) in [(395.5, 0.0, 395), (399.5, 0.0, 399), (399.5, 0.6, 402)] {
            let n = path.nearest(&Vector3::new(x, y, 100.0), a, 0.0).unwrap();
            assert_eq!(n.segment, segment, "{x} {y}");
        }
        let mut beside = 0;
        for k in 0..399 {
            let x = 398.5 - k as f64;
            let n = path.nearest(&Vector3::new(x, 0.35, 100.0), a, 0.0).unwrap();
            assert_eq!(n.segment, 403 + k, "{x}: {n:?}");
            assert!((n.distance - 0.25).abs() < 1e-9, "{x}: {n:?}");
            if x < 360.0 {
                let n = path.nearest(&Vector3::new(x, 0.25, 100.0), a, 0.0).unwrap();
                assert_eq!(n.segment, 403 + k, "{x}: {n:?}");
                assert!((n.distance - 0.35).abs() < 1e-9, "{x}: {n:?}");
                beside += 1;
            }
        }
        assert_eq!(beside, 360);
        // 2 mm off the path near its start, the window at the path's end (the way back's start
        // there is 2.6 mm away): beyond the trust of the window, searched whole.
        let n = path
            .nearest(&Vector3::new(3.5, -2.0, 100.0), a, 0.0)
            .unwrap();
        assert_eq!(n.segment, 3);
        assert!((n.distance - 2.0).abs() < 1e-9);
        let mut empty = ContourPath::new(Vec::new());
        assert_eq!((empty.len(), empty.is_empty()), (0, true));
        assert_eq!(empty.nearest(&Vector3::zeros(), 0.0, 0.0), None);
    }

    /// Two parts of a path with the same tips and different tool angles (tilted 10 degrees on
    /// the way out, 30 on the way back, over the same line): the sample's angles pick the part,
    /// given in either orientation solution (phi1, phi2) or (-phi1, phi2 + 180 degrees); a
    /// difference of phi2 counts by sin(phi1), as the angle between the axes does.
    #[test]
    fn the_tool_angles_pick_between_parts_with_the_same_tips() {
        let out = (0..=10).map(|k| point(k as f64, 0.0, 100.0, 10.0, 30.0));
        let back = (0..=10)
            .rev()
            .map(|k| point(k as f64, 0.0, 100.0, 30.0, 30.0));
        let points: Vec<PathPoint> = out.chain(back).collect();
        for (tilt, first) in [(10.0, 0), (30.0, 11)] {
            for (phi1, phi2) in [(tilt, 30.0), (-tilt, -150.0)] {
                let mut path = ContourPath::new(points.clone());
                let tip = Vector3::new(6.5, 0.0, 100.0);
                let n = path
                    .nearest(&tip, f64::to_radians(phi1), f64::to_radians(phi2))
                    .unwrap();
                let part = if first == 0 { 6 } else { 14 };
                assert_eq!(n.segment, part, "{phi1} {phi2}: {n:?}");
                assert!(n.distance < 1e-9, "{phi1} {phi2}: {n:?}");
            }
        }
        // Parts 0.6 mm apart, tilted 10 degrees, phi2 0 on the way out and 3 degrees back: a
        // sample on the way out's tips with the way back's angles is nearer the way out (its
        // axis 3 sin(10) = 0.52 degrees off, 0.52 mm weighted) than the way back (0.6 mm).
        let out = (0..=10).map(|k| point(k as f64, 0.0, 100.0, 10.0, 0.0));
        let back = (0..=10)
            .rev()
            .map(|k| point(k as f64, 0.6, 100.0, 10.0, 3.0));
        let mut path = ContourPath::new(out.chain(back).collect());
        let n = path
            .nearest(
                &Vector3::new(5.5, 0.0, 100.0),
                10f64.to_radians(),
                3f64.to_radians(),
            )
            .unwrap();
        let off = tool_axis(10f64.to_radians(), 0.0)
            .angle(&tool_axis(10f64.to_radians(), 3f64.to_radians()));
        assert_eq!(n.segment, 5, "{n:?}");
        assert!(
            (n.distance - ANGLE_WEIGHT_MM_PER_RAD * off).abs() < 1e-9,
            "{n:?}"
        );
        assert!((n.distance - 0.52).abs() < 0.01, "{n:?}");
    }

    /// A path of one point is a segment from it to itself: every sample is nearest to it, at
    /// parameter 0, by its distance from it (the projection divides by nothing).
    #[test]
    fn a_path_of_one_point_is_that_point() {
        let mut path = ContourPath::new(vec![point(10.0, 20.0, 30.0, 15.0, 40.0)]);
        assert_eq!(path.len(), 1);
        let n = path
            .nearest(
                &Vector3::new(13.0, 24.0, 30.0),
                15f64.to_radians(),
                40f64.to_radians(),
            )
            .unwrap();
        assert_eq!((n.segment, n.u), (0, 0.0));
        assert!((n.distance - 5.0).abs() < 1e-12, "{n:?}");
        // The same axis in the other orientation solution: the same distance.
        let m = path
            .nearest(
                &Vector3::new(13.0, 24.0, 30.0),
                -15f64.to_radians(),
                -140f64.to_radians(),
            )
            .unwrap();
        assert!((m.distance - 5.0).abs() < 1e-9, "{m:?}");
    }
}
