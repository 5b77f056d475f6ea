//! `garnet eval --save-drapes DIR`: every evaluated drape as meshes, to look at in a 3D tool
//! or to analyse elsewhere, and a table of each drape's errors to find the worst ones.
//!
//! For the model file `NAME.garnet`, `DIR/NAME/` (see [`save_folders`] when two models share
//! a file name) gets, per sample index `I` (zero-padded to six digits): `I-net.ply` (the network's drape, before any push-out), `I-sim.ply` (the
//! simulator's), `I-dqs.ply` (the warped template M, the network's input) and `I-body.ply`
//! (the posed body), in metres; and `samples.csv`: index, pose id, the network's E_dist (cm)
//! and E_norm (degrees), and the DQS warp's E_dist (cm). Every file is written atomically.

use std::path::{Path, PathBuf};

use anyhow::Context;
use geom::TriMesh;
use glam::Vec3;

/// One evaluated drape as [`DrapeSaver::save`] takes it: positions in metres, `[N]` for the
/// garment meshes (the template's vertex order) and `[V]` for the body.
pub struct SavedDrape<'a> {
    /// The dataset's sample index.
    pub index: u64,
    /// The sample's pose id.
    pub pose: &'a str,
    /// The posed body `[V]`.
    pub body: &'a [Vec3],
    /// The simulator's drape `[N]`.
    pub sim: &'a [Vec3],
    /// The warped template M `[N]`.
    pub dqs: &'a [Vec3],
    /// The network's drape `[N]`.
    pub net: &'a [Vec3],
    /// The network's E_dist (cm) and E_norm (degrees), and the DQS warp's E_dist (cm).
    pub errors: [f32; 3],
}

/// Writes one model's evaluated drapes into its own folder.
pub struct DrapeSaver<'a> {
    dir: PathBuf,
    garment_faces: &'a [[u32; 3]],
    body_faces: &'a [[u32; 3]],
    rows: Vec<String>,
}

impl<'a> DrapeSaver<'a> {
    /// Creates the folder `dir` for one model; `garment_faces` are its template's triangles,
    /// `body_faces` the dataset body's.
    pub fn new(
        dir: &Path,
        garment_faces: &'a [[u32; 3]],
        body_faces: &'a [[u32; 3]],
    ) -> anyhow::Result<Self> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(DrapeSaver {
            dir: dir.to_path_buf(),
            garment_faces,
            body_faces,
            rows: Vec::new(),
        })
    }

    /// Writes the four meshes of `drape` and remembers its row of `samples.csv`.
    pub fn save(&mut self, drape: &SavedDrape) -> anyhow::Result<()> {
        let meshes = [
            ("net", drape.net, self.garment_faces),
            ("sim", drape.sim, self.garment_faces),
            ("dqs", drape.dqs, self.garment_faces),
            ("body", drape.body, self.body_faces),
        ];
        for (what, vertices, faces) in meshes {
            let path = self.dir.join(format!("{:06}-{what}.ply", drape.index));
            let mesh = TriMesh::new(vertices.to_vec(), faces.to_vec());
            geom::io::write_mesh(&path, &mesh)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        let [dist, norm, dqs] = drape.errors;
        self.rows.push(format!(
            "{},{},{dist:.4},{norm:.3},{dqs:.4}",
            drape.index,
            csv_field(drape.pose)
        ));
        Ok(())
    }

    /// Writes `samples.csv` (one row per saved drape, in the order saved); returns the folder.
    pub fn finish(self) -> anyhow::Result<PathBuf> {
        let path = self.dir.join("samples.csv");
        geom::io::write_atomic(&path, |w| {
            writeln!(w, "index,pose,e_dist_cm,e_norm_deg,dqs_e_dist_cm")?;
            for row in &self.rows {
                writeln!(w, "{row}")?;
            }
            Ok(())
        })
        .with_context(|| format!("writing {}", path.display()))?;
        Ok(self.dir)
    }
}

/// One folder under `root` per model file of `models`, in order: the file stem
/// (`runs/a/best.garnet` -> `best`); where stems repeat, the parent folder's name before it
/// (`a-best`); where those repeat too, the model's position after it (`a-best-2`).
pub fn save_folders(root: &Path, models: &[PathBuf]) -> Vec<PathBuf> {
    let part = |p: Option<&Path>| {
        p.and_then(|p| p.file_stem())
            .map_or_else(|| "model".to_string(), |s| s.to_string_lossy().into_owned())
    };
    let count = |names: &[String], n: &String| names.iter().filter(|m| *m == n).count();
    let stems: Vec<String> = models.iter().map(|m| part(Some(m))).collect();
    let named: Vec<String> = models
        .iter()
        .zip(&stems)
        .map(|(m, stem)| match count(&stems, stem) {
            1 => stem.clone(),
            _ => format!("{}-{stem}", part(m.parent())),
        })
        .collect();
    named
        .iter()
        .enumerate()
        .map(|(i, n)| match count(&named, n) {
            1 => root.join(n),
            _ => root.join(format!("{n}-{}", i + 1)),
        })
        .collect()
}

/// `s` as one CSV field: quoted (inner quotes doubled) when it holds a comma or a quote.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_with_one_file_name_get_their_own_folders() {
        let paths = |v: &[&str]| v.iter().map(PathBuf::from).collect::<Vec<_>>();
        let root = Path::new("out");
        assert_eq!(
            save_folders(
                root,
                &paths(&["runs/a/best.garnet", "runs/b/best.garnet", "tshirt.garnet"])
            ),
            paths(&["out/a-best", "out/b-best", "out/tshirt"])
        );
        assert_eq!(
            save_folders(root, &paths(&["x/m.garnet", "y/x/m.garnet"])),
            paths(&["out/x-m-1", "out/x-m-2"])
        );
    }

    #[test]
    fn pose_ids_with_commas_or_quotes_are_quoted() {
        assert_eq!(csv_field("cmu/02/02_01.amc#10"), "cmu/02/02_01.amc#10");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
