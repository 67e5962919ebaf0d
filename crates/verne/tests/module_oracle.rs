//! An independent, slow oracle for the parallel module's inverse and forward kinematics: dense
//! scans of one-dimensional residual functions built directly from the constraint equations
//! (3)-(6), (10) and (14) of IFToMM 2007, with sign changes bisected. It shares no code with the
//! solvers (no cubic (9), no degree-8 polynomial, no Newton polish) and is compared with
//! `ik::solve` and `fk::solve` on thousands of deterministic pseudo-random inputs.
//!
//! Where the scan is genuinely ambiguous (a local minimum of |f| within rounding distance of zero:
//! a double root, two roots too close to separate, or a near tangency), the input is skipped and
//! counted; the tests assert that such skips are rare.

use std::f64::consts::PI;

use nalgebra::{Matrix3, Vector3};
use verne::parallel_module::equations::{ModulePose, residual_mm};
use verne::parallel_module::fk;
use verne::parallel_module::ik;
use verne::spec::{Machine, ModuleGeometry};

/// Samples per scan of a full turn of alpha (or of one leg-I loop).
const SCAN_STEPS: usize = 20_000;
/// Every returned solution must satisfy eqs. (3)-(6) to this length error along the rod (mm).
const EQ_MM: f64 = 1e-6;
/// A refined local minimum of |f| (f expressed as a length, mm) below this is a near-double root
/// the scan cannot decide: the input is skipped.
const AMBIGUOUS_MM: f64 = 1e-6;
/// A square-root argument of eqs. (12)-(13) within this fraction of L^2 of zero is a fully
/// stretched rod (leg II or III tangent to reachability): ambiguous.
const STRETCHED_REL: f64 = 1e-9;
/// Matching an oracle root with a solver solution: angle (rad) and length (mm). The oracle's
/// own accuracy is limited by the square root of eq. (11) near a stretched leg I, hence the
/// looser length tolerance; exactness of every solver solution is checked separately (EQ_MM).
const MATCH_RAD: f64 = 1e-7;
const MATCH_MM: f64 = 1e-4;
/// A forward-kinematics root of the scanned function where eq. (3)'s residual g is not this
/// small (mm) would be a zero of the determinant, not a root of g.
const POLE_MM: f64 = 1e-6;
/// At most this fraction of inputs may be skipped as ambiguous.
const MAX_SKIPPED_FRACTION: f64 = 0.01;

// ---------------------------------------------------------------- deterministic pseudo-random

/// xorshift64* (Vigna 2016): a tiny deterministic generator, no rand crate.
struct XorShift(u64);

impl XorShift {
    fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(2.0 * PI);
    if w > PI { w - 2.0 * PI } else { w }
}

fn ang(a: f64, b: f64) -> f64 {
    wrap(a - b).abs()
}

/// Eqs. (3)-(6) of IFToMM 2007 written out again, as length errors |f| / (2 L) (mm): an
/// independent check of the library's `residual_mm`.
fn paper_residual_mm(g: &ModuleGeometry, p: &Vector3<f64>, alpha: f64, rho: &Vector3<f64>) -> f64 {
    let (s, c) = alpha.sin_cos();
    let (x, y, z) = (p.x, p.y, p.z);
    let sq = |a: f64| a * a;
    let f3 =
        sq(x + g.dx1) + sq(y + g.r_big1 * c - g.r_small1) + sq(z + g.r_big1 * s - rho.x) - sq(g.l1);
    let f4 =
        sq(x + g.dx1) + sq(y - g.r_big1 * c + g.r_small1) + sq(z - g.r_big1 * s - rho.x) - sq(g.l1);
    let f5 = sq(x + g.dx2) + sq(y - g.r_big2 * c + g.r4) + sq(z - g.r_big2 * s - rho.y) - sq(g.l2);
    let f6 = sq(x + g.dx2) + sq(y + g.r_big2 * c - g.r4) + sq(z + g.r_big2 * s - rho.z) - sq(g.l3);
    [
        f3 / (2.0 * g.l1),
        f4 / (2.0 * g.l1),
        f5 / (2.0 * g.l2),
        f6 / (2.0 * g.l3),
    ]
    .iter()
    .fold(0.0f64, |m, v| m.max(v.abs()))
}

// ---------------------------------------------------------------- generic cyclic scan

/// Outcome of scanning one periodic function.
enum Scan {
    /// Parameters of every root found.
    Roots(Vec<f64>),
    /// A near-double root the scan cannot decide.
    Ambiguous,
}

