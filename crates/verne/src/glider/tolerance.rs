//! Every numerical tolerance of the glider module, with its unit, in one place.

/// A square-root argument (strut reach in the inverse kinematics, half-chord in the forward
/// kinematics) whose magnitude is below this fraction of L^2 is a double root: the two
/// branches meet there (a serial singularity for the IK, a parallel one for the FK).
/// Dimensionless (relative to the squared strut length).
pub const DOUBLE_ROOT_REL: f64 = 1e-12;

/// Two slider points closer than this fraction of the strut length coincide: with L1 = L2 the
/// mechanism is then at a structural singularity (section 2.4, Fig. 5, Wenger 2001).
/// Dimensionless (relative to L1).
pub const COINCIDENT_REL: f64 = 1e-12;

/// A strut whose component along its guide, (p - c).u / L, is below this in magnitude is
/// orthogonal to its guide: serial singularity (section 2.5, Wenger 2001). Dimensionless
/// (cosine of the angle between strut and guide).
pub const SERIAL_SINGULAR_COS: f64 = 1e-9;

/// |det A| / (L1 L2) below this is a parallel singularity: C, D and P aligned (section 2.4,
/// Wenger 2001). Dimensionless (sine of the angle between the two struts).
pub const PARALLEL_SINGULAR_SIN: f64 = 1e-9;

/// Joint values are compared with their limits with this slack, relative to the strut length,
/// so that a value computed exactly at a limit (a corner of the joint box) is inside it.
/// Dimensionless (relative to L1).
pub const JOINT_LIMIT_REL: f64 = 1e-12;

/// The amplification bounds of eq. (4) are checked with this slack, so that the corners of a
/// joint box designed to touch the bounds exactly (section 3.2) stay inside. Dimensionless.
pub const LAMBDA_BOUND_SLACK: f64 = 1e-9;

/// Bisection of a design length (L0 or delta-rho, section 3.2) stops when the bracket is below
/// this fraction of L. Dimensionless (relative to L).
pub const DESIGN_BISECTION_REL: f64 = 1e-13;
