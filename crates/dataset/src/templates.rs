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
    /// The dataset folder; `None`: templates are built in memory and never saved.
    dir: Option<PathBuf>,
    cache: KeyedCache<String, TemplateResult>,
}

impl TemplateStore {
    /// The templates of dataset folder `dir`, keeping at most `capacity` in memory.
    pub fn new(dir: &Path, capacity: usize) -> Self {
        Self {
            dir: Some(dir.to_path_buf()),
            cache: KeyedCache::new(capacity),
        }
    }

    /// Templates without a dataset folder: each built on first use and kept in memory only
    /// (at most `capacity` of them); nothing is read or written.
    pub fn in_memory(capacity: usize) -> Self {
        Self {
            dir: None,
            cache: KeyedCache::new(capacity),
        }
    }

    /// The template body `body` wears of `garment` (index `g`, dataset `seed`): read from
    /// its file if a run saved it, else built (with the body's cut) and saved (in memory
    /// only for [`TemplateStore::in_memory`]). The error says why the template could not
    /// be built or saved.
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
            let path = self.dir.as_ref().map(|d| d.join(template_file(&id)));
            if let Some(path) = path.as_ref().filter(|p| p.is_file()) {
                if let Ok(t) = GarmentTemplate::load(path) {
                    return Ok(Arc::new(t));
                }
            }
            let cut = garment.cut_for(seed, g, body);
            let t = build_template(model, &garment.kind, &cut, garment.edge)
                .map_err(|e| TemplateError::Build(format!("template {id}: {e}")))?;
            if let Some(path) = &path {
                t.save(path)
                    .map_err(|e| TemplateError::Save(format!("saving template {id}: {e}")))?;
            }
            Ok(Arc::new(t))
        })
    }
}
