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

use crate::parallel_module::equations::Sliders;
use crate::parallel_module::fk::FkMode;
use crate::parallel_module::ik::{self, IkBranch, wrap_angle};
use crate::spec::Machine;

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
    /// A leg's square root at zero (eqs. (11)-(13): leg I's height, L2^2 - dx^2 - dy^2 for leg
    /// II, the same for leg III): a fully stretched rod, where the branch meets its mirror in
    /// that leg and ends.
    StretchedLeg,
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
        HardSet::StretchedLeg,
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
            HardSet::StretchedLeg => "stretched_leg",
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
            HardSet::StretchedLeg => {
                let u = p.x + g.dx1;
                let k1 = g.l1 * g.l1 - g.r_big1 * g.r_big1 - g.r_small1 * g.r_small1
                    + 2.0 * g.r_big1 * g.r_small1 * c;
                let dx = p.x + g.dx2;
                let dy2 = p.y - g.r_big2 * c + g.r4;
                let dy3 = p.y + g.r_big2 * c - g.r4;
                [
                    (k1 - u * u - p.y * p.y) / (g.l1 * g.l1),
                    (g.l2 * g.l2 - dx * dx - dy2 * dy2) / (g.l2 * g.l2),
                    (g.l3 * g.l3 - dx * dx - dy3 * dy3) / (g.l3 * g.l3),
                ]
                .into_iter()
                .fold(f64::INFINITY, f64::min)
            }
            HardSet::ParallelSingularity => {
                let pose = crate::parallel_module::equations::ModulePose {
                    p: *p,
                    alpha: b.alpha,
                };
                crate::parallel_module::equations::jacobian_pose(g, &pose, &b.rho).determinant()
            }
            HardSet::Cubic9DoubleRoot => {
                let k = ik::eq9_coefficients(g, p);
                (3.0 * k[3] * c + 2.0 * k[2]) * c + k[1]
            }
        }
    }
}

/// Where condition (21) (Det = 0), b = 0 and a tangent of leg I (Delta = 0: the two tau of
/// eq. (10) on the line of eq. (14) are equal) meet at one alpha on the default machine: (rho2 -
/// rho1, rho3 - rho1, alpha) (mm, mm, rad), found by `mpmath.findroot` on Det = b = Delta = 0
/// at 40 digits and rounded to doubles. Two assembly modes merge there, at a zero of Det.
pub const DET_B_DELTA_ZERO: [(f64, f64, f64); 4] = [
    (
        -1627.7550604132189,
        -1627.8666764352438,
        -4.787157408607968e-5,
    ),
    (1283.040403527657, 1283.1107411285327, -3.141465950265598),
    (1627.7550604132189, 1627.8666764352438, 4.787157408607968e-5),
    (-1283.040403527657, -1283.1107411285327, -3.1417193569139883),
];

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
    ik::solve(m, p)
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
    let step = reach / SCAN_STEPS as f64;
    // The branch at s, followed from `prev`, with the quantity there. A stretched leg is a fold:
    // past it the branch does not exist (the square root's argument would be negative), which
    // counts as the quantity's other sign; for the other sets a lost branch ends the search.
    let probe = |s: f64, prev: &IkBranch| -> Option<(IkBranch, f64)> {
        let p = at(s);
        match follow(m, &p, prev) {
            Some(b) if branch_distance(&b, prev) <= 50.0 * step.max(1.0) => {
                Some((b, set.quantity(m, &p, &b)))
            }
            _ if set == HardSet::StretchedLeg => Some((*prev, -1.0)),
            _ => None,
        }
    };
    // Scan outwards from s = 0 in both directions, following the branch step by step.
    let mut bracket = None;
    'sides: for side in [1.0, -1.0] {
        let mut prev = *branch;
        let mut q_prev = set.quantity(m, p0, &prev);
        for k in 1..=SCAN_STEPS {
            let s = side * step * k as f64;
            let Some((b, q)) = probe(s, &prev) else {
                continue 'sides;
            };
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
        let Some((bm, q)) = probe(sm, &ba) else {
            return Vec::new();
        };
        if !q.is_finite() {
            return Vec::new();
        }
        if (q < 0.0) == neg_a {
            (sa, ba) = (sm, bm);
        } else {
            (sb, bb) = (sm, bm);
        }
    }
    // A branch lost for another reason than a stretched leg (two postures meeting) is not this
    // set.
    if set == HardSet::StretchedLeg && set.quantity(m, &at(sa), &ba).abs() > 1e-9 {
        return Vec::new();
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
    crate::parallel_module::fk::solve(m, rho)
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
        let modes = crate::parallel_module::fk::solve(m, &rho);
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
        let modes = crate::parallel_module::fk::solve(m, &rho);
        if modes.is_empty() {
            continue;
        }
        let mode = modes[(rng.next_u64() % modes.len() as u64) as usize];
        let branches = ik::solve(m, &mode.pose.p);
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

/// A constructed pose matches a solution within these (mm, rad): its own accuracy is that of
/// the kinematics it came from, about 1e-12 mm.
pub const MATCH_MM: f64 = 1e-6;
pub const MATCH_RAD: f64 = 1e-8;
/// The same at a fold (a parallel singularity, or two leg-I postures meeting): there the pose is
/// fixed by the joints only to the square root of their rounding (about 1e-5 mm).
pub const FOLD_MATCH_MM: f64 = 1e-4;
pub const FOLD_MATCH_RAD: f64 = 1e-6;
/// Within this offset (mm) of a fold the line of construction maps to joints within rounding of
/// the fold (it is tangent to it): a pair of solutions there may be real or not for the rounded
/// joints, and either answer is correct when it is proved.
pub const FOLD_ROUNDING_OFFSET_MM: f64 = 1e-5;

/// What a batch of constructed poses showed.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    pub poses: u64,
    /// Poses whose solution the solver did not return, the first few described (with the
    /// joints that reproduce them).
    pub lost: u64,
    /// Answers proved by the factors, in double-double, or not proved.
    pub factored: u64,
    pub extended: u64,
    pub unproved: u64,
    pub examples: Vec<String>,
}

