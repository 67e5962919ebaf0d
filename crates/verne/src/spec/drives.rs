//! The `[drives]` table of a machine file: the largest speed and acceleration of each joint and
//! the rapid rate. One place for them: `verne ik --format gcode` times its programs within them
//! and `verne verify` checks against them (unless its `[verify]` table or `--threshold` says
//! otherwise). The VERNE's drive data are not published: the defaults are assumptions, to be set
//! from the machine's data sheet.

use crate::error::Problem;

/// One key of the table: name, default, unit, meaning, and whether it is an angle (degrees in the
/// file, radians in [`Drives`]).
struct DriveKey {
    name: &'static str,
    default: f64,
    meaning: &'static str,
}

/// The keys, in the order of [`Drives::velocity`] / [`Drives::acceleration`] (rho, theta1,
/// theta2 for each), then the rapid rate.
const KEYS: [DriveKey; 7] = [
    DriveKey {
        name: "rho_velocity_mm_s",
        default: 500.0,
        meaning: "largest slider speed (mm/s)",
    },
    DriveKey {
        name: "theta1_velocity_deg_s",
        default: 90.0,
        meaning: "largest tilting-axis speed (deg/s)",
    },
    DriveKey {
        name: "theta2_velocity_deg_s",
        default: 180.0,
        meaning: "largest rotary-axis speed (deg/s)",
    },
    DriveKey {
        name: "rho_accel_mm_s2",
        default: 5000.0,
        meaning: "largest slider acceleration (mm/s^2)",
    },
    DriveKey {
        name: "theta1_accel_deg_s2",
        default: 900.0,
        meaning: "largest tilting-axis acceleration (deg/s^2)",
    },
    DriveKey {
        name: "theta2_accel_deg_s2",
        default: 1800.0,
        meaning: "largest rotary-axis acceleration (deg/s^2)",
    },
    DriveKey {
        name: "rapid_mm_min",
        default: 15000.0,
        meaning: "rapid rate of the tool tip (mm/min)",
    },
];

/// The drives' limits, per joint rho1, rho2, rho3, theta1, theta2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drives {
    /// Largest speed of each joint (mm/s for the sliders, rad/s for the table).
    pub velocity: [f64; 5],
    /// Largest acceleration of each joint (mm/s^2, rad/s^2).
    pub acceleration: [f64; 5],
    /// The rate of rapid moves of the tool tip (mm/min).
    pub rapid_mm_min: f64,
}

impl Drives {
    /// The table from its keys' values in file units (degrees), in the order of [`KEYS`].
    fn from_values(v: [f64; 7]) -> Drives {
        Drives {
            velocity: [v[0], v[0], v[0], v[1].to_radians(), v[2].to_radians()],
            acceleration: [v[3], v[3], v[3], v[4].to_radians(), v[5].to_radians()],
            rapid_mm_min: v[6],
        }
    }

    /// The values in file units, in the order of [`KEYS`].
    fn values(&self) -> [f64; 7] {
        [
            self.velocity[0],
            self.velocity[3].to_degrees(),
            self.velocity[4].to_degrees(),
            self.acceleration[0],
            self.acceleration[3].to_degrees(),
            self.acceleration[4].to_degrees(),
            self.rapid_mm_min,
        ]
    }

    /// The table's entries (key after `drives.`, value, line), each a positive finite number;
    /// keys not given keep their default. Problems are added to `problems`.
    pub(crate) fn from_entries(
        entries: &[(String, f64, Option<usize>)],
        problems: &mut Vec<Problem>,
    ) -> Drives {
        let mut v: [f64; 7] = std::array::from_fn(|k| KEYS[k].default);
        for (key, value, line) in entries {
            let Some(k) = KEYS.iter().position(|d| d.name == key) else {
                let known: Vec<&str> = KEYS.iter().map(|d| d.name).collect();
                problems.push(Problem {
                    line: *line,
                    key: format!("drives.{key}"),
                    message: format!("unknown key; known keys: {}", known.join(", ")),
                });
                continue;
            };
            if !(value.is_finite() && *value > 0.0) {
                problems.push(Problem {
                    line: *line,
                    key: format!("drives.{key}"),
                    message: format!(
                        "must be a positive number ({}), found {value}",
                        KEYS[k].meaning
                    ),
                });
                continue;
            }
            v[k] = *value;
        }
        Drives::from_values(v)
    }

    /// The table as TOML, every key.
    pub fn to_toml(&self) -> String {
        let mut s = String::from("[drives]\n");
        for (d, v) in KEYS.iter().zip(self.values()) {
            s.push_str(&format!("{} = {v}\n", d.name));
        }
        s
    }
}

impl Default for Drives {
    /// The assumed limits of the default machine.
    fn default() -> Drives {
        Drives::from_values(std::array::from_fn(|k| KEYS[k].default))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip_and_bad_values_are_refused_with_their_line() {
        let mut problems = Vec::new();
        let d = Drives::from_entries(
            &[
                ("theta2_velocity_deg_s".into(), 90.0, Some(3)),
                ("rapid_mm_min".into(), 0.0, Some(4)),
                ("rho_speed".into(), 1.0, Some(5)),
            ],
            &mut problems,
        );
        assert!((d.velocity[4] - 90f64.to_radians()).abs() < 1e-15);
        assert_eq!(d.rapid_mm_min, Drives::default().rapid_mm_min);
        assert_eq!(problems.len(), 2);
        assert_eq!(problems[0].line, Some(4));
        assert_eq!(problems[1].line, Some(5));
        let back = Drives::from_values(d.values());
        for k in 0..5 {
            assert!((back.velocity[k] - d.velocity[k]).abs() < 1e-12);
            assert!((back.acceleration[k] - d.acceleration[k]).abs() < 1e-12);
        }
    }
}
