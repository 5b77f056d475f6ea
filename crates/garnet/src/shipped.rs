//! The models shipped in the repository's `models/` folder.

use std::path::{Path, PathBuf};

use anyhow::bail;

/// The shipped GarNet-Local models that the main job drapes: T-shirt, sweater, jeans.
pub const SHIPPED_MODELS: [&str; 3] = [
    "tshirt-local.garnet",
    "sweater-local.garnet",
    "jeans-local.garnet",
];

/// Where the shipped models are: `models/` in the working directory when it holds them,
/// else the `models/` folder of the repository this library was built from.
pub fn shipped_models_dir() -> PathBuf {
    let local = PathBuf::from("models");
    if local.join(SHIPPED_MODELS[0]).is_file() {
        return local;
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models")
}

/// The paths of [`SHIPPED_MODELS`] in [`shipped_models_dir`]; fails, naming the file, when
/// one is missing.
pub fn shipped_models() -> anyhow::Result<Vec<PathBuf>> {
    let dir = shipped_models_dir();
    let models: Vec<PathBuf> = SHIPPED_MODELS.iter().map(|m| dir.join(m)).collect();
    if let Some(missing) = models.iter().find(|m| !m.is_file()) {
        bail!(
            "{}: shipped model missing (the main job drapes {}; train and export them as the \
             README shows)",
            missing.display(),
            SHIPPED_MODELS.join(", ")
        );
    }
    Ok(models)
}
