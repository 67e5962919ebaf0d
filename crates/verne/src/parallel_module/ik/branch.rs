//! What the inverse kinematics returns ([`IkBranch`], [`IkBranches`]) and the leg-I postures it
//! builds the branches on ([`Leg1`]), with the order the branches come out in
//! ([`posture_order`]): shared by the posture-by-posture path (`ik`) and the four-lane path
//! (`ik::lanes`), which use it and not each other.

use crate::certificate::Certified;
use crate::parallel_module::branches::{Config, Verdict, listed_in_order};
use crate::parallel_module::equations::Sliders;

/// Most branches one point can have: three roots of eq. (9), two alphas each, two rho2, two rho3.
pub const MAX_IK_BRANCHES: usize = 24;

/// One inverse-kinematics branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkBranch {
    pub alpha: f64,
    pub rho: Sliders,
    pub config: Config,
    pub verdict: Verdict,
}

impl IkBranch {
    pub fn working(&self) -> bool {
        self.verdict.feasible()
    }
}

/// Every inverse-kinematics branch of one point, with the certificate that says why there are
/// no others.
pub type IkBranches = Certified<IkBranch, MAX_IK_BRANCHES>;

/// The distinct branches among one posture's four (in `four_branches`' order: (s2, s3) = lower
/// or upper root of eqs. (12)-(13), lower first), as the first `n` of the returned four: all four,
/// but where the two roots of (12) or (13) meet (a stretched outer leg, its rod horizontal:
/// h = sqrt(L^2 - dx^2 - dy^2) within [`crate::tolerance::CONFIG_SIGN_MM`] of zero, both roots
/// labelled -1) the branch is listed once, with the lower root (the two differ by 2 h). The
/// lower root is always labelled -1, so two of a posture's branches share a configuration
/// exactly when a leg's roots meet.
#[inline(always)]
pub(crate) fn distinct_branches(four: [IkBranch; 4]) -> ([IkBranch; 4], usize) {
    let leg3_meets = four[0].config == four[1].config;
    let leg2_meets = four[0].config == four[2].config;
    match (leg2_meets, leg3_meets) {
        (false, false) => (four, 4),
        (false, true) => ([four[0], four[2], four[1], four[3]], 2),
        (true, false) => (four, 2),
        (true, true) => (four, 1),
    }
}

/// Pushes the distinct branches among one posture's four ([`distinct_branches`]) onto `out`;
/// false when they do not fit. The usual case, four distinct branches, is one fixed-size copy:
/// a copy of a variable `n` branches made the complete solver (`ik/all_branches` in
/// docs/benchmarks.md) a quarter slower.
#[inline(always)]
pub(crate) fn push_distinct(
    out: &mut arrayvec::ArrayVec<IkBranch, MAX_IK_BRANCHES>,
    four: [IkBranch; 4],
) -> bool {
    let config = four[0].config;
    if config != four[1].config && config != four[2].config {
        return out.try_extend_from_slice(&four).is_ok();
    }
    push_meeting(out, four)
}

/// [`push_distinct`] where a leg's two roots meet (a stretched outer leg: rare).
#[cold]
#[inline(never)]
fn push_meeting(
    out: &mut arrayvec::ArrayVec<IkBranch, MAX_IK_BRANCHES>,
    four: [IkBranch; 4],
) -> bool {
    let (four, n) = distinct_branches(four);
    out.try_extend_from_slice(&four[..n]).is_ok()
}

/// A leg-I posture: an orientation alpha and the slider-1 position that goes with it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Leg1 {
    pub alpha: f64,
    pub rho1: f64,
    pub sin: f64,
    pub cos: f64,
}

/// The order in which the branches of the leg-I postures `legs1` come out, with their leg-I
/// configuration indices `s1`: the first `legs1.len()` entries, indices into `legs1`.
/// Branches come out ordered by alpha, then (s1, s2, s3): postures sorted by (alpha, s1), and
/// within a posture s2, s3 = -1 before +1 (the roots of (12)-(13) in increasing order).
/// Postures come in pairs (alpha >= 0, its mirror) by increasing cos(alpha): the mirrors in
/// that order, then the others in reverse, is usually the order already; sorted if not.
#[inline(always)]
pub(crate) fn posture_order(legs1: &[Leg1], s1: &[i8; 6]) -> ([usize; 6], usize) {
    let n = legs1.len().min(6);
    let mut order = [0usize; 6];
    let (mut front, mut back) = (0, n);
    for (k, leg1) in legs1[..n].iter().enumerate() {
        if leg1.alpha < 0.0 {
            order[front] = k;
            front += 1;
        } else {
            back -= 1;
            order[back] = k;
        }
    }
    let listed = &mut order[..n];
    let in_order = listed
        .windows(2)
        .all(|w| listed_in_order((legs1[w[0]].alpha, s1[w[0]]), (legs1[w[1]].alpha, s1[w[1]])));
    if !in_order {
        let key = |k: usize| (legs1[k].alpha, s1[k]);
        listed.sort_unstable_by(|&a, &b| {
            let (ka, kb) = (key(a), key(b));
            ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1))
        });
    }
    (order, n)
}
