//! The specialised entry points below the main ones: the batched kernels that the row engine of
//! `verne ik` / `verne fk` runs (many points side by side, into lists the caller keeps), and the
//! builds for the x86-64 baseline that the benchmarks and tests compare with the AVX2 builds
//! (bench scaffolding, hidden from the documentation).
//!
//! The main entry points are [`crate::parallel_module::ik::solve`],
//! [`crate::parallel_module::fk::solve`], [`crate::machine::machine_ik`] and
//! [`crate::machine::machine_fk`]; what is here gives the same results, faster for a stream.

pub use crate::machine::{machine_ik_into, path_candidates_into};
pub use crate::parallel_module::ik::{
    LANES, solve_each, solve_into, solve_working_each, solve_working_into,
};
pub use crate::parallel_module::track::FkTracker;

#[doc(hidden)]
pub use crate::math::test_rng::lcg;
#[doc(hidden)]
pub use crate::parallel_module::fk::solve_baseline as fk_solve_baseline;
#[doc(hidden)]
pub use crate::parallel_module::ik::{solve_each_baseline, solve_working_each_baseline};
