//! Scene input: [`RenderMesh`], its validation and its smooth vertex normals.

use glam::Vec3;

use crate::RenderError;

/// How a mesh's colours are lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shading {
    /// Full lighting: key, fill, ambient, ambient occlusion and a faint specular.
    #[default]
    Lit,
    /// Colours stay close to their given value (a heat map stays readable against its legend)
    /// with a mild diffuse term so the shape still shows.
    Soft,
    /// Colours exactly as given, no lighting at all.
    Unlit,
}

/// One mesh of a scene, borrowed from the caller.
///
/// Positions are in metres (Y up, body facing +Z); faces are counter-clockwise seen from the
/// outside. Open surfaces are fine: both sides are shaded (the inside slightly darker).
/// Faces with a non-finite vertex or with zero area are skipped; a face index out of range is
/// an error ([`RenderError::FaceIndex`]).
#[derive(Clone, Copy, Debug)]
pub struct RenderMesh<'a> {
    /// Vertex positions, shape `[N]`, metres.
    pub vertices: &'a [Vec3],
    /// Triangles, shape `[F]`, indices into `vertices`.
    pub faces: &'a [[u32; 3]],
    /// Base colour, sRGB; used where no per-vertex or per-face colour is given.
    pub color: [u8; 3],
    /// Optional per-vertex sRGB colours, shape `[N]`, interpolated across faces.
    pub vertex_colors: Option<&'a [[u8; 3]]>,
    /// Optional per-face sRGB colours, shape `[F]`; wins over `vertex_colors`.
    pub face_colors: Option<&'a [[u8; 3]]>,
    /// How the colours are lit.
    pub shading: Shading,
    /// Moves this mesh towards the camera by this many metres for the depth test only, so a
    /// garment lying a few millimetres over the skin wins where both are close (3 mm is a good
    /// value for garments); 0 for bodies.
    pub depth_bias: f32,
}

impl<'a> RenderMesh<'a> {
    /// A lit mesh of one colour. `vertices`: `[N]` metres; `faces`: `[F]`; `color`: sRGB.
    pub fn new(vertices: &'a [Vec3], faces: &'a [[u32; 3]], color: [u8; 3]) -> Self {
        Self {
            vertices,
            faces,
            color,
            vertex_colors: None,
            face_colors: None,
            shading: Shading::Lit,
            depth_bias: 0.0,
        }
    }

    /// Adds per-vertex sRGB colours, shape `[N]` (checked when rendering).
    pub fn with_vertex_colors(mut self, colors: &'a [[u8; 3]]) -> Self {
        self.vertex_colors = Some(colors);
        self
    }

    /// Adds per-face sRGB colours, shape `[F]` (checked when rendering).
    pub fn with_face_colors(mut self, colors: &'a [[u8; 3]]) -> Self {
        self.face_colors = Some(colors);
        self
    }

    /// Sets how the mesh is lit.
    pub fn with_shading(mut self, shading: Shading) -> Self {
        self.shading = shading;
        self
    }

    /// Sets the depth bias in metres towards the camera (see [`RenderMesh::depth_bias`]).
    pub fn with_depth_bias(mut self, metres: f32) -> Self {
        self.depth_bias = metres;
        self
    }

    /// Checks face indices and colour slice lengths; `index` is the mesh's place in the scene.
    pub(crate) fn validate(&self, index: usize) -> Result<(), RenderError> {
        let n = self.vertices.len();
        for (f, face) in self.faces.iter().enumerate() {
            if let Some(&bad) = face.iter().find(|&&i| i as usize >= n) {
                return Err(RenderError::FaceIndex {
                    mesh: index,
                    face: f,
                    index: bad,
                    vertices: n,
                });
            }
        }
        let check = |what, got: Option<&[[u8; 3]]>, expected| match got {
            Some(c) if c.len() != expected => Err(RenderError::ColorCount {
                mesh: index,
                what,
                got: c.len(),
                expected,
            }),
            _ => Ok(()),
        };
        check("vertex_colors", self.vertex_colors, n)?;
        check("face_colors", self.face_colors, self.faces.len())
    }
}

/// True when all three coordinates are finite.
pub(crate) fn finite(v: Vec3) -> bool {
    v.is_finite()
}

/// Area-weighted vertex normals, unit length, shape `[N]`.
///
/// Each face adds its unnormalised cross product (twice its area along its normal) to its three
/// vertices. Faces touching a non-finite vertex are skipped; a vertex no valid face touches gets
/// a zero normal (the renderer then falls back to the face normal). Indices must be valid.
pub(crate) fn vertex_normals(vertices: &[Vec3], faces: &[[u32; 3]]) -> Vec<Vec3> {
    let mut acc = vec![Vec3::ZERO; vertices.len()];
    for f in faces {
        let [a, b, c] = f.map(|i| vertices[i as usize]);
        let n = (b - a).cross(c - a);
        if !n.is_finite() {
            continue;
        }
        for &i in f {
            acc[i as usize] += n;
        }
    }
    for n in &mut acc {
        *n = n.normalize_or_zero();
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_of_a_tetrahedron_point_outwards() {
        let v = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let f = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let n = vertex_normals(&v, &f);
        let centre = Vec3::splat(0.25);
        for (p, n) in v.iter().zip(&n) {
            assert!((*p - centre).dot(*n) > 0.0);
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn validation_reports_the_bad_face() {
        let v = [Vec3::ZERO; 3];
        let f = [[0, 1, 2], [0, 1, 3]];
        let err = RenderMesh::new(&v, &f, [0; 3]).validate(4).unwrap_err();
        assert!(matches!(
            err,
            RenderError::FaceIndex {
                mesh: 4,
                face: 1,
                index: 3,
                vertices: 3
            }
        ));
        let c = [[0u8; 3]; 2];
        let err = RenderMesh::new(&v, &f[..1], [0; 3])
            .with_vertex_colors(&c)
            .validate(0)
            .unwrap_err();
        assert!(matches!(
            err,
            RenderError::ColorCount {
                got: 2,
                expected: 3,
                ..
            }
        ));
    }
}
