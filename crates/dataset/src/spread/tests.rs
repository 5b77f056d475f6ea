//! Tests of the spread measurement.

use super::report::*;
use super::*;

#[test]
fn samples_are_spread_evenly_and_deterministically() {
    assert_eq!(spread_evenly(10, 5), vec![0, 2, 4, 6, 8]);
    assert_eq!(spread_evenly(10, 3), vec![0, 3, 6]);
    assert_eq!(spread_evenly(3, 40), vec![0, 1, 2]);
    assert_eq!(spread_evenly(0, 4), Vec::<usize>::new());
    for (count, n) in [(800, 40), (1000, 7), (41, 40), (5, 1)] {
        let picks = spread_evenly(count, n);
        assert_eq!(picks.len(), n);
        assert!(picks.windows(2).all(|w| w[0] < w[1]), "{picks:?}");
        assert!(*picks.last().unwrap() < count);
        // Gaps differ by at most one: evenly spread.
        let gaps: Vec<usize> = picks.windows(2).map(|w| w[1] - w[0]).collect();
        if let (Some(lo), Some(hi)) = (gaps.iter().min(), gaps.iter().max()) {
            assert!(hi - lo <= 1, "{gaps:?}");
        }
        assert_eq!(picks, spread_evenly(count, n));
    }
}

#[test]
fn chosen_samples_follow_the_split_in_plan_order() {
    let text = r#"
format = 2
seed = 3
[bodies]
count = 6
[[garments]]
kind = "tshirt"
edge = 0.05
poses_per_body = 2
[[garments]]
kind = "jeans"
edge = 0.05
poses_per_body = 1
[[poses.procedural]]
kind = "walk"
count = 4
[splits.bodies]
train = 3
test = 3
"#;
    let spec = LoadedSpec::parse(text, std::path::Path::new("spread.toml")).unwrap();
    let library = PoseLibrary::load(&spec.spec, None).unwrap();
    let plan = Plan::new(&spec, &library.frame_counts()).unwrap();
    let test = plan.split_names.iter().position(|n| n == "test").unwrap();
    let all = chosen_samples(&plan, test, 100);
    assert_eq!(all.len(), 2);
    assert_eq!((all[0].len(), all[1].len()), (6, 3));
    for (g, ks) in all.iter().enumerate() {
        assert!(ks.windows(2).all(|w| w[0] < w[1]));
        for &k in ks {
            let d = plan.sample(k);
            assert_eq!((d.garment, d.split), (g, test));
        }
    }
    let two = chosen_samples(&plan, test, 2);
    assert_eq!(two[0], vec![all[0][0], all[0][3]]);
    assert_eq!(two[1], vec![all[1][0], all[1][1]]);
    assert_eq!(two, chosen_samples(&plan, test, 2));
}

#[test]
fn overrides_replace_the_spec_key_by_key() {
    let spec = SimulatorSpec {
        density: Some(0.2),
        max_settle_steps: Some(300),
        skinning: Some("lbs".into()),
        waistband: Some(false),
        ..Default::default()
    };
    let over = SimulatorSpec {
        max_settle_steps: Some(50),
        friction: Some(0.3),
        waistband: Some(true),
        ..Default::default()
    };
    let m = merged_simulator(&spec, &over);
    assert_eq!(
        m,
        SimulatorSpec {
            density: Some(0.2),
            max_settle_steps: Some(50),
            friction: Some(0.3),
            skinning: Some("lbs".into()),
            waistband: Some(true),
            ..Default::default()
        }
    );
    assert_eq!(merged_simulator(&spec, &SimulatorSpec::default()), spec);
    assert_eq!(merged_simulator(&SimulatorSpec::default(), &over), over);
}

fn figures(converged: bool, settle: u32, strain: f32, pen: f32, wall: f64) -> DrapeFigures {
    DrapeFigures {
        converged,
        animation_steps: 50,
        settle_steps: settle,
        strain_p99: strain,
        max_penetration_m: pen,
        wall_time_s: wall,
    }
}

fn row(index: u64, dist: [f32; 2], norm: [f32; 2], drapes: [Option<DrapeFigures>; 3]) -> SpreadRow {
    let all = drapes.iter().all(Option::is_some);
    SpreadRow {
        index,
        garment: "tshirt".into(),
        body: index as u32,
        pose: format!("walk#{index}"),
        e_dist_up_cm: all.then_some(dist[0]),
        e_dist_down_cm: all.then_some(dist[1]),
        e_norm_up_deg: all.then_some(norm[0]),
        e_norm_down_deg: all.then_some(norm[1]),
        drapes: drapes
            .into_iter()
            .zip(VARIANTS)
            .map(|(f, v)| SpreadDrape {
                variant: v.into(),
                density_kg_m2: 0.15,
                error: f.is_none().then(|| "drape: diverged".to_string()),
                figures: f,
            })
            .collect(),
        error: None,
    }
}