/// Bisection of a bracketed sign change of `f` on [a, b] to machine precision.
fn bisect(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let fa = f(a);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = f(m);
        if fm == 0.0 {
            return m;
        }
        if (fm < 0.0) == (fa < 0.0) {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// Minimises `sign * f` on [a, b] by golden-section search; returns (argmin, f(argmin)).
fn golden_min(f: &dyn Fn(f64) -> f64, sign: f64, mut a: f64, mut b: f64) -> (f64, f64) {
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let mut x1 = b - phi * (b - a);
    let mut x2 = a + phi * (b - a);
    let mut f1 = sign * f(x1);
    let mut f2 = sign * f(x2);
    for _ in 0..120 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - phi * (b - a);
            f1 = sign * f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + phi * (b - a);
            f2 = sign * f(x2);
        }
        if b - a <= 1e-15 * (1.0 + a.abs()) {
            break;
        }
    }
    let x = 0.5 * (a + b);
    (x, f(x))
}

/// Every root of the `period`-periodic function `f` (values in mm), from `n` samples: sign
/// changes bisected, local minima of |f| refined (two close roots or none). `f` must be
/// continuous (no poles). `in_mm(t)` is the residual at t as a length (mm), by which a refined
/// local minimum is judged a near-double root (ambiguous).
fn scan_cyclic(f: &dyn Fn(f64) -> f64, in_mm: &dyn Fn(f64) -> f64, period: f64, n: usize) -> Scan {
    let h = period / n as f64;
    let v: Vec<f64> = (0..n).map(|i| f(i as f64 * h)).collect();
    let mut roots = Vec::new();
    let push = |t: f64, roots: &mut Vec<f64>| roots.push(t.rem_euclid(period));
    for i in 0..n {
        let (vp, vi, vn) = (v[(i + n - 1) % n], v[i], v[(i + 1) % n]);
        let ti = i as f64 * h;
        if !vi.is_finite() {
            continue;
        }
        if vi == 0.0 {
            push(ti, &mut roots);
            continue;
        }
        if vn != 0.0 && vn.is_finite() && (vi < 0.0) != (vn < 0.0) {
            push(bisect(f, ti, ti + h), &mut roots);
            continue;
        }
        // A local minimum of |f| with no sign change around it: refine.
        let same_sign = (vp < 0.0) == (vi < 0.0) && (vn < 0.0) == (vi < 0.0);
        if same_sign && vi.abs() <= vp.abs() && vi.abs() < vn.abs() {
            let sign = vi.signum();
            let (tm, fm) = golden_min(f, sign, ti - h, ti + h);
            if in_mm(tm).abs() <= AMBIGUOUS_MM {
                return Scan::Ambiguous;
            }
            if (fm < 0.0) != (vi < 0.0) {
                push(bisect(f, ti - h, tm), &mut roots);
                push(bisect(f, tm, ti + h), &mut roots);
            }
        }
    }
    Scan::Roots(roots)
}

// ---------------------------------------------------------------- IK oracle

/// Leg-I postures (alpha, rho1) of point p by scanning alpha: eq. (10) gives
/// rho1 - zp = +-sqrt(h2(alpha)), and the residual of eq. (14) is scanned along the closed curve
/// (alpha, +sqrt) then (alpha, -sqrt) back. At y_p = 0 the postures are written down directly
/// (alpha in {0, pi} with both signs, or alpha = +-alpha1 with rho1 = zp, Tables I-II).
fn ik_oracle_leg1(g: &ModuleGeometry, p: &Vector3<f64>) -> Option<Vec<(f64, f64)>> {
    let (r, rr) = (g.r_big1, g.r_small1);
    let u = p.x + g.dx1;
    let y = p.y;
    let k0 = g.l1 * g.l1 - r * r - rr * rr;
    let h2 = |a: f64| k0 + 2.0 * r * rr * a.cos() - u * u - y * y;
    // h2 >= 0 exactly where cos(alpha) >= cstar.
    let cstar = (u * u + y * y - k0) / (2.0 * r * rr);
    if cstar >= 1.0 {
        return Some(vec![]);
    }
    if y == 0.0 {
        let mut out = Vec::new();
        if (cstar + 1.0).abs() < 1e-12 || (cstar - 1.0).abs() < 1e-12 {
            return None;
        }
        for a0 in [0.0, PI] {
            let d2 = h2(a0);
            if d2 > 0.0 {
                out.push((a0, p.z + d2.sqrt()));
                out.push((a0, p.z - d2.sqrt()));
            }
        }
        if cstar > -1.0 {
            let a1 = cstar.acos();
            out.push((a1, p.z));
            out.push((-a1, p.z));
        }
        return Some(out);
    }
    // eq. (14) residual divided by R1 (mm): y (cos a - r1/R1) - sin a (rho1 - zp).
    let e = |a: f64, s: f64| y * (a.cos() - rr / r) - a.sin() * s * h2(a).max(0.0).sqrt();
    let mut out = Vec::new();
    if cstar <= -1.0 {
        // Two separate periodic branches.
        for s in [1.0, -1.0] {
            let f = |t: f64| e(t - PI, s);
            match scan_cyclic(&f, &f, 2.0 * PI, SCAN_STEPS) {
                Scan::Ambiguous => return None,
                Scan::Roots(ts) => {
                    for t in ts {
                        let a = wrap(t - PI);
                        out.push((a, p.z + s * h2(a).max(0.0).sqrt()));
                    }
                }
            }
        }
    } else {
        // One closed loop over [-am, am] and back: theta in [0, 2).
        let am = cstar.acos();
        let at = |t: f64| {
            let t = t.rem_euclid(2.0);
            if t < 1.0 {
                (-am + 2.0 * am * t, 1.0)
            } else {
                (am - 2.0 * am * (t - 1.0), -1.0)
            }
        };
        let f = |t: f64| {
            let (a, s) = at(t);
            e(a, s)
        };
        match scan_cyclic(&f, &f, 2.0, 2 * SCAN_STEPS) {
            Scan::Ambiguous => return None,
            Scan::Roots(ts) => {
                for t in ts {
                    let (a, s) = at(t);
                    out.push((a, p.z + s * h2(a).max(0.0).sqrt()));
                }
            }
        }
    }
    Some(out)
}

