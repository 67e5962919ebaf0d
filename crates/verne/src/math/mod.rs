//! The numerical tools under the solvers: real roots of small polynomials ([`poly`], [`cubic`])
//! and of trigonometric polynomials on the circle ([`trig`]), interval ([`interval`]) and
//! double-double ([`dd`]) arithmetic, formulas written once over several arithmetics
//! ([`scalar`]), the hash and confidence bound of the workspaces' sampled estimates
//! ([`sampling`]), the proofs of completeness where double precision cannot decide (`certify`),
//! and the run-time choice of the AVX2 builds ([`cpu`]).

pub(crate) mod certify;
pub mod cpu;
pub mod cubic;
pub mod dd;
pub mod interval;
pub mod poly;
pub mod sampling;
pub mod scalar;
pub(crate) mod test_rng;
pub mod trig;
