//! Detection of a posed body passing through itself (an arm through the torso, a leg
//! through the other), used to reject implausible poses.
//!
//! Vertices are grouped into nine segments by their heaviest bone (torso with head,
//! and the upper and lower part of each limb). Skinning folds the skin where segments
//! meet (armpits, groin, elbows, knees), so only segments that are not neighbours in
//! the body are tested: an intersection is a mesh edge of one segment crossing a
//! triangle of a non-neighbouring segment.

use geom::bvh::Bvh;
use geom::TriMesh;
use glam::Vec3;

use crate::model::ShapedBody;

/// Segment names, indexed by segment number.
pub const SEGMENTS: [&str; 9] = [
    "torso",
    "left upper arm",
    "left forearm",
    "right upper arm",
    "right forearm",
    "left thigh",
    "left shin",
    "right thigh",
    "right shin",
];

/// Pairs of segments that touch in the body (their contact is not an intersection).
const NEIGHBOURS: [(u8, u8); 9] = [
    (0, 1),
    (1, 2),
    (0, 3),
    (3, 4),
    (0, 5),
    (5, 6),
    (0, 7),
    (7, 8),
    (5, 7),
];

/// Segment of a rig bone by name.
pub fn segment_of_bone(name: &str) -> u8 {
    let left = name.starts_with("Left") || name.starts_with('L') && !name.starts_with("Lower");
    let side = |l: u8, r: u8| if left { l } else { r };
    match name {
        n if n.ends_with("Arm") && !n.ends_with("ForeArm") => side(1, 3),
        n if n.ends_with("ForeArm")
            || n.contains("Hand")
            || n.contains("Finger")
            || n.contains("Thumb") =>
        {
            side(2, 4)
        }
        n if n.ends_with("UpLeg") => side(5, 7),
        n if n.ends_with("Leg") || n.ends_with("Foot") || n.ends_with("ToeBase") => side(6, 8),
        _ => 0,
    }
}

/// Per-vertex segments of a shaped body, ready to test posed meshes of it.
#[derive(Clone, Debug)]
pub struct SelfContact {
    /// `[N]` segment of every vertex.
    pub vertex_segment: Vec<u8>,
    /// Mesh edges `[E]` whose two ends lie in the same segment.
    edges: Vec<[u32; 2]>,
}

fn neighbours(a: u8, b: u8) -> bool {
    a == b
        || NEIGHBOURS
            .iter()
            .any(|&(x, y)| (x, y) == (a, b) || (y, x) == (a, b))
}

/// The segment (index into [`SEGMENTS`]) of every vertex `[N]` of `body`: the segment of
/// its heaviest bone.
pub fn vertex_segments(body: &ShapedBody) -> Vec<u8> {
    let bone_segment: Vec<u8> = body
        .rig
        .bones
        .iter()
        .map(|b| segment_of_bone(&b.name))
        .collect();
    (0..body.weights.len())
        .map(|v| bone_segment[body.weights.heaviest(v)])
        .collect()
}

impl SelfContact {
    /// Segments the vertices of `body` by their heaviest bone.
    pub fn new(body: &ShapedBody) -> Self {
        let vertex_segment = vertex_segments(body);
        let edges = geom::adjacency::edges(&body.mesh.faces)
            .into_iter()
            .filter(|e| vertex_segment[e[0] as usize] == vertex_segment[e[1] as usize])
            .collect();
        Self {
            vertex_segment,
            edges,
        }
    }

    /// Number of edges of one segment that cross a triangle of a non-neighbouring
    /// segment in the posed mesh `posed` (same topology as the shaped body). Zero for a
    /// plausible pose.
    pub fn count_intersections(&self, posed: &TriMesh) -> usize {
        let seg = &self.vertex_segment;
        let face_segment = |f: &[u32; 3]| -> Option<u8> {
            let s = seg[f[0] as usize];
            (seg[f[1] as usize] == s && seg[f[2] as usize] == s).then_some(s)
        };
        // Only segments whose boxes overlap a non-neighbour's box can intersect.
        let mut boxes =
            [(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); SEGMENTS.len()];
        for (p, &s) in posed.vertices.iter().zip(seg) {
            let b = &mut boxes[s as usize];
            *b = (b.0.min(*p), b.1.max(*p));
        }
        let overlap = |a: usize, b: usize| {
            (boxes[a].0.cmple(boxes[b].1) & boxes[b].0.cmple(boxes[a].1)).all()
        };
        let risky: Vec<bool> = (0..SEGMENTS.len())
            .map(|a| (0..SEGMENTS.len()).any(|b| !neighbours(a as u8, b as u8) && overlap(a, b)))
            .collect();
        if !risky.iter().any(|&r| r) {
            return 0;
        }
        let Ok(bvh) = Bvh::from_mesh(posed) else {
            return 0;
        };
        self.edges
            .iter()
            .filter(|e| risky[seg[e[0] as usize] as usize])
            .filter(|e| {
                let a = seg[e[0] as usize];
                let (p, q) = (posed.vertices[e[0] as usize], posed.vertices[e[1] as usize]);
                bvh.segment_faces(p, q).into_iter().any(|f| {
                    face_segment(&posed.faces[f as usize]).is_some_and(|b| !neighbours(a, b))
                })
            })
            .count()
    }
}

/// Draws procedural poses from `generator` until one poses `body` (with DQS) without
/// self-intersection; errors after `max_tries` rejected draws.
pub fn sample_valid_pose(
    body: &ShapedBody,
    generator: &mut crate::pose::ProceduralPoseGenerator,
    max_tries: usize,
) -> Result<crate::rig::Pose, crate::BodyError> {
    let contact = SelfContact::new(body);
    let pose = generator.sample_accepted(
        &body.rig,
        |pose| {
            body.posed(pose, crate::skin::Skinning::Dqs)
                .is_ok_and(|mesh| contact.count_intersections(&mesh) == 0)
        },
        max_tries,
    )?;
    Ok(pose)
}
