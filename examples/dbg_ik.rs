use verne::hard_sets::*;
use verne::machine::Machine;
use verne::module_ik;
fn main() {
    let mut machines = vec![Machine::default_verne()];
    machines.extend(random_geometries(10, 99));
    let mut rng = Sampler::new(11);
    let mut shown = 0;
    for m in &machines {
        for set in HardSet::ALL {
            let mut built = 0;
            for _ in 0..60 {
                if built >= 3 {
                    break;
                }
                let Some((rho0, mode)) = random_slider_start(m, &mut rng) else {
                    continue;
                };
                let dir = rng.direction();
                let cs = construct_from_sliders(m, set, &rho0, &dir, &mode, 300.0);
                if cs.is_empty() {
                    continue;
                }
                built += 1;
                for c in cs {
                    let ik = module_ik::solve(m, &c.p);
                    if !ik.certificate.proved() && shown < 3 {
                        shown += 1;
                        println!(
                            "{} {:?} off {:e} P {:?} alpha {} n {}",
                            m.name,
                            set,
                            c.offset_mm,
                            c.p,
                            c.alpha,
                            ik.len()
                        );
                        let k = module_ik::eq9_coefficients(&m.module, &c.p);
                        let sc = k.iter().fold(0.0f64, |a, b| a.max(b.abs()));
                        println!("  cubic {:?}", k.map(|x| x / sc));
                        println!(
                            "  roots {:?}",
                            verne::cubic::cubic_roots_in(&k.map(|x| x / sc), -1.0, 1.0)
                        );
                    }
                }
            }
        }
    }
}
