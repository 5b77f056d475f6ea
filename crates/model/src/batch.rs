//! Inputs: one training or inference sample as plain [`glam::Vec3`] lists ([`Sample`]), and a
//! batch of them as tensors ([`Batch`]).

use std::sync::Arc;

use burn::prelude::*;
use glam::Vec3;

use crate::contact::{contact_features, CONTACT_WIDTH};
use crate::error::{check_count, check_finite, ModelError, Result};
use crate::frame::CanonicalFrame;
use crate::local::{BodySampling, LocalIndices};
use crate::tensors::{points_tensor, vec_tensor};
use crate::topology::GarmentTopology;

/// The body mesh connectivity shared by the samples of a dataset (all bodies have one
/// topology): faces and unique edges, for the body normals and mean edge length that the
/// penetration loss needs.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyTopology {
    /// Number of body vertices V.
    pub n_vertices: usize,
    /// `[F]` body triangles, counter-clockwise seen from outside.
    pub faces: Vec<[u32; 3]>,
    /// `[E]` unique edges.
    pub edges: Vec<[u32; 2]>,
}

impl BodyTopology {
    /// From the body's vertex count and faces; fails on an out-of-range face index.
    pub fn new(n_vertices: usize, faces: Vec<[u32; 3]>) -> Result<Self> {
        geom::adjacency::check_indices(n_vertices, &faces)?;
        let edges = geom::adjacency::edges(&faces);
        Ok(BodyTopology {
            n_vertices,
            faces,
            edges,
        })
    }

    /// Mean edge length (metres) of the body with vertices `body` `[V]`.
    pub fn mean_edge_length(&self, body: &[Vec3]) -> f32 {
        if self.edges.is_empty() {
            return 0.0;
        }
        let sum: f64 = self
            .edges
            .iter()
            .map(|&[a, b]| body[a as usize].distance(body[b as usize]) as f64)
            .sum();
        (sum / self.edges.len() as f64) as f32
    }
}

/// One sample, in metres.
#[derive(Clone, Debug, PartialEq)]
pub struct Sample {
    /// Body vertices `[V]`.
    pub body: Vec<Vec3>,
    /// Unit outward body vertex normals `[V]` (used by the penetration loss only).
    pub body_normals: Vec<Vec3>,
    /// Mean body edge length (used by the penetration loss only).
    pub body_edge: f32,
    /// The DQS-warped garment M `[N]` (the network input).
    pub warped: Vec<Vec3>,
    /// The simulated garment G `[N]` (the target), absent at inference.
    pub target: Option<Vec<Vec3>>,
}

impl Sample {
    /// A sample from a posed body `[V]` with the dataset's body topology, the warped garment
    /// M `[N]` and optionally the simulated garment G `[N]`. Computes the body normals and mean
    /// edge length. Fails on mismatched counts or non-finite coordinates.
    pub fn new(
        body: Vec<Vec3>,
        body_topology: &BodyTopology,
        warped: Vec<Vec3>,
        target: Option<Vec<Vec3>>,
    ) -> Result<Sample> {
        check_count("body vertices", body_topology.n_vertices, body.len())?;
        check_finite("body vertices", &body)?;
        check_finite("warped garment M", &warped)?;
        if let Some(t) = &target {
            check_count("target garment G", warped.len(), t.len())?;
            check_finite("target garment G", t)?;
        }
        let body_normals = geom::normals::vertex_normals(&body, &body_topology.faces);
        let body_edge = body_topology.mean_edge_length(&body);
        Ok(Sample {
            body,
            body_normals,
            body_edge,
            warped,
            target,
        })
    }
}

/// How samples become network inputs: the body points the stream sees and, for
/// GarNet-Local, the neighbour counts of its tables. Made by
/// [`crate::checkpoint::ModelSetup::input_spec`].
#[derive(Clone, Debug, PartialEq)]
pub struct InputSpec {
    /// The body subsampling (stream points and GarNet-Local's kept points).
    pub sampling: BodySampling,
    /// GarNet-Local: (stream points averaged per kept point (16), kept points max-pooled per
    /// garment vertex (15)); `None` for the other variants.
    pub local: Option<(usize, usize)>,
    /// The template's rest vertices `[N]` (metres) that each sample's canonical frame is
    /// fitted to (see [`crate::frame`]); `None` keeps world coordinates.
    pub canonical_rest: Option<Vec<Vec3>>,
    /// The body faces `[F]` when the network takes body-contact features (see
    /// [`crate::contact`]; the faces give the body normals).
    pub contact_faces: Option<Vec<[u32; 3]>>,
    /// The template's vertices `[N]` (metres) when the network takes them as an input (see
    /// [`crate::GarNetConfig::rest_input`]).
    pub rest_input: Option<Vec<Vec3>>,
}

impl InputSpec {
    /// The canonical frame of a sample with warped garment `warped` `[N]` (the identity
    /// without [`InputSpec::canonical_rest`]).
    pub fn frame(&self, warped: &[Vec3]) -> CanonicalFrame {
        match &self.canonical_rest {
            Some(rest) => CanonicalFrame::fit(rest, warped),
            None => CanonicalFrame::fit(&[], &[]),
        }
    }

