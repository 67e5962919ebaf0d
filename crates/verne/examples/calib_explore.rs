use nalgebra::{Rotation3, Vector3};
use verne::calibrate::model::{DEFAULT_NOISE, Device, Instrument};
use verne::calibrate::plan::{PlanOptions, plan};
use verne::calibrate::synthetic::{TYPICAL, joints, measure, perturbed};
use verne::calibrate::{Options, calibrate};
use verne::spec::Machine;

fn main() {
    let nominal = Machine::default_verne();
    let args: Vec<String> = std::env::args().collect();
    let device = match args.get(1).map(|s| s.as_str()) {
        Some("ballbar") => Device::Ballbar,
        Some("probe") => Device::Probe,
        Some("platform") => Device::Platform,
        _ => Device::Tracker,
    };
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let truth = perturbed(&nominal, &TYPICAL, 7);
    let inst = Instrument {
        rotation: Rotation3::new(Vector3::new(0.1, -0.2, 2.0)),
        translation: Vector3::new(2500.0, -400.0, 300.0),
        ball: Vector3::new(80.3, -0.2, 0.1),
    };
    let t0 = std::time::Instant::now();
    let j = joints(&nominal, device, n, 11);
    println!("joints {} in {:?}", j.len(), t0.elapsed());
    let rows = measure(&truth, &j, device, &inst, 0.01, 1e-4, false, 5);
    let t0 = std::time::Instant::now();
    let cal = calibrate(&nominal, &rows, &Options::default());
    println!("calibrate in {:?}", t0.elapsed());
    match cal {
        Err(e) => println!("error: {e}"),
        Ok(c) => {
            println!("sv {:?}", c.identifiability.singular_values);
            for h in &c.identifiability.held {
                println!("held {}: {} {:?}", h.param.key(), h.why, h.combination);
            }
            for w in &c.weak {
                println!("weak {:?}", w);
            }
            for e in &c.estimates {
                println!(
                    "{:14} nominal {:10.4} value {:10.4} truth {:10.4} sigma {:?}",
                    e.param.key(),
                    e.param.shown(e.nominal),
                    e.param.shown(e.value),
                    e.param.shown(e.param.value(&truth)),
                    e.sigma.map(|s| e.param.shown(s))
                );
            }
            println!("corr {:?}", c.correlations);
            println!(
                "before {:?}\nafter {:?}\nholdout {:?}",
                c.before, c.after, c.holdout
            );
            println!(
                "noise {} fk {} + {} it {}",
                c.noise_mm, c.fk_complete, c.fk_followed, c.iterations
            );
        }
    }
    let t0 = std::time::Instant::now();
    let p = plan(
        &nominal,
        &PlanOptions {
            device,
            poses: 30,
            noise: DEFAULT_NOISE,
            ..PlanOptions::default()
        },
    );
    println!("plan in {:?}", t0.elapsed());
    match p {
        Err(e) => println!("plan error {e}"),
        Ok(p) => {
            for (q, s) in &p.sigmas {
                println!("{:14} sigma {:.5}", q.key(), q.shown(*s));
            }
            println!("undetermined {:?}", p.undetermined);
            for h in &p.identifiability.held {
                println!("held {}: {}", h.param.key(), h.why);
            }
            println!(
                "worst {} random median {} ratio {} tip {} {} cands {}",
                p.worst_mm,
                p.random_worst_mm,
                p.worst_mm / p.random_worst_mm,
                p.tip_rms_mm,
                p.tip_max_mm,
                p.candidates
            );
        }
    }
}
