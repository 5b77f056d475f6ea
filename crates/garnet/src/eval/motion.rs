//! `garnet eval`'s breakdown by motion: the network's and the DQS warp's E_dist over the
//! drapes of each pose source (a CMU clip, or a kind of procedural pose), to show where the
//! error is.

use std::collections::BTreeMap;

use serde::Serialize;

/// The motion a dataset pose id comes from: the clip's file stem (`02_07` for
/// `cmu/02/02_07.amc#120`), or `procedural KIND` for `procedural[S]:KIND#DRAW`.
pub fn motion_of(pose: &str) -> String {
    let source = pose.split('#').next().unwrap_or(pose);
    match source.split_once(':') {
        Some((p, kind)) if p.starts_with("procedural") => format!("procedural {kind}"),
        _ => std::path::Path::new(source)
            .file_stem()
            .map_or_else(|| source.to_string(), |s| s.to_string_lossy().into_owned()),
    }
}

/// E_dist (cm) of a model and of the DQS warp over one motion's drapes.
#[derive(Serialize)]
pub struct MotionRow {
    garment: String,
    method: String,
    motion: String,
    samples: usize,
    e_dist_cm: f32,
    dqs_e_dist_cm: f32,
}

impl MotionRow {
    /// Names the row's method `method`.
    pub fn set_method(&mut self, method: &str) {
        self.method = method.into();
    }

    /// Appends `suffix` to the method name.
    pub fn add_to_method(&mut self, suffix: &str) {
        self.method.push_str(suffix);
    }
}

/// Drape count and summed E_dist (cm) of the network and of DQS, by motion.
#[derive(Default)]
pub struct ByMotion(BTreeMap<String, (usize, f64, f64)>);

impl ByMotion {
    /// Records one drape of pose id `pose`: the network's and the DQS warp's mean vertex
    /// distance, cm.
    pub fn add(&mut self, pose: &str, net_cm: f32, dqs_cm: f32) {
        let (count, net, dqs) = self.0.entry(motion_of(pose)).or_default();
        *count += 1;
        *net += net_cm as f64;
        *dqs += dqs_cm as f64;
    }

    /// One row per motion, in name order.
    pub fn rows(&self, garment: &str, method: &str) -> Vec<MotionRow> {
        self.0
            .iter()
            .map(|(motion, &(count, net, dqs))| MotionRow {
                garment: garment.into(),
                method: method.into(),
                motion: motion.clone(),
                samples: count,
                e_dist_cm: (net / count as f64) as f32,
                dqs_e_dist_cm: (dqs / count as f64) as f32,
            })
            .collect()
    }
}

/// The markdown section of `rows`.
pub fn markdown(rows: &[MotionRow]) -> String {
    let mut md = String::from(
        "\n## E_dist by motion\n\n| garment | method | motion | samples | E_dist (cm) | DQS E_dist (cm) |\n|---|---|---|---:|---:|---:|\n",
    );
    for r in rows {
        md += &format!(
            "| {} | {} | {} | {} | {:.3} | {:.3} |\n",
            r.garment, r.method, r.motion, r.samples, r.e_dist_cm, r.dqs_e_dist_cm
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motions_are_clips_and_procedural_kinds() {
        assert_eq!(motion_of("cmu/02/02_07.amc#120"), "02_07");
        assert_eq!(motion_of("procedural[2]:yoga#80"), "procedural yoga");
        assert_eq!(motion_of("clips/run.bvh#3"), "run");
        let mut m = ByMotion::default();
        m.add("procedural[2]:yoga#1", 3.0, 6.0);
        m.add("procedural[2]:yoga#7", 1.0, 4.0);
        m.add("cmu/02/02_01.amc#90", 2.0, 5.0);
        let rows = m.rows("tshirt", "GarNet-local");
        assert_eq!(rows.len(), 2);
        assert_eq!(
            (rows[1].motion.as_str(), rows[1].samples),
            ("procedural yoga", 2)
        );
        assert_eq!((rows[1].e_dist_cm, rows[1].dqs_e_dist_cm), (2.0, 5.0));
        assert!(markdown(&rows).contains("| tshirt | GarNet-local | 02_01 | 1 | 2.000 | 5.000 |"));
    }
}
