//! A random walk of tool poses at a controller's servo period, each pose answered by the
//! continuation (`verne::machine::continue_branch`) and by the complete solve's choice
//! (`choose_continuation` of `machine_ik`), compared: the branch, its joints, and the verdict of
//! the singularity thresholds. `tests/machine_kin.rs` walks a few hundred thousand poses,
//! `examples/continuation_walk.rs` a million (docs/benchmarks.md).

use nalgebra::Vector3;
use verne::details::lcg;
use verne::machine::{
    Fallback, MachineIkBranch, MachineIkBranches, NoBranch, PreviousJoints, ToolPose,
    choose_continuation, continue_branch, machine_ik,
};
use verne::parallel_module::equations::ModulePose;
use verne::parallel_module::ik::wrap_angle;
use verne::parallel_module::kinetostatics::{SingularityLimits, kinetostatics};
use verne::spec::Machine;

/// Largest difference allowed between the two answers' joints (mm for the sliders, degrees for
/// theta1): the two Newton iterations that reach the posture start from different points and
/// may end a few units in the last place apart.
pub const SAME_JOINTS: f64 = 1e-12;

/// The largest change of each coordinate of the pose in one servo period of 1 ms: the tip at
/// 12 m/min (0.2 mm), phi1 at 90 deg/s and phi2 at 180 deg/s (the velocity limits of
/// `verne verify`'s tilting and rotary axes).
pub const SERVO_STEP: Step = Step {
    tip_mm: 0.2,
    phi1_deg: 0.09,
    phi2_deg: 0.18,
};

/// Largest change per step of each coordinate.
#[derive(Debug, Clone, Copy)]
pub struct Step {
    pub tip_mm: f64,
    pub phi1_deg: f64,
    pub phi2_deg: f64,
}

impl Step {
    pub fn times(self, k: f64) -> Step {
        Step {
            tip_mm: self.tip_mm * k,
            phi1_deg: self.phi1_deg * k,
            phi2_deg: self.phi2_deg * k,
        }
    }
}

/// What a walk found.
#[derive(Debug, Default)]
pub struct Walk {
    pub poses: u64,
    /// Answered by the continuation's proof.
    pub continued: u64,
    /// Fallbacks by reason: not finite, no posture, not working, not isolated.
    pub fallbacks: [u64; 4],
    /// The complete solve's answers that were not a branch: uncertified, unreachable, branch
    /// lost, limits.
    pub no_branch: [u64; 4],
    /// Poses whose branch the singularity thresholds refuse.
    pub near_singularity: u64,
    /// Largest difference of the joints of the two answers (mm, degrees), and the number of
    /// answers with the same joints bit for bit.
    pub worst: f64,
    pub identical: u64,
    /// Answers that differ (the branch, the joints beyond [`SAME_JOINTS`], the verdict of the
    /// thresholds): the first few, described.
    pub differences: Vec<String>,
    pub different: u64,
}

/// Where the tool pose walks: a box around a centre (mm) and a tilt up to `tilt_deg`,
/// reflected at the walls.
#[derive(Debug, Clone, Copy)]
pub struct Region {
    pub centre_mm: [f64; 3],
    pub half_mm: [f64; 3],
    pub tilt_deg: f64,
}

/// Inside the default machine's workspace: the tip within 100 mm of (0, 0, 30) in x and y and
/// 70 mm in z, tilts up to 30 degrees.
pub const WORKSPACE: Region = Region {
    centre_mm: [0.0, 0.0, 30.0],
    half_mm: [100.0, 100.0, 70.0],
    tilt_deg: 30.0,
};

/// Across the workspace's boundary: the tip within 250 mm in x and y and 200 mm in z, tilts up
/// to 60 degrees (beyond the tilting axis's 45).
pub const ACROSS: Region = Region {
    centre_mm: [0.0, 0.0, 30.0],
    half_mm: [250.0, 250.0, 200.0],
    tilt_deg: 60.0,
};

/// `x` reflected into [lo, hi], and whether it was (the walk then turns back).
fn reflect(x: f64, lo: f64, hi: f64) -> (f64, bool) {
    if x < lo {
        (2.0 * lo - x, true)
    } else if x > hi {
        (2.0 * hi - x, true)
    } else {
        (x, false)
    }
}

