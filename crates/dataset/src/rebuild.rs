//! Rebuilding what a compact dataset does not store (spec `[output] compact = true`): the
//! posed body and M follow from a sample's phenotype, pose and template, given the body
//! model, so they are computed again when the sample is read.

use std::sync::{Arc, OnceLock};

use body::{BodyModel, Phenotype, Pose, ShapedBody, Skinning};
use garment::warp::warp;
use garment::GarmentTemplate;

use crate::cache::KeyedCache;
use crate::error::{DatasetError, Result};
use crate::records::SampleRecord;
use crate::tensors::SampleArrays;

/// Shaped bodies kept: a body's samples of one garment are stored next to each other.
const BODIES_KEPT: usize = 8;

/// Rebuilds bodies and M for a dataset whose simulator skinned the body with `skinning`.
pub struct Rebuilder {
    skinning: Skinning,
    model: OnceLock<std::result::Result<Arc<BodyModel>, String>>,
    bodies: KeyedCache<u32, std::result::Result<Arc<ShapedBody>, String>>,
}

impl Rebuilder {
    /// The skinning the bodies are posed with.
    pub fn skinning(&self) -> Skinning {
        self.skinning
    }

    /// A rebuilder for bodies posed with `skinning`; the body model is loaded (from the
    /// installed assets, [`BodyModel::load`]) on first use.
    pub fn new(skinning: Skinning) -> Self {
        Self {
            skinning,
            model: OnceLock::new(),
            bodies: KeyedCache::new(BODIES_KEPT),
        }
    }

    fn model(&self) -> Result<Arc<BodyModel>> {
        self.model
            .get_or_init(|| {
                BodyModel::load()
                    .map(Arc::new)
                    .map_err(|e| format!("the dataset is compact: rebuilding its bodies needs the body model, which failed to load: {e}"))
            })
            .clone()
            .map_err(DatasetError::Invalid)
    }

    /// Fills `arrays.body` (`[V]`, metres, the body posed as the simulator posed it) and
    /// `arrays.warped` (M `[N]`, metres, the template skinned by DQS) of the sample
    /// `record` from its phenotype, pose and `template`.
    pub fn fill(
        &self,
        record: &SampleRecord,
        arrays: &mut SampleArrays,
        template: &GarmentTemplate,
    ) -> Result<()> {
        let model = self.model()?;
        let shaped = self
            .bodies
            .get_or_init(&record.body, || {
                Phenotype::from_values(&arrays.phenotype)
                    .and_then(|p| model.shape(&p))
                    .map(Arc::new)
                    .map_err(|e| format!("sample {}: body {}: {e}", record.index, record.body))
            })
            .map_err(DatasetError::Invalid)?;
        let pose = Pose {
            root_translation: arrays.root_translation,
            rotations: arrays.rotations.clone(),
        };
        arrays.body = shaped.posed(&pose, self.skinning)?.vertices;
        arrays.warped = warp(template, &shaped, &pose, Skinning::Dqs)?.vertices;
        Ok(())
    }
}
