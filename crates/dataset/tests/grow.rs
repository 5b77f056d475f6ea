//! Growing a dataset: a spec with more bodies takes the smaller dataset's samples
//! (`--reuse`) and simulates only the new bodies; a compact dataset stores no bodies and
//! no M, and reading rebuilds them as they were stored.

mod common;

use common::{generate, options, reference, FAST};
use dataset::{Dataset, ShardSelection};

/// [`FAST`] with 5 bodies split 3 / 2, stored compact, in shards of 4.
fn grown() -> String {
    FAST.replace("count = 3", "count = 5")
        .replace("train = 2\ntest = 1", "train = 3\ntest = 2")
        .replace("shard_size = 2", "shard_size = 4")
        + "[output]\ncompact = true\n"
}

/// The index of the sample of `data` with `record`'s garment, body and pose.
fn twin(data: &Dataset, record: &dataset::records::SampleRecord) -> u64 {
    let key = |r: &dataset::records::SampleRecord| (r.garment.clone(), r.body, r.pose.clone());
    data.manifest()
        .samples
        .iter()
        .find(|n| key(&n.record) == key(record))
        .expect("reused")
        .record
        .index
}

#[test]
fn a_grown_compact_dataset_reuses_the_smaller_one_and_rebuilds_what_it_does_not_store() {
    let dir = tempfile::tempdir().unwrap();
    let mut o = options(2);
    o.reuse = Some(reference().to_path_buf());
    let r = generate(&grown(), dir.path(), &o);
    // 5 bodies x (2 T-shirt + 1 jeans) = 15 samples; the first 3 bodies' 9 are reused.
    assert!(r.complete && r.reused == 9 && r.made == 6, "{r:?}");
    let (old, new) = (
        Dataset::open(reference()).unwrap(),
        Dataset::open(dir.path()).unwrap(),
    );
    let old_shards = std::fs::metadata(reference().join("shards/shard-000000.safetensors"));
    let new_shards = std::fs::metadata(dir.path().join("shards/shard-000000.safetensors"));
    // Shard 0 holds 2 samples there and 4 here, but no bodies here: still smaller.
    assert!(new_shards.unwrap().len() < old_shards.unwrap().len());
    let mut compared = 0;
    for e in &old.manifest().samples {
        let a = old.sample(e.record.index).unwrap();
        let b = new.sample(twin(&new, &a.record)).unwrap();
        assert_eq!(a.arrays.draped, b.arrays.draped, "G is copied as it was");
        assert_eq!(a.record.stats, b.record.stats);
        let worst = |x: &[glam::Vec3], y: &[glam::Vec3]| {
            assert_eq!(x.len(), y.len());
            x.iter()
                .zip(y)
                .map(|(p, q)| p.distance(*q))
                .fold(0.0, f32::max)
        };
        // The simulator posed the body without the root's yaw and turned it after;
        // rebuilding poses it directly: the same body up to rounding.
        let body = worst(&a.arrays.body, &b.arrays.body);
        let m = worst(&a.arrays.warped, &b.arrays.warped);
        assert!(body < 1e-5 && m < 1e-5, "body {body} m, M {m} m");
        compared += 1;
    }
    assert_eq!(compared, old.manifest().samples.len());
    // The new bodies' samples read back whole too.
    for e in new.manifest().samples.iter().filter(|e| e.record.body >= 3) {
        let s = new.sample(e.record.index).unwrap();
        assert_eq!(s.arrays.body.len(), 13380);
        assert_eq!(s.arrays.warped.len(), s.arrays.draped.len());
    }
}

#[test]
fn reuse_refuses_a_dataset_of_another_seed_and_takes_nothing_outside_the_selection() {
    let dir = tempfile::tempdir().unwrap();
    let mut o = options(1);
    o.reuse = Some(reference().to_path_buf());
    let other = grown().replace("seed = 3", "seed = 4");
    let e = dataset::generate(common::model(), &common::spec(&other), dir.path(), &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("--reuse") && e.contains("differs") && e.contains("in the seed"),
        "{e}"
    );
    // Shards 1-2 of the grown dataset: samples 4-11, the T-shirts of bodies 2-4 and the
    // jeans of bodies 0-1; bodies 0-2 come from the reference.
    o.selection = ShardSelection::parse("1-2").unwrap();
    let r = generate(&grown(), &dir.path().join("part"), &o);
    assert!(r.finished && !r.complete, "{r:?}");
    assert_eq!((r.selected_samples, r.reused), (8, 4));
}

#[test]
fn more_poses_per_body_reuse_the_first_poses_of_each_body() {
    let dir = tempfile::tempdir().unwrap();
    let mut o = options(2);
    o.reuse = Some(reference().to_path_buf());
    // T-shirt 2 -> 3 poses per body, jeans 1 -> 2, on the same 3 bodies.
    let more = FAST
        .replace("poses_per_body = 2", "poses_per_body = 3")
        .replace("poses_per_body = 1", "poses_per_body = 2");
    let r = generate(&more, dir.path(), &o);
    assert!(r.complete && r.reused == 9 && r.made == 6, "{r:?}");
    let (old, new) = (
        Dataset::open(reference()).unwrap(),
        Dataset::open(dir.path()).unwrap(),
    );
    // Each body's first poses are the smaller spec's, copied as they were; the new slots
    // hold poses of their own.
    for e in &old.manifest().samples {
        let a = old.sample(e.record.index).unwrap();
        let b = new.sample(twin(&new, &a.record)).unwrap();
        assert_eq!(a.arrays.draped, b.arrays.draped);
        assert_eq!(a.record.stats, b.record.stats);
    }
    for g in ["tshirt", "jeans"] {
        for body in 0..3 {
            let mut poses: Vec<&str> = new
                .manifest()
                .samples
                .iter()
                .filter(|n| n.record.garment == g && n.record.body == body)
                .map(|n| n.record.pose.as_str())
                .collect();
            let n = poses.len();
            poses.sort();
            poses.dedup();
            assert_eq!(poses.len(), n, "{g} body {body}: distinct poses");
        }
    }
}
