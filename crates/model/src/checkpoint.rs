//! Checkpoints: everything a drape needs (config, weights, garment template, body sampling)
//! and, for resuming training, the optimiser state and the training progress, in one file.
//!
//! Format (`.garnet`, format name `garnet-model-2`): one safetensors file with
//!
//! | tensor | dtype | shape | holds |
//! |---|---|---|---|
//! | `model` | U8 | `[L]` | the network parameters as burn's burnpack bytes (`Module::into_record`) |
//! | `optimizer` | U8 | `[L2]` | optional: the Adam state as burnpack bytes (`ModuleOptimizer::into_bytes`) |
//! | `template.vertices` | F32 | `[N,3]` | the garment template mesh, metres |
//! | `template.faces` | U32 | `[F,3]` | its triangles |
//! | `body.stream` | U32 | `[P]` | the body vertices the body stream sees, farthest-point order |
//! | `garment.file` | U8 | `[L3]` | optional: the `.garment` template file M is warped with |
//! | `body.faces` | U32 | `[F,3]` | optional: the body's triangles (networks with body-contact features) |
//!
//! and metadata: `format`, `config` ([`GarNetConfig`], JSON), `loss` ([`LossConfig`], JSON),
//! `state` ([`TrainState`], JSON), `body.n_vertices` (V), `body.n_centres` (GarNet-Local's
//! kept points, a prefix of `body.stream`), `body.skinning` (`lbs` or `dqs`), optionally
//! `recipe` (the [`Recipe`] it was trained by, TOML) with `recipe.command`, and `checksum`:
//! the SHA-256 of every tensor (name, a zero byte, its bytes; in name order), checked on
//! load, so a file whose weights were damaged is refused. Parameters are stored bit for bit,
//! so a reloaded network gives bit-identical outputs. Files are written to a temporary file
//! and renamed.

use std::collections::HashMap;
use std::path::Path;

use burn::optim::ModuleOptimizer;
use burn::prelude::*;
use burn::store::ModuleRecord;
use burn::tensor::Bytes;
use geom::io::le::typed_tensor;
use glam::Vec3;
use safetensors::{tensor::TensorView, Dtype, SafeTensors};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::batch::InputSpec;
use crate::config::GarNetConfig;
use crate::epoch_progress::EpochProgress;
use crate::error::{ModelError, Result};
use crate::garnet::GarNet;
use crate::local::BodySampling;
use crate::loss::LossConfig;
use crate::recipe::{Recipe, RecipeRecord};
use crate::schedule::{CosineSchedule, TimeBudget};

/// The format name in a checkpoint's metadata.
pub const FORMAT: &str = "garnet-model-2";

/// What a network needs besides its weights: the architecture, the garment template it was
/// trained for (its vertex count fixes N, its faces the topology) and the body sampling (which
/// fixes the body vertex count V).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSetup {
    /// Architecture.
    pub config: GarNetConfig,
    /// Garment template mesh `[N]` vertices (metres) and `[F]` faces.
    pub template: geom::TriMesh,
    /// The body points the network sees.
    pub body_sampling: BodySampling,
    /// The garment template file (`.garment` bytes: weights, rig, template body) the
    /// network's input M is warped with, so a checkpoint alone can drape; opaque here.
    pub garment_file: Option<Vec<u8>>,
    /// How the bodies it learned from were posed: [`BODY_SKINNINGS`] names, `"lbs"` (linear
    /// blending) or `"dqs"` (dual quaternions), the skinning of the dataset's simulator.
    /// A body given to the network must be posed the same way.
    pub body_skinning: String,
    /// The body's faces `[F]` (indices below V), which a network with body-contact features
    /// (see [`GarNetConfig::body_contact`]) needs for the body normals; may be absent
    /// otherwise.
    pub body_faces: Option<Vec<[u32; 3]>>,
}

/// The names [`ModelSetup::body_skinning`] may take.
pub const BODY_SKINNINGS: [&str; 2] = ["lbs", "dqs"];

/// Fails on a body skinning name not in [`BODY_SKINNINGS`].
fn known_body_skinning(name: &str) -> Result<()> {
    if BODY_SKINNINGS.contains(&name) {
        Ok(())
    } else {
        Err(ModelError::InvalidInput(format!(
            "body skinning '{name}' is not one of {BODY_SKINNINGS:?}"
        )))
    }
}

