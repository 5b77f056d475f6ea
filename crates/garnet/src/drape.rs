//! The main job: garments draped on a body by trained GarNet models, in milliseconds.
//!
//! A [`GarmentModel`] is one `.garnet` file: the network, the garment template it drapes and
//! the body points it sees. [`drape`] takes a shaped body and a pose, clears the limbs out of
//! the body (as the training poses were), poses the body with the skinning the models learned
//! from, warps each template onto it (the network's input M, made as the network learned it:
//! dual quaternion skinning, or placed on the body's surface by the template's surface
//! anchors; see [`model::Base`]), runs
//! the networks and moves the vertices they leave inside the body, or nearer its skin than
//! the simulator's cloth thickness, out to that distance.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context};
use body::clearance::{clear_limbs, ClearanceOptions};
use body::BodyModel;
use body::{Pose, RigidTransform, ShapedBody, Skinning};
use burn::prelude::Device;
use garment::warp::{warp, SurfaceAnchors};
use garment::GarmentTemplate;
use geom::TriMesh;
use model::{Base, Draper};

/// How far from the skin the push-out looks for garment vertices, metres: on the
/// benchmark's test split 6 cm left 0.17-0.36% of the vertices inside the body, 3 cm
/// 0.74-1.87%.
pub const PUSH_OUT_WITHIN: f32 = 0.06;

/// The gap the push-out leaves between the skin and a garment vertex it moves: the
/// simulator's cloth thickness, metres.
pub fn push_out_gap() -> f32 {
    sim::ClothParams::default().thickness
}

/// One trained model file: the network and the garment template it drapes.
pub struct GarmentModel {
    path: PathBuf,
    draper: Draper,
    template: GarmentTemplate,
    /// The anchors M is placed with ([`Base::Anchored`] networks only).
    anchors: Option<SurfaceAnchors>,
}

impl GarmentModel {
    /// Loads the model file at `path` (`.garnet`) onto `device` (`Device::flex()` for the
    /// CPU). Fails, naming the file, when it is missing, damaged, of another format, or
    /// carries no garment template. A network whose M is anchored ([`Base::Anchored`])
    /// also loads the body model, to anchor the template on its template body.
    pub fn load(path: &Path, device: &Device) -> anyhow::Result<Self> {
        let draper =
            Draper::load(path, device).with_context(|| format!("loading {}", path.display()))?;
        let template = checkpoint_template(&draper, path)?;
        let anchors = match draper.setup().config.base {
            Base::Dqs => None,
            base => base_anchors(base, &template, &BodyModel::load()?)
                .with_context(|| format!("{}: anchoring the garment", path.display()))?,
        };
        Ok(GarmentModel {
            path: path.to_path_buf(),
            draper,
            template,
            anchors,
        })
    }

    /// The network's input M on `posed_body` (`[V]`, metres) when the network places it by
    /// surface anchors ([`Base::Anchored`]); `None` when M is skinned from the bones.
    pub fn anchored_m(&self, posed_body: &TriMesh) -> Option<Vec<glam::Vec3>> {
        self.anchors.as_ref().map(|a| a.place(posed_body))
    }

    /// The file it was loaded from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The network with its setup.
    pub fn draper(&self) -> &Draper {
        &self.draper
    }

    /// The garment template the network drapes (`N` vertices, metres, on the template body).
    pub fn template(&self) -> &GarmentTemplate {
        &self.template
    }

    /// The network's name in reports (`GarNet-local +contact +rest`).
    pub fn method_name(&self) -> String {
        self.draper.setup().config.method_name()
    }

    /// How the bodies it learned from were posed (the dataset's skinning).
    pub fn body_skinning(&self) -> anyhow::Result<Skinning> {
        let name = &self.draper.setup().body_skinning;
        Skinning::from_name(name)
            .with_context(|| format!("{}: unknown body skinning '{name}'", self.path.display()))
    }
}

