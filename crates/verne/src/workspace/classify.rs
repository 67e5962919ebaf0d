//! One grid point of the workspace: the platform points it stands for (the point itself, or
//! P(alpha) for a tool tip), their branches with s = (-1, -1, -1), the constraints each fails,
//! and the outcome (inside, or the binding constraint of the reference branch).

use nalgebra::Vector3;

use arrayvec::ArrayVec;

use crate::math::scalar::{Mag, Scalar};
use crate::math::trig::{MAX_TRIG_ROOTS, Trig};
use crate::parallel_module::branches::{Reason, WORKING_CONFIG};
use crate::parallel_module::equations::ModulePose;
use crate::parallel_module::ik::{self, IkBranch, wrap_angle};
use crate::parallel_module::kinetostatics::amplification_factors;
use crate::parallel_module::leg1_certify::{self, AllForms, PathForms};
use crate::spec::{Machine, ModuleGeometry, TableGeometry};
use crate::tolerance::LIMIT_SLACK;

use super::{Constraint, Fails, Of, Outcome, PointBranch, PointResult, WorkspaceOptions};

/// An inverse-kinematics branch of P(alpha_root) belongs to the root alpha_root when their
/// angles differ by less than this (rad). The root of the degree-6 polynomial and the branch's
/// alpha (polished on eqs. (3)-(6)) agree to about 1e-12 rad at a simple root.
pub const ALPHA_MATCH_RAD: f64 = 1e-7;

/// Tool tip U = bT_pl (0, 0, Delta): eq. (27), AIM 2007.
pub fn tool_tip(p: &Vector3<f64>, alpha: f64, delta: f64) -> Vector3<f64> {
    let (s, c) = alpha.sin_cos();
    Vector3::new(p.x, p.y - delta * s, p.z + delta * c)
}

/// Tool tip in the table frame with theta1 = alpha, theta2 = phi1 = phi2 = 0 (the equations'
/// angles): eq. (26), AIM 2007, X_u = xp, Y_u = V1, Z_u = sin(theta1) yp + V2 with
/// V1 = Delta sin(alpha - theta1) - cos(theta1) yp - sin(theta1) (zp - d_a) + y_t,
/// V2 = d_t - cos(theta1) zp + d_a cos(theta1) - Delta cos(alpha - theta1).
pub fn manufacturing_tip(
    t: &TableGeometry,
    p: &Vector3<f64>,
    alpha: f64,
    delta: f64,
) -> Vector3<f64> {
    let theta1 = alpha;
    let (s, c) = theta1.sin_cos();
    let v1 = delta * (alpha - theta1).sin() - c * p.y - s * (p.z - t.d_a) + t.y_t;
    let v2 = t.d_t - c * p.z + t.d_a * c - delta * (alpha - theta1).cos();
    Vector3::new(p.x, v1, s * p.y + v2)
}

/// The grid point of a platform pose for the chosen workspace.
pub fn grid_point_of(
    m: &Machine,
    of: Of,
    delta: f64,
    p: &Vector3<f64>,
    alpha: f64,
) -> Vector3<f64> {
    match of {
        Of::Platform => *p,
        Of::Tool => tool_tip(p, alpha, delta),
        Of::Manufacturing => manufacturing_tip(&m.table, p, alpha, delta),
    }
}

/// P as a function of alpha for a fixed grid point: (x, a0 + a_s s + a_c c, b0 + b_s s + b_c c),
/// eqs. (26)-(27) solved for P.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PlatformOfAlpha {
    x: f64,
    /// [a0, a_s, a_c]
    a: [f64; 3],
    /// [b0, b_s, b_c]
    b: [f64; 3],
}

impl PlatformOfAlpha {
    fn new(of: Of, t: &TableGeometry, delta: f64, q: &Vector3<f64>) -> Self {
        match of {
            Of::Platform => PlatformOfAlpha {
                x: q.x,
                a: [q.y, 0.0, 0.0],
                b: [q.z, 0.0, 0.0],
            },
            // eq. (27): yp = y_U + Delta sin(alpha), zp = z_U - Delta cos(alpha).
            Of::Tool => PlatformOfAlpha {
                x: q.x,
                a: [q.y, delta, 0.0],
                b: [q.z, 0.0, -delta],
            },
            // eq. (26) with theta1 = alpha: (Y, Z') = -R(alpha) (yp, zp - d_a) with
            // Z' = Z - d_t + Delta and R = [[c, s], [-s, c]], so yp = -c Y + s Z',
            // zp = d_a - s Y - c Z'.
            // (Y is Y_u - y_t when the rotary axis is off the tilting axis's plane.)
            Of::Manufacturing => {
                let zq = q.z - t.d_t + delta;
                let yq = q.y - t.y_t;
                PlatformOfAlpha {
                    x: q.x,
                    a: [0.0, zq, -yq],
                    b: [t.d_a, -yq, -zq],
                }
            }
        }
    }

