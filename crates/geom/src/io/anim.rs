//! Animations of meshes whose vertices move frame by frame (a draped garment, a posed body
//! along a clip): glTF 2.0 binary with morph-target animation, and the PC2 point cache that
//! Blender, 3ds Max and Maya import.
//!
//! GLB: each mesh's frame 0 is its base geometry (`POSITION`, `NORMAL`); frame `k > 0` is
//! morph target `k - 1`, holding the displacements from frame 0 (and the normals' changes,
//! when asked). One animation drives every mesh's morph weights with LINEAR interpolation:
//! at time `k / fps` the weight of target `k - 1` is 1 and every other 0, so a player shows
//! frame `k` exactly and blends neighbouring frames in between.
//!
//! PC2: a 32-byte header (`POINTCACHE2\0`, version 1, point count, start frame, sample
//! interval in frames, sample count), then each sample's points as little-endian f32 xyz.

use std::path::Path;

use glam::Vec3;
use serde_json::json;

use super::atomic::write_atomic;
use super::glb::{assemble, exact, ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, FLOAT, UNSIGNED_INT};
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

/// One animated mesh: shared faces, one vertex array per frame.
#[derive(Clone, Copy, Debug)]
pub struct AnimatedMesh<'a> {
    /// Node, mesh and material name.
    pub name: &'a str,
    /// Triangles `[F]`, indices below the vertex count.
    pub faces: &'a [[u32; 3]],
    /// Vertex positions `[T][N]` (metres), one array per frame; every frame has `N` vertices.
    pub frames: &'a [Vec<Vec3>],
    /// Base colour, linear RGBA in [0, 1].
    pub color: [f32; 4],
    /// Also animate the normals (morph targets with `NORMAL` changes): exact shading in every
    /// frame, at twice the size.
    pub normals: bool,
}

/// Appends `words` (4-byte values, little endian) to `bin` and returns the index of the
/// buffer view of them (4-byte aligned: every value is 4 bytes).
fn push_view(
    bin: &mut Vec<u8>,
    views: &mut Vec<serde_json::Value>,
    words: impl IntoIterator<Item = [u8; 4]>,
    target: Option<u32>,
) -> usize {
    let off = bin.len();
    for w in words {
        bin.extend_from_slice(&w);
    }
    let mut view = json!({"buffer": 0, "byteOffset": off, "byteLength": bin.len() - off});
    if let Some(t) = target {
        view["target"] = json!(t);
    }
    views.push(view);
    views.len() - 1
}

/// Appends `vs` as a float VEC3 accessor (with its bounds when `with_bounds`, as `POSITION`
/// accessors need) and returns its index.
fn vec3_accessor(
    bin: &mut Vec<u8>,
    views: &mut Vec<serde_json::Value>,
    accessors: &mut Vec<serde_json::Value>,
    vs: &[Vec3],
    with_bounds: bool,
) -> usize {
    let words = vs.iter().flat_map(|v| v.to_array()).map(f32::to_le_bytes);
    let view = push_view(bin, views, words, Some(ARRAY_BUFFER));
    let mut acc =
        json!({"bufferView": view, "componentType": FLOAT, "count": vs.len(), "type": "VEC3"});
    if with_bounds {
        let (lo, hi) = bounds(vs);
        acc["min"] = json!(exact(lo));
        acc["max"] = json!(exact(hi));
    }
    accessors.push(acc);
    accessors.len() - 1
}

/// Component-wise bounds of `vs` (zero for none).
fn bounds(vs: &[Vec3]) -> (Vec3, Vec3) {
    vs.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &v| (lo.min(v), hi.max(v)),
    )
}

/// Checks `m`: at least one frame and one face, the same vertex count in every frame,
/// finite coordinates, indices in range, a colour in [0, 1].
fn check(i: usize, m: &AnimatedMesh) -> Result<()> {
    let bad = |msg: String| {
        Err(GeomError::InvalidInput(format!(
            "animated mesh {i} ({}): {msg}",
            m.name
        )))
    };
    let Some(first) = m.frames.first() else {
        return bad("no frame".into());
    };
    if m.faces.is_empty() {
        return bad("no face".into());
    }
    for (k, f) in m.frames.iter().enumerate() {
        if f.len() != first.len() {
            return bad(format!(
                "frame {k} has {} vertices, frame 0 has {}",
                f.len(),
                first.len()
            ));
        }
        if let Some(j) = f.iter().position(|v| !v.is_finite()) {
            return bad(format!("frame {k}, vertex {j} is not finite"));
        }
    }
    TriMesh::new(first.clone(), m.faces.to_vec())
        .validate()
        .or_else(|e| bad(e.to_string()))?;
    if m.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return bad(format!("colour {:?} outside [0, 1]", m.color));
    }
    Ok(())
}

