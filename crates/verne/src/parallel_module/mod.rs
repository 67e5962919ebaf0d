//! The 3-DOF parallel module of the VERNE machine (IFToMM 2007): three vertical sliders, legs I
//! (a non-parallelogram of two rods), II and III, and a platform that moves in x, y, z and tilts
//! by alpha about x.
//!
//! - [`equations`]: the constraint equations (3)-(6), rod vectors and residuals;
//! - [`branches`]: configuration indices (s1, s2, s3) and the verdict that picks the working
//!   branch;
//! - [`ik`]: inverse kinematics, every real branch of a point (section V);
//! - [`fk`]: forward kinematics, every real assembly mode of three slider positions (section VI);
//! - [`track`]: the working assembly mode along a path, following the previous row;
//! - [`kinetostatics`]: the Jacobians A and B, singularities and amplification factors;
//! - [`reach`]: the box the platform reaches with every slider within its stroke, checked before
//!   solving;
//! - [`fk_certify`], `leg1_certify`: the proofs of completeness where double precision cannot
//!   decide.

pub mod branches;
pub mod enclosure;
pub mod equations;
pub mod fk;
pub mod fk_certify;
pub mod ik;
pub mod kinetostatics;
pub(crate) mod leg1_certify;
pub mod reach;
#[doc(hidden)]
pub mod track;
