//! Whether a solution of a glider is a pose of the machine: the machine works in working mode
//! `++` and assembly mode `+` (the paper's figures, section 3.2, Wenger 2001); a solution is `ok`
//! when it is in both, inside the joint ranges and not singular ([`verdict`]). Otherwise its
//! [`Verdict`] lists why, as reason codes (docs/gliders.md).

use std::sync::OnceLock;

use nalgebra::{Point2, Vector2};

use super::jacobian::{is_parallel_singular, is_serial_singular};
use super::kinematics::{Branch, WorkingMode};
use super::spec::GliderSpec;
use super::tolerance::{COINCIDENT_REL, JOINT_LIMIT_REL};

/// The working mode of the machine (paper's figures, docs/gliders.md).
pub const WORKING_MODE: WorkingMode = WorkingMode::new(Branch::Plus, Branch::Plus);

/// The assembly mode of the machine.
pub const WORKING_ASSEMBLY: Branch = Branch::Plus;

/// Why a solution is not a pose of the machine: a set of reasons, empty when it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Verdict(u8);

// Reason codes of a solution, in the order they are written.
const OTHER_WORKING_MODE: u8 = 1 << 0;
const OTHER_ASSEMBLY: u8 = 1 << 1;
const RHO1_RANGE: u8 = 1 << 2;
const RHO2_RANGE: u8 = 1 << 3;
const STRUCTURAL: u8 = 1 << 4;
const PARALLEL: u8 = 1 << 5;
const SERIAL: u8 = 1 << 6;
const CODES: [&str; 7] = [
    "other_working_mode",
    "other_assembly",
    "rho1_range",
    "rho2_range",
    "structural_singularity",
    "parallel_singularity",
    "serial_singularity",
];

impl Verdict {
    /// True when the solution is a pose of the machine (no reason).
    pub fn ok(self) -> bool {
        self.0 == 0
    }

    /// `ok`, or the reasons' codes joined by `;`, in a fixed order.
    pub fn as_str(self) -> &'static str {
        static TEXT: OnceLock<Vec<String>> = OnceLock::new();
        let text = TEXT.get_or_init(|| {
            (0..1u16 << CODES.len())
                .map(|b| {
                    if b == 0 {
                        return "ok".to_string();
                    }
                    let set: Vec<&str> = CODES
                        .iter()
                        .enumerate()
                        .filter(|(k, _)| b & (1 << k) != 0)
                        .map(|(_, c)| *c)
                        .collect();
                    set.join(";")
                })
                .collect()
        });
        &text[self.0 as usize]
    }
}

/// `++`, `+-`, ... as a static string.
pub fn mode_label(m: WorkingMode) -> &'static str {
    const LABELS: [&str; 9] = ["++", "+-", "+0", "-+", "--", "-0", "0+", "0-", "00"];
    let k = |b: Branch| match b {
        Branch::Plus => 0,
        Branch::Minus => 1,
        Branch::Double => 2,
    };
    LABELS[3 * k(m.strut1) + k(m.strut2)]
}

/// `+`, `-`, or `0` for a double root.
pub fn branch_label(b: Branch) -> &'static str {
    match b {
        Branch::Plus => "+",
        Branch::Minus => "-",
        Branch::Double => "0",
    }
}

/// C = D with l1 = l2: the structural singularity of section 2.4 (Fig. 5), Wenger 2001.
pub fn is_structural(spec: &GliderSpec, rho: Vector2<f64>) -> bool {
    let (c, d) = spec.sliders(rho);
    (c - d).norm() <= COINCIDENT_REL * spec.l1
        && (spec.l1 - spec.l2).abs() <= COINCIDENT_REL * spec.l1
}

/// Why the pose (P, rho) of the given modes is not a pose of the machine (ok: it is).
pub fn verdict(
    spec: &GliderSpec,
    p: Point2<f64>,
    rho: Vector2<f64>,
    mode: WorkingMode,
    assembly: Branch,
) -> Verdict {
    let mut bits = 0;
    // A double root (`0`) is the limit of both signs: flagged as a singularity, not a mode.
    if mode.strut1 == Branch::Minus || mode.strut2 == Branch::Minus {
        bits |= OTHER_WORKING_MODE;
    }
    if assembly == Branch::Minus {
        bits |= OTHER_ASSEMBLY;
    }
    let slack = JOINT_LIMIT_REL * spec.l1;
    let outside = |v: f64, [lo, hi]: [f64; 2]| v < lo - slack || v > hi + slack;
    if outside(rho.x, spec.rho1_range) {
        bits |= RHO1_RANGE;
    }
    if outside(rho.y, spec.rho2_range) {
        bits |= RHO2_RANGE;
    }
    if is_structural(spec, rho) {
        bits |= STRUCTURAL;
    } else if is_parallel_singular(spec, p, rho) {
        bits |= PARALLEL;
    }
    if is_serial_singular(spec, p, rho) {
        bits |= SERIAL;
    }
    Verdict(bits)
}

/// Whether a solution's label is the machine's, a double root counting as either sign.
pub fn compatible(b: Branch, working: Branch) -> bool {
    b == working || b == Branch::Double
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_codes_join_in_order() {
        assert_eq!(Verdict(0).as_str(), "ok");
        assert_eq!(
            Verdict(RHO2_RANGE | OTHER_ASSEMBLY).as_str(),
            "other_assembly;rho2_range"
        );
        assert_eq!(mode_label(WORKING_MODE), "++");
        assert_eq!(
            mode_label(WorkingMode::new(Branch::Double, Branch::Minus)),
            "0-"
        );
    }
}
