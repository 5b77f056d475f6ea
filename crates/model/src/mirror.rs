//! Left-right mirror augmentation: a training sample reflected through the garment's plane of
//! symmetry is another valid drape.
//!
//! Cloth physics is unchanged by a reflection through a vertical plane (gravity is +Y), and a
//! reflected human in a reflected pose is another human in another pose, so the reflected
//! scene is a drape the simulator could have made. Its garment is indexed by the template's
//! vertices, though, and a remeshed template is symmetric as a surface, not vertex for
//! vertex: each template vertex takes its mirrored position from the point of the template
//! surface that its reflection lands on (a face and barycentric coordinates, found once).
//! Inside a face the mesh is linear, so the reflected garment is the simulated surface itself,
//! sampled at the template's own vertices.

use geom::TriMesh;
use glam::Vec3;

use crate::batch::{InputSpec, Sample};
use crate::error::{check_count, ModelError, Result};

/// Where each template vertex's mirror image lies on the template, and the plane `x = c`
/// (canonical frame, metres) it is mirrored through.
#[derive(Clone, Debug, PartialEq)]
pub struct MirrorMap {
    plane_x: f32,
    /// `[N]`: the template face (vertex indices) holding each vertex's reflection, and its
    /// barycentric coordinates there.
    sources: Vec<([u32; 3], [f32; 3])>,
    /// Largest distance from a vertex's reflection to the template surface, metres.
    max_offset: f32,
}

impl MirrorMap {
    /// The map of the template `template` (rest vertices `[N]`, metres, canonical frame, and
    /// faces `[F]`), mirrored through the plane `x = c` halfway between its extreme
    /// x. Fails when the template is not left-right symmetric: when a vertex's reflection lies
    /// farther from the surface than the mean edge length. Tessellation asymmetry passes (on
    /// the 2.5 cm `standard` templates the reflections lie within 3.3 mm of the surface at
    /// the 99th percentile, 4.8-12.4 mm at most), a garment cut differently on each side does
    /// not.
    pub fn new(template: &TriMesh) -> Result<MirrorMap> {
        let (rest, faces) = (&template.vertices, &template.faces);
        let (lo, hi) = rest
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.x), hi.max(p.x))
            });
        let plane_x = 0.5 * (lo + hi);
        let bvh = geom::bvh::Bvh::from_mesh(template)?;
        let mut sources = Vec::with_capacity(rest.len());
        let mut max_offset = 0.0f32;
        for &p in rest.iter() {
            let hit = bvh
                .closest_point(reflect(p, plane_x))
                .ok_or_else(|| ModelError::InvalidInput("the template has no faces".into()))?;
            max_offset = max_offset.max(hit.distance);
            sources.push((faces[hit.face as usize], hit.bary));
        }
        let mean_edge = template.mean_edge_length();
        if max_offset > mean_edge {
            return Err(ModelError::InvalidInput(format!(
                "the garment template is not left-right symmetric: a vertex's reflection \
                 lies {:.1} mm from its surface, more than its mean edge ({:.1} mm), so \
                 samples cannot be mirrored",
                max_offset * 1e3,
                mean_edge * 1e3
            )));
        }
        Ok(MirrorMap {
            plane_x,
            sources,
            max_offset,
        })
    }

    /// The x of the mirror plane, metres (canonical frame).
    pub fn plane_x(&self) -> f32 {
        self.plane_x
    }

    /// Largest distance from a template vertex's reflection to the template surface, metres.
    pub fn max_offset(&self) -> f32 {
        self.max_offset
    }

    /// `points` `[N]` (per template vertex, metres) reflected and re-indexed: entry i is the
    /// reflection of the point of the mesh `points` at template vertex i's mirror image.
    pub fn mirror_garment(&self, points: &[Vec3]) -> Result<Vec<Vec3>> {
        check_count("garment vertices", self.sources.len(), points.len())?;
        Ok(self
            .sources
            .iter()
            .map(|(face, bary)| {
                let p = face
                    .iter()
                    .zip(bary)
                    .fold(Vec3::ZERO, |acc, (&v, &w)| acc + w * points[v as usize]);
                reflect(p, self.plane_x)
            })
            .collect())
    }

    /// `sample` reflected: moved into its canonical frame (`spec`), then its body, body
    /// normals, warped garment M and target G reflected through the plane (the garments
    /// re-indexed by [`MirrorMap::mirror_garment`]). The result is in the canonical frame.
    pub fn mirror_sample(&self, sample: &Sample, spec: &InputSpec) -> Result<Sample> {
        let frame = spec.frame(&sample.warped);
        let canonical = |points: &[Vec3]| frame.points_to_canonical(points);
        let body = canonical(&sample.body)
            .into_iter()
            .map(|p| reflect(p, self.plane_x))
            .collect();
        // A reflected normal is the reflection of the normal (the faces' winding flips with
        // the reflection, so normals recomputed from the faces would point inwards).
        let body_normals = sample
            .body_normals
            .iter()
            .map(|&n| {
                let d = frame.direction_to_canonical(n);
                Vec3::new(-d.x, d.y, d.z)
            })
            .collect();
        let target = match &sample.target {
            Some(t) => Some(self.mirror_garment(&canonical(t))?),
            None => None,
        };
        Ok(Sample {
            body,
            body_normals,
            body_edge: sample.body_edge,
            warped: self.mirror_garment(&canonical(&sample.warped))?,
            target,
        })
    }
}

