//! Text and CSV that the commands write from the core's typed results: the summary and help of
//! `verne verify` ([`verify`]), the points CSV of `verne workspace` ([`workspace`]), and small
//! tables as aligned text or CSV ([`text_table`]).

pub mod text_table;
pub mod verify;
pub mod workspace;
