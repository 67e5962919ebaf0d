//! The thresholds of `verne verify`'s checks: their names (as in a machine file's `[verify]`
//! table), defaults, units and meanings, and the values of one run.

use crate::error::{MachineError, Problem, shown};
use crate::spec::Machine;

/// One threshold: name (as in `[verify]` and `--threshold`), default, unit, meaning.
#[derive(Debug, Clone, Copy)]
pub struct ThresholdSpec {
    pub name: &'static str,
    pub default: f64,
    pub unit: &'static str,
    pub meaning: &'static str,
}

/// Index of a threshold in [`THRESHOLDS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Th {
    TipErrorMm,
    AxisErrorDeg,
    ChordErrorMm,
    LambdaMin,
    LambdaMax,
    ParallelMarginMin,
    RhoStepMm,
    Theta1StepDeg,
    Theta2StepDeg,
    Theta2FlipTolDeg,
    RhoVelocityMmS,
    Theta1VelocityDegS,
    Theta2VelocityDegS,
    RhoAccelMmS2,
    Theta1AccelDegS2,
    Theta2AccelDegS2,
    ChordAxisErrorDeg,
}

/// Every threshold with its default. The velocity and acceleration limits are assumptions (the
/// VERNE's drive data are not published): set them from the machine's data sheet.
pub const THRESHOLDS: [ThresholdSpec; 17] = [
    ThresholdSpec {
        name: "tip_error_mm",
        default: 0.005,
        unit: "mm",
        meaning: "tip of fk(joints) vs the intended tip",
    },
    ThresholdSpec {
        name: "axis_error_deg",
        default: 0.005,
        unit: "deg",
        meaning: "axis of fk(joints) vs the intended axis",
    },
    ThresholdSpec {
        name: "chord_error_mm",
        default: 0.01,
        unit: "mm",
        meaning: "tip at the joints' midpoint vs the intended midpoint",
    },
    ThresholdSpec {
        name: "lambda_min",
        default: 1.0 / 3.0,
        unit: "",
        meaning: "smallest velocity amplification factor",
    },
    ThresholdSpec {
        name: "lambda_max",
        default: 3.0,
        unit: "",
        meaning: "largest velocity amplification factor",
    },
    ThresholdSpec {
        name: "parallel_margin_min",
        default: 0.05,
        unit: "",
        meaning: "smallest inverse condition number of A",
    },
    ThresholdSpec {
        name: "rho_step_mm",
        default: 20.0,
        unit: "mm",
        meaning: "largest slider change between rows",
    },
    ThresholdSpec {
        name: "theta1_step_deg",
        default: 5.0,
        unit: "deg",
        meaning: "largest tilting-axis change between rows",
    },
    ThresholdSpec {
        name: "theta2_step_deg",
        default: 30.0,
        unit: "deg",
        meaning: "largest rotary-axis change between rows",
    },
    ThresholdSpec {
        name: "theta2_flip_tol_deg",
        default: 20.0,
        unit: "deg",
        meaning: "theta2 change this close to 180 deg: a flip",
    },
    ThresholdSpec {
        name: "rho_velocity_mm_s",
        default: 500.0,
        unit: "mm/s",
        meaning: "slider speed (needs a t or feed column)",
    },
    ThresholdSpec {
        name: "theta1_velocity_deg_s",
        default: 90.0,
        unit: "deg/s",
        meaning: "tilting-axis speed",
    },
    ThresholdSpec {
        name: "theta2_velocity_deg_s",
        default: 180.0,
        unit: "deg/s",
        meaning: "rotary-axis speed",
    },
    ThresholdSpec {
        name: "rho_accel_mm_s2",
        default: 5000.0,
        unit: "mm/s^2",
        meaning: "slider acceleration",
    },
    ThresholdSpec {
        name: "theta1_accel_deg_s2",
        default: 900.0,
        unit: "deg/s^2",
        meaning: "tilting-axis acceleration",
    },
    ThresholdSpec {
        name: "theta2_accel_deg_s2",
        default: 1800.0,
        unit: "deg/s^2",
        meaning: "rotary-axis acceleration",
    },
    ThresholdSpec {
        name: "chord_axis_error_deg",
        default: 0.01,
        unit: "deg",
        meaning: "tool axis along a block vs the intended axis there",
    },
];

/// The thresholds of one run, in the units of [`THRESHOLDS`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds([f64; 17]);

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds(std::array::from_fn(|i| THRESHOLDS[i].default))
    }
}

/// Index of a threshold by name.
pub fn threshold_index(name: &str) -> Option<usize> {
    THRESHOLDS.iter().position(|t| t.name == name)
}