impl ModelSetup {
    /// The setup of `config` for the garment `template`, sampling the body points on
    /// `reference_body` (`[V]`, metres; any body of the dataset, e.g. the template body).
    pub fn new(
        config: GarNetConfig,
        template: geom::TriMesh,
        reference_body: &[Vec3],
    ) -> Result<Self> {
        let mut config = config;
        config.validate()?;
        template.validate()?;
        let n = template.vertices.len().max(1) as f32;
        let centroid = template.vertices.iter().copied().sum::<Vec3>() / n;
        config.input_centre = centroid.to_array().to_vec();
        let body_sampling = BodySampling::farthest_point(
            reference_body,
            config.body_subsample,
            config.body_downsample,
        )?;
        Ok(ModelSetup {
            config,
            template,
            body_sampling,
            garment_file: None,
            body_skinning: BODY_SKINNINGS[0].into(),
            body_faces: None,
        })
    }

    /// This setup with the body's faces `[F]` (see [`ModelSetup::body_faces`]); fails on an
    /// index not below the body vertex count V.
    pub fn with_body_faces(mut self, faces: Vec<[u32; 3]>) -> Result<Self> {
        geom::adjacency::check_indices(self.body_sampling.n_body, &faces)?;
        self.body_faces = Some(faces);
        Ok(self)
    }

    /// This setup for bodies posed with the skinning named `name` (see
    /// [`ModelSetup::body_skinning`]); fails on a name not in [`BODY_SKINNINGS`].
    pub fn with_body_skinning(mut self, name: &str) -> Result<Self> {
        known_body_skinning(name)?;
        self.body_skinning = name.to_string();
        Ok(self)
    }

    /// This setup carrying the garment template file `bytes` (see [`ModelSetup::garment_file`]).
    pub fn with_garment_file(mut self, bytes: Vec<u8>) -> Self {
        self.garment_file = Some(bytes);
        self
    }

    /// How samples become this network's inputs.
    pub fn input_spec(&self) -> InputSpec {
        InputSpec {
            sampling: self.body_sampling.clone(),
            local: self
                .config
                .variant
                .has_local()
                .then_some((self.config.pool_neighbours, self.config.local_neighbours)),
            canonical_rest: Some(self.template.vertices.clone()),
            contact_faces: self
                .config
                .body_contact
                .then(|| self.body_faces.clone())
                .flatten(),
            rest_input: self
                .config
                .rest_input
                .then(|| self.template.vertices.clone()),
        }
    }

    /// Fails when the body skinning is not one of [`BODY_SKINNINGS`], the template or the
    /// sampling is invalid, or the sampling has fewer kept points than GarNet-Local's
    /// neighbour count.
    pub fn validate(&self) -> Result<()> {
        known_body_skinning(&self.body_skinning)?;
        self.config.validate()?;
        self.template.validate()?;
        self.body_sampling.validate()?;
        match &self.body_faces {
            Some(faces) => geom::adjacency::check_indices(self.body_sampling.n_body, faces)?,
            None if self.config.body_contact => {
                return Err(ModelError::InvalidInput(
                    "a network with body-contact features needs the body's faces".into(),
                ))
            }
            None => {}
        }
        if self.config.variant.has_local()
            && (self.body_sampling.n_centres < self.config.local_neighbours
                || self.body_sampling.len() < self.config.pool_neighbours)
        {
            return Err(ModelError::InvalidInput(format!(
                "GarNet-Local needs at least {} kept and {} stream body points, the sampling \
                 has {} and {}",
                self.config.local_neighbours,
                self.config.pool_neighbours,
                self.body_sampling.n_centres,
                self.body_sampling.len()
            )));
        }
        Ok(())
    }
}

/// Training progress stored with a checkpoint.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrainState {
    /// Epochs completed.
    pub epoch: usize,
    /// Optimiser steps taken.
    pub step: u64,
    /// Learning rate of the last step.
    pub lr: f64,
    /// Best validation E_dist so far, centimetres (`None` before the first validation).
    pub best_e_dist_cm: Option<f32>,
    /// The validation set `best_e_dist_cm` was measured on (`dataset:garment:count`), when
    /// the run named it (see [`crate::Trainer::set_validation_set`]).
    pub validation: Option<String>,
    /// Joint L2 norm the gradients are clipped to (`None`: no clipping).
    pub max_grad_norm: Option<f32>,
    /// Learning-rate schedule (`None`: the rate stays as set).
    pub schedule: Option<CosineSchedule>,
    /// A compute budget that ends the run and sets its rate (see [`TimeBudget`]); it
    /// overrides `schedule`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<TimeBudget>,
    /// CPU time the run's training steps have used so far, over every sitting, seconds.
    #[serde(default)]
    pub train_cpu_s: f64,
    /// In a mid-epoch checkpoint, how far epoch `epoch + 1` has gone (see
    /// [`crate::trainer::MID_EPOCH_CHECKPOINT`]); `None` at an epoch's end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partial: Option<EpochProgress>,
}

