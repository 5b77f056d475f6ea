//! The plan: splits never share a body, unseen-pose splits never share a pose, and every
//! sample is a pure function of the spec and its index. No drapes: clip frame counts are
//! given directly.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use dataset::{LoadedSpec, Manifest, Plan};

const SPEC: &str = r#"
format = 2
seed = 17
shard_size = 8
[bodies]
count = 60
[[garments]]
kind = "tshirt"
edge = 0.03
poses_per_body = 6
[[garments]]
kind = "jeans"
edge = 0.03
poses_per_body = 3
cut_ranges = { leg_length = [0.6, 0.8] }
[[poses.amc]]
clips = ["cmu/02/02_01.amc", "cmu/02/02_02.amc"]
every = 10
[[poses.bvh]]
clips = ["x/walk.bvh"]
random = 12
[[poses.procedural]]
kind = "yoga"
count = 20
[[poses.procedural]]
kind = "dance"
count = 20
[splits.bodies]
train = 0.8
val = 0.05
test = 0.15
"#;

const FRAMES: [usize; 3] = [343, 250, 500];

fn plan(text: &str) -> Plan {
    let spec = LoadedSpec::parse(text, Path::new("s.toml")).unwrap();
    Plan::new(&spec, &FRAMES).unwrap()
}

fn unseen(text: &str, fraction: f64) -> String {
    format!("{text}[splits.unseen_poses]\nseen_fraction = {fraction}\nheld_out = [\"test\"]\n")
}

#[test]
fn splits_have_the_asked_sizes_and_never_share_a_body() {
    let p = plan(SPEC);
    let sizes: BTreeMap<&str, usize> = p
        .split_names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), p.split_bodies(i).len()))
        .collect();
    assert_eq!(
        sizes,
        BTreeMap::from([("test", 9), ("train", 48), ("val", 3)])
    );
    let mut body_split = BTreeMap::new();
    for k in 0..p.total() {
        let s = p.sample(k);
        let prev = body_split.insert(s.body, s.split);
        assert!(
            prev.is_none_or(|x| x == s.split),
            "body {} in two splits",
            s.body
        );
    }
    assert_eq!(body_split.len(), 60);
    assert_eq!(p.total(), 60 * 6 + 60 * 3);
}

#[test]
fn samples_are_a_function_of_the_seed_and_index() {
    let (a, b) = (plan(SPEC), plan(SPEC));
    let ka: Vec<_> = (0..a.total()).map(|k| a.sample(k)).collect();
    // Any order, any subset: the same samples.
    for k in (0..b.total()).rev().step_by(7) {
        assert_eq!(b.sample(k), ka[k as usize]);
    }
    // Each body wears distinct poses of a garment.
    for g in 0..2 {
        for body in 0..60u32 {
            let poses: Vec<usize> = ka
                .iter()
                .filter(|s| s.garment == g && s.body == body)
                .map(|s| s.pose)
                .collect();
            let distinct: BTreeSet<_> = poses.iter().collect();
            assert_eq!(distinct.len(), poses.len());
        }
    }
    let other = plan(&SPEC.replace("seed = 17", "seed = 18"));
    let differs = (0..a.total()).filter(|&k| other.sample(k).pose != ka[k as usize].pose);
    assert!(differs.count() > a.total() as usize / 2);
}

#[test]
fn unseen_pose_splits_share_no_pose_with_the_others() {
    for fraction in [0.5, 0.25] {
        let p = plan(&unseen(SPEC, fraction));
        let test = p.split_names.iter().position(|n| n == "test").unwrap();
        let (mut held, mut open) = (BTreeSet::new(), BTreeSet::new());
        for k in 0..p.total() {
            let s = p.sample(k);
            if s.split == test {
                held.insert(s.pose);
            } else {
                open.insert(s.pose);
            }
        }
        assert!(held.is_disjoint(&open), "fraction {fraction}");
        assert!(!held.is_empty() && !open.is_empty());
        // Within every motion, the open share is `fraction` of its poses.
        for m in &p.pool.motions {
            let n = m.range.len() as f64;
            let seen = m.range.clone().filter(|&i| p.pool.seen[i]).count() as f64;
            assert!(
                (seen - fraction * n).abs() <= 1.0,
                "{}: {seen} of {n}",
                m.name
            );
        }
    }
}

