//! Every numerical tolerance of the library, with its unit, in one place.

/// Largest residual of a constraint equation (3)-(6), expressed as a distance error along the rod
/// (|f| / (2 L), mm), for a polished solution to be accepted as a real solution.
pub const ACCEPT_RESIDUAL_MM: f64 = 1e-6;

/// A Newton polish stops once its step is below this (mm for positions and joints, rad for angles).
pub const NEWTON_STEP_STOP: f64 = 1e-13;

/// Iteration cap of the Newton polish on the original equations. Polishing starts from an
/// analytic root, so it converges in two or three steps; the cap only guards degenerate inputs.
pub const NEWTON_MAX_ITER: usize = 12;

/// Two solutions whose angles differ by less than this (rad) and whose positions or joints differ
/// by less than [`SAME_SOLUTION_MM`] are the same solution.
pub const SAME_SOLUTION_RAD: f64 = 1e-9;

/// See [`SAME_SOLUTION_RAD`] (mm).
pub const SAME_SOLUTION_MM: f64 = 1e-7;

/// |sin(alpha)| below this (rad) is treated as alpha in {0, pi} by the inverse kinematics: there
/// eq. (14) no longer fixes the sign of rho1 - zp, so both signs of eq. (11) are tried and the
/// Newton polish moves each to its own exact solution (IFToMM 2007, Table II).
pub const SIN_ALPHA_ZERO: f64 = 1e-7;

/// A square root argument of eqs. (11)-(13) that is negative by less than this fraction of L^2
/// is rounding noise at a fully stretched rod (a serial singularity) and is taken as zero.
pub const SQRT_ARG_REL: f64 = 1e-12;

/// Relative size of |det| (eq. (21), scaled by its coefficient sizes) below which the linear
/// (yp, zp) system of the forward kinematics is treated as singular and the robust fixed-angle
/// sphere intersection is used instead.
pub const FK_DET_REL: f64 = 1e-9;

/// A configuration index s_i (eqs. (11)-(13)) is reported as -1 when its signed quantity is below
/// this (mm); exactly stretched-horizontal rods (quantity 0) belong to the machine's side.
pub const CONFIG_SIGN_MM: f64 = 1e-9;

/// Joint limits are checked with this slack (mm for sliders, rad for angles) so that a value
/// computed exactly at a limit is inside it.
pub const LIMIT_SLACK: f64 = 1e-9;

/// A platform point is proved beyond the rods' reach from the strokes only when it lies outside
/// the reach box by more than this (mm), plus [`REACH_MARGIN_REL`] of the magnitudes involved:
/// far more than the rounding of the box and of the point, and than [`LIMIT_SLACK`].
pub const REACH_MARGIN_MM: f64 = 1e-6;

/// See [`REACH_MARGIN_MM`] (dimensionless).
pub const REACH_MARGIN_REL: f64 = 1e-12;
