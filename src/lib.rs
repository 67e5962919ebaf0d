//! verne: exact kinematics of the VERNE hybrid machine tool and of planar glider mechanisms.
//!
//! The library computes; the binary (`src/main.rs`) talks. Nothing here prints or exits.

pub mod glider;
