//! Machine parameters: the geometry, limits and tool of a VERNE-type machine ([`Machine`]) and
//! its machine file (TOML or two-column CSV, [`file`]: schema, reading and validation).

pub mod drives;
mod file;
pub mod gcode;

pub use file::{BaseResolver, MAX_BASE_DEPTH, MAX_LENGTH_MM};

use crate::parallel_module::equations::Sliders;

/// The embedded default machine (data/verne.toml).
pub const DEFAULT_MACHINE_TOML: &str = include_str!("../../data/verne.toml");

/// Geometry of the parallel module, IFToMM 2007 Fig. 4 and eqs. (3)-(6) (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModuleGeometry {
    /// D1 - d1: x offset of leg I in eqs. (3)-(4).
    pub dx1: f64,
    /// D2 - d2: x offset of legs II and III in eqs. (5)-(6).
    pub dx2: f64,
    pub r_big1: f64,
    pub r_small1: f64,
    pub l1: f64,
    pub r_big2: f64,
    pub r4: f64,
    pub l2: f64,
    pub l3: f64,
    /// d1 and d2 as the machine file gives them (mm): only D1 - d1 and D2 - d2 enter the
    /// equations, so these only say how a file splits them (a calibrated file keeps them).
    pub d1: f64,
    pub d2: f64,
    /// The sliders' zero offsets (mm): the equations' rho_i is the joint's rho_i plus this
    /// (`[zeros]` of the machine file, 0 by default). Applied where a slider enters the
    /// constraint equations (3)-(6) ([`crate::parallel_module::equations::rod_vectors`]);
    /// the solvers run on [`Machine::model`], where it is zero.
    pub rho_zero: [f64; 3],
}

/// Joint and passive-joint limits (mm and rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    pub rho_min: [f64; 3],
    pub rho_max: [f64; 3],
    /// Largest angle between a rod and the vertical slider axis (rad).
    pub rod_tilt_max: f64,
    /// cos(rod_tilt_max + LIMIT_SLACK), derived from it when the machine is read: the rod-tilt
    /// test compares cosines ([`crate::parallel_module::branches::leg_state`]).
    pub cos_rod_tilt_max: f64,
    pub theta1_min: f64,
    pub theta1_max: f64,
}

/// Tilting table of AIM 2007 eq. (7) (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableGeometry {
    pub d_a: f64,
    pub d_t: f64,
    /// The rotary axis's offset from the tilting axis along y of the tilted frame (mm, 0 by
    /// default): eq. (7) with trans(y, y_t) next to trans(z, d_t).
    pub y_t: f64,
    /// The table axes' zero offsets (rad): the equations' theta1, theta2 are the joints' plus
    /// these (`[zeros]` of the machine file, 0 by default), applied where the angles enter
    /// eq. (7) ([`crate::machine::table_transform`], [`crate::machine::tool_pose_eq26`]).
    pub theta_zero: [f64; 2],
}

/// A validated VERNE-type machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    pub name: String,
    pub module: ModuleGeometry,
    pub limits: Limits,
    pub table: TableGeometry,
    /// Tool length Delta (mm), AIM 2007 eq. (8).
    pub tool_length: f64,
    /// The `[drives]` table (optional, with assumed defaults): each joint's largest speed and
    /// acceleration, and the rapid rate.
    pub drives: drives::Drives,
    /// The optional `[verify]` table: thresholds of `verne verify` by name, as written (the
    /// verify module checks the names and values).
    pub verify: Vec<(String, f64, Option<usize>)>,
    /// The optional `[gcode]` table: the words of the machine's joint and tool-centre programs.
    pub gcode: gcode::GcodeWords,
}

impl Machine {
    /// True when a joint zero offset is not zero: the joints the machine's controller reads
    /// then differ from the equations' variables.
    pub fn has_zeros(&self) -> bool {
        self.module.rho_zero.iter().any(|&z| z != 0.0)
            || self.table.theta_zero.iter().any(|&z| z != 0.0)
    }

    /// The machine the solvers run on: its joints are the equations' variables (every zero
    /// offset 0) and its limits are the file's moved by the zero offsets, so that a branch
    /// within them is within the file's limits. The machine itself when it has no zero offsets;
    /// otherwise a copy without name or `[verify]` table (nothing to allocate).
    pub fn model(&self) -> std::borrow::Cow<'_, Machine> {
        if !self.has_zeros() {
            return std::borrow::Cow::Borrowed(self);
        }
        let (rz, tz) = (self.module.rho_zero, self.table.theta_zero);
        let mut limits = self.limits;
        for ((min, max), z) in limits.rho_min.iter_mut().zip(&mut limits.rho_max).zip(rz) {
            *min += z;
            *max += z;
        }
        limits.theta1_min += tz[0];
        limits.theta1_max += tz[0];
        std::borrow::Cow::Owned(Machine {
            name: String::new(),
            module: ModuleGeometry {
                rho_zero: [0.0; 3],
                ..self.module
            },
            limits,
            table: TableGeometry {
                theta_zero: [0.0; 2],
                ..self.table
            },
            tool_length: self.tool_length,
            drives: self.drives,
            verify: Vec::new(),
            gcode: self.gcode,
        })
    }

    /// Slider positions of the equations (of [`Machine::model`]) as the joints read them.
    #[inline]
    pub fn joint_sliders(&self, model: &Sliders) -> Sliders {
        model - Sliders::from(self.module.rho_zero)
    }

    /// Joint slider positions as the equations (and [`Machine::model`]) take them.
    #[inline]
    pub fn model_sliders(&self, joints: &Sliders) -> Sliders {
        joints + Sliders::from(self.module.rho_zero)
    }

    /// The embedded VERNE machine.
    pub fn default_verne() -> Machine {
        Machine::from_toml_str(DEFAULT_MACHINE_TOML, "<default>")
            .expect("the embedded default machine file is valid (tested)")
    }

    /// The machine with every length times `k`: the module's, the strokes' limits, the table's
    /// and the tool's (angles unchanged). For the tests of scale: with k a power of two, every
    /// equation scales exactly.
    #[cfg(test)]
    pub(crate) fn scaled(&self, k: f64) -> Machine {
        let mut m = self.clone();
        m.module = self.module.scaled(k);
        m.limits.rho_min = self.limits.rho_min.map(|r| r * k);
        m.limits.rho_max = self.limits.rho_max.map(|r| r * k);
        m.table.d_a *= k;
        m.table.d_t *= k;
        m.table.y_t *= k;
        m.tool_length *= k;
        m
    }
}

impl ModuleGeometry {
    /// The module's lengths times `k` (the shape of every equation unchanged).
    #[cfg(test)]
    pub(crate) fn scaled(&self, k: f64) -> ModuleGeometry {
        ModuleGeometry {
            dx1: self.dx1 * k,
            dx2: self.dx2 * k,
            r_big1: self.r_big1 * k,
            r_small1: self.r_small1 * k,
            l1: self.l1 * k,
            r_big2: self.r_big2 * k,
            r4: self.r4 * k,
            l2: self.l2 * k,
            l3: self.l3 * k,
            d1: self.d1 * k,
            d2: self.d2 * k,
            rho_zero: self.rho_zero.map(|z| z * k),
        }
    }
}
