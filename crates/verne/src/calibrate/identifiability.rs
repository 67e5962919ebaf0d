//! What the readings can determine: the rank of the identification Jacobian, the combinations
//! of parameters they cannot tell apart, named in words, and which parameters are then held at
//! their nominal values.
//!
//! The instrument's parameters are always fitted, so they are projected out first: the
//! machine's columns of the weighted Jacobian J = [Jm Jn] become (I - Qn Qn^T) Jm (Qn an
//! orthonormal basis of Jn's columns), each divided by the norm it had before (a parameter that
//! the instrument's frame absorbs entirely then has a column near zero). The singular values of
//! that matrix say how many directions the readings determine (those above [`RANK_TOL`]); the
//! parameters kept are chosen in [`Param::preference`] order by Gram-Schmidt (a column whose
//! part outside the kept ones' span is below [`RANK_TOL`] is held), the structural combinations
//! of the VERNE module ([`PATTERNS`]) first, so that each held parameter comes with the reason
//! the equations give.

use nalgebra::DMatrix;

use super::model::Device;
use super::params::Param;

/// A singular value of the projected, column-normalised Jacobian below this (dimensionless) is a
/// direction the readings do not determine: structural combinations come out near 1e-14
/// (rounding); the weakest parameters the VERNE's readings do determine, above 1e-6.
pub const RANK_TOL: f64 = 1e-9;

/// A structural combination is a direction the readings do not determine when the projected
/// Jacobian moves by at most this (relative to the direction's length) along it: rounding, far
/// below the weakest direction they do determine.
pub const PATTERN_TOL: f64 = 1e-8;

/// A column whose norm is below this fraction of the largest is a parameter the readings do
/// not depend on at all.
pub const ABSENT_TOL: f64 = 1e-12;

/// A combination the equations cannot see, with the parameter it holds and why, per device.
pub struct Pattern {
    /// The combination (parameter, coefficient), in the units the parameters are written in.
    pub moves: &'static [(Param, f64)],
    /// The parameter held at its nominal value for it.
    pub holds: Param,
    /// Why, in words, for the readings of these devices.
    pub why: fn(&[Device]) -> &'static str,
}

/// The structural combinations of the VERNE module and table, in the order they are tried.
pub const PATTERNS: &[Pattern] = &[
    Pattern {
        moves: &[(Param::D1, 1.0), (Param::LowerD1, 1.0)],
        holds: Param::LowerD1,
        why: |_| "D1 and d1 enter eqs. (3)-(4) of IFToMM 2007 only as D1 - d1",
    },
    Pattern {
        moves: &[(Param::D2, 1.0), (Param::LowerD2, 1.0)],
        holds: Param::LowerD2,
        why: |_| "D2 and d2 enter eqs. (5)-(6) of IFToMM 2007 only as D2 - d2",
    },
    Pattern {
        moves: &[(Param::D1, 1.0), (Param::D2, 1.0)],
        holds: Param::D2,
        why: |d| {
            if reads_points(d) {
                "a common x shift of the legs (D1 and D2 together) moves the whole module along x: it is the instrument frame's x"
            } else if d.contains(&Device::Ballbar) {
                "a common x shift of the legs (D1 and D2 together) moves the whole module along the tilting axis: it is the table ball's x"
            } else {
                "a common x shift of the legs (D1 and D2 together) moves the whole module along x, which heights do not see"
            }
        },
    },
    Pattern {
        moves: &[
            (Param::Rho1Zero, 1.0),
            (Param::Rho2Zero, 1.0),
            (Param::Rho3Zero, 1.0),
        ],
        holds: Param::Rho3Zero,
        why: |d| {
            if reads_points(d) {
                "a common offset of the three slider zeros moves the whole module along z: it is the instrument frame's z"
            } else if d.contains(&Device::Probe) {
                "a common offset of the three slider zeros moves the whole module along z: it is the plane's height"
            } else {
                "a common offset of the three slider zeros moves the whole module along z: it is the table's height d_a"
            }
        },
    },
    Pattern {
        moves: &[
            (Param::Rho1Zero, 1.0),
            (Param::Rho2Zero, 1.0),
            (Param::Rho3Zero, 1.0),
            (Param::TableDa, 1.0),
        ],
        holds: Param::Rho3Zero,
        why: |_| "a common offset of the three slider zeros and d_a move the module and the table together along z: no reading sees where both are",
    },
    Pattern {
        moves: &[(Param::Theta2Zero, 1.0)],
        holds: Param::Theta2Zero,
        why: |_| "the rotary axis's zero turns the table ball about the rotary axis: it is the ball's angle on the table",
    },
    Pattern {
        moves: &[(Param::TableDt, 1.0)],
        holds: Param::TableDt,
        why: |_| "d_t moves the table ball along the rotary axis: it is the ball's height on the table",
    },
];

