//! verne: exact kinematics of the VERNE hybrid machine tool and of planar glider mechanisms.
//!
//! The library computes; the binary (`src/main.rs`) talks. Nothing here prints or exits.

pub mod branches;
pub mod glider;
pub mod machine;
pub mod module_fk;
pub mod module_geometry;
pub mod module_ik;
pub mod poly;
pub mod tolerance;
pub mod trig;
