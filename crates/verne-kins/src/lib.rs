//! C interface to the VERNE machine's kinematics, for controllers: LinuxCNC's kinematics
//! component (`linuxcnc/vernekins.comp`) calls it every servo cycle.
//!
//! World coordinates: the tool tip (X, Y, Z, mm) in the workpiece frame and the tool
//! orientation angles (phi1, phi2) of AIM 2007 eq. (8) (degrees, or radians with
//! [`VERNE_KINS_RADIANS`]); joints: the sliders rho1, rho2, rho3 (mm), the tilting axis theta1
//! and the rotary axis theta2 (degrees, or radians). See docs/linuxcnc.md.
//!
//! Every call takes the previous solution in its `*_in_out` array: the inverse keeps the branch
//! of the previous joints (proved from them alone where it can be, by the complete solve
//! otherwise: `verne::machine::continuation`) and unwraps theta2 next to them; the forward
//! returns the machine's assembly mode and unwraps phi2 next to the previous world angle.
//! Nothing is allocated per call, no function panics across the boundary (each body runs under
//! `catch_unwind`, and a panic is reported as [`VerneKinsStatus::Internal`]), and on any status
//! but [`VerneKinsStatus::Ok`] the output array is left as it came.

#![deny(missing_docs)]

use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::Vector3;
use verne::machine::{
    MachineIkBranch, MachineIkBranches, NoBranch, PreviousJoints, ToolPose, choose_continuation,
    continue_branch, machine_ik_into, tool_pose_eq26,
};
use verne::parallel_module::equations::ModulePose;
use verne::parallel_module::fk::{self as module_fk, FkModes};
use verne::parallel_module::ik::wrap_angle;
use verne::parallel_module::kinetostatics::{SingularityLimits, kinetostatics};
use verne::parallel_module::track::FkTracker;
use verne::spec::Machine;
use verne::verify::{Th, Thresholds};

/// Angles in radians instead of degrees (flags bit).
pub const VERNE_KINS_RADIANS: u32 = 1;

/// Inverse: solve every branch of the pose and choose the continuation among them, on every
/// call (flags bit), instead of proving the continuation from the previous joints first; and
/// decide the singularity thresholds by singular value decompositions alone. The same answers,
/// slower: for comparisons.
pub const VERNE_KINS_COMPLETE: u32 = 2;

/// What a call returns.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VerneKinsStatus {
    /// The output array holds the solution.
    Ok = 0,
    /// No real solution: the pose (or the joints) cannot be reached by any branch.
    Unreachable = 1,
    /// Real solutions exist, but none of the machine's kind within its limits (strokes, rod
    /// tilt, tilting-axis range).
    Limits = 2,
    /// The branch of the previous joints does not continue within the limits, and only a
    /// different branch (a jump of the joints) would: the controller must stop.
    BranchLost = 3,
    /// The solution is next to a singularity by the machine's `[verify]` thresholds
    /// (`lambda_min`, `lambda_max`, `parallel_margin_min`; docs/verify.md).
    NearSingularity = 4,
    /// An argument is missing (a null pointer) or not finite.
    BadArguments = 5,
    /// The solver could not prove its list of branches complete (see docs/reliability.md).
    Uncertified = 6,
    /// An internal error (a panic, caught): a bug, to be reported.
    Internal = 7,
}

/// Counts from the last call, for the controller's diagnostics pins.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VerneKinsInfo {
    /// Inverse: 1 when the branch of the previous joints was continued (proved from them
    /// alone), else the number of real branches of the complete solve.
    pub branches: u32,
    /// Forward: 1 when the previous call's mode was followed (certified tracking), else the
    /// number of real assembly modes of the complete solution.
    pub modes: u32,
}

/// A machine with its tool length and the forward solution's tracking state: what every call
/// needs. Opaque to C.
pub struct VerneKins {
    /// Follows the working assembly mode from call to call (certified tracking, the complete
    /// solution when tracking cannot prove itself). Declared first: dropped before `machine`,
    /// which it borrows.
    tracker: FkTracker<'static>,
    /// Boxed so that its address stays fixed while the handle moves (the tracker points at it).
    machine: Box<Machine>,
    tool_length: f64,
    /// The singularity thresholds of `verne verify` (the machine file's `[verify]` table):
    /// amplification factors within [lambda_min, lambda_max], parallel margin at least its
    /// minimum (docs/verify.md).
    singularity: SingularityLimits,
    /// The forward's output list, kept to allocate nothing per call.
    modes: FkModes,
    /// Inverse calls the continuation could not prove, answered by the complete solve
    /// ([`verne_kins_inverse_fallbacks`]). Atomic: the inverse takes a shared handle.
    fallbacks: AtomicU64,
}