impl Tally {
    fn note(&mut self, what: String) {
        if self.examples.len() < 10 {
            self.examples.push(what);
        }
    }

    fn count(&mut self, c: crate::certificate::Certificate) {
        use crate::certificate::Certificate;
        match c {
            Certificate::Double => {}
            Certificate::Factored => self.factored += 1,
            Certificate::Extended => self.extended += 1,
            _ => self.unproved += 1,
        }
    }

    pub fn add(&mut self, o: Tally) {
        self.poses += o.poses;
        self.lost += o.lost;
        self.factored += o.factored;
        self.extended += o.extended;
        self.unproved += o.unproved;
        for e in o.examples {
            self.note(e);
        }
    }
}

/// Whether a solution (p, alpha, rho) matches the constructed pose, with the fold's tolerance
/// where the set is a fold.
fn matches(set: HardSet, c: &Constructed, p: &Vector3<f64>, alpha: f64, rho: &Sliders) -> bool {
    let fold = matches!(
        set,
        HardSet::ParallelSingularity | HardSet::Cubic9DoubleRoot
    );
    let (mm, rad) = if fold {
        (FOLD_MATCH_MM, FOLD_MATCH_RAD)
    } else {
        (MATCH_MM, MATCH_RAD)
    };
    (p - c.p).amax() < mm && (rho - c.rho).amax() < mm && wrap_angle(alpha - c.alpha).abs() < rad
}

/// The fold's allowance: within rounding of a fold, a proved answer without the pose is right.
fn fold_allows(set: HardSet, c: &Constructed, proved: bool) -> bool {
    matches!(
        set,
        HardSet::ParallelSingularity | HardSet::Cubic9DoubleRoot
    ) && c.offset_mm.abs() <= FOLD_ROUNDING_OFFSET_MM
        && proved
}

/// The forward kinematics on poses built on `set` from `starts` random starts (each giving up
/// to eleven poses): the modes of each pose's sliders must contain it.
pub fn check_fk(m: &Machine, set: HardSet, starts: usize, rng: &mut Sampler) -> Tally {
    let mut t = Tally::default();
    let mut built = 0;
    for _ in 0..20 * starts.max(1) {
        if built >= starts {
            break;
        }
        let Some((p0, b)) = random_start(m, rng) else {
            continue;
        };
        let poses = construct(m, set, &p0, &rng.direction(), &b, 300.0);
        built += usize::from(!poses.is_empty());
        for c in poses {
            t.poses += 1;
            let modes = crate::parallel_module::fk::solve(m, &c.rho);
            t.count(modes.certificate);
            let found = modes
                .iter()
                .any(|f| matches(set, &c, &f.pose.p, f.pose.alpha, &c.rho))
                || fold_allows(set, &c, modes.certificate.proved());
            if !found || !modes.certificate.proved() {
                t.lost += u64::from(!found);
                t.note(format!(
                    "{}: `verne modes --joints {},{},{}` {} the pose P = ({}, {}, {}), alpha = {} rad ({}, offset {:e} mm; {})",
                    m.name,
                    c.rho.x,
                    c.rho.y,
                    c.rho.z,
                    if found { "has" } else { "lacks" },
                    c.p.x,
                    c.p.y,
                    c.p.z,
                    c.alpha,
                    set.name(),
                    c.offset_mm,
                    modes.certificate.code()
                ));
            }
        }
    }
    t
}

