//! Poses built on the sets where the parallel module's solvers divide by, or isolate roots of,
//! something that vanishes (IFToMM 2007): condition (21) at the pose's alpha, rho1 = (rho2 +
//! rho3) / 2 on a machine with L2 = L3 (the right side b of (6) - (5) vanishes identically),
//! condition (20), y_p = 0 (Table I), rho2 = rho3, alpha = pi, a stretched leg II (the square
//! root of (12) at zero). Random sampling meets these sets with probability zero; the solvers'
//! tests and `verne selftest` build poses on them instead.
//!
//! Construction: from a point P0 and one of its inverse-kinematics branches, P moves along a
//! line P0 + s d while the branch is followed (at each step the branch nearest the previous
//! one); the vanishing quantity is bracketed and bisected to s*, then the poses at s* + offset
//! for the [`OFFSETS_MM`] are taken, each with the branch's (alpha, rho). The forward
//! kinematics of rho must then contain (P, alpha).

use nalgebra::Vector3;

use crate::machine::Machine;
use crate::module_fk::FkMode;
use crate::module_geometry::Sliders;
use crate::module_ik::{self, IkBranch, wrap_angle};

/// The sets, by the quantity that vanishes on them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HardSet {
    /// Det = 2 (p2 - p3)(R1 cos a - r1) + 4 (R1 r4 - r1 R2) sin a = 0 (condition (21)): two
    /// assembly modes share alpha, the linear (y, z) system of the elimination is singular.
    Condition21,
    /// rho1 - (rho2 + rho3) / 2 = 0: with L2 = L3 the right side of (6) - (5) is zero for every
    /// alpha, and every zero of Det is a double root of F.
    SliderMean,
    /// R1 cos(alpha) - r1 = 0 (condition (20)): the coupling ellipse (8) is a circle.
    Condition20,
    /// y_p = 0 (Table I).
    YpZero,
    /// rho2 - rho3 = 0: Det vanishes at alpha in {0, pi}.
    EqualOuterSliders,
    /// sin(alpha) = 0 with cos(alpha) < 0: alpha = pi, where t = tan(alpha / 2) is infinite.
    AlphaPi,
    /// L2^2 - dx^2 - dy^2 = 0 for leg II (the square root of eq. (12)): a fully stretched rod.
    StretchedLeg2,
    /// det A = 0 (A the Jacobian of (3)-(6) in the pose): a parallel singularity, where two
    /// assembly modes meet and F has a double root; next to it, two close simple roots.
    ParallelSingularity,
    /// The cubic (9) in cos(alpha) has a double root at the branch's cos(alpha) (its derivative
    /// vanishes there): two leg-I postures of the point meet.
    Cubic9DoubleRoot,
}

impl HardSet {
    pub const ALL: [HardSet; 9] = [
        HardSet::Condition21,
        HardSet::SliderMean,
        HardSet::Condition20,
        HardSet::YpZero,
        HardSet::EqualOuterSliders,
        HardSet::AlphaPi,
        HardSet::StretchedLeg2,
        HardSet::ParallelSingularity,
        HardSet::Cubic9DoubleRoot,
    ];

    pub fn name(self) -> &'static str {
        match self {
            HardSet::Condition21 => "condition_21",
            HardSet::SliderMean => "slider_mean",
            HardSet::Condition20 => "condition_20",
            HardSet::YpZero => "yp_zero",
            HardSet::EqualOuterSliders => "rho2_eq_rho3",
            HardSet::AlphaPi => "alpha_pi",
            HardSet::StretchedLeg2 => "stretched_leg2",
            HardSet::ParallelSingularity => "parallel_singularity",
            HardSet::Cubic9DoubleRoot => "cubic9_double_root",
        }
    }

    /// The vanishing quantity for a branch of point `p`.
    pub fn quantity(self, m: &Machine, p: &Vector3<f64>, b: &IkBranch) -> f64 {
        let g = &m.module;
        let (s, c) = b.alpha.sin_cos();
        let (p2, p3) = (b.rho.y - b.rho.x, b.rho.z - b.rho.x);
        match self {
            HardSet::Condition21 => {
                2.0 * (p2 - p3) * (g.r_big1 * c - g.r_small1)
                    + 4.0 * (g.r_big1 * g.r4 - g.r_small1 * g.r_big2) * s
            }
            HardSet::SliderMean => b.rho.x - 0.5 * (b.rho.y + b.rho.z),
            HardSet::Condition20 => g.r_big1 * c - g.r_small1,
            HardSet::YpZero => p.y,
            HardSet::EqualOuterSliders => b.rho.y - b.rho.z,
            HardSet::AlphaPi => {
                if c < 0.0 {
                    s
                } else {
                    f64::NAN
                }
            }
            HardSet::StretchedLeg2 => {
                let dx = p.x + g.dx2;
                let dy = p.y - g.r_big2 * c + g.r4;
                g.l2 * g.l2 - dx * dx - dy * dy
            }
            HardSet::ParallelSingularity => {
                let pose = crate::module_geometry::ModulePose {
                    p: *p,
                    alpha: b.alpha,
                };
                crate::module_geometry::jacobian_pose(g, &pose, &b.rho).determinant()
            }
            HardSet::Cubic9DoubleRoot => {
                let k = module_ik::eq9_coefficients(g, p);
                (3.0 * k[3] * c + 2.0 * k[2]) * c + k[1]
            }
        }
    }
}

