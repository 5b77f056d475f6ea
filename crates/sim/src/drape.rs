//! The drape driver: a garment template starts on the template body; the body morphs
//! into the target shape, then moves into the target pose (every joint slerped from
//! the rest pose), the cloth following by contact and friction; then the cloth settles
//! until its kinetic energy falls below a threshold or the step budget runs out. Every
//! output vertex is the template vertex of the same index.
//!
//! The yaw of the target's root (a turn about the vertical) changes nothing physical, so
//! the animation runs without it and the result is turned at the end: garments are not
//! dragged around by a body spinning in place.

use std::time::Instant;

use body::clearance::{clear_limbs, ClearanceOptions};
use body::{Pose, ShapedBody, Skinning};
use garment::GarmentTemplate;
use geom::TriMesh;
use glam::{Quat, Vec3};

use crate::morph::{morph, Morphed};
use crate::stats::{percentile, DrapeStats, SKIN_TOUCH_M};
use crate::waistband::Waistband;
use crate::{ClothParams, SimError};

/// Settings of a drape.
#[derive(Clone, Debug)]
pub struct DrapeOptions {
    /// The cloth material and solver settings.
    pub cloth: ClothParams,
    /// Most steps over which the body morphs from the template shape to the target shape.
    pub morph_steps: u32,
    /// Most steps over which the body moves from the rest pose to the target pose.
    pub pose_steps: u32,
    /// Most distance a body vertex travels in one animation step, metres: each phase takes
    /// as few steps as keep its fastest vertex under it (at most the phase's step count
    /// above), so a small change of shape or pose is animated in few steps. 0 (or less)
    /// always uses the full step counts.
    pub body_step: f32,
    /// Most steps spent settling after the animation.
    pub max_settle_steps: u32,
    /// While settling, every this many steps (from the first), cloth caught inside the
    /// body where its closest surface leads no way out (between overlapping body parts) is
    /// walked out ([`crate::ClothSim::walk_out_of`]), so the cloth relaxes around it instead of
    /// jittering against the per-step projection; 0: only by the exact pass after the
    /// last step.
    pub walk_out_every: u32,
    /// The cloth is at rest when its root-mean-square speed falls below this, m/s.
    pub rest_speed: f32,
    /// A drape whose cloth moves faster than this (root-mean-square, m/s) has diverged.
    pub explode_speed: f32,
    /// A drape that leaves a garment vertex deeper than this inside the body failed, m.
    pub max_penetration: f32,
    /// How the body is skinned during the animation (and so the body the garment rests on).
    /// Linear blending by default: dual quaternion skinning keeps a joint's volume by
    /// bulging it, and a shoulder raised overhead then outgrows the armhole, which no
    /// garment can fit without stretching. Measured on the 30-drape sheet at 1 cm: the arms-up drapes' strain p99 fell from 23.7 / 18.3% to 11.6 / 4.1% (T-shirt
    /// yoga 103 / 109) and from 13.4 / 8.1% to 2.2 / 6.3% (sweater), one more drape came
    /// to rest (25 of 30), and as many ended under 2% (21).
    pub skinning: Skinning,
    /// Grade the garment to the target body, as a shop sells sizes: the cloth's rest
    /// lengths are those of the template carried onto the target's rest shape by its
    /// surface anchors, so a garment fits a larger body as it fits the template body.
    /// Without it a small template is stretched over a large body.
    pub grade: bool,
    /// Correct the pose first so no limb sinks into the body (see [`body::clearance`]):
    /// cloth cannot lie where a skinned arm overlaps the chest. `None` drapes the pose as
    /// given.
    pub clearance: Option<ClearanceOptions>,
    /// The garment's waistband, where it has one (the jeans): elastic and cut to less than
    /// the waist's girth, so that it holds the garment up. `None`: the band is cloth like
    /// the rest.
    pub waistband: Option<Waistband>,
    /// Where the cloth starts: carried along by the body from the template body
    /// ([`Start::Animate`]) or placed on the posed target by its surface anchors
    /// ([`Start::Fitted`]).
    pub start: Start,
}