/// The anchors a network's `base` places M with: `None` for [`Base::Dqs`]; for
/// [`Base::Anchored`] the anchors of `template` (`[N]` vertices, metres) on its template
/// body, shaped by `bodies` from the template's phenotype (as the dataset's simulator
/// anchors it).
pub fn base_anchors(
    base: Base,
    template: &GarmentTemplate,
    bodies: &BodyModel,
) -> anyhow::Result<Option<SurfaceAnchors>> {
    match base {
        Base::Dqs => Ok(None),
        Base::Anchored => {
            let template_body = bodies.shape(&template.body_phenotype)?;
            Ok(Some(SurfaceAnchors::new(
                &template.mesh,
                &template_body.mesh,
            )?))
        }
    }
}

/// The garment template a checkpoint carries.
pub fn checkpoint_template(draper: &Draper, path: &Path) -> anyhow::Result<GarmentTemplate> {
    let bytes = draper.setup().garment_file.as_ref().ok_or_else(|| {
        anyhow!(
            "{}: the model carries no garment template (train it with `garnet train`)",
            path.display()
        )
    })?;
    Ok(GarmentTemplate::from_bytes(bytes, path)?)
}

/// Options of [`drape`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrapeOptions {
    /// Clear the limbs out of the body first (the models were trained on cleared poses).
    pub clear_limbs: bool,
    /// Move the vertices the networks leave inside the body, or nearer its skin than the
    /// cloth thickness, out to that distance ([`PUSH_OUT_WITHIN`], [`push_out_gap`]).
    pub push_out: bool,
}

impl Default for DrapeOptions {
    /// Limb clearance and the push-out on: what `garnet drape` does.
    fn default() -> Self {
        DrapeOptions {
            clear_limbs: true,
            push_out: true,
        }
    }
}

/// One draped garment.
#[derive(Clone, Debug)]
pub struct DrapedGarment {
    /// The garment kind's name (`tshirt`, `sweater`, `jeans`, or a user garment's name).
    pub kind: String,
    /// The draped mesh: `[N]` vertices (metres, the body's frame) and the template's faces.
    pub mesh: TriMesh,
    /// The network's input M: the template warped onto the posed body as the network
    /// learned it (DQS, or placed by surface anchors), `[N]` vertices (metres).
    pub warped: Vec<glam::Vec3>,
    /// What the time went to, ms.
    pub timings: DrapeTimings,
    /// How many vertices the push-out moved (0 without it).
    pub pushed_out: usize,
}

/// Times of one garment's drape, milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DrapeTimings {
    /// The warp of the template (the network's input M).
    pub warp_ms: f64,
    /// The network's forward pass.
    pub network_ms: f64,
    /// The push-out.
    pub push_out_ms: f64,
}

/// What [`drape`] gives: the posed body and each model's garment on it.
#[derive(Clone, Debug)]
pub struct Drape {
    /// The posed body (`[V]` vertices, metres; the body model's faces).
    pub body: TriMesh,
    /// The pose after the limb clearance, as the body was posed.
    pub pose: Pose,
    /// One garment per model, in the models' order.
    pub garments: Vec<DrapedGarment>,
    /// Time to build the body's collider for the push-out (beside the networks), ms.
    pub collider_ms: Option<f64>,
}

/// A body posed by the caller's own code: its mesh, in garnet's body topology, and where
/// each bone of garnet's rig went.
#[derive(Clone, Debug, PartialEq)]
pub struct PosedBody {
    /// The posed body's vertices `[V]` (metres), in the body model's vertex order.
    pub vertices: Vec<glam::Vec3>,
    /// Each rig bone's posed placement `[B]`, in rig order: its head (metres) and its frame
    /// (the rotation taking +Y to the bone's head-to-tail direction, with its roll).
    pub joints: Vec<(glam::Vec3, glam::Quat)>,
}

