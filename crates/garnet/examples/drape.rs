//! Drape the shipped GarNet-Local T-shirt on a random realistic adult in a procedural walk,
//! with the library alone, and write the garment and the body as OBJ files.
//!
//! ```sh
//! cargo run --release --example drape
//! ```

use garnet::body::pose::{PoseKind, ProceduralPoseGenerator};
use garnet::body::self_contact::sample_valid_pose;
use garnet::body::shape_sampler::ShapeDistribution;
use garnet::body::BodyModel;
use garnet::{drape, shipped_models_dir, Device, DrapeOptions, GarmentModel};

fn main() -> anyhow::Result<()> {
    // Process-wide malloc tuning for the networks' large temporaries (see model::alloc).
    garnet::model::tune_allocator();
    // The body: a random adult (seed 7) in a procedural walking pose (seed 3).
    let bodies = BodyModel::load()?;
    let shape = ShapeDistribution::default().sample(&bodies, 7)?;
    let target = bodies.shape(&shape.phenotype)?;
    let mut walks = ProceduralPoseGenerator::new(3, PoseKind::Walk);
    let pose = sample_valid_pose(&target, &mut walks, 200)?;

    // The garment: the shipped T-shirt model, on the CPU.
    let model_path = shipped_models_dir().join("tshirt-local.garnet");
    let model = GarmentModel::load(&model_path, &Device::flex())?;
    let result = drape(&[model], &target, &pose, DrapeOptions::default())?;

    let shirt = &result.garments[0];
    let t = shirt.timings;
    println!(
        "{} on a {:.1} cm body: {} vertices, warp {:.2} ms, network {:.1} ms, {} pushed out",
        shirt.kind,
        target.height() * 100.0,
        shirt.mesh.vertices.len(),
        t.warp_ms,
        t.network_ms,
        shirt.pushed_out
    );
    std::fs::create_dir_all("out")?;
    garnet::geom::io::write_mesh("out/example-tshirt.obj", &shirt.mesh)?;
    garnet::geom::io::write_mesh("out/example-body.obj", &result.body)?;
    println!("wrote out/example-tshirt.obj and out/example-body.obj");
    Ok(())
}