/// The module's inverse kinematics on points built on `set` from the slider side
/// ([`construct_from_sliders`]): the branches of each point must contain its sliders.
pub fn check_ik(m: &Machine, set: HardSet, starts: usize, rng: &mut Sampler) -> Tally {
    let mut t = Tally::default();
    let mut built = 0;
    for _ in 0..20 * starts.max(1) {
        if built >= starts {
            break;
        }
        let Some((rho0, mode)) = random_slider_start(m, rng) else {
            continue;
        };
        let cs = construct_from_sliders(m, set, &rho0, &rng.direction(), &mode, 300.0);
        built += usize::from(!cs.is_empty());
        for c in cs {
            t.poses += 1;
            let ik = ik::solve(m, &c.p);
            t.count(ik.certificate);
            let found = ik.iter().any(|b| matches(set, &c, &c.p, b.alpha, &b.rho))
                || fold_allows(set, &c, ik.certificate.proved());
            if !found || !ik.certificate.proved() {
                t.lost += u64::from(!found);
                t.note(format!(
                    "{}: `verne modes --pose={},{},{}` {} the branch alpha = {} rad, rho = ({}, {}, {}) ({}, offset {:e} mm; {})",
                    m.name,
                    c.p.x,
                    c.p.y,
                    c.p.z,
                    if found { "has" } else { "lacks" },
                    c.alpha,
                    c.rho.x,
                    c.rho.y,
                    c.rho.z,
                    set.name(),
                    c.offset_mm,
                    ik.certificate.code()
                ));
            }
        }
    }
    t
}

/// The machine's inverse kinematics on tool poses whose theta1 equation has its double root
/// (Table II of IFToMM 2007 along the pose: at the theta1 where alpha = 0 the platform point has
/// y_p = 0 and rho1 - z_p takes both signs) or is next to it: P = (x, offset, z) with a module
/// branch at alpha near 0, random theta1 within its range and theta2, the tool pose from eq. (26)
/// of AIM 2007. The machine's branches must contain the joints.
pub fn check_machine_ik(m: &Machine, starts: usize, rng: &mut Sampler) -> Tally {
    use crate::machine::{machine_ik, tool_pose_eq26};
    let mut t = Tally::default();
    let mut built = 0;
    for _ in 0..50 * starts.max(1) {
        if built >= starts {
            break;
        }
        let Some((p0, _)) = random_start(m, rng) else {
            continue;
        };
        let theta1 = rng.uniform(m.limits.theta1_min, m.limits.theta1_max);
        let theta2 = rng.uniform(-3.0, 3.0);
        let mut any = false;
        for off in OFFSETS_MM {
            let p = Vector3::new(p0.x, off, p0.z);
            for b in ik::solve(m, &p) {
                if b.alpha.abs() > 0.1 {
                    continue;
                }
                any = true;
                t.poses += 1;
                let module = crate::parallel_module::equations::ModulePose { p, alpha: b.alpha };
                let tool = tool_pose_eq26(&m.table, &module, theta1, theta2, m.tool_length);
                let ik = machine_ik(m, &tool, m.tool_length);
                t.count(ik.certificate);
                let found = ik.iter().any(|x| {
                    (x.rho - b.rho).amax() < MATCH_MM
                        && wrap_angle(x.theta1 - theta1).abs() < MATCH_RAD
                });
                if !found || !ik.certificate.proved() {
                    t.lost += u64::from(!found);
                    t.note(format!(
                        "{}: tool pose {:?} {} the joints rho = {:?}, theta1 = {theta1} rad ({})",
                        m.name,
                        tool,
                        if found { "has" } else { "lacks" },
                        b.rho,
                        ik.certificate.code()
                    ));
                }
            }
        }
        built += usize::from(any);
    }
    t
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
                    let b = ik::solve(&m, &c.p)
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