/// The leg-I postures for which legs II and III can also be assembled (eqs. (12)-(13) real),
/// or None when the point is ambiguous for the scan.
fn ik_oracle(g: &ModuleGeometry, p: &Vector3<f64>) -> Option<Vec<(f64, f64)>> {
    let leg1 = ik_oracle_leg1(g, p)?;
    let dx2 = p.x + g.dx2;
    let mut out = Vec::new();
    for (a, rho1) in leg1 {
        let c = a.cos();
        let arg2 = g.l2 * g.l2 - dx2 * dx2 - (p.y - g.r_big2 * c + g.r4).powi(2);
        let arg3 = g.l3 * g.l3 - dx2 * dx2 - (p.y + g.r_big2 * c - g.r4).powi(2);
        if arg2.abs() < STRETCHED_REL * g.l2 * g.l2 || arg3.abs() < STRETCHED_REL * g.l3 * g.l3 {
            return None;
        }
        if arg2 > 0.0 && arg3 > 0.0 {
            out.push((a, rho1));
        }
    }
    Some(out)
}

#[derive(Default, Debug)]
struct Tally {
    inputs: usize,
    skipped: usize,
    solutions: usize,
    worst_residual_mm: f64,
    worst_match_rad: f64,
    worst_match_mm: f64,
    /// Histogram of the number of solutions per input (index = count).
    histogram: [usize; 17],
    failures: Vec<String>,
}

impl Tally {
    fn fail(&mut self, msg: String) {
        if self.failures.len() < 20 {
            self.failures.push(msg);
        } else if self.failures.len() == 20 {
            self.failures.push("...".into());
        }
    }

    fn check(&self, what: &str) {
        eprintln!("{what}: {self:#?}");
        assert!(self.failures.is_empty(), "{what}: {:#?}", self.failures);
        assert!(
            (self.skipped as f64) <= MAX_SKIPPED_FRACTION * self.inputs as f64,
            "{what}: {} of {} inputs skipped as ambiguous",
            self.skipped,
            self.inputs
        );
    }
}

