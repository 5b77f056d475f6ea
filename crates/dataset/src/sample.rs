//! Making one sample: the body of its index, its pose, its garment template, the drape
//! (G) and the paper's warp (M).

use std::sync::Arc;
use std::time::Instant;

use body::shape_sampler::stature_and_bmi;
use body::{BodyModel, Pose, ShapedBody, Skinning};
use garment::warp::{warp, warp_fitted, SurfaceAnchors};
use garment::GarmentTemplate;
use sim::drape::{drape_morphed, DrapeOptions};
use sim::morph::{morph, Morphed};

use crate::cache::KeyedCache;
use crate::error::{DatasetError, Result};
use crate::plan::{Plan, SampleDesc};
use crate::poses::PoseLibrary;
use crate::records::{FailureRecord, SampleRecord, SimStats, Timing};
use crate::spec::Spec;
use crate::templates::{TemplateError, TemplateStore};
use crate::tensors::SampleArrays;

/// A shaped body of the dataset, with its stature (m) and BMI (kg/m^2).
pub type BodyEntry = Arc<(ShapedBody, f32, f32)>;

/// What a sample drapes: its body, its garment template and its pose (see
/// [`Maker::inputs`]).
pub type SampleInputs = (BodyEntry, Arc<GarmentTemplate>, Pose);

/// Everything a worker needs to make samples.
pub struct Maker<'a> {
    /// The body model.
    pub model: &'a BodyModel,
    /// The template body (default phenotype, rest pose): where drapes start.
    pub template_body: ShapedBody,
    /// The spec.
    pub spec: &'a Spec,
    /// The plan.
    pub plan: &'a Plan,
    /// The clips.
    pub library: &'a PoseLibrary,
    /// Simulator settings.
    pub drape_options: DrapeOptions,
    /// Templates of the dataset folder.
    pub templates: TemplateStore,
    /// Recently shaped bodies.
    pub bodies: KeyedCache<u32, std::result::Result<BodyEntry, String>>,
    /// The cloth after the shape morph, by garment and body: the part of a drape that
    /// every pose of one body shares (the drapes are the same to the bit; only the morph
    /// is not simulated again). A failed morph is kept as its message.
    pub morphs: KeyedCache<(usize, u32), std::result::Result<Arc<Morphed>, String>>,
}

/// What became of a sample.
pub enum Outcome {
    /// Made: its record and arrays.
    Done(Box<(SampleRecord, SampleArrays)>),
    /// Not made, and why.
    Failed(FailureRecord),
}

impl Maker<'_> {
    /// Body `b` of the dataset: its shape drawn from the spec's distribution and solved
    /// on the mesh.
    pub fn body(&self, b: u32) -> Result<BodyEntry> {
        self.bodies
            .get_or_init(&b, || {
                let dist = &self.spec.bodies.distribution;
                let shape = dist
                    .sample(self.model, self.plan.body_seed(b))
                    .and_then(|s| self.model.shape(&s.phenotype))
                    .map_err(|e| format!("body {b}: {e}"))?;
                let (stature, bmi) = stature_and_bmi(&shape);
                Ok(Arc::new((shape, stature, bmi)))
            })
            .map_err(|e| DatasetError::Body(body::BodyError::Parameter(e)))
    }

    /// What sample `desc` drapes: its body (shape, stature, BMI), its garment template and
    /// its pose as the pool gives it (before the simulator's limb clearance). `Ok(Err(m))`:
    /// the sample cannot be made (a cut that cannot be built, a pose that cannot be
    /// found), and why; errors are problems of the machine or the installation.
    pub fn inputs(&self, desc: &SampleDesc) -> Result<std::result::Result<SampleInputs, String>> {
        let garment = &self.plan.garments[desc.garment];
        let body = self.body(desc.body)?;
        let template =
            match self
                .templates
                .get(self.model, self.plan.seed, desc.garment, garment, desc.body)
            {
                Ok(t) => t,
                Err(TemplateError::Build(m)) => return Ok(Err(m)),
                Err(TemplateError::Save(m)) => return Err(DatasetError::Invalid(m)),
            };
        let pose = match self
            .library
            .pose(self.spec, self.plan.pool.poses[desc.pose], &body.0)
        {
            Ok(p) => p,
            Err(m) => return Ok(Err(m)),
        };
        Ok(Ok((body, template, pose)))
    }

    /// Makes sample `desc`. A failed drape (or a pose or cut that cannot be made) is an
    /// [`Outcome::Failed`]; errors are problems of the machine or the installation.
    pub fn make(&self, desc: &SampleDesc) -> Result<(Outcome, Timing)> {
        let start = Instant::now();
        let garment = &self.plan.garments[desc.garment];
        let pose_id = self.plan.pool.pose_id(desc.pose);
        let split = self.plan.split_names[desc.split].clone();
        let fail = |reason: String, drape_s: f64| {
            let f = FailureRecord {
                index: desc.index,
                garment: garment.name.clone(),
                body: desc.body,
                split: split.clone(),
                pose: pose_id.clone(),
                reason,
            };
            let t = Timing {
                sample_s: start.elapsed().as_secs_f64(),
                drape_s,
            };
            Ok((Outcome::Failed(f), t))
        };
        let (body, template, pose) = match self.inputs(desc)? {
            Ok(inputs) => inputs,
            Err(m) => return fail(m, 0.0),
        };
        let (target, stature, bmi) = (&body.0, body.1, body.2);
        let opts = &self.drape_options;
        let morphed = self.morphs.get_or_init(&(desc.garment, desc.body), || {
            morph(
                &template,
                &self.template_body,
                target,
                opts,
                &mut |_, _, _| {},
            )
            .map(Arc::new)
            .map_err(|e| e.to_string())
        });
        let draped = match morphed.and_then(|m| {
            drape_morphed(
                (*m).clone(),
                &template,
                target,
                &pose,
                opts,
                &mut |_, _, _| {},
            )
            .map_err(|e| e.to_string())
        }) {
            Ok(d) => d,
            Err(e) => return fail(format!("drape: {e}"), start.elapsed().as_secs_f64()),
        };
        // The drape may have corrected the pose (limb clearance): M, G, the body and the
        // stored pose parameters all use the pose the body actually took.
        let pose = &draped.pose;
        let warped = warp(&template, target, pose, Skinning::Dqs)?;
        let fitted = if self.spec.output.fitted {
            let anchors = SurfaceAnchors::new(&template.mesh, &self.template_body.mesh)?;
            Some(warp_fitted(&template, &anchors, target, pose, Skinning::Dqs)?.vertices)
        } else {
            None
        };
        let record = SampleRecord {
            index: desc.index,
            garment: garment.name.clone(),
            template: garment.template_id(desc.body),
            body: desc.body,
            split,
            pose: pose_id,
            stature_m: stature,
            bmi,
            stats: SimStats::from(&draped.stats),
        };
        let arrays = SampleArrays {
            body: draped.body.vertices,
            warped: warped.vertices,
            draped: draped.garment.vertices,
            fitted,
            phenotype: target.phenotype.named_values().map(|(_, v)| v).to_vec(),
            root_translation: pose.root_translation,
            rotations: pose.rotations.clone(),
        };
        let timing = Timing {
            sample_s: start.elapsed().as_secs_f64(),
            drape_s: draped.stats.wall_time_s,
        };
        Ok((Outcome::Done(Box::new((record, arrays))), timing))
    }
}
