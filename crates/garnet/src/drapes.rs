//! Which drapes of a dataset training and evaluation use, and whether a model fits a
//! dataset's bodies.

use anyhow::bail;
use dataset::{Dataset, DrapeFilter};
use model::ModelSetup;

/// Keeps in `indices` (the `garment` samples of `split` in `data`) only the drapes `filter`
/// passes; returns how many were dropped. Errors, naming the dataset and the filter, when
/// none is left.
pub fn keep_drapes(
    data: &Dataset,
    split: &str,
    garment: &str,
    indices: &mut Vec<u64>,
    filter: &DrapeFilter,
) -> anyhow::Result<usize> {
    let before = indices.len();
    let dropped = data.retain_drapes(indices, filter);
    if indices.is_empty() {
        bail!(
            "{}: no '{garment}' sample of split '{split}' is one of the {} (none of the {before} \
             samples is)",
            data.dir().display(),
            filter.describe()
        );
    }
    Ok(dropped)
}

/// Fails, naming `model`, when the network `setup` learned from bodies posed another way than
/// the dataset `data` poses them: its inputs would not be what it learned from.
pub fn check_body_skinning(
    setup: &ModelSetup,
    data: &Dataset,
    model: &std::path::Path,
) -> anyhow::Result<()> {
    let expected = data.body_skinning().name();
    if setup.body_skinning != expected {
        bail!(
            "{}: the network learned from bodies posed with {}, the dataset in {} poses them \
             with {expected}",
            model.display(),
            setup.body_skinning,
            data.dir().display()
        );
    }
    Ok(())
}