/// `p` reflected through the plane `x = plane_x`.
fn reflect(p: Vec3, plane_x: f32) -> Vec3 {
    Vec3::new(2.0 * plane_x - p.x, p.y, p.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::BodyTopology;

    /// A closed, exactly symmetric tube around the Y axis (x in [-r, r]) offset to x = 0.4,
    /// with `ring` vertices per ring: `[N]` vertices and faces.
    fn tube(ring: usize, offset: f32, twist: f32) -> TriMesh {
        let mut v = Vec::new();
        for k in 0..4 {
            for i in 0..ring {
                let a = (i as f32 + twist * k as f32) / ring as f32 * std::f32::consts::TAU;
                v.push(Vec3::new(
                    offset + 0.2 * a.cos(),
                    0.1 * k as f32,
                    0.1 * a.sin(),
                ));
            }
        }
        let mut f = Vec::new();
        for k in 0..3u32 {
            for i in 0..ring as u32 {
                let (a, b) = (k * ring as u32 + i, k * ring as u32 + (i + 1) % ring as u32);
                let (c, d) = (a + ring as u32, b + ring as u32);
                f.push([a, b, d]);
                f.push([a, d, c]);
            }
        }
        TriMesh::new(v, f)
    }

    #[test]
    fn a_symmetric_template_maps_onto_its_own_vertices() {
        let template = tube(12, 0.4, 0.0);
        let rest = &template.vertices;
        let map = MirrorMap::new(&template).unwrap();
        assert!((map.plane_x() - 0.4).abs() < 1e-6);
        assert!(map.max_offset() < 1e-5);
        let mirrored = map.mirror_garment(rest).unwrap();
        // The reflected template is the template: each vertex lands on its mirror twin.
        for (m, r) in mirrored.iter().zip(rest) {
            assert!(m.distance(*r) < 1e-5, "{m} vs {r}");
        }
        // Twice mirrored is the original, for any garment shape.
        let bent: Vec<Vec3> = rest
            .iter()
            .map(|&p| p + Vec3::new(0.1 * p.y * p.y, 0.05 * p.x, -0.2 * p.x * p.y))
            .collect();
        let twice = map
            .mirror_garment(&map.mirror_garment(&bent).unwrap())
            .unwrap();
        for (t, b) in twice.iter().zip(&bent) {
            assert!(t.distance(*b) < 1e-5);
        }
    }

    #[test]
    fn a_tessellation_asymmetric_template_resamples_its_surface() {
        // Rings turned by 0.3 of a step each: no vertex has a mirror twin, but the surface is
        // symmetric up to its facets' sagitta.
        let template = tube(24, 0.0, 0.3);
        let rest = &template.vertices;
        let map = MirrorMap::new(&template).unwrap();
        assert!(map.max_offset() < 2e-3, "{}", map.max_offset());
        // A garment that is the template moved rigidly up and sideways: its mirror is the
        // template moved up and the other way, vertex by vertex, up to the facets.
        let moved: Vec<Vec3> = rest
            .iter()
            .map(|&p| p + Vec3::new(0.05, 0.3, 0.0))
            .collect();
        let mirrored = map.mirror_garment(&moved).unwrap();
        for (m, r) in mirrored.iter().zip(rest) {
            let expected = *r + Vec3::new(-0.05, 0.3, 0.0);
            assert!(m.distance(expected) < 3e-3, "{m} vs {expected}");
        }
    }

    #[test]
    fn a_lopsided_template_is_refused() {
        let mut template = tube(12, 0.0, 0.0);
        // One side cut 40 cm longer than the other.
        for p in template.vertices.iter_mut().filter(|p| p.x > 0.1) {
            p.y += 0.4;
        }
        let err = MirrorMap::new(&template).unwrap_err().to_string();
        assert!(err.contains("not left-right symmetric"), "{err}");
    }

    #[test]
    fn a_mirrored_sample_keeps_normals_outward_and_distances() {
        // The body is the tube; the garment a copy 2 cm out along the normals.
        let TriMesh {
            vertices: rest,
            faces,
        } = tube(16, 0.0, 0.0);
        let topo = BodyTopology::new(rest.len(), faces.clone()).unwrap();
        let normals = geom::normals::vertex_normals(&rest, &faces);
        let garment: Vec<Vec3> = rest
            .iter()
            .zip(&normals)
            .map(|(&p, &n)| p + 0.02 * n)
            .collect();
        let target: Vec<Vec3> = garment.iter().map(|&p| p - Vec3::Y * 0.01).collect();
        let sample = Sample::new(rest.clone(), &topo, garment.clone(), Some(target)).unwrap();
        let spec = InputSpec {
            sampling: crate::local::BodySampling::farthest_point(&rest, 1, 4).unwrap(),
            local: None,
            canonical_rest: Some(garment.clone()),
            contact_faces: None,
            rest_input: None,
        };
        let map = MirrorMap::new(&TriMesh::new(garment.clone(), faces.clone())).unwrap();
        let m = map.mirror_sample(&sample, &spec).unwrap();
        let recomputed = geom::normals::vertex_normals(&m.body, &faces);
        for (n, r) in m.body_normals.iter().zip(&recomputed) {
            // The faces' winding flipped, the carried normals did not.
            assert!(n.dot(*r) < -0.99);
        }
        for (w, t) in m.warped.iter().zip(m.target.as_ref().unwrap()) {
            assert!((w.distance(*t) - 0.01).abs() < 1e-4);
        }
        assert_eq!(m.body_edge, sample.body_edge);
        // Regression: the contact features of the mirrored sample take its carried normals,
        // so its garment, 2 cm outside the body, is 2 cm outside (it was 2 cm inside when
        // they were recomputed from the inward-wound faces).
        let spec = InputSpec {
            contact_faces: Some(faces.clone()),
            ..spec
        };
        let topology =
            crate::topology::GarmentTopology::from_mesh(&TriMesh::new(garment, faces)).unwrap();
        let device = burn::prelude::Device::flex();
        let batch = crate::batch::Batch::new(&[m], &topology, &spec, &device).unwrap();
        let contact = crate::tensors::read_f32(batch.inputs.contact.unwrap()).unwrap();
        for row in contact.chunks_exact(crate::contact::CONTACT_WIDTH) {
            assert!((row[6] - 2.0).abs() < 0.2, "signed distance {} cm", row[6]);
        }
    }
}