/// A tracker or the module alone among the devices: an instrument frame that reads points.
fn reads_points(devices: &[Device]) -> bool {
    devices
        .iter()
        .any(|d| matches!(d, Device::Tracker | Device::Platform))
}

/// A parameter held at its nominal value, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Held {
    pub param: Param,
    /// The combination the readings cannot see, (parameter, coefficient) in the units they are
    /// written in (mm, degrees), the held parameter's coefficient 1.
    pub combination: Vec<(Param, f64)>,
    /// In words: the reason the equations give, or the combination written out.
    pub why: String,
}

/// What the readings determine.
#[derive(Debug, Clone, PartialEq)]
pub struct Identifiability {
    /// Singular values of the projected, column-normalised Jacobian, largest first.
    pub singular_values: Vec<f64>,
    /// The directions they determine (those above [`RANK_TOL`]).
    pub rank: usize,
    /// The parameters the fit moves, in the order given.
    pub identified: Vec<Param>,
    /// The parameters held at their nominal values, each with the combination it stands for.
    pub held: Vec<Held>,
}

/// The machine columns of `j` (the first `params.len()`), the instrument's projected out and
/// each divided by its own norm before the projection; and those norms.
fn projected_columns(j: &DMatrix<f64>, n_params: usize) -> (DMatrix<f64>, Vec<f64>) {
    let jm = j.columns(0, n_params).into_owned();
    let jn = j.columns(n_params, j.ncols() - n_params).into_owned();
    let norms: Vec<f64> = (0..n_params).map(|c| jm.column(c).norm()).collect();
    let mut out = jm.clone();
    if jn.ncols() > 0 {
        let q = orthonormal_basis(&jn);
        out -= &q * (q.transpose() * &jm);
    }
    for (c, &norm) in norms.iter().enumerate() {
        if norm > 0.0 {
            out.column_mut(c).scale_mut(1.0 / norm);
        }
    }
    (out, norms)
}

/// An orthonormal basis of the columns of `a` (Gram-Schmidt twice, columns below [`RANK_TOL`]
/// of their norm dropped).
fn orthonormal_basis(a: &DMatrix<f64>) -> DMatrix<f64> {
    let mut basis: Vec<nalgebra::DVector<f64>> = Vec::new();
    for c in 0..a.ncols() {
        let col = a.column(c).into_owned();
        let norm = col.norm();
        if let Some(v) = orthogonal_part(&basis, &col)
            && v.norm() > RANK_TOL * norm
        {
            basis.push(v.normalize());
        }
    }
    if basis.is_empty() {
        return DMatrix::zeros(a.nrows(), 0);
    }
    DMatrix::from_columns(&basis)
}

/// The part of `v` orthogonal to the orthonormal `basis` (two passes of Gram-Schmidt).
fn orthogonal_part(
    basis: &[nalgebra::DVector<f64>],
    v: &nalgebra::DVector<f64>,
) -> Option<nalgebra::DVector<f64>> {
    let mut w = v.clone();
    for _ in 0..2 {
        for b in basis {
            let d = b.dot(&w);
            w.axpy(-d, b, 1.0);
        }
    }
    w.iter().all(|x| x.is_finite()).then_some(w)
}