/// `n` poses from the walk with the given seed, compared. Each coordinate moves by a velocity
/// that changes by up to a twentieth of its largest step each period and stays within it (a
/// toolpath's smooth changes of direction, not a diffusion that would stay near its start),
/// turned back at the region's walls.
pub fn walk(m: &Machine, n: u64, region: Region, step: Step, seed: u64) -> Walk {
    let limits = SingularityLimits {
        lambda_min: 1.0 / 3.0,
        lambda_max: 3.0,
        parallel_margin_min: 0.05,
    };
    let mut unit = lcg(seed);
    let mut pose = ToolPose {
        tip: Vector3::from(region.centre_mm),
        phi1: 0.1,
        phi2: 0.0,
    };
    let mut prev = PreviousJoints {
        rho: Vector3::new(300.0, 250.0, 250.0),
        theta1: 0.0,
    };
    let largest = [
        step.tip_mm,
        step.tip_mm,
        step.tip_mm,
        step.phi1_deg.to_radians(),
        step.phi2_deg.to_radians(),
    ];
    let mut velocity = [0.0f64; 5];
    let mut out = Walk::default();
    let mut scratch = MachineIkBranches::new();
    for _ in 0..n {
        for (v, top) in velocity.iter_mut().zip(largest) {
            *v = (*v + 0.05 * top * (2.0 * unit() - 1.0)).clamp(-top, top);
        }
        for (k, v) in velocity.iter_mut().take(3).enumerate() {
            let (c, h) = (region.centre_mm[k], region.half_mm[k]);
            let (x, turned) = reflect(pose.tip[k] + *v, c - h, c + h);
            pose.tip[k] = x;
            if turned {
                *v = -*v;
            }
        }
        let tilt = region.tilt_deg.to_radians();
        let (phi1, turned) = reflect(pose.phi1 + velocity[3], -tilt, tilt);
        pose.phi1 = phi1;
        if turned {
            velocity[3] = -velocity[3];
        }
        pose.phi2 += velocity[4];
        out.poses += 1;
        let want = choose_continuation(&machine_ik(m, &pose, m.tool_length), &prev);
        let got = continue_branch(m, &pose, m.tool_length, &prev, &mut scratch);
        match got.fallback {
            None => out.continued += 1,
            Some(why) => {
                out.fallbacks[match why {
                    Fallback::NotFinite => 0,
                    Fallback::NoPosture => 1,
                    Fallback::NotWorking => 2,
                    Fallback::NotIsolated => 3,
                }] += 1
            }
        }
        let mut differ = |what: String| {
            out.different += 1;
            if out.differences.len() < 10 {
                out.differences.push(what);
            }
        };
        match (&got.answer, &want) {
            (Ok(a), Ok(b)) => {
                let gap = (a.rho - b.rho)
                    .amax()
                    .max(wrap_angle(a.theta1 - b.theta1).abs().to_degrees());
                out.worst = out.worst.max(gap);
                out.identical += u64::from(a.rho == b.rho && a.theta1 == b.theta1);
                if gap > SAME_JOINTS || a.config != b.config || a.verdict != b.verdict {
                    differ(format!("{pose:?} from {prev:?}: {a:?} vs {b:?}"));
                }
                let clear = limits.admit_pose(&m.module, &module_pose(a), &a.rho);
                if !clear {
                    out.near_singularity += 1;
                }
                if clear != limits.admit(&kinetostatics(&m.module, &module_pose(b), &b.rho)) {
                    differ(format!("{pose:?}: the thresholds' verdicts differ"));
                }
            }
            (Err(a), Err(b)) if a == b => {
                out.no_branch[match a {
                    NoBranch::Uncertified => 0,
                    NoBranch::Unreachable => 1,
                    NoBranch::BranchLost => 2,
                    NoBranch::Limits => 3,
                }] += 1;
            }
            (a, b) => differ(format!("{pose:?} from {prev:?}: {a:?} vs {b:?}")),
        }
        if let Ok(b) = got.answer {
            prev = PreviousJoints {
                rho: b.rho,
                theta1: b.theta1,
            };
        }
    }
    out
}

fn module_pose(b: &MachineIkBranch) -> ModulePose {
    ModulePose {
        p: b.platform,
        alpha: b.alpha,
    }
}