    /// Each (body `[V]`, warped garment `[N]`) pair moved into its canonical frame: the
    /// frames, the bodies and the warped garments (metres).
    pub fn to_canonical(
        &self,
        pairs: &[(&[Vec3], &[Vec3])],
    ) -> (Vec<CanonicalFrame>, Vec<Vec<Vec3>>, Vec<Vec<Vec3>>) {
        let frames: Vec<CanonicalFrame> = pairs.iter().map(|(_, w)| self.frame(w)).collect();
        let bodies = pairs
            .iter()
            .zip(&frames)
            .map(|((b, _), f)| f.points_to_canonical(b))
            .collect();
        let warped = pairs
            .iter()
            .zip(&frames)
            .map(|((_, w), f)| f.points_to_canonical(w))
            .collect();
        (frames, bodies, warped)
    }

    /// The contact features `[B,N,CONTACT_WIDTH]` of `bodies` `[B][V]` and `warped` `[B][N]`
    /// when the spec has them (see [`InputSpec::inputs`]).
    fn contact(
        &self,
        bodies: &[&[Vec3]],
        known: Option<KnownBodies>,
        warped: &[&[Vec3]],
        device: &Device,
    ) -> Result<Option<Tensor<3>>> {
        let Some(faces) = &self.contact_faces else {
            return Ok(None);
        };
        let mut flat = Vec::new();
        for (b, (body, m)) in bodies.iter().zip(warped).enumerate() {
            let features = match &known {
                Some(k) => contact_features(&k.index[b], body, k.normals[b], m)?,
                None => {
                    geom::adjacency::check_indices(body.len(), faces)?;
                    let normals = geom::normals::vertex_normals(body, faces);
                    contact_features(&geom::KnnIndex::new(body)?, body, &normals, m)?
                }
            };
            flat.extend(features);
        }
        let n = warped.first().map_or(0, |m| m.len());
        Ok(Some(vec_tensor(
            flat,
            [warped.len(), n, CONTACT_WIDTH],
            device,
        )))
    }

    /// The network inputs of B samples: stream points `[B][P]` of `bodies` `[B][V]`, and the
    /// local tables and the contact features `[B,N,CONTACT_WIDTH]` of them and `warped`
    /// `[B][N]` (metres, one frame) when the spec has them. The contact features take what
    /// the caller already has of the bodies (`known`: their normals and k-d trees), else
    /// compute it from the spec's faces.
    pub fn inputs(
        &self,
        bodies: &[&[Vec3]],
        known: Option<KnownBodies>,
        warped: &[&[Vec3]],
        device: &Device,
    ) -> Result<NetInputs> {
        let streams = bodies
            .iter()
            .map(|b| self.sampling.stream_points(b))
            .collect::<Result<Vec<_>>>()?;
        let refs: Vec<&[Vec3]> = streams.iter().map(Vec::as_slice).collect();
        // The local tables and the contact features side by side: each builds k-d trees on
        // one thread before its queries spread over all of them.
        let (local, contact) = rayon::join(
            || match self.local {
                Some((pool_k, knn_k)) => {
                    LocalIndices::build(&self.sampling, pool_k, knn_k, &refs, warped, device)
                        .map(Some)
                }
                None => Ok(None),
            },
            || self.contact(bodies, known, warped, device),
        );
        let (local, contact) = (local?, contact?);
        let rest = self.rest_input.as_ref().map(|r| {
            let copies: Vec<&[Vec3]> = warped.iter().map(|_| r.as_slice()).collect();
            points_tensor(&copies, device)
        });
        Ok(NetInputs {
            body_stream: points_tensor(&refs, device),
            local,
            contact,
            rest,
        })
    }
}

/// What a caller of [`InputSpec::inputs`] already has of its B bodies.
#[derive(Clone, Copy)]
pub struct KnownBodies<'a> {
    /// Unit outward vertex normals `[B][V]`.
    pub normals: &'a [&'a [Vec3]],
    /// k-d trees over the body vertices `[B]`.
    pub index: &'a [Arc<geom::KnnIndex>],
}

/// What [`InputSpec::inputs`] makes of B samples besides M: the network's inputs (see
/// [`crate::GarNet::translations`]).
#[derive(Clone, Debug)]
pub struct NetInputs {
    /// The body points the body stream sees `[B,P,3]`, metres.
    pub body_stream: Tensor<3>,
    /// GarNet-Local's neighbour tables.
    pub local: Option<LocalIndices>,
    /// Body-contact features `[B,N,CONTACT_WIDTH]` (see [`crate::contact`]).
    pub contact: Option<Tensor<3>>,
    /// The template's vertices `[B,N,3]`, metres (see [`crate::GarNetConfig::rest_input`]).
    pub rest: Option<Tensor<3>>,
}