fn ik_compare(m: &Machine, p: &Vector3<f64>, t: &mut Tally) {
    let g = &m.module;
    t.inputs += 1;
    let branches = ik::solve(m, p);
    // Exactness does not depend on the oracle.
    for b in &branches {
        let pose = ModulePose {
            p: *p,
            alpha: b.alpha,
        };
        let r = residual_mm(g, &pose, &b.rho).max(paper_residual_mm(g, p, b.alpha, &b.rho));
        t.worst_residual_mm = t.worst_residual_mm.max(r);
        if r.is_nan() || r >= EQ_MM {
            t.fail(format!("IK p={p:?}: branch {b:?} residual {r:e} mm"));
        }
    }
    if branches.iter().filter(|b| b.working()).count() > 1 {
        t.fail(format!("IK p={p:?}: several working branches"));
    }
    let Some(oracle) = ik_oracle(g, p) else {
        t.skipped += 1;
        return;
    };
    // Distinct leg-I postures of the solver.
    let mut pairs: Vec<(f64, f64)> = Vec::new();
    for b in &branches {
        if !pairs
            .iter()
            .any(|&(a, r1)| ang(a, b.alpha) < 1e-12 && (r1 - b.rho.x).abs() < 1e-9)
        {
            pairs.push((b.alpha, b.rho.x));
        }
    }
    t.solutions += pairs.len();
    t.histogram[pairs.len().min(16)] += 1;
    if pairs.len() != oracle.len() || branches.len() != 4 * oracle.len() {
        t.fail(format!(
            "IK p={p:?}: oracle {} postures {oracle:?}, solver {} postures {pairs:?}, {} branches",
            oracle.len(),
            pairs.len(),
            branches.len()
        ));
        return;
    }
    for &(a, r1) in &oracle {
        let best = pairs
            .iter()
            .map(|&(b, s1)| (ang(a, b), (r1 - s1).abs()))
            .min_by(|x, y| (x.0 + x.1 * 1e-3).total_cmp(&(y.0 + y.1 * 1e-3)));
        match best {
            Some((da, dr)) if da <= MATCH_RAD && dr <= MATCH_MM => {
                t.worst_match_rad = t.worst_match_rad.max(da);
                t.worst_match_mm = t.worst_match_mm.max(dr);
            }
            _ => t.fail(format!(
                "IK p={p:?}: oracle posture ({a}, {r1}) not in solver {pairs:?}"
            )),
        }
    }
}

#[test]
fn ik_matches_scan_oracle_on_random_points() {
    let m = Machine::default_verne();
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let mut t = Tally::default();
    // Inside and around the workspace.
    for _ in 0..3000 {
        let p = Vector3::new(
            rng.uniform(-600.0, 400.0),
            rng.uniform(-500.0, 500.0),
            rng.uniform(500.0, 1600.0),
        );
        ik_compare(&m, &p, &mut t);
    }
    // Wider, including unreachable points.
    for _ in 0..1000 {
        let p = Vector3::new(
            rng.uniform(-2000.0, 1500.0),
            rng.uniform(-1500.0, 1500.0),
            rng.uniform(-1000.0, 3000.0),
        );
        ik_compare(&m, &p, &mut t);
    }
    // On y_p = 0 exactly and within 1e-9 of it.
    for k in 0..600 {
        let y = [0.0, 1e-9, -1e-9][k % 3];
        let p = Vector3::new(rng.uniform(-900.0, 600.0), y, rng.uniform(500.0, 1600.0));
        ik_compare(&m, &p, &mut t);
    }
    t.check("IK vs scan oracle");
    // Not vacuous: unreachable points, and points with the full four postures, both occurred.
    assert!(
        t.histogram[0] > 0 && t.histogram[4] > 0,
        "{:?}",
        t.histogram
    );
}

// ---------------------------------------------------------------- FK oracle

/// Centres of the four spheres of eqs. (3)-(6) at a fixed alpha: P lies at distance L_i from C_i.
fn sphere_centres(g: &ModuleGeometry, rho: &Vector3<f64>, alpha: f64) -> [Vector3<f64>; 4] {
    let (s, c) = alpha.sin_cos();
    [
        Vector3::new(-g.dx1, g.r_small1 - g.r_big1 * c, rho.x - g.r_big1 * s),
        Vector3::new(-g.dx1, g.r_big1 * c - g.r_small1, rho.x + g.r_big1 * s),
        Vector3::new(-g.dx2, g.r_big2 * c - g.r4, rho.y + g.r_big2 * s),
        Vector3::new(-g.dx2, g.r4 - g.r_big2 * c, rho.z - g.r_big2 * s),
    ]
}

/// The point on spheres (4)-(6) minus sphere (3) (three planes), by a 3x3 linear solve.
fn planes_point(g: &ModuleGeometry, rho: &Vector3<f64>, alpha: f64) -> Option<Vector3<f64>> {
    let c = sphere_centres(g, rho, alpha);
    let l = [g.l1, g.l1, g.l2, g.l3];
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for j in 1..4 {
        let d = c[j] - c[0];
        a.set_row(j - 1, &(2.0 * d).transpose());
        b[j - 1] = c[j].norm_squared() - c[0].norm_squared() - l[j] * l[j] + l[0] * l[0];
    }
    a.lu().solve(&b)
}

/// g(alpha): residual of eq. (3) at the planes' point, as a length (mm). It has double poles
/// where the three planes are parallel to one line (det = 0, condition (21)), or None there.
fn fk_g(g: &ModuleGeometry, rho: &Vector3<f64>, alpha: f64) -> Option<f64> {
    let p = planes_point(g, rho, alpha)?;
    let c0 = sphere_centres(g, rho, alpha)[0];
    Some(((p - c0).norm_squared() - g.l1 * g.l1) / (2.0 * g.l1))
}

