//! The first phase of a drape: the garment graded to the target body, placed on the
//! template body, and carried along while that body morphs into the target's rest shape.
//! Nothing of it depends on the pose, so every drape of one garment on one body can start
//! from one [`Morphed`] (the dataset makes up to 36 per body): [`crate::drape::drape`]
//! is [`morph`] followed by [`crate::drape::drape_morphed`], with the same result to the
//! bit.

use body::ShapedBody;
use garment::warp::SurfaceAnchors;
use garment::GarmentTemplate;
use geom::TriMesh;
use glam::Vec3;

use crate::drape::{DrapeOptions, FrameObserver, Start};
use crate::{BodyCollider, ClothSim, SimError};

/// The cloth on the target body in its rest pose, after the shape morph.
#[derive(Clone, Debug)]
pub struct Morphed {
    /// The cloth: graded rest shape, state and factored system.
    pub(crate) sim: ClothSim,
    /// The body collider, at the target's rest shape.
    pub(crate) collider: BodyCollider,
    /// The template's surface anchors on the template body (where `slid_m` measures from).
    pub(crate) anchors: SurfaceAnchors,
    /// Steps taken so far (the morph's).
    pub(crate) steps: u32,
    /// Total mass of the cloth, kg.
    pub(crate) mass: f32,
    /// Wall time of making it (set-up and morph), seconds: counted into the wall time of
    /// every drape finished from it, which is thus what a drape from scratch takes.
    pub(crate) wall_time_s: f64,
}

/// Grades `template` (fitted on `template_body`, its rest shape) to `target` and carries it
/// through the morph of the body from the template shape to the target's rest shape.
/// `on_frame(step, garment [N], body [V])` sees every step, metres. Errors if the bodies do
/// not share a mesh, the template is empty, or the cloth diverges.
pub fn morph(
    template: &GarmentTemplate,
    template_body: &ShapedBody,
    target: &ShapedBody,
    opts: &DrapeOptions,
    on_frame: &mut FrameObserver<'_>,
) -> Result<Morphed, SimError> {
    let start = std::time::Instant::now();
    if template_body.mesh.vertices.len() != target.mesh.vertices.len()
        || template.mesh.vertices.is_empty()
    {
        return Err(SimError::InvalidInput(
            "the target body does not share the template body's mesh".into(),
        ));
    }
    let anchors = SurfaceAnchors::new(&template.mesh, &template_body.mesh)
        .map_err(|e| SimError::InvalidInput(e.to_string()))?;
    let (mut rest, rest_body) = if opts.grade {
        (anchors.place(&target.mesh), &target.mesh)
    } else {
        (template.mesh.vertices.clone(), &template_body.mesh)
    };
    let stretch_scale = match &opts.waistband {
        Some(band) => band.apply(template, &mut rest, rest_body)?,
        None => None,
    }
    .unwrap_or_else(|| vec![1.0; rest.len()]);
    let rest = TriMesh {
        vertices: rest,
        faces: template.mesh.faces.clone(),
    };
    let mut sim = ClothSim::with_stretch_scale(&rest, &opts.cloth, &stretch_scale)?;
    sim.set_positions(&template.mesh.vertices)?;
    let fitted = opts.start == Start::Fitted;
    let start_body = if fitted {
        &target.mesh
    } else {
        &template_body.mesh
    };
    let mut m = Morphed {
        sim,
        collider: BodyCollider::new(start_body, opts.cloth.thickness)?,
        anchors,
        steps: 0,
        mass: cloth_mass(&template.mesh, opts.cloth.density),
        wall_time_s: 0.0,
    };
    // The body's rest mesh morphs linearly from the template shape to the target's.
    let morphed = |t: f32| -> Result<Vec<Vec3>, SimError> {
        Ok(template_body
            .mesh
            .vertices
            .iter()
            .zip(&target.mesh.vertices)
            .map(|(a, b)| a.lerp(*b, t))
            .collect())
    };
    let morph_steps = if fitted {
        0
    } else {
        crate::drape::phase_steps(opts.morph_steps, opts.body_step, 1, &morphed)?
    };
    for k in 1..=morph_steps {
        let body = morphed(k as f32 / morph_steps as f32)?;
        m.advance(&body, opts, on_frame)?;
    }
    m.wall_time_s = start.elapsed().as_secs_f64();
    Ok(m)
}

impl Morphed {
    /// Wall time of making it (set-up and morph), seconds.
    pub fn wall_time_s(&self) -> f64 {
        self.wall_time_s
    }

    /// Errors unless this cloth was morphed from `template` onto a body of `target`'s mesh.
    pub(crate) fn check_fits(
        &self,
        template: &GarmentTemplate,
        target: &ShapedBody,
    ) -> Result<(), SimError> {
        if self.sim.positions().len() != template.mesh.vertices.len()
            || self.collider.vertices().len() != target.mesh.vertices.len()
        {
            return Err(SimError::InvalidInput(format!(
                "the morphed cloth ({} vertices on a body of {}) is not of this garment ({} vertices) and body ({})",
                self.sim.positions().len(),
                self.collider.vertices().len(),
                template.mesh.vertices.len(),
                target.mesh.vertices.len()
            )));
        }
        Ok(())
    }

    /// Root-mean-square speed of the cloth, m/s.
    pub(crate) fn rms_speed(&self) -> f32 {
        (2.0 * self.sim.kinetic_energy() / self.mass).sqrt()
    }

    /// Holds the body at `body` (`[V]` metres) and places the cloth at `start` (`[N]`
    /// metres), at rest, moving every vertex inside the body (or nearer it than half the
    /// thickness) out.
    pub(crate) fn place_at(&mut self, body: &[Vec3], start: &[Vec3]) -> Result<(), SimError> {
        self.collider.move_to(body)?;
        self.collider.commit();
        self.sim.set_positions(start)?;
        self.sim.project_out_of(&self.collider);
        Ok(())
    }

    /// One step with the body at `body` (`[V]` metres): errors if the cloth diverged.
    pub(crate) fn advance(
        &mut self,
        body: &[Vec3],
        opts: &DrapeOptions,
        on_frame: &mut FrameObserver<'_>,
    ) -> Result<(), SimError> {
        self.collider.move_to(body)?;
        self.sim.step(Some(&mut self.collider))?;
        let speed = self.rms_speed();
        if !speed.is_finite() || speed > opts.explode_speed {
            return Err(SimError::Diverged(format!(
                "cloth speed {speed:.1} m/s at step {}",
                self.steps
            )));
        }
        on_frame(self.steps, self.sim.positions(), body);
        self.steps += 1;
        Ok(())
    }
}

/// Total mass of a cloth mesh of `density` kg/m^2.
fn cloth_mass(mesh: &TriMesh, density: f32) -> f32 {
    geom::normals::face_areas(&mesh.vertices, &mesh.faces)
        .iter()
        .sum::<f32>()
        * density
}
