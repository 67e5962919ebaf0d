//! Text and CSV that the commands write from the core's typed results: the summary and help of
//! `verne verify` ([`verify`]) and the points CSV of `verne workspace` ([`workspace`]).

pub mod verify;
pub mod workspace;
