//! The C interface driven as a controller drives it (through the `extern "C"` functions).

use std::ffi::CStr;
use verne_kins::*;

fn handle() -> *mut VerneKins {
    let mut err = [0 as std::ffi::c_char; 256];
    let k = unsafe { verne_kins_new(std::ptr::null(), err.as_mut_ptr(), err.len()) };
    assert!(!k.is_null());
    k
}

#[test]
fn round_trip_keeps_the_pose() {
    let k = handle();
    let world = [10.0, -20.0, 5.0, 12.0, 30.0];
    let mut joints = [300.0, 250.0, 250.0, 0.0, 0.0];
    let mut info = VerneKinsInfo::default();
    let s = unsafe { verne_kins_inverse(k, world.as_ptr(), joints.as_mut_ptr(), 0, &mut info) };
    assert_eq!(s, VerneKinsStatus::Ok, "{joints:?}");
    assert!(info.branches > 0);
    let mut back = [0.0, 0.0, 0.0, 0.0, 25.0];
    let s = unsafe { verne_kins_forward(k, joints.as_ptr(), back.as_mut_ptr(), 0, &mut info) };
    assert_eq!(s, VerneKinsStatus::Ok);
    for d in 0..5 {
        assert!((back[d] - world[d]).abs() < 1e-7, "{back:?} vs {world:?}");
    }
    unsafe { verne_kins_free(k) };
}

/// A step of a servo period is continued from the previous joints (`info.branches` is 1, no
/// fallback counted); with `VERNE_KINS_COMPLETE` every branch is solved (the pose's 16) and the
/// same joints come back; a call the continuation cannot prove (an unreachable pose) is
/// answered by the complete solve and counted; a null handle counts nothing.
#[test]
fn the_continuation_and_its_fallbacks_are_counted() {
    let k = handle();
    let inverse = |world: &[f64; 5], joints: &mut [f64; 5], flags: u32| {
        let mut info = VerneKinsInfo::default();
        let s =
            unsafe { verne_kins_inverse(k, world.as_ptr(), joints.as_mut_ptr(), flags, &mut info) };
        (s, info.branches)
    };
    let world = [10.0, -20.0, 5.0, 12.0, 30.0];
    let mut start = [300.0, 250.0, 250.0, 0.0, 0.0];
    assert_eq!(
        inverse(&world, &mut start, VERNE_KINS_COMPLETE),
        (VerneKinsStatus::Ok, 16)
    );
    assert_eq!(unsafe { verne_kins_inverse_fallbacks(k) }, 0);
    let next = [10.1, -20.0, 5.0, 12.05, 30.1];
    let (mut cont, mut full) = (start, start);
    assert_eq!(inverse(&next, &mut cont, 0), (VerneKinsStatus::Ok, 1));
    assert_eq!(
        inverse(&next, &mut full, VERNE_KINS_COMPLETE),
        (VerneKinsStatus::Ok, 16)
    );
    for d in 0..5 {
        assert!((cont[d] - full[d]).abs() <= 1e-12, "{cont:?} vs {full:?}");
    }
    assert_eq!(unsafe { verne_kins_inverse_fallbacks(k) }, 0);
    let far = [5000.0, 0.0, 0.0, 0.0, 0.0];
    assert_eq!(
        inverse(&far, &mut cont, 0),
        (VerneKinsStatus::Unreachable, 0)
    );
    assert_eq!(unsafe { verne_kins_inverse_fallbacks(k) }, 1);
    assert_eq!(unsafe { verne_kins_inverse_fallbacks(std::ptr::null()) }, 0);
    unsafe { verne_kins_free(k) };
}