impl VerneKins {
    fn new(machine: Machine, source: &str) -> Result<VerneKins, String> {
        let th = Thresholds::from_machine(&machine, source).map_err(|e| e.to_string())?;
        let singularity = SingularityLimits {
            lambda_min: th.get(Th::LambdaMin),
            lambda_max: th.get(Th::LambdaMax),
            parallel_margin_min: th.get(Th::ParallelMarginMin),
        };
        let machine = Box::new(machine);
        // SAFETY: the box's contents never move and outlive the tracker (field order above);
        // the reference is never handed out.
        let fixed: &'static Machine = unsafe { &*(&*machine as *const Machine) };
        Ok(VerneKins {
            tracker: FkTracker::new(fixed),
            tool_length: machine.tool_length,
            machine,
            singularity,
            modes: FkModes::default(),
            fallbacks: AtomicU64::new(0),
        })
    }
}

/// Writes `msg` into the caller's buffer, NUL-terminated, cut to fit.
fn write_error(msg: &str, error: *mut c_char, error_len: usize) {
    if error.is_null() || error_len == 0 {
        return;
    }
    let n = msg.len().min(error_len - 1);
    // SAFETY: the caller gives a buffer of `error_len` bytes (documented); n < error_len.
    unsafe {
        std::ptr::copy_nonoverlapping(msg.as_ptr().cast::<c_char>(), error, n);
        *error.add(n) = 0;
    }
}

/// Runs `f`, turning a panic into `fallback`.
fn guarded<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// A kinematics handle for the machine file at `machine_path`, or the embedded VERNE machine
/// when `machine_path` is null or empty. Null on failure, with the reason (every problem of the
/// file, with its line) in `error` (a buffer of `error_len` bytes; may be null). Free it with
/// [`verne_kins_free`]. Reads the file: call it at start-up, not in a realtime thread.
///
/// # Safety
/// `machine_path` is null or a NUL-terminated string; `error` is null or points to
/// `error_len` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_new(
    machine_path: *const c_char,
    error: *mut c_char,
    error_len: usize,
) -> *mut VerneKins {
    guarded(std::ptr::null_mut(), || {
        let path = if machine_path.is_null() {
            None
        } else {
            // SAFETY: NUL-terminated (the caller's contract).
            let s = unsafe { CStr::from_ptr(machine_path) };
            Some(s.to_string_lossy().into_owned()).filter(|s| !s.is_empty())
        };
        let source = path.clone().unwrap_or_else(|| "<default>".to_string());
        let machine = match path {
            None => Machine::default_verne(),
            Some(p) => {
                let text = match std::fs::read_to_string(&p) {
                    Ok(t) => t,
                    Err(e) => {
                        write_error(&format!("{p}: {e}"), error, error_len);
                        return std::ptr::null_mut();
                    }
                };
                match Machine::from_str_auto(&text, &p) {
                    Ok(m) => m,
                    Err(e) => {
                        write_error(&e.to_string(), error, error_len);
                        return std::ptr::null_mut();
                    }
                }
            }
        };
        match VerneKins::new(machine, &source) {
            Ok(k) => Box::into_raw(Box::new(k)),
            Err(e) => {
                write_error(&e, error, error_len);
                std::ptr::null_mut()
            }
        }
    })
}

/// Frees a handle from [`verne_kins_new`] (null: nothing).
///
/// # Safety
/// `k` is null or a handle from [`verne_kins_new`] not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_free(k: *mut VerneKins) {
    if !k.is_null() {
        // SAFETY: a handle from verne_kins_new, freed once (the caller's contract).
        drop(unsafe { Box::from_raw(k) });
    }
}

/// Sets the tool length (mm, from the spindle nose reference to the tip, AIM 2007's Delta),
/// used from the next call on. [`VerneKinsStatus::BadArguments`] for a null handle or a length
/// that is not finite.
///
/// # Safety
/// `k` is null or a valid handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_set_tool_length(k: *mut VerneKins, mm: f64) -> VerneKinsStatus {
    // SAFETY: null or valid (the caller's contract).
    let Some(k) = (unsafe { k.as_mut() }) else {
        return VerneKinsStatus::BadArguments;
    };
    if !mm.is_finite() {
        return VerneKinsStatus::BadArguments;
    }
    k.tool_length = mm;
    VerneKinsStatus::Ok
}

/// The tool length in use (mm); NaN for a null handle.
///
/// # Safety
/// `k` is null or a valid handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_tool_length(k: *const VerneKins) -> f64 {
    // SAFETY: null or valid (the caller's contract).
    unsafe { k.as_ref() }.map_or(f64::NAN, |k| k.tool_length)
}