#[test]
fn aggregation_of_hand_made_rows() {
    let f = figures;
    let rows = vec![
        row(
            1,
            [0.1, 0.3],
            [1.0, 2.0],
            [
                Some(f(true, 100, 0.01, 0.0005, 1.0)),
                Some(f(true, 120, 0.01, 0.0, 2.0)),
                Some(f(false, 400, 0.03, 0.0002, 3.0)),
            ],
        ),
        row(
            2,
            [0.5, 0.7],
            [3.0, 4.0],
            [
                Some(f(true, 80, 0.015, 0.0001, 1.0)),
                Some(f(true, 90, 0.01, 0.0, 1.0)),
                Some(f(true, 100, 0.01, 0.0, 1.0)),
            ],
        ),
        // The up drape failed: no distances, its base still counts.
        row(
            3,
            [9.0, 9.0],
            [9.0, 9.0],
            [
                Some(f(false, 400, 0.05, 0.0009, 2.0)),
                None,
                Some(f(true, 60, 0.01, 0.0, 2.0)),
            ],
        ),
        SpreadRow {
            drapes: Vec::new(),
            error: Some("procedural pose: no valid pose".into()),
            ..row(4, [0.0; 2], [0.0; 2], [None, None, None])
        },
    ];
    let g = summarise("tshirt", &rows, 30.0);
    let close = |a: Option<f64>, b: f64| {
        assert!((a.unwrap() - b).abs() < 1e-6, "{a:?} vs {b}");
    };
    assert_eq!((g.samples, g.drapes, g.failed, g.compared), (4, 12, 4, 2));
    close(g.e_dist_up_cm, 0.3);
    close(g.e_dist_down_cm, 0.5);
    close(g.e_dist_cm, 0.4);
    close(g.e_norm_up_deg, 2.0);
    close(g.e_norm_down_deg, 3.0);
    close(g.e_norm_deg, 2.5);
    // Base drapes made: rows 1, 2, 3; at rest: 1 and 2.
    close(g.base_at_rest, 2.0 / 3.0);
    // Compared rows 1 and 2: only 2 has all three at rest.
    close(g.all_at_rest, 0.5);
    assert_eq!(g.max_penetration_m, Some(0.0009));
    // 8 drapes made; strain p99 under 2%: all but two.
    close(g.strain_ok, 6.0 / 8.0);
    // Settle steps 60 80 90 100 100 120 400 400: median (100 + 100) / 2.
    close(g.median_settle_steps, 100.0);
    close(g.median_animation_steps, 50.0);
    close(g.mean_drape_s, 13.0 / 8.0);
    close(Some(g.drapes_per_min), 24.0);
    assert_eq!(g.failures.len(), 2);
    assert_eq!(
        (g.failures[0].index, g.failures[0].variant.as_str()),
        (3, "up")
    );
    assert_eq!(
        (g.failures[1].index, g.failures[1].variant.as_str()),
        (4, "all")
    );
    assert!(g.failures[1].message.contains("no valid pose"));
    // No rows: no figures, no division by zero.
    let none = summarise("jeans", &[], 0.0);
    assert_eq!(
        (none.samples, none.e_dist_cm, none.drapes_per_min),
        (0, None, 0.0)
    );
}

#[test]
fn report_renders_a_table_and_csv() {
    let f = figures(true, 10, 0.01, 0.0, 1.5);
    let rows = vec![row(
        7,
        [0.25, 0.5],
        [1.0, 1.5],
        [Some(f.clone()), Some(f.clone()), Some(f)],
    )];
    let report = SpreadReport {
        spec_name: "t".into(),
        spec_path: "t.toml".into(),
        spec_hash: "0123456789abcdef0123".into(),
        split: "test".into(),
        per_garment: 1,
        step: 0.001,
        densities_kg_m2: [0.15, 0.15015, 0.14985],
        simulator_file: None,
        simulator: SimulatorSpec::default(),
        jobs: 1,
        wall_s: 4.5,
        drapes_per_min: 40.0,
        garments: vec![summarise("tshirt", &rows, 4.5)],
        rows,
    };
    let md = report.markdown();
    assert!(
        md.contains("| tshirt | 3 | 0 | 0.250 / 0.500 | 0.375 |"),
        "{md}"
    );
    let csv = report.csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(
        lines[1],
        "7,tshirt,7,walk#7,0.25,0.5,1,1.5,true,true,true,10,10,10,0.01,4.500,"
    );
    assert_eq!(
        lines[0].split(',').count(),
        lines[1].split(',').count(),
        "{csv}"
    );
    let json = serde_json::to_string(&report).unwrap();
    let back: SpreadReport = serde_json::from_str(&json).unwrap();
    assert_eq!(back, report);
    assert_eq!(csv_field("a,b \"c\""), "\"a,b \"\"c\"\"\"");
}