/// The scanned function: g(alpha) times (det / h)^2, with det the determinant of the planes'
/// 3x3 system and h its Hadamard bound (the product of the row norms, so |det / h| <= 1).
/// Multiplying by det^2 removes the double poles of g without adding sign changes (at det = 0
/// the product is |adj(A) b|^2 / h^2 >= 0). This matters: where rho2 = rho3 a pole sits at
/// alpha = 0 with a real root on each side of it 1e-4 rad away, a pair that a scan of g itself
/// steps over without seeing (g is positive on both sides of a double pole). The planes' point is
/// written with Cramer's rule, P det = b1 (a2 x a3) + b2 (a3 x a1) + b3 (a1 x a2).
fn fk_scanned(g: &ModuleGeometry, rho: &Vector3<f64>, alpha: f64) -> f64 {
    let c = sphere_centres(g, rho, alpha);
    let l = [g.l1, g.l1, g.l2, g.l3];
    let a: [Vector3<f64>; 3] = std::array::from_fn(|j| 2.0 * (c[j + 1] - c[0]));
    let b: [f64; 3] = std::array::from_fn(|j| {
        c[j + 1].norm_squared() - c[0].norm_squared() - l[j + 1] * l[j + 1] + l[0] * l[0]
    });
    let h = a[0].norm() * a[1].norm() * a[2].norm();
    let cof = [a[1].cross(&a[2]), a[2].cross(&a[0]), a[0].cross(&a[1])];
    let d = a[0].dot(&cof[0]) / h;
    let q = (cof[0] * b[0] + cof[1] * b[1] + cof[2] * b[2]) / h; // = d P
    ((q - c[0] * d).norm_squared() - l[0] * l[0] * d * d) / (2.0 * l[0])
}

/// Every assembly mode (alpha, P) found by the scan, or None when ambiguous.
fn fk_oracle(g: &ModuleGeometry, rho: &Vector3<f64>) -> Option<Vec<(f64, Vector3<f64>)>> {
    let f = |t: f64| fk_scanned(g, rho, t - PI);
    // Near-double roots are judged on g itself: near a pole the scanned product is small only
    // because det is.
    let in_mm = |t: f64| fk_g(g, rho, t - PI).unwrap_or(f64::INFINITY);
    let Scan::Roots(ts) = scan_cyclic(&f, &in_mm, 2.0 * PI, SCAN_STEPS) else {
        return None;
    };
    let mut out = Vec::new();
    for t in ts {
        let a = wrap(t - PI);
        // A root must be a root of g itself, not a zero of det (|g| bounded).
        match (fk_g(g, rho, a), planes_point(g, rho, a)) {
            (Some(v), Some(p)) if v.abs() <= POLE_MM => out.push((a, p)),
            _ => return None,
        }
    }
    Some(out)
}

fn fk_compare(m: &Machine, rho: &Vector3<f64>, t: &mut Tally) {
    let g = &m.module;
    t.inputs += 1;
    let modes = fk::solve(m, rho);
    for md in &modes {
        let r =
            residual_mm(g, &md.pose, rho).max(paper_residual_mm(g, &md.pose.p, md.pose.alpha, rho));
        t.worst_residual_mm = t.worst_residual_mm.max(r);
        if r.is_nan() || r >= EQ_MM {
            t.fail(format!("FK rho={rho:?}: mode {md:?} residual {r:e} mm"));
        }
    }
    if modes.iter().filter(|md| md.working()).count() > 1 {
        t.fail(format!("FK rho={rho:?}: several working modes"));
    }
    let Some(oracle) = fk_oracle(g, rho) else {
        t.skipped += 1;
        return;
    };
    t.solutions += modes.len();
    t.histogram[modes.len().min(16)] += 1;
    if modes.len() != oracle.len() {
        t.fail(format!(
            "FK rho={rho:?}: oracle {} modes {oracle:?}, solver {} modes {:?}",
            oracle.len(),
            modes.len(),
            modes.iter().map(|md| md.pose).collect::<Vec<_>>()
        ));
        return;
    }
    for (a, p) in &oracle {
        let best = modes
            .iter()
            .map(|md| (ang(*a, md.pose.alpha), (p - md.pose.p).amax()))
            .min_by(|x, y| (x.0 + x.1 * 1e-3).total_cmp(&(y.0 + y.1 * 1e-3)));
        match best {
            Some((da, dp)) if da <= MATCH_RAD && dp <= MATCH_MM * (1.0 + p.amax() * 1e-3) => {
                t.worst_match_rad = t.worst_match_rad.max(da);
                t.worst_match_mm = t.worst_match_mm.max(dp);
            }
            _ => t.fail(format!(
                "FK rho={rho:?}: oracle mode ({a}, {p:?}) not found"
            )),
        }
    }
}

