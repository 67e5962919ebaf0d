//! The machine's parameters a calibration can identify: the module's dimensions of eqs.
//! (3)-(6), IFToMM 2007, the joints' zero offsets, the tool length of eq. (8) and the table of
//! eq. (7), AIM 2007, each named by its machine-file key, with its unit and its prior bound.

use crate::spec::Machine;

/// One parameter of the machine file a calibration can identify.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Param {
    D1,
    LowerD1,
    R1,
    LowerR1,
    L1,
    D2,
    LowerD2,
    R2,
    R4,
    L2,
    L3,
    Rho1Zero,
    Rho2Zero,
    Rho3Zero,
    ToolLength,
    TableDa,
    TableDt,
    TableYt,
    Theta1Zero,
    Theta2Zero,
}

/// Every parameter, in the order of the machine file.
pub const ALL: [Param; 20] = [
    Param::D1,
    Param::LowerD1,
    Param::R1,
    Param::LowerR1,
    Param::L1,
    Param::D2,
    Param::LowerD2,
    Param::R2,
    Param::R4,
    Param::L2,
    Param::L3,
    Param::Rho1Zero,
    Param::Rho2Zero,
    Param::Rho3Zero,
    Param::ToolLength,
    Param::TableDa,
    Param::TableDt,
    Param::TableYt,
    Param::Theta1Zero,
    Param::Theta2Zero,
];

/// The prior bound of a length or offset (mm): a calibrated value farther than this from the
/// nominal is refused unless the user allows it (a machine differs from its drawing by tenths of
/// a millimetre; a move of centimetres is the fit absorbing something else).
pub const PRIOR_BOUND_MM: f64 = 5.0;

/// The prior bound of an angle (degrees), as [`PRIOR_BOUND_MM`].
pub const PRIOR_BOUND_DEG: f64 = 1.0;

