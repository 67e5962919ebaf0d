//! Branch labels and feasibility: the configuration indices s1, s2, s3 of IFToMM 2007 eqs.
//! (11)-(13), and the verdict that picks the machine's own ("working") branch (section V).

use std::fmt;

use crate::parallel_module::equations::{ModulePose, Sliders};
use crate::spec::Machine;
use crate::tolerance::{CONFIG_SIGN_MM, LIMIT_SLACK};

/// Configuration indices (s1, s2, s3), each -1 or +1: the signs of rho1 - zp,
/// rho2 - zp + R2 sin(alpha) and rho3 - zp - R2 sin(alpha). With z pointing down, -1 means the
/// slider attachment is above the platform attachment, as on the machine.
pub type Config = [i8; 3];

/// The machine's configuration.
pub const WORKING_CONFIG: Config = [-1, -1, -1];

pub fn config_of(g: &crate::spec::ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> Config {
    let s = pose.alpha.sin() * g.r_big2;
    let sign = |q: f64| if q > CONFIG_SIGN_MM { 1 } else { -1 };
    // The equations' sliders: the joints' plus their zero offsets.
    let [z1, z2, z3] = g.rho_zero;
    [
        sign(rho.x + z1 - pose.p.z),
        sign(rho.y + z2 - pose.p.z + s),
        sign(rho.z + z3 - pose.p.z - s),
    ]
}

/// Why a branch is not the machine's: a set of reasons, empty when feasible.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct Verdict(u16);

/// One reason a branch is infeasible, with its code in the `status` column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reason {
    /// s1 = +1: slider-1 attachment below the platform attachment.
    Leg1Inverted,
    Leg2Inverted,
    Leg3Inverted,
    /// R1 cos(alpha) <= r1: the two rods of leg I cross.
    RodsCross,
    Rho1Stroke,
    Rho2Stroke,
    Rho3Stroke,
    /// A rod is tilted beyond the passive joints' limit.
    RodTilt,
    /// The tilting axis theta1 is outside its range (machine kinematics).
    Theta1Range,
    /// The solver could not prove that its list of branches is complete
    /// ([`crate::certificate::Certificate::Unproved`]): every branch of such a row carries it.
    Uncertified,
}

impl Reason {
    pub const ALL: [Reason; 10] = [
        Reason::Leg1Inverted,
        Reason::Leg2Inverted,
        Reason::Leg3Inverted,
        Reason::RodsCross,
        Reason::Rho1Stroke,
        Reason::Rho2Stroke,
        Reason::Rho3Stroke,
        Reason::RodTilt,
        Reason::Theta1Range,
        Reason::Uncertified,
    ];

    pub fn code(self) -> &'static str {
        match self {
            Reason::Leg1Inverted => "leg1_inverted",
            Reason::Leg2Inverted => "leg2_inverted",
            Reason::Leg3Inverted => "leg3_inverted",
            Reason::RodsCross => "rods_cross",
            Reason::Rho1Stroke => "rho1_stroke",
            Reason::Rho2Stroke => "rho2_stroke",
            Reason::Rho3Stroke => "rho3_stroke",
            Reason::RodTilt => "rod_tilt",
            Reason::Theta1Range => "theta1_range",
            Reason::Uncertified => "uncertified",
        }
    }

    fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

impl Verdict {
    pub fn feasible(self) -> bool {
        self.0 == 0
    }

    pub fn add(&mut self, r: Reason) {
        self.0 |= r.bit();
    }

    /// The verdict whose reasons are the bits of `bits`, bit i for [`Reason`] i in declaration
    /// order.
    #[inline]
    pub(crate) fn from_bits(bits: u16) -> Verdict {
        Verdict(bits)
    }

    /// The reasons of both.
    #[inline]
    pub fn with(self, other: Verdict) -> Verdict {
        Verdict(self.0 | other.0)
    }

    pub fn has(self, r: Reason) -> bool {
        self.0 & r.bit() != 0
    }

    pub fn reasons(self) -> impl Iterator<Item = Reason> {
        Reason::ALL.into_iter().filter(move |r| self.has(*r))
    }