/// Inverse kinematics: `world` = (X, Y, Z, phi1, phi2) to `joints_in_out` = (rho1, rho2, rho3,
/// theta1, theta2), which holds the previous joints on entry: the branch that continues them is
/// kept, and theta2 is unwrapped next to them. The branch is proved to be the continuation from
/// the previous joints alone where it can be (a step of a servo period), else chosen among every
/// branch of the pose (the complete solve, counted by [`verne_kins_inverse_fallbacks`]): the same
/// branch either way. `info` (may be null) receives the number of branches the answer was
/// chosen from (1 when continued).
///
/// # Safety
/// `k` is null or a valid handle; `world` is null or points to 5 doubles; `joints_in_out` is
/// null or points to 5 writable doubles; `info` is null or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_inverse(
    k: *const VerneKins,
    world: *const f64,
    joints_in_out: *mut f64,
    flags: u32,
    info: *mut VerneKinsInfo,
) -> VerneKinsStatus {
    guarded(VerneKinsStatus::Internal, || {
        // SAFETY: null or valid and sized as documented (the caller's contract).
        let (Some(k), false, false) = (
            unsafe { k.as_ref() },
            world.is_null(),
            joints_in_out.is_null(),
        ) else {
            return VerneKinsStatus::BadArguments;
        };
        // SAFETY: non-null, 5 doubles each.
        let (w, j) = unsafe {
            (
                &*world.cast::<[f64; 5]>(),
                &mut *joints_in_out.cast::<[f64; 5]>(),
            )
        };
        let mut out = VerneKinsInfo::default();
        let status = inverse(k, w, j, flags, &mut out);
        // SAFETY: null or writable.
        if let Some(i) = unsafe { info.as_mut() } {
            *i = out;
        }
        status
    })
}

/// Forward kinematics: `joints` = (rho1, rho2, rho3, theta1, theta2) to `world_in_out` = (X, Y,
/// Z, phi1, phi2), which holds the previous world position on entry (phi2 is unwrapped next to
/// it). `info` (may be null) receives the number of real assembly modes.
///
/// # Safety
/// As [`verne_kins_inverse`], with `joints` read and `world_in_out` written.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_forward(
    k: *mut VerneKins,
    joints: *const f64,
    world_in_out: *mut f64,
    flags: u32,
    info: *mut VerneKinsInfo,
) -> VerneKinsStatus {
    guarded(VerneKinsStatus::Internal, || {
        // SAFETY: null or valid and sized as documented (the caller's contract).
        let (Some(k), false, false) = (
            unsafe { k.as_mut() },
            joints.is_null(),
            world_in_out.is_null(),
        ) else {
            return VerneKinsStatus::BadArguments;
        };
        // SAFETY: non-null, 5 doubles each.
        let (j, w) = unsafe {
            (
                &*joints.cast::<[f64; 5]>(),
                &mut *world_in_out.cast::<[f64; 5]>(),
            )
        };
        let mut out = VerneKinsInfo::default();
        let status = forward(k, j, w, flags, &mut out);
        // SAFETY: null or writable.
        if let Some(i) = unsafe { info.as_mut() } {
            *i = out;
        }
        status
    })
}

/// Inverse calls so far whose continuation could not be proved from the previous joints alone
/// (the first call of a move from afar, a jump of the pose, a singularity or another branch
/// nearby, a limit), answered by the complete solve; 0 for a null handle.
///
/// # Safety
/// `k` is null or a valid handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn verne_kins_inverse_fallbacks(k: *const VerneKins) -> u64 {
    // SAFETY: null or valid (the caller's contract).
    unsafe { k.as_ref() }.map_or(0, |k| k.fallbacks.load(Ordering::Relaxed))
}

/// A short English description of a status (a static string; "unknown status" for other
/// values).
#[unsafe(no_mangle)]
pub extern "C" fn verne_kins_status_text(status: i32) -> *const c_char {
    let s: &'static CStr = match status {
        0 => c"ok",
        1 => c"unreachable: no real branch reaches the pose",
        2 => c"no branch of the machine's kind within its limits",
        3 => c"branch lost: continuing would need a jump to another branch",
        4 => c"near a singularity: velocity amplification beyond the machine's limit",
        5 => c"bad arguments: a null pointer or a value that is not finite",
        6 => c"uncertified: the solver could not prove its branches complete",
        7 => c"internal error (please report)",
        _ => c"unknown status",
    };
    s.as_ptr()
}

/// Angle scale from the caller's unit to radians.
fn to_rad(flags: u32) -> f64 {
    if flags & VERNE_KINS_RADIANS != 0 {
        1.0
    } else {
        std::f64::consts::PI / 180.0
    }
}

