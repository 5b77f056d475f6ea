//! Reading a dataset: the manifest, samples by index, templates and body faces, with
//! every file's sha256 checked against the manifest when it is read. Shards are opened
//! lazily and only the most recent few are kept in memory.

use std::collections::{HashMap, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use body::Skinning;
use garment::GarmentTemplate;

use crate::error::{DatasetError, Result};
use crate::hash::sha256_hex;
use crate::layout;
use crate::manifest::{FileEntry, Manifest};
use crate::rebuild::Rebuilder;
use crate::records::{DrapeFilter, SampleRecord};
use crate::tensors::{self, SampleArrays};

/// One stored sample: what it is and its arrays (shapes and units in
/// [`crate::tensors`]; garment faces from [`Dataset::template`], body faces from
/// [`Dataset::body_faces`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Index, garment, template id, body, split, pose and simulator statistics.
    pub record: SampleRecord,
    /// Body `[V,3]`, M `[N,3]`, G `[N,3]` (metres), phenotype `[11]`, pose.
    pub arrays: SampleArrays,
}

/// A dataset folder opened for reading.
pub struct Dataset {
    dir: PathBuf,
    manifest: Manifest,
    cache_shards: usize,
    shards: Mutex<VecDeque<(u64, Arc<Vec<u8>>)>>,
    templates: Mutex<HashMap<String, Arc<GarmentTemplate>>>,
    rebuild: Rebuilder,
}

/// Reads `dir/rel` and checks its sha256.
fn read_checked(dir: &Path, entry: &FileEntry) -> Result<Vec<u8>> {
    let path = dir.join(&entry.file);
    let bytes = std::fs::read(&path).map_err(|e| DatasetError::io(&path, e))?;
    let actual = sha256_hex(&bytes);
    if actual != entry.sha256 {
        return Err(DatasetError::corrupt(
            &path,
            format!(
                "checksum mismatch: the file's sha256 is {actual}, the manifest says {}; the file is damaged",
                entry.sha256
            ),
        ));
    }
    Ok(bytes)
}

impl Dataset {
    /// How the dataset's simulator posed its bodies (and so how a network trained on it
    /// expects bodies posed).
    pub fn body_skinning(&self) -> Skinning {
        self.rebuild.skinning()
    }

    /// Opens the dataset in `dir`, keeping at most two shards in memory.
    pub fn open(dir: &Path) -> Result<Self> {
        let manifest = Manifest::load(dir)?;
        let skinning = manifest
            .spec
            .simulator
            .drape_options()
            .map_err(|(field, m)| {
                DatasetError::corrupt(
                    &layout::manifest_path(dir),
                    format!("simulator.{field}: {m}"),
                )
            })?
            .skinning;
        Ok(Self {
            manifest,
            rebuild: Rebuilder::new(skinning),
            dir: dir.to_path_buf(),
            cache_shards: 2,
            shards: Mutex::new(VecDeque::new()),
            templates: Mutex::new(HashMap::new()),
        })
    }

    /// Keeps at most `n` (at least 1) shards in memory.
    pub fn with_cache_shards(mut self, n: usize) -> Self {
        self.cache_shards = n.max(1);
        self
    }

    /// Shards kept in memory.
    pub fn cache_shards(&self) -> usize {
        self.cache_shards
    }

    /// The manifest.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// The dataset folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Indices of the stored samples of `split` and `garment` (`None`: any), ascending.
    /// An unknown split or garment name is an error listing the known ones.
    pub fn select(&self, split: Option<&str>, garment: Option<&str>) -> Result<Vec<u64>> {
        let m = &self.manifest;
        let splits: Vec<&str> = m.splits.keys().map(String::as_str).collect();
        DatasetError::check_known("split", split, &splits)?;
        let garments: Vec<&str> = m.garments.iter().map(|x| x.name.as_str()).collect();
        DatasetError::check_known("garment", garment, &garments)?;
        Ok(m.samples
            .iter()
            .filter(|e| split.is_none_or(|s| e.record.split == s))
            .filter(|e| garment.is_none_or(|g| e.record.garment == g))
            .map(|e| e.record.index)
            .collect())
    }