/// `stored`, a JSON object of `T`'s fields, read with every field it leaves out taken from
/// `defaults`: an option added to a config after a file was written reads as its default.
fn with_defaults<T>(stored: &str, defaults: T) -> serde_json::Result<T>
where
    T: Serialize + serde::de::DeserializeOwned,
{
    let mut merged = serde_json::to_value(defaults)?;
    let stored: serde_json::Value = serde_json::from_str(stored)?;
    match (merged.as_object_mut(), stored) {
        (Some(all), serde_json::Value::Object(given)) => all.extend(given),
        (_, other) => merged = other,
    }
    serde_json::from_value(merged)
}

/// A stored [`GarNetConfig`] (see [`with_defaults`]; the defaults of its variant).
fn stored_config(stored: &str) -> serde_json::Result<GarNetConfig> {
    #[derive(Deserialize)]
    struct Named {
        variant: crate::config::Variant,
    }
    let named: Named = serde_json::from_str(stored)?;
    with_defaults(stored, GarNetConfig::new(named.variant))
}

/// A checkpoint read from disk; [`Checkpoint::model`] and [`Checkpoint::optimizer`] rebuild
/// the network and the optimiser.
pub struct Checkpoint {
    /// Architecture, template, body sampling.
    pub setup: ModelSetup,
    /// Loss weights the network was trained with.
    pub loss: LossConfig,
    /// Training progress.
    pub state: TrainState,
    /// The recipe it was trained by, when it was trained by one.
    pub recipe: Option<RecipeRecord>,
    model_bytes: Vec<u8>,
    optimizer_bytes: Option<Vec<u8>>,
}

impl std::fmt::Debug for Checkpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Checkpoint")
            .field("setup", &self.setup)
            .field("state", &self.state)
            .field("model_bytes", &self.model_bytes.len())
            .field("has_optimizer", &self.optimizer_bytes.is_some())
            .finish()
    }
}

fn to_le<T: Copy, const W: usize>(values: impl Iterator<Item = T>, f: fn(T) -> [u8; W]) -> Vec<u8> {
    values.flat_map(f).collect()
}

fn json<T: Serialize>(value: &T) -> Result<String> {
    serde_json::to_string(value).map_err(|e| ModelError::InvalidInput(e.to_string()))
}

/// The SHA-256 (lower-case hex) of `tensors` (name, bytes): each name, a zero byte and its
/// bytes, in name order; what a checkpoint's `checksum` holds.
fn tensors_checksum<'a>(tensors: impl IntoIterator<Item = (&'a str, &'a [u8])>) -> String {
    let mut sorted: Vec<_> = tensors.into_iter().collect();
    sorted.sort_by_key(|(name, _)| *name);
    let mut hash = Sha256::new();
    for (name, bytes) in sorted {
        hash.update(name.as_bytes());
        hash.update([0u8]);
        hash.update(bytes);
    }
    hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Writes `model` (any device) with `setup`, `loss`, `state`, optionally the optimiser state