impl Param {
    /// The machine-file key (`module.R1`).
    pub fn key(self) -> &'static str {
        match self {
            Param::D1 => "module.D1",
            Param::LowerD1 => "module.d1",
            Param::R1 => "module.R1",
            Param::LowerR1 => "module.r1",
            Param::L1 => "module.L1",
            Param::D2 => "module.D2",
            Param::LowerD2 => "module.d2",
            Param::R2 => "module.R2",
            Param::R4 => "module.r4",
            Param::L2 => "module.L2",
            Param::L3 => "module.L3",
            Param::Rho1Zero => "zeros.rho1",
            Param::Rho2Zero => "zeros.rho2",
            Param::Rho3Zero => "zeros.rho3",
            Param::ToolLength => "tool.length",
            Param::TableDa => "table.d_a",
            Param::TableDt => "table.d_t",
            Param::TableYt => "table.y_t",
            Param::Theta1Zero => "zeros.theta1",
            Param::Theta2Zero => "zeros.theta2",
        }
    }

    /// The parameter of a machine-file key.
    pub fn from_key(key: &str) -> Option<Param> {
        ALL.into_iter().find(|p| p.key() == key)
    }

    /// An angle (stored in rad, written in degrees) rather than a length (mm).
    pub fn is_angle(self) -> bool {
        matches!(self, Param::Theta1Zero | Param::Theta2Zero)
    }

    /// The unit it is written in.
    pub fn unit(self) -> &'static str {
        if self.is_angle() { "deg" } else { "mm" }
    }

    /// A value in the unit it is written in, from the stored one (rad for angles).
    pub fn shown(self, value: f64) -> f64 {
        if self.is_angle() {
            value.to_degrees()
        } else {
            value
        }
    }

    /// The stored value (rad for angles) of a value in the unit it is written in.
    pub fn stored(self, shown: f64) -> f64 {
        if self.is_angle() {
            shown.to_radians()
        } else {
            shown
        }
    }

    /// The default prior bound, stored units.
    pub fn default_prior(self) -> f64 {
        if self.is_angle() {
            PRIOR_BOUND_DEG.to_radians()
        } else {
            PRIOR_BOUND_MM
        }
    }

    /// The value of the parameter in the machine (stored units: mm, rad).
    pub fn value(self, m: &Machine) -> f64 {
        let g = &m.module;
        match self {
            Param::D1 => g.dx1 + g.d1,
            Param::LowerD1 => g.d1,
            Param::R1 => g.r_big1,
            Param::LowerR1 => g.r_small1,
            Param::L1 => g.l1,
            Param::D2 => g.dx2 + g.d2,
            Param::LowerD2 => g.d2,
            Param::R2 => g.r_big2,
            Param::R4 => g.r4,
            Param::L2 => g.l2,
            Param::L3 => g.l3,
            Param::Rho1Zero => g.rho_zero[0],
            Param::Rho2Zero => g.rho_zero[1],
            Param::Rho3Zero => g.rho_zero[2],
            Param::ToolLength => m.tool_length,
            Param::TableDa => m.table.d_a,
            Param::TableDt => m.table.d_t,
            Param::TableYt => m.table.y_t,
            Param::Theta1Zero => m.table.theta_zero[0],
            Param::Theta2Zero => m.table.theta_zero[1],
        }
    }

    /// Moves the parameter of `m` by `delta` (stored units): D1 and d1 move D1 - d1, the one
    /// quantity of eqs. (3)-(4) (and D2, d2 that of eqs. (5)-(6)).
    pub fn add_to(self, m: &mut Machine, delta: f64) {
        let g = &mut m.module;
        match self {
            Param::D1 => g.dx1 += delta,
            Param::LowerD1 => {
                g.dx1 -= delta;
                g.d1 += delta;
            }
            Param::R1 => g.r_big1 += delta,
            Param::LowerR1 => g.r_small1 += delta,
            Param::L1 => g.l1 += delta,
            Param::D2 => g.dx2 += delta,
            Param::LowerD2 => {
                g.dx2 -= delta;
                g.d2 += delta;
            }
            Param::R2 => g.r_big2 += delta,
            Param::R4 => g.r4 += delta,
            Param::L2 => g.l2 += delta,
            Param::L3 => g.l3 += delta,
            Param::Rho1Zero => g.rho_zero[0] += delta,
            Param::Rho2Zero => g.rho_zero[1] += delta,
            Param::Rho3Zero => g.rho_zero[2] += delta,
            Param::ToolLength => m.tool_length += delta,
            Param::TableDa => m.table.d_a += delta,
            Param::TableDt => m.table.d_t += delta,
            Param::TableYt => m.table.y_t += delta,
            Param::Theta1Zero => m.table.theta_zero[0] += delta,
            Param::Theta2Zero => m.table.theta_zero[1] += delta,
        }
    }

    /// The order in which parameters are kept when the data cannot tell some apart: of a set
    /// of parameters that only move together, the last in this order is held at its nominal
    /// value (d1 and d2, which the papers set to 0 since only D - d enters, come last).
    pub fn preference(self) -> usize {
        const ORDER: [Param; 20] = [
            Param::L1,
            Param::L2,
            Param::L3,
            Param::R1,
            Param::LowerR1,
            Param::R2,
            Param::R4,
            Param::D1,
            Param::D2,
            Param::ToolLength,
            Param::Rho1Zero,
            Param::Rho2Zero,
            Param::Rho3Zero,
            Param::TableDa,
            Param::TableYt,
            Param::TableDt,
            Param::Theta1Zero,
            Param::Theta2Zero,
            Param::LowerD1,
            Param::LowerD2,
        ];
        ORDER.iter().position(|&p| p == self).unwrap_or(ORDER.len())
    }
}

/// `m` with each parameter moved by its `delta` (stored units).
pub fn moved(m: &Machine, params: &[Param], delta: &[f64]) -> Machine {
    let mut out = m.clone();
    for (p, d) in params.iter().zip(delta) {
        p.add_to(&mut out, *d);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each parameter's value moves by what is added to it, and no other parameter's does
    /// (d1 moves D1 - d1 and d1, leaving D1 as the file writes it).
    #[test]
    fn each_parameter_moves_alone() {
        let m = Machine::default_verne();
        for p in ALL {
            let n = moved(&m, &[p], &[0.25]);
            for q in ALL {
                let want = if q == p { 0.25 } else { 0.0 };
                let got = q.value(&n) - q.value(&m);
                assert!((got - want).abs() < 1e-12, "{p:?} moved {q:?} by {got}");
            }
            assert_eq!(Param::from_key(p.key()), Some(p));
        }
        // Written and read back through the machine file.
        let n = moved(&m, &ALL, &[0.125; 20]);
        let again = Machine::from_toml_str(&n.to_toml(), "moved").unwrap();
        for q in ALL {
            assert!((q.value(&again) - q.value(&n)).abs() < 1e-12, "{q:?}");
        }
    }
}
