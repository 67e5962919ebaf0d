//! Readers of the inputs that are not plain row tables: CL files ([`cl`], over the `verne-cl`
//! crate) and the two inputs of `verne verify` ([`verify_files`]). CSV reading itself is in
//! [`crate::table`].

pub mod as_csv;
pub mod cl;
pub mod gcode;
pub mod resample;
pub mod verify_files;