impl PosedBody {
    /// `target` posed in `pose` with `skinning`, as a [`PosedBody`].
    pub fn from_pose(target: &ShapedBody, pose: &Pose, skinning: Skinning) -> anyhow::Result<Self> {
        let vertices = target.posed(pose, skinning)?.vertices;
        let joints = target
            .rig
            .skinning_transforms(pose)
            .iter()
            .zip(&target.rig.bones)
            .map(|(s, b)| {
                (
                    s.rotation * b.head + s.translation,
                    (s.rotation * b.frame).normalize(),
                )
            })
            .collect();
        Ok(PosedBody { vertices, joints })
    }
}

/// Drapes every model's garment on `target` (a shaped body in its rest pose) in `pose`.
/// The models must have learned from bodies posed the same way (they are drawn on one
/// body). Fails, naming the files, on models that disagree, and on a pose or body the
/// networks cannot take.
pub fn drape(
    models: &[GarmentModel],
    target: &ShapedBody,
    pose: &Pose,
    opts: DrapeOptions,
) -> anyhow::Result<Drape> {
    let skinning = shared_skinning(models)?;
    let pose = if opts.clear_limbs {
        clear_limbs(target, pose, &ClearanceOptions::default())?.0
    } else {
        pose.clone()
    };
    let body = target.posed(&pose, skinning)?;
    let warp_m = |m: &GarmentModel| -> anyhow::Result<Vec<glam::Vec3>> {
        Ok(warp(&m.template, target, &pose, Skinning::Dqs)?.vertices)
    };
    let (garments, collider_ms) = drape_on(models, &body, warp_m, opts.push_out)?;
    Ok(Drape {
        body,
        pose,
        garments,
        collider_ms,
    })
}

/// Drapes every model's garment on a body the caller posed ([`PosedBody`]; posed as the
/// models' training bodies were, see [`GarmentModel::body_skinning`]): M is each template
/// skinned by DQS with the bones' placements, or placed on the body by its surface anchors. No limb clearance (the pose is not known);
/// the push-out as `push_out` says. Fails on a vertex or bone count that is not the body
/// model's, a non-finite input, or models that disagree.
pub fn drape_posed(
    models: &[GarmentModel],
    posed: &PosedBody,
    push_out: bool,
) -> anyhow::Result<Vec<DrapedGarment>> {
    shared_skinning(models)?;
    let body_faces = models[0].draper.setup().body_faces.clone().ok_or_else(|| {
        anyhow!(
            "{}: the model carries no body faces",
            models[0].path.display()
        )
    })?;
    let n_body = models[0].draper.setup().body_sampling.n_body;
    if posed.vertices.len() != n_body {
        bail!(
            "the posed body has {} vertices, the body model {n_body}",
            posed.vertices.len()
        );
    }
    if let Some(k) = posed.vertices.iter().position(|v| !v.is_finite()) {
        bail!("the posed body's vertex {k} is not finite");
    }
    if let Some(k) = posed
        .joints
        .iter()
        .position(|(h, q)| !h.is_finite() || !q.is_finite() || q.length() < 1e-6)
    {
        bail!("the posed body's joint {k} is not finite, or its frame is not a rotation");
    }
    let body = TriMesh::new(posed.vertices.clone(), body_faces);
    let warp_m = |m: &GarmentModel| -> anyhow::Result<Vec<glam::Vec3>> {
        let rig = &m.template.rig;
        if posed.joints.len() != rig.bones.len() {
            bail!(
                "the posed body has {} joints, the rig {}",
                posed.joints.len(),
                rig.bones.len()
            );
        }
        let transforms: Vec<RigidTransform> = rig
            .bones
            .iter()
            .zip(&posed.joints)
            .map(|(rest, (head, frame))| {
                let rotation = (frame.normalize() * rest.frame.inverse()).normalize();
                RigidTransform {
                    rotation,
                    translation: *head - rotation * rest.head,
                }
            })
            .collect();
        let t = &m.template;
        Ok(t.weights
            .apply(&t.mesh.vertices, &transforms, Skinning::Dqs))
    };
    Ok(drape_on(models, &body, warp_m, push_out)?.0)
}

