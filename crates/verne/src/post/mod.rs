//! The post: what turns a toolpath's rows, solved into joints, into a program a machine can run.
//! A controller moves the joints linearly between the blocks of a joint program; on a parallel
//! machine with a tilting table the tool then leaves the intended move inside a block, and the
//! joints' speeds and accelerations depend on the block times.
//!
//! - [`deviation`]: how far the tool goes from the intended move inside a block, at one point and
//!   proved over an interval;
//! - [`linearize`]: the poses inserted between two rows so that every block stays within the
//!   tolerances, each solved exactly on the path;
//! - [`schedule`]: the time of every block, as fast as the joints' speed and acceleration limits
//!   and the programmed feeds allow.

pub mod deviation;
pub mod linearize;
pub mod schedule;