/// A batch of B samples as tensors on one device, sharing one garment topology.
#[derive(Clone)]
pub struct Batch {
    /// Number of samples B.
    pub size: usize,
    /// Body vertices per sample V.
    pub n_body: usize,
    /// Garment vertices per sample N.
    pub n_garment: usize,
    /// The network's inputs besides M: the body points the body stream sees, GarNet-Local's
    /// tables, the contact features and the template's vertices.
    pub inputs: NetInputs,
    /// Body vertices `[B,V,3]`, metres (the penetration loss).
    pub body: Tensor<3>,
    /// Unit body vertex normals `[B,V,3]`.
    pub body_normals: Tensor<3>,
    /// Mean body edge length per sample `[B]`, metres.
    pub body_edge: Tensor<1>,
    /// Warped garment M `[B,N,3]`, metres.
    pub warped: Tensor<3>,
    /// Target garment G `[B,N,3]`, metres (present when every sample has one).
    pub target: Option<Tensor<3>>,
    /// Per-sample k-d trees over the body vertices (the penetration loss's nearest-vertex
    /// search, and the contact features'), built with the batch when it has targets or the
    /// network takes contact features.
    pub(crate) body_index: Vec<Arc<geom::KnnIndex>>,
    /// Targets on the CPU `[B][N]`, canonical frame (the penetration mask and the metrics).
    pub(crate) target_points: Option<Vec<Vec<Vec3>>>,
}

impl std::fmt::Debug for Batch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Batch")
            .field("size", &self.size)
            .field("n_body", &self.n_body)
            .field("n_garment", &self.n_garment)
            .field("has_target", &self.target.is_some())
            .field("has_local", &self.inputs.local.is_some())
            .finish()
    }
}

impl Batch {
    /// Stacks `samples` (body vertex count as `spec`, the garment matching `topology`) into
    /// tensors on `device`, with GarNet-Local's tables when `spec` has them. Fails on an empty
    /// slice, mismatched counts or non-finite coordinates.
    pub fn new(
        samples: &[Sample],
        topology: &GarmentTopology,
        spec: &InputSpec,
        device: &Device,
    ) -> Result<Batch> {
        let first = samples
            .first()
            .ok_or_else(|| ModelError::InvalidInput("empty batch".into()))?;
        let v = spec.sampling.n_body;
        let n = topology.n_vertices;
        check_count("body vertices", v, first.body.len())?;
        let with_target = samples.iter().all(|s| s.target.is_some());
        for s in samples {
            check_count("body vertices", v, s.body.len())?;
            check_count("body normals", v, s.body_normals.len())?;
            check_count("warped garment M", n, s.warped.len())?;
            check_finite("body vertices", &s.body)?;
            check_finite("warped garment M", &s.warped)?;
            if !s.body_edge.is_finite() {
                return Err(ModelError::InvalidInput(
                    "body edge length is not finite".into(),
                ));
            }
            if let Some(t) = &s.target {
                check_count("target garment G", n, t.len())?;
                check_finite("target garment G", t)?;
            }
        }
        let pairs: Vec<(&[Vec3], &[Vec3])> = samples
            .iter()
            .map(|s| (s.body.as_slice(), s.warped.as_slice()))
            .collect();
        let (frames, bodies, warped) = spec.to_canonical(&pairs);
        let targets: Vec<Vec<Vec3>> = samples
            .iter()
            .zip(&frames)
            .map(|(s, f)| f.points_to_canonical(s.target.as_deref().unwrap_or(&[])))
            .collect();
        let normals: Vec<Vec<Vec3>> = samples
            .iter()
            .zip(&frames)
            .map(|(s, f)| {
                s.body_normals
                    .iter()
                    .map(|&d| f.direction_to_canonical(d))
                    .collect()
            })
            .collect();
        let bodies: Vec<&[Vec3]> = bodies.iter().map(Vec::as_slice).collect();
        let normals: Vec<&[Vec3]> = normals.iter().map(Vec::as_slice).collect();
        let warped: Vec<&[Vec3]> = warped.iter().map(Vec::as_slice).collect();
        let body_index = if with_target || spec.contact_faces.is_some() {
            bodies
                .iter()
                .map(|b| geom::KnnIndex::new(b).map(Arc::new))
                .collect::<std::result::Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        let known = KnownBodies {
            normals: &normals,
            index: &body_index,
        };
        let inputs = spec.inputs(&bodies, Some(known), &warped, device)?;
        let (target, target_points) = if with_target {
            let targets: Vec<&[Vec3]> = targets.iter().map(Vec::as_slice).collect();
            (
                Some(points_tensor(&targets, device)),
                Some(targets.iter().map(|t| t.to_vec()).collect()),
            )
        } else {
            (None, None)
        };
        Ok(Batch {
            size: samples.len(),
            n_body: v,
            n_garment: n,
            inputs,
            body: points_tensor(&bodies, device),
            body_normals: points_tensor(&normals, device),
            body_edge: vec_tensor(
                samples.iter().map(|s| s.body_edge).collect(),
                [samples.len()],
                device,
            ),
            warped: points_tensor(&warped, device),
            target,
            body_index,
            target_points,
        })
    }

    /// The targets on the CPU (`[B][N]`), when the batch has them.
    pub fn target_points(&self) -> Option<&[Vec<Vec3>]> {
        self.target_points.as_deref()
    }
}