    /// Keeps in `indices` (stored sample indices) only the samples whose drape passes
    /// `filter`; returns how many were dropped.
    pub fn retain_drapes(&self, indices: &mut Vec<u64>, filter: &DrapeFilter) -> usize {
        let before = indices.len();
        indices.retain(|&k| {
            self.manifest
                .sample(k)
                .is_some_and(|e| filter.keeps(&e.record.stats))
        });
        before - indices.len()
    }

    /// The bytes of shard `s`, checked, from memory or disk.
    fn shard_bytes(&self, s: u64) -> Result<Arc<Vec<u8>>> {
        let mut cache = self.shards.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(pos) = cache.iter().position(|(i, _)| *i == s) {
            let hit = cache.remove(pos).expect("present");
            cache.push_back(hit.clone());
            return Ok(hit.1);
        }
        let entry = self
            .manifest
            .shard(s)
            .ok_or_else(|| DatasetError::Invalid(format!("shard {s} is not in this dataset")))?;
        let entry = FileEntry {
            file: entry.file.clone(),
            sha256: entry.sha256.clone(),
        };
        let bytes = Arc::new(read_checked(&self.dir, &entry)?);
        cache.push_back((s, bytes.clone()));
        while cache.len() > self.cache_shards {
            cache.pop_front();
        }
        Ok(bytes)
    }

    /// Stored sample `k`. A sample that failed, was not made, or does not exist is an
    /// error saying which; a damaged shard is an error naming its file. A compact
    /// sample's body and M are rebuilt (see [`crate::rebuild`]).
    pub fn sample(&self, k: u64) -> Result<Sample> {
        let m = &self.manifest;
        let Some(entry) = m.sample(k) else {
            let why = match m.failures.iter().find(|f| f.record.index == k) {
                Some(f) => format!("its drape failed: {}", f.record.reason),
                None if k >= m.total_samples => {
                    format!("the dataset has {} samples", m.total_samples)
                }
                None => "its shard is not in this folder".into(),
            };
            return Err(DatasetError::Invalid(format!(
                "sample {k} is not stored: {why}"
            )));
        };
        let bytes = self.shard_bytes(entry.shard)?;
        let path = self.dir.join(crate::layout::shard_file(entry.shard));
        let (st, _) = tensors::parse(&bytes, crate::shard::SHARD_KEY, &path)?;
        let mut arrays = SampleArrays::read(&st, k, &path)?;
        if arrays.body.is_empty() {
            let template = self.template(&entry.record.template)?;
            self.rebuild.fill(&entry.record, &mut arrays, &template)?;
        }
        Ok(Sample {
            record: entry.record.clone(),
            arrays,
        })
    }

    /// Template `id` (the garment faces and rest shape of samples that name it).
    pub fn template(&self, id: &str) -> Result<Arc<GarmentTemplate>> {
        let mut cache = self.templates.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(t) = cache.get(id) {
            return Ok(t.clone());
        }
        self.template_bytes(id)?;
        let file = &self.manifest.templates[id].file;
        let t = Arc::new(GarmentTemplate::load(&self.dir.join(file))?);
        cache.insert(id.to_string(), t.clone());
        Ok(t)
    }

    /// The bytes of template `id`'s file, checked against the manifest.
    pub fn template_bytes(&self, id: &str) -> Result<Vec<u8>> {
        let entry = self
            .manifest
            .templates
            .get(id)
            .ok_or_else(|| DatasetError::Invalid(format!("no template '{id}'")))?;
        read_checked(&self.dir, entry)
    }

    /// The body faces `[F]` (vertex index triples into a sample's `body`).
    pub fn body_faces(&self) -> Result<Vec<[u32; 3]>> {
        let entry = self
            .manifest
            .body_faces
            .as_ref()
            .ok_or_else(|| DatasetError::Invalid("the manifest lists no body faces".into()))?;
        let bytes = read_checked(&self.dir, entry)?;
        crate::body_faces::parse(&bytes, &self.dir.join(&entry.file))
    }

    /// Reads every file the manifest lists and checks its sha256; returns the problems
    /// found (none: the dataset is intact).
    pub fn verify(&self) -> Vec<DatasetError> {
        let m = &self.manifest;
        let shards = m.shards.iter().map(|e| FileEntry {
            file: e.file.clone(),
            sha256: e.sha256.clone(),
        });
        let others = m.body_faces.iter().chain(m.templates.values()).cloned();
        shards
            .chain(others)
            .filter_map(|e| read_checked(&self.dir, &e).err())
            .collect()
    }
}
