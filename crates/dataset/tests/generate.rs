//! Generation is reproducible: the same spec and seed give byte-identical shards whatever
//! the number of jobs, the `--shard i/n` split of the work (then merged), interruptions
//! (a sample limit, a cancellation, stray temporary files) and resumption.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};

use common::{assert_same_shards, generate, options, reference, shards, FAST};
use dataset::{merge, Manifest, ShardSelection};

#[test]
fn same_shards_with_one_job() {
    let dir = tempfile::tempdir().unwrap();
    let r = generate(FAST, dir.path(), &options(1));
    assert!(
        r.complete && r.finished && r.made == 9 && r.shards_written == 5,
        "{r:?}"
    );
    assert_same_shards(dir.path());
    let (a, b) = (
        Manifest::load(reference()).unwrap(),
        Manifest::load(dir.path()).unwrap(),
    );
    assert_eq!(a.shards, b.shards, "same checksums in the manifests");
    assert_eq!(a.samples.len() + a.failures.len(), 9);
}

#[test]
fn two_job_array_runs_merge_into_the_same_dataset() {
    let root = tempfile::tempdir().unwrap();
    let runs: Vec<_> = (0..2)
        .map(|i| root.path().join(format!("run{i}")))
        .collect();
    for (i, dir) in runs.iter().enumerate() {
        let mut o = options(1);
        o.selection = ShardSelection::parse(&format!("{i}/2")).unwrap();
        let r = generate(FAST, dir, &o);
        assert!(r.finished && !r.complete, "{r:?}");
        assert_eq!(r.selected_samples, if i == 0 { 5 } else { 4 });
    }
    let merged = root.path().join("merged");
    let m = merge(&merged, &runs).unwrap();
    assert!(m.complete && m.shards == 5 && m.missing.is_empty(), "{m:?}");
    assert_same_shards(&merged);
    let manifest = Manifest::load(&merged).unwrap();
    assert_eq!(
        manifest.samples.len() as u64 + manifest.failures.len() as u64,
        9
    );
    assert!(manifest.complete);
    // Merging an incomplete set says what is missing; merging into a dataset is refused.
    let part = merge(&root.path().join("half"), &runs[..1]).unwrap();
    assert_eq!(part.missing, vec![1, 3]);
    assert!(merge(&merged, &runs)
        .unwrap_err()
        .to_string()
        .contains("already holds"));
    // A template that differs between the inputs is refused.
    let file = runs[1].join("templates/tshirt.garment");
    let mut t = garment::GarmentTemplate::load(&file).unwrap();
    t.mesh.vertices[0].x += 0.01;
    t.save(&file).unwrap();
    let mut m = Manifest::load(&runs[1]).unwrap();
    m.templates.get_mut("tshirt").unwrap().sha256 = dataset::hash::sha256_file(&file).unwrap();
    m.save(&runs[1]).unwrap();
    let e = merge(&root.path().join("bad"), &runs)
        .unwrap_err()
        .to_string();
    assert!(e.contains("template tshirt differs"), "{e}");
}

#[test]
fn interrupted_and_resumed_generation_loses_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Stop after 3 samples: shard 0 is written, sample 2 waits as a part file.
    let mut o = options(2);
    o.max_new_samples = Some(3);
    let r = generate(FAST, d, &o);
    assert!(!r.finished && r.made == 3, "{r:?}");
    assert_eq!(shards(d).len(), 1);
    // Leave the debris of writes killed half-way.
    std::fs::write(
        d.join("shards/.shard-000001.safetensors.tmp.99999.0"),
        b"half",
    )
    .unwrap();
    std::fs::write(d.join("parts/.0000000003.part.tmp.99999.1"), b"half").unwrap();
    std::fs::write(d.join(".manifest.json.tmp.99999.2"), b"{").unwrap();
    // Resume, cancelled from the progress hook after two more samples.
    let cancel = AtomicBool::new(false);
    let hook = |p: &dataset::Progress| {
        if p.made >= 2 {
            cancel.store(true, Ordering::SeqCst);
        }
    };
    let mut o = options(1);
    o.cancel = Some(&cancel);
    o.progress = Some(&hook);
    let r = generate(FAST, d, &o);
    assert_eq!(
        (r.resumed, r.made, r.stray_temps_removed),
        (3, 2, 3),
        "{r:?}"
    );
    assert!(!r.finished);
    // Finish.
    let r = generate(FAST, d, &options(2));
    assert_eq!((r.resumed, r.made), (5, 4), "{r:?}");
    assert!(r.complete);
    assert_same_shards(d);
    let parts = std::fs::read_dir(d.join("parts")).unwrap().count();
    assert_eq!(
        parts, 0,
        "part files are removed once their shard is written"
    );
    // Nothing is left to do.
    let r = generate(FAST, d, &options(1));
    assert_eq!((r.resumed, r.made, r.shards_written), (9, 0, 0));
}

#[test]
fn a_shard_written_but_not_recorded_is_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut o = options(1);
    o.max_new_samples = Some(4);
    generate(FAST, d, &o);
    // As if killed between writing shard 1 and the manifest.
    let mut m = Manifest::load(d).unwrap();
    m.remove_shard(1);
    m.save(d).unwrap();
    let r = generate(FAST, d, &options(1));
    assert!(r.complete && r.made == 5, "{r:?}");
    assert_same_shards(d);
}

#[test]
fn another_spec_in_the_same_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut o = options(1);
    o.max_new_samples = Some(1);
    generate(FAST, dir.path(), &o);
    let other = common::spec(&FAST.replace("seed = 3", "seed = 4"));
    let e = dataset::generate(common::model(), &other, dir.path(), &o).unwrap_err();
    assert!(e.to_string().contains("another spec"), "{e}");
}
