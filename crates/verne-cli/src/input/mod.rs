//! Readers of the inputs that are not plain row tables: APT CL files ([`apt`]) and the two inputs
//! of `verne verify` ([`verify_files`]). CSV reading itself is in [`crate::table`].

pub mod apt;
pub mod verify_files;