/// How a drape reaches the target body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// The garment starts on the template body; the body morphs into the target shape,
    /// then moves into the target pose, the cloth following by contact and friction.
    Animate,
    /// The garment starts on the posed target, placed by the template's surface anchors
    /// (each vertex keeps its offset in the frame of its closest skin point), is moved out
    /// of the body, and settles there: no shape or pose animation.
    Fitted,
}

impl Start {
    /// The method of a name: `animate` or `fitted`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "animate" => Some(Start::Animate),
            "fitted" => Some(Start::Fitted),
            _ => None,
        }
    }
}

impl Default for DrapeOptions {
    fn default() -> Self {
        Self {
            cloth: ClothParams::default(),
            morph_steps: 40,
            pose_steps: 60,
            body_step: 0.008,
            max_settle_steps: 400,
            walk_out_every: 50,
            rest_speed: 0.005,
            explode_speed: 30.0,
            max_penetration: 0.001,
            skinning: Skinning::Lbs,
            grade: true,
            clearance: Some(ClearanceOptions::default()),
            waistband: Some(Waistband::default()),
            start: Start::Animate,
        }
    }
}

/// Sees every step of a drape: `(step, garment [N], body [V])`, metres.
pub type FrameObserver<'a> = dyn FnMut(u32, &[Vec3], &[Vec3]) + 'a;

/// A finished drape: the garment (template topology) and the body it rests on.
#[derive(Clone, Debug)]
pub struct Drape {
    /// The draped garment: the template's topology, metres.
    pub garment: TriMesh,
    /// The body in the target shape and pose.
    pub body: TriMesh,
    /// The pose the body took: the target pose after the limb clearance correction.
    pub pose: Pose,
    /// `[N]` the largest strain (length / rest - 1) of each garment vertex's edges at the
    /// end: where the cloth is stretched.
    pub vertex_strain: Vec<f32>,
    /// What the drape took and reached.
    pub stats: DrapeStats,
}

/// The root's turn about the vertical and the rest of its rotation: `world = yaw * tilt`.
fn split_yaw(world: Quat) -> (Quat, Quat) {
    let twist = Quat::from_xyzw(0.0, world.y, 0.0, world.w);
    let yaw = if twist.length_squared() < 1e-12 {
        Quat::IDENTITY
    } else {
        twist.normalize()
    };
    (yaw, (yaw.inverse() * world).normalize())
}

/// Drapes `template` (fitted on `template_body`, its rest shape) onto `target` in `pose`.
/// `on_frame(step, garment, body)` sees every step (for recording the animation).
/// Errors if the simulation diverges (NaN, exploding speed) or leaves cloth inside the
/// body; the error says which and when. The same as [`morph`] then [`drape_morphed`].
pub fn drape(
    template: &GarmentTemplate,
    template_body: &ShapedBody,
    target: &ShapedBody,
    pose: &Pose,
    opts: &DrapeOptions,
    on_frame: &mut FrameObserver<'_>,
) -> Result<Drape, SimError> {
    check_pose(target, pose)?;
    let morphed = morph(template, template_body, target, opts, on_frame)?;
    drape_morphed(morphed, template, target, pose, opts, on_frame)
}

/// Errors unless `pose` fits `target`'s rig and is finite.
fn check_pose(target: &ShapedBody, pose: &Pose) -> Result<(), SimError> {
    if pose.rotations.len() != target.rig.len()
        || !pose.root_translation.is_finite()
        || pose.rotations.iter().any(|q| !q.is_finite())
    {
        return Err(SimError::InvalidInput(
            "the pose does not fit the body's rig or holds NaN".into(),
        ));
    }
    Ok(())
}

