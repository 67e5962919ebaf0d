//! The labels and verdicts of four leg-I postures side by side, one AVX register per quantity:
//! what `ik::branches_into` computes posture by posture (leg I's state, the square roots
//! of eqs. (12)-(13) with legs II and III's labels, the strokes of the four branches and the
//! rods' crossing), for a point with exactly four postures, as `verne ik --all` meets on most
//! points (two roots of (9), each with its mirror image). Every number is the same operation on
//! the same operands as there, lane by lane (an AVX lane rounds as a scalar SSE2 instruction
//! does, and Rust neither fuses nor reorders), so the branches are the same bit for bit; the
//! tests compare the two (tests/module_fast_paths.rs). x86-64 only: elsewhere the AVX2 build
//! does not exist.

use std::arch::x86_64::*;

use nalgebra::Vector3;

use super::branch::{IkBranch, IkBranches, Leg1, posture_order, push_distinct};
use crate::parallel_module::branches::{Reason, Verdict};
use crate::parallel_module::equations::Sliders;
use crate::spec::Machine;
use crate::tolerance::{CONFIG_SIGN_MM, LIMIT_SLACK, SQRT_ARG_REL};

/// Every branch on the four leg-I postures `legs1` of `p` into `out` (cleared first), as
/// `ik::branches_into` gives them.
///
/// # Safety
/// The processor must have AVX2 ([`crate::math::cpu::has_avx2`]).
#[inline(always)]
pub(crate) unsafe fn branches_into(
    m: &Machine,
    p: &Vector3<f64>,
    legs1: &[Leg1; 4],
    out: &mut IkBranches,
) {
    out.reset();
    if !p.iter().all(|v| v.is_finite()) {
        return;
    }
    // SAFETY: the caller guarantees AVX2 (and with it AVX).
    let lanes = unsafe { PostureLanes::new(m, p, legs1) };
    let s1: [i8; 6] = std::array::from_fn(|k| if k < 4 { lanes.s1[k] as i8 } else { -1 });
    let (order, n) = posture_order(legs1, &s1);
    for &k in &order[..n] {
        if lanes.reach >> k & 1 == 0 {
            continue;
        }
        let s2 = [lanes.s2[0][k] as i8, lanes.s2[1][k] as i8];
        let s3 = [lanes.s3[0][k] as i8, lanes.s3[1][k] as i8];
        let leg1 = &legs1[k];
        let branch = |k2: usize, k3: usize| IkBranch {
            alpha: leg1.alpha,
            rho: Sliders::new(leg1.rho1, lanes.rho2[k2][k], lanes.rho3[k3][k]),
            config: [s1[k], s2[k2], s3[k3]],
            verdict: Verdict::from_bits(lanes.verdict[2 * k2 + k3][k] as u16),
        };
        let pushed = push_distinct(
            out,
            [branch(0, 0), branch(0, 1), branch(1, 0), branch(1, 1)],
        );
        debug_assert!(pushed, "four postures of four branches fit MAX_IK_BRANCHES");
    }
}

/// What the four postures' branches need, lane k for posture k.
struct PostureLanes {
    /// Bit k: legs II and III both reach at posture k (eqs. (12)-(13) have real roots).
    reach: u32,
    /// s1 (+1 or -1) of each posture, and s2 and s3 at the [lower, upper] roots of (12)-(13).
    s1: [i64; 4],
    s2: [[i64; 4]; 2],
    s3: [[i64; 4]; 2],
    /// rho2 and rho3 at the [lower, upper] roots of (12)-(13).
    rho2: [[f64; 4]; 2],
    rho3: [[f64; 4]; 2],
    /// Verdict bits of branch (s2, s3) = (lower, lower), (lower, upper), (upper, lower),
    /// (upper, upper).
    verdict: [[u64; 4]; 4],
}

