//! `garnet bench model`: GarNet's forward time per drape (batch 1) for each variant at
//! given garment sizes on the 13,380-vertex body, and a training step, each with its ratio
//! to the DQS warp of the 1 cm T-shirt measured in the same run.

use body::BodyModel;
use body::Skinning;
use burn::prelude::Device;
use model::bench::{bench_forward, bench_train_step, Timing};
use model::{Draper, GarNetConfig, ModelSetup, Variant};

use crate::bench_cmd::TshirtCase;
use crate::model_device::DeviceArg;
use garnet::drape::{beside_push_out_collider, push_out_gap, PUSH_OUT_WITHIN};
use std::path::Path;

/// Body vertices the networks see (the body model's mesh).
const BODY_VERTICES: usize = 13380;

/// Runs the benchmark and prints a Markdown table; the reference is the DQS warp of a T-shirt
/// with `edge` metres; with `simulator`, also the GarNet-Local and simulator times of the same
/// drape of that T-shirt. The networks run on `device` (the DQS warp and the simulator always
/// on the CPU) with the widths and inputs of the `config` recipe (its `[network]`), or the
/// defaults.
pub fn bench_model(
    runs: usize,
    sizes: &[usize],
    simulator: bool,
    edge: f32,
    device: DeviceArg,
    config: Option<&Path>,
) -> anyhow::Result<()> {
    let networks = BenchNetworks::new(config)?;
    let backend = device.backend_name();
    let device = device.device()?;
    let body_model = BodyModel::load()?;
    let reference = TshirtCase::new(&body_model, edge, 5)?;
    let warp_ms = reference.warp.as_secs_f64() * 1e3;
    println!(
        "garnet bench model: {backend}, {} CPU threads; body {BODY_VERTICES} vertices; \
         reference: DQS warp of the {}-vertex T-shirt",
        rayon::current_num_threads(),
        reference.template.mesh.vertices.len()
    );
    println!("| measure | variant | garment vertices | parameters | median (min..max) ms | CPU ms | ratio to DQS warp |");
    println!("|---|---|---:|---:|---:|---:|---:|");
    println!(
        "| DQS warp (reference) | | {} | | {warp_ms:.2} | | 1 |",
        reference.template.mesh.vertices.len()
    );
    if let Some(path) = config {
        println!(
            "networks of {}; the synthetic rows without body contact (their ellipsoid body \
             has no faces), the same-drape rows with every input of the file",
            path.display()
        );
    }
    for &n in sizes {
        for variant in Variant::ALL {
            let b = bench_forward(
                &networks.synthetic(variant),
                n,
                BODY_VERTICES,
                runs,
                &device,
            )?;
            let t = &b.drape;
            println!(
                "| drape (forward, batch 1) | {} | {} | {} | {:.1} ({:.1}..{:.1}) | {:.1} | {:.0} |",
                b.variant,
                b.n_garment,
                b.params,
                t.median_ms,
                t.min_ms,
                t.max_ms,
                t.cpu_ms.unwrap_or(f64::NAN),
                t.median_ms / warp_ms
            );
        }
    }
    if simulator {
        same_drape(&reference, &body_model, runs, &device, &networks)?;
    }
    for &n in sizes {
        for variant in Variant::ALL {
            let b = bench_train_step(
                &networks.synthetic(variant),
                n,
                BODY_VERTICES,
                1,
                runs.clamp(1, 3),
                &device,
            )?;
            let t = &b.step;
            println!(
                "| training step (batch 1) | {} | {} | | {:.1} ({:.1}..{:.1}) | {:.1} | {:.0} |",
                b.variant,
                b.n_garment,
                t.median_ms,
                t.min_ms,
                t.max_ms,
                t.cpu_ms.unwrap_or(f64::NAN),
                t.median_ms / warp_ms
            );
        }
    }
    Ok(())
}

/// The networks a run of the benchmark times: the defaults, or a recipe's widths and inputs
/// (read once).
struct BenchNetworks {
    /// Each variant's config, in the order of [`Variant::ALL`].
    configs: Vec<GarNetConfig>,
    from_file: bool,
}

