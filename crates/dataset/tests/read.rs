//! Reading: samples and their shapes, batches in order and shuffled per epoch, damaged
//! files detected by checksum, failed drapes listed and never stored.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::{generate, options, reference, FAST};
use dataset::batches::{epoch_order, stack};
use dataset::{BatchOptions, Batches, Dataset, Order, Summary};

fn copy_dir(from: &Path, to: &Path) {
    for entry in walk(from) {
        let rel = entry.strip_prefix(from).unwrap();
        std::fs::create_dir_all(to.join(rel).parent().unwrap()).unwrap();
        std::fs::copy(&entry, to.join(rel)).unwrap();
    }
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn samples_have_the_documented_shapes() {
    let data = Dataset::open(reference()).unwrap();
    let faces = data.body_faces().unwrap();
    assert_eq!(faces.len(), 26756);
    for k in data.select(None, None).unwrap() {
        let s = data.sample(k).unwrap();
        let a = &s.arrays;
        let t = data.template(&s.record.template).unwrap();
        assert_eq!(a.body.len(), 13380);
        assert_eq!(a.warped.len(), t.mesh.vertices.len());
        assert_eq!(a.draped.len(), t.mesh.vertices.len());
        assert_eq!((a.phenotype.len(), a.rotations.len()), (11, 31));
        assert!(a.fitted.is_none());
        assert!(a.body.iter().chain(&a.draped).all(|p| p.is_finite()));
        // Metres: a standing adult, the garment near the body.
        let top = a.body.iter().map(|p| p.y).fold(f32::MIN, f32::max);
        assert!((1.2..2.2).contains(&top), "{top}");
        assert_eq!(s.record.index, k);
        let per_body = format!("jeans-b{:05}", s.record.body);
        let id = if s.record.garment == "jeans" {
            per_body.as_str()
        } else {
            "tshirt"
        };
        assert_eq!(s.record.template, id);
    }
    // Each body's jeans have their own cut, so their own template.
    let jeans: Vec<_> = (0..3)
        .map(|b| data.template(&format!("jeans-b{b:05}")))
        .collect();
    let jeans: Vec<_> = jeans.into_iter().map(|t| t.unwrap().cut.unwrap()).collect();
    assert!(
        jeans[0].leg_length != jeans[1].leg_length && jeans[1].leg_length != jeans[2].leg_length
    );
    assert!(jeans.iter().all(|c| (0.5..=0.8).contains(&c.leg_length)));
    assert!(data
        .sample(999)
        .unwrap_err()
        .to_string()
        .contains("has 9 samples"));
}

#[test]
fn batches_stream_a_split_in_order_or_shuffled_per_epoch() {
    let data = Dataset::open(reference()).unwrap();
    let train = data.select(Some("train"), None).unwrap();
    let test = data.select(Some("test"), Some("tshirt")).unwrap();
    assert!(train.len() >= 4 && !test.is_empty());
    assert!(data
        .select(Some("nope"), None)
        .unwrap_err()
        .to_string()
        .contains("train"));
    let opts = BatchOptions {
        batch_size: 2,
        order: Order::InOrder,
        drop_last: false,
    };
    let batches = Batches::new(&data, &train, opts);
    assert_eq!(batches.batch_count(), train.len().div_ceil(2));
    let seen: Vec<u64> = batches
        .flat_map(|b| b.unwrap().into_iter().map(|s| s.record.index))
        .collect();
    assert_eq!(seen, train);
    // Skipping batches starts the epoch further on, reading nothing before it.
    let rest: Vec<u64> = Batches::new(&data, &train, opts)
        .skip_batches(1)
        .flat_map(|b| b.unwrap().into_iter().map(|s| s.record.index))
        .collect();
    assert_eq!(rest, train[2..]);
    assert_eq!(
        Batches::new(&data, &train, opts)
            .skip_batches(usize::MAX)
            .count(),
        0
    );
    let shuffled = |epoch| epoch_order(&data, &train, Order::Shuffled { seed: 1, epoch });
    let (e0, e1) = (shuffled(0), shuffled(1));
    assert_eq!(e0, shuffled(0));
    assert_eq!(BTreeSet::from_iter(&e0), BTreeSet::from_iter(&train));
    assert!((0..8).any(|e| shuffled(e) != e0) && e0.len() == e1.len());
    let garment = data.select(Some("train"), Some("tshirt")).unwrap();
    let batch: Vec<_> = garment
        .iter()
        .take(2)
        .map(|&k| data.sample(k).unwrap())
        .collect();
    let stacked = stack(&batch, |s| &s.arrays.draped).unwrap();
    assert_eq!(stacked.len(), 2 * batch[0].arrays.draped.len() * 3);
}

#[test]
fn a_damaged_shard_is_detected_by_its_checksum() {
    let dir = tempfile::tempdir().unwrap();
    copy_dir(reference(), dir.path());
    let shard = dir.path().join("shards/shard-000001.safetensors");
    let mut bytes = std::fs::read(&shard).unwrap();
    let n = bytes.len();
    bytes[n - 100] ^= 0x40;
    std::fs::write(&shard, bytes).unwrap();
    let data = Dataset::open(dir.path()).unwrap();
    let k = data
        .manifest()
        .samples
        .iter()
        .find(|e| e.shard == 1)
        .unwrap()
        .record
        .index;
    let e = data.sample(k).unwrap_err().to_string();
    assert!(
        e.contains("shard-000001.safetensors") && e.contains("checksum"),
        "{e}"
    );
    let problems = data.verify();
    assert_eq!(problems.len(), 1);
    assert!(problems[0].to_string().contains("shard-000001"));
    let k0 = data
        .manifest()
        .samples
        .iter()
        .find(|e| e.shard == 0)
        .unwrap()
        .record
        .index;
    assert!(data.sample(k0).is_ok(), "other shards still read");
    assert!(Dataset::open(reference()).unwrap().verify().is_empty());
}

#[test]
fn failed_drapes_are_listed_never_stored() {
    // Every drape "diverges" at its first step.
    let text = FAST
        .replace("count = 3", "count = 1")
        .replace("train = 2\ntest = 1", "train = 1")
        .replace("iterations = 2", "iterations = 2\nexplode_speed = 1e-9");
    let dir = tempfile::tempdir().unwrap();
    let r = generate(&text, dir.path(), &options(2));
    assert!(r.complete && r.made == 3 && r.failed == 3, "{r:?}");
    let data = Dataset::open(dir.path()).unwrap();
    let m = data.manifest();
    assert!(m.samples.is_empty() && m.failures.len() == 3);
    assert!(m
        .failures
        .iter()
        .all(|f| f.record.reason.contains("diverged")));
    let e = data.sample(0).unwrap_err().to_string();
    assert!(e.contains("failed") && e.contains("diverged"), "{e}");
    let summary = Summary::of(m);
    assert_eq!(summary.failures.len(), 3);
    assert!(summary
        .report()
        .contains("sample 0 (tshirt): drape: simulation diverged"));
}
