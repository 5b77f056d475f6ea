//! An elastic waistband: what holds trousers up. The band along the waist opening is cut
//! to a smaller girth than the waist it is worn on and made of a softer, stretchier
//! material, so that worn it is stretched and presses on the body all round, and friction
//! holds the garment where it was put on.

use garment::waistband::waistband;
use garment::GarmentTemplate;
use geom::bvh::Bvh;
use geom::TriMesh;
use glam::Vec3;

use crate::SimError;

/// How a garment's waistband is made (see [`garment::waistband`]; garments without one,
/// the tops, are unaffected).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waistband {
    /// How far the band reaches below the waist opening, metres.
    pub width: f32,
    /// The band's girth at rest as a fraction of the body's girth under it (the skin under
    /// each band vertex, its horizontal distance from the band's centre scaled by this):
    /// under 1 the band must stretch by at least `1 / girth - 1` to go round the waist,
    /// whatever the garment's ease.
    pub girth: f32,
    /// The band's stretch modulus as a fraction of the cloth's
    /// ([`crate::ClothParams::stretch_stiffness`]).
    pub stiffness: f32,
}

impl Default for Waistband {
    /// A 4 cm band cut to 90% of the body's girth, 0.7 times as stiff as the cloth.
    /// Measured at 1 cm on the 30-drape sheet's ten jeans (jeans cut with
    /// `waist_height 0.10`, 2-4 cm ease): a band a tenth as stiff let the looser jeans slide
    /// (ease 4 cm: 2 of 10 still sliding after 400 settling steps, against none at 0.2 and
    /// 0.3); cut to 85% of the girth it held as well, but pressed the skin's facets through
    /// the cloth between its vertices. With the default jeans, stiffness 0.3 / 0.5 / 0.7
    /// all pass the sheet's ten; on 16 random 2 cm jeans drapes 10 / 12 / 12 pass and 14 /
    /// 15 / 16 come to rest (the weaker bands let a heavy belly push the jeans down and
    /// some jeans slide slowly). As stiff as the cloth the band would be overstretched
    /// cloth (strain p99 2-10%).
    fn default() -> Self {
        Self {
            width: 0.04,
            girth: 0.9,
            stiffness: 0.7,
        }
    }
}

impl Waistband {
    /// Makes the band in the cloth's rest shape `rest` (`[N]` metres, the garment on `body`
    /// in rest pose, updated in place) and returns each vertex's stretch modulus as a
    /// fraction of the cloth's (`[N]`: [`Waistband::stiffness`] in the band, 1 elsewhere),
    /// or `None` when `template` has no waistband. Errors on settings outside `(0, 1]`.
    pub fn apply(
        &self,
        template: &GarmentTemplate,
        rest: &mut [Vec3],
        body: &TriMesh,
    ) -> Result<Option<Vec<f32>>, SimError> {
        let fraction = |name: &str, v: f32| {
            if v.is_finite() && v > 0.0 && v <= 1.0 {
                Ok(())
            } else {
                Err(SimError::InvalidParams(format!(
                    "waistband {name} must be in (0, 1], got {v}"
                )))
            }
        };
        fraction("girth", self.girth)?;
        fraction("stiffness", self.stiffness)?;
        if !(self.width.is_finite() && self.width > 0.0) {
            return Err(SimError::InvalidParams(format!(
                "waistband width must be positive, got {} m",
                self.width
            )));
        }
        let Some(band) =
            waistband(template, self.width).map_err(|e| SimError::InvalidInput(e.to_string()))?
        else {
            return Ok(None);
        };
        // The skin is searched only for a garment that has a band.
        let bvh = Bvh::from_mesh(body)?;
        let inside = || rest.iter().zip(&band).filter(|(_, &b)| b).map(|(p, _)| *p);
        let count = inside().count().max(1) as f32;
        let centre = inside().sum::<Vec3>() / count;
        for (p, _) in rest.iter_mut().zip(&band).filter(|(_, &b)| b) {
            let skin = bvh.closest_point(*p).map_or(*p, |hit| hit.point);
            p.x = centre.x + (skin.x - centre.x) * self.girth;
            p.z = centre.z + (skin.z - centre.z) * self.girth;
        }
        Ok(Some(
            band.iter()
                .map(|&b| if b { self.stiffness } else { 1.0 })
                .collect(),
        ))
    }
}