/// and the recipe it was trained by to `path` (atomically: a temporary file, then a rename).
pub fn save_checkpoint(
    path: &Path,
    model: &GarNet,
    optim: Option<&ModuleOptimizer>,
    setup: &ModelSetup,
    loss: &LossConfig,
    state: &TrainState,
    recipe: Option<&RecipeRecord>,
) -> Result<()> {
    let bad = |m: String| ModelError::checkpoint(path, m);
    setup.validate()?;
    if model.variant() != setup.config.variant {
        return Err(bad(format!(
            "network is GarNet-{} but its config says {}",
            model.variant().name(),
            setup.config.variant.name()
        )));
    }
    let model_bytes = model
        .clone()
        .into_record()
        .into_bytes()
        .map_err(|e| bad(e.to_string()))?;
    let optim_bytes = match optim {
        Some(o) => Some(o.into_bytes().map_err(|e| bad(e.to_string()))?),
        None => None,
    };
    let t = &setup.template;
    let mut tensors: Vec<(&str, Dtype, Vec<usize>, Vec<u8>)> = vec![
        (
            "model",
            Dtype::U8,
            vec![model_bytes.len()],
            model_bytes.to_vec(),
        ),
        (
            "template.vertices",
            Dtype::F32,
            vec![t.vertices.len(), 3],
            to_le(
                t.vertices.iter().flat_map(|v| v.to_array()),
                f32::to_le_bytes,
            ),
        ),
        (
            "template.faces",
            Dtype::U32,
            vec![t.faces.len(), 3],
            to_le(t.faces.iter().flatten().copied(), u32::to_le_bytes),
        ),
    ];
    let s = &setup.body_sampling;
    tensors.push((
        "body.stream",
        Dtype::U32,
        vec![s.stream.len()],
        to_le(s.stream.iter().copied(), u32::to_le_bytes),
    ));
    if let Some(o) = &optim_bytes {
        tensors.push(("optimizer", Dtype::U8, vec![o.len()], o.to_vec()));
    }
    if let Some(g) = &setup.garment_file {
        tensors.push(("garment.file", Dtype::U8, vec![g.len()], g.clone()));
    }
    if let Some(f) = &setup.body_faces {
        tensors.push((
            "body.faces",
            Dtype::U32,
            vec![f.len(), 3],
            to_le(f.iter().flatten().copied(), u32::to_le_bytes),
        ));
    }
    let checksum = tensors_checksum(tensors.iter().map(|(n, _, _, b)| (*n, b.as_slice())));
    let mut meta: HashMap<String, String> = HashMap::from([
        ("format".into(), FORMAT.into()),
        ("config".into(), json(&setup.config)?),
        ("loss".into(), json(loss)?),
        ("state".into(), json(state)?),
        ("body.n_vertices".into(), s.n_body.to_string()),
        ("body.n_centres".into(), s.n_centres.to_string()),
        ("body.skinning".into(), setup.body_skinning.clone()),
        ("checksum".into(), checksum),
    ]);
    if let Some(r) = recipe {
        meta.insert("recipe".into(), r.recipe.to_toml());
        meta.insert("recipe.command".into(), r.command.clone());
    }
    let views = tensors
        .iter()
        .map(|(name, d, shape, bytes)| {
            TensorView::new(*d, shape.clone(), bytes)
                .map(|v| (*name, v))
                .map_err(|e| bad(e.to_string()))
        })
        .collect::<Result<Vec<_>>>()?;
    let bytes = safetensors::serialize(views, Some(meta)).map_err(|e| bad(e.to_string()))?;
    geom::io::write_bytes_atomic(path, &bytes)?;
    Ok(())
}

