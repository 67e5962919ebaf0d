//! The one detector of a CSV's toolpath columns (`x,y,z` with `i,j,k` or `phi1,phi2`), and the
//! one reader of the cells every command reads the same way (`motion`, `feed`, `dt`): `verne
//! ik`, `verne ik --period` and `verne verify` cannot read one file two ways.

use super::Motion;

/// How a CSV gives the tool orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrientationColumns {
    /// `i,j,k`: the tool axis, tip towards spindle (CAM convention).
    Axis,
    /// `phi1,phi2`: the angles of AIM 2007 eq. (8).
    Angles,
}

impl OrientationColumns {
    /// Chooses from a header: `i,j,k` or `phi1,phi2`, exactly one of the two.
    pub fn detect(has: impl Fn(&str) -> bool) -> Result<OrientationColumns, String> {
        let axis = ["i", "j", "k"].iter().filter(|c| has(c)).count();
        let angles = ["phi1", "phi2"].iter().filter(|c| has(c)).count();
        match (axis, angles) {
            (3, 0) => Ok(OrientationColumns::Axis),
            (0, 2) => Ok(OrientationColumns::Angles),
            (0, 0) => Err(
                "tool poses need the tool axis `i,j,k` or the angles `phi1,phi2` besides `x,y,z`"
                    .into(),
            ),
            (3, 2) => Err("both `i,j,k` and `phi1,phi2` are present: keep one orientation".into()),
            _ => Err(
                "incomplete orientation columns: expected all of `i,j,k` or both `phi1,phi2`"
                    .into(),
            ),
        }
    }

    /// The columns' names, in order.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            OrientationColumns::Axis => &["i", "j", "k"],
            OrientationColumns::Angles => &["phi1", "phi2"],
        }
    }
}

/// What a CSV's header holds: tool poses, platform points, or neither.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableKind {
    /// `x,y,z` (and an orientation, checked by [`OrientationColumns::detect`]).
    ToolPoses,
    /// `xp,yp,zp`: points of the parallel module's platform.
    PlatformPoints,
    /// Neither: the command's own columns are read (joints, sliders).
    Other,
}

impl TableKind {
    /// The kind of a header; both tool poses and platform points is an error.
    pub fn detect(has: impl Fn(&str) -> bool) -> Result<TableKind, String> {
        let tool = ["x", "y", "z"].iter().all(|c| has(c));
        let platform = ["xp", "yp", "zp"].iter().all(|c| has(c));
        match (tool, platform) {
            (true, true) => Err(
                "both tool poses (x,y,z) and platform points (xp,yp,zp) are present: keep one (xp,yp,zp is the parallel module alone)".into(),
            ),
            (true, false) => Ok(TableKind::ToolPoses),
            (false, true) => Ok(TableKind::PlatformPoints),
            (false, false) => Ok(TableKind::Other),
        }
    }
}

/// A `motion` cell: `rapid` or `feed` in any case, or empty (the input does not say).
pub fn parse_motion(cell: &[u8]) -> Result<Option<Motion>, String> {
    if cell.is_empty() {
        Ok(None)
    } else if cell.eq_ignore_ascii_case(b"rapid") {
        Ok(Some(Motion::Rapid))
    } else if cell.eq_ignore_ascii_case(b"feed") {
        Ok(Some(Motion::Feed))
    } else {
        Err(format!(
            "expected `rapid` or `feed` (or an empty cell), found `{}`",
            verne::error::shown(cell)
        ))
    }
}

/// A positive duration or rate cell (`dt` in s, `feed` in mm/min): a finite number above 0, or
/// empty. `what` names it in the message.
pub fn parse_positive_cell(cell: &[u8], what: &str) -> Result<Option<f64>, String> {
    if cell.is_empty() {
        return Ok(None);
    }
    let text = std::str::from_utf8(cell).ok();
    match text.and_then(|t| t.parse::<f64>().ok()) {
        Some(v) if v.is_finite() && v > 0.0 => Ok(Some(v)),
        Some(v) => Err(format!("expected {what} above 0, found {v}")),
        None => Err(format!(
            "expected {what} (a number above 0) or an empty cell, found `{}`",
            verne::error::shown(cell)
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motion_cells_are_read_in_any_case_and_nothing_else_is_taken() {
        assert_eq!(parse_motion(b"rapid"), Ok(Some(Motion::Rapid)));
        assert_eq!(parse_motion(b"RAPID"), Ok(Some(Motion::Rapid)));
        assert_eq!(parse_motion(b"Feed"), Ok(Some(Motion::Feed)));
        assert_eq!(parse_motion(b""), Ok(None));
        assert!(parse_motion(b"bogus").is_err());
        assert!(parse_motion(b"rapids").is_err());
    }

    #[test]
    fn durations_must_be_positive_numbers() {
        assert_eq!(parse_positive_cell(b"0.5", "dt"), Ok(Some(0.5)));
        assert_eq!(parse_positive_cell(b"", "dt"), Ok(None));
        for bad in [&b"0"[..], b"-1", b"1e400", b"NaN", b"soon", b"inf"] {
            assert!(parse_positive_cell(bad, "dt").is_err(), "{bad:?}");
        }
    }

    #[test]
    fn one_orientation_exactly() {
        let has = |cols: &'static [&'static str]| move |c: &str| cols.contains(&c);
        assert_eq!(
            OrientationColumns::detect(has(&["x", "y", "z", "i", "j", "k"])),
            Ok(OrientationColumns::Axis)
        );
        assert_eq!(
            OrientationColumns::detect(has(&["phi1", "phi2"])),
            Ok(OrientationColumns::Angles)
        );
        assert!(OrientationColumns::detect(has(&["i", "j", "k", "phi1", "phi2"])).is_err());
        assert!(OrientationColumns::detect(has(&["i", "j"])).is_err());
        assert!(OrientationColumns::detect(has(&[])).is_err());
    }
}