/// The networks of `models` on `body` (posed, `[V]`), each with its M placed on `body` by
/// its anchors or, for a DQS network, from `warp_m`; then the push-out when asked; the
/// collider's build time (ms) with it.
fn drape_on(
    models: &[GarmentModel],
    body: &TriMesh,
    warp_m: impl Fn(&GarmentModel) -> anyhow::Result<Vec<glam::Vec3>> + Sync,
    push_out: bool,
) -> anyhow::Result<(Vec<DrapedGarment>, Option<f64>)> {
    // The networks first (the body's collider is built beside them), then the push-out.
    let (predicted, collider) = beside_push_out_collider(push_out.then_some(body), || {
        models
            .iter()
            .map(|m| {
                let start = Instant::now();
                let warped = match m.anchored_m(body) {
                    Some(placed) => placed,
                    None => warp_m(m)?,
                };
                let warp_ms = start.elapsed().as_secs_f64() * 1e3;
                let start = Instant::now();
                let draped = m
                    .draper
                    .drape(&body.vertices, &warped)
                    .with_context(|| format!("{}: draping", m.path.display()))?;
                let timings = DrapeTimings {
                    warp_ms,
                    network_ms: start.elapsed().as_secs_f64() * 1e3,
                    push_out_ms: 0.0,
                };
                Ok((draped, warped, timings))
            })
            .collect::<anyhow::Result<Vec<_>>>()
    });
    let collider = collider?;
    let mut garments = Vec::with_capacity(models.len());
    for (m, (mut vertices, warped, mut timings)) in models.iter().zip(predicted?) {
        let start = Instant::now();
        let pushed_out = collider.as_ref().map_or(0, |(c, _)| {
            c.push_out(&mut vertices, PUSH_OUT_WITHIN, push_out_gap())
        });
        timings.push_out_ms = start.elapsed().as_secs_f64() * 1e3;
        garments.push(DrapedGarment {
            kind: m.template.kind.name().to_string(),
            mesh: TriMesh {
                vertices,
                faces: m.template.mesh.faces.clone(),
            },
            warped,
            timings,
            pushed_out,
        });
    }
    Ok((garments, collider.map(|(_, ms)| ms)))
}

/// The body skinning `models` share; fails, naming two of them, when they differ.
fn shared_skinning(models: &[GarmentModel]) -> anyhow::Result<Skinning> {
    let Some(first) = models.first() else {
        bail!("no model to drape with");
    };
    let name = |m: &GarmentModel| m.draper.setup().body_skinning.clone();
    if let Some(other) = models.iter().find(|m| name(m) != name(first)) {
        bail!(
            "{} learned from bodies posed with {}, {} with {}: drape them in separate runs",
            first.path.display(),
            name(first),
            other.path.display(),
            name(other)
        );
    }
    first.body_skinning()
}

/// Runs `networks` while another thread builds the collider of `body` for the push-out
/// (`None` for none): a forward pass of the flex backend keeps only about one of two cores
/// busy, so the build (18 ms for the 13,380-vertex body) mostly hides behind it. Returns
/// what `networks` returned, and the collider with its build time in ms.
pub fn beside_push_out_collider<T: Send>(
    body: Option<&TriMesh>,
    networks: impl FnOnce() -> T,
) -> (T, anyhow::Result<Option<(sim::BodyCollider, f64)>>) {
    std::thread::scope(|scope| {
        let building = body.map(|b| {
            scope.spawn(move || {
                let start = Instant::now();
                sim::BodyCollider::new(b, push_out_gap())
                    .map(|c| (c, start.elapsed().as_secs_f64() * 1e3))
            })
        });
        let out = networks();
        let collider = building
            .map(|h| {
                h.join()
                    .map_err(|_| anyhow!("building the body's collider failed"))?
                    .map_err(anyhow::Error::from)
            })
            .transpose();
        (out, collider)
    })
}