/// Reads a checkpoint written by [`save_checkpoint`]; a malformed file is an error naming
/// the file and the problem.
pub fn load_checkpoint(path: &Path) -> Result<Checkpoint> {
    let bad = |m: String| ModelError::checkpoint(path, m);
    let bytes = std::fs::read(path).map_err(|e| bad(e.to_string()))?;
    let (_, meta) = SafeTensors::read_metadata(&bytes)
        .map_err(|e| bad(format!("not a GarNet checkpoint: {e}")))?;
    let meta = meta.metadata().clone().unwrap_or_default();
    if meta.get("format").map(String::as_str) != Some(FORMAT) {
        return Err(bad(format!("not a {FORMAT} file")));
    }
    let field = |key: &str| -> Result<&String> {
        meta.get(key)
            .ok_or_else(|| bad(format!("missing metadata {key}")))
    };
    let config =
        stored_config(field("config")?).map_err(|e| bad(format!("metadata config: {e}")))?;
    let loss = with_defaults(field("loss")?, LossConfig::new())
        .map_err(|e| bad(format!("metadata loss: {e}")))?;
    let state: TrainState =
        serde_json::from_str(field("state")?).map_err(|e| bad(format!("metadata state: {e}")))?;
    let recipe = match meta.get("recipe") {
        None => None,
        Some(text) => Some(RecipeRecord {
            recipe: Recipe::parse(text).map_err(|e| bad(format!("metadata recipe: {e}")))?,
            command: field("recipe.command")?.clone(),
        }),
    };
    let st = SafeTensors::deserialize(&bytes).map_err(|e| bad(e.to_string()))?;
    let names = st.names();
    let computed = tensors_checksum(names.iter().map(|&n| {
        let data = st.tensor(n).map(|t| t.data()).unwrap_or_default();
        (n, data)
    }));
    if field("checksum")? != &computed {
        return Err(bad(format!(
            "its tensors do not match their checksum: the file is damaged (stored {}, \
             computed {computed})",
            field("checksum")?
        )));
    }
    let data = |name: &str, dtype: Dtype| -> Result<&[u8]> {
        Ok(typed_tensor(&st, name, dtype).map_err(bad)?.data())
    };
    let f32s: Vec<f32> = data("template.vertices", Dtype::F32)?
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let u32s = |name: &str| -> Result<Vec<u32>> {
        Ok(data(name, Dtype::U32)?
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    };
    let faces = u32s("template.faces")?;
    if f32s.len() % 3 != 0 || faces.len() % 3 != 0 {
        return Err(bad("template arrays are not [N,3] / [F,3]".into()));
    }
    let template = geom::TriMesh::new(
        f32s.chunks_exact(3).map(Vec3::from_slice).collect(),
        faces.chunks_exact(3).map(|f| [f[0], f[1], f[2]]).collect(),
    );
    let count = |key: &str| -> Result<usize> {
        field(key)?
            .parse()
            .map_err(|e| bad(format!("metadata {key}: {e}")))
    };
    let body_sampling = BodySampling {
        n_body: count("body.n_vertices")?,
        n_centres: count("body.n_centres")?,
        stream: u32s("body.stream")?,
    };
    let model_bytes = data("model", Dtype::U8)?.to_vec();
    let optimizer_bytes = if names.contains(&"optimizer") {
        Some(data("optimizer", Dtype::U8)?.to_vec())
    } else {
        None
    };
    let garment_file = if names.contains(&"garment.file") {
        Some(data("garment.file", Dtype::U8)?.to_vec())
    } else {
        None
    };
    let body_faces = if names.contains(&"body.faces") {
        let flat = u32s("body.faces")?;
        if flat.len() % 3 != 0 {
            return Err(bad("body.faces is not [F,3]".into()));
        }
        Some(flat.chunks_exact(3).map(|f| [f[0], f[1], f[2]]).collect())
    } else {
        None
    };
    let setup = ModelSetup {
        config,
        template,
        body_sampling,
        garment_file,
        body_faces,
        body_skinning: field("body.skinning")?.clone(),
    };
    setup.validate().map_err(|e| bad(e.to_string()))?;
    Ok(Checkpoint {
        setup,
        loss,
        state,
        recipe,
        model_bytes,
        optimizer_bytes,
    })
}

impl Checkpoint {
    /// The network with the stored parameters, on `device` (a plain device for inference, an
    /// autodiff device to train on). Fails when the stored parameters do not fit the config.
    pub fn model(&self, device: &Device) -> Result<GarNet> {
        let model = self.setup.config.init(device)?;
        let record = ModuleRecord::from_bytes(Bytes::from_bytes_vec(self.model_bytes.clone()))
            .map_err(|e| ModelError::Checkpoint {
                path: "<model record>".into(),
                msg: e.to_string(),
            })?;
        model
            .try_load_record(record)
            .map_err(|e| ModelError::Checkpoint {
                path: "<model record>".into(),
                msg: e.to_string(),
            })
    }

    /// The stored Adam state applied to a fresh Adam optimiser, when the checkpoint has one.
    pub fn optimizer(&self) -> Result<Option<ModuleOptimizer>> {
        match &self.optimizer_bytes {
            None => Ok(None),
            Some(b) => crate::train::adam()
                .from_bytes(Bytes::from_bytes_vec(b.clone()))
                .map(Some)
                .map_err(|e| ModelError::Checkpoint {
                    path: "<optimizer record>".into(),
                    msg: e.to_string(),
                }),
        }
    }

    /// Whether the checkpoint holds an optimiser state.
    pub fn has_optimizer(&self) -> bool {
        self.optimizer_bytes.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Variant;
    use crate::loss::NormalLoss;

    /// A config or loss written before an option existed reads with the option's default;
    /// what the file sets is kept, and text that is not a config is refused.
    #[test]
    fn options_a_stored_config_leaves_out_take_their_defaults() {
        let cfg = GarNetConfig::new(Variant::Global)
            .with_conv_width(48)
            .with_body_contact(true);
        let mut json: serde_json::Value = serde_json::to_value(&cfg).unwrap();
        let object = json.as_object_mut().unwrap();
        object.remove("rest_input");
        let read = stored_config(&json.to_string()).unwrap();
        assert_eq!(read, cfg);
        let loss = LossConfig::new().with_norm(0.7);
        let mut json: serde_json::Value = serde_json::to_value(&loss).unwrap();
        json.as_object_mut().unwrap().remove("normal_loss");
        let read: LossConfig = with_defaults(&json.to_string(), LossConfig::new()).unwrap();
        assert_eq!((read.norm, read.normal_loss), (0.7, NormalLoss::Paper));
        assert!(stored_config("{\"conv_width\": 48}").is_err());
        assert!(with_defaults("[1, 2]", LossConfig::new()).is_err());
    }
}
