//! `generate --reuse DIR`: taking the samples that a dataset of a smaller spec already
//! made. A sample depends on the seed, the garment, the body index, its slot and the pose
//! pool, not on the number of bodies, the poses per body, the splits, the shard size or the
//! storage, so a spec that only adds bodies or poses shares the smaller one's samples; they
//! are copied instead of simulated again. (A body's poses are drawn by a partial shuffle,
//! so its first k of n poses are the k poses a spec of k per body draws.)

use std::path::Path;

use crate::error::{DatasetError, Result};
use crate::layout::template_file;
use crate::parts::{self, FailedPart, PartMeta};
use crate::plan::Plan;
use crate::poses::PoseLibrary;
use crate::reader::Dataset;
use crate::spec::LoadedSpec;

/// An earlier dataset whose samples a generation run takes where they fit.
pub struct Reuse {
    data: Dataset,
    plan: Plan,
    /// The new spec's hash and storage, written into the parts.
    hash: String,
    compact: bool,
}

impl Reuse {
    /// Opens the dataset in `dir` for the generation of `spec` (whose clips are `library`).
    /// Errors unless the two specs differ only in name, body count, poses per body, splits,
    /// shard size and `output.compact`, and the clips are the same files.
    pub fn open(dir: &Path, spec: &LoadedSpec, library: &PoseLibrary) -> Result<Self> {
        let data = Dataset::open(dir)?;
        let new = &spec.spec;
        let mut old = data.manifest().spec.clone();
        let differs = |what: &str| {
            DatasetError::Invalid(format!(
                "--reuse {}: its spec differs from {} in {what}; only the name, the body count, the poses per body, the splits, the shard size and output.compact may differ",
                dir.display(),
                spec.path.display()
            ))
        };
        old.name.clone_from(&new.name);
        old.bodies.count = new.bodies.count;
        old.splits = new.splits.clone();
        old.shard_size = new.shard_size;
        old.output.compact = new.output.compact;
        let old_poses: Vec<u32> = old.garments.iter().map(|g| g.poses_per_body).collect();
        if old.garments.len() == new.garments.len() {
            for (o, n) in old.garments.iter_mut().zip(&new.garments) {
                o.poses_per_body = n.poses_per_body;
            }
        }
        let fields = [
            ("the seed", old.seed == new.seed),
            ("the body distribution", old.bodies == new.bodies),
            ("the garments", old.garments == new.garments),
            ("the poses", old.poses == new.poses),
            ("the simulator settings", old.simulator == new.simulator),
            ("the stored arrays", old.output == new.output),
        ];
        if let Some((what, _)) = fields.iter().find(|(_, same)| !same) {
            return Err(differs(what));
        }
        if old != *new {
            return Err(differs("its other settings"));
        }
        for f in &library.files {
            let same = data.manifest().mocap.iter().any(|o| o == f);
            if !same {
                return Err(differs(&format!("mocap file {} (or its content)", f.path)));
            }
        }
        old.bodies.count = data.manifest().spec.bodies.count;
        old.splits = data.manifest().spec.splits.clone();
        for (g, ppb) in old.garments.iter_mut().zip(old_poses) {
            g.poses_per_body = ppb;
        }
        let old_spec = LoadedSpec {
            hash: crate::spec::spec_hash(&old),
            spec: old,
            path: crate::layout::spec_path(dir),
        };
        Ok(Self {
            plan: Plan::new(&old_spec, &library.frame_counts())?,
            data,
            hash: spec.hash.clone(),
            compact: new.output.compact,
        })
    }

    /// Takes sample `k` of `plan` from the earlier dataset if it holds it: writes its part
    /// into `out` (with the template file it names) and returns whether the drape had
    /// failed; `None` when the sample must be made.
    pub fn take(&self, out: &Path, plan: &Plan, k: u64) -> Result<Option<bool>> {
        let desc = plan.sample(k);
        if desc.body >= self.plan.bodies {
            return Ok(None);
        }
        let old_ppb = self.plan.garments[desc.garment].poses_per_body;
        if desc.slot >= old_ppb {
            return Ok(None);
        }
        let old_k =
            self.plan.offsets[desc.garment] + desc.body as u64 * old_ppb as u64 + desc.slot as u64;
        let old = self.plan.sample(old_k);
        if self.plan.pool.pose_id(old.pose) != plan.pool.pose_id(desc.pose) {
            return Ok(None);
        }
        let split = plan.split_names[desc.split].clone();
        let m = self.data.manifest();
        if let Some(entry) = m.sample(old_k) {
            let sample = self.data.sample(old_k)?;
            let path = out.join(template_file(&sample.record.template));
            if !path.is_file() {
                let bytes = self.data.template_bytes(&sample.record.template)?;
                geom::io::write_bytes_atomic(&path, &bytes)?;
            }
            let mut record = sample.record;
            (record.index, record.split) = (k, split);
            let meta = PartMeta {
                spec_hash: self.hash.clone(),
                record,
                timing: entry.timing.unwrap_or_default(),
            };
            parts::write_done(out, &sample.arrays, &meta, self.compact)?;
            return Ok(Some(false));
        }
        if let Some(f) = m.failures.iter().find(|f| f.record.index == old_k) {
            let mut failure = f.record.clone();
            (failure.index, failure.split) = (k, split);
            let part = FailedPart {
                spec_hash: self.hash.clone(),
                failure,
                timing: f.timing.unwrap_or_default(),
            };
            parts::write_failed(out, &part)?;
            return Ok(Some(true));
        }
        Ok(None)
    }
}
