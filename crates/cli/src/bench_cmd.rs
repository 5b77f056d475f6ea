//! `garnet bench`: timings measured inside one run, reported with ratios to a
//! reference measured in the same run so that noisy machines still compare.

use std::time::{Duration, Instant};

use body::{BodyModel, Phenotype, Pose, Skinning};
use clap::Subcommand;

use crate::model_device::DeviceArg;

/// What to benchmark.
#[derive(Subcommand, Debug)]
pub enum BenchCmd {
    /// Loading, shaping and posing the body (LBS and DQS, one core and all cores).
    Body {
        /// Repetitions per measurement (the median is reported).
        #[arg(long, default_value_t = 50)]
        repeat: usize,
    },
    /// The simulator: a T-shirt draped on a random posed body, to rest.
    Sim {
        /// Template edge length, metres (0.01: the paper's ~10k-vertex garment).
        #[arg(long, default_value_t = 0.01)]
        edge: f32,
        /// Seed of the random shape and procedural pose.
        #[arg(long, default_value_t = 5)]
        seed: u64,
        /// Drapes of each setting, taken in turn (the medians are reported).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Simulator settings of the drape timed (a spec or settings file, as
        /// `garnet simulate --simulator`); the simulator's defaults when absent.
        #[arg(long, value_name = "FILE.toml")]
        simulator: Option<std::path::PathBuf>,
        /// Simulator settings of a reference drape timed in turn with it (e.g. an older
        /// benchmark's spec), reported as a ratio.
        #[arg(long, value_name = "FILE.toml")]
        reference: Option<std::path::PathBuf>,
    },
    /// GarNet: forward time per drape of each variant at two garment sizes, and a
    /// training step, against the DQS warp of the 1 cm T-shirt.
    Model {
        /// Repetitions per measurement (the median is reported).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Garment vertex counts (comma-separated).
        #[arg(long, value_delimiter = ',', default_value = "3000,10000")]
        sizes: Vec<usize>,
        /// Also drape the T-shirt on the benchmark body with GarNet-Local and with the
        /// simulator: the time of each on the same drape and their ratio.
        #[arg(long)]
        simulator: bool,
        /// Edge length of the reference T-shirt, metres (0.01: ~8k vertices).
        #[arg(long, default_value_t = 0.01)]
        edge: f32,
        /// Where the networks run.
        #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
        device: DeviceArg,
        /// Time networks of a training recipe's widths and inputs (its `[network]`, each
        /// variant in turn) instead of the defaults; the same-drape rows then compare
        /// GarNet-Local of this recipe with the paper's.
        #[arg(long = "recipe", value_name = "FILE.toml")]
        config: Option<std::path::PathBuf>,
    },
}