/// Encodes `meshes` as one animated GLB at `fps` frames a second. Every mesh must have the
/// same number of frames. Fails on an empty list, a bad mesh (see [`AnimatedMesh`]),
/// differing frame counts or a frame rate that is not positive.
pub fn encode_animated_glb(meshes: &[AnimatedMesh], fps: f32) -> Result<Vec<u8>> {
    let Some(first) = meshes.first() else {
        return Err(GeomError::InvalidInput(
            "an animation needs at least one mesh".into(),
        ));
    };
    if !(fps.is_finite() && fps > 0.0) {
        return Err(GeomError::InvalidInput(format!(
            "frame rate must be > 0, got {fps}"
        )));
    }
    let frames = first.frames.len();
    for (i, m) in meshes.iter().enumerate() {
        check(i, m)?;
        if m.frames.len() != frames {
            return Err(GeomError::InvalidInput(format!(
                "animated mesh {i} ({}) has {} frames, mesh 0 has {frames}",
                m.name,
                m.frames.len()
            )));
        }
    }
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut gmeshes, mut materials, mut nodes) =
        (vec![], vec![], vec![], vec![], vec![]);
    let floats = |vs: &[f32]| -> Vec<[u8; 4]> { vs.iter().map(|v| v.to_le_bytes()).collect() };
    for (i, m) in meshes.iter().enumerate() {
        let base = &m.frames[0];
        let normals_of = |vs: &[Vec3]| -> Vec<Vec3> {
            TriMesh::new(vs.to_vec(), m.faces.to_vec())
                .vertex_normals()
                .into_iter()
                .map(|n| if n == Vec3::ZERO { Vec3::Y } else { n })
                .collect()
        };
        let base_normals = normals_of(base);
        let position = vec3_accessor(&mut bin, &mut views, &mut accessors, base, true);
        let normal = vec3_accessor(&mut bin, &mut views, &mut accessors, &base_normals, false);
        let indices = m.faces.as_flattened();
        let view = push_view(
            &mut bin,
            &mut views,
            indices.iter().map(|k| k.to_le_bytes()),
            Some(ELEMENT_ARRAY_BUFFER),
        );
        accessors.push(json!({"bufferView": view, "componentType": UNSIGNED_INT,
                              "count": indices.len(), "type": "SCALAR"}));
        let index_accessor = accessors.len() - 1;
        let mut targets = Vec::with_capacity(frames.saturating_sub(1));
        for frame in &m.frames[1..] {
            let delta: Vec<Vec3> = frame.iter().zip(base).map(|(a, b)| *a - *b).collect();
            let mut target = json!({"POSITION": vec3_accessor(&mut bin, &mut views, &mut accessors, &delta, true)});
            if m.normals {
                let dn: Vec<Vec3> = normals_of(frame)
                    .iter()
                    .zip(&base_normals)
                    .map(|(a, b)| *a - *b)
                    .collect();
                target["NORMAL"] = json!(vec3_accessor(
                    &mut bin,
                    &mut views,
                    &mut accessors,
                    &dn,
                    false
                ));
            }
            targets.push(target);
        }
        let mut primitive = json!({"attributes": {"POSITION": position, "NORMAL": normal},
                                   "indices": index_accessor, "material": i, "mode": 4});
        let mut mesh = json!({"name": m.name});
        if !targets.is_empty() {
            primitive["targets"] = json!(targets);
            mesh["weights"] = json!(vec![0.0; targets.len()]);
        }
        mesh["primitives"] = json!([primitive]);
        gmeshes.push(mesh);
        materials.push(
            json!({"name": m.name, "doubleSided": true, "pbrMetallicRoughness": {
            "baseColorFactor": m.color, "metallicFactor": 0.0, "roughnessFactor": 0.8}}),
        );
        nodes.push(json!({"name": m.name, "mesh": i}));
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "garnet geom"},
        "scene": 0,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": gmeshes,
        "materials": materials,
    });
    if frames > 1 {
        // Key k at k / fps; its weights are one-hot at target k - 1 (none for frame 0).
        let times: Vec<f32> = (0..frames).map(|k| k as f32 / fps).collect();
        let time_view = push_view(&mut bin, &mut views, floats(&times), None);
        accessors.push(
            json!({"bufferView": time_view, "componentType": FLOAT, "count": frames,
            "type": "SCALAR", "min": [times[0] as f64], "max": [times[frames - 1] as f64]}),
        );
        let time_accessor = accessors.len() - 1;
        let targets = frames - 1;
        let mut weights = vec![0.0f32; frames * targets];
        for k in 1..frames {
            weights[k * targets + k - 1] = 1.0;
        }
        let weight_view = push_view(&mut bin, &mut views, floats(&weights), None);
        accessors.push(json!({"bufferView": weight_view, "componentType": FLOAT,
            "count": weights.len(), "type": "SCALAR"}));
        let weight_accessor = accessors.len() - 1;
        let samplers = vec![
            json!({"input": time_accessor, "output": weight_accessor, "interpolation": "LINEAR"}),
        ];
        let channels: Vec<_> = (0..meshes.len())
            .map(|node| json!({"sampler": 0, "target": {"node": node, "path": "weights"}}))
            .collect();
        doc["animations"] = json!([{"name": "drape", "samplers": samplers, "channels": channels}]);
    }
    doc["accessors"] = json!(accessors);
    doc["bufferViews"] = json!(views);
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    Ok(assemble(&doc, &bin))
}

