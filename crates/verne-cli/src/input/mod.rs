//! Readers of the joint inputs of `verne verify`: a joint table or a G-code joint program
//! ([`verify_files`], [`gcode`]) and a controller's recorded joints ([`recording`]). Toolpaths
//! are read by [`crate::toolpath`]; CSV reading itself is in [`crate::table`].

pub mod gcode;
pub mod recording;
pub mod verify_files;

/// A reader's warnings on stderr, `verne CMD: NAME: warning: ...`, and how many it stopped
/// keeping: nothing a reader saw is dropped silently.
pub fn write_warnings(
    err: &mut impl std::io::Write,
    cmd: &str,
    name: &str,
    warnings: &[impl std::fmt::Display],
    dropped: u64,
) {
    for w in warnings {
        let _ = writeln!(err, "verne {cmd}: {name}: warning: {w}");
    }
    if dropped > 0 {
        let _ = writeln!(
            err,
            "verne {cmd}: {name}: {dropped} more warnings not shown"
        );
    }
}
