//! `garnet eval --pictures`: the same drape drawn by every evaluated model, beside the
//! simulator's, one row per garment (`drapes.png`), so that a table's rows can be compared by
//! eye (folds kept or smoothed away, cloth sunk into the body).
//!
//! The drape shown for a garment is the one of median E_dist among the first model of that
//! garment's drapes: a typical drape, not a chosen one.

use anyhow::Context;
use glam::Vec3;
use render::{palette, Image, RenderMesh, RenderOptions, Sheet, View};

use super::ModelEvaluation;
use crate::eval::EvalData;

/// Pixels of one picture (width, height).
const PANEL: (u32, u32) = (260, 420);

/// Every drape one model made on a split, kept for the pictures.
#[derive(Default)]
pub struct KeptDrapes {
    /// `[S]` dataset sample indices, in evaluation order.
    indices: Vec<u64>,
    /// `[S]` the network's drapes, `[N]` positions each, metres.
    drapes: Vec<Vec<Vec3>>,
    /// `[S]` E_dist of each drape, cm.
    e_dist_cm: Vec<f32>,
}

impl KeptDrapes {
    /// Keeps the network's drape `pred` (`[N]`, metres) of sample `index`, E_dist `e_dist_cm`.
    pub fn push(&mut self, index: u64, pred: &[Vec3], e_dist_cm: f32) {
        self.indices.push(index);
        self.drapes.push(pred.to_vec());
        self.e_dist_cm.push(e_dist_cm);
    }

    /// The sample of median E_dist (the upper median for an even count), when any.
    fn median_sample(&self) -> Option<u64> {
        let mut order: Vec<usize> = (0..self.indices.len()).collect();
        order.sort_by(|&a, &b| self.e_dist_cm[a].total_cmp(&self.e_dist_cm[b]));
        order.get(order.len() / 2).map(|&k| self.indices[k])
    }

    /// The drape of sample `index` and its E_dist (cm), when this model drew it.
    fn drape_of(&self, index: u64) -> Option<(&[Vec3], f32)> {
        let k = self.indices.iter().position(|&i| i == index)?;
        Some((&self.drapes[k], self.e_dist_cm[k]))
    }
}

/// The colour a garment is drawn in.
fn garment_color(garment: &str) -> [u8; 3] {
    match garment {
        g if g.contains("jeans") => palette::JEANS_INDIGO,
        g if g.contains("sweater") => palette::SWEATER_RED,
        g if g.contains("shirt") => palette::TSHIRT_BLUE,
        _ => palette::OLIVE,
    }
}

/// The front view of `garment` (`[N]`, metres, on `faces`) on `body` (`[V]`, on
/// `body_faces`).
fn picture(
    body: &[Vec3],
    body_faces: &[[u32; 3]],
    garment: &[Vec3],
    faces: &[[u32; 3]],
    color: [u8; 3],
) -> anyhow::Result<Image> {
    let scene = [
        RenderMesh::new(body, body_faces, palette::SKIN),
        RenderMesh::new(garment, faces, color),
    ];
    Ok(render::render_view(
        &scene,
        View::Front,
        PANEL,
        &RenderOptions::default(),
    )?)
}

/// The sheet of `evaluations` (those that kept their drapes): per garment, in the order the
/// garments first appear, the simulator's drape of the chosen sample and then every model's
/// of the same sample, captioned with the row's method and that drape's E_dist. `None` when
/// no evaluation kept a drape.
pub fn draw(data: &EvalData, evaluations: &[ModelEvaluation]) -> anyhow::Result<Option<Image>> {
    let mut garments: Vec<&str> = Vec::new();
    for e in evaluations.iter().filter(|e| e.kept.is_some()) {
        if !garments.contains(&e.garment.as_str()) {
            garments.push(&e.garment);
        }
    }
    fn of<'a>(
        evaluations: &'a [ModelEvaluation],
        g: &'a str,
    ) -> impl Iterator<Item = (&'a ModelEvaluation, &'a KeptDrapes)> + 'a {
        evaluations
            .iter()
            .filter(move |e| e.garment == g)
            .filter_map(|e| Some((e, e.kept.as_ref()?)))
    }
    let cols = 1 + garments
        .iter()
        .map(|g| of(evaluations, g).count())
        .max()
        .unwrap_or(0);
    let mut sheet = Sheet::new(cols);
    for &g in &garments {
        let Some(index) = of(evaluations, g)
            .next()
            .and_then(|(_, k)| k.median_sample())
        else {
            continue;
        };
        let sample = data
            .dataset()
            .sample(index)
            .with_context(|| format!("reading sample {index} for the pictures"))?;
        let a = &sample.arrays;
        let faces = &data.dataset().template(&sample.record.template)?.mesh.faces;
        let color = garment_color(g);
        let draw = |garment: &[Vec3]| picture(&a.body, &data.body_faces, garment, faces, color);
        sheet.push(draw(&a.draped)?, format!("simulator: {g} sample {index}"));
        let mut shown = 1;
        for (e, kept) in of(evaluations, g) {
            if let Some((pred, e_dist)) = kept.drape_of(index) {
                sheet.push(draw(pred)?, format!("{}: {e_dist:.2} cm", e.net.method));
                shown += 1;
            }
        }
        for _ in shown..cols {
            sheet.push(Image::new(PANEL.0, PANEL.1, palette::BACKGROUND), "");
        }
    }
    Ok((!sheet.is_empty()).then(|| sheet.compose()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_drape_is_chosen_and_found_again() {
        let mut k = KeptDrapes::default();
        for (i, e) in [(10, 3.0), (11, 1.0), (12, 2.0), (13, 5.0)] {
            k.push(i, &[Vec3::splat(e)], e);
        }
        // E_dist sorted: 1 (11), 2 (12), 3 (10), 5 (13); the upper median is 10.
        assert_eq!(k.median_sample(), Some(10));
        let (d, e) = k.drape_of(12).unwrap();
        assert_eq!((d[0], e), (Vec3::splat(2.0), 2.0));
        assert!(k.drape_of(99).is_none());
        assert_eq!(KeptDrapes::default().median_sample(), None);
    }
}