#[test]
fn bad_arguments_are_refused_without_writing() {
    let k = handle();
    let mut joints = [1.0, 2.0, 3.0, 4.0, 5.0];
    let nan = [f64::NAN, 0.0, 0.0, 0.0, 0.0];
    let s = unsafe {
        verne_kins_inverse(
            k,
            nan.as_ptr(),
            joints.as_mut_ptr(),
            0,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, VerneKinsStatus::BadArguments);
    assert_eq!(joints, [1.0, 2.0, 3.0, 4.0, 5.0]);
    let s = unsafe {
        verne_kins_inverse(
            std::ptr::null(),
            nan.as_ptr(),
            joints.as_mut_ptr(),
            0,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, VerneKinsStatus::BadArguments);
    let s = unsafe {
        verne_kins_forward(
            k,
            std::ptr::null(),
            joints.as_mut_ptr(),
            0,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, VerneKinsStatus::BadArguments);
    let text = unsafe { CStr::from_ptr(verne_kins_status_text(5)) };
    assert!(text.to_str().unwrap().starts_with("bad arguments"));
    unsafe { verne_kins_free(k) };
}

#[test]
fn unreachable_is_an_answer() {
    let k = handle();
    let world = [5000.0, 0.0, 0.0, 0.0, 0.0];
    let mut joints = [300.0, 250.0, 250.0, 0.0, 0.0];
    let s = unsafe {
        verne_kins_inverse(
            k,
            world.as_ptr(),
            joints.as_mut_ptr(),
            0,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, VerneKinsStatus::Unreachable);
    assert_eq!(joints, [300.0, 250.0, 250.0, 0.0, 0.0]);
    unsafe { verne_kins_free(k) };
}

#[test]
fn theta2_unwraps_along_a_turn() {
    let k = handle();
    let mut joints = [300.0, 250.0, 250.0, 0.0, 0.0];
    let mut last = 0.0;
    for step in 0..=800 {
        let phi2 = step as f64; // degrees: more than two turns
        let world = [0.0, 0.0, 0.0, 20.0, phi2];
        let s = unsafe {
            verne_kins_inverse(
                k,
                world.as_ptr(),
                joints.as_mut_ptr(),
                0,
                std::ptr::null_mut(),
            )
        };
        assert_eq!(s, VerneKinsStatus::Ok, "phi2 {phi2}");
        assert!(
            (joints[4] - last).abs() < 2.0,
            "theta2 jumped at phi2 = {phi2}: {} -> {}",
            last,
            joints[4]
        );
        assert!((joints[4] + phi2).abs() < 1e-9, "theta2 = -phi2 unwrapped");
        last = joints[4];
    }
    unsafe { verne_kins_free(k) };
}

/// The forward along 11 rows 0.002 mm apart across the set of slider triples where a solver
/// without certified root isolation loses the working mode (docs/reliability.md,
/// "Completeness"; IFToMM 2007 condition (21)): every row is answered, by the followed mode,
/// and equals the working mode of the complete machine forward kinematics.
#[test]
fn forward_follows_the_working_mode_across_a_hard_set() {
    let k = handle();
    let m = verne::spec::Machine::default_verne();
    let base = [923.8484370198487, 967.2529090413111, 876.4439649983864];
    let mut world = [0.0; 5];
    for step in -5..=5 {
        let rho = [base[0], base[1] + 0.002 * step as f64, base[2]];
        let joints = [rho[0], rho[1], rho[2], 0.0, 0.0];
        let mut info = VerneKinsInfo::default();
        let s = unsafe { verne_kins_forward(k, joints.as_ptr(), world.as_mut_ptr(), 0, &mut info) };
        assert_eq!(s, VerneKinsStatus::Ok, "rho2 step {step}");
        let modes =
            verne::machine::machine_fk(&m, &nalgebra::Vector3::from(rho), 0.0, 0.0, m.tool_length);
        let w = modes
            .iter()
            .find(|md| md.working())
            .expect("a working mode");
        let want = [w.tool.tip.x, w.tool.tip.y, w.tool.tip.z];
        for d in 0..3 {
            assert!(
                (world[d] - want[d]).abs() < 1e-6,
                "step {step}: {world:?} vs {want:?}"
            );
        }
        assert!((world[3] - w.tool.phi1.to_degrees()).abs() < 1e-6);
    }
    unsafe { verne_kins_free(k) };
}

/// A pose whose module is close to a singularity by the machine file's thresholds is refused
/// with `NearSingularity`, the joints left as they came; a machine file the thresholds reject
/// gives no handle and the reason.
#[test]
fn near_singularity_and_bad_machine_files_are_reported() {
    let dir = std::env::temp_dir().join(format!("verne-kins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = verne::spec::Machine::default_verne().to_toml();
    // Every pose amplifies slider speed by more than 1.0001 or less than 0.9999.
    text.push_str("\n[verify]\nlambda_max = 1.0001\nlambda_min = 0.9999\n");
    let strict = dir.join("strict.toml");
    std::fs::write(&strict, &text).unwrap();
    let path = std::ffi::CString::new(strict.to_str().unwrap()).unwrap();
    let mut err = [0 as std::ffi::c_char; 256];
    let k = unsafe { verne_kins_new(path.as_ptr(), err.as_mut_ptr(), err.len()) };
    assert!(!k.is_null(), "{:?}", unsafe {
        CStr::from_ptr(err.as_ptr())
    });
    let world = [10.0, -20.0, 5.0, 12.0, 30.0];
    let mut joints = [300.0, 250.0, 250.0, 0.0, 0.0];
    let s = unsafe {
        verne_kins_inverse(
            k,
            world.as_ptr(),
            joints.as_mut_ptr(),
            0,
            std::ptr::null_mut(),
        )
    };
    assert_eq!(s, VerneKinsStatus::NearSingularity);
    assert_eq!(joints, [300.0, 250.0, 250.0, 0.0, 0.0]);
    unsafe { verne_kins_free(k) };

    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replace("lambda_max = 1.0001", "lambda_max = -1")).unwrap();
    let path = std::ffi::CString::new(bad.to_str().unwrap()).unwrap();
    let k = unsafe { verne_kins_new(path.as_ptr(), err.as_mut_ptr(), err.len()) };
    assert!(k.is_null());
    let msg = unsafe { CStr::from_ptr(err.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    assert!(msg.contains("lambda_max"), "{msg}");
}

/// The machine file's offsets through the C interface: the zero offsets of the sliders and the
/// table axes only rename the joints (a machine without them, its limits moved by them by
/// hand, gives the joints plus the offsets), the rotary axis's offset y_t enters both ways, and
/// the forward gives the inverse's pose back.
#[test]
fn the_machine_files_offsets_are_applied() {
    let dir = std::env::temp_dir().join(format!("verne-kins-zeros-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rho_zero = [0.4, -0.3, 0.2];
    let theta_zero_deg = [0.05, -0.1];
    let mut offsets = verne::spec::Machine::default_verne();
    offsets.module.rho_zero = rho_zero;
    offsets.table.theta_zero = theta_zero_deg.map(f64::to_radians);
    offsets.table.y_t = 0.25;
    let mut hand = verne::spec::Machine::default_verne();
    hand.table.y_t = 0.25;
    for (k, z) in rho_zero.iter().enumerate() {
        hand.limits.rho_min[k] += z;
        hand.limits.rho_max[k] += z;
    }
    hand.limits.theta1_min += theta_zero_deg[0].to_radians();
    hand.limits.theta1_max += theta_zero_deg[0].to_radians();
    let open = |m: &verne::spec::Machine, name: &str| {
        let file = dir.join(name);
        std::fs::write(&file, m.to_toml()).unwrap();
        let path = std::ffi::CString::new(file.to_str().unwrap()).unwrap();
        let mut err = [0 as std::ffi::c_char; 256];
        let k = unsafe { verne_kins_new(path.as_ptr(), err.as_mut_ptr(), err.len()) };
        assert!(!k.is_null(), "{:?}", unsafe {
            CStr::from_ptr(err.as_ptr())
        });
        k
    };
    let (ko, kh) = (open(&offsets, "offsets.toml"), open(&hand, "hand.toml"));
    let inverse = |k: *mut VerneKins, world: &[f64; 5]| {
        let mut joints = [300.0, 250.0, 250.0, 0.0, 0.0];
        let s = unsafe {
            verne_kins_inverse(
                k,
                world.as_ptr(),
                joints.as_mut_ptr(),
                VERNE_KINS_COMPLETE,
                std::ptr::null_mut(),
            )
        };
        assert_eq!(s, VerneKinsStatus::Ok, "{world:?}");
        joints
    };
    let zero = [
        rho_zero[0],
        rho_zero[1],
        rho_zero[2],
        theta_zero_deg[0],
        theta_zero_deg[1],
    ];
    for world in [
        [10.0, -20.0, 5.0, 12.0, 30.0],
        [-30.0, 15.0, 20.0, 20.0, -60.0],
        [40.0, 30.0, -10.0, 8.0, 135.0],
    ] {
        let (j, h) = (inverse(ko, &world), inverse(kh, &world));
        for d in 0..5 {
            assert!(
                (j[d] + zero[d] - h[d]).abs() < 1e-9,
                "{j:?} + offsets vs {h:?}"
            );
        }
        let mut back = [0.0, 0.0, 0.0, 0.0, world[4]];
        let s = unsafe {
            verne_kins_forward(ko, j.as_ptr(), back.as_mut_ptr(), 0, std::ptr::null_mut())
        };
        assert_eq!(s, VerneKinsStatus::Ok);
        for d in 0..5 {
            assert!((back[d] - world[d]).abs() < 1e-7, "{back:?} vs {world:?}");
        }
    }
    // Without y_t the same joints are another pose: the machine's y_t is used.
    let mut no_yt = offsets.clone();
    no_yt.table.y_t = 0.0;
    let kn = open(&no_yt, "no_yt.toml");
    let world = [10.0, -20.0, 5.0, 12.0, 30.0];
    let (a, b) = (inverse(ko, &world), inverse(kn, &world));
    assert!((0..3).any(|d| (a[d] - b[d]).abs() > 1e-3), "{a:?} vs {b:?}");
    unsafe {
        verne_kins_free(ko);
        verne_kins_free(kh);
        verne_kins_free(kn);
    }
}