    /// True when the branch is the machine's kind of branch (s = -1,-1,-1, rods not crossing) and
    /// only joint or passive-joint limits fail.
    pub fn only_limits(self) -> bool {
        !self.feasible()
            && !self.has(Reason::Leg1Inverted)
            && !self.has(Reason::Leg2Inverted)
            && !self.has(Reason::Leg3Inverted)
            && !self.has(Reason::RodsCross)
    }
}

impl fmt::Display for Verdict {
    /// `ok`, or the reason codes joined by `;`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.feasible() {
            return f.write_str("ok");
        }
        let mut first = true;
        for r in self.reasons() {
            if !first {
                f.write_str(";")?;
            }
            f.write_str(r.code())?;
            first = false;
        }
        Ok(())
    }
}

/// What one leg contributes to a branch's label and verdict: the signed quantity whose sign is
/// its configuration index s_i (eqs. (11)-(13): rho1 - zp, rho2 - zp + R2 sin(alpha),
/// rho3 - zp - R2 sin(alpha)), whether a rod is tilted beyond the passive joints' limit, and
/// whether the slider is outside its stroke.
#[derive(Debug, Clone, Copy)]
pub struct LegState {
    leg: usize,
    q: f64,
    tilted: bool,
    outside_stroke: bool,
}

impl LegState {
    /// The configuration index s_i.
    #[inline]
    pub fn sign(self) -> i8 {
        if self.q > CONFIG_SIGN_MM { 1 } else { -1 }
    }

    /// The leg's reasons (inverted, stroke, rod tilt), set without branching: the reasons of
    /// leg i are Leg1Inverted + i and Rho1Stroke + i in [`Reason`]'s order.
    #[inline]
    pub fn verdict(self) -> Verdict {
        let bit = |on: bool, r: u16| (on as u16) << r;
        Verdict(
            bit(
                self.sign() != -1,
                Reason::Leg1Inverted as u16 + self.leg as u16,
            ) | stroke_bit(self.leg, self.outside_stroke)
                | bit(self.tilted, Reason::RodTilt as u16),
        )
    }

    /// Label and verdict.
    #[inline]
    pub fn check(self) -> (i8, Verdict) {
        (self.sign(), self.verdict())
    }

    /// Nothing against the leg: [`LegState::verdict`] is empty (without building it).
    #[inline]
    pub fn ok(self) -> bool {
        let inverted = self.q > CONFIG_SIGN_MM;
        !inverted && !self.tilted && !self.outside_stroke
    }
}

/// Leg `leg` (0, 1, 2) at slider position `rho_i` with P = `p`; (s, c) = sin, cos of alpha.
/// `cos_tilt_max` is cos(rod_tilt_max + slack): a rod is too tilted when v_z < cos_tilt_max |v|,
/// which avoids an acos per rod.
#[inline]
pub fn leg_state(
    m: &Machine,
    leg: usize,
    p: &nalgebra::Vector3<f64>,
    s: f64,
    c: f64,
    rho_i: f64,
    cos_tilt_max: f64,
) -> LegState {
    let g = &m.module;
    let too_tilted =
        |r: nalgebra::Vector3<f64>| rod_too_tilted(r.z, r.norm_squared(), cos_tilt_max);
    // The stroke is the joint's; the rods see the equations' slider (plus its zero offset).
    let joint = rho_i;
    let rho_i = rho_i + g.rho_zero[leg];
    let (q, tilted) = match leg {
        0 => {
            let (dy, dz) = (g.r_big1 * c - g.r_small1, g.r_big1 * s);
            let u = p.x + g.dx1;
            let r3 = nalgebra::Vector3::new(u, p.y + dy, p.z + dz - rho_i);
            let r4 = nalgebra::Vector3::new(u, p.y - dy, p.z - dz - rho_i);
            (rho_i - p.z, too_tilted(r3) || too_tilted(r4))
        }
        1 => {
            let r5 = nalgebra::Vector3::new(
                p.x + g.dx2,
                p.y - g.r_big2 * c + g.r4,
                p.z - g.r_big2 * s - rho_i,
            );
            (rho_i - p.z + g.r_big2 * s, too_tilted(r5))
        }
        _ => {
            let r6 = nalgebra::Vector3::new(
                p.x + g.dx2,
                p.y + g.r_big2 * c - g.r4,
                p.z + g.r_big2 * s - rho_i,
            );
            (rho_i - p.z - g.r_big2 * s, too_tilted(r6))
        }
    };
    LegState {
        leg,
        q,
        tilted,
        outside_stroke: outside_stroke(m, leg, joint),
    }
}