#[test]
fn pool_and_shards_cover_the_samples() {
    let p = plan(SPEC);
    assert_eq!(p.pool.poses.len(), 35 + 25 + 12 + 20 + 20);
    assert_eq!(p.pool.pose_id(0), "cmu/02/02_01.amc#0");
    assert_eq!(
        p.pool.pose_id(p.pool.poses.len() - 1),
        "procedural[1]:dance#19"
    );
    let covered: u64 = (0..p.shard_count())
        .map(|s| p.shard_range(s).count() as u64)
        .sum();
    assert_eq!(covered, p.total());
    assert!((0..p.total()).all(|k| p.shard_range(p.shard_of(k)).contains(&k)));
}

/// `Plan::shards_holding` (by body ranges) against a plain walk over every sample.
#[test]
fn shards_holding_a_split_and_garment_are_those_of_its_samples() {
    let p = plan(SPEC);
    let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    for (splits, garments) in [
        (names(&["test"]), names(&[])),
        (names(&["val"]), names(&["jeans"])),
        (names(&["val", "test"]), names(&["tshirt"])),
        (names(&[]), names(&[])),
    ] {
        let reference: BTreeSet<u64> = (0..p.total())
            .map(|k| p.sample(k))
            .filter(|d| splits.is_empty() || splits.contains(&p.split_names[d.split]))
            .filter(|d| garments.is_empty() || garments.contains(&p.garments[d.garment].name))
            .map(|d| p.shard_of(d.index))
            .collect();
        let got = p.shards_holding(&splits, &garments).unwrap();
        assert_eq!(
            got,
            reference.into_iter().collect::<Vec<_>>(),
            "{splits:?} {garments:?}"
        );
    }
    let test_only = p.shards_holding(&names(&["test"]), &[]).unwrap();
    assert!(!test_only.is_empty() && (test_only.len() as u64) < p.shard_count());
    for (splits, garments, named) in [
        (
            names(&["tset"]),
            names(&[]),
            "no split 'tset' (the splits are test, train, val)",
        ),
        (
            names(&[]),
            names(&["shirt"]),
            "no garment 'shirt' (the garments are tshirt, jeans)",
        ),
    ] {
        let err = p
            .shards_holding(&splits, &garments)
            .unwrap_err()
            .to_string();
        assert!(err.contains(named), "{err}");
    }
}

#[test]
fn datasets_drawing_bodies_alike_share_bodies_split_by_split() {
    let manifest = |text: &str| {
        let spec = LoadedSpec::parse(text, Path::new("s.toml")).unwrap();
        Manifest::new(&spec, &Plan::new(&spec, &FRAMES).unwrap(), Vec::new())
    };
    let base = manifest(SPEC);
    // More poses per body (as standard-x9-lbs to standard-lbs): the same bodies in the same
    // splits.
    let more = manifest(&SPEC.replace("poses_per_body = 6", "poses_per_body = 18"));
    assert!(more
        .shared_bodies("train", &base, "test")
        .unwrap()
        .is_empty());
    assert_eq!(
        more.shared_bodies("test", &base, "test").unwrap(),
        base.splits["test"]
    );
    assert_eq!(
        base.shared_bodies("train", &base, "train").unwrap().len(),
        48
    );
    // Another seed draws other bodies: nothing can be matched.
    let other = manifest(&SPEC.replace("seed = 17", "seed = 18"));
    let err = other.shared_bodies("train", &base, "test").unwrap_err();
    assert!(
        err.to_string().contains("draw their bodies differently"),
        "{err}"
    );
    let err = base.shared_bodies("train", &base, "holdout").unwrap_err();
    assert!(err.to_string().contains("no split 'holdout'"), "{err}");
}
