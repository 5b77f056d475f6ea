//! `garnet`: fast, accurate 3D cloth draping. Thin commands over the `garnet` library and
//! the pipeline crates.

mod assets_cmd;
mod bench_cmd;
mod bench_model;
mod body_cmd;
mod compare_cmd;
mod dataset_cmd;
mod dataset_show;
mod dataset_spread;
mod drape_cmd;
mod drape_filter_args;
mod drape_motion;
mod eval_cmd;
mod export_cmd;
mod garment_cmd;
mod garment_sheet;
mod log_lines;
mod model_device;
mod output;
mod pose_args;
mod pose_cmd;
mod shape_args;
mod simulate_cmd;
mod simulate_sheet;
mod train_cmd;
mod view_cmd;

use clap::{Parser, Subcommand};

/// garnet: fast, accurate 3D cloth draping (GarNet, ICCV 2019) in one binary.
///
/// With no command, runs the main job on the embedded defaults: the three shipped GarNet
/// models (models/) drape a T-shirt, a sweater and jeans on a random realistic adult in a
/// procedural pose, written to out/draped-*.glb, out/body.glb and out/drape-*.png.
#[derive(Parser, Debug)]
#[command(name = "garnet", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Fetch, verify and convert the body assets, or show where they are.
    #[command(subcommand)]
    Assets(assets_cmd::AssetsCmd),
    /// Make a body of a given shape and pose: mesh file, picture, or a picture sheet.
    Body(body_cmd::BodyArgs),
    /// Garment templates: make, import, warp onto a body.
    #[command(subcommand)]
    Garment(garment_cmd::GarmentCmd),
    /// Pose files: convert CMU ASF/AMC clips to BVH.
    #[command(subcommand)]
    Pose(pose_cmd::PoseCmd),
    /// Drape a garment template on a body with the cloth simulator.
    Simulate(simulate_cmd::SimulateArgs),
    /// Datasets: check a spec, generate (sharded, resumable), merge, inspect, show, spread.
    #[command(subcommand)]
    Dataset(dataset_cmd::DatasetCmd),
    /// Drape garments on a body with trained GarNet models (milliseconds, no simulation).
    Drape(drape_cmd::DrapeArgs),
    /// Evaluate trained models on a dataset split: the paper's Table 1, Table 2, Figure 4.
    Eval(eval_cmd::EvalArgs),
    /// Train a GarNet network for one garment of a dataset, by a recipe.
    Train(train_cmd::TrainArgs),
    /// Export a training checkpoint as a model to ship, with its model card.
    Export(export_cmd::ExportArgs),
    /// The paper's errors (E_dist, E_norm) between two drapes of one garment mesh.
    Compare(compare_cmd::CompareArgs),
    /// Benchmarks measured in one run, reported with ratios to a reference.
    #[command(subcommand)]
    Bench(bench_cmd::BenchCmd),
    /// Meshes, animations and evaluated drapes in 3D: one self-contained HTML page (offline).
    View(view_cmd::ViewArgs),
}

fn main() {
    // Process-wide malloc tuning for the networks' large temporaries (see model::alloc).
    model::tune_allocator();
    let cli = Cli::parse();
    let result = match &cli.cmd {
        None => drape_cmd::DrapeArgs::main_job().and_then(|a| drape_cmd::run(&a)),
        Some(Cmd::Assets(c)) => assets_cmd::run(c),
        Some(Cmd::Body(a)) => body_cmd::run(a),
        Some(Cmd::Garment(c)) => garment_cmd::run(c),
        Some(Cmd::Pose(c)) => pose_cmd::run(c),
        Some(Cmd::Simulate(a)) => simulate_cmd::run(a),
        Some(Cmd::Dataset(c)) => dataset_cmd::run(c),
        Some(Cmd::Drape(a)) => drape_cmd::run(a),
        Some(Cmd::Eval(a)) => eval_cmd::run(a),
        Some(Cmd::Export(a)) => export_cmd::run(a),
        Some(Cmd::Compare(a)) => compare_cmd::run(a),
        Some(Cmd::Train(a)) => train_cmd::run(a),
        Some(Cmd::Bench(c)) => bench_cmd::run(c),
        Some(Cmd::View(a)) => view_cmd::run(a),
    };
    if let Err(e) = result {
        eprintln!("garnet: error: {e:#}");
        std::process::exit(1);
    }
}
