//! verne: exact kinematics of the VERNE hybrid machine tool and of planar glider mechanisms.
//!
//! The library computes; the binary (`src/main.rs`) talks. Nothing here prints or exits.

pub mod apt;
pub mod arg_values;
pub mod branches;
pub mod certificate;
pub(crate) mod certify;
pub mod cpu;
pub mod cubic;
pub mod dd;
pub mod error;
pub mod fk_certify;
#[doc(hidden)]
pub mod fk_track;
pub mod fuzz_entry;
pub mod glider;
pub mod hard_sets;
pub mod interval;
pub mod jacobian;
pub(crate) mod leg1_certify;
pub mod machine;
pub mod machine_kin;

pub mod machine_rows;
pub mod module_fk;
pub mod module_geometry;
pub mod module_ik;
#[cfg(target_arch = "x86_64")]
mod module_ik_x4;
pub mod module_rows;
pub mod orientation;
pub mod pipeline;
pub mod plot;
pub mod poly;
pub mod scalar;
pub mod selftest;
pub mod table;
#[cfg(test)]
mod test_rng;
pub mod tolerance;
pub mod trig;
pub mod verify;
pub mod workspace;
