//! `garnet bench`: timings measured inside one run, reported with ratios to a
//! reference measured in the same run so that noisy machines still compare.

use std::time::{Duration, Instant};

use body::{BodyModel, Phenotype, Pose, Skinning};
use clap::Subcommand;

/// What to benchmark.
#[derive(Subcommand, Debug)]
pub enum BenchCmd {
    /// Loading, shaping and posing the body (LBS and DQS, one core and all cores).
    Body {
        /// Repetitions per measurement (the median is reported).
        #[arg(long, default_value_t = 50)]
        repeat: usize,
    },
}

pub fn run(cmd: &BenchCmd) -> anyhow::Result<()> {
    match cmd {
        BenchCmd::Body { repeat } => bench_body(*repeat.max(&3)),
    }
}

/// Median wall time of `repeat` calls of `f` after one warm-up call.
fn median_time<T>(repeat: usize, mut f: impl FnMut() -> T) -> Duration {
    std::hint::black_box(f());
    let mut times: Vec<Duration> = (0..repeat)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed()
        })
        .collect();
    times.sort();
    times[times.len() / 2]
}

fn bench_body(repeat: usize) -> anyhow::Result<()> {
    let cache = body::assets::ensure_body_cache()?;
    let load = median_time(repeat.min(10), || {
        BodyModel::from_file(&cache).expect("body file")
    });
    let model = BodyModel::from_file(&cache)?;
    let phenotype = Phenotype {
        gender: 0.2,
        weight: 0.7,
        ..Default::default()
    };
    let shape = median_time(repeat, || model.shape(&phenotype).expect("shape"));
    let body = model.shape(&phenotype)?;
    // A non-trivial pose: the T-pose plus a bent elbow and knee.
    let mut pose: Pose = model.tpose();
    for (name, angle) in [("LeftForeArm", 1.0f32), ("RightLeg", -0.8)] {
        let b = body
            .rig
            .index(name)
            .ok_or_else(|| anyhow::anyhow!("rig has no {name}"))?;
        pose.rotations[b] *= glam::Quat::from_rotation_x(angle);
    }
    let one_core = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let pose_time =
        |method: Skinning| median_time(repeat, || body.posed(&pose, method).expect("pose"));
    let lbs_1 = one_core.install(|| pose_time(Skinning::Lbs));
    let dqs_1 = one_core.install(|| pose_time(Skinning::Dqs));
    let dqs_n = pose_time(Skinning::Dqs);
    let fk = median_time(repeat, || body.rig.skinning_transforms(&pose));
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!("garnet bench body: 13380-vertex body, median of {repeat} runs");
    println!("| step | time (ms) | ratio to LBS pose, 1 core |");
    println!("|---|---:|---:|");
    let rows = [
        ("load body file", load),
        ("shape (blend targets + rig)", shape),
        ("forward kinematics (31 bones)", fk),
        ("pose LBS, 1 core (reference)", lbs_1),
        ("pose DQS, 1 core", dqs_1),
        (
            &*format!("pose DQS, {} cores", rayon::current_num_threads()),
            dqs_n,
        ),
    ];
    for (name, t) in rows {
        println!("| {name} | {:.3} | {:.2} |", ms(t), ms(t) / ms(lbs_1));
    }
    let target = 5.0;
    println!(
        "DQS posing on one core: {:.3} ms ({} the {target} ms target)",
        ms(dqs_1),
        if ms(dqs_1) < target {
            "meets"
        } else {
            "misses"
        }
    );
    Ok(())
}