    fn at(&self, alpha: f64) -> Vector3<f64> {
        let (s, c) = alpha.sin_cos();
        Vector3::new(
            self.x,
            self.a[0] + self.a[1] * s + self.a[2] * c,
            self.b[0] + self.b[1] * s + self.b[2] * c,
        )
    }

    /// Eq. (15), AIM 2007, at P(alpha): a trigonometric polynomial of degree 3 in alpha (the
    /// paper's degree-6 polynomial in tan(alpha/2)),
    ///
    /// G = R1^2 sin^2(alpha) (u^2 - K1) + yp^2 N, K1 = L1^2 - N, N = R1^2 + r1^2 - 2 R1 r1 cos(alpha),
    /// u = xp + D1 - d1, yp = a0 + a_s sin(alpha) + a_c cos(alpha),
    ///
    /// computed as the machine's `theta1_equation` computes it, so that the bound of
    /// [`leg1_certify::forms_error`] holds for it.
    fn coupling_equation(&self, g: &ModuleGeometry) -> Trig {
        let (r, rr) = (g.r_big1, g.r_small1);
        let u = self.x + g.dx1;
        let k0 = g.l1 * g.l1 - r * r - rr * rr;
        let ca = Trig::linear(0.0, 1.0, 0.0);
        let sa = Trig::linear(0.0, 0.0, 1.0);
        let yp = Trig::linear(self.a[0], self.a[2], self.a[1]);
        let u2_k1 = Trig::linear(u * u - k0, 0.0, 0.0).add(&ca.scale(-2.0 * r * rr));
        let n1 = Trig::linear(r * r + rr * rr, 0.0, 0.0).add(&ca.scale(-2.0 * r * rr));
        sa.mul_deg::<1, 1>(&sa)
            .mul_deg::<2, 1>(&u2_k1)
            .scale(r * r)
            .add(&yp.mul_deg::<1, 1>(&yp).mul_deg::<2, 1>(&n1))
    }

    /// The leg-I forms of P(alpha) ([`leg1_certify::alpha_forms`]) in any arithmetic.
    fn forms<T: Scalar>(&self, g: &ModuleGeometry) -> PathForms<T> {
        leg1_certify::alpha_forms(
            g,
            self.x,
            [self.a[0], self.a[2], self.a[1]],
            [self.b[0], self.b[2], self.b[1]],
        )
    }
}

/// Most candidate angles of one grid point: the roots isolated on the circle and the postures
/// of the intervals the isolation left undecided (proved, allowed, best effort).
const MAX_CANDIDATES: usize = MAX_TRIG_ROOTS + 36;

/// Every real alpha with G(alpha) = 0 for the exact G, as candidates for the inverse
/// kinematics at P(alpha) to decide. The simple roots are isolated on the circle with G's
/// rounding accounted for ([`Trig::roots_certified`] with the bound of
/// [`leg1_certify::forms_error`]). Where G comes within its rounding of zero, the isolation
/// cannot tell a double root from a close pair or from none: that happens on the symmetry
/// plane y = 0, where yp(alpha) = w sin(alpha) and G = sin^2(alpha) (...) has double roots at
/// alpha = 0 and pi, which the rounding of G's coefficients turns into no root or into two.
/// G = h+ h- is the product of leg I's two unsquared equations, one per sign of rho1 - zp, and
/// each has a simple root there: those intervals are decided on the factors
/// ([`leg1_certify::resolve_forms`]), or by double-double, with best-effort candidates where
/// nothing is proved.
fn coupling_candidates(g: &ModuleGeometry, map: &PlatformOfAlpha) -> ArrayVec<f64, MAX_CANDIDATES> {
    let mut out: ArrayVec<f64, MAX_CANDIDATES> = ArrayVec::new();
    let err = leg1_certify::forms_error(g, &map.forms::<Mag>(g));
    if !err.is_finite() {
        return out;
    }
    let iso = map.coupling_equation(g).roots_certified(err);
    out.extend(iso.roots.iter().map(|r| wrap_angle(r.x)));
    if !iso.ambiguous.is_empty() {
        let forms = AllForms {
            iv: map.forms(g),
            f64: map.forms(g),
            tracked: map.forms(g),
        };
        let (mut proved, mut allowed, mut fallback) =
            (ArrayVec::new(), ArrayVec::new(), ArrayVec::new());
        leg1_certify::resolve_forms(
            &forms,
            &iso.ambiguous,
            &mut proved,
            &mut allowed,
            &mut fallback,
        );
        for (alpha, _) in proved.iter().chain(&allowed).chain(&fallback) {
            let _ = out.try_push(wrap_angle(*alpha));
        }
    }
    out
}

