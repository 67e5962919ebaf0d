//! What the processor offers beyond the x86-64 baseline the crate is built for (SSE2).
//!
//! The module IK's kernels that `verne ik` runs ([`crate::parallel_module::ik::solve_working_each`],
//! [`crate::parallel_module::ik::solve_each`]), the module FK ([`crate::parallel_module::fk::solve`]) and the root
//! isolation on the circle that the FK, the machine IK and the workspace share
//! ([`crate::math::trig::Trig::roots_sin_cos`]) are built twice, for the baseline and with AVX2, and
//! choose at run time. With AVX2 the four points the IK solves side by side fit one register,
//! and three-operand instructions leave out most of the register copies that two-operand SSE2
//! needs: a third fewer instructions for the working branch, 15 % fewer for every branch, a
//! fifth fewer for the FK (docs/benchmarks.md). Both builds give the same results bit for bit
//! (Rust neither fuses nor reorders floating-point operations, whatever the instruction set);
//! the tests compare them. The AVX2 build of `solve_each` also labels a point's four leg-I
//! postures side by side with AVX intrinsics (`parallel_module::ik::lanes`), the same operations lane by lane,
//! where the baseline build labels them one by one.
//!
//! The pattern (`ik::each_in_lanes`): one dispatcher checks [`has_avx2`] and calls a
//! function marked `#[target_feature(enable = "avx2")]` or the baseline one; both inline one
//! body (`#[inline(always)]`, with what it calls in the hot loop), which takes a
//! `const AVX2: bool` only to tell the builds apart, so that each has its own copy of the
//! closures inside (one copy, called from both, would be built for the baseline). A recursive
//! function (the root isolation's bisection, `trig::Isolation::interval`) cannot be inlined into
//! itself: its dispatch calls the function of its build, so the recursion stays in that build.

/// True when the processor runs AVX2 code (the standard library asks it once and remembers).
#[inline]
pub fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