/// Distances (mm) from the set along the line at which poses are taken: on it, and on both
/// sides at 1e-9 to 0.1 mm.
pub const OFFSETS_MM: [f64; 11] = [
    0.0, 1e-9, -1e-9, 1e-7, -1e-7, 1e-5, -1e-5, 1e-3, -1e-3, 1e-1, -1e-1,
];

/// A pose on (or next to) a hard set, with the branch that reaches it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constructed {
    pub set: HardSet,
    /// Signed distance from the set along the line (mm).
    pub offset_mm: f64,
    pub p: Vector3<f64>,
    pub alpha: f64,
    pub rho: Sliders,
}

/// Distance between two branches: alpha (scaled by 1000 mm) and the sliders.
fn branch_distance(a: &IkBranch, b: &IkBranch) -> f64 {
    1000.0 * wrap_angle(a.alpha - b.alpha).abs() + (a.rho - b.rho).amax()
}

/// The branch of `p` nearest `prev`, if `p` has any.
fn follow(m: &Machine, p: &Vector3<f64>, prev: &IkBranch) -> Option<IkBranch> {
    module_ik::solve(m, p)
        .into_iter()
        .min_by(|a, b| branch_distance(a, prev).total_cmp(&branch_distance(b, prev)))
}

/// Steps of the bracketing scan along the line.
const SCAN_STEPS: usize = 96;

/// Poses on `set` near the line `p0 + s dir` (|s| <= `reach` mm), following the branch of `p0`
/// nearest `branch`: one per offset of [`OFFSETS_MM`], or none when the quantity does not
/// change sign along the line (or the branch is lost: the line leaves the workspace, or the
/// branch meets another one on the way).
pub fn construct(
    m: &Machine,
    set: HardSet,
    p0: &Vector3<f64>,
    dir: &Vector3<f64>,
    branch: &IkBranch,
    reach: f64,
) -> Vec<Constructed> {
    let dir = dir.normalize();
    let at = |s: f64| p0 + dir * s;
    // Scan outwards from s = 0 in both directions, following the branch step by step.
    let step = reach / SCAN_STEPS as f64;
    let mut bracket = None;
    'sides: for side in [1.0, -1.0] {
        let mut prev = *branch;
        let mut q_prev = set.quantity(m, p0, &prev);
        for k in 1..=SCAN_STEPS {
            let s = side * step * k as f64;
            let p = at(s);
            let Some(b) = follow(m, &p, &prev) else {
                continue 'sides;
            };
            if branch_distance(&b, &prev) > 50.0 * step.max(1.0) {
                continue 'sides; // jumped to another branch
            }
            let q = set.quantity(m, &p, &b);
            if q.is_finite() && q_prev.is_finite() && (q < 0.0) != (q_prev < 0.0) {
                bracket = Some((s - side * step, prev, s, b));
                break 'sides;
            }
            prev = b;
            q_prev = q;
        }
    }
    let Some((mut sa, mut ba, mut sb, mut bb)) = bracket else {
        return Vec::new();
    };
    let neg_a = set.quantity(m, &at(sa), &ba) < 0.0;
    for _ in 0..200 {
        let sm = 0.5 * (sa + sb);
        if sm == sa || sm == sb {
            break;
        }
        let p = at(sm);
        let Some(bm) = follow(m, &p, &ba) else {
            return Vec::new();
        };
        let q = set.quantity(m, &p, &bm);
        if !q.is_finite() {
            return Vec::new();
        }
        if (q < 0.0) == neg_a {
            (sa, ba) = (sm, bm);
        } else {
            (sb, bb) = (sm, bm);
        }
    }
    let star = sa;
    let near = if (sb - sa).abs() < 1.0 { ba } else { bb };
    OFFSETS_MM
        .iter()
        .filter_map(|&off| {
            let p = at(star + off);
            let b = follow(m, &p, &near)?;
            Some(Constructed {
                set,
                offset_mm: off,
                p,
                alpha: b.alpha,
                rho: b.rho,
            })
        })
        .collect()
}