/// Constraints (i)-(v) for one branch with s = (-1, -1, -1).
fn branch_fails(
    m: &Machine,
    of: Of,
    lambda: [f64; 2],
    b: &IkBranch,
    p: &Vector3<f64>,
) -> (Fails, [f64; 3]) {
    let mut f = Fails::default();
    if b.verdict.has(Reason::RodsCross) {
        f.add(Constraint::RodsCross);
    }
    if b.verdict.has(Reason::RodTilt) {
        f.add(Constraint::RodTilt);
    }
    let pose = ModulePose {
        p: *p,
        alpha: b.alpha,
    };
    let amplification = amplification_factors(&m.module, &pose, &b.rho);
    if !amplification
        .iter()
        .all(|&l| l >= lambda[0] && l <= lambda[1])
    {
        f.add(Constraint::Singularity);
    }
    if b.verdict.has(Reason::Rho1Stroke)
        || b.verdict.has(Reason::Rho2Stroke)
        || b.verdict.has(Reason::Rho3Stroke)
    {
        f.add(Constraint::Stroke);
    }
    // theta1 = alpha is the equations' angle: the joint's is alpha less the table's zero.
    let theta1 = b.alpha - m.table.theta_zero[0];
    if of == Of::Manufacturing
        && (theta1 < m.limits.theta1_min - LIMIT_SLACK
            || theta1 > m.limits.theta1_max + LIMIT_SLACK)
    {
        f.add(Constraint::Theta1Range);
    }
    (f, amplification)
}

