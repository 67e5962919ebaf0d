//! Branch labels and feasibility: the configuration indices s1, s2, s3 of IFToMM 2007 eqs.
//! (11)-(13), and the verdict that picks the machine's own ("working") branch (section V).

use std::fmt;

use crate::machine::Machine;
use crate::module_geometry::{ModulePose, Sliders, rod_vectors};
use crate::tolerance::{CONFIG_SIGN_MM, LIMIT_SLACK};

/// Configuration indices (s1, s2, s3), each -1 or +1: the signs of rho1 - zp,
/// rho2 - zp + R2 sin(alpha) and rho3 - zp - R2 sin(alpha). With z pointing down, -1 means the
/// slider attachment is above the platform attachment, as on the machine.
pub type Config = [i8; 3];

/// The machine's configuration.
pub const WORKING_CONFIG: Config = [-1, -1, -1];

pub fn config_of(g: &crate::machine::ModuleGeometry, pose: &ModulePose, rho: &Sliders) -> Config {
    let s = pose.alpha.sin() * g.r_big2;
    let sign = |q: f64| if q > CONFIG_SIGN_MM { 1 } else { -1 };
    [
        sign(rho.x - pose.p.z),
        sign(rho.y - pose.p.z + s),
        sign(rho.z - pose.p.z - s),
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
}

impl Reason {
    pub const ALL: [Reason; 9] = [
        Reason::Leg1Inverted,
        Reason::Leg2Inverted,
        Reason::Leg3Inverted,
        Reason::RodsCross,
        Reason::Rho1Stroke,
        Reason::Rho2Stroke,
        Reason::Rho3Stroke,
        Reason::RodTilt,
        Reason::Theta1Range,
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

/// The verdict of a parallel-module branch: configuration, rod crossing (section V), slider
/// strokes and rod tilts from the machine file.
pub fn module_verdict(m: &Machine, pose: &ModulePose, rho: &Sliders, config: Config) -> Verdict {
    let g = &m.module;
    let mut v = Verdict::default();
    let inverted = [
        Reason::Leg1Inverted,
        Reason::Leg2Inverted,
        Reason::Leg3Inverted,
    ];
    let stroke = [Reason::Rho1Stroke, Reason::Rho2Stroke, Reason::Rho3Stroke];
    for i in 0..3 {
        if config[i] != -1 {
            v.add(inverted[i]);
        }
        if rho[i] < m.limits.rho_min[i] - LIMIT_SLACK || rho[i] > m.limits.rho_max[i] + LIMIT_SLACK
        {
            v.add(stroke[i]);
        }
    }
    if g.r_big1 * pose.alpha.cos() <= g.r_small1 {
        v.add(Reason::RodsCross);
    }
    // tilt = acos(v_z / |v|) > tilt_max  <=>  v_z < cos(tilt_max) |v| (no acos per rod).
    let cos_max = (m.limits.rod_tilt_max + LIMIT_SLACK).cos();
    if rod_vectors(g, pose, rho)
        .iter()
        .any(|r| r.z < cos_max * r.norm())
    {
        v.add(Reason::RodTilt);
    }
    v
}