/// The branch of the inverse kinematics that a forward-kinematics mode is.
fn as_branch(mode: &FkMode, rho: &Sliders) -> IkBranch {
    IkBranch {
        alpha: mode.pose.alpha,
        rho: *rho,
        config: mode.config,
        verdict: mode.verdict,
    }
}

/// The mode of `rho` nearest `prev` (pose and alpha), if `rho` has any.
fn follow_mode(m: &Machine, rho: &Sliders, prev: &FkMode) -> Option<FkMode> {
    let d = |a: &FkMode| {
        1000.0 * wrap_angle(a.pose.alpha - prev.pose.alpha).abs() + (a.pose.p - prev.pose.p).amax()
    };
    crate::module_fk::solve(m, rho)
        .into_iter()
        .min_by(|a, b| d(a).total_cmp(&d(b)))
}

/// [`construct`] from the other side: the sliders move along `rho0 + s dir` and an assembly
/// mode is followed (for the inverse kinematics' tests: its branches at the mode's point must
/// contain the sliders). The quantity is that of [`HardSet::quantity`] at the mode.
pub fn construct_from_sliders(
    m: &Machine,
    set: HardSet,
    rho0: &Sliders,
    dir: &Vector3<f64>,
    mode: &FkMode,
    reach: f64,
) -> Vec<Constructed> {
    let dir = dir.normalize();
    let at = |s: f64| rho0 + dir * s;
    let q_of = |rho: &Sliders, md: &FkMode| set.quantity(m, &md.pose.p, &as_branch(md, rho));
    let dist = |a: &FkMode, b: &FkMode| {
        1000.0 * wrap_angle(a.pose.alpha - b.pose.alpha).abs() + (a.pose.p - b.pose.p).amax()
    };
    let step = reach / SCAN_STEPS as f64;
    let mut bracket = None;
    'sides: for side in [1.0, -1.0] {
        let mut prev = *mode;
        let mut q_prev = q_of(rho0, &prev);
        for k in 1..=SCAN_STEPS {
            let s = side * step * k as f64;
            let rho = at(s);
            let Some(md) = follow_mode(m, &rho, &prev) else {
                continue 'sides;
            };
            if dist(&md, &prev) > 50.0 * step.max(1.0) {
                continue 'sides;
            }
            let q = q_of(&rho, &md);
            if q.is_finite() && q_prev.is_finite() && (q < 0.0) != (q_prev < 0.0) {
                bracket = Some((s - side * step, prev, s, md));
                break 'sides;
            }
            prev = md;
            q_prev = q;
        }
    }
    let Some((mut sa, mut ma, mut sb, mut mb)) = bracket else {
        return Vec::new();
    };
    let neg_a = q_of(&at(sa), &ma) < 0.0;
    for _ in 0..200 {
        let sm = 0.5 * (sa + sb);
        if sm == sa || sm == sb {
            break;
        }
        let rho = at(sm);
        let Some(mm) = follow_mode(m, &rho, &ma) else {
            return Vec::new();
        };
        let q = q_of(&rho, &mm);
        if !q.is_finite() {
            return Vec::new();
        }
        if (q < 0.0) == neg_a {
            (sa, ma) = (sm, mm);
        } else {
            (sb, mb) = (sm, mm);
        }
    }
    let near = if (sb - sa).abs() < 1.0 { ma } else { mb };
    OFFSETS_MM
        .iter()
        .filter_map(|&off| {
            let rho = at(sa + off);
            let md = follow_mode(m, &rho, &near)?;
            Some(Constructed {
                set,
                offset_mm: off,
                p: md.pose.p,
                alpha: md.pose.alpha,
                rho,
            })
        })
        .collect()
}