/// What the readings determine of `params` (the first columns of the weighted Jacobian `j`, the
/// instruments' after them), for data sets of `devices`.
pub fn analyse(j: &DMatrix<f64>, params: &[Param], devices: &[Device]) -> Identifiability {
    let n = params.len();
    let (a, norms) = projected_columns(j, n);
    let largest = norms.iter().cloned().fold(0.0, f64::max);
    let singular_values = {
        let mut s: Vec<f64> = if a.ncols() > 0 && a.nrows() > 0 {
            a.clone()
                .svd(false, false)
                .singular_values
                .iter()
                .copied()
                .collect()
        } else {
            Vec::new()
        };
        s.sort_by(|x, y| y.total_cmp(x));
        s
    };
    let rank = singular_values.iter().filter(|&&s| s > RANK_TOL).count();
    let index = |p: Param| params.iter().position(|&q| q == p);
    let mut held: Vec<Held> = Vec::new();
    // Parameters the readings do not depend on at all.
    for (c, &p) in params.iter().enumerate() {
        if norms[c] <= ABSENT_TOL * largest {
            held.push(Held {
                param: p,
                combination: vec![(p, 1.0)],
                why: format!("{} does not enter these readings", p.key()),
            });
        }
    }
    // The structural combinations, each when it is a null direction independent of those
    // already found, its parameter not yet held.
    let mut found: Vec<nalgebra::DVector<f64>> = Vec::new();
    for pattern in PATTERNS {
        if held.iter().any(|h| h.param == pattern.holds) {
            continue;
        }
        let Some(cols) = pattern
            .moves
            .iter()
            .map(|&(p, k)| index(p).map(|c| (c, k)))
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        // The direction in normalised coordinates: u_c = norm_c * (stored move of c).
        let mut u = nalgebra::DVector::zeros(n);
        for &(c, k) in &cols {
            u[c] = norms[c] * params[c].stored(k);
        }
        if u.norm() == 0.0 {
            continue;
        }
        let residual = (&a * &u).norm() / u.norm();
        if residual > PATTERN_TOL {
            continue;
        }
        let independent = orthogonal_part(&found, &u).is_some_and(|w| w.norm() > 1e-6 * u.norm());
        if !independent {
            continue;
        }
        found.push(u.normalize());
        held.push(Held {
            param: pattern.holds,
            combination: pattern.moves.to_vec(),
            why: (pattern.why)(devices).to_string(),
        });
    }
    // The others, by Gram-Schmidt in preference order: a column within the span of those kept
    // is held, its dependence written out.
    let mut order: Vec<usize> = (0..n)
        .filter(|&c| !held.iter().any(|h| h.param == params[c]))
        .collect();
    order.sort_by_key(|&c| params[c].preference());
    let mut basis: Vec<nalgebra::DVector<f64>> = Vec::new();
    let mut kept: Vec<usize> = Vec::new();
    for c in order {
        let col = a.column(c).into_owned();
        let w = orthogonal_part(&basis, &col).unwrap_or_else(|| col.clone());
        if w.norm() > RANK_TOL {
            basis.push(w.normalize());
            kept.push(c);
            continue;
        }
        // Its column as a combination of those kept (least squares), as a null direction in
        // the parameters' own units.
        let combination = if kept.is_empty() {
            vec![(params[c], 1.0)]
        } else {
            let k = DMatrix::from_columns(
                &kept
                    .iter()
                    .map(|&i| a.column(i).into_owned())
                    .collect::<Vec<_>>(),
            );
            let beta = k
                .clone()
                .svd(true, true)
                .solve(&col, 1e-12)
                .unwrap_or_else(|_| nalgebra::DVector::zeros(kept.len()));
            let mut comb = vec![(params[c], 1.0)];
            for (i, &kc) in kept.iter().enumerate() {
                // c moved by one unit (as written) is undone by kc moved by -beta_i in the
                // normalised coordinates, scaled to the same move of c.
                let stored =
                    -beta[i] * params[c].stored(1.0) * norms[c] / norms[kc].max(f64::MIN_POSITIVE);
                let shown = params[kc].shown(stored);
                if shown.abs() > 1e-6 {
                    comb.push((params[kc], shown));
                }
            }
            comb
        };
        let others: Vec<String> = combination[1..]
            .iter()
            .map(|(p, k)| format!("{} by {:+.4} {}", p.key(), k, p.unit()))
            .collect();
        let why = if others.is_empty() {
            format!(
                "the instrument's parameters absorb {} entirely",
                params[c].key()
            )
        } else {
            format!(
                "moving {} by +1 {} and {} changes no reading",
                params[c].key(),
                params[c].unit(),
                others.join(", ")
            )
        };
        held.push(Held {
            param: params[c],
            combination,
            why,
        });
    }
    let identified = params
        .iter()
        .copied()
        .filter(|p| !held.iter().any(|h| h.param == *p))
        .collect();
    Identifiability {
        singular_values,
        rank,
        identified,
        held,
    }
}