/// Slider `leg` outside its stroke (with the slack of the limits).
#[inline]
fn outside_stroke(m: &Machine, leg: usize, rho_i: f64) -> bool {
    rho_i < m.limits.rho_min[leg] - LIMIT_SLACK || rho_i > m.limits.rho_max[leg] + LIMIT_SLACK
}

/// A rod with z component `rz` and squared length `norm_sq` tilted beyond the passive joints'
/// limit: r.z < cos_tilt_max |r|, squared (no square root).
#[inline]
fn rod_too_tilted(rz: f64, norm_sq: f64, cos_tilt_max: f64) -> bool {
    let (zz, ct2) = (rz * rz, cos_tilt_max * cos_tilt_max);
    if cos_tilt_max >= 0.0 {
        rz < 0.0 || zz < ct2 * norm_sq
    } else {
        rz < 0.0 && zz > ct2 * norm_sq
    }
}

/// Leg II or III (`leg` 1 or 2) at both roots of its eq. (12) or (13), rho = offset - h and
/// offset + h, where h is the square root and (dx, dy) the rod's horizontal components: what
/// [`leg_state`] says at each, with the rod's z component (+h, -h) and the signed quantity of
/// s_i (-h, +h) taken from the square root instead of recomputed from rho (they agree to
/// rounding), and the rod's length computed once for both.
#[inline]
pub fn outer_leg_states(
    m: &Machine,
    leg: usize,
    dx_dy_h: (f64, f64, f64),
    rho: [f64; 2],
    cos_tilt_max: f64,
) -> [LegState; 2] {
    outer_leg_pair(leg, dx_dy_h, cos_tilt_max, |k| {
        outside_stroke(m, leg, rho[k])
    })
}

/// [`outer_leg_states`] but the strokes: the label and verdict of leg II or III at both roots
/// of its eq. (12) or (13) as far as they depend on the square root alone, which a leg-I
/// posture shares with its mirror image (same cos(alpha)). Add [`stroke_verdict`] of each rho.
#[inline]
pub fn outer_leg_labels(
    leg: usize,
    dx_dy_h: (f64, f64, f64),
    cos_tilt_max: f64,
) -> [(i8, Verdict); 2] {
    // Element by element: `map` on the array was a call of its own on the inverse's hot path.
    let [lower, upper] = outer_leg_pair(leg, dx_dy_h, cos_tilt_max, |_| false);
    [lower.check(), upper.check()]
}

/// The states of [`outer_leg_states`], root k outside its stroke when `outside(k)`.
#[inline(always)]
fn outer_leg_pair(
    leg: usize,
    (dx, dy, h): (f64, f64, f64),
    cos_tilt_max: f64,
    outside: impl Fn(usize) -> bool,
) -> [LegState; 2] {
    let norm_sq = dx * dx + dy * dy + h * h;
    let state = |k: usize, q: f64| LegState {
        leg,
        q,
        tilted: rod_too_tilted(-q, norm_sq, cos_tilt_max),
        outside_stroke: outside(k),
    };
    [state(0, -h), state(1, h)]
}

/// The stroke reason of slider `leg` (0, 1, 2) at `rho_i`, when it is outside its stroke.
#[inline]
pub fn stroke_verdict(m: &Machine, leg: usize, rho_i: f64) -> Verdict {
    Verdict(stroke_bit(leg, outside_stroke(m, leg, rho_i)))
}

/// The bit of leg `leg`'s stroke reason (Rho1Stroke + leg in [`Reason`]'s order) when `on`.
#[inline]
fn stroke_bit(leg: usize, on: bool) -> u16 {
    (on as u16) << (Reason::Rho1Stroke as u16 + leg as u16)
}