/// Finishes a drape from the cloth `m` that [`morph`] made for `template` on `target`:
/// the body moves into `pose`, the cloth settles, and the result is checked and measured.
/// `on_frame` sees the steps after the morph's. `stats.wall_time_s` is the morph's wall time
/// plus this part's: what the drape would take from scratch, however many share the morph.
pub fn drape_morphed(
    mut m: Morphed,
    template: &GarmentTemplate,
    target: &ShapedBody,
    pose: &Pose,
    opts: &DrapeOptions,
    on_frame: &mut FrameObserver<'_>,
) -> Result<Drape, SimError> {
    let start = Instant::now();
    check_pose(target, pose)?;
    m.check_fits(template, target)?;
    let (pose, limb_turn_deg) = match &opts.clearance {
        Some(c) => {
            let (p, report) =
                clear_limbs(target, pose, c).map_err(|e| SimError::InvalidInput(e.to_string()))?;
            (p, report.largest_turn_deg())
        }
        None => (pose.clone(), 0.0),
    };
    let (yaw, mut calm) = remove_root_yaw(target, &pose);
    calm.rotations.iter_mut().for_each(|q| *q = q.normalize());
    // Pose: every joint slerps from rest to the target (root yaw left out).
    let rest = Pose::identity(target.rig.len());
    let posed = |t: f32| -> Result<Vec<Vec3>, SimError> {
        Ok(target
            .posed(&rest.slerp(&calm, t), opts.skinning)
            .map_err(|e| SimError::InvalidInput(e.to_string()))?
            .vertices)
    };
    let body = match opts.start {
        Start::Animate => {
            let pose_steps =
                phase_steps(opts.pose_steps, opts.body_step, POSE_PATH_SAMPLES, &posed)?;
            let mut body = target.mesh.vertices.clone();
            for k in 1..=pose_steps {
                body = posed(k as f32 / pose_steps as f32)?;
                m.advance(&body, opts, on_frame)?;
            }
            body
        }
        Start::Fitted => {
            let body = posed(1.0)?;
            let start = m.anchors.place(&TriMesh {
                vertices: body.clone(),
                faces: target.mesh.faces.clone(),
            });
            m.place_at(&body, &start)?;
            on_frame(m.steps, m.sim.positions(), &body);
            body
        }
    };
    let animation_steps = m.steps;
    let mut converged = false;
    let mut walked = 0;
    while m.steps - animation_steps < opts.max_settle_steps {
        let settled = m.steps - animation_steps;
        if opts.walk_out_every > 0 && settled % opts.walk_out_every == 0 {
            walked += m.sim.walk_out_of(&m.collider);
        }
        m.advance(&body, opts, on_frame)?;
        if m.rms_speed() < opts.rest_speed {
            converged = true;
            break;
        }
    }
    let (sim, collider) = (&mut m.sim, &m.collider);
    walked += sim.project_out_of(collider).1;
    let mut stats = DrapeStats {
        walked_out: walked as u32,
        animation_steps,
        settle_steps: m.steps - animation_steps,
        final_kinetic_energy: sim.kinetic_energy(),
        converged,
        limb_turn_deg,
        slid_m: mean_distance(
            sim.positions(),
            &m.anchors.place(&TriMesh {
                vertices: body.clone(),
                faces: target.mesh.faces.clone(),
            }),
        ),
        ..Default::default()
    };
    stats.measure(
        &collider.penetration_depths(sim.positions()),
        &sim.strains(),
    );
    stats.elastic_strain_p99 = percentile(&sim.elastic_strains(), 0.99);
    stats.skin_stretch_p90 = percentile(
        &collider.skin_stretch_under(&target.mesh.vertices, sim.positions(), SKIN_TOUCH_M)?,
        0.9,
    );
    if stats.max_penetration_m > opts.max_penetration {
        return Err(SimError::Rejected(format!(
            "cloth left {:.2} mm inside the body (at most {:.2} mm allowed)",
            stats.max_penetration_m * 1e3,
            opts.max_penetration * 1e3
        )));
    }
    // Turn the result by the root's yaw about the vertical through the root.
    let centre = target.rig.bones[0].head + pose.root_translation;
    let turn = |p: &Vec3| yaw * (*p - centre) + centre;
    stats.wall_time_s = m.wall_time_s + start.elapsed().as_secs_f64();
    Ok(Drape {
        garment: TriMesh {
            vertices: sim.positions().iter().map(turn).collect(),
            faces: template.mesh.faces.clone(),
        },
        body: TriMesh {
            vertices: body.iter().map(turn).collect(),
            faces: target.mesh.faces.clone(),
        },
        pose,
        vertex_strain: sim.vertex_strains(),
        stats,
    })
}

