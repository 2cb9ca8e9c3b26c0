//! Per-joint rotation error of a model on one take, clean and noisy (a
//! diagnostic).
//!
//! cargo run --release -p mocap-studies --example clean_joint_errors -- TAKE.bvh [MODEL]

use mocap_clean::{add_random_noise_sigma, CleanModel, RandomNoise};
use mocap_core::io::bvh::read_bvh;
use mocap_core::metrics::joint_rotation_errors_degrees;
use rand::SeedableRng;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let motion = read_bvh(std::path::Path::new(&args[0]))?;
    let model = match args.get(1) {
        Some(p) => CleanModel::load(std::path::Path::new(p), Default::default())?,
        None => CleanModel::load_default(Default::default())?,
    };
    let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(1);
    let noisy = add_random_noise_sigma(&motion, 5.0, &RandomNoise::default(), &mut rng);
    let on_clean = model.clean(&motion, None)?;
    let on_noisy = model.clean(&noisy, None)?;
    let e_clean = joint_rotation_errors_degrees(&motion, &on_clean)?;
    let e_noisy_in = joint_rotation_errors_degrees(&motion, &noisy)?;
    let e_noisy_out = joint_rotation_errors_degrees(&motion, &on_noisy)?;
    println!("joint | model on clean | noisy | model on noisy");
    for (j, joint) in motion.skeleton().joints().iter().enumerate() {
        println!(
            "{:12} | {:6.2} | {:6.2} | {:6.2}",
            joint.name, e_clean[j], e_noisy_in[j], e_noisy_out[j]
        );
    }
    Ok(())
}