#[test]
fn fk_matches_scan_oracle_on_random_joints() {
    let m = Machine::default_verne();
    let mut rng = XorShift(0xD1B5_4A32_D192_ED03);
    let mut t = Tally::default();
    for _ in 0..1500 {
        let rho = Vector3::new(
            rng.uniform(0.0, 1100.0),
            rng.uniform(0.0, 1100.0),
            rng.uniform(0.0, 1100.0),
        );
        fk_compare(&m, &rho, &mut t);
    }
    for _ in 0..1000 {
        let rho = Vector3::new(
            rng.uniform(-1500.0, 2500.0),
            rng.uniform(-1500.0, 2500.0),
            rng.uniform(-1500.0, 2500.0),
        );
        fk_compare(&m, &rho, &mut t);
    }
    // Joints of IK solutions (every branch, not only the working one): always assemblable.
    for _ in 0..150 {
        let p = Vector3::new(
            rng.uniform(-600.0, 400.0),
            rng.uniform(-500.0, 500.0),
            rng.uniform(500.0, 1600.0),
        );
        for b in ik::solve(&m, &p).iter().step_by(3) {
            fk_compare(&m, &b.rho, &mut t);
        }
    }
    t.check("FK vs scan oracle");
    assert!(
        t.histogram[0] > 0 && t.histogram[4] > 0,
        "{:?}",
        t.histogram
    );
}

#[test]
fn fk_matches_scan_oracle_on_special_joints() {
    // Joints where the elimination degenerates or roots crowd: every IK branch of points on
    // y_p = 0 (alpha in {0, pi}: pairs of modes 1e-4 rad apart with the poles of condition (21)
    // beside them), the same within 1e-9 mm, and rho2 = rho3 (condition (21) at alpha in {0, pi}).
    let m = Machine::default_verne();
    let mut rng = XorShift(0x0123_4567_89AB_CDEF);
    let mut t = Tally::default();
    for k in 0..120 {
        let p = Vector3::new(rng.uniform(-600.0, 400.0), 0.0, rng.uniform(500.0, 1600.0));
        let eps = [0.0, 1e-9, -1e-9][k % 3];
        for b in ik::solve(&m, &p).iter().step_by(2) {
            fk_compare(&m, &(b.rho + Vector3::new(eps, -eps, eps)), &mut t);
        }
    }
    for k in 0..600 {
        let r = rng.uniform(0.0, 1100.0);
        let eps = [0.0, 1e-9, -1e-9][k % 3];
        let rho = Vector3::new(rng.uniform(0.0, 1100.0), r, r + eps);
        fk_compare(&m, &rho, &mut t);
    }
    t.check("FK vs scan oracle, special joints");
    assert!(t.histogram[4] > 0, "{:?}", t.histogram);
}

// ---------------------------------------------------------------- FK oracle without Det

/// The pose of parameter (alpha, tau): (y, zp - rho1) = tau (-R1 sin a, R1 cos a - r1) solves
/// eq. (14) for any tau; xp from (5) - (10) (linear in xp once y and z are known), computed from
/// the two equations' residual terms written out again. No division by condition (21).
fn tau_pose(g: &ModuleGeometry, rho: &Vector3<f64>, alpha: f64, tau: f64) -> Vector3<f64> {
    let (s, c) = alpha.sin_cos();
    let y = -g.r_big1 * s * tau;
    let zr = (g.r_big1 * c - g.r_small1) * tau;
    let z = zr + rho.x;
    let delta = g.dx2 - g.dx1;
    let k1 = g.l1 * g.l1 - g.r_big1 * g.r_big1 - g.r_small1 * g.r_small1
        + 2.0 * g.r_big1 * g.r_small1 * c;
    let y5 = y - g.r_big2 * c + g.r4;
    let z5 = z - g.r_big2 * s - rho.y;
    // (u + delta)^2 + y5^2 + z5^2 - L2^2 - (u^2 + y^2 + zr^2 - K1) = 0, u = xp + D1 - d1.
    let u =
        (g.l2 * g.l2 - k1 - delta * delta - y5 * y5 - z5 * z5 + y * y + zr * zr) / (2.0 * delta);
    Vector3::new(u - g.dx1, y, z)
}

