use nalgebra::Vector3;
use verne::machine::Machine;
fn main() {
    let m = Machine::default_verne();
    for rho in [
        Vector3::new(674.0, 685.0, 250.0),
        Vector3::new(520.690065682, 228.944160917, 228.769607739),
    ] {
        let modes = verne::module_fk::solve(&m, &rho);
        println!("FK {:?}: {}", rho, modes.len());
        for md in &modes {
            println!(
                "  a={:.12} p=({:.6},{:.6},{:.6}) {:?} {}",
                md.pose.alpha, md.pose.p.x, md.pose.p.y, md.pose.p.z, md.config, md.verdict
            );
        }
    }
    for p in [
        Vector3::new(-240.0, -86.0, 1000.0),
        Vector3::new(-300.0, 0.0, 1100.0),
    ] {
        let br = verne::module_ik::solve(&m, &p);
        println!("IK {:?}: {}", p, br.len());
        for b in &br {
            println!(
                "  a={:.9} rho=({:.6},{:.6},{:.6}) {:?} {}",
                b.alpha, b.rho.x, b.rho.y, b.rho.z, b.config, b.verdict
            );
        }
    }
}