/// cos of the largest rod tilt with its slack, for [`leg_state`].
pub fn cos_tilt_max(m: &Machine) -> f64 {
    m.limits.cos_rod_tilt_max
}

/// The reasons of a whole branch: its legs' and R1 cos(alpha) <= r1 (rods of leg I cross).
#[inline]
pub fn combine(m: &Machine, c: f64, legs: [Verdict; 3]) -> Verdict {
    legs[0].with(legs[1]).with(legs[2]).with(rods_cross(m, c))
}

/// Whether two branches keyed (angle, configuration) are listed as the sort by the angle's
/// `total_cmp`, then the configuration, lists them: the angle below the next, or the same bits
/// and a configuration no larger. Plain comparisons, to check a list that is usually in order
/// already before sorting it (a pair it cannot vouch for, such as -0 before +0, only sends the
/// list to the sort).
#[inline]
pub fn listed_in_order<K: PartialOrd>((a, key_a): (f64, K), (b, key_b): (f64, K)) -> bool {
    a < b || (a.to_bits() == b.to_bits() && key_a <= key_b)
}

/// [`Reason::RodsCross`] when R1 cos(alpha) <= r1, else nothing.
#[inline]
pub fn rods_cross(m: &Machine, c: f64) -> Verdict {
    let crossed = m.module.r_big1 * c <= m.module.r_small1;
    Verdict((crossed as u16) << Reason::RodsCross as u16)
}

/// Configuration and verdict of a pose of the module with slider positions `rho`, from
/// (s, c) = sin, cos of its alpha: [`config_of`] and [`module_verdict`] in one pass over the legs.
#[inline(always)]
pub fn label(
    m: &Machine,
    p: &nalgebra::Vector3<f64>,
    s: f64,
    c: f64,
    rho: &Sliders,
) -> (Config, Verdict) {
    let ct = cos_tilt_max(m);
    let leg = |i: usize| leg_state(m, i, p, s, c, rho[i], ct).check();
    let legs = [leg(0), leg(1), leg(2)];
    (
        [legs[0].0, legs[1].0, legs[2].0],
        combine(m, c, [legs[0].1, legs[1].1, legs[2].1]),
    )
}