/// Points at which the pose phase's path is sampled to measure how far its vertices travel
/// (joints slerp, so vertices move on arcs; 8 chords are within 0.5% of a half-turn arc).
const POSE_PATH_SAMPLES: u32 = 8;

/// Steps of an animation phase whose body is `at(t)` (`[V]` metres, `t` in `[0, 1]`): the
/// fewest that keep every vertex's travel per step, measured along the path through
/// `samples` equal chords, at most `step_len` metres; at least 1 and at most `max_steps`
/// (which a non-positive or non-finite `step_len` always gives).
pub(crate) fn phase_steps(
    max_steps: u32,
    step_len: f32,
    samples: u32,
    at: &dyn Fn(f32) -> Result<Vec<Vec3>, SimError>,
) -> Result<u32, SimError> {
    if !step_len.is_finite() || step_len <= 0.0 || max_steps <= 1 {
        return Ok(max_steps);
    }
    let mut prev = at(0.0)?;
    let mut travel = vec![0.0f32; prev.len()];
    for k in 1..=samples {
        let next = at(k as f32 / samples as f32)?;
        for ((d, a), b) in travel.iter_mut().zip(&prev).zip(&next) {
            *d += a.distance(*b);
        }
        prev = next;
    }
    let longest = travel.into_iter().fold(0.0f32, f32::max);
    Ok(((longest / step_len).ceil() as u32).clamp(1, max_steps))
}

/// The root's yaw and `pose` with the root's world rotation reduced to its tilt.
fn remove_root_yaw(target: &ShapedBody, pose: &Pose) -> (Quat, Pose) {
    let root = &target.rig.bones[0];
    let world = root.frame * pose.rotations[0] * root.frame.inverse();
    let (yaw, tilt) = split_yaw(world);
    let mut calm = pose.clone();
    calm.rotations[0] = root.frame.inverse() * tilt * root.frame;
    (yaw, calm)
}

/// Mean distance between corresponding points of `a` and `b` (`[N]` each), metres; 0 for
/// none.
fn mean_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    let sum: f64 = a.iter().zip(b).map(|(p, q)| p.distance(*q) as f64).sum();
    (sum / a.len().max(1) as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phase_steps_keep_the_fastest_vertex_under_the_step_length() {
        // A vertex moving 0.1 m in a straight line, another on a half circle of radius 0.1 m
        // (path 0.314 m, chord 0.2 m).
        let at = |t: f32| -> Result<Vec<Vec3>, SimError> {
            let a = std::f32::consts::PI * t;
            Ok(vec![
                Vec3::new(0.1 * t, 0.0, 0.0),
                Vec3::new(0.1 * a.cos(), 0.1 * a.sin(), 0.0),
            ])
        };
        // Measured along 8 chords: 0.3136 m, so 40 steps of 8 mm.
        assert_eq!(phase_steps(60, 0.008, 8, &at).unwrap(), 40);
        // One chord sees only 0.2 m.
        assert_eq!(phase_steps(60, 0.008, 1, &at).unwrap(), 25);
        assert_eq!(phase_steps(30, 0.008, 8, &at).unwrap(), 30);
        assert_eq!(phase_steps(30, 0.0, 8, &at).unwrap(), 30);
        assert_eq!(phase_steps(30, f32::NAN, 8, &at).unwrap(), 30);
        let still = |_: f32| -> Result<Vec<Vec3>, SimError> { Ok(vec![Vec3::ONE]) };
        assert_eq!(phase_steps(30, 0.008, 8, &still).unwrap(), 1);
    }

    #[test]
    fn yaw_split_recomposes_and_is_vertical() {
        let q = Quat::from_rotation_y(1.1) * Quat::from_rotation_x(0.4);
        let (yaw, tilt) = split_yaw(q);
        assert!((yaw * tilt).angle_between(q) < 1e-5);
        let axis = yaw.to_axis_angle().0;
        assert!(axis.cross(Vec3::Y).length() < 1e-4);
        assert!((yaw.to_axis_angle().1 - 1.1).abs() < 0.05);
    }
}
