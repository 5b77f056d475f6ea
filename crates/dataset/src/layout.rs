//! Where things are in a dataset folder.
//!
//! ```text
//! DIR/manifest.json                 the manifest (see crate::manifest)
//! DIR/spec.toml                     the spec as given
//! DIR/body_faces.safetensors        `faces` u32 [F,3] of every body
//! DIR/templates/ID.garment          garment templates (garment::GarmentTemplate files)
//! DIR/shards/shard-NNNNNN.safetensors  finished shards
//! DIR/parts/NNNNNNNNNN.part|.failed samples of unfinished shards (removed when done)
//! ```

use std::path::{Path, PathBuf};

use crate::error::{DatasetError, Result};

/// The manifest file of `dir`.
pub fn manifest_path(dir: &Path) -> PathBuf {
    dir.join("manifest.json")
}

/// The copy of the spec in `dir`.
pub fn spec_path(dir: &Path) -> PathBuf {
    dir.join("spec.toml")
}

/// The body faces file of `dir`.
pub fn body_faces_path(dir: &Path) -> PathBuf {
    dir.join(BODY_FACES)
}

/// Body faces file name, relative to the dataset folder.
pub const BODY_FACES: &str = "body_faces.safetensors";

/// The template `id`, relative to the dataset folder.
pub fn template_file(id: &str) -> String {
    format!("templates/{id}.garment")
}

/// Shard `s`, relative to the dataset folder.
pub fn shard_file(s: u64) -> String {
    format!("shards/shard-{s:06}.safetensors")
}

/// The shard index of a shard file name (`shard-000012.safetensors` -> 12).
pub fn parse_shard_name(name: &str) -> Option<u64> {
    name.strip_prefix("shard-")?
        .strip_suffix(".safetensors")?
        .parse()
        .ok()
}

/// The part file of a finished sample `k`.
pub fn part_path(dir: &Path, k: u64) -> PathBuf {
    dir.join(format!("parts/{k:010}.part"))
}

/// The part file of a failed sample `k`.
pub fn failed_path(dir: &Path, k: u64) -> PathBuf {
    dir.join(format!("parts/{k:010}.failed"))
}

/// The sample index of a part file name, and whether it is a failure.
pub fn parse_part_name(name: &str) -> Option<(u64, bool)> {
    let (stem, ext) = name.split_once('.')?;
    let failed = match ext {
        "part" => false,
        "failed" => true,
        _ => return None,
    };
    Some((stem.parse().ok()?, failed))
}

/// The sub-folders a dataset folder has.
pub const SUBDIRS: [&str; 3] = ["templates", "shards", "parts"];

/// Creates `dir` and its sub-folders.
pub fn create_dirs(dir: &Path) -> Result<()> {
    for sub in SUBDIRS {
        let p = dir.join(sub);
        std::fs::create_dir_all(&p).map_err(|e| DatasetError::io(&p, e))?;
    }
    Ok(())
}

/// The names of the entries of `dir` (none if it does not exist), sorted.
pub fn list(dir: &Path) -> Result<Vec<String>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(DatasetError::io(dir, e)),
    };
    let mut names = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| DatasetError::io(dir, e))?;
        names.push(entry.file_name().to_string_lossy().into_owned());
    }
    names.sort();
    Ok(names)
}

/// Removes the temporary files an interrupted atomic write left in `dir` and its
/// sub-folders (`.NAME.tmp.*`, see `geom::io::write_atomic`). Returns how many.
pub fn remove_stray_temps(dir: &Path) -> Result<usize> {
    let mut removed = 0;
    let folders = std::iter::once(dir.to_path_buf()).chain(SUBDIRS.iter().map(|s| dir.join(s)));
    for folder in folders {
        for name in list(&folder)? {
            if name.starts_with('.') && name.contains(".tmp.") {
                let p = folder.join(&name);
                std::fs::remove_file(&p).map_err(|e| DatasetError::io(&p, e))?;
                removed += 1;
            }
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        assert_eq!(parse_shard_name(&shard_file(12)[7..]), Some(12));
        let p = part_path(Path::new("d"), 42);
        let name = p.file_name().unwrap().to_str().unwrap();
        assert_eq!(parse_part_name(name), Some((42, false)));
        let f = failed_path(Path::new("d"), 7);
        assert_eq!(
            parse_part_name(f.file_name().unwrap().to_str().unwrap()),
            Some((7, true))
        );
        assert_eq!(parse_part_name(".0000000001.part.tmp.3.0"), None);
    }

    #[test]
    fn stray_temps_are_removed() {
        let d = tempfile::tempdir().unwrap();
        create_dirs(d.path()).unwrap();
        std::fs::write(
            d.path().join("shards/.shard-000001.safetensors.tmp.9.0"),
            b"x",
        )
        .unwrap();
        std::fs::write(d.path().join(".manifest.json.tmp.9.1"), b"x").unwrap();
        std::fs::write(d.path().join("shards/shard-000001.safetensors"), b"x").unwrap();
        assert_eq!(remove_stray_temps(d.path()).unwrap(), 2);
        assert_eq!(list(&d.path().join("shards")).unwrap().len(), 1);
    }
}