impl PostureLanes {
    /// # Safety
    /// The processor must have AVX2.
    #[target_feature(enable = "avx2")]
    #[inline]
    unsafe fn new(m: &Machine, p: &Vector3<f64>, legs1: &[Leg1; 4]) -> PostureLanes {
        let g = &m.module;
        let lim = &m.limits;
        let ct = lim.cos_rod_tilt_max;
        // SAFETY: the caller guarantees AVX; the loads and stores are of local arrays.
        unsafe {
            let set1 = _mm256_set1_pd;
            let column = |f: fn(&Leg1) -> f64| {
                _mm256_setr_pd(f(&legs1[0]), f(&legs1[1]), f(&legs1[2]), f(&legs1[3]))
            };
            let (rho1, s, c) = (column(|l| l.rho1), column(|l| l.sin), column(|l| l.cos));
            let (y, z) = (set1(p.y), set1(p.z));
            let zero = _mm256_setzero_pd();
            let add = |a, b| _mm256_add_pd(a, b);
            let sub = |a, b| _mm256_sub_pd(a, b);
            let mul = |a, b| _mm256_mul_pd(a, b);
            let or = |a, b| _mm256_or_pd(a, b);
            let lt = |a, b| _mm256_cmp_pd::<_CMP_LT_OQ>(a, b);
            let gt = |a, b| _mm256_cmp_pd::<_CMP_GT_OQ>(a, b);
            let le = |a, b| _mm256_cmp_pd::<_CMP_LE_OQ>(a, b);
            // branches::rod_too_tilted: r.z < cos_tilt_max |r|, squared.
            let ct2 = set1(ct * ct);
            let tilted = |rz, norm_sq| {
                let (zz, bound) = (mul(rz, rz), mul(ct2, norm_sq));
                if ct >= 0.0 {
                    or(lt(rz, zero), lt(zz, bound))
                } else {
                    _mm256_and_pd(lt(rz, zero), gt(zz, bound))
                }
            };
            // branches::outside_stroke.
            let outside = |rho, leg: usize| {
                or(
                    lt(rho, set1(lim.rho_min[leg] - LIMIT_SLACK)),
                    gt(rho, set1(lim.rho_max[leg] + LIMIT_SLACK)),
                )
            };
            let config = set1(CONFIG_SIGN_MM);

            // Leg I (branches::leg_state, leg 0): the rods r3, r4 of the parallelogram.
            let r1 = set1(g.r_big1);
            let dy = sub(mul(r1, c), set1(g.r_small1));
            let dz = mul(r1, s);
            let u = p.x + g.dx1;
            let uu = set1(u * u);
            let (y3, y4) = (add(y, dy), sub(y, dy));
            let z3 = sub(add(z, dz), rho1);
            let z4 = sub(sub(z, dz), rho1);
            let n3 = add(add(uu, mul(y3, y3)), mul(z3, z3));
            let n4 = add(add(uu, mul(y4, y4)), mul(z4, z4));
            let tilted1 = or(tilted(z3, n3), tilted(z4, n4));
            let inverted1 = gt(sub(rho1, z), config);
            let stroke1 = outside(rho1, 0);
            // branches::rods_cross.
            let cross = le(mul(r1, c), set1(g.r_small1));

            // Legs II and III (ik::outer_legs, leg_root, branches::outer_leg_labels).
            let dx2 = p.x + g.dx2;
            let dx2_sq = dx2 * dx2;
            let r2c = mul(set1(g.r_big2), c);
            let dy2 = add(sub(y, r2c), set1(g.r4));
            let dy3 = sub(add(y, r2c), set1(g.r4));
            let abs = |a| _mm256_andnot_pd(set1(-0.0), a);
            let root = |l: f64, dy| {
                let arg = sub(set1(l * l - dx2_sq), mul(dy, dy));
                let finite = lt(abs(arg), set1(f64::INFINITY));
                let fails = or(
                    lt(arg, set1(-SQRT_ARG_REL * l * l)),
                    _mm256_xor_pd(finite, _mm256_castsi256_pd(_mm256_set1_epi64x(-1))),
                );
                (_mm256_sqrt_pd(_mm256_max_pd(arg, zero)), fails)
            };
            let (h2, fails2) = root(g.l2, dy2);
            let (h3, fails3) = root(g.l3, dy3);
            let reach = !_mm256_movemask_pd(or(fails2, fails3)) as u32 & 0b1111;
            let neg = |a| _mm256_xor_pd(a, set1(-0.0));
            // Each leg's [lower, upper] root: the sign quantity -h, +h; the rod's z component
            // +h, -h.
            let outer = |dy, h| {
                let norm_sq = add(add(set1(dx2_sq), mul(dy, dy)), mul(h, h));
                (
                    [gt(neg(h), config), gt(h, config)],
                    [tilted(h, norm_sq), tilted(neg(h), norm_sq)],
                )
            };
            let (inverted2, tilted2) = outer(dy2, h2);
            let (inverted3, tilted3) = outer(dy3, h3);

            // The four branches (ik::four_branches).
            let r2s = mul(set1(g.r_big2), s);
            let (off2, off3) = (sub(z, r2s), add(z, r2s));
            let rho2 = [sub(off2, h2), add(off2, h2)];
            let rho3 = [sub(off3, h3), add(off3, h3)];

            // Verdict bits, 64 per lane.
            let bit = |on: __m256d, r: Reason| {
                _mm256_and_si256(
                    _mm256_castpd_si256(on),
                    _mm256_set1_epi64x(1i64 << (r as u32)),
                )
            };
            let ori = |a, b| _mm256_or_si256(a, b);
            let tilt = Reason::RodTilt;
            let v1 = ori(
                ori(
                    bit(inverted1, Reason::Leg1Inverted),
                    bit(stroke1, Reason::Rho1Stroke),
                ),
                ori(bit(tilted1, tilt), bit(cross, Reason::RodsCross)),
            );
            // Leg II or III (slider `leg`, 1 or 2) at its [lower, upper] root. Closures are
            // called directly: through `array::map` they stay calls, outside the AVX2 context.
            let outer_verdict =
                |inverted: [__m256d; 2],
                 tilted: [__m256d; 2],
                 rho: [__m256d; 2],
                 leg: usize,
                 (inverted_reason, stroke_reason): (Reason, Reason)| {
                    let verdict = |j: usize| {
                        ori(
                            ori(bit(inverted[j], inverted_reason), bit(tilted[j], tilt)),
                            bit(outside(rho[j], leg), stroke_reason),
                        )
                    };
                    [verdict(0), verdict(1)]
                };
            let v2 = outer_verdict(
                inverted2,
                tilted2,
                rho2,
                1,
                (Reason::Leg2Inverted, Reason::Rho2Stroke),
            );
            let v3 = outer_verdict(
                inverted3,
                tilted3,
                rho3,
                2,
                (Reason::Leg3Inverted, Reason::Rho3Stroke),
            );
            let mut verdict = [[0u64; 4]; 4];
            for (b, v) in verdict.iter_mut().enumerate() {
                let both = ori(v1, ori(v2[b / 2], v3[b % 2]));
                _mm256_storeu_si256(v.as_mut_ptr().cast(), both);
            }
            let store = |a: __m256d| {
                let mut v = [0.0; 4];
                _mm256_storeu_pd(v.as_mut_ptr(), a);
                v
            };
            // s_i = +1 where inverted (all ones: 2 - 1), else -1 (0 - 1).
            let sign = |inverted: __m256d| {
                let two = _mm256_and_si256(_mm256_castpd_si256(inverted), _mm256_set1_epi64x(2));
                let mut v = [0i64; 4];
                _mm256_storeu_si256(
                    v.as_mut_ptr().cast(),
                    _mm256_sub_epi64(two, _mm256_set1_epi64x(1)),
                );
                v
            };
            PostureLanes {
                reach,
                s1: sign(inverted1),
                s2: [sign(inverted2[0]), sign(inverted2[1])],
                s3: [sign(inverted3[0]), sign(inverted3[1])],
                rho2: [store(rho2[0]), store(rho2[1])],
                rho3: [store(rho3[0]), store(rho3[1])],
                verdict,
            }
        }
    }
}