pub fn run(cmd: &BenchCmd) -> anyhow::Result<()> {
    match cmd {
        BenchCmd::Body { repeat } => bench_body(*repeat.max(&3)),
        BenchCmd::Sim {
            edge,
            seed,
            runs,
            simulator,
            reference,
        } => bench_sim(
            *edge,
            *seed,
            (*runs).max(1),
            simulator.as_deref(),
            reference.as_deref(),
        ),
        BenchCmd::Model {
            runs,
            sizes,
            simulator,
            edge,
            device,
            config,
        } => crate::bench_model::bench_model(
            *runs,
            sizes,
            *simulator,
            *edge,
            *device,
            config.as_deref(),
        ),
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

/// A T-shirt of `edge` metres, the template body, a random body (`seed`) in a procedural
/// walk pose, and the median time of the DQS warp of the T-shirt onto it (the reference of
/// the simulator and network benchmarks).
pub struct TshirtCase {
    /// The T-shirt template (metres).
    pub template: garment::GarmentTemplate,
    /// The body the template was made on.
    pub template_body: body::ShapedBody,
    /// The random body.
    pub target: body::ShapedBody,
    /// Its procedural walk pose (free of self-intersection).
    pub pose: Pose,
    /// Median wall time of the DQS warp of the template onto the posed target.
    pub warp: Duration,
}

impl TshirtCase {
    /// Builds the case: template with `edge` metres, random shape and pose from `seed`.
    pub fn new(model: &BodyModel, edge: f32, seed: u64) -> anyhow::Result<Self> {
        use body::pose::{PoseKind, ProceduralPoseGenerator};
        use body::shape_sampler::ShapeDistribution;
        use garment::{build_template, CutParams, GarmentKind};

        let kind = GarmentKind::Tshirt;
        let template = build_template(model, &kind, &CutParams::default_for(&kind), edge)?;
        let template_body = model.shape(&template.body_phenotype)?;
        let target = model.shape(&ShapeDistribution::default().sample(model, seed)?.phenotype)?;
        let mut generator = ProceduralPoseGenerator::new(seed, PoseKind::Walk);
        let pose = body::self_contact::sample_valid_pose(&target, &mut generator, 200)?;
        let warp = median_time(20, || {
            garment::warp::warp(&template, &target, &pose, Skinning::Dqs).expect("warp")
        });
        Ok(Self {
            template,
            template_body,
            target,
            pose,
            warp,
        })
    }

    /// Drapes the T-shirt on the posed body with the simulator (default options, except
    /// that penetration is reported instead of failing the drape).
    pub fn simulate(&self) -> anyhow::Result<sim::drape::Drape> {
        self.simulate_with(&sim::drape::DrapeOptions::default())
    }

    /// Drapes the T-shirt on the posed body with the simulator settings `opts`, except
    /// that penetration is reported instead of failing the drape.
    pub fn simulate_with(
        &self,
        opts: &sim::drape::DrapeOptions,
    ) -> anyhow::Result<sim::drape::Drape> {
        let opts = sim::drape::DrapeOptions {
            max_penetration: f32::INFINITY,
            ..opts.clone()
        };
        Ok(sim::drape::drape(
            &self.template,
            &self.template_body,
            &self.target,
            &self.pose,
            &opts,
            &mut |_, _, _| {},
        )?)
    }
}

/// The drape of the median wall time of `drapes`.
fn median_drape(mut drapes: Vec<sim::drape::Drape>) -> sim::drape::Drape {
    drapes.sort_by(|a, b| a.stats.wall_time_s.total_cmp(&b.stats.wall_time_s));
    drapes.swap_remove(drapes.len() / 2)
}

fn bench_sim(
    edge: f32,
    seed: u64,
    runs: usize,
    simulator: Option<&std::path::Path>,
    reference: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    use dataset::simulator::{load_drape_options, load_drape_options_or_default};
    let opts = load_drape_options_or_default(simulator)?;
    let ref_opts = reference.map(load_drape_options).transpose()?;
    let model = BodyModel::load()?;
    let case = TshirtCase::new(&model, edge, seed)?;
    let (template, warp) = (&case.template, case.warp);
    // The two settings in turn, so that a machine's drift affects both alike.
    let (mut drapes, mut refs) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        drapes.push(case.simulate_with(&opts)?);
        if let Some(r) = &ref_opts {
            refs.push(case.simulate_with(r)?);
        }
    }
    let result = median_drape(drapes);
    let s = &result.stats;
    let steps = s.animation_steps + s.settle_steps;
    let per_step = s.wall_time_s / steps.max(1) as f64;
    let name = |p: Option<&std::path::Path>| {
        p.map_or("the simulator's defaults".to_string(), |p| {
            p.display().to_string()
        })
    };
    println!(
        "garnet bench sim: {}-vertex T-shirt ({} cm edges) on random shape {seed} in a procedural walk pose, {} threads, medians of {runs}; settings: {}",
        template.mesh.vertices.len(),
        edge * 100.0,
        rayon::current_num_threads(),
        name(simulator)
    );
    println!("| measure | value | ratio to DQS warp (M) |");
    println!("|---|---:|---:|");
    let ms = |d: f64| d * 1e3;
    println!(
        "| DQS warp (reference) | {:.2} ms | 1 |",
        ms(warp.as_secs_f64())
    );
    println!(
        "| time per step | {:.1} ms | {:.0} |",
        ms(per_step),
        per_step / warp.as_secs_f64()
    );
    println!(
        "| steps (animation + settling) | {} + {} | |",
        s.animation_steps, s.settle_steps
    );
    println!(
        "| wall time to rest | {:.2} s | {:.0} |",
        s.wall_time_s,
        s.wall_time_s / warp.as_secs_f64()
    );
    println!("{}", s.summary());
    if !refs.is_empty() {
        let r = median_drape(refs);
        let rs = &r.stats;
        println!(
            "reference ({}): {:.2} s, {} + {} steps, {}; time against the reference: {:.2}",
            name(reference),
            rs.wall_time_s,
            rs.animation_steps,
            rs.settle_steps,
            if rs.converged {
                "at rest"
            } else {
                "not at rest"
            },
            s.wall_time_s / rs.wall_time_s
        );
    }
    Ok(())
}