/// Eq. (10)'s residual (the sphere of leg I's midpoint) at (alpha, tau), and (6) - (5)'s, both
/// from the pose of [`tau_pose`] through `paper`-style terms (mm^2).
fn tau_residuals(g: &ModuleGeometry, rho: &Vector3<f64>, alpha: f64, tau: f64) -> (f64, f64) {
    let p = tau_pose(g, rho, alpha, tau);
    let (s, c) = alpha.sin_cos();
    let sq = |a: f64| a * a;
    let u = p.x + g.dx1;
    let k1 = g.l1 * g.l1 - g.r_big1 * g.r_big1 - g.r_small1 * g.r_small1
        + 2.0 * g.r_big1 * g.r_small1 * c;
    let f10 = sq(u) + sq(p.y) + sq(p.z - rho.x) - k1;
    let f5 =
        sq(p.x + g.dx2) + sq(p.y - g.r_big2 * c + g.r4) + sq(p.z - g.r_big2 * s - rho.y) - sq(g.l2);
    let f6 =
        sq(p.x + g.dx2) + sq(p.y + g.r_big2 * c - g.r4) + sq(p.z + g.r_big2 * s - rho.z) - sq(g.l3);
    (f10, f6 - f5)
}

/// Every assembly mode by a second scan that never divides by condition (21): for each alpha of
/// a dense grid, eq. (10) along the (y, z) line of eq. (14) is a quadratic in tau (its three
/// coefficients from its values at tau = -1, 0, 1); along each of its two roots tau+-(alpha),
/// the residual of (6) - (5) is scanned for sign changes, which bisection refines. Where the
/// two roots meet (the quadratic's discriminant changes sign) the two scans join. None where a
/// local minimum of a scanned residual is within rounding of zero (undecided: the caller counts
/// it). Two modes that share alpha (a zero of condition (21)) have different tau: both found.
fn fk_oracle_tau(g: &ModuleGeometry, rho: &Vector3<f64>) -> Option<Vec<(f64, Vector3<f64>)>> {
    let taus = |alpha: f64| -> Option<[f64; 2]> {
        let q = |t: f64| tau_residuals(g, rho, alpha, t).0;
        let (qm, q0, qp) = (q(-1.0), q(0.0), q(1.0));
        let (a2, a1, a0) = (0.5 * (qp + qm) - q0, 0.5 * (qp - qm), q0);
        let disc = a1 * a1 - 4.0 * a2 * a0;
        if disc < 0.0 || a2 == 0.0 {
            return None;
        }
        let h = -0.5 * (a1 + a1.signum() * disc.sqrt());
        let (t1, t2) = (h / a2, a0 / h);
        Some(if t1 <= t2 { [t1, t2] } else { [t2, t1] })
    };
    // The residual of (6) - (5) along root k, with the two roots' curves joined into one
    // closed curve where they meet: parameter x in [0, 2 pi) runs root 0, [2 pi, 4 pi) root 1
    // backwards.
    let n = SCAN_STEPS;
    let h = 2.0 * PI / n as f64;
    let g_of = |alpha: f64, k: usize| -> Option<f64> {
        taus(alpha).map(|t| tau_residuals(g, rho, alpha, t[k]).1 / (2.0 * g.l2))
    };
    let mut out: Vec<(f64, Vector3<f64>)> = Vec::new();
    for k in 0..2 {
        let vals: Vec<Option<f64>> = (0..=n).map(|i| g_of(-PI + i as f64 * h, k)).collect();
        for i in 0..n {
            let (a, b) = (-PI + i as f64 * h, -PI + (i + 1) as f64 * h);
            let (Some(va), Some(vb)) = (vals[i], vals[i + 1]) else {
                // An end of an arc where the two roots in tau meet (between two samples): the
                // end found by bisection on whether the roots are real, and a sign change of the
                // residual between the end and the sample inside bisected (a mode there would
                // hide from the samples).
                let (inside, outside, v) = match (vals[i], vals[i + 1]) {
                    (Some(v), None) => (a, b, v),
                    (None, Some(v)) => (b, a, v),
                    _ => continue,
                };
                let (mut lo, mut hi) = (inside, outside);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if taus(mid).is_some() {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let Some(ve) = g_of(lo, k) else { continue };
                if ve.abs() <= AMBIGUOUS_MM {
                    return None;
                }
                if (ve < 0.0) != (v < 0.0) {
                    let f = |x: f64| g_of(x, k).unwrap_or(f64::NAN);
                    let alpha = bisect(&f, lo.min(inside), lo.max(inside));
                    let tau = taus(alpha)?[k];
                    out.push((alpha, tau_pose(g, rho, alpha, tau)));
                }
                continue;
            };
            if va == 0.0 || (va < 0.0) != (vb < 0.0) {
                let f = |x: f64| g_of(x, k).unwrap_or(f64::NAN);
                let alpha = bisect(&f, a, b);
                let tau = taus(alpha)?[k];
                out.push((alpha, tau_pose(g, rho, alpha, tau)));
                continue;
            }
            // A local minimum of |g| between samples: two roots or none, undecided if near 0.
            let prev = if i > 0 { vals[i - 1] } else { None };
            if let Some(vp) = prev {
                if (vp < 0.0) == (va < 0.0) && va.abs() <= vp.abs() && va.abs() < vb.abs() {
                    let f = |x: f64| g_of(x, k).unwrap_or(f64::NAN);
                    let (xm, fm) = golden_min(&f, va.signum(), a - h, b);
                    if fm.is_nan() || fm.abs() <= AMBIGUOUS_MM {
                        return None;
                    }
                    if (fm < 0.0) != (va < 0.0) {
                        for (lo, hi) in [(a - h, xm), (xm, b)] {
                            let alpha = bisect(&f, lo, hi);
                            let tau = taus(alpha)?[k];
                            out.push((alpha, tau_pose(g, rho, alpha, tau)));
                        }
                    }
                }
            }
        }
    }
    // Keep what solves (3)-(6) (a bisection across the meeting of the two roots gives a point
    // that does not), one copy of each.
    out.retain(|(a, p)| paper_residual_mm(g, p, *a, rho) < EQ_MM);
    let mut unique: Vec<(f64, Vector3<f64>)> = Vec::new();
    for (a, p) in out {
        if !unique
            .iter()
            .any(|(b, q)| ang(a, *b) < 1e-9 && (p - q).amax() < 1e-6)
        {
            unique.push((wrap(a), p));
        }
    }
    Some(unique)
}

/// The second oracle on poses built on the solvers' degenerate sets (verne::selftest::hard_sets): every
/// mode it finds is among the solver's and the reverse; the rows it cannot decide are counted
/// and reported (not skipped silently), and must stay rare.
#[test]
fn fk_matches_the_tau_scan_oracle_on_constructed_hard_poses() {
    use verne::selftest::hard_sets::{
        HardSet, Sampler, construct, random_geometries, random_start,
    };
    let mut machines = vec![Machine::default_verne()];
    machines.extend(random_geometries(4, 5150));
    let (mut rows, mut undecided, mut compared) = (0usize, Vec::new(), 0usize);
    let mut failures = Vec::new();
    let mut rng = Sampler::new(4242);
    for m in &machines {
        let g = &m.module;
        for set in [
            HardSet::Condition21,
            HardSet::SliderMean,
            HardSet::EqualOuterSliders,
            HardSet::YpZero,
        ] {
            let mut built = 0;
            for _ in 0..40 {
                if built >= 2 {
                    break;
                }
                let Some((p0, b)) = random_start(m, &mut rng) else {
                    continue;
                };
                let poses = construct(m, set, &p0, &rng.direction(), &b, 300.0);
                built += usize::from(!poses.is_empty());
                for c in poses.iter().step_by(2) {
                    rows += 1;
                    let Some(oracle) = fk_oracle_tau(g, &c.rho) else {
                        undecided.push(format!("{} {set:?} rho = {:?}", m.name, c.rho));
                        continue;
                    };
                    compared += 1;
                    let modes = fk::solve(m, &c.rho);
                    let same = |a: f64, p: &Vector3<f64>, md: &fk::FkMode| {
                        ang(a, md.pose.alpha) <= MATCH_RAD && (p - md.pose.p).amax() <= MATCH_MM
                    };
                    for (a, p) in &oracle {
                        if !modes.iter().any(|md| same(*a, p, md)) {
                            failures.push(format!(
                                "{} {set:?} rho = {:?}: oracle mode ({a}, {p:?}) not in the solver's",
                                m.name, c.rho
                            ));
                        }
                    }
                    for md in &modes {
                        if !oracle.iter().any(|(a, p)| same(*a, p, md)) {
                            failures.push(format!(
                                "{} {set:?} rho = {:?}: solver mode {:?} not found by the oracle",
                                m.name, c.rho, md.pose
                            ));
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "tau-scan oracle: {rows} constructed rows, {compared} compared, {} undecided: {:#?}",
        undecided.len(),
        undecided
    );
    assert!(compared > 50, "only {compared} rows compared");
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(
        undecided.len() as f64 <= 0.2 * rows as f64,
        "{} of {rows} undecided",
        undecided.len()
    );
}
