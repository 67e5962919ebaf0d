//! Text and CSV that the commands write from the core's typed results: the summary and help of
//! `verne verify` ([`verify`]), the points CSV of `verne workspace` ([`workspace`]), and small
//! tables as aligned text or CSV ([`text_table`]); the reports of `verne verify` for people and
//! CI systems ([`html`], [`junit`], [`sarif`]) and the 3D views of `verne modes` ([`html`]).

pub mod html;
pub mod junit;
pub mod sarif;
pub mod text_table;
pub mod verify;
pub mod workspace;