/// The verdict of a parallel-module branch: configuration, rod crossing (section V), slider
/// strokes and rod tilts from the machine file. `config` is as given by [`config_of`].
pub fn module_verdict(m: &Machine, pose: &ModulePose, rho: &Sliders, config: Config) -> Verdict {
    let (s, c) = pose.alpha.sin_cos();
    let ct = cos_tilt_max(m);
    let legs: [Verdict; 3] = std::array::from_fn(|i| {
        let mut v = leg_state(m, i, &pose.p, s, c, rho[i], ct).verdict();
        // The configuration given wins over the recomputed sign (they agree up to rounding).
        for r in [
            Reason::Leg1Inverted,
            Reason::Leg2Inverted,
            Reason::Leg3Inverted,
        ] {
            v.0 &= !r.bit();
        }
        if config[i] != -1 {
            v.add(
                [
                    Reason::Leg1Inverted,
                    Reason::Leg2Inverted,
                    Reason::Leg3Inverted,
                ][i],
            );
        }
        v
    });
    combine(m, c, legs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branch-free [`LegState::verdict`] names each leg's own reasons.
    #[test]
    fn leg_verdict_names_its_own_reasons() {
        let inverted = [
            Reason::Leg1Inverted,
            Reason::Leg2Inverted,
            Reason::Leg3Inverted,
        ];
        let stroke = [Reason::Rho1Stroke, Reason::Rho2Stroke, Reason::Rho3Stroke];
        for leg in 0..3 {
            let state = |q: f64, tilted: bool, outside_stroke: bool| LegState {
                leg,
                q,
                tilted,
                outside_stroke,
            };
            assert!(state(-1.0, false, false).verdict().feasible());
            let all: Vec<Reason> = state(1.0, true, true).verdict().reasons().collect();
            assert_eq!(all, vec![inverted[leg], stroke[leg], Reason::RodTilt]);
            let v = state(-1.0, false, true).verdict();
            assert_eq!(v.reasons().collect::<Vec<_>>(), vec![stroke[leg]]);
            let v = state(2.0 * CONFIG_SIGN_MM, false, false).verdict();
            assert_eq!(v.reasons().collect::<Vec<_>>(), vec![inverted[leg]]);
        }
    }

    /// [`LegState::ok`] (built without the verdict) is [`LegState::verdict`] being empty, for
    /// every leg, signed quantity about `CONFIG_SIGN_MM`, tilt and stroke.
    #[test]
    fn leg_ok_is_an_empty_verdict() {
        for leg in 0..3 {
            for q in [-1.0, 0.0, 0.5 * CONFIG_SIGN_MM, 2.0 * CONFIG_SIGN_MM, 1.0] {
                for (tilted, outside_stroke) in [(false, false), (true, false), (false, true)] {
                    let state = LegState {
                        leg,
                        q,
                        tilted,
                        outside_stroke,
                    };
                    assert_eq!(state.ok(), state.verdict().feasible(), "{state:?}");
                }
            }
        }
    }

    /// [`Verdict::only_limits`]: infeasible, and every reason a limit (a stroke, a rod tilt,
    /// theta1's range) or the missing proof, none an inverted leg or crossed rods; over all
    /// 1,024 verdicts.
    #[test]
    fn only_limits_means_limits_alone_fail() {
        for bits in 0..1u16 << Reason::ALL.len() {
            let v = Verdict::from_bits(bits);
            let limits = v.reasons().all(|r| {
                matches!(
                    r,
                    Reason::Rho1Stroke
                        | Reason::Rho2Stroke
                        | Reason::Rho3Stroke
                        | Reason::RodTilt
                        | Reason::Theta1Range
                        | Reason::Uncertified
                )
            });
            assert_eq!(v.only_limits(), bits != 0 && limits, "{v}");
        }
    }

    /// [`leg_state`] builds the rods that eqs. (3)-(6) do: for random poses and sliders of the
    /// default machine and four random ones (dx1 and dx2 over 1 mm on some), and tilt limits
    /// from 10 to 170 degrees, a leg is tilted exactly when one of its rods' `rod_tilts` is
    /// beyond the limit, and its signed quantity is that of [`config_of`] (rods within 1e-9 rad
    /// of the limit left out).
    #[test]
    fn leg_state_tilts_the_rods_of_the_constraint_equations() {
        use crate::parallel_module::equations::rod_tilts;
        use crate::selftest::hard_sets::random_geometries;
        let mut unit = crate::math::test_rng::lcg(0x1e95_7a7e_0000_0001);
        let mut machines = vec![Machine::default_verne()];
        machines.extend(random_geometries(4, 27));
        let offset = |dx: fn(&Machine) -> f64| machines.iter().any(|m| dx(m).abs() > 1.0);
        assert!(offset(|m| m.module.dx1) && offset(|m| m.module.dx2));
        let mut seen = [false; 2];
        for m in &machines {
            for _ in 0..2_000 {
                let pose = ModulePose {
                    p: nalgebra::Vector3::new(
                        (unit() - 0.5) * 1200.0,
                        (unit() - 0.5) * 1200.0,
                        (unit() - 0.5) * 2400.0,
                    ),
                    alpha: (unit() - 0.5) * 6.0,
                };
                let rho = Sliders::from_fn(|_, _| (unit() - 0.5) * 2400.0);
                let tilt_max = (10.0 + 160.0 * unit()).to_radians();
                let tilts = rod_tilts(&m.module, &pose, &rho);
                let (s, c) = pose.alpha.sin_cos();
                let config = config_of(&m.module, &pose, &rho);
                for (leg, rods) in [&[0usize, 1][..], &[2], &[3]].into_iter().enumerate() {
                    if rods.iter().any(|&i| (tilts[i] - tilt_max).abs() < 1e-9) {
                        continue;
                    }
                    let state = leg_state(m, leg, &pose.p, s, c, rho[leg], tilt_max.cos());
                    let want = rods.iter().any(|&i| tilts[i] > tilt_max);
                    assert_eq!(state.tilted, want, "{}: leg {leg}, {pose:?} {rho}", m.name);
                    assert_eq!(state.sign(), config[leg], "{}: leg {leg}", m.name);
                    seen[usize::from(want)] = true;
                }
            }
        }
        assert_eq!(seen, [true; 2]);
    }

    /// [`module_verdict`] of an inverse-kinematics branch, given its configuration, is the
    /// verdict the solver gave it (every branch of 400 points on five machines, infeasible ones
    /// of every kind among them); given a configuration with one leg's sign flipped, only that
    /// leg's inverted reason changes.
    #[test]
    fn module_verdict_is_the_solvers_verdict_with_the_configuration_given() {
        use crate::selftest::hard_sets::random_geometries;
        let mut unit = crate::math::test_rng::lcg(0x0de7_e4d1_0000_0001);
        let mut machines = vec![Machine::default_verne()];
        machines.extend(random_geometries(4, 33));
        let inverted = [
            Reason::Leg1Inverted,
            Reason::Leg2Inverted,
            Reason::Leg3Inverted,
        ];
        let (mut feasible, mut reasons) = (0, Verdict::default());
        for m in &machines {
            for (p, branches) in solved_points(m, 80, &mut unit) {
                for b in branches {
                    let pose = ModulePose { p, alpha: b.alpha };
                    let v = module_verdict(m, &pose, &b.rho, b.config);
                    assert_eq!(v, b.verdict, "{}: {p:?} {b:?}", m.name);
                    feasible += usize::from(v.feasible());
                    reasons = reasons.with(v);
                    for (leg, reason) in inverted.iter().enumerate() {
                        let mut flipped = b.config;
                        flipped[leg] = -flipped[leg];
                        let w = module_verdict(m, &pose, &b.rho, flipped);
                        assert_eq!(w.has(*reason), flipped[leg] != -1, "{b:?}");
                        let others = |v: Verdict| v.reasons().filter(|r| r != reason).count();
                        assert_eq!(others(w), others(v), "{b:?}");
                    }
                }
            }
        }
        let kinds = [Reason::RodsCross, Reason::Rho1Stroke, Reason::RodTilt];
        assert!(feasible > 0 && inverted.iter().chain(&kinds).all(|r| reasons.has(*r)));
    }

    /// `rod_too_tilted` (no square root) says what acos(r_z / |r|) > tilt_max says, for limits
    /// below and above 90 degrees (cos_tilt_max of either sign) and rods pointing up or down:
    /// 20,000 rods, those within 1e-9 rad of the limit left out.
    #[test]
    fn rod_too_tilted_is_the_angle_from_the_axis_beyond_the_limit() {
        let mut unit = crate::math::test_rng::lcg(0x7117_ed00_0000_0001);
        let mut both = [false; 2];
        for _ in 0..20_000 {
            let r = nalgebra::Vector3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 2000.0;
            let tilt_max = std::f64::consts::PI * unit();
            let tilt = (r.z / r.norm()).acos();
            if (tilt - tilt_max).abs() < 1e-9 {
                continue;
            }
            let got = rod_too_tilted(r.z, r.norm_squared(), tilt_max.cos());
            assert_eq!(got, tilt > tilt_max, "{r} {tilt} {tilt_max}");
            both[usize::from(got)] = true;
        }
        assert_eq!(both, [true; 2]);
    }

    /// A slider is outside its stroke only beyond it by more than `LIMIT_SLACK`, on either
    /// side, for each leg.
    #[test]
    fn outside_stroke_allows_the_slack_only() {
        let m = Machine::default_verne();
        for leg in 0..3 {
            let (lo, hi) = (m.limits.rho_min[leg], m.limits.rho_max[leg]);
            for (rho, out) in [
                (lo, false),
                (hi, false),
                (0.5 * (lo + hi), false),
                (lo - 0.5 * LIMIT_SLACK, false),
                (hi + 0.5 * LIMIT_SLACK, false),
                (lo - 2.0 * LIMIT_SLACK - 1e-9 * lo.abs(), true),
                (hi + 2.0 * LIMIT_SLACK + 1e-9 * hi.abs(), true),
            ] {
                assert_eq!(outside_stroke(&m, leg, rho), out, "leg {leg}, {rho}");
                assert_eq!(
                    stroke_verdict(&m, leg, rho).feasible(),
                    !out,
                    "leg {leg}, {rho}"
                );
            }
        }
    }

    /// `listed_in_order` vouches for a pair only when the sort (the angle's `total_cmp`, then
    /// the key) keeps it in that order: equal angles with keys either way, -0 and +0, angles a
    /// few ulps apart.
    #[test]
    fn listed_in_order_agrees_with_the_sort() {
        let angles = [-1.0, -0.0, 0.0, 1e-300, 0.5, 0.5 + f64::EPSILON, 3.0];
        for &a in &angles {
            for &b in &angles {
                for (ka, kb) in [(0, 0), (0, 1), (1, 0)] {
                    let sorted = a.total_cmp(&b).then(ka.cmp(&kb)).is_le();
                    if listed_in_order((a, ka), (b, kb)) {
                        assert!(sorted, "{a} {ka} before {b} {kb}");
                    }
                    // Only -0 before +0 is left to the sort among pairs it keeps.
                    if sorted && !(a == b && a.to_bits() != b.to_bits()) {
                        assert!(listed_in_order((a, ka), (b, kb)), "{a} {ka}, {b} {kb}");
                    }
                }
            }
        }
    }

    /// `count` points of a box around the module's workspace, drawn from `unit` (uniform in [0,
    /// 1)), each with every branch the inverse kinematics finds there.
    fn solved_points(
        m: &Machine,
        count: usize,
        unit: &mut impl FnMut() -> f64,
    ) -> Vec<(
        nalgebra::Vector3<f64>,
        crate::parallel_module::ik::IkBranches,
    )> {
        (0..count)
            .map(|_| {
                let p = nalgebra::Vector3::new(
                    (unit() - 0.5) * 800.0,
                    (unit() - 0.5) * 600.0,
                    (unit() - 0.5) * 1600.0,
                );
                (p, crate::parallel_module::ik::solve(m, &p))
            })
            .collect()
    }

    /// [`config_of`] (the signs of rho1 - zp, rho2 - zp + R2 sin(alpha), rho3 - zp - R2
    /// sin(alpha), used by `verify`) agrees with the labels the inverse kinematics gives its
    /// branches, which come from the order of each leg's two roots, not from these signs:
    /// every branch of 2,000 points on the default machine and four random ones, both sides of
    /// every leg (each label of each leg met). A branch with a sign within 1e-6 mm of zero is
    /// left out (a stretched rod, where both labels are right).
    #[test]
    fn config_of_agrees_with_the_inverse_kinematics_labels() {
        use crate::parallel_module::equations::ModulePose;
        use crate::selftest::hard_sets::random_geometries;
        let mut unit = crate::math::test_rng::lcg(0x0c0f_1605);
        let mut machines = vec![Machine::default_verne()];
        machines.extend(random_geometries(4, 15));
        let (mut checked, mut met) = (0, [[false; 2]; 3]);
        for m in &machines {
            let g = &m.module;
            for (p, branches) in solved_points(m, 400, &mut unit) {
                for b in branches {
                    let pose = ModulePose { p, alpha: b.alpha };
                    let s = b.alpha.sin() * g.r_big2;
                    let q = [b.rho.x - p.z, b.rho.y - p.z + s, b.rho.z - p.z - s];
                    if q.iter().any(|q| q.abs() < 1e-6) {
                        continue;
                    }
                    assert_eq!(
                        config_of(g, &pose, &b.rho),
                        b.config,
                        "{}: {p:?} {b:?}",
                        m.name
                    );
                    for (leg, label) in b.config.iter().enumerate() {
                        met[leg][usize::from(*label > 0)] = true;
                    }
                    checked += 1;
                }
            }
        }
        assert!(
            checked > 10_000 && met == [[true; 2]; 3],
            "{checked} {met:?}"
        );
    }
}
