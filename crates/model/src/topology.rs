//! The garment template's connectivity, shared by every sample of a batch: faces (for the
//! normal loss), the padded 1-ring table (for the FeaStNet convolutions) and the two-ring
//! pairs (for the bending loss).

use std::sync::Arc;

use burn::prelude::*;

use crate::error::{ModelError, Result};
use crate::feast_rows::HostRing;
use crate::tensors::{index_tensor, vec_tensor};

/// Garment connectivity on the CPU.
#[derive(Clone, Debug, PartialEq)]
pub struct GarmentTopology {
    /// Number of garment vertices N.
    pub n_vertices: usize,
    /// `[F]` triangles.
    pub faces: Vec<[u32; 3]>,
    /// Row width K of the padded neighbourhood table: 1 + the largest vertex degree.
    pub ring_width: usize,
    /// `[N*K]` neighbourhoods, row-major: row i holds i itself, then its 1-ring (ascending),
    /// then i again as padding.
    pub ring: Vec<u32>,
    /// `[N*K]` weights of the entries of `ring`: `1/|N_i|` for i and its neighbours
    /// (`|N_i|` = degree + 1), 0 for padding.
    pub ring_weight: Vec<f32>,
    /// `[P]` vertex pairs `[i, k]`, `i < k`, two edges apart (the bending pairs).
    pub bend_pairs: Vec<[u32; 2]>,
}

impl GarmentTopology {
    /// The topology of the garment template `mesh` (`[N]` vertices, `[F]` faces). Fails on an
    /// invalid mesh (non-finite vertex, face index out of range) or one without faces.
    pub fn from_mesh(mesh: &geom::TriMesh) -> Result<Self> {
        mesh.validate()?;
        if mesh.faces.is_empty() {
            return Err(ModelError::InvalidInput(
                "garment template has no faces".into(),
            ));
        }
        let n = mesh.num_vertices();
        let rings = geom::adjacency::one_ring(n, &mesh.faces)?;
        let max_degree = (0..n).map(|i| rings.row(i).len()).max().unwrap_or(0);
        let k = max_degree + 1;
        let mut ring = Vec::with_capacity(n * k);
        let mut ring_weight = Vec::with_capacity(n * k);
        for i in 0..n {
            let row = rings.row(i);
            let w = 1.0 / (row.len() + 1) as f32;
            ring.push(i as u32);
            ring_weight.push(w);
            for &j in row {
                ring.push(j);
                ring_weight.push(w);
            }
            for _ in row.len() + 1..k {
                ring.push(i as u32);
                ring_weight.push(0.0);
            }
        }
        let bend_pairs = geom::adjacency::two_ring_pairs(n, &mesh.faces)?;
        Ok(GarmentTopology {
            n_vertices: n,
            faces: mesh.faces.clone(),
            ring_width: k,
            ring,
            ring_weight,
            bend_pairs,
        })
    }

    /// The topology as tensors on `device` (upload once, reuse for every batch).
    pub fn to_device(&self, device: &Device) -> TopologyTensors {
        let n = self.n_vertices;
        let k = self.ring_width;
        let face_col = |c: usize| index_tensor(self.faces.iter().map(|f| f[c] as i64), device);
        let pair_col = |c: usize| index_tensor(self.bend_pairs.iter().map(|p| p[c] as i64), device);
        TopologyTensors {
            n_vertices: n,
            ring_width: k,
            n_faces: self.faces.len(),
            n_bend_pairs: self.bend_pairs.len(),
            ring: index_tensor(self.ring.iter().map(|&i| i as i64), device),
            host_ring: Arc::new(HostRing {
                ring: self.ring.clone(),
                weight: self.ring_weight.clone(),
                k,
            }),
            ring_weight: vec_tensor(self.ring_weight.clone(), [1, n, k, 1], device),
            faces: [face_col(0), face_col(1), face_col(2)],
            bend_pairs: [pair_col(0), pair_col(1)],
        }
    }
}

/// [`GarmentTopology`] on a device, as the network and the losses use it.
#[derive(Clone, Debug)]
pub struct TopologyTensors {
    /// Number of garment vertices N.
    pub n_vertices: usize,
    /// Neighbourhood row width K.
    pub ring_width: usize,
    /// Number of faces F.
    pub n_faces: usize,
    /// Number of bending pairs P.
    pub n_bend_pairs: usize,
    /// `[N*K]` neighbourhood indices (see [`GarmentTopology::ring`]).
    pub ring: Tensor<1, Int>,
    /// `[1,N,K,1]` neighbourhood weights.
    pub ring_weight: Tensor<4>,
    /// The same neighbourhoods on the host, for the CPU's plain-loop convolutions.
    pub host_ring: Arc<HostRing>,
    /// Face corners: three `[F]` index tensors (first, second, third vertex of each face).
    pub faces: [Tensor<1, Int>; 3],
    /// Bending pairs: two `[P]` index tensors.
    pub bend_pairs: [Tensor<1, Int>; 2],
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_rows_hold_self_then_neighbours_then_padding() {
        let mesh = geom::TriMesh::grid(4, 3, 0.1);
        let topo = GarmentTopology::from_mesh(&mesh).unwrap();
        let rings = geom::adjacency::one_ring(12, &mesh.faces).unwrap();
        let max_degree = (0..12).map(|i| rings.row(i).len()).max().unwrap();
        assert_eq!(topo.ring_width, max_degree + 1);
        for i in 0..12 {
            let row = &topo.ring[i * topo.ring_width..(i + 1) * topo.ring_width];
            let w = &topo.ring_weight[i * topo.ring_width..(i + 1) * topo.ring_width];
            let deg = rings.row(i).len();
            assert_eq!(row[0] as usize, i);
            assert_eq!(&row[1..=deg], rings.row(i));
            assert!(row[deg + 1..].iter().all(|&j| j as usize == i));
            assert!(w[deg + 1..].iter().all(|&v| v == 0.0));
            let s: f32 = w.iter().sum();
            assert!((s - 1.0).abs() < 1e-6);
        }
        assert_eq!(
            topo.bend_pairs,
            geom::adjacency::two_ring_pairs(12, &mesh.faces).unwrap()
        );
    }

    #[test]
    fn refuses_meshes_without_faces_or_with_bad_indices() {
        let empty = geom::TriMesh::new(vec![glam::Vec3::ZERO; 3], vec![]);
        assert!(GarmentTopology::from_mesh(&empty).is_err());
        let bad = geom::TriMesh::new(vec![glam::Vec3::ZERO; 3], vec![[0, 1, 3]]);
        assert!(GarmentTopology::from_mesh(&bad).is_err());
    }
}