/// Writes [`encode_animated_glb`]'s file atomically.
pub fn write_animated_glb(path: impl AsRef<Path>, meshes: &[AnimatedMesh], fps: f32) -> Result<()> {
    let bytes = encode_animated_glb(meshes, fps)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// The PC2 signature.
const PC2_MAGIC: &[u8; 12] = b"POINTCACHE2\0";

/// A point cache: the frames of one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct PointCache {
    /// The frame the first sample is at.
    pub start_frame: f32,
    /// Frames between samples (1: one sample a frame).
    pub sample_interval: f32,
    /// The samples `[T][N]`, metres.
    pub frames: Vec<Vec<Vec3>>,
}

/// Encodes `frames` (`[T][N]`, every frame `N` finite points) as a PC2 file, one sample a
/// frame from frame 0.
pub fn encode_pc2(frames: &[Vec<Vec3>]) -> Result<Vec<u8>> {
    let n = frames.first().map_or(0, Vec::len);
    if frames.is_empty() || n == 0 {
        return Err(GeomError::InvalidInput(
            "a point cache needs a frame with points".into(),
        ));
    }
    let mut out = Vec::with_capacity(32 + frames.len() * n * 12);
    out.extend_from_slice(PC2_MAGIC);
    out.extend_from_slice(&1i32.to_le_bytes());
    out.extend_from_slice(&(n as i32).to_le_bytes());
    out.extend_from_slice(&0f32.to_le_bytes());
    out.extend_from_slice(&1f32.to_le_bytes());
    out.extend_from_slice(&(frames.len() as i32).to_le_bytes());
    for (k, f) in frames.iter().enumerate() {
        if f.len() != n {
            return Err(GeomError::InvalidInput(format!(
                "point cache frame {k} has {} points, frame 0 has {n}",
                f.len()
            )));
        }
        if let Some(j) = f.iter().position(|v| !v.is_finite()) {
            return Err(GeomError::InvalidInput(format!(
                "point cache frame {k}, point {j} is not finite"
            )));
        }
        for c in f.iter().flat_map(|v| v.to_array()) {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    Ok(out)
}

/// Writes [`encode_pc2`]'s file atomically.
pub fn write_pc2(path: impl AsRef<Path>, frames: &[Vec<Vec3>]) -> Result<()> {
    let bytes = encode_pc2(frames)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Parses a PC2 file's bytes; `path` names it in errors.
pub fn parse_pc2(bytes: &[u8], path: &Path) -> Result<PointCache> {
    let bad = |m: &str| GeomError::format(path, m);
    if bytes.len() < 32 || &bytes[..12] != PC2_MAGIC {
        return Err(bad("not a PC2 point cache (no POINTCACHE2 header)"));
    }
    let i32_at = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
    if i32_at(12) != 1 {
        return Err(bad("PC2 version is not 1"));
    }
    let (n, samples) = (i32_at(16), i32_at(28));
    if n <= 0 || samples <= 0 {
        return Err(bad("PC2 point or sample count is not positive"));
    }
    let (n, samples) = (n as usize, samples as usize);
    let needed = n
        .checked_mul(samples)
        .and_then(|p| p.checked_mul(12))
        .and_then(|b| b.checked_add(32));
    if needed != Some(bytes.len()) {
        return Err(bad(&format!(
            "PC2 of {samples} samples of {n} points does not fit the file's {} bytes",
            bytes.len()
        )));
    }
    let frames = (0..samples)
        .map(|s| {
            (0..n)
                .map(|j| {
                    let o = 32 + (s * n + j) * 12;
                    Vec3::new(f32_at(o), f32_at(o + 4), f32_at(o + 8))
                })
                .collect()
        })
        .collect();
    Ok(PointCache {
        start_frame: f32_at(20),
        sample_interval: f32_at(24),
        frames,
    })
}

/// Reads a PC2 file.
pub fn read_pc2(path: impl AsRef<Path>) -> Result<PointCache> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| GeomError::format(path, e.to_string()))?;
    parse_pc2(&bytes, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames() -> (TriMesh, Vec<Vec<Vec3>>) {
        let m = TriMesh::grid(3, 2, 0.1);
        let frames = (0..4)
            .map(|k| {
                m.vertices
                    .iter()
                    .map(|v| *v + Vec3::new(0.0, 0.01 * k as f32, 0.0))
                    .collect()
            })
            .collect();
        (m, frames)
    }

    #[test]
    fn the_animation_keys_one_target_a_frame() {
        let (m, f) = frames();
        let mesh = AnimatedMesh {
            name: "sheet",
            faces: &m.faces,
            frames: &f,
            color: [0.5; 4],
            normals: true,
        };
        let bytes = encode_animated_glb(&[mesh], 30.0).unwrap();
        let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let doc: serde_json::Value = serde_json::from_slice(&bytes[20..20 + jlen]).unwrap();
        assert_eq!(
            doc["meshes"][0]["primitives"][0]["targets"]
                .as_array()
                .unwrap()
                .len(),
            3
        );
        assert_eq!(doc["meshes"][0]["weights"].as_array().unwrap().len(), 3);
        let anim = &doc["animations"][0];
        assert_eq!(anim["channels"][0]["target"]["path"], "weights");
        let times = &doc["accessors"][anim["samplers"][0]["input"].as_u64().unwrap() as usize];
        assert_eq!(times["count"], 4);
        assert!((times["max"][0].as_f64().unwrap() - 0.1).abs() < 1e-6);
        for v in doc["bufferViews"].as_array().unwrap() {
            assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0);
        }
        // The base geometry reads back as frame 0.
        let back = super::super::parse_glb(&bytes, Path::new("a.glb")).unwrap();
        assert_eq!(back[0].mesh.vertices, f[0]);
    }

    #[test]
    fn bad_animations_are_refused() {
        let (m, f) = frames();
        let ok = AnimatedMesh {
            name: "a",
            faces: &m.faces,
            frames: &f,
            color: [0.5; 4],
            normals: false,
        };
        assert!(encode_animated_glb(&[ok], 0.0).is_err());
        let short = vec![f[0].clone(), f[1][..3].to_vec()];
        assert!(encode_animated_glb(
            &[AnimatedMesh {
                frames: &short,
                ..ok
            }],
            30.0
        )
        .is_err());
        let two = &f[..2];
        let err = encode_animated_glb(&[ok, AnimatedMesh { frames: two, ..ok }], 30.0).unwrap_err();
        assert!(err.to_string().contains("frames"), "{err}");
        let mut nan = f.clone();
        nan[2][1].x = f32::NAN;
        assert!(encode_animated_glb(&[AnimatedMesh { frames: &nan, ..ok }], 30.0).is_err());
    }

    #[test]
    fn point_caches_round_trip_and_bad_files_are_named() {
        let (_, f) = frames();
        let bytes = encode_pc2(&f).unwrap();
        assert_eq!(bytes.len(), 32 + 4 * f[0].len() * 12);
        let back = parse_pc2(&bytes, Path::new("x.pc2")).unwrap();
        assert_eq!((back.start_frame, back.sample_interval), (0.0, 1.0));
        assert_eq!(back.frames, f);
        let err = parse_pc2(&bytes[..40], Path::new("cut.pc2")).unwrap_err();
        assert!(err.to_string().contains("cut.pc2"), "{err}");
        assert!(parse_pc2(b"POINTCACHE3\0xxxxxxxxxxxxxxxxxxxx", Path::new("y.pc2")).is_err());
        // Counts whose byte size overflows are refused, not wrapped.
        let mut huge = bytes.clone();
        huge[16..20].copy_from_slice(&i32::MAX.to_le_bytes());
        huge[28..32].copy_from_slice(&i32::MAX.to_le_bytes());
        assert!(parse_pc2(&huge, Path::new("huge.pc2")).is_err());
        assert!(encode_pc2(&[]).is_err());
    }
}
