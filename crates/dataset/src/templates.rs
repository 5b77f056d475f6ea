//! The garment templates of a dataset: built from the spec, saved once under
//! `templates/`, and read back by later runs and readers.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use body::BodyModel;
use garment::{build_template, GarmentTemplate};

use crate::cache::KeyedCache;
use crate::cuts::GarmentPlan;
use crate::layout::template_file;

/// Why a template is not available.
#[derive(Clone, Debug, PartialEq)]
pub enum TemplateError {
    /// The garment cannot be built with this cut (a property of the sample).
    Build(String),
    /// The built template could not be saved (a problem of the machine).
    Save(String),
}

/// A template or why it is not available.
pub type TemplateResult = Result<Arc<GarmentTemplate>, TemplateError>;

/// Templates of a dataset folder, built or loaded on first use.
pub struct TemplateStore {
    dir: PathBuf,
    cache: KeyedCache<String, TemplateResult>,
}

impl TemplateStore {
    /// The templates of dataset folder `dir`, keeping at most `capacity` in memory.
    pub fn new(dir: &Path, capacity: usize) -> Self {
        Self {
            dir: dir.to_path_buf(),
            cache: KeyedCache::new(capacity),
        }
    }

    /// The template body `body` wears of `garment` (index `g`, dataset `seed`): read from
    /// its file if a run saved it, else built (with the body's cut) and saved. The error
    /// says why the template could not be built or saved.
    pub fn get(
        &self,
        model: &BodyModel,
        seed: u64,
        g: usize,
        garment: &GarmentPlan,
        body: u32,
    ) -> TemplateResult {
        let id = garment.template_id(body);
        self.cache.get_or_init(&id, || {
            let path = self.dir.join(template_file(&id));
            if path.is_file() {
                if let Ok(t) = GarmentTemplate::load(&path) {
                    return Ok(Arc::new(t));
                }
            }
            let cut = garment.cut_for(seed, g, body);
            let t = build_template(model, &garment.kind, &cut, garment.edge)
                .map_err(|e| TemplateError::Build(format!("template {id}: {e}")))?;
            t.save(&path)
                .map_err(|e| TemplateError::Save(format!("saving template {id}: {e}")))?;
            Ok(Arc::new(t))
        })
    }
}
