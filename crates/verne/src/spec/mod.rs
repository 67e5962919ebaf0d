//! Machine parameters: the geometry, limits and tool of a VERNE-type machine ([`Machine`]) and
//! its machine file (TOML or two-column CSV, [`file`]: schema, reading and validation).

pub mod drives;
mod file;
pub mod gcode;

pub use file::{BaseResolver, MAX_BASE_DEPTH, MAX_LENGTH_MM};

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
        }
    }
}