impl BenchNetworks {
    /// The networks of the recipe `file`'s widths and inputs (each variant in turn), or the
    /// defaults.
    fn new(file: Option<&Path>) -> anyhow::Result<Self> {
        let recipe = file.map(model::Recipe::load).transpose()?;
        let configs = Variant::ALL
            .iter()
            .map(|&v| match &recipe {
                Some(r) => r.network_config().map(|c| GarNetConfig { variant: v, ..c }),
                None => Ok(GarNetConfig::new(v)),
            })
            .collect::<model::Result<_>>()?;
        Ok(Self {
            configs,
            from_file: file.is_some(),
        })
    }

    /// `variant` with the file's widths and inputs, or the defaults.
    fn config(&self, variant: Variant) -> &GarNetConfig {
        let i = Variant::ALL.iter().position(|&v| v == variant);
        &self.configs[i.expect("Variant::ALL holds every variant")]
    }

    /// [`BenchNetworks::config`] for the synthetic ellipsoid body, which has no faces for the
    /// body-contact features.
    fn synthetic(&self, variant: Variant) -> GarNetConfig {
        self.config(variant).clone().with_body_contact(false)
    }

    /// The GarNet-Local networks of the same-drape rows: the paper's, then the file's (the
    /// defaults with our body-contact features when no file is given).
    fn same_drape(&self) -> [GarNetConfig; 2] {
        let paper = GarNetConfig::new(Variant::Local);
        let ours = if self.from_file {
            self.config(Variant::Local).clone()
        } else {
            paper.clone().with_body_contact(true)
        };
        [paper, ours]
    }
}

/// GarNet-Local (the time does not depend on the trained values) and the simulator on the
/// same drape: the benchmark's T-shirt on its posed body. Prints a row each and their ratio.
/// `bodies` shapes the template body an anchored network's anchors are made on.
fn same_drape(
    case: &TshirtCase,
    bodies: &BodyModel,
    runs: usize,
    device: &Device,
    networks: &BenchNetworks,
) -> anyhow::Result<()> {
    let sim = case.simulate()?;
    let body = &sim.body.vertices;
    let warped = garment::warp::warp(&case.template, &case.target, &sim.pose, Skinning::Dqs)?;
    let n = case.template.mesh.vertices.len();
    let sim_ms = sim.stats.wall_time_s * 1e3;
    let warp_ms = case.warp.as_secs_f64() * 1e3;
    // The paper's GarNet-Local, then ours (the body-contact features' nearest-vertex search
    // and body normals run per drape).
    for config in networks.same_drape() {
        let setup = ModelSetup::new(config, case.template.mesh.clone(), body)?
            .with_body_faces(sim.body.faces.clone())?;
        let name = setup.config.method_name();
        // An anchored network's M is placed on the posed body per drape, timed with it.
        let anchors = garnet::base_anchors(setup.config.base, &case.template, bodies)?;
        let draper = Draper::new(setup.config.init(device)?, setup, device)?;
        let net = || match &anchors {
            Some(a) => draper.drape(body, &a.place(&sim.body)),
            None => draper.drape(body, &warped.vertices),
        };
        let t = Timing::measure(runs, || net().map(|_| ()))?;
        // As `garnet drape` runs it: the network beside the build of the body's collider,
        // then the push-out of the vertices left inside the body.
        let with_push = Timing::measure(runs, || {
            let (pred, collider) = beside_push_out_collider(Some(&sim.body), net);
            let collider = collider.map_err(|e| model::ModelError::InvalidInput(e.to_string()))?;
            let mut g = pred?;
            if let Some((c, _)) = collider {
                c.push_out(&mut g, PUSH_OUT_WITHIN, push_out_gap());
            }
            Ok(())
        })?;
        for (what, t) in [("", &t), (" with the push-out", &with_push)] {
            println!(
                "| same drape: {name}{what} | local | {n} | | {:.1} ({:.1}..{:.1}) | {:.1} | {:.0} |",
                t.median_ms,
                t.min_ms,
                t.max_ms,
                t.cpu_ms.unwrap_or(f64::NAN),
                t.median_ms / warp_ms
            );
        }
        let total = with_push.median_ms;
        println!(
            "{name} drapes the {n}-vertex T-shirt in {:.1} ms ({total:.1} ms with the \
             push-out), {:.0}x faster than the simulator on the same drape ({:.2} s); target \
             under 150 ms: {}",
            t.median_ms,
            sim_ms / total,
            sim.stats.wall_time_s,
            if total < 150.0 { "met" } else { "missed" }
        );
    }
    println!(
        "| same drape: simulator to rest | | {n} | | {sim_ms:.0} | | {:.0} |",
        sim_ms / warp_ms
    );
    Ok(())
}