/// Checks one threshold value on its own; the message says what was expected.
pub fn check_threshold_value(name: &str, value: f64) -> Result<(), String> {
    let Some(i) = threshold_index(name) else {
        let names: Vec<&str> = THRESHOLDS.iter().map(|t| t.name).collect();
        return Err(format!(
            "unknown threshold `{}`; known: {}",
            shown(name.as_bytes()),
            names.join(", ")
        ));
    };
    let ok = value.is_finite()
        && match i {
            i if i == Th::ParallelMarginMin as usize => (0.0..1.0).contains(&value),
            i if i == Th::Theta2FlipTolDeg as usize => value > 0.0 && value < 90.0,
            _ => value > 0.0,
        };
    if ok {
        Ok(())
    } else if i == Th::ParallelMarginMin as usize {
        Err(format!("{name} must be in [0, 1), found {value}"))
    } else if i == Th::Theta2FlipTolDeg as usize {
        Err(format!("{name} must be in (0, 90) degrees, found {value}"))
    } else {
        Err(format!("{name} must be a positive number, found {value}"))
    }
}

impl Thresholds {
    pub fn get(&self, t: Th) -> f64 {
        self.0[t as usize]
    }

    /// Sets a threshold by name, checking the value (not the cross-checks, see [`Self::check`]).
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), String> {
        check_threshold_value(name, value)?;
        if let Some(i) = threshold_index(name) {
            self.0[i] = value;
        }
        Ok(())
    }

    /// Cross-checks between thresholds.
    pub fn check(&self) -> Result<(), String> {
        let (lo, hi) = (self.get(Th::LambdaMin), self.get(Th::LambdaMax));
        if lo >= hi {
            return Err(format!("lambda_min ({lo}) must be below lambda_max ({hi})"));
        }
        Ok(())
    }

    /// The defaults, the joints' speeds and accelerations from the machine file's `[drives]`
    /// table, overridden by its `[verify]` table. Unknown names and bad values are reported all
    /// at once, each with its line.
    pub fn from_machine(m: &Machine, source: &str) -> Result<Thresholds, MachineError> {
        let mut t = Thresholds::default();
        let d = &m.drives;
        t.0[Th::RhoVelocityMmS as usize] = d.velocity[0];
        t.0[Th::Theta1VelocityDegS as usize] = d.velocity[3].to_degrees();
        t.0[Th::Theta2VelocityDegS as usize] = d.velocity[4].to_degrees();
        t.0[Th::RhoAccelMmS2 as usize] = d.acceleration[0];
        t.0[Th::Theta1AccelDegS2 as usize] = d.acceleration[3].to_degrees();
        t.0[Th::Theta2AccelDegS2 as usize] = d.acceleration[4].to_degrees();
        let mut problems = Vec::new();
        for (name, value, line) in &m.verify {
            if let Err(message) = t.set(name, *value) {
                problems.push(Problem {
                    line: *line,
                    key: format!("verify.{name}"),
                    message,
                });
            }
        }
        if problems.is_empty()
            && let Err(message) = t.check()
        {
            problems.push(Problem {
                line: None,
                key: "verify".into(),
                message,
            });
        }
        if problems.is_empty() {
            Ok(t)
        } else {
            Err(MachineError {
                source: source.to_string(),
                problems,
            })
        }
    }

    /// Per-joint limits (rho1, rho2, rho3 in mm..., theta1, theta2 in rad...) of a kind.
    pub(super) fn per_joint(&self, rho: Th, t1: Th, t2: Th) -> [f64; 5] {
        let r = self.get(rho);
        [
            r,
            r,
            r,
            self.get(t1).to_radians(),
            self.get(t2).to_radians(),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_parse_and_validate() {
        let mut t = Thresholds::default();
        assert_eq!(t.get(Th::TipErrorMm), 0.005);
        assert!(t.set("tip_error_mm", 0.01).is_ok());
        assert_eq!(t.get(Th::TipErrorMm), 0.01);
        assert!(t.set("tip_eror_mm", 1.0).unwrap_err().contains("unknown"));
        assert!(t.set("chord_error_mm", -1.0).is_err());
        assert!(t.set("parallel_margin_min", 0.0).is_ok());
        assert!(t.set("theta2_flip_tol_deg", 95.0).is_err());
        t.set("lambda_min", 4.0).unwrap();
        assert!(t.check().is_err());
        assert_eq!(THRESHOLDS.len(), Th::ChordAxisErrorDeg as usize + 1);
    }
}
