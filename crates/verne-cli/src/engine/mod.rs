//! The streaming row engine of `verne ik` and `verne fk`: [`pipeline`] reads a CSV in batches,
//! solves the rows in parallel and writes them in input order; the jobs say what a row reads,
//! solves and writes: the parallel module's ([`module_rows`]), the whole machine's
//! ([`machine_rows`]) and the gliders' ([`glider_rows`]).

pub mod glider_rows;
pub mod machine_rows;
pub mod module_rows;
pub mod pipeline;