/// A start for [`construct_from_sliders`]: random sliders within the strokes with one of their
/// assembly modes.
pub fn random_slider_start(m: &Machine, rng: &mut Sampler) -> Option<(Sliders, FkMode)> {
    let l = &m.limits;
    for _ in 0..50 {
        let rho = Sliders::from_fn(|j, _| rng.uniform(l.rho_min[j], l.rho_max[j]));
        let modes = crate::module_fk::solve(m, &rho);
        if modes.is_empty() {
            continue;
        }
        let mode = modes[(rng.next_u64() % modes.len() as u64) as usize];
        return Some((rho, mode));
    }
    None
}

/// A small deterministic generator (xorshift64*), for sampling starts reproducibly.
#[derive(Debug, Clone)]
pub struct Sampler(u64);

impl Sampler {
    pub fn new(seed: u64) -> Sampler {
        Sampler(seed.max(1))
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }

    /// A random unit vector.
    pub fn direction(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// A start for [`construct`]: a point of the machine's reach (a forward-kinematics mode of
/// random sliders within the strokes) and one of its branches, chosen at random.
pub fn random_start(m: &Machine, rng: &mut Sampler) -> Option<(Vector3<f64>, IkBranch)> {
    let l = &m.limits;
    for _ in 0..50 {
        let rho = Sliders::from_fn(|j, _| rng.uniform(l.rho_min[j], l.rho_max[j]));
        let modes = crate::module_fk::solve(m, &rho);
        if modes.is_empty() {
            continue;
        }
        let mode = modes[(rng.next_u64() % modes.len() as u64) as usize];
        let branches = module_ik::solve(m, &mode.pose.p);
        if branches.is_empty() {
            continue;
        }
        let b = branches[(rng.next_u64() % branches.len() as u64) as usize];
        return Some((mode.pose.p, b));
    }
    None
}

/// Machines other than the default for the tests: each dimension of the default perturbed by up
/// to 30 %, plus the variants the degenerate sets need (L2 = L3; small and large R2; both signs
/// of D - d), each checked by the machine file's validation (an invalid draw is drawn again).
pub fn random_geometries(count: usize, seed: u64) -> Vec<Machine> {
    let base = Machine::default_verne();
    let mut rng = Sampler::new(seed);
    let mut out = Vec::new();
    let mut k = 0usize;
    while out.len() < count && k < 100 * count.max(1) {
        k += 1;
        let mut m = base.clone();
        let mut jiggle = |v: f64| v * rng.uniform(0.7, 1.3);
        let g = &mut m.module;
        g.dx1 = jiggle(g.dx1);
        g.dx2 = jiggle(g.dx2);
        g.r_big1 = jiggle(g.r_big1);
        g.r_small1 = jiggle(g.r_small1);
        g.l1 = jiggle(g.l1);
        g.r_big2 = jiggle(g.r_big2);
        g.r4 = jiggle(g.r4);
        g.l2 = jiggle(g.l2);
        g.l3 = jiggle(g.l3);
        match out.len() % 5 {
            0 => g.l3 = g.l2,
            1 => g.r_big2 *= 0.25,
            2 => g.r_big2 *= 1.8,
            3 => {
                g.dx1 = -g.dx1;
                g.dx2 = -g.dx2;
            }
            _ => {}
        }
        m.name = format!("random geometry {}", out.len() + 1);
        if let Ok(valid) = Machine::from_toml_str(&m.to_toml(), &m.name) {
            out.push(valid);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constructed_poses_lie_on_their_set() {
        let m = Machine::default_verne();
        let mut rng = Sampler::new(7);
        let mut built = 0;
        for set in HardSet::ALL {
            for _ in 0..60 {
                let Some((p0, b)) = random_start(&m, &mut rng) else {
                    continue;
                };
                let dir = rng.direction();
                let poses = construct(&m, set, &p0, &dir, &b, 300.0);
                let q_at = |off: f64| {
                    let c = poses.iter().find(|c| c.offset_mm == off)?;
                    let b = module_ik::solve(&m, &c.p)
                        .into_iter()
                        .min_by(|x, y| (x.rho - c.rho).amax().total_cmp(&(y.rho - c.rho).amax()))?;
                    Some(set.quantity(&m, &c.p, &b).abs())
                };
                if let (Some(on), Some(plus), Some(minus)) = (q_at(0.0), q_at(0.1), q_at(-0.1)) {
                    // On the set the quantity is a million times smaller than 0.1 mm away.
                    assert!(
                        on <= 1e-6 * plus.max(minus),
                        "{set:?}: {on} vs {plus}, {minus}"
                    );
                    built += 1;
                }
            }
        }
        assert!(built >= 40, "only {built} constructions");
    }
}