/// Classifies one grid point.
pub fn classify(m: &Machine, opts: &WorkspaceOptions, q: &Vector3<f64>) -> PointResult {
    let mut best: Option<(Fails, PointBranch)> = None;
    let mut consider = |b: &IkBranch, p: &Vector3<f64>| {
        if b.config != WORKING_CONFIG {
            return;
        }
        let (fails, lambda) = branch_fails(m, opts.of, opts.lambda, b, p);
        let better = match &best {
            None => true,
            Some((bf, bb)) => {
                (fails.count(), b.alpha.abs(), b.alpha).partial_cmp(&(
                    bf.count(),
                    bb.pose.alpha.abs(),
                    bb.pose.alpha,
                )) == Some(std::cmp::Ordering::Less)
            }
        };
        if better {
            best = Some((
                fails,
                PointBranch {
                    pose: ModulePose {
                        p: *p,
                        alpha: b.alpha,
                    },
                    rho: b.rho,
                    lambda,
                },
            ));
        }
    };
    match opts.of {
        Of::Platform => {
            for b in ik::solve(m, q) {
                consider(&b, q);
            }
        }
        Of::Tool | Of::Manufacturing => {
            let map = PlatformOfAlpha::new(opts.of, &m.table, opts.tool_length, q);
            for alpha in coupling_candidates(&m.module, &map) {
                let p = map.at(alpha);
                for b in ik::solve(m, &p) {
                    if wrap_angle(b.alpha - alpha).abs() < ALPHA_MATCH_RAD {
                        consider(&b, &p);
                    }
                }
            }
        }
    }
    match best {
        None => PointResult {
            q: *q,
            outcome: Outcome::OutOfReach,
            fails: Fails::default(),
            branch: None,
        },
        Some((fails, branch)) => PointResult {
            q: *q,
            outcome: fails.first().map_or(Outcome::Inside, Outcome::Bound),
            fails,
            branch: Some(branch),
        },
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;
    use crate::machine::{platform_transform, table_transform};
    use nalgebra::Vector4;

    #[test]
    fn eq_26_and_27_match_the_matrix_products() {
        let m = Machine::default_verne();
        let t = m.table;
        for (p, alpha, delta) in [
            (Vector3::new(-240.0, -86.0, 1000.0), 0.0522, 50.0),
            (Vector3::new(120.0, 300.0, 1400.0), -0.4, 150.0),
            (Vector3::new(0.0, 0.0, 800.0), 0.0, 0.0),
        ] {
            // bT_pl = trans(P) rot(x, alpha), eq. (1); tool tip (0, 0, Delta) in R_pl.
            let b_t_pl = platform_transform(&ModulePose { p, alpha });
            let u = b_t_pl * Vector4::new(0.0, 0.0, delta, 1.0);
            let tip = tool_tip(&p, alpha, delta);
            assert!((u.xyz() - tip).amax() < 1e-9, "{u} vs {tip}");
            // bT_t = trans(z, d_a) rot(x, theta1) trans(z, d_t) rot(x, pi) rot(z, theta2),
            // eq. (7), with theta1 = alpha, theta2 = 0; tU = bT_t^-1 bU, eq. (25).
            let b_t_t = table_transform(&t, alpha, 0.0);
            let t_u = b_t_t.try_inverse().unwrap() * u;
            let mt = manufacturing_tip(&t, &p, alpha, delta);
            assert!((t_u.xyz() - mt).amax() < 1e-9, "{t_u} vs {mt}");
            // The inverse maps used by the grid search.
            for (of, q) in [(Of::Tool, tip), (Of::Manufacturing, mt)] {
                let back = PlatformOfAlpha::new(of, &t, delta, &q).at(alpha);
                assert!((back - p).amax() < 1e-9, "{of:?}: {back} vs {p}");
            }
        }
    }

    /// The bound the isolation is given covers the rounding of G's coefficients: G as
    /// [`PlatformOfAlpha::coupling_equation`] computes it against eq. (15) evaluated in
    /// double-double from the same inputs, at 64 angles, for tool tips and manufacturing points
    /// near and far, on and off the plane y = 0, with tool lengths that are not round.
    #[test]
    fn the_coupling_error_bound_covers_its_rounding() {
        use crate::math::dd::Tracked;
        let m = Machine::default_verne();
        let g = m.module;
        let mut unit = crate::math::test_rng::lcg(0xc0_9e15);
        let mut worst = 0.0f64;
        for k in 0..400 {
            let span = [600.0, 1500.0, 1e4][k % 3];
            let y = if k % 4 == 0 {
                0.0
            } else {
                (unit() - 0.5) * span
            };
            let q = Vector3::new((unit() - 0.5) * span, y, unit() * span);
            let delta = unit() * 200.0;
            let of = [Of::Tool, Of::Manufacturing][k % 2];
            let map = PlatformOfAlpha::new(of, &m.table, delta, &q);
            let coupling = map.coupling_equation(&g);
            let bound = leg1_certify::forms_error(&g, &map.forms::<Mag>(&g));
            let t = Tracked::exact;
            let (r, rr, l) = (t(g.r_big1), t(g.r_small1), t(g.l1));
            let u = t(map.x) + t(g.dx1);
            for i in 0..64 {
                let (s, c) = (PI * (f64::from(i) / 32.0 - 1.0) + 0.01).sin_cos();
                let (ts, tc) = (t(s), t(c));
                let yp = t(map.a[0]) + t(map.a[1]) * ts + t(map.a[2]) * tc;
                let n = r * r + rr * rr - t(2.0) * r * rr * tc;
                let exact = r * r * ts * ts * (u * u - (l * l - n)) + yp * yp * n;
                let diff = (coupling.eval_sc(s, c) - exact.v.to_f64()).abs();
                assert!(
                    diff <= bound,
                    "{of:?} {q:?} Delta {delta}: {diff:e} > {bound:e}"
                );
                worst = worst.max(diff / bound);
            }
        }
        assert!(worst > 0.0, "no rounding seen at all");
    }

    #[test]
    fn coupling_equation_is_eq_15() {
        let m = Machine::default_verne();
        let g = m.module;
        let map = PlatformOfAlpha::new(
            Of::Tool,
            &m.table,
            70.0,
            &Vector3::new(-200.0, 40.0, 1100.0),
        );
        let coupling = map.coupling_equation(&g);
        for alpha in [-2.5, -0.7, -0.1, 0.0, 0.3, 1.2, 2.9, PI] {
            let (s, co) = f64::sin_cos(alpha);
            let p = map.at(alpha);
            let k =
                g.r_big1 * g.r_big1 + g.r_small1 * g.r_small1 - 2.0 * g.r_big1 * g.r_small1 * co;
            let r2s2 = g.r_big1 * g.r_big1 * s * s;
            let u = p.x + g.dx1;
            let eq15 = r2s2 * u * u + k * p.y * p.y - r2s2 * (g.l1 * g.l1 - k);
            let got = coupling.eval(alpha);
            assert!(
                (got - eq15).abs() < 1e-9 * (1.0 + eq15.abs()),
                "{alpha}: {got} vs {eq15}"
            );
        }
    }
}