fn inverse(
    k: &VerneKins,
    w: &[f64; 5],
    j: &mut [f64; 5],
    flags: u32,
    info: &mut VerneKinsInfo,
) -> VerneKinsStatus {
    if !(w.iter().all(|v| v.is_finite()) && j.iter().all(|v| v.is_finite())) {
        return VerneKinsStatus::BadArguments;
    }
    let a = to_rad(flags);
    let pose = ToolPose {
        tip: Vector3::new(w[0], w[1], w[2]),
        phi1: w[3] * a,
        phi2: w[4] * a,
    };
    let prev = PreviousJoints {
        rho: Vector3::new(j[0], j[1], j[2]),
        theta1: j[3] * a,
    };
    let prev_theta2 = j[4] * a;
    let mut branches = MachineIkBranches::new();
    let complete = flags & VERNE_KINS_COMPLETE != 0;
    // The continuation of the previous joints' branch: proved from them alone, or chosen from
    // every branch of the pose (the complete solve) when that proof fails or is not wanted.
    let answer = if complete {
        machine_ik_into(&k.machine, &pose, k.tool_length, &mut branches);
        info.branches = branches.len() as u32;
        choose_continuation(&branches, &prev)
    } else {
        let c = continue_branch(&k.machine, &pose, k.tool_length, &prev, &mut branches);
        if c.fallback.is_some() {
            k.fallbacks.fetch_add(1, Ordering::Relaxed);
        }
        info.branches = c.branches as u32;
        c.answer
    };
    let chosen = match answer {
        Ok(b) => b,
        Err(NoBranch::Uncertified) => return VerneKinsStatus::Uncertified,
        Err(NoBranch::Unreachable) => return VerneKinsStatus::Unreachable,
        Err(NoBranch::BranchLost) => return VerneKinsStatus::BranchLost,
        Err(NoBranch::Limits) => return VerneKinsStatus::Limits,
    };
    if near_singularity(k, &chosen, complete) {
        return VerneKinsStatus::NearSingularity;
    }
    let theta2 = prev_theta2 + wrap_angle(chosen.theta2 - prev_theta2);
    *j = [
        chosen.rho.x,
        chosen.rho.y,
        chosen.rho.z,
        chosen.theta1 / a,
        theta2 / a,
    ];
    VerneKinsStatus::Ok
}

/// The branch's module pose is next to a singularity by the thresholds of `verne verify`:
/// an amplification factor outside [lambda_min, lambda_max] or a parallel margin below its
/// minimum (IFToMM 2007 section VII; docs/verify.md). Proved clear without singular value
/// decompositions where it can be, unless `complete`; the same verdict either way.
fn near_singularity(k: &VerneKins, b: &MachineIkBranch, complete: bool) -> bool {
    let pose = ModulePose {
        p: b.platform,
        alpha: b.alpha,
    };
    let (g, l) = (&k.machine.module, &k.singularity);
    if complete {
        !l.admit(&kinetostatics(g, &pose, &b.rho))
    } else {
        !l.admit_pose(g, &pose, &b.rho)
    }
}

fn forward(
    k: &mut VerneKins,
    j: &[f64; 5],
    w: &mut [f64; 5],
    flags: u32,
    info: &mut VerneKinsInfo,
) -> VerneKinsStatus {
    if !(j.iter().all(|v| v.is_finite()) && w.iter().all(|v| v.is_finite())) {
        return VerneKinsStatus::BadArguments;
    }
    let a = to_rad(flags);
    let rho = Vector3::new(j[0], j[1], j[2]);
    let (theta1, theta2) = (j[3] * a, j[4] * a);
    // The previous call's mode, followed (one mode in `modes`), or every mode of the complete
    // solution (IFToMM 2007 section VI) when tracking cannot certify the step.
    k.tracker.working_into(&rho, &mut k.modes);
    let modes = &k.modes;
    info.modes = modes.len() as u32;
    if !modes.certificate.proved() {
        return VerneKinsStatus::Uncertified;
    }
    if modes.is_empty() {
        return VerneKinsStatus::Unreachable;
    }
    let Some(mode) = module_fk::working(modes) else {
        return VerneKinsStatus::Limits;
    };
    let lim = &k.machine.limits;
    if !(theta1 >= lim.theta1_min - 1e-9 && theta1 <= lim.theta1_max + 1e-9) {
        return VerneKinsStatus::Limits;
    }
    let tool = tool_pose_eq26(&k.machine.table, &mode.pose, theta1, theta2, k.tool_length);
    let prev_phi2 = w[4] * a;
    let phi2 = prev_phi2 + wrap_angle(tool.phi2 - prev_phi2);
    *w = [tool.tip.x, tool.tip.y, tool.tip.z, tool.phi1 / a, phi2 / a];
    VerneKinsStatus::Ok
}
